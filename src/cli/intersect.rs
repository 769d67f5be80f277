//! `knotwork intersect`: the branches where two objects meet, as JSON.

use std::process::ExitCode;

use super::*;

/// `knotwork intersect`: every branch of the intersection of two named objects' faces (each
/// face of one with each of the other), as JSON on standard output.
pub fn intersect(path: &std::path::Path, names: &[String], tolerance: f64) -> ExitCode {
    use knotwork::kernel::intersect::IntersectOptions;
    let run = || -> Result<serde_json::Value, String> {
        if !(tolerance.is_finite() && tolerance > 0.0) {
            return Err(format!(
                "--tolerance must be a number above 0 (got {tolerance})"
            ));
        }
        let project = open_project(path)?;
        let scene = &project.scene;
        let size = knotwork::doc::surface_ops::scene_size(scene);
        if let Some(points) = curve_points(scene, names, tolerance * size, 1e-2 * size)? {
            return Ok(serde_json::json!({
                "curves": [],
                "points": points,
                "touching": [],
            }));
        }
        let object = |name: &String| surface_named(scene, name).map(|k| &scene.objects[k]);
        let (a, b) = (object(&names[0])?, object(&names[1])?);
        let options = IntersectOptions {
            tolerance: tolerance * size,
            ..IntersectOptions::for_size(size)
        };
        let started = std::time::Instant::now();
        let mut curves = Vec::new();
        let mut touching = Vec::new();
        let found_all = knotwork::doc::surface_ops::object_intersections(a, b, &options)
            .map_err(|e| e.to_string())?;
        for found in found_all {
            touching.extend(found.touching.iter().map(|p| p.to_array()));
            for c in found.curves {
                let uv = |points: &[glam::DVec2]| -> Vec<[f64; 2]> {
                    points.iter().map(|p| p.to_array()).collect()
                };
                let mut by_name = serde_json::Map::new();
                by_name.insert(a.name.clone(), serde_json::json!(uv(&c.uv_a)));
                by_name.insert(b.name.clone(), serde_json::json!(uv(&c.uv_b)));
                curves.push(serde_json::json!({
                    "closed": c.closed,
                    "points": c.points.iter().map(|p| p.to_array()).collect::<Vec<_>>(),
                    "uv": by_name,
                }));
            }
        }
        eprintln!(
            "{} branch(es), {} touching point(s) in {:.1} ms (size {size:.4}, tolerance {:.3e})",
            curves.len(),
            touching.len(),
            started.elapsed().as_secs_f64() * 1e3,
            options.tolerance
        );
        Ok(serde_json::json!({ "curves": curves, "touching": touching }))
    };
    finish("intersect", run())
}

/// Where a curve meets a surface or another curve (`None` when neither named object is a
/// curve): each point with the curve's parameter `t` (per curve, by name, for two curves)
/// and the surface's `uv` by name.
fn curve_points(
    scene: &knotwork::scene::Scene,
    names: &[String],
    tolerance: f64,
    smallest: f64,
) -> Result<Option<Vec<serde_json::Value>>, String> {
    use knotwork::kernel::intersect_curve::{intersect_curve_surface, intersect_curves};
    let find = |name: &String| {
        scene
            .objects
            .iter()
            .find(|o| &o.name == name)
            .ok_or_else(|| format!("no object named {name:?}"))
    };
    let (a, b) = (find(&names[0])?, find(&names[1])?);
    let (ca, cb) = (a.kind().space_curve(), b.kind().space_curve());
    let points = match (ca, cb) {
        (None, None) => return Ok(None),
        (Some(x), Some(y)) => intersect_curves(x, y, tolerance, smallest)
            .map_err(|e| e.to_string())?
            .into_iter()
            .map(|h| {
                let mut t = serde_json::Map::new();
                t.insert(a.name.clone(), h.t_a.into());
                t.insert(b.name.clone(), h.t_b.into());
                serde_json::json!({ "point": h.point.to_array(), "t": t })
            })
            .collect(),
        (Some(curve), None) | (None, Some(curve)) => {
            let (surface, curve_name) = if ca.is_some() {
                (b, &a.name)
            } else {
                (a, &b.name)
            };
            surface_named(scene, &surface.name)?;
            let mut out = Vec::new();
            for (_, face) in surface.faces() {
                for h in intersect_curve_surface(curve, face.as_ref(), tolerance, smallest)
                    .map_err(|e| e.to_string())?
                {
                    let mut uv = serde_json::Map::new();
                    uv.insert(surface.name.clone(), serde_json::json!(h.uv.to_array()));
                    let mut t = serde_json::Map::new();
                    t.insert(curve_name.clone(), h.t.into());
                    out.push(serde_json::json!({
                        "point": h.point.to_array(), "t": t, "uv": uv,
                    }));
                }
            }
            out
        }
    };
    Ok(Some(points))
}
