//! Shells of smooth solids: every edge tangent (a body whose every edge is filleted, a ball
//! with a cap blended in), every face a plane, ball, cylinder, cone or torus. At a tangent
//! edge both faces have one normal, so their offsets S + dN meet along the edge moved by dN:
//! each face's exact offset (an affine image, the same parameters: [`crate::offset`]) keeps
//! its trim loops, and the offsets close up as the solid did. The shell is the outer body's
//! faces and the inner one's turned over (a solid with a void); a face left open (a flat one)
//! is left out of both, and its boundary swept across the wall (its neighbours meet it
//! tangentially, so its offset's boundary is its own moved along its normal) closes the wall
//! round the opening. No boolean is needed.

use glam::DVec3;

use crate::boolean::outward_faces;
use crate::construct::extrude;
use crate::error::{GeometryError, construction};
use crate::join::{face_loops, find_topology};
use crate::offset::offset_nurbs;
use crate::trim::TrimmedSurface;

use super::{FeatureResult, WHAT, point};

/// Samples per shared edge at which the faces' normals are compared.
const EDGE_SAMPLES: usize = 5;
/// The largest angle (radians) between the faces' normals at a tangent edge.
const TANGENT_ANGLE: f64 = 1e-5;

/// The smooth solid `faces` hollowed to `thickness` (below 0 inward), the flat faces nearest
/// `open` removed, at `tolerance`; refused where an edge is not tangent, a face has no exact
/// offset, or the wall is thicker than a face's curvature allows.
pub(crate) fn shell_smooth(
    faces: &[TrimmedSurface],
    thickness: f64,
    open: &[DVec3],
    tolerance: f64,
) -> Result<FeatureResult, GeometryError> {
    let (faces, _) = outward_faces(faces, tolerance, "the solid")?;
    let topology = find_topology(&faces, tolerance)?;
    // Every shared edge tangent.
    for shared in &topology.shared {
        let (a, b) = (&faces[shared.a.face], &faces[shared.b.face]);
        let loops = face_loops(a)?;
        let Some(curve) = loops
            .get(shared.a.loop_index)
            .and_then(|l| l.get(shared.a.curve))
        else {
            continue;
        };
        let (t0, t1) = curve.domain();
        for i in 0..EDGE_SAMPLES {
            let t = t0 + (t1 - t0) * (i as f64 + 0.5) / EDGE_SAMPLES as f64;
            let uv = curve.point_at(t)?;
            let p = a.surface().point_at_clamped(uv)?;
            let na = a.surface().normal(uv.x, uv.y)?;
            let c = b.surface().closest_point(p)?;
            let nb = b.surface().normal(c.u, c.v)?;
            if na.angle_between(nb) > TANGENT_ANGLE {
                return Err(construction(
                    WHAT,
                    format!(
                        "the edge at {} is sharp ({:.2}°) between curved faces; a shell is built \
                         on flat-faced solids, solids of revolution, and solids whose every edge \
                         is smooth",
                        point(p),
                        na.angle_between(nb).to_degrees()
                    ),
                ));
            }
        }
    }
    // The faces left open: flat ones, nearest the points.
    let mut opened = Vec::new();
    for &p in open {
        if !p.is_finite() {
            return Err(construction(WHAT, "a picking point is not a finite number"));
        }
        let nearest = (0..faces.len())
            .filter_map(|k| {
                let c = faces[k].surface().closest_point(p).ok()?;
                faces[k].contains(c.u, c.v).then_some((k, c.distance))
            })
            .min_by(|x, y| x.1.total_cmp(&y.1))
            .map(|(k, _)| k)
            .ok_or_else(|| construction(WHAT, format!("no face lies under {}", point(p))))?;
        if faces[nearest].surface().plane(tolerance).is_none() {
            return Err(construction(
                WHAT,
                format!(
                    "the face at {} is curved; a smooth solid's shell opens flat faces only",
                    point(p)
                ),
            ));
        }
        opened.push(nearest);
    }
    opened.sort_unstable();
    opened.dedup();
    if opened.len() >= faces.len() {
        return Err(construction(WHAT, "a shell cannot leave every face open"));
    }
    let offset = |d: f64| -> Result<Vec<TrimmedSurface>, GeometryError> {
        faces
            .iter()
            .enumerate()
            .map(|(k, face)| {
                let moved = offset_nurbs(face.surface(), d, tolerance)?;
                if !moved.is_exact() || moved.deviation > tolerance || !moved.folds.is_empty() {
                    return Err(construction(
                        WHAT,
                        format!(
                            "face {k} has no exact offset at {d} (a wall thicker than its \
                             curvature allows, or a free-form face)"
                        ),
                    ));
                }
                face.with_surface(moved.surface)
            })
            .collect()
    };
    let t = thickness.abs();
    let (outer, inner) = if thickness < 0.0 {
        (faces.clone(), offset(-t)?)
    } else {
        (offset(t)?, faces.clone())
    };
    // The outer faces and the inner ones turned over, each open face left out of both, and
    // the wall between its two copies: its boundary swept across the wall's thickness.
    let mut shell = Vec::with_capacity(2 * faces.len());
    for k in (0..faces.len()).filter(|k| !opened.contains(k)) {
        shell.push(outer[k].clone());
        shell.push(inner[k].reverse(crate::surface::Direction::U)?);
    }
    for &k in &opened {
        let low = &inner[k];
        let Some((_, normal)) = faces[k].surface().plane(tolerance) else {
            continue;
        };
        let surface = low.surface();
        for trim_loop in face_loops(low)? {
            let edges = super::polyhedron::in_space(surface, &trim_loop, tolerance).ok_or_else(
                || {
                    construction(
                        WHAT,
                        format!("face {k}'s plane is not an affine image of its domain"),
                    )
                },
            )??;
            for (curve, edge) in trim_loop.iter().zip(&edges) {
                let wall = extrude(edge, normal * t)?;
                // Facing into the opening: to the left of the edge about the face's normal
                // (the loops keep the face on their left).
                let (t0, t1) = curve.domain();
                let middle = 0.5 * (t0 + t1);
                let along = edge.derivatives(middle, 1)?[1];
                let into = normal.cross(along);
                let [(u0, u1), (v0, v1)] = wall.domain();
                let n = wall.normal(0.5 * (u0 + u1), 0.5 * (v0 + v1))?;
                let wall = TrimmedSurface::untrimmed(wall);
                shell.push(if n.dot(into) < 0.0 {
                    wall.reverse(crate::surface::Direction::U)?
                } else {
                    wall
                });
            }
        }
    }
    let made = super::closed_result(shell, tolerance * 10.0, opened.len(), "shell")?;
    Ok(made)
}
