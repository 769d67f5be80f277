//! Export tessellation of a trimmed surface: the untrimmed surface's parameter grid
//! ([`crate::tess::grid_for`]) clipped by the trim loops.
//!
//! The trim loops are flattened so that every boundary chord stays within a quarter of the
//! tolerance of the trim curve on the surface, then split where they cross the grid's lines, so
//! that every piece lies in one cell. A cell no chord touches is kept whole (its two triangles)
//! or dropped, by the parity of its centre; a cell a chord cuts is triangulated on its own (a
//! constrained Delaunay triangulation, spade, of its corners, the chord points in it and the
//! crossings on its sides) and keeps the triangles whose centroids lie inside the loops.
//! Neighbouring cells see the same points on the side they share, so the mesh has no cracks.
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
use crate::diffgeo::CurvatureValues;
use crate::surface::GridSample;
use crate::tess::{self, GridSampler, MAX_TRIANGLES, ParameterGrid, Tessellation, TriangleMesh};
use crate::{GeometryError, NurbsSurface};

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
    let surface = trimmed.surface();
    let on_surface = |p: DVec2| surface.point_at_clamped(p);
    let pieces = trimmed.monotone_pieces();
    let mut out = Vec::new();
    for lp in pieces.chunk_by(|a, b| a.source.0 == b.source.0) {
        let curves = lp.chunk_by(|a, b| a.source.1 == b.source.1);
        let (polygon, _) = flatten_pieces_mapped(curves, tolerance, SURFACE_DEPTHS, on_surface)?;
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
    let polygons = flatten_on_surface(trimmed, BOUNDARY_SHARE * tolerance)?;
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
        let failing = if checked && round <= REFINE_ROUNDS {
            clipped.failing_cells(surface, tolerance)?
        } else {
            Vec::new()
        };
        if failing.is_empty() {
            return mesh_from(
                surface,
                &grid,
                &clipped.points,
                clipped.triangles,
                curvature,
                sampler,
            );
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
}

impl ClippedGrid {
    /// The cut cells where a triangle's centroid or an edge midpoint lies farther than
    /// `tolerance` from the surface at the same (u, v) (an upper bound of its distance). Each
    /// point is evaluated once, and each edge's midpoint once for the two triangles sharing it.
    fn failing_cells(
        &self,
        surface: &NurbsSurface,
        tolerance: f64,
    ) -> Result<Vec<[usize; 2]>, GeometryError> {
        let mut positions: Vec<Option<DVec3>> = vec![None; self.points.len()];
        let mut edges: HashMap<[u32; 2], f64> = HashMap::default();
        let mut failing = Vec::new();
        for &(start, end, cell) in &self.cut {
            for t in &self.triangles[start..end] {
                let mut corners = [DVec3::ZERO; 3];
                for (slot, &k) in corners.iter_mut().zip(t) {
                    *slot = match positions[k as usize] {
                        Some(p) => p,
                        None => {
                            let p = surface.point_at_clamped(self.points[k as usize])?;
                            positions[k as usize] = Some(p);
                            p
                        }
                    };
                }
                let uv = t.map(|k| self.points[k as usize]);
                let centroid = (uv[0] + uv[1] + uv[2]) / 3.0;
                let flat = (corners[0] + corners[1] + corners[2]) / 3.0;
                let mut worst = (surface.point_at_clamped(centroid)? - flat).length();
                for (a, b) in [(0, 1), (1, 2), (2, 0)] {
                    let key = [t[a].min(t[b]), t[a].max(t[b])];
                    let deviation = match edges.get(&key) {
                        Some(&d) => d,
                        None => {
                            let m = surface.point_at_clamped(0.5 * (uv[a] + uv[b]))?;
                            let d = (m - 0.5 * (corners[a] + corners[b])).length();
                            edges.insert(key, d);
                            d
                        }
                    };
                    worst = worst.max(deviation);
                }
                if worst > tolerance {
                    failing.push(cell);
                    break;
                }
            }
        }
        Ok(failing)
    }
}

/// The (u, v) points of a clipped grid, each stored once (by its exact coordinates).
#[derive(Default)]
struct PointPool {
    points: Vec<DVec2>,
    index: HashMap<[u64; 2], u32>,
}

impl PointPool {
    fn id(&mut self, p: DVec2) -> u32 {
        let key = [p.x.to_bits(), p.y.to_bits()];
        *self.index.entry(key).or_insert_with(|| {
            self.points.push(p);
            (self.points.len() - 1) as u32
        })
    }
}

/// What the chords leave in one cell: the points on it or in it, and the chord pieces.
#[derive(Default)]
struct CellCut {
    points: Vec<u32>,
    pieces: Vec<[u32; 2]>,
}

/// `x` moved onto the nearest of the sorted `lines` when it lies within `snap` of it.
fn snap_to(lines: &[f64], x: f64, snap: f64) -> f64 {
    let k = lines.partition_point(|&l| l < x);
    [k.checked_sub(1), Some(k)]
        .into_iter()
        .flatten()
        .filter_map(|k| lines.get(k))
        .find(|&&l| (l - x).abs() <= snap)
        .copied()
        .unwrap_or(x)
}

/// The cells (spans of the sorted `lines`) whose closed interval holds x: two where x lies on
/// an inner line, one elsewhere.
fn spans_holding(lines: &[f64], x: f64) -> std::ops::RangeInclusive<usize> {
    let last = lines.len() - 2;
    let k = lines.partition_point(|&l| l < x);
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
    polygons
        .iter()
        .map(|poly| {
            let mut out: Vec<DVec2> = Vec::with_capacity(poly.len());
            for p in poly {
                let q = DVec2::new(snap_to(&grid.us, p.x, snap), snap_to(&grid.vs, p.y, snap));
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
/// line lie exactly on it).
fn chord_points(grid: &ParameterGrid, a: DVec2, b: DVec2, snap: f64) -> Vec<DVec2> {
    let mut out = vec![(0.0, a), (1.0, b)];
    let crossings = |lines: &[f64], from: f64, to: f64| {
        let (lo, hi) = (from.min(to), from.max(to));
        let start = lines.partition_point(|&l| l <= lo);
        let end = lines.partition_point(|&l| l < hi);
        lines[start..end.max(start)].to_vec()
    };
    for u in crossings(&grid.us, a.x, b.x) {
        let t = (u - a.x) / (b.x - a.x);
        let v = snap_to(&grid.vs, a.y + t * (b.y - a.y), snap);
        out.push((t, DVec2::new(u, v)));
    }
    for v in crossings(&grid.vs, a.y, b.y) {
        let t = (v - a.y) / (b.y - a.y);
        let u = snap_to(&grid.us, a.x + t * (b.x - a.x), snap);
        out.push((t, DVec2::new(u, v)));
    }
    out.sort_by(|p, q| p.0.total_cmp(&q.0));
    let mut points: Vec<DVec2> = out.into_iter().map(|(_, p)| p).collect();
    points.dedup();
    points
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
    let mut rows = vec![Vec::new(); grid.vs.len() - 1];
    for poly in polygons {
        for k in 0..poly.len() {
            let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
            let first = *spans_holding(&grid.vs, a.y.min(b.y)).start();
            let last = *spans_holding(&grid.vs, a.y.max(b.y)).end();
            for row in &mut rows[first..=last] {
                row.push([a, b]);
            }
        }
    }
    rows.into_iter()
        .map(|mut chords: Vec<[DVec2; 2]>| {
            chords.sort_by(|p, q| p[0].x.max(p[1].x).total_cmp(&q[0].x.max(q[1].x)));
            RowChords {
                right: chords.iter().map(|c| c[0].x.max(c[1].x)).collect(),
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
    let (us, vs) = (&grid.us, &grid.vs);
    // Points within SNAP of the domain's size from a grid line are moved onto it.
    let snap = SNAP * (us[us.len() - 1] - us[0]).max(vs[vs.len() - 1] - vs[0]);
    let polygons = snapped(grid, polygons, snap);
    let mut pool = PointPool::default();
    // The cut of cell (i, j) at i * rows + j.
    let rows_count = vs.len() - 1;
    let mut cuts: Vec<CellCut> = Vec::new();
    cuts.resize_with((us.len() - 1) * rows_count, CellCut::default);
    for poly in &polygons {
        for k in 0..poly.len() {
            let points = chord_points(grid, poly[k], poly[(k + 1) % poly.len()], snap);
            let ids: Vec<u32> = points.iter().map(|&p| pool.id(p)).collect();
            for (&p, &id) in points.iter().zip(&ids) {
                for i in spans_holding(us, p.x) {
                    for j in spans_holding(vs, p.y) {
                        cuts[i * rows_count + j].points.push(id);
                    }
                }
            }
            for (w, pair) in points.windows(2).zip(ids.windows(2)) {
                let m = 0.5 * (w[0] + w[1]);
                for i in spans_holding(us, m.x) {
                    for j in spans_holding(vs, m.y) {
                        cuts[i * rows_count + j].pieces.push([pair[0], pair[1]]);
                    }
                }
            }
        }
    }
    let rows = chords_by_row(grid, &polygons);
    let mut triangles = Vec::new();
    let mut cut = Vec::new();
    for i in 0..us.len() - 1 {
        for j in 0..vs.len() - 1 {
            let rect = [us[i], us[i + 1], vs[j], vs[j + 1]];
            let corners = corners_of(rect);
            let cell = &cuts[i * rows_count + j];
            match Some(cell).filter(|c| c.cuts(&pool.points, rect)) {
                Some(cell) => {
                    let start = triangles.len();
                    triangulate_cell(&mut pool, cell, rect, &rows[j], &mut triangles)?;
                    cut.push((start, triangles.len(), [i, j]));
                }
                None => {
                    if inside(&rows[j], 0.5 * (corners[0] + corners[2])) {
                        let [c00, c10, c11, c01] = corners.map(|p| pool.id(p));
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

impl CellCut {
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

/// The triangles of one cut cell inside the loops: a constrained Delaunay triangulation of its
/// corners and chord points, the cell's sides and the chord pieces fixed.
fn triangulate_cell(
    pool: &mut PointPool,
    cell: &CellCut,
    rect: [f64; 4],
    row: &RowChords,
    out: &mut Vec<[u32; 3]>,
) -> Result<(), GeometryError> {
    let corners = corners_of(rect);
    let mut ids: Vec<u32> = corners.iter().map(|&p| pool.id(p)).collect();
    for &k in &cell.points {
        if !ids.contains(&k) {
            ids.push(k);
        }
    }
    // A cell holds a few points: a linear search finds a point's place in it.
    let local = |k: u32| ids.iter().position(|&x| x == k);
    let points: Vec<DVec2> = ids.iter().map(|&k| pool.points[k as usize]).collect();
    // The sides: consecutive points around the perimeter.
    let mut around: Vec<(f64, usize)> = points
        .iter()
        .enumerate()
        .filter_map(|(n, &p)| perimeter_position(corners, p).map(|s| (s, n)))
        .collect();
    around.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut edges: Vec<[usize; 2]> = (0..around.len())
        .map(|k| [around[k].1, around[(k + 1) % around.len()].1])
        .collect();
    for &[a, b] in &cell.pieces {
        let (Some(a), Some(b)) = (local(a), local(b)) else {
            continue;
        };
        if !along_side(rect, points[a], points[b]) {
            edges.push([a, b]);
        }
    }
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

/// Positions, normals, normalised (u, v) and curvatures at `vertices`; unused vertices dropped.
/// Vertices on the crossings of `grid` (most of them, where the holes are small against the
/// surface) come from one evaluation of the whole grid by `sampler` (the kernel's SIMD lanes,
/// [`NurbsSurface::tessellate_grid`], or the GPU's); the chord points, and every point where
/// less than half the grid is used, one at a time from the kernel.
fn mesh_from(
    surface: &NurbsSurface,
    grid: &ParameterGrid,
    vertices: &[DVec2],
    triangles: Vec<[u32; 3]>,
    curvature: bool,
    sampler: &dyn GridSampler,
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
    let crossing = |p: DVec2| -> Option<usize> {
        let i = grid.us.binary_search_by(|u| u.total_cmp(&p.x)).ok()?;
        let j = grid.vs.binary_search_by(|v| v.total_cmp(&p.y)).ok()?;
        Some(i * grid.vs.len() + j)
    };
    let on_grid = order
        .iter()
        .filter(|&&k| crossing(vertices[k]).is_some())
        .count();
    let evaluated: Option<Vec<(GridSample, CurvatureValues)>> =
        if 2 * on_grid >= grid.us.len() * grid.vs.len() {
            sampler
                .sample_grids(&[(surface, grid)], curvature)
                .ok()
                .and_then(|mut values| values.pop())
                .filter(|values| {
                    values.samples.len() == grid.us.len() * grid.vs.len()
                        && (!curvature || values.curvatures.len() == values.samples.len())
                })
                .map(|values| {
                    let mut curvatures = values.curvatures.into_iter();
                    values
                        .samples
                        .into_iter()
                        .map(|s| (s, curvatures.next().unwrap_or_default()))
                        .collect()
                })
        } else {
            None
        };
    let [(u0, u1), (v0, v1)] = surface.domain();
    let mut mesh = TriangleMesh::default();
    for &k in &order {
        let p = vertices[k];
        let (u, v) = (p.x.clamp(u0, u1), p.y.clamp(v0, v1));
        if let Some((sample, values)) = crossing(p)
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
            let d = surface.evaluate(u, v)?;
            mesh.normals.push(surface.normal_from(&d, u, v));
            mesh.positions.push(d.point);
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
