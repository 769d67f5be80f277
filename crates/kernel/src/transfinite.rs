//! Transfinite surfaces as exact NURBS: the bicubic Hermite patch, the bicubically blended Coons
//! patch and the Gordon surface of a curve network (seed notes "Hermite surfaces", "Coons
//! patch", "Gordon surfaces"; The NURBS Book §10.5). Each is a Boolean sum P₁ ⊕ P₂ =
//! P₁ + P₂ − P₁P₂ of blends of non-rational curves; every term is a B-spline surface, so after
//! bringing the terms to common degrees and knot vectors the sum of their control points is the
//! surface exactly ([`boolean_sum`]).
//!
//! Parameters run over [0, 1]²: the curves are reparametrized linearly onto [0, 1] first, and
//! derivatives (cross-boundary tangents, twists) are taken with respect to those parameters.

use glam::{DVec3, DVec4};

use super::basis::{interior_knots, merge_knots, missing_knots};
use super::curve::SpaceCurve;
use super::error::GeometryError;
use super::error::construction;
use super::interpolation::{averaged_knots, interpolate_points, make_compatible, skin};
use super::surface::{Direction, NurbsSurface};

/// The corners of [0, 1]² in the order the Hermite data lists them.
pub const CORNERS: [(usize, usize); 4] = [(0, 0), (1, 0), (0, 1), (1, 1)];

/// The 16 vectors of a bicubic Hermite patch, per corner in the order of [`CORNERS`]: the
/// point S, the derivatives S_u and S_v and the twist S_uv.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HermiteData {
    pub points: [DVec3; 4],
    pub su: [DVec3; 4],
    pub sv: [DVec3; 4],
    pub twist: [DVec3; 4],
}

/// The bicubic Hermite patch S(u, v) = H(u) G H(v)ᵀ of `data` (Ferguson/Coons; seed notes
/// "Hermite surfaces") as the bicubic Bézier patch with the same 16 corner conditions: at a
/// corner with signs σ_u, σ_v (+1 at 0, −1 at 1) the corner point is S, its neighbours along u
/// and v are S + σ_u S_u/3 and S + σ_v S_v/3, and the inner point is
/// S + σ_u S_u/3 + σ_v S_v/3 + σ_u σ_v S_uv/9 (from S_uv(0, 0) = 9(b₀₀ − b₁₀ − b₀₁ + b₁₁)).
pub fn hermite_patch(data: &HermiteData) -> Result<NurbsSurface, GeometryError> {
    let all = [data.points, data.su, data.sv, data.twist];
    if all.iter().flatten().any(|p| !p.is_finite()) {
        return Err(construction("hermite patch", "a vector is not finite"));
    }
    let mut b = vec![DVec3::ZERO; 16];
    for (c, &(a, e)) in CORNERS.iter().enumerate() {
        let (su, sv) = (
            if a == 0 { 1.0 } else { -1.0 },
            if e == 0 { 1.0 } else { -1.0 },
        );
        let (i0, i1) = (3 * a, if a == 0 { 1 } else { 2 });
        let (j0, j1) = (3 * e, if e == 0 { 1 } else { 2 });
        let p = data.points[c];
        let du = data.su[c] * (su / 3.0);
        let dv = data.sv[c] * (sv / 3.0);
        b[i0 * 4 + j0] = p;
        b[i1 * 4 + j0] = p + du;
        b[i0 * 4 + j1] = p + dv;
        b[i1 * 4 + j1] = p + du + dv + data.twist[c] * (su * sv / 9.0);
    }
    NurbsSurface::bezier([3, 3], b, None)
}

/// `curve` reparametrized onto [0, 1].
pub(super) fn normalized(curve: &SpaceCurve) -> Result<SpaceCurve, GeometryError> {
    curve.reparametrized(0.0, 1.0)
}

/// The point and first derivative of a curve on [0, 1] at `t`.
fn point_and_tangent(curve: &SpaceCurve, t: f64) -> Result<(DVec3, DVec3), GeometryError> {
    let d = curve.derivatives(t, 1)?;
    Ok((d[0], d[1]))
}

/// The largest control point distance from the origin (at least 1): the scale tolerances are
/// relative to.
fn scale_of(curves: &[&SpaceCurve]) -> f64 {
    curves
        .iter()
        .flat_map(|c| (0..c.count()).map(|i| c.control_point(i).length()))
        .fold(1.0, f64::max)
}

/// Checks that four boundary curves (bottom v = 0, top v = 1, left u = 0, right u = 1) are
/// non-rational and meet at the corners: bottom(0) = left(0), bottom(1) = right(0),
/// top(0) = left(1), top(1) = right(1), within 1e-9 of their size. Returns the corners in the
/// order of [`CORNERS`].
pub fn meeting_corners(
    curves: [&SpaceCurve; 4],
    what: &'static str,
) -> Result<[DVec3; 4], GeometryError> {
    let [bottom, top, left, right] = curves;
    if curves.iter().any(|c| !c.is_polynomial()) {
        return Err(construction(
            what,
            "the boundary curves must be non-rational (all weights 1)",
        ));
    }
    let end = |c: &SpaceCurve, at_end: bool| -> Result<DVec3, GeometryError> {
        let (a, b) = c.domain();
        c.point_at(if at_end { b } else { a })
    };
    let pairs = [
        (bottom, false, left, false, "bottom start and left start"),
        (bottom, true, right, false, "bottom end and right start"),
        (top, false, left, true, "top start and left end"),
        (top, true, right, true, "top end and right end"),
    ];
    let scale = scale_of(&curves);
    let mut corners = [DVec3::ZERO; 4];
    for (k, (c, ce, d, de, name)) in pairs.into_iter().enumerate() {
        let (a, b) = (end(c, ce)?, end(d, de)?);
        if a.distance(b) > 1e-9 * scale {
            return Err(construction(
                what,
                format!(
                    "the corners do not meet: {name} differ by {}",
                    a.distance(b)
                ),
            ));
        }
        corners[k] = a;
    }
    Ok(corners)
}

/// Σ `plus` − Σ `minus` of non-rational surfaces on [0, 1]²: each term is raised to the
/// highest degree in each direction (A5.10) and refined to the union of all interior knots
/// (A5.5), which leaves its shape unchanged, and then the control points are summed. Exact.
pub fn boolean_sum(
    plus: &[NurbsSurface],
    minus: &[NurbsSurface],
    what: &'static str,
) -> Result<NurbsSurface, GeometryError> {
    let terms: Vec<(&NurbsSurface, f64)> = plus
        .iter()
        .map(|s| (s, 1.0))
        .chain(minus.iter().map(|s| (s, -1.0)))
        .collect();
    if terms.is_empty() {
        return Err(construction(what, "nothing to sum"));
    }
    // Interpolated skins carry weights 1 up to rounding.
    let non_rational = |s: &NurbsSurface| {
        s.homogeneous_points()
            .iter()
            .all(|h| (h.w - 1.0).abs() <= 1e-12)
    };
    if terms.iter().any(|(s, _)| !non_rational(s)) {
        return Err(construction(
            what,
            "the blended surfaces must be non-rational",
        ));
    }
    if terms
        .iter()
        .any(|(s, _)| s.domain() != [(0.0, 1.0), (0.0, 1.0)])
    {
        return Err(construction(
            what,
            "the blended surfaces must be on [0, 1]²",
        ));
    }
    let interior =
        |s: &NurbsSurface, d: usize| interior_knots(s.knots()[d], s.degree()[d], s.count()[d]);
    let degree = [0, 1].map(|d| terms.iter().map(|(s, _)| s.degree()[d]).max().unwrap_or(1));
    let mut raised = Vec::with_capacity(terms.len());
    let mut unions: [Vec<(f64, usize)>; 2] = [Vec::new(), Vec::new()];
    for &(s, _) in &terms {
        let [du, dv] = s.degree();
        let s = s
            .elevate_degree(Direction::U, degree[0] - du)?
            .elevate_degree(Direction::V, degree[1] - dv)?;
        for (d, union) in unions.iter_mut().enumerate() {
            merge_knots(union, &interior(&s, d), 1e-12);
        }
        raised.push(s);
    }
    let mut conformed: Vec<NurbsSurface> = Vec::with_capacity(raised.len());
    for mut s in raised {
        for (d, direction) in [Direction::U, Direction::V].into_iter().enumerate() {
            let missing = missing_knots(&interior(&s, d), &unions[d], 1e-12);
            if !missing.is_empty() {
                s = s.refine(direction, &missing)?;
            }
        }
        conformed.push(s);
    }
    let first = &conformed[0];
    if conformed.iter().any(|s| s.count() != first.count()) {
        return Err(construction(
            what,
            "the blended surfaces did not become compatible",
        ));
    }
    let mut points = vec![DVec4::ZERO; first.homogeneous_points().len()];
    for (s, &(_, sign)) in conformed.iter().zip(&terms) {
        for (acc, h) in points.iter_mut().zip(s.homogeneous_points()) {
            *acc += h.truncate().extend(0.0) * sign;
        }
    }
    for p in &mut points {
        p.w = 1.0;
    }
    let knots = [first.knots()[0].to_vec(), first.knots()[1].to_vec()];
    NurbsSurface::from_homogeneous(degree, knots, first.count(), points)
}

/// The cubic Hermite blend in u of two curves in v and their u-derivatives,
/// c₀(v)H₀(u) + d₀(v)H₁(u) + d₁(v)H₂(u) + c₁(v)H₃(u) (seed notes, bicubically blended Coons),
/// as a degree-(3, q) B-spline: the Hermite basis in Bernstein form is H₀ = B₀ + B₁,
/// H₁ = B₁/3, H₂ = −B₂/3, H₃ = B₂ + B₃, so the four Bézier rows are c₀, c₀ + d₀/3,
/// c₁ − d₁/3, c₁ over the curves' common knots.
fn hermite_blend(
    c0: &SpaceCurve,
    d0: &SpaceCurve,
    c1: &SpaceCurve,
    d1: &SpaceCurve,
) -> Result<NurbsSurface, GeometryError> {
    let polys = make_compatible(&[c0.clone(), d0.clone(), c1.clone(), d1.clone()])?;
    let n = polys[0].points.len();
    let row = |k: usize, j: usize| polys[k].points[j].truncate();
    let mut points = Vec::with_capacity(4 * n);
    for i in 0..4 {
        for j in 0..n {
            points.push(match i {
                0 => row(0, j),
                1 => row(0, j) + row(1, j) / 3.0,
                2 => row(2, j) - row(3, j) / 3.0,
                _ => row(2, j),
            });
        }
    }
    NurbsSurface::new(
        [3, polys[0].degree],
        [
            vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0],
            polys[0].knots.clone(),
        ],
        [4, n],
        points,
        None,
    )
}

/// Whether two vectors that should agree do, within 1e-6 of `scale` (or of their length).
fn agree(a: DVec3, b: DVec3, scale: f64) -> bool {
    a.distance(b) <= 1e-6 * scale.max(a.length()).max(b.length())
}

/// The bicubically blended Coons patch (seed notes "Coons patch"): P₁ blends the left
/// (u = 0) and right (u = 1) curves and their cross-boundary derivatives S_u with the cubic
/// Hermite functions in u, P₂ the bottom (v = 0) and top (v = 1) curves and their S_v in v, and
/// P₁P₂ is the bicubic Hermite patch of the corners' points, tangents and twists. The patch
/// interpolates the four curves and the four cross-boundary derivative curves.
///
/// `boundary` = [bottom, top, left, right]; `cross` = [S_v along the bottom, S_v along the top,
/// S_u along the left, S_u along the right], each a non-rational curve of vectors over the same
/// boundary parameter. The data must be compatible at the corners: the cross derivatives there
/// equal the neighbouring boundary curves' tangents, and the two twists each corner gets (the
/// derivative of S_u along v and of S_v along u) agree. Otherwise the error says which corner.
pub fn bicubic_coons(
    boundary: [&SpaceCurve; 4],
    cross: [&SpaceCurve; 4],
) -> Result<NurbsSurface, GeometryError> {
    const WHAT: &str = "bicubic coons";
    let corners = meeting_corners(boundary, WHAT)?;
    if cross.iter().any(|c| !c.is_polynomial()) {
        return Err(construction(
            WHAT,
            "the cross-derivative curves must be non-rational (all weights 1)",
        ));
    }
    let [bottom, top, left, right] = boundary.map(normalized);
    let [bottom, top, left, right] = [bottom?, top?, left?, right?];
    let [d_bottom, d_top, d_left, d_right] = cross.map(normalized);
    let [d_bottom, d_top, d_left, d_right] = [d_bottom?, d_top?, d_left?, d_right?];
    let scale = scale_of(&[&bottom, &top, &left, &right]);
    // Per corner (order of CORNERS): the u-curve through it (bottom or top) at u = a, the
    // v-curve (left or right) at v = b, and the two cross curves.
    let mut data = HermiteData {
        points: corners,
        su: [DVec3::ZERO; 4],
        sv: [DVec3::ZERO; 4],
        twist: [DVec3::ZERO; 4],
    };
    for (c, &(a, b)) in CORNERS.iter().enumerate() {
        let (u_curve, d_u_curve) = [(&bottom, &d_bottom), (&top, &d_top)][b];
        let (v_curve, d_v_curve) = [(&left, &d_left), (&right, &d_right)][a];
        let (u, v) = (a as f64, b as f64);
        let (_, su) = point_and_tangent(u_curve, u)?;
        let (_, sv) = point_and_tangent(v_curve, v)?;
        let (su_cross, twist_u) = point_and_tangent(d_v_curve, v)?;
        let (sv_cross, twist_v) = point_and_tangent(d_u_curve, u)?;
        let at = format!("(u, v) = ({a}, {b})");
        if !agree(su, su_cross, scale) {
            return Err(construction(
                WHAT,
                format!(
                    "at {at} the boundary tangent S_u = {su} differs from the cross derivative {su_cross}"
                ),
            ));
        }
        if !agree(sv, sv_cross, scale) {
            return Err(construction(
                WHAT,
                format!(
                    "at {at} the boundary tangent S_v = {sv} differs from the cross derivative {sv_cross}"
                ),
            ));
        }
        if !agree(twist_u, twist_v, scale) {
            return Err(construction(
                WHAT,
                format!("at {at} the twists disagree: ∂S_u/∂v = {twist_u}, ∂S_v/∂u = {twist_v}"),
            ));
        }
        data.su[c] = su;
        data.sv[c] = sv;
        data.twist[c] = twist_u;
    }
    let p1 = hermite_blend(&left, &d_left, &right, &d_right)?;
    let p2 = hermite_blend(&bottom, &d_bottom, &top, &d_top)?.swap_uv();
    let p12 = hermite_patch(&data)?;
    boolean_sum(&[p1, p2], &[p12], WHAT)
}

/// Samples at which [`crossing`] starts its search: SAMPLES + 1 evenly spaced parameters.
const SAMPLES: usize = 96;

/// `curve` (on [0, 1]) at the [`SAMPLES`] + 1 evenly spaced parameters.
pub(super) fn samples(curve: &SpaceCurve) -> Result<Vec<DVec3>, GeometryError> {
    (0..=SAMPLES)
        .map(|i| curve.point_at(i as f64 / SAMPLES as f64))
        .collect()
}

/// Where two curves on [0, 1] come closest: (s on `c`, t on `d`, distance). The nearest pair
/// of their [`samples`] (`cs`, `ds`), then Gauss-Newton on |c(s) − d(t)|² (the normal
/// equations of J = [c′, −d′]), clamped to the domains.
pub(super) fn crossing(
    (c, cs): (&SpaceCurve, &[DVec3]),
    (d, ds): (&SpaceCurve, &[DVec3]),
) -> Result<(f64, f64, f64), GeometryError> {
    let mut best = (f64::INFINITY, 0, 0);
    for (i, p) in cs.iter().enumerate() {
        for (j, q) in ds.iter().enumerate() {
            let dist = p.distance_squared(*q);
            if dist < best.0 {
                best = (dist, i, j);
            }
        }
    }
    let (mut s, mut t) = (
        best.1 as f64 / SAMPLES as f64,
        best.2 as f64 / SAMPLES as f64,
    );
    for _ in 0..60 {
        let (pc, a) = point_and_tangent(c, s)?;
        let (pd, td) = point_and_tangent(d, t)?;
        let (r, b) = (pc - pd, -td);
        let (aa, ab, bb) = (a.dot(a), a.dot(b), b.dot(b));
        let det = aa * bb - ab * ab;
        if !(det > 1e-300) {
            break;
        }
        let (ra, rb) = (-a.dot(r), -b.dot(r));
        let ds = (ra * bb - ab * rb) / det;
        let dt = (aa * rb - ab * ra) / det;
        let (ns, nt) = ((s + ds).clamp(0.0, 1.0), (t + dt).clamp(0.0, 1.0));
        let moved = (ns - s).abs() + (nt - t).abs();
        (s, t) = (ns, nt);
        if moved < 1e-15 {
            break;
        }
    }
    Ok((s, t, c.point_at(s)?.distance(d.point_at(t)?)))
}

/// The common parameters at which the curves of one family are crossed: `params[k][l]` is
/// where curve k meets curve l of the other family. Each column l must be one value for all k
/// (within 1e-6) and the values must increase with l. `family`/`other` name the two families in
/// the errors.
fn common_parameters(
    params: &[Vec<f64>],
    family: &str,
    other: &str,
    axis: &str,
) -> Result<Vec<f64>, GeometryError> {
    let columns = params[0].len();
    let mut common = Vec::with_capacity(columns);
    for l in 0..columns {
        let mean = params.iter().map(|row| row[l]).sum::<f64>() / params.len() as f64;
        if params.iter().any(|row| (row[l] - mean).abs() > 1e-6) {
            // Name the two curves crossed farthest apart.
            let by_value =
                |a: &(usize, &Vec<f64>), b: &(usize, &Vec<f64>)| a.1[l].total_cmp(&b.1[l]);
            let (low, high) = (
                params.iter().enumerate().min_by(by_value),
                params.iter().enumerate().max_by(by_value),
            );
            if let (Some((a, low)), Some((b, high))) = (low, high) {
                return Err(construction(
                    "gordon",
                    format!(
                        "{other} {l} crosses {family} {a} at {axis} = {:.6} but {family} {b} at \
                         {axis} = {:.6}; a Gordon surface needs every {other} to cross all the \
                         {family}s at one common {axis} (reparametrize the curves)",
                        low[l], high[l]
                    ),
                ));
            }
        }
        if let Some(&previous) = common.last()
            && !(mean > previous + 1e-9)
        {
            return Err(construction(
                "gordon",
                format!(
                    "the {other}s must be given in order of increasing {axis}: {other} {l} \
                     crosses at {axis} = {mean:.6}, {other} {} at {previous:.6}",
                    l - 1
                ),
            ));
        }
        common.push(mean);
    }
    Ok(common)
}

/// The Gordon surface through a network of curves (seed notes "Gordon surfaces"; The NURBS
/// Book §10.5): `u_curves` run along u at increasing v, `v_curves` along v at increasing u,
/// and every u-curve k crosses every v-curve l at one common pair (u_l, v_k), found by closest
/// points. S = L_v + L_u − T: L_v skins the u-curves across v (interpolating u-curve k at v_k),
/// L_u skins the v-curves across u, and T is the tensor-product interpolant of the crossing
/// points, with the same parameters, degrees (`degree`, lowered to the number of curves − 1)
/// and averaged knots as the skins, so that S(u, v_k) is u-curve k and S(u_l, v) is v-curve l
/// exactly. The curves must be non-rational. With two curves each way this is the bilinearly
/// blended Coons patch.
pub fn gordon(
    u_curves: &[SpaceCurve],
    v_curves: &[SpaceCurve],
    degree: usize,
) -> Result<NurbsSurface, GeometryError> {
    const WHAT: &str = "gordon";
    const MAX_CURVES: usize = 64;
    for (name, curves) in [("u-curve", u_curves), ("v-curve", v_curves)] {
        if !(2..=MAX_CURVES).contains(&curves.len()) {
            return Err(construction(
                WHAT,
                format!("needs 2 to {MAX_CURVES} {name}s, found {}", curves.len()),
            ));
        }
        if let Some(k) = curves.iter().position(|c| !c.is_polynomial()) {
            return Err(construction(
                WHAT,
                format!("{name} {k} is rational; the network must be non-rational (weights 1)"),
            ));
        }
    }
    if degree == 0 {
        return Err(construction(WHAT, "the degree must be ≥ 1"));
    }
    let us: Vec<SpaceCurve> = u_curves.iter().map(normalized).collect::<Result<_, _>>()?;
    let vs: Vec<SpaceCurve> = v_curves.iter().map(normalized).collect::<Result<_, _>>()?;
    let scale = scale_of(&us.iter().chain(&vs).collect::<Vec<_>>());
    let (k_count, l_count) = (us.len(), vs.len());
    let mut at_u = vec![vec![0.0; l_count]; k_count];
    let mut at_v = vec![vec![0.0; k_count]; l_count];
    // Each curve sampled once for all its crossings.
    let u_samples: Vec<Vec<DVec3>> = us.iter().map(samples).collect::<Result<_, _>>()?;
    let v_samples: Vec<Vec<DVec3>> = vs.iter().map(samples).collect::<Result<_, _>>()?;
    for (k, (c, cs)) in us.iter().zip(&u_samples).enumerate() {
        for (l, (d, ds)) in vs.iter().zip(&v_samples).enumerate() {
            let (s, t, distance) = crossing((c, cs), (d, ds))?;
            if distance > 1e-6 * scale {
                return Err(construction(
                    WHAT,
                    format!(
                        "u-curve {k} and v-curve {l} do not meet (they come within {distance:.3e})"
                    ),
                ));
            }
            at_u[k][l] = s;
            at_v[l][k] = t;
        }
    }
    let u_params = common_parameters(&at_u, "u-curve", "v-curve", "u")?;
    let v_params = common_parameters(&at_v, "v-curve", "u-curve", "v")?;
    gordon_at(&us, &vs, &u_params, &v_params, degree)
}

/// The Gordon surface S = L_v + L_u − T of curves on [0, 1] whose crossings are known: u-curve
/// k meets v-curve l near us[k](u_params[l]) and vs[l](v_params[k]) (both parameter lists
/// increasing). The skins interpolate the curves at those parameters with degree `degree`
/// (lowered to the number of curves − 1) over averaged knots, and T interpolates the midpoints
/// of the two curves' points at each crossing, so S(u, v_k) = u-curve k + (the interpolant of
/// the crossing mismatches), exactly u-curve k where the curves meet exactly.
pub(super) fn gordon_at(
    us: &[SpaceCurve],
    vs: &[SpaceCurve],
    u_params: &[f64],
    v_params: &[f64],
    degree: usize,
) -> Result<NurbsSurface, GeometryError> {
    const WHAT: &str = "gordon";
    let (k_count, l_count) = (us.len(), vs.len());
    let p = degree.min(l_count - 1);
    let q = degree.min(k_count - 1);
    let skin_u_curves = skin(&make_compatible(us)?, v_params, q, WHAT)?;
    let skin_v_curves = skin(&make_compatible(vs)?, u_params, p, WHAT)?.swap_uv();
    // T: the crossing points interpolated along u per u-curve, then across v per column.
    let knots_u = averaged_knots(u_params, p);
    let knots_v = averaged_knots(v_params, q);
    let mut rows = Vec::with_capacity(k_count);
    for (k, c) in us.iter().enumerate() {
        let crossings: Vec<DVec3> = vs
            .iter()
            .enumerate()
            .map(|(l, d)| Ok((c.point_at(u_params[l])? + d.point_at(v_params[k])?) * 0.5))
            .collect::<Result<_, GeometryError>>()?;
        rows.push(interpolate_points(&crossings, u_params, p, &knots_u, WHAT)?);
    }
    let mut points = vec![DVec3::ZERO; l_count * k_count];
    for i in 0..l_count {
        let column: Vec<DVec3> = rows.iter().map(|row| row[i]).collect();
        let control = interpolate_points(&column, v_params, q, &knots_v, WHAT)?;
        for (k, point) in control.into_iter().enumerate() {
            points[i * k_count + k] = point;
        }
    }
    let tensor = NurbsSurface::new([p, q], [knots_u, knots_v], [l_count, k_count], points, None)?;
    boolean_sum(&[skin_u_curves, skin_v_curves], &[tensor], WHAT)
}
