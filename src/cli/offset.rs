//! `knotwork offset`: a surface offset by a distance, added to the project through the
//! document (the offset operation, [`knotwork::ops::offset`]).

use std::process::ExitCode;

use super::*;

/// `knotwork offset`: the project with the offset of the named object added.
pub fn offset(
    path: &std::path::Path,
    name: &str,
    distance: f64,
    tolerance: f64,
    output: &std::path::Path,
) -> ExitCode {
    let run = || -> Result<serde_json::Value, String> {
        let mut project = open_project(path)?;
        let k = surface_named(&project.scene, name)?;
        let started = std::time::Instant::now();
        let operation = knotwork::ops::offset::Offset {
            object: k.into(),
            distance,
            tolerance,
        };
        let (edit, report) = knotwork::doc::apply_reporting(
            &mut project.scene,
            &knotwork::doc::Command::operation(operation),
        )
        .map_err(|e| e.to_string())?;
        let millis = started.elapsed().as_secs_f64() * 1e3;
        write_project(&project, output)?;
        let mut report = report.unwrap_or_else(|| serde_json::json!({}));
        let summary = report["summary"].as_str().unwrap_or_default().to_owned();
        eprintln!("{summary} in {millis:.1} ms; wrote {}", output.display());
        report["objects"] = added_names(&edit).into();
        Ok(report)
    };
    finish("offset", run())
}
