//! Continuity across shared edges (G0 / G1 / G2 with numbers), as CAD tools measure it
//! (Rhino's GCon, on every edge at once).
//!
//! Faces are parametric surfaces over a rectangle, optionally trimmed
//! ([`ParametricSurface`]). Two face sides share an
//! edge when their boundary curves lie within a matching distance of each other over their
//! whole length (either direction; one face's two sides too, a closed surface's seam). The
//! matching distance is a share of the size of the smaller of the two faces' objects
//! ([`shared_edges_scaled`]): in a scene of objects set apart, the scene's size would make two
//! neighbouring boundaries of one small object (a teapot's rim, top and bottom) look like one
//! edge with a gap. Along a
//! shared edge, at samples uniform in the first side's parameter, the closest point of the
//! other side is found by Newton's method on the boundary curve, and there:
//! - **G0**: the gap |Sa − Sb|;
//! - **G1**: the angle between the two faces' tangent planes, measured as the angle between
//!   the inward cross-boundary directions ta and −tb (each the interior derivative with its
//!   component along the edge removed). For consistently oriented faces it is the angle between
//!   the normals; it does not depend on either face's orientation or parametrization;
//! - **G2**: the difference of the normal curvatures in the cross-boundary directions,
//!   κ = II(t) / I(t) (do Carmo §3.2), each taken about the normal e × t of the face's own
//!   side, so that a smooth continuation compares like with like; absolute and relative to the
//!   larger of the two.

use glam::DVec3;

use super::SurfaceDerivatives;
use super::parametric::ParametricSurface;

/// A side of a face's parameter rectangle (serde: "u0", "u1", "v0", "v1").
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "lowercase")]
pub enum Side {
    /// u = u0 (v runs along the edge).
    U0,
    U1,
    /// v = v0 (u runs along the edge).
    V0,
    V1,
}

impl Side {
    pub const ALL: [Side; 4] = [Side::U0, Side::U1, Side::V0, Side::V1];

    /// "u0", "u1", "v0", "v1".
    pub fn name(self) -> &'static str {
        match self {
            Side::U0 => "u0",
            Side::U1 => "u1",
            Side::V0 => "v0",
            Side::V1 => "v1",
        }
    }

    /// The parameter (u, v) of the side at t in [0, 1] and the parameter-space derivative of
    /// that point with respect to t.
    pub(crate) fn parameter(self, domain: [(f64, f64); 2], t: f64) -> ((f64, f64), (f64, f64)) {
        let [(u0, u1), (v0, v1)] = domain;
        let along_u = u0 + t * (u1 - u0);
        let along_v = v0 + t * (v1 - v0);
        match self {
            Side::U0 => ((u0, along_v), (0.0, v1 - v0)),
            Side::U1 => ((u1, along_v), (0.0, v1 - v0)),
            Side::V0 => ((along_u, v0), (u1 - u0, 0.0)),
            Side::V1 => ((along_u, v1), (u1 - u0, 0.0)),
        }
    }

    /// The derivative pointing into the face's interior, across this side.
    pub(crate) fn inward(self, d: &SurfaceDerivatives) -> DVec3 {
        match self {
            Side::U0 => d.su,
            Side::U1 => -d.su,
            Side::V0 => d.sv,
            Side::V1 => -d.sv,
        }
    }
}

/// The verdict on one shared edge.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Continuity {
    /// The gap exceeds the distance tolerance.
    Open,
    G0,
    G1,
    G2,
}

impl Continuity {
    /// "open", "G0", "G1", "G2".
    pub fn name(self) -> &'static str {
        match self {
            Continuity::Open => "open",
            Continuity::G0 => "G0",
            Continuity::G1 => "G1",
            Continuity::G2 => "G2",
        }
    }
}

/// What counts as shared and what passes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tolerances {
    /// Boundary curves closer than this everywhere share an edge.
    pub matching: f64,
    /// The largest gap that passes G0.
    pub distance: f64,
    /// The largest angle between the tangent planes (degrees) that passes G1.
    pub angle_degrees: f64,
    /// The largest relative difference of normal curvature that passes G2.
    pub curvature: f64,
    /// Samples along each edge (at least 2).
    pub samples: usize,
}

/// One sample along a shared edge.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EdgeSample {
    /// The point on the first face.
    pub point: DVec3,
    /// The first face's unit normal there (for drawing).
    pub normal: DVec3,
    pub gap: f64,
    pub angle_degrees: f64,
    /// |κa − κb| (None where a curvature is undefined).
    pub curvature_difference: Option<f64>,
    pub relative_curvature_difference: Option<f64>,
}

/// The largest value of one measure along an edge and where it is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Maximum {
    pub value: f64,
    pub at: DVec3,
}

/// The continuity of one shared edge: face `a`'s side against face `b`'s.
#[derive(Debug, Clone, PartialEq)]
pub struct SharedEdge {
    pub a: (usize, Side),
    pub b: (usize, Side),
    /// Whether b's side runs the opposite way to a's.
    pub reversed: bool,
    pub samples: Vec<EdgeSample>,
    pub max_gap: Maximum,
    pub max_angle_degrees: Maximum,
    pub max_curvature_difference: Maximum,
    pub max_relative_curvature_difference: Maximum,
    pub verdict: Continuity,
}

/// Boundary samples of one face side used for matching.
struct SideCurve {
    face: usize,
    side: Side,
    points: Vec<DVec3>,
    lo: DVec3,
    hi: DVec3,
}

/// Points per side for matching.
const MATCH_POINTS: usize = 17;
/// How far inside the domain (as a share of its size) trims are asked about boundary points.
const TRIM_NUDGE: f64 = 1e-6;

fn side_point(face: &dyn ParametricSurface, side: Side, t: f64) -> Option<DVec3> {
    let ((u, v), _) = side.parameter(face.domain(), t);
    face.derivatives(u, v).map(|d| d.point)
}

/// Whether the trims keep the side's point at t (asked just inside the domain).
fn side_kept(face: &dyn ParametricSurface, side: Side, t: f64) -> bool {
    let domain = face.domain();
    let ((u, v), _) = side.parameter(domain, t);
    let [(u0, u1), (v0, v1)] = domain;
    let (du, dv) = (TRIM_NUDGE * (u1 - u0), TRIM_NUDGE * (v1 - v0));
    let (u, v) = match side {
        Side::U0 => (u + du, v),
        Side::U1 => (u - du, v),
        Side::V0 => (u, v + dv),
        Side::V1 => (u, v - dv),
    };
    face.keeps(u, v)
}

/// Distance from p to the polyline.
fn polyline_distance(points: &[DVec3], p: DVec3) -> f64 {
    points
        .windows(2)
        .map(|w| super::vector::distance_to_segment(p, w[0], w[1]))
        .fold(f64::INFINITY, f64::min)
}

/// The parameter t in [0, 1] of the point of `side` closest to `target`, from the start `t0`:
/// Newton's method on f(t) = (C(t) − p)·C′(t), f′ = C′·C′ + (C − p)·C″ (The NURBS Book §6.1),
/// clamped to the side.
fn closest_on_side(face: &dyn ParametricSurface, side: Side, target: DVec3, t0: f64) -> f64 {
    let domain = face.domain();
    let mut t = t0;
    for _ in 0..30 {
        let ((u, v), (du, dv)) = side.parameter(domain, t);
        let Some(d) = face.derivatives(u, v) else {
            break;
        };
        let c1 = d.su * du + d.sv * dv;
        let c2 = d.suu * du * du + 2.0 * d.suv * du * dv + d.svv * dv * dv;
        let r = d.point - target;
        let f = r.dot(c1);
        let fp = c1.dot(c1) + r.dot(c2);
        if !(fp > 0.0) {
            break;
        }
        let next = (t - f / fp).clamp(0.0, 1.0);
        if (next - t).abs() < 1e-14 {
            t = next;
            break;
        }
        t = next;
    }
    t
}

/// What one face gives at a point of its side: derivatives, the unit edge tangent, the inward
/// cross-boundary direction and the normal about which its curvature is taken.
struct SideFrame {
    d: SurfaceDerivatives,
    inward: DVec3,
    normal: DVec3,
}

fn side_frame(face: &dyn ParametricSurface, side: Side, t: f64, edge: DVec3) -> Option<SideFrame> {
    let ((u, v), _) = side.parameter(face.domain(), t);
    let d = face.derivatives(u, v)?;
    let inward = side.inward(&d);
    let inward = (inward - inward.dot(edge) * edge).try_normalize()?;
    Some(SideFrame {
        d,
        inward,
        normal: edge.cross(inward),
    })
}

/// The normal curvature II(w)/I(w) of the surface with derivatives `d` in the tangent direction
/// `w`, about the unit normal `normal`: w = αSu + βSv solved from the first fundamental form,
/// then (Lα² + 2Mαβ + Nβ²) / (Eα² + 2Fαβ + Gβ²).
pub fn normal_curvature(d: &SurfaceDerivatives, normal: DVec3, w: DVec3) -> Option<f64> {
    let forms = super::FundamentalForms::new(d, normal);
    let det = forms.determinant();
    if !(det > 0.0) || !det.is_finite() {
        return None;
    }
    let (a1, a2) = (w.dot(d.su), w.dot(d.sv));
    let alpha = (forms.g * a1 - forms.f * a2) / det;
    let beta = (forms.e * a2 - forms.f * a1) / det;
    let first = forms.e * alpha * alpha + 2.0 * forms.f * alpha * beta + forms.g * beta * beta;
    let second = forms.l * alpha * alpha + 2.0 * forms.m * alpha * beta + forms.n * beta * beta;
    let k = second / first;
    (first > 0.0 && k.is_finite()).then_some(k)
}

/// Every shared edge between the faces (and between two sides of one face), with its numbers.
/// `size` is the scene's size, the scale below which curvatures count as zero for the relative
/// difference (1e-4 / size).
pub fn shared_edges(
    faces: &[&dyn ParametricSurface],
    tolerances: &Tolerances,
    size: f64,
) -> Vec<SharedEdge> {
    shared_edges_scaled(faces, &vec![size; faces.len()], tolerances, size)
}

/// [`shared_edges`] where each face has a size of its own, `scales[k]` (its object's box
/// diagonal): two sides share an edge when they lie within `tolerances.matching × s / size`
/// of each other, s the smaller of their faces' scales (capped at `size`).
pub fn shared_edges_scaled(
    faces: &[&dyn ParametricSurface],
    scales: &[f64],
    tolerances: &Tolerances,
    size: f64,
) -> Vec<SharedEdge> {
    let scale = |face: usize| {
        let s = scales.get(face).copied().unwrap_or(size);
        if s.is_finite() && s > 0.0 && s < size {
            s / size
        } else {
            1.0
        }
    };
    let sides = side_curves(faces, |face| tolerances.matching * scale(face));
    let mut edges = Vec::new();
    for (i, a) in sides.iter().enumerate() {
        for b in &sides[i + 1..] {
            let matching = tolerances.matching * scale(a.face).min(scale(b.face));
            let far = (a.lo - b.hi).max(b.lo - a.hi).max_element();
            if far > matching {
                continue;
            }
            let within = |from: &SideCurve, to: &SideCurve| {
                from.points
                    .iter()
                    .all(|&p| polyline_distance(&to.points, p) <= matching)
            };
            if !(within(a, b) && within(b, a)) {
                continue;
            }
            let reversed = a.points[0].distance(b.points[0])
                > a.points[0].distance(b.points[MATCH_POINTS - 1]);
            if let Some(edge) = measure(faces, a, b, reversed, tolerances, size) {
                edges.push(edge);
            }
        }
    }
    edges
}

/// The matching samples of every face side that is not degenerate (shorter than the matching
/// distance) nor mostly trimmed away.
/// `matching(face)`: the face's matching distance, under which a side counts as degenerate.
fn side_curves(
    faces: &[&dyn ParametricSurface],
    matching: impl Fn(usize) -> f64,
) -> Vec<SideCurve> {
    let mut sides = Vec::new();
    for (face_index, &face) in faces.iter().enumerate() {
        for side in Side::ALL {
            let ts: Vec<f64> = (0..MATCH_POINTS)
                .map(|k| k as f64 / (MATCH_POINTS - 1) as f64)
                .collect();
            let kept = ts.iter().filter(|&&t| side_kept(face, side, t)).count();
            if 2 * kept < MATCH_POINTS {
                continue;
            }
            let Some(points) = ts
                .iter()
                .map(|&t| side_point(face, side, t))
                .collect::<Option<Vec<DVec3>>>()
            else {
                continue;
            };
            let length: f64 = points.windows(2).map(|w| w[0].distance(w[1])).sum();
            if !(length > matching(face_index)) {
                continue;
            }
            let lo = points
                .iter()
                .copied()
                .reduce(DVec3::min)
                .unwrap_or_default();
            let hi = points
                .iter()
                .copied()
                .reduce(DVec3::max)
                .unwrap_or_default();
            sides.push(SideCurve {
                face: face_index,
                side,
                points,
                lo,
                hi,
            });
        }
    }
    sides
}

/// The parameter of side `b` closest to `target`: Newton's method from each of the two nearest
/// matching samples, the better result. A closed side (a seam) has the same point at both ends,
/// and from the wrong one Newton stops at the clamp, a whole period away.
fn closest_on_side_from_samples(face: &dyn ParametricSurface, b: &SideCurve, target: DVec3) -> f64 {
    let mut order: Vec<usize> = (0..b.points.len()).collect();
    order.sort_by(|&x, &y| {
        b.points[x]
            .distance(target)
            .total_cmp(&b.points[y].distance(target))
    });
    let distance =
        |t: f64| side_point(face, b.side, t).map_or(f64::INFINITY, |p| p.distance(target));
    order
        .iter()
        .take(2)
        .map(|&k| closest_on_side(face, b.side, target, k as f64 / (MATCH_POINTS - 1) as f64))
        .min_by(|&x, &y| distance(x).total_cmp(&distance(y)))
        .unwrap_or(0.5)
}

fn measure(
    faces: &[&dyn ParametricSurface],
    a: &SideCurve,
    b: &SideCurve,
    reversed: bool,
    tolerances: &Tolerances,
    size: f64,
) -> Option<SharedEdge> {
    let (fa, fb) = (faces[a.face], faces[b.face]);
    let n = tolerances.samples.max(2);
    let floor = 1e-4 / size.max(f64::MIN_POSITIVE);
    let mut samples = Vec::with_capacity(n);
    for k in 0..n {
        let t = k as f64 / (n - 1) as f64;
        if !side_kept(fa, a.side, t) {
            continue;
        }
        let ((u, v), (du, dv)) = a.side.parameter(fa.domain(), t);
        let Some(da) = fa.derivatives(u, v) else {
            continue;
        };
        let Some(edge) = (da.su * du + da.sv * dv).try_normalize() else {
            continue;
        };
        let tb = closest_on_side_from_samples(fb, b, da.point);
        if !side_kept(fb, b.side, tb) {
            continue;
        }
        let (Some(sa), Some(sb)) = (
            side_frame(fa, a.side, t, edge),
            side_frame(fb, b.side, tb, edge),
        ) else {
            continue;
        };
        let gap = sa.d.point.distance(sb.d.point);
        let angle_degrees = (-sa.inward.dot(sb.inward))
            .clamp(-1.0, 1.0)
            .acos()
            .to_degrees();
        // b's curvature about the normal of a smooth continuation of a: e × (−tb).
        let ka = normal_curvature(&sa.d, sa.normal, sa.inward);
        let kb = normal_curvature(&sb.d, -sb.normal, sb.inward);
        let (difference, relative) = match (ka, kb) {
            (Some(ka), Some(kb)) => {
                let difference = (ka - kb).abs();
                (
                    Some(difference),
                    Some(difference / ka.abs().max(kb.abs()).max(floor)),
                )
            }
            _ => (None, None),
        };
        let normal = sa.d.regular_normal().unwrap_or(sa.normal);
        samples.push(EdgeSample {
            point: sa.d.point,
            normal,
            gap,
            angle_degrees,
            curvature_difference: difference,
            relative_curvature_difference: relative,
        });
    }
    if samples.is_empty() {
        return None;
    }
    let maximum = |value: &dyn Fn(&EdgeSample) -> Option<f64>| {
        samples
            .iter()
            .filter_map(|s| value(s).map(|v| (v, s.point)))
            .max_by(|x, y| x.0.total_cmp(&y.0))
            .map_or(
                Maximum {
                    value: 0.0,
                    at: samples[0].point,
                },
                |(value, at)| Maximum { value, at },
            )
    };
    let max_gap = maximum(&|s| Some(s.gap));
    let max_angle_degrees = maximum(&|s| Some(s.angle_degrees));
    let max_curvature_difference = maximum(&|s| s.curvature_difference);
    let max_relative_curvature_difference = maximum(&|s| s.relative_curvature_difference);
    let verdict = if max_gap.value > tolerances.distance {
        Continuity::Open
    } else if max_angle_degrees.value > tolerances.angle_degrees {
        Continuity::G0
    } else if max_relative_curvature_difference.value > tolerances.curvature {
        Continuity::G1
    } else {
        Continuity::G2
    };
    Some(SharedEdge {
        a: (a.face, a.side),
        b: (b.face, b.side),
        reversed,
        samples,
        max_gap,
        max_angle_degrees,
        max_curvature_difference,
        max_relative_curvature_difference,
        verdict,
    })
}
