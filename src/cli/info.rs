//! `knotwork info`: a STEP file described as JSON.

use std::process::ExitCode;

/// Runs `knotwork info`: the STEP file's description as JSON.
pub fn info(input: &std::path::Path) -> ExitCode {
    let result = std::fs::read(input)
        .map_err(|e| format!("cannot read {}: {e}", input.display()))
        .and_then(|bytes| knotwork::io::step::info(&bytes).map_err(|e| e.to_string()));
    match result {
        Ok(json) => {
            println!("{json:#}");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("knotwork info: {e}");
            ExitCode::FAILURE
        }
    }
}
