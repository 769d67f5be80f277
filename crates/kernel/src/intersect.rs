//! Surface–surface intersection by marching, on the one surface interface
//! ([`ParametricSurface`]), so it serves every kind with faces.
//!
//! 1. **Seeds.** Both domains are cut into cells whose boxes hold the surface: the box of the
//!    corners and the centre, grown by twice the second-order Taylor bound
//!    (|S_uu| Δu² + 2|S_uv| Δu Δv + |S_vv| Δv²)/8 at the samples. Pairs of cells whose boxes
//!    meet are cut again, the larger first, until both cells are smaller than
//!    [`IntersectOptions::smallest`]: a closed loop at least that large crosses such a pair, so
//!    none is missed; a pair is also dropped when one cell's box lies wholly on one side of
//!    the other's slab (its samples' extent along its normal, grown by the same bound), which
//!    a flat, tilted piece's axis-aligned box cannot tell. Each such pair off the branches
//!    traced so far gives a seed by Gauss–Newton from the cells' centres on A(u, v) − B(s, t)
//!    = 0 (the least-norm step of the 3 × 4 system). A pair that a branch crosses is not cut
//!    further when both cells are flat (normals within 15°) and their normal cones are apart
//!    as lines (the pieces meet transversally, in one arc at most; no closed loop by Sinha,
//!    Klassen and Wang's test, 1985). Nearly parallel pieces are cut down to the smallest
//!    size, since their difference may vanish along several arcs.
//! 2. **Marching.** From a seed, the curve's tangent is T = N_A × N_B. A step of length h is
//!    predicted along T and corrected by Newton onto both surfaces with the plane (X − P)·T = h
//!    as the fourth equation. The chord from the last point to the new one is compared with the
//!    curve's point half-way (corrected the same way): when it is off by more than
//!    [`IntersectOptions::chord`] the step is halved, when by far less it grows by half.
//! 3. **Ends.** A branch ends on a domain boundary or a trim (found by bisection on h), closes
//!    when it comes back to its start, or stops where the surfaces touch (|N_A × N_B| below
//!    [`TANGENT_SINE`]); a touching point is reported, not marched through. Each seed not
//!    already on a traced branch starts a new one, marched both ways unless it closes.
//!
//! (Patrikalakis and Maekawa, *Shape Interrogation for Computer Aided Design and
//! Manufacturing*, §5.8: subdivision for seeds, marching with Newton correction.)

use glam::{DVec2, DVec3};

use crate::diffgeo::SurfaceDerivatives;
use crate::error::GeometryError;
use crate::parametric::ParametricSurface;

/// Below this sine of the angle between the normals, the surfaces are taken to touch there.
pub const TANGENT_SINE: f64 = 1e-6;

/// The least cosine between the curve's directions at the two ends of a step (about 30°).
const TURN_COSINE: f64 = 0.866;

/// The most points one branch may have.
const MAX_POINTS: usize = 200_000;

/// What an intersection must meet (absolute distances, in model units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IntersectOptions {
    /// Every point lies within this of both surfaces.
    pub tolerance: f64,
    /// The polyline's chords deviate from the curve by at most this.
    pub chord: f64,
    /// Closed loops at least this large are found.
    pub smallest: f64,
    /// The most pairs of cells one intersection looks at before it takes the surfaces for
    /// coinciding ([`MAX_CELL_PAIRS`] by default).
    pub cell_pairs: usize,
}

impl IntersectOptions {
    /// The defaults for a scene of diagonal `size`: tolerance 1e-6, chord 1e-3 and smallest
    /// loop 1e-2 of it.
    pub fn for_size(size: f64) -> Self {
        let size = size.max(1e-300);
        Self {
            tolerance: 1e-6 * size,
            chord: 1e-3 * size,
            smallest: 1e-2 * size,
            cell_pairs: MAX_CELL_PAIRS,
        }
    }
}

/// How a branch ends.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BranchEnd {
    /// On the boundary of one surface's domain.
    Boundary,
    /// On a trim loop (outside it the surface is cut away).
    Trim,
    /// Where the surfaces touch (the normals are parallel).
    Tangent,
    /// The step fell below the tolerance without reaching an end (reported, not hidden).
    Stalled,
}

/// One branch of the intersection: points on both surfaces and their parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct IntersectionCurve {
    /// Whether it is a closed loop (its last point is its first again).
    pub closed: bool,
    pub points: Vec<DVec3>,
    /// (u, v) on the first surface and (s, t) on the second, one per point.
    pub uv_a: Vec<DVec2>,
    pub uv_b: Vec<DVec2>,
    /// How its start and end stop (`None` for a closed loop).
    pub ends: [Option<BranchEnd>; 2],
}

/// Every branch, and the points where the surfaces touch.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Intersection {
    pub curves: Vec<IntersectionCurve>,
    pub touching: Vec<DVec3>,
    /// Whether the search stopped before it was done ([`MAX_CELL_PAIRS`]): the surfaces lie
    /// on one another over an area (coincide there), where cells meet everywhere and every
    /// seed is a point of tangency.
    pub overlapping: bool,
}

impl Intersection {
    /// The branches with those that meet end to end on a domain boundary (within `gap`, in
    /// space) joined into one: a loop across a seam (a closed surface's domain boundary) is
    /// marched as branches that end on the seam from either side; joined, it is one branch,
    /// closed where it comes back to its start. The parameters jump where it crosses the
    /// seam. Branches that meet where the surfaces touch (a [`BranchEnd::Tangent`] end, where
    /// two branches cross) stay apart.
    pub fn joined_across_seams(mut self, gap: f64) -> Self {
        let (mut open, mut out): (Vec<IntersectionCurve>, Vec<IntersectionCurve>) =
            self.curves.into_iter().partition(|c| !c.closed);
        let at_seam = |c: &IntersectionCurve, end: usize| c.ends[end] == Some(BranchEnd::Boundary);
        let end_point = |c: &IntersectionCurve, end: usize| {
            if end == 0 {
                c.points[0]
            } else {
                c.points[c.points.len() - 1]
            }
        };
        while let Some(mut chain) = open.pop() {
            loop {
                // Another branch whose start or end meets the chain's end.
                let found = open.iter().enumerate().find_map(|(k, c)| {
                    (0..2).find_map(|end| {
                        (at_seam(&chain, 1)
                            && at_seam(c, end)
                            && end_point(c, end).distance(end_point(&chain, 1)) <= gap)
                            .then_some((k, end))
                    })
                });
                let Some((k, end)) = found else {
                    break;
                };
                let mut next = open.swap_remove(k);
                if end == 1 {
                    next.points.reverse();
                    next.uv_a.reverse();
                    next.uv_b.reverse();
                    next.ends.reverse();
                }
                // The joint is one point: the chain's.
                chain.points.extend(next.points.into_iter().skip(1));
                chain.uv_a.extend(next.uv_a.into_iter().skip(1));
                chain.uv_b.extend(next.uv_b.into_iter().skip(1));
                chain.ends[1] = next.ends[1];
            }
            let n = chain.points.len();
            if n > 3
                && at_seam(&chain, 0)
                && at_seam(&chain, 1)
                && chain.points[0].distance(chain.points[n - 1]) <= gap
            {
                chain.points[n - 1] = chain.points[0];
                chain.uv_a[n - 1] = chain.uv_a[0];
                chain.uv_b[n - 1] = chain.uv_b[0];
                chain.closed = true;
                chain.ends = [None, None];
            }
            out.push(chain);
        }
        self.curves = out;
        self
    }
}

/// A point on both surfaces: parameters (u, v, s, t) and the point.
#[derive(Debug, Clone, Copy)]
struct Common {
    x: [f64; 4],
    point: DVec3,
}

/// One surface with what the marching asks of it.
#[derive(Clone, Copy)]
pub(crate) struct Side<'a> {
    pub(crate) surface: &'a dyn ParametricSurface,
    pub(crate) domain: [(f64, f64); 2],
}

impl<'a> Side<'a> {
    pub(crate) fn of(surface: &'a dyn ParametricSurface) -> Self {
        Self {
            surface,
            domain: surface.domain(),
        }
    }

    fn inside(&self, u: f64, v: f64) -> bool {
        let [(u0, u1), (v0, v1)] = self.domain;
        u >= u0 && u <= u1 && v >= v0 && v <= v1
    }

    /// Within one domain width of the domain (where [`newton_step`] may extrapolate).
    fn near(&self, u: f64, v: f64) -> bool {
        let [(u0, u1), (v0, v1)] = self.domain;
        let (du, dv) = (u1 - u0, v1 - v0);
        u >= u0 - du && u <= u1 + du && v >= v0 - dv && v <= v1 + dv
    }

    pub(crate) fn clamp(&self, u: f64, v: f64) -> (f64, f64) {
        let [(u0, u1), (v0, v1)] = self.domain;
        (u.clamp(u0, u1), v.clamp(v0, v1))
    }

    pub(crate) fn at(&self, u: f64, v: f64) -> Option<SurfaceDerivatives> {
        self.surface.derivatives(u, v)
    }

    /// The derivatives at the nearest point of the domain and the point there moved to first
    /// order to (u, v): the surface itself inside the domain, its tangent plane beyond.
    fn extrapolated(&self, u: f64, v: f64) -> Option<(SurfaceDerivatives, DVec3)> {
        let (cu, cv) = self.clamp(u, v);
        let d = self.at(cu, cv)?;
        let p = d.point + d.su * (u - cu) + d.sv * (v - cv);
        Some((d, p))
    }
}

/// The sine of the angle between the two surfaces' tangent planes and the unit tangent of
/// their intersection at `x`.
fn tangent(a: &SurfaceDerivatives, b: &SurfaceDerivatives) -> Option<(f64, DVec3)> {
    let na = a.su.cross(a.sv).try_normalize()?;
    let nb = b.su.cross(b.sv).try_normalize()?;
    let t = na.cross(nb);
    let sine = t.length();
    Some((sine, t / sine.max(1e-300)))
}

/// Solves the 4 × 4 system `m x = r` (rows of `m`) by the inverse; `None` when it is singular.
fn solve4(m: [[f64; 4]; 4], r: [f64; 4]) -> Option<[f64; 4]> {
    let m = glam::DMat4::from_cols_array_2d(&m).transpose();
    let det = m.determinant();
    if !(det.abs() > 1e-300) {
        return None;
    }
    let x = (m.inverse() * glam::DVec4::from_array(r)).to_array();
    x.iter().all(|c| c.is_finite()).then_some(x)
}

/// Gauss–Newton from `x` onto A(u, v) = B(s, t): the least-norm step of the 3 × 4 system
/// J dx = −F, J = [A_u A_v −B_s −B_t], parameters kept in the domains. `None` when it does not
/// come within `tolerance`.
fn converge(a: &Side<'_>, b: &Side<'_>, mut x: [f64; 4], tolerance: f64) -> Option<Common> {
    for _ in 0..40 {
        let da = a.at(x[0], x[1])?;
        let db = b.at(x[2], x[3])?;
        let f = da.point - db.point;
        if f.length() <= tolerance * 1e-3 {
            return Some(Common {
                x,
                point: 0.5 * (da.point + db.point),
            });
        }
        let cols = [da.su, da.sv, -db.su, -db.sv];
        // (J Jᵀ) y = −F, dx = Jᵀ y.
        let mut jjt = [[0.0; 3]; 3];
        for (i, row) in jjt.iter_mut().enumerate() {
            for (j, entry) in row.iter_mut().enumerate() {
                *entry = cols.iter().map(|c| c[i] * c[j]).sum();
            }
        }
        let m = glam::DMat3::from_cols_array_2d(&jjt).transpose();
        if m.determinant().abs() < 1e-300 {
            return None;
        }
        let y = m.inverse() * (-f);
        let step: Vec<f64> = cols.iter().map(|c| c.dot(y)).collect();
        let (u, v) = a.clamp(x[0] + step[0], x[1] + step[1]);
        let (s, t) = b.clamp(x[2] + step[2], x[3] + step[3]);
        let moved = (u - x[0]).abs() + (v - x[1]).abs() + (s - x[2]).abs() + (t - x[3]).abs();
        x = [u, v, s, t];
        if moved == 0.0 {
            break;
        }
    }
    let (pa, pb) = (a.surface.point(x[0], x[1])?, b.surface.point(x[2], x[3])?);
    (pa.distance(pb) <= tolerance).then(|| Common {
        x,
        point: 0.5 * (pa + pb),
    })
}

/// Where a point stops being usable: outside a domain, or cut away by a trim.
fn stop_kind(a: &Side<'_>, b: &Side<'_>, x: &[f64; 4]) -> Option<BranchEnd> {
    if !a.inside(x[0], x[1]) || !b.inside(x[2], x[3]) {
        return Some(BranchEnd::Boundary);
    }
    if !a.surface.keeps(x[0], x[1]) || !b.surface.keeps(x[2], x[3]) {
        return Some(BranchEnd::Trim);
    }
    None
}

/// The share of the chord tolerance a step's middle may stray: the curve strays from a chord
/// most at its middle only where its curvature is even along it, and up to a third more
/// elsewhere (as OpenCASCADE's lines, sampled finely, show on random sheets).
const CHORD_MARGIN: f64 = 0.75;

/// How many chord tolerances a surface's point half-way between a step's ends in its own
/// parameters may stray across the chord ([`parameter_bend`]), beyond the curve's own bow,
/// before the step is shortened.
const BEND_FACTOR: f64 = 0.25;

/// The cosine of the largest turn between two steps in either surface's (u, v) (20°; see
/// [`parameters_turn`]).
const PARAMETER_TURN_COSINE: f64 = 0.94;

/// The share of the chord tolerance below which a step's middle alone is checked
/// ([`chord_error`]): a curve that strays this little at its middle is far inside the
/// tolerance at its quarters unless it turns back within the step, which the turn check cuts.
const PLAIN: f64 = 0.25;

/// One direction of a branch from `start`, along `sign`·T: its points after `start`, whether
/// it came back to `start`, and how it ended.
fn march(
    a: &Side<'_>,
    b: &Side<'_>,
    start: &Common,
    sign: f64,
    options: &IntersectOptions,
) -> (Vec<Common>, bool, BranchEnd) {
    let mut points: Vec<Common> = Vec::new();
    let mut current = *start;
    // The point before `current`, once there is one.
    let mut before: Option<Common> = None;
    let mut previous_direction: Option<DVec3> = None;
    let mut h = (options.chord * 8.0).max(options.tolerance * 100.0);
    let h_min = options.tolerance * 10.0;
    let mut travelled = 0.0;
    // Both surfaces' derivatives at the current point, when the last step worked them out.
    let mut known: Option<(SurfaceDerivatives, SurfaceDerivatives)> = None;
    loop {
        if points.len() >= MAX_POINTS {
            return (points, false, BranchEnd::Stalled);
        }
        let Some((da, db)) = known.take().or_else(|| {
            a.at(current.x[0], current.x[1])
                .zip(b.at(current.x[2], current.x[3]))
        }) else {
            return (points, false, BranchEnd::Stalled);
        };
        let Some((sine, t)) = tangent(&da, &db) else {
            return (points, false, BranchEnd::Tangent);
        };
        if sine < TANGENT_SINE {
            return (points, false, BranchEnd::Tangent);
        }
        // Keep going the same way: the tangent's sign is fixed by the last step.
        let direction = match previous_direction {
            Some(before) if t.dot(before) < 0.0 => -t,
            Some(_) => t,
            None => t * sign,
        };
        // Closing: the start lies ahead within this step.
        if travelled > 4.0 * h.max(options.chord) {
            let to_start = start.point - current.point;
            let ahead = to_start.dot(direction);
            if ahead > 0.0
                && ahead <= 1.5 * h
                && (to_start - direction * ahead).length() <= options.chord.max(ahead * 0.2)
            {
                // The closing chord passes the same check as any step: the curve's point half
                // way to the start lies within the chord tolerance of the chord's middle;
                // otherwise step short of the start and look again.
                let error = chord_error(
                    a,
                    b,
                    &current,
                    start,
                    options.tolerance,
                    PLAIN * options.chord,
                );
                if error <= CHORD_MARGIN * options.chord {
                    points.push(*start);
                    return (points, true, BranchEnd::Boundary);
                }
                h = h.min(0.5 * ahead);
            }
        }
        let next = loop {
            if h < h_min {
                return (points, false, BranchEnd::Stalled);
            }
            let candidate = newton_step(a, b, &current, direction, h, options.tolerance);
            match candidate {
                Some(next) if stop_kind(a, b, &next.x).is_none() => {
                    // Chord check against the curve's point half-way.
                    let error = chord_error(
                        a,
                        b,
                        &current,
                        &next,
                        options.tolerance,
                        PLAIN * options.chord,
                    );
                    // The curve's direction at the new point (the same cross product, so it
                    // turns continuously along the branch) within about 30° of this one:
                    // a step that lands on another arm of the curve (across a narrow
                    // finger, say) points elsewhere and is cut.
                    let at_next = a.at(next.x[0], next.x[1]).zip(b.at(next.x[2], next.x[3]));
                    let turned = at_next
                        .as_ref()
                        .and_then(|(na, nb)| tangent(na, nb))
                        .is_none_or(|(_, t2)| {
                            (t2 * t.dot(direction).signum()).dot(direction) < TURN_COSINE
                        });
                    // Where a surface's parameters run unevenly along the step (near a
                    // sphere's pole, where a curve passing close sweeps u), the (u, v)
                    // points are kept close enough for curves through them to follow.
                    if error > CHORD_MARGIN * options.chord
                        || (turned && h > 2.0 * h_min)
                        || (h > 2.0 * h_min
                            && uneven(a, b, before.as_ref(), &current, &next, error, options))
                    {
                        h *= 0.5;
                        continue;
                    }
                    if error < options.chord * 0.25 {
                        h *= 1.5;
                    }
                    known = at_next;
                    break next;
                }
                _ => {
                    // Past a boundary or a trim (or no convergence there): bisect the step
                    // down to the last point that is still on both surfaces.
                    let Some((end, kind)) = boundary_between(a, b, &current, direction, h, options)
                    else {
                        h *= 0.5;
                        continue;
                    };
                    // The last chord, to the boundary, is held to the tolerance and to even
                    // (u, v) steps too: where it strays, a shorter step first.
                    let along = (end.point - current.point).dot(direction);
                    let error = chord_error(
                        a,
                        b,
                        &current,
                        &end,
                        options.tolerance,
                        PLAIN * options.chord,
                    );
                    if (error > CHORD_MARGIN * options.chord
                        || uneven(a, b, before.as_ref(), &current, &end, error, options))
                        && along > 4.0 * h_min
                    {
                        h = 0.5 * along;
                        continue;
                    }
                    if end.point.distance(current.point) > options.tolerance {
                        points.push(end);
                    }
                    return (points, false, kind);
                }
            }
        };
        travelled += next.point.distance(current.point);
        previous_direction = Some(direction);
        points.push(next);
        before = Some(current);
        current = next;
    }
}

/// Whether the step `from`–`to` (after `before`, where there is one) runs unevenly in either
/// surface's parameters: its (u, v) middle strays across the chord by more than the curve's
/// own bow (`error`) and a share of the chord tolerance, or its (u, v) turns sharply from the
/// step before.
fn uneven(
    a: &Side<'_>,
    b: &Side<'_>,
    before: Option<&Common>,
    from: &Common,
    to: &Common,
    error: f64,
    options: &IntersectOptions,
) -> bool {
    parameter_bend(a, b, from, to) > error + BEND_FACTOR * options.chord
        || before.is_some_and(|p| parameters_turn(p, from, to))
}

/// How far each surface's point half-way between the step's ends in its own parameters
/// lies from the line of the chord `from`–`to`, the larger (across the chord only: sliding
/// along the curve does no harm). About the curve's own bow from the chord where the
/// parameters run evenly, far more where they do not (near a sphere's pole, where a curve
/// passing close sweeps u), where (u, v) curves through the points would stray in space
/// between them.
fn parameter_bend(a: &Side<'_>, b: &Side<'_>, from: &Common, to: &Common) -> f64 {
    let chord = to.point - from.point;
    let length2 = chord.length_squared();
    if !(length2 > 0.0) {
        return 0.0;
    }
    let off = |side: &Side<'_>, i: usize| {
        let (u, v) = (
            0.5 * (from.x[i] + to.x[i]),
            0.5 * (from.x[i + 1] + to.x[i + 1]),
        );
        side.surface.point(u, v).map_or(f64::INFINITY, |p| {
            let d = p - from.point;
            (d - chord * (d.dot(chord) / length2)).length()
        })
    };
    off(a, 0).max(off(b, 2))
}

/// Whether the (u, v) points `p`, `q`, `r` on either surface turn by more than about 20° at
/// `q`: a curve through such points overshoots the corner by a share of the step, which in
/// space is large where the parameters are bunched (the same turn near a sphere's pole).
fn parameters_turn(p: &Common, q: &Common, r: &Common) -> bool {
    [0, 2].into_iter().any(|i| {
        let d1 = DVec2::new(q.x[i] - p.x[i], q.x[i + 1] - p.x[i + 1]);
        let d2 = DVec2::new(r.x[i] - q.x[i], r.x[i + 1] - q.x[i + 1]);
        d1.dot(d2) < PARAMETER_TURN_COSINE * d1.length() * d2.length()
    })
}

/// How far the curve strays from the chord `from`–`to`: the distance from the chord's middle
/// to the curve's point on the plane through it normal to the chord and, where that is more
/// than `plain` (a step near its limit), the same at a quarter and three quarters of it (the
/// middle alone misses a curve whose curvature changes along the step, as near an
/// inflection), the largest; infinite where such a point is not found.
fn chord_error(
    a: &Side<'_>,
    b: &Side<'_>,
    from: &Common,
    to: &Common,
    tolerance: f64,
    plain: f64,
) -> f64 {
    let chord = to.point - from.point;
    let length = chord.length();
    if !(length > 0.0) {
        return 0.0;
    }
    let off = |f: f64| {
        newton_step(a, b, from, chord / length, f * length, tolerance)
            .map_or(f64::INFINITY, |m| m.point.distance(from.point + f * chord))
    };
    let middle = off(0.5);
    if middle <= plain {
        return middle;
    }
    middle.max(off(0.25)).max(off(0.75))
}

/// The last point on both surfaces along `direction` from `from` before a step of `h` leaves a
/// domain or a trim, by bisection on the step; `None` when the full step stays usable (it
/// failed for another reason).
fn boundary_between(
    a: &Side<'_>,
    b: &Side<'_>,
    from: &Common,
    direction: DVec3,
    h: f64,
    options: &IntersectOptions,
) -> Option<(Common, BranchEnd)> {
    // The full step leaves a domain or a trim (or does not converge).
    let beyond = newton_step(a, b, from, direction, h, options.tolerance)?;
    stop_kind(a, b, &beyond.x)?;
    let (mut lo, mut hi) = (0.0, h);
    let mut last = *from;
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        match newton_step(a, b, from, direction, mid, options.tolerance) {
            Some(p) if stop_kind(a, b, &p.x).is_none() => {
                lo = mid;
                last = p;
            }
            _ => hi = mid,
        }
        if hi - lo <= options.tolerance * 1e-3 {
            break;
        }
    }
    // What is crossed first is what the step just past the last usable point crosses: a
    // trim lying inside the domain (a face trimmed a little short of its surface's edge)
    // stops the branch before the domain's edge does.
    let past = newton_step(a, b, from, direction, hi, options.tolerance).unwrap_or(beyond);
    let mut kind = stop_kind(a, b, &past.x).or(stop_kind(a, b, &beyond.x))?;
    // Onto the boundary itself: the crossed parameter held at its bound while the other
    // three solve A = B, where that converges and the point is kept by both faces' trims or
    // lies within a hair of where the trim stopped the branch (a trim along a seam, a
    // rounding inside it: the branch's piece on the seam's other side ends on the seam
    // too); else clamp and converge.
    let bounds = parameter_bounds(a, b);
    let hair = |i: usize| hair(&bounds, i);
    let near_last = |p: &Common| (0..4).all(|i| (p.x[i] - last.x[i]).abs() <= hair(i));
    let onto = crossed_bound(a, b, &past.x)
        .or(crossed_bound(a, b, &beyond.x))
        .filter(|&(i, bound)| kind == BranchEnd::Boundary || (last.x[i] - bound).abs() <= hair(i))
        .and_then(|(i, bound)| converge_holding(a, b, last.x, i, bound, options.tolerance))
        .filter(|p| {
            (a.surface.keeps(p.x[0], p.x[1]) && b.surface.keeps(p.x[2], p.x[3])) || near_last(p)
        });
    if onto.is_some() {
        kind = BranchEnd::Boundary;
    }
    let end = onto.unwrap_or_else(|| {
        let (u, v) = a.clamp(last.x[0], last.x[1]);
        let (s, t) = b.clamp(last.x[2], last.x[3]);
        converge(a, b, [u, v, s, t], options.tolerance).unwrap_or(last)
    });
    Some((end, kind))
}

/// The ranges of the four parameters (u, v, s, t).
fn parameter_bounds(a: &Side<'_>, b: &Side<'_>) -> [(f64, f64); 4] {
    [a.domain[0], a.domain[1], b.domain[0], b.domain[1]]
}

/// A hair in parameter `i` (0–3: u, v, s, t): 1e-9 of its range.
fn hair(bounds: &[(f64, f64); 4], i: usize) -> f64 {
    1e-9 * (bounds[i].1 - bounds[i].0)
}

/// The parameter (0–3: u, v, s, t) that `x` takes past its domain, and the bound it passed.
fn crossed_bound(a: &Side<'_>, b: &Side<'_>, x: &[f64; 4]) -> Option<(usize, f64)> {
    let bounds = parameter_bounds(a, b);
    (0..4).find_map(|i| {
        let (lo, hi) = bounds[i];
        if x[i] < lo {
            Some((i, lo))
        } else if x[i] > hi {
            Some((i, hi))
        } else {
            None
        }
    })
}

/// Newton from `x` onto A(u, v) = B(s, t) with parameter `held` fixed at `value`: the 3 × 3
/// system of the other three (a boundary isocurve of one surface meeting the other surface),
/// so that a branch ends exactly on the boundary it crosses, where a branch from the other
/// side of a seam ends too. `None` when it does not converge within `tolerance` or leaves a
/// domain.
fn converge_holding(
    a: &Side<'_>,
    b: &Side<'_>,
    mut x: [f64; 4],
    held: usize,
    value: f64,
    tolerance: f64,
) -> Option<Common> {
    x[held] = value;
    let free: Vec<usize> = (0..4).filter(|&i| i != held).collect();
    for _ in 0..30 {
        let (da, pa) = a.extrapolated(x[0], x[1])?;
        let (db, pb) = b.extrapolated(x[2], x[3])?;
        let f = pa - pb;
        if f.length() <= tolerance * 1e-3 {
            // A parameter a hair past its bound is on it (a boundary shared by both surfaces
            // is met on both at once).
            let bounds = parameter_bounds(a, b);
            for (i, c) in x.iter_mut().enumerate() {
                let (lo, hi) = bounds[i];
                if *c < lo && *c >= lo - hair(&bounds, i) {
                    *c = lo;
                } else if *c > hi && *c <= hi + hair(&bounds, i) {
                    *c = hi;
                }
            }
            return (a.inside(x[0], x[1]) && b.inside(x[2], x[3])).then(|| Common {
                x,
                point: 0.5 * (pa + pb),
            });
        }
        let cols = [da.su, da.sv, -db.su, -db.sv];
        let m = glam::DMat3::from_cols(cols[free[0]], cols[free[1]], cols[free[2]]);
        if !(m.determinant().abs() > 1e-300) {
            return None;
        }
        let step = m.inverse() * (-f);
        for (k, &i) in free.iter().enumerate() {
            x[i] += step[k];
        }
        if !x.iter().all(|c| c.is_finite()) || !a.near(x[0], x[1]) || !b.near(x[2], x[3]) {
            return None;
        }
    }
    None
}

/// The point of the intersection on the plane (X − `from`)·`direction` = `h`, by Newton from
/// `from`'s parameters moved to first order, with the fourth equation of the plane. The
/// surfaces are evaluated at the nearest point of their domains and extrapolated linearly
/// beyond, so the parameters may leave a domain (by at most its width): the caller sees where
/// a branch crosses a boundary.
fn newton_step(
    a: &Side<'_>,
    b: &Side<'_>,
    from: &Common,
    direction: DVec3,
    h: f64,
    tolerance: f64,
) -> Option<Common> {
    // First order: the parameter steps along each surface that move by h·T.
    let first = |d: &SurfaceDerivatives| -> Option<(f64, f64)> {
        let target = direction * h;
        let (e, f, g) = (d.su.dot(d.su), d.su.dot(d.sv), d.sv.dot(d.sv));
        let det = e * g - f * f;
        if det.abs() < 1e-300 {
            return None;
        }
        let (p, q) = (d.su.dot(target), d.sv.dot(target));
        Some(((g * p - f * q) / det, (e * q - f * p) / det))
    };
    let da = a.at(from.x[0], from.x[1])?;
    let db = b.at(from.x[2], from.x[3])?;
    let (du, dv) = first(&da)?;
    let (ds, dt) = first(&db)?;
    let mut x = [
        from.x[0] + du,
        from.x[1] + dv,
        from.x[2] + ds,
        from.x[3] + dt,
    ];
    for _ in 0..20 {
        if !(a.near(x[0], x[1]) && b.near(x[2], x[3])) {
            return None;
        }
        let (da, pa) = a.extrapolated(x[0], x[1])?;
        let (db, pb) = b.extrapolated(x[2], x[3])?;
        let f = pa - pb;
        let g = (pa - from.point).dot(direction) - h;
        if f.length() <= tolerance * 1e-2 && g.abs() <= tolerance * 1e-2 {
            return Some(Common {
                x,
                point: 0.5 * (pa + pb),
            });
        }
        let m = [
            [da.su.x, da.sv.x, -db.su.x, -db.sv.x],
            [da.su.y, da.sv.y, -db.su.y, -db.sv.y],
            [da.su.z, da.sv.z, -db.su.z, -db.sv.z],
            [da.su.dot(direction), da.sv.dot(direction), 0.0, 0.0],
        ];
        let dx = solve4(m, [-f.x, -f.y, -f.z, -g])?;
        for k in 0..4 {
            x[k] += dx[k];
        }
    }
    None
}

/// A surface's cells as a quadtree whose quarters are made once, however many cells of the
/// other surface each is paired with (node 0: the whole domain).
pub(crate) struct CellTree {
    /// Each cell with its quarters' indices (a range: they are made together), once made.
    nodes: Vec<(Cell, Option<std::ops::Range<usize>>)>,
}

impl CellTree {
    pub(crate) fn new(side: &Side<'_>) -> Option<Self> {
        let [u, v] = side.domain;
        Some(Self {
            nodes: vec![(Cell::new(side, u, v)?, None)],
        })
    }

    pub(crate) fn cell(&self, k: usize) -> Cell {
        self.nodes[k].0
    }

    /// The indices of node `k`'s quarters (those the surface is defined on), made on first
    /// asking.
    pub(crate) fn children(&mut self, side: &Side<'_>, k: usize) -> std::ops::Range<usize> {
        if let Some(children) = &self.nodes[k].1 {
            return children.clone();
        }
        let quarters = self.nodes[k].0.quarters(side);
        let first = self.nodes.len();
        self.nodes.extend(quarters.into_iter().map(|q| (q, None)));
        let children = first..self.nodes.len();
        self.nodes[k].1 = Some(children.clone());
        children
    }
}

/// Whether the segment from `a` to `b` passes through the box [lo, hi] (the slab method: the
/// parameter intervals where it lies between each pair of faces overlap within [0, 1]).
fn segment_meets_box(a: DVec3, b: DVec3, lo: DVec3, hi: DVec3) -> bool {
    let d = b - a;
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for k in 0..3 {
        if d[k].abs() < 1e-300 {
            if a[k] < lo[k] || a[k] > hi[k] {
                return false;
            }
            continue;
        }
        let (p, q) = ((lo[k] - a[k]) / d[k], (hi[k] - a[k]) / d[k]);
        t0 = t0.max(p.min(q));
        t1 = t1.min(p.max(q));
        if t0 > t1 {
            return false;
        }
    }
    true
}

/// A cell of a surface's domain and the box that holds its piece of the surface.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Cell {
    u: (f64, f64),
    v: (f64, f64),
    pub(crate) lo: DVec3,
    pub(crate) hi: DVec3,
    /// The cone of the normals at the samples: its axis (the first regular normal) and
    /// half-angle (radians). Where two cells' cones are apart as lines, their pieces meet
    /// transversally everywhere and hold no closed loop.
    axis: Option<DVec3>,
    spread: f64,
    /// The piece's extent along `axis` (the samples' projections, grown like the box): a slab
    /// that holds the piece, tighter than the box where the piece is flat and tilted.
    slab: (f64, f64),
}

/// How many times [`IntersectOptions::smallest`] a pair of flat, transversal cells that a
/// branch crosses may measure and be passed over as holding nothing more.
const SETTLED_CELLS: f64 = 8.0;

/// The largest spread (radians, about 15°) of a flat cell's normals.
const FLAT_SPREAD: f64 = 0.26;

/// Added to the cones' half-angles (about 5°): the samples are not every normal.
const CONE_MARGIN: f64 = 0.09;

impl Cell {
    /// The cell over [u0, u1] × [v0, v1] with its box (see the module documentation).
    fn new(side: &Side<'_>, u: (f64, f64), v: (f64, f64)) -> Option<Self> {
        let (du, dv) = (u.1 - u.0, v.1 - v.0);
        let at = |i: f64, j: f64| side.at(u.0 + du * i, v.0 + dv * j);
        Some(Self::from_samples(
            u,
            v,
            [
                at(0.0, 0.0)?,
                at(1.0, 0.0)?,
                at(0.0, 1.0)?,
                at(1.0, 1.0)?,
                at(0.5, 0.5)?,
            ],
        ))
    }

    /// The cell over [u0, u1] × [v0, v1] from the surface at its corners ((u0, v0), (u1, v0),
    /// (u0, v1), (u1, v1)) and its centre.
    fn from_samples(u: (f64, f64), v: (f64, f64), samples: [SurfaceDerivatives; 5]) -> Self {
        let (du, dv) = (u.1 - u.0, v.1 - v.0);
        let mut lo = DVec3::INFINITY;
        let mut hi = DVec3::NEG_INFINITY;
        let mut bound = 0.0f64;
        let mut first_normal: Option<DVec3> = None;
        let mut spread = 0.0f64;
        let mut points = [DVec3::ZERO; 5];
        for (k, d) in samples.iter().enumerate() {
            points[k] = d.point;
            lo = lo.min(d.point);
            hi = hi.max(d.point);
            match (d.regular_normal(), first_normal) {
                (Some(n), None) => first_normal = Some(n),
                (Some(n), Some(f)) => spread = spread.max(n.dot(f).clamp(-1.0, 1.0).acos()),
                // A pole (a collapsed edge) has no normal; its neighbours decide.
                (None, _) => {}
            }
            let second = d.suu.length() * du * du
                + 2.0 * d.suv.length() * du * dv
                + d.svv.length() * dv * dv;
            bound = bound.max(second / 8.0);
        }
        let grow = DVec3::splat(2.0 * bound);
        let slab = first_normal.map_or((0.0, 0.0), |n| {
            let (a, b) = points
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
                    (a.min(p.dot(n)), b.max(p.dot(n)))
                });
            (a - 2.0 * bound, b + 2.0 * bound)
        });
        Self {
            u,
            v,
            lo: lo - grow,
            hi: hi + grow,
            axis: first_normal,
            spread,
            slab,
        }
    }

    /// Whether the normals at the samples lie within [`FLAT_SPREAD`] of each other.
    fn flat(&self) -> bool {
        self.axis.is_some() && self.spread <= FLAT_SPREAD
    }

    /// Whether the two cells' normal cones are apart as lines (no normal of one parallel to a
    /// normal of the other): their pieces then meet transversally, in no closed loop.
    fn transversal(&self, other: &Cell) -> bool {
        let (Some(a), Some(b)) = (self.axis, other.axis) else {
            return false;
        };
        let angle = a.dot(b).abs().clamp(0.0, 1.0).acos();
        angle > self.spread + other.spread + 2.0 * CONE_MARGIN
    }

    /// Whether `other`'s box lies wholly on one side of this cell's slab (more than `slack`
    /// away): the two pieces cannot meet.
    fn slab_separates(&self, other: &Cell, slack: f64) -> bool {
        let Some(n) = self.axis else {
            return false;
        };
        // The box's extent along n: its centre's projection ± the half-diagonal's.
        let centre = 0.5 * (other.lo + other.hi);
        let half = 0.5 * (other.hi - other.lo);
        let c = centre.dot(n);
        let r = half.dot(n.abs());
        let (mut lo, mut hi) = (c - r, c + r);
        // Where the other piece's normals lie near n (two offset surfaces, a thin wall, in
        // general position, where the box is much wider than the piece along n), its own
        // slab bounds it more tightly: with m its axis turned toward n, a point p of it has
        // p·m within its slab and |p − centre| within the box's half-diagonal h, so
        // p·n = p·m + (p − centre)·(n − m) + centre·(n − m) lies within
        // [slab] + centre·(n − m) ± h |n − m|.
        if let Some(m) = other.axis {
            let (m, (s0, s1)) = if m.dot(n) < 0.0 {
                (-m, (-other.slab.1, -other.slab.0))
            } else {
                (m, other.slab)
            };
            let tilt = n - m;
            let (shift, reach) = (centre.dot(tilt), half.length() * tilt.length());
            lo = lo.max(s0 + shift - reach);
            hi = hi.min(s1 + shift + reach);
        }
        hi < self.slab.0 - slack || lo > self.slab.1 + slack
    }

    pub(crate) fn size(&self) -> f64 {
        self.lo.distance(self.hi)
    }

    fn meets(&self, other: &Cell, slack: f64) -> bool {
        (self.lo - slack).cmple(other.hi).all() && (other.lo - slack).cmple(self.hi).all()
    }

    fn quarters(&self, side: &Side<'_>) -> Vec<Cell> {
        let (um, vm) = (0.5 * (self.u.0 + self.u.1), 0.5 * (self.v.0 + self.v.1));
        // The 3 × 3 corners the quarters share, each worked out once.
        let (us, vs) = ([self.u.0, um, self.u.1], [self.v.0, vm, self.v.1]);
        let corner: [[Option<SurfaceDerivatives>; 3]; 3] =
            std::array::from_fn(|j| std::array::from_fn(|i| side.at(us[i], vs[j])));
        let mut out = Vec::with_capacity(4);
        for (i, j) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
            let (u, v) = ((us[i], us[i + 1]), (vs[j], vs[j + 1]));
            let centre = side.at(0.5 * (u.0 + u.1), 0.5 * (v.0 + v.1));
            let samples = [
                corner[j][i],
                corner[j][i + 1],
                corner[j + 1][i],
                corner[j + 1][i + 1],
                centre,
            ];
            if let [Some(a), Some(b), Some(c), Some(d), Some(e)] = samples {
                out.push(Cell::from_samples(u, v, [a, b, c, d, e]));
            }
        }
        out
    }

    pub(crate) fn centre(&self) -> (f64, f64) {
        (0.5 * (self.u.0 + self.u.1), 0.5 * (self.v.0 + self.v.1))
    }
}

/// The distance from `p` to the polyline `points`.
fn distance_to_polyline(points: &[DVec3], p: DVec3) -> f64 {
    if points.len() == 1 {
        return points[0].distance(p);
    }
    points
        .windows(2)
        .map(|w| {
            let ab = w[1] - w[0];
            let t = ((p - w[0]).dot(ab) / ab.length_squared().max(1e-300)).clamp(0.0, 1.0);
            p.distance(w[0] + ab * t)
        })
        .fold(f64::INFINITY, f64::min)
}

/// Every branch of the intersection of `a` and `b` (see the module documentation).
pub fn intersect_surfaces(
    a: &dyn ParametricSurface,
    b: &dyn ParametricSurface,
    options: &IntersectOptions,
) -> Result<Intersection, GeometryError> {
    check_options(options)?;
    let (a, b) = (Side::of(a), Side::of(b));
    let (Some(mut tree_a), Some(mut tree_b)) = (CellTree::new(&a), CellTree::new(&b)) else {
        return Ok(Intersection::default());
    };
    Ok(intersect_trees(
        (&a, &mut tree_a),
        (&b, &mut tree_b),
        options,
    ))
}

/// The cell trees of a list of faces, each made on first use and kept (with the cells
/// refined so far) for every other pair the face takes part in.
pub(crate) struct CachedTrees {
    trees: Vec<Option<Option<CellTree>>>,
}

impl CachedTrees {
    /// No tree made yet for any of `count` faces.
    pub(crate) fn new(count: usize) -> Self {
        Self {
            trees: (0..count).map(|_| None).collect(),
        }
    }
}

/// [`intersect_surfaces`] of face `a` (number `i` of its list) and face `b` (number `j` of
/// its), each face's cell tree made once for all its pairs.
pub(crate) fn intersect_cached(
    (a, trees_a, i): (&dyn ParametricSurface, &mut CachedTrees, usize),
    (b, trees_b, j): (&dyn ParametricSurface, &mut CachedTrees, usize),
    options: &IntersectOptions,
) -> Result<Intersection, GeometryError> {
    check_options(options)?;
    let (side_a, side_b) = (Side::of(a), Side::of(b));
    let tree_a = trees_a.trees[i].get_or_insert_with(|| CellTree::new(&side_a));
    let tree_b = trees_b.trees[j].get_or_insert_with(|| CellTree::new(&side_b));
    let (Some(tree_a), Some(tree_b)) = (tree_a.as_mut(), tree_b.as_mut()) else {
        return Ok(Intersection::default());
    };
    Ok(intersect_trees(
        (&side_a, tree_a),
        (&side_b, tree_b),
        options,
    ))
}

/// The most pairs of cells one intersection looks at. Surfaces that cross are done in a few
/// thousand (a plate and a pin through it: about 1,500; a ball through a block's face 26,000;
/// the most in the kernel's tests 55,000); surfaces that coincide over an area meet in every
/// pair of cells down to the smallest, which would take hours.
pub const MAX_CELL_PAIRS: usize = 200_000;

/// The branches between face i of one set and face j of another: ((i, j), branches).
pub type FacePairIntersection = ((usize, usize), Intersection);

/// Every intersection of a face of `a` with a face of `b`, as [`intersect_surfaces`] finds
/// them, each face's cells made once for all its pairs (a patch set against a surface):
/// `((i, j), branches)` for each pair of faces that meet.
pub fn intersect_face_sets(
    a: &[&dyn ParametricSurface],
    b: &[&dyn ParametricSurface],
    options: &IntersectOptions,
) -> Result<Vec<FacePairIntersection>, GeometryError> {
    check_options(options)?;
    let sides_a: Vec<Side<'_>> = a.iter().map(|&f| Side::of(f)).collect();
    let sides_b: Vec<Side<'_>> = b.iter().map(|&f| Side::of(f)).collect();
    let mut trees_a: Vec<Option<CellTree>> = sides_a.iter().map(CellTree::new).collect();
    let mut trees_b: Vec<Option<CellTree>> = sides_b.iter().map(CellTree::new).collect();
    let mut out = Vec::new();
    for (i, side_a) in sides_a.iter().enumerate() {
        for (j, side_b) in sides_b.iter().enumerate() {
            let (Some(ta), Some(tb)) = (trees_a[i].as_mut(), trees_b[j].as_mut()) else {
                continue;
            };
            let found = intersect_trees((side_a, ta), (side_b, tb), options);
            if !(found.curves.is_empty() && found.touching.is_empty()) {
                out.push(((i, j), found));
            }
        }
    }
    Ok(out)
}

fn check_options(options: &IntersectOptions) -> Result<(), GeometryError> {
    let positive = |x: f64| x > 0.0 && x.is_finite();
    if !(positive(options.tolerance) && positive(options.chord) && positive(options.smallest)) {
        return Err(GeometryError::Construction {
            what: "intersection",
            message: "the tolerance, chord and smallest loop must be numbers > 0".into(),
        });
    }
    Ok(())
}

/// The intersection of two surfaces given with their cell trees (see the module
/// documentation).
fn intersect_trees(
    (a, tree_a): (&Side<'_>, &mut CellTree),
    (b, tree_b): (&Side<'_>, &mut CellTree),
    options: &IntersectOptions,
) -> Intersection {
    let (a, b) = (*a, *b);
    let mut result = Intersection::default();
    let near = seed_reach(options);
    // Depth first over pairs of cells whose boxes meet, tracing a branch as soon as a pair of
    // small cells gives a seed off the branches so far; a pair of flat cells with cones apart
    // that a branch crosses already holds nothing more.
    let mut stack: Vec<(usize, usize, u32)> = vec![(0, 0, 0)];
    let mut visited = 0usize;
    while let Some((ia, ib, depth)) = stack.pop() {
        visited += 1;
        if visited > options.cell_pairs {
            result.overlapping = true;
            break;
        }
        let (ca, cb) = (tree_a.cell(ia), tree_b.cell(ib));
        if !ca.meets(&cb, options.tolerance)
            || ca.slab_separates(&cb, options.tolerance)
            || cb.slab_separates(&ca, options.tolerance)
        {
            continue;
        }
        let box_lo = ca.lo.max(cb.lo);
        let box_hi = ca.hi.min(cb.hi);
        let (lo, hi) = (box_lo - near, box_hi + near);
        let covered = result.curves.iter().any(|c| {
            c.points
                .first()
                .is_some_and(|&p| segment_meets_box(p, p, lo, hi))
                || c.points
                    .windows(2)
                    .any(|w| segment_meets_box(w[0], w[1], lo, hi))
        });
        let small = ca.size() <= options.smallest && cb.size() <= options.smallest;
        // Flat cells with cones apart hold no closed loop, but a large one may hold a second
        // arc beside the branch that crosses it (its image is not convex, or a short branch
        // cuts its corner): only cells within a few times the smallest loop are passed over.
        let settled = ca.flat()
            && cb.flat()
            && ca.transversal(&cb)
            && ca.size().max(cb.size()) <= SETTLED_CELLS * options.smallest;
        if covered && (small || settled) {
            continue;
        }
        if !small && depth < 40 {
            if ca.size() >= cb.size() {
                let children = tree_a.children(&a, ia);
                stack.extend(children.map(|q| (q, ib, depth + 1)));
            } else {
                let children = tree_b.children(&b, ib);
                stack.extend(children.map(|q| (ia, q, depth + 1)));
            }
            continue;
        }
        let (u, v) = ca.centre();
        let (s, t) = cb.centre();
        let start = [u, v, s, t];
        let Some(seed) = converge(&a, &b, start, options.tolerance)
            .or_else(|| boundary_seed((&a, &ca), (&b, &cb), start, options.tolerance))
        else {
            continue;
        };
        if stop_kind(&a, &b, &seed.x) == Some(BranchEnd::Trim) {
            continue;
        }
        if result
            .curves
            .iter()
            .any(|c| distance_to_polyline(&c.points, seed.point) <= near)
            || result
                .touching
                .iter()
                .any(|p| p.distance(seed.point) <= near)
        {
            continue;
        }
        let (Some(da), Some(db)) = (a.at(seed.x[0], seed.x[1]), b.at(seed.x[2], seed.x[3])) else {
            continue;
        };
        if tangent(&da, &db).is_none_or(|(sine, _)| sine < TANGENT_SINE) {
            result.touching.push(seed.point);
            continue;
        }
        let (forward, mut closed, end_forward) = march(&a, &b, &seed, 1.0, options);
        let mut chain: Vec<Common> = Vec::new();
        let ends = if closed {
            chain.push(seed);
            chain.extend(forward);
            [None, None]
        } else {
            let (backward, back_closed, end_backward) = march(&a, &b, &seed, -1.0, options);
            if back_closed {
                // The loop came round the other way back to the seed: the forward march
                // stopped at a seam (a closed surface's domain boundary) that the backward
                // one crossed on its closing chord. The loop is closed, and the forward piece
                // lies on it.
                closed = true;
                chain.extend(backward.into_iter().rev());
                chain.push(seed);
                [None, None]
            } else {
                chain.extend(backward.into_iter().rev());
                chain.push(seed);
                chain.extend(forward);
                [Some(end_backward), Some(end_forward)]
            }
        };
        for (end, at) in ends.iter().zip([0, chain.len().saturating_sub(1)]) {
            if *end == Some(BranchEnd::Tangent) {
                let p = chain[at].point;
                if result.touching.iter().all(|q| q.distance(p) > near) {
                    result.touching.push(p);
                }
            }
        }
        if chain.len() < 2 {
            continue;
        }
        result.curves.push(branch(&chain, closed, ends));
    }
    continue_across_seams(&a, &b, &mut result, options);
    result
}

/// A seed on a domain boundary that cell `ca` or `cb` lies on, where [`converge`] from the
/// cells' centres `start` found none: a short branch that cuts a domain's corner or edge has
/// its nearest points on the surfaces' extensions past the boundary, where the clamped
/// least-norm steps stall; the boundary isocurve meeting the other surface
/// ([`converge_holding`]) finds where the branch enters the domain.
fn boundary_seed(
    (a, ca): (&Side<'_>, &Cell),
    (b, cb): (&Side<'_>, &Cell),
    start: [f64; 4],
    tolerance: f64,
) -> Option<Common> {
    let bounds = parameter_bounds(a, b);
    let ranges = [ca.u, ca.v, cb.u, cb.v];
    (0..4)
        .flat_map(|i| [(i, bounds[i].0, ranges[i].0), (i, bounds[i].1, ranges[i].1)])
        .filter(|&(_, bound, end)| bound == end)
        .find_map(|(i, bound, _)| converge_holding(a, b, start, i, bound, tolerance))
}

/// How near a branch already traced a seed (or a seam's continuation) belongs to it.
fn seed_reach(options: &IntersectOptions) -> f64 {
    (options.chord * 4.0).max(options.tolerance * 100.0)
}

/// The branch through the marched points `chain`.
fn branch(chain: &[Common], closed: bool, ends: [Option<BranchEnd>; 2]) -> IntersectionCurve {
    IntersectionCurve {
        closed,
        points: chain.iter().map(|c| c.point).collect(),
        uv_a: chain.iter().map(|c| DVec2::new(c.x[0], c.x[1])).collect(),
        uv_b: chain.iter().map(|c| DVec2::new(c.x[2], c.x[3])).collect(),
        ends,
    }
}

/// Branches carried on across closed surfaces' seams: where a branch ends on a domain edge
/// that its surface meets again on the opposite edge (a cylinder's or a torus's seam), and
/// no branch starts or ends at the matching point there, the march goes on from it. The
/// seeds miss such a piece when it is short: its cells lie next to the branch it continues,
/// so they look traced already (a circle crossing a cylinder's seam just above its rim).
fn continue_across_seams(
    a: &Side<'_>,
    b: &Side<'_>,
    result: &mut Intersection,
    options: &IntersectOptions,
) {
    let bounds = parameter_bounds(a, b);
    let hair = |i: usize| hair(&bounds, i);
    let gap = (options.tolerance * 100.0).max(options.chord * 1e-3);
    let near = seed_reach(options);
    let at = |c: &IntersectionCurve, k: usize| Common {
        x: [c.uv_a[k].x, c.uv_a[k].y, c.uv_b[k].x, c.uv_b[k].y],
        point: c.points[k],
    };
    let same = |p: &[f64; 4], q: &[f64; 4]| (0..4).all(|i| (p[i] - q[i]).abs() <= hair(i) * 10.0);
    let mut queue: Vec<(usize, usize)> = (0..result.curves.len())
        .flat_map(|c| [(c, 0), (c, usize::MAX)])
        .collect();
    let mut added = 0;
    while let Some((c, end)) = queue.pop() {
        let curve = &result.curves[c];
        let (k, kind) = match end {
            0 => (0, curve.ends[0]),
            _ => (curve.points.len() - 1, curve.ends[1]),
        };
        if curve.closed || kind != Some(BranchEnd::Boundary) || added >= 64 {
            continue;
        }
        let from = at(curve, k);
        for i in 0..4 {
            let (lo, hi) = bounds[i];
            let mut x = from.x;
            x[i] = if (x[i] - lo).abs() <= hair(i) {
                hi
            } else if (x[i] - hi).abs() <= hair(i) {
                lo
            } else {
                continue;
            };
            let (side, j) = if i < 2 { (a, 0) } else { (b, 2) };
            if !side
                .surface
                .point(x[j], x[j + 1])
                .is_some_and(|p| p.distance(from.point) <= gap)
            {
                continue;
            }
            let taken = result.curves.iter().any(|other| {
                !other.points.is_empty()
                    && [0, other.points.len() - 1]
                        .into_iter()
                        .any(|m| same(&at(other, m).x, &x))
            });
            if taken {
                continue;
            }
            let seed = Common {
                x,
                point: from.point,
            };
            // Of the two ways from the seam, the one into the domain.
            let Some((points, _, stop)) = [1.0, -1.0]
                .into_iter()
                .map(|sign| march(a, b, &seed, sign, options))
                .max_by_key(|(points, _, _)| points.len())
                .filter(|(points, _, _)| !points.is_empty())
            else {
                continue;
            };
            let middle = points[points.len() / 2].point;
            if result
                .curves
                .iter()
                .any(|other| distance_to_polyline(&other.points, middle) <= near)
            {
                continue;
            }
            let chain: Vec<Common> = std::iter::once(seed).chain(points).collect();
            result.curves.push(branch(
                &chain,
                false,
                [Some(BranchEnd::Boundary), Some(stop)],
            ));
            added += 1;
            queue.push((result.curves.len() - 1, usize::MAX));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::construct;

    /// The square plane z = `z` of half-width `half` about the z axis.
    fn level_plane(z: f64, half: f64) -> crate::NurbsSurface {
        construct::plane(
            DVec3::new(-half, -half, z),
            DVec3::new(2.0 * half, 0.0, 0.0),
            DVec3::new(0.0, 2.0 * half, 0.0),
        )
        .unwrap()
    }

    /// The length of every branch's polyline together.
    fn total_length(found: &Intersection) -> f64 {
        found
            .curves
            .iter()
            .map(|c| {
                c.points
                    .windows(2)
                    .map(|w| w[0].distance(w[1]))
                    .sum::<f64>()
            })
            .sum()
    }

    fn options() -> IntersectOptions {
        IntersectOptions {
            tolerance: 1e-9,
            chord: 1e-3,
            smallest: 0.05,
            cell_pairs: MAX_CELL_PAIRS,
        }
    }

    /// Every point lies on both surfaces at its own parameters, and every chord's middle lies
    /// within the chord tolerance of the curve `on_curve` measures.
    fn check(
        a: &dyn ParametricSurface,
        b: &dyn ParametricSurface,
        curve: &IntersectionCurve,
        on_curve: impl Fn(DVec3) -> f64,
    ) {
        for ((p, uv), st) in curve.points.iter().zip(&curve.uv_a).zip(&curve.uv_b) {
            assert!(a.point(uv.x, uv.y).unwrap().distance(*p) < 1e-8, "{p}");
            assert!(b.point(st.x, st.y).unwrap().distance(*p) < 1e-8, "{p}");
            assert!(on_curve(*p) < 1e-8, "{p}: {:e}", on_curve(*p));
        }
        for w in curve.points.windows(2) {
            let middle = 0.5 * (w[0] + w[1]);
            assert!(on_curve(middle) <= 1.2e-3, "chord {:e}", on_curve(middle));
        }
    }

    #[test]
    fn a_plane_cuts_a_sphere_in_a_circle() {
        let sphere = construct::sphere(DVec3::ZERO, 1.0).unwrap();
        let plane = level_plane(0.3, 2.0);
        let found = intersect_surfaces(&sphere, &plane, &options()).unwrap();
        let r = (1.0f64 - 0.09).sqrt();
        // The sphere's seam (u = 0 and u = 1 meet) may cut the circle into one branch that
        // ends on the boundary twice; either way the circle is covered once.
        let length = total_length(&found);
        // An inscribed polyline with chords within e of a circle of radius r falls short by
        // about e/(3r) of its length.
        assert!(
            (length - std::f64::consts::TAU * r).abs() < 1e-3 * std::f64::consts::TAU * r,
            "{length}"
        );
        for c in &found.curves {
            check(&sphere, &plane, c, |p| {
                ((p.x * p.x + p.y * p.y).sqrt() - r).abs() + (p.z - 0.3).abs()
            });
        }
        assert!(found.touching.is_empty());
    }

    #[test]
    fn a_plane_through_a_torus_gives_two_circles() {
        let torus = construct::torus(DVec3::ZERO, DVec3::Z, 2.0, 0.5).unwrap();
        let plane = level_plane(0.2, 3.0);
        let found = intersect_surfaces(&torus, &plane, &options()).unwrap();
        // z = 0.2 cuts the tube (radius 0.5 about the circle of radius 2) at 2 ± √(0.25 − 0.04).
        let offset = (0.25f64 - 0.04).sqrt();
        let (outer, inner) = (2.0 + offset, 2.0 - offset);
        let mut length = 0.0;
        for c in &found.curves {
            check(&torus, &plane, c, |p| {
                let rho = (p.x * p.x + p.y * p.y).sqrt();
                (rho - outer).abs().min((rho - inner).abs()) + (p.z - 0.2).abs()
            });
            length += c
                .points
                .windows(2)
                .map(|w| w[0].distance(w[1]))
                .sum::<f64>();
        }
        let expected = std::f64::consts::TAU * (outer + inner);
        assert!(
            (length - expected).abs() < 1e-3 * expected,
            "{length} vs {expected}"
        );
    }

    #[test]
    fn surfaces_apart_do_not_meet() {
        let sphere = construct::sphere(DVec3::ZERO, 1.0).unwrap();
        let plane = level_plane(1.5, 2.0);
        let found = intersect_surfaces(&sphere, &plane, &options()).unwrap();
        assert!(found.curves.is_empty() && found.touching.is_empty());
        let bad = IntersectOptions {
            tolerance: 0.0,
            ..options()
        };
        assert!(intersect_surfaces(&sphere, &plane, &bad).is_err());
    }

    #[test]
    fn two_crossing_cylinders_meet_in_the_steinmetz_curves_and_touch_at_the_top() {
        // Radius 1 about the x axis and about the y axis: the intersection is two ellipses in
        // the planes x = ±y, which cross where the surfaces touch, at (0, 0, ±1).
        let along_x =
            construct::cylinder(DVec3::new(-2.0, 0.0, 0.0), DVec3::new(4.0, 0.0, 0.0), 1.0)
                .unwrap();
        let along_y =
            construct::cylinder(DVec3::new(0.0, -2.0, 0.0), DVec3::new(0.0, 4.0, 0.0), 1.0)
                .unwrap();
        let found = intersect_surfaces(&along_x, &along_y, &options()).unwrap();
        assert!(!found.curves.is_empty());
        for c in &found.curves {
            // The distance to the farther cylinder (no more than the distance to the curve).
            check(&along_x, &along_y, c, |p| {
                let to_x = ((p.y * p.y + p.z * p.z).sqrt() - 1.0).abs();
                let to_y = ((p.x * p.x + p.z * p.z).sqrt() - 1.0).abs();
                to_x.max(to_y)
            });
            for p in &c.points {
                assert!((p.x.abs() - p.y.abs()).abs() < 1e-7, "{p}");
            }
        }
        // The touching points are reported.
        for top in [DVec3::Z, DVec3::NEG_Z] {
            assert!(
                found.touching.iter().any(|p| p.distance(top) < 1e-2)
                    || found
                        .curves
                        .iter()
                        .any(|c| c.points.iter().any(|p| p.distance(top) < 1e-2)),
                "{top}: {:?}",
                found.touching
            );
        }
        // Two ellipses of semi-axes √2 and 1: each about 7.64 long, 15.28 in all.
        let length = total_length(&found);
        assert!((length - 15.28).abs() < 0.05, "{length}");
    }

    #[test]
    fn every_component_and_a_small_loop_are_found() {
        // The plane x = 0 through a torus's axis cuts its tube in two circles of radius 0.5
        // about (0, ±2, 0); a sphere of radius 0.04 (a loop 0.08 across, above the smallest
        // 0.05) sits on the same plane far from them.
        let torus = construct::torus(DVec3::ZERO, DVec3::Z, 2.0, 0.5).unwrap();
        let plane = construct::plane(
            DVec3::new(0.0, -3.0, -1.0),
            DVec3::new(0.0, 6.0, 0.0),
            DVec3::new(0.0, 0.0, 2.0),
        )
        .unwrap();
        let found = intersect_surfaces(&torus, &plane, &options()).unwrap();
        let mut length = [0.0f64; 2];
        for c in &found.curves {
            let side = usize::from(c.points[0].y > 0.0);
            check(&torus, &plane, c, |p| {
                let centre = DVec3::new(0.0, if side == 1 { 2.0 } else { -2.0 }, 0.0);
                (p.distance(centre) - 0.5).abs() + p.x.abs()
            });
            length[side] += c
                .points
                .windows(2)
                .map(|w| w[0].distance(w[1]))
                .sum::<f64>();
        }
        for l in length {
            assert!((l - std::f64::consts::PI).abs() < 3e-3, "{length:?}");
        }
        let bead = construct::sphere(DVec3::new(0.0, 0.0, 0.6), 0.04).unwrap();
        let found = intersect_surfaces(&bead, &plane, &options()).unwrap();
        let length = total_length(&found);
        let expected = std::f64::consts::TAU * 0.04;
        assert!(
            (length - expected).abs() < 1e-2 * expected,
            "{length} vs {expected}"
        );
    }
}
