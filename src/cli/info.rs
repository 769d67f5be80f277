//! `knotwork info`: a model described as JSON: a STEP file's bodies as the file has them, or
//! the objects of anything else knotwork opens (a project, glTF, OBJ), each with its area and,
//! closed, its volume and centroid.

use std::process::ExitCode;

/// Runs `knotwork info`: the file's description as JSON.
pub fn info(input: &std::path::Path, self_intersections: bool) -> ExitCode {
    let name = input.to_string_lossy();
    let result = std::fs::read(input)
        .map_err(|e| format!("cannot read {}: {e}", input.display()))
        .and_then(|bytes| {
            let format = knotwork::io::formats::format_of(&name, &bytes);
            if matches!(format.reader, knotwork::io::formats::Reader::Step) {
                knotwork::io::step::info(&bytes, self_intersections).map_err(|e| e.to_string())
            } else {
                let project = knotwork::io::open(&name, &bytes, &|_| {
                    Err("external files are not read here".into())
                })
                .map_err(|e| e.to_string())?;
                Ok(knotwork::io::scene_info(&project.scene, self_intersections))
            }
        });
    match result {
        Ok(json) => {
            println!("{json:#}");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("knotwork info: {e}");
            ExitCode::FAILURE
        }
    }
}
