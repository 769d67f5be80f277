//! Constructors of exact NURBS curves and surfaces: lines, polylines, circular arcs, curve
//! interpolation; planes, cylinders, cones, spheres, tori, surfaces of revolution, extrusions,
//! ruled surfaces, lofts, Coons patches and sweeps (the other transfinite surfaces — Hermite,
//! bicubically blended Coons and Gordon — are in [`super::transfinite`]).
//!
//! Circles are the exact rational quadratic form of The NURBS Book, A7.1 "MakeNurbsCircle"
//! (at most 90° per segment, middle weights cos(Δθ/2)); revolution is A8.1 "MakeRevolvedSurf".
//! Surfaces built by revolution put u around the axis (counter-clockwise seen from the axis tip)
//! and v along the profile, so a profile that rises on the axis's +x side has outward normals.

use std::f64::consts::{FRAC_PI_2, TAU};

use glam::{DVec3, DVec4};

use super::basis::uniform_clamped_knots;
use super::curve::{NurbsCurve, SpaceCurve};
use super::error::{GeometryError, Location, construction};
pub use super::interpolation::make_compatible;
use super::interpolation::skin;
use super::surface::NurbsSurface;
use super::vector::{CurvePoint, Vector};

fn check_finite(what: &'static str, values: &[f64]) -> Result<(), GeometryError> {
    if values.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(construction(what, "a parameter is not finite"))
    }
}

fn check_positive(what: &'static str, name: &str, value: f64) -> Result<(), GeometryError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(construction(what, format!("{name} = {value} must be > 0")))
    }
}

/// An orthonormal pair (x, y) perpendicular to `axis` (any choice; stable for all directions).
pub(crate) fn perpendicular_frame(axis: DVec3) -> (DVec3, DVec3) {
    let z = axis.normalize();
    let x = z.any_orthonormal_vector();
    (x, z.cross(x))
}

// ----- curves --------------------------------------------------------------------------------

/// The straight segment from `a` to `b`, degree 1 on [0, 1].
pub fn line<P: CurvePoint>(a: P, b: P) -> Result<NurbsCurve<P>, GeometryError> {
    NurbsCurve::new(1, vec![0.0, 0.0, 1.0, 1.0], vec![a, b], None)
}

/// A degree-1 curve through `points` on [0, 1], knots at the normalized cumulative chord length
/// (so the parameter is proportional to arc length).
pub fn polyline<P: CurvePoint>(points: &[P]) -> Result<NurbsCurve<P>, GeometryError> {
    if points.len() < 2 {
        return Err(construction("polyline", "needs at least 2 points"));
    }
    let params = chord_length_parameters(points, "polyline")?;
    let mut knots = vec![0.0];
    knots.extend_from_slice(&params);
    knots.push(1.0);
    NurbsCurve::new(1, knots, points.to_vec(), None)
}

/// An exact circular arc around `center` in the plane of the orthonormal axes `x`, `y`, from
/// angle `start` to `end` (radians, measured from x toward y; end > start, at most 2π apart),
/// as a rational quadratic on [0, 1] (The NURBS Book, A7.1).
pub fn arc(
    center: DVec3,
    x: DVec3,
    y: DVec3,
    radius: f64,
    start: f64,
    end: f64,
) -> Result<SpaceCurve, GeometryError> {
    check_finite("arc", &[center.x, center.y, center.z, start, end])?;
    check_positive("arc", "radius", radius)?;
    let sweep = end - start;
    if !(sweep > 0.0 && sweep <= TAU + 1e-12) {
        return Err(construction(
            "arc",
            format!("the sweep {sweep} must be in (0, 2π]"),
        ));
    }
    if x.length() < 1e-12 || y.length() < 1e-12 || x.cross(y).length() < 1e-12 {
        return Err(construction("arc", "the axes must be independent"));
    }
    let (x, y) = (x.normalize(), x.cross(y).cross(x).normalize());
    let arcs = (sweep / FRAC_PI_2 - 1e-9).ceil().max(1.0) as usize;
    let dtheta = sweep / arcs as f64;
    let w1 = (dtheta / 2.0).cos();
    let at = |angle: f64, r: f64| center + (x * angle.cos() + y * angle.sin()) * r;
    let mut points = vec![at(start, radius)];
    let mut weights = vec![1.0];
    let mut knots = vec![0.0; 3];
    for i in 1..=arcs {
        let angle = start + dtheta * i as f64;
        // The middle point: the intersection of the end tangents, at distance r / cos(Δθ/2).
        points.push(at(angle - dtheta / 2.0, radius / w1));
        weights.push(w1);
        points.push(at(angle, radius));
        weights.push(1.0);
        if i < arcs {
            let k = i as f64 / arcs as f64;
            knots.extend([k, k]);
        }
    }
    knots.extend([1.0; 3]);
    NurbsCurve::new(2, knots, points, Some(weights))
}

/// The full circle around `center` with unit normal `normal` (counter-clockwise seen from its
/// tip), starting on `x` (projected into the circle's plane), four 90° arcs.
pub fn circle(
    center: DVec3,
    normal: DVec3,
    x: DVec3,
    radius: f64,
) -> Result<SpaceCurve, GeometryError> {
    let n = normal.normalize_or_zero();
    let x = (x - n * x.dot(n)).normalize_or_zero();
    if n == DVec3::ZERO || x == DVec3::ZERO {
        return Err(construction(
            "circle",
            "the normal and x axis must be independent",
        ));
    }
    arc(center, x, n.cross(x), radius, 0.0, TAU)
}

/// The ellipse around `center` in the plane with unit normal `normal` (counter-clockwise seen
/// from its tip), with semi-axis `radii[0]` along `x` (projected into the plane) and `radii[1]`
/// across: the unit circle's rational quadratic scaled along the two axes, an affine map, so
/// the ellipse is exact.
pub fn ellipse(
    center: DVec3,
    normal: DVec3,
    x: DVec3,
    radii: [f64; 2],
) -> Result<SpaceCurve, GeometryError> {
    check_positive("ellipse", "first radius", radii[0])?;
    check_positive("ellipse", "second radius", radii[1])?;
    let unit = circle(DVec3::ZERO, normal, x, 1.0)?;
    let n = normal.normalize();
    let x = (x - n * x.dot(n)).normalize();
    let y = n.cross(x);
    unit.map_points(|p| center + x * (p.dot(x) * radii[0]) + y * (p.dot(y) * radii[1]))
}

/// The circular arc from `start` through `through` to `end` (three points not on a line): its
/// centre is their circumcentre, and it turns from `start` toward `through`. Exact.
pub fn arc_through(start: DVec3, through: DVec3, end: DVec3) -> Result<SpaceCurve, GeometryError> {
    let coordinates: Vec<f64> = [start, through, end]
        .iter()
        .flat_map(|p| p.to_array())
        .collect();
    check_finite("arc", &coordinates)?;
    let (a, b) = (through - start, end - start);
    let normal = a.cross(b);
    if !(normal.length() > 1e-12 * a.length().max(b.length()).powi(2)) {
        return Err(construction(
            "arc",
            "the three points are on one line (or two coincide)",
        ));
    }
    // The circumcentre: start + (|a|² (b × n) + |b|² (n × a)) / (2 |n|²), n = a × b.
    let center = start
        + (normal.cross(a) * b.length_squared() + b.cross(normal) * a.length_squared())
            / (2.0 * normal.length_squared());
    let radius = start.distance(center);
    let x = (start - center) / radius;
    let y = normal.normalize().cross(x);
    let angle_of = |p: DVec3| {
        let d = p - center;
        d.dot(y).atan2(d.dot(x)).rem_euclid(TAU)
    };
    arc(center, x, y, radius, 0.0, angle_of(end))
}

/// Chord-length parameters t_0 = 0 … t_n = 1 (The NURBS Book, eq. 9.5). Coincident
/// consecutive points are an error.
fn chord_length_parameters<V: Vector>(
    points: &[V],
    what: &'static str,
) -> Result<Vec<f64>, GeometryError> {
    super::splines::parameters(points, super::splines::Parametrization::ChordLength, what)
}

/// The non-rational B-spline of degree `degree` (lowered to points − 1 if there are too few
/// points) on [0, 1] through all `points`, with chord-length parameters and averaged knots
/// (The NURBS Book, A9.1).
pub fn interpolate<P: CurvePoint>(
    points: &[P],
    degree: usize,
) -> Result<NurbsCurve<P>, GeometryError> {
    super::splines::interpolate_through(
        points,
        degree,
        super::splines::Parametrization::ChordLength,
        None,
    )
}

// ----- making curves compatible --------------------------------------------------------------

// ----- surfaces ------------------------------------------------------------------------------

/// The bilinear patch through four corners: S(0,0) = p00, S(1,0) = p10, S(0,1) = p01,
/// S(1,1) = p11. Planar if the corners are coplanar.
pub fn bilinear(
    p00: DVec3,
    p10: DVec3,
    p01: DVec3,
    p11: DVec3,
) -> Result<NurbsSurface, GeometryError> {
    NurbsSurface::bezier([1, 1], vec![p00, p01, p10, p11], None)
}

/// The rectangle origin + s·u_axis + t·v_axis, s, t ∈ [0, 1] (normal u_axis × v_axis).
pub fn plane(origin: DVec3, u_axis: DVec3, v_axis: DVec3) -> Result<NurbsSurface, GeometryError> {
    if u_axis.cross(v_axis).length() <= 1e-300 {
        return Err(construction(
            "plane",
            "the two edge vectors must be independent",
        ));
    }
    bilinear(
        origin,
        origin + u_axis,
        origin + v_axis,
        origin + u_axis + v_axis,
    )
}

/// The surface swept by `curve` moved along `direction` (u along the curve, v ∈ [0, 1] along
/// the direction). Exact for rational curves.
pub fn extrude(curve: &SpaceCurve, direction: DVec3) -> Result<NurbsSurface, GeometryError> {
    check_finite("extrude", &direction.to_array())?;
    let n = curve.count();
    let mut points = Vec::with_capacity(2 * n);
    for &h in curve.homogeneous_points() {
        points.push(h);
        points.push(h + (direction * h.w).extend(0.0));
    }
    NurbsSurface::from_homogeneous(
        [curve.degree(), 1],
        [curve.knots().to_vec(), vec![0.0, 0.0, 1.0, 1.0]],
        [n, 2],
        points,
    )
}

/// The translational surface of `curve` moved along `path`: S(u, v) = C(u) + P(v) − P(v₀)
/// (u along the curve, v along the path). Exact for rational curves too: with control points
/// C_i + P_j − P(v₀) and weights w_i·ω_j, the numerator splits into C(u)·Σ M_j ω_j and
/// P(v)·Σ N_i w_i, so the quotient is C(u) + P(v).
pub fn extrude_along(curve: &SpaceCurve, path: &SpaceCurve) -> Result<NurbsSurface, GeometryError> {
    let start = path.point_at(path.domain().0)?;
    let (n, m) = (curve.count(), path.count());
    let mut points = Vec::with_capacity(n * m);
    for i in 0..n {
        let (c, w) = (curve.control_point(i), curve.weight(i));
        for j in 0..m {
            let (p, omega) = (path.control_point(j), path.weight(j));
            let weight = w * omega;
            points.push(((c + p - start) * weight).extend(weight));
        }
    }
    NurbsSurface::from_homogeneous(
        [curve.degree(), path.degree()],
        [curve.knots().to_vec(), path.knots().to_vec()],
        [n, m],
        points,
    )
}

/// The ruled surface S(u, v) = (1 − v) C0(u) + v C1(u), after making the curves compatible
/// (for rational curves this is the ruled surface between their homogeneous forms, which is the
/// standard NURBS ruled surface; The NURBS Book §8.3).
pub fn ruled(c0: &SpaceCurve, c1: &SpaceCurve) -> Result<NurbsSurface, GeometryError> {
    let polys = make_compatible(&[c0.clone(), c1.clone()])?;
    let n = polys[0].points.len();
    let mut points = Vec::with_capacity(2 * n);
    for i in 0..n {
        points.push(polys[0].points[i]);
        points.push(polys[1].points[i]);
    }
    NurbsSurface::from_homogeneous(
        [polys[0].degree, 1],
        [polys[0].knots.clone(), vec![0.0, 0.0, 1.0, 1.0]],
        [n, 2],
        points,
    )
}

/// The surface of revolution of `profile` about the axis through `origin` along `axis`, over
/// `angle` radians (0 < angle ≤ 2π; The NURBS Book, A8.1). u runs around the axis (circle
/// degree 2), v along the profile. Profile points on the axis give collapsed rows (poles).
pub fn revolve(
    profile: &SpaceCurve,
    origin: DVec3,
    axis: DVec3,
    angle: f64,
) -> Result<NurbsSurface, GeometryError> {
    check_finite(
        "revolve",
        &[origin.x, origin.y, origin.z, axis.x, axis.y, axis.z, angle],
    )?;
    if axis.length() <= 1e-300 {
        return Err(construction("revolve", "the axis has zero length"));
    }
    let z = axis.normalize();
    // The unit arc of the revolution, in a frame (x, y) to be rotated per profile point.
    let unit = arc(DVec3::ZERO, DVec3::X, DVec3::Y, 1.0, 0.0, angle)?;
    let arc_points: Vec<DVec4> = unit.homogeneous_points().to_vec();
    let m = profile.count();
    let n = arc_points.len();
    let mut points = vec![DVec4::ZERO; n * m];
    for j in 0..m {
        let pj = profile.control_point(j);
        let wj = profile.weight(j);
        let o = origin + z * (pj - origin).dot(z);
        let radial = pj - o;
        let r = radial.length();
        let (x, y) = if r > 1e-14 * (1.0 + pj.length()) {
            let x = radial / r;
            (x, z.cross(x))
        } else {
            (DVec3::ZERO, DVec3::ZERO)
        };
        for (i, a) in arc_points.iter().enumerate() {
            // Arc point in the unit frame: (a.x, a.y) / a.w at weight a.w.
            let (cx, cy, w) = (a.x / a.w, a.y / a.w, a.w);
            let p = o + (x * cx + y * cy) * r;
            points[i * m + j] = (p * (w * wj)).extend(w * wj);
        }
    }
    NurbsSurface::from_homogeneous(
        [2, profile.degree()],
        [unit.knots().to_vec(), profile.knots().to_vec()],
        [n, m],
        points,
    )
}

/// The closed cylinder side of radius `radius` around the axis from `base` to `base + axis`
/// (u around, v along the axis, outward normals). Degree (2, 1), exact.
pub fn cylinder(base: DVec3, axis: DVec3, radius: f64) -> Result<NurbsSurface, GeometryError> {
    check_positive("cylinder", "radius", radius)?;
    cone(base, axis, radius, radius)
}

/// The side of a (truncated) cone around the axis from `base` to `base + axis`, with radius
/// `base_radius` at the base and `top_radius` (≥ 0; 0 gives an apex) at the top. Exact.
pub fn cone(
    base: DVec3,
    axis: DVec3,
    base_radius: f64,
    top_radius: f64,
) -> Result<NurbsSurface, GeometryError> {
    check_finite("cone", &[base.x, base.y, base.z, axis.x, axis.y, axis.z])?;
    check_positive("cone", "base radius", base_radius)?;
    if !(top_radius.is_finite() && top_radius >= 0.0) {
        return Err(construction(
            "cone",
            format!("top radius = {top_radius} must be ≥ 0"),
        ));
    }
    if axis.length() <= 1e-300 {
        return Err(construction("cone", "the axis has zero length"));
    }
    let (x, _) = perpendicular_frame(axis);
    let profile = line(base + x * base_radius, base + axis + x * top_radius)?;
    revolve(&profile, base, axis, TAU)
}

/// The sphere of radius `radius` around `center`: a semicircle from the south to the north
/// pole (along +z) revolved about z. Degree (2, 2), exact, outward normals; the poles are
/// collapsed rows.
pub fn sphere(center: DVec3, radius: f64) -> Result<NurbsSurface, GeometryError> {
    check_positive("sphere", "radius", radius)?;
    let profile = arc(center, DVec3::X, DVec3::Z, radius, -FRAC_PI_2, FRAC_PI_2)?;
    revolve(&profile, center, DVec3::Z, TAU)
}

/// The torus around `center` with axis `axis`, major radius `major` (centre to tube centre)
/// and minor radius `minor` (tube), 0 < minor < major. Degree (2, 2), exact, outward normals.
/// v runs around the tube starting at the outer equator.
pub fn torus(
    center: DVec3,
    axis: DVec3,
    major: f64,
    minor: f64,
) -> Result<NurbsSurface, GeometryError> {
    check_positive("torus", "major radius", major)?;
    check_positive("torus", "minor radius", minor)?;
    if minor >= major {
        return Err(construction(
            "torus",
            "the minor radius must be smaller than the major radius",
        ));
    }
    if !(axis.length() > 1e-300) {
        return Err(construction("torus", "the axis has zero length"));
    }
    let (x, _) = perpendicular_frame(axis);
    let z = axis.normalize();
    let profile = arc(center + x * major, x, z, minor, 0.0, TAU)?;
    revolve(&profile, center, z, TAU)
}

/// A skinned (lofted) surface through the section curves (The NURBS Book, §10.3): the sections
/// are made compatible (u), then each column of homogeneous control points is interpolated
/// across the sections (v) with degree `degree_v` (lowered if there are too few sections),
/// parameters from the averaged chord lengths (eq. 10.8) and averaged knots. Section k is
/// reproduced exactly at v = v_k.
pub fn loft(sections: &[SpaceCurve], degree_v: usize) -> Result<NurbsSurface, GeometryError> {
    if sections.len() < 2 {
        return Err(construction("loft", "needs at least 2 sections"));
    }
    if degree_v == 0 {
        return Err(construction("loft", "the degree must be ≥ 1"));
    }
    let polys = make_compatible(sections)?;
    let q = degree_v.min(sections.len() - 1);
    let n = polys[0].points.len();
    let k = polys.len();
    // Averaged chord-length parameters over all columns (eq. 10.8).
    let mut params = vec![0.0; k];
    for i in 0..n {
        let column: Vec<DVec3> = polys.iter().map(|p| DVec3::project(p.points[i])).collect();
        let params_i = chord_length_parameters(&column, "loft").ok();
        match params_i {
            Some(t) => params
                .iter_mut()
                .zip(t)
                .for_each(|(a, b)| *a += b / n as f64),
            None => {
                return Err(construction(
                    "loft",
                    format!("control point {i} coincides in two consecutive sections"),
                ));
            }
        }
    }
    skin(&polys, &params, q, "loft")
}

/// The bilinearly blended Coons patch of four boundary curves (seed notes "Hermite and Coons
/// patches"; The NURBS Book §10.5 for the NURBS form): S = R_v + R_u − B, where R_v is the
/// ruled surface between `bottom` (v = 0) and `top` (v = 1), R_u the one between `left` (u = 0)
/// and `right` (u = 1), and B the bilinear patch of the corners; all three are brought to
/// common degrees and knots and their control points summed. The curves must be polynomial
/// (weights 1: a sum of rational surfaces with different weights is not a NURBS of this
/// form) and meet at the corners: bottom(0) = left(0), bottom(1) = right(0), top(0) = left(1),
/// top(1) = right(1).
pub fn coons(
    bottom: &SpaceCurve,
    top: &SpaceCurve,
    left: &SpaceCurve,
    right: &SpaceCurve,
) -> Result<NurbsSurface, GeometryError> {
    let corners = super::transfinite::meeting_corners([bottom, top, left, right], "coons")?;
    let rv = ruled(bottom, top)?; // degree (p, 1), u along bottom/top
    let ru = ruled(left, right)?.swap_uv(); // degree (1, q), v along left/right
    let corner = bilinear(corners[0], corners[1], corners[2], corners[3])?;
    super::transfinite::boolean_sum(&[rv, ru], &[corner], "coons")
}

/// A sweep of `profile` along `rail` with a rotation-minimizing frame (double reflection,
/// Wang, Jüttler, Zheng and Liu, "Computation of rotation minimizing frames", ACM TOG 2008).
/// The profile is given in space relative to the rail's start: it is carried to `sections`
/// frames along the rail (rigidly, by the rotation from the start frame) and the copies are
/// lofted with degree 3 in v. The sections are exact; between them the surface is the loft's
/// interpolant, so more sections follow a curved rail more closely (a general sweep has no exact
/// NURBS form).
pub fn sweep(
    profile: &SpaceCurve,
    rail: &SpaceCurve,
    sections: usize,
) -> Result<NurbsSurface, GeometryError> {
    if !(2..=1000).contains(&sections) {
        return Err(construction(
            "sweep",
            format!("sections = {sections} must be in 2..=1000"),
        ));
    }
    let rail = rail.reparametrized(0.0, 1.0)?;
    let params: Vec<f64> = (0..sections)
        .map(|k| k as f64 / (sections - 1) as f64)
        .collect();
    let frames = super::sweep::rotation_minimizing_frames(&rail, &params, "sweep")?;
    let start = frames[0];
    let copies = frames
        .iter()
        .map(|f| profile.map_points(|p| f.placed(start.local(p))))
        .collect::<Result<Vec<_>, _>>()?;
    loft(&copies, 3)
}

/// A degree (p, q) Bézier patch on [0, 1]² with control points on a flat grid of size
/// `width` × `depth` in the xy-plane, centred at the origin (the editor's "new patch").
pub fn flat_bezier_patch(
    degree: [usize; 2],
    width: f64,
    depth: f64,
) -> Result<NurbsSurface, GeometryError> {
    let [p, q] = degree;
    for (d, degree) in [p, q].into_iter().enumerate() {
        if !(1..=super::basis::MAX_DEGREE).contains(&degree) {
            return Err(GeometryError::Degree {
                at: Location::field("degree").index(d),
                degree,
                max: super::basis::MAX_DEGREE,
            });
        }
    }
    let mut points = Vec::with_capacity((p + 1) * (q + 1));
    for i in 0..=p {
        for j in 0..=q {
            points.push(DVec3::new(
                (i as f64 / p as f64 - 0.5) * width,
                (j as f64 / q as f64 - 0.5) * depth,
                0.0,
            ));
        }
    }
    NurbsSurface::bezier(degree, points, None)
}

/// A non-rational B-spline surface of degree (p, q) over uniform clamped knots with the given
/// control net (row-major, i along u).
pub fn bspline_surface(
    degree: [usize; 2],
    count: [usize; 2],
    points: Vec<DVec3>,
) -> Result<NurbsSurface, GeometryError> {
    for (d, (&p, &c)) in degree.iter().zip(&count).enumerate() {
        if c < p + 1 {
            return Err(GeometryError::TooFewControlPoints {
                at: Location::field("knots").index(d),
                count: c,
                degree: p,
            });
        }
    }
    NurbsSurface::new(
        degree,
        [
            uniform_clamped_knots(degree[0], count[0]),
            uniform_clamped_knots(degree[1], count[1]),
        ],
        count,
        points,
        None,
    )
}
