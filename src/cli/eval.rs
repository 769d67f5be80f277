//! `knotwork eval`: a NURBS surface evaluated at parameters, on the CPU or the GPU.

use std::process::ExitCode;

use super::*;

/// Runs `knotwork eval`: exit code 0 with the results on stdout, 1 with the error on stderr.
pub fn eval(path: &str, backend: Backend) -> ExitCode {
    let text = match read_request(path) {
        Ok(text) => text,
        Err(message) => {
            eprintln!("knotwork eval: {message}");
            return ExitCode::FAILURE;
        }
    };
    let response = match backend {
        Backend::Cpu => knotwork::io::eval::evaluate_request(&text).map_err(|e| e.to_string()),
        Backend::Gpu => eval_gpu(&text),
    };
    match response {
        Ok(response) => {
            println!("{response}");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("knotwork eval: {e}");
            ExitCode::FAILURE
        }
    }
}

/// The request evaluated by the compute shaders on a headless device.
fn eval_gpu(text: &str) -> Result<serde_json::Value, String> {
    use knotwork::io::eval;
    let request = eval::parse_request(text).map_err(|e| e.to_string())?;
    let context = knotwork::gpu::GpuContext::headless_blocking().map_err(|e| e.to_string())?;
    let mut failure = None;
    let response =
        eval::respond(
            &request,
            |surface, pairs| match knotwork::gpu::point_eval::evaluate_points(
                &context.device,
                &context.queue,
                surface,
                pairs,
            ) {
                Ok(results) => results
                    .into_iter()
                    .map(|r| r.map_err(|e| e.to_string()))
                    .collect(),
                Err(e) => {
                    failure = Some(e.to_string());
                    Vec::new()
                }
            },
        );
    match failure {
        Some(e) => Err(e),
        None => Ok(response),
    }
}
