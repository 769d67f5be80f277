//! `knotwork bench`: the benchmarks, printed.

use std::process::ExitCode;

pub mod groups;

/// Runs `knotwork bench`.
pub fn bench(iterations: u64, only: &str) -> ExitCode {
    let context = match knotwork::gpu::GpuContext::headless_blocking() {
        Ok(c) => c,
        Err(e) => {
            eprintln!("knotwork bench: {e}");
            return ExitCode::FAILURE;
        }
    };
    match groups::run(&context, iterations as usize, only, &mut std::io::stdout()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("knotwork bench: {e}");
            ExitCode::FAILURE
        }
    }
}
