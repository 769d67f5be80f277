//! File formats: knotwork's JSON format for curves and surfaces, the project file that extends
//! it to a scene, the `eval` and `construct` request formats, glTF 2.0 export and import, and OBJ import.

pub mod construct;
pub mod eval;
pub mod formats;
// The fuzz checks panic by design: not in the page.
#[cfg(not(target_arch = "wasm32"))]
pub mod fuzz;
pub mod gltf;
pub mod gltf_import;
pub mod height_image;

pub mod obj;
pub mod project;
pub mod step;
pub mod stl;
pub mod threemf;
pub mod zip;

use crate::scene::json::{self, FormatError};
use project::Project;

/// Reads any document knotwork opens, by its contents and name ([`formats::format_of`]): glTF
/// (a GLB by its magic bytes, or `.gltf`), an `.obj`, or a project (JSON). `external(name)`
/// reads a file beside it (a `.gltf`'s `.bin`); where there is none, it returns why. A PNG, a
/// height map, is refused with what to do with it instead; a file of a format knotwork does not
/// read is named, with the formats it reads.
pub fn open(
    name: &str,
    bytes: &[u8],
    external: &dyn Fn(&str) -> Result<Vec<u8>, String>,
) -> Result<Project, FormatError> {
    project::check_size(bytes.len() as u64)?;
    match formats::format_of(name, bytes).reader {
        formats::Reader::Gltf => return gltf_import::read(bytes, external),
        formats::Reader::Obj => return obj::read(&String::from_utf8_lossy(bytes)),
        formats::Reader::Step => return step::read_project(bytes, &mut |_, _| true),
        formats::Reader::HeightImage => {
            return Err(FormatError::new(
                "",
                "a PNG is a height map, not a document: select a surface and open the PNG in its Displacement panel (or drop it on the window)",
            ));
        }
        formats::Reader::Project => {}
    }
    if let Some(foreign) = formats::foreign_format(name, bytes) {
        return Err(FormatError::new(
            "",
            format!(
                "this is a {foreign} file, which knotwork does not read; it reads {}",
                formats::readable_list()
            ),
        ));
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

/// A bare object of knotwork's JSON format ([`json::read`]) as a project of its surfaces and
/// curves.
fn bare_surfaces(text: &str) -> Result<Project, FormatError> {
    let mut scene = crate::scene::Scene::default();
    for (k, object) in json::read(text)?.into_iter().enumerate() {
        let geometry = match object.geometry {
            json::Geometry::Surface(surface) => crate::scene::ObjectGeometry::new(surface),
            json::Geometry::TrimmedSurface(t) => crate::scene::ObjectGeometry::from_trimmed(t),
            json::Geometry::Curve(curve) => crate::scene::ObjectGeometry::new(curve),
            json::Geometry::Trim(_) => {
                return Err(FormatError::new(
                    "type",
                    "a trim curve is not a scene object: open a surface, a curve or a project",
                ));
            }
        };
        let base = if geometry.kind().space_curve().is_some() {
            "Curve"
        } else {
            "Surface"
        };
        let name = object.name.unwrap_or_else(|| format!("{base} {}", k + 1));
        scene
            .objects
            .push(crate::scene::SceneObject::new(name, geometry));
    }
    Ok(Project { scene, view: None })
}

/// A scene described for `knotwork info`: its unit and each object as a body (name, kind,
/// faces, whether they close it, area and, closed, volume and centroid; exact:
/// [`crate::kernel::mass`]). Objects without NURBS faces give their name and kind alone.
pub fn scene_info(scene: &crate::scene::Scene, self_intersections: bool) -> serde_json::Value {
    let bodies: Vec<serde_json::Value> = scene
        .objects
        .iter()
        .map(|object| {
            let mut body = serde_json::json!({
                "name": object.name,
                "kind": object.kind().kind_name(),
            });
            if let Some(faces) = object.body() {
                body["faces"] = faces.faces.len().into();
                body["closed"] = faces.closed().into();
                if let Some(validity) = &faces.validity {
                    body["validity"] = validity_value(&faces.faces, validity, self_intersections);
                }
                match faces.measure() {
                    Ok((area, mass)) => {
                        body["area"] = area.into();
                        if let Some(m) = mass {
                            body["volume"] = m.volume.into();
                            body["centroid"] = serde_json::json!(m.centroid.to_array());
                        }
                    }
                    Err(e) => body["error"] = e.to_string().into(),
                }
            }
            body
        })
        .collect();
    serde_json::json!({
        "unit": scene.unit.map(|u| u.symbol()),
        "bodies": bodies,
    })
}

/// A body's validity `v` for `knotwork info` ([`crate::kernel::join::validity`]): the counts
/// of naked, non-manifold and misoriented edges, and each one's place (its face, loop and
/// curve, and a point half way along it); with `self_intersections`, also where its faces
/// cross each other ([`crate::kernel::boolean::self_intersections`] at 1e-6 of the body's
/// size: the two faces and a point on the crossing).
pub fn validity_value(
    faces: &[crate::kernel::trim::TrimmedSurface],
    v: &crate::kernel::join::Validity,
    self_intersections: bool,
) -> serde_json::Value {
    use crate::kernel::join::{EdgeId, edge_polyline};
    let size = faces.iter().map(|f| f.surface().size()).fold(0.0, f64::max);
    let place = |e: EdgeId| {
        let at = edge_polyline(faces, e, 1e-3 * size)
            .ok()
            .and_then(|points| points.get(points.len() / 2).copied())
            .map(|p| p.to_array());
        serde_json::json!({"face": e.face, "loop": e.loop_index, "curve": e.curve, "at": at})
    };
    let mut value = serde_json::json!({
        "closed_shell": v.is_closed_shell(),
        "naked_edges": v.naked.len(),
        "non_manifold_edges": v.non_manifold.len(),
        "misoriented_edges": v.misoriented.len(),
        "places": {
            "naked": v.naked.iter().map(|&e| place(e)).collect::<Vec<_>>(),
            "non_manifold": v.non_manifold.iter().map(|&e| place(e)).collect::<Vec<_>>(),
            "misoriented": v.misoriented.iter().map(|&(a, _)| place(a)).collect::<Vec<_>>(),
        },
    });
    if self_intersections {
        let (lo, hi) = faces.iter().map(|f| f.surface().bounds()).fold(
            (glam::DVec3::INFINITY, glam::DVec3::NEG_INFINITY),
            |(lo, hi), (l, h)| (lo.min(l), hi.max(h)),
        );
        let tolerance = 1e-6 * lo.distance(hi).max(f64::MIN_POSITIVE);
        match crate::kernel::boolean::self_intersections(faces, tolerance) {
            Ok(found) => {
                value["self_intersections"] = found.len().into();
                value["places"]["self_intersections"] = found
                    .iter()
                    .map(|c| serde_json::json!({"faces": [c.faces.0, c.faces.1], "at": c.at.to_array()}))
                    .collect::<Vec<_>>()
                    .into();
            }
            Err(e) => value["self_intersections_error"] = e.to_string().into(),
        }
    }
    value
}
