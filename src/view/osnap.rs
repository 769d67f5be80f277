//! Object snaps for drawing on curves: the exact points a click near them lands on — where two
//! curves cross, the foot of the perpendicular from the last point placed, and the points
//! where a line from it touches a curve. Each is computed on the f64 curve and refined there;
//! the screen only says which one is meant.

use glam::{DVec2, DVec3};

use super::pick::PickView;
use crate::kernel::SpaceCurve;

/// Samples per curve for finding snaps before refinement.
const SAMPLES: usize = 200;

/// A curve sampled at [`SAMPLES`] + 1 evenly spaced parameters: (parameter, point, screen).
pub struct Sampled<'a> {
    pub curve: &'a SpaceCurve,
    samples: Vec<(f64, DVec3, Option<DVec2>)>,
}

impl<'a> Sampled<'a> {
    pub fn new(curve: &'a SpaceCurve, view: &PickView) -> Self {
        let samples = (0..=SAMPLES)
            .filter_map(|k| {
                let t = curve.parameter_at(k as f64 / SAMPLES as f64);
                let p = curve.point_at(t).ok()?;
                Some((t, p, view.project(p).map(|q| q.screen)))
            })
            .collect();
        Self { curve, samples }
    }

    /// Whether the curve passes within `radius` pixels of `cursor` on screen.
    pub fn near(&self, cursor: DVec2, radius: f64) -> bool {
        self.samples.windows(2).any(|w| match (w[0].2, w[1].2) {
            (Some(a), Some(b)) => segment_distance(a, b, cursor) <= radius,
            _ => false,
        })
    }
}

/// The distance from `p` to the segment ab.
fn segment_distance(a: DVec2, b: DVec2, p: DVec2) -> f64 {
    let ab = b - a;
    let t = ((p - a).dot(ab) / ab.length_squared().max(1e-300)).clamp(0.0, 1.0);
    p.distance(a + ab * t)
}

/// Where the segments ab and cd cross, as the fraction along each, if they do.
fn segments_cross(a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> Option<(f64, f64)> {
    let (r, s) = (b - a, d - c);
    let denom = r.perp_dot(s);
    if denom.abs() < 1e-300 {
        return None;
    }
    let t = (c - a).perp_dot(s) / denom;
    let u = (c - a).perp_dot(r) / denom;
    ((0.0..=1.0).contains(&t) && (0.0..=1.0).contains(&u)).then_some((t, u))
}

/// The points where curves `a` and `b` cross in space (within `tolerance`), whose screen
/// position is within `radius` of `cursor`: the crossings of their projections near the
/// cursor, each refined by alternating point inversions (The NURBS Book §6.1) and kept only
/// where the curves really meet.
pub fn intersections(
    a: &Sampled<'_>,
    b: &Sampled<'_>,
    view: &PickView,
    cursor: DVec2,
    radius: f64,
    tolerance: f64,
) -> Vec<DVec3> {
    let mut found: Vec<DVec3> = Vec::new();
    for p in a.samples.windows(2) {
        let (Some(p0), Some(p1)) = (p[0].2, p[1].2) else {
            continue;
        };
        if segment_distance(p0, p1, cursor) > radius {
            continue;
        }
        for q in b.samples.windows(2) {
            let (Some(q0), Some(q1)) = (q[0].2, q[1].2) else {
                continue;
            };
            let Some((f, g)) = segments_cross(p0, p1, q0, q1) else {
                continue;
            };
            let mut s = p[0].0 + (p[1].0 - p[0].0) * f;
            let mut t = q[0].0 + (q[1].0 - q[0].0) * g;
            for _ in 0..30 {
                let (Ok(on_a), Ok(on_b)) = (a.curve.point_at(s), b.curve.point_at(t)) else {
                    break;
                };
                let Ok(next_t) = b.curve.closest_parameter(on_a) else {
                    break;
                };
                let Ok(next_s) = a.curve.closest_parameter(on_b) else {
                    break;
                };
                let moved = (next_s - s).abs() + (next_t - t).abs();
                (s, t) = (next_s, next_t);
                if moved < 1e-15 {
                    break;
                }
            }
            let (Ok(x), Ok(y)) = (a.curve.point_at(s), b.curve.point_at(t)) else {
                continue;
            };
            let on_screen = view
                .project(x)
                .is_some_and(|q| q.screen.distance(cursor) <= radius);
            if x.distance(y) <= tolerance
                && on_screen
                && found.iter().all(|f| f.distance(x) > tolerance)
            {
                found.push(x);
            }
        }
    }
    found
}

/// The foot of the perpendicular from `from` to the curve, where it is inside the curve (not
/// an end), by point inversion.
pub fn perpendicular(curve: &SpaceCurve, from: DVec3) -> Option<DVec3> {
    let t = curve.closest_parameter(from).ok()?;
    let (a, b) = curve.domain();
    let inside = t > a + 1e-9 * (b - a) && t < b - 1e-9 * (b - a);
    inside.then(|| curve.point_at(t).ok()).flatten()
}

/// The points where a line from `from`, in the plane with normal `normal`, touches the curve:
/// the roots of f(t) = ((C(t) − P) × C′(t)) · n, bracketed on the samples and bisected.
pub fn tangents(curve: &SpaceCurve, from: DVec3, normal: DVec3) -> Vec<DVec3> {
    let f = |t: f64| -> Option<f64> {
        let d = curve.derivatives(t, 1).ok()?;
        Some((d[0] - from).cross(d[1]).dot(normal))
    };
    let mut roots = Vec::new();
    let mut previous: Option<(f64, f64)> = None;
    for k in 0..=SAMPLES {
        let t = curve.parameter_at(k as f64 / SAMPLES as f64);
        let Some(value) = f(t) else {
            previous = None;
            continue;
        };
        if let Some((t0, v0)) = previous
            && v0 * value < 0.0
        {
            let (mut lo, mut hi, mut flo) = (t0, t, v0);
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                let Some(fm) = f(mid) else { break };
                if fm * flo <= 0.0 {
                    hi = mid;
                } else {
                    (lo, flo) = (mid, fm);
                }
            }
            if let Ok(p) = curve.point_at(0.5 * (lo + hi)) {
                // A root where C − P vanishes (the curve through P) touches nothing.
                if p.distance(from) > 1e-9 * (1.0 + from.length()) {
                    roots.push(p);
                }
            }
        }
        previous = Some((t, value));
    }
    roots
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernel::construct;

    /// Looking down on the ground from above: orthographic, 10 units across 1000 pixels.
    fn top_view() -> PickView {
        let projection =
            glam::camera::rh::proj::directx::orthographic(-5.0, 5.0, -5.0, 5.0, 0.1, 100.0);
        let view = glam::camera::rh::view::look_at_mat4(
            glam::Vec3::new(0.0, 0.0, 10.0),
            glam::Vec3::ZERO,
            glam::Vec3::Y,
        );
        PickView::new(projection * view, 1000.0, 1000.0)
    }

    fn circle(center: DVec3, radius: f64) -> SpaceCurve {
        construct::circle(center, DVec3::Z, DVec3::X, radius).unwrap()
    }

    #[test]
    fn two_circles_cross_where_the_formula_says() {
        // Unit circles about (0, 0) and (1, 0) cross at (1/2, ±√3/2).
        let view = top_view();
        let (a, b) = (circle(DVec3::ZERO, 1.0), circle(DVec3::X, 1.0));
        let (sa, sb) = (Sampled::new(&a, &view), Sampled::new(&b, &view));
        let expected = DVec3::new(0.5, 0.75f64.sqrt(), 0.0);
        let cursor = view
            .project(expected + DVec3::new(0.02, 0.0, 0.0))
            .unwrap()
            .screen;
        assert!(sa.near(cursor, 8.0) && sb.near(cursor, 8.0));
        let found = intersections(&sa, &sb, &view, cursor, 8.0, 1e-9);
        assert_eq!(found.len(), 1, "{found:?}");
        assert!(found[0].distance(expected) < 1e-12, "{}", found[0]);
        // Far from any crossing, none.
        let away = view.project(DVec3::new(-1.0, 0.0, 0.0)).unwrap().screen;
        assert!(intersections(&sa, &sb, &view, away, 8.0, 1e-9).is_empty());
        // Curves that only seem to cross (one lifted) do not snap.
        let lifted = construct::circle(DVec3::new(1.0, 0.0, 0.5), DVec3::Z, DVec3::X, 1.0).unwrap();
        let sl = Sampled::new(&lifted, &view);
        assert!(intersections(&sa, &sl, &view, cursor, 8.0, 1e-9).is_empty());
    }

    #[test]
    fn perpendicular_and_tangents_from_a_point_to_a_circle() {
        let c = circle(DVec3::ZERO, 1.0);
        let from = DVec3::new(2.0, 0.0, 0.0);
        let foot = perpendicular(&c, DVec3::new(2.0, 2.0, 0.0)).unwrap();
        let expected = DVec3::new(1.0, 1.0, 0.0).normalize();
        assert!(foot.distance(expected) < 1e-12, "{foot}");
        // Tangents from (2, 0): the touching points are (1/2, ±√3/2).
        let touching = tangents(&c, from, DVec3::Z);
        assert_eq!(touching.len(), 2, "{touching:?}");
        for p in touching {
            assert!(
                (p.x - 0.5).abs() < 1e-12 && (p.y.abs() - 0.75f64.sqrt()).abs() < 1e-12,
                "{p}"
            );
        }
        // From inside, no line touches it.
        assert!(tangents(&c, DVec3::new(0.2, 0.1, 0.0), DVec3::Z).is_empty());
    }
}
