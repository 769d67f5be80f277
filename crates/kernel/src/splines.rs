//! Interpolating curves as exact NURBS curves: global B-spline interpolation with a choice of
//! parameters and optional end tangents (The NURBS Book §9.2), cubic Hermite splines (points,
//! tangents and parameters) and Catmull-Rom splines in the Barry–Goldman form (uniform,
//! centripetal and chordal: α = 0, 0.5, 1).
//!
//! Both are piecewise cubic in their own parameter, so each piece is exactly one cubic Bézier
//! segment: on [t_i, t_{i+1}] with h = t_{i+1} − t_i the Hermite data (P_i, m_i, P_{i+1},
//! m_{i+1}) are the Bézier points P_i, P_i + h m_i / 3, P_{i+1} − h m_{i+1} / 3, P_{i+1}, and the
//! pieces join in one cubic B-spline whose interior knots t_i have multiplicity 3 (C¹ there,
//! as the splines are).

use super::basis::{basis_functions, find_span};
use super::curve::NurbsCurve;
use super::error::GeometryError;
use super::error::construction;
use super::interpolation::{averaged_knots, interpolate_points};
use super::vector::{CurvePoint, Vector};

/// How the parameters of the points an interpolant passes through are spaced (The NURBS Book
/// eq. 9.5–9.6): by the distances between them raised to the power 1, ½ or 0.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Parametrization {
    /// Chord length (eq. 9.5).
    ChordLength,
    /// Centripetal (eq. 9.6): the square roots of the chords; better for sharp turns.
    Centripetal,
    /// Equally spaced.
    Uniform,
}

impl Parametrization {
    fn exponent(self) -> f64 {
        match self {
            Parametrization::ChordLength => 1.0,
            Parametrization::Centripetal => 0.5,
            Parametrization::Uniform => 0.0,
        }
    }
}

/// The parameters ū_0 = 0 < … < ū_n = 1 of `points` by `parametrization`; coincident
/// consecutive points (or points that are not finite) are refused.
pub fn parameters<V: Vector>(
    points: &[V],
    parametrization: Parametrization,
    what: &'static str,
) -> Result<Vec<f64>, GeometryError> {
    let mut steps = Vec::with_capacity(points.len().saturating_sub(1));
    for (i, w) in points.windows(2).enumerate() {
        let chord = (w[1] - w[0]).norm();
        if !(chord > 0.0 && chord.is_finite()) {
            return Err(construction(
                what,
                format!("points {i} and {} coincide (or are not finite)", i + 1),
            ));
        }
        steps.push(chord.powf(parametrization.exponent()));
    }
    let total: f64 = steps.iter().sum();
    let mut params = vec![0.0];
    let mut acc = 0.0;
    for s in &steps {
        acc += s;
        params.push(acc / total);
    }
    if let Some(last) = params.last_mut() {
        *last = 1.0;
    }
    Ok(params)
}

/// The non-rational B-spline of degree `degree` (lowered where there are too few points) on
/// [0, 1] through every point of `points` at the parameters `parametrization` gives. Without
/// end tangents: averaged knots (eq. 9.8) and the collocation system (A9.1). With end
/// tangents (D_0, D_n), the derivatives C′(0) = D_0 and C′(1) = D_n in the curve's [0, 1]
/// parameter: two more control points, the knots of eq. 9.22 and the rows
/// P_1 − P_0 = (u_{p+1}/p) D_0 and P_{n+2} − P_{n+1} = ((1 − u_{m−p−1})/p) D_n (§9.2.2).
pub fn interpolate_through<P: CurvePoint>(
    points: &[P],
    degree: usize,
    parametrization: Parametrization,
    end_tangents: Option<(P, P)>,
) -> Result<NurbsCurve<P>, GeometryError> {
    let what = "interpolate";
    if points.len() < 2 {
        return Err(construction(what, "needs at least 2 points"));
    }
    if degree == 0 {
        return Err(construction(what, "the degree must be ≥ 1"));
    }
    let params = parameters(points, parametrization, what)?;
    let Some((start, end)) = end_tangents else {
        return interpolate_at_parameters(points, &params, degree);
    };
    if degree < 2 {
        return Err(construction(
            what,
            "end tangents need degree 2 or more (a degree-1 curve's ends are its chords)",
        ));
    }
    if !start
        .coordinates()
        .iter()
        .chain(&end.coordinates())
        .all(|c| c.is_finite())
    {
        return Err(construction(what, "an end tangent is not finite"));
    }
    let n = points.len() - 1;
    let p = degree.min(n + 2);
    let count = n + 3;
    // Eq. 9.22: u_{j+p+1} = (1/p) Σ_{i=j}^{j+p−1} ū_i for j = 0 … n − p + 1 (ū padded with its
    // ends where p > n + 1).
    let at = |i: usize| params[i.min(n)];
    let mut knots = vec![0.0; p + 1];
    for j in 0..count - p - 1 {
        knots.push((j..j + p).map(at).sum::<f64>() / p as f64);
    }
    knots.extend(std::iter::repeat_n(1.0, p + 1));
    let m = knots.len() - 1;
    let mut matrix = vec![vec![0.0; count]; count];
    let mut rhs = Vec::with_capacity(count);
    let mut basis = vec![0.0; p + 1];
    // Row 0: the start point; row 1: the start tangent; rows 2 … n: the inner points; row
    // n + 1: the end tangent; row n + 2: the end point.
    for (k, &t) in params.iter().enumerate() {
        let row = match k {
            0 => 0,
            k if k == n => n + 2,
            k => k + 1,
        };
        let span = find_span(&knots, p, count, t);
        basis_functions(&knots, p, span, t, &mut basis);
        matrix[row][span - p..=span].copy_from_slice(&basis);
    }
    matrix[1][0] = -1.0;
    matrix[1][1] = 1.0;
    matrix[n + 1][n + 1] = -1.0;
    matrix[n + 1][n + 2] = 1.0;
    for row in 0..count {
        rhs.push(match row {
            0 => points[0],
            1 => start * (knots[p + 1] / p as f64),
            r if r == n + 1 => end * ((1.0 - knots[m - p - 1]) / p as f64),
            r if r == n + 2 => points[n],
            r => points[r - 1],
        });
    }
    let control = super::vector::solve_linear(matrix, rhs)
        .ok_or_else(|| construction(what, "the interpolation system is singular"))?;
    NurbsCurve::new(p, knots, control, None)
}

/// The non-rational B-spline of degree `degree` (lowered where there are too few points) on
/// [0, 1] through `points[k]` at the given parameter `params[k]`, which must rise strictly
/// from 0 to 1: averaged knots (The NURBS Book eq. 9.8) and the collocation system (A9.1).
/// For points whose parameters are known (samples of a curve at its own parameter), where
/// chord lengths would not follow the curve's speed.
pub fn interpolate_at_parameters<P: CurvePoint>(
    points: &[P],
    params: &[f64],
    degree: usize,
) -> Result<NurbsCurve<P>, GeometryError> {
    let what = "interpolate";
    if points.len() < 2 || params.len() != points.len() {
        return Err(construction(
            what,
            "needs at least 2 points, each with one parameter",
        ));
    }
    if degree == 0 {
        return Err(construction(what, "the degree must be ≥ 1"));
    }
    let rising = params.windows(2).all(|w| w[1] > w[0]);
    if !(rising && params[0] == 0.0 && params[params.len() - 1] == 1.0) {
        return Err(construction(
            what,
            "the parameters must rise strictly from 0 to 1",
        ));
    }
    let degree = degree.min(points.len() - 1);
    let knots = averaged_knots(params, degree);
    let control = interpolate_points(points, params, degree, &knots, what)?;
    NurbsCurve::new(degree, knots, control, None)
}

/// The closed B-spline of degree `degree` (lowered to points − 1 where there are too few)
/// through every point of `points` and back to the first, which is not repeated: C^{p−1} all
/// round, the seam included. Parameters by `parametrization` over the closed polygon (its
/// closing chord too), period 1; the knots are the parameters for an odd degree and the
/// midpoints between them for an even one (so that the periodic collocation system is
/// well posed, as in cubic spline interpolation), extended periodically; the n × n cyclic
/// system Σ N_j(ū_k) P_{j mod n} = Q_k gives the n control points, and the curve is their
/// unclamped B-spline with the first `degree` points repeated at the end, on [κ_p, κ_{p+n}].
pub fn interpolate_closed<P: CurvePoint>(
    points: &[P],
    degree: usize,
    parametrization: Parametrization,
) -> Result<NurbsCurve<P>, GeometryError> {
    let what = "closed interpolation";
    let n = points.len();
    if n < 3 {
        return Err(construction(
            what,
            format!("needs at least 3 points, got {n}"),
        ));
    }
    if degree == 0 {
        return Err(construction(what, "the degree must be ≥ 1"));
    }
    let p = degree.min(n - 1);
    let mut closed = points.to_vec();
    closed.push(points[0]);
    let params = parameters(&closed, parametrization, what)?;
    let knots = periodic_knots(&params, p);
    let wrapped = periodic_control(points, &params, p, &knots, what)?;
    NurbsCurve::new(p, knots, wrapped, None)
}

/// The unclamped knot vector of a closed interpolant of degree `p` through n points at
/// `params` (n + 1 values from 0 to 1, the last for the return to the first point): the
/// parameters for an odd degree and the midpoints between them for an even one, extended
/// periodically with period 1 to n + 2p + 1 knots; the domain is [κ_p, κ_{p+n}].
pub(super) fn periodic_knots(params: &[f64], p: usize) -> Vec<f64> {
    let n = params.len() - 1;
    let base = |j: usize| {
        if p % 2 == 1 {
            params[j]
        } else {
            0.5 * (params[j] + params[j + 1])
        }
    };
    let s = |j: i64| {
        let k = j.rem_euclid(n as i64) as usize;
        base(k) + j.div_euclid(n as i64) as f64
    };
    (0..=(n + 2 * p) as i64).map(|i| s(i - p as i64)).collect()
}

/// The n + p control points (the first p repeated at the end) of the closed B-spline of degree
/// `p` over [`periodic_knots`] that passes through `points[k]` at `params[k]`: the n × n cyclic
/// collocation system Σ N_j(ū_k) P_{j mod n} = Q_k.
pub(super) fn periodic_control<V: Vector>(
    points: &[V],
    params: &[f64],
    p: usize,
    knots: &[f64],
    what: &'static str,
) -> Result<Vec<V>, GeometryError> {
    let n = points.len();
    let (start, end) = (knots[p], knots[p + n]);
    let count = n + p;
    let mut matrix = vec![vec![0.0; n]; n];
    let mut basis = vec![0.0; p + 1];
    for (k, row) in matrix.iter_mut().enumerate() {
        // The point's parameter, brought into the domain by whole periods.
        let mut u = params[k];
        while u < start {
            u += 1.0;
        }
        while u >= end {
            u -= 1.0;
        }
        let span = find_span(knots, p, count, u);
        basis_functions(knots, p, span, u, &mut basis);
        for (offset, &b) in basis.iter().enumerate() {
            row[(span - p + offset) % n] += b;
        }
    }
    let control = super::vector::solve_linear(matrix, points.to_vec())
        .ok_or_else(|| construction(what, "the interpolation system is singular"))?;
    Ok((0..count).map(|i| control[i % n]).collect())
}

/// The C¹ cubic through `points` at the parameters `params` (strictly increasing) with the
/// derivatives `tangents` there (d/dt in that parameter): one cubic Hermite piece per interval,
/// as an exact cubic NURBS curve on [params[0], params[n − 1]].
pub fn hermite_spline<P: CurvePoint>(
    points: &[P],
    tangents: &[P],
    params: &[f64],
) -> Result<NurbsCurve<P>, GeometryError> {
    let what = "Hermite spline";
    let n = points.len();
    if n < 2 {
        return Err(construction(what, "needs at least 2 points"));
    }
    if tangents.len() != n || params.len() != n {
        return Err(construction(
            what,
            format!(
                "needs a tangent and a parameter per point: {n} points, {} tangents, {} parameters",
                tangents.len(),
                params.len()
            ),
        ));
    }
    if let Some(k) = (1..n).find(|&k| !(params[k] > params[k - 1]) || !params[k].is_finite()) {
        return Err(construction(
            what,
            format!(
                "the parameters must increase: {} then {}",
                params[k - 1],
                params[k]
            ),
        ));
    }
    let mut control = Vec::with_capacity(3 * n - 2);
    let mut knots = vec![params[0]; 4];
    for k in 0..n - 1 {
        let h = params[k + 1] - params[k];
        if k == 0 {
            control.push(points[0]);
        }
        control.push(points[k] + tangents[k] * (h / 3.0));
        control.push(points[k + 1] - tangents[k + 1] * (h / 3.0));
        control.push(points[k + 1]);
        let multiplicity = if k + 1 == n - 1 { 4 } else { 3 };
        knots.extend(std::iter::repeat_n(params[k + 1], multiplicity));
    }
    NurbsCurve::new(3, knots, control, None)
}

/// The most pieces per span [`polynomial_approximation`] uses.
const MAX_PIECES_PER_SPAN: usize = 256;

/// A non-rational cubic within `tolerance` of `curve` at the same parameters (a rational curve
/// with uneven weights has no exact place where homogeneous points are blended, as in a loft
/// across sections with different weights). Per Bézier span, the cubic Hermite spline of the
/// curve's points and first derivatives ([`hermite_spline`]) at m evenly spaced parameters, with
/// m doubled from 1 until it is within `tolerance` at the quarter points of every piece (the
/// Hermite error is O(h⁴)); the spans are joined at their knots, so kinks stay kinks.
/// A non-rational curve comes back unchanged.
pub fn polynomial_approximation(
    curve: &NurbsCurve<glam::DVec3>,
    tolerance: f64,
) -> Result<NurbsCurve<glam::DVec3>, GeometryError> {
    if curve.is_polynomial() {
        return Ok(curve.clone());
    }
    let mut joined: Option<NurbsCurve<glam::DVec3>> = None;
    for span in curve.bezier_segments() {
        let mut pieces = 1;
        let fitted = loop {
            let params: Vec<f64> = (0..=pieces)
                .map(|i| span.parameter_at(i as f64 / pieces as f64))
                .collect();
            let mut points = Vec::with_capacity(params.len());
            let mut tangents = Vec::with_capacity(params.len());
            for &t in &params {
                let d = span.derivatives(t, 1)?;
                points.push(d[0]);
                tangents.push(d[1]);
            }
            let fitted = hermite_spline(&points, &tangents, &params)?;
            let mut worst = 0.0_f64;
            for w in params.windows(2) {
                for f in [0.25, 0.5, 0.75] {
                    let t = w[0] + (w[1] - w[0]) * f;
                    worst = worst.max(fitted.point_at(t)?.distance(span.point_at(t)?));
                }
            }
            if worst <= tolerance || pieces >= MAX_PIECES_PER_SPAN {
                break fitted;
            }
            pieces *= 2;
        };
        joined = Some(match joined {
            None => fitted,
            Some(c) => c.join(&fitted)?,
        });
    }
    joined.ok_or_else(|| construction("approximation", "the curve has no spans"))
}

/// The Catmull-Rom spline through `points[1] … points[n − 2]` (the first and last points only
/// steer the ends), with knots t_0 = 0, t_{i+1} = t_i + |P_{i+1} − P_i|^α: α = 0 uniform, 0.5
/// centripetal (no cusps or self-intersections within a segment), 1 chordal. Each segment is
/// the Barry–Goldman pyramid of linear interpolations ("A recursive evaluation algorithm for a
/// class of Catmull-Rom splines", SIGGRAPH 1988), a cubic in t whose derivative at P_i is
/// m_i = (P_i − P_{i−1})/(t_i − t_{i−1}) − (P_{i+1} − P_{i−1})/(t_{i+1} − t_{i−1})
///       + (P_{i+1} − P_i)/(t_{i+1} − t_i)
/// (Yuksel, Schaefer & Keyser 2011); so the spline is exactly [`hermite_spline`] with those
/// tangents, on [t_1, t_{n−2}].
pub fn catmull_rom<P: CurvePoint>(
    points: &[P],
    alpha: f64,
) -> Result<NurbsCurve<P>, GeometryError> {
    let what = "Catmull-Rom spline";
    if points.len() < 4 {
        return Err(construction(
            what,
            format!(
                "needs at least 4 points (two to pass through and one end control on each side), got {}",
                points.len()
            ),
        ));
    }
    if !(0.0..=1.0).contains(&alpha) {
        return Err(construction(
            what,
            format!("α must be in [0, 1] (0 uniform, 0.5 centripetal, 1 chordal), got {alpha}"),
        ));
    }
    let mut t = vec![0.0];
    for k in 1..points.len() {
        let step = (points[k] - points[k - 1]).norm().powf(alpha);
        if !(step > 0.0 && step.is_finite()) {
            return Err(construction(
                what,
                format!("points {} and {k} coincide (or are not finite)", k - 1),
            ));
        }
        t.push(t[k - 1] + step);
    }
    let inner = 1..points.len() - 1;
    let tangents: Vec<P> = inner
        .clone()
        .map(|i| {
            let (p0, p1, p2) = (points[i - 1], points[i], points[i + 1]);
            (p1 - p0) / (t[i] - t[i - 1]) - (p2 - p0) / (t[i + 1] - t[i - 1])
                + (p2 - p1) / (t[i + 1] - t[i])
        })
        .collect();
    hermite_spline(&points[inner.clone()], &tangents, &t[inner])
}

/// The closed (periodic) B-spline of degree `degree` on the control polygon `points` (not
/// repeating its first point): uniform knots κ_i = (i − p)/n, the first p points repeated at
/// the end, over the domain [0, 1]. C^{p−1} everywhere, seam included (The NURBS Book §12.2);
/// what a designer placing control points of a closed curve expects.
pub fn periodic_from_control<P: CurvePoint>(
    points: &[P],
    degree: usize,
) -> Result<NurbsCurve<P>, GeometryError> {
    let n = points.len();
    if degree == 0 || n < degree + 1 {
        return Err(GeometryError::Construction {
            what: "closed curve",
            message: format!(
                "a closed curve of degree {degree} needs at least {} points, found {n}",
                degree + 1
            ),
        });
    }
    let mut wrapped = points.to_vec();
    wrapped.extend_from_slice(&points[..degree]);
    let knots = (0..n + 2 * degree + 1)
        .map(|i| (i as f64 - degree as f64) / n as f64)
        .collect();
    NurbsCurve::new(degree, knots, wrapped, None)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    /// The Barry–Goldman pyramid for the segment between points[1] and points[2] of four
    /// points at knots t: three linear interpolations, two, then one (the recursive
    /// definition, independent of the Hermite form).
    fn barry_goldman(p: [DVec3; 4], t: [f64; 4], s: f64) -> DVec3 {
        let lerp = |a: DVec3, b: DVec3, ta: f64, tb: f64| {
            a * ((tb - s) / (tb - ta)) + b * ((s - ta) / (tb - ta))
        };
        let a1 = lerp(p[0], p[1], t[0], t[1]);
        let a2 = lerp(p[1], p[2], t[1], t[2]);
        let a3 = lerp(p[2], p[3], t[2], t[3]);
        let b1 = a1 * ((t[2] - s) / (t[2] - t[0])) + a2 * ((s - t[0]) / (t[2] - t[0]));
        let b2 = a2 * ((t[3] - s) / (t[3] - t[1])) + a3 * ((s - t[1]) / (t[3] - t[1]));
        b1 * ((t[2] - s) / (t[2] - t[1])) + b2 * ((s - t[1]) / (t[2] - t[1]))
    }

    fn points() -> Vec<DVec3> {
        vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 2.0, 0.5),
            DVec3::new(4.0, 2.5, -1.0),
            DVec3::new(5.0, -1.0, 0.0),
            DVec3::new(7.5, 0.0, 2.0),
            DVec3::new(8.0, 3.0, 1.0),
        ]
    }

    #[test]
    fn interpolation_at_given_parameters_reproduces_a_cubic_and_refuses_bad_parameters() {
        // A cubic interpolant on the averaged knots reproduces every cubic polynomial
        // (Schoenberg–Whitney holds there), whatever the spacing of the parameters.
        let f = |t: f64| DVec3::new(t, 2.0 * t * t - t, 3.0 * t * t * t - t * t + 0.5);
        let params = [0.0, 0.01, 0.05, 0.3, 0.31, 0.7, 0.9, 1.0];
        let points: Vec<DVec3> = params.iter().map(|&t| f(t)).collect();
        let c = interpolate_at_parameters(&points, &params, 3).unwrap();
        for k in 0..=100 {
            let t = f64::from(k) / 100.0;
            assert!(c.point_at(t).unwrap().distance(f(t)) < 1e-12, "at {t}");
        }
        for bad in [
            vec![0.0, 0.5, 0.5, 1.0],
            vec![0.1, 0.2, 0.3, 1.0],
            vec![0.0, 0.2, 0.3, 0.9],
        ] {
            assert!(interpolate_at_parameters(&points[..4], &bad, 3).is_err());
        }
        assert!(interpolate_at_parameters(&points[..4], &params[..3], 3).is_err());
    }

    #[test]
    fn catmull_rom_is_the_barry_goldman_pyramid_for_every_alpha() {
        let p = points();
        for alpha in [0.0, 0.5, 1.0, 0.3] {
            let curve = catmull_rom(&p, alpha).unwrap();
            let mut t = vec![0.0];
            for k in 1..p.len() {
                t.push(t[k - 1] + (p[k] - p[k - 1]).length().powf(alpha));
            }
            assert_eq!(curve.domain(), (t[1], t[p.len() - 2]));
            for i in 1..p.len() - 2 {
                let window = [p[i - 1], p[i], p[i + 1], p[i + 2]];
                let knots = [t[i - 1], t[i], t[i + 1], t[i + 2]];
                for k in 0..=10 {
                    let s = t[i] + (t[i + 1] - t[i]) * f64::from(k) / 10.0;
                    let expected = barry_goldman(window, knots, s);
                    let got = curve.point_at(s).unwrap();
                    assert!(
                        got.distance(expected) < 1e-12,
                        "α {alpha} at {s}: {got} vs {expected}"
                    );
                }
            }
            // Through the inner points, C¹ at them.
            for i in 1..p.len() - 1 {
                assert!(curve.point_at(t[i]).unwrap().distance(p[i]) < 1e-12);
            }
            for &joint in &t[2..p.len() - 2] {
                let before = curve.derivatives(joint - 1e-9, 1).unwrap()[1];
                let after = curve.derivatives(joint + 1e-9, 1).unwrap()[1];
                let jump = before.distance(after);
                assert!(jump < 1e-5 * after.length(), "α {alpha} at {joint}");
            }
        }
    }

    #[test]
    fn uniform_catmull_rom_is_the_classic_matrix_form() {
        let p = points();
        let curve = catmull_rom(&p, 0.0).unwrap();
        // 0.5 · [(2 P1) + (−P0 + P2) s + (2P0 − 5P1 + 4P2 − P3) s² + (−P0 + 3P1 − 3P2 + P3) s³]
        let (p0, p1, p2, p3) = (p[0], p[1], p[2], p[3]);
        for k in 0..=8 {
            let s = f64::from(k) / 8.0;
            let classic = 0.5
                * (2.0 * p1
                    + (p2 - p0) * s
                    + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * s * s
                    + (3.0 * p1 - p0 - 3.0 * p2 + p3) * s * s * s);
            assert!(curve.point_at(1.0 + s).unwrap().distance(classic) < 1e-12);
        }
    }

    #[test]
    fn a_hermite_spline_takes_its_points_and_tangents_and_bad_input_is_refused() {
        let points = [
            DVec3::ZERO,
            DVec3::new(2.0, 1.0, 0.0),
            DVec3::new(3.0, 0.0, 1.0),
        ];
        let tangents = [DVec3::X, DVec3::new(1.0, -1.0, 0.5), DVec3::Z * 2.0];
        let params = [0.0, 1.5, 4.0];
        let curve = hermite_spline(&points, &tangents, &params).unwrap();
        for k in 0..3 {
            let d = curve
                .derivatives(params[k].clamp(0.0, 4.0 - 1e-12), 1)
                .unwrap();
            assert!(d[0].distance(points[k]) < 1e-9);
            assert!(d[1].distance(tangents[k]) < 1e-6, "{k}: {}", d[1]);
        }
        assert!(hermite_spline(&points, &tangents, &[0.0, 2.0, 2.0]).is_err());
        assert!(hermite_spline(&points, &tangents[..2], &params).is_err());
        assert!(catmull_rom(&points, 0.5).is_err());
        let mut doubled = super::tests::points();
        doubled[2] = doubled[1];
        assert!(catmull_rom(&doubled, 0.5).is_err());
        assert!(catmull_rom(&super::tests::points(), 1.5).is_err());
        assert!(catmull_rom(&super::tests::points(), f64::NAN).is_err());
    }

    #[test]
    fn interpolants_pass_through_their_points_at_their_parameters_and_take_the_end_tangents() {
        let p = points();
        let (d0, dn) = (DVec3::new(3.0, 0.0, 1.0), DVec3::new(-2.0, 6.0, 0.0));
        for parametrization in [
            Parametrization::ChordLength,
            Parametrization::Centripetal,
            Parametrization::Uniform,
        ] {
            let params = parameters(&p, parametrization, "test").unwrap();
            // The parameters follow the chords to the power 1, ½ or 0.
            let e = match parametrization {
                Parametrization::ChordLength => 1.0,
                Parametrization::Centripetal => 0.5,
                Parametrization::Uniform => 0.0,
            };
            let steps: Vec<f64> = p.windows(2).map(|w| w[0].distance(w[1]).powf(e)).collect();
            let total: f64 = steps.iter().sum();
            assert!((params[1] - steps[0] / total).abs() < 1e-15);
            for degree in [1, 2, 3, 5] {
                let choices = [None, Some((d0, dn))];
                for tangents in choices.into_iter().filter(|t| degree > 1 || t.is_none()) {
                    let curve = interpolate_through(&p, degree, parametrization, tangents).unwrap();
                    for (q, &t) in p.iter().zip(&params) {
                        let at = curve.point_at(t).unwrap();
                        assert!(
                            at.distance(*q) < 1e-10,
                            "{parametrization:?} {degree}: {at} vs {q}"
                        );
                    }
                    if let Some((a, b)) = tangents {
                        let start = curve.derivatives(0.0, 1).unwrap()[1];
                        let end = curve.derivatives(1.0, 1).unwrap()[1];
                        assert!(
                            start.distance(a) < 1e-9 && end.distance(b) < 1e-9,
                            "{degree}"
                        );
                    }
                }
            }
        }
        // Two points and tangents: the cubic Hermite segment on [0, 1].
        let two = [DVec3::ZERO, DVec3::X * 2.0];
        let curve = interpolate_through(
            &two,
            3,
            Parametrization::ChordLength,
            Some((DVec3::Y, DVec3::Y)),
        )
        .unwrap();
        let hermite = hermite_spline(&two, &[DVec3::Y, DVec3::Y], &[0.0, 1.0]).unwrap();
        for k in 0..=4 {
            let t = f64::from(k) / 4.0;
            assert!(
                curve
                    .point_at(t)
                    .unwrap()
                    .distance(hermite.point_at(t).unwrap())
                    < 1e-12
            );
        }
        // Bad input is refused with the reason.
        let doubled = [p[0], p[0], p[1]];
        assert!(interpolate_through(&doubled, 3, Parametrization::Centripetal, None).is_err());
        assert!(interpolate_through(&p[..1], 3, Parametrization::Centripetal, None).is_err());
        assert!(interpolate_through(&p, 0, Parametrization::Centripetal, None).is_err());
        let linear = interpolate_through(&p, 1, Parametrization::Uniform, Some((d0, dn)));
        assert!(linear.is_err());
        let nan = Some((DVec3::NAN, DVec3::X));
        assert!(interpolate_through(&p, 3, Parametrization::Centripetal, nan).is_err());
    }

    #[test]
    fn a_closed_interpolant_passes_every_point_once_and_is_smooth_at_the_seam() {
        // Eight points of a circle of radius 2, unevenly spaced.
        let angles = [0.0f64, 0.6, 1.1, 2.0, 3.1, 3.9, 4.8, 5.6];
        let circle: Vec<DVec3> = angles
            .iter()
            .map(|a| DVec3::new(2.0 * a.cos(), 2.0 * a.sin(), 0.0))
            .collect();
        for degree in [2, 3, 4, 5] {
            for parametrization in [Parametrization::ChordLength, Parametrization::Centripetal] {
                let curve = interpolate_closed(&circle, degree, parametrization).unwrap();
                assert_eq!(
                    curve.count(),
                    circle.len() + degree,
                    "no point is repeated by hand"
                );
                let (start, end) = curve.domain();
                assert!((end - start - 1.0).abs() < 1e-12);
                // Through every point (the closed polygon's parameters, shifted by a period
                // into the domain where needed).
                let mut closed = circle.clone();
                closed.push(circle[0]);
                let params = parameters(&closed, parametrization, "test").unwrap();
                for (q, &t) in circle.iter().zip(&params) {
                    let t = if t < start { t + 1.0 } else { t };
                    let at = curve.point_at(t).unwrap();
                    assert!(at.distance(*q) < 1e-10, "{degree}: {at} vs {q}");
                }
                // The seam: the same point and derivatives up to order p − 1 at both ends.
                let a = curve.derivatives(start, degree - 1).unwrap();
                let b = curve.derivatives(end, degree - 1).unwrap();
                for (order, (x, y)) in a.iter().zip(&b).enumerate() {
                    let scale = x.length().max(1.0);
                    assert!(
                        x.distance(*y) < 1e-8 * scale,
                        "{degree}: order {order}: {x} vs {y}"
                    );
                }
                // A cubic or higher through 8 points of a circle stays near it: the cubic
                // spline's error bound (5/384) h⁴ max|C⁗| with h = 2.2 (the widest gap's arc)
                // and |C⁗| = 1/r³ is 0.038.
                if degree >= 3 {
                    for k in 0..64 {
                        let u = start + (end - start) * f64::from(k) / 64.0;
                        let r = curve.point_at(u).unwrap().length();
                        assert!((r - 2.0).abs() < 0.05, "{degree}: radius {r} at {u}");
                    }
                }
            }
        }
        assert!(interpolate_closed(&circle[..2], 3, Parametrization::Centripetal).is_err());
        let mut doubled = circle.clone();
        doubled[3] = doubled[2];
        assert!(interpolate_closed(&doubled, 3, Parametrization::Centripetal).is_err());
    }

    #[test]
    fn a_periodic_curve_from_control_points_closes_smoothly() {
        let points: Vec<DVec3> = (0..7)
            .map(|i| {
                let a = i as f64 * std::f64::consts::TAU / 7.0;
                DVec3::new(a.cos(), a.sin(), 0.1 * (3.0 * a).sin())
            })
            .collect();
        for p in 1..=4 {
            let c = periodic_from_control(&points, p).unwrap();
            assert_eq!(c.domain(), (0.0, 1.0));
            let (d0, d1) = (
                c.derivatives(0.0, p).unwrap(),
                c.derivatives(1.0, p).unwrap(),
            );
            for k in 0..p {
                let scale = 1.0 + d0[k].length();
                assert!(
                    d0[k].distance(d1[k]) < 1e-9 * scale,
                    "degree {p}, derivative {k}"
                );
            }
        }
        assert!(periodic_from_control(&points[..2], 2).is_err());
    }
}
