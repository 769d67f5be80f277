//! NURBS surfaces: S(u, v) = Σ_i Σ_j N_{i,p}(u) N_{j,q}(v) w_ij P_ij / Σ_i Σ_j N_{i,p}(u) N_{j,q}(v) w_ij.
//!
//! Control points are stored homogeneous, (w·P, w), row-major with i along u:
//! `points[i * count_v + j]`. Bézier patches and non-rational B-spline surfaces are special cases
//! of the same type. Evaluation follows The NURBS Book: knot spans by A2.1, basis derivatives by
//! A2.3, homogeneous surface derivatives by A3.6, rational derivatives by A4.4 (eq. 4.20).

use glam::{DAffine3, DVec2, DVec3, DVec4};

use super::basis::{
    MAX_DEGREE, basis_derivatives_into, basis_functions, domain, find_span, validate_knots,
};
use super::bezier::{BezierPatch, BezierPatchSet};
use super::curve::{
    NurbsCurve, SpaceCurve, check_insertion, check_interior, check_point, check_refinement,
    homogeneous_tolerance,
};
use super::diffgeo::{
    CURVATURE_NUDGE, Curvature, CurvatureValues, FundamentalForms, NORMAL_NUDGE,
    SurfaceDerivatives, rational_derivatives,
};
use super::error::{GeometryError, Location};
use super::ops::{self, Polygon};

mod grid;
mod patches;
pub use patches::{DerivativeBounds, ScatteredEvaluator, interpolation_error};

/// A parameter direction of a surface.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Direction {
    U,
    V,
}

impl Direction {
    pub fn index(self) -> usize {
        match self {
            Direction::U => 0,
            Direction::V => 1,
        }
    }

    fn name(self) -> &'static str {
        match self {
            Direction::U => "u",
            Direction::V => "v",
        }
    }
}

/// A NURBS surface of degree (p, q) with (n + 1) × (m + 1) control points.
#[derive(Debug, Clone, PartialEq)]
pub struct NurbsSurface {
    degree: [usize; 2],
    knots: [Vec<f64>; 2],
    count: [usize; 2],
    points: Vec<DVec4>,
}

/// Everything the kernel knows about one surface point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LocalGeometry {
    pub derivatives: SurfaceDerivatives,
    /// The unit normal, from the limit rule where the tangent plane degenerates.
    pub normal: DVec3,
    /// Curvatures; at a degenerate point they are the limit sampled just inside the domain.
    pub curvature: Curvature,
    /// False where |Su × Sv| vanishes (a pole or collapsed edge).
    pub regular: bool,
}

/// The result of [`NurbsSurface::closest_point`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClosestPoint {
    pub u: f64,
    pub v: f64,
    pub point: DVec3,
    pub distance: f64,
}

/// A position and unit normal, the output of grid tessellation.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct GridSample {
    pub point: DVec3,
    pub normal: DVec3,
}

/// Basis functions (value and derivatives) at a list of parameters, computed once and reused for
/// every row or column of a grid.
struct ParameterBasis {
    spans: Vec<usize>,
    /// Per parameter, (order + 1)(p + 1) values: `values[t * stride + k * (p + 1) + j]`.
    values: Vec<f64>,
    stride: usize,
}

impl ParameterBasis {
    fn new(knots: &[f64], degree: usize, count: usize, params: &[f64], order: usize) -> Self {
        let stride = (order + 1) * (degree + 1);
        let mut values = vec![0.0; stride * params.len()];
        let spans = params
            .iter()
            .zip(values.chunks_mut(stride))
            .map(|(&t, out)| {
                let span = find_span(knots, degree, count, t);
                basis_derivatives_into(knots, degree, span, t, order, out);
                span
            })
            .collect();
        Self {
            spans,
            values,
            stride,
        }
    }

    fn at(&self, t: usize, k: usize, size: usize) -> &[f64] {
        let start = t * self.stride + k * size;
        &self.values[start..start + size]
    }
}

/// Orders (degree + 1) below this are evaluated with scratch space on the stack of this size.
const SMALL_ORDER: usize = 8;

impl NurbsSurface {
    /// A surface from Cartesian control points (row-major, i along u) and optional weights
    /// (`None`: all 1). `count` = [points along u, points along v].
    pub fn new(
        degree: [usize; 2],
        knots: [Vec<f64>; 2],
        count: [usize; 2],
        points: Vec<DVec3>,
        weights: Option<Vec<f64>>,
    ) -> Result<Self, GeometryError> {
        let weights = super::curve::weights_or_ones(points.len(), weights)?;
        check_count(count, points.len())?;
        for (index, (p, &w)) in points.iter().zip(&weights).enumerate() {
            let (i, j) = (index / count[1], index % count[1]);
            check_point(|| Location::grid_point(i, j), &p.to_array(), w)?;
        }
        let homogeneous = points
            .iter()
            .zip(&weights)
            .map(|(&p, &w)| (p * w).extend(w))
            .collect();
        Self::from_homogeneous(degree, knots, count, homogeneous)
    }

    /// A surface from homogeneous control points (w·x, w·y, w·z, w), validated.
    pub fn from_homogeneous(
        degree: [usize; 2],
        knots: [Vec<f64>; 2],
        count: [usize; 2],
        points: Vec<DVec4>,
    ) -> Result<Self, GeometryError> {
        validate_knots("knots[0]", degree[0], count[0], &knots[0])?;
        validate_knots("knots[1]", degree[1], count[1], &knots[1])?;
        check_count(count, points.len())?;
        for (index, h) in points.iter().enumerate() {
            let (i, j) = (index / count[1], index % count[1]);
            check_point(|| Location::grid_point(i, j), &h.to_array()[..3], h.w)?;
        }
        Ok(Self {
            degree,
            knots,
            count,
            points,
        })
    }

    /// A single rational Bézier patch over [0, 1]² (`points` row-major with i along u).
    pub fn bezier(
        degree: [usize; 2],
        points: Vec<DVec3>,
        weights: Option<Vec<f64>>,
    ) -> Result<Self, GeometryError> {
        let knots = degree.map(|p| {
            let mut k = vec![0.0; p + 1];
            k.extend(std::iter::repeat_n(1.0, p + 1));
            k
        });
        Self::new(degree, knots, degree.map(|p| p + 1), points, weights)
    }

    /// Degrees (p, q).
    pub fn degree(&self) -> [usize; 2] {
        self.degree
    }

    /// Knot vectors (u, v).
    pub fn knots(&self) -> [&[f64]; 2] {
        [&self.knots[0], &self.knots[1]]
    }

    /// Control point counts (along u, along v).
    pub fn count(&self) -> [usize; 2] {
        self.count
    }

    /// All homogeneous control points, row-major with i along u.
    pub fn homogeneous_points(&self) -> &[DVec4] {
        &self.points
    }

    /// The Cartesian control point (i, j).
    pub fn control_point(&self, i: usize, j: usize) -> DVec3 {
        let h = self.points[i * self.count[1] + j];
        h.truncate() / h.w
    }

    pub fn weight(&self, i: usize, j: usize) -> f64 {
        self.points[i * self.count[1] + j].w
    }

    /// True if every weight is 1.
    pub fn is_polynomial(&self) -> bool {
        self.points.iter().all(|h| h.w == 1.0)
    }

    /// The parameter domains ([u_p, u_{n+1}], [v_q, v_{m+1}]).
    pub fn domain(&self) -> [(f64, f64); 2] {
        [0, 1].map(|d| domain(&self.knots[d], self.degree[d], self.count[d]))
    }

    /// The plane the surface lies in, when every control point lies within `tolerance` of
    /// the tangent plane at the middle of the domain (then the whole surface does, by the
    /// convex hull property): that point and the unit normal there.
    pub fn plane(&self, tolerance: f64) -> Option<(DVec3, DVec3)> {
        let [(u0, u1), (v0, v1)] = self.domain();
        let d = self.evaluate(0.5 * (u0 + u1), 0.5 * (v0 + v1)).ok()?;
        let normal = d.regular_normal()?;
        let [n, m] = self.count;
        let flat = (0..n)
            .flat_map(|i| (0..m).map(move |j| (i, j)))
            .all(|(i, j)| (self.control_point(i, j) - d.point).dot(normal).abs() <= tolerance);
        flat.then_some((d.point, normal))
    }

    /// The axis-aligned box of the control points, which contains the surface (convex hull).
    pub fn bounds(&self) -> (DVec3, DVec3) {
        let first = self.control_point(0, 0);
        (0..self.count[0])
            .flat_map(|i| (0..self.count[1]).map(move |j| (i, j)))
            .map(|(i, j)| self.control_point(i, j))
            .fold((first, first), |(lo, hi), p| (lo.min(p), hi.max(p)))
    }

    /// The length of the bounding box diagonal (a scale for tolerances).
    pub fn size(&self) -> f64 {
        let (lo, hi) = self.bounds();
        (hi - lo).length()
    }

    /// Moves control point (i, j) to `position`, keeping its weight. Rejects a non-finite
    /// position or an index out of range and leaves the surface unchanged.
    pub fn set_point(&mut self, i: usize, j: usize, position: DVec3) -> Result<(), GeometryError> {
        let index = self.index_checked(i, j)?;
        let w = self.points[index].w;
        check_point(|| Location::grid_point(i, j), &position.to_array(), w)?;
        self.points[index] = (position * w).extend(w);
        Ok(())
    }

    /// Sets the weight of control point (i, j), keeping its Cartesian position. Rejects a
    /// weight that is not finite and > 0.
    pub fn set_weight(&mut self, i: usize, j: usize, weight: f64) -> Result<(), GeometryError> {
        let index = self.index_checked(i, j)?;
        let p = self.control_point(i, j);
        check_point(|| Location::grid_point(i, j), &p.to_array(), weight)?;
        self.points[index] = (p * weight).extend(weight);
        Ok(())
    }

    fn index_checked(&self, i: usize, j: usize) -> Result<usize, GeometryError> {
        if i < self.count[0] && j < self.count[1] {
            Ok(i * self.count[1] + j)
        } else {
            Err(GeometryError::NoSuchPoint {
                index: i * self.count[1] + j,
                count: self.points.len(),
            })
        }
    }

    fn check_parameters(&self, u: f64, v: f64) -> Result<(), GeometryError> {
        self.check_grid(&[u], &[v])
    }

    /// Position and all partial derivatives up to order 2 at (u, v) (The NURBS Book, A3.6 for
    /// the homogeneous derivatives A_kl, then eq. 4.20 / A4.4 for the rational ones).
    pub fn evaluate(&self, u: f64, v: f64) -> Result<SurfaceDerivatives, GeometryError> {
        self.check_parameters(u, v)?;
        Ok(rational_derivatives(&self.homogeneous_derivatives(u, v)))
    }

    /// The isoparametric curve `direction` = `value` (order 0), or for a non-rational surface
    /// the curve of its `order`-th partial derivative across it (order 1: ∂S/∂u along u = value
    /// for [`Direction::U`]): the control points of each row across `direction` blended by the
    /// basis functions (or their derivatives, A2.3) at `value`. Exact; the curve runs along the
    /// other direction with its degree and knots.
    pub fn isocurve(
        &self,
        direction: Direction,
        value: f64,
        order: usize,
    ) -> Result<SpaceCurve, GeometryError> {
        let d = direction.index();
        let (lo, hi) = self.domain()[d];
        if !crate::basis::in_domain(value, lo, hi) {
            return Err(GeometryError::OutsideDomain {
                parameter: direction.name(),
                value,
                start: lo,
                end: hi,
            });
        }
        // Σ N_i = 1, so a non-rational surface's curves have weight 1 (exactly, not rounded).
        let polynomial = self.is_polynomial();
        if order > 0 && !polynomial {
            return Err(GeometryError::Construction {
                what: "cross derivative",
                message: "a rational surface's derivative along a curve is not a NURBS curve \
                          of this form"
                    .into(),
            });
        }
        let (p, count) = (self.degree[d], self.count[d]);
        let knots = &self.knots[d];
        let span = find_span(knots, p, count, value);
        let mut basis = vec![0.0; (order + 1) * (p + 1)];
        basis_derivatives_into(knots, p, span, value, order, &mut basis);
        let weights = &basis[order * (p + 1)..];
        let other = 1 - d;
        let at = |i: usize, j: usize| {
            let (a, b) = if d == 0 { (i, j) } else { (j, i) };
            self.points[a * self.count[1] + b]
        };
        let points: Vec<DVec4> = (0..self.count[other])
            .map(|j| {
                let mut h = DVec4::ZERO;
                for (k, &w) in weights.iter().enumerate() {
                    h += at(span - p + k, j) * w;
                }
                if polynomial {
                    h.w = 1.0;
                }
                h
            })
            .collect();
        NurbsCurve::from_homogeneous(self.degree[other], self.knots[other].clone(), points)
    }

    /// The point S(u, v).
    pub fn point_at(&self, u: f64, v: f64) -> Result<DVec3, GeometryError> {
        self.check_parameters(u, v)?;
        let a = self.homogeneous_point(u, v);
        Ok(a.truncate() / a.w)
    }

    /// The point and derivatives at (u, v) = (p.x, p.y) moved into the domain first; `None`
    /// where they cannot be evaluated.
    pub fn evaluate_clamped(&self, p: DVec2) -> Option<SurfaceDerivatives> {
        let [(u0, u1), (v0, v1)] = self.domain();
        self.evaluate(p.x.clamp(u0, u1), p.y.clamp(v0, v1)).ok()
    }

    /// The point at (u, v) = (p.x, p.y) moved into the domain first.
    pub fn point_at_clamped(&self, p: DVec2) -> Result<DVec3, GeometryError> {
        let [(u0, u1), (v0, v1)] = self.domain();
        self.point_at(p.x.clamp(u0, u1), p.y.clamp(v0, v1))
    }

    /// A(u, v) = Σ_r Σ_s N_r(u) N_s(v) P^w_rs, the homogeneous point alone (The NURBS Book,
    /// A4.3 "SurfacePoint" without the division): the basis functions by A2.2, each row of
    /// control points blended in u first, as [`Self::homogeneous_derivatives`] does, so the
    /// point is the same to the bit as [`Self::evaluate`]'s. Nothing is allocated.
    fn homogeneous_point(&self, u: f64, v: f64) -> DVec4 {
        if self.degree[0].max(self.degree[1]) < SMALL_ORDER {
            self.homogeneous_point_in::<SMALL_ORDER>(u, v)
        } else {
            self.homogeneous_point_in::<{ MAX_DEGREE + 1 }>(u, v)
        }
    }

    /// [`Self::homogeneous_point`] with scratch space for degrees below `CAP`.
    fn homogeneous_point_in<const CAP: usize>(&self, u: f64, v: f64) -> DVec4 {
        let [p, q] = self.degree;
        let su = find_span(&self.knots[0], p, self.count[0], u);
        let sv = find_span(&self.knots[1], q, self.count[1], v);
        let mut nu = [0.0; CAP];
        let mut nv = [0.0; CAP];
        basis_functions(&self.knots[0], p, su, u, &mut nu[..=p]);
        basis_functions(&self.knots[1], q, sv, v, &mut nv[..=q]);
        let mut sum = DVec4::ZERO;
        for (s, &b) in nv.iter().enumerate().take(q + 1) {
            let t = nu
                .iter()
                .enumerate()
                .take(p + 1)
                .fold(DVec4::ZERO, |acc, (r, &a)| {
                    acc + self.points[(su - p + r) * self.count[1] + sv - q + s] * a
                });
            sum += t * b;
        }
        sum
    }

    /// A_kl = ∂^{k+l} A / ∂u^k ∂v^l for k + l ≤ 2 of the homogeneous surface (A3.6).
    fn homogeneous_derivatives(&self, u: f64, v: f64) -> [[DVec4; 3]; 3] {
        self.homogeneous_derivatives_to::<2>(u, v)
    }

    /// A_kl for k + l ≤ `ORDER` (1 or 2; the others zero), the same numbers to the bit
    /// whatever the order (A2.3's first derivatives do not depend on how many it computes).
    fn homogeneous_derivatives_to<const ORDER: usize>(&self, u: f64, v: f64) -> [[DVec4; 3]; 3] {
        const LARGE: usize = MAX_DEGREE + 1;
        if self.degree[0].max(self.degree[1]) < SMALL_ORDER {
            self.homogeneous_derivatives_in::<ORDER, SMALL_ORDER, { 3 * SMALL_ORDER }>(u, v)
        } else {
            self.homogeneous_derivatives_in::<ORDER, LARGE, { 3 * LARGE }>(u, v)
        }
    }

    /// [`Self::homogeneous_derivatives_to`] with scratch space for degrees below `CAP`
    /// (`CAP3` = 3 `CAP`): zeroing scratch sized for the largest degree took longer than the
    /// sums themselves.
    fn homogeneous_derivatives_in<const ORDER: usize, const CAP: usize, const CAP3: usize>(
        &self,
        u: f64,
        v: f64,
    ) -> [[DVec4; 3]; 3] {
        let [p, q] = self.degree;
        let su = find_span(&self.knots[0], p, self.count[0], u);
        let sv = find_span(&self.knots[1], q, self.count[1], v);
        let mut nu = [0.0; CAP3];
        let mut nv = [0.0; CAP3];
        let (rows_u, rows_v) = ((ORDER + 1) * (p + 1), (ORDER + 1) * (q + 1));
        basis_derivatives_into(&self.knots[0], p, su, u, ORDER, &mut nu[..rows_u]);
        basis_derivatives_into(&self.knots[1], q, sv, v, ORDER, &mut nv[..rows_v]);
        let mut skl = [[DVec4::ZERO; 3]; 3];
        let mut temp = [DVec4::ZERO; CAP];
        for k in 0..=ORDER {
            let bu = &nu[k * (p + 1)..(k + 1) * (p + 1)];
            for (s, t) in temp.iter_mut().enumerate().take(q + 1) {
                *t = bu.iter().enumerate().fold(DVec4::ZERO, |acc, (r, &b)| {
                    acc + self.points[(su - p + r) * self.count[1] + sv - q + s] * b
                });
            }
            for l in 0..=ORDER - k {
                let bv = &nv[l * (q + 1)..(l + 1) * (q + 1)];
                skl[k][l] = bv
                    .iter()
                    .zip(&temp)
                    .fold(DVec4::ZERO, |acc, (&b, &t)| acc + t * b);
            }
        }
        skl
    }

    /// (u, v) mapped to [0, 1]² over the domain, for the side tests of the normal rule.
    fn normalized(&self, u: f64, v: f64) -> (f64, f64) {
        let [(u0, u1), (v0, v1)] = self.domain();
        ((u - u0) / (u1 - u0), (v - v0) / (v1 - v0))
    }

    /// (u, v) moved toward the domain centre by `fraction` of the distance.
    fn nudged(&self, u: f64, v: f64, fraction: f64) -> (f64, f64) {
        let [(u0, u1), (v0, v1)] = self.domain();
        (
            u + (0.5 * (u0 + u1) - u) * fraction,
            v + (0.5 * (v0 + v1) - v) * fraction,
        )
    }

    /// The unit normal for derivatives `d` already evaluated at (u, v), defined everywhere:
    /// Su × Sv where regular; at a collapsed edge or pole the limit from the interior
    /// ([`SurfaceDerivatives::collapsed_edge_normal`]); failing that the regular normal a little
    /// inside the domain ([`NORMAL_NUDGE`]); +z as the last resort. Never NaN.
    pub fn normal_from(&self, d: &SurfaceDerivatives, u: f64, v: f64) -> DVec3 {
        let (s, t) = self.normalized(u, v);
        if let Some(n) = d.regular_normal().or_else(|| d.collapsed_edge_normal(s, t)) {
            return n;
        }
        let (un, vn) = self.nudged(u, v, NORMAL_NUDGE);
        let nudged = rational_derivatives(&self.homogeneous_derivatives(un, vn));
        let (s, t) = self.normalized(un, vn);
        nudged
            .regular_normal()
            .or_else(|| nudged.collapsed_edge_normal(s, t))
            .unwrap_or(DVec3::Z)
    }

    /// The unit normal at (u, v) (see [`Self::normal_from`]). Where the tangent plane is
    /// regular the first derivatives suffice (the same S_u and S_v to the bit as
    /// [`Self::evaluate`]'s); elsewhere the limit rules take the second ones too.
    pub fn normal(&self, u: f64, v: f64) -> Result<DVec3, GeometryError> {
        self.check_parameters(u, v)?;
        let first = rational_derivatives(&self.homogeneous_derivatives_to::<1>(u, v));
        if let Some(n) = first.regular_normal() {
            return Ok(n);
        }
        let d = self.evaluate(u, v)?;
        Ok(self.normal_from(&d, u, v))
    }

    /// Derivatives, normal, fundamental forms and curvatures at (u, v). At a degenerate point
    /// the curvatures are the limit, sampled [`CURVATURE_NUDGE`] of the way toward the centre.
    pub fn local_geometry(&self, u: f64, v: f64) -> Result<LocalGeometry, GeometryError> {
        let derivatives = self.evaluate(u, v)?;
        let normal = self.normal_from(&derivatives, u, v);
        let regular = derivatives.regular_normal().is_some();
        let curvature = self.curvature_from(&derivatives, normal, u, v);
        Ok(LocalGeometry {
            derivatives,
            normal,
            curvature,
            regular,
        })
    }

    fn curvature_from(&self, d: &SurfaceDerivatives, normal: DVec3, u: f64, v: f64) -> Curvature {
        if d.regular_normal().is_some()
            && let Some(c) = Curvature::from_forms(d, &FundamentalForms::new(d, normal))
        {
            return c;
        }
        let (un, vn) = self.nudged(u, v, CURVATURE_NUDGE);
        let nd = rational_derivatives(&self.homogeneous_derivatives(un, vn));
        let nn = self.normal_from(&nd, un, vn);
        // Keep the orientation of the limit normal at the point itself.
        let nn = if nn.dot(normal) < 0.0 { -nn } else { nn };
        Curvature::from_forms(&nd, &FundamentalForms::new(&nd, nn)).unwrap_or(Curvature {
            gaussian: 0.0,
            mean: 0.0,
            k1: 0.0,
            k2: 0.0,
            directions: None,
        })
    }

    /// Evaluates a grid of parameters (`us` × `vs`, each inside the domain), calling
    /// `f(i, j, derivatives)` for every (us[i], vs[j]). Basis functions are computed once per
    /// grid column and row; for each u the control net is first reduced to the isoparametric
    /// curve's homogeneous points (and their u-derivatives), so each grid point costs only a
    /// (q + 1)-term sum per derivative. `second_order = false` skips Suu, Suv, Svv (left zero).
    pub fn evaluate_grid(
        &self,
        us: &[f64],
        vs: &[f64],
        second_order: bool,
        f: impl FnMut(usize, usize, &SurfaceDerivatives),
    ) -> Result<(), GeometryError> {
        self.check_grid(us, vs)?;
        self.evaluate_grid_unchecked(us, vs, second_order, f);
        Ok(())
    }

    /// [`Self::evaluate_grid`] for parameters already checked against the domain.
    fn evaluate_grid_unchecked(
        &self,
        us: &[f64],
        vs: &[f64],
        second_order: bool,
        mut f: impl FnMut(usize, usize, &SurfaceDerivatives),
    ) {
        let [p, q] = self.degree;
        let order = if second_order { 2 } else { 1 };
        let basis_u = ParameterBasis::new(&self.knots[0], p, self.count[0], us, order);
        let basis_v = ParameterBasis::new(&self.knots[1], q, self.count[1], vs, order);
        let cv = self.count[1];
        // iso[k][j]: ∂^k/∂u^k of the homogeneous isoparametric curve's control point j.
        let mut iso = vec![vec![DVec4::ZERO; cv]; order + 1];
        for (i, &span_u) in basis_u.spans.iter().enumerate() {
            for (k, row) in iso.iter_mut().enumerate() {
                let bu = basis_u.at(i, k, p + 1);
                for (j, out) in row.iter_mut().enumerate() {
                    let mut acc = DVec4::ZERO;
                    for (r, &b) in bu.iter().enumerate() {
                        acc += self.points[(span_u - p + r) * cv + j] * b;
                    }
                    *out = acc;
                }
            }
            for (jv, &span_v) in basis_v.spans.iter().enumerate() {
                let first = span_v - q;
                let sum = |k: usize, l: usize| {
                    let bv = basis_v.at(jv, l, q + 1);
                    let pts = &iso[k][first..first + q + 1];
                    let mut acc = DVec4::ZERO;
                    for (&b, &h) in bv.iter().zip(pts) {
                        acc += h * b;
                    }
                    acc
                };
                let zero = DVec4::ZERO;
                let a = if second_order {
                    [
                        [sum(0, 0), sum(0, 1), sum(0, 2)],
                        [sum(1, 0), sum(1, 1), zero],
                        [sum(2, 0), zero, zero],
                    ]
                } else {
                    [
                        [sum(0, 0), sum(0, 1), zero],
                        [sum(1, 0), zero, zero],
                        [zero; 3],
                    ]
                };
                f(i, jv, &rational_derivatives(&a));
            }
        }
    }

    /// Positions only on the grid `us` × `vs`, row-major with i along u: the point of
    /// [`Self::evaluate_grid`] without its derivatives. Per row of the grid the homogeneous
    /// isoparametric curve is formed once (The NURBS Book, A4.3 split into its two sums: first
    /// along u, then along v), so a point costs q + 1 four-vector products and one division.
    pub fn point_grid(&self, us: &[f64], vs: &[f64]) -> Result<Vec<DVec3>, GeometryError> {
        self.check_grid(us, vs)?;
        let [p, q] = self.degree;
        let cv = self.count[1];
        let basis_u = ParameterBasis::new(&self.knots[0], p, self.count[0], us, 0);
        let basis_v = ParameterBasis::new(&self.knots[1], q, cv, vs, 0);
        let mut out = Vec::with_capacity(us.len() * vs.len());
        let mut iso = vec![DVec4::ZERO; cv];
        for (i, &span_u) in basis_u.spans.iter().enumerate() {
            let bu = basis_u.at(i, 0, p + 1);
            let rows = &self.points[(span_u - p) * cv..(span_u + 1) * cv];
            for (j, point) in iso.iter_mut().enumerate() {
                *point = bu
                    .iter()
                    .zip(rows.chunks_exact(cv))
                    .fold(DVec4::ZERO, |acc, (&b, row)| acc + row[j] * b);
            }
            for (jv, &span_v) in basis_v.spans.iter().enumerate() {
                let bv = basis_v.at(jv, 0, q + 1);
                let h = bv
                    .iter()
                    .zip(&iso[span_v - q..=span_v])
                    .fold(DVec4::ZERO, |acc, (&b, &h)| acc + h * b);
                out.push(h.truncate() / h.w);
            }
        }
        Ok(out)
    }

    /// Positions and unit normals on the grid `us` × `vs`, row-major with i along u.
    ///
    /// The fast path of [`Self::evaluate_grid`] for tessellation: v-degrees up to 5 run a loop
    /// specialized to the degree, and the normal is taken from the homogeneous derivatives,
    /// n ∥ (w A_u − w_u A) × (w A_v − w_v A) (= w⁴ Su × Sv, eq. 4.20 without the divisions).
    /// Degenerate points fall back to the limit rule of [`Self::normal_from`].
    pub fn tessellate_grid(
        &self,
        us: &[f64],
        vs: &[f64],
    ) -> Result<Vec<GridSample>, GeometryError> {
        let mut out = Vec::new();
        self.tessellate_grid_into(us, vs, &mut out)?;
        Ok(out)
    }

    /// [`Self::tessellate_grid`] into a caller's buffer (cleared first), so repeated
    /// tessellation — every frame of a drag — reuses one allocation.
    pub fn tessellate_grid_into(
        &self,
        us: &[f64],
        vs: &[f64],
        out: &mut Vec<GridSample>,
    ) -> Result<(), GeometryError> {
        out.clear();
        out.reserve(us.len() * vs.len());
        self.check_grid(us, vs)?;
        if !self.grid_specialized(us, vs, out) {
            self.evaluate_grid_unchecked(us, vs, false, |i, j, d| {
                out.push(GridSample {
                    point: d.point,
                    normal: self.normal_from(d, us[i], vs[j]),
                });
            });
        }
        Ok(())
    }

    /// Positions, normals and curvatures (K, H, k1, k2) on the grid `us` × `vs`, row-major with
    /// i along u. Specialized like [`Self::tessellate_grid`]; degenerate points get the limit
    /// curvature of [`Self::local_geometry`].
    pub fn curvature_grid(
        &self,
        us: &[f64],
        vs: &[f64],
    ) -> Result<Vec<(GridSample, CurvatureValues)>, GeometryError> {
        let mut out = Vec::new();
        self.curvature_grid_into(us, vs, &mut out)?;
        Ok(out)
    }

    /// [`Self::curvature_grid`] into a caller's buffer (cleared first).
    pub fn curvature_grid_into(
        &self,
        us: &[f64],
        vs: &[f64],
        out: &mut Vec<(GridSample, CurvatureValues)>,
    ) -> Result<(), GeometryError> {
        out.clear();
        out.reserve(us.len() * vs.len());
        self.check_grid(us, vs)?;
        if !self.grid_specialized(us, vs, out) {
            self.evaluate_grid_unchecked(us, vs, true, |i, j, d| {
                let normal = self.normal_from(d, us[i], vs[j]);
                let curvature = self.curvature_from(d, normal, us[i], vs[j]);
                out.push((
                    GridSample {
                        point: d.point,
                        normal,
                    },
                    curvature.values(),
                ));
            });
        }
        Ok(())
    }

    fn check_grid(&self, us: &[f64], vs: &[f64]) -> Result<(), GeometryError> {
        let [(u0, u1), (v0, v1)] = self.domain();
        for (values, parameter, start, end) in [(us, "u", u0, u1), (vs, "v", v0, v1)] {
            if let Some(&value) = values
                .iter()
                .find(|&&t| !crate::basis::in_domain(t, start, end))
            {
                return Err(GeometryError::OutsideDomain {
                    parameter,
                    value,
                    start,
                    end,
                });
            }
        }
        Ok(())
    }

    /// Runs [`Self::grid_lanes`] for v-degrees 1 to 5, appending to `out`; false (nothing
    /// done) for higher ones.
    fn grid_specialized<T: grid::GridOutput>(
        &self,
        us: &[f64],
        vs: &[f64],
        out: &mut Vec<T>,
    ) -> bool {
        match self.degree[1] {
            1 => self.grid_lanes::<2, T>(us, vs, out),
            2 => self.grid_lanes::<3, T>(us, vs, out),
            3 => self.grid_lanes::<4, T>(us, vs, out),
            4 => self.grid_lanes::<5, T>(us, vs, out),
            5 => self.grid_lanes::<6, T>(us, vs, out),
            _ => return false,
        }
        true
    }

    /// `segments + 1` parameters per Bézier span of `direction`, spans' ends shared: the
    /// tessellation parameters a GPU patch evaluator uses.
    pub fn span_parameters(&self, direction: Direction, segments: usize) -> Vec<f64> {
        let d = direction.index();
        let breaks = ops::distinct_breaks(&self.knots[d], self.degree[d], self.count[d]);
        let segments = segments.max(1);
        let mut params = vec![breaks[0]];
        for w in breaks.windows(2) {
            for s in 1..=segments {
                let t = s as f64 / segments as f64;
                params.push(if s == segments {
                    w[1]
                } else {
                    w[0] + (w[1] - w[0]) * t
                });
            }
        }
        params
    }

    // ----- operations ---------------------------------------------------------------------

    /// The control polygon along `direction` through row/column `index` of the other direction.
    fn polygon(&self, direction: Direction, index: usize) -> Polygon<DVec4> {
        let d = direction.index();
        let points = match direction {
            Direction::U => (0..self.count[0])
                .map(|i| self.points[i * self.count[1] + index])
                .collect(),
            Direction::V => {
                self.points[index * self.count[1]..(index + 1) * self.count[1]].to_vec()
            }
        };
        Polygon {
            degree: self.degree[d],
            knots: self.knots[d].clone(),
            points,
        }
    }

    /// Applies a polygon operation to every row (or column) along `direction`; all results
    /// share one knot vector because the operation sees the same knots each time (The NURBS
    /// Book's surface algorithms A5.3, A5.5, A5.7, A5.10 work this way).
    fn map_direction(
        &self,
        direction: Direction,
        mut op: impl FnMut(&Polygon<DVec4>) -> Polygon<DVec4>,
    ) -> Self {
        let d = direction.index();
        let other = self.count[1 - d];
        let results: Vec<Polygon<DVec4>> = (0..other)
            .map(|k| op(&self.polygon(direction, k)))
            .collect();
        let first = &results[0];
        let along = first.points.len();
        let mut count = self.count;
        count[d] = along;
        let mut degree = self.degree;
        degree[d] = first.degree;
        let mut knots = self.knots.clone();
        knots[d] = first.knots.clone();
        let mut points = vec![DVec4::ZERO; along * other];
        for (k, poly) in results.iter().enumerate() {
            for (t, &h) in poly.points.iter().enumerate() {
                let index = match direction {
                    Direction::U => t * other + k,
                    Direction::V => k * along + t,
                };
                points[index] = h;
            }
        }
        let surface = Self {
            degree,
            knots,
            count,
            points,
        };
        debug_assert!(
            Self::from_homogeneous(
                surface.degree,
                surface.knots.clone(),
                surface.count,
                surface.points.clone()
            )
            .is_ok()
        );
        surface
    }

    /// The same surface with knot `value` inserted `times` times in `direction` (A5.3).
    pub fn insert_knot(
        &self,
        direction: Direction,
        value: f64,
        times: usize,
    ) -> Result<Self, GeometryError> {
        let d = direction.index();
        check_interior(self.domain()[d], value, direction.name())?;
        check_insertion(&self.polygon(direction, 0), value, times)?;
        Ok(self.map_direction(direction, |poly| ops::insert_knot(poly, value, times)))
    }

    /// The same surface with all knots of `knots` inserted in `direction` (A5.5).
    pub fn refine(&self, direction: Direction, knots: &[f64]) -> Result<Self, GeometryError> {
        let mut x = knots.to_vec();
        check_refinement(&self.polygon(direction, 0), &mut x, direction.name())?;
        Ok(self.map_direction(direction, |poly| ops::refine_knots(poly, &x)))
    }

    /// The same surface with its degree in `direction` raised by `times` (A5.10).
    pub fn elevate_degree(
        &self,
        direction: Direction,
        times: usize,
    ) -> Result<Self, GeometryError> {
        let degree = self.degree[direction.index()] + times;
        if degree > MAX_DEGREE {
            return Err(GeometryError::Degree {
                at: Location::field("degree").index(direction.index()),
                degree,
                max: MAX_DEGREE,
            });
        }
        Ok(self.map_direction(direction, |poly| ops::elevate_degree(poly, times)))
    }

    /// The two surfaces on either side of the isoparametric curve `direction` = `value`.
    pub fn split(&self, direction: Direction, value: f64) -> Result<(Self, Self), GeometryError> {
        check_interior(self.domain()[direction.index()], value, direction.name())?;
        let left = self.map_direction(direction, |poly| ops::split(poly, value).0);
        let right = self.map_direction(direction, |poly| ops::split(poly, value).1);
        Ok((left, right))
    }

    /// The same surface, closed in `direction` (its first and last control rows there
    /// coincide within `tolerance`, as they do on a clamped closed or periodic B-spline),
    /// with its seam moved to `value` ([`ops::moved_seam`] along every row: split there, the
    /// part after `value` first, then the part before it shifted by the period, joined at
    /// the old seam by a knot of multiplicity p, C0 in the parameter and the shape as it
    /// was). The domain becomes [value, value + period]: the point at u is the old point at
    /// u, or at u − period past the old end. The second part's weights are scaled by one
    /// factor (the same shape) so that its first row meets the first part's last row in
    /// homogeneous coordinates; a surface whose seam rows are not in one ratio is refused.
    pub fn moved_seam(
        &self,
        direction: Direction,
        value: f64,
        tolerance: f64,
    ) -> Result<Self, GeometryError> {
        let what = "move the seam";
        let d = direction.index();
        check_interior(self.domain()[d], value, direction.name())?;
        let other = self.count[1 - d];
        let mut ratio: Option<f64> = None;
        // Each row's ends, which the seam joins (the part after `value` ends at the last,
        // the part before it starts at the first).
        for k in 0..other {
            let row = self.polygon(direction, k);
            let a = *row.points.last().unwrap_or(&DVec4::ONE);
            let b = *row.points.first().unwrap_or(&DVec4::ONE);
            let gap = (a.truncate() / a.w).distance(b.truncate() / b.w);
            if !(gap <= tolerance) {
                return Err(GeometryError::Construction {
                    what,
                    message: format!(
                        "the surface is not closed in {}: row {k} is {gap:.3e} apart at its seam",
                        direction.name()
                    ),
                });
            }
            let r = a.w / b.w;
            match ratio {
                Some(q) if ((r - q) / q).abs() > 1e-9 => {
                    return Err(GeometryError::Construction {
                        what,
                        message: "the weights at the seam are not in one ratio".into(),
                    });
                }
                _ => ratio = Some(r),
            }
        }
        let scale = ratio.unwrap_or(1.0);
        Ok(self.map_direction(direction, |poly| ops::moved_seam(poly, value, scale)))
    }

    /// The same surface with `direction` reversed (the normal flips).
    pub fn reverse(&self, direction: Direction) -> Self {
        self.map_direction(direction, ops::reverse)
    }

    /// The same surface over clamped knot vectors in both directions.
    pub fn clamped(&self) -> Self {
        self.map_direction(Direction::U, ops::clamp)
            .map_direction(Direction::V, ops::clamp)
    }

    /// The same surface with u and v exchanged (the normal flips).
    pub fn swap_uv(&self) -> Self {
        let [cu, cv] = self.count;
        let mut points = Vec::with_capacity(self.points.len());
        for j in 0..cv {
            for i in 0..cu {
                points.push(self.points[i * cv + j]);
            }
        }
        Self {
            degree: [self.degree[1], self.degree[0]],
            knots: [self.knots[1].clone(), self.knots[0].clone()],
            count: [cv, cu],
            points,
        }
    }

    /// The surface mapped by an affine transformation (applied to the control points; NURBS
    /// are affinely invariant). Fails only if the transformation produces non-finite points.
    pub fn transformed(&self, transform: &DAffine3) -> Result<Self, GeometryError> {
        let points = self
            .points
            .iter()
            .map(|h| {
                let p = transform.transform_point3(h.truncate() / h.w);
                (p * h.w).extend(h.w)
            })
            .collect();
        Self::from_homogeneous(self.degree, self.knots.clone(), self.count, points)
    }

    /// Removes the interior knot `value` of `direction` up to `times` times where every row
    /// stays within `tolerance` (a distance in model units; The NURBS Book, A5.8 applied to all
    /// rows, a removal kept only if it succeeds in each). Returns the surface and the number of
    /// knots removed.
    pub fn remove_knot(
        &self,
        direction: Direction,
        value: f64,
        times: usize,
        tolerance: f64,
    ) -> (Self, usize) {
        let tol = homogeneous_tolerance(
            tolerance,
            self.points
                .iter()
                .map(|h| (h.w, (h.truncate() / h.w).length())),
        );
        let d = direction.index();
        let mut current = self.clone();
        let mut removed = 0;
        while removed < times {
            let rows: Option<Vec<Polygon<DVec4>>> = (0..current.count[1 - d])
                .map(|k| ops::remove_knot(&current.polygon(direction, k), value, tol))
                .collect();
            let Some(rows) = rows else { break };
            let mut iter = rows.into_iter();
            current =
                current.map_direction(direction, |_| iter.next().unwrap_or_else(|| unreachable!()));
            removed += 1;
        }
        (current, removed)
    }

    /// The Bézier patches of the surface (The NURBS Book, A5.7 "DecomposeSurface", done as a
    /// refinement that raises every interior knot to full multiplicity in both directions), each
    /// with its parameter rectangle [[u0, u1], [v0, v1]], ordered with u outermost.
    pub fn bezier_patches(&self) -> Vec<(NurbsSurface, [[f64; 2]; 2])> {
        let refined = self.bezier_refined();
        let [p, q] = refined.degree;
        let bu = ops::distinct_breaks(&refined.knots[0], p, refined.count[0]);
        let bv = ops::distinct_breaks(&refined.knots[1], q, refined.count[1]);
        let mut patches = Vec::new();
        for (a, wu) in bu.windows(2).enumerate() {
            for (b, wv) in bv.windows(2).enumerate() {
                let points = refined
                    .patch_indices(a, b)
                    .map(|k| refined.points[k])
                    .collect();
                let knots = [(p, wu), (q, wv)].map(|(deg, w)| {
                    let mut k = vec![w[0]; deg + 1];
                    k.extend(std::iter::repeat_n(w[1], deg + 1));
                    k
                });
                patches.push((
                    Self {
                        degree: [p, q],
                        knots,
                        count: [p + 1, q + 1],
                        points,
                    },
                    [[wu[0], wu[1]], [wv[0], wv[1]]],
                ));
            }
        }
        patches
    }

    /// On a net refined by [`Self::bezier_refined`]: the indices of the control points of the
    /// Bézier patch of span (a, b), row-major with u outermost.
    fn patch_indices(&self, a: usize, b: usize) -> impl Iterator<Item = usize> {
        let [p, q] = self.degree;
        let cv = self.count[1];
        (0..=p).flat_map(move |i| (0..=q).map(move |j| (a * p + i) * cv + b * q + j))
    }

    /// Clamped, with every interior knot at full multiplicity: the control net is the union of
    /// the Bézier patches' nets, neighbours sharing their boundary rows.
    fn bezier_refined(&self) -> Self {
        self.map_direction(Direction::U, |poly| {
            ops::refine_to_bezier(&ops::clamp(poly))
        })
        .map_direction(Direction::V, |poly| {
            ops::refine_to_bezier(&ops::clamp(poly))
        })
    }

    /// The distinct knot values bounding the Bézier spans in `direction`: the domain's start, its
    /// interior breaks and its end. Span `a` of [`Self::bezier_patches`] and
    /// [`Self::to_bezier_patch_set`] is `[breaks[a], breaks[a + 1]]`.
    pub fn span_breaks(&self, direction: Direction) -> Vec<f64> {
        let d = direction.index();
        ops::distinct_breaks(&self.knots[d], self.degree[d], self.count[d])
    }

    /// The homogeneous control points of Bézier patch `patch` of [`Self::to_bezier_patch_set`]
    /// ((p + 1)(q + 1) of them, row-major with i along u), computed from the span's own
    /// (p + 1) × (q + 1) control points and its 2p + 2 and 2q + 2 knots alone: the local
    /// B-spline of that span refined to Bézier form (The NURBS Book A5.4/A5.6, applied to the
    /// span's knot vector). A drag uses it to re-decompose only the patches it moves; the result
    /// equals the global decomposition's up to rounding.
    pub fn bezier_patch_points(&self, patch: usize) -> Result<Vec<DVec4>, GeometryError> {
        let breaks = [
            self.span_breaks(Direction::U),
            self.span_breaks(Direction::V),
        ];
        let spans = [breaks[0].len() - 1, breaks[1].len() - 1];
        let (a, b) = (patch / spans[1].max(1), patch % spans[1].max(1));
        if a >= spans[0] {
            return Err(GeometryError::NoSuchPatch {
                patch,
                count: spans[0] * spans[1],
            });
        }
        // The knot span index of each direction's span, and its local knot vector.
        let local = |d: usize, s: usize| {
            let mid = 0.5 * (breaks[d][s] + breaks[d][s + 1]);
            let p = self.degree[d];
            let k = find_span(&self.knots[d], p, self.count[d], mid);
            (k - p, self.knots[d][k - p..=k + p + 1].to_vec())
        };
        let ((i0, ku), (j0, kv)) = (local(0, a), local(1, b));
        let [p, q] = self.degree;
        let points = (i0..=i0 + p)
            .flat_map(|i| (j0..=j0 + q).map(move |j| (i, j)))
            .map(|(i, j)| self.points[i * self.count[1] + j])
            .collect();
        let span = Self::from_homogeneous(self.degree, [ku, kv], [p + 1, q + 1], points)?;
        Ok(span.bezier_refined().points)
    }

    /// The Bézier patches (indices in the order of [`Self::to_bezier_patch_set`]) on which the
    /// basis function of control point (i, j) is non-zero, so the patches that change when that
    /// point moves. Local support (The NURBS Book, property P2.1, and its tensor-product form for
    /// surfaces): N_{i,p}(u) N_{j,q}(v) vanishes outside [u_i, u_{i+p+1}) × [v_j, v_{j+q+1}).
    pub fn patches_supported_by(&self, i: usize, j: usize) -> Vec<usize> {
        let spans = |d: usize, k: usize| -> Vec<usize> {
            let breaks = self.span_breaks(if d == 0 { Direction::U } else { Direction::V });
            let knots = &self.knots[d];
            let (lo, hi) = (knots[k], knots[k + self.degree[d] + 1]);
            breaks
                .windows(2)
                .enumerate()
                .filter(|(_, w)| w[0] < hi && w[1] > lo)
                .map(|(a, _)| a)
                .collect()
        };
        if i >= self.count[0] || j >= self.count[1] {
            return Vec::new();
        }
        let nv = self.span_breaks(Direction::V).len().saturating_sub(1);
        let (su, sv) = (spans(0, i), spans(1, j));
        su.iter()
            .flat_map(|&a| sv.iter().map(move |&b| a * nv + b))
            .collect()
    }

    /// The Bézier patches as a [`BezierPatchSet`] over one shared pool of control points
    /// (patches share their boundary points, so moving one moves both sides of the seam).
    pub fn to_bezier_patch_set(&self) -> Result<BezierPatchSet, GeometryError> {
        let refined = self.bezier_refined();
        let [p, q] = refined.degree;
        let [cu, cv] = refined.count;
        let points = refined.points.iter().map(|h| h.truncate() / h.w).collect();
        let weights = refined.points.iter().map(|h| h.w).collect();
        let mut patches = Vec::new();
        for a in 0..(cu - 1) / p {
            for b in 0..(cv - 1) / q {
                let indices = refined.patch_indices(a, b).map(|k| k as u32).collect();
                patches.push(BezierPatch::new(p, q, indices));
            }
        }
        BezierPatchSet::new(points, Some(weights), patches)
    }

    /// The closest point of the surface to `target` (point inversion, The NURBS Book §6.1):
    /// the local minima of the distance over a grid of samples (8 per Bézier span and
    /// direction, down to 1 where a direction has more than 8 spans), and the samples lowest
    /// along the domain's edges, the six nearest, each start Newton's iteration on
    /// f = Su·(S − P) = 0,
    /// g = Sv·(S − P) = 0 (eq. 6.6). Steps leaving the domain are clamped to its boundary; a
    /// step that does not reduce the distance is halved, and where no Newton step does, a
    /// steepest-descent step is tried; the nearest point found is returned.
    pub fn closest_point(&self, target: DVec3) -> Result<ClosestPoint, GeometryError> {
        if let Some(coordinate) = target.to_array().iter().position(|c| !c.is_finite()) {
            return Err(GeometryError::NonFinitePoint {
                at: Location::field("target"),
                coordinate,
            });
        }
        // 8 samples per span, fewer where there are many spans (at least one per span).
        let per_span = |d: Direction| {
            let spans = self.span_breaks(d).len().saturating_sub(1).max(1);
            (64 / spans).clamp(1, 8)
        };
        let us = self.span_parameters(Direction::U, per_span(Direction::U));
        let vs = self.span_parameters(Direction::V, per_span(Direction::V));
        let (nu, nv) = (us.len(), vs.len());
        let mut grid = vec![f64::INFINITY; nu * nv];
        self.evaluate_grid(&us, &vs, false, |i, j, d| {
            grid[i * nv + j] = d.point.distance_squared(target);
        })?;
        // Newton from the grid's local minima (up to six, nearest first): one start can
        // land in a local minimum of the distance where the surface folds. A sample on the
        // domain's edge that is lowest along that edge is a start too: the closest point can
        // be on the edge (where the distance need not be stationary) with a lower sample
        // beside it inside, whose Newton ends in an interior local minimum.
        let mut starts: Vec<(f64, usize, usize)> = Vec::new();
        for i in 0..nu {
            for j in 0..nv {
                let here = grid[i * nv + j];
                let around = |a: usize, b: usize| grid[a * nv + b] >= here;
                let (is, js) = (
                    i.saturating_sub(1)..=(i + 1).min(nu - 1),
                    j.saturating_sub(1)..=(j + 1).min(nv - 1),
                );
                let lowest = is.clone().all(|a| js.clone().all(|b| around(a, b)));
                let lowest_on_edge = ((i == 0 || i == nu - 1) && js.clone().all(|b| around(i, b)))
                    || ((j == 0 || j == nv - 1) && is.clone().all(|a| around(a, j)));
                if lowest || lowest_on_edge {
                    starts.push((here, i, j));
                }
            }
        }
        starts.sort_by(|a, b| a.0.total_cmp(&b.0));
        starts.truncate(6);
        let mut best: Option<ClosestPoint> = None;
        for &(_, i, j) in &starts {
            let found = self.newton_closest_point(target, us[i], vs[j]);
            if best.as_ref().is_none_or(|b| found.distance < b.distance) {
                best = Some(found);
            }
        }
        best.ok_or_else(|| GeometryError::Construction {
            what: "closest point",
            message: "the surface has no finite sample".into(),
        })
    }

    /// The closest point to `target` found by Newton's iteration from (u, v) alone (see
    /// [`Self::closest_point`]): for a target near a known point, such as the next sample
    /// along a curve on the surface.
    pub fn closest_point_from(&self, target: DVec3, u: f64, v: f64) -> ClosestPoint {
        self.newton_closest_point(target, u, v)
    }

    /// Newton's iteration for the closest point from (u, v) (see [`Self::closest_point`]).
    fn newton_closest_point(&self, target: DVec3, u: f64, v: f64) -> ClosestPoint {
        let [(u0, u1), (v0, v1)] = self.domain();
        let (mut u, mut v) = (u, v);
        let mut d = rational_derivatives(&self.homogeneous_derivatives(u, v));
        let mut dist = d.point.distance(target);
        for _ in 0..50 {
            let r = d.point - target;
            let f = d.su.dot(r);
            let g = d.sv.dot(r);
            let j00 = d.su.length_squared() + r.dot(d.suu);
            let j01 = d.su.dot(d.sv) + r.dot(d.suv);
            let j11 = d.sv.length_squared() + r.dot(d.svv);
            let det = j00 * j11 - j01 * j01;
            let (du, dv) = if det.abs() > 1e-300 && det.is_finite() {
                ((-f * j11 + g * j01) / det, (-g * j00 + f * j01) / det)
            } else {
                // Singular Jacobian: a gradient step scaled by the tangent lengths.
                (
                    -f / d.su.length_squared().max(1e-300),
                    -g / d.sv.length_squared().max(1e-300),
                )
            };
            // Backtracking: halve the step until the distance shrinks. Where the Newton
            // step finds no such point (an indefinite Jacobian near a tight fold), the
            // steepest-descent step scaled by the tangent lengths is tried the same way.
            let descend = |(du, dv): (f64, f64)| {
                let mut step = 1.0;
                loop {
                    let un = (u + du * step).clamp(u0, u1);
                    let vn = (v + dv * step).clamp(v0, v1);
                    let dn = rational_derivatives(&self.homogeneous_derivatives(un, vn));
                    let distn = dn.point.distance(target);
                    // Strictly closer: a step the domain's edge clamps to no move at all is
                    // no step (the steepest descent is tried next).
                    if distn < dist {
                        return Some((un, vn, dn, distn));
                    }
                    step *= 0.5;
                    if step < 1e-6 {
                        return None;
                    }
                }
            };
            let gradient = (
                -f / d.su.length_squared().max(1e-300),
                -g / d.sv.length_squared().max(1e-300),
            );
            let Some((un, vn, dn, distn)) = descend((du, dv)).or_else(|| descend(gradient)) else {
                break;
            };
            // Converged once the parameters stop moving (relative to the domain).
            let moved = (un - u).abs() / (u1 - u0) + (vn - v).abs() / (v1 - v0);
            (u, v, d, dist) = (un, vn, dn, distn);
            if moved < 1e-15 {
                break;
            }
        }
        ClosestPoint {
            u,
            v,
            point: d.point,
            distance: dist,
        }
    }
}

fn check_count(count: [usize; 2], found: usize) -> Result<(), GeometryError> {
    let expected = count[0].saturating_mul(count[1]);
    if found != expected {
        return Err(GeometryError::PointCount {
            at: Location::field("points"),
            found,
            expected,
        });
    }
    Ok(())
}
