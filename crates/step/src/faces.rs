//! STEP faces as trimmed NURBS: an `ADVANCED_FACE`'s surface becomes an exact NURBS surface
//! over just the part of it the face covers, and its edge loops become trim loops in that
//! surface's (u, v) domain, computed from the edges' 3D curves (the file's p-curves are not
//! needed, and a face without them reads the same).
//!
//! - **Analytic surfaces** (plane, cylinder, cone, sphere, torus, surfaces of revolution) are
//!   rational NURBS built over the face's range of STEP's own parameters (angles, heights), so
//!   every point of an edge has closed-form parameters: the angle maps to the rational circle's
//!   parameter by t = ½ + tan((α − h)/2) / (2 tan(h/2)) in each arc of half-sweep h (the
//!   rational quadratic arc is the tan-half-angle parametrization, The NURBS Book §7.3). A
//!   face that does not go all the way round gets a surface that starts at its first angle; one
//!   that does has the file's seam, and its loops are cut where they cross the seam. A piece of
//!   loop lying on the seam takes the side the face is on (the face lies left of its loops seen
//!   along the face's normal, ISO 10303-42), points at a pole take the angle of their
//!   neighbours, and a loop that goes round the axis once (a cap) is closed through its pole.
//!   Edges along iso-lines (circles of a cylinder, meridians) are exact lines in (u, v), and
//!   every edge of a plane is its exact NURBS curve mapped into the plane's (u, v).
//! - **B-spline surfaces** keep their knots, points and weights; their loops come from point
//!   inversion (Newton's iteration from the previous point, The NURBS Book §6.1). Linear
//!   extrusions are built as NURBS over the face's range and read the same way.
//!
//! Elsewhere a loop is a polyline in (u, v) whose image stays within the trim tolerance of the
//! edge (checked at the middle of every chord).

use std::f64::consts::{FRAC_PI_2, PI, TAU};
use std::sync::atomic::{AtomicUsize, Ordering};

use glam::{DMat3, DVec2, DVec3};

use super::entities::{Curve3, Frame, Surface3};
use crate::kernel::{NurbsSurface, SpaceCurve, TrimCurve, TrimmedSurface, construct};

/// One edge: its curve between its vertices.
#[derive(Debug, Clone)]
pub struct EdgeGeometry {
    pub curve: Curve3,
    pub t0: f64,
    pub t1: f64,
    pub start: DVec3,
    pub end: DVec3,
    /// The file's p-curves of the edge: (surface id, the curve in its (u, v) at z = 0).
    pub pcurves: Vec<(u64, Curve3)>,
}

impl EdgeGeometry {
    /// The edge from `start` to `end` along `curve` (`same_sense` false: against the curve's
    /// direction). A closed curve gives the whole period when the ends coincide.
    pub fn new(
        mut curve: Curve3,
        start: DVec3,
        end: DVec3,
        same_sense: bool,
        tolerance: f64,
    ) -> Self {
        let mut t0 = curve.parameter_of(start);
        let mut t1 = curve.parameter_of(end);
        let closed = start.distance(end) <= tolerance;
        if let Some(period) = curve.period() {
            if same_sense {
                while t1 <= t0 + 1e-12 {
                    t1 += period;
                }
                if !closed && t1 - t0 > period {
                    t1 -= period;
                }
            } else {
                while t1 >= t0 - 1e-12 {
                    t1 -= period;
                }
                if !closed && t0 - t1 > period {
                    t1 += period;
                }
            }
        } else if let Curve3::Spline(c) = &curve
            && c.ends().is_ok_and(|(a, b)| a.distance(b) <= tolerance)
        {
            // A closed B-spline: the edge may run across the curve's own seam, or round
            // from a vertex that is not at it. The seam moves to the edge's start then (the
            // same curve), and the edge runs within the domain.
            let (a, b) = c.domain();
            let period = b - a;
            let near = |t: f64, x: f64| (t - x).abs() <= 1e-9 * period;
            let (first, last) = if same_sense { (a, b) } else { (b, a) };
            if near(t0, last) {
                t0 = first;
            }
            if near(t1, first) {
                t1 = last;
            }
            let wraps = closed || if same_sense { t1 < t0 } else { t1 > t0 };
            if wraps && !near(t0, first) {
                if let Ok(moved) = c.moved_seam(t0, tolerance) {
                    let along = if closed { t0 } else { t1 };
                    (t0, t1) = if same_sense {
                        (t0, along + period)
                    } else {
                        (t0 + period, along)
                    };
                    curve = Curve3::Spline(moved);
                }
            } else if closed {
                (t0, t1) = (first, last);
            }
        }
        Self {
            curve,
            t0,
            t1,
            start,
            end,
            pcurves: Vec::new(),
        }
    }

    /// The point at s ∈ [0, 1] from start to end.
    pub fn point(&self, s: f64) -> DVec3 {
        if s <= 0.0 {
            return self.start;
        }
        if s >= 1.0 {
            return self.end;
        }
        self.curve.point(self.t0 + (self.t1 - self.t0) * s)
    }

    /// The edge as an exact NURBS curve from start to end.
    pub fn nurbs(&self) -> Result<SpaceCurve, crate::kernel::GeometryError> {
        self.curve.piece(self.t0, self.t1)
    }
}

/// What a curve of a built face's loop lies on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CurveOrigin {
    /// The file's edge `id`, traversed start to end when `forward`.
    Edge { id: u64, forward: bool },
    /// One side of a seam closed by the reader: the two curves with the same number meet.
    Seam(usize),
    /// A connector the reader added (through a pole, or along the domain's side).
    Added,
}

/// One use of an edge in a loop.
#[derive(Debug, Clone)]
pub struct LoopEdge {
    pub id: u64,
    pub forward: bool,
    pub geometry: std::sync::Arc<EdgeGeometry>,
}

/// A face's bound: its edges in order, and whether the bound is used as written.
#[derive(Debug, Clone)]
pub struct Bound {
    pub edges: Vec<LoopEdge>,
    pub orientation: bool,
}

/// A face built: its trimmed surface and what each loop curve lies on.
pub struct BuiltFace {
    pub face: TrimmedSurface,
    pub origins: Vec<Vec<CurveOrigin>>,
}

/// How a natural parameter (an angle, a height) maps to the NURBS surface's parameter.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Range {
    /// An angle relative to `start`, over a rational arc of `span` (≤ 2π) on [0, 1]; `full`
    /// when it goes all the way round.
    Angle { start: f64, span: f64, full: bool },
    /// A non-periodic angle from `lo` over `span`, a rational arc on [0, 1] (a sphere's
    /// latitude).
    Arc { lo: f64, span: f64 },
    /// Linear from [lo, hi] to [0, 1].
    Linear { lo: f64, hi: f64 },
    /// The parameter as it is (B-splines, the meridian of a revolution) over [lo, hi].
    Raw { lo: f64, hi: f64 },
    /// A closed B-spline direction [lo, hi] (its two ends meet: the surface's own seam), read
    /// as an angle: x ∈ [0, 2π] ↦ lo + (hi − lo)·x / 2π.
    Closed { lo: f64, hi: f64 },
}

/// The rational arc's parameter (on [0, 1]) of the angle `x` ∈ [0, span] along it: the arc is
/// made of ⌈span / 90°⌉ equal arcs ([`construct::arc`]), each on an equal knot interval.
pub fn arc_parameter(x: f64, span: f64) -> f64 {
    let arcs = (span / FRAC_PI_2 - 1e-9).ceil().max(1.0);
    let d = span / arcs;
    let x = x.clamp(0.0, span);
    let i = (x / d).floor().min(arcs - 1.0);
    let local = x - i * d;
    let h = d / 2.0;
    let s = ((local - h) / 2.0).tan() / (h / 2.0).tan();
    ((i + (1.0 + s) / 2.0) / arcs).clamp(0.0, 1.0)
}

impl Range {
    /// The surface parameter of `x` (for an angle, relative to its start, unwrapped into
    /// [0, span]).
    fn parameter(&self, x: f64) -> f64 {
        match *self {
            Range::Angle { span, .. } => arc_parameter(x, span),
            Range::Arc { lo, span } => arc_parameter(x - lo, span),
            Range::Linear { lo, hi } => ((x - lo) / (hi - lo)).clamp(0.0, 1.0),
            Range::Raw { lo, hi } => x.clamp(lo, hi),
            Range::Closed { lo, hi } => lo + (hi - lo) * (x / TAU).clamp(0.0, 1.0),
        }
    }

    fn bounds(&self) -> (f64, f64) {
        match *self {
            Range::Raw { lo, hi } | Range::Closed { lo, hi } => (lo, hi),
            _ => (0.0, 1.0),
        }
    }

    fn full(&self) -> bool {
        matches!(self, Range::Angle { full: true, .. } | Range::Closed { .. })
    }

    /// How far apart in (u, v) the two sides of a full range's seam are.
    fn seam_width(&self) -> f64 {
        let (lo, hi) = self.bounds();
        hi - lo
    }
}

fn wrap(a: f64) -> f64 {
    let w = a.rem_euclid(TAU);
    if w > PI { w - TAU } else { w }
}

/// One sample of a loop: the point, its natural parameters (NaN: an angle undefined at a pole),
/// and its parameter along its edge.
#[derive(Debug, Clone, Copy)]
struct Sample {
    p: DVec3,
    n: [f64; 2],
    s: f64,
    pole: bool,
}

/// Natural parameters and their inverse for one surface.
struct Natural<'a> {
    surface: &'a Surface3,
    /// The NURBS for B-splines and extrusions (natural = its (u, v)).
    nurbs: Option<&'a NurbsSurface>,
    periodic: [bool; 2],
    /// The domain of each closed direction of `nurbs`, whose natural parameter is then an
    /// angle (its seam at 0).
    closed: [Option<(f64, f64)>; 2],
    small: f64,
    /// The sides of `nurbs` collapsed to a point (a B-spline's pole): the direction whose
    /// parameter is fixed on the side, and the point. A sample there has no parameter along
    /// the side; it takes its neighbours' ([`fill_poles`]).
    collapsed: Vec<(usize, f64, DVec3)>,
    /// Global point inversions left for this face (each is a grid search; an edge that is not
    /// on its surface would otherwise ask for one per sample). Only a B-spline's or an
    /// extrusion's points spend them.
    searches: AtomicUsize,
}

/// The fewest loops a face on an analytic surface has sampled on every core.
const PARALLEL_SAMPLED_LOOPS: usize = 8;

impl Natural<'_> {
    fn of(&self, p: DVec3, hint: Option<[f64; 2]>) -> [f64; 2] {
        let angle = |l: DVec3| {
            if l.x.hypot(l.y) <= self.small {
                f64::NAN
            } else {
                l.y.atan2(l.x)
            }
        };
        match self.surface {
            Surface3::Plane(f) => {
                let l = f.local(p);
                [l.x, l.y]
            }
            Surface3::Cylinder { frame, .. } | Surface3::Cone { frame, .. } => {
                let l = frame.local(p);
                [angle(l), l.z]
            }
            Surface3::Sphere { frame, radius } => {
                let l = frame.local(p);
                // Within the tolerance of a pole, the pole: its latitude exactly ±π/2 (else a
                // loop through a pole vertex a rounding step off the axis leaves a hole of
                // that latitude's circle round it) and no longitude.
                if l.x.hypot(l.y) <= self.small * 1e3 {
                    return [f64::NAN, FRAC_PI_2.copysign(l.z)];
                }
                [angle(l), (l.z / radius).clamp(-1.0, 1.0).asin()]
            }
            Surface3::Torus { frame, major, .. } => {
                let l = frame.local(p);
                [angle(l), l.z.atan2(l.x.hypot(l.y) - major)]
            }
            Surface3::Revolution { frame, curve } => {
                let l = frame.local(p);
                let meridian = frame.at(DVec3::new(l.x.hypot(l.y), 0.0, l.z));
                [
                    angle(l),
                    curve
                        .closest_parameter(meridian)
                        .unwrap_or(curve.domain().0),
                ]
            }
            Surface3::Extrusion { .. } | Surface3::Spline(_) => {
                let Some(s) = self.nurbs else {
                    return [f64::NAN; 2];
                };
                // A hint at a pole has no parameter along the collapsed side: the middle.
                let domain = s.domain();
                let hint = hint.map(|n| {
                    let r = self.raw(n);
                    [0, 1].map(|d| {
                        if r[d].is_finite() {
                            r[d]
                        } else {
                            0.5 * (domain[d].0 + domain[d].1)
                        }
                    })
                });
                let near = hint.map(|[u, v]| s.closest_point_from(p, u, v));
                let found = match near {
                    // From the previous point, Newton finds this one unless it went to another
                    // local minimum (far off: the edge lies within its tolerance).
                    Some(c) if c.distance <= self.small * 1e4 => c,
                    _ => {
                        let left = self.searches.load(Ordering::Relaxed);
                        if left == 0 {
                            return [f64::NAN; 2];
                        }
                        self.searches.store(left - 1, Ordering::Relaxed);
                        match s.closest_point(p) {
                            Ok(c) => c,
                            Err(_) => return [f64::NAN; 2],
                        }
                    }
                };
                let mut n = [found.u, found.v];
                for (d, closed) in self.closed.iter().enumerate() {
                    if let Some((lo, hi)) = *closed {
                        n[d] = (n[d] - lo) / (hi - lo) * TAU;
                    }
                }
                // On a collapsed side (the point there, or Newton's answer on that side's
                // parameter, where it stops for points close to the pole) the parameter along
                // the side is undefined.
                let on_side = self.collapsed.iter().find(|&&(d, value, _)| {
                    let (lo, hi) = s.domain()[d];
                    ([found.u, found.v][d] - value).abs() <= 1e-9 * (hi - lo)
                });
                if let Some(&(d, _, _)) = self.pole_at(p).or(on_side) {
                    n[1 - d] = f64::NAN;
                }
                n
            }
        }
    }

    /// The collapsed side `p` lies at, if any.
    fn pole_at(&self, p: DVec3) -> Option<&(usize, f64, DVec3)> {
        self.collapsed
            .iter()
            .find(|(_, _, q)| q.distance(p) <= self.small * 1e3)
    }

    /// A B-spline's (u, v) from natural parameters (an angle back to its closed direction).
    fn raw(&self, n: [f64; 2]) -> [f64; 2] {
        let mut r = n;
        for (d, closed) in self.closed.iter().enumerate() {
            if let Some((lo, hi)) = *closed {
                r[d] = lo + (hi - lo) * n[d].rem_euclid(TAU) / TAU;
            }
        }
        r
    }

    fn point(&self, n: [f64; 2]) -> DVec3 {
        let a = if n[0].is_nan() { 0.0 } else { n[0] };
        match self.surface {
            Surface3::Plane(f) => f.at(DVec3::new(n[0], n[1], 0.0)),
            Surface3::Cylinder { frame, radius } => {
                frame.origin + frame.radial(a) * *radius + frame.z * n[1]
            }
            Surface3::Cone { frame, radius, tan } => {
                frame.origin + frame.radial(a) * (radius + n[1] * tan) + frame.z * n[1]
            }
            Surface3::Sphere { frame, radius } => {
                frame.origin + (frame.radial(a) * n[1].cos() + frame.z * n[1].sin()) * *radius
            }
            Surface3::Torus {
                frame,
                major,
                minor,
            } => {
                frame.origin
                    + frame.radial(a) * (major + minor * n[1].cos())
                    + frame.z * (minor * n[1].sin())
            }
            Surface3::Revolution { frame, curve } => {
                let m = frame.local(curve.point_at(n[1]).unwrap_or(frame.origin));
                let rotated = Frame {
                    origin: frame.origin,
                    x: frame.radial(a),
                    y: frame.z.cross(frame.radial(a)),
                    z: frame.z,
                };
                rotated.at(DVec3::new(m.x, 0.0, m.z))
            }
            Surface3::Extrusion { .. } | Surface3::Spline(_) => {
                let [u, v] = self.raw(n);
                self.nurbs
                    .and_then(|s| s.point_at(u, v).ok())
                    .unwrap_or(DVec3::NAN)
            }
        }
    }

    /// The middle of two natural points (angles the short way round).
    fn middle(&self, a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
        let mut m = [0.0; 2];
        for d in 0..2 {
            m[d] = if a[d].is_nan() {
                b[d]
            } else if b[d].is_nan() {
                a[d]
            } else if self.periodic[d] {
                a[d] + 0.5 * wrap(b[d] - a[d])
            } else {
                0.5 * (a[d] + b[d])
            };
        }
        m
    }
}

/// Samples along one edge use, from its start to its end as the loop runs: at least `initial`
/// chords, each split while the surface point at its natural middle is farther than
/// `tolerance` from the edge's point at its middle parameter.
fn sample_edge(
    edge: &LoopEdge,
    natural: &Natural,
    tolerance: f64,
    hint: Option<[f64; 2]>,
) -> Vec<Sample> {
    let g = &edge.geometry;
    let at = |s: f64| {
        if edge.forward {
            g.point(s)
        } else {
            g.point(1.0 - s)
        }
    };
    let turns = match g.curve {
        Curve3::Circle { .. } | Curve3::Ellipse { .. } => {
            ((g.t1 - g.t0).abs() / (PI / 8.0)).ceil() as usize
        }
        Curve3::Line { .. } => 1,
        Curve3::Spline(ref c) => (c.count() - c.degree()).clamp(1, 64) * 2,
    };
    let initial = turns.max(2);
    let make = |s: f64, hint: Option<[f64; 2]>| {
        let p = at(s);
        let n = natural.of(p, hint);
        Sample {
            p,
            n,
            s,
            pole: (n[0].is_nan() && natural.periodic[0]) || natural.pole_at(p).is_some(),
        }
    };
    let mut out = vec![make(0.0, hint)];
    let mut stack: Vec<(f64, f64, usize)> = (0..initial)
        .rev()
        .map(|k| {
            (
                k as f64 / initial as f64,
                (k + 1) as f64 / initial as f64,
                0,
            )
        })
        .collect();
    const MAX_SAMPLES: usize = 4096;
    while let Some((a, b, depth)) = stack.pop() {
        let last = match out.last() {
            Some(s) => *s,
            None => make(a, hint),
        };
        let end = make(b, Some(last.n));
        let m = 0.5 * (a + b);
        // The loop's middle against the edge's middle projected onto the surface (an edge
        // may lie up to its tolerance off the surface; that offset is not the loop's error).
        let mid_point = at(m);
        let mid_on_surface = natural.point(natural.of(mid_point, Some(last.n)));
        let guess = natural.point(natural.middle(last.n, end.n));
        if depth < 16
            && out.len() + stack.len() < MAX_SAMPLES
            && guess.distance(mid_on_surface) > tolerance
        {
            stack.push((m, b, depth + 1));
            stack.push((a, m, depth + 1));
        } else {
            out.push(end);
        }
    }
    out
}

/// The domain of each direction in which the surface closes on itself: its two boundary
/// curves in that direction coincide within `tolerance` (checked at 17 points across).
fn closed_directions(s: &NurbsSurface, tolerance: f64) -> [Option<(f64, f64)>; 2] {
    let [du, dv] = s.domain();
    let mut out = [None, None];
    for (d, ((lo, hi), (a, b))) in [(du, dv), (dv, du)].into_iter().enumerate() {
        let side = |x: f64| -> Option<Vec<DVec3>> {
            (0..=16)
                .map(|k| {
                    let t = (a + (b - a) * k as f64 / 16.0).clamp(a, b);
                    if d == 0 {
                        s.point_at(x, t)
                    } else {
                        s.point_at(t, x)
                    }
                    .ok()
                })
                .collect()
        };
        let (Some(first), Some(last)) = (side(lo), side(hi)) else {
            continue;
        };
        let meets = first
            .iter()
            .zip(&last)
            .all(|(p, q)| p.distance(*q) <= tolerance);
        // Two sides collapsed to one point (a pole) do not make a closed direction.
        let collapsed = first.iter().all(|p| p.distance(first[0]) <= tolerance);
        if meets && !collapsed {
            out[d] = Some((lo, hi));
        }
    }
    out
}

/// Why a face was skipped (a warning, not an error).
pub type Skip = String;

/// A face with no edge loop (bounded by a vertex alone, or by nothing): the whole of a surface
/// that closes on itself, untrimmed. A sphere is both angles' full range (its poles the
/// vertices), a torus both full turns, a B-spline that is closed in both directions or
/// closed in one and collapsed at the ends of the other as it is. A surface with a boundary
/// cannot be such a face.
fn whole_face(surface: &Surface3, tolerance: f64) -> Result<BuiltFace, Skip> {
    let full = Range::Angle {
        start: 0.0,
        span: TAU,
        full: true,
    };
    let nurbs = match surface {
        Surface3::Sphere { .. } => analytic_nurbs(
            surface,
            &[
                full,
                Range::Arc {
                    lo: -FRAC_PI_2,
                    span: PI,
                },
            ],
        ),
        Surface3::Torus { .. } => analytic_nurbs(surface, &[full, full]),
        Surface3::Spline(s) => {
            let closed = closed_directions(s, tolerance);
            let collapsed = collapsed_sides(s, tolerance);
            let bounded = (0..2).any(|d| {
                closed[d].is_none() && collapsed.iter().filter(|(c, _, _)| *c == d).count() < 2
            });
            if bounded {
                return Err("it has no edges, but its B-spline surface has a boundary".into());
            }
            Ok(s.clone())
        }
        other => {
            return Err(format!(
                "it has no edges, but a {} has a boundary",
                other.type_name()
            ));
        }
    }
    .map_err(|e| format!("its surface could not be built: {e}"))?;
    Ok(BuiltFace {
        face: TrimmedSurface::untrimmed(nurbs),
        origins: Vec::new(),
    })
}

/// Builds the face on `surface` bounded by `bounds`; `same_sense`: the face's normal is the
/// surface's. `tolerance` bounds the trim loops' distance from the edges.
pub fn build_face(
    surface: &Surface3,
    surface_id: u64,
    bounds: &[Bound],
    same_sense: bool,
    tolerance: f64,
) -> Result<BuiltFace, Skip> {
    if bounds.is_empty() {
        return whole_face(surface, tolerance);
    }
    if let Surface3::Spline(s) = surface
        && let Some(built) = face_from_pcurves(s, surface_id, bounds, same_sense, tolerance)
    {
        return Ok(built);
    }
    let mut periodic = match surface {
        Surface3::Plane(_) | Surface3::Extrusion { .. } | Surface3::Spline(_) => [false, false],
        Surface3::Torus { .. } => [true, true],
        _ => [true, false],
    };
    // Extrusions: a NURBS over a range that holds every edge point.
    let extrusion = match surface {
        Surface3::Extrusion { curve, vector } => Some(build_extrusion(curve, *vector, bounds)?),
        _ => None,
    };
    let nurbs: Option<&NurbsSurface> = match surface {
        Surface3::Spline(s) => Some(s),
        _ => extrusion.as_ref(),
    };
    let mut closed = nurbs.map_or([None, None], |s| closed_directions(s, tolerance));
    for d in 0..2 {
        periodic[d] |= closed[d].is_some();
    }
    let natural = Natural {
        surface,
        nurbs,
        periodic,
        closed,
        small: tolerance * 1e-3,
        collapsed: nurbs.map_or_else(Vec::new, |s| collapsed_sides(s, tolerance)),
        searches: AtomicUsize::new(64 + 4 * bounds.iter().map(|b| b.edges.len()).sum::<usize>()),
    };
    // Samples of every loop, per edge use.
    let sample_loop = |bound: &Bound| {
        let mut edges = Vec::new();
        let mut hint = None;
        for e in &bound.edges {
            let samples = sample_edge(e, &natural, tolerance, hint);
            hint = samples.last().map(|s| s.n);
            edges.push(samples);
        }
        fill_poles(&mut edges);
        edges
    };
    // On an analytic surface a point's parameters are in closed form, so a face with many
    // loops (a plate with hundreds of holes, otherwise the longest piece of its reading
    // step) has them sampled on every core, with the same samples. On a B-spline the global
    // searches share one budget, spent in the loops' order, so the loops are sampled in turn.
    let mut loops: Vec<Vec<Vec<Sample>>> =
        if nurbs.is_none() && bounds.len() >= PARALLEL_SAMPLED_LOOPS {
            crate::kernel::par::map(bounds.len(), |k| sample_loop(&bounds[k]))
        } else {
            bounds.iter().map(sample_loop).collect()
        };
    if nurbs.is_some()
        && loops
            .iter()
            .flatten()
            .flatten()
            .any(|s| !(s.n[0].is_finite() && s.n[1].is_finite()))
    {
        return Err("its edges do not lie on its surface".into());
    }
    let sense: Vec<f64> = bounds
        .iter()
        .map(|b| {
            if b.orientation == same_sense {
                1.0
            } else {
                -1.0
            }
        })
        .collect();
    // A face across the seam of a surface closed on itself, without going round it: the
    // seam moves into the gap the face leaves (the same surface), so that the face is one
    // region of the domain.
    let mut reseamed: Option<NurbsSurface> = None;
    for (d, direction) in [
        (0, crate::kernel::Direction::U),
        (1, crate::kernel::Direction::V),
    ] {
        let (Some((lo, hi)), Some(s)) = (closed[d], reseamed.as_ref().or(nurbs)) else {
            continue;
        };
        if !crosses_seam(&loops, d) {
            continue;
        }
        let (range, windings) =
            angle_range(&loops, d, bounds, (!periodic[1 - d]).then_some(&sense));
        let Range::Angle {
            start,
            span,
            full: false,
        } = range
        else {
            continue;
        };
        if windings.iter().any(|&w| w != 0) {
            continue;
        }
        let cut = (start - 0.5 * (TAU - span)).rem_euclid(TAU);
        let value = lo + (hi - lo) * cut / TAU;
        let moved = s
            .moved_seam(direction, value, tolerance)
            .map_err(|e| format!("its surface's seam could not be moved: {e}"))?;
        for sample in loops.iter_mut().flatten().flatten() {
            sample.n[d] = (sample.n[d] - cut).rem_euclid(TAU);
        }
        closed[d] = Some((value, value + (hi - lo)));
        reseamed = Some(moved);
    }
    let nurbs = reseamed.as_ref().or(nurbs);
    let natural = Natural {
        nurbs,
        closed,
        ..natural
    };
    // Ranges of the natural parameters.
    let mut ranges = [Range::Linear { lo: 0.0, hi: 1.0 }; 2];
    let mut windings: Vec<[i64; 2]> = vec![[0, 0]; loops.len()];
    for d in 0..2 {
        if periodic[d] {
            let (range, w) = angle_range(&loops, d, bounds, (!periodic[1 - d]).then_some(&sense));
            // A closed B-spline keeps its own seam.
            ranges[d] = match closed[d] {
                Some((lo, hi)) => Range::Closed { lo, hi },
                None => range,
            };
            for (k, wk) in w.into_iter().enumerate() {
                windings[k][d] = wk;
            }
        } else {
            let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
            for s in loops.iter().flatten().flatten() {
                if s.n[d].is_finite() {
                    lo = lo.min(s.n[d]);
                    hi = hi.max(s.n[d]);
                }
            }
            if !(lo.is_finite() && hi.is_finite()) {
                return Err("its edges could not be placed on its surface".into());
            }
            // A loop going once round the axis (a cap): the face reaches the pole on its left.
            let caps: Vec<usize> = (0..loops.len()).filter(|&k| windings[k][0] != 0).collect();
            let (lo_sampled, hi_sampled) = (lo, hi);
            if d == 1 && caps.len() == 1 {
                let k = caps[0];
                let up = (windings[k][0] as f64 * sense[k]) > 0.0;
                match surface {
                    Surface3::Sphere { .. } => {
                        if up {
                            hi = FRAC_PI_2;
                        } else {
                            lo = -FRAC_PI_2;
                        }
                    }
                    Surface3::Cone { radius, tan, .. } => {
                        let apex = -radius / tan;
                        if up && apex > hi {
                            hi = apex;
                        } else if !up && apex < lo {
                            lo = apex;
                        }
                    }
                    _ => {}
                }
            }
            // Room for the edges between their samples (exact on planes, smooth elsewhere:
            // a curve bulges past its samples), except at a pole or an apex the face reaches.
            let pad = match surface {
                Surface3::Plane(_) => 0.01 * (hi - lo) + tolerance,
                Surface3::Sphere { .. } => arc_margin(hi - lo),
                _ => RANGE_MARGIN * (hi - lo) + tolerance,
            };
            if lo == lo_sampled {
                lo -= pad;
            }
            if hi == hi_sampled {
                hi += pad;
            }
            if matches!(surface, Surface3::Sphere { .. }) {
                lo = lo.max(-FRAC_PI_2);
                hi = hi.min(FRAC_PI_2);
            }
            ranges[d] = match surface {
                Surface3::Sphere { .. } => Range::Arc { lo, span: hi - lo },
                Surface3::Revolution { curve, .. } => {
                    let (a, b) = curve.domain();
                    Range::Raw { lo: a, hi: b }
                }
                Surface3::Extrusion { .. } | Surface3::Spline(_) => {
                    let [du, dv] = nurbs.map(|s| s.domain()).unwrap_or([(0.0, 1.0); 2]);
                    let (a, b) = if d == 0 { du } else { dv };
                    Range::Raw { lo: a, hi: b }
                }
                _ => Range::Linear { lo, hi },
            };
            let size = hi - lo;
            if !(size > tolerance * 1e-6) && !matches!(ranges[d], Range::Raw { .. }) {
                return Err("the face has no extent on its surface".into());
            }
        }
    }
    let built_surface = match (surface, nurbs) {
        (Surface3::Spline(_) | Surface3::Extrusion { .. }, Some(s)) => s.clone(),
        _ => analytic_nurbs(surface, &ranges)
            .map_err(|e| format!("its surface could not be built: {e}"))?,
    };
    let uv_size = {
        let [(u0, u1), (v0, v1)] = built_surface.domain();
        (u1 - u0).hypot(v1 - v0)
    };
    // Consecutive pieces whose ends miss each other in (u, v) by less than the tolerance
    // on the surface (edges meeting within the file's uncertainty) are snapped together;
    // a connector is added only across a larger gap in (u, v) that is one point in space (a
    // pole, a collapsed side). A connector across a tiny gap would make a zigzag that the
    // loop's own curves cross.
    let needs_connector = |a: DVec2, b: DVec2| {
        let gap = a.distance(b);
        if gap <= 1e-9 * uv_size {
            return false;
        }
        let middle = 0.5 * (a + b);
        match built_surface.evaluate_clamped(middle) {
            Some(d) => d.su.length().max(d.sv.length()) * gap > tolerance,
            None => true,
        }
    };
    // Loops in (u, v): pieces per edge use, joined, chains closed.
    let seam_pairs = 0usize;
    let mut trim_loops: Vec<Vec<(TrimCurve, CurveOrigin)>> = Vec::new();
    let mut chains: Vec<Vec<Piece>> = Vec::new();
    for (k, edges) in loops.iter().enumerate() {
        let pieces = match surface {
            Surface3::Plane(frame) => exact_plane_pieces(&bounds[k], frame, &ranges)?,
            _ => {
                let mut pieces = loop_pieces(edges, &bounds[k], &ranges, sense[k], &natural);
                for p in &mut pieces {
                    if let Some(e) = p.edge.and_then(|i| bounds[k].edges.get(i)) {
                        p.exact = smooth_piece(p, e, &built_surface, tolerance, uv_size);
                    }
                }
                pieces
            }
        };
        // Join the pieces: snap small gaps, bridge poles, break at seam jumps.
        let n = pieces.len();
        let mut breaks = Vec::new();
        for i in 0..n {
            let a = &pieces[i];
            let b = &pieces[(i + 1) % n];
            let (pa, pb) = (a.last(), b.first());
            if pa.distance(pb) <= 1e-9 * uv_size {
                continue;
            }
            let same_point = a.end_point.distance(b.start_point) <= tolerance;
            let across = |d: usize| {
                ranges[d].full()
                    && ((pa[d] - pb[d]).abs() - ranges[d].seam_width()).abs()
                        < 1e-6 * ranges[d].seam_width()
            };
            let seam_jump = (0..2).any(across)
                && (0..2).all(|d| across(d) || (pa[d] - pb[d]).abs() < 1e-6 * uv_size);
            if same_point && seam_jump && !(a.end_pole || b.start_pole) {
                breaks.push(i);
            } else if same_point {
                // Through a pole or along a collapsed side: a connector.
            } else {
                return Err(format!(
                    "its loop {} does not close: an edge ends {:.3e} from where the next starts",
                    k + 1,
                    a.end_point.distance(b.start_point)
                ));
            }
        }
        if breaks.is_empty() {
            let mut curves = Vec::new();
            for i in 0..n {
                let a = &pieces[i];
                let b = &pieces[(i + 1) % n];
                curves.push(a.clone());
                if needs_connector(a.last(), b.first()) {
                    curves.push(Piece::connector(
                        a.last(),
                        b.first(),
                        CurveOrigin::Added,
                        a.end_point,
                    ));
                }
            }
            trim_loops.push(to_trim_curves(curves, uv_size)?);
        } else {
            // Chains: from just after each break to the next break.
            let mut current: Vec<Piece> = Vec::new();
            let start = (breaks[0] + 1) % n;
            for j in 0..n {
                let i = (start + j) % n;
                current.push(pieces[i].clone());
                if breaks.contains(&i) {
                    chains.push(std::mem::take(&mut current));
                } else {
                    let b = &pieces[(i + 1) % n];
                    if needs_connector(pieces[i].last(), b.first()) {
                        current.push(Piece::connector(
                            pieces[i].last(),
                            b.first(),
                            CurveOrigin::Added,
                            pieces[i].end_point,
                        ));
                    }
                }
            }
        }
    }
    match chains.len() {
        0 => {}
        1 => {
            // A cap: close through the pole on the face's side.
            let chain = chains.remove(0);
            let (a, b) = (chain[0].first(), chain[chain.len() - 1].last());
            let d = if ranges[0].full() { 0 } else { 1 };
            let e = 1 - d;
            let travel = b[d] - a[d];
            let k_sense = sense.first().copied().unwrap_or(1.0);
            let left_is_up = if d == 0 {
                (travel > 0.0) == (k_sense > 0.0)
            } else {
                (travel < 0.0) == (k_sense > 0.0)
            };
            let (lo, hi) = ranges[e].bounds();
            let pole = if left_is_up { hi } else { lo };
            let mut b_pole = b;
            b_pole[e] = pole;
            let mut a_pole = a;
            a_pole[e] = pole;
            let mut curves = chain;
            let seam = seam_pairs;
            let end_point = curves[curves.len() - 1].end_point;
            let start_point = curves[0].start_point;
            curves.push(Piece::connector(
                b,
                b_pole,
                CurveOrigin::Seam(seam),
                end_point,
            ));
            curves.push(Piece::connector(
                b_pole,
                a_pole,
                CurveOrigin::Added,
                end_point,
            ));
            curves.push(Piece::connector(
                a_pole,
                a,
                CurveOrigin::Seam(seam),
                start_point,
            ));
            trim_loops.push(to_trim_curves(curves, uv_size)?);
        }
        2 => {
            let mut second = chains.pop().unwrap_or_default();
            let first = chains.pop().unwrap_or_default();
            let d = if ranges[0].full() { 0 } else { 1 };
            let t1 = first[first.len() - 1].last()[d] - first[0].first()[d];
            let t2 = second[second.len() - 1].last()[d] - second[0].first()[d];
            if (t1 > 0.0) == (t2 > 0.0) {
                second = second.into_iter().rev().map(Piece::reversed).collect();
            }
            let seam = seam_pairs;
            let mut curves = first.clone();
            let (fa, fb) = (first[0].first(), first[first.len() - 1].last());
            let (sa, sb) = (second[0].first(), second[second.len() - 1].last());
            curves.push(Piece::connector(
                fb,
                sa,
                CurveOrigin::Seam(seam),
                first[first.len() - 1].end_point,
            ));
            curves.extend(second.iter().cloned());
            curves.push(Piece::connector(
                sb,
                fa,
                CurveOrigin::Seam(seam),
                second[second.len() - 1].end_point,
            ));
            trim_loops.push(to_trim_curves(curves, uv_size)?);
        }
        n => {
            return Err(format!(
                "{n} of its loops go round its surface's axis; knotwork reads up to 2"
            ));
        }
    }
    finish_face(built_surface, trim_loops)
}

/// The trimmed surface of `trim_loops` on `surface`, with what each of its loop curves lies
/// on.
fn finish_face(
    surface: NurbsSurface,
    trim_loops: Vec<Vec<(TrimCurve, CurveOrigin)>>,
) -> Result<BuiltFace, Skip> {
    let (curves, origins): (Vec<Vec<TrimCurve>>, Vec<Vec<CurveOrigin>>) = trim_loops
        .into_iter()
        .map(|l| l.into_iter().unzip())
        .unzip();
    // Loop points computed from the file's edges and p-curves can land a few rounding steps
    // outside the surface's domain (a vertex on the domain's side): they are moved onto it.
    let [(u0, u1), (v0, v1)] = surface.domain();
    let slack = 1e-9 * (u1 - u0).hypot(v1 - v0);
    let onto = |p: DVec2| {
        let near = |x: f64, lo: f64, hi: f64| {
            if (lo - slack..=hi + slack).contains(&x) {
                x.clamp(lo, hi)
            } else {
                x
            }
        };
        DVec2::new(near(p.x, u0, u1), near(p.y, v0, v1))
    };
    let curves: Vec<Vec<TrimCurve>> = curves
        .into_iter()
        .map(|l| {
            l.into_iter()
                .map(|c| c.map_points(onto).unwrap_or(c))
                .collect()
        })
        .collect();
    let given = curves.clone();
    let face = TrimmedSurface::new(surface, curves)
        .map_err(|e| format!("its trim loops are not valid: {e}"))?;
    // Construction turns loops to run with the kept region on their left: a loop turned is
    // its curves in reverse order, each reversed, so their origins follow.
    let mut origins = origins;
    for (k, l) in face.loops().iter().enumerate() {
        if let (Some(o), Some(g)) = (origins.get_mut(k), given.get(k))
            && l.first() != g.first()
        {
            o.reverse();
            for c in o.iter_mut() {
                if let CurveOrigin::Edge { forward, .. } = c {
                    *forward = !*forward;
                }
            }
        }
    }
    Ok(BuiltFace { face, origins })
}

/// The face on the B-spline surface `s` (the file's surface `surface_id`) with the file's own
/// p-curves as its trim loops, where every edge has one on it that fits: its ends and its
/// middle on the surface lie within `tolerance` of the edge's ends and of its 3D curve. The
/// p-curve is taken whole where its ends are the edge's (a writer that gives each edge its
/// own p-curve, as knotwork's does), else from the edge's parameters on its 3D curve (a
/// writer whose p-curves share the 3D curve's parameter). A seam edge has two p-curves on the
/// surface; each use takes the one that continues the loop. Where consecutive p-curves leave
/// a gap in (u, v) at one point in space (a collapsed side), a straight connector closes it.
/// `None`: some edge has no such p-curve, or the loops do not close, or the surface closes on
/// itself and no edge is a seam, and the face is built from its 3D edges instead.
fn face_from_pcurves(
    s: &NurbsSurface,
    surface_id: u64,
    bounds: &[Bound],
    same_sense: bool,
    tolerance: f64,
) -> Option<BuiltFace> {
    // On a surface that closes on itself, a loop alone may mean the part outside it (a
    // sphere-like surface with a hole): the p-curves say which with a seam edge, whose two
    // p-curves on the surface make the loops bound the face within the domain, or by their
    // direction (below).
    let seamed = bounds.iter().flat_map(|b| &b.edges).any(|e| {
        e.geometry
            .pcurves
            .iter()
            .filter(|(id, _)| *id == surface_id)
            .count()
            >= 2
    });
    let ambiguous = !seamed && closed_directions(s, tolerance).iter().any(Option::is_some);
    let [(u0, u1), (v0, v1)] = s.domain();
    let uv_size = (u1 - u0).hypot(v1 - v0);
    let on = |p: DVec2| s.point_at_clamped(p).ok();
    let mut trim_loops = Vec::new();
    for bound in bounds {
        // Each use's candidates, running with the loop.
        let mut uses: Vec<Vec<TrimCurve>> = Vec::new();
        for e in &bound.edges {
            let g = &e.geometry;
            let candidates: Vec<TrimCurve> = g
                .pcurves
                .iter()
                .filter(|(id, _)| *id == surface_id)
                .filter_map(|(_, pc)| pcurve_piece(pc, g, &on, tolerance))
                .map(|c| if e.forward { c } else { c.reverse() })
                .collect();
            if candidates.is_empty() {
                return None;
            }
            uses.push(candidates);
        }
        // The first use's choice decides the rest (each the candidate nearest the last end).
        let mut best: Option<(f64, Vec<(TrimCurve, CurveOrigin)>)> = None;
        for first in 0..uses[0].len() {
            let mut chain: Vec<(TrimCurve, CurveOrigin)> = Vec::new();
            let mut worst = 0.0f64;
            // The candidate each edge took: a seam used twice in the loop takes its other
            // p-curve the second time (down one side and up the other, even where the two
            // meet at a pole, whose gap a connector then closes).
            let mut taken: std::collections::HashMap<u64, usize> = std::collections::HashMap::new();
            for (k, (candidates, e)) in uses.iter().zip(&bound.edges).enumerate() {
                let choice = if k == 0 {
                    first
                } else {
                    let end = chain.last().map(|(c, _)| c.control_point(c.count() - 1))?;
                    let before = taken.get(&e.id).copied().filter(|_| candidates.len() > 1);
                    (0..candidates.len())
                        .filter(|&i| Some(i) != before)
                        .min_by(|&a, &b| {
                            candidates[a]
                                .control_point(0)
                                .distance(end)
                                .total_cmp(&candidates[b].control_point(0).distance(end))
                        })?
                };
                taken.insert(e.id, choice);
                let curve = candidates[choice].clone();
                chain.push((
                    curve,
                    CurveOrigin::Edge {
                        id: e.id,
                        forward: e.forward,
                    },
                ));
            }
            // Gaps: closed by a connector where both sides are one point in space.
            let mut closed: Vec<(TrimCurve, CurveOrigin)> = Vec::new();
            let n = chain.len();
            for k in 0..n {
                let (c, o) = &chain[k];
                closed.push((c.clone(), *o));
                let a = c.control_point(c.count() - 1);
                let b = chain[(k + 1) % n].0.control_point(0);
                let gap = a.distance(b);
                if gap <= 1e-9 * uv_size {
                    continue;
                }
                if on(a)?.distance(on(b)?) > tolerance {
                    worst = f64::INFINITY;
                    break;
                }
                worst = worst.max(gap);
                let connector =
                    TrimCurve::new(1, vec![0.0, 0.0, 1.0, 1.0], vec![a, b], None).ok()?;
                closed.push((connector, CurveOrigin::Added));
            }
            if worst.is_finite() && best.as_ref().is_none_or(|(w, _)| worst < *w) {
                best = Some((worst, closed));
            }
        }
        trim_loops.push(best?.1);
    }
    if ambiguous {
        // The face lies on the left of each bound's loop seen from its normal: in (u, v),
        // inside the loops where they run counter-clockwise once turned by each bound's
        // sense. Where they run the other way the face is the part outside them, which the
        // general path builds.
        let kept: f64 = trim_loops
            .iter()
            .zip(bounds)
            .map(|(l, b)| {
                let curves: Vec<TrimCurve> = l.iter().map(|(c, _)| c.clone()).collect();
                let area = crate::kernel::trim::signed_area(&crate::kernel::trim::flatten_loop(
                    &curves,
                    1e-6 * uv_size,
                ));
                if b.orientation == same_sense {
                    area
                } else {
                    -area
                }
            })
            .sum();
        if !(kept > 0.0) {
            return None;
        }
    }
    finish_face(s.clone(), trim_loops).ok()
}

/// The part of the p-curve `pc` that is the edge `g`, running from its start to its end, as a
/// trim curve; `on` maps (u, v) to the surface. `None` where it does not fit the edge.
fn pcurve_piece(
    pc: &Curve3,
    g: &EdgeGeometry,
    on: &dyn Fn(DVec2) -> Option<DVec3>,
    tolerance: f64,
) -> Option<TrimCurve> {
    let flat = |p: DVec3| DVec2::new(p.x, p.y);
    let closed = g.start.distance(g.end) <= tolerance;
    let mut ranges = Vec::new();
    if let Curve3::Spline(c) = pc {
        let (a, b) = c.domain();
        // A closed edge: the p-curve runs with the 3D curve, the edge with it when t1 > t0.
        if !closed || g.t1 >= g.t0 {
            ranges.push((a, b));
        }
        if !closed || g.t1 < g.t0 {
            ranges.push((b, a));
        }
    }
    ranges.push((g.t0, g.t1));
    for (a, b) in ranges {
        let near =
            |t: f64, p: DVec3| on(flat(pc.point(t))).is_some_and(|q| q.distance(p) <= tolerance);
        if !(near(a, g.start) && near(b, g.end)) {
            continue;
        }
        // Its middle on the surface lies on the edge's 3D curve.
        let m = on(flat(pc.point(0.5 * (a + b))))?;
        let off = |t: f64| g.curve.point(t).distance(m) > tolerance;
        // Newton from the edge's middle finds it first nearly always; the global search only
        // where it does not.
        if off(g.curve.parameter_near(m, 0.5 * (g.t0 + g.t1))) && off(g.curve.parameter_of(m)) {
            continue;
        }
        return pc.piece(a, b).ok()?.map_into(flat).ok();
    }
    None
}

/// A piece of loop in (u, v).
#[derive(Debug, Clone)]
struct Piece {
    uv: Vec<DVec2>,
    origin: CurveOrigin,
    /// An exact curve (plane edges), or a smooth one through the points
    /// ([`smooth_piece`]), instead of the polyline.
    exact: Option<TrimCurve>,
    /// The parameter along its edge use of each point of `uv` (from 0 at the use's start),
    /// where the piece comes from sampling one edge; empty otherwise.
    s: Vec<f64>,
    /// The index in its bound of that edge.
    edge: Option<usize>,
    start_point: DVec3,
    end_point: DVec3,
    start_pole: bool,
    end_pole: bool,
}

impl Piece {
    fn first(&self) -> DVec2 {
        self.uv[0]
    }
    fn last(&self) -> DVec2 {
        self.uv[self.uv.len() - 1]
    }
    fn connector(a: DVec2, b: DVec2, origin: CurveOrigin, at: DVec3) -> Self {
        Piece {
            uv: vec![a, b],
            origin,
            exact: None,
            s: Vec::new(),
            edge: None,
            start_point: at,
            end_point: at,
            start_pole: false,
            end_pole: false,
        }
    }
    fn reversed(self) -> Self {
        Piece {
            uv: self.uv.into_iter().rev().collect(),
            origin: match self.origin {
                CurveOrigin::Edge { id, forward } => CurveOrigin::Edge {
                    id,
                    forward: !forward,
                },
                o => o,
            },
            exact: self.exact.map(|c| c.reverse()),
            s: self.s.into_iter().rev().collect(),
            edge: self.edge,
            start_point: self.end_point,
            end_point: self.start_point,
            start_pole: self.end_pole,
            end_pole: self.start_pole,
        }
    }
}

/// The margin a face's range of an angle or a height gets each side of its edges' samples,
/// as a fraction of the range.
const RANGE_MARGIN: f64 = 1e-3;

/// The margin each side of an angle range of `span`: `RANGE_MARGIN` of it, but no more than
/// leaves it on as many rational arcs (a quarter turn each, [`arc_parameter`]) as before.
fn arc_margin(span: f64) -> f64 {
    let arcs = (span / FRAC_PI_2 - 1e-9).ceil().max(1.0);
    let room = (arcs * FRAC_PI_2 * (1.0 - 1e-9) - span).max(0.0);
    (RANGE_MARGIN * span).min(0.5 * room)
}

/// Whether every point of `uv` lies on the chord from its first to its last point (within
/// 1e-12 of `uv_size`; a zero chord: every point at the first).
fn on_chord(uv: &[DVec2], uv_size: f64) -> bool {
    let (Some(&a), Some(&b)) = (uv.first(), uv.last()) else {
        return true;
    };
    let chord = b - a;
    uv.iter().all(|&q| {
        let t = if chord.length_squared() > 0.0 {
            (q - a).dot(chord) / chord.length_squared()
        } else {
            0.0
        };
        (a + chord * t).distance(q) <= 1e-12 * uv_size
    })
}

/// How close to its edge a smooth trim curve must come, as a fraction of the loop
/// tolerance: far inside it, so that the face's area and the 3D curves made from the trim
/// curves do not depend on the tolerance.
const SMOOTH_FRACTION: f64 = 1e-2;

/// The most points a smooth trim curve is refined to.
const SMOOTH_MAX_POINTS: usize = 1 << 14;

/// A cubic B-spline through a curved piece's points at their edge parameters (polylines
/// meet the tolerance with chords; a cubic through the same points is O(h⁴) from the edge
/// instead of O(h²)). Checked half way between its points: the surface at the cubic's
/// (u, v) against the surface's closest point to the edge there must lie within
/// `SMOOTH_FRACTION` of `tolerance`; where it does not, that half-way point (placed on the
/// surface by Newton's iteration from the cubic's guess) joins the points, and the cubic is
/// made again. `None` for a straight piece, and where the check still fails (a pole, a kink),
/// so the polyline stays.
fn smooth_piece(
    piece: &Piece,
    edge: &LoopEdge,
    surface: &NurbsSurface,
    tolerance: f64,
    uv_size: f64,
) -> Option<TrimCurve> {
    if piece.uv.len() < 3 || piece.s.len() != piece.uv.len() || piece.start_pole || piece.end_pole {
        return None;
    }
    if on_chord(&piece.uv, uv_size) {
        return None;
    }
    let at = |s: f64| {
        if edge.forward {
            edge.geometry.point(s)
        } else {
            edge.geometry.point(1.0 - s)
        }
    };
    let fine = tolerance * SMOOTH_FRACTION;
    let [(u0, u1), (v0, v1)] = surface.domain();
    let (lo, hi) = (DVec2::new(u0, v0), DVec2::new(u1, v1));
    let mut points: Vec<(f64, DVec2)> = piece
        .s
        .iter()
        .copied()
        .zip(piece.uv.iter().copied())
        .collect();
    for _ in 0..8 {
        let (s0, s1) = (points[0].0, points[points.len() - 1].0);
        if !(s1 > s0) {
            return None;
        }
        let mut params: Vec<f64> = points.iter().map(|&(s, _)| (s - s0) / (s1 - s0)).collect();
        let last = params.len() - 1;
        params[0] = 0.0;
        params[last] = 1.0;
        let uv: Vec<DVec2> = points.iter().map(|&(_, q)| q).collect();
        // Control points held inside the domain (so the curve is, by the convex hull): near a
        // side the face reaches, the interpolant may overshoot it by a rounding's width.
        let curve = crate::kernel::splines::interpolate_at_parameters(&uv, &params, 3)
            .and_then(|c| c.map_points(|q| q.clamp(lo, hi)))
            .ok()?;
        let mut refined = Vec::with_capacity(points.len() * 2);
        let mut good = true;
        for (i, w) in points.windows(2).enumerate() {
            refined.push(w[0]);
            let s = 0.5 * (w[0].0 + w[1].0);
            let guess = curve.point_at(0.5 * (params[i] + params[i + 1])).ok()?;
            let fitted = surface.point_at_clamped(guess).ok()?;
            let found = surface.closest_point_from(at(s), guess.x, guess.y);
            let placed = DVec2::new(found.u, found.v);
            // Newton stays near the guess; a jump (a pole, another sheet) ends the attempt.
            if !(placed.distance(guess) <= w[0].1.distance(w[1].1) + 1e-9 * uv_size) {
                return None;
            }
            if fitted.distance(found.point) > fine {
                good = false;
                refined.push((s, placed));
            }
        }
        if good {
            return Some(curve);
        }
        refined.push(points[points.len() - 1]);
        if refined.len() > SMOOTH_MAX_POINTS {
            return None;
        }
        points = refined;
    }
    None
}

/// Trim curves from pieces, each starting exactly where the one before ends: exact or smooth
/// curves as they are (their ends snapped onto the loop's points), straight pieces (two
/// points, or every point on the chord) as lines, the rest as polylines.
fn to_trim_curves(pieces: Vec<Piece>, uv_size: f64) -> Result<Vec<(TrimCurve, CurveOrigin)>, Skip> {
    let mut out = Vec::new();
    let mut previous_end: Option<DVec2> = pieces.last().map(Piece::last);
    for p in pieces {
        let mut uv = p.uv.clone();
        if let Some(e) = previous_end {
            uv[0] = e;
        }
        uv.dedup_by(|a, b| a.distance(*b) <= 1e-12 * uv_size);
        if uv.len() < 2 && p.exact.is_none() {
            // A piece that collapsed to a point in (u, v): nothing to add.
            continue;
        }
        if uv.len() < 2 {
            uv.push(uv[0]);
        }
        let (a, b) = (uv[0], uv[uv.len() - 1]);
        let straight = on_chord(&uv, uv_size);
        let curve = match (&p.exact, straight) {
            (Some(c), _) => {
                let c = c.clone();
                let (c0, c1) = c.ends().map_err(|e| e.to_string())?;
                // Snap the exact curve's ends onto the loop's points.
                let n = c.count();
                let mut c = c;
                if c0.distance(uv[0]) > 0.0 {
                    c = c.with_point(0, uv[0]).map_err(|e| e.to_string())?;
                }
                if c1.distance(b) > 0.0 {
                    c = c.with_point(n - 1, b).map_err(|e| e.to_string())?;
                }
                c
            }
            (None, true) => construct::line(a, b).map_err(|e| e.to_string())?,
            (None, false) => construct::polyline(&uv).map_err(|e| e.to_string())?,
        };
        previous_end = Some(b);
        out.push((curve, p.origin));
    }
    // Close exactly: the first curve starts where the last ends.
    if let (Some(first), Some(last)) = (out.first(), out.last()) {
        let end = last.0.ends().map_err(|e| e.to_string())?.1;
        let (start, _) = first.0.ends().map_err(|e| e.to_string())?;
        if start != end {
            let fixed = first.0.with_point(0, end).map_err(|e| e.to_string())?;
            out[0].0 = fixed;
        }
    }
    if out.is_empty() {
        return Err("a loop collapsed to a point".into());
    }
    Ok(out)
}

/// Gives pole samples (an angle undefined at an analytic surface's pole, or the parameter
/// along a B-spline's collapsed side) the value of their nearest neighbour on the edge that
/// has one, or of the neighbouring edge's end.
fn fill_poles(edges: &mut [Vec<Sample>]) {
    for d in 0..2 {
        let undefined = |s: &Sample| s.pole && s.n[d].is_nan();
        for samples in edges.iter_mut() {
            let n = samples.len();
            for i in 0..n {
                if undefined(&samples[i]) {
                    let near = (1..n).find_map(|k| {
                        [i.checked_sub(k), (i + k < n).then_some(i + k)]
                            .into_iter()
                            .flatten()
                            .find(|&j| samples[j].n[d].is_finite())
                    });
                    if let Some(j) = near {
                        samples[i].n[d] = samples[j].n[d];
                    }
                }
            }
        }
        let m = edges.len();
        for k in 0..m {
            if edges[k].iter().all(|s| s.n[d].is_nan()) {
                let before = edges[(k + m - 1) % m].last().map(|s| s.n[d]);
                if let Some(a) = before.filter(|a| a.is_finite()) {
                    for s in edges[k].iter_mut().filter(|s| s.pole) {
                        s.n[d] = a;
                    }
                }
            }
        }
    }
}

/// The sides of `s` collapsed to a point within `tolerance` (every control point of the
/// boundary row or column there): the direction whose parameter is fixed on the side, that
/// parameter, and the point.
fn collapsed_sides(s: &NurbsSurface, tolerance: f64) -> Vec<(usize, f64, DVec3)> {
    let [nu, nv] = s.count();
    let point = |i: usize, j: usize| s.control_point(i, j);
    let domain = s.domain();
    let mut out = Vec::new();
    for (d, rows) in [(0, [0, nu - 1]), (1, [0, nv - 1])] {
        for (end, k) in rows.into_iter().enumerate() {
            let side: Vec<DVec3> = if d == 0 {
                (0..nv).map(|j| point(k, j)).collect()
            } else {
                (0..nu).map(|i| point(i, k)).collect()
            };
            if side.iter().all(|p| p.distance(side[0]) <= tolerance) {
                let value = if end == 0 { domain[d].0 } else { domain[d].1 };
                out.push((d, value, side[0]));
            }
        }
    }
    out
}

/// Whether a loop steps across the seam (natural parameter 0 ≡ 2π) of direction `d`
/// between consecutive samples.
fn crosses_seam(loops: &[Vec<Vec<Sample>>], d: usize) -> bool {
    loops.iter().any(|edges| {
        let angles: Vec<f64> = edges
            .iter()
            .flatten()
            .map(|s| s.n[d])
            .filter(|a| a.is_finite())
            .collect();
        let n = angles.len();
        (0..n).any(|i| (angles[(i + 1) % n] - angles[i]).abs() > PI)
    })
}

/// The range of the periodic natural parameter `d` over the face, and each loop's winding
/// number about it.
fn angle_range(
    loops: &[Vec<Vec<Sample>>],
    d: usize,
    bounds: &[Bound],
    sense: Option<&[f64]>,
) -> (Range, Vec<i64>) {
    let mut windings = Vec::new();
    let mut intervals: Vec<(f64, f64)> = Vec::new();
    let mut full = false;
    let mut seam_angle: Option<f64> = None;
    for (k, edges) in loops.iter().enumerate() {
        let mut total = 0.0;
        let mut prev: Option<f64> = None;
        for samples in edges {
            let mut lo = f64::INFINITY;
            let mut hi = f64::NEG_INFINITY;
            let mut x = f64::NAN;
            for s in samples {
                let a = s.n[d];
                if !a.is_finite() {
                    continue;
                }
                if let Some(p) = prev {
                    total += wrap(a - p);
                }
                prev = Some(a);
                x = if x.is_nan() {
                    a
                } else {
                    x + wrap(a - wrap_to(x, a))
                };
                lo = lo.min(x);
                hi = hi.max(x);
            }
            if hi - lo >= TAU - 1e-9 {
                full = true;
            } else if lo.is_finite() {
                intervals.push((lo, hi));
            }
        }
        // Close the loop.
        if let (Some(p), Some(first)) = (prev, edges.iter().flatten().find(|s| s.n[d].is_finite()))
        {
            total += wrap(first.n[d] - p);
        }
        windings.push((total / TAU).round() as i64);
        // A seam: an edge the face uses twice.
        let ids: Vec<u64> = bounds[k].edges.iter().map(|e| e.id).collect();
        for (i, e) in bounds[k].edges.iter().enumerate() {
            if (ids.iter().filter(|&&id| id == e.id).count() > 1
                || bounds
                    .iter()
                    .enumerate()
                    .any(|(j, b)| j != k && b.edges.iter().any(|o| o.id == e.id)))
                && let Some(s) = edges[i].iter().find(|s| s.n[d].is_finite())
            {
                seam_angle.get_or_insert(s.n[d]);
            }
        }
    }
    if windings.iter().any(|&w| w != 0) {
        full = true;
    }
    if !full {
        // The largest gap between the covered intervals.
        let mut pieces: Vec<(f64, f64)> = Vec::new();
        for &(lo, hi) in &intervals {
            let a = lo.rem_euclid(TAU);
            let b = a + (hi - lo);
            if b > TAU {
                pieces.push((a, TAU));
                pieces.push((0.0, b - TAU));
            } else {
                pieces.push((a, b));
            }
        }
        pieces.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut merged: Vec<(f64, f64)> = Vec::new();
        for p in pieces {
            match merged.last_mut() {
                Some(m) if p.0 <= m.1 + 1e-12 => m.1 = m.1.max(p.1),
                _ => merged.push(p),
            }
        }
        if let (Some(first), Some(last)) = (merged.first().copied(), merged.last().copied()) {
            // The gaps (width, start), widest first: the face is all but one of them.
            let mut gaps = vec![(first.0 + TAU - last.1, last.1)];
            gaps.extend(merged.windows(2).map(|w| (w[1].0 - w[0].1, w[0].1)));
            gaps.sort_by(|a, b| b.0.total_cmp(&a.0));
            // Edges that cover no angle between their ends (meridians, seen from the axis)
            // leave gaps alike: the loops' direction says which side the face lies on (the
            // kept region on their left, turned by each bound's sense).
            let best = sense
                .and_then(|sense| {
                    gaps.iter()
                        .copied()
                        .filter(|g| g.0 > 1e-9)
                        .find(|&(width, start)| {
                            kept_area(loops, d, (start + 0.5 * width).rem_euclid(TAU), sense) > 0.0
                        })
                })
                .unwrap_or(gaps[0]);
            if best.0 > 1e-9 {
                // A margin each side: the edges bulge past their samples.
                let span = TAU - best.0;
                let margin = arc_margin(span).min(0.25 * best.0);
                let start = (best.1 + best.0 - margin).rem_euclid(TAU);
                return (
                    Range::Angle {
                        start,
                        span: span + 2.0 * margin,
                        full: false,
                    },
                    windings,
                );
            }
        }
    }
    (
        Range::Angle {
            start: seam_angle.unwrap_or(0.0),
            span: TAU,
            full: true,
        },
        windings,
    )
}

/// The area in natural parameters that the loops enclose (each counted with its bound's
/// `sense`, positive where the loop runs counter-clockwise in (u, v)), with angle `d` measured
/// from `start` (the middle of a gap no edge covers) round to a full turn (the other parameter
/// as it is; samples at a pole, whose angle is undefined, left out): positive where the face
/// lies in that turn.
fn kept_area(loops: &[Vec<Vec<Sample>>], d: usize, start: f64, sense: &[f64]) -> f64 {
    let mut total = 0.0;
    for (edges, &sense) in loops.iter().zip(sense) {
        let points: Vec<[f64; 2]> = edges
            .iter()
            .flatten()
            .filter(|s| !s.pole && s.n[0].is_finite() && s.n[1].is_finite())
            .map(|s| {
                let mut n = s.n;
                n[d] = (n[d] - start).rem_euclid(TAU);
                n
            })
            .collect();
        let twice: f64 = (0..points.len())
            .map(|k| {
                let (a, b) = (points[k], points[(k + 1) % points.len()]);
                a[0] * b[1] - b[0] * a[1]
            })
            .sum();
        total += 0.5 * sense * twice;
    }
    total
}

/// `x` moved by whole turns to be nearest `a`.
fn wrap_to(x: f64, a: f64) -> f64 {
    a + wrap(x - a)
}

/// The pieces of one loop in (u, v): each edge use's samples mapped through the ranges; where
/// an angle goes all the way round, cut where the loop crosses the seam (the crossing found
/// by bisection on the edge), and a piece on the seam takes the face's side.
fn loop_pieces(
    edges: &[Vec<Sample>],
    bound: &Bound,
    ranges: &[Range; 2],
    sense: f64,
    natural: &Natural,
) -> Vec<Piece> {
    // Unwrapped natural coordinates relative to each angle's start.
    let mut prev: [Option<f64>; 2] = [None, None];
    let mut pieces = Vec::new();
    for (k, samples) in edges.iter().enumerate() {
        let edge = &bound.edges[k];
        let mut xs: Vec<(Sample, [f64; 2])> = Vec::new();
        for s in samples {
            let mut x = [0.0; 2];
            for d in 0..2 {
                x[d] = match ranges[d] {
                    Range::Angle { start, span, full } => {
                        let a = s.n[d] - start;
                        if full {
                            match prev[d] {
                                Some(p) => p + wrap(a - p),
                                None => a.rem_euclid(TAU),
                            }
                        } else {
                            let r = a.rem_euclid(TAU);
                            if r > span + 1e-12 {
                                if r - span < TAU - r { span } else { 0.0 }
                            } else {
                                r
                            }
                        }
                    }
                    Range::Closed { .. } => match prev[d] {
                        Some(p) => p + wrap(s.n[d] - p),
                        None => s.n[d].rem_euclid(TAU),
                    },
                    _ => s.n[d],
                };
                if !x[d].is_finite() {
                    x[d] = prev[d].unwrap_or(0.0);
                }
                prev[d] = Some(x[d]);
            }
            xs.push((*s, x));
        }
        // Cut at seam crossings (full angles only).
        let mut cut: Vec<(Sample, [f64; 2])> = Vec::new();
        for i in 0..xs.len() {
            if i > 0 {
                let (sa, xa) = xs[i - 1];
                let (_, xb) = xs[i];
                for d in 0..2 {
                    if !ranges[d].full() {
                        continue;
                    }
                    let (fa, fb) = (xa[d] / TAU, xb[d] / TAU);
                    let (ka, kb) = (fa.floor(), fb.floor());
                    let on = |f: f64| (f - f.round()).abs() < 1e-9;
                    if ka != kb && !on(fa) && !on(fb) {
                        let seam = ka.max(kb) * TAU;
                        // Bisect on the edge parameter for the point at the seam.
                        let (mut lo, mut hi) = (sa.s, xs[i].0.s);
                        let at = |s: f64| {
                            if edge.forward {
                                edge.geometry.point(s)
                            } else {
                                edge.geometry.point(1.0 - s)
                            }
                        };
                        let x_of = |s: f64| {
                            let n = natural.of(at(s), Some(sa.n));
                            let start = match ranges[d] {
                                Range::Angle { start, .. } => start,
                                _ => 0.0,
                            };
                            xa[d] + wrap(n[d] - start - xa[d])
                        };
                        let rising = xb[d] > xa[d];
                        for _ in 0..60 {
                            let m = 0.5 * (lo + hi);
                            if (x_of(m) < seam) == rising {
                                lo = m;
                            } else {
                                hi = m;
                            }
                        }
                        let s = 0.5 * (lo + hi);
                        let p = at(s);
                        let mut n = natural.of(p, Some(sa.n));
                        let mut x = xa;
                        x[d] = seam;
                        let e = 1 - d;
                        if !ranges[e].full() {
                            x[e] = xa[e] + (xb[e] - xa[e]) * ((seam - xa[d]) / (xb[d] - xa[d]));
                            if matches!(
                                ranges[e],
                                Range::Linear { .. }
                                    | Range::Arc { .. }
                                    | Range::Raw { .. }
                                    | Range::Closed { .. }
                            ) && n[e].is_finite()
                            {
                                x[e] = n[e];
                            }
                        }
                        n[d] = f64::NAN;
                        cut.push((
                            Sample {
                                p,
                                n,
                                s,
                                pole: false,
                            },
                            x,
                        ));
                    }
                }
            }
            cut.push(xs[i]);
        }
        // Windows per segment, pieces where the window changes.
        let window_of = |a: [f64; 2], b: [f64; 2]| -> [f64; 2] {
            let mut w = [0.0; 2];
            for d in 0..2 {
                if !ranges[d].full() {
                    continue;
                }
                let (fa, fb) = (a[d] / TAU, b[d] / TAU);
                let on_same_seam = (fa - fa.round()).abs() < 1e-9
                    && (fb - fb.round()).abs() < 1e-9
                    && fa.round() == fb.round();
                w[d] = if on_same_seam {
                    let m = fa.round();
                    let e = 1 - d;
                    let travel = b[e] - a[e];
                    // Left of +v travel lies −u; left of +u travel lies +v.
                    let region_low = if d == 0 {
                        (travel > 0.0) == (sense > 0.0)
                    } else {
                        (travel < 0.0) == (sense > 0.0)
                    };
                    if region_low { m - 1.0 } else { m }
                } else {
                    (0.5 * (fa + fb)).floor()
                };
            }
            w
        };
        let to_uv = |x: [f64; 2], w: [f64; 2]| {
            DVec2::new(
                ranges[0].parameter(x[0] - w[0] * TAU),
                ranges[1].parameter(x[1] - w[1] * TAU),
            )
        };
        let origin = CurveOrigin::Edge {
            id: edge.id,
            forward: edge.forward,
        };
        if cut.len() < 2 {
            continue;
        }
        let mut current: Option<([f64; 2], Piece)> = None;
        for i in 1..cut.len() {
            let (sa, xa) = cut[i - 1];
            let (sb, xb) = cut[i];
            let w = window_of(xa, xb);
            match &mut current {
                Some((cw, piece)) if *cw == w => {
                    piece.uv.push(to_uv(xb, w));
                    piece.s.push(sb.s);
                    piece.end_point = sb.p;
                    piece.end_pole = sb.pole;
                }
                _ => {
                    if let Some((_, piece)) = current.take() {
                        pieces.push(piece);
                    }
                    current = Some((
                        w,
                        Piece {
                            uv: vec![to_uv(xa, w), to_uv(xb, w)],
                            origin,
                            exact: None,
                            s: vec![sa.s, sb.s],
                            edge: Some(k),
                            start_point: sa.p,
                            end_point: sb.p,
                            start_pole: sa.pole,
                            end_pole: sb.pole,
                        },
                    ));
                }
            }
        }
        if let Some((_, piece)) = current {
            pieces.push(piece);
        }
    }
    pieces
}

/// A plane's loop: every edge its exact NURBS curve mapped into the plane's (u, v).
fn exact_plane_pieces(
    bound: &Bound,
    frame: &Frame,
    ranges: &[Range; 2],
) -> Result<Vec<Piece>, Skip> {
    let (Range::Linear { lo: u0, hi: u1 }, Range::Linear { lo: v0, hi: v1 }) =
        (ranges[0], ranges[1])
    else {
        return Err("a plane without a linear range".into());
    };
    let mut out = Vec::new();
    for e in &bound.edges {
        let g = &e.geometry;
        let curve = g.nurbs().map_err(|err| format!("edge #{}: {err}", e.id))?;
        let curve = if e.forward { curve } else { curve.reverse() };
        let map = |p: DVec3| {
            let l = frame.local(p);
            DVec2::new((l.x - u0) / (u1 - u0), (l.y - v0) / (v1 - v0))
        };
        let uv = curve
            .map_into(map)
            .map_err(|err| format!("edge #{}: {err}", e.id))?;
        let (a, b) = uv.ends().map_err(|err| err.to_string())?;
        let (pa, pb) = if e.forward {
            (g.start, g.end)
        } else {
            (g.end, g.start)
        };
        out.push(Piece {
            uv: vec![a, b],
            origin: CurveOrigin::Edge {
                id: e.id,
                forward: e.forward,
            },
            exact: Some(uv),
            s: Vec::new(),
            edge: None,
            start_point: pa,
            end_point: pb,
            start_pole: false,
            end_pole: false,
        });
    }
    Ok(out)
}

/// The NURBS of an analytic surface over the face's ranges.
fn analytic_nurbs(
    surface: &Surface3,
    ranges: &[Range; 2],
) -> Result<NurbsSurface, crate::kernel::GeometryError> {
    let angle = |r: Range| match r {
        Range::Angle { start, span, .. } => (start, span),
        _ => (0.0, TAU),
    };
    let linear = |r: Range| match r {
        Range::Linear { lo, hi } | Range::Raw { lo, hi } => (lo, hi),
        Range::Arc { lo, span } => (lo, lo + span),
        _ => (0.0, 1.0),
    };
    match surface {
        Surface3::Plane(f) => {
            let (u0, u1) = linear(ranges[0]);
            let (v0, v1) = linear(ranges[1]);
            construct::plane(
                f.at(DVec3::new(u0, v0, 0.0)),
                f.x * (u1 - u0),
                f.y * (v1 - v0),
            )
        }
        Surface3::Cylinder { frame, radius } => {
            let (start, span) = angle(ranges[0]);
            let (v0, v1) = linear(ranges[1]);
            let x = frame.radial(start);
            let profile = construct::line(
                frame.origin + x * *radius + frame.z * v0,
                frame.origin + x * *radius + frame.z * v1,
            )?;
            construct::revolve(&profile, frame.origin, frame.z, span)
        }
        Surface3::Cone { frame, radius, tan } => {
            let (start, span) = angle(ranges[0]);
            let (v0, v1) = linear(ranges[1]);
            let x = frame.radial(start);
            let at = |v: f64| frame.origin + x * (radius + v * tan) + frame.z * v;
            let profile = construct::line(at(v0), at(v1))?;
            construct::revolve(&profile, frame.origin, frame.z, span)
        }
        Surface3::Sphere { frame, radius } => {
            let (start, span) = angle(ranges[0]);
            let (v0, v1) = linear(ranges[1]);
            let profile =
                construct::arc(frame.origin, frame.radial(start), frame.z, *radius, v0, v1)?;
            construct::revolve(&profile, frame.origin, frame.z, span)
        }
        Surface3::Torus {
            frame,
            major,
            minor,
        } => {
            let (start, span) = angle(ranges[0]);
            let (vs, vspan) = angle(ranges[1]);
            let x = frame.radial(start);
            let profile = construct::arc(
                frame.origin + x * *major,
                x,
                frame.z,
                *minor,
                vs,
                vs + vspan,
            )?;
            construct::revolve(&profile, frame.origin, frame.z, span)
        }
        Surface3::Revolution { frame, curve } => {
            let (start, span) = angle(ranges[0]);
            let turn = DMat3::from_axis_angle(frame.z, start);
            let o = frame.origin;
            let rotated = curve.map_points(|p| o + turn * (p - o))?;
            construct::revolve(&rotated, frame.origin, frame.z, span)
        }
        Surface3::Extrusion { .. } | Surface3::Spline(_) => {
            Err(crate::kernel::GeometryError::Construction {
                what: "STEP face",
                message: "not an analytic surface".into(),
            })
        }
    }
}

/// An extrusion's NURBS over a range along its vector that holds every edge point.
fn build_extrusion(
    curve: &SpaceCurve,
    vector: DVec3,
    bounds: &[Bound],
) -> Result<NurbsSurface, Skip> {
    let dir = vector.normalize_or_zero();
    if dir == DVec3::ZERO {
        return Err("the extrusion's vector has zero length".into());
    }
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for b in bounds {
        for e in &b.edges {
            for k in 0..=16 {
                let x = e.geometry.point(k as f64 / 16.0).dot(dir);
                lo = lo.min(x);
                hi = hi.max(x);
            }
        }
    }
    let (mut c_lo, mut c_hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for k in 0..curve.count() {
        let x = curve.control_point(k).dot(dir);
        c_lo = c_lo.min(x);
        c_hi = c_hi.max(x);
    }
    let (v0, v1) = (lo - c_hi, hi - c_lo);
    if !(v1 > v0) {
        return Err("the face has no extent along its extrusion".into());
    }
    let base = curve
        .map_points(|p| p + dir * v0)
        .map_err(|e| e.to_string())?;
    construct::extrude(&base, dir * (v1 - v0)).map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_arc_parameter_inverts_the_rational_arc() {
        for span in [0.3, FRAC_PI_2, 2.0, PI, 4.5, TAU] {
            let arc = construct::arc(DVec3::ZERO, DVec3::X, DVec3::Y, 1.0, 0.0, span).unwrap();
            for k in 0..=40 {
                let angle = span * k as f64 / 40.0;
                let t = arc_parameter(angle, span);
                let p = arc.point_at(t).unwrap();
                let expected = DVec3::new(angle.cos(), angle.sin(), 0.0);
                assert!(
                    p.distance(expected) < 1e-13,
                    "span {span} angle {angle}: {p} vs {expected}"
                );
            }
        }
    }
}
