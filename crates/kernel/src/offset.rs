//! Offsets of surfaces: the surface O(u, v) = S(u, v) + d N(u, v) at signed distance d along the
//! unit normal, over the same domain.
//!
//! - **Exact** where the offset is an affine image of the surface, which a NURBS surface
//!   follows exactly (NURBS are affinely invariant): a plane moves by d N; a sphere of radius r
//!   scales about its centre by (r ± d)/r; a circular cylinder scales across its axis by
//!   (r ± d)/r. The shape is recognised from samples (every sample on the plane, sphere or
//!   cylinder within 1e-9 of the surface's size, with the normal along the radius).
//! - **Exact for surfaces of revolution** whose meridian is a line or a circle (cones, tori,
//!   and revolutions of lines and arcs in general): the control net of a surface of revolution
//!   is P_ij = O_j + ρ_j g_i (O_j the foot on the axis of the meridian's point j, ρ_j its
//!   distance from the axis, g_i the same for every j; The NURBS Book A8.1), and its offset is
//!   the revolution of the meridian's offset in its plane, which for a line is a translate
//!   and for a circle the concentric circle (its control points scaled about the centre). So
//!   P'_ij = O'_j + ρ'_j g_i from the offset meridian, the weights unchanged. The axis comes
//!   from the circles of three iso-curves; the result is kept only where it lies at the
//!   distance at every sample (within 1e-9 of the size), so nothing else is taken for one.
//! - **Fitted** elsewhere: a bicubic B-spline that interpolates O at the Greville abscissae of
//!   its knots (The NURBS Book §9.2.5, A9.4 as two passes of curve interpolation), its spans
//!   halved where O and the fit differ by more than the tolerance between the interpolated
//!   points, until they agree everywhere the check samples look (3 × 3 points in every span
//!   cell, plus the cells' corners). The largest difference found is reported.
//! - **Folds.** Along a principal direction the offset's tangent scales by 1 − d κ (κ positive
//!   where the surface bends toward N; do Carmo §3-3), so the offset folds (a cusp edge, the
//!   surface turning back on itself) where d κ ≥ 1 for a principal curvature κ: the distance is
//!   at least the radius of curvature on the side the offset goes to. Those places are reported.

use glam::{DAffine3, DMat3, DVec2, DVec3};

use crate::basis::{basis_functions, find_span};
use crate::error::GeometryError;
use crate::error::construction;
use crate::parametric::ParametricSurface;
use crate::surface::{Direction, NurbsSurface};

/// The most control points a fitted offset may have along one direction.
pub const MAX_OFFSET_POINTS: usize = 256;

/// Relative (to the surface's size) distance within which samples count as lying on a plane,
/// sphere or cylinder.
const SHAPE_TOLERANCE: f64 = 1e-9;

/// The most fold places listed (the count says how many samples fold).
const MAX_FOLDS_LISTED: usize = 32;

/// How the offset was made.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum OffsetShape {
    /// A plane, moved along its normal (exact).
    Plane,
    /// A sphere, scaled about its centre (exact).
    Sphere { centre: DVec3, radius: f64 },
    /// A circular cylinder, scaled across its axis (exact).
    Cylinder {
        point: DVec3,
        axis: DVec3,
        radius: f64,
    },
    /// A surface of revolution whose meridian is a line or a circle (a cone, a torus, …):
    /// its meridian offset in its plane and revolved again (exact).
    Revolution { point: DVec3, axis: DVec3 },
    /// Fitted within the tolerance (a bicubic B-spline).
    Fitted,
}

/// A place where the offset folds: the radius of curvature there is below |d| on the side the
/// offset goes to.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fold {
    pub uv: DVec2,
    pub point: DVec3,
    /// The radius of curvature 1/|κ| there.
    pub radius: f64,
}

/// An offset surface with how it was made and how far it is from the true offset.
#[derive(Debug, Clone, PartialEq)]
pub struct Offset {
    pub surface: NurbsSurface,
    pub shape: OffsetShape,
    /// The largest distance found between the result and S + d N at the same parameters (0 for
    /// an exact offset, up to rounding).
    pub deviation: f64,
    /// Some of the places where the offset folds (empty when it does not).
    pub folds: Vec<Fold>,
    /// How many samples fold in all.
    pub fold_samples: usize,
}

impl Offset {
    /// Whether the offset is exact (an affine image of the surface).
    pub fn is_exact(&self) -> bool {
        !matches!(self.shape, OffsetShape::Fitted)
    }
}

/// The offset of a NURBS surface by signed `distance` along its normal, exact for planes,
/// spheres and circular cylinders and fitted within `tolerance` (a distance in model units)
/// elsewhere.
pub fn offset_nurbs(
    surface: &NurbsSurface,
    distance: f64,
    tolerance: f64,
) -> Result<Offset, GeometryError> {
    check_arguments(distance, tolerance)?;
    let normal = |u: f64, v: f64| surface.normal(u, v).ok();
    let [us, vs] = [Direction::U, Direction::V].map(|d| sample_parameters(surface, d));
    let samples = sample_grid(surface, &normal, &us, &vs);
    let (folds, fold_samples) = find_folds(surface, &samples, distance);
    // The largest distance of a result from S + d N at the samples (a sample it cannot
    // evaluate is infinitely off).
    let off_by = |result: &NurbsSurface| {
        samples
            .iter()
            .map(|s| {
                result
                    .point_at(s.uv.x, s.uv.y)
                    .map_or(f64::INFINITY, |p| p.distance(s.point + distance * s.normal))
            })
            .fold(0.0, f64::max)
    };
    if let Some((shape, transform)) = recognise(surface, &samples, distance) {
        let result = surface.transformed(&transform)?;
        let deviation = off_by(&result);
        return Ok(Offset {
            surface: result,
            shape,
            deviation,
            folds,
            fold_samples,
        });
    }
    let tol = SHAPE_TOLERANCE * surface.size().max(f64::MIN_POSITIVE);
    for swapped in [false, true] {
        let turned = if swapped {
            surface.swap_uv()
        } else {
            surface.clone()
        };
        if let Some((shape, result)) = revolution_offset(&turned.clamped(), distance, tol) {
            let result = if swapped { result.swap_uv() } else { result };
            let deviation = off_by(&result);
            if deviation <= tol.max(1e-3 * tolerance) {
                return Ok(Offset {
                    surface: result,
                    shape,
                    deviation,
                    folds,
                    fold_samples,
                });
            }
        }
    }
    let breaks = [Direction::U, Direction::V].map(|d| fit_breaks(surface, d));
    let (result, deviation) = fitted_offset(surface, &normal, breaks, distance, tolerance)?;
    Ok(Offset {
        surface: result,
        shape: OffsetShape::Fitted,
        deviation,
        folds,
        fold_samples,
    })
}

/// The offset of any face (a Bézier patch, a subdivision limit patch, a triangle over the
/// square) fitted within `tolerance`, starting from `spans` × `spans` spans.
pub fn offset_face(
    face: &dyn ParametricSurface,
    distance: f64,
    tolerance: f64,
    spans: usize,
) -> Result<Offset, GeometryError> {
    check_arguments(distance, tolerance)?;
    let normal = |u: f64, v: f64| face_normal(face, u, v);
    let domain = face.domain();
    let spans = spans.clamp(1, 64);
    let breaks = domain.map(|(a, b)| {
        (0..=spans)
            .map(|i| (a + (b - a) * i as f64 / spans as f64, 1))
            .collect::<Vec<_>>()
    });
    let params = |(a, b): (f64, f64)| -> Vec<f64> {
        let n = 4 * spans;
        (0..=n).map(|i| a + (b - a) * i as f64 / n as f64).collect()
    };
    let samples = sample_grid(face, &normal, &params(domain[0]), &params(domain[1]));
    let (folds, fold_samples) = find_folds(face, &samples, distance);
    let (surface, deviation) = fitted_offset(face, &normal, breaks, distance, tolerance)?;
    Ok(Offset {
        surface,
        shape: OffsetShape::Fitted,
        deviation,
        folds,
        fold_samples,
    })
}

fn check_arguments(distance: f64, tolerance: f64) -> Result<(), GeometryError> {
    if !distance.is_finite() {
        return Err(construction(
            "offset",
            format!("the distance must be a finite number (got {distance})"),
        ));
    }
    if !(tolerance.is_finite() && tolerance > 0.0) {
        return Err(construction(
            "offset",
            format!("the tolerance must be a number above 0 (got {tolerance})"),
        ));
    }
    Ok(())
}

/// The unit normal of a face, with the limit rule at collapsed edges and a nudge inward where
/// both fail.
pub fn face_normal(face: &dyn ParametricSurface, u: f64, v: f64) -> Option<DVec3> {
    let [(u0, u1), (v0, v1)] = face.domain();
    let d = face.derivatives(u, v)?;
    let (s, t) = (
        (u - u0) / (u1 - u0).max(f64::MIN_POSITIVE),
        (v - v0) / (v1 - v0).max(f64::MIN_POSITIVE),
    );
    if let Some(n) = d.regular_normal().or_else(|| d.collapsed_edge_normal(s, t)) {
        return Some(n);
    }
    let (cu, cv) = (0.5 * (u0 + u1), 0.5 * (v0 + v1));
    let nudge = crate::diffgeo::NORMAL_NUDGE;
    face.derivatives(u + (cu - u) * nudge, v + (cv - v) * nudge)?
        .regular_normal()
}

/// One sample of the surface: parameters, point and unit normal.
#[derive(Debug, Clone, Copy)]
struct Sample {
    uv: DVec2,
    point: DVec3,
    normal: DVec3,
}

fn sample_grid(
    face: &dyn ParametricSurface,
    normal: &dyn Fn(f64, f64) -> Option<DVec3>,
    us: &[f64],
    vs: &[f64],
) -> Vec<Sample> {
    let mut out = Vec::with_capacity(us.len() * vs.len());
    for &u in us {
        for &v in vs {
            if let (Some(point), Some(normal)) = (face.point(u, v), normal(u, v)) {
                out.push(Sample {
                    uv: DVec2::new(u, v),
                    point,
                    normal,
                });
            }
        }
    }
    out
}

/// Four samples per span (and the breaks), at most about 64 along a direction.
fn sample_parameters(surface: &NurbsSurface, direction: Direction) -> Vec<f64> {
    let breaks = surface.span_breaks(direction);
    let per = (64 / breaks.len().max(2)).clamp(1, 4);
    let mut out = Vec::new();
    for w in breaks.windows(2) {
        for k in 0..per {
            out.push(w[0] + (w[1] - w[0]) * k as f64 / per as f64);
        }
    }
    out.extend(breaks.last());
    out
}

/// The places among `samples` where d κ ≥ 1 for a principal curvature κ.
fn find_folds(
    face: &dyn ParametricSurface,
    samples: &[Sample],
    distance: f64,
) -> (Vec<Fold>, usize) {
    let mut folds = Vec::new();
    let mut count = 0;
    for s in samples {
        let Some(c) = face.curvature(s.uv.x, s.uv.y) else {
            continue;
        };
        // The sample's normal may be the limit one; the curvature's sign follows the regular
        // normal, which agrees with it wherever the curvature is defined.
        let k = if distance >= 0.0 { c.k1 } else { c.k2 };
        if distance * k >= 1.0 {
            count += 1;
            if folds.len() < MAX_FOLDS_LISTED {
                folds.push(Fold {
                    uv: s.uv,
                    point: s.point,
                    radius: 1.0 / k.abs(),
                });
            }
        }
    }
    (folds, count)
}

/// Recognises a plane, sphere or circular cylinder and returns the affine map that offsets it.
fn recognise(
    surface: &NurbsSurface,
    samples: &[Sample],
    distance: f64,
) -> Option<(OffsetShape, DAffine3)> {
    let size = surface.size().max(f64::MIN_POSITIVE);
    let tol = SHAPE_TOLERANCE * size;
    let first = samples.first()?;
    // A plane: every control point on the plane of the first sample.
    let n = first.normal;
    if surface
        .homogeneous_points()
        .iter()
        .all(|h| (h.truncate() / h.w - first.point).dot(n).abs() <= tol)
        && samples.iter().all(|s| s.normal.dot(n) > 0.0)
    {
        return Some((OffsetShape::Plane, DAffine3::from_translation(distance * n)));
    }
    // A sphere or cylinder: from the curvature in the middle of the domain (a regular point of
    // a revolved surface, where the curvature needs no nudging).
    let [(u0, u1), (v0, v1)] = surface.domain();
    let (um, vm) = (0.5 * (u0 + u1), 0.5 * (v0 + v1));
    let middle = Sample {
        uv: DVec2::new(um, vm),
        point: surface.point_at(um, vm).ok()?,
        normal: surface.evaluate(um, vm).ok()?.regular_normal()?,
    };
    let c = surface.local_geometry(um, vm).ok()?;
    let curvature = c.curvature;
    let (k1, k2) = (curvature.k1, curvature.k2);
    let scale = k1.abs().max(k2.abs());
    if scale * size < 1e-9 {
        return None;
    }
    let normal = middle.normal;
    if (k1 - k2).abs() <= 1e-6 * scale {
        // Sphere: centre P + N / H, radius 1/|H| (the mean curvature: k1 and k2 carry the
        // rounding of √(H² − K) at an umbilic).
        let h = curvature.mean;
        let radius = 1.0 / h.abs();
        let centre = middle.point + normal / h;
        let on_sphere = samples.iter().all(|s| {
            let r = s.point - centre;
            (r.length() - radius).abs() <= tol
                && s.normal.cross(r).length() <= tol.max(1e-9 * radius)
        });
        if !on_sphere {
            return None;
        }
        // Outward normals (κ < 0) grow the radius by d.
        let outward = if h < 0.0 { 1.0 } else { -1.0 };
        let factor = (radius + outward * distance) / radius;
        if factor.abs() < 1e-12 {
            return None;
        }
        let transform = DAffine3::from_translation(centre)
            * DAffine3::from_scale(DVec3::splat(factor))
            * DAffine3::from_translation(-centre);
        return Some((OffsetShape::Sphere { centre, radius }, transform));
    }
    // Cylinder: one principal curvature 0, the axis along its direction.
    let (flat, bent) = if k1.abs() < k2.abs() {
        (0, k2)
    } else {
        (1, k1)
    };
    let other = if flat == 0 { k1 } else { k2 };
    if other.abs() > 1e-9 * scale {
        return None;
    }
    let axis = curvature.directions?[flat].normalize_or_zero();
    if axis == DVec3::ZERO {
        return None;
    }
    let radius = 1.0 / bent.abs();
    let point = middle.point + normal / bent;
    let radial = |p: DVec3| {
        let r = p - point;
        r - axis * r.dot(axis)
    };
    let on_cylinder = samples.iter().all(|s| {
        let r = radial(s.point);
        (r.length() - radius).abs() <= tol && s.normal.cross(r).length() <= tol.max(1e-9 * radius)
    });
    if !on_cylinder {
        return None;
    }
    let outward = if bent < 0.0 { 1.0 } else { -1.0 };
    let factor = (radius + outward * distance) / radius;
    if factor.abs() < 1e-12 {
        return None;
    }
    // x' = point + a (a·r) + factor (r − a (a·r)), r = x − point.
    let along = DMat3::from_cols(axis * axis.x, axis * axis.y, axis * axis.z);
    let matrix = DMat3::IDENTITY * factor + along * (1.0 - factor);
    let transform = DAffine3::from_translation(point)
        * DAffine3::from_mat3(matrix)
        * DAffine3::from_translation(-point);
    Some((
        OffsetShape::Cylinder {
            point,
            axis,
            radius,
        },
        transform,
    ))
}

/// The centre and unit normal of the circle through three points (`None` when they are
/// nearly collinear).
fn circle_through(p0: DVec3, p1: DVec3, p2: DVec3) -> Option<(DVec3, DVec3)> {
    let (a, b) = (p1 - p0, p2 - p0);
    let n = a.cross(b);
    let nn = n.length_squared();
    if nn <= 1e-24 * a.length_squared() * b.length_squared() {
        return None;
    }
    let centre =
        p0 + (b.cross(n) * a.length_squared() + n.cross(a) * b.length_squared()) / (2.0 * nn);
    Some((centre, n / nn.sqrt()))
}

/// The offset of `surface` (clamped) as a surface of revolution about an axis along which u
/// runs around, its meridian (the v-curve at u₀) a line or a circle (see the module
/// documentation); `None` where it is not one.
fn revolution_offset(
    surface: &NurbsSurface,
    distance: f64,
    tol: f64,
) -> Option<(OffsetShape, NurbsSurface)> {
    let [(u0, u1), (v0, v1)] = surface.domain();
    // The axis: the circles of three u-curves share it.
    let mut circles = Vec::new();
    for f in [0.3, 0.5, 0.7] {
        let v = v0 + (v1 - v0) * f;
        let at = |t: f64| surface.point_at(u0 + (u1 - u0) * t, v).ok();
        circles.push(circle_through(at(0.0)?, at(0.3)?, at(0.6)?)?);
    }
    let (point, axis) = circles[0];
    let on_axis = |c: DVec3| (c - point).cross(axis).length() <= 1e3 * tol;
    if !circles
        .iter()
        .all(|&(c, n)| n.cross(axis).length() <= 1e-9 && on_axis(c))
    {
        return None;
    }
    let foot = |p: DVec3| point + axis * (p - point).dot(axis);
    // The meridian (the first row along v) and its offset in its plane.
    let [_, m] = surface.count();
    let h = surface.homogeneous_points();
    let meridian: Vec<DVec3> = (0..m).map(|j| h[j].truncate() / h[j].w).collect();
    let vm = 0.5 * (v0 + v1);
    let sample = |t: f64| surface.point_at(u0, v0 + (v1 - v0) * t).ok();
    let (first, middle, last) = (sample(0.0)?, sample(0.5)?, sample(1.0)?);
    let normal = surface.normal(u0, vm).ok()?;
    let moved: Vec<DVec3> = match circle_through(first, middle, last) {
        None => {
            // A line: every meridian point moves by d N.
            let along = (last - first).normalize_or_zero();
            let straight = (0..=8).all(|k| {
                sample(k as f64 / 8.0).is_some_and(|p| (p - first).cross(along).length() <= tol)
            });
            if !straight {
                return None;
            }
            meridian.iter().map(|&p| p + normal * distance).collect()
        }
        Some((centre, _)) => {
            // A circle: its points scale about the centre by (R ± d)/R.
            let radius = centre.distance(middle);
            let round = (0..=8).all(|k| {
                sample(k as f64 / 8.0).is_some_and(|p| (p.distance(centre) - radius).abs() <= tol)
            });
            if !round || radius <= tol {
                return None;
            }
            let outward = normal.dot((middle - centre) / radius).signum();
            let factor = (radius + outward * distance) / radius;
            meridian
                .iter()
                .map(|&p| centre + (p - centre) * factor)
                .collect()
        }
    };
    // g_i from the meridian point farthest from the axis; every row must follow it.
    let (far, reach) = meridian
        .iter()
        .enumerate()
        .map(|(j, &p)| (j, (p - foot(p)).length()))
        .max_by(|a, b| a.1.total_cmp(&b.1))?;
    if reach <= tol {
        return None;
    }
    let [n, _] = surface.count();
    let g: Vec<DVec3> = (0..n)
        .map(|i| {
            let q = h[i * m + far].truncate() / h[i * m + far].w;
            (q - foot(meridian[far])) / reach
        })
        .collect();
    for i in 0..n {
        for j in 0..m {
            let p = meridian[j];
            let rho = (p - foot(p)).length();
            let q = h[i * m + j].truncate() / h[i * m + j].w;
            if q.distance(foot(p) + g[i] * rho) > tol {
                return None;
            }
        }
    }
    let mut points = Vec::with_capacity(n * m);
    for (i, gi) in g.iter().enumerate() {
        for (j, &p) in moved.iter().enumerate() {
            let o = foot(p);
            let rho = (p - o).dot(g[0]);
            let w = h[i * m + j].w;
            points.push(((o + *gi * rho) * w).extend(w));
        }
    }
    let [p, q] = surface.degree();
    let [ku, kv] = surface.knots();
    let result =
        NurbsSurface::from_homogeneous([p, q], [ku.to_vec(), kv.to_vec()], [n, m], points).ok()?;
    Some((OffsetShape::Revolution { point, axis }, result))
}

/// The breaks of the fit along a direction: the surface's own span breaks, each span halved,
/// with multiplicity 3 − (p − m) clamped to 1..=3 where the surface's knot of multiplicity m
/// leaves it less than C² (so the fit may follow a crease in the normal).
fn fit_breaks(surface: &NurbsSurface, direction: Direction) -> Vec<(f64, usize)> {
    let d = direction.index();
    let p = surface.degree()[d];
    let knots = surface.knots()[d];
    let breaks = surface.span_breaks(direction);
    let mut out = Vec::new();
    for (i, w) in breaks.windows(2).enumerate() {
        let m = if i == 0 {
            1
        } else {
            crate::basis::multiplicity(knots, w[0])
        };
        let fitted = (3 + m).saturating_sub(p).clamp(1, 3);
        out.push((w[0], if i == 0 { 1 } else { fitted }));
        out.push((0.5 * (w[0] + w[1]), 1));
    }
    out.extend(breaks.last().map(|&b| (b, 1)));
    out
}

/// A clamped cubic knot vector with the given breaks (first and last get multiplicity 4).
fn cubic_knots(breaks: &[(f64, usize)]) -> Vec<f64> {
    let mut knots = Vec::new();
    let last = breaks.len() - 1;
    for (i, &(b, m)) in breaks.iter().enumerate() {
        let times = if i == 0 || i == last { 4 } else { m };
        knots.extend(std::iter::repeat_n(b, times));
    }
    knots
}

/// The Greville abscissae (t_{i+1} + t_{i+2} + t_{i+3}) / 3 of a cubic knot vector.
fn greville(knots: &[f64]) -> Vec<f64> {
    (0..knots.len() - 4)
        .map(|i| (knots[i + 1] + knots[i + 2] + knots[i + 3]) / 3.0)
        .collect()
}

/// The collocation matrix N_k(params[i]) of a cubic knot vector.
fn collocation(knots: &[f64], params: &[f64]) -> Vec<Vec<f64>> {
    let n = knots.len() - 4;
    let mut out = vec![vec![0.0; n]; params.len()];
    let mut basis = [0.0; 4];
    for (row, &t) in out.iter_mut().zip(params) {
        let span = find_span(knots, 3, n, t);
        basis_functions(knots, 3, span, t, &mut basis);
        for (k, b) in basis.iter().enumerate() {
            row[span - 3 + k] = *b;
        }
    }
    out
}

/// Solves `matrix` X = B for every column of B at once (`columns[c][i]` is row i of column c),
/// by Gaussian elimination with partial pivoting; `None` if singular.
fn solve_columns(mut matrix: Vec<Vec<f64>>, columns: &mut [Vec<DVec3>]) -> Option<()> {
    let n = matrix.len();
    for col in 0..n {
        let pivot =
            (col..n).max_by(|&a, &b| matrix[a][col].abs().total_cmp(&matrix[b][col].abs()))?;
        if !(matrix[pivot][col].abs() >= 1e-14) {
            return None;
        }
        matrix.swap(col, pivot);
        for c in columns.iter_mut() {
            c.swap(col, pivot);
        }
        for r in col + 1..n {
            let factor = matrix[r][col] / matrix[col][col];
            if factor == 0.0 {
                continue;
            }
            let (upper, lower) = matrix.split_at_mut(r);
            for (x, &y) in lower[0][col..].iter_mut().zip(&upper[col][col..]) {
                *x -= factor * y;
            }
            for c in columns.iter_mut() {
                let v = c[col];
                c[r] -= factor * v;
            }
        }
    }
    for c in columns.iter_mut() {
        for r in (0..n).rev() {
            let mut v = c[r];
            for k in r + 1..n {
                v -= matrix[r][k] * c[k];
            }
            c[r] = v / matrix[r][r];
        }
    }
    Some(())
}

/// The bicubic B-spline with the given breaks that interpolates `target` at the Greville grid.
fn interpolate_grid(
    breaks: &[Vec<(f64, usize)>; 2],
    target: &dyn Fn(f64, f64) -> Result<DVec3, GeometryError>,
) -> Result<NurbsSurface, GeometryError> {
    let knots = [cubic_knots(&breaks[0]), cubic_knots(&breaks[1])];
    let params = [greville(&knots[0]), greville(&knots[1])];
    let (nu, nv) = (params[0].len(), params[1].len());
    // Columns along u, one per v parameter.
    let mut columns: Vec<Vec<DVec3>> = Vec::with_capacity(nv);
    for &v in &params[1] {
        let mut column = Vec::with_capacity(nu);
        for &u in &params[0] {
            column.push(target(u, v)?);
        }
        columns.push(column);
    }
    let singular = || construction("offset", "the fit's collocation matrix is singular");
    solve_columns(collocation(&knots[0], &params[0]), &mut columns).ok_or_else(singular)?;
    // Rows along v, one per u index.
    let mut rows: Vec<Vec<DVec3>> = (0..nu)
        .map(|i| columns.iter().map(|c| c[i]).collect())
        .collect();
    solve_columns(collocation(&knots[1], &params[1]), &mut rows).ok_or_else(singular)?;
    let points = rows.into_iter().flatten().collect();
    NurbsSurface::new([3, 3], knots, [nu, nv], points, None)
}

/// Fits S + d N by bicubic interpolation, halving spans until the check samples agree within
/// `tolerance`; returns the fit and the largest difference found.
fn fitted_offset(
    face: &dyn ParametricSurface,
    normal: &dyn Fn(f64, f64) -> Option<DVec3>,
    mut breaks: [Vec<(f64, usize)>; 2],
    distance: f64,
    tolerance: f64,
) -> Result<(NurbsSurface, f64), GeometryError> {
    let target = |u: f64, v: f64| -> Result<DVec3, GeometryError> {
        let p = face.point(u, v);
        let n = normal(u, v);
        match (p, n) {
            (Some(p), Some(n)) => Ok(p + distance * n),
            _ => Err(construction(
                "offset",
                format!("the surface has no normal at (u, v) = ({u:.6}, {v:.6})"),
            )),
        }
    };
    // Aim a little inside the tolerance: the check samples are not every point.
    let aim = 0.5 * tolerance;
    loop {
        let fit = interpolate_grid(&breaks, &target)?;
        let spans = [breaks[0].len() - 1, breaks[1].len() - 1];
        let mut worst = [vec![0.0f64; spans[0]], vec![0.0f64; spans[1]]];
        let mut deviation = 0.0f64;
        const AT: [f64; 4] = [0.0, 1.0 / 6.0, 0.5, 5.0 / 6.0];
        for i in 0..spans[0] {
            let (u0, u1) = (breaks[0][i].0, breaks[0][i + 1].0);
            for j in 0..spans[1] {
                let (v0, v1) = (breaks[1][j].0, breaks[1][j + 1].0);
                for a in AT {
                    for b in AT {
                        let (u, v) = (u0 + (u1 - u0) * a, v0 + (v1 - v0) * b);
                        let error = fit.point_at(u, v)?.distance(target(u, v)?);
                        deviation = deviation.max(error);
                        worst[0][i] = worst[0][i].max(error);
                        worst[1][j] = worst[1][j].max(error);
                    }
                }
            }
        }
        if deviation <= aim {
            return Ok((fit, deviation));
        }
        let mut refined = false;
        for (d, list) in breaks.iter_mut().enumerate() {
            let bad: Vec<usize> = (0..worst[d].len()).filter(|&s| worst[d][s] > aim).collect();
            if bad.is_empty() || list.len() + bad.len() + 2 > MAX_OFFSET_POINTS {
                continue;
            }
            let mut next = Vec::with_capacity(list.len() + bad.len());
            for s in 0..list.len() - 1 {
                next.push(list[s]);
                if bad.contains(&s) {
                    next.push((0.5 * (list[s].0 + list[s + 1].0), 1));
                }
            }
            next.extend(list.last().copied());
            *list = next;
            refined = true;
        }
        if !refined {
            // At the size limit: the best fit, with its deviation reported.
            return Ok((fit, deviation));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::construct;

    fn distance_to(surface: &NurbsSurface, p: DVec3) -> f64 {
        surface
            .closest_point(p)
            .map(|c| c.point.distance(p))
            .unwrap_or(f64::INFINITY)
    }

    #[test]
    fn a_plane_moves_along_its_normal_exactly() {
        let plane = NurbsSurface::new(
            [1, 1],
            [vec![0.0, 0.0, 1.0, 1.0], vec![0.0, 0.0, 1.0, 1.0]],
            [2, 2],
            vec![
                DVec3::ZERO,
                DVec3::new(0.0, 2.0, 0.0),
                DVec3::new(3.0, 0.0, 0.0),
                DVec3::new(3.0, 2.0, 0.0),
            ],
            None,
        )
        .unwrap();
        let n = plane.normal(0.5, 0.5).unwrap();
        let o = offset_nurbs(&plane, 0.25, 1e-6).unwrap();
        assert_eq!(o.shape, OffsetShape::Plane);
        let p = o.surface.point_at(0.3, 0.7).unwrap();
        let q = plane.point_at(0.3, 0.7).unwrap() + 0.25 * n;
        assert!(p.distance(q) < 1e-12);
        assert!(o.folds.is_empty());
    }

    #[test]
    fn a_sphere_scales_about_its_centre_exactly_and_folds_past_its_radius() {
        let c = DVec3::new(1.0, -2.0, 0.5);
        let sphere = construct::sphere(c, 2.0).unwrap();
        let o = offset_nurbs(&sphere, 0.5, 1e-6).unwrap();
        assert!(
            matches!(o.shape, OffsetShape::Sphere { radius, .. } if (radius - 2.0).abs() < 1e-9)
        );
        for (u, v) in [(0.1, 0.2), (0.5, 0.5), (0.9, 0.99), (0.3, 0.0)] {
            let p = o.surface.point_at(u, v).unwrap();
            assert!((p.distance(c) - 2.5).abs() < 1e-12, "{}", p.distance(c));
        }
        assert!(o.folds.is_empty());
        let inward = offset_nurbs(&sphere, -0.5, 1e-6).unwrap();
        let p = inward.surface.point_at(0.4, 0.6).unwrap();
        assert!((p.distance(c) - 1.5).abs() < 1e-12);
        assert!(inward.folds.is_empty());
        let through = offset_nurbs(&sphere, -2.5, 1e-6).unwrap();
        assert!(through.fold_samples > 0);
        assert!((through.folds[0].radius - 2.0).abs() < 1e-6);
    }

    /// A single-span surface with its homogeneous points P_ij w_ij scaled by a^i b^j: the
    /// same surface under a rational linear reparametrisation in each direction (The NURBS
    /// Book §6.4), with other weights.
    fn reweighted(s: &NurbsSurface, a: f64, b: f64) -> NurbsSurface {
        let [_, m] = s.count();
        let points = s
            .homogeneous_points()
            .iter()
            .enumerate()
            .map(|(k, h)| *h * a.powi((k / m) as i32) * b.powi((k % m) as i32))
            .collect();
        let knots = s.knots().map(<[f64]>::to_vec);
        NurbsSurface::from_homogeneous(s.degree(), knots, s.count(), points).unwrap()
    }

    /// A 90° × 90° rational biquadratic sphere patch (latitudes −45° to 45°, a quarter turn
    /// of longitude) in general position: rotated about a skew axis, moved and scaled, with
    /// its weights changed by a rational reparametrisation (the same surface). Its offset lies
    /// on the concentric sphere at every parameter tried, not only at the corners.
    #[test]
    fn a_sphere_patch_in_general_position_offsets_to_the_concentric_sphere() {
        for (seed, &(axis, angle, centre, radius, d, lat0)) in [
            (
                DVec3::new(0.3, -0.8, 0.5),
                1.1,
                DVec3::new(3.0, -7.0, 2.5),
                4.0,
                0.75,
                -1.0,
            ),
            (
                DVec3::new(-0.2, 0.1, 0.9),
                2.7,
                DVec3::new(-120.0, 40.0, 9.0),
                250.0,
                -30.0,
                -1.0,
            ),
            (
                DVec3::new(1.0, 1.0, 0.0),
                0.4,
                DVec3::new(0.01, 0.02, -0.03),
                0.05,
                0.01,
                -1.0,
            ),
            // The octant: latitudes 0° to 90°, its last row collapsed at the pole.
            (
                DVec3::new(0.6, 0.3, -0.7),
                0.9,
                DVec3::new(5.0, 1.0, -2.0),
                3.0,
                0.75,
                0.0,
            ),
            (DVec3::new(0.0, 0.0, 1.0), 0.0, DVec3::ZERO, 3.0, 0.75, 0.0),
        ]
        .iter()
        .enumerate()
        {
            let profile = construct::arc(
                DVec3::ZERO,
                DVec3::X,
                DVec3::Z,
                1.0,
                lat0 * std::f64::consts::FRAC_PI_4,
                lat0 * std::f64::consts::FRAC_PI_4 + std::f64::consts::FRAC_PI_2,
            )
            .unwrap();
            let patch =
                construct::revolve(&profile, DVec3::ZERO, DVec3::Z, std::f64::consts::FRAC_PI_2)
                    .unwrap();
            let place = DAffine3::from_translation(centre)
                * DAffine3::from_axis_angle(axis.normalize(), angle)
                * DAffine3::from_scale(DVec3::splat(radius));
            let placed = patch.transformed(&place).unwrap();
            for surface in [placed.clone(), reweighted(&placed, 1.7, 0.6)] {
                let o = offset_nurbs(&surface, d, 1e-6 * radius).unwrap();
                assert!(
                    matches!(
                        o.shape,
                        OffsetShape::Sphere { .. } | OffsetShape::Revolution { .. }
                    ),
                    "seed {seed}: {:?}",
                    o.shape
                );
                let [(u0, u1), (v0, v1)] = o.surface.domain();
                for i in 0..=8 {
                    for j in 0..=8 {
                        let (u, v) = (
                            u0 + (u1 - u0) * i as f64 / 8.0,
                            v0 + (v1 - v0) * j as f64 / 8.0,
                        );
                        let p = o.surface.point_at(u, v).unwrap();
                        let off = (p.distance(centre) - (radius + d)).abs();
                        assert!(off < 1e-9 * radius, "seed {seed}: {off} at ({u}, {v})");
                    }
                }
            }
        }
    }

    #[test]
    fn a_cylinder_scales_across_its_axis_exactly() {
        let axis = DVec3::new(0.0, 1.0, 1.0);
        let cylinder = construct::cylinder(DVec3::new(0.5, 0.0, 0.0), axis, 1.5).unwrap();
        let o = offset_nurbs(&cylinder, 0.25, 1e-6).unwrap();
        assert!(
            matches!(o.shape, OffsetShape::Cylinder { .. }),
            "{:?}",
            o.shape
        );
        let a = axis.normalize();
        for (u, v) in [(0.1, 0.2), (0.5, 0.5), (0.9, 1.0)] {
            let r = o.surface.point_at(u, v).unwrap() - DVec3::new(0.5, 0.0, 0.0);
            let radial = (r - a * r.dot(a)).length();
            assert!((radial - 1.75).abs() < 1e-12, "{radial}");
        }
        // The same domain: the offset's points lie along the normal of the same parameters.
        let p = cylinder.point_at(0.3, 0.4).unwrap() + 0.25 * cylinder.normal(0.3, 0.4).unwrap();
        assert!(o.surface.point_at(0.3, 0.4).unwrap().distance(p) < 1e-12);
    }

    #[test]
    fn a_cone_offset_is_a_cone_at_the_distance() {
        // A truncated cone about z from radius 2 at z = 0 to 1 at z = 3: in the meridian plane
        // the line through (2, 0) and (1, 3), at distance |(ρ − 2)·3 + z·1| / √10 from it.
        let cone = construct::cone(DVec3::ZERO, DVec3::Z * 3.0, 2.0, 1.0).unwrap();
        for d in [0.3, -0.2] {
            let o = offset_nurbs(&cone, d, 1e-5).unwrap();
            assert!(
                matches!(o.shape, OffsetShape::Revolution { .. }),
                "{:?}",
                o.shape
            );
            let mut worst = 0.0f64;
            for i in 0..=20 {
                for j in 0..=20 {
                    let p = o
                        .surface
                        .point_at(i as f64 / 20.0, j as f64 / 20.0)
                        .unwrap();
                    let dist = ((p.x.hypot(p.y) - 2.0) * 3.0 + p.z).abs() / 10f64.sqrt();
                    worst = worst.max((dist - d.abs()).abs());
                }
            }
            assert!(worst < 1e-12, "d = {d}: {worst}");
        }
    }

    #[test]
    fn a_torus_offset_is_the_torus_of_the_tube_radius_r_plus_d() {
        let (major, minor) = (3.0, 1.0);
        let torus = construct::torus(DVec3::ZERO, DVec3::Z, major, minor).unwrap();
        let tolerance = 1e-5;
        for d in [0.4, -0.6] {
            let o = offset_nurbs(&torus, d, tolerance).unwrap();
            assert!(
                matches!(o.shape, OffsetShape::Revolution { axis, .. } if axis.cross(DVec3::Z).length() < 1e-9),
                "{:?}",
                o.shape
            );
            // Exact: the same net structure, the tube's radius changed.
            assert_eq!(o.surface.count(), torus.count());
            assert!(o.deviation <= 1e-9, "{}", o.deviation);
            assert!(o.folds.is_empty());
            // Distance to the torus in closed form: |√((ρ − R)² + z²) − r|.
            let mut worst = 0.0f64;
            for i in 0..=37 {
                for j in 0..=41 {
                    let p = o
                        .surface
                        .point_at(i as f64 / 37.0, j as f64 / 41.0)
                        .unwrap();
                    let rho = p.x.hypot(p.y);
                    let dist = ((rho - major).hypot(p.z) - minor).abs();
                    worst = worst.max((dist - d.abs()).abs());
                }
            }
            assert!(worst <= 1e-9, "d = {d}: {worst}");
        }
        // Inward by more than the tube's radius the offset folds everywhere.
        let folded = offset_nurbs(&torus, -1.2, 1e-3).unwrap();
        assert!(folded.fold_samples > 0);
    }

    #[test]
    fn a_bicubic_offset_lies_at_the_distance_from_the_surface() {
        let mut points = Vec::new();
        for i in 0..5 {
            for j in 0..6 {
                let (x, y) = (i as f64, j as f64 * 0.8);
                points.push(DVec3::new(x, y, 0.4 * (x * 0.9).sin() * (y * 1.1).cos()));
            }
        }
        let surface = construct::bspline_surface([3, 3], [5, 6], points).unwrap();
        let tolerance = 1e-5;
        let o = offset_nurbs(&surface, 0.3, tolerance).unwrap();
        assert_eq!(o.shape, OffsetShape::Fitted);
        assert_eq!(o.surface.domain(), surface.domain());
        for i in 1..20 {
            for j in 1..20 {
                let p = o
                    .surface
                    .point_at(i as f64 / 20.0, j as f64 / 20.0)
                    .unwrap();
                let d = distance_to(&surface, p);
                assert!((d - 0.3).abs() <= tolerance, "{d}");
            }
        }
    }

    #[test]
    fn bad_arguments_are_refused() {
        let sphere = construct::sphere(DVec3::ZERO, 1.0).unwrap();
        assert!(offset_nurbs(&sphere, f64::NAN, 1e-6).is_err());
        assert!(offset_nurbs(&sphere, 0.1, 0.0).is_err());
        assert!(offset_nurbs(&sphere, 0.1, -1.0).is_err());
    }
}
