//! `knotwork construct`: a surface or a curve built from a JSON request.

use std::process::ExitCode;

use super::*;

/// Runs `knotwork construct`: the surface as JSON on standard output, or a knotwork file
/// at `output` (which the editor opens).
pub fn construct(path: &str, output: Option<&std::path::Path>) -> ExitCode {
    let result = read_request(path).and_then(|text| {
        let knotwork::io::construct::Built {
            geometry,
            name,
            report,
        } = knotwork::io::construct::build(&text).map_err(|e| e.to_string())?;
        if let Some(report) = report {
            eprintln!("knotwork construct: {report}");
        }
        match output {
            None => Ok(knotwork::io::construct::geometry_value(geometry, name).to_string()),
            Some(_) if matches!(geometry, knotwork::scene::json::Geometry::Curve(_)) => {
                Err(format!(
                    "the {name} is a curve, and the editor opens surfaces only: leave out -o \
                     to print it"
                ))
            }
            Some(out) => {
                let objects = [knotwork::scene::json::NamedGeometry {
                    name: Some(name.to_string()),
                    geometry,
                }];
                std::fs::write(out, knotwork::scene::json::write(&objects))
                    .map_err(|e| format!("cannot write {}: {e}", out.display()))?;
                Ok(format!("wrote {} ({name})", out.display()))
            }
        }
    });
    match result {
        Ok(text) => {
            println!("{text}");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("knotwork construct: {e}");
            ExitCode::FAILURE
        }
    }
}
