//! NURBS curves in 2D (trim curves, `NurbsCurve<DVec2>`) and 3D (`NurbsCurve<DVec3>`).
//!
//! C(u) = Σ N_{i,p}(u) w_i P_i / Σ N_{i,p}(u) w_i. The control points are stored in homogeneous
//! form (w·P, w), where knot insertion, refinement and degree elevation are linear.

use glam::{DAffine3, DVec3};

use super::basis::{
    MAX_DEGREE, basis_derivatives_into, basis_functions, domain, find_span, interior_knots,
    multiplicity, validate_knots,
};
use super::error::{GeometryError, Location};
use super::ops::{self, Polygon};
use super::vector::{CurvePoint, Vector, binomial};

/// A NURBS curve: degree p ≥ 1, a knot vector of n + p + 2 knots and n + 1 weighted control
/// points. Construction validates everything (see [`validate_knots`]).
#[derive(Debug, Clone, PartialEq)]
pub struct NurbsCurve<P: CurvePoint> {
    poly: Polygon<P::Homogeneous>,
}

/// A 2D curve in a surface's (u, v) parameter plane.
pub type TrimCurve = NurbsCurve<glam::DVec2>;
/// A curve in space.
pub type SpaceCurve = NurbsCurve<DVec3>;

impl<P: CurvePoint> NurbsCurve<P> {
    /// A curve from Cartesian control points and optional weights (`None`: all 1).
    pub fn new(
        degree: usize,
        knots: Vec<f64>,
        points: Vec<P>,
        weights: Option<Vec<f64>>,
    ) -> Result<Self, GeometryError> {
        let weights = weights_or_ones(points.len(), weights)?;
        for (i, (p, &w)) in points.iter().zip(&weights).enumerate() {
            check_point(|| Location::point(i), &p.coordinates(), w)?;
        }
        let homogeneous = points
            .iter()
            .zip(&weights)
            .map(|(&p, &w)| p.to_homogeneous(w))
            .collect();
        Self::from_homogeneous(degree, knots, homogeneous)
    }

    /// A curve from homogeneous control points (w·P, w), validated.
    pub fn from_homogeneous(
        degree: usize,
        knots: Vec<f64>,
        points: Vec<P::Homogeneous>,
    ) -> Result<Self, GeometryError> {
        validate_knots("knots", degree, points.len(), &knots)?;
        for (i, &h) in points.iter().enumerate() {
            check_point(
                || Location::point(i),
                &P::weighted_part(h).coordinates(),
                P::weight_of(h),
            )?;
        }
        Ok(Self {
            poly: Polygon {
                degree,
                knots,
                points,
            },
        })
    }

    /// A polygon produced by a shape-preserving operation on a valid curve.
    fn from_polygon(poly: Polygon<P::Homogeneous>) -> Self {
        debug_assert!(validate_knots("knots", poly.degree, poly.points.len(), &poly.knots).is_ok());
        Self { poly }
    }

    pub fn degree(&self) -> usize {
        self.poly.degree
    }

    pub fn knots(&self) -> &[f64] {
        &self.poly.knots
    }

    /// The number of control points.
    pub fn count(&self) -> usize {
        self.poly.points.len()
    }

    /// Control points in homogeneous form (w·P, w).
    pub fn homogeneous_points(&self) -> &[P::Homogeneous] {
        &self.poly.points
    }

    /// The Cartesian control point i.
    pub fn control_point(&self, i: usize) -> P {
        P::project(self.poly.points[i])
    }

    pub fn weight(&self, i: usize) -> f64 {
        P::weight_of(self.poly.points[i])
    }

    /// True if every weight is 1 (a polynomial B-spline).
    pub fn is_polynomial(&self) -> bool {
        self.poly.points.iter().all(|&h| P::weight_of(h) == 1.0)
    }

    /// The parameter domain [u_p, u_{n+1}].
    pub fn domain(&self) -> (f64, f64) {
        domain(&self.poly.knots, self.poly.degree, self.count())
    }

    pub(crate) fn polygon(&self) -> &Polygon<P::Homogeneous> {
        &self.poly
    }

    fn check_in_domain(&self, u: f64) -> Result<(), GeometryError> {
        let (start, end) = self.domain();
        if crate::basis::in_domain(u, start, end) {
            Ok(())
        } else {
            Err(GeometryError::OutsideDomain {
                parameter: "u",
                value: u,
                start,
                end,
            })
        }
    }

    /// The point C(u).
    pub fn point_at(&self, u: f64) -> Result<P, GeometryError> {
        self.check_in_domain(u)?;
        let p = self.poly.degree;
        let span = find_span(&self.poly.knots, p, self.count(), u);
        // Scratch for the usual degrees, not zeroed at the largest.
        let mut small = [0.0; 8];
        let mut large;
        let basis: &mut [f64] = if p < small.len() {
            &mut small[..=p]
        } else {
            large = [0.0; MAX_DEGREE + 1];
            &mut large[..=p]
        };
        basis_functions(&self.poly.knots, p, span, u, basis);
        // The same sum, in the same order, as `derivatives` with order 0 (A4.1).
        let a = (0..=p).fold(P::Homogeneous::ZERO, |acc, j| {
            acc + self.poly.points[span - p + j] * basis[j]
        });
        Ok(P::weighted_part(a) / P::weight_of(a))
    }

    /// C(u) and its derivatives up to `order`: `[C, C′, C″, …]` (homogeneous derivatives by
    /// The NURBS Book A3.2 "CurveDerivsAlg1", then the rational ones by A4.2 "RatCurveDerivs":
    /// C^(k) = (A^(k) − Σ_{i=1..k} C(k,i) w^(i) C^(k−i)) / w).
    pub fn derivatives(&self, u: f64, order: usize) -> Result<Vec<P>, GeometryError> {
        self.check_in_domain(u)?;
        let p = self.poly.degree;
        let span = find_span(&self.poly.knots, p, self.count(), u);
        let mut ders = vec![0.0; (order + 1) * (p + 1)];
        basis_derivatives_into(&self.poly.knots, p, span, u, order, &mut ders);
        let homogeneous: Vec<P::Homogeneous> = (0..=order)
            .map(|k| {
                (0..=p).fold(P::Homogeneous::ZERO, |acc, j| {
                    acc + self.poly.points[span - p + j] * ders[k * (p + 1) + j]
                })
            })
            .collect();
        let w0 = P::weight_of(homogeneous[0]);
        let mut result: Vec<P> = Vec::with_capacity(order + 1);
        for k in 0..=order {
            let mut v = P::weighted_part(homogeneous[k]);
            for i in 1..=k {
                v = v - result[k - i] * (binomial(k, i) * P::weight_of(homogeneous[i]));
            }
            result.push(v / w0);
        }
        Ok(result)
    }

    /// The same curve with knot `u` inserted `times` times (The NURBS Book, A5.1).
    pub fn insert_knot(&self, u: f64, times: usize) -> Result<Self, GeometryError> {
        check_interior(self.domain(), u, "u")?;
        check_insertion(&self.poly, u, times)?;
        Ok(Self::from_polygon(ops::insert_knot(&self.poly, u, times)))
    }

    /// The same curve with all knots of `knots` inserted (The NURBS Book, A5.4). The list is
    /// sorted first; every knot must lie inside the domain and no multiplicity may exceed p.
    pub fn refine(&self, knots: &[f64]) -> Result<Self, GeometryError> {
        let mut x = knots.to_vec();
        check_refinement(&self.poly, &mut x, "u")?;
        Ok(Self::from_polygon(ops::refine_knots(&self.poly, &x)))
    }

    /// The same curve with its degree raised by `times` (The NURBS Book, A5.9).
    pub fn elevate_degree(&self, times: usize) -> Result<Self, GeometryError> {
        let degree = self.poly.degree + times;
        if degree > MAX_DEGREE {
            return Err(GeometryError::Degree {
                at: Location::field("degree"),
                degree,
                max: MAX_DEGREE,
            });
        }
        Ok(Self::from_polygon(ops::elevate_degree(&self.poly, times)))
    }

    /// The two pieces over [a, u] and [u, b].
    pub fn split(&self, u: f64) -> Result<(Self, Self), GeometryError> {
        check_interior(self.domain(), u, "u")?;
        let (left, right) = ops::split(&self.poly, u);
        Ok((Self::from_polygon(left), Self::from_polygon(right)))
    }

    /// The same closed curve (its ends within `tolerance`) with its seam moved to `u` inside
    /// its domain [a, b] ([`ops::moved_seam`]): over [u, u + b − a], the point at t is the
    /// old point at t, or at t − (b − a) past b. The part before `u` has its weights scaled by
    /// one factor (the same shape) so that it meets the part after `u` in homogeneous
    /// coordinates.
    pub fn moved_seam(&self, u: f64, tolerance: f64) -> Result<Self, GeometryError> {
        check_interior(self.domain(), u, "u")?;
        // The ends the seam joins: the last point (the part after `u` ends there) and the
        // first (the part before it starts there).
        let (Some(&a), Some(&b)) = (self.poly.points.last(), self.poly.points.first()) else {
            return Err(GeometryError::Construction {
                what: "move the seam",
                message: "the curve has no control points".into(),
            });
        };
        let (pa, pb) = (P::project(a), P::project(b));
        let gap = (pa - pb).norm();
        if !(gap <= tolerance) {
            return Err(GeometryError::Construction {
                what: "move the seam",
                message: format!("the curve is not closed: its ends are {gap:.3e} apart"),
            });
        }
        let scale = P::weight_of(a) / P::weight_of(b);
        Ok(Self::from_polygon(ops::moved_seam(&self.poly, u, scale)))
    }

    /// The same curve traversed in the opposite direction over the same domain.
    pub fn reverse(&self) -> Self {
        Self::from_polygon(ops::reverse(&self.poly))
    }

    /// The same shape over a clamped knot vector.
    pub fn clamped(&self) -> Self {
        Self::from_polygon(ops::clamp(&self.poly))
    }

    /// The Bézier segments (each a clamped curve of one span) in order.
    pub fn bezier_segments(&self) -> Vec<Self> {
        let p = self.poly.degree;
        ops::bezier_segments(&self.poly)
            .into_iter()
            .map(|(points, [a, b])| {
                let mut knots = vec![a; p + 1];
                knots.extend(std::iter::repeat_n(b, p + 1));
                Self::from_polygon(Polygon {
                    degree: p,
                    knots,
                    points,
                })
            })
            .collect()
    }

    /// Removes the interior knot `u` up to `times` times where the curve moves by at most
    /// `tolerance` (The NURBS Book, A5.8, with the book's bound TOL = d·w_min / (1 + |P|_max)
    /// on the homogeneous points). Returns the new curve and how many were removed.
    pub fn remove_knot(&self, u: f64, times: usize, tolerance: f64) -> (Self, usize) {
        let tol = homogeneous_tolerance(
            tolerance,
            self.poly
                .points
                .iter()
                .map(|&h| (P::weight_of(h), P::project(h).norm())),
        );
        let mut poly = self.poly.clone();
        let mut removed = 0;
        while removed < times {
            match ops::remove_knot(&poly, u, tol) {
                Some(next) => {
                    poly = next;
                    removed += 1;
                }
                None => break,
            }
        }
        (Self::from_polygon(poly), removed)
    }

    /// The same curve with every control point mapped by `f` (weights kept).
    pub fn map_points(&self, f: impl Fn(P) -> P) -> Result<Self, GeometryError> {
        self.map_into(f)
    }

    /// The curve whose control points are this one's mapped by `f`, possibly into another
    /// space (a plane's (u, v) and 3D), with the same degree, knots and weights: for an affine
    /// `f`, the image of the curve at the same parameter.
    pub fn map_into<Q: CurvePoint>(
        &self,
        f: impl Fn(P) -> Q,
    ) -> Result<NurbsCurve<Q>, GeometryError> {
        let points = (0..self.count()).map(|i| self.control_point(i)).map(f);
        let weights = (0..self.count()).map(|i| self.weight(i)).collect();
        NurbsCurve::new(
            self.poly.degree,
            self.poly.knots.clone(),
            points.collect(),
            Some(weights),
        )
    }

    /// The same curve with its parameter mapped linearly onto [start, end].
    pub fn reparametrized(&self, start: f64, end: f64) -> Result<Self, GeometryError> {
        let (a, b) = self.domain();
        if !(start.is_finite() && end.is_finite() && start < end) {
            return Err(GeometryError::EmptyDomain {
                at: Location::field("domain"),
                start,
                end,
            });
        }
        let knots = self
            .poly
            .knots
            .iter()
            .map(|&k| start + (k - a) / (b - a) * (end - start))
            .collect();
        Self::from_homogeneous(self.poly.degree, knots, self.poly.points.clone())
    }

    /// This curve followed by `next`, which starts where this one ends, as one curve: both are
    /// clamped and raised to the higher degree, `next`'s parameter continues this one's
    /// (shifted by the end of this domain) and its weights are scaled so that its first weight
    /// is this curve's last (which leaves its shape unchanged); the joint is a knot of
    /// multiplicity p, where the curve keeps this curve's end point. A gap between the ends
    /// closes there.
    pub fn join(&self, next: &Self) -> Result<Self, GeometryError> {
        let p = self.degree().max(next.degree());
        let a = self.clamped().elevate_degree(p - self.degree())?;
        let b = next.clamped().elevate_degree(p - next.degree())?;
        let (_, a_end) = a.domain();
        let (b_start, b_end) = b.domain();
        let b = b.reparametrized(a_end, a_end + (b_end - b_start))?;
        let scale = P::weight_of(a.poly.points[a.count() - 1]) / P::weight_of(b.poly.points[0]);
        let mut points = a.poly.points.clone();
        points.extend(b.poly.points[1..].iter().map(|&h| h * scale));
        let mut knots = a.poly.knots[..a.poly.knots.len() - 1].to_vec();
        knots.extend_from_slice(&b.poly.knots[p + 1..]);
        Self::from_homogeneous(p, knots, points)
    }

    /// The start and end points C(a) and C(b).
    pub fn ends(&self) -> Result<(P, P), GeometryError> {
        let (a, b) = self.domain();
        Ok((self.point_at(a)?, self.point_at(b)?))
    }

    /// The parameter a `fraction` of the way through the domain [a, b], kept inside it (a +
    /// (b − a)·1 can round past b).
    pub fn parameter_at(&self, fraction: f64) -> f64 {
        let (a, b) = self.domain();
        (a + (b - a) * fraction).clamp(a, b)
    }

    /// The distinct knots of the domain [a, b], a and b included: the ends of the Bézier
    /// segments of [`Self::bezier_segments`].
    pub fn span_breaks(&self) -> Vec<f64> {
        ops::distinct_breaks(&self.poly.knots, self.poly.degree, self.count())
    }

    /// The indices of the Bézier segments ([`Self::bezier_segments`]) that control point `i`
    /// moves: those overlapping its support [u_i, u_{i+p+1}) (The NURBS Book P2.1); none for a
    /// point it does not have.
    pub fn segments_supported_by(&self, i: usize) -> Vec<usize> {
        if i >= self.count() {
            return Vec::new();
        }
        let (lo, hi) = (
            self.poly.knots[i],
            self.poly.knots[i + self.poly.degree + 1],
        );
        self.span_breaks()
            .windows(2)
            .enumerate()
            .filter(|(_, w)| w[0] < hi && w[1] > lo)
            .map(|(k, _)| k)
            .collect()
    }

    /// The curve with control point `i` moved to `position`, its weight kept. Refused for a
    /// point it does not have and a position that is not finite.
    pub fn with_point(&self, i: usize, position: P) -> Result<Self, GeometryError> {
        let count = self.count();
        let Some(&h) = self.poly.points.get(i) else {
            return Err(GeometryError::NoSuchPoint { index: i, count });
        };
        let w = P::weight_of(h);
        check_point(|| Location::point(i), &position.coordinates(), w)?;
        let mut poly = self.poly.clone();
        poly.points[i] = position.to_homogeneous(w);
        Ok(Self { poly })
    }

    /// The curve with the weight of control point `i` set to `weight` (finite and > 0), its
    /// Cartesian position kept.
    pub fn with_weight(&self, i: usize, weight: f64) -> Result<Self, GeometryError> {
        let count = self.count();
        if i >= count {
            return Err(GeometryError::NoSuchPoint { index: i, count });
        }
        let position = self.control_point(i);
        check_point(|| Location::point(i), &position.coordinates(), weight)?;
        let mut poly = self.poly.clone();
        poly.points[i] = position.to_homogeneous(weight);
        Ok(Self { poly })
    }

    /// The interior knots of the domain with their multiplicities.
    pub fn interior_knots(&self) -> Vec<(f64, usize)> {
        interior_knots(&self.poly.knots, self.poly.degree, self.count())
    }
}

impl NurbsCurve<DVec3> {
    /// The parameter of the curve's point nearest `target`: the nearest of 200 samples at
    /// evenly spaced parameters, refined by Newton's iteration on C′·(C − P) = 0 (The NURBS Book
    /// §6.1), clamped to the domain.
    ///
    /// A target within 1e-10 of the chord's length of one end of an open curve (a STEP
    /// vertex at its edge's end, most often) is that end's: the samples would pick it, so
    /// Newton starts there without them.
    pub fn closest_parameter(&self, target: DVec3) -> Result<f64, GeometryError> {
        const SAMPLES: usize = 200;
        let (a, b) = self.domain();
        let (first, last) = (self.point_at(a)?, self.point_at(b)?);
        let near = 1e-20 * first.distance_squared(last);
        if first.distance_squared(target) <= near {
            return self.closest_parameter_from(target, a);
        }
        if last.distance_squared(target) <= near {
            return self.closest_parameter_from(target, b);
        }
        let mut nearest = (f64::INFINITY, 0.0);
        for i in 0..=SAMPLES {
            let t = self.parameter_at(i as f64 / SAMPLES as f64);
            let d = self.point_at(t)?.distance_squared(target);
            if d < nearest.0 {
                nearest = (d, t);
            }
        }
        self.closest_parameter_from(target, nearest.1)
    }

    /// The parameter of a point of the curve nearest `target`, by Newton's iteration on
    /// C′·(C − P) = 0 from `start` (The NURBS Book §6.1), clamped to the domain: the nearest
    /// point near `start`, a local minimum of the distance.
    pub fn closest_parameter_from(&self, target: DVec3, start: f64) -> Result<f64, GeometryError> {
        let (a, b) = self.domain();
        let mut t = start.clamp(a, b);
        for _ in 0..30 {
            let d = self.derivatives(t, 2)?;
            let r = d[0] - target;
            let f = d[1].dot(r);
            let df = d[2].dot(r) + d[1].dot(d[1]);
            if !(df.abs() > 1e-300) {
                break;
            }
            let next = (t - f / df).clamp(a, b);
            let moved = (next - t).abs();
            t = next;
            if moved <= 1e-15 * (b - a) {
                break;
            }
        }
        Ok(t)
    }

    /// The curve mapped by an affine transformation. NURBS are affinely invariant: mapping the
    /// control points maps the curve.
    pub fn transformed(&self, transform: &DAffine3) -> Result<Self, GeometryError> {
        self.map_points(|p| transform.transform_point3(p))
    }
}

/// The diagonal of the box around the curves' control points (which contains the curves): the
/// size that the tolerances of constructions from curves are fractions of; 0 for no points.
pub fn control_box_size<'a>(curves: impl IntoIterator<Item = &'a SpaceCurve>) -> f64 {
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for c in curves {
        for i in 0..c.count() {
            lo = lo.min(c.control_point(i));
            hi = hi.max(c.control_point(i));
        }
    }
    if lo.x > hi.x { 0.0 } else { lo.distance(hi) }
}

/// The weights of `count` control points: `None` means all 1; a list of another length is an
/// error.
pub(crate) fn weights_or_ones(
    count: usize,
    weights: Option<Vec<f64>>,
) -> Result<Vec<f64>, GeometryError> {
    let weights = weights.unwrap_or_else(|| vec![1.0; count]);
    if weights.len() != count {
        return Err(GeometryError::WeightCount {
            points: count,
            weights: weights.len(),
        });
    }
    Ok(weights)
}

/// Checks a Cartesian control point and its weight; `at` names it in errors (made only for an
/// error: formatting a name for each of a million points showed in profiles).
pub(crate) fn check_point(
    at: impl FnOnce() -> Location,
    coordinates: &[f64],
    weight: f64,
) -> Result<(), GeometryError> {
    if let Some(coordinate) = coordinates.iter().position(|c| !c.is_finite()) {
        return Err(GeometryError::NonFinitePoint {
            at: at(),
            coordinate,
        });
    }
    if !(weight.is_finite() && weight > 0.0) {
        return Err(GeometryError::BadWeight { at: at(), weight });
    }
    Ok(())
}

/// The NURBS Book's tolerance for knot removal on homogeneous points (eq. 5.30 and the text
/// around A5.8): a deviation of at most d in space is guaranteed by d·w_min / (1 + |P|_max).
pub(crate) fn homogeneous_tolerance(
    distance: f64,
    weights_and_norms: impl Iterator<Item = (f64, f64)>,
) -> f64 {
    let (w_min, p_max) = weights_and_norms.fold((f64::INFINITY, 0.0f64), |(w, p), (wi, pi)| {
        (w.min(wi), p.max(pi))
    });
    distance * w_min / (1.0 + p_max)
}

/// Requires `u` strictly inside `domain`.
pub(crate) fn check_interior(
    (start, end): (f64, f64),
    u: f64,
    parameter: &'static str,
) -> Result<(), GeometryError> {
    if u > start && u < end {
        Ok(())
    } else {
        Err(GeometryError::NotInterior {
            parameter,
            value: u,
            start,
            end,
        })
    }
}

/// Sorts a refinement list and checks it: knots strictly inside the domain, and no resulting
/// multiplicity above the degree.
pub(crate) fn check_refinement<V: Vector>(
    poly: &Polygon<V>,
    x: &mut [f64],
    parameter: &'static str,
) -> Result<(), GeometryError> {
    x.sort_by(f64::total_cmp);
    let d = domain(&poly.knots, poly.degree, poly.points.len());
    for &k in x.iter() {
        check_interior(d, k, parameter)?;
        let total = multiplicity(&poly.knots, k) + x.iter().filter(|&&y| y == k).count();
        if total > poly.degree {
            return Err(GeometryError::InsertionTooMany {
                value: k,
                times: total - multiplicity(&poly.knots, k),
                degree: poly.degree,
            });
        }
    }
    Ok(())
}

/// Requires that inserting `u` `times` times keeps its multiplicity ≤ the degree.
pub(crate) fn check_insertion<V: Vector>(
    poly: &Polygon<V>,
    u: f64,
    times: usize,
) -> Result<(), GeometryError> {
    if multiplicity(&poly.knots, u) + times > poly.degree {
        return Err(GeometryError::InsertionTooMany {
            value: u,
            times,
            degree: poly.degree,
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cubic() -> SpaceCurve {
        let points = (0..6)
            .map(|i| DVec3::new(i as f64, (i * i % 5) as f64, 0.0))
            .collect();
        let knots = vec![0.0, 0.0, 0.0, 0.0, 1.0, 2.0, 3.0, 3.0, 3.0, 3.0];
        SpaceCurve::new(3, knots, points, None).unwrap()
    }

    #[test]
    fn a_point_moves_only_the_segments_of_its_support() {
        let curve = cubic();
        assert_eq!(curve.span_breaks(), [0.0, 1.0, 2.0, 3.0]);
        // N_{0,3} lives on [0, 1), N_{2,3} on [0, 3), N_{5,3} on [2, 3) (The NURBS Book P2.1).
        assert_eq!(curve.segments_supported_by(0), [0]);
        assert_eq!(curve.segments_supported_by(2), [0, 1, 2]);
        assert_eq!(curve.segments_supported_by(5), [2]);
        assert!(curve.segments_supported_by(6).is_empty());
        let moved = curve.with_point(0, DVec3::new(0.0, 0.0, 4.0)).unwrap();
        for t in [1.0, 1.5, 2.5, 3.0] {
            assert_eq!(moved.point_at(t).unwrap(), curve.point_at(t).unwrap());
        }
        assert_ne!(moved.point_at(0.5).unwrap(), curve.point_at(0.5).unwrap());
        assert!(curve.with_point(9, DVec3::ZERO).is_err());
        assert!(curve.with_point(1, DVec3::NAN).is_err());
        // A new weight keeps the point where it is.
        let weighted = curve.with_weight(2, 3.0).unwrap();
        assert_eq!(weighted.control_point(2), curve.control_point(2));
        assert_eq!(weighted.weight(2), 3.0);
        assert!(curve.with_weight(2, 0.0).is_err());
    }

    /// The global search without its shortcut at the ends: the nearest of 201 samples,
    /// refined by Newton.
    fn closest_by_samples(c: &SpaceCurve, target: DVec3) -> f64 {
        let mut nearest = (f64::INFINITY, 0.0);
        for i in 0..=200 {
            let t = c.parameter_at(i as f64 / 200.0);
            let d = c.point_at(t).unwrap().distance_squared(target);
            if d < nearest.0 {
                nearest = (d, t);
            }
        }
        c.closest_parameter_from(target, nearest.1).unwrap()
    }

    #[test]
    fn a_point_at_an_end_is_found_there_as_the_samples_find_it() {
        let mut state = 11u64;
        let mut unit = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..300 {
            let degree = 1 + (unit() * 4.0) as usize;
            let count = degree + 1 + (unit() * 6.0) as usize;
            let scale = 10f64.powf(4.0 * unit() - 2.0);
            let points: Vec<DVec3> = (0..count)
                .map(|_| DVec3::new(unit(), unit(), unit()) * scale)
                .collect();
            let weights = (0..count).map(|_| 0.2 + 5.0 * unit()).collect();
            let mut knots = vec![0.0; degree + 1];
            let mut t = 0.0;
            for _ in 0..count - degree - 1 {
                t += 0.1 + unit();
                knots.push(t);
            }
            knots.extend(vec![t + 0.1 + unit(); degree + 1]);
            let (shift, stretch) = (100.0 * unit() - 50.0, 0.5 + unit());
            let knots = knots.iter().map(|k| k * stretch + shift).collect();
            let c = SpaceCurve::new(degree, knots, points, Some(weights)).unwrap();
            let (a, b) = c.domain();
            let chord = c.point_at(a).unwrap().distance(c.point_at(b).unwrap());
            for (end, t) in [(a, a), (b, b)] {
                let noise = DVec3::new(unit(), unit(), unit()) - 0.5;
                for off in [0.0, 1e-13, 5e-11] {
                    let target = c.point_at(end).unwrap() + noise * off * chord;
                    let found = c.closest_parameter(target).unwrap();
                    assert_eq!(found, closest_by_samples(&c, target), "{off} from {t}");
                    assert!((found - t).abs() <= 1e-6 * (b - a), "{found} against {t}");
                }
            }
            // Elsewhere the samples alone.
            let target = c.point_at(c.parameter_at(unit())).unwrap();
            assert_eq!(
                c.closest_parameter(target).unwrap(),
                closest_by_samples(&c, target)
            );
        }
    }
}
