//! The acceleration structure that makes classifying a point against the trim loops cost the
//! same however many curves a surface has: a grid of cells over the domain, each listing the
//! monotone pieces that pass through it and holding one reference point whose side (kept or
//! trimmed) is known. A point is classified by the crossing parity of the short L-shaped path
//! from it to its cell's reference point against the cell's few pieces. The reference points'
//! sides are found the same way, cell to neighbouring cell, starting left of the domain where
//! every point is outside. The fragment shader reads this structure (packed by
//! `gpu::trim_buffer`) and runs the same test.

use std::sync::Arc;

use glam::DVec2;

use super::piece::{MonotonePiece, distance_to_segment, path_parity};

/// The most cells per direction.
const MAX_CELLS: usize = 256;
/// Cells per monotone piece the grid aims at.
const CELLS_PER_PIECE: f64 = 4.0;
/// Reference point candidates in a cell, as fractions of its size.
const CANDIDATES: [(f64, f64); 6] = [
    (0.5, 0.5),
    (0.37, 0.61),
    (0.71, 0.29),
    (0.23, 0.83),
    (0.81, 0.77),
    (0.17, 0.19),
];

/// Chord tolerance of the polygons [`TrimIndex::build`] lists and places by, as a fraction of
/// a cell's smaller side (at least 1e-6 of the domain's longer side).
const CELL_FLATTEN: f64 = 5e-3;

/// Of `candidates`, the one farthest from every segment of `chords` (the last of equals), or
/// `None` where there are no candidates. A candidate stops being measured once it comes
/// closer to a chord than the best before it: it cannot be chosen then.
fn clearest<'a>(
    candidates: impl Iterator<Item = DVec2>,
    chords: impl Iterator<Item = &'a [DVec2]> + Clone,
) -> Option<DVec2> {
    let mut best: Option<(DVec2, f64)> = None;
    for p in candidates {
        let floor = best.map_or(f64::NEG_INFINITY, |(_, c)| c);
        let mut clearance = f64::INFINITY;
        for w in chords.clone() {
            clearance = clearance.min(distance_to_segment(p, w[0], w[1]));
            if clearance < floor {
                break;
            }
        }
        if clearance >= floor {
            best = Some((p, clearance));
        }
    }
    best.map(|(p, _)| p)
}

/// One grid cell.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cell {
    /// A point of the cell away from every curve.
    pub reference: DVec2,
    /// Whether `reference` is in the kept region.
    pub inside: bool,
    /// The cell's pieces: `lists[first..first + count]`.
    pub first: u32,
    pub count: u32,
}

/// How a rectangle of the domain (a Bézier patch) lies against the trim loops.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Coverage {
    /// Wholly kept: no test needed.
    Inside,
    /// Wholly trimmed away: neither evaluated nor drawn.
    Outside,
    /// A trim curve passes through it.
    Partial,
}

/// The grid over one surface's domain.
#[derive(Debug, Clone, PartialEq)]
pub struct TrimIndex {
    /// (u0, u1, v0, v1).
    pub domain: [f64; 4],
    /// Cells along u and along v; cell (i, j) is `cells[j * cells_u + i]`.
    pub cells_u: usize,
    pub cells_v: usize,
    pub cells: Vec<Cell>,
    /// Piece indices of every cell, cell after cell.
    pub lists: Vec<u32>,
    /// Every loop's monotone pieces, loop by loop and curve by curve (shared with the trimmed
    /// surface they came from).
    pub pieces: Arc<[MonotonePiece]>,
}

impl TrimIndex {
    /// The grid over `domain` for `pieces`. Each piece is flattened to chords within
    /// [`CELL_FLATTEN`] of a cell's smaller side and listed in every cell its chords' boxes
    /// touch. The arc between two points of a monotone piece lies in the box they span, so
    /// those cells hold every cell the piece passes through at any tolerance (a superset is
    /// all the parity test asks); the boxes are widened by twice the tolerance against
    /// rounding, the shader's f32 look-up of a point's cell included. The tolerance only
    /// decides how few cells beyond those are listed, and how well the reference points are
    /// placed (by their distance from the chords): no finer polygon is needed.
    pub fn build(domain: [f64; 4], pieces: Arc<[MonotonePiece]>) -> Self {
        let per_side =
            ((pieces.len() as f64 * CELLS_PER_PIECE).sqrt().ceil() as usize).clamp(1, MAX_CELLS);
        let (cells_u, cells_v) = (per_side, per_side);
        let [u0, u1, v0, v1] = domain;
        let (du, dv) = ((u1 - u0) / cells_u as f64, (v1 - v0) / cells_v as f64);
        let cell_of = |p: DVec2| -> (usize, usize) {
            let i = ((p.x - u0) / du).floor().clamp(0.0, (cells_u - 1) as f64) as usize;
            let j = ((p.y - v0) / dv).floor().clamp(0.0, (cells_v - 1) as f64) as usize;
            (i, j)
        };
        // Never finer than 1e-6 of the domain's longer side: a long thin domain's short cells
        // would otherwise ask for millions of chords.
        let tolerance = (CELL_FLATTEN * du.abs().min(dv.abs()))
            .max(1e-6 * (u1 - u0).abs().max((v1 - v0).abs()));
        let flat: Vec<Vec<DVec2>> = pieces
            .iter()
            .map(|p| {
                let mut out = Vec::new();
                p.flatten(tolerance, &mut out);
                out
            })
            .collect();
        let margin = 2.0 * tolerance;
        let mut members: Vec<Vec<u32>> = vec![Vec::new(); cells_u * cells_v];
        for (k, points) in flat.iter().enumerate() {
            for w in points.windows(2) {
                let lo = w[0].min(w[1]) - DVec2::splat(margin);
                let hi = w[0].max(w[1]) + DVec2::splat(margin);
                let (i0, j0) = cell_of(lo);
                let (i1, j1) = cell_of(hi);
                for j in j0..=j1 {
                    for i in i0..=i1 {
                        // Pieces come in order, so a repeat is always the last entry.
                        let cell = &mut members[j * cells_u + i];
                        if cell.last() != Some(&(k as u32)) {
                            cell.push(k as u32);
                        }
                    }
                }
            }
        }
        let mut lists = Vec::new();
        let mut cells = Vec::with_capacity(cells_u * cells_v);
        for j in 0..cells_v {
            for i in 0..cells_u {
                let m = &members[j * cells_u + i];
                let origin = DVec2::new(u0 + i as f64 * du, v0 + j as f64 * dv);
                let reference = clearest(
                    CANDIDATES
                        .iter()
                        .map(|&(a, b)| origin + DVec2::new(a * du, b * dv)),
                    m.iter().flat_map(|&k| flat[k as usize].windows(2)),
                )
                .unwrap_or(origin);
                cells.push(Cell {
                    reference,
                    inside: false,
                    first: lists.len() as u32,
                    count: m.len() as u32,
                });
                lists.extend_from_slice(m);
            }
        }
        let mut index = Self {
            domain,
            cells_u,
            cells_v,
            cells,
            lists,
            pieces,
        };
        index.propagate_sides();
        index
    }

    /// The pieces listed in cell `c`.
    pub fn cell_pieces(&self, c: usize) -> impl Iterator<Item = &MonotonePiece> + Clone {
        let cell = &self.cells[c];
        self.lists[cell.first as usize..(cell.first + cell.count) as usize]
            .iter()
            .map(|&k| &self.pieces[k as usize])
    }

    /// Sets every reference point's side, row by row from left of the domain.
    fn propagate_sides(&mut self) {
        let width = (self.domain[1] - self.domain[0]).abs().max(1.0);
        for j in 0..self.cells_v {
            let first = j * self.cells_u;
            let to = self.cells[first].reference;
            let outside = DVec2::new(self.domain[0] - width, to.y);
            let mut inside = path_parity(self.cell_pieces(first), outside, to);
            self.cells[first].inside = inside;
            for i in 1..self.cells_u {
                let (a, b) = (first + i - 1, first + i);
                let (from, to) = (self.cells[a].reference, self.cells[b].reference);
                // The path runs through both cells: each of their pieces once.
                let mut both: Vec<u32> = self.list(a).iter().chain(self.list(b)).copied().collect();
                both.sort_unstable();
                both.dedup();
                inside ^= path_parity(both.iter().map(|&k| &self.pieces[k as usize]), from, to);
                self.cells[b].inside = inside;
            }
        }
    }

    fn list(&self, c: usize) -> &[u32] {
        let cell = &self.cells[c];
        &self.lists[cell.first as usize..(cell.first + cell.count) as usize]
    }

    /// The cell holding (u, v) (clamped into the grid).
    pub fn cell_at(&self, p: DVec2) -> usize {
        let [u0, u1, v0, v1] = self.domain;
        let i = ((p.x - u0) / (u1 - u0) * self.cells_u as f64)
            .floor()
            .clamp(0.0, (self.cells_u - 1) as f64) as usize;
        let j = ((p.y - v0) / (v1 - v0) * self.cells_v as f64)
            .floor()
            .clamp(0.0, (self.cells_v - 1) as f64) as usize;
        j * self.cells_u + i
    }

    /// Whether (u, v) is in the kept region (inside an odd number of loops).
    pub fn contains(&self, u: f64, v: f64) -> bool {
        let p = DVec2::new(u, v);
        let c = self.cell_at(p);
        let cell = &self.cells[c];
        cell.inside ^ path_parity(self.cell_pieces(c), p, cell.reference)
    }

    /// How the rectangle (u0, u1, v0, v1) lies against the loops.
    pub fn coverage(&self, rect: [f64; 4]) -> Coverage {
        let [a, b, c, d] = rect;
        let lo = self.cell_at(DVec2::new(a, c));
        let hi = self.cell_at(DVec2::new(b, d));
        let (i0, j0) = (lo % self.cells_u, lo / self.cells_u);
        let (i1, j1) = (hi % self.cells_u, hi / self.cells_u);
        for j in j0..=j1 {
            for i in i0..=i1 {
                for piece in self.cell_pieces(j * self.cells_u + i) {
                    let [pa, pb, pc, pd] = piece.bounds;
                    if pa <= b && pb >= a && pc <= d && pd >= c {
                        return Coverage::Partial;
                    }
                }
            }
        }
        if self.contains(0.5 * (a + b), 0.5 * (c + d)) {
            Coverage::Inside
        } else {
            Coverage::Outside
        }
    }
}
