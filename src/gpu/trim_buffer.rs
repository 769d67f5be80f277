//! The trim loops of every trimmed object packed into one buffer of 32-bit words that the
//! surface fragment shader reads (`shaders/surface.wgsl`, `trim_words`). Floats are stored as
//! their bits. Word offsets are absolute, so one buffer serves every object:
//!
//! - header (at a patch record's `trim_offset`, [`TRIM_HEADER_WORDS`]): u0, v0, cells per unit
//!   of u, cells per unit of v (f32); cells along u and v, first cell word (u32); unused;
//! - cell ([`TRIM_CELL_WORDS`]): reference (u, v) (f32), `count << 1 | inside`, first list word;
//! - list entry: the word of a piece;
//! - piece: degree, u_min, u_max, v_min, v_max, then (degree + 1) homogeneous points
//!   (w·u, w·v, w); lines and conics are raised to cubics.

use crate::kernel::trim::index::TrimIndex;

/// Words of a trim header. WGSL: `TRIM_HEADER_WORDS`.
pub const TRIM_HEADER_WORDS: u32 = 8;
/// Words of a grid cell. WGSL: `TRIM_CELL_WORDS`.
pub const TRIM_CELL_WORDS: u32 = 4;
/// Words before a piece's points. WGSL: `TRIM_PIECE_HEADER_WORDS`.
pub const TRIM_PIECE_HEADER_WORDS: u32 = 5;
/// [`super::PatchRecord::trim_count`] of a patch cut by a trim loop: its fragments are
/// classified. WGSL: `TRIM_PARTIAL`.
pub const TRIM_PARTIAL: u32 = 1;
/// [`super::PatchRecord::trim_count`] of a patch wholly trimmed away: it is neither evaluated
/// nor drawn. WGSL: `TRIM_CULLED`.
pub const TRIM_CULLED: u32 = 0xFFFF_FFFF;

/// Appends `index` to `words` and returns the word of its header.
pub fn pack_index(index: &TrimIndex, words: &mut Vec<u32>) -> u32 {
    let f = |x: f64| (x as f32).to_bits();
    let header = words.len() as u32;
    let [u0, u1, v0, v1] = index.domain;
    let cells_start = header + TRIM_HEADER_WORDS;
    words.extend([
        f(u0),
        f(v0),
        f(index.cells_u as f64 / (u1 - u0)),
        f(index.cells_v as f64 / (v1 - v0)),
        index.cells_u as u32,
        index.cells_v as u32,
        cells_start,
        0,
    ]);
    let lists_start = cells_start + TRIM_CELL_WORDS * index.cells.len() as u32;
    let pieces_start = lists_start + index.lists.len() as u32;
    // Each piece's word, in piece order.
    let mut piece_words = Vec::with_capacity(index.pieces.len());
    let mut at = pieces_start;
    // Pieces below degree 3 are raised to 3 (exactly): the shader keeps a cubic in registers.
    let points: Vec<Vec<glam::DVec3>> = index
        .pieces
        .iter()
        .map(|p| raised_to_cubic(&p.points))
        .collect();
    for p in &points {
        piece_words.push(at);
        at += TRIM_PIECE_HEADER_WORDS + 3 * p.len() as u32;
    }
    for cell in &index.cells {
        words.extend([
            f(cell.reference.x),
            f(cell.reference.y),
            (cell.count << 1) | u32::from(cell.inside),
            lists_start + cell.first,
        ]);
    }
    words.extend(index.lists.iter().map(|&k| piece_words[k as usize]));
    for (piece, points) in index.pieces.iter().zip(&points) {
        words.push((points.len() - 1) as u32);
        words.extend(piece.bounds.map(f));
        for h in points {
            words.extend([f(h.x), f(h.y), f(h.z)]);
        }
    }
    header
}

/// The homogeneous Bézier `points` raised to degree 3 when lower (The NURBS Book eq. 5.36:
/// Q_i = i/(n+1) P_{i−1} + (1 − i/(n+1)) P_i per step; the curve is unchanged).
fn raised_to_cubic(points: &[glam::DVec3]) -> Vec<glam::DVec3> {
    let mut p = points.to_vec();
    while p.len() < 4 {
        let n = p.len() - 1;
        let mut q = Vec::with_capacity(n + 2);
        q.push(p[0]);
        for i in 1..=n {
            let a = i as f64 / (n + 1) as f64;
            q.push(p[i - 1] * a + p[i] * (1.0 - a));
        }
        q.push(p[n]);
        p = q;
    }
    p
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernel::trim::piece::bezier_point;
    use glam::DVec3;

    #[test]
    fn raising_lines_and_conics_to_cubics_keeps_the_curve() {
        let line = [DVec3::new(0.1, 0.2, 1.0), DVec3::new(0.9, 0.4, 1.0)];
        // A rational quarter circle: weights 1, √2/2, 1 (homogeneous points).
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let arc = [
            DVec3::new(1.0, 0.0, 1.0),
            DVec3::new(h, h, h),
            DVec3::new(0.0, 1.0, 1.0),
        ];
        for points in [&line[..], &arc[..]] {
            let cubic = raised_to_cubic(points);
            assert_eq!(cubic.len(), 4);
            for k in 0..=20 {
                let t = k as f64 / 20.0;
                let (a, b) = (bezier_point(points, t), bezier_point(&cubic, t));
                assert!(a.distance(b) < 1e-15, "{a} vs {b} at {t}");
            }
        }
    }
}
