//! `knotwork apply`: any registered operation, given as its JSON value, run on a project
//! through the document ([`knotwork::app::apply_to_file`]).

use std::process::ExitCode;

use super::*;

/// `knotwork apply OPERATION PROJECT -o OUT`: the project with the operation applied.
pub fn apply(
    operation: &std::path::Path,
    project: &std::path::Path,
    history: bool,
    output: &std::path::Path,
) -> ExitCode {
    let run = || -> Result<serde_json::Value, String> {
        let text = read_request(&operation.display().to_string())?;
        knotwork::app::apply_to_file(&text, project, output, history)
    };
    finish("apply", run())
}
