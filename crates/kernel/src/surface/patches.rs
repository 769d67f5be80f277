//! A surface held as its Bézier patches, for evaluating many scattered points: a point is a
//! look-up of its span in each direction and a tensor product of Bernstein values, with none
//! of the knot arithmetic (and divisions) of the basis functions (A2.2) at every point. The
//! trimmed export evaluates some 70,000 scattered points a surface (the boundary's flattening,
//! the tolerance check, the boundary's vertices) this way.

use std::borrow::Cow;

use crate::par::RaceCell;

use glam::{DVec2, DVec3, DVec4};

use super::NurbsSurface;
use crate::GeometryError;
use crate::diffgeo::regular_normal_of;

/// Degrees from this one up are evaluated by the surface itself.
const ORDER_CAP: usize = 8;
/// The most homogeneous points held (32 MB); a surface with more Bézier points is evaluated by
/// itself.
const POINTS_CAP: usize = 1 << 20;

/// A surface's Bézier patches ([`NurbsSurface::bezier_patches`]'s, held flat) for scattered
/// evaluation; degrees of 8 and more, and very large nets, are evaluated by the surface.
#[derive(Debug, Clone)]
pub struct ScatteredEvaluator<'a> {
    /// Borrowed, or owned once [`ScatteredEvaluator::into_owned`] made it outlive the surface.
    surface: Cow<'a, NurbsSurface>,
    /// Empty where the surface evaluates itself.
    patches: Vec<DVec4>,
    breaks: [Vec<f64>; 2],
    /// 1 / (breaks[k + 1] − breaks[k]).
    inverse_widths: [Vec<f64>; 2],
    /// Spans over the domain's width, in each direction.
    spans_per_unit: [f64; 2],
    /// Each patch's [`DerivativeBounds`], computed when first asked for.
    bounds: Vec<RaceCell<Option<DerivativeBounds>>>,
}

/// B_{i,n}(t) for i = 0..=n (The NURBS Book, A1.3 "AllBernstein") in `out[..=n]`, and where
/// `lower` is given the degree n − 1 values in it (for derivatives).
fn all_bernstein(
    n: usize,
    t: f64,
    out: &mut [f64; ORDER_CAP],
    lower: Option<&mut [f64; ORDER_CAP]>,
) {
    let s = 1.0 - t;
    if n == 3 {
        // The cubic's, written out: most surfaces are bicubic.
        let (s2, t2) = (s * s, t * t);
        out[..4].copy_from_slice(&[s2 * s, 3.0 * t * s2, 3.0 * t2 * s, t2 * t]);
        if let Some(l) = lower {
            l[..3].copy_from_slice(&[s2, 2.0 * t * s, t2]);
        }
        return;
    }
    out[0] = 1.0;
    let mut lower = lower;
    for j in 1..=n {
        if j == n
            && let Some(l) = lower.take()
        {
            l[..n].copy_from_slice(&out[..n]);
        }
        let mut saved = 0.0;
        for slot in &mut out[..j] {
            let temp = *slot;
            *slot = saved + s * temp;
            saved = t * temp;
        }
        out[j] = saved;
    }
    if let Some(l) = lower {
        // n = 0: the derivative's basis is empty.
        l[0] = 0.0;
    }
}

/// dB_{i,n}/dt = n (B_{i−1,n−1} − B_{i,n−1}) (The NURBS Book, eq. 1.9) from the degree n − 1
/// values.
fn bernstein_derivatives(n: usize, lower: &[f64; ORDER_CAP]) -> [f64; ORDER_CAP] {
    let mut out = [0.0; ORDER_CAP];
    let scale = n as f64;
    for (i, slot) in out.iter_mut().enumerate().take(n + 1) {
        let before = if i > 0 { lower[i - 1] } else { 0.0 };
        let here = if i < n { lower[i] } else { 0.0 };
        *slot = scale * (before - here);
    }
    out
}

/// The Bernstein values and their derivatives in one direction.
type Basis<'a> = [&'a [f64; ORDER_CAP]; 2];

/// The tensor products of a p × q patch with the values and derivatives `bu`, `bv`: A =
/// Σ_i Σ_j bu_i bv_j net_ij, and where `DERIVATIVES` also A_s (eu for bu) and A_t (ev for bv),
/// each row blended in v first. Runs the AVX2 build where the CPU has it: the four coordinates
/// of a homogeneous point in one 256-bit register, a multiply and an add for each control
/// point (no fused multiply-add, so both builds give the same bits, and A is the same with or
/// without the derivatives).
fn tensor<const DERIVATIVES: bool>(
    net: &[DVec4],
    p: usize,
    q: usize,
    bu: Basis,
    bv: Basis,
) -> [DVec4; 3] {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the function only enables AVX2, which the CPU was just found to have.
        return unsafe { tensor_avx2::<DERIVATIVES>(net, p, q, bu, bv) };
    }
    tensor_body::<DERIVATIVES>(net, p, q, bu, bv)
}

/// [`tensor_body`] compiled with AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn tensor_avx2<const DERIVATIVES: bool>(
    net: &[DVec4],
    p: usize,
    q: usize,
    bu: Basis,
    bv: Basis,
) -> [DVec4; 3] {
    tensor_body::<DERIVATIVES>(net, p, q, bu, bv)
}

#[inline(always)]
fn tensor_body<const DERIVATIVES: bool>(
    net: &[DVec4],
    p: usize,
    q: usize,
    [bu, eu]: Basis,
    [bv, ev]: Basis,
) -> [DVec4; 3] {
    let (mut sum, mut sum_s, mut sum_t) = ([0.0f64; 4], [0.0f64; 4], [0.0f64; 4]);
    for i in 0..p {
        let (mut row, mut row_t) = ([0.0f64; 4], [0.0f64; 4]);
        for (j, h) in net[i * q..][..q].iter().enumerate() {
            let h = h.to_array();
            for l in 0..4 {
                row[l] += h[l] * bv[j];
                if DERIVATIVES {
                    row_t[l] += h[l] * ev[j];
                }
            }
        }
        for l in 0..4 {
            sum[l] += row[l] * bu[i];
            if DERIVATIVES {
                sum_s[l] += row[l] * eu[i];
                sum_t[l] += row_t[l] * bu[i];
            }
        }
    }
    [sum, sum_s, sum_t].map(DVec4::from_array)
}

/// Upper bounds of a surface's derivatives over a region of (u, v): |S_u| ≤ `first[0]`,
/// |S_v| ≤ `first[1]`, |S_uu| ≤ `second[0]`, |S_uv| ≤ `second[1]`, |S_vv| ≤ `second[2]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DerivativeBounds {
    pub first: [f64; 2],
    pub second: [f64; 3],
}

impl DerivativeBounds {
    /// (√(A + B), √(B + C)) for the second-derivative bounds A, B, C: since 2 |d_u d_v| is at
    /// most d_u² + d_v², |D²S(d, d)| ≤ A d_u² + 2B |d_u d_v| + C d_v² ≤ |d'|² for d scaled by
    /// it ([`interpolation_error`]).
    pub fn metric(&self) -> DVec2 {
        let [a, b, c] = self.second;
        DVec2::new((a + b).sqrt(), (b + c).sqrt())
    }

    /// The bounds over a Bézier patch with positive weights (`net`, homogeneous, row-major in
    /// u, of `degree`, its span's 1 / width in `inverse_widths`), or None where a weight is
    /// not positive. A patch's derivatives are Bézier patches of its control points'
    /// differences, times p, p(p − 1), pq, … (The NURBS Book, eq. 3.17 and its second
    /// derivatives); the Bernstein values are non-negative and sum to 1, so each derivative is
    /// at most its largest difference. Here that bounds the homogeneous patch A = (S − c) w,
    /// moved by the first control point c so that |S − c| ≤ R, the net's radius about c (S is a
    /// convex combination of the net), and w ≥ its least weight. The quotient rule (eq. 4.8,
    /// 4.20) then gives S_u = (A_u − (S − c) w_u) / w, S_uu = (A_uu − 2 S_u w_u − (S − c) w_uu)
    /// / w and S_uv = (A_uv − S_u w_v − S_v w_u − (S − c) w_uv) / w. For equal weights w's
    /// differences vanish and these are the polynomial patch's own bounds. The chain rule
    /// through the span's widths gives the (u, v) derivatives.
    fn of_patch(net: &[DVec4], [du, dv]: [usize; 2], [iu, iv]: [f64; 2]) -> Option<Self> {
        let least = net.iter().map(|h| h.w).fold(f64::INFINITY, f64::min);
        if !(least > 0.0) {
            return None;
        }
        let centre = net[0].truncate() / net[0].w;
        let radius = net
            .iter()
            .map(|h| (h.truncate() / h.w).distance_squared(centre))
            .fold(0.0f64, f64::max)
            .sqrt();
        let q = dv + 1;
        // (S − c) w with its weight.
        let at = |i: usize, j: usize| {
            let h = net[i * q + j];
            (h.truncate() - centre * h.w).extend(h.w)
        };
        // The largest squared differences of A (most) and absolute differences of w (weight):
        // along u, along v, twice along u, along both, twice along v.
        let (mut most, mut weight) = ([0.0f64; 5], [0.0f64; 5]);
        let mut keep = |k: usize, d: DVec4| {
            most[k] = most[k].max(d.truncate().length_squared());
            weight[k] = weight[k].max(d.w.abs());
        };
        for i in 0..=du {
            for j in 0..=dv {
                let here = at(i, j);
                if i < du {
                    keep(0, at(i + 1, j) - here);
                }
                if j < dv {
                    keep(1, at(i, j + 1) - here);
                }
                if i + 2 <= du {
                    keep(2, at(i + 2, j) - 2.0 * at(i + 1, j) + here);
                }
                if i < du && j < dv {
                    keep(3, at(i + 1, j + 1) - at(i + 1, j) - at(i, j + 1) + here);
                }
                if j + 2 <= dv {
                    keep(4, at(i, j + 2) - 2.0 * at(i, j + 1) + here);
                }
            }
        }
        let (p, q) = (du as f64, dv as f64);
        let factors = [
            p * iu,
            q * iv,
            p * (p - 1.0) * iu * iu,
            p * q * iu * iv,
            q * (q - 1.0) * iv * iv,
        ];
        let mut a = [0.0; 5];
        let mut w = [0.0; 5];
        for k in 0..5 {
            a[k] = factors[k] * most[k].sqrt();
            w[k] = factors[k] * weight[k];
        }
        let su = (a[0] + radius * w[0]) / least;
        let sv = (a[1] + radius * w[1]) / least;
        let bounds = Self {
            first: [su, sv],
            second: [
                (a[2] + 2.0 * su * w[0] + radius * w[2]) / least,
                (a[3] + su * w[1] + sv * w[0] + radius * w[3]) / least,
                (a[4] + 2.0 * sv * w[1] + radius * w[4]) / least,
            ],
        };
        bounds
            .first
            .iter()
            .chain(&bounds.second)
            .all(|m| m.is_finite())
            .then_some(bounds)
    }
}

/// An upper bound of |S(x) − L(x)| over the segment or triangle with corners `scaled`, where L
/// interpolates S linearly at the corners, and the corners are (u, v) points scaled by
/// [`DerivativeBounds::metric`] of bounds that hold on the segment or triangle. Taylor's
/// remainder at each corner x_i (weighted by x's barycentric λ_i, whose first-order terms
/// cancel) gives |S − L| ≤ ½ Σ λ_i |D²S(x − x_i, x − x_i)| ≤ ½ Σ λ_i |x' − x_i'|². On a
/// segment that sum is t(1 − t) |d'|² ≤ |d'|² / 4; on a triangle it is at most R² for R the
/// radius of the smallest circle about the corners (it equals Σ λ_i |x_i − c|² − |x − c|² for
/// that circle's centre c): half the longest side on a triangle that is not acute, else the
/// circumradius abc / 4K. Other counts of corners give infinity.
pub fn interpolation_error(scaled: &[DVec2]) -> f64 {
    match *scaled {
        [a, b] => 0.125 * a.distance_squared(b),
        [a, b, c] => {
            let mut sides = [
                b.distance_squared(c),
                c.distance_squared(a),
                a.distance_squared(b),
            ];
            sides.sort_by(f64::total_cmp);
            let radius_squared = if sides[2] >= sides[0] + sides[1] {
                0.25 * sides[2]
            } else {
                let twice_area = (b - a).perp_dot(c - a);
                sides[0] * sides[1] * sides[2] / (4.0 * twice_area * twice_area)
            };
            0.5 * radius_squared
        }
        _ => f64::INFINITY,
    }
}

impl NurbsSurface {
    /// This surface prepared for many scattered evaluations ([`ScatteredEvaluator`]).
    pub fn scattered_evaluator(&self) -> ScatteredEvaluator<'_> {
        let [p, q] = self.degree;
        let breaks = [
            self.span_breaks(crate::Direction::U),
            self.span_breaks(crate::Direction::V),
        ];
        let spans = (breaks[0].len() - 1) * (breaks[1].len() - 1);
        let inverse_widths = breaks
            .clone()
            .map(|b| b.windows(2).map(|w| 1.0 / (w[1] - w[0])).collect());
        let mut patches = Vec::new();
        if p.max(q) < ORDER_CAP && spans * (p + 1) * (q + 1) <= POINTS_CAP {
            let refined = self.bezier_refined();
            patches.reserve(spans * (p + 1) * (q + 1));
            for a in 0..breaks[0].len() - 1 {
                for b in 0..breaks[1].len() - 1 {
                    patches.extend(refined.patch_indices(a, b).map(|k| refined.points[k]));
                }
            }
        }
        let spans_per_unit = [0, 1].map(|d| {
            let b = &breaks[d];
            (b.len() - 1) as f64 / (b[b.len() - 1] - b[0])
        });
        let bounds = if patches.is_empty() {
            Vec::new()
        } else {
            (0..spans).map(|_| RaceCell::new()).collect()
        };
        ScatteredEvaluator {
            surface: Cow::Borrowed(self),
            bounds,
            patches,
            breaks,
            inverse_widths,
            spans_per_unit,
        }
    }
}

impl ScatteredEvaluator<'_> {
    /// The surface evaluated.
    pub fn surface(&self) -> &NurbsSurface {
        &self.surface
    }

    /// This evaluator with its own copy of the surface, so that it can outlive the surface
    /// it was made from (the patches and the bounds found so far are kept).
    pub fn into_owned(self) -> ScatteredEvaluator<'static> {
        ScatteredEvaluator {
            surface: Cow::Owned(self.surface.into_owned()),
            patches: self.patches,
            breaks: self.breaks,
            inverse_widths: self.inverse_widths,
            spans_per_unit: self.spans_per_unit,
            bounds: self.bounds,
        }
    }

    /// The span holding `x` (moved into the domain) in direction `d` and the local parameter in
    /// it, in [0, 1]; a value on a break belongs to the span after it, the domain's end to the
    /// last span (as [`crate::basis::find_span`] places it).
    fn locate(&self, d: usize, x: f64) -> (usize, f64) {
        let b = &self.breaks[d];
        let last = b.len() - 2;
        let x = x.clamp(b[0], b[last + 1]);
        // The span of evenly spaced breaks first (most surfaces' knots are), then a search.
        let guess = ((x - b[0]) * self.spans_per_unit[d]) as usize;
        let k = if guess <= last && b[guess] <= x && (x < b[guess + 1] || guess == last) {
            guess
        } else {
            b.partition_point(|&t| t <= x).saturating_sub(1).min(last)
        };
        (k, ((x - b[k]) * self.inverse_widths[d][k]).clamp(0.0, 1.0))
    }

    /// The Bézier patch holding p (moved into the domain) and the local parameters in it.
    fn patch_at(&self, p: DVec2) -> (&[DVec4], [usize; 2], f64, f64) {
        let (a, s) = self.locate(0, p.x);
        let (b, t) = self.locate(1, p.y);
        (self.net(self.patch_index(a, b)), [a, b], s, t)
    }

    /// The patch of span (a, b), in `patches` and `bounds`.
    fn patch_index(&self, a: usize, b: usize) -> usize {
        a * (self.breaks[1].len() - 1) + b
    }

    /// Patch `index`'s homogeneous control points.
    fn net(&self, index: usize) -> &[DVec4] {
        let [du, dv] = self.surface.degree;
        let size = (du + 1) * (dv + 1);
        &self.patches[index * size..][..size]
    }

    /// The homogeneous point A(u, v) at p.
    fn homogeneous(&self, p: DVec2) -> DVec4 {
        let [du, dv] = self.surface.degree;
        let (net, _, s, t) = self.patch_at(p);
        let (mut bu, mut bv) = ([0.0; ORDER_CAP], [0.0; ORDER_CAP]);
        all_bernstein(du, s, &mut bu, None);
        all_bernstein(dv, t, &mut bv, None);
        let none = [0.0; ORDER_CAP];
        tensor::<false>(net, du + 1, dv + 1, [&bu, &none], [&bv, &none])[0]
    }

    /// A, A_u and A_v at p: the derivatives from the Bernstein polynomials' (eq. 1.9), times
    /// the span's 1 / width for the chain rule.
    fn homogeneous_derivatives(&self, p: DVec2) -> [DVec4; 3] {
        let [du, dv] = self.surface.degree;
        let (net, [a, b], s, t) = self.patch_at(p);
        let (mut bu, mut bv) = ([0.0; ORDER_CAP], [0.0; ORDER_CAP]);
        let (mut lu, mut lv) = ([0.0; ORDER_CAP], [0.0; ORDER_CAP]);
        all_bernstein(du, s, &mut bu, Some(&mut lu));
        all_bernstein(dv, t, &mut bv, Some(&mut lv));
        let (eu, ev) = (
            bernstein_derivatives(du, &lu),
            bernstein_derivatives(dv, &lv),
        );
        let [sum, sum_s, sum_t] = tensor::<true>(net, du + 1, dv + 1, [&bu, &eu], [&bv, &ev]);
        [
            sum,
            sum_s * self.inverse_widths[0][a],
            sum_t * self.inverse_widths[1][b],
        ]
    }

    /// Bounds on the surface's derivatives over the box of (u, v) from `lo` to `hi`, where the
    /// box lies in one Bézier patch inside the domain; else None. Each patch's bounds are computed once
    /// ([`DerivativeBounds::of_patch`]).
    pub fn derivative_bounds(&self, lo: DVec2, hi: DVec2) -> Option<DerivativeBounds> {
        if self.patches.is_empty() || !(lo.is_finite() && hi.is_finite()) {
            return None;
        }
        let mut span = [0; 2];
        for (d, slot) in span.iter_mut().enumerate() {
            let (from, to) = (lo[d], hi[d]);
            let b = &self.breaks[d];
            if !(b[0] <= from && from <= to && to <= b[b.len() - 1]) {
                return None;
            }
            let (k, _) = self.locate(d, from);
            // A box starting on a break belongs to the span after it; one ending on a break
            // also lies in the span before it.
            let k = if from == b[k] && k > 0 && to <= b[k] {
                k - 1
            } else {
                k
            };
            if to > b[k + 1] {
                return None;
            }
            *slot = k;
        }
        let index = self.patch_index(span[0], span[1]);
        *self.bounds[index].get_or_init(|| {
            DerivativeBounds::of_patch(
                self.net(index),
                self.surface.degree,
                [
                    self.inverse_widths[0][span[0]],
                    self.inverse_widths[1][span[1]],
                ],
            )
        })
    }

    /// S(u, v) at (u, v) = p moved into the domain first (as
    /// [`NurbsSurface::point_at_clamped`], equal to it up to rounding).
    pub fn point(&self, p: DVec2) -> Result<DVec3, GeometryError> {
        if self.patches.is_empty() || !p.is_finite() {
            return self.surface.point_at_clamped(p);
        }
        let a = self.homogeneous(p);
        Ok(a.truncate() / a.w)
    }

    /// The point and unit normal at (u, v) = p moved into the domain first; where the tangent
    /// plane is degenerate (a pole, a collapsed edge) the normal is
    /// [`NurbsSurface::normal_from`]'s limit.
    pub fn point_and_normal(&self, p: DVec2) -> Result<(DVec3, DVec3), GeometryError> {
        let [(u0, u1), (v0, v1)] = self.surface.domain();
        let (u, v) = (p.x.clamp(u0, u1), p.y.clamp(v0, v1));
        if !self.patches.is_empty() && p.is_finite() {
            // S = A/w, S_u = (A_u − w_u S)/w (eq. 4.20 with first derivatives alone).
            let [a, a_u, a_v] = self.homogeneous_derivatives(DVec2::new(u, v));
            let point = a.truncate() / a.w;
            let su = (a_u.truncate() - point * a_u.w) / a.w;
            let sv = (a_v.truncate() - point * a_v.w) / a.w;
            if let Some(normal) = regular_normal_of(su, sv) {
                return Ok((point, normal));
            }
        }
        let d = self.surface.evaluate(u, v)?;
        Ok((d.point, self.surface.normal_from(&d, u, v)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::construct;
    use crate::test_support::{random_bspline_surface, uniform};

    #[test]
    fn scattered_points_and_normals_are_the_surfaces() {
        let mut state = 7;
        let sphere = construct::sphere(DVec3::new(1.0, -2.0, 0.5), 3.0).unwrap();
        let torus = construct::torus(DVec3::ZERO, DVec3::new(0.3, 0.2, 1.0), 4.0, 1.5).unwrap();
        let n = 9;
        let points = (0..n * n)
            .map(|k| {
                let (i, j) = (k / n, k % n);
                DVec3::new(i as f64, j as f64 * 1.3, uniform(&mut state) * 2.0)
            })
            .collect();
        let spline = construct::bspline_surface([3, 2], [n, n], points).unwrap();
        for surface in [&sphere, &torus, &spline] {
            let eval = surface.scattered_evaluator();
            assert!(!eval.patches.is_empty());
            let [(u0, u1), (v0, v1)] = surface.domain();
            let scale = surface.size();
            for k in 0..2000 {
                // Random points, the domain's corners and edges, and points beyond it.
                let (s, t) = (uniform(&mut state), uniform(&mut state));
                let (s, t) = match k % 10 {
                    0 => (s.round(), t),
                    1 => (s, t.round() * 1.2 - 0.1),
                    _ => (s, t),
                };
                let p = DVec2::new(u0 + s * (u1 - u0), v0 + t * (v1 - v0));
                let expected = surface.point_at_clamped(p).unwrap();
                let got = eval.point(p).unwrap();
                assert!(
                    (got - expected).length() <= 1e-13 * scale,
                    "{p}: {got} vs {expected}"
                );
                let (point, normal) = eval.point_and_normal(p).unwrap();
                let (u, v) = (p.x.clamp(u0, u1), p.y.clamp(v0, v1));
                let reference = surface.normal(u, v).unwrap();
                assert!((point - expected).length() <= 1e-13 * scale);
                assert!(
                    (normal - reference).length() <= 1e-9,
                    "{p}: {normal} vs {reference}"
                );
            }
        }
    }

    #[test]
    fn the_avx2_and_baseline_builds_agree_to_the_bit() {
        let mut state = 11;
        for (p, q) in [(4, 4), (3, 2), (2, 2), (6, 3), (1, 5)] {
            let net: Vec<DVec4> = (0..p * q)
                .map(|_| {
                    DVec4::new(
                        uniform(&mut state) * 10.0 - 5.0,
                        uniform(&mut state) * 1e3,
                        uniform(&mut state) - 0.5,
                        0.5 + uniform(&mut state),
                    )
                })
                .collect();
            let mut basis = || {
                let mut b = [0.0; ORDER_CAP];
                b.iter_mut()
                    .for_each(|x| *x = uniform(&mut state) * 3.0 - 1.0);
                b
            };
            let [bu, bv, eu, ev] = [basis(), basis(), basis(), basis()];
            let (u, v) = ([&bu, &eu], [&bv, &ev]);
            assert_eq!(
                tensor::<true>(&net, p, q, u, v),
                tensor_body::<true>(&net, p, q, u, v)
            );
            assert_eq!(
                tensor::<false>(&net, p, q, u, v),
                tensor_body::<false>(&net, p, q, u, v)
            );
            // The point is the same with or without the derivatives, to the bit.
            assert_eq!(
                tensor::<false>(&net, p, q, u, v)[0],
                tensor::<true>(&net, p, q, u, v)[0]
            );
        }
    }

    #[test]
    fn derivative_bounds_hold_over_each_patch_and_only_there() {
        let mut state = 5;
        for seed in 0..90 {
            let surface = match seed % 3 {
                0 => random_bspline_surface(&mut state, true),
                1 => construct::torus(
                    DVec3::new(uniform(&mut state), 0.0, -3.0),
                    DVec3::new(0.3, uniform(&mut state), 1.0),
                    4.0,
                    0.5 + uniform(&mut state),
                )
                .unwrap(),
                _ => random_bspline_surface(&mut state, false),
            };
            let [(du0, du1), (dv0, dv1)] = surface.domain();
            let eval = surface.scattered_evaluator();
            for _ in 0..20 {
                // A random box inside the span of a random point.
                let p = DVec2::new(
                    du0 + (du1 - du0) * uniform(&mut state),
                    dv0 + (dv1 - dv0) * uniform(&mut state),
                );
                let spans = [0, 1].map(|d| eval.locate(d, p[d]).0);
                let side = |d: usize, state: &mut u64| {
                    let b = &eval.breaks[d];
                    let (a, c) = (b[spans[d]], b[spans[d] + 1]);
                    let (x, y) = (uniform(state), uniform(state));
                    (a + (c - a) * x.min(y), a + (c - a) * x.max(y))
                };
                let ((u0, u1), (v0, v1)) = (side(0, &mut state), side(1, &mut state));
                let (lo, hi) = (DVec2::new(u0, v0), DVec2::new(u1, v1));
                let bounds = eval.derivative_bounds(lo, hi).unwrap();
                let limits = bounds.first.iter().chain(&bounds.second);
                let slack = 1e-9 * limits.fold(0.0f64, |a, &b| a.max(b));
                for _ in 0..40 {
                    let (s, t) = (uniform(&mut state), uniform(&mut state));
                    let d = surface
                        .evaluate(u0 + s * (u1 - u0), v0 + t * (v1 - v0))
                        .unwrap();
                    let values = [d.su, d.sv, d.suu, d.suv, d.svv].map(|x| x.length());
                    let limits = bounds.first.iter().chain(&bounds.second);
                    for (value, &limit) in values.iter().zip(limits) {
                        assert!(
                            value <= &(limit + slack),
                            "seed {seed}: {values:?} vs {bounds:?}"
                        );
                    }
                }
                // A box across a break has none.
                let b = &eval.breaks[0];
                if b.len() > 2 {
                    let across = DVec2::new(0.5 * (b[1] + b[2]), v1);
                    assert_eq!(eval.derivative_bounds(DVec2::new(b[0], v0), across), None);
                }
            }
        }
        // A box outside the domain has none.
        let plane = construct::bspline_surface([1, 1], [2, 2], vec![DVec3::ZERO; 4]).unwrap();
        let eval = plane.scattered_evaluator();
        assert!(eval.derivative_bounds(DVec2::ZERO, DVec2::ONE).is_some());
        assert_eq!(eval.derivative_bounds(DVec2::splat(-0.1), DVec2::ONE), None);
    }

    #[test]
    fn the_normal_from_first_derivatives_is_the_full_evaluations_to_the_bit() {
        let mut state = 41;
        let sphere = construct::sphere(DVec3::new(0.5, 1.0, -2.0), 2.5).unwrap();
        for seed in 0..60 {
            let random = random_bspline_surface(&mut state, seed % 2 == 0);
            let surface = if seed % 5 == 0 { &sphere } else { &random };
            let [(u0, u1), (v0, v1)] = surface.domain();
            for k in 0..50 {
                let (s, t) = (uniform(&mut state), uniform(&mut state));
                // Corners, edges (the sphere's poles) and breaks too.
                let (s, t) = match k % 5 {
                    0 => (s.round(), t.round()),
                    1 => (s, t.round()),
                    _ => (s, t),
                };
                let (u, v) = (u0 + s * (u1 - u0), v0 + t * (v1 - v0));
                let full = surface.normal_from(&surface.evaluate(u, v).unwrap(), u, v);
                assert_eq!(
                    surface.normal(u, v).unwrap(),
                    full,
                    "seed {seed} at ({u}, {v})"
                );
            }
        }
        assert!(sphere.normal(f64::NAN, 0.0).is_err());
    }

    #[test]
    fn a_bad_parameter_is_the_surfaces_error() {
        let sphere = construct::sphere(DVec3::ZERO, 1.0).unwrap();
        let eval = sphere.scattered_evaluator();
        let p = DVec2::new(f64::NAN, 0.5);
        assert_eq!(
            eval.point(p).unwrap_err().to_string(),
            sphere.point_at_clamped(p).unwrap_err().to_string()
        );
        assert!(eval.point_and_normal(p).is_err());
    }
}
