//! `knotwork offset`: a surface offset by a distance, added to the project.

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
    use knotwork::doc::surface_ops::{offset_geometry, offset_summary};
    let run = || -> Result<serde_json::Value, String> {
        let mut project = open_project(path)?;
        let k = surface_named(&project.scene, name)?;
        let started = std::time::Instant::now();
        let made =
            offset_geometry(&project.scene, k, distance, tolerance).map_err(|e| e.to_string())?;
        let millis = started.elapsed().as_secs_f64() * 1e3;
        let offsets: Vec<_> = made.iter().map(|(_, o)| o.clone()).collect();
        let mut names = Vec::new();
        for (geometry, _) in made {
            let object_name = project.scene.unique_name(&format!("{name} offset"));
            names.push(object_name.clone());
            project
                .scene
                .objects
                .push(knotwork::scene::SceneObject::new(object_name, geometry));
        }
        write_project(&project, output)?;
        let summary = offset_summary(&offsets, distance);
        eprintln!("{summary} in {millis:.1} ms; wrote {}", output.display());
        let folds: Vec<_> = offsets
            .iter()
            .flat_map(|o| &o.folds)
            .map(|f| {
                serde_json::json!({
                    "point": f.point.to_array(),
                    "uv": f.uv.to_array(),
                    "radius": f.radius,
                })
            })
            .collect();
        Ok(serde_json::json!({
            "objects": names,
            "exact": offsets.iter().all(|o| o.is_exact()),
            "deviation": offsets.iter().map(|o| o.deviation).fold(0.0, f64::max),
            "fold_samples": offsets.iter().map(|o| o.fold_samples).sum::<usize>(),
            "folds": folds,
            "summary": summary,
        }))
    };
    finish("offset", run())
}
