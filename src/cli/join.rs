//! `knotwork join`: surfaces that share edges joined into polysurfaces.

use std::process::ExitCode;

use super::*;

/// `knotwork join`: the project with its surfaces joined where they share edges.
pub fn join(path: &std::path::Path, tolerance: f64, output: &std::path::Path) -> ExitCode {
    let run = || -> Result<serde_json::Value, String> {
        let mut project = open_project(path)?;
        let started = std::time::Instant::now();
        let command = knotwork::doc::Command::operation(knotwork::ops::join::Join {
            objects: Vec::new(),
            tolerance,
        });
        let edit = knotwork::doc::apply(&mut project.scene, &command).map_err(|e| e.to_string())?;
        let millis = started.elapsed().as_secs_f64() * 1e3;
        let mut joined = Vec::new();
        for object in &project.scene.objects {
            let Some(p) = object.geometry.as_polysurface() else {
                continue;
            };
            let topology = p.topology().map_err(|e| e.to_string())?;
            joined.push(serde_json::json!({
                "name": object.name,
                "faces": p.faces().len(),
                "shared_edges": topology.shared.len(),
                "naked_edges": topology.naked.len(),
                "closed": topology.is_closed(),
            }));
        }
        write_project(&project, output)?;
        eprintln!(
            "{} in {millis:.1} ms; wrote {}",
            edit.label,
            output.display()
        );
        Ok(serde_json::json!({ "polysurfaces": joined }))
    };
    finish("join", run())
}
