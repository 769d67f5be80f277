//! `knotwork fillet`: a rolling-ball fillet between two surfaces, added to the project.

use std::process::ExitCode;

use super::*;

/// The options of `knotwork fillet`.
pub struct FilletArgs<'a> {
    pub input: &'a std::path::Path,
    pub names: &'a [String],
    pub radius: f64,
    pub radius_end: Option<f64>,
    pub sides: [&'a str; 2],
    pub tolerance: f64,
    pub output: &'a std::path::Path,
}

/// `knotwork fillet`: the project with both objects trimmed back and the fillet added, through
/// the document (the fillet operation, [`knotwork::ops::fillet`]).
pub fn fillet(args: FilletArgs) -> ExitCode {
    use knotwork::doc::surface_ops::FilletRequest;
    let run = || -> Result<serde_json::Value, String> {
        let mut project = open_project(args.input)?;
        let a = surface_named(&project.scene, &args.names[0])?;
        let b = surface_named(&project.scene, &args.names[1])?;
        let request = FilletRequest {
            a: a.into(),
            b: b.into(),
            radius: args.radius,
            radius_end: args.radius_end,
            front_a: args.sides[0] == "front",
            front_b: args.sides[1] == "front",
            tolerance: args.tolerance,
        };
        let started = std::time::Instant::now();
        let (edit, report) = knotwork::doc::apply_reporting(
            &mut project.scene,
            &knotwork::doc::Command::operation(request),
        )
        .map_err(|e| e.to_string())?;
        let millis = started.elapsed().as_secs_f64() * 1e3;
        let trimmed: Vec<String> = edit
            .changes
            .iter()
            .filter_map(|c| match c {
                knotwork::doc::Change::Replace { after, .. } => Some(after.name.clone()),
                _ => None,
            })
            .collect();
        let name = added_names(&edit).into_iter().next().unwrap_or_default();
        write_project(&project, args.output)?;
        let mut report = report.unwrap_or_else(|| serde_json::json!({}));
        eprintln!(
            "{} sections in {millis:.1} ms; wrote {}",
            report["sections"],
            args.output.display()
        );
        for note in report["notes"].as_array().into_iter().flatten() {
            eprintln!("knotwork fillet: {}", note.as_str().unwrap_or_default());
        }
        report["fillet"] = name.into();
        report["trimmed"] = trimmed.into();
        Ok(report)
    };
    finish("fillet", run())
}
