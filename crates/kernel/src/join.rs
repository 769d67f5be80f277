//! Joining faces into polysurfaces: which boundary edges of trimmed NURBS faces coincide
//! within a tolerance (shared edges), which belong to one face only (naked edges), and a
//! tessellation that is watertight across the shared edges.
//!
//! - **Edges.** Every face is a set of loops in its (u, v) domain: its trim loops, or the
//!   domain's rectangle (four sides) for an untrimmed face. Each curve of a loop is an edge;
//!   its image on the surface, S(c(t)), is the edge in space. An edge shorter than the
//!   tolerance in space (a pole, a collapsed side) is degenerate: neither shared nor naked.
//! - **Sharing.** Two edges are shared when their ends meet (in the same or the opposite
//!   direction; a closed edge meets a closed edge) and every one of 17 samples of each lies
//!   within the tolerance of the other (the distance found by Brent's minimisation near the
//!   nearest of 64 samples). Each edge is shared at most once, the closest pairs first.
//! - **Watertight tessellation.** Each shared edge is sampled once, on one of its faces, at
//!   a chord tolerance; the other face takes the same points in space, at the parameters of
//!   its own edge nearest to them. Corners where edges meet are merged into one point. Every
//!   face is then a constrained Delaunay triangulation of its (u, v) domain with those
//!   boundary points and the inner points of its tolerance grid, so the two faces at a shared
//!   edge use one vertex sequence, and a closed polysurface gives a closed mesh. Faces are
//!   turned to agree in orientation across their shared edges where they can be.

use glam::{DVec2, DVec3};
use spade::{ConstrainedDelaunayTriangulation, Point2, Triangulation};

use crate::error::GeometryError;
use crate::tess::{self, MAX_TRIANGLES, Tessellation, TriangleMesh};
use crate::trim::{TrimLoop, TrimmedSurface, domain_rect, shapes};
use crate::{CurvatureValues, TrimCurve};

/// Samples per edge compared when edges are matched.
const MATCH_SAMPLES: usize = 16;
/// Samples per edge searched first for the nearest point.
const SEARCH_SAMPLES: usize = 64;
/// The nearest point on an edge is found to this fraction of the tolerance.
const SEARCH_PRECISION: f64 = 1e-2;

/// One edge: curve `curve` of loop `loop_index` of face `face`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct EdgeId {
    pub face: usize,
    pub loop_index: usize,
    pub curve: usize,
}

/// Two edges that coincide.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SharedEdge {
    pub a: EdgeId,
    pub b: EdgeId,
    /// Whether b runs the opposite way to a (what two consistently oriented faces give).
    pub reversed: bool,
    /// The largest distance found between them.
    pub gap: f64,
}

/// The edges of a set of faces, sorted out.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Topology {
    pub shared: Vec<SharedEdge>,
    pub naked: Vec<EdgeId>,
    pub degenerate: Vec<EdgeId>,
}

/// The items `0..count` in connected groups, `links` joining pairs (union–find with path
/// halving), each group sorted, in order of its first item.
pub fn connected_groups(
    count: usize,
    links: impl IntoIterator<Item = (usize, usize)>,
) -> Vec<Vec<usize>> {
    let mut parent: Vec<usize> = (0..count).collect();
    fn root(parent: &mut [usize], mut k: usize) -> usize {
        while parent[k] != k {
            parent[k] = parent[parent[k]];
            k = parent[k];
        }
        k
    }
    for (a, b) in links {
        let (x, y) = (root(&mut parent, a), root(&mut parent, b));
        if x != y {
            parent[x.max(y)] = x.min(y);
        }
    }
    let mut groups: Vec<Vec<usize>> = Vec::new();
    let mut slot = vec![usize::MAX; count];
    for k in 0..count {
        let r = root(&mut parent, k);
        if slot[r] == usize::MAX {
            slot[r] = groups.len();
            groups.push(Vec::new());
        }
        groups[slot[r]].push(k);
    }
    groups
}

impl Topology {
    /// The faces in connected groups (joined through shared edges), each sorted, in order of
    /// their first face.
    pub fn components(&self, faces: usize) -> Vec<Vec<usize>> {
        connected_groups(faces, self.shared.iter().map(|s| (s.a.face, s.b.face)))
    }

    /// The topologies of several face lists put one after another: each part's faces
    /// numbered on from the faces before it (`parts`: each topology with its face count).
    pub fn concatenated<'a>(parts: impl IntoIterator<Item = (&'a Topology, usize)>) -> Topology {
        let mut out = Topology::default();
        let mut offset = 0;
        for (t, faces) in parts {
            let shift = |e: EdgeId| EdgeId {
                face: e.face + offset,
                ..e
            };
            out.shared.extend(t.shared.iter().map(|s| SharedEdge {
                a: shift(s.a),
                b: shift(s.b),
                ..*s
            }));
            out.naked.extend(t.naked.iter().map(|&e| shift(e)));
            out.degenerate
                .extend(t.degenerate.iter().map(|&e| shift(e)));
            offset += faces;
        }
        out
    }

    /// The edges of the faces `faces` (indices into this topology's faces) alone, numbered as
    /// they come in `faces`; a shared edge with a face outside them is left out.
    pub fn restricted(&self, faces: &[usize]) -> Topology {
        let local: std::collections::HashMap<usize, usize> =
            faces.iter().enumerate().map(|(k, &f)| (f, k)).collect();
        let to_local = |e: EdgeId| local.get(&e.face).map(|&face| EdgeId { face, ..e });
        Topology {
            shared: self
                .shared
                .iter()
                .filter_map(|s| {
                    Some(SharedEdge {
                        a: to_local(s.a)?,
                        b: to_local(s.b)?,
                        ..*s
                    })
                })
                .collect(),
            naked: self.naked.iter().filter_map(|&e| to_local(e)).collect(),
            degenerate: self
                .degenerate
                .iter()
                .filter_map(|&e| to_local(e))
                .collect(),
        }
    }

    /// Whether every non-degenerate edge is shared (the faces close up).
    pub fn is_closed(&self) -> bool {
        self.naked.is_empty() && !self.shared.is_empty()
    }
}

/// The loops of a face: its trim loops, or the domain's rectangle.
pub fn face_loops(face: &TrimmedSurface) -> Result<Vec<TrimLoop>, GeometryError> {
    if face.is_trimmed() {
        return Ok(face.loops().to_vec());
    }
    let [u0, u1, v0, v1] = domain_rect(face.surface());
    Ok(vec![shapes::rectangle(
        DVec2::new(u0, v0),
        DVec2::new(u1, v1),
    )?])
}

/// The point of a (u, v) curve at t ∈ [0, 1] of its domain.
fn curve_uv(curve: &TrimCurve, t: f64) -> DVec2 {
    let (a, b) = curve.domain();
    // a + (b − a) can round past b: the parameter is kept in the domain.
    let at = (a + (b - a) * t.clamp(0.0, 1.0)).clamp(a, b);
    curve
        .point_at(at)
        .unwrap_or_else(|_| curve.control_point(0))
}

/// One edge with its surface, ready to be sampled.
struct Edge<'a> {
    id: EdgeId,
    face: &'a TrimmedSurface,
    curve: &'a TrimCurve,
    /// Samples at t = k / SEARCH_SAMPLES.
    samples: Vec<DVec3>,
    lo: DVec3,
    hi: DVec3,
    /// Closed in space (its ends meet).
    closed: bool,
    /// Closed in (u, v).
    closed_uv: bool,
    degenerate: bool,
    /// How far in space a nearest point may be off: the search for it stops there.
    precision: f64,
    /// How far the edge bows away from the chords between its samples, worked out when
    /// first needed ([`Edge::bow`]).
    bow: crate::par::RaceCell<f64>,
}

impl Edge<'_> {
    fn point(&self, t: f64) -> DVec3 {
        let uv = curve_uv(self.curve, t);
        self.face
            .surface()
            .point_at_clamped(uv)
            .unwrap_or(self.samples[0])
    }

    fn uv(&self, t: f64) -> DVec2 {
        curve_uv(self.curve, t)
    }

    /// An allowance for how far the edge strays from the polyline through its samples: one
    /// and a half times the largest distance of a chord's middle from the edge's point
    /// halfway along it (a smooth curve's chord error peaks about its middle); zero for a
    /// straight edge.
    fn bow(&self) -> f64 {
        *self.bow.get_or_init(|| {
            let n = SEARCH_SAMPLES;
            let largest = (0..n)
                .map(|k| {
                    let middle = self.point((k as f64 + 0.5) / n as f64);
                    middle.distance(0.5 * (self.samples[k] + self.samples[k + 1]))
                })
                .fold(0.0, f64::max);
            1.5 * largest
        })
    }

    /// The distance from `p` to the edge, as far as telling whether it is within `tolerance`
    /// needs: the distance to the polyline through the samples, grown by the edge's bow,
    /// where that settles it (an upper bound when within, a lower bound when beyond), else
    /// the nearest point's ([`Edge::closest`]).
    fn distance_within(&self, p: DVec3, tolerance: f64) -> f64 {
        let polyline = self
            .samples
            .windows(2)
            .map(|w| {
                let d = w[1] - w[0];
                let t =
                    ((p - w[0]).dot(d) / d.length_squared().max(f64::MIN_POSITIVE)).clamp(0.0, 1.0);
                (w[0] + d * t).distance_squared(p)
            })
            .fold(f64::INFINITY, f64::min)
            .sqrt();
        let bow = self.bow();
        if polyline + bow <= tolerance {
            polyline + bow
        } else if polyline - bow > tolerance {
            polyline - bow
        } else {
            self.closest(p, None).1
        }
    }

    /// The parameter of the edge's point nearest `p` and the distance: the nearest sample
    /// (that sample itself where `p` lies within [`Edge::precision`] of it), then Brent's
    /// minimisation on the intervals either side of it, or on the one the point lies along
    /// where it lies near the edge (the samples within `window` of a hint when given).
    fn closest(&self, p: DVec3, hint: Option<(f64, f64)>) -> (f64, f64) {
        let n = SEARCH_SAMPLES;
        let candidates: Vec<usize> = match hint {
            Some((t, window)) => {
                let lo = ((t - window).max(0.0) * n as f64).floor() as usize;
                let hi = (((t + window).min(1.0) * n as f64).ceil() as usize).min(n);
                (lo..=hi).collect()
            }
            None => (0..=n).collect(),
        };
        let k = candidates
            .iter()
            .copied()
            .min_by(|&a, &b| {
                self.samples[a]
                    .distance_squared(p)
                    .total_cmp(&self.samples[b].distance_squared(p))
            })
            .unwrap_or(0);
        // A point at a sample (a follower's vertex where the owner put one: nearly every
        // search while joining) is found there, to the search's precision, without searching.
        let at_sample = self.samples[k].distance(p);
        if at_sample <= self.precision {
            return (k as f64 / n as f64, at_sample);
        }
        // The intervals either side of the nearest sample (and, on a curve closed in
        // space, the other end's interval at its ends).
        let mut intervals = vec![(k.saturating_sub(1), k), (k, (k + 1).min(n))];
        // Near the edge (a follower's vertex lies on it), the nearest point lies in the
        // interval whose chord passes within a tenth of its length, where the point projects
        // well inside that chord: that interval alone.
        if k > 0 && k < n {
            let off = |i: usize| {
                let (a, b) = (self.samples[i], self.samples[i + 1]);
                let d = b - a;
                let length = d.length().max(f64::MIN_POSITIVE);
                let t = (p - a).dot(d) / (length * length);
                let clamped = t.clamp(0.0, 1.0);
                ((a + d * clamped).distance(p) / length, t)
            };
            let near = [(k - 1, off(k - 1)), (k, off(k))]
                .into_iter()
                .find(|(_, (distance, t))| *distance < 0.1 && (0.05..=0.95).contains(t));
            if let Some((i, _)) = near {
                intervals = vec![(i, i + 1)];
            }
        }
        if self.closed && (k == 0 || k == n) {
            intervals.push((0, 1));
            intervals.push((n - 1, n));
        }
        intervals
            .into_iter()
            .filter(|(a, b)| a < b)
            .map(|(a, b)| self.nearest_between(p, a as f64 / n as f64, b as f64 / n as f64))
            .min_by(|x, y| x.1.total_cmp(&y.1))
            .unwrap_or((0.0, self.samples[0].distance(p)))
    }

    /// The parameter in [a, b] nearest `p`, and the distance: Brent's minimisation of the
    /// squared distance (parabolic interpolation through the three best points, a
    /// golden-section step where the parabola's step is not trusted; R. P. Brent, Algorithms
    /// for Minimization without Derivatives, 1973, ch. 5), 60 steps at most. [a, b] is one
    /// interval between samples; the search stops once the bracket, scaled by that interval's
    /// chord, is shorter than [`Edge::precision`] in space. The interval's ends (samples) count
    /// too: the search only narrows toward them.
    fn nearest_between(&self, p: DVec3, a: f64, b: f64) -> (f64, f64) {
        let f = |t: f64| self.point(t).distance_squared(p);
        let n = SEARCH_SAMPLES as f64;
        let sample = |t: f64| ((t * n).round() as usize).min(SEARCH_SAMPLES);
        let (ka, kb) = (sample(a), sample(b));
        let chord = self.samples[ka].distance(self.samples[kb]);
        let stop = 0.5 * (b - a) * self.precision / chord.max(f64::MIN_POSITIVE);
        let (t, d2) = brent_minimum(f, a, b, stop);
        [
            (t, d2),
            (a, self.samples[ka].distance_squared(p)),
            (b, self.samples[kb].distance_squared(p)),
        ]
        .into_iter()
        .min_by(|x, y| x.1.total_cmp(&y.1))
        .map(|(t, d2)| (t, d2.sqrt()))
        .unwrap_or((t, d2.sqrt()))
    }
}

/// The minimum of `f` on [a, b] to within `tolerance` in the argument, and its value: Brent's
/// method (R. P. Brent, Algorithms for Minimization without Derivatives, 1973, ch. 5):
/// successive parabolic interpolation through the three best points so far, with a
/// golden-section step into the larger part of the bracket whenever the parabola's step falls
/// outside it or does not halve the step before last. At most 60 evaluations.
fn brent_minimum(f: impl Fn(f64) -> f64, mut a: f64, mut b: f64, tolerance: f64) -> (f64, f64) {
    // (3 − √5) / 2: the golden section's smaller part.
    let golden = 0.5 * (3.0 - 5f64.sqrt());
    let mut x = a + golden * (b - a);
    let (mut w, mut v) = (x, x);
    let mut fx = f(x);
    let (mut fw, mut fv) = (fx, fx);
    // The step just taken and the one before it.
    let (mut d, mut e) = (0.0f64, 0.0f64);
    for _ in 0..60 {
        let middle = 0.5 * (a + b);
        let tol1 = tolerance.max(4.0 * f64::EPSILON * x.abs());
        let tol2 = 2.0 * tol1;
        if (x - middle).abs() <= tol2 - 0.5 * (b - a) {
            break;
        }
        let mut parabolic = false;
        if e.abs() > tol1 {
            // The parabola through (x, fx), (w, fw), (v, fv): its vertex at x + p / q.
            let r = (x - w) * (fx - fv);
            let mut q = (x - v) * (fx - fw);
            let mut p = (x - v) * q - (x - w) * r;
            q = 2.0 * (q - r);
            if q > 0.0 {
                p = -p;
            } else {
                q = -q;
            }
            let before = e;
            if p.abs() < (0.5 * q * before).abs() && p > q * (a - x) && p < q * (b - x) {
                e = d;
                d = p / q;
                let u = x + d;
                if u - a < tol2 || b - u < tol2 {
                    d = tol1.copysign(middle - x);
                }
                parabolic = true;
            }
        }
        if !parabolic {
            e = if x >= middle { a - x } else { b - x };
            d = golden * e;
        }
        let u = if d.abs() >= tol1 {
            x + d
        } else {
            x + tol1.copysign(d)
        };
        let fu = f(u);
        if fu <= fx {
            if u >= x {
                a = x;
            } else {
                b = x;
            }
            (v, fv) = (w, fw);
            (w, fw) = (x, fx);
            (x, fx) = (u, fu);
        } else {
            if u < x {
                a = u;
            } else {
                b = u;
            }
            if fu <= fw || w == x {
                (v, fv) = (w, fw);
                (w, fw) = (u, fu);
            } else if fu <= fv || v == x || v == w {
                (v, fv) = (u, fu);
            }
        }
    }
    (x, fx)
}

fn edges_of<'a>(
    faces: &'a [TrimmedSurface],
    loops: &'a [Vec<TrimLoop>],
    tolerance: f64,
) -> Vec<Edge<'a>> {
    // Face by face on every core, in face order.
    let per_face: Vec<Vec<Edge<'a>>> = crate::par::map(faces.len().min(loops.len()), |f| {
        let (face, face_loops) = (&faces[f], &loops[f]);
        let mut out = Vec::new();
        for (l, lp) in face_loops.iter().enumerate() {
            for (c, curve) in lp.iter().enumerate() {
                let id = EdgeId {
                    face: f,
                    loop_index: l,
                    curve: c,
                };
                out.push(make_edge(id, face, curve, tolerance));
            }
        }
        out
    });
    per_face.into_iter().flatten().collect()
}

fn make_edge<'a>(
    id: EdgeId,
    face: &'a TrimmedSurface,
    curve: &'a TrimCurve,
    tolerance: f64,
) -> Edge<'a> {
    let surface = face.surface();
    let samples: Vec<DVec3> = (0..=SEARCH_SAMPLES)
        .map(|k| {
            let uv = curve_uv(curve, k as f64 / SEARCH_SAMPLES as f64);
            surface.point_at_clamped(uv).unwrap_or(DVec3::ZERO)
        })
        .collect();
    let lo = samples.iter().copied().fold(DVec3::INFINITY, DVec3::min);
    let hi = samples
        .iter()
        .copied()
        .fold(DVec3::NEG_INFINITY, DVec3::max);
    let length: f64 = samples.windows(2).map(|w| w[0].distance(w[1])).sum();
    let (first, last) = (samples[0], samples[SEARCH_SAMPLES]);
    let closed_uv = curve_uv(curve, 0.0).distance(curve_uv(curve, 1.0)) <= 1e-12;
    Edge {
        id,
        face,
        curve,
        lo,
        hi,
        closed: first.distance(last) <= tolerance,
        closed_uv,
        degenerate: length <= tolerance,
        samples,
        precision: SEARCH_PRECISION * tolerance,
        bow: crate::par::RaceCell::new(),
    }
}

/// Whether edges `e` and `f` coincide within `tolerance`: `Some((reversed, gap))`.
fn match_edges(e: &Edge, f: &Edge, tolerance: f64) -> Option<(bool, f64)> {
    if e.closed != f.closed {
        return None;
    }
    let grow = DVec3::splat(tolerance);
    if (e.lo - grow).cmpgt(f.hi).any() || (f.lo - grow).cmpgt(e.hi).any() {
        return None;
    }
    let n = SEARCH_SAMPLES;
    let (e0, e1, f0, f1) = (e.samples[0], e.samples[n], f.samples[0], f.samples[n]);
    let mut gap: f64 = 0.0;
    let reversed = if e.closed {
        // Compare directions where e's quarter point lands on f.
        let (t, d) = f.closest(e.point(0.25), None);
        if d > tolerance {
            return None;
        }
        let (t2, _) = f.closest(e.point(0.3), None);
        let step = t2 - t;
        let step = if step.abs() > 0.5 { -step } else { step };
        step < 0.0
    } else if e0.distance(f0) <= tolerance && e1.distance(f1) <= tolerance {
        gap = e0.distance(f0).max(e1.distance(f1));
        false
    } else if e0.distance(f1) <= tolerance && e1.distance(f0) <= tolerance {
        gap = e0.distance(f1).max(e1.distance(f0));
        true
    } else {
        return None;
    };
    for (x, y) in [(e, f), (f, e)] {
        for k in 1..MATCH_SAMPLES {
            let d = y.distance_within(x.point(k as f64 / MATCH_SAMPLES as f64), tolerance);
            if d > tolerance {
                return None;
            }
            gap = gap.max(d);
        }
    }
    Some((reversed, gap))
}

/// The shared, naked and degenerate edges of `faces` at `tolerance` (model units).
pub fn find_topology(faces: &[TrimmedSurface], tolerance: f64) -> Result<Topology, GeometryError> {
    let loops: Vec<Vec<TrimLoop>> = faces.iter().map(face_loops).collect::<Result<_, _>>()?;
    let edges = edges_of(faces, &loops, tolerance);
    let mut candidates = Vec::new();
    for i in 0..edges.len() {
        if edges[i].degenerate {
            continue;
        }
        for j in i + 1..edges.len() {
            if edges[j].degenerate {
                continue;
            }
            if let Some((reversed, gap)) = match_edges(&edges[i], &edges[j], tolerance) {
                candidates.push((gap, i, j, reversed));
            }
        }
    }
    candidates.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut used = vec![false; edges.len()];
    let mut topology = Topology::default();
    for (gap, i, j, reversed) in candidates {
        if used[i] || used[j] {
            continue;
        }
        used[i] = true;
        used[j] = true;
        topology.shared.push(SharedEdge {
            a: edges[i].id,
            b: edges[j].id,
            reversed,
            gap,
        });
    }
    for (k, e) in edges.iter().enumerate() {
        if e.degenerate {
            topology.degenerate.push(e.id);
        } else if !used[k] {
            topology.naked.push(e.id);
        }
    }
    Ok(topology)
}

/// The edge's points in space at chord tolerance `tolerance` (for drawing naked edges).
pub fn edge_polyline(
    faces: &[TrimmedSurface],
    id: EdgeId,
    tolerance: f64,
) -> Result<Vec<DVec3>, GeometryError> {
    let face = faces
        .get(id.face)
        .ok_or_else(|| failed(format!("there is no face {}", id.face)))?;
    let loops = face_loops(face)?;
    let curve = loops
        .get(id.loop_index)
        .and_then(|l| l.get(id.curve))
        .ok_or_else(|| failed("there is no such edge".into()))?;
    let edge = make_edge(id, face, curve, tolerance);
    Ok(sample_edge(&edge, tolerance)
        .into_iter()
        .map(|t| edge.point(t))
        .collect())
}

fn failed(message: String) -> GeometryError {
    GeometryError::Construction {
        what: "join",
        message,
    }
}

/// Parameters along an edge whose chords stay within `tolerance` of it (checked at each
/// chord's middle), at least 8 intervals.
fn sample_edge(edge: &Edge, tolerance: f64) -> Vec<f64> {
    let mut out = vec![0.0];
    let mut stack: Vec<(f64, f64, usize)> = (0..8)
        .rev()
        .map(|k| (k as f64 / 8.0, (k + 1) as f64 / 8.0, 0))
        .collect();
    while let Some((a, b, depth)) = stack.pop() {
        let m = 0.5 * (a + b);
        let (pa, pb, pm) = (edge.point(a), edge.point(b), edge.point(m));
        if depth < 24 && pm.distance(0.5 * (pa + pb)) > tolerance {
            stack.push((m, b, depth + 1));
            stack.push((a, m, depth + 1));
        } else {
            out.push(b);
        }
    }
    out
}

/// One vertex of the joined mesh: where it is and which faces use it at which (u, v).
struct JoinedVertex {
    position: DVec3,
    uses: Vec<(usize, DVec2)>,
}

/// The faces' tessellation as one mesh, watertight across the shared edges of `topology`:
/// `tolerance` bounds the chords (edges at a quarter of it) and the inner grids.
pub fn tessellate_joined(
    faces: &[TrimmedSurface],
    topology: &Topology,
    tolerance: f64,
    curvature: bool,
) -> Result<TriangleMesh, GeometryError> {
    if !(tolerance.is_finite() && tolerance > 0.0) {
        return Err(failed(format!(
            "the tolerance must be finite and > 0, got {tolerance}"
        )));
    }
    let loops: Vec<Vec<TrimLoop>> = faces.iter().map(face_loops).collect::<Result<_, _>>()?;
    let edges = edges_of(faces, &loops, tolerance);
    let positions: std::collections::HashMap<EdgeId, usize> =
        edges.iter().enumerate().map(|(k, e)| (e.id, k)).collect();
    let index_of = |id: EdgeId| positions.get(&id).copied();
    let merge = topology.shared.iter().map(|s| s.gap).fold(0.0, f64::max) + tolerance * 1e-3;
    let mut vertices: Vec<JoinedVertex> = Vec::new();
    // Corners: every edge's ends, merged within the largest gap (the first corner within it,
    // found through a grid of cells of that size).
    let cell_size = merge.max(1e-300);
    let cell_of = |p: DVec3| (p / cell_size).floor().to_array().map(|c| c as i64);
    let mut cells: std::collections::HashMap<[i64; 3], Vec<usize>> =
        std::collections::HashMap::new();
    let mut corner_of = |p: DVec3, vertices: &mut Vec<JoinedVertex>| -> usize {
        let [x, y, z] = cell_of(p);
        let mut found: Option<usize> = None;
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    for &k in cells.get(&[x + dx, y + dy, z + dz]).into_iter().flatten() {
                        if vertices[k].position.distance(p) <= cell_size
                            && found.is_none_or(|f| k < f)
                        {
                            found = Some(k);
                        }
                    }
                }
            }
        }
        if let Some(k) = found {
            return k;
        }
        vertices.push(JoinedVertex {
            position: p,
            uses: Vec::new(),
        });
        cells.entry([x, y, z]).or_default().push(vertices.len() - 1);
        vertices.len() - 1
    };
    // Each edge's vertex sequence, in its own direction: (vertex, t on the edge).
    let mut sequences: Vec<Option<Vec<(usize, f64)>>> = vec![None; edges.len()];
    let mut corners_done: Vec<(usize, usize)> = Vec::new();
    for e in &edges {
        let start = corner_of(e.samples[0], &mut vertices);
        let end = corner_of(e.samples[SEARCH_SAMPLES], &mut vertices);
        corners_done.push((start, end));
    }
    // Owners first (naked edges and the first of each shared pair; a closed-in-(u, v) edge
    // gives way to an open one so the corner sits at the open edge's ends).
    let mut owners: Vec<(usize, Option<(usize, bool)>)> = Vec::new();
    let mut followers: Vec<(usize, usize, bool)> = Vec::new();
    for s in &topology.shared {
        let (Some(a), Some(b)) = (index_of(s.a), index_of(s.b)) else {
            continue;
        };
        let (own, follow) = if edges[a].closed_uv && !edges[b].closed_uv {
            (b, a)
        } else {
            (a, b)
        };
        owners.push((own, None));
        followers.push((follow, own, s.reversed));
    }
    for &id in &topology.naked {
        if let Some(k) = index_of(id) {
            owners.push((k, None));
        }
    }
    // The owners' samples along their edges, on every core; their vertices numbered in order.
    let owner_samples: Vec<Vec<(f64, DVec3)>> = crate::par::map(owners.len(), |i| {
        let e = &edges[owners[i].0];
        sample_edge(e, 0.25 * tolerance)
            .into_iter()
            .map(|t| (t, e.point(t)))
            .collect()
    });
    for (&(k, _), samples) in owners.iter().zip(owner_samples) {
        let (start, end) = corners_done[k];
        let mut seq = Vec::with_capacity(samples.len());
        for (i, &(t, position)) in samples.iter().enumerate() {
            let v = if i == 0 {
                start
            } else if i + 1 == samples.len() {
                end
            } else {
                vertices.push(JoinedVertex {
                    position,
                    uses: Vec::new(),
                });
                vertices.len() - 1
            };
            seq.push((v, t));
        }
        sequences[k] = Some(seq);
    }
    // The followers' parameters at the owners' points (a search each, on every core). Where a
    // follower is also another's owner, its sequence must be in place first: one at a time.
    let follows_a_follower = {
        let following: std::collections::HashSet<usize> =
            followers.iter().map(|&(f, _, _)| f).collect();
        followers
            .iter()
            .any(|&(_, own, _)| following.contains(&own))
    };
    let follow = |&(follow, own, reversed): &(usize, usize, bool),
                  sequences: &[Option<Vec<(usize, f64)>>]| {
        let theirs = sequences[own].as_ref()?;
        Some(follower_sequence(
            &edges[follow],
            theirs,
            reversed,
            &vertices,
        ))
    };
    if follows_a_follower {
        for pair in &followers {
            if let Some(seq) = follow(pair, &sequences) {
                sequences[pair.0] = Some(seq);
            }
        }
    } else {
        let found: Vec<Option<Vec<(usize, f64)>>> =
            crate::par::map(followers.len(), |i| follow(&followers[i], &sequences));
        for (pair, seq) in followers.iter().zip(found) {
            if let Some(seq) = seq {
                sequences[pair.0] = Some(seq);
            }
        }
    }
    // Degenerate edges (a pole, a collapsed side): one point in space, but a line in the
    // face's (u, v), sampled along it so that the triangles next to it fan into the point.
    // With its two ends alone, the one triangle across the whole line would have two corners
    // at the same vertex and be dropped, leaving a hole round the pole.
    for (k, sequence) in sequences.iter_mut().enumerate() {
        if sequence.is_none() {
            let (start, end) = corners_done[k];
            let n = DEGENERATE_SAMPLES;
            *sequence = Some(
                (0..=n)
                    .map(|i| (if i < n { start } else { end }, i as f64 / n as f64))
                    .collect(),
            );
        }
    }
    // Each face: its loops as (vertex, (u, v)) polygons, then the triangulation and its inner
    // points on every core, merged in face order (the same mesh whatever the thread count, the
    // first face that fails named).
    let polygons: Vec<Vec<Vec<(usize, DVec2)>>> = (0..faces.len())
        .map(|f| face_polygons(f, &loops[f], &edges, &sequences, &index_of))
        .collect();
    let triangulated: Vec<Result<(FaceTriangulation, Vec<DVec3>), GeometryError>> =
        crate::par::map(faces.len().min(polygons.len()), |f| {
            let (face, polygons) = (&faces[f], &polygons[f]);
            let local = triangulate_face(face, polygons, tolerance)?;
            let points = local
                .interior
                .iter()
                .map(|(uv, _)| face.surface().point_at_clamped(*uv))
                .collect::<Result<Vec<_>, _>>()?;
            Ok((local, points))
        });
    let mut triangles: Vec<[u32; 3]> = Vec::new();
    let mut triangle_face: Vec<usize> = Vec::new();
    for (f, (result, polygons)) in triangulated.into_iter().zip(&polygons).enumerate() {
        let (local, points) = result?;
        let interior_base = vertices.len();
        for ((uv, _), position) in local.interior.iter().zip(points) {
            vertices.push(JoinedVertex {
                position,
                uses: vec![(f, *uv)],
            });
        }
        // Boundary vertices record this face's (u, v).
        for polygon in polygons {
            for &(v, uv) in polygon {
                if !vertices[v].uses.iter().any(|(g, _)| *g == f) {
                    vertices[v].uses.push((f, uv));
                }
            }
        }
        for t in local.triangles {
            let id = t.map(|x| match x {
                Local::Boundary(v) => v,
                Local::Interior(i) => interior_base + i,
            });
            if id[0] == id[1] || id[1] == id[2] || id[0] == id[2] {
                continue;
            }
            triangles.push(id.map(|x| x as u32));
            triangle_face.push(f);
        }
        if triangles.len() > MAX_TRIANGLES {
            return Err(failed(format!(
                "more than {MAX_TRIANGLES} triangles: choose a larger tolerance"
            )));
        }
    }
    // Orientation: flip faces so that shared edges run opposite ways where possible.
    let flip = orientation(faces.len(), topology);
    for (t, &f) in triangles.iter_mut().zip(&triangle_face) {
        if flip[f] {
            t.swap(1, 2);
        }
    }
    build_mesh(faces, &vertices, triangles, &flip, curvature)
}

/// A follower edge's vertex sequence: the owner's vertices `theirs` (in the owner's direction,
/// turned round when `reversed`), each at the parameter of `e` nearest it, searched near the
/// last one found (and over all of a closed edge, whose parameter wraps round).
fn follower_sequence(
    e: &Edge<'_>,
    theirs: &[(usize, f64)],
    reversed: bool,
    vertices: &[JoinedVertex],
) -> Vec<(usize, f64)> {
    let mut seq = Vec::with_capacity(theirs.len());
    let count = theirs.len();
    let mut hint: Option<f64> = None;
    let mut previous_own: Option<f64> = None;
    let ordered: Vec<(usize, f64)> = if reversed {
        theirs.iter().rev().copied().collect()
    } else {
        theirs.to_vec()
    };
    for (i, (v, own_t)) in ordered.into_iter().enumerate() {
        // The search window around the last point: at least 4 samples, and three times the
        // owner's step (its points may be far apart along a straight edge).
        let step = previous_own.map_or(0.0, |p| (own_t - p).abs());
        previous_own = Some(own_t);
        let t = if !e.closed_uv && i == 0 {
            0.0
        } else if !e.closed_uv && i + 1 == count {
            1.0
        } else {
            // A closed curve's parameter wraps round at its own seam: search it all.
            let window = hint
                .filter(|_| !e.closed_uv)
                .map(|h| (h, (4.0 / SEARCH_SAMPLES as f64).max(3.0 * step)));
            let (t, _) = e.closest(vertices[v].position, window);
            t
        };
        hint = Some(t);
        seq.push((v, t));
    }
    seq
}

/// Face `f`'s loops as (vertex, (u, v)) polygons: each curve's vertex sequence on the shared
/// edges, all but its last point (the next curve's first), a loop of one closed curve once
/// round; loops of fewer than three points left out.
fn face_polygons(
    f: usize,
    loops: &[TrimLoop],
    edges: &[Edge<'_>],
    sequences: &[Option<Vec<(usize, f64)>>],
    index_of: &dyn Fn(EdgeId) -> Option<usize>,
) -> Vec<Vec<(usize, DVec2)>> {
    let mut polygons: Vec<Vec<(usize, DVec2)>> = Vec::new();
    for (l, lp) in loops.iter().enumerate() {
        let mut polygon: Vec<(usize, DVec2)> = Vec::new();
        for c in 0..lp.len() {
            let id = EdgeId {
                face: f,
                loop_index: l,
                curve: c,
            };
            let Some(k) = index_of(id) else { continue };
            let Some(seq) = &sequences[k] else { continue };
            let e = &edges[k];
            let closed_alone = e.closed_uv && lp.len() == 1;
            let take = if closed_alone {
                // A loop of one closed curve: its points once round.
                let mut s = seq.clone();
                if s.len() > 1 && s[0].0 == s[s.len() - 1].0 {
                    s.pop();
                }
                s
            } else {
                seq[..seq.len() - 1].to_vec()
            };
            for (v, t) in take {
                polygon.push((v, e.uv(t)));
            }
        }
        if polygon.len() >= 3 {
            polygons.push(polygon);
        }
    }
    polygons
}

/// Which faces to turn over so that faces sharing an edge agree (breadth-first from each
/// group's first face; a group that cannot agree keeps what the search gave it).
pub fn orientation(faces: usize, topology: &Topology) -> Vec<bool> {
    let mut flip: Vec<Option<bool>> = vec![None; faces];
    for start in 0..faces {
        if flip[start].is_some() {
            continue;
        }
        flip[start] = Some(false);
        let mut queue = vec![start];
        while let Some(f) = queue.pop() {
            let here = flip[f].unwrap_or(false);
            for s in &topology.shared {
                let other = if s.a.face == f {
                    s.b.face
                } else if s.b.face == f {
                    s.a.face
                } else {
                    continue;
                };
                if flip[other].is_none() {
                    // Consistent faces traverse a shared edge in opposite directions.
                    flip[other] = Some(here == s.reversed);
                    queue.push(other);
                }
            }
        }
    }
    flip.into_iter().map(|f| f.unwrap_or(false)).collect()
}

/// How a body's closed shells nest, from each shell's bounding box (`boxes`, corners) and the
/// volume it encloses (`volumes`, either sign): for each shell, the innermost shell around it
/// (whose box holds its box strictly and which encloses more), or `None` for an outermost one;
/// and whether it is a void (inside an odd number of shells: a cavity, whereas a shell inside a
/// cavity is a solid again). Shells of one valid body do not cross, so boxes decide.
pub fn shell_nesting(boxes: &[(DVec3, DVec3)], volumes: &[f64]) -> Vec<(Option<usize>, bool)> {
    let around = |i: usize, j: usize| {
        j != i
            && boxes[j].0.cmplt(boxes[i].0).all()
            && boxes[j].1.cmpgt(boxes[i].1).all()
            && volumes[j].abs() > volumes[i].abs()
    };
    (0..boxes.len())
        .map(|i| {
            let outside: Vec<usize> = (0..boxes.len()).filter(|&j| around(i, j)).collect();
            let innermost = outside
                .iter()
                .copied()
                .min_by(|&a, &b| volumes[a].abs().total_cmp(&volumes[b].abs()));
            (innermost, !outside.len().is_multiple_of(2))
        })
        .collect()
}

/// What keeps a set of faces from bounding a solid, edge by edge: naked edges (one face
/// only), edges that more than two faces share (non-manifold), and shared edges whose two faces
/// cannot be turned to agree once every other edge is satisfied (a one-sided surface, or faces
/// stitched with a twist), each pair as found.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Validity {
    pub naked: Vec<EdgeId>,
    pub non_manifold: Vec<EdgeId>,
    pub misoriented: Vec<(EdgeId, EdgeId)>,
    /// The faces turned over to agree across shared edges ([`orientation`]).
    pub flipped: Vec<bool>,
}

impl Validity {
    /// Whether the faces close a consistently oriented, manifold shell.
    pub fn is_closed_shell(&self) -> bool {
        self.naked.is_empty() && self.non_manifold.is_empty() && self.misoriented.is_empty()
    }
}

/// The validity of `faces` faces joined as `topology` says ([`Validity`]): the orientation is
/// [`orientation`]'s, and an edge it leaves disagreeing is misoriented.
pub fn validity(faces: usize, topology: &Topology) -> Validity {
    let flip = orientation(faces, topology);
    let mut uses: std::collections::BTreeMap<EdgeId, usize> = Default::default();
    for s in &topology.shared {
        *uses.entry(s.a).or_default() += 1;
        *uses.entry(s.b).or_default() += 1;
    }
    let flipped = |f: usize| flip.get(f).copied().unwrap_or(false);
    Validity {
        naked: topology.naked.clone(),
        non_manifold: uses
            .into_iter()
            .filter(|&(_, n)| n > 1)
            .map(|(e, _)| e)
            .collect(),
        // Consistent faces traverse a shared edge in opposite directions (as `orientation`
        // turns them).
        misoriented: topology
            .shared
            .iter()
            .filter(|s| flipped(s.b.face) != (flipped(s.a.face) == s.reversed))
            .map(|s| (s.a, s.b))
            .collect(),
        flipped: flip,
    }
}

/// A vertex of one face's triangulation.
#[derive(Debug, Clone, Copy)]
enum Local {
    Boundary(usize),
    Interior(usize),
}

/// Points along a degenerate edge's line in (u, v) (all of them one vertex).
const DEGENERATE_SAMPLES: usize = 64;

/// How many times a face's triangles farther than the tolerance from it are split.
const REFINE_ROUNDS: usize = 6;

struct FaceTriangulation {
    interior: Vec<(DVec2, ())>,
    triangles: Vec<[Local; 3]>,
}

/// The constrained Delaunay triangulation of one face: its boundary polygons (vertex, (u, v))
/// as constraints and the inner points of its tolerance grid that keep clear of them.
/// A number in [0, 1) different for every row `j` (the fractional part of j times the golden
/// ratio), so that no two rows of a grid are shifted alike.
fn row_shift(j: usize) -> f64 {
    (j as f64 * 0.618_033_988_749_894_9).fract()
}

fn triangulate_face(
    face: &TrimmedSurface,
    polygons: &[Vec<(usize, DVec2)>],
    tolerance: f64,
) -> Result<FaceTriangulation, GeometryError> {
    let surface = face.surface();
    // The refinement's check evaluates points scattered over the face: from its Bézier patches.
    let scattered = surface.scattered_evaluator();
    let mut grid = tess::grid_for(surface, Tessellation::Tolerance(tolerance))?;
    // The metric: mean |S_u| and |S_v| at the grid's points. The triangulation is Delaunay in
    // (u |S_u|, v |S_v|), close to the surface's own lengths, and the grid's cells are split
    // until none is more than twice as long one way as the other there (a grid that may be
    // coarse along a straight direction must not leave long fans across a curved one).
    let scale = metric(surface, &grid);
    refine_aspect(&mut grid, scale);
    let flat: Vec<Vec<DVec2>> = polygons
        .iter()
        .map(|p| p.iter().map(|(_, uv)| *uv).collect())
        .collect();
    let crossings = Crossings::new(&flat);
    let inside = |p: DVec2| crossings.inside(p);
    // Keep grid points a third of a cell from the boundary (no slivers, no point on a chord).
    let cell = |values: &[f64], k: usize| {
        let a = if k > 0 {
            values[k] - values[k - 1]
        } else {
            f64::INFINITY
        };
        let b = if k + 1 < values.len() {
            values[k + 1] - values[k]
        } else {
            f64::INFINITY
        };
        a.min(b)
    };
    let segments: Vec<(DVec2, DVec2)> = flat
        .iter()
        .flat_map(|p| (0..p.len()).map(move |i| (p[i], p[(i + 1) % p.len()])))
        .collect();
    // Only the segments reaching within a third of a cell of a grid row can be too near its
    // points: those, row by row.
    let reach = 0.34;
    let near_row: Vec<Vec<(DVec2, DVec2)>> = (0..grid.vs.len())
        .map(|j| {
            let (v, cv) = (grid.vs[j], reach * cell(&grid.vs, j));
            segments
                .iter()
                .filter(|(a, b)| a.y.min(b.y) <= v + cv && a.y.max(b.y) >= v - cv)
                .copied()
                .collect()
        })
        .collect();
    let mut interior = Vec::new();
    for (i, &u) in grid.us.iter().enumerate() {
        for (j, &v) in grid.vs.iter().enumerate() {
            let p = DVec2::new(u, v);
            if !inside(p) {
                continue;
            }
            let (cu, cv) = (cell(&grid.us, i), cell(&grid.vs, j));
            let clear = near_row[j].iter().all(|&(a, b)| {
                if a.x.min(b.x) > u + reach * cu || a.x.max(b.x) < u - reach * cu {
                    return true;
                }
                let d = b - a;
                let t =
                    ((p - a).dot(d) / d.length_squared().max(f64::MIN_POSITIVE)).clamp(0.0, 1.0);
                let q = a + d * t - p;
                (q.x / cu).powi(2) + (q.y / cv).powi(2) > reach * reach
            });
            if clear {
                // Moved along u by a millionth of the cell, by a different amount in every
                // row: a grid's cells are rectangles, whose corners lie on one circle, which
                // sends each Delaunay in-circle test to exact arithmetic; sheared into
                // parallelograms they are decided in floating point.
                let shift = 1e-6 * cu * row_shift(j);
                interior.push((DVec2::new(u + shift, v), ()));
            }
        }
    }
    let mut points: Vec<Point2<f64>> = Vec::new();
    let mut labels: Vec<Local> = Vec::new();
    let mut edges: Vec<[usize; 2]> = Vec::new();
    // Coordinates within 2^-142 of zero (rounding off a zero parameter) are zero: the
    // triangulation refuses smaller ones (TooSmall).
    let scaled = |p: DVec2| spade::mitigate_underflow(Point2::new(p.x * scale.x, p.y * scale.y));
    for polygon in polygons {
        let first = points.len();
        for (k, &(v, uv)) in polygon.iter().enumerate() {
            points.push(scaled(uv));
            labels.push(Local::Boundary(v));
            let next = if k + 1 == polygon.len() {
                first
            } else {
                points.len()
            };
            edges.push([points.len() - 1, next]);
        }
    }
    for (k, (p, _)) in interior.iter().enumerate() {
        points.push(scaled(*p));
        labels.push(Local::Interior(k));
    }
    let count = points.len();
    let mut crossed = false;
    let mut cdt = ConstrainedDelaunayTriangulation::<Point2<f64>>::try_bulk_load_cdt(
        points.clone(),
        edges,
        |_| crossed = true,
    )
    .map_err(|e| failed(format!("the triangulation failed: {e:?}")))?;
    if crossed || cdt.num_vertices() != count {
        return Err(failed(
            "a face's boundary points come closer than the tolerance (or cross): choose a \
             smaller tolerance"
                .into(),
        ));
    }
    // Every triangle within the tolerance, not only its vertices: a triangle whose centroid or
    // edge midpoint (in (u, v)) is farther than the tolerance from the flat triangle's point
    // there gets a vertex at its centroid, a few rounds at most. The tolerance grid bounds the
    // cells, but a triangle joining a boundary to a grid point a third of a cell inside can
    // be wider than a cell.
    // A flat face needs no check: its triangles and the face lie in one slab a quarter of the
    // tolerance thick on either side of its plane. A triangle that passed keeps passing: later
    // rounds check only the triangles that are new (by their three corners).
    let unscaled = |p: Point2<f64>| DVec2::new(p.x / scale.x, p.y / scale.y);
    let mut corner_points: Vec<Option<DVec3>> = vec![None; points.len()];
    let rounds = if surface.plane(0.25 * tolerance).is_some() {
        0
    } else {
        REFINE_ROUNDS
    };
    let mut passed: rustc_hash::FxHashSet<[usize; 3]> = Default::default();
    let mut edge_fails: rustc_hash::FxHashMap<[usize; 2], bool> = Default::default();
    for _ in 0..rounds {
        let kept = kept_faces(&cdt);
        let mut centroids = Vec::new();
        for f in cdt.inner_faces() {
            let ids = f.vertices().map(|v| v.fix().index());
            let uv = f.vertices().map(|v| unscaled(v.position()));
            let centroid = (uv[0] + uv[1] + uv[2]) / 3.0;
            if (uv[1] - uv[0]).perp_dot(uv[2] - uv[0]) == 0.0 || !kept[f.fix().index()] {
                continue;
            }
            let mut key = ids;
            key.sort_unstable();
            if passed.contains(&key) {
                continue;
            }
            let mut corners = [DVec3::ZERO; 3];
            for k in 0..3 {
                if corner_points.len() <= ids[k] {
                    corner_points.resize(ids[k] + 1, None);
                }
                corners[k] = match corner_points[ids[k]] {
                    Some(p) => p,
                    None => {
                        let p = scattered.point(uv[k])?;
                        corner_points[ids[k]] = Some(p);
                        p
                    }
                };
            }
            let flat = (corners[0] + corners[1] + corners[2]) / 3.0;
            let mut fails = scattered.point(centroid)?.distance(flat) > tolerance;
            for (a, b) in [(0, 1), (1, 2), (2, 0)] {
                if fails {
                    break;
                }
                // An edge's midpoint depends on the edge alone: both its triangles, and every
                // round, share one answer.
                let edge = [ids[a].min(ids[b]), ids[a].max(ids[b])];
                fails = match edge_fails.get(&edge) {
                    Some(&known) => known,
                    None => {
                        let at = 0.5 * (uv[a] + uv[b]);
                        let flat = 0.5 * (corners[a] + corners[b]);
                        let known = scattered.point(at)?.distance(flat) > tolerance;
                        edge_fails.insert(edge, known);
                        known
                    }
                };
            }
            if fails {
                centroids.push(centroid);
            } else {
                passed.insert(key);
            }
        }
        if centroids.is_empty() {
            break;
        }
        for c in centroids {
            let handle = cdt
                .insert(scaled(c))
                .map_err(|e| failed(format!("the triangulation failed: {e:?}")))?;
            if handle.index() == labels.len() {
                points.push(scaled(c));
                labels.push(Local::Interior(interior.len()));
                interior.push((c, ()));
            }
        }
        if labels.len() > MAX_TRIANGLES {
            return Err(failed(format!(
                "more than {MAX_TRIANGLES} triangles: choose a larger tolerance"
            )));
        }
    }
    let mut triangles = Vec::new();
    let kept = kept_faces(&cdt);
    for f in cdt.inner_faces() {
        let ids = f.vertices().map(|v| v.fix().index());
        let [a, b, c] = ids.map(|k| DVec2::new(points[k].x / scale.x, points[k].y / scale.y));
        let twice = (b - a).perp_dot(c - a);
        if twice == 0.0 || !kept[f.fix().index()] {
            continue;
        }
        let t = ids.map(|k| labels[k]);
        triangles.push(if twice > 0.0 { t } else { [t[0], t[2], t[1]] });
    }
    Ok(FaceTriangulation {
        interior,
        triangles,
    })
}

/// Which faces of the triangulation (by index) lie inside the loops: those reached from
/// outside the hull across an odd number of constraint edges (the even-odd rule, decided by
/// the triangulation's own edges, so a sliver between three nearly collinear boundary points
/// is classified by which side of the boundary it is on, not by a point test at its centroid
/// within rounding of the boundary). A breadth-first search that crosses constraints last
/// finds the fewest crossings.
fn kept_faces(cdt: &ConstrainedDelaunayTriangulation<Point2<f64>>) -> Vec<bool> {
    let mut crossings: Vec<Option<u32>> = vec![None; cdt.num_all_faces()];
    type Fixed = spade::handles::FixedFaceHandle<spade::handles::InnerTag>;
    let mut queue: std::collections::VecDeque<(Fixed, u32)> = std::collections::VecDeque::new();
    for f in cdt.inner_faces() {
        for e in f.adjacent_edges() {
            if e.rev().face().is_outer() {
                if e.is_constraint_edge() {
                    queue.push_back((f.fix(), 1));
                } else {
                    queue.push_front((f.fix(), 0));
                }
            }
        }
    }
    while let Some((handle, level)) = queue.pop_front() {
        if crossings[handle.index()].is_some_and(|c| c <= level) {
            continue;
        }
        crossings[handle.index()] = Some(level);
        for e in cdt.face(handle).adjacent_edges() {
            let Some(next) = e.rev().face().as_inner() else {
                continue;
            };
            let j = next.fix().index();
            if e.is_constraint_edge() {
                if crossings[j].is_none_or(|c| c > level + 1) {
                    queue.push_back((next.fix(), level + 1));
                }
            } else if crossings[j].is_none_or(|c| c > level) {
                queue.push_front((next.fix(), level));
            }
        }
    }
    crossings
        .into_iter()
        .map(|c| c.is_some_and(|c| c % 2 == 1))
        .collect()
}

/// The loops' segments in horizontal bands, for the even-odd test of many points: a point
/// lies inside an odd number of loops exactly when a ray from it toward +x crosses an odd
/// number of segments, and only the segments of its band can cross it.
struct Crossings {
    lo: f64,
    height: f64,
    bands: Vec<Vec<(DVec2, DVec2)>>,
}

impl Crossings {
    fn new(polygons: &[Vec<DVec2>]) -> Self {
        let segments: Vec<(DVec2, DVec2)> = polygons
            .iter()
            .flat_map(|p| (0..p.len()).map(move |i| (p[i], p[(i + 1) % p.len()])))
            .collect();
        let (lo, hi) = segments
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), (a, b)| {
                (l.min(a.y).min(b.y), h.max(a.y).max(b.y))
            });
        let count = ((segments.len() as f64).sqrt().ceil() as usize).clamp(1, 4096);
        let height = if hi > lo {
            (hi - lo) / count as f64
        } else {
            1.0
        };
        let mut bands = vec![Vec::new(); count];
        let band = |y: f64| (((y - lo) / height).floor().max(0.0) as usize).min(count - 1);
        for &(a, b) in &segments {
            for list in &mut bands[band(a.y.min(b.y))..=band(a.y.max(b.y))] {
                list.push((a, b));
            }
        }
        Self { lo, height, bands }
    }

    fn inside(&self, p: DVec2) -> bool {
        if self.bands.is_empty() || !(p.y >= self.lo) {
            return false;
        }
        let k = ((p.y - self.lo) / self.height).floor() as usize;
        let Some(band) = self.bands.get(k) else {
            return false;
        };
        let mut inside = false;
        for &(a, b) in band {
            if (a.y <= p.y) != (b.y <= p.y) {
                let x = a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x);
                if x > p.x {
                    inside = !inside;
                }
            }
        }
        inside
    }
}

/// The mean lengths of S_u and S_v over the grid's points (each at least a millionth of the
/// larger, and 1 where the surface has no extent).
fn metric(surface: &crate::NurbsSurface, grid: &tess::ParameterGrid) -> DVec2 {
    let step = |n: usize| (n / 16).max(1);
    let (mut su, mut sv, mut count) = (0.0, 0.0, 0.0);
    for &u in grid.us.iter().step_by(step(grid.us.len())) {
        for &v in grid.vs.iter().step_by(step(grid.vs.len())) {
            if let Ok(d) = surface.evaluate(u, v) {
                su += d.su.length();
                sv += d.sv.length();
                count += 1.0;
            }
        }
    }
    let m = DVec2::new(su, sv) / f64::max(count, 1.0);
    let top = m.x.max(m.y);
    if !(top > 0.0 && top.is_finite()) {
        return DVec2::ONE;
    }
    m.max(DVec2::splat(1e-6 * top))
}

/// Splits the grid's cells evenly so that, in the metric `scale`, no cell is more than twice
/// as long one way as the finest cell's size the other way (at most 4096 lines a direction).
fn refine_aspect(grid: &mut tess::ParameterGrid, scale: DVec2) {
    let widest = |values: &[f64], s: f64| {
        values
            .windows(2)
            .map(|w| (w[1] - w[0]) * s)
            .fold(0.0, f64::max)
    };
    let (hu, hv) = (widest(&grid.us, scale.x), widest(&grid.vs, scale.y));
    let split = |values: &mut Vec<f64>, s: f64, target: f64| {
        if !(target > 0.0) {
            return;
        }
        let mut out = Vec::with_capacity(values.len());
        for w in values.windows(2) {
            let pieces = (((w[1] - w[0]) * s / target).ceil() as usize).clamp(1, 4096);
            for k in 0..pieces {
                out.push(w[0] + (w[1] - w[0]) * k as f64 / pieces as f64);
            }
        }
        out.extend(values.last().copied());
        if out.len() <= 4096 {
            *values = out;
        }
    };
    if hv > 2.0 * hu {
        split(&mut grid.vs, scale.y, 2.0 * hu);
    } else if hu > 2.0 * hv {
        split(&mut grid.us, scale.x, 2.0 * hv);
    }
}

/// Positions, normals (the mean of the faces' at a shared vertex, turned with the face),
/// (u, v) of the first face using each vertex, and curvatures.
fn build_mesh(
    faces: &[TrimmedSurface],
    vertices: &[JoinedVertex],
    triangles: Vec<[u32; 3]>,
    flip: &[bool],
    curvature: bool,
) -> Result<TriangleMesh, GeometryError> {
    let mut used = vec![u32::MAX; vertices.len()];
    let mut order = Vec::new();
    for t in &triangles {
        for &k in t {
            if used[k as usize] == u32::MAX {
                used[k as usize] = order.len() as u32;
                order.push(k as usize);
            }
        }
    }
    let mut mesh = TriangleMesh {
        positions: Vec::with_capacity(order.len()),
        normals: Vec::with_capacity(order.len()),
        uvs: Vec::with_capacity(order.len()),
        curvatures: Vec::new(),
        triangles: triangles
            .into_iter()
            .map(|t| t.map(|k| used[k as usize]))
            .collect(),
    };
    // Each vertex's normal, (u, v) and curvature on every core, pushed in order.
    type VertexData = (DVec3, [f64; 2], Option<CurvatureValues>);
    let data: Vec<Result<VertexData, GeometryError>> = crate::par::map(order.len(), |i| {
        let v = &vertices[order[i]];
        let mut normal = DVec3::ZERO;
        for &(f, uv) in &v.uses {
            // A boundary vertex may lie a rounding step outside its face's domain (the
            // loop computed from the file's edges): its normal is the one at the nearest
            // point.
            let surface = faces[f].surface();
            let [(u0, u1), (v0, v1)] = surface.domain();
            let n = surface.normal(uv.x.clamp(u0, u1), uv.y.clamp(v0, v1))?;
            normal += if flip[f] { -n } else { n };
        }
        let (f, uv) = v.uses.first().copied().unwrap_or((0, DVec2::ZERO));
        let [u0, u1, v0, v1] = faces
            .get(f)
            .map_or([0.0, 1.0, 0.0, 1.0], |face| domain_rect(face.surface()));
        let unit_uv = [
            (uv.x - u0) / (u1 - u0).max(f64::MIN_POSITIVE),
            (uv.y - v0) / (v1 - v0).max(f64::MIN_POSITIVE),
        ];
        let curvature = curvature.then(|| {
            let values = faces
                .get(f)
                .and_then(|face| face.surface().local_geometry(uv.x, uv.y).ok())
                .map(|g| g.curvature.values())
                .unwrap_or(CurvatureValues::default());
            let sign = if flip.get(f).copied().unwrap_or(false) {
                -1.0
            } else {
                1.0
            };
            CurvatureValues {
                gaussian: values.gaussian,
                mean: sign * values.mean,
                k1: if sign > 0.0 { values.k1 } else { -values.k2 },
                k2: if sign > 0.0 { values.k2 } else { -values.k1 },
            }
        });
        Ok((normal.normalize_or(DVec3::Z), unit_uv, curvature))
    });
    for (&k, result) in order.iter().zip(data) {
        let (normal, uv, curvature) = result?;
        mesh.positions.push(vertices[k].position);
        mesh.normals.push(normal);
        mesh.uvs.push(uv);
        mesh.curvatures.extend(curvature);
    }
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::construct;
    use std::collections::HashMap;

    /// A whole sphere and a whole torus, one untrimmed face each (its seam and, for the
    /// sphere, its poles inside the one face): the joined mesh is closed, with the closed
    /// forms' area and volume.
    #[test]
    fn a_whole_sphere_and_a_whole_torus_mesh_closed_with_their_area_and_volume() {
        use std::f64::consts::PI;
        let r = 0.93;
        let sphere = construct::sphere(DVec3::new(1.0, -2.0, 0.5), r).unwrap();
        let torus = construct::torus(
            DVec3::new(3.0, 1.0, -1.0),
            DVec3::new(0.2, 0.5, 1.0),
            2.0,
            0.5,
        )
        .unwrap();
        for (surface, area, volume) in [
            (sphere, 4.0 * PI * r * r, 4.0 / 3.0 * PI * r * r * r),
            (torus, 4.0 * PI * PI * 2.0 * 0.5, 2.0 * PI * PI * 2.0 * 0.25),
        ] {
            let faces = vec![TrimmedSurface::untrimmed(surface)];
            let topology = find_topology(&faces, 1e-6).unwrap();
            let mesh = tessellate_joined(&faces, &topology, 1e-4, false).unwrap();
            let v = mesh.signed_volume();
            let a = mesh.area();
            assert!((a - area).abs() < 1e-3 * area, "area {a}, exact {area}");
            assert!(
                (v.abs() - volume).abs() < 1e-3 * volume,
                "volume {v}, exact {volume}"
            );
        }
    }

    /// The six faces of the box [0, a] × [0, b] × [0, c], as planes with mixed orientations.
    pub(crate) fn box_faces(a: f64, b: f64, c: f64) -> Vec<TrimmedSurface> {
        let plane = |o: DVec3, u: DVec3, v: DVec3| {
            TrimmedSurface::untrimmed(construct::plane(o, u, v).unwrap())
        };
        let (x, y, z) = (DVec3::X * a, DVec3::Y * b, DVec3::Z * c);
        vec![
            plane(DVec3::ZERO, x, y),
            plane(z, x, y),
            plane(DVec3::ZERO, x, z),
            plane(y, z, x),
            plane(DVec3::ZERO, z, y),
            plane(x, y, z),
        ]
    }

    /// Every undirected edge's count of triangles, after welding equal positions.
    fn edge_uses(mesh: &TriangleMesh) -> HashMap<(u32, u32), usize> {
        let mut weld: HashMap<[u64; 3], u32> = HashMap::new();
        let ids: Vec<u32> = mesh
            .positions
            .iter()
            .map(|p| {
                let key = p.to_array().map(f64::to_bits);
                let n = weld.len() as u32;
                *weld.entry(key).or_insert(n)
            })
            .collect();
        let mut uses = HashMap::new();
        for t in &mesh.triangles {
            for k in 0..3 {
                let (a, b) = (ids[t[k] as usize], ids[t[(k + 1) % 3] as usize]);
                *uses.entry((a.min(b), a.max(b))).or_insert(0) += 1;
            }
        }
        uses
    }

    #[test]
    fn no_sliver_outside_a_side_of_many_nearly_collinear_points_is_kept() {
        // A triangle whose sides run along a slanted straight side of 400 points: the points
        // lie on the line only to rounding, so the triangulation has slivers on both sides of
        // it. Every boundary segment must belong to exactly one kept triangle (a sliver kept
        // outside would give it a second), and the kept triangles cover the triangle's area.
        let (a, b, c) = (
            DVec2::new(0.013, 0.071),
            DVec2::new(0.937, 0.383),
            DVec2::new(0.211, 0.947),
        );
        let n = 400;
        let mut polygon: Vec<(usize, DVec2)> = (0..n)
            .map(|k| a + (b - a) * (k as f64 / n as f64))
            .chain([b, c])
            .enumerate()
            .collect();
        polygon.push((polygon.len(), 0.5 * (c + a)));
        let surface = construct::plane(DVec3::ZERO, DVec3::X, DVec3::Y).unwrap();
        let face = TrimmedSurface::untrimmed(surface);
        let local = triangulate_face(&face, std::slice::from_ref(&polygon), 10.0).unwrap();
        let mut uses: HashMap<(usize, usize), usize> = HashMap::new();
        let mut area = 0.0;
        for t in &local.triangles {
            let ids = t.map(|l| match l {
                Local::Boundary(v) => v,
                Local::Interior(i) => 1_000_000 + i,
            });
            let uv = ids.map(|v| {
                if v >= 1_000_000 {
                    local.interior[v - 1_000_000].0
                } else {
                    polygon[v].1
                }
            });
            area += 0.5 * (uv[1] - uv[0]).perp_dot(uv[2] - uv[0]).abs();
            for k in 0..3 {
                let (p, q) = (ids[k], ids[(k + 1) % 3]);
                *uses.entry((p.min(q), p.max(q))).or_insert(0) += 1;
            }
        }
        let m = polygon.len();
        for k in 0..m {
            let key = (k.min((k + 1) % m), k.max((k + 1) % m));
            assert_eq!(uses.get(&key), Some(&1), "boundary segment {key:?}");
        }
        let expected = 0.5 * (b - a).perp_dot(c - a).abs();
        assert!((area - expected).abs() < 1e-12, "{area} against {expected}");
    }

    #[test]
    fn a_box_of_six_planes_joins_into_one_closed_watertight_mesh() {
        let faces = box_faces(2.0, 1.0, 1.5);
        let topology = find_topology(&faces, 1e-9).unwrap();
        assert_eq!(topology.shared.len(), 12, "{topology:?}");
        assert!(topology.naked.is_empty());
        assert!(topology.is_closed());
        assert_eq!(topology.components(6), vec![vec![0, 1, 2, 3, 4, 5]]);
        let mesh = tessellate_joined(&faces, &topology, 1e-3, false).unwrap();
        let uses = edge_uses(&mesh);
        assert!(
            uses.values().all(|&n| n == 2),
            "{:?}",
            uses.values().filter(|&&n| n != 2).count()
        );
        // Consistently oriented: the signed volume is the box's (or its negative).
        let volume = mesh.signed_volume();
        assert!((volume.abs() - 3.0).abs() < 1e-9, "{volume}");
    }

    #[test]
    fn a_face_following_a_straight_shared_edge_takes_its_points_where_they_are() {
        // A square with a hole near its edge x = 0, joined to a wall along that edge: the wall's
        // edge is sampled in 8 chords, and the square must place each point at its own (u, v)
        // (a search window narrower than the chords once put them elsewhere, folding triangles
        // over the hole's side and adding area).
        let square = construct::plane(DVec3::ZERO, DVec3::Y * 4.0, DVec3::X * 4.0).unwrap();
        let hole = shapes::ellipse(DVec2::new(0.5, 0.15), DVec2::splat(0.1)).unwrap();
        let square = TrimmedSurface::new(
            square,
            vec![shapes::rectangle(DVec2::ZERO, DVec2::ONE).unwrap(), hole],
        )
        .unwrap();
        let wall = TrimmedSurface::untrimmed(
            construct::plane(DVec3::ZERO, DVec3::Z, DVec3::Y * 4.0).unwrap(),
        );
        let faces = vec![wall, square];
        let topology = find_topology(&faces, 1e-9).unwrap();
        assert_eq!(topology.shared.len(), 1, "{topology:?}");
        let joined = tessellate_joined(&faces, &topology, 1e-3, false)
            .unwrap()
            .area();
        let expected = 4.0 + 16.0 - std::f64::consts::PI * 0.4 * 0.4;
        assert!(
            (joined - expected).abs() < 2e-3 * expected,
            "{joined} vs {expected}"
        );
    }

    /// Brent's minimum of functions with known minima, within the tolerance asked, in far
    /// fewer evaluations than golden sections alone (about 1.44 per halving of the bracket);
    /// a minimum at an end of the bracket is approached.
    #[test]
    fn brent_finds_known_minima_in_few_steps() {
        // The function, its bracket and where its minimum lies.
        type Case<'a> = (&'a dyn Fn(f64) -> f64, f64, f64, f64);
        let cases: [Case; 4] = [
            (&|t: f64| (t - 0.3).powi(2) + 1.0, 0.0, 1.0, 0.3),
            (
                &|t: f64| (t - 2.1).powi(4) + (t - 2.1).powi(2),
                1.0,
                3.5,
                2.1,
            ),
            (&|t: f64| -(t.sin()), 0.0, 3.0, std::f64::consts::FRAC_PI_2),
            (&|t: f64| t * t, 0.5, 2.0, 0.5),
        ];
        for (f, a, b, expected) in cases {
            let calls = std::cell::Cell::new(0);
            let counted = |t: f64| {
                calls.set(calls.get() + 1);
                assert!((a..=b).contains(&t), "{t} outside [{a}, {b}]");
                f(t)
            };
            let (t, ft) = brent_minimum(counted, a, b, 1e-9);
            assert!((t - expected).abs() < 1e-6, "{t} vs {expected}");
            assert!((ft - f(t)).abs() == 0.0);
            assert!(calls.get() <= 45, "{} evaluations", calls.get());
        }
    }

    /// A trim corner a rounding step off u = 0 (1e-200, as a parameter computed near zero
    /// comes out): its area is the polygon's, where the triangulation once refused the
    /// coordinate (TooSmall, below 2^-142).
    #[test]
    fn a_trim_point_a_rounding_step_off_zero_is_meshed() {
        let plane = construct::plane(
            DVec3::new(2.0, -1.0, 0.5),
            DVec3::new(3.0, 1.0, 0.0),
            DVec3::new(0.0, -1.0, 2.0),
        )
        .unwrap();
        let corners = [
            DVec2::new(1e-200, 0.2),
            DVec2::new(0.8, -1e-180),
            DVec2::new(0.9, 0.9),
            DVec2::new(-1e-190, 0.7),
        ];
        let face =
            TrimmedSurface::new(plane.clone(), vec![shapes::polygon(&corners).unwrap()]).unwrap();
        let faces = vec![face];
        let topology = find_topology(&faces, 1e-9).unwrap();
        let area = tessellate_joined(&faces, &topology, 1e-3, false)
            .unwrap()
            .area();
        // The polygon's (u, v) area (shoelace) times |S_u × S_v|.
        let uv: f64 = (0..4)
            .map(|k| corners[k].perp_dot(corners[(k + 1) % 4]))
            .sum::<f64>()
            .abs()
            / 2.0;
        let jacobian = DVec3::new(3.0, 1.0, 0.0)
            .cross(DVec3::new(0.0, -1.0, 2.0))
            .length();
        assert!(
            (area - uv * jacobian).abs() < 1e-9 * area,
            "{area} vs {}",
            uv * jacobian
        );
    }

    #[test]
    fn faces_apart_stay_apart_and_their_edges_are_naked() {
        let mut faces = box_faces(1.0, 1.0, 1.0);
        faces.truncate(2);
        let topology = find_topology(&faces, 1e-9).unwrap();
        assert!(topology.shared.is_empty());
        assert_eq!(topology.naked.len(), 8);
        assert_eq!(topology.components(2), vec![vec![0], vec![1]]);
    }

    #[test]
    fn a_cylinder_with_two_caps_closes_across_its_seam_and_circles() {
        let cylinder = construct::cylinder(DVec3::ZERO, DVec3::Z * 2.0, 1.0).unwrap();
        let circle = |z: f64| construct::circle(DVec3::Z * z, DVec3::Z, DVec3::X, 1.0).unwrap();
        let cap = |z: f64| {
            let c = circle(z);
            crate::planar::planar_face(&[c]).unwrap()
        };
        let faces = vec![TrimmedSurface::untrimmed(cylinder), cap(0.0), cap(2.0)];
        let topology = find_topology(&faces, 1e-7).unwrap();
        // The seam, and the two circles.
        assert_eq!(topology.shared.len(), 3, "{topology:?}");
        assert!(topology.naked.is_empty(), "{topology:?}");
        let mesh = tessellate_joined(&faces, &topology, 1e-3, false).unwrap();
        let uses = edge_uses(&mesh);
        let bad = uses.values().filter(|&&n| n != 2).count();
        assert_eq!(bad, 0);
        let volume = mesh.signed_volume();
        // Every triangle keeps to the tolerance: its centroid off the side or a cap by at
        // most 1e-3 (a bound the tessellation's grid keeps for its cells).
        for t in &mesh.triangles {
            let [a, b, c] = t.map(|k| mesh.positions[k as usize]);
            let m = (a + b + c) / 3.0;
            let off_side = (m.x.hypot(m.y) - 1.0).abs();
            let off_cap = m.z.abs().min((m.z - 2.0).abs());
            assert!(off_side.min(off_cap) <= 1e-3, "{a} {b} {c}");
        }
        let exact = std::f64::consts::PI * 2.0;
        assert!((volume.abs() - exact).abs() < 1e-2 * exact, "{volume}");
    }

    /// The validity check finds each kind of fault by edge: a box of planes with mixed
    /// orientations is a closed shell; without its top it has four naked edges; three faces
    /// stitched in a ring with one twist cannot agree in orientation; an edge in two pairs is
    /// non-manifold.
    #[test]
    fn validity_reports_naked_non_manifold_and_misoriented_edges_by_place() {
        let faces = box_faces(2.0, 1.0, 1.5);
        let topology = find_topology(&faces, 1e-9).unwrap();
        let v = validity(faces.len(), &topology);
        assert!(v.is_closed_shell(), "{v:?}");
        let open: Vec<TrimmedSurface> = faces[..5].to_vec();
        let v = validity(open.len(), &find_topology(&open, 1e-9).unwrap());
        assert_eq!(v.naked.len(), 4, "{v:?}");
        assert!(v.misoriented.is_empty() && v.non_manifold.is_empty());
        let edge = |face: usize, curve: usize| EdgeId {
            face,
            loop_index: 0,
            curve,
        };
        let pair = |a: EdgeId, b: EdgeId, reversed: bool| SharedEdge {
            a,
            b,
            reversed,
            gap: 0.0,
        };
        let twisted = Topology {
            shared: vec![
                pair(edge(0, 0), edge(1, 0), true),
                pair(edge(1, 1), edge(2, 0), true),
                pair(edge(2, 1), edge(0, 1), false),
            ],
            naked: Vec::new(),
            degenerate: Vec::new(),
        };
        // Any two of the three pairs can be satisfied, never the third: one is reported.
        let v = validity(3, &twisted);
        assert_eq!(v.misoriented.len(), 1, "{v:?}");
        assert!(
            twisted
                .shared
                .iter()
                .any(|p| (p.a, p.b) == v.misoriented[0])
        );
        let shared_thrice = Topology {
            shared: vec![
                pair(edge(0, 0), edge(1, 0), true),
                pair(edge(0, 0), edge(2, 0), true),
            ],
            naked: Vec::new(),
            degenerate: Vec::new(),
        };
        assert_eq!(validity(3, &shared_thrice).non_manifold, vec![edge(0, 0)]);
    }
}
