//! Blends between two surface edges and the matching of one surface's edge to another's, at
//! G0, G1 or G2, on the one surface interface ([`ParametricSurface`]).
//!
//! Both rest on one observation. Near a side of a face, reparametrize the face so that the
//! cross parameter runs outward at a rate α(s): X(s, t) = F(c(s), w₀ ± α(s)·t), where c maps
//! the edge parameter s ∈ [0, 1] onto the side. Then X_t = α·D₁ and X_tt = α²·D₂ at t = 0,
//! where D₁ is the face's outward cross derivative and D₂ its second derivative along the cross
//! parameter (the sign squares away). A surface whose point, first and second cross derivatives
//! along the edge equal these is C² to the reparametrized face there, and so G2 to it (the
//! mixed derivatives agree as s-derivatives of equal functions); with only the point and first
//! derivative it is G1.
//!
//! - **Blend** ([`blend_edges`]): the surface across the gap between side A and side B is a
//!   Bézier of degree 5 (G2), 3 (G1) or 1 (G0) in t whose control rows are the Hermite data:
//!   for degree n, R₁ = R₀ + α·D₁/n and R₂ = 2R₁ − R₀ + α²·D₂/(n(n − 1)), and likewise from
//!   B's side (The NURBS Book eq. 3.8: C′(0) = n(P₁ − P₀), C″(0) = n(n − 1)(P₂ − 2P₁ + P₀)).
//!   The tension scales α: α(s) = tension · L / |D₁(s)|, L the mean width of the gap, so the
//!   blend leaves each edge at the same speed along it. Each row is interpolated along s by a
//!   cubic (averaged knots, A9.1) at more and more samples until every row is within the
//!   tolerance between the samples.
//! - **Match** ([`match_edge`]): the first k + 1 control rows next to A's side (k = 0, 1, 2)
//!   are replaced so that A's point and cross derivatives along the side equal the target's
//!   reparametrized ones, α(s) keeping A's own cross speed |∂A/∂w|. At a clamped end the
//!   derivatives are those of the rows (The NURBS Book eq. 3.7–3.9: P⁽¹⁾₀ = q(P₁ − P₀) /
//!   (v_{q+1} − v₁), P⁽²⁾₀ = (q − 1)(P⁽¹⁾₁ − P⁽¹⁾₀)/(v_{q+1} − v₂)), so each new row is a
//!   curve in A's own u-knots, interpolated at their Greville abscissae; A's knots are refined
//!   (which keeps its shape) until the rows are within the tolerance. The moved rows get
//!   weight 1, so the derivatives up to order k are those of the polynomial rows even on a
//!   rational surface.

use glam::DVec3;

use crate::continuity::Side;
use crate::error::GeometryError;
use crate::error::construction;
use crate::interpolation::{averaged_knots, interpolate_points};
use crate::parametric::ParametricSurface;
use crate::surface::{Direction, NurbsSurface};

/// The continuity a blend or a match keeps with the surfaces it meets (serde: "G0", "G1", "G2").
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize, serde::Deserialize,
)]
pub enum EdgeContinuity {
    /// Position only.
    G0,
    /// Position and tangent plane.
    G1,
    /// Position, tangent plane and curvature.
    G2,
}

impl EdgeContinuity {
    /// The highest cross derivative matched: 0, 1 or 2.
    pub fn order(self) -> usize {
        match self {
            EdgeContinuity::G0 => 0,
            EdgeContinuity::G1 => 1,
            EdgeContinuity::G2 => 2,
        }
    }

    /// "G0", "G1" or "G2".
    pub fn name(self) -> &'static str {
        ["G0", "G1", "G2"][self.order()]
    }

    /// The continuity named "g0", "G1", "2", … (`None` for anything else).
    pub fn parse(text: &str) -> Option<Self> {
        match text.trim().trim_start_matches(['g', 'G']) {
            "0" => Some(EdgeContinuity::G0),
            "1" => Some(EdgeContinuity::G1),
            "2" => Some(EdgeContinuity::G2),
            _ => None,
        }
    }
}

/// The most samples along an edge a blend interpolates.
const MAX_BLEND_SAMPLES: usize = 1025;

/// The most times a match halves its surface's spans along the edge.
const MAX_MATCH_REFINEMENTS: usize = 6;

/// The cross-boundary jet of `face` at fraction `s` ∈ [0, 1] along `side`: the point, the
/// outward first derivative D₁ and the second derivative D₂ along the cross parameter.
pub fn side_jet(face: &dyn ParametricSurface, side: Side, s: f64) -> Option<[DVec3; 3]> {
    let ((u, v), _) = side.parameter(face.domain(), s);
    let d = face.derivatives(u, v)?;
    let second = match side {
        Side::U0 | Side::U1 => d.suu,
        Side::V0 | Side::V1 => d.svv,
    };
    Some([d.point, -side.inward(&d), second])
}

/// Whether the sides run opposite ways: the ends of A's side nearer the swapped ends of B's.
fn runs_opposite(
    a: &dyn ParametricSurface,
    side_a: Side,
    b: &dyn ParametricSurface,
    side_b: Side,
) -> Option<bool> {
    let end = |f: &dyn ParametricSurface, side: Side, s: f64| side_jet(f, side, s).map(|j| j[0]);
    let (a0, a1) = (end(a, side_a, 0.0)?, end(a, side_a, 1.0)?);
    let (b0, b1) = (end(b, side_b, 0.0)?, end(b, side_b, 1.0)?);
    Some(a0.distance(b0) + a1.distance(b1) > a0.distance(b1) + a1.distance(b0))
}

/// The length of a side (16 chords).
fn side_length(face: &dyn ParametricSurface, side: Side) -> f64 {
    let points: Vec<DVec3> = (0..=16)
        .filter_map(|k| side_jet(face, side, k as f64 / 16.0).map(|j| j[0]))
        .collect();
    points.windows(2).map(|w| w[0].distance(w[1])).sum()
}

/// The pair of sides, one of `a` and one of `b`, that lie nearest each other (the mean
/// distance between them at 9 points, matched end to end either way), sides shorter than
/// `degenerate` (poles) left out; with that distance.
pub fn nearest_sides(
    a: &dyn ParametricSurface,
    b: &dyn ParametricSurface,
    degenerate: f64,
) -> Option<(Side, Side, f64)> {
    let long = |f: &dyn ParametricSurface| Side::ALL.map(|s| side_length(f, s) > degenerate);
    let (long_a, long_b) = (long(a), long(b));
    let mut best: Option<(Side, Side, f64)> = None;
    for (sa, _) in Side::ALL.into_iter().zip(long_a).filter(|(_, l)| *l) {
        for (sb, _) in Side::ALL.into_iter().zip(long_b).filter(|(_, l)| *l) {
            let Some(opposite) = runs_opposite(a, sa, b, sb) else {
                continue;
            };
            let mut sum = 0.0;
            let mut ok = true;
            for k in 0..=8 {
                let s = k as f64 / 8.0;
                let t = if opposite { 1.0 - s } else { s };
                match (side_jet(a, sa, s), side_jet(b, sb, t)) {
                    (Some(p), Some(q)) => sum += p[0].distance(q[0]),
                    _ => ok = false,
                }
            }
            let mean = sum / 9.0;
            if ok && best.is_none_or(|(_, _, d)| mean < d) {
                best = Some((sa, sb, mean));
            }
        }
    }
    best
}

/// A blend made by [`blend_edges`].
#[derive(Debug, Clone)]
pub struct Blend {
    /// The blend: u along the edges (from A's side's start), v from A (v = 0) to B (v = 1).
    pub surface: NurbsSurface,
    /// Whether B's side runs against A's.
    pub reversed: bool,
    /// The largest distance between the interpolated control rows and the Hermite data
    /// between the samples (the blend's deviation from the exact construction).
    pub deviation: f64,
    /// The samples along the edges.
    pub samples: usize,
}

/// What a blend asks for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BlendOptions {
    pub continuity: EdgeContinuity,
    /// The tension at A's and at B's edge (above 0; 1 is a natural bulge).
    pub tension: [f64; 2],
    /// The largest deviation of the control rows, in model units.
    pub tolerance: f64,
}

fn check_positive(what: &'static str, name: &str, value: f64) -> Result<(), GeometryError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(construction(
            what,
            format!("the {name} must be a number above 0 (got {value})"),
        ))
    }
}

/// The blend from side `side_a` of `a` to side `side_b` of `b` with the continuity and tension
/// of `options` (see the module documentation): a NURBS surface, cubic along the edges.
pub fn blend_edges(
    a: &dyn ParametricSurface,
    side_a: Side,
    b: &dyn ParametricSurface,
    side_b: Side,
    options: &BlendOptions,
) -> Result<Blend, GeometryError> {
    const WHAT: &str = "blend";
    check_positive(WHAT, "tension at the first edge", options.tension[0])?;
    check_positive(WHAT, "tension at the second edge", options.tension[1])?;
    check_positive(WHAT, "tolerance", options.tolerance)?;
    let off_surface = || construction(WHAT, "an edge leaves its surface's domain");
    let reversed = runs_opposite(a, side_a, b, side_b).ok_or_else(off_surface)?;
    let along_b = |s: f64| if reversed { 1.0 - s } else { s };
    let mut width = 0.0;
    for k in 0..=8 {
        let s = k as f64 / 8.0;
        let (Some(p), Some(q)) = (side_jet(a, side_a, s), side_jet(b, side_b, along_b(s))) else {
            return Err(off_surface());
        };
        width += p[0].distance(q[0]);
    }
    let width = width / 9.0;
    if width <= options.tolerance {
        return Err(construction(
            WHAT,
            "the edges touch: there is no gap to blend (match the edges instead)",
        ));
    }
    let degree = [1, 3, 5][options.continuity.order()];
    // The Bézier rows across the gap at fraction s.
    let rows = |s: f64| -> Option<Vec<DVec3>> {
        let [p, d1, d2] = side_jet(a, side_a, s)?;
        let [q, e1, e2] = side_jet(b, side_b, along_b(s))?;
        let (ld, le) = (d1.length(), e1.length());
        if !(ld > 1e-300 && le > 1e-300) {
            return None;
        }
        let alpha = options.tension[0] * width / ld;
        let beta = options.tension[1] * width / le;
        let n = degree as f64;
        Some(match options.continuity {
            EdgeContinuity::G0 => vec![p, q],
            EdgeContinuity::G1 => vec![p, p + d1 * (alpha / n), q + e1 * (beta / n), q],
            EdgeContinuity::G2 => {
                let (a1, b1) = (p + d1 * (alpha / n), q + e1 * (beta / n));
                let k = n * (n - 1.0);
                vec![
                    p,
                    a1,
                    2.0 * a1 - p + d2 * (alpha * alpha / k),
                    2.0 * b1 - q + e2 * (beta * beta / k),
                    b1,
                    q,
                ]
            }
        })
    };
    let degenerate = || {
        construction(
            WHAT,
            "a surface has no cross derivative along its edge (the edge is degenerate there)",
        )
    };
    let mut samples = 9;
    loop {
        let params: Vec<f64> = (0..samples)
            .map(|k| k as f64 / (samples - 1) as f64)
            .collect();
        let data: Vec<Vec<DVec3>> = params
            .iter()
            .map(|&s| rows(s))
            .collect::<Option<_>>()
            .ok_or_else(degenerate)?;
        let p = 3.min(samples - 1);
        let knots = averaged_knots(&params, p);
        let mut fitted = Vec::with_capacity(degree + 1);
        for r in 0..=degree {
            let row: Vec<DVec3> = data.iter().map(|d| d[r]).collect();
            fitted.push(interpolate_points(&row, &params, p, &knots, WHAT)?);
        }
        let curves: Vec<crate::SpaceCurve> = fitted
            .iter()
            .map(|points| crate::SpaceCurve::new(p, knots.clone(), points.clone(), None))
            .collect::<Result<_, _>>()?;
        let mut deviation = 0.0f64;
        for w in params.windows(2) {
            let s = 0.5 * (w[0] + w[1]);
            let target = rows(s).ok_or_else(degenerate)?;
            for (curve, t) in curves.iter().zip(&target) {
                deviation = deviation.max(curve.point_at(s)?.distance(*t));
            }
        }
        if deviation <= options.tolerance || samples >= MAX_BLEND_SAMPLES {
            let mut points = Vec::with_capacity(samples * (degree + 1));
            for i in 0..samples {
                for row in &fitted {
                    points.push(row[i]);
                }
            }
            let across = bezier_knots(degree);
            let surface = NurbsSurface::new(
                [p, degree],
                [knots, across],
                [samples, degree + 1],
                points,
                None,
            )?;
            return Ok(Blend {
                surface,
                reversed,
                deviation,
                samples,
            });
        }
        samples = 2 * samples - 1;
    }
}

/// The knots of one Bézier span of degree `p` on [0, 1].
fn bezier_knots(p: usize) -> Vec<f64> {
    let mut k = vec![0.0; p + 1];
    k.extend(std::iter::repeat_n(1.0, p + 1));
    k
}

/// A match made by [`match_edge`].
#[derive(Debug, Clone)]
pub struct Matched {
    /// The surface with its edge matched (same domain and orientation).
    pub surface: NurbsSurface,
    /// Whether the target's side runs against the matched side.
    pub reversed: bool,
    /// The largest distance between the new control rows and the exact data between the
    /// interpolation points.
    pub deviation: f64,
}

/// How a surface is turned so that a side becomes its v = v₀ side, and back.
fn turn(surface: &NurbsSurface, side: Side) -> NurbsSurface {
    match side {
        Side::V0 => surface.clone(),
        Side::V1 => surface.reverse(Direction::V),
        Side::U0 => surface.swap_uv(),
        Side::U1 => surface.swap_uv().reverse(Direction::V),
    }
}

fn turn_back(surface: &NurbsSurface, side: Side) -> NurbsSurface {
    match side {
        Side::V0 => surface.clone(),
        Side::V1 => surface.reverse(Direction::V),
        Side::U0 => surface.swap_uv(),
        Side::U1 => surface.reverse(Direction::V).swap_uv(),
    }
}

/// The Greville abscissae of a knot vector of degree `p` (the means of p consecutive knots,
/// de Boor, *A Practical Guide to Splines*, ch. XIII), one per control point.
fn greville(knots: &[f64], p: usize, count: usize) -> Vec<f64> {
    (0..count)
        .map(|i| knots[i + 1..=i + p].iter().sum::<f64>() / p.max(1) as f64)
        .collect()
}

/// `surface` with side `side` moved onto side `target_side` of `target` at `continuity`
/// (see the module documentation): its first k + 1 control rows along the side replaced, its
/// knots along the side refined until they are within `tolerance` (model units). The degree
/// across is raised to k where it is lower, and knots are inserted across where the surface
/// has fewer than k + 2 rows, so the opposite side stays where it was.
pub fn match_edge(
    surface: &NurbsSurface,
    side: Side,
    target: &dyn ParametricSurface,
    target_side: Side,
    continuity: EdgeContinuity,
    tolerance: f64,
) -> Result<Matched, GeometryError> {
    const WHAT: &str = "match";
    check_positive(WHAT, "tolerance", tolerance)?;
    let k = continuity.order();
    let mut s = turn(surface, side).clamped();
    let q = s.degree()[1];
    if q < k {
        s = s.elevate_degree(Direction::V, k - q)?;
    }
    while s.count()[1] < k + 2 {
        let knots = s.knots()[1];
        let (mut lo, mut hi) = (knots[0], knots[0]);
        for w in knots.windows(2) {
            if w[1] - w[0] > hi - lo {
                (lo, hi) = (w[0], w[1]);
            }
        }
        s = s.insert_knot(Direction::V, 0.5 * (lo + hi), 1)?;
    }
    let reversed = runs_opposite(&s, Side::V0, target, target_side)
        .ok_or_else(|| construction(WHAT, "an edge leaves its surface's domain"))?;
    let [(u0, u1), _] = s.domain();
    let fraction = |u: f64| (u - u0) / (u1 - u0);
    let on_target = |f: f64| if reversed { 1.0 - f } else { f };
    let original = s.clone();
    let [_, q] = s.degree();
    let v = s.knots()[1].to_vec();
    // The rows' target values at fraction f along the edge.
    let rows = |f: f64| -> Option<Vec<DVec3>> {
        let [t0, e1, e2] = side_jet(target, target_side, on_target(f))?;
        let mut out = vec![t0];
        if k >= 1 {
            let [_, own, _] = side_jet(&original, Side::V0, f)?;
            let le = e1.length();
            if le <= 1e-300 {
                return None;
            }
            // A's cross derivative points into A (−outward), along the target's outward one.
            let alpha = own.length() / le;
            let d1 = e1 * alpha;
            let r1 = t0 + d1 * ((v[q + 1] - v[1]) / q as f64);
            out.push(r1);
            if k >= 2 {
                let d2 = e2 * (alpha * alpha);
                let first1 = d1 + d2 * ((v[q + 1] - v[2]) / (q - 1) as f64);
                out.push(r1 + first1 * ((v[q + 2] - v[2]) / q as f64));
            }
        }
        Some(out)
    };
    let degenerate = || {
        construction(
            WHAT,
            "a surface has no cross derivative along the edge (the edge is degenerate there)",
        )
    };
    let mut refinements = 0;
    loop {
        let [p, _] = s.degree();
        let [m, n] = s.count();
        let u = s.knots()[0].to_vec();
        let params = greville(&u, p, m);
        let data: Vec<Vec<DVec3>> = params
            .iter()
            .map(|&g| rows(fraction(g)))
            .collect::<Option<_>>()
            .ok_or_else(degenerate)?;
        let mut fitted = Vec::with_capacity(k + 1);
        for r in 0..=k {
            let row: Vec<DVec3> = data.iter().map(|d| d[r]).collect();
            fitted.push(interpolate_points(&row, &params, p, &u, WHAT)?);
        }
        let mut deviation = 0.0f64;
        for (r, points) in fitted.iter().enumerate() {
            let curve = crate::SpaceCurve::new(p, u.clone(), points.clone(), None)?;
            for w in params.windows(2) {
                let g = 0.5 * (w[0] + w[1]);
                let target_row = rows(fraction(g)).ok_or_else(degenerate)?;
                deviation = deviation.max(curve.point_at(g)?.distance(target_row[r]));
            }
        }
        if deviation <= tolerance || refinements >= MAX_MATCH_REFINEMENTS {
            let mut points = s.homogeneous_points().to_vec();
            for (j, row) in fitted.iter().enumerate() {
                for (i, x) in row.iter().enumerate() {
                    points[i * n + j] = x.extend(1.0);
                }
            }
            let moved = NurbsSurface::from_homogeneous([p, q], [u, v.clone()], [m, n], points)?;
            return Ok(Matched {
                surface: turn_back(&moved, side),
                reversed,
                deviation,
            });
        }
        let mids: Vec<f64> = u
            .windows(2)
            .filter(|w| w[1] > w[0])
            .map(|w| 0.5 * (w[0] + w[1]))
            .collect();
        s = s.refine(Direction::U, &mids)?;
        refinements += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::construct;
    use crate::continuity::{Tolerances, shared_edges};
    use std::f64::consts::FRAC_PI_2;

    fn tolerances() -> Tolerances {
        Tolerances {
            matching: 1e-4,
            distance: 1e-6,
            angle_degrees: 0.01,
            curvature: 1e-3,
            samples: 33,
        }
    }

    /// A bicubic sheet over [x0, x0 + 2] × [0, 2] with a bump, heights from `h`.
    fn sheet(x0: f64, h: impl Fn(f64, f64) -> f64) -> NurbsSurface {
        let n = 5;
        let knots = vec![0.0, 0.0, 0.0, 0.0, 0.5, 1.0, 1.0, 1.0, 1.0];
        let mut points = Vec::new();
        for i in 0..n {
            for j in 0..n {
                let (x, y) = (x0 + 2.0 * i as f64 / 4.0, 2.0 * j as f64 / 4.0);
                points.push(DVec3::new(x, y, h(x, y)));
            }
        }
        NurbsSurface::new([3, 3], [knots.clone(), knots], [n, n], points, None).unwrap()
    }

    #[test]
    fn a_g2_blend_between_two_sheets_is_curvature_continuous_at_both_edges() {
        let a = sheet(-3.0, |x, y| 0.2 * (x * 0.7).sin() + 0.1 * y * y);
        let b = sheet(1.0, |x, y| 0.5 + 0.3 * (x * 0.5).cos() * y);
        let (sa, sb, _) = nearest_sides(&a, &b, 1e-9).unwrap();
        assert_eq!((sa, sb), (Side::U1, Side::U0));
        for continuity in [EdgeContinuity::G1, EdgeContinuity::G2] {
            let options = BlendOptions {
                continuity,
                tension: [1.0, 1.0],
                tolerance: 1e-7,
            };
            let blend = blend_edges(&a, sa, &b, sb, &options).unwrap();
            assert!(!blend.reversed && blend.deviation <= 1e-7, "{blend:?}");
            let faces: [&dyn ParametricSurface; 3] = [&a, &blend.surface, &b];
            let edges = shared_edges(&faces, &tolerances(), 5.0);
            assert_eq!(edges.len(), 2, "{edges:?}");
            for e in &edges {
                assert!(e.max_gap.value < 1e-6, "{e:?}");
                assert!(e.max_angle_degrees.value < 1e-3, "{e:?}");
                if continuity == EdgeContinuity::G2 {
                    assert!(e.max_relative_curvature_difference.value < 1e-3, "{e:?}");
                }
            }
        }
    }

    #[test]
    fn a_blend_with_a_reversed_edge_and_bad_tension_or_touching_edges() {
        let a = sheet(-3.0, |_, _| 0.0);
        let b = sheet(1.0, |_, _| 1.0).reverse(Direction::V);
        let options = BlendOptions {
            continuity: EdgeContinuity::G1,
            tension: [1.0, 1.0],
            tolerance: 1e-7,
        };
        let blend = blend_edges(&a, Side::U1, &b, Side::U0, &options).unwrap();
        assert!(blend.reversed);
        // The blend of two parallel planes, G1 with equal tensions, is symmetric about the
        // middle: its centre lies halfway up.
        let mid = blend.surface.point_at(0.5, 0.5).unwrap();
        assert!((mid - DVec3::new(0.0, 1.0, 0.5)).length() < 1e-9, "{mid}");
        let bad = BlendOptions {
            tension: [0.0, 1.0],
            ..options
        };
        assert!(blend_edges(&a, Side::U1, &b, Side::U0, &bad).is_err());
        let touching = sheet(-1.0, |_, _| 0.0);
        assert!(blend_edges(&a, Side::U1, &touching, Side::U0, &options).is_err());
    }

    #[test]
    fn matching_a_sheet_to_a_cylinder_gives_the_continuity_asked_and_keeps_the_far_edge() {
        // A quarter cylinder of radius 1 about the y axis from x = 1 to the top, z = 1, where
        // it leaves horizontally towards −x; a sheet beside it whose near edge is a little
        // off, tilted.
        let arc = construct::arc(DVec3::ZERO, DVec3::X, DVec3::Z, 1.0, 0.0, FRAC_PI_2).unwrap();
        let cylinder = construct::extrude(&arc, DVec3::Y * 2.0).unwrap();
        let sheet = sheet(-2.1, |x, y| 1.0 + 0.05 * (x + 0.1) + 0.02 * y);
        let (side, target_side, _) = nearest_sides(&sheet, &cylinder, 1e-9).unwrap();
        assert_eq!((side, target_side), (Side::U1, Side::U1));
        for continuity in [EdgeContinuity::G0, EdgeContinuity::G1, EdgeContinuity::G2] {
            let matched =
                match_edge(&sheet, side, &cylinder, target_side, continuity, 1e-8).unwrap();
            assert!(
                matched.deviation <= 1e-8,
                "{continuity:?} {}",
                matched.deviation
            );
            let faces: [&dyn ParametricSurface; 2] = [&cylinder, &matched.surface];
            let edges = shared_edges(&faces, &tolerances(), 4.0);
            assert_eq!(edges.len(), 1, "{continuity:?} {edges:?}");
            let e = &edges[0];
            assert!(e.max_gap.value < 1e-6, "{e:?}");
            if continuity >= EdgeContinuity::G1 {
                assert!(e.max_angle_degrees.value < 1e-3, "{continuity:?} {e:?}");
            } else {
                assert!(
                    e.max_angle_degrees.value > 1.0,
                    "G0 leaves the angle: {e:?}"
                );
            }
            if continuity == EdgeContinuity::G2 {
                assert!(e.max_relative_curvature_difference.value < 1e-3, "{e:?}");
            }
            // The far edge did not move.
            let [(a0, _), (b0, b1)] = matched.surface.domain();
            for k in 0..=8 {
                let t = b0 + (b1 - b0) * k as f64 / 8.0;
                let before = sheet.point_at(a0, t).unwrap();
                let after = matched.surface.point_at(a0, t).unwrap();
                assert!(before.distance(after) < 1e-12, "{before} {after}");
            }
        }
    }
}
