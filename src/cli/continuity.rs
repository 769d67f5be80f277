//! `knotwork continuity`: the gap, angle and curvature across shared edges, as JSON.

use std::process::ExitCode;

/// `knotwork continuity`: the shared edges' numbers as JSON on standard output.
pub fn continuity(
    path: &std::path::Path,
    names: &[String],
    samples: u32,
    [distance, angle, curvature]: [Option<f64>; 3],
) -> ExitCode {
    use knotwork::scene::continuity::{ContinuityOptions, analyse};
    let run = || -> Result<String, String> {
        let project = knotwork::app::open_path(path)
            .map_err(|e| format!("cannot open {}: {e}", path.display()))?;
        let scene = &project.scene;
        let mut objects = Vec::new();
        for name in names {
            let k = scene
                .objects
                .iter()
                .position(|o| &o.name == name)
                .ok_or_else(|| format!("no object named {name:?}"))?;
            objects.push(k);
        }
        let saved = project
            .view
            .map(|v| v.analysis)
            .unwrap_or_default()
            .continuity_options();
        let options = ContinuityOptions {
            gap: distance.unwrap_or(saved.gap),
            angle_degrees: angle.unwrap_or(saved.angle_degrees),
            curvature: curvature.unwrap_or(saved.curvature),
            samples: samples as usize,
        };
        for (name, value) in [
            ("--distance", options.gap),
            ("--angle", options.angle_degrees),
            ("--curvature", options.curvature),
        ] {
            if !(value.is_finite() && value > 0.0) {
                return Err(format!("{name} must be a number above 0 (got {value})"));
            }
        }
        let started = std::time::Instant::now();
        let report = analyse(
            scene,
            (!objects.is_empty()).then_some(&objects[..]),
            &options,
        );
        eprintln!(
            "{} shared edges among {} faces in {:.1} ms (size {:.4}, gap tolerance {:.3e}, angle {}°, curvature {})",
            report.edges.len(),
            report.faces.len(),
            started.elapsed().as_secs_f64() * 1e3,
            report.size,
            report.tolerances.distance,
            report.tolerances.angle_degrees,
            report.tolerances.curvature
        );
        serde_json::to_string_pretty(&report.to_json(scene)).map_err(|e| e.to_string())
    };
    match run() {
        Ok(json) => {
            println!("{json}");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("knotwork continuity: {e}");
            ExitCode::FAILURE
        }
    }
}
