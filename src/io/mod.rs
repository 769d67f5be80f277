//! File formats: knotwork's JSON format for curves and surfaces, the project file that extends
//! it to a scene, the `eval` and `construct` request formats, glTF 2.0 export and import, and OBJ import.

pub mod construct;
pub mod eval;
pub mod fuzz;
pub mod gltf;
pub mod gltf_import;
pub mod height_image;
pub mod json;
pub mod obj;
pub mod project;

use json::FormatError;
use project::Project;

/// The file extensions [`open`] reads.
pub const OPEN_EXTENSIONS: [&str; 5] = ["json", "knotwork", "glb", "gltf", "obj"];

/// Reads any file knotwork opens, by its contents and name: a GLB (by its magic bytes), a
/// `.gltf`, an `.obj`, or a project (JSON). `external(name)` reads a file beside it (a
/// `.gltf`'s `.bin`); where there is none, it returns why.
pub fn open(
    name: &str,
    bytes: &[u8],
    external: &dyn Fn(&str) -> Result<Vec<u8>, String>,
) -> Result<Project, FormatError> {
    project::check_size(bytes.len() as u64)?;
    let extension = name
        .rsplit_once('.')
        .map(|(_, e)| e.to_ascii_lowercase())
        .unwrap_or_default();
    if gltf_import::is_glb(bytes) || extension == "gltf" || extension == "glb" {
        return gltf_import::read(bytes, external);
    }
    if extension == "obj" {
        return obj::read(&String::from_utf8_lossy(bytes));
    }
    let text = std::str::from_utf8(bytes)
        .map_err(|e| FormatError::new("", format!("the file is not UTF-8 text: {e}")))?;
    // A glTF file under another name still opens as glTF.
    let head: String = text.chars().take(4096).collect();
    if head.contains("\"asset\"") && !head.contains("\"format\"") {
        return gltf_import::read(bytes, external);
    }
    if head.contains("\"type\"") && !head.contains("\"format\"") {
        return bare_surfaces(text);
    }
    project::read(text)
}

/// A bare object of knotwork's JSON format ([`json::read`]) as a project of its surfaces.
fn bare_surfaces(text: &str) -> Result<Project, FormatError> {
    let mut scene = crate::scene::Scene::default();
    for (k, object) in json::read(text)?.into_iter().enumerate() {
        let geometry = match object.geometry {
            json::Geometry::Surface(surface) => crate::scene::ObjectGeometry::Nurbs(surface),
            json::Geometry::TrimmedSurface(t) => crate::scene::ObjectGeometry::from_trimmed(t),
            _ => {
                return Err(FormatError::new(
                    "type",
                    "a curve is not a scene object: open a surface or a project",
                ));
            }
        };
        let name = object.name.unwrap_or_else(|| format!("Surface {}", k + 1));
        scene
            .objects
            .push(crate::scene::SceneObject::new(name, geometry));
    }
    Ok(Project { scene, view: None })
}
