//! Shells of polyhedra (see the module documentation of [`super`]): the solid hollowed to a
//! wall thickness, inward or outward, with chosen faces left open, and sharp walls where the
//! offset faces meet (the intersection join).

use glam::{DMat3, DVec3};

use crate::boolean::{BooleanJob, BooleanOp};
use crate::construct::line;
use crate::curve::SpaceCurve;
use crate::error::{GeometryError, construction};
use crate::planar::planar_face;
use crate::trim::TrimmedSurface;

use super::polyhedron::Polyhedron;
use super::{FeatureResult, WHAT, facing, point};

/// The polyhedron with each face `f`'s plane moved `distance(f)` along its outward normal and
/// each corner where its faces' moved planes meet, as flat faces; refused where a corner's
/// planes do not meet in one point or a face turns over (the offset is more than the body
/// allows there).
pub fn offset_polyhedron(
    solid: &Polyhedron,
    distance: impl Fn(usize) -> f64,
    tolerance: f64,
) -> Result<Vec<TrimmedSurface>, GeometryError> {
    replaned(
        solid,
        |f| {
            let facet = &solid.faces[f];
            (facet.normal, facet.offset + distance(f))
        },
        tolerance,
        "the wall is thicker than the body allows",
    )
}

/// The polyhedron with each face `f` on the plane `plane(f)` (its unit outward normal n and
/// offset k: n · x = k) and each corner where its faces' planes meet (least squares about the
/// old corner, (Σ nnᵀ) δ = Σ n (k − n · p), exact where three planes meet), as flat faces;
/// refused where a corner's planes do not meet in one point, or an edge vanishes or turns
/// over (`too_far` says why).
pub fn replaned(
    solid: &Polyhedron,
    plane: impl Fn(usize) -> (DVec3, f64),
    tolerance: f64,
    too_far: &str,
) -> Result<Vec<TrimmedSurface>, GeometryError> {
    replaned_with(solid, plane, &[], tolerance, too_far)
}

/// [`replaned`], each face given the loops `extra` names for it (face, closed curve) too:
/// the circles of round walls offset with it.
pub fn replaned_with(
    solid: &Polyhedron,
    plane: impl Fn(usize) -> (DVec3, f64),
    extra: &[(usize, SpaceCurve)],
    tolerance: f64,
    too_far: &str,
) -> Result<Vec<TrimmedSurface>, GeometryError> {
    let planes: Vec<(DVec3, f64)> = (0..solid.faces.len()).map(plane).collect();
    let mut moved = Vec::with_capacity(solid.vertices.len());
    for (v, &p) in solid.vertices.iter().enumerate() {
        let mut faces: Vec<usize> = solid
            .edges_at(v)
            .into_iter()
            .flat_map(|k| [solid.edges[k].left, solid.edges[k].right])
            .collect();
        faces.sort_unstable();
        faces.dedup();
        if faces.is_empty() {
            // A point dropped from every loop (where an edge runs straight on): no corner.
            moved.push(p);
            continue;
        }
        let mut m = DMat3::ZERO;
        let mut rhs = DVec3::ZERO;
        for &f in &faces {
            let (n, k) = planes[f];
            m += DMat3::from_cols(n * n.x, n * n.y, n * n.z);
            rhs += n * (k - n.dot(p));
        }
        if m.determinant().abs() < 1e-12 {
            return Err(construction(
                WHAT,
                format!("the faces at the corner {} do not fix a point", point(p)),
            ));
        }
        let q = p + m.inverse() * rhs;
        let off = faces
            .iter()
            .map(|&f| (planes[f].0.dot(q) - planes[f].1).abs())
            .fold(0.0, f64::max);
        if off > tolerance {
            return Err(construction(
                WHAT,
                format!(
                    "the {} faces at the corner {} do not meet in one point once moved; the \
                     feature is built only where they do",
                    faces.len(),
                    point(p)
                ),
            ));
        }
        moved.push(q);
    }
    let mut out = Vec::with_capacity(solid.faces.len());
    for (f, facet) in solid.faces.iter().enumerate() {
        let mut boundary = Vec::new();
        for ring in &facet.loops {
            for i in 0..ring.len() {
                let (a, b) = (ring[i], ring[(i + 1) % ring.len()]);
                let (old, new) = (solid.vertices[b] - solid.vertices[a], moved[b] - moved[a]);
                if new.dot(old) <= tolerance * old.length() {
                    return Err(construction(
                        WHAT,
                        format!(
                            "{too_far}: the edge from {} to {} of face {f} vanishes",
                            point(solid.vertices[a]),
                            point(solid.vertices[b])
                        ),
                    ));
                }
                boundary.push(line(moved[a], moved[b])?);
            }
        }
        boundary.extend(
            extra
                .iter()
                .filter(|(g, _)| *g == f)
                .map(|(_, c)| c.clone()),
        );
        let face = planar_face(&boundary)
            .map_err(|e| construction(WHAT, format!("{too_far} at face {f} ({e})")))?;
        let normal = planes[f].0;
        out.push(facing(face, |_| normal)?);
    }
    Ok(out)
}

/// The polyhedral solid `faces` hollowed to the wall thickness `thickness` (below 0 inward,
/// above 0 outward), the faces nearest the points `open` removed, at `tolerance`.
pub fn shell(
    faces: &[TrimmedSurface],
    thickness: f64,
    open: &[DVec3],
    tolerance: f64,
) -> Result<FeatureResult, GeometryError> {
    if !(thickness.is_finite() && thickness != 0.0) {
        return Err(construction(
            WHAT,
            format!("the thickness must be a number other than 0, got {thickness}"),
        ));
    }
    if !(tolerance.is_finite() && tolerance > 0.0) {
        return Err(construction(
            WHAT,
            format!("the tolerance must be a number above 0, got {tolerance}"),
        ));
    }
    if faces.iter().any(|f| f.surface().plane(tolerance).is_none()) {
        // A solid of revolution, an extruded outline of lines and arcs (a plate with a round
        // hole, a box with rounded upright edges), else a solid whose every edge is tangent.
        let made = match super::revolved::shell_revolved(faces, thickness, open, tolerance) {
            Ok(made) => made,
            Err(_) => {
                if let Some(made) = super::extruded::shell_prism(faces, thickness, open, tolerance)
                {
                    return made;
                }
                if let Some(made) = shell_walled(faces, thickness, open, tolerance) {
                    return made;
                }
                return super::smooth::shell_smooth(faces, thickness, open, tolerance);
            }
        };
        return match made {
            // Nothing open: the solid with the inner body as a void.
            (outer, inner, 0) => {
                let mut faces = outer;
                for face in &inner {
                    faces.push(face.reverse(crate::surface::Direction::U)?);
                }
                super::closed_result(faces, tolerance * 10.0, 0, "shell")
            }
            (outer, inner, picked) => hollow(&outer, &inner, tolerance, picked),
        };
    }
    let solid = Polyhedron::from_faces(faces, tolerance)?;
    let opened = solid.nearest_faces(open)?;
    if opened.len() >= solid.faces.len() {
        return Err(construction(WHAT, "a shell cannot leave every face open"));
    }
    let is_open = |f: usize| opened.contains(&f);
    let t = thickness.abs();
    let (outer, inner) = if thickness < 0.0 {
        (
            offset_polyhedron(&solid, |_| 0.0, tolerance)?,
            offset_polyhedron(&solid, |f| if is_open(f) { t } else { -t }, tolerance)?,
        )
    } else {
        (
            offset_polyhedron(&solid, |f| if is_open(f) { 0.0 } else { t }, tolerance)?,
            offset_polyhedron(&solid, |f| if is_open(f) { t } else { 0.0 }, tolerance)?,
        )
    };
    hollow(&outer, &inner, tolerance, opened.len())
}

/// The shell of a flat-faced solid with round walls square to its faces (a pin standing on
/// a block, a drilled hole, a blind pocket): every flat face and wall offset exactly
/// ([`super::rims::offset_walls`]), the corners where the moved planes meet; None where the
/// solid is not one (then another reader tries).
fn shell_walled(
    faces: &[TrimmedSurface],
    thickness: f64,
    open: &[DVec3],
    tolerance: f64,
) -> Option<Result<FeatureResult, GeometryError>> {
    let mut solid = Polyhedron::with_curved(faces, tolerance).ok()?;
    // Picked while the flat faces still hold their rims (a pin's top is a disc).
    let opened = solid.nearest_faces(open);
    let face_near = |p: DVec3| solid.nearest_face(p).map(|f| solid.face_distance(f, p));
    let near: Vec<Option<f64>> = open.iter().map(|&p| face_near(p)).collect();
    let walls = super::rims::take_walls(&mut solid, tolerance).ok()?;
    if solid.edges.is_empty()
        || walls.is_empty()
        || !solid.kept.is_empty()
        || solid.faces.iter().any(|f| !f.kept.is_empty())
    {
        return None;
    }
    Some((|| {
        let opened = opened?;
        for (&p, &face) in open.iter().zip(&near) {
            let wall = walls
                .iter()
                .map(|w| super::rims::wall_distance(w, p))
                .fold(f64::INFINITY, f64::min);
            if face.is_none_or(|d| wall < d) {
                return Err(construction(
                    WHAT,
                    format!(
                        "the face nearest {} is a round wall; a shell opens flat faces only",
                        point(p)
                    ),
                ));
            }
        }
        if opened.len() >= solid.faces.len() {
            return Err(construction(WHAT, "a shell cannot leave every face open"));
        }
        let is_open = |f: usize| opened.contains(&f);
        let t = thickness.abs();
        let offset = |face: &dyn Fn(usize) -> f64, wall: f64| {
            let (wall_faces, circles) =
                super::rims::offset_walls(&solid, &walls, face, &|_| wall, tolerance)?;
            let mut made = replaned_with(
                &solid,
                |f| {
                    let facet = &solid.faces[f];
                    (facet.normal, facet.offset + face(f))
                },
                &circles,
                tolerance,
                "the wall is thicker than the body allows",
            )?;
            made.extend(wall_faces);
            Ok::<_, GeometryError>(made)
        };
        let (outer, inner) = if thickness < 0.0 {
            (
                offset(&|_| 0.0, 0.0)?,
                offset(&|f| if is_open(f) { t } else { -t }, -t)?,
            )
        } else {
            (
                offset(&|f| if is_open(f) { 0.0 } else { t }, t)?,
                offset(&|f| if is_open(f) { t } else { 0.0 }, 0.0)?,
            )
        };
        hollow(&outer, &inner, tolerance, opened.len())
    })())
}

/// `outer` less `inner`: the shell's last step.
fn hollow(
    outer: &[TrimmedSurface],
    inner: &[TrimmedSurface],
    tolerance: f64,
    picked: usize,
) -> Result<FeatureResult, GeometryError> {
    // The offset body lies along the solid a wall's thickness away, never on it: a thin
    // wall in general position takes more cell pairs than the boolean's default to tell
    // the two apart.
    let result = BooleanJob::new(
        BooleanOp::Difference,
        (outer.to_vec(), None),
        (inner.to_vec(), None),
        tolerance,
    )?
    .with_cell_pairs(10 * crate::intersect::MAX_CELL_PAIRS)
    .run()?;
    if result.solids.is_empty() {
        return Err(construction(WHAT, "the shell leaves nothing"));
    }
    Ok(FeatureResult {
        faces: result.faces(),
        topology: result.topology(),
        picked,
    })
}
