//! Where a flat face meets a ruled face, without marching: a ruled surface, straight along
//! one parameter t (degree 1 and one span that way, its weights equal across it; a cylinder,
//! a cone, an extrusion, a two-curve loft), is S(s, t) = (1 − τ)·C₀(s) + τ·C₁(s) between its
//! two rim curves (τ the fraction of t across the kept rectangle). With gₖ(s) = n·Cₖ(s) − h
//! the rims' signed distances from the plane n·x = h, the plane meets the ruling at s where
//! g₀ and g₁ differ in sign, at τ(s) = g₀ / (g₀ − g₁) (Hoschek and Lasser, *Fundamentals of
//! CAGD*, §13.2: a plane section of a ruled surface is a rational curve of the same degree).
//! The intervals of s are bounded by the rims' roots, isolated on the Bézier coefficients
//! of the rims' distance numerators (Descartes' rule of signs for the Bernstein basis, Lane
//! and Riesenfeld, 1981) and found by bisection; each interval is sampled to the chord
//! tolerance and cut where either face's trim leaves it. Every point lies on the ruled face
//! exactly (its parameters are the point's) and on the plane to rounding; the march's
//! chord checks and four-unknown Newton steps fall away.
//!
//! Where the construction degenerates (a rim lying in the plane, a ruling in the plane, a
//! rim touching it without crossing, a flat face that is not an affine map of its domain),
//! `None` hands the pair back to marching.

use glam::{DVec2, DVec3};

use super::affine;
use crate::NurbsSurface;
use crate::SpaceCurve;
use crate::intersect::{BranchEnd, IntersectOptions, IntersectionCurve};
use crate::surface::Direction;
use crate::trim::piece::split_bezier;
use crate::trim::{TrimmedSurface, domain_rect, domain_size};
use crate::vector::distance_to_segment;

/// The deepest Bézier subdivision while isolating a rim's roots (2⁻⁴⁰ of a span): roots
/// still not apart there are a double root, where the plane touches a rim.
const ISOLATION_DEPTH: usize = 40;

/// The deepest halving of a step while sampling a branch to the chord tolerance.
const SAMPLING_DEPTH: usize = 40;

/// The least number of chords on a branch (as the planes' lines have).
const LEAST_CHORDS: usize = 8;

/// The greatest turn of the curve over one chord: its cosine (about 30°, as marching).
const TURN_COSINE: f64 = 0.866;

/// An affine surface's parameters of a point in its plane: S(u, v) = o + (u − u₀)·U +
/// (v − v₀)·V solved by the normal equations of the 2 × 2 Gram matrix.
struct AffineFrame {
    origin: DVec3,
    su: DVec3,
    sv: DVec3,
    start: DVec2,
    /// The Gram matrix's entries and determinant.
    gram: (f64, f64, f64, f64),
}

impl AffineFrame {
    fn of(surface: &NurbsSurface) -> Option<Self> {
        if !affine(surface) {
            return None;
        }
        let [(u0, u1), (v0, v1)] = surface.domain();
        let p = |i, j| surface.control_point(i, j);
        let (su, sv) = (
            (p(1, 0) - p(0, 0)) / (u1 - u0),
            (p(0, 1) - p(0, 0)) / (v1 - v0),
        );
        let (e, f, g) = (su.dot(su), su.dot(sv), sv.dot(sv));
        let det = e * g - f * f;
        (det.is_finite() && det > 0.0).then_some(Self {
            origin: p(0, 0),
            su,
            sv,
            start: DVec2::new(u0, v0),
            gram: (e, f, g, det),
        })
    }

    fn uv(&self, point: DVec3) -> DVec2 {
        let r = point - self.origin;
        let (e, f, g, det) = self.gram;
        let (x, y) = (self.su.dot(r), self.sv.dot(r));
        self.start + DVec2::new((g * x - f * y) / det, (e * y - f * x) / det)
    }
}

/// A face straight along one parameter, over the rectangle of its domain it is asked on.
struct Ruled {
    /// The straight parameter's index (0: u, 1: v); s is the other.
    straight: usize,
    s_range: (f64, f64),
    t_range: (f64, f64),
    /// The iso-curves t = t₀ and t = t₁, along s.
    rims: [SpaceCurve; 2],
    /// Whether it closes on itself across s = s₀, s₁ (a seam).
    closed: bool,
}

impl Ruled {
    /// The face's ruled surface over the rectangle it keeps; `None` for another surface or
    /// a face that keeps no rectangle.
    fn of(face: &TrimmedSurface) -> Option<Self> {
        let surface = face.surface();
        let [n, m] = surface.count();
        let straight = [1, 0].into_iter().find(|&d| {
            surface.degree()[d] == 1
                && surface.count()[d] == 2
                && if d == 1 {
                    (0..n).all(|i| surface.weight(i, 0) == surface.weight(i, 1))
                } else {
                    (0..m).all(|j| surface.weight(0, j) == surface.weight(1, j))
                }
        })?;
        let domain = domain_rect(surface);
        let rect = face.kept_rectangle()?;
        let ranges = [(rect[0], rect[1]), (rect[2], rect[3])];
        let (s_range, t_range) = (ranges[1 - straight], ranges[straight]);
        let direction = if straight == 0 {
            Direction::U
        } else {
            Direction::V
        };
        let rims = [
            surface.isocurve(direction, t_range.0, 0).ok()?,
            surface.isocurve(direction, t_range.1, 0).ok()?,
        ];
        let s_domain = [(domain[0], domain[1]), (domain[2], domain[3])][1 - straight];
        // Closed across s: the rectangle spans the domain that way and both rims close.
        let gap = 1e-9 * surface.size();
        let closed = s_range == s_domain
            && rims
                .iter()
                .all(|rim| matches!(rim.ends(), Ok((first, last)) if first.distance(last) <= gap));
        Some(Self {
            straight,
            s_range,
            t_range,
            rims,
            closed,
        })
    }

    /// The face's (u, v) at (s, t).
    fn uv(&self, s: f64, t: f64) -> DVec2 {
        if self.straight == 1 {
            DVec2::new(s, t)
        } else {
            DVec2::new(t, s)
        }
    }
}

/// The largest share of the rulings' length one chord of a section may cross
/// ([`Section::refine`]).
const MAX_TAU_STEP: f64 = 0.125;

/// One point of a branch: its s, the point, and its (u, v) on the flat and the ruled face.
#[derive(Clone, Copy)]
struct Sample {
    s: f64,
    /// Where the point lies along its ruling (0 on the first rim, 1 on the second).
    tau: f64,
    point: DVec3,
    uv_flat: DVec2,
    uv_ruled: DVec2,
}

/// Where the flat face (with its plane: a point and the unit normal) and the ruled face
/// cross, as branches with (u, v) on the flat face first: see the module documentation.
/// `None` where either face is not of its kind or the construction degenerates.
pub(super) fn plane_ruled_branches(
    flat: &TrimmedSurface,
    (point, normal): (DVec3, DVec3),
    ruled: &TrimmedSurface,
    options: &IntersectOptions,
    tolerance: f64,
) -> Option<Vec<IntersectionCurve>> {
    let frame = AffineFrame::of(flat.surface())?;
    let ruled = Ruled::of(ruled)?;
    let rect = flat.kept_rectangle()?;
    let h = normal.dot(point);
    let section = Section {
        ruled: &ruled,
        frame: &frame,
        normal,
        h,
        rect,
        end: if rect == domain_rect(flat.surface()) {
            BranchEnd::Boundary
        } else {
            BranchEnd::Trim
        },
        tolerance,
    };
    // Each rim's roots; a rim lying in the plane is left to marching.
    let (s0, s1) = ruled.s_range;
    let mut breaks = vec![s0, s1];
    let mut roots: [Vec<f64>; 2] = [Vec::new(), Vec::new()];
    for (k, rim) in ruled.rims.iter().enumerate() {
        let far = (0..rim.count())
            .map(|i| (normal.dot(rim.control_point(i)) - h).abs())
            .fold(0.0, f64::max);
        if far <= tolerance {
            return None;
        }
        roots[k] = rim_roots(rim, (normal, h), ruled.s_range, tolerance)?;
        breaks.extend(roots[k].iter().copied());
    }
    // A root of one rim where the other is on the plane too: a ruling in the plane.
    for (k, list) in roots.iter().enumerate() {
        for &s in list {
            let other = section.distance(1 - k, s)?;
            if other.abs() <= tolerance {
                return None;
            }
        }
    }
    breaks.sort_by(f64::total_cmp);
    breaks.dedup();
    // The intervals where the rims lie on either side of the plane, joined where they meet.
    let mut intervals: Vec<(f64, f64)> = Vec::new();
    for w in breaks.windows(2) {
        let (a, b) = (w[0], w[1]);
        if b <= a {
            continue;
        }
        let middle = 0.5 * (a + b);
        if section.distance(0, middle)? * section.distance(1, middle)? >= 0.0 {
            continue;
        }
        match intervals.last_mut() {
            Some(last) if last.1 == a => last.1 = b,
            _ => intervals.push((a, b)),
        }
    }
    // Across a seam, the last interval runs on into the first.
    let whole = ruled.closed && intervals.len() == 1 && intervals[0] == (s0, s1);
    let mut branches: Vec<(Vec<Sample>, bool)> = Vec::new();
    if whole {
        let mut samples = section.sampled(s0, s1, options.chord)?;
        samples.pop();
        branches.push((samples, true));
    } else {
        let wraps = ruled.closed && intervals.len() >= 2 && intervals[0].0 == s0 && {
            intervals.last().is_some_and(|last| last.1 == s1)
        };
        let first = if wraps {
            Some(intervals.remove(0))
        } else {
            None
        };
        for (k, &(a, b)) in intervals.iter().enumerate() {
            let mut samples = section.sampled(a, b, options.chord)?;
            if let (Some((fa, fb)), true) = (first, k + 1 == intervals.len()) {
                let period = s1 - s0;
                let on = section.sampled(fa + period, fb + period, options.chord)?;
                samples.extend(on.into_iter().skip(1));
            }
            branches.push((samples, false));
        }
    }
    let mut curves = Vec::new();
    for (samples, closed) in branches {
        let samples = section.near_edges(samples)?;
        section.kept_runs(samples, closed, options, &mut curves)?;
    }
    Some(curves)
}

/// The plane's section of a ruled face, with the flat face's frame and the rectangle of
/// its domain it keeps.
struct Section<'a> {
    ruled: &'a Ruled,
    frame: &'a AffineFrame,
    normal: DVec3,
    h: f64,
    rect: [f64; 4],
    /// How a branch ends on the rectangle's sides: the domain's boundary, or a trim.
    end: BranchEnd,
    /// The boolean's tolerance.
    tolerance: f64,
}

impl Section<'_> {
    /// Rim `k`'s signed distance from the plane at s.
    fn distance(&self, k: usize, s: f64) -> Option<f64> {
        let p = self.ruled.rims[k].point_at(s).ok()?;
        Some(self.normal.dot(p) - self.h)
    }

    /// The branch's point at s (between two roots, where the rims lie on either side); on
    /// a closed face, s past s₁ goes on round it (a walk across the seam keeps s rising).
    fn sample(&self, s: f64) -> Option<Sample> {
        let (s0, s1) = self.ruled.s_range;
        let at = if self.ruled.closed && s > s1 {
            s - (s1 - s0)
        } else {
            s
        };
        let c0 = self.ruled.rims[0].point_at(at).ok()?;
        let c1 = self.ruled.rims[1].point_at(at).ok()?;
        let (g0, g1) = (self.normal.dot(c0) - self.h, self.normal.dot(c1) - self.h);
        let tau = if g0 == g1 {
            0.5
        } else {
            (g0 / (g0 - g1)).clamp(0.0, 1.0)
        };
        let point = c0 + (c1 - c0) * tau;
        let (t0, t1) = self.ruled.t_range;
        let t = if tau == 1.0 { t1 } else { t0 + (t1 - t0) * tau };
        point.is_finite().then(|| Sample {
            s,
            tau,
            point,
            uv_flat: self.frame.uv(point),
            uv_ruled: self.ruled.uv(at, t),
        })
    }

    /// The branch over [a, b] sampled so that each chord strays from the curve by at most
    /// half of `chord` at its middle and the curve turns less than 30° over it: at least
    /// [`LEAST_CHORDS`] chords, every rim span halved, each chord halved until it holds.
    fn sampled(&self, a: f64, b: f64, chord: f64) -> Option<Vec<Sample>> {
        let mut cuts: Vec<f64> = vec![a];
        for rim in &self.ruled.rims {
            cuts.extend(rim.span_breaks().into_iter().filter(|&s| s > a && s < b));
        }
        cuts.push(b);
        cuts.sort_by(f64::total_cmp);
        cuts.dedup();
        let pieces = LEAST_CHORDS.div_ceil(cuts.len() - 1).max(2);
        let mut starts = Vec::new();
        for w in cuts.windows(2) {
            for k in 0..pieces {
                starts.push(w[0] + (w[1] - w[0]) * k as f64 / pieces as f64);
            }
        }
        starts.push(b);
        let mut out = vec![self.sample(a)?];
        for w in starts.windows(2) {
            let end = self.sample(w[1])?;
            self.refine(*out.last()?, end, chord, 0, &mut out)?;
        }
        Some(out)
    }

    /// The chord `from`–`to` halved until it holds ([`Self::sampled`]); pushes its points
    /// after `from`.
    fn refine(
        &self,
        from: Sample,
        to: Sample,
        chord: f64,
        depth: usize,
        out: &mut Vec<Sample>,
    ) -> Option<()> {
        let middle = self.sample(0.5 * (from.s + to.s))?;
        let (d0, d1) = (middle.point - from.point, to.point - middle.point);
        let line = to.point - from.point;
        let off = if line.length_squared() > 0.0 {
            d0.cross(line).length() / line.length()
        } else {
            d0.length()
        };
        let straight = d0.length_squared() == 0.0
            || d1.length_squared() == 0.0
            || d0.normalize().dot(d1.normalize()) >= TURN_COSINE;
        // Where the section runs almost along the rulings, τ races through most of its
        // range over a short stretch of s: samples even in s would leave long gaps, which
        // curves through the (u, v) points cannot follow (a little off in s is far off in
        // space round the rim). A chord crosses at most a share of the rulings' length.
        let short = (to.tau - from.tau).abs() <= MAX_TAU_STEP;
        if off <= 0.5 * chord && straight && short {
            out.push(to);
            return Some(());
        }
        if depth >= SAMPLING_DEPTH {
            return None;
        }
        self.refine(from, middle, chord, depth + 1, out)?;
        self.refine(middle, to, chord, depth + 1, out)
    }

    /// The rectangle's corners.
    fn corners(&self) -> (DVec2, DVec2) {
        let [u0, u1, v0, v1] = self.rect;
        (DVec2::new(u0, v0), DVec2::new(u1, v1))
    }

    /// Whether the flat face keeps the sample (within its rectangle); else how it leaves.
    fn leaves(&self, sample: &Sample) -> Option<BranchEnd> {
        let (lo, hi) = self.corners();
        let uv = sample.uv_flat;
        (!(uv.cmpge(lo).all() && uv.cmple(hi).all())).then_some(self.end)
    }

    /// `samples` with more between each two where the curve may cross the rectangle's
    /// sides unseen (a corner clipped between two samples outside, or an excursion between
    /// two inside): where the chord, widened by twice its middle's distance from the curve
    /// (in (u, v)), reaches a side, the step is halved, down to ten times the tolerance in
    /// space.
    fn near_edges(&self, samples: Vec<Sample>) -> Option<Vec<Sample>> {
        let mut out = Vec::with_capacity(samples.len());
        let Some(&first) = samples.first() else {
            return Some(out);
        };
        out.push(first);
        for w in samples.windows(2) {
            self.split_near_edges(w[0], w[1], 0, &mut out)?;
        }
        Some(out)
    }

    /// One step of [`Self::near_edges`]; pushes its points after `from`.
    fn split_near_edges(
        &self,
        from: Sample,
        to: Sample,
        depth: usize,
        out: &mut Vec<Sample>,
    ) -> Option<()> {
        let (a, b) = (from.uv_flat, to.uv_flat);
        let (lo, hi) = self.corners();
        // Cheap first: a chord whose box, widened by its length, misses every side.
        let reach = a.distance(b);
        let (bl, bh) = (a.min(b) - reach, a.max(b) + reach);
        let away =
            bh.cmplt(lo).any() || bl.cmpgt(hi).any() || (bl.cmpgt(lo).all() && bh.cmplt(hi).all());
        let changes = self.leaves(&from).is_some() != self.leaves(&to).is_some();
        if away
            || changes
            || depth >= SAMPLING_DEPTH
            || from.point.distance(to.point) <= 10.0 * self.tolerance
        {
            out.push(to);
            return Some(());
        }
        let middle = self.sample(0.5 * (from.s + to.s))?;
        let bulge = distance_to_segment(middle.uv_flat, a, b);
        if distance_to_sides(a, b, lo, hi) > 2.0 * bulge {
            out.push(to);
            return Some(());
        }
        self.split_near_edges(from, middle, depth + 1, out)?;
        self.split_near_edges(middle, to, depth + 1, out)
    }

    /// Where the branch leaves between the kept sample `inside` and `outside`, by bisection
    /// on s to a thousandth of the marching tolerance in space; on the flat face's domain
    /// boundary, its (u, v) put onto it.
    fn crossing(&self, mut inside: Sample, mut outside: Sample, tolerance: f64) -> Option<Sample> {
        for _ in 0..200 {
            let s = 0.5 * (inside.s + outside.s);
            if inside.point.distance(outside.point) <= 1e-3 * tolerance
                || s == inside.s
                || s == outside.s
            {
                break;
            }
            let middle = self.sample(s)?;
            if self.leaves(&middle).is_none() {
                inside = middle;
            } else {
                outside = middle;
            }
        }
        // Onto the side crossed: the coordinate the outer point has past it.
        let (lo, hi) = self.corners();
        let past = outside.uv_flat.clamp(lo, hi);
        for axis in 0..2 {
            if past[axis] != outside.uv_flat[axis] {
                inside.uv_flat[axis] = past[axis];
            }
        }
        Some(inside)
    }

    /// The runs of `samples` both faces keep, each ended where it leaves, as branches pushed
    /// to `out` (a closed branch kept whole stays closed: its first point repeated last).
    fn kept_runs(
        &self,
        mut samples: Vec<Sample>,
        closed: bool,
        options: &IntersectOptions,
        out: &mut Vec<IntersectionCurve>,
    ) -> Option<()> {
        let mut ends: Vec<Option<BranchEnd>> = samples.iter().map(|p| self.leaves(p)).collect();
        self.keep_grazing(&mut samples, &mut ends);
        if closed {
            match ends.iter().position(Option::is_some) {
                None => {
                    let first = *samples.first()?;
                    samples.push(first);
                    out.push(curve(&samples, true, [None, None]));
                    return Some(());
                }
                // Walked from a sample it leaves at, round to it again (past the seam, s
                // goes on rising).
                Some(k) => {
                    let (s0, s1) = self.ruled.s_range;
                    let mut walk = samples.split_off(k);
                    let back = walk[0];
                    walk.extend(samples.into_iter().chain([back]).map(|mut p| {
                        p.s += s1 - s0;
                        p
                    }));
                    ends.rotate_left(k);
                    ends.push(ends[0]);
                    return self.runs(&walk, &ends, options, out);
                }
            }
        }
        self.runs(&samples, &ends, options, out)
    }

    /// Runs of samples that leave the flat face's rectangle by no more than a rounding (1e-9 of
    /// its size; a branch grazing its edge) kept, put onto the edge: a loop touching an edge
    /// is not cut there. A lone sample on the edge between two well inside it is replaced by
    /// two a quarter step either side of it, off the edge: the face's part beyond the loop
    /// could not be trimmed pinched to a point there.
    fn keep_grazing(&self, samples: &mut Vec<Sample>, ends: &mut Vec<Option<BranchEnd>>) {
        let [u0, u1, v0, v1] = self.rect;
        let slack = 1e-9 * domain_size(self.rect);
        let (lo, hi) = self.corners();
        let grazing = |p: &Sample| p.uv_flat.distance(p.uv_flat.clamp(lo, hi)) <= slack;
        let on_edge = |p: &Sample| {
            let uv = p.uv_flat;
            (uv.x - u0)
                .abs()
                .min((uv.x - u1).abs())
                .min((uv.y - v0).abs())
                .min((uv.y - v1).abs())
                <= slack
        };
        for range in runs_of(ends, true) {
            if samples[range.clone()].iter().all(grazing) {
                for m in range {
                    ends[m] = None;
                    samples[m].uv_flat = samples[m].uv_flat.clamp(lo, hi);
                }
            }
        }
        let mut k = 1;
        while k + 1 < samples.len() {
            let lone = on_edge(&samples[k])
                && [k - 1, k + 1]
                    .iter()
                    .all(|&m| ends[m].is_none() && !on_edge(&samples[m]));
            if lone {
                let (before, s, after) = (samples[k - 1].s, samples[k].s, samples[k + 1].s);
                let off = [s - 0.25 * (s - before), s + 0.25 * (after - s)];
                let pair: Option<Vec<Sample>> = off.iter().map(|&t| self.sample(t)).collect();
                if let Some(pair) = pair
                    && pair.iter().all(|p| self.leaves(p).is_none() && !on_edge(p))
                {
                    samples.splice(k..=k, pair);
                    ends.splice(k..=k, [None, None]);
                    k += 1;
                }
            }
            k += 1;
        }
    }

    /// [`Self::kept_runs`] on an open walk.
    fn runs(
        &self,
        samples: &[Sample],
        ends: &[Option<BranchEnd>],
        options: &IntersectOptions,
        out: &mut Vec<IntersectionCurve>,
    ) -> Option<()> {
        let n = samples.len();
        for std::ops::Range { start, end } in runs_of(ends, false) {
            let mut run: Vec<Sample> = samples[start..end].to_vec();
            let mut kinds = [Some(BranchEnd::Boundary); 2];
            if start > 0 {
                let cut = self.crossing(samples[start], samples[start - 1], options.tolerance)?;
                if cut.point.distance(run[0].point) > options.tolerance {
                    run.insert(0, cut);
                } else {
                    run[0] = cut;
                }
                kinds[0] = ends[start - 1];
            }
            if end < n {
                let cut = self.crossing(samples[end - 1], samples[end], options.tolerance)?;
                let last = run.len() - 1;
                if cut.point.distance(run[last].point) > options.tolerance {
                    run.push(cut);
                } else {
                    run[last] = cut;
                }
                kinds[1] = ends[end];
            }
            // No point within a few tolerances of an end, where splitting would snap it on.
            let (first, last) = (run[0], run[run.len() - 1]);
            let near = 4.0 * self.tolerance;
            let clear = |p: &Sample| {
                p.point.distance(first.point) > near && p.point.distance(last.point) > near
            };
            if run.len() > 2 {
                run = std::iter::once(first)
                    .chain(run[1..run.len() - 1].iter().copied().filter(clear))
                    .chain(std::iter::once(last))
                    .collect();
            }
            // A short run (a corner clipped) gets points enough for a cubic through them
            // to follow it: at least LEAST_CHORDS chords between its ends.
            if run.len() >= 2 && run.len() <= LEAST_CHORDS {
                let (first, last) = (run[0], run[run.len() - 1]);
                let inner = self.sampled(first.s, last.s, options.chord)?;
                run = std::iter::once(first)
                    .chain(inner[1..inner.len() - 1].iter().copied())
                    .chain(std::iter::once(last))
                    .collect();
            }
            if run.len() >= 2 {
                out.push(curve(&run, false, kinds));
            }
        }
        Some(())
    }
}

/// The index ranges of the longest runs of samples that leave (`leaving`) or are kept.
fn runs_of(ends: &[Option<BranchEnd>], leaving: bool) -> Vec<std::ops::Range<usize>> {
    let mut out = Vec::new();
    let mut k = 0;
    while k < ends.len() {
        let start = k;
        while k < ends.len() && ends[k].is_some() == ends[start].is_some() {
            k += 1;
        }
        if ends[start].is_some() == leaving {
            out.push(start..k);
        }
    }
    out
}

/// The distance from the segment `a`–`b` to the sides of the rectangle `lo`–`hi` (zero
/// where it crosses one).
fn distance_to_sides(a: DVec2, b: DVec2, lo: DVec2, hi: DVec2) -> f64 {
    let corners = [lo, DVec2::new(hi.x, lo.y), hi, DVec2::new(lo.x, hi.y)];
    let mut nearest = f64::INFINITY;
    for k in 0..4 {
        let (c, d) = (corners[k], corners[(k + 1) % 4]);
        // Crossing a side: each segment's ends on either side of the other's line.
        let side = |p: DVec2, q: DVec2, r: DVec2| (q - p).perp_dot(r - p);
        if side(a, b, c) * side(a, b, d) <= 0.0 && side(c, d, a) * side(c, d, b) <= 0.0 {
            return 0.0;
        }
        nearest = nearest
            .min(distance_to_segment(c, a, b))
            .min(distance_to_segment(a, c, d))
            .min(distance_to_segment(b, c, d));
    }
    nearest
}

/// The branch through `samples`.
fn curve(samples: &[Sample], closed: bool, ends: [Option<BranchEnd>; 2]) -> IntersectionCurve {
    IntersectionCurve {
        closed,
        points: samples.iter().map(|p| p.point).collect(),
        uv_a: samples.iter().map(|p| p.uv_flat).collect(),
        uv_b: samples.iter().map(|p| p.uv_ruled).collect(),
        ends,
    }
}

/// The s in (s₀, s₁) where `rim` crosses the plane n·x = h: on each Bézier segment the
/// numerator of its distance, N(s) = Σ Bᵢ(s)·wᵢ(n·Pᵢ − h), has Bernstein coefficients that
/// change sign at least as often as it has roots (Descartes' rule): one change, one root,
/// found by bisection; none, no root, once every coefficient is also beyond ±`tolerance`·wᵢ
/// (then |N / W| > `tolerance`: the rim stays clear of the plane); otherwise halved (de
/// Casteljau) and looked at again. `None` where that does not settle within
/// [`ISOLATION_DEPTH`] halvings: the rim touches the plane, or comes within the tolerance.
fn rim_roots(
    rim: &SpaceCurve,
    (normal, h): (DVec3, f64),
    (s0, s1): (f64, f64),
    tolerance: f64,
) -> Option<Vec<f64>> {
    let mut roots = Vec::new();
    for segment in rim.bezier_segments() {
        let (a, b) = segment.domain();
        if b <= s0 || a >= s1 {
            continue;
        }
        let (numerator, weights): (Vec<f64>, Vec<f64>) = segment
            .homogeneous_points()
            .iter()
            .map(|q| (normal.dot(q.truncate()) - h * q.w, q.w))
            .unzip();
        Bernstein::new(&numerator, &weights, tolerance).isolate((a, b), 0, &mut roots)?;
    }
    roots.retain(|&s| s > s0 && s < s1);
    roots.sort_by(f64::total_cmp);
    roots.dedup();
    Some(roots)
}

/// How often the coefficients change sign (zeros skipped).
fn sign_changes(c: &[f64]) -> usize {
    let mut last = 0.0;
    let mut changes = 0;
    for &x in c {
        if x != 0.0 {
            if last != 0.0 && (x > 0.0) != (last > 0.0) {
                changes += 1;
            }
            last = x;
        }
    }
    changes
}

/// A rational function in one Bernstein basis, each coefficient (numerator, weight, 0) (so
/// that de Casteljau's [`split_bezier`] halves both at once), with how close to zero it may
/// come without crossing ([`rim_roots`]).
struct Bernstein {
    coefficients: Vec<DVec3>,
    tolerance: f64,
}

impl Bernstein {
    fn new(numerator: &[f64], weights: &[f64], tolerance: f64) -> Self {
        Self {
            coefficients: numerator
                .iter()
                .zip(weights)
                .map(|(&c, &w)| DVec3::new(c, w, 0.0))
                .collect(),
            tolerance,
        }
    }

    /// The numerator at x in [0, 1]: the last point of the left half at x.
    fn numerator_at(&self, x: f64) -> f64 {
        split_bezier(&self.coefficients, x)
            .0
            .last()
            .map_or(0.0, |p| p.x)
    }

    /// Whether the function stays beyond ±tolerance over the whole interval.
    fn clear(&self) -> bool {
        let all = |f: &dyn Fn(&DVec3) -> bool| self.coefficients.iter().all(f);
        all(&|p| p.x > self.tolerance * p.y) || all(&|p| p.x < -self.tolerance * p.y)
    }

    /// Its roots on the parameter interval `(a, b)`, pushed to `out` ([`rim_roots`]).
    fn isolate(&self, (a, b): (f64, f64), depth: usize, out: &mut Vec<f64>) -> Option<()> {
        let numerator: Vec<f64> = self.coefficients.iter().map(|p| p.x).collect();
        let changes = sign_changes(&numerator);
        if changes == 0 && self.clear() {
            return Some(());
        }
        if changes == 1 {
            // One root: bisection on the numerator, from the first coefficient's sign.
            let (mut lo, mut hi) = (0.0, 1.0);
            let low_sign = numerator
                .iter()
                .find(|&&x| x != 0.0)
                .is_some_and(|&x| x > 0.0);
            for _ in 0..64 {
                let mid = 0.5 * (lo + hi);
                if mid <= lo || mid >= hi {
                    break;
                }
                let value = self.numerator_at(mid);
                if value == 0.0 {
                    (lo, hi) = (mid, mid);
                    break;
                }
                if (value > 0.0) == low_sign {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            out.push(a + (b - a) * 0.5 * (lo + hi));
            return Some(());
        }
        if depth >= ISOLATION_DEPTH {
            return None;
        }
        let (left, right) = split_bezier(&self.coefficients, 0.5);
        let middle = 0.5 * (a + b);
        let half = |coefficients| Self {
            coefficients,
            tolerance: self.tolerance,
        };
        half(left).isolate((a, middle), depth + 1, out)?;
        half(right).isolate((middle, b), depth + 1, out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::intersect::intersect_surfaces;
    use crate::solids::{block, capped_cone, capped_cylinder, transformed};
    use crate::test_support::placement;
    use glam::{DAffine3, DQuat};

    /// A tilted slab's faces cut a cylinder's and a cone's side, in general position: every
    /// point lies on the plane, on the side at its own (u, v) and at the distance from the
    /// axis the closed form gives (r, or the cone's radius at that height), and on the flat
    /// face at its (u, v); the loops are closed, as many as marching finds, and every point
    /// marching finds lies within its chord tolerance of them.
    #[test]
    fn a_plane_cuts_a_cylinder_and_a_cone_as_the_closed_forms_say() {
        let radius = |height: f64, cone: bool| if cone { 0.8 - 0.2 * height } else { 0.5 };
        for seed in 1..6 {
            let (motion, scale) = placement(seed);
            for cone in [false, true] {
                let body = if cone {
                    capped_cone(
                        DVec3::new(0.0, 0.0, -1.0),
                        DVec3::new(0.0, 0.0, 2.0),
                        0.8,
                        0.4,
                    )
                } else {
                    capped_cylinder(DVec3::new(0.0, 0.0, -1.0), DVec3::new(0.0, 0.0, 2.0), 0.5)
                }
                .unwrap();
                let tilt = DAffine3::from_quat(DQuat::from_rotation_x(0.4 + 0.05 * seed as f64));
                let slab = block(DVec3::new(-2.0, -2.0, -0.3), DVec3::new(4.0, 4.0, 0.6)).unwrap();
                let slab = transformed(&slab, &(motion * tilt)).unwrap();
                let body = transformed(&body, &motion).unwrap();
                let side = &body[0];
                let (base, axis) = (
                    motion.transform_point3(DVec3::new(0.0, 0.0, -1.0)),
                    motion.transform_vector3(DVec3::Z).normalize(),
                );
                let size = 4.0 * scale;
                let options = IntersectOptions {
                    tolerance: 1e-11 * size,
                    chord: 2e-4 * size,
                    smallest: 1e-2 * size,
                    cell_pairs: crate::intersect::MAX_CELL_PAIRS,
                };
                let mut loops = 0;
                for flat in &slab {
                    let plane = super::super::plane_of(flat, 1e-9 * size).unwrap();
                    let curves =
                        plane_ruled_branches(flat, plane, side, &options, 1e-6 * size).unwrap();
                    let marched = intersect_surfaces(flat, side, &options)
                        .unwrap()
                        .joined_across_seams(1e-6 * size);
                    assert_eq!(
                        curves.len(),
                        marched.curves.len(),
                        "seed {seed} cone {cone}"
                    );
                    for c in &curves {
                        assert!(c.closed, "seed {seed} cone {cone}");
                        loops += 1;
                        for ((p, a), b) in c.points.iter().zip(&c.uv_a).zip(&c.uv_b) {
                            let (point, normal) = plane;
                            assert!((*p - point).dot(normal).abs() <= 1e-12 * size);
                            let on_side = side.surface().point_at(b.x, b.y).unwrap();
                            assert!(on_side.distance(*p) <= 1e-12 * size);
                            let on_flat = flat.surface().point_at(a.x, a.y).unwrap();
                            assert!(on_flat.distance(*p) <= 1e-12 * size);
                            let height = (*p - base).dot(axis) / scale;
                            let off = (*p - base - axis * height * scale).length() / scale;
                            assert!((off - radius(height, cone)).abs() <= 1e-12, "{off}");
                        }
                        for m in marched.curves.iter().flat_map(|m| &m.points) {
                            let n = c.points.len();
                            let near = (0..n)
                                .map(|k| {
                                    distance_to_segment(*m, c.points[k], c.points[(k + 1) % n])
                                })
                                .fold(f64::INFINITY, f64::min);
                            assert!(near <= options.chord, "{near}");
                        }
                    }
                }
                assert_eq!(loops, 2, "seed {seed} cone {cone}: the slab's two faces");
            }
        }
    }

    #[test]
    fn bernstein_roots_are_isolated_and_found() {
        // (x − 0.2)(x − 0.7)(x − 0.9) in the Bernstein basis of degree 3, from its monomial
        // coefficients (a₀ + a₁x + a₂x² + a₃x³: cᵢ = Σⱼ≤ᵢ C(i,j)/C(3,j)·aⱼ).
        let (r1, r2, r3) = (0.2, 0.7, 0.9);
        let a0 = -r1 * r2 * r3;
        let a1 = r1 * r2 + r1 * r3 + r2 * r3;
        let a2 = -(r1 + r2 + r3);
        let a3 = 1.0;
        let c = [
            a0,
            a0 + a1 / 3.0,
            a0 + 2.0 * a1 / 3.0 + a2 / 3.0,
            a0 + a1 + a2 + a3,
        ];
        let cubic = Bernstein::new(&c, &[1.0; 4], 1e-9);
        let mut roots = Vec::new();
        cubic.isolate((2.0, 4.0), 0, &mut roots).unwrap();
        roots.sort_by(f64::total_cmp);
        assert_eq!(roots.len(), 3);
        for (found, want) in roots.iter().zip([r1, r2, r3]) {
            assert!((found - (2.0 + 2.0 * want)).abs() < 1e-12, "{found}");
        }
        // A double root (at 0.3, never a halving point), where the function touches zero,
        // and a function coming within the tolerance of zero are not settled.
        for numerator in [
            vec![0.09, -0.21, 0.49],
            vec![0.09 + 1e-10, -0.21 + 1e-10, 0.49 + 1e-10],
        ] {
            let near = Bernstein::new(&numerator, &[1.0; 3], 1e-9);
            assert!(near.isolate((0.0, 1.0), 0, &mut Vec::new()).is_none());
        }
        // One kept clear of it is: no root.
        let clear = Bernstein::new(&[0.09 + 1e-3, -0.21 + 1e-3, 0.49 + 1e-3], &[1.0; 3], 1e-9);
        let mut none = Vec::new();
        clear.isolate((0.0, 1.0), 0, &mut none).unwrap();
        assert!(none.is_empty());
    }
}
