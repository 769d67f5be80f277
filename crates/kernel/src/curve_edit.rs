//! Exact edits of curves that change their shape: projection onto a plane and extension by a
//! tangent line (the approximating ones, rebuild, fit and offset, are in [`super::fit`]).

use glam::DVec3;

use super::construct::line;
use super::curve::SpaceCurve;
use super::error::GeometryError;
use super::error::construction;

/// `curve` projected onto the plane through `origin` with normal `normal` along the normal:
/// P ↦ P − n ((P − o)·n). The projection is affine, so mapping the control points (weights
/// kept) projects the curve exactly.
pub fn projected_onto_plane(
    curve: &SpaceCurve,
    origin: DVec3,
    normal: DVec3,
) -> Result<SpaceCurve, GeometryError> {
    if !(normal.length() > 0.0 && normal.is_finite() && origin.is_finite()) {
        return Err(construction(
            "project",
            "the plane needs a finite origin and a normal of non-zero length",
        ));
    }
    let n = normal.normalize();
    curve.map_points(|p| p - n * (p - origin).dot(n))
}

/// Which end of a curve.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CurveEnd {
    Start,
    End,
}

/// `curve` extended at `end` by a straight line of `length` along its tangent there, joined
/// to it with a knot of full multiplicity ([`SpaceCurve::join`]): the same curve up to the old
/// end, then the line, tangent-continuous (G1) at the joint. Exact.
pub fn extended(
    curve: &SpaceCurve,
    length: f64,
    end: CurveEnd,
) -> Result<SpaceCurve, GeometryError> {
    const WHAT: &str = "extend";
    if !(length > 0.0 && length.is_finite()) {
        return Err(construction(
            WHAT,
            format!("the length {length} must be a positive number"),
        ));
    }
    let (a, b) = curve.domain();
    let at = if end == CurveEnd::Start { a } else { b };
    let d = curve.derivatives(at, 1)?;
    if !(d[1].length() > 1e-300) {
        return Err(construction(WHAT, "the tangent vanishes at that end"));
    }
    let step = d[1].normalize() * length;
    match end {
        CurveEnd::End => curve.join(&line(d[0], d[0] + step)?),
        CurveEnd::Start => line(d[0] - step, d[0])?.join(curve),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::construct::arc;

    #[test]
    fn a_projected_curve_lies_in_the_plane_over_the_original() {
        let c = arc(
            DVec3::new(0.0, 0.0, 2.0),
            DVec3::X,
            DVec3::new(0.0, 0.6, 0.8),
            1.0,
            0.0,
            2.0,
        )
        .unwrap();
        let normal = DVec3::new(0.0, 0.0, 2.0);
        let p = projected_onto_plane(&c, DVec3::new(0.0, 0.0, -1.0), normal).unwrap();
        for i in 0..=20 {
            let t = i as f64 / 20.0;
            let (q, r) = (p.point_at(t).unwrap(), c.point_at(t).unwrap());
            assert!((q.z + 1.0).abs() < 1e-12);
            assert!((q.truncate() - r.truncate()).length() < 1e-12);
        }
    }

    #[test]
    fn an_extended_arc_keeps_the_arc_and_continues_along_its_tangent() {
        let c = arc(DVec3::ZERO, DVec3::X, DVec3::Y, 1.0, 0.0, 1.0).unwrap();
        for end in [CurveEnd::Start, CurveEnd::End] {
            let e = extended(&c, 0.5, end).unwrap();
            let (a, b) = e.domain();
            let (tip, joint) = match end {
                CurveEnd::Start => (e.point_at(a).unwrap(), DVec3::X),
                CurveEnd::End => (
                    e.point_at(b).unwrap(),
                    DVec3::new(1f64.cos(), 1f64.sin(), 0.0),
                ),
            };
            // The tip is 0.5 from the old end, along the circle's tangent there.
            assert!((tip.distance(joint) - 0.5).abs() < 1e-12);
            assert!((tip - joint).dot(joint).abs() < 1e-12, "not tangent");
            // The arc is still there: every point of it lies on the unit circle or the line.
            let on_circle = (0..=40)
                .map(|i| e.point_at(e.parameter_at(i as f64 / 40.0)).unwrap())
                .filter(|p| (p.length() - 1.0).abs() < 1e-12)
                .count();
            assert!(on_circle >= 20, "{on_circle} of 41 samples on the arc");
        }
        assert!(extended(&c, 0.0, CurveEnd::End).is_err());
    }
}
