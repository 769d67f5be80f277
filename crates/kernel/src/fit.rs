//! Approximating curves: least-squares B-spline fitting (The NURBS Book §9.4.1, A9.7), the
//! rebuild of a curve with a chosen number of points and degree, the fit of a curve to a
//! tolerance, and the deviation between two curves.

use glam::DVec3;

use super::basis::{basis_functions, find_span};
use super::curve::SpaceCurve;
use super::error::GeometryError;
use super::error::construction;
use super::splines::{Parametrization, parameters};

/// The most control points a rebuilt or fitted curve may have.
pub const MAX_FIT_POINTS: usize = 1024;

/// The non-rational B-spline of degree `degree` with `count` control points that passes
/// through the first and last of `points` and approximates the rest in the least-squares sense
/// at `params` (increasing from 0 to 1; The NURBS Book A9.7): knots by eq. 9.68–9.69 (d =
/// (m + 1)/(n − p + 1), u_{p+j} = (1 − α) ū_{i−1} + α ū_i with i = ⌊jd⌋, α = jd − i), then the
/// normal equations (NᵀN) P = R for the inner control points.
pub fn least_squares(
    points: &[DVec3],
    params: &[f64],
    degree: usize,
    count: usize,
) -> Result<SpaceCurve, GeometryError> {
    const WHAT: &str = "least-squares fit";
    let m = points.len().saturating_sub(1);
    if params.len() != points.len() {
        return Err(construction(WHAT, "one parameter per point"));
    }
    if degree == 0 || count < degree + 1 {
        return Err(construction(
            WHAT,
            format!("{count} control points cannot carry degree {degree}"),
        ));
    }
    if count > m + 1 {
        return Err(construction(
            WHAT,
            format!(
                "{count} control points need at least as many samples, got {}",
                m + 1
            ),
        ));
    }
    let n = count - 1;
    let p = degree;
    let d = (m + 1) as f64 / (n - p + 1) as f64;
    let mut knots = vec![0.0; p + 1];
    for j in 1..=n - p {
        let jd = j as f64 * d;
        let i = jd.floor() as usize;
        let alpha = jd - i as f64;
        knots.push((1.0 - alpha) * params[i - 1] + alpha * params[i.min(m)]);
    }
    knots.extend(std::iter::repeat_n(1.0, p + 1));
    if n < 2 {
        // Two control points: the line between the ends.
        return SpaceCurve::new(p, knots, vec![points[0], points[m]], None);
    }
    // Rows k = 1 … m − 1: N_{i}(ū_k) for i = 1 … n − 1, and R_k = Q_k − N_0 Q_0 − N_n Q_m.
    let inner = n - 1;
    let mut normal = vec![vec![0.0; inner]; inner];
    let mut rhs = vec![DVec3::ZERO; inner];
    let mut basis = vec![0.0; p + 1];
    for k in 1..m {
        let t = params[k];
        let span = find_span(&knots, p, count, t);
        basis_functions(&knots, p, span, t, &mut basis);
        let mut row = vec![0.0; count];
        row[span - p..=span].copy_from_slice(&basis);
        let r = points[k] - points[0] * row[0] - points[m] * row[n];
        for a in 1..n {
            if row[a] == 0.0 {
                continue;
            }
            rhs[a - 1] += r * row[a];
            for b in 1..n {
                normal[a - 1][b - 1] += row[a] * row[b];
            }
        }
    }
    let inner_points = super::vector::solve_linear(normal, rhs).ok_or_else(|| {
        construction(
            WHAT,
            "the normal equations are singular (too few samples between the knots)",
        )
    })?;
    let mut control = Vec::with_capacity(count);
    control.push(points[0]);
    control.extend(inner_points);
    control.push(points[m]);
    SpaceCurve::new(p, knots, control, None)
}

/// The largest distance from `original` (sampled at `samples` + 1 evenly spaced parameters) to
/// `approximation` (by point inversion on it), and where on `original` it occurs.
pub fn deviation(
    original: &SpaceCurve,
    approximation: &SpaceCurve,
    samples: usize,
) -> Result<(f64, DVec3), GeometryError> {
    function_deviation(
        &|f| original.point_at(original.parameter_at(f)),
        approximation,
        samples,
    )
}

/// A rebuilt curve and how far it is from the original.
#[derive(Debug, Clone)]
pub struct Rebuilt {
    pub curve: SpaceCurve,
    /// The largest distance from the original to the rebuilt curve, and where on the original.
    pub deviation: f64,
    pub at: DVec3,
}

/// Samples of a point function on [0, 1] for fitting: `count` + 1 points at evenly spaced
/// fractions, with chord-length parameters (close to arc length, whatever the function's own
/// speed, so that the fit follows the shape rather than the parametrization; coincident
/// neighbours, as at a curve's collapsed end, share a parameter step of zero length and are
/// skipped).
fn samples(
    at: &impl Fn(f64) -> Result<DVec3, GeometryError>,
    count: usize,
) -> Result<(Vec<DVec3>, Vec<f64>), GeometryError> {
    let mut points: Vec<DVec3> = Vec::with_capacity(count + 1);
    for i in 0..=count {
        let p = at(i as f64 / count as f64)?;
        if points.last().is_none_or(|q| q.distance(p) > 0.0) || i == count {
            points.push(p);
        }
    }
    let params = parameters(&points, Parametrization::ChordLength, "fit")?;
    Ok((points, params))
}

/// The largest distance from the points of `at` (a function on [0, 1]) at `samples` + 1 evenly
/// spaced fractions to `approximation`, and where.
fn function_deviation(
    at: &impl Fn(f64) -> Result<DVec3, GeometryError>,
    approximation: &SpaceCurve,
    samples: usize,
) -> Result<(f64, DVec3), GeometryError> {
    let mut worst = (0.0, at(0.0)?);
    for i in 0..=samples {
        let p = at(i as f64 / samples as f64)?;
        let t = approximation.closest_parameter(p)?;
        let d = approximation.point_at(t)?.distance(p);
        if d > worst.0 {
            worst = (d, p);
        }
    }
    Ok(worst)
}

/// The least-squares B-spline with `count` points of degree `degree` (lowered to count − 1)
/// through the ends of the point function `at` on [0, 1], fitted to 8 samples per control
/// point (at least 200), with its largest deviation at 400 points.
fn rebuild_function(
    at: &impl Fn(f64) -> Result<DVec3, GeometryError>,
    count: usize,
    degree: usize,
    what: &'static str,
) -> Result<Rebuilt, GeometryError> {
    if !(2..=MAX_FIT_POINTS).contains(&count) {
        return Err(construction(
            what,
            format!("{count} points: a rebuilt curve has 2 to {MAX_FIT_POINTS}"),
        ));
    }
    if degree == 0 {
        return Err(construction(what, "the degree must be ≥ 1"));
    }
    let degree = degree.min(count - 1);
    let (points, params) = samples(at, (8 * count).max(200))?;
    let curve = least_squares(&points, &params, degree, count)?;
    let (deviation, at) = function_deviation(at, &curve, 400)?;
    Ok(Rebuilt {
        curve,
        deviation,
        at,
    })
}

/// The fewest-point cubic (to within a factor of two) within `tolerance` of the point
/// function `at` on [0, 1]: [`rebuild_function`] with 4, 8, 16 … points.
fn fit_function(
    at: &impl Fn(f64) -> Result<DVec3, GeometryError>,
    tolerance: f64,
    what: &'static str,
) -> Result<Rebuilt, GeometryError> {
    if !(tolerance > 0.0 && tolerance.is_finite()) {
        return Err(construction(
            what,
            format!("the tolerance {tolerance} must be a positive number"),
        ));
    }
    let mut count = 4;
    loop {
        let rebuilt = rebuild_function(at, count, 3, what)?;
        if rebuilt.deviation <= tolerance {
            return Ok(rebuilt);
        }
        if count >= MAX_FIT_POINTS {
            return Err(construction(
                what,
                format!(
                    "{MAX_FIT_POINTS} points come only within {:.3e}, more than the tolerance \
                     {tolerance}",
                    rebuilt.deviation
                ),
            ));
        }
        count = (count * 2).min(MAX_FIT_POINTS);
    }
}

/// `curve` rebuilt as a non-rational B-spline with `count` control points of degree `degree`
/// (lowered to count − 1): a least-squares fit ([`least_squares`]) to 8 samples per control
/// point (at least 200, evenly spaced in the curve's parameter, at their chord-length
/// parameters) through its ends, with the largest deviation measured at 400 points. The
/// direction and end points are kept; the rebuilt curve runs over [0, 1].
pub fn rebuild(curve: &SpaceCurve, count: usize, degree: usize) -> Result<Rebuilt, GeometryError> {
    rebuild_function(
        &|f| curve.point_at(curve.parameter_at(f)),
        count,
        degree,
        "rebuild",
    )
}

/// The fewest-point non-rational cubic (to within a factor of two) that is within `tolerance`
/// of `curve`: [`rebuild`] with 4, 8, 16 … control points until the deviation is within it.
/// Refused if even [`MAX_FIT_POINTS`] points are not.
pub fn fit(curve: &SpaceCurve, tolerance: f64) -> Result<Rebuilt, GeometryError> {
    fit_function(&|f| curve.point_at(curve.parameter_at(f)), tolerance, "fit")
}

/// The offset of a planar curve by `distance` in its plane: C(t) + distance · (C′(t) × n) /
/// |C′(t) × n|, to the right of the direction of travel seen from the tip of the plane's
/// normal n. Without a given normal, n is Newell's normal of the curve's samples, which makes
/// a closed curve turn counter-clockwise, so a positive distance grows a closed curve. Offsets
/// are not NURBS in general: the result is a cubic fitted within `tolerance`. Refused: a curve
/// off its plane by more than 1e-6 of its size, a straight curve without a normal, a point
/// where the tangent vanishes.
pub fn offset_planar(
    curve: &SpaceCurve,
    distance: f64,
    normal: Option<DVec3>,
    tolerance: f64,
) -> Result<Rebuilt, GeometryError> {
    const WHAT: &str = "offset";
    if !distance.is_finite() {
        return Err(construction(WHAT, "the distance is not a number"));
    }
    let points: Vec<DVec3> = (0..=128)
        .map(|i| curve.point_at(curve.parameter_at(i as f64 / 128.0)))
        .collect::<Result<_, _>>()?;
    let size = points
        .iter()
        .map(|p| p.distance(points[0]))
        .fold(0.0, f64::max)
        .max(1e-300);
    let centre = points.iter().copied().sum::<DVec3>() / points.len() as f64;
    let n = match normal {
        Some(n) if n.length() > 0.0 && n.is_finite() => n.normalize(),
        Some(_) => return Err(construction(WHAT, "the normal has zero length")),
        None => {
            let mut area = DVec3::ZERO;
            for w in points.windows(2) {
                area += (w[0] - centre).cross(w[1] - centre);
            }
            if !(area.length() > 1e-12 * size * size) {
                return Err(construction(
                    WHAT,
                    "the curve is straight, so it has no plane of its own: give the normal",
                ));
            }
            area.normalize()
        }
    };
    if let Some(off) = points
        .iter()
        .map(|p| (*p - centre).dot(n).abs())
        .find(|&d| d > 1e-6 * size)
    {
        return Err(construction(
            WHAT,
            format!("the curve is not planar: a point is {off:.3e} off its plane"),
        ));
    }
    let at = |f: f64| -> Result<DVec3, GeometryError> {
        let d = curve.derivatives(curve.parameter_at(f), 1)?;
        let side = d[1].cross(n);
        if !(side.length() > 1e-300) {
            return Err(construction(WHAT, "the curve's tangent vanishes"));
        }
        Ok(d[0] + side.normalize() * distance)
    };
    fit_function(&at, tolerance, WHAT)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::construct::circle;

    #[test]
    fn a_rebuilt_circle_is_near_the_circle_and_a_fit_meets_its_tolerance() {
        let c = circle(DVec3::ZERO, DVec3::Z, DVec3::X, 2.0).unwrap();
        let rebuilt = rebuild(&c, 12, 3).unwrap();
        assert_eq!(rebuilt.curve.count(), 12);
        assert_eq!(rebuilt.curve.degree(), 3);
        // An independent measure: the radius of the rebuilt curve's points.
        let worst = (0..=200)
            .map(|i| rebuilt.curve.point_at(i as f64 / 200.0).unwrap().length() - 2.0)
            .fold(0.0_f64, |a, b| a.max(b.abs()));
        assert!(worst < 1e-3, "radius off by {worst}");
        assert!(
            rebuilt.deviation <= worst * 1.01 + 1e-12,
            "{} vs {worst}",
            rebuilt.deviation
        );
        for tolerance in [1e-2, 1e-4, 1e-6] {
            let fitted = fit(&c, tolerance).unwrap();
            assert!(fitted.deviation <= tolerance);
            let worst = (0..=500)
                .map(|i| fitted.curve.point_at(i as f64 / 500.0).unwrap().length() - 2.0)
                .fold(0.0_f64, |a, b| a.max(b.abs()));
            assert!(worst <= tolerance * 1.01, "{worst} > {tolerance}");
        }
    }

    #[test]
    fn a_rebuilt_cubic_converges_to_itself() {
        let pts = [
            DVec3::ZERO,
            DVec3::new(1.0, 2.0, 0.0),
            DVec3::new(3.0, -1.0, 1.0),
            DVec3::new(4.0, 0.0, 0.0),
        ];
        let knots = vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0];
        let c = SpaceCurve::new(3, knots, pts.to_vec(), None).unwrap();
        let mut previous = f64::INFINITY;
        for count in [4, 8, 16, 32] {
            let rebuilt = rebuild(&c, count, 3).unwrap();
            let (independent, _) = deviation(&c, &rebuilt.curve, 1000).unwrap();
            assert!(rebuilt.deviation <= independent * 1.5 + 1e-12);
            assert!(
                rebuilt.deviation < previous,
                "{count} points: {}",
                rebuilt.deviation
            );
            previous = rebuilt.deviation;
        }
        assert!(previous < 1e-5, "{previous}");
    }

    #[test]
    fn a_circle_offset_outwards_is_the_larger_circle() {
        let c = circle(
            DVec3::new(1.0, 2.0, 3.0),
            DVec3::new(0.0, 1.0, 1.0),
            DVec3::X,
            2.0,
        )
        .unwrap();
        for (distance, radius) in [(0.5, 2.5), (-0.5, 1.5)] {
            let off = offset_planar(&c, distance, None, 1e-6).unwrap();
            assert!(off.deviation <= 1e-6);
            for i in 0..=100 {
                let p = off.curve.point_at(i as f64 / 100.0).unwrap();
                let r = p.distance(DVec3::new(1.0, 2.0, 3.0));
                assert!((r - radius).abs() < 2e-6, "radius {r} for {radius}");
            }
        }
        // A straight line needs a normal; with one it moves sideways.
        let line = crate::construct::line(DVec3::ZERO, DVec3::X).unwrap();
        assert!(offset_planar(&line, 1.0, None, 1e-6).is_err());
        let moved = offset_planar(&line, 1.0, Some(DVec3::Z), 1e-6).unwrap();
        let p = moved.curve.point_at(0.5).unwrap();
        assert!(p.distance(DVec3::new(0.5, -1.0, 0.0)) < 1e-9, "{p}");
    }

    #[test]
    fn bad_requests_are_refused() {
        let c = circle(DVec3::ZERO, DVec3::Z, DVec3::X, 1.0).unwrap();
        assert!(rebuild(&c, 1, 3).is_err());
        assert!(rebuild(&c, 5000, 3).is_err());
        assert!(fit(&c, 0.0).is_err());
        assert!(fit(&c, f64::NAN).is_err());
    }
}
