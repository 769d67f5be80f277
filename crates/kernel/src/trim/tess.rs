//! Export tessellation of a trimmed surface: the untrimmed surface's parameter grid
//! ([`crate::tess::grid_for`]) clipped by the trim loops.
//!
//! The trim loops are flattened so that every boundary chord stays within a quarter of the
//! tolerance of the trim curve on the surface, then split where they cross the grid's lines, so
//! that every piece lies in one cell. A cell no chord touches is kept whole (its two triangles)
//! or dropped, by the parity of its centre; a cell a chord cuts is triangulated on its own, with
//! its corners, the chord points in it and the crossings on its sides as vertices, and keeps the
//! part inside the loops. Where the pieces in it run as chains from side to side (nearly every
//! cut cell) the faces they cut the cell into are traced, classified by parity and the kept
//! ones triangulated by clipping ears; elsewhere (a loop wholly inside the cell, a loop touching
//! a side and turning back, pieces that cross) a constrained Delaunay triangulation (spade)
//! keeps the triangles inside. Neighbouring cells see the same points on the side they share,
//! so the mesh has no cracks. The surface's points along the way (the boundary's flattening,
//! the check below, the boundary's vertices) come from its Bézier patches
//! ([`ScatteredEvaluator`]).
//!
//! **Why this keeps the tolerance.** The linear interpolant of a function whose Hessian is
//! bounded by M deviates by at most M R² / 2 over a triangle, R the radius of the smallest disc
//! containing it (Waldron, "The error in linear interpolation at the vertices of a simplex",
//! SIAM J. Numer. Anal. 35, 1998). A piece of a cell lies in the cell's smallest disc, so its
//! bound is at most the cell's, and the grid keeps the cell's triangles within the tolerance.
//! A bound is not a measurement, so every triangle of a cut cell is then checked at its
//! centroid and edge midpoints; a cell that fails gets new grid lines through its middle, until
//! none does. The triangle count stays that of the untrimmed grid plus a few per boundary
//! chord.

use rustc_hash::FxHashMap as HashMap;

use glam::{DVec2, DVec3};
use spade::{ConstrainedDelaunayTriangulation, Point2, Triangulation};

use super::{TrimmedSurface, flatten_pieces_mapped};
use crate::GeometryError;
use crate::diffgeo::CurvatureValues;
use crate::surface::GridSample;
use crate::surface::{DerivativeBounds, ScatteredEvaluator, interpolation_error};
use crate::tess::{self, GridSampler, MAX_TRIANGLES, ParameterGrid, Tessellation, TriangleMesh};

/// The share of the tolerance the boundary chords keep to.
const BOUNDARY_SHARE: f64 = 0.25;
/// The least and most halvings of a trim piece flattened on the surface.
const SURFACE_DEPTHS: (usize, usize) = (2, 30);
/// Rounds of grid refinement where a cut cell's triangles miss the tolerance.
const REFINE_ROUNDS: usize = 10;
/// Chord points this close to a grid line (a share of the domain's size) are moved onto it, so
/// that a loop along a grid line, or through a grid corner, meets it exactly.
const SNAP: f64 = 1e-11;

fn failed(message: String) -> GeometryError {
    GeometryError::Construction {
        what: "trimmed tessellation",
        message,
    }
}

/// The loops flattened for the surface: each chord's midpoint on the surface within
/// `tolerance` of the chord in space (checked at t = 1/4, 1/2, 3/4 of every chord). The loops'
/// monotone pieces are the trimmed surface's, cut once and shared with its classification
/// index, rather than cut again on every export.
pub fn flatten_on_surface(
    trimmed: &TrimmedSurface,
    tolerance: f64,
) -> Result<Vec<Vec<DVec2>>, GeometryError> {
    flatten_with(trimmed, tolerance, &trimmed.surface().scattered_evaluator())
}

/// [`flatten_on_surface`] with the surface's points from `surface`.
fn flatten_with(
    trimmed: &TrimmedSurface,
    tolerance: f64,
    surface: &ScatteredEvaluator<'_>,
) -> Result<Vec<Vec<DVec2>>, GeometryError> {
    let on_surface = |p: DVec2| surface.point(p);
    let pieces = trimmed.monotone_pieces();
    let mut out = Vec::new();
    for lp in pieces.chunk_by(|a, b| a.source.0 == b.source.0) {
        let curves = lp.chunk_by(|a, b| a.source.1 == b.source.1);
        let bounds = |lo, hi| surface.derivative_bounds(lo, hi);
        let (polygon, _) =
            flatten_pieces_mapped(curves, tolerance, SURFACE_DEPTHS, on_surface, bounds)?;
        if polygon.len() > MAX_TRIANGLES {
            return Err(failed(
                "the trim loops need too many points at this tolerance".into(),
            ));
        }
        out.push(polygon);
    }
    Ok(out)
}

/// The trimmed surface as a triangle mesh within `tessellation` (a tolerance, or segments per
/// span for the grid with the loops flattened to 1/1000 of the surface's size).
pub fn tessellate_trimmed(
    trimmed: &TrimmedSurface,
    tessellation: Tessellation,
    curvature: bool,
) -> Result<TriangleMesh, GeometryError> {
    tessellate_trimmed_with(trimmed, tessellation, curvature, &tess::KernelGrids)
}

/// [`tessellate_trimmed`] with the vertices on the grid's crossings evaluated by `sampler`
/// (the cut cells are clipped, and the boundary's vertices evaluated, by the kernel).
pub fn tessellate_trimmed_with(
    trimmed: &TrimmedSurface,
    tessellation: Tessellation,
    curvature: bool,
    sampler: &dyn GridSampler,
) -> Result<TriangleMesh, GeometryError> {
    plan_trimmed(trimmed, tessellation, curvature)?
        .run(sampler)?
        .pop()
        .ok_or_else(|| failed("the tessellation made no mesh".to_owned()))
}

/// [`tessellate_trimmed`] up to the evaluation of its grid's crossings ([`tess::GridPlan`]):
/// the boundary flattened, the grid refined and clipped, the cut cells triangulated. Its one
/// job is the whole grid where at least half of the crossings are used, and none otherwise
/// (then every vertex is evaluated on its own); finished without the grid's values (the
/// sampler failed), it evaluates the vertices on its own too.
pub fn plan_trimmed(
    trimmed: &TrimmedSurface,
    tessellation: Tessellation,
    curvature: bool,
) -> Result<tess::GridPlan, GeometryError> {
    let surface = trimmed.surface();
    let tolerance = match tessellation {
        Tessellation::Tolerance(t) => t,
        Tessellation::Segments(_) => 1e-3 * surface.size(),
    };
    if !(tolerance > 0.0 && tolerance.is_finite()) {
        return Err(failed(format!(
            "the tolerance must be finite and > 0, got {tolerance}"
        )));
    }
    let mut grid = tess::grid_for(surface, tessellation)?;
    // The boundary at a quarter of the tolerance: the area lost between the chords and the trim
    // curve grows with the perimeter, so a small trimmed face would otherwise lose a larger
    // share of its area than the interior's error.
    let scattered = surface.scattered_evaluator();
    let polygons = flatten_with(trimmed, BOUNDARY_SHARE * tolerance, &scattered)?;
    let checked = matches!(tessellation, Tessellation::Tolerance(_));
    let mut round = 0;
    loop {
        if grid.triangle_count() > MAX_TRIANGLES {
            return Err(failed(format!(
                "more than {MAX_TRIANGLES} triangles: choose a larger tolerance"
            )));
        }
        let clipped = clip_grid(&grid, &polygons)?;
        round += 1;
        let (failing, known) = if checked && round <= REFINE_ROUNDS {
            let bounds = |lo, hi| scattered.derivative_bounds(lo, hi);
            clipped.failing_cells(&grid, &scattered, bounds, tolerance, !curvature)?
        } else {
            (Vec::new(), Vec::new())
        };
        if failing.is_empty() {
            let known = if curvature { Vec::new() } else { known };
            return Ok(planned_mesh(
                scattered.into_owned(),
                grid,
                (clipped.points, known),
                clipped.triangles,
                curvature,
            ));
        }
        grid = split_cells(&grid, &failing);
    }
}

/// The grid with a line through the middle of every cell in `cells` (in both directions).
fn split_cells(grid: &ParameterGrid, cells: &[[usize; 2]]) -> ParameterGrid {
    let with_middles = |values: &[f64], at: &mut dyn Iterator<Item = usize>| {
        let mut out = values.to_vec();
        out.extend(at.map(|k| 0.5 * (values[k] + values[k + 1])));
        out.sort_by(f64::total_cmp);
        out.dedup();
        out
    };
    ParameterGrid {
        us: with_middles(&grid.us, &mut cells.iter().map(|c| c[0])),
        vs: with_middles(&grid.vs, &mut cells.iter().map(|c| c[1])),
    }
}

/// The grid clipped by the loops: (u, v) points, triangles counter-clockwise in (u, v), and
/// which triangles lie in a cut cell.
struct ClippedGrid {
    points: Vec<DVec2>,
    triangles: Vec<[u32; 3]>,
    /// The cut cells' triangles: (first triangle, end, cell).
    cut: Vec<(usize, usize, [usize; 2])>,
    /// How many of the cut cells were ear-clipped.
    #[cfg_attr(not(test), allow(dead_code))]
    ear_clipped: usize,
}

impl ClippedGrid {
    /// The cut cells where a triangle's centroid or an edge midpoint lies farther than
    /// `tolerance` from the surface at the same (u, v) (an upper bound of its distance). Each
    /// vertex is evaluated once, and each edge's midpoint once in a cell (an edge on a cell's
    /// side, once in each cell beside it). A triangle or an edge that the surface's
    /// second-derivative bounds over its cell (from `bounds`, where it has them) already keep
    /// within `tolerance` ([`interpolation_error`]) is not sampled: its samples could not fail.
    /// With the failing cells come the points (and where `normals`, the unit normals) of the
    /// vertices it evaluated, for the mesh to keep.
    fn failing_cells(
        &self,
        grid: &ParameterGrid,
        surface: &ScatteredEvaluator<'_>,
        bounds: impl Fn(DVec2, DVec2) -> Option<DerivativeBounds>,
        tolerance: f64,
        normals: bool,
    ) -> Result<(Vec<[usize; 2]>, Vec<Known>), GeometryError> {
        let mut positions: Vec<Known> = vec![None; self.points.len()];
        let mut edges: Vec<[u32; 2]> = Vec::new();
        let mut failing = Vec::new();
        // Rounding in the samples stays far below this margin.
        let limit = tolerance * (1.0 - 1e-9);
        for &(start, end, cell) in &self.cut {
            let triangles = &self.triangles[start..end];
            let mut position = |k: u32| -> Result<DVec3, GeometryError> {
                Ok(match positions[k as usize] {
                    Some((p, _)) => p,
                    None => {
                        let uv = self.points[k as usize];
                        let known = if normals {
                            surface.point_and_normal(uv)?
                        } else {
                            (surface.point(uv)?, DVec3::ZERO)
                        };
                        positions[k as usize] = Some(known);
                        known.0
                    }
                })
            };
            let [i, j] = cell;
            let scale = bounds(
                DVec2::new(grid.us[i], grid.vs[j]),
                DVec2::new(grid.us[i + 1], grid.vs[j + 1]),
            )
            .map(|b| b.metric());
            let bounded = |corners: &[u32]| {
                scale.is_some_and(|scale| {
                    let mut scaled = [DVec2::ZERO; 3];
                    for (slot, &k) in scaled.iter_mut().zip(corners) {
                        *slot = self.points[k as usize] * scale;
                    }
                    interpolation_error(&scaled[..corners.len()]) <= limit
                })
            };
            let mut worst: f64 = 0.0;
            edges.clear();
            for t in triangles {
                // A bounded triangle's sides are bounded too (half a side is at most the
                // radius of the triangle's smallest circle).
                if bounded(t) {
                    continue;
                }
                let flat = (position(t[0])? + position(t[1])? + position(t[2])?) / 3.0;
                let centroid = t.map(|k| self.points[k as usize]).iter().sum::<DVec2>() / 3.0;
                worst = worst.max((surface.point(centroid)? - flat).length());
                edges.extend(
                    [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])].map(|(a, b)| [a.min(b), a.max(b)]),
                );
            }
            // Each edge of the cell once (the two triangles on an inner edge share it).
            edges.sort_unstable();
            edges.dedup();
            for &[a, b] in &edges {
                if worst > tolerance {
                    break;
                }
                if bounded(&[a, b]) {
                    continue;
                }
                let (pa, pb) = (position(a)?, position(b)?);
                let middle = 0.5 * (self.points[a as usize] + self.points[b as usize]);
                worst = worst.max((surface.point(middle)? - 0.5 * (pa + pb)).length());
            }
            if worst > tolerance {
                failing.push(cell);
            }
        }
        Ok((failing, positions))
    }
}

/// The (u, v) points of a clipped grid, each stored once: the grid's crossings first, point
/// i * vs.len() + j at (us[i], vs[j]) (the order of the grid's evaluation), then the chord
/// points off them, found by their exact coordinates.
struct PointPool<'g> {
    grid: &'g ParameterGrid,
    points: Vec<DVec2>,
    index: HashMap<[u64; 2], u32>,
    /// Where the last point's look-ups ended among the grid's lines ([`below`]).
    near: [usize; 2],
}

impl<'g> PointPool<'g> {
    /// The grid's crossings, with room for about `expected` points off them.
    fn new(grid: &'g ParameterGrid, expected: usize) -> Self {
        let mut points = Vec::with_capacity(grid.us.len() * grid.vs.len() + expected);
        points.extend(
            grid.us
                .iter()
                .flat_map(|&u| grid.vs.iter().map(move |&v| DVec2::new(u, v))),
        );
        Self {
            grid,
            points,
            index: HashMap::with_capacity_and_hasher(expected, Default::default()),
            near: [0, 0],
        }
    }

    /// The id of the grid's crossing (i, j).
    fn crossing(&self, i: usize, j: usize) -> u32 {
        (i * self.grid.vs.len() + j) as u32
    }

    fn id(&mut self, p: DVec2) -> u32 {
        let line = |lines: &[f64], x: f64, hint: &mut usize| {
            let k = below(lines, x, hint);
            (lines.get(k) == Some(&x)).then_some(k)
        };
        if let Some(i) = line(&self.grid.us, p.x, &mut self.near[0])
            && let Some(j) = line(&self.grid.vs, p.y, &mut self.near[1])
        {
            return self.crossing(i, j);
        }
        let key = [p.x.to_bits(), p.y.to_bits()];
        *self.index.entry(key).or_insert_with(|| {
            self.points.push(p);
            (self.points.len() - 1) as u32
        })
    }
}

/// What the chords leave in one cell: the points on it or in it, and the chord pieces.
#[derive(Clone, Copy)]
struct CellCut<'a> {
    points: &'a [u32],
    pieces: &'a [[u32; 2]],
}

/// `entries` (cell, value) grouped by cell, keeping their order within a cell (a counting
/// sort): the values, and where each cell's start (`cells + 1` offsets).
fn group_by_cell<T: Copy + Default>(entries: &[(u32, T)], cells: usize) -> (Vec<T>, Vec<usize>) {
    let mut starts = vec![0usize; cells + 1];
    for &(cell, _) in entries {
        starts[cell as usize + 1] += 1;
    }
    for k in 0..cells {
        starts[k + 1] += starts[k];
    }
    let mut fill = starts.clone();
    let mut values = vec![T::default(); entries.len()];
    for &(cell, value) in entries {
        values[fill[cell as usize]] = value;
        fill[cell as usize] += 1;
    }
    (values, starts)
}

/// `x` moved onto the nearest of the sorted `lines` when it lies within `snap` of it.
fn snap_to(lines: &[f64], x: f64, snap: f64, hint: &mut usize) -> f64 {
    let k = below(lines, x, hint);
    [k.checked_sub(1), Some(k)]
        .into_iter()
        .flatten()
        .filter_map(|k| lines.get(k))
        .find(|&&l| (l - x).abs() <= snap)
        .copied()
        .unwrap_or(x)
}

/// partition_point(l < x) of the sorted `lines` (how many lie below x), the search started at
/// the last answer (`hint`, updated): consecutive points of a polygon lie in the same cell or
/// the next, so one or two comparisons usually find it.
fn below(lines: &[f64], x: f64, hint: &mut usize) -> usize {
    let n = lines.len();
    let fits = |k: usize| (k == 0 || lines[k - 1] < x) && (k == n || !(lines[k] < x));
    let h = (*hint).min(n);
    let k = if fits(h) {
        h
    } else if h < n && fits(h + 1) {
        h + 1
    } else if h > 0 && fits(h - 1) {
        h - 1
    } else {
        lines.partition_point(|&l| l < x)
    };
    *hint = k;
    k
}

/// The cells (spans of the sorted `lines`) whose closed interval holds x: two where x lies on
/// an inner line, one elsewhere (the search from `hint`, as [`below`]).
fn spans_holding_near(lines: &[f64], x: f64, hint: &mut usize) -> std::ops::RangeInclusive<usize> {
    spans_at(lines, x, below(lines, x, hint))
}

/// [`spans_holding_near`] given k, the first line not below x.
fn spans_at(lines: &[f64], x: f64, k: usize) -> std::ops::RangeInclusive<usize> {
    let last = lines.len() - 2;
    if lines.get(k) == Some(&x) {
        k.saturating_sub(1).min(last)..=k.min(last)
    } else {
        let k = k.saturating_sub(1).min(last);
        k..=k
    }
}

/// The polygons with every point within `snap` of a grid line moved onto it, repeated points
/// dropped.
fn snapped(grid: &ParameterGrid, polygons: &[Vec<DVec2>], snap: f64) -> Vec<Vec<DVec2>> {
    let mut near = [0, 0];
    polygons
        .iter()
        .map(|poly| {
            let mut out: Vec<DVec2> = Vec::with_capacity(poly.len());
            for p in poly {
                let q = DVec2::new(
                    snap_to(&grid.us, p.x, snap, &mut near[0]),
                    snap_to(&grid.vs, p.y, snap, &mut near[1]),
                );
                if out.last() != Some(&q) {
                    out.push(q);
                }
            }
            while out.len() > 1 && out.first() == out.last() {
                out.pop();
            }
            out
        })
        .filter(|poly| poly.len() >= 3)
        .collect()
}

/// The chord from a to b split where it crosses the grid's lines, from a to b (points on a
/// line lie exactly on it), into `out` (cleared first; `work` is scratch).
#[allow(clippy::too_many_arguments)]
fn chord_points(
    grid: &ParameterGrid,
    a: DVec2,
    b: DVec2,
    snap: f64,
    near: &mut [usize; 2],
    work: &mut Vec<(f64, DVec2)>,
    out: &mut Vec<DVec2>,
) {
    work.clear();
    work.extend([(0.0, a), (1.0, b)]);
    // The lines strictly between from and to.
    let crossings = |lines: &[f64], from: f64, to: f64, hint: &mut usize| {
        let (lo, hi) = (from.min(to), from.max(to));
        let k = below(lines, lo, hint);
        let start = k + usize::from(lines.get(k) == Some(&lo));
        let end = below(lines, hi, hint);
        start..end.max(start)
    };
    for k in crossings(&grid.us, a.x, b.x, &mut near[0]) {
        let u = grid.us[k];
        let t = (u - a.x) / (b.x - a.x);
        let v = snap_to(&grid.vs, a.y + t * (b.y - a.y), snap, &mut near[1]);
        work.push((t, DVec2::new(u, v)));
    }
    for k in crossings(&grid.vs, a.y, b.y, &mut near[1]) {
        let v = grid.vs[k];
        let t = (v - a.y) / (b.y - a.y);
        let u = snap_to(&grid.us, a.x + t * (b.x - a.x), snap, &mut near[0]);
        work.push((t, DVec2::new(u, v)));
    }
    work.sort_by(|p, q| p.0.total_cmp(&q.0));
    out.clear();
    out.extend(work.iter().map(|&(_, p)| p));
    out.dedup();
}

/// The chords of the polygons that overlap one row of cells (in v), sorted by their larger u,
/// for parity tests.
#[derive(Default)]
struct RowChords {
    /// Each chord's larger u, ascending.
    right: Vec<f64>,
    chords: Vec<[DVec2; 2]>,
}

/// The chords of the polygons by row of cells.
fn chords_by_row(grid: &ParameterGrid, polygons: &[Vec<DVec2>]) -> Vec<RowChords> {
    // Each chord with the rows it overlaps, then each row sized before it is filled.
    let mut spans = Vec::with_capacity(polygons.iter().map(Vec::len).sum());
    let mut sizes = vec![0usize; grid.vs.len() - 1];
    let mut near = 0;
    for poly in polygons {
        for k in 0..poly.len() {
            let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
            let first = *spans_holding_near(&grid.vs, a.y.min(b.y), &mut near).start();
            let last = *spans_holding_near(&grid.vs, a.y.max(b.y), &mut near).end();
            sizes[first..=last].iter_mut().for_each(|n| *n += 1);
            spans.push(([a, b], first..=last));
        }
    }
    let mut rows: Vec<Vec<[DVec2; 2]>> = sizes.iter().map(|&n| Vec::with_capacity(n)).collect();
    for (chord, range) in spans {
        for row in &mut rows[range] {
            row.push(chord);
        }
    }
    let right = |c: &[DVec2; 2]| c[0].x.max(c[1].x);
    rows.into_iter()
        .map(|mut chords| {
            // The parity counts every chord from the first reaching past p, so chords ending
            // at the same u may come in any order.
            chords.sort_unstable_by(|p, q| right(p).total_cmp(&right(q)));
            RowChords {
                right: chords.iter().map(right).collect(),
                chords,
            }
        })
        .collect()
}

/// Whether p (strictly inside a cell of the row whose chords are `row`) lies inside the
/// loops: the parity of the chords crossing the ray from p towards +u. Chords that end left
/// of p cannot cross it, so only those reaching past p.x are tested.
fn inside(row: &RowChords, p: DVec2) -> bool {
    let first = row.right.partition_point(|&x| x <= p.x);
    let mut parity = false;
    for &[a, b] in &row.chords[first..] {
        if (a.y > p.y) != (b.y > p.y) {
            let x = a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x);
            if x > p.x {
                parity = !parity;
            }
        }
    }
    parity
}

/// The grid clipped by the (closed, even-odd) polygons.
fn clip_grid(grid: &ParameterGrid, polygons: &[Vec<DVec2>]) -> Result<ClippedGrid, GeometryError> {
    clip_grid_with(grid, polygons, true)
}

/// [`clip_grid`], with the cut cells ear-clipped where they can be (`ear_clipping`) or all
/// triangulated by the constrained Delaunay triangulation (the tests compare the two).
fn clip_grid_with(
    grid: &ParameterGrid,
    polygons: &[Vec<DVec2>],
    ear_clipping: bool,
) -> Result<ClippedGrid, GeometryError> {
    let (us, vs) = (&grid.us, &grid.vs);
    // Points within SNAP of the domain's size from a grid line are moved onto it.
    let snap = SNAP * (us[us.len() - 1] - us[0]).max(vs[vs.len() - 1] - vs[0]);
    let polygons = snapped(grid, polygons, snap);
    // The loops' points, and about as many again where their chords cross the grid's lines.
    let mut pool = PointPool::new(grid, 2 * polygons.iter().map(Vec::len).sum::<usize>());
    // The cut of cell (i, j) at i * rows + j: its points and pieces, gathered flat.
    let rows_count = vs.len() - 1;
    let cells = (us.len() - 1) * rows_count;
    let mut cell_points: Vec<(u32, u32)> = Vec::new();
    let mut cell_pieces: Vec<(u32, [u32; 2])> = Vec::new();
    let (mut work, mut points, mut ids) = (Vec::new(), Vec::new(), Vec::new());
    let (mut near_u, mut near_v, mut near_chord) = (0, 0, [0, 0]);
    for poly in &polygons {
        // A chord starts where the one before it ended, and the last ends where the first
        // started: those ids are carried rather than looked up again.
        let (mut first, mut carried) = (None, None);
        for k in 0..poly.len() {
            let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
            chord_points(grid, a, b, snap, &mut near_chord, &mut work, &mut points);
            ids.clear();
            let closing = k + 1 == poly.len();
            for (n, &p) in points.iter().enumerate() {
                let id = match (n == 0, n + 1 == points.len() && closing) {
                    (true, _) if carried.is_some() => carried,
                    (_, true) => first,
                    _ => None,
                };
                ids.push(id.unwrap_or_else(|| pool.id(p)));
            }
            first = first.or(ids.first().copied());
            carried = ids.last().copied();
            for (&p, &id) in points.iter().zip(&ids) {
                for i in spans_holding_near(us, p.x, &mut near_u) {
                    for j in spans_holding_near(vs, p.y, &mut near_v) {
                        cell_points.push(((i * rows_count + j) as u32, id));
                    }
                }
            }
            for (w, pair) in points.windows(2).zip(ids.windows(2)) {
                let m = 0.5 * (w[0] + w[1]);
                for i in spans_holding_near(us, m.x, &mut near_u) {
                    for j in spans_holding_near(vs, m.y, &mut near_v) {
                        cell_pieces.push(((i * rows_count + j) as u32, [pair[0], pair[1]]));
                    }
                }
            }
        }
    }
    let (cell_points, point_starts) = group_by_cell(&cell_points, cells);
    let (cell_pieces, piece_starts) = group_by_cell(&cell_pieces, cells);
    let rows = chords_by_row(grid, &polygons);
    let mut scratch = CellScratch {
        ear_clipping,
        ..CellScratch::default()
    };
    let mut triangles = Vec::new();
    let mut cut = Vec::new();
    for i in 0..us.len() - 1 {
        for j in 0..vs.len() - 1 {
            let rect = [us[i], us[i + 1], vs[j], vs[j + 1]];
            let corners = corners_of(rect);
            let c = i * rows_count + j;
            let cell = CellCut {
                points: &cell_points[point_starts[c]..point_starts[c + 1]],
                pieces: &cell_pieces[piece_starts[c]..piece_starts[c + 1]],
            };
            match Some(cell).filter(|c| c.cuts(&pool.points, rect)) {
                Some(cell) => {
                    let start = triangles.len();
                    triangulate_cell(
                        &mut pool,
                        cell,
                        [i, j],
                        &rows[j],
                        &mut scratch,
                        &mut triangles,
                    )?;
                    cut.push((start, triangles.len(), [i, j]));
                }
                None => {
                    if inside(&rows[j], 0.5 * (corners[0] + corners[2])) {
                        let [c00, c10, c11, c01] = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)]
                            .map(|(a, b)| pool.crossing(a, b));
                        triangles.push([c00, c10, c11]);
                        triangles.push([c00, c11, c01]);
                    }
                }
            }
        }
    }
    Ok(ClippedGrid {
        points: pool.points,
        triangles,
        cut,
        ear_clipped: scratch.ear_clipped,
    })
}

/// The corners of the cell `rect` (u0, u1, v0, v1), counter-clockwise from (u0, v0).
fn corners_of(rect: [f64; 4]) -> [DVec2; 4] {
    [
        DVec2::new(rect[0], rect[2]),
        DVec2::new(rect[1], rect[2]),
        DVec2::new(rect[1], rect[3]),
        DVec2::new(rect[0], rect[3]),
    ]
}

/// Whether the segment from p to q runs along a side of the cell `rect` (u0, u1, v0, v1).
fn along_side(rect: [f64; 4], p: DVec2, q: DVec2) -> bool {
    (p.x == q.x && (p.x == rect[0] || p.x == rect[1]))
        || (p.y == q.y && (p.y == rect[2] || p.y == rect[3]))
}

impl CellCut<'_> {
    /// Whether the chords cut the cell `rect` (u0, u1, v0, v1): a point other than its corners,
    /// or a piece not along its sides.
    fn cuts(&self, points: &[DVec2], rect: [f64; 4]) -> bool {
        let corner =
            |p: DVec2| (p.x == rect[0] || p.x == rect[1]) && (p.y == rect[2] || p.y == rect[3]);
        self.points.iter().any(|&k| !corner(points[k as usize]))
            || self
                .pieces
                .iter()
                .any(|&[a, b]| !along_side(rect, points[a as usize], points[b as usize]))
    }
}

/// Where p lies along the boundary of the cell with `corners` (counter-clockwise from the
/// first), or None inside.
fn perimeter_position(corners: [DVec2; 4], p: DVec2) -> Option<f64> {
    let [c00, c10, c11, c01] = corners;
    let (w, h) = (c10.x - c00.x, c01.y - c00.y);
    if p.y == c00.y {
        Some(p.x - c00.x)
    } else if p.x == c11.x {
        Some(w + (p.y - c00.y))
    } else if p.y == c11.y {
        Some(w + h + (c11.x - p.x))
    } else if p.x == c00.x {
        Some(2.0 * w + h + (c11.y - p.y))
    } else {
        None
    }
}

/// Buffers a cut cell's triangulation reuses from one cell to the next (a cell holds a few
/// dozen points; allocating them for each of a surface's hundreds of cut cells was a tenth of
/// its export).
#[derive(Default)]
struct CellScratch {
    /// The cell's points: their ids in the pool, and positions.
    ids: Vec<u32>,
    /// Each pool point's place in `ids`, u32::MAX between cells.
    local_of: Vec<u32>,
    points: Vec<DVec2>,
    /// (position along the perimeter, point) for the points on it, in order.
    around: Vec<(f64, usize)>,
    /// The chord pieces not along a side, as pairs of the cell's points.
    pieces: Vec<[usize; 2]>,
    faces: FaceScratch,
    /// Whether cells are ear-clipped where they can be, and how many were.
    ear_clipping: bool,
    ear_clipped: usize,
}

/// The buffers of [`ear_clipped_cell`].
#[derive(Default)]
struct FaceScratch {
    perimeter_at: Vec<usize>,
    links: Vec<[usize; 2]>,
    /// For a chain's end: (its other end, the range of the points between in `between`, whether
    /// they are read backwards from this end).
    chain_to: Vec<Option<(usize, std::ops::Range<usize>, bool)>>,
    between: Vec<usize>,
    used: Vec<bool>,
    /// The faces' corners, one after another, and each face's range in it.
    face: Vec<usize>,
    faces: Vec<std::ops::Range<usize>>,
    sides_of: Vec<(usize, usize)>,
    kept: Vec<Option<bool>>,
    clip: EarScratch,
}

/// The buffers of [`clip_ears`].
#[derive(Default)]
struct EarScratch {
    prev: Vec<usize>,
    next: Vec<usize>,
    flat: Vec<bool>,
    shape: Vec<f64>,
    blocking: Vec<usize>,
}

/// The triangles of one cut cell inside the loops: its corners and chord points triangulated
/// with the cell's sides and the chord pieces as edges, by [`ear_clipped_cell`] where the cell
/// is simple, else by a constrained Delaunay triangulation (spade).
fn triangulate_cell(
    pool: &mut PointPool<'_>,
    cell: CellCut<'_>,
    [i, j]: [usize; 2],
    row: &RowChords,
    scratch: &mut CellScratch,
    out: &mut Vec<[u32; 3]>,
) -> Result<(), GeometryError> {
    let (us, vs) = (&pool.grid.us, &pool.grid.vs);
    let rect = [us[i], us[i + 1], vs[j], vs[j + 1]];
    let corners = corners_of(rect);
    let CellScratch {
        ids,
        local_of,
        points,
        around,
        pieces,
        faces,
        ear_clipping,
        ear_clipped,
    } = scratch;
    ids.clear();
    ids.extend([(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)].map(|(a, b)| pool.crossing(a, b)));
    // Each pool point's place among the cell's (u32::MAX: not in it), set for this cell and
    // cleared after it.
    if local_of.len() < pool.points.len() {
        local_of.resize(pool.points.len(), u32::MAX);
    }
    for (n, &k) in ids.iter().enumerate() {
        local_of[k as usize] = n as u32;
    }
    for &k in cell.points {
        if local_of[k as usize] == u32::MAX {
            local_of[k as usize] = ids.len() as u32;
            ids.push(k);
        }
    }
    points.clear();
    points.extend(ids.iter().map(|&k| pool.points[k as usize]));
    // The sides: consecutive points around the perimeter.
    around.clear();
    around.extend(
        points
            .iter()
            .enumerate()
            .filter_map(|(n, &p)| perimeter_position(corners, p).map(|s| (s, n))),
    );
    around.sort_by(|a, b| a.0.total_cmp(&b.0));
    pieces.clear();
    for &[a, b] in cell.pieces {
        let [a, b] = [a, b].map(|k| local_of[k as usize]);
        if a == u32::MAX || b == u32::MAX {
            continue;
        }
        let [a, b] = [a, b].map(|k| k as usize);
        if !along_side(rect, points[a], points[b]) {
            pieces.push([a, b]);
        }
    }
    for &k in ids.iter() {
        local_of[k as usize] = u32::MAX;
    }
    let start = out.len();
    if *ear_clipping && ear_clipped_cell(points, around, pieces, row, faces, out).is_some() {
        *ear_clipped += 1;
        for t in &mut out[start..] {
            *t = t.map(|k| ids[k as usize]);
        }
        return Ok(());
    }
    out.truncate(start);
    let edges: Vec<[usize; 2]> = (0..around.len())
        .map(|k| [around[k].1, around[(k + 1) % around.len()].1])
        .chain(pieces.iter().copied())
        .collect();
    let mut crossed = false;
    let cdt = ConstrainedDelaunayTriangulation::<Point2<f64>>::try_bulk_load_cdt(
        points
            .iter()
            .map(|p| spade::mitigate_underflow(Point2::new(p.x, p.y)))
            .collect(),
        edges,
        |_| crossed = true,
    )
    .map_err(|e| failed(format!("the triangulation failed: {e:?}")))?;
    if crossed || cdt.num_vertices() != points.len() {
        return Err(failed(format!(
            "two trim loops come closer than the tolerance near (u, v) = ({:.6}, {:.6}): choose a smaller tolerance",
            corners[0].x, corners[0].y
        )));
    }
    // Which triangles lie inside the loops: one ray for the largest triangle, then a flood
    // across the cell that flips at every constraint edge it crosses (the sides are
    // never crossed, so those are the chord pieces, or their parts where a point split one).
    let mut kept: Vec<Option<bool>> = vec![None; cdt.num_all_faces()];
    let mut queue = std::collections::VecDeque::new();
    let area = |face: &spade::handles::FaceHandle<'_, spade::handles::InnerTag, _, _, _, _>| {
        let [pa, pb, pc] = face.vertices().map(|v| points[v.fix().index()]);
        ((pb - pa).perp_dot(pc - pa), (pa + pb + pc) / 3.0)
    };
    // Seeds from the largest triangles first: a sliver's centroid may sit on a chord.
    let mut seeds: Vec<_> = cdt.inner_faces().map(|f| (area(&f).0.abs(), f)).collect();
    seeds.sort_by(|a, b| b.0.total_cmp(&a.0));
    for (twice, face) in seeds {
        if kept[face.fix().index()].is_some() || twice == 0.0 {
            continue;
        }
        kept[face.fix().index()] = Some(inside(row, area(&face).1));
        queue.push_back(face);
        while let Some(face) = queue.pop_front() {
            let here = kept[face.fix().index()].unwrap_or(false);
            for edge in face.adjacent_edges() {
                if let Some(next) = edge.rev().face().as_inner()
                    && kept[next.fix().index()].is_none()
                {
                    kept[next.fix().index()] = Some(here != edge.is_constraint_edge());
                    queue.push_back(next);
                }
            }
        }
    }
    for face in cdt.inner_faces() {
        let (twice, _) = area(&face);
        if twice == 0.0 || kept[face.fix().index()] != Some(true) {
            continue;
        }
        let [a, b, c] = face.vertices().map(|v| ids[v.fix().index()]);
        out.push(if twice > 0.0 { [a, b, c] } else { [a, c, b] });
    }
    Ok(())
}

/// Corners of a face turning by less than this sine are flat for [`clip_ears`].
const FLAT: f64 = 1e-9;
/// At most this many chord pieces in a cell are tested pairwise for crossings; a cell with more
/// goes to the constrained Delaunay triangulation.
const EAR_CLIP_PIECES: usize = 96;

/// The triangles (local indices into `points`, counter-clockwise) of a cut cell inside the
/// loops, for the common cell: the chord pieces (`pieces`) form chains from one side point to
/// another that neither cross nor touch, and cut the cell into faces, each traced around
/// (counter-clockwise: along the perimeter `around`, into a chain at its end, out at its
/// other end). The largest face is kept by the parity of the loops at its largest triangle's
/// centroid, the faces across a chain from a face have the other parity, and the kept faces are
/// triangulated by clipping ears ([`clip_ears`]). `None`, with `out` to be truncated by the caller, where the cell is not
/// of that kind (more than two pieces at a point, a chain touching a side between its ends, a
/// loop wholly inside, pieces that cross, a face without an ear), which the constrained
/// Delaunay triangulation handles.
fn ear_clipped_cell(
    points: &[DVec2],
    around: &[(f64, usize)],
    pieces: &[[usize; 2]],
    row: &RowChords,
    scratch: &mut FaceScratch,
    out: &mut Vec<[u32; 3]>,
) -> Option<()> {
    let n = points.len();
    if pieces.len() > EAR_CLIP_PIECES {
        return None;
    }
    // Where each point lies around the perimeter (usize::MAX: inside), and its chain neighbours.
    let perimeter_at = &mut scratch.perimeter_at;
    perimeter_at.clear();
    perimeter_at.resize(n, usize::MAX);
    for (k, &(_, p)) in around.iter().enumerate() {
        perimeter_at[p] = k;
    }
    let links = &mut scratch.links;
    links.clear();
    links.resize(n, [usize::MAX; 2]);
    for &[a, b] in pieces {
        if a == b {
            return None;
        }
        for (p, q) in [(a, b), (b, a)] {
            match links[p] {
                [x, _] if x == q => return None,
                [usize::MAX, _] => links[p][0] = q,
                [_, usize::MAX] => links[p][1] = q,
                _ => return None,
            }
        }
    }
    let degree = |p: usize| links[p].iter().filter(|&&q| q != usize::MAX).count();
    // Each chain from one end on the perimeter to the other.
    let (chain_to, between) = (&mut scratch.chain_to, &mut scratch.between);
    chain_to.clear();
    chain_to.resize(n, None);
    between.clear();
    for p in 0..n {
        let on_side = perimeter_at[p] != usize::MAX;
        match (on_side, degree(p)) {
            (true, 0) | (false, 2) => continue,
            (true, 1) => {}
            _ => return None,
        }
        if chain_to[p].is_some() {
            continue;
        }
        let first = between.len();
        let (mut previous, mut here) = (p, links[p][0]);
        while perimeter_at[here] == usize::MAX {
            between.push(here);
            let [x, y] = links[here];
            (previous, here) = (here, if x == previous { y } else { x });
            if between.len() > n {
                return None;
            }
        }
        let range = first..between.len();
        chain_to[here] = Some((p, range.clone(), true));
        chain_to[p] = Some((here, range, false));
    }
    let inner = perimeter_at.iter().filter(|&&k| k == usize::MAX).count();
    if between.len() != inner || pieces_cross(points, pieces) {
        return None;
    }
    // The faces, each traced from a perimeter edge not yet used; the chains each runs along.
    let m = around.len();
    let used = &mut scratch.used;
    used.clear();
    used.resize(m, false);
    let (corners, faces) = (&mut scratch.face, &mut scratch.faces);
    corners.clear();
    faces.clear();
    // (face, chain by its smaller end) for every chain a face runs along.
    scratch.sides_of.clear();
    for first in 0..m {
        if used[first] {
            continue;
        }
        let start = corners.len();
        let mut k = first;
        loop {
            if used[k] || corners.len() - start > n {
                return None;
            }
            used[k] = true;
            corners.push(around[k].1);
            let next = around[(k + 1) % m].1;
            k = match &chain_to[next] {
                Some((end, range, backwards)) => {
                    corners.push(next);
                    let stretch = &between[range.clone()];
                    if *backwards {
                        corners.extend(stretch.iter().rev());
                    } else {
                        corners.extend(stretch);
                    }
                    scratch.sides_of.push((faces.len(), next.min(*end)));
                    perimeter_at[*end]
                }
                None => (k + 1) % m,
            };
            if k == first {
                break;
            }
        }
        faces.push(start..corners.len());
    }
    // The largest face (by its area, the shoelace formula) is clipped first, and the parity of
    // the loops at the centroid of its largest triangle decides it; a small face's triangles
    // may all be slivers whose centroids sit on a chord.
    let twice_area = |range: &std::ops::Range<usize>| {
        let ring = &corners[range.clone()];
        (0..ring.len())
            .map(|k| points[ring[k]].perp_dot(points[ring[(k + 1) % ring.len()]]))
            .sum::<f64>()
    };
    let largest_face = faces
        .iter()
        .map(twice_area)
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(&b.1))?
        .0;
    let start = out.len();
    clip_ears(
        points,
        &corners[faces[largest_face].clone()],
        &mut scratch.clip,
        out,
    )?;
    let (twice, centroid) = out[start..]
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|k| points[k as usize]);
            ((b - a).perp_dot(c - a), (a + b + c) / 3.0)
        })
        .max_by(|a, b| a.0.total_cmp(&b.0))?;
    if twice <= 0.0 {
        return None;
    }
    // The parity flips across every chain.
    let kept = &mut scratch.kept;
    kept.clear();
    kept.resize(faces.len(), None);
    kept[largest_face] = Some(inside(row, centroid));
    let sides_of = &mut scratch.sides_of;
    sides_of.sort_unstable_by_key(|&(_, chain)| chain);
    let mut changed = true;
    while changed {
        changed = false;
        for pair in sides_of.chunks(2) {
            let [(f, c), (g, d)] = pair else {
                return None;
            };
            if c != d {
                return None;
            }
            match (kept[*f], kept[*g]) {
                (Some(x), Some(y)) if x == y => return None,
                (Some(x), None) => kept[*g] = Some(!x),
                (None, Some(y)) => kept[*f] = Some(!y),
                _ => continue,
            }
            changed = true;
        }
    }
    // The kept faces' triangles.
    if kept[largest_face] != Some(true) {
        out.truncate(start);
    }
    for (f, range) in faces.iter().enumerate() {
        match kept[f] {
            Some(true) if f != largest_face => {
                clip_ears(points, &corners[range.clone()], &mut scratch.clip, out)?;
            }
            Some(_) => {}
            None => return None,
        }
    }
    Some(())
}

/// Whether two of the chord pieces cross or touch anywhere but at a point they share (two
/// pieces of a chain meet at their shared point, and a piece folding back along the one before
/// it counts as touching).
fn pieces_cross(points: &[DVec2], pieces: &[[usize; 2]]) -> bool {
    let orient = |a: DVec2, b: DVec2, c: DVec2| (b - a).perp_dot(c - a);
    for (i, &[a, b]) in pieces.iter().enumerate() {
        let (pa, pb) = (points[a], points[b]);
        let (lo, hi) = (pa.min(pb), pa.max(pb));
        for &[c, d] in &pieces[i + 1..] {
            let (pc, pd) = (points[c], points[d]);
            if pc.max(pd).cmplt(lo).any() || pc.min(pd).cmpgt(hi).any() {
                continue;
            }
            let shared = [a, b].iter().filter(|&&x| x == c || x == d).count();
            let (o1, o2) = (orient(pa, pb, pc), orient(pa, pb, pd));
            let (o3, o4) = (orient(pc, pd, pa), orient(pc, pd, pb));
            let touches = match shared {
                // Sharing an end: they overlap only where both run from it along one line
                // the same way.
                1 => {
                    let s = if a == c || a == d { pa } else { pb };
                    let x = if s == pa { pb } else { pa };
                    let y = if s == pc { pd } else { pc };
                    o1 == 0.0 && o2 == 0.0 && (x - s).dot(y - s) > 0.0
                }
                0 => {
                    o1.signum() * o2.signum() <= 0.0
                        && o3.signum() * o4.signum() <= 0.0
                        && (o1 != 0.0 || o2 != 0.0 || o3 != 0.0 || o4 != 0.0 || {
                            // All on one line: do the spans overlap?
                            let axis = pb - pa;
                            let (s, t) = ((pc - pa).dot(axis), (pd - pa).dot(axis));
                            s.max(t) >= 0.0 && s.min(t) <= axis.length_squared()
                        })
                }
                _ => true,
            };
            if touches {
                return true;
            }
        }
    }
    false
}

/// The triangles of the simple counter-clockwise polygon `face` (indices into `points`) by
/// clipping ears: an ear is a corner turning left whose triangle holds no corner of the polygon
/// that does not turn left (only those can lie in it; Meisters, "Polygons have ears", 1975),
/// even on its sides, so no triangle has a corner in the middle of a side. The ear whose
/// triangle is least thin (largest area over its longest side squared) is clipped first; a
/// clip changes only its two neighbours' ears (a corner's triangle loses nothing it held), and
/// where no known ear is left every corner is looked at again. `None` where a polygon has no
/// ear before its last triangle.
fn clip_ears(
    points: &[DVec2],
    face: &[usize],
    scratch: &mut EarScratch,
    out: &mut Vec<[u32; 3]>,
) -> Option<()> {
    let m = face.len();
    if m < 3 {
        return None;
    }
    let at = |i: usize| points[face[i]];
    let EarScratch {
        prev,
        next,
        flat,
        shape,
        blocking,
    } = scratch;
    prev.clear();
    prev.extend((0..m).map(|i| (i + m - 1) % m));
    next.clear();
    next.extend((0..m).map(|i| (i + 1) % m));
    // Whether a corner turns left by more than FLAT (as a sine): a corner in a run of chord
    // points that rounding moved off their line is flat, neither an ear (its triangle would be
    // a sliver, whose centroid rounding may put on either side of the loop) nor convex.
    let turns_left = |prev: &[usize], next: &[usize], i: usize| {
        let (pa, pb, pc) = (at(prev[i]), at(i), at(next[i]));
        let longest = (pb - pa).length_squared().max((pc - pb).length_squared());
        (pb - pa).perp_dot(pc - pb) > FLAT * longest
    };
    // The corners that do not turn left, the only ones that can block an ear (`blocking`,
    // with `flat` telling which still do not: a clip only ever turns a corner convex, and
    // never clips one that is not).
    flat.clear();
    flat.extend((0..m).map(|i| !turns_left(prev, next, i)));
    blocking.clear();
    blocking.extend((0..m).filter(|&i| flat[i]));
    // The shape of corner i's ear (its doubled area over its longest side squared), or
    // NEG_INFINITY where it is not an ear.
    let ear_shape =
        |prev: &[usize], next: &[usize], flat: &[bool], blocking: &[usize], i: usize| {
            let (a, c) = (prev[i], next[i]);
            let (pa, pb, pc) = (at(a), at(i), at(c));
            let sides = [pb - pa, pc - pb, pa - pc];
            let lengths = sides.map(|d| d.length_squared());
            let longest = lengths[0].max(lengths[1]).max(lengths[2]);
            let twice = sides[0].perp_dot(pc - pa);
            if !(twice > FLAT * longest) {
                return f64::NEG_INFINITY;
            }
            // Held: inside the triangle, on it, or within FLAT of a side (so within FLAT times the
            // longest side of its bounding box).
            let margin = DVec2::splat(FLAT * longest.sqrt());
            let (lo, hi) = (pa.min(pb).min(pc) - margin, pa.max(pb).max(pc) + margin);
            let slack = lengths.map(|l| -FLAT * l);
            let holds = |p: DVec2| {
                !(p.cmplt(lo).any() || p.cmpgt(hi).any())
                    && sides[0].perp_dot(p - pa) >= slack[0]
                    && sides[1].perp_dot(p - pb) >= slack[1]
                    && sides[2].perp_dot(p - pc) >= slack[2]
            };
            let blocked = blocking
                .iter()
                .any(|&k| flat[k] && k != a && k != c && holds(at(k)));
            if blocked {
                return f64::NEG_INFINITY;
            }
            twice / longest
        };
    shape.clear();
    shape.extend((0..m).map(|i| ear_shape(prev, next, flat, blocking, i)));
    let mut left = m;
    let mut start = 0;
    let mut looked_again = false;
    while left > 3 {
        // The best ear, going round the corners left.
        let (mut best, mut k) = (start, next[start]);
        while k != start {
            if shape[k] > shape[best] {
                best = k;
            }
            k = next[k];
        }
        if shape[best] == f64::NEG_INFINITY {
            // A corner that turned convex may have freed an ear elsewhere: look once more.
            if looked_again {
                return None;
            }
            looked_again = true;
            let mut k = start;
            loop {
                shape[k] = ear_shape(prev, next, flat, blocking, k);
                k = next[k];
                if k == start {
                    break;
                }
            }
            continue;
        }
        looked_again = false;
        let (a, c) = (prev[best], next[best]);
        out.push([face[a], face[best], face[c]].map(|k| k as u32));
        left -= 1;
        next[a] = c;
        prev[c] = a;
        for k in [a, c] {
            flat[k] = flat[k] && !turns_left(prev, next, k);
        }
        for k in [a, c] {
            shape[k] = ear_shape(prev, next, flat, blocking, k);
        }
        start = c;
    }
    if ear_shape(prev, next, flat, &[], start) == f64::NEG_INFINITY {
        return None;
    }
    out.push([face[prev[start]], face[start], face[next[start]]].map(|k| k as u32));
    Some(())
}

/// The (u, v) points of a clipped grid (its crossings first, in the grid's order) and the
/// points and normals the tolerance check already evaluated at some of them (or nothing).
struct Vertices<'a> {
    uvs: &'a [DVec2],
    known: &'a [Known],
}

/// A vertex's point and unit normal, where the tolerance check evaluated it.
type Known = Option<(DVec3, DVec3)>;

/// The plan of the mesh on `triangles` of the vertices `uvs` (of which the first are `grid`'s
/// crossings, and `known` holds those the tolerance check evaluated): the grid is evaluated
/// where at least half of its crossings are used, and the rest of the work is [`mesh_from`]
/// (the plan owns the evaluator, so it outlives the trimmed surface it was made from).
fn planned_mesh(
    scattered: ScatteredEvaluator<'static>,
    grid: ParameterGrid,
    (uvs, known): (Vec<DVec2>, Vec<Known>),
    triangles: Vec<[u32; 3]>,
    curvature: bool,
) -> tess::GridPlan {
    let mut used = vec![u32::MAX; uvs.len()];
    let mut order = Vec::new();
    for t in &triangles {
        for &k in t {
            if used[k as usize] == u32::MAX {
                used[k as usize] = order.len() as u32;
                order.push(k as usize);
            }
        }
    }
    // The grid's crossings are the pool's first points, in the grid's order.
    let crossings = grid.us.len() * grid.vs.len();
    let on_grid = order.iter().filter(|&&k| k < crossings).count();
    let jobs = if 2 * on_grid >= crossings {
        vec![(scattered.surface().clone(), grid)]
    } else {
        Vec::new()
    };
    tess::GridPlan::new(jobs, curvature, move |_, values, _| {
        let evaluated = values
            .ok()
            .and_then(|mut values| values.pop())
            .filter(|values| {
                values.samples.len() == crossings
                    && (!curvature || values.curvatures.len() == values.samples.len())
            })
            .map(|values| {
                let mut curvatures = values.curvatures.into_iter();
                values
                    .samples
                    .into_iter()
                    .map(|s| (s, curvatures.next().unwrap_or_default()))
                    .collect()
            });
        let vertices = Vertices {
            uvs: &uvs,
            known: &known,
        };
        let mesh = mesh_from(
            &scattered,
            crossings,
            vertices,
            (&used, &order),
            triangles,
            curvature,
            evaluated,
        )?;
        Ok(vec![mesh])
    })
}

/// Positions, normals, normalised (u, v) and curvatures at `vertices`; unused vertices dropped
/// (`used`: each vertex's place in the mesh, `order`: the vertices in that order). Vertices on
/// the grid's `crossings` (most of them, where the holes are small against the surface) come
/// from `evaluated`, the whole grid's values from one call of a sampler (the kernel's SIMD
/// lanes, [`crate::NurbsSurface::tessellate_grid`], or the GPU's) where it has them; the chord
/// points, and every point where the grid was not evaluated, from the tolerance check where it
/// evaluated them, else one at a time from the surface's Bézier patches
/// ([`ScatteredEvaluator`]).
fn mesh_from(
    scattered: &ScatteredEvaluator<'_>,
    crossings: usize,
    Vertices {
        uvs: vertices,
        known,
    }: Vertices<'_>,
    (used, order): (&[u32], &[usize]),
    triangles: Vec<[u32; 3]>,
    curvature: bool,
    evaluated: Option<Vec<(GridSample, CurvatureValues)>>,
) -> Result<TriangleMesh, GeometryError> {
    let surface = scattered.surface();
    let crossing = |k: usize| (k < crossings).then_some(k);
    let [(u0, u1), (v0, v1)] = surface.domain();
    let mut mesh = TriangleMesh {
        positions: Vec::with_capacity(order.len()),
        normals: Vec::with_capacity(order.len()),
        uvs: Vec::with_capacity(order.len()),
        triangles: Vec::with_capacity(triangles.len()),
        ..TriangleMesh::default()
    };
    for &k in order {
        let p = vertices[k];
        let (u, v) = (p.x.clamp(u0, u1), p.y.clamp(v0, v1));
        if let Some((sample, values)) = crossing(k)
            .and_then(|at| evaluated.as_ref()?.get(at))
            .filter(|_| (u, v) == (p.x, p.y))
        {
            mesh.positions.push(sample.point);
            mesh.normals.push(sample.normal);
            if curvature {
                mesh.curvatures.push(*values);
            }
        } else if curvature {
            let local = surface.local_geometry(u, v)?;
            mesh.positions.push(local.derivatives.point);
            mesh.normals.push(local.normal);
            mesh.curvatures.push(local.curvature.values());
        } else {
            let (point, normal) = match known.get(k) {
                Some(&Some(known)) => known,
                _ => scattered.point_and_normal(DVec2::new(u, v))?,
            };
            mesh.positions.push(point);
            mesh.normals.push(normal);
        }
        mesh.uvs.push([(u - u0) / (u1 - u0), (v - v0) / (v1 - v0)]);
    }
    for t in triangles {
        let t = t.map(|k| used[k as usize]);
        let [a, b, c] = t.map(|k| mesh.positions[k as usize]);
        let (e1, e2) = (b - a, c - a);
        let scale = e1.length_squared().max(e2.length_squared());
        if e1.cross(e2).length() > 1e-12 * scale {
            mesh.triangles.push(t);
        }
    }
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::{random_bspline_surface, uniform};
    use crate::trim::piece::{
        MonotonePiece, bezier_point, chord_deviation_bound, distance_to_segment, monotone_pieces,
    };

    /// A random grid over [0, 1]²: 2 to 12 lines each way between the ends, unevenly spaced.
    fn random_grid(state: &mut u64) -> ParameterGrid {
        let lines = |state: &mut u64| {
            let n = 2 + (uniform(state) * 11.0) as usize;
            let mut out: Vec<f64> = (0..n).map(|_| uniform(state)).collect();
            out.extend([0.0, 1.0]);
            out.sort_by(f64::total_cmp);
            out.dedup_by(|a, b| (*a - *b).abs() < 1e-3);
            *out.last_mut().unwrap() = 1.0;
            out
        };
        ParameterGrid {
            us: lines(state),
            vs: lines(state),
        }
    }

    /// Star-shaped loops in discs apart from each other (so the loops neither cross nor touch):
    /// big ones across many cells, small ones inside one, some with corners on grid lines and
    /// crossings; and sometimes the domain's boundary.
    fn random_loops(state: &mut u64, grid: &ParameterGrid) -> Vec<Vec<DVec2>> {
        let mut discs: Vec<(DVec2, f64)> = Vec::new();
        let mut loops = Vec::new();
        if uniform(state) < 0.5 {
            loops.push(vec![
                DVec2::ZERO,
                DVec2::new(1.0, 0.0),
                DVec2::ONE,
                DVec2::new(0.0, 1.0),
            ]);
        }
        for _ in 0..12 {
            let r = 0.01 + 0.3 * uniform(state).powi(2);
            let c = DVec2::new(uniform(state), uniform(state)) * (1.0 - 2.2 * r) + 1.1 * r;
            if discs
                .iter()
                .any(|&(d, s)| (d - c).length() < 1.05 * (r + s))
            {
                continue;
            }
            discs.push((c, r));
            let n = 3 + (uniform(state) * 40.0) as usize;
            let turn = uniform(state) * std::f64::consts::TAU;
            let mut poly: Vec<DVec2> = (0..n)
                .map(|k| {
                    let a = turn + k as f64 * std::f64::consts::TAU / n as f64;
                    c + DVec2::from_angle(a) * r * (0.4 + 0.6 * uniform(state))
                })
                .collect();
            // Corners near grid lines moved onto them, or onto a crossing (moved little, so
            // the loop stays simple).
            for p in poly.iter_mut() {
                let pick = |lines: &[f64], x: f64| {
                    let k = lines.partition_point(|&l| l < x).min(lines.len() - 1);
                    if (lines[k] - x).abs() < 0.1 * r {
                        lines[k]
                    } else {
                        x
                    }
                };
                let roll = uniform(state);
                if roll < 0.2 {
                    p.x = pick(&grid.us, p.x);
                } else if roll < 0.4 {
                    p.y = pick(&grid.vs, p.y);
                } else if roll < 0.5 {
                    *p = DVec2::new(pick(&grid.us, p.x), pick(&grid.vs, p.y));
                }
            }
            if uniform(state) < 0.5 {
                poly.reverse();
            }
            loops.push(poly);
        }
        loops
    }

    /// The directed edges of `triangles` without their reverse among them, sorted: the
    /// boundary of the region they cover.
    fn boundary(triangles: &[[u32; 3]]) -> Vec<[u32; 2]> {
        let edges: Vec<[u32; 2]> = triangles
            .iter()
            .flat_map(|t| [[t[0], t[1]], [t[1], t[2]], [t[2], t[0]]])
            .collect();
        let set: std::collections::HashSet<[u32; 2]> = edges.iter().copied().collect();
        let mut out: Vec<[u32; 2]> = edges
            .into_iter()
            .filter(|&[a, b]| !set.contains(&[b, a]))
            .collect();
        out.sort_unstable();
        out
    }

    #[test]
    fn ear_clipped_cells_cover_what_the_constrained_triangulation_covers() {
        let (mut cut_cells, mut clipped) = (0, 0);
        for seed in 0..60u64 {
            let mut state = seed;
            let grid = random_grid(&mut state);
            let loops = random_loops(&mut state, &grid);
            let fast = clip_grid_with(&grid, &loops, true).unwrap();
            let reference = clip_grid_with(&grid, &loops, false).unwrap();
            assert_eq!(fast.points, reference.points, "seed {seed}");
            assert_eq!(fast.cut.len(), reference.cut.len(), "seed {seed}");
            cut_cells += fast.cut.len();
            clipped += fast.ear_clipped;
            let area = |t: &[u32; 3]| {
                let [a, b, c] = t.map(|k| fast.points[k as usize]);
                (b - a).perp_dot(c - a) / 2.0
            };
            for (&(s0, e0, cell), &(s1, e1, other)) in fast.cut.iter().zip(&reference.cut) {
                assert_eq!(cell, other, "seed {seed}");
                let (ours, theirs) = (&fast.triangles[s0..e0], &reference.triangles[s1..e1]);
                assert!(
                    ours.iter().all(|t| area(t) > 0.0),
                    "seed {seed} cell {cell:?}"
                );
                let [i, j] = cell;
                let size = (grid.us[i + 1] - grid.us[i]) * (grid.vs[j + 1] - grid.vs[j]);
                let (a, b) = (
                    ours.iter().map(area).sum::<f64>(),
                    theirs.iter().map(area).sum::<f64>(),
                );
                assert!(
                    (a - b).abs() <= 1e-12 * size,
                    "seed {seed} cell {cell:?}: {a} vs {b}"
                );
                assert_eq!(
                    boundary(ours),
                    boundary(theirs),
                    "seed {seed} cell {cell:?}"
                );
            }
            // The cells no chord cuts are the same two triangles, or none.
            let whole = |g: &ClippedGrid| {
                let mut cut = vec![false; g.triangles.len()];
                for &(s, e, _) in &g.cut {
                    cut[s..e].iter_mut().for_each(|c| *c = true);
                }
                let mut out: Vec<[u32; 3]> = (0..g.triangles.len())
                    .filter(|&k| !cut[k])
                    .map(|k| g.triangles[k])
                    .collect();
                out.sort_unstable();
                out
            };
            assert_eq!(whole(&fast), whole(&reference), "seed {seed}");
        }
        eprintln!("{clipped} of {cut_cells} cut cells ear-clipped");
        // Most cut cells take the ear-clipped path; the rest (loops wholly inside a cell,
        // chains touching a side) the constrained triangulation.
        assert!(clipped > cut_cells / 2, "{clipped} of {cut_cells}");
        assert!(clipped < cut_cells, "{clipped} of {cut_cells}");
    }

    #[test]
    fn the_search_from_a_hint_is_the_binary_search() {
        let mut state = 3;
        for _ in 0..200 {
            let grid = random_grid(&mut state);
            let lines = &grid.us;
            let mut hint = (uniform(&mut state) * 20.0) as usize;
            for _ in 0..50 {
                // Near the last, far from it, on a line, beyond the ends.
                let x = match (uniform(&mut state) * 4.0) as usize {
                    0 => lines[(uniform(&mut state) * lines.len() as f64) as usize],
                    1 => uniform(&mut state) * 1.4 - 0.2,
                    _ => uniform(&mut state),
                };
                let expected = lines.partition_point(|&l| l < x);
                assert_eq!(below(lines, x, &mut hint), expected, "{x} in {lines:?}");
                assert_eq!(hint, expected);
            }
        }
    }

    #[test]
    fn a_face_without_an_ear_or_with_crossing_pieces_is_refused() {
        let square = [
            DVec2::ZERO,
            DVec2::new(1.0, 0.0),
            DVec2::ONE,
            DVec2::new(0.0, 1.0),
        ];
        let mut out = Vec::new();
        let mut scratch = EarScratch::default();
        // A square, with a flat corner in the middle of a side: two triangles, neither thin.
        let mut points = square.to_vec();
        points.push(DVec2::new(0.5, 0.0));
        clip_ears(&points, &[0, 4, 1, 2, 3], &mut scratch, &mut out).unwrap();
        assert_eq!(out.len(), 3);
        // All on one line: no ear.
        let line = [DVec2::ZERO, DVec2::new(1.0, 0.0), DVec2::new(2.0, 0.0)];
        assert!(clip_ears(&line, &[0, 1, 2], &mut scratch, &mut out).is_none());
        // Clockwise: no ear either.
        assert!(clip_ears(&square, &[3, 2, 1, 0], &mut scratch, &mut out).is_none());
        // Crossing diagonals, pieces folding back, and a chain continuing straight on.
        assert!(pieces_cross(&square, &[[0, 2], [1, 3]]));
        assert!(!pieces_cross(&square, &[[0, 1], [2, 3]]));
        let run = [DVec2::ZERO, DVec2::new(1.0, 0.0), DVec2::new(2.0, 0.0)];
        assert!(!pieces_cross(&run, &[[0, 1], [1, 2]]));
        assert!(pieces_cross(&run, &[[0, 2], [1, 2]]));
        assert!(pieces_cross(&run, &[[0, 2], [0, 1]]));
    }

    /// The box of the Bézier patch holding a random point of the surface's domain.
    fn random_patch_box(state: &mut u64, surface: &crate::NurbsSurface) -> (DVec2, DVec2) {
        let [bu, bv] = [crate::Direction::U, crate::Direction::V].map(|d| surface.span_breaks(d));
        let pick = |b: &[f64], x: f64| {
            let k = ((x * (b.len() - 1) as f64) as usize).min(b.len() - 2);
            (b[k], b[k + 1])
        };
        let ((u0, u1), (v0, v1)) = (pick(&bu, uniform(state)), pick(&bv, uniform(state)));
        (DVec2::new(u0, v0), DVec2::new(u1, v1))
    }

    #[test]
    fn the_interpolation_bound_holds_on_triangles_and_segments() {
        let mut state = 3;
        for seed in 0..80 {
            let surface = random_bspline_surface(&mut state, seed % 2 == 0);
            let eval = surface.scattered_evaluator();
            let (lo, hi) = random_patch_box(&mut state, &surface);
            let mut random_point =
                || lo + (hi - lo) * DVec2::new(uniform(&mut state), uniform(&mut state));
            let mut corners = [random_point(), random_point(), random_point()];
            if seed % 5 == 0 {
                // Nearly flat.
                corners[2] = corners[0].lerp(corners[1], 0.3) + (corners[2] - corners[0]) * 1e-3;
            }
            let box_lo = corners[0].min(corners[1]).min(corners[2]);
            let box_hi = corners[0].max(corners[1]).max(corners[2]);
            let bounds = eval.derivative_bounds(box_lo, box_hi).unwrap();
            let scale = bounds.metric();
            let at = |p: DVec2| surface.point_at_clamped(p).unwrap();
            let images = corners.map(at);
            let slack = 1e-12 * surface.size();
            // The triangle, on a barycentric lattice.
            let bound = interpolation_error(&corners.map(|p| p * scale));
            let n = 12;
            for i in 0..=n {
                for j in 0..=n - i {
                    let l = [i as f64, j as f64, (n - i - j) as f64].map(|x| x / n as f64);
                    let x = corners[0] * l[0] + corners[1] * l[1] + corners[2] * l[2];
                    let flat = images[0] * l[0] + images[1] * l[1] + images[2] * l[2];
                    let off = at(x).distance(flat);
                    assert!(off <= bound + slack, "seed {seed}: {off} > {bound}");
                }
            }
            // Each side.
            for k in 0..3 {
                let (p, q) = (corners[k], corners[(k + 1) % 3]);
                let bound = interpolation_error(&[p * scale, q * scale]);
                for i in 0..=16 {
                    let t = i as f64 / 16.0;
                    let off = at(p.lerp(q, t)).distance(images[k].lerp(images[(k + 1) % 3], t));
                    assert!(off <= bound + slack, "seed {seed}: side {off} > {bound}");
                }
            }
        }
    }

    /// A random cubic trim curve (weighted where `weighted`) inside the box from `lo` to `hi`.
    fn random_cubic(state: &mut u64, lo: DVec2, hi: DVec2, weighted: bool) -> crate::TrimCurve {
        let points = (0..4)
            .map(|_| lo + (hi - lo) * DVec2::new(uniform(state), uniform(state)))
            .collect();
        let weights = weighted.then(|| (0..4).map(|_| 0.3 + 3.0 * uniform(state)).collect());
        let knots = vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0];
        crate::TrimCurve::new(3, knots, points, weights).unwrap()
    }

    #[test]
    fn the_chord_bound_holds_on_monotone_pieces() {
        let mut state = 17;
        for seed in 0..80 {
            let surface = random_bspline_surface(&mut state, seed % 2 == 0);
            let eval = surface.scattered_evaluator();
            let (lo, hi) = random_patch_box(&mut state, &surface);
            let curve = random_cubic(&mut state, lo, hi, seed % 3 == 0);
            let at = |p: DVec2| surface.point_at_clamped(p).unwrap();
            for piece in monotone_pieces(&curve, (0, 0)) {
                let speeds = piece.derivative_bounds().unwrap();
                for _ in 0..4 {
                    let (x, y) = (uniform(&mut state), uniform(&mut state));
                    let (t0, t1) = (x.min(y), x.max(y));
                    let (a, b) = (
                        bezier_point(&piece.points, t0),
                        bezier_point(&piece.points, t1),
                    );
                    let bounds = eval.derivative_bounds(a.min(b), a.max(b)).unwrap();
                    let bound = chord_deviation_bound(t1 - t0, speeds, bounds);
                    let (sa, sb) = (at(a), at(b));
                    for i in 0..=16 {
                        let t = t0 + (t1 - t0) * i as f64 / 16.0;
                        let off = distance_to_segment(at(bezier_point(&piece.points, t)), sa, sb);
                        assert!(
                            off <= bound + 1e-12 * surface.size(),
                            "seed {seed}: {off} > {bound}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn the_bounds_leave_the_flattening_and_the_check_unchanged() {
        let mut state = 29;
        let (mut skipped, mut flattened) = (0, [0usize; 2]);
        for seed in 0..40 {
            let surface = random_bspline_surface(&mut state, seed % 2 == 0);
            let tolerance = surface.size() * 10f64.powf(-2.0 - 1.5 * uniform(&mut state));
            let eval = surface.scattered_evaluator();
            let bounds = |lo, hi| eval.derivative_bounds(lo, hi);
            let none = |_, _| None;
            // The flattening of random curves across the domain.
            let count = std::cell::Cell::new(0);
            let map = |p: DVec2| {
                count.set(count.get() + 1);
                eval.point(p)
            };
            let curves: Vec<Vec<MonotonePiece>> = (0..6)
                .map(|k| {
                    let curve = random_cubic(&mut state, DVec2::ZERO, DVec2::ONE, k % 2 == 0);
                    monotone_pieces(&curve, (0, k))
                })
                .collect();
            let mut flatten = |bounds: &dyn Fn(DVec2, DVec2) -> Option<DerivativeBounds>,
                               k: usize| {
                count.set(0);
                let slices = curves.iter().map(Vec::as_slice);
                let out = flatten_pieces_mapped(slices, tolerance, SURFACE_DEPTHS, map, bounds);
                flattened[k] += count.get();
                out.unwrap()
            };
            assert_eq!(flatten(&bounds, 0), flatten(&none, 1), "seed {seed}");
            // The check of a clipped tolerance grid.
            let grid = tess::grid_for(&surface, Tessellation::Tolerance(tolerance)).unwrap();
            let loops = random_loops(&mut state, &grid);
            let clipped = clip_grid(&grid, &loops).unwrap();
            let normals = seed % 3 != 0;
            let (failing, known) = clipped
                .failing_cells(&grid, &eval, bounds, tolerance, normals)
                .unwrap();
            let (all_failing, all_known) = clipped
                .failing_cells(&grid, &eval, none, tolerance, normals)
                .unwrap();
            assert_eq!(failing, all_failing, "seed {seed}");
            for (ours, theirs) in known.iter().zip(&all_known) {
                match ours {
                    Some(k) => assert_eq!(Some(*k), *theirs, "seed {seed}"),
                    None => skipped += usize::from(theirs.is_some()),
                }
            }
        }
        // The bounds did spare samples.
        assert!(
            skipped > 0 && flattened[0] < flattened[1],
            "{skipped} {flattened:?}"
        );
    }
}
