//! Trim curves cut into pieces that are monotone in both u and v, the unit every trimming
//! query works on: a monotone piece meets a line u = const or v = const at most once, and the
//! crossing is found by bisection on the piece's own parameter (Schollmeyer & Fröhlich,
//! "Direct trimming of NURBS surfaces on the GPU", SIGGRAPH 2009, §4). The CPU classifier here
//! and the fragment shader (`shaders/trim.wgsl`) run the same tests, the CPU in f64.

use glam::{DVec2, DVec3};

use crate::TrimCurve;
use crate::surface::DerivativeBounds;
use crate::vector::{Vector, binomial};

/// Sign samples per Bézier segment when looking for the extrema of u(t) and v(t).
const EXTREMUM_SAMPLES: usize = 48;
/// Turns closer than this to a Bézier segment's end (in its parameter) are not cut at.
const END_SLACK: f64 = 1e-9;
/// Bisection steps that pin a crossing or an extremum (2⁻⁶⁰ of the parameter interval).
const BISECTION_STEPS: usize = 60;

/// A rational Bézier piece of a trim curve over t ∈ [0, 1], monotone in u and in v.
#[derive(Debug, Clone, PartialEq)]
pub struct MonotonePiece {
    /// Homogeneous control points (w·u, w·v, w).
    pub points: Vec<DVec3>,
    /// The piece's box [u_min, u_max, v_min, v_max] (spanned by its end points).
    pub bounds: [f64; 4],
    /// The loop and the curve of the loop it came from.
    pub source: (usize, usize),
}

/// The point of the rational Bézier curve `points` at t (de Casteljau, The NURBS Book A1.5, on
/// homogeneous points), projected.
pub fn bezier_point(points: &[DVec3], t: f64) -> DVec2 {
    let s = 1.0 - t;
    // Degrees up to 3 (nearly every trim curve) by their Bernstein polynomials (eq. 1.8),
    // written out.
    let h = match *points {
        [a, b] => a * s + b * t,
        [a, b, c] => a * (s * s) + b * (2.0 * s * t) + c * (t * t),
        [a, b, c, d] => {
            let (s2, t2) = (s * s, t * t);
            a * (s2 * s) + b * (3.0 * s2 * t) + c * (3.0 * s * t2) + d * (t2 * t)
        }
        _ => DVec3::NAN,
    };
    if points.len() >= 2 && points.len() <= 4 {
        return h.truncate() / h.z;
    }
    with_copy(points, |work| {
        let n = work.len();
        for r in 1..n {
            for i in 0..n - r {
                work[i] = work[i] * (1.0 - t) + work[i + 1] * t;
            }
        }
        work[0].truncate() / work[0].z
    })
}

/// `f` of a scratch copy of `points` (on the stack for degrees up to 7, the usual ones).
fn with_copy<R>(points: &[DVec3], f: impl FnOnce(&mut [DVec3]) -> R) -> R {
    const SMALL: usize = 8;
    if points.len() <= SMALL {
        let mut small = [DVec3::ZERO; SMALL];
        small[..points.len()].copy_from_slice(points);
        f(&mut small[..points.len()])
    } else {
        f(&mut points.to_vec())
    }
}

/// The two halves of the Bézier curve `points` at t (de Casteljau subdivision), each over
/// [0, 1].
pub fn split_bezier(points: &[DVec3], t: f64) -> (Vec<DVec3>, Vec<DVec3>) {
    let n = points.len();
    let mut work = points.to_vec();
    let mut left = vec![work[0]];
    let mut right = vec![work[n - 1]];
    for r in 1..n {
        for i in 0..n - r {
            work[i] = work[i] * (1.0 - t) + work[i + 1] * t;
        }
        left.push(work[0]);
        right.push(work[n - r - 1]);
    }
    right.reverse();
    (left, right)
}

/// d/dt of coordinate `axis` (0: u, 1: v) of the rational curve, up to the positive factor
/// 1/w²: x'w − xw' of the homogeneous Bézier polynomials.
fn derivative_numerator(points: &[DVec3], axis: usize, t: f64) -> f64 {
    with_copy(points, |work| derivative_numerator_in(work, axis, t))
}

/// [`derivative_numerator`] on `work`, a scratch copy of the points.
fn derivative_numerator_in(work: &mut [DVec3], axis: usize, t: f64) -> f64 {
    let n = work.len() - 1;
    for r in 1..n {
        for i in 0..=n - r {
            work[i] = work[i] * (1.0 - t) + work[i + 1] * t;
        }
    }
    // After n − 1 steps work[0], work[1] span the tangent: P = (1−t)a + tb, P' = n(b − a).
    let (a, b) = (work[0], work[1]);
    let p = a * (1.0 - t) + b * t;
    let d = (b - a) * n as f64;
    d[axis] * p.z - p[axis] * d.z
}

/// Whether x'w − xw' of coordinate `axis` ([`derivative_numerator`]) keeps one sign over
/// [0, 1], so that the coordinate does not turn: where all its Bernstein coefficients do (the
/// basis is non-negative). With X' = p Σ ΔXᵢ Bᵢᵖ⁻¹ and the product rule
/// Bᵢᵖ⁻¹ Bⱼᵖ = C(p − 1, i) C(p, j) / C(2p − 1, i + j) Bᵢ₊ⱼ²ᵖ⁻¹ (Farouki and Rajan, Algorithms
/// for polynomials in Bernstein form, 1988), the coefficient of B_k²ᵖ⁻¹ is, up to the positive
/// factor p / C(2p − 1, k), Σ over i + j = k of C(p − 1, i) C(p, j) (ΔXᵢ wⱼ − Xⱼ Δwᵢ). For a
/// polynomial curve this holds where the control points never step back along the axis (The
/// NURBS Book eq. 1.9); for a rational one it also settles a circle's quarter arcs without
/// sampling.
fn derivative_keeps_sign(points: &[DVec3], axis: usize) -> bool {
    let p = points.len() - 1;
    let (mut rising, mut falling) = (false, false);
    for k in 0..2 * p {
        let mut c = 0.0;
        for i in k.saturating_sub(p)..=k.min(p - 1) {
            let j = k - i;
            let dx = points[i + 1][axis] - points[i][axis];
            let dw = points[i + 1].z - points[i].z;
            c += binomial(p - 1, i) * binomial(p, j) * (dx * points[j].z - points[j][axis] * dw);
        }
        rising |= c > 0.0;
        falling |= c < 0.0;
    }
    !(rising && falling)
}

/// The parameters in (0, 1) where u(t) or v(t) turns (sign changes of the derivative, sampled
/// and pinned by bisection), sorted.
fn turning_parameters(points: &[DVec3]) -> Vec<f64> {
    let mut out = Vec::new();
    if points.len() < 3 {
        return out;
    }
    for axis in 0..2 {
        if derivative_keeps_sign(points, axis) {
            continue;
        }
        let f = |t: f64| derivative_numerator(points, axis, t);
        let mut t0 = 0.0;
        let mut f0 = f(t0);
        for k in 1..=EXTREMUM_SAMPLES {
            let t1 = k as f64 / EXTREMUM_SAMPLES as f64;
            let f1 = f(t1);
            if f0 * f1 < 0.0 {
                let (mut a, mut b, fa) = (t0, t1, f0);
                for _ in 0..BISECTION_STEPS {
                    let m = 0.5 * (a + b);
                    if f(m) * fa > 0.0 {
                        a = m;
                    } else {
                        b = m;
                    }
                }
                out.push(0.5 * (a + b));
            }
            if f1 != 0.0 {
                t0 = t1;
                f0 = f1;
            }
        }
    }
    out.sort_by(f64::total_cmp);
    out.dedup_by(|a, b| (*a - *b).abs() < 1e-12);
    // Where a segment ends with a coordinate's derivative at zero (a circle's quarter arcs
    // do), rounding gives it either sign there, so a turn may be "found" 1e-12 from the end:
    // a piece that short made a circle far from the origin cross itself. A true turn that
    // close to an end moves the coordinate by (1e-9)² of the segment's second derivative,
    // far below rounding, so the piece is taken as monotone.
    out.retain(|&t| t > END_SLACK && t < 1.0 - END_SLACK);
    out
}

/// The box of a monotone piece: its end points.
fn end_bounds(points: &[DVec3]) -> [f64; 4] {
    let a = points[0].truncate() / points[0].z;
    let b = points[points.len() - 1].truncate() / points[points.len() - 1].z;
    [a.x.min(b.x), a.x.max(b.x), a.y.min(b.y), a.y.max(b.y)]
}

/// Curve `curve` of loop `loop_index` as monotone pieces, in order along the curve.
pub fn monotone_pieces(curve: &TrimCurve, source: (usize, usize)) -> Vec<MonotonePiece> {
    let mut out = Vec::new();
    for segment in curve.bezier_segments() {
        let mut rest = segment.homogeneous_points().to_vec();
        let mut consumed = 0.0;
        for t in turning_parameters(segment.homogeneous_points()) {
            // Map t of the whole segment onto what is left of it.
            let local = (t - consumed) / (1.0 - consumed);
            let (left, right) = split_bezier(&rest, local);
            out.push(MonotonePiece {
                bounds: end_bounds(&left),
                points: left,
                source,
            });
            rest = right;
            consumed = t;
        }
        out.push(MonotonePiece {
            bounds: end_bounds(&rest),
            points: rest,
            source,
        });
    }
    out
}

impl MonotonePiece {
    /// The parameter where coordinate `axis` (0: u, 1: v) equals `value`, which must lie in the
    /// piece's range of that coordinate (bisection on the monotone coordinate).
    pub fn parameter_at(&self, axis: usize, value: f64) -> f64 {
        let start = bezier_point(&self.points, 0.0)[axis];
        let rising = bezier_point(&self.points, 1.0)[axis] >= start;
        let (mut a, mut b) = (0.0, 1.0);
        for _ in 0..BISECTION_STEPS {
            let m = 0.5 * (a + b);
            let x = bezier_point(&self.points, m)[axis];
            if (x < value) == rising {
                a = m;
            } else {
                b = m;
            }
            if b - a < 1e-15 {
                break;
            }
        }
        0.5 * (a + b)
    }

    /// The other coordinate where coordinate `axis` equals `value`.
    pub fn cross_at(&self, axis: usize, value: f64) -> f64 {
        bezier_point(&self.points, self.parameter_at(axis, value))[1 - axis]
    }

    /// Whether the piece crosses the segment of the line (coordinate 1 − `axis` = `level`) with
    /// coordinate `axis` in [min(a, b), max(a, b)): the piece's range of the line's fixed
    /// coordinate is taken half-open ([min, max)), so a loop crossing the line at a piece's end
    /// is counted once and a touching extremum twice or not at all.
    pub fn crosses(&self, axis: usize, level: f64, a: f64, b: f64) -> bool {
        let fixed = 1 - axis;
        let [lo_f, hi_f] = [self.bounds[2 * fixed], self.bounds[2 * fixed + 1]];
        if !(lo_f <= level && level < hi_f) {
            return false;
        }
        let (lo, hi) = (a.min(b), a.max(b));
        let [lo_a, hi_a] = [self.bounds[2 * axis], self.bounds[2 * axis + 1]];
        if hi_a < lo || lo_a >= hi {
            return false;
        }
        if lo <= lo_a && hi_a < hi {
            return true;
        }
        let x = self.cross_at(fixed, level);
        lo <= x && x < hi
    }

    /// Points along the piece with chords within `tolerance` (in (u, v)) of it, ends included
    /// (the first only where `out` does not end with it already).
    pub fn flatten(&self, tolerance: f64, out: &mut Vec<DVec2>) {
        let identity = |p: DVec2| Ok::<DVec2, std::convert::Infallible>(p);
        let Ok(()) = self.flatten_mapped(tolerance, UV_DEPTHS, identity, |_, _| None, out);
    }

    /// Points along the piece such that, mapped by `map` (into (u, v) itself, or onto a
    /// surface), every chord stays within `tolerance` of the mapped curve, checked at 1/4, 1/2
    /// and 3/4 of each chord's parameter interval; each interval is halved at least
    /// `depths.0` and at most `depths.1` times. Depth first, left half first, so the points come
    /// out in order; the first only where `out` does not end with it already.
    ///
    /// Where `bounds` gives the map's derivative bounds over an interval's box of (u, v) (the
    /// piece is monotone, so it stays in the box its ends span) and the piece's weights are
    /// positive, an interval that [`chord_deviation_bound`] keeps within `tolerance` is kept
    /// without sampling: its samples could not fail, so the points are the same.
    pub fn flatten_mapped<V: Vector, E>(
        &self,
        tolerance: f64,
        (min_depth, max_depth): (usize, usize),
        map: impl Fn(DVec2) -> Result<V, E>,
        bounds: impl Fn(DVec2, DVec2) -> Option<DerivativeBounds>,
        out: &mut Vec<DVec2>,
    ) -> Result<(), E> {
        let at = |t: f64| bezier_point(&self.points, t);
        let start = at(0.0);
        if out.last() != Some(&start) {
            out.push(start);
        }
        let speeds = self.derivative_bounds();
        // Rounding in the samples stays far below this margin.
        let limit = tolerance * (1.0 - 1e-9);
        let bounded = |t0: f64, t1: f64, from: DVec2, to: DVec2| {
            speeds.is_some_and(|speeds| {
                bounds(from.min(to), from.max(to))
                    .is_some_and(|b| chord_deviation_bound(t1 - t0, speeds, b) <= limit)
            })
        };
        // Where the bounds settle every interval of the least depth, those are the points (the
        // halvings below give the same dyadic parameters), and nothing is sampled.
        if min_depth <= max_depth.min(MAX_SETTLED_DEPTH) {
            let n = 1usize << min_depth;
            let mut points = [DVec2::ZERO; (1 << MAX_SETTLED_DEPTH) + 1];
            for (k, slot) in points.iter_mut().enumerate().take(n + 1) {
                *slot = at(k as f64 / n as f64);
            }
            let settled = (0..n).all(|k| {
                let (t0, t1) = (k as f64 / n as f64, (k + 1) as f64 / n as f64);
                bounded(t0, t1, points[k], points[k + 1])
            });
            if settled {
                out.extend_from_slice(&points[1..=n]);
                return Ok(());
            }
        }
        // Each interval's midpoint is its parent's quarter point, carried down rather than
        // evaluated again (the parameters are dyadic, so they are the same numbers exactly).
        let (end, middle) = (at(1.0), at(0.5));
        let mut stack = vec![Interval {
            t0: 0.0,
            t1: 1.0,
            s0: map(start)?,
            s1: map(end)?,
            start,
            end,
            middle: (middle, map(middle)?),
            depth: 0,
        }];
        while let Some(span) = stack.pop() {
            let Interval {
                t0,
                t1,
                s0,
                s1,
                start,
                end,
                middle,
                depth,
            } = span;
            if depth >= min_depth && bounded(t0, t1, start, end) {
                out.push(end);
                continue;
            }
            let tm = 0.5 * (t0 + t1);
            let (first, third) = (at(t0 + 0.25 * (t1 - t0)), at(t0 + 0.75 * (t1 - t0)));
            let (q1, q3) = (map(first)?, map(third)?);
            let sm = middle.1;
            let worst = distance_to_segment(sm, s0, s1)
                .max(distance_to_segment(q1, s0, s1))
                .max(distance_to_segment(q3, s0, s1));
            if (worst > tolerance || depth < min_depth) && depth < max_depth {
                stack.push(Interval {
                    t0: tm,
                    t1,
                    s0: sm,
                    s1,
                    start: middle.0,
                    end,
                    middle: (third, q3),
                    depth: depth + 1,
                });
                stack.push(Interval {
                    t0,
                    t1: tm,
                    s0,
                    s1: sm,
                    start,
                    end: middle.0,
                    middle: (first, q1),
                    depth: depth + 1,
                });
            } else {
                out.push(end);
            }
        }
        Ok(())
    }

    /// Bounds on the piece's first and second derivatives in t over the whole piece:
    /// [max |u'|, max |v'|, max |u''|, max |v''|], or None where a weight is not positive. The
    /// derivatives of a Bézier curve are Bézier curves of its points' differences, times n and
    /// n(n − 1) (The NURBS Book, eq. 1.10), so each is at most its largest difference. That
    /// bounds a = (c − c₀) w, moved by the first point c₀ so that each coordinate of c − c₀ is
    /// at most the points' spread from it, and with w at least the least weight the quotient
    /// rule (eq. 4.8) gives c' = (a' − (c − c₀) w') / w and c'' = (a'' − 2 c' w' − (c − c₀) w'')
    /// / w; for equal weights these are the polynomial's own bounds.
    pub(crate) fn derivative_bounds(&self) -> Option<[f64; 4]> {
        let least = self
            .points
            .iter()
            .map(|h| h.z)
            .fold(f64::INFINITY, f64::min);
        let first = self.points.first()?;
        if !(least > 0.0) || self.points.len() < 2 {
            return None;
        }
        let origin = first.truncate() / first.z;
        let moved = |h: DVec3| (h.truncate() - origin * h.z).extend(h.z);
        let spread = self.points.iter().fold(DVec2::ZERO, |m, h| {
            m.max((h.truncate() / h.z - origin).abs())
        });
        let n = (self.points.len() - 1) as f64;
        // Largest |Δ| and |Δ²| of (a_u, a_v, w).
        let (mut d1, mut d2) = (DVec3::ZERO, DVec3::ZERO);
        for (k, pair) in self.points.windows(2).enumerate() {
            let (a, b) = (moved(pair[0]), moved(pair[1]));
            d1 = d1.max((b - a).abs());
            if let Some(&next) = self.points.get(k + 2) {
                d2 = d2.max((moved(next) - 2.0 * b + a).abs());
            }
        }
        let (d1, d2) = (d1 * n, d2 * (n * (n - 1.0)));
        let speed = (d1.truncate() + spread * d1.z) / least;
        let bend = (d2.truncate() + 2.0 * speed * d1.z + spread * d2.z) / least;
        let bounds = [speed.x, speed.y, bend.x, bend.y];
        bounds.iter().all(|b| b.is_finite()).then_some(bounds)
    }
}

/// An upper bound of the distance from S(c(t)) to the chord between S(c(t0)) and S(c(t1)),
/// for t in an interval of `length` of a curve c whose derivative bounds are `speeds`
/// ([max |u'|, max |v'|, max |u''|, max |v''|]) on a surface with `bounds` over the curve's
/// box. With g(τ) = S(c(t0 + τ·length)), g'' = length² (D²S(c', c') + DS c''), bounded by
/// length² (A u'² + 2B u' v' + C v'² + |S_u| u'' + |S_v| v''); the distance from g(τ) to the
/// chord is at most |g(τ) − the chord's point at τ| ≤ τ(1 − τ) max |g''| / 2 ≤ max |g''| / 8.
pub fn chord_deviation_bound(length: f64, speeds: [f64; 4], bounds: DerivativeBounds) -> f64 {
    let [u1, v1, u2, v2] = speeds;
    let [a, b, c] = bounds.second;
    let [su, sv] = bounds.first;
    let curvature = a * u1 * u1 + 2.0 * b * u1 * v1 + c * v1 * v1 + su * u2 + sv * v2;
    0.125 * length * length * curvature
}

/// One parameter interval of [`MonotonePiece::flatten_mapped`]: its ends, their mapped
/// points, the (u, v) points at its ends and its midpoint with its mapped point.
struct Interval<V> {
    t0: f64,
    t1: f64,
    s0: V,
    s1: V,
    start: DVec2,
    end: DVec2,
    middle: (DVec2, V),
    depth: usize,
}

/// The deepest least depth for which [`MonotonePiece::flatten_mapped`] tries to settle every
/// interval by its bounds before sampling any.
const MAX_SETTLED_DEPTH: usize = 4;

/// The least and most halvings of a piece flattened in (u, v).
pub const UV_DEPTHS: (usize, usize) = (1, 24);

pub use crate::vector::distance_to_segment;

/// Crossing parity of the L-shaped path from `from` to `to` (first along u at `from`'s v, then
/// along v at `to`'s u) with `pieces`: whether the two points are on different sides of the
/// loops.
pub fn path_parity<'a>(
    pieces: impl Iterator<Item = &'a MonotonePiece> + Clone,
    from: DVec2,
    to: DVec2,
) -> bool {
    let mut odd = false;
    for piece in pieces.clone() {
        odd ^= piece.crosses(0, from.y, from.x, to.x);
    }
    for piece in pieces {
        odd ^= piece.crosses(1, to.x, from.y, to.y);
    }
    odd
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Uniform numbers in [0, 1) from `seed` ([`crate::test_support::uniform`]).
    fn uniform(seed: u64) -> impl FnMut() -> f64 {
        let mut state = seed;
        move || crate::test_support::uniform(&mut state)
    }

    /// Random rational Bézier curves of degrees 2 to 6 (weights 0.2 to 5, points anywhere in
    /// a box 1e3 wide): where the coefficient test says a coordinate keeps its direction, the
    /// derivative sampled at 4,001 parameters never changes sign; and the test does say so for
    /// a rotated circular arc exactly where the arc holds no extremum of that coordinate.
    #[test]
    fn a_derivative_said_to_keep_its_sign_keeps_it() {
        let mut random = uniform(7);
        let mut kept = 0;
        for case in 0..3000 {
            let degree = 2 + case % 5;
            let points: Vec<DVec3> = (0..=degree)
                .map(|_| {
                    let w = 0.2 + 4.8 * random() * random();
                    let p = DVec2::new(random(), random()) * 1e3 - 500.0;
                    (p * w).extend(w)
                })
                .collect();
            for axis in 0..2 {
                if !derivative_keeps_sign(&points, axis) {
                    continue;
                }
                kept += 1;
                let values: Vec<f64> = (0..=4000)
                    .map(|k| derivative_numerator(&points, axis, k as f64 / 4000.0))
                    .collect();
                let scale = values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                let noise = 1e-12 * scale;
                let rising = values.iter().any(|&v| v > noise);
                let falling = values.iter().any(|&v| v < -noise);
                assert!(!(rising && falling), "case {case}, axis {axis}: {points:?}");
            }
        }
        assert!(kept > 500, "only {kept} coordinates kept their sign");
        // A circular arc of opening 2θ < π as a rational quadratic (middle weight cos θ),
        // rotated to start at angle a: x = cos turns where the arc passes 0 or π, y = sin
        // where it passes ±π/2.
        for k in 0..400 {
            let (a, theta) = (random() * 6.3 - 3.15, 0.05 + 1.45 * random());
            let at = |s: f64| DVec2::new(s.cos(), s.sin());
            let w = theta.cos();
            let middle = at(a + theta) / w;
            let points = [
                at(a).extend(1.0),
                (middle * w).extend(w),
                at(a + 2.0 * theta).extend(1.0),
            ];
            let passes = |s: f64| {
                (-4..=4).any(|n| {
                    let t = s + std::f64::consts::TAU * n as f64;
                    a + 1e-9 < t && t < a + 2.0 * theta - 1e-9
                })
            };
            let half_pi = std::f64::consts::FRAC_PI_2;
            let x_turns = passes(0.0) || passes(std::f64::consts::PI);
            let y_turns = passes(half_pi) || passes(-half_pi);
            assert_eq!(
                derivative_keeps_sign(&points, 0),
                !x_turns,
                "arc {k}: a {a}, θ {theta}"
            );
            assert_eq!(
                derivative_keeps_sign(&points, 1),
                !y_turns,
                "arc {k}: a {a}, θ {theta}"
            );
        }
    }
}
