//! Intersections of curves: a curve with a surface (any face, through [`ParametricSurface`])
//! and a curve with a curve. Both subdivide until the pieces' boxes are small (a piece's box
//! holds the samples at its ends and middle, grown by the second-order Taylor bound, as the
//! surface–surface seeds do), then converge by Newton's method: C(t) − S(u, v) = 0 (3 × 3) for
//! a curve and a surface, Gauss–Newton on |C₁(s) − C₂(t)|² for two curves. Points found twice
//! are kept once. (Patrikalakis and Maekawa, *Shape Interrogation*, §5.5–5.6.)

use glam::{DVec2, DVec3};

use crate::curve::SpaceCurve;
use crate::error::GeometryError;
use crate::intersect::{CellTree, Side};
use crate::parametric::ParametricSurface;

/// A point where a curve meets a surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurveSurfacePoint {
    pub point: DVec3,
    /// The curve's parameter.
    pub t: f64,
    /// The surface's parameters.
    pub uv: DVec2,
}

/// A point where two curves meet.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurveCurvePoint {
    pub point: DVec3,
    pub t_a: f64,
    pub t_b: f64,
}

/// The most points one intersection reports (a curve lying in the surface meets it
/// everywhere).
const MAX_POINTS: usize = 10_000;

/// A piece of a curve and the box that holds it.
#[derive(Debug, Clone, Copy)]
struct Piece {
    t: (f64, f64),
    lo: DVec3,
    hi: DVec3,
}

impl Piece {
    fn new(curve: &SpaceCurve, t: (f64, f64)) -> Option<Self> {
        let dt = t.1 - t.0;
        let mut lo = DVec3::INFINITY;
        let mut hi = DVec3::NEG_INFINITY;
        let mut bound = 0.0f64;
        for s in [0.0, 0.5, 1.0] {
            let d = curve.derivatives(t.0 + dt * s, 2).ok()?;
            lo = lo.min(d[0]);
            hi = hi.max(d[0]);
            bound = bound.max(d[2].length() * dt * dt / 8.0);
        }
        let grow = DVec3::splat(2.0 * bound);
        Some(Self {
            t,
            lo: lo - grow,
            hi: hi + grow,
        })
    }

    fn size(&self) -> f64 {
        self.lo.distance(self.hi)
    }

    fn halves(&self, curve: &SpaceCurve) -> Vec<Piece> {
        let m = 0.5 * (self.t.0 + self.t.1);
        [(self.t.0, m), (m, self.t.1)]
            .into_iter()
            .filter_map(|t| Piece::new(curve, t))
            .collect()
    }

    fn meets(&self, lo: DVec3, hi: DVec3, slack: f64) -> bool {
        (self.lo - slack).cmple(hi).all() && (lo - slack).cmple(self.hi).all()
    }
}

/// The curve's pieces between its knots.
fn pieces(curve: &SpaceCurve) -> Vec<Piece> {
    curve
        .span_breaks()
        .windows(2)
        .filter_map(|w| Piece::new(curve, (w[0], w[1])))
        .collect()
}

fn check(tolerance: f64, smallest: f64) -> Result<(), GeometryError> {
    if !(tolerance.is_finite() && tolerance > 0.0 && smallest.is_finite() && smallest > 0.0) {
        return Err(GeometryError::Construction {
            what: "curve intersection",
            message: "the tolerance and the smallest size must be numbers above 0".into(),
        });
    }
    Ok(())
}

/// Every point where `curve` meets `surface` (within `tolerance` of both), pieces subdivided
/// until smaller than `smallest`, in order along the curve.
pub fn intersect_curve_surface(
    curve: &SpaceCurve,
    surface: &dyn ParametricSurface,
    tolerance: f64,
    smallest: f64,
) -> Result<Vec<CurveSurfacePoint>, GeometryError> {
    Ok(
        intersect_curves_surface(&[curve], surface, tolerance, smallest)?
            .pop()
            .unwrap_or_default(),
    )
}

/// [`intersect_curve_surface`] for several curves against one surface, whose cells are made
/// once for them all (a curve projected by many rays): one list of points per curve.
pub fn intersect_curves_surface(
    curves: &[&SpaceCurve],
    surface: &dyn ParametricSurface,
    tolerance: f64,
    smallest: f64,
) -> Result<Vec<Vec<CurveSurfacePoint>>, GeometryError> {
    check(tolerance, smallest)?;
    let side = Side::of(surface);
    let Some(mut tree) = CellTree::new(&side) else {
        return Ok(vec![Vec::new(); curves.len()]);
    };
    Ok(curves
        .iter()
        .map(|curve| curve_against_cells(curve, &side, &mut tree, tolerance, smallest))
        .collect())
}

/// The points where `curve` meets the surface of `side`, over its cells in `tree`.
fn curve_against_cells(
    curve: &SpaceCurve,
    side: &Side<'_>,
    tree: &mut CellTree,
    tolerance: f64,
    smallest: f64,
) -> Vec<CurveSurfacePoint> {
    let mut stack: Vec<(Piece, usize)> = pieces(curve).into_iter().map(|p| (p, 0)).collect();
    let mut found: Vec<CurveSurfacePoint> = Vec::new();
    let mut work = 0usize;
    while let Some((p, k)) = stack.pop() {
        work += 1;
        if work > 4_000_000 || found.len() >= MAX_POINTS {
            break;
        }
        let c = tree.cell(k);
        if !p.meets(c.lo, c.hi, tolerance) {
            continue;
        }
        let (ps, cs) = (p.size(), c.size());
        if ps <= smallest && cs <= smallest {
            let (u, v) = c.centre();
            let t = 0.5 * (p.t.0 + p.t.1);
            if let Some(hit) = newton_curve_surface(curve, side, [t, u, v], tolerance)
                && !found
                    .iter()
                    .any(|f| f.point.distance(hit.point) <= 10.0 * tolerance)
            {
                found.push(hit);
            }
            continue;
        }
        if ps >= cs {
            for h in p.halves(curve) {
                stack.push((h, k));
            }
        } else {
            for q in tree.children(side, k) {
                stack.push((p, q));
            }
        }
    }
    found.sort_by(|a, b| a.t.total_cmp(&b.t));
    found
}

fn newton_curve_surface(
    curve: &SpaceCurve,
    side: &Side<'_>,
    mut x: [f64; 3],
    tolerance: f64,
) -> Option<CurveSurfacePoint> {
    let (t0, t1) = curve.domain();
    for _ in 0..40 {
        let c = curve.derivatives(x[0], 1).ok()?;
        let (u, v) = side.clamp(x[1], x[2]);
        let s = side.at(u, v)?;
        let f = c[0] - s.point;
        if f.length() <= tolerance {
            if !side.surface.keeps(u, v) {
                return None;
            }
            return Some(CurveSurfacePoint {
                point: 0.5 * (c[0] + s.point),
                t: x[0],
                uv: DVec2::new(u, v),
            });
        }
        // [C' −Su −Sv] dx = −f.
        let m = glam::DMat3::from_cols(c[1], -s.su, -s.sv);
        if m.determinant().abs() < 1e-300 {
            return None;
        }
        let dx = m.inverse() * -f;
        x = [(x[0] + dx.x).clamp(t0, t1), u + dx.y, v + dx.z];
        let (cu, cv) = side.clamp(x[1], x[2]);
        x[1] = cu;
        x[2] = cv;
    }
    None
}

/// Every point where curves `a` and `b` meet (within `tolerance`), in order along `a`.
pub fn intersect_curves(
    a: &SpaceCurve,
    b: &SpaceCurve,
    tolerance: f64,
    smallest: f64,
) -> Result<Vec<CurveCurvePoint>, GeometryError> {
    check(tolerance, smallest)?;
    let mut stack: Vec<(Piece, Piece)> = Vec::new();
    let pb = pieces(b);
    for p in pieces(a) {
        for q in &pb {
            stack.push((p, *q));
        }
    }
    let mut found: Vec<CurveCurvePoint> = Vec::new();
    let mut work = 0usize;
    while let Some((p, q)) = stack.pop() {
        work += 1;
        if work > 4_000_000 || found.len() >= MAX_POINTS {
            break;
        }
        if !p.meets(q.lo, q.hi, tolerance) {
            continue;
        }
        let (ps, qs) = (p.size(), q.size());
        if ps <= smallest && qs <= smallest {
            let s = [0.5 * (p.t.0 + p.t.1), 0.5 * (q.t.0 + q.t.1)];
            if let Some(hit) = newton_curves(a, b, s, tolerance)
                && !found
                    .iter()
                    .any(|f| f.point.distance(hit.point) <= 10.0 * tolerance)
            {
                found.push(hit);
            }
            continue;
        }
        if ps >= qs {
            for h in p.halves(a) {
                stack.push((h, q));
            }
        } else {
            for h in q.halves(b) {
                stack.push((p, h));
            }
        }
    }
    found.sort_by(|x, y| x.t_a.total_cmp(&y.t_a));
    Ok(found)
}

fn newton_curves(
    a: &SpaceCurve,
    b: &SpaceCurve,
    mut x: [f64; 2],
    tolerance: f64,
) -> Option<CurveCurvePoint> {
    let (da, db) = (a.domain(), b.domain());
    for _ in 0..40 {
        let ca = a.derivatives(x[0], 1).ok()?;
        let cb = b.derivatives(x[1], 1).ok()?;
        let f = ca[0] - cb[0];
        if f.length() <= tolerance {
            return Some(CurveCurvePoint {
                point: 0.5 * (ca[0] + cb[0]),
                t_a: x[0],
                t_b: x[1],
            });
        }
        // Gauss–Newton on |f|² with J = [A', −B'].
        let (j0, j1) = (ca[1], -cb[1]);
        let (m00, m01, m11) = (j0.dot(j0), j0.dot(j1), j1.dot(j1));
        let (r0, r1) = (-j0.dot(f), -j1.dot(f));
        let det = m00 * m11 - m01 * m01;
        if det.abs() < 1e-300 {
            return None;
        }
        let d0 = (r0 * m11 - r1 * m01) / det;
        let d1 = (m00 * r1 - m01 * r0) / det;
        let next = [(x[0] + d0).clamp(da.0, da.1), (x[1] + d1).clamp(db.0, db.1)];
        if (next[0] - x[0]).abs() + (next[1] - x[1]).abs() < 1e-16 {
            return None;
        }
        x = next;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::construct;

    #[test]
    fn a_line_through_a_sphere_meets_it_twice() {
        let sphere = construct::sphere(DVec3::new(0.0, 0.0, 0.0), 1.0).unwrap();
        let line = construct::line(DVec3::new(-2.0, 0.3, 0.4), DVec3::new(2.0, 0.3, 0.4)).unwrap();
        let hits = intersect_curve_surface(&line, &sphere, 1e-9, 1e-2).unwrap();
        assert_eq!(hits.len(), 2, "{hits:?}");
        let x = (1.0f64 - 0.09 - 0.16).sqrt();
        assert!((hits[0].point - DVec3::new(-x, 0.3, 0.4)).length() < 1e-8);
        assert!((hits[1].point - DVec3::new(x, 0.3, 0.4)).length() < 1e-8);
        for h in &hits {
            assert!(sphere.point_at(h.uv.x, h.uv.y).unwrap().distance(h.point) < 1e-8);
        }
        let miss = construct::line(DVec3::new(-2.0, 1.3, 0.0), DVec3::new(2.0, 1.3, 0.0)).unwrap();
        assert!(
            intersect_curve_surface(&miss, &sphere, 1e-9, 1e-2)
                .unwrap()
                .is_empty()
        );
    }

    #[test]
    fn two_circles_cross_at_two_points() {
        let a = construct::circle(DVec3::ZERO, DVec3::Z, DVec3::X, 1.0).unwrap();
        let b = construct::circle(DVec3::new(1.0, 0.0, 0.0), DVec3::Z, DVec3::X, 1.0).unwrap();
        let hits = intersect_curves(&a, &b, 1e-9, 1e-2).unwrap();
        assert_eq!(hits.len(), 2, "{hits:?}");
        for h in &hits {
            assert!(
                (h.point.x - 0.5).abs() < 1e-8 && (h.point.y.abs() - 0.75f64.sqrt()).abs() < 1e-8
            );
        }
    }
}
