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

/// `knotwork fillet`: the project with both objects trimmed back and the fillet added.
pub fn fillet(args: FilletArgs) -> ExitCode {
    use knotwork::doc::surface_ops::{FilletRequest, fillet_objects};
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
        let made = fillet_objects(&project.scene, &request).map_err(|e| e.to_string())?;
        let millis = started.elapsed().as_secs_f64() * 1e3;
        let mut trimmed = Vec::new();
        for (index, after) in [a, b].into_iter().zip(made.trimmed) {
            if let Some(after) = after {
                trimmed.push(after.name.clone());
                project.scene.objects[index] = after;
            }
        }
        let name = project.scene.unique_name("fillet");
        project
            .scene
            .objects
            .push(knotwork::scene::SceneObject::new(
                name.clone(),
                knotwork::scene::ObjectGeometry::new(made.fillet.surface.clone()),
            ));
        write_project(&project, args.output)?;
        eprintln!(
            "{} sections in {millis:.1} ms; wrote {}",
            made.fillet.centres.len(),
            args.output.display()
        );
        for note in &made.notes {
            eprintln!("knotwork fillet: {note}");
        }
        Ok(serde_json::json!({
            "fillet": name,
            "trimmed": trimmed,
            "sections": made.fillet.centres.len(),
            "closed": made.fillet.closed,
            "branches": made.fillet.branches,
            "notes": made.notes,
        }))
    };
    finish("fillet", run())
}
