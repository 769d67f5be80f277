//! Surfaces from two, three or four edge curves (Rhino's EdgeSrf): two curves give the ruled
//! surface between them; three or four that meet end to end give a Coons patch bounded by them
//! (with three, one side collapses to a corner).

use glam::DVec3;

use super::construct::{coons, ruled};
use super::curve::{SpaceCurve, control_box_size};
use super::error::GeometryError;
use super::error::construction;
use super::loft::align_sections;
use super::planar::chained;
use super::splines::polynomial_approximation;
use super::surface::NurbsSurface;

/// Edge curves meet where their ends are closer than this fraction of their size.
pub const EDGE_TOLERANCE: f64 = 1e-4;
/// Rational edges are followed by non-rational ones within this fraction of their size.
const APPROXIMATION: f64 = 1e-9;

/// `curve` clamped and non-rational (within `tolerance`), with its first control point moved
/// to `start` (its start point: a gap within the chaining tolerance closes there).
fn snapped(curve: &SpaceCurve, start: DVec3, tolerance: f64) -> Result<SpaceCurve, GeometryError> {
    let c = polynomial_approximation(&curve.clamped(), tolerance)?.clamped();
    let mut points: Vec<DVec3> = (0..c.count()).map(|i| c.control_point(i)).collect();
    points[0] = start;
    SpaceCurve::new(c.degree(), c.knots().to_vec(), points, None)
}

/// The surface bounded by 2 to 4 edge curves given in any order of a chain and any direction:
/// two curves give the ruled surface between them (turned to run the same way); three or four
/// that meet end to end (within [`EDGE_TOLERANCE`] of their size) give the bilinearly blended
/// Coons patch with the first curve along u at v = 0 and the second along v at u = 1 (with
/// three, the side u = 0 is the corner where the first curve starts). Rational curves are
/// followed within 1e-9 of their size by non-rational ones, which a Coons patch needs.
pub fn edge_surface(curves: &[SpaceCurve]) -> Result<NurbsSurface, GeometryError> {
    const WHAT: &str = "edge surface";
    let size = control_box_size(curves);
    if !(size > 0.0) && !curves.is_empty() {
        return Err(construction(WHAT, "the curves have no extent"));
    }
    match curves.len() {
        2 => {
            let aligned = align_sections(curves)?;
            ruled(&aligned[0], &aligned[1])
        }
        3 | 4 => {
            let chain = chained(curves, EDGE_TOLERANCE * size)?;
            let tolerance = APPROXIMATION * size;
            // Each curve starts exactly where the one before ends.
            let mut edges: Vec<SpaceCurve> = Vec::with_capacity(chain.len());
            for c in &chain {
                let start = match edges.last() {
                    Some(previous) => previous.ends()?.1,
                    None => c.ends()?.0,
                };
                edges.push(snapped(c, start, tolerance)?);
            }
            // The last one ends at the first one's start.
            let (first_start, _) = edges[0].ends()?;
            let last = edges.len() - 1;
            let reversed = snapped(&edges[last].reverse(), first_start, tolerance)?;
            edges[last] = reversed.reverse();
            let bottom = &edges[0];
            let right = &edges[1];
            let top = edges[2].reverse();
            let left = if edges.len() == 4 {
                edges[3].reverse()
            } else {
                SpaceCurve::new(1, vec![0.0, 0.0, 1.0, 1.0], vec![first_start; 2], None)?
            };
            coons(bottom, &top, &left, right)
        }
        n => Err(construction(
            WHAT,
            format!("needs 2, 3 or 4 curves, found {n}"),
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::construct::{arc, line};
    use std::f64::consts::FRAC_PI_2;

    /// The largest distance from the curve's points to the surface.
    fn distance_from(surface: &NurbsSurface, curve: &SpaceCurve) -> f64 {
        crate::test_support::curve_to_surface(surface, curve, 30)
    }

    #[test]
    fn four_edges_in_any_order_and_direction_bound_the_surface() {
        // A saddle-ish boundary: two lines and two arcs (rational), shuffled and reversed.
        let a = line(DVec3::ZERO, DVec3::new(2.0, 0.0, 0.0)).unwrap();
        let b = arc(
            DVec3::new(2.0, 1.0, 0.0),
            DVec3::new(0.0, -1.0, 0.0),
            DVec3::Z,
            1.0,
            0.0,
            2.0 * FRAC_PI_2,
        )
        .unwrap();
        let c = line(DVec3::new(2.0, 2.0, 0.0), DVec3::new(0.0, 2.0, 0.0)).unwrap();
        let d = line(DVec3::new(0.0, 2.0, 0.0), DVec3::ZERO).unwrap();
        let curves = [a.clone(), c.reverse(), b.clone(), d.clone()];
        // Not a chain in this order: the second curve does not start where the first ends.
        assert!(edge_surface(&curves).is_err());
        let chain = [a.clone(), b.clone(), c.reverse().reverse(), d.clone()];
        let s = edge_surface(&chain).unwrap();
        for edge in &chain {
            let gap = distance_from(&s, edge);
            assert!(gap < 1e-8, "an edge is {gap:e} from the surface");
        }
        // With reversed members the chain still closes.
        let mixed = [a.clone(), b.reverse(), c.clone(), d.reverse()];
        let s = edge_surface(&mixed).unwrap();
        for edge in &mixed {
            assert!(distance_from(&s, edge) < 1e-8);
        }
    }

    #[test]
    fn three_edges_make_a_patch_with_a_corner() {
        let a = line(DVec3::ZERO, DVec3::X).unwrap();
        let b = line(DVec3::X, DVec3::new(0.0, 1.0, 0.3)).unwrap();
        let c = line(DVec3::new(0.0, 1.0, 0.3), DVec3::ZERO).unwrap();
        let s = edge_surface(&[a.clone(), b.clone(), c.clone()]).unwrap();
        // The boundary in the curves' own parameters: bottom a, right b, top c reversed (point
        // inversion is ill-posed next to the collapsed side, so the check is parametric).
        for i in 0..=10 {
            let t = i as f64 / 10.0;
            let pairs = [
                (s.point_at(t, 0.0).unwrap(), a.point_at(t).unwrap()),
                (s.point_at(1.0, t).unwrap(), b.point_at(t).unwrap()),
                (s.point_at(t, 1.0).unwrap(), c.point_at(1.0 - t).unwrap()),
            ];
            for (on_surface, on_curve) in pairs {
                assert!(
                    on_surface.distance(on_curve) < 1e-12,
                    "{on_surface} vs {on_curve}"
                );
            }
        }
        // The side u = 0 is the corner at the origin.
        for j in 0..=4 {
            let p = s.point_at(0.0, j as f64 / 4.0).unwrap();
            assert!(p.length() < 1e-12, "{p}");
        }
    }

    #[test]
    fn two_edges_give_the_ruled_surface_and_other_counts_are_refused() {
        let a = line(DVec3::ZERO, DVec3::X).unwrap();
        let b = line(DVec3::new(1.0, 1.0, 1.0), DVec3::new(0.0, 1.0, 1.0)).unwrap();
        let s = edge_surface(&[a.clone(), b.clone()]).unwrap();
        // Turned to run the same way: no twist, so the middle is the middle of the box.
        let p = s.point_at(0.5, 0.5).unwrap();
        assert!(p.distance(DVec3::new(0.5, 0.5, 0.5)) < 1e-12, "{p}");
        assert!(edge_surface(std::slice::from_ref(&a)).is_err());
        assert!(edge_surface(&[a.clone(), b.clone(), a.clone(), b.clone(), a]).is_err());
    }
}
