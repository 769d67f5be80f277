//! Planar faces: closed chains of planar curves become a plane trimmed by them (inner chains
//! make holes). The plane is a bilinear patch a little larger than the chains' control points;
//! each trim loop is a chain itself in the plane's (u, v) coordinates, which is exact because
//! the map from the plane to its parameters is affine and NURBS are affinely invariant (the
//! weights are kept).

use glam::{DVec2, DVec3};

use super::construct::plane;
use super::curve::{SpaceCurve, TrimCurve, control_box_size};
use super::error::GeometryError;
use super::error::construction;
use super::trim::TrimmedSurface;

/// How far off their plane the curves may be, as a fraction of the chain's size.
pub const PLANAR_TOLERANCE: f64 = 1e-6;
/// How far one curve's end may be from the next one's start, as a fraction of the chain's size.
pub const CHAIN_TOLERANCE: f64 = 1e-6;
/// The plane reaches this fraction of the chain's size beyond it on every side.
const MARGIN: f64 = 0.02;
/// Points per curve that fix the plane and check planarity.
const SAMPLES: usize = 32;

/// The curves of a chain put end to end: each starts where the one before ends (a curve given
/// the other way round is reversed), and the last ends where the first starts, within
/// `tolerance`. A single curve must be closed.
pub fn chained(curves: &[SpaceCurve], tolerance: f64) -> Result<Vec<SpaceCurve>, GeometryError> {
    const WHAT: &str = "planar";
    let mut chain: Vec<SpaceCurve> = Vec::with_capacity(curves.len());
    for (k, c) in curves.iter().enumerate() {
        let Some(previous) = chain.last() else {
            chain.push(c.clone());
            continue;
        };
        let (_, previous_end) = previous.ends()?;
        let (start, end) = c.ends()?;
        if start.distance(previous_end) <= tolerance {
            chain.push(c.clone());
        } else if end.distance(previous_end) <= tolerance {
            chain.push(c.reverse());
        } else if k == 1 && {
            let (first_start, _) = chain[0].ends()?;
            start.distance(first_start) <= tolerance || end.distance(first_start) <= tolerance
        } {
            // The first curve was given backwards.
            chain[0] = chain[0].reverse();
            let (_, first_end) = chain[0].ends()?;
            chain.push(if start.distance(first_end) <= tolerance {
                c.clone()
            } else {
                c.reverse()
            });
        } else {
            return Err(construction(
                WHAT,
                format!(
                    "curve {k} does not start where curve {} ends (the gap is {:.3e}); give the \
                     boundary end to end",
                    k - 1,
                    start.distance(previous_end).min(end.distance(previous_end))
                ),
            ));
        }
    }
    let (Some(first), Some(last)) = (chain.first(), chain.last()) else {
        return Err(construction(WHAT, "the boundary has no curves"));
    };
    let (start, _) = first.ends()?;
    let (_, end) = last.ends()?;
    if start.distance(end) > tolerance {
        return Err(construction(
            WHAT,
            format!(
                "the boundary is open: it ends {:.3e} away from where it starts",
                start.distance(end)
            ),
        ));
    }
    Ok(chain)
}

/// The curves sorted into closed loops: each loop starts with the first curve not yet used
/// and grows at either end by a curve (either way round) that starts or ends there, within
/// `tolerance`, until it closes. A loop that cannot close is refused.
pub fn loops_of(
    curves: &[SpaceCurve],
    tolerance: f64,
) -> Result<Vec<Vec<SpaceCurve>>, GeometryError> {
    const WHAT: &str = "planar";
    let mut left: Vec<(usize, SpaceCurve)> = curves.iter().cloned().enumerate().collect();
    let mut loops = Vec::new();
    while !left.is_empty() {
        let (first, curve) = left.remove(0);
        let mut chain = std::collections::VecDeque::from([curve]);
        loop {
            let (start, _) = chain[0].ends()?;
            let (_, end) = chain[chain.len() - 1].ends()?;
            if start.distance(end) <= tolerance {
                break;
            }
            let mut found = None;
            for (k, (_, c)) in left.iter().enumerate() {
                let (a, b) = c.ends()?;
                if a.distance(end) <= tolerance {
                    found = Some((k, c.clone(), true));
                } else if b.distance(end) <= tolerance {
                    found = Some((k, c.reverse(), true));
                } else if b.distance(start) <= tolerance {
                    found = Some((k, c.clone(), false));
                } else if a.distance(start) <= tolerance {
                    found = Some((k, c.reverse(), false));
                }
                if found.is_some() {
                    break;
                }
            }
            let Some((k, c, at_end)) = found else {
                return Err(construction(
                    WHAT,
                    format!(
                        "the boundary is open: the chain from curve {first} ends {:.3e} away \
                         from where it starts and no other curve continues it",
                        start.distance(end)
                    ),
                ));
            };
            left.remove(k);
            if at_end {
                chain.push_back(c);
            } else {
                chain.push_front(c);
            }
        }
        loops.push(chain.into_iter().collect());
    }
    Ok(loops)
}

/// The plane of a closed chain of points: their centroid, the unit normal of Newell's method
/// (the direction of the polygon's vector area, which turns counter-clockwise with the chain),
/// and the area (the vector area's length).
fn newell_plane(points: &[DVec3]) -> Option<(DVec3, DVec3, f64)> {
    let centroid = points.iter().copied().sum::<DVec3>() / points.len() as f64;
    let mut normal = DVec3::ZERO;
    for (i, p) in points.iter().enumerate() {
        let q = points[(i + 1) % points.len()];
        normal += (*p - centroid).cross(q - centroid);
    }
    (normal.length() > 0.0).then(|| (centroid, normal.normalize(), normal.length() / 2.0))
}

/// A plane trimmed by the closed chains `boundary` holds (see the module documentation and
/// [`loops_of`]: the curves in any order and direction, sorted into loops): one loop gives a
/// face, loops inside it holes, loops inside holes islands. The normal turns counter-clockwise
/// with the largest loop (the right-hand rule). Refused: a chain that does not close, curves off
/// one plane by more than [`PLANAR_TOLERANCE`] of their size, loops on a line, loops that cross.
pub fn planar_face(boundary: &[SpaceCurve]) -> Result<TrimmedSurface, GeometryError> {
    const WHAT: &str = "planar";
    if boundary.is_empty() {
        return Err(construction(WHAT, "the boundary has no curves"));
    }
    let size = control_box_size(boundary);
    if !(size > 0.0) {
        return Err(construction(WHAT, "the boundary has no extent"));
    }
    let loops = loops_of(boundary, CHAIN_TOLERANCE * size)?;
    let sample = |chain: &[SpaceCurve]| -> Result<Vec<DVec3>, GeometryError> {
        let mut samples = Vec::with_capacity(chain.len() * SAMPLES);
        for c in chain {
            for i in 0..SAMPLES {
                samples.push(c.point_at(c.parameter_at(i as f64 / SAMPLES as f64))?);
            }
        }
        Ok(samples)
    };
    let samples: Vec<Vec<DVec3>> = loops.iter().map(|l| sample(l)).collect::<Result<_, _>>()?;
    // The plane of the loop with the largest area (the outer one): its normal turns with it.
    let Some((centre, normal, _)) = samples
        .iter()
        .filter_map(|s| newell_plane(s))
        .max_by(|a, b| a.2.total_cmp(&b.2))
    else {
        return Err(construction(WHAT, "the boundary encloses no area"));
    };
    let off = |p: DVec3| (p - centre).dot(normal).abs();
    let control = loops
        .iter()
        .flatten()
        .flat_map(|c| (0..c.count()).map(|i| c.control_point(i)));
    if let Some(worst) = samples
        .iter()
        .flatten()
        .copied()
        .chain(control)
        .max_by(|a, b| off(*a).total_cmp(&off(*b)))
        .filter(|&p| off(p) > PLANAR_TOLERANCE * size)
    {
        return Err(construction(
            WHAT,
            format!(
                "the boundary is not planar: the point ({:.6}, {:.6}, {:.6}) is {:.3e} off the \
                 plane of the rest",
                worst.x,
                worst.y,
                worst.z,
                off(worst)
            ),
        ));
    }
    // The plane's axes: the world x axis in the plane (y where x is along the normal).
    let reference = if normal.x.abs() < 0.9 {
        DVec3::X
    } else {
        DVec3::Y
    };
    let e1 = (reference - normal * reference.dot(normal)).normalize();
    let e2 = normal.cross(e1);
    let local = |p: DVec3| DVec2::new((p - centre).dot(e1), (p - centre).dot(e2));
    let mut min = DVec2::splat(f64::INFINITY);
    let mut max = DVec2::splat(f64::NEG_INFINITY);
    for c in loops.iter().flatten() {
        for i in 0..c.count() {
            min = min.min(local(c.control_point(i)));
            max = max.max(local(c.control_point(i)));
        }
    }
    let margin = MARGIN * (max - min).max_element();
    let (min, max) = (min - margin, max + margin);
    let extent = max - min;
    let surface = plane(
        centre + e1 * min.x + e2 * min.y,
        e1 * extent.x,
        e2 * extent.y,
    )?;
    let to_uv = |p: DVec3| (local(p) - min) / extent;
    let trims = loops
        .iter()
        .map(|chain| trim_loop(chain, &to_uv))
        .collect::<Result<Vec<_>, _>>()?;
    TrimmedSurface::new(surface, trims)
}

/// A closed chain of planar curves as a trim loop in the plane's (u, v) (`to_uv`, affine, so
/// the control points map exactly and the weights stay), its joints closed exactly: each curve
/// starts at the end of the one before, and the last ends at the first one's start.
fn trim_loop(
    chain: &[SpaceCurve],
    to_uv: &impl Fn(DVec3) -> DVec2,
) -> Result<Vec<TrimCurve>, GeometryError> {
    let mut trims: Vec<TrimCurve> = Vec::with_capacity(chain.len());
    for c in chain {
        let c = c.clamped();
        let mut points: Vec<DVec2> = (0..c.count()).map(|i| to_uv(c.control_point(i))).collect();
        let weights = (0..c.count()).map(|i| c.weight(i)).collect();
        if let Some(previous) = trims.last() {
            points[0] = previous.control_point(previous.count() - 1);
        }
        trims.push(TrimCurve::new(
            c.degree(),
            c.knots().to_vec(),
            points,
            Some(weights),
        )?);
    }
    if let (Some(first), Some(last)) = (trims.first().cloned(), trims.last_mut()) {
        let n = last.count();
        let mut points: Vec<DVec2> = (0..n).map(|i| last.control_point(i)).collect();
        points[n - 1] = first.control_point(0);
        let weights = (0..n).map(|i| last.weight(i)).collect();
        *last = TrimCurve::new(last.degree(), last.knots().to_vec(), points, Some(weights))?;
    }
    Ok(trims)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::construct::{arc, circle, line};
    use std::f64::consts::PI;

    #[test]
    fn a_tilted_circle_gives_a_disc_of_its_area() {
        let normal = DVec3::new(1.0, 2.0, 3.0).normalize();
        let c = circle(DVec3::new(1.0, -1.0, 2.0), normal, DVec3::X, 2.0).unwrap();
        let face = planar_face(&[c]).unwrap();
        let s = face.surface();
        // The surface's normal is the circle's.
        let n = s.normal(0.5, 0.5).unwrap();
        assert!(n.distance(normal) < 1e-12, "{n}");
        // The kept area, in parameters times the patch's area, is π r².
        let [(u0, u1), (v0, v1)] = s.domain();
        let side_u = s.point_at(u1, v0).unwrap() - s.point_at(u0, v0).unwrap();
        let side_v = s.point_at(u0, v1).unwrap() - s.point_at(u0, v0).unwrap();
        let area = face.parameter_area(1e-7) * side_u.cross(side_v).length();
        assert!((area - PI * 4.0).abs() < 1e-4, "area {area}");
    }

    #[test]
    fn a_chain_of_lines_and_arcs_in_any_direction_closes() {
        // A stadium: two lines and two half circles, the second line given backwards.
        let a = line(DVec3::new(0.0, 0.0, 0.0), DVec3::new(2.0, 0.0, 0.0)).unwrap();
        let b = arc(
            DVec3::new(2.0, 1.0, 0.0),
            DVec3::Y,
            -DVec3::X,
            1.0,
            PI,
            2.0 * PI,
        )
        .unwrap();
        let c = line(DVec3::new(0.0, 2.0, 0.0), DVec3::new(2.0, 2.0, 0.0)).unwrap();
        let d = arc(DVec3::new(0.0, 1.0, 0.0), DVec3::Y, -DVec3::X, 1.0, 0.0, PI).unwrap();
        let face = planar_face(&[a, b, c, d]);
        let face = face.unwrap();
        assert_eq!(face.loops().len(), 1);
    }

    #[test]
    fn a_square_with_a_round_hole_has_the_area_between() {
        // The square's sides out of order and one reversed, then the circle.
        let c = [
            DVec3::ZERO,
            DVec3::new(4.0, 0.0, 0.0),
            DVec3::new(4.0, 4.0, 0.0),
            DVec3::new(0.0, 4.0, 0.0),
        ];
        let side = |k: usize| line(c[k], c[(k + 1) % 4]).unwrap();
        let hole = circle(DVec3::new(2.0, 2.0, 0.0), DVec3::Z, DVec3::X, 1.0).unwrap();
        let face = planar_face(&[side(2), hole, side(0), side(3).reverse(), side(1)]).unwrap();
        assert_eq!(face.loops().len(), 2);
        let s = face.surface();
        let corner = s.point_at(0.0, 0.0).unwrap();
        let side_u = s.point_at(1.0, 0.0).unwrap() - corner;
        let side_v = s.point_at(0.0, 1.0).unwrap() - corner;
        let area = face.parameter_area(1e-7) * side_u.cross(side_v).length();
        assert!((area - (16.0 - PI)).abs() < 1e-5, "area {area}");
        // The normal follows the square (counter-clockwise seen from +z).
        assert!(s.normal(0.5, 0.5).unwrap().z > 0.999);
    }

    #[test]
    fn open_and_bent_boundaries_are_refused() {
        let a = line(DVec3::ZERO, DVec3::X).unwrap();
        let b = line(DVec3::X, DVec3::Y).unwrap();
        let e = planar_face(&[a.clone(), b.clone()]).unwrap_err();
        assert!(e.to_string().contains("open"), "{e}");
        let c = line(DVec3::Y, DVec3::new(0.0, 0.5, 0.5)).unwrap();
        let d = line(DVec3::new(0.0, 0.5, 0.5), DVec3::ZERO).unwrap();
        let e = planar_face(&[a, b, c, d]).unwrap_err();
        assert!(e.to_string().contains("not planar"), "{e}");
    }
}
