//! The parts that a face's boundary and the cuts across it divide its (u, v) domain into: a
//! planar arrangement of polylines (de Berg et al., *Computational Geometry*, ch. 2, the
//! doubly connected edge list).
//!
//! 1. Every polyline's points become vertices; points closer than the snap distance are one
//!    vertex (the boundary's, which comes first, stands).
//! 2. A vertex within the snap distance of another polyline's segment splits that segment
//!    there, and segments that cross split each other at a new vertex.
//! 3. Segments joining the same two vertices are one (a boundary segment is kept over a cut
//!    lying on it), and segments with a free end are dropped until none is left.
//! 4. Around each vertex the segments are ordered by angle; walking each directed segment
//!    with the region on its left, turning at every vertex onto the next segment clockwise
//!    from the way back, traces every cycle. A counter-clockwise cycle bounds a region; a
//!    clockwise one is the outside of a connected group, a hole of the smallest region of
//!    another group that holds it.
//!
//! Each region's loops come back as runs: maximal pieces of one polyline between vertices
//! where polylines meet, end or turn from one to another, with the parameters along a
//! boundary curve carried through the splits.

use rustc_hash::{FxHashMap as HashMap, FxHashSet as HashSet};

use glam::DVec2;

/// Where a polyline comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Source {
    /// Curve `curve` of the face's boundary (the loops' curves numbered in order).
    Boundary(usize),
    /// Cut number `k`.
    Cut(usize),
}

/// A polyline to arrange: its points and, for a boundary curve, the curve's parameter at each.
#[derive(Debug, Clone)]
pub struct Polyline {
    pub source: Source,
    pub points: Vec<DVec2>,
    /// The curve parameter at each point (empty for a cut).
    pub params: Vec<f64>,
    /// A closed ring (its last point joins its first; the first is not repeated).
    pub closed: bool,
}

/// A piece of a region's loop along one polyline, in the loop's direction.
#[derive(Debug, Clone)]
pub struct Run {
    pub source: Source,
    pub points: Vec<DVec2>,
    /// The boundary curve's parameters at the points (empty for a cut).
    pub params: Vec<f64>,
    /// The run goes all the way round a ring without meeting anything (its last point is its
    /// first again).
    pub closed: bool,
}

/// One part of the domain: its outer loop (counter-clockwise) then its holes (clockwise),
/// and points well inside it, the one furthest from its boundary first ([`points_inside`]).
#[derive(Debug, Clone)]
pub struct Region {
    pub loops: Vec<Vec<Run>>,
    pub inside: Vec<DVec2>,
}

#[derive(Debug, Clone, Copy)]
struct Segment {
    a: usize,
    b: usize,
    source: Source,
    ta: f64,
    tb: f64,
}

struct UnionFind(Vec<usize>);

impl UnionFind {
    fn new(n: usize) -> Self {
        Self((0..n).collect())
    }

    fn root(&mut self, mut k: usize) -> usize {
        while self.0[k] != k {
            self.0[k] = self.0[self.0[k]];
            k = self.0[k];
        }
        k
    }

    /// Joins the groups of x and y; the lower index stands for both.
    fn join(&mut self, x: usize, y: usize) {
        let (x, y) = (self.root(x), self.root(y));
        if x != y {
            self.0[x.max(y)] = x.min(y);
        }
    }
}

/// Buckets of a uniform grid over boxes: each box is listed in every cell it overlaps.
struct Grid {
    lo: DVec2,
    cell: f64,
    cells: HashMap<(i64, i64), Vec<usize>>,
}

impl Grid {
    fn new(lo: DVec2, cell: f64) -> Self {
        Self {
            lo,
            cell,
            cells: HashMap::default(),
        }
    }

    fn range(&self, lo: DVec2, hi: DVec2) -> (i64, i64, i64, i64) {
        let f = |x: f64, o: f64| ((x - o) / self.cell).floor() as i64;
        (
            f(lo.x, self.lo.x),
            f(hi.x, self.lo.x),
            f(lo.y, self.lo.y),
            f(hi.y, self.lo.y),
        )
    }

    fn insert(&mut self, k: usize, lo: DVec2, hi: DVec2) {
        let (x0, x1, y0, y1) = self.range(lo, hi);
        for x in x0..=x1 {
            for y in y0..=y1 {
                self.cells.entry((x, y)).or_default().push(k);
            }
        }
    }
}

/// The regions `polylines` divide the plane into, snapping at `snap` (see the module
/// documentation). Every bounded region comes back; the caller keeps those its face keeps.
pub fn regions(polylines: &[Polyline], snap: f64) -> Vec<Region> {
    let mut points: Vec<DVec2> = Vec::new();
    let mut hard: Vec<bool> = Vec::new();
    let mut segments: Vec<Segment> = Vec::new();
    for line in polylines {
        let n = line.points.len();
        if n < 2 {
            continue;
        }
        let first = points.len();
        for (k, &p) in line.points.iter().enumerate() {
            points.push(p);
            hard.push(!line.closed && (k == 0 || k + 1 == n));
        }
        let param = |k: usize| line.params.get(k).copied().unwrap_or(0.0);
        for k in 0..n - 1 {
            segments.push(Segment {
                a: first + k,
                b: first + k + 1,
                source: line.source,
                ta: param(k),
                tb: param(k + 1),
            });
        }
        if line.closed {
            segments.push(Segment {
                a: first + n - 1,
                b: first,
                source: line.source,
                ta: param(n - 1),
                tb: param(0),
            });
        }
    }
    if segments.is_empty() {
        return Vec::new();
    }
    // 1. Points within the snap distance are one.
    let merged = merge_close(&points, &hard, snap);
    let mut remap = vec![0; points.len()];
    let mut kept_points = Vec::new();
    let mut kept_hard = Vec::new();
    let mut slot: HashMap<usize, usize> = HashMap::default();
    for k in 0..points.len() {
        let r = merged[k];
        let s = *slot.entry(r).or_insert_with(|| {
            kept_points.push(points[r]);
            kept_hard.push(false);
            kept_points.len() - 1
        });
        kept_hard[s] |= hard[k];
        remap[k] = s;
    }
    let mut points = kept_points;
    let mut hard = kept_hard;
    for s in &mut segments {
        s.a = remap[s.a];
        s.b = remap[s.b];
    }
    segments.retain(|s| s.a != s.b);
    // 2. Splits where a vertex touches a segment or two segments cross.
    let segments = split_segments(&mut points, &mut hard, segments, snap);
    // 3. One segment per pair of vertices, then no free ends.
    let mut by_pair: HashMap<(usize, usize), usize> = HashMap::default();
    let mut unique: Vec<Segment> = Vec::new();
    for s in segments {
        if s.a == s.b {
            continue;
        }
        let key = (s.a.min(s.b), s.a.max(s.b));
        match by_pair.get(&key) {
            Some(&k) => {
                if matches!(s.source, Source::Boundary(_))
                    && matches!(unique[k].source, Source::Cut(_))
                {
                    unique[k] = s;
                }
                // Where two polylines lie along each other, both their ends are corners.
                hard[s.a] = true;
                hard[s.b] = true;
            }
            None => {
                by_pair.insert(key, unique.len());
                unique.push(s);
            }
        }
    }
    let segments = without_free_ends(points.len(), unique);
    trace(&points, &hard, &segments)
}

/// For each point, the lowest index of the points within `snap` of it (transitively), and of
/// the `end` points (an open polyline's first or last) within [`END_SNAP`] times `snap` of
/// another end: two cuts meeting at a point where three faces meet come from two different
/// intersections, each ending where it leaves a face, and their ends may lie a tolerance or
/// so apart.
fn merge_close(points: &[DVec2], end: &[bool], snap: f64) -> Vec<usize> {
    let mut groups = UnionFind::new(points.len());
    let cell = (snap * END_SNAP).max(1e-300) * 2.0;
    let key = |p: DVec2| ((p.x / cell).floor() as i64, (p.y / cell).floor() as i64);
    let mut grid: HashMap<(i64, i64), Vec<usize>> = HashMap::default();
    for (k, &p) in points.iter().enumerate() {
        let (x, y) = key(p);
        for dx in -1..=1 {
            for dy in -1..=1 {
                if let Some(list) = grid.get(&(x + dx, y + dy)) {
                    for &j in list {
                        let reach = if end[j] && end[k] {
                            snap * END_SNAP
                        } else {
                            snap
                        };
                        if points[j].distance(p) <= reach {
                            groups.join(j, k);
                        }
                    }
                }
            }
        }
        grid.entry((x, y)).or_default().push(k);
    }
    (0..points.len()).map(|k| groups.root(k)).collect()
}

/// How many times the snap distance two polylines' ends may lie apart and still be one
/// point ([`merge_close`]).
const END_SNAP: f64 = 4.0;

/// The segments split where a vertex lies within `snap` of a segment's inside, and where two
/// cross (a new vertex, a corner).
fn split_segments(
    points: &mut Vec<DVec2>,
    hard: &mut Vec<bool>,
    segments: Vec<Segment>,
    snap: f64,
) -> Vec<Segment> {
    let (mut lo, mut hi) = (DVec2::INFINITY, DVec2::NEG_INFINITY);
    let mut total = 0.0;
    for s in &segments {
        let (a, b) = (points[s.a], points[s.b]);
        lo = lo.min(a.min(b));
        hi = hi.max(a.max(b));
        total += a.distance(b);
    }
    let mean = total / segments.len() as f64;
    let extent = (hi - lo).max_element().max(snap);
    let cell = (mean * 4.0).max(extent / 512.0).max(snap * 4.0).max(1e-300);
    let mut grid = Grid::new(lo, cell);
    for (k, s) in segments.iter().enumerate() {
        let (a, b) = (points[s.a], points[s.b]);
        grid.insert(k, a.min(b) - snap, a.max(b) + snap);
    }
    // Splits per segment: (fraction along it, vertex).
    let mut splits: Vec<Vec<(f64, usize)>> = vec![Vec::new(); segments.len()];
    let mut seen: HashSet<(usize, usize)> = HashSet::default();
    let mut crossings: Vec<(usize, usize, f64, f64)> = Vec::new();
    for list in grid.cells.values() {
        for (x, &i) in list.iter().enumerate() {
            for &j in &list[x + 1..] {
                let key = (i.min(j), i.max(j));
                if !seen.insert(key) {
                    continue;
                }
                let (s, t) = (segments[key.0], segments[key.1]);
                // A vertex of one on the inside of the other.
                for (own, other, ko) in [(s, t, key.1), (t, s, key.0)] {
                    for v in [own.a, own.b] {
                        if v == other.a || v == other.b {
                            continue;
                        }
                        if let Some(f) = touch(points[other.a], points[other.b], points[v], snap) {
                            splits[ko].push((f, v));
                        }
                    }
                }
                if [s.a, s.b].iter().any(|v| *v == t.a || *v == t.b) {
                    continue;
                }
                if let Some((f, g)) =
                    cross(points[s.a], points[s.b], points[t.a], points[t.b], snap)
                {
                    crossings.push((key.0, key.1, f, g));
                }
            }
        }
    }
    for (i, j, f, g) in crossings {
        // A crossing already split by a touching vertex is not split again.
        let near = |list: &[(f64, usize)], p: DVec2, pts: &[DVec2]| {
            list.iter().any(|&(_, v)| pts[v].distance(p) <= snap)
        };
        let p = points[segments[i].a].lerp(points[segments[i].b], f);
        if near(&splits[i], p, points) || near(&splits[j], p, points) {
            continue;
        }
        points.push(p);
        hard.push(true);
        let v = points.len() - 1;
        splits[i].push((f, v));
        splits[j].push((g, v));
    }
    let mut out = Vec::with_capacity(segments.len());
    for (k, s) in segments.into_iter().enumerate() {
        let list = &mut splits[k];
        if list.is_empty() {
            out.push(s);
            continue;
        }
        list.sort_by(|x, y| x.0.total_cmp(&y.0));
        let (mut at, mut t_at) = (s.a, s.ta);
        for &(f, v) in list.iter() {
            let t = s.ta + (s.tb - s.ta) * f;
            hard[v] = true;
            out.push(Segment {
                a: at,
                b: v,
                source: s.source,
                ta: t_at,
                tb: t,
            });
            at = v;
            t_at = t;
        }
        out.push(Segment {
            a: at,
            b: s.b,
            source: s.source,
            ta: t_at,
            tb: s.tb,
        });
    }
    out
}

/// The fraction along a–b of the point nearest `p`, where `p` lies within `snap` of the
/// segment's inside (not of its ends).
fn touch(a: DVec2, b: DVec2, p: DVec2, snap: f64) -> Option<f64> {
    let ab = b - a;
    let length2 = ab.length_squared();
    if length2 <= 0.0 {
        return None;
    }
    let f = (p - a).dot(ab) / length2;
    let q = a + ab * f;
    (q.distance(p) <= snap && q.distance(a) > snap && q.distance(b) > snap && f > 0.0 && f < 1.0)
        .then_some(f)
}

/// Where a–b and c–d cross inside both (fractions along each), away from their ends.
fn cross(a: DVec2, b: DVec2, c: DVec2, d: DVec2, snap: f64) -> Option<(f64, f64)> {
    let r = b - a;
    let s = d - c;
    let denominator = r.perp_dot(s);
    if denominator == 0.0 {
        return None;
    }
    let f = (c - a).perp_dot(s) / denominator;
    let g = (c - a).perp_dot(r) / denominator;
    if !(f > 0.0 && f < 1.0 && g > 0.0 && g < 1.0) {
        return None;
    }
    let p = a + r * f;
    let away = [a, b, c, d].iter().all(|q| q.distance(p) > snap);
    away.then_some((f, g))
}

/// The segments without those that end at a vertex no other segment reaches, repeatedly.
fn without_free_ends(vertices: usize, mut segments: Vec<Segment>) -> Vec<Segment> {
    loop {
        let mut degree = vec![0usize; vertices];
        for s in &segments {
            degree[s.a] += 1;
            degree[s.b] += 1;
        }
        let before = segments.len();
        segments.retain(|s| degree[s.a] > 1 && degree[s.b] > 1);
        if segments.len() == before {
            return segments;
        }
    }
}

/// Twice the signed area of a closed polygon (positive counter-clockwise).
fn twice_area(polygon: &[DVec2]) -> f64 {
    let n = polygon.len();
    (0..n)
        .map(|k| polygon[k].perp_dot(polygon[(k + 1) % n]))
        .sum()
}

fn contains(polygon: &[DVec2], p: DVec2) -> bool {
    let mut inside = false;
    let n = polygon.len();
    for k in 0..n {
        let (a, b) = (polygon[k], polygon[(k + 1) % n]);
        if (a.y > p.y) != (b.y > p.y) {
            let x = a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x);
            if x > p.x {
                inside = !inside;
            }
        }
    }
    inside
}

/// The cycles of the arrangement, sorted into regions with their holes (see the module
/// documentation).
fn trace(points: &[DVec2], hard: &[bool], segments: &[Segment]) -> Vec<Region> {
    // Half-edge h runs segment h / 2 forwards when h is even.
    let tail = |h: usize| {
        let s = &segments[h / 2];
        if h.is_multiple_of(2) { s.a } else { s.b }
    };
    let head = |h: usize| tail(h ^ 1);
    let mut outgoing: Vec<Vec<usize>> = vec![Vec::new(); points.len()];
    for h in 0..segments.len() * 2 {
        outgoing[tail(h)].push(h);
    }
    let angle = |h: usize| {
        let d = points[head(h)] - points[tail(h)];
        d.y.atan2(d.x)
    };
    // Each half-edge's place around its tail.
    let mut place = vec![0usize; segments.len() * 2];
    for list in &mut outgoing {
        list.sort_by(|&x, &y| angle(x).total_cmp(&angle(y)));
        for (k, &h) in list.iter().enumerate() {
            place[h] = k;
        }
    }
    let next = |h: usize| {
        let v = head(h);
        let list = &outgoing[v];
        let back = place[h ^ 1];
        list[(back + list.len() - 1) % list.len()]
    };
    let mut groups = UnionFind::new(points.len());
    for s in segments {
        groups.join(s.a, s.b);
    }
    let mut done = vec![false; segments.len() * 2];
    let mut cycles: Vec<Vec<usize>> = Vec::new();
    for start in 0..segments.len() * 2 {
        if done[start] {
            continue;
        }
        let mut cycle = Vec::new();
        let mut h = start;
        while !done[h] {
            done[h] = true;
            cycle.push(h);
            h = next(h);
        }
        cycles.push(cycle);
    }
    let polygons: Vec<Vec<DVec2>> = cycles
        .iter()
        .map(|c| c.iter().map(|&h| points[tail(h)]).collect())
        .collect();
    let areas: Vec<f64> = polygons.iter().map(|p| twice_area(p)).collect();
    let group_of: Vec<usize> = cycles.iter().map(|c| groups.root(tail(c[0]))).collect();
    let outer: Vec<usize> = (0..cycles.len()).filter(|&k| areas[k] > 0.0).collect();
    let mut holes: Vec<Vec<usize>> = vec![Vec::new(); cycles.len()];
    for k in (0..cycles.len()).filter(|&k| areas[k] < 0.0) {
        let probe = polygons[k][0];
        let holder = outer
            .iter()
            .copied()
            .filter(|&o| group_of[o] != group_of[k] && contains(&polygons[o], probe))
            .min_by(|&x, &y| areas[x].total_cmp(&areas[y]));
        if let Some(o) = holder {
            holes[o].push(k);
        }
    }
    let degree = {
        let mut d = vec![0usize; points.len()];
        for s in segments {
            d[s.a] += 1;
            d[s.b] += 1;
        }
        d
    };
    let runs_of = |cycle: &[usize]| -> Vec<Run> {
        let source = |h: usize| segments[h / 2].source;
        // A run starts at a vertex where polylines meet or end, or the source changes.
        let breaks = |k: usize| {
            let h = cycle[k];
            let prev = cycle[(k + cycle.len() - 1) % cycle.len()];
            let v = tail(h);
            hard[v] || degree[v] != 2 || source(prev) != source(h)
        };
        let first = (0..cycle.len()).find(|&k| breaks(k));
        let start = first.unwrap_or(0);
        let mut runs: Vec<Run> = Vec::new();
        for step in 0..cycle.len() {
            let k = (start + step) % cycle.len();
            let h = cycle[k];
            let s = &segments[h / 2];
            let (t0, t1) = if h.is_multiple_of(2) {
                (s.ta, s.tb)
            } else {
                (s.tb, s.ta)
            };
            let boundary = matches!(s.source, Source::Boundary(_));
            if step == 0 || breaks(k) {
                runs.push(Run {
                    source: s.source,
                    points: vec![points[tail(h)]],
                    params: if boundary { vec![t0] } else { Vec::new() },
                    closed: first.is_none(),
                });
            }
            if let Some(run) = runs.last_mut() {
                run.points.push(points[head(h)]);
                if boundary {
                    run.params.push(t1);
                }
            }
        }
        runs
    };
    outer
        .iter()
        .map(|&o| {
            let hole_polygons: Vec<&Vec<DVec2>> = holes[o].iter().map(|&k| &polygons[k]).collect();
            let inside = points_inside(&polygons[o], &hole_polygons);
            let mut loops = vec![runs_of(&cycles[o])];
            loops.extend(holes[o].iter().map(|&k| runs_of(&cycles[k])));
            Region { loops, inside }
        })
        .collect()
}

/// Points well inside `outer` and outside every hole, the surest first: the middle of the
/// widest span that a few horizontal lines across the region have inside it, then that span's
/// points a third of the way from either end, then the middles of the other lines' widest
/// spans (more than one, for a region that some other body touches along a line through the
/// first).
pub fn points_inside(outer: &[DVec2], holes: &[&Vec<DVec2>]) -> Vec<DVec2> {
    let (lo, hi) = outer
        .iter()
        .fold((DVec2::INFINITY, DVec2::NEG_INFINITY), |(lo, hi), &p| {
            (lo.min(p), hi.max(p))
        });
    // Each line's widest span: (width, its ends' x, the line's y).
    let mut spans: Vec<(f64, f64, f64, f64)> = Vec::new();
    // Irrational-looking heights, so a line rarely passes through a vertex.
    for f in [0.496_7, 0.327_9, 0.681_3, 0.141_421_36, 0.886_226_9] {
        let y = lo.y + (hi.y - lo.y) * f;
        let mut xs: Vec<f64> = Vec::new();
        for polygon in std::iter::once(outer).chain(holes.iter().map(|h| h.as_slice())) {
            let n = polygon.len();
            for k in 0..n {
                let (a, b) = (polygon[k], polygon[(k + 1) % n]);
                if (a.y > y) != (b.y > y) {
                    xs.push(a.x + (y - a.y) / (b.y - a.y) * (b.x - a.x));
                }
            }
        }
        xs.sort_by(f64::total_cmp);
        let widest = xs
            .chunks_exact(2)
            .map(|pair| (pair[1] - pair[0], pair[0], pair[1], y))
            .max_by(|p, q| p.0.total_cmp(&q.0));
        spans.extend(widest);
    }
    spans.sort_by(|p, q| q.0.total_cmp(&p.0));
    let Some(&(_, x0, x1, y)) = spans.first() else {
        return vec![outer[0]];
    };
    let mut points = vec![
        DVec2::new(0.5 * (x0 + x1), y),
        DVec2::new(x0 + (x1 - x0) / 3.0, y),
        DVec2::new(x1 - (x1 - x0) / 3.0, y),
    ];
    points.extend(
        spans[1..]
            .iter()
            .map(|&(_, x0, x1, y)| DVec2::new(0.5 * (x0 + x1), y)),
    );
    points
}

/// The first of [`points_inside`]: a point well inside `outer` and outside every hole.
pub fn point_inside(outer: &[DVec2], holes: &[&Vec<DVec2>]) -> DVec2 {
    points_inside(outer, holes)[0]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ring(points: &[(f64, f64)], source: Source) -> Polyline {
        Polyline {
            source,
            points: points.iter().map(|&(x, y)| DVec2::new(x, y)).collect(),
            params: Vec::new(),
            closed: true,
        }
    }

    fn open(points: &[(f64, f64)], source: Source) -> Polyline {
        Polyline {
            closed: false,
            ..ring(points, source)
        }
    }

    fn square() -> Polyline {
        ring(
            &[(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)],
            Source::Boundary(0),
        )
    }

    fn areas(regions: &[Region]) -> Vec<f64> {
        let mut out: Vec<f64> = regions
            .iter()
            .map(|r| {
                r.loops
                    .iter()
                    .map(|l| {
                        let p: Vec<DVec2> = l
                            .iter()
                            .flat_map(|run| run.points[..run.points.len() - 1].iter().copied())
                            .collect();
                        0.5 * twice_area(&p)
                    })
                    .sum()
            })
            .collect();
        out.sort_by(f64::total_cmp);
        out
    }

    #[test]
    fn a_cut_across_a_square_makes_two_parts() {
        let cut = open(
            &[(0.3, -1e-12), (0.35, 0.5), (0.3, 1.0 + 1e-12)],
            Source::Cut(0),
        );
        let regions = regions(&[square(), cut], 1e-9);
        let a = areas(&regions);
        assert_eq!(a.len(), 2, "{a:?}");
        assert!((a[0] - 0.325).abs() < 1e-12 && (a[1] - 0.675).abs() < 1e-12);
        for r in &regions {
            assert_eq!(r.loops.len(), 1);
            assert!(r.loops[0].iter().any(|run| run.source == Source::Cut(0)));
        }
    }

    #[test]
    fn a_ring_inside_makes_a_hole_and_a_disc() {
        let ring = ring(
            &[(0.4, 0.4), (0.6, 0.4), (0.6, 0.6), (0.4, 0.6)],
            Source::Cut(0),
        );
        let regions = regions(&[square(), ring], 1e-9);
        let a = areas(&regions);
        assert_eq!(a.len(), 2);
        assert!(
            (a[0] - 0.04).abs() < 1e-12 && (a[1] - 0.96).abs() < 1e-12,
            "{a:?}"
        );
        let holed = regions
            .iter()
            .find(|r| r.loops.len() == 2)
            .expect("a holed part");
        assert!(holed.loops[1][0].closed);
        let p = holed.inside[0];
        assert!(!(p.x > 0.4 && p.x < 0.6 && p.y > 0.4 && p.y < 0.6));
    }

    #[test]
    fn crossing_cuts_and_an_overlapping_square_split_where_they_meet() {
        // A second square overlapping the first by a quarter, and a cut ending on nothing.
        let other = ring(
            &[(0.5, 0.5), (1.5, 0.5), (1.5, 1.5), (0.5, 1.5)],
            Source::Cut(0),
        );
        let dangling = open(&[(0.1, 0.1), (0.2, 0.2)], Source::Cut(1));
        let a = areas(&regions(&[square(), other, dangling], 1e-9));
        assert_eq!(a.len(), 3, "{a:?}");
        assert!(
            a.iter()
                .all(|x| (x - 0.25).abs() < 1e-12 || (x - 0.75).abs() < 1e-12)
        );
    }

    #[test]
    fn a_square_on_the_boundary_shares_its_segments() {
        let half = ring(
            &[(0.0, 0.0), (0.5, 0.0), (0.5, 1.0), (0.0, 1.0)],
            Source::Cut(0),
        );
        let regions = regions(&[square(), half], 1e-9);
        let a = areas(&regions);
        assert_eq!(a.len(), 2, "{a:?}");
        assert!((a[0] - 0.5).abs() < 1e-12 && (a[1] - 0.5).abs() < 1e-12);
    }
}
