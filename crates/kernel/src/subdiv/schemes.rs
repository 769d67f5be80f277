//! The schemes beside Catmull-Clark and Loop: Doo-Sabin (dual, corner cutting), Kobbelt's √3
//! (triangles, 1-to-3 split with edge flips) and the modified butterfly (interpolating,
//! triangles, 1-to-4 split). Each refinement step yields the child level and the stencils
//! giving its vertices from the parent's, as [`super::refine::refine`] does for the others,
//! so the hierarchy, the composition onto the cage and the GPU's stencil pass are shared.
//!
//! Boundaries: Doo-Sabin cuts the boundary polygon by Chaikin's rule (3/4, 1/4), so the limit
//! boundary is the quadratic B-spline of the cage's boundary; √3 refines the boundary polygon
//! every second step by the ternary cubic B-spline rule (Kobbelt 2000, §4); the butterfly runs
//! the four-point rule (−1, 9, 9, −1)/16 along boundary edges. None of them has crease rules:
//! a cage's creases and corners apply under Catmull-Clark and Loop only.

use std::f64::consts::TAU;

use super::level::{INFINITE_SHARPNESS, Level, NONE, Ring};
use super::stencil::{Row, Stencils};
use crate::GeometryError;

/// The Doo-Sabin weight of corner i of an n-gon for the new point of corner 0 (Doo & Sabin
/// 1978): α₀ = 1/4 + 5/(4n), αᵢ = (3 + 2 cos(2πi/n))/(4n). For quads (9, 3, 1, 3)/16, the
/// biquadratic B-spline's.
pub fn doo_sabin_weight(n: usize, i: usize) -> f64 {
    let nf = n as f64;
    if i.is_multiple_of(n) {
        0.25 + 5.0 / (4.0 * nf)
    } else {
        (3.0 + 2.0 * (TAU * i as f64 / nf).cos()) / (4.0 * nf)
    }
}

/// Kobbelt's √3 smoothing weight α(n) = (4 − 2 cos(2π/n))/9 (Kobbelt 2000, eq. 3).
pub fn sqrt3_alpha(n: usize) -> f64 {
    (4.0 - 2.0 * (TAU / n as f64).cos()) / 9.0
}

/// The weight β∞(n) = 3α/(1 + 3α) of the √3 limit mask p∞ = (1 − β∞) p + β∞/n Σ pᵢ: the
/// left eigenvector of eigenvalue 1 of the step on (p, mean of the ring), where
/// p' = (1 − α) p + α r and r' = (p + 2r)/3 (the new ring is the n face centroids).
pub fn sqrt3_limit_beta(n: usize) -> f64 {
    let alpha = sqrt3_alpha(n);
    3.0 * alpha / (1.0 + 3.0 * alpha)
}

/// The modified butterfly's weights sⱼ for the ring of an extraordinary vertex of valence k
/// (Zorin, Schröder & Sweldens 1996): the new edge point is 3/4 v + Σ sⱼ eⱼ with e₀ the
/// edge's other end. k = 3: (5, −1, −1)/12; k = 4: (3/8, 0, −1/8, 0); k ≥ 5:
/// sⱼ = (1/4 + cos(2πj/k) + 1/2 cos(4πj/k))/k.
pub fn butterfly_ring_weights(k: usize) -> Vec<f64> {
    match k {
        3 => vec![5.0 / 12.0, -1.0 / 12.0, -1.0 / 12.0],
        4 => vec![0.375, 0.0, -0.125, 0.0],
        _ => {
            let kf = k as f64;
            (0..k)
                .map(|j| {
                    let a = TAU * j as f64 / kf;
                    (0.25 + a.cos() + 0.5 * (2.0 * a).cos()) / kf
                })
                .collect()
        }
    }
}

/// The edge between `a` and `b`, if there is one.
pub fn edge_between(level: &Level, a: u32, b: u32) -> Option<u32> {
    level
        .vertex_edges(a)
        .iter()
        .copied()
        .find(|&e| level.other_end(e, a) == b)
}

/// The boundary edges of boundary vertex `v` with ring `ring`: the one leaving it (its first
/// face's), then the one arriving (its last face's).
pub fn ring_boundary_edges(level: &Level, v: u32, ring: &Ring) -> Option<[u32; 2]> {
    let first = *ring.neighbours.first()?;
    let last = *ring.neighbours.last()?;
    Some([
        edge_between(level, v, first)?,
        edge_between(level, last, v)?,
    ])
}

/// The ends of edge `e` in the order its first face runs along it.
pub fn directed_ends(level: &Level, e: u32) -> [u32; 2] {
    let [a, b] = level.edges[e as usize];
    let f = level.edge_faces[e as usize][0];
    let face = level.face(f);
    let n = face.len();
    let j = face.iter().position(|&x| x == a).unwrap_or(0);
    if face[(j + 1) % n] == b {
        [a, b]
    } else {
        [b, a]
    }
}

/// Boundary edge `e`'s ends in the boundary's direction with the boundary vertex before and
/// after them: [x₋, x, y, y₊], the support of a curve rule along the boundary.
fn boundary_run(level: &Level, e: u32) -> [u32; 4] {
    let [x, y] = directed_ends(level, e);
    [
        boundary_neighbours(level, x)[1],
        x,
        y,
        boundary_neighbours(level, y)[0],
    ]
}

/// The corner index of `v` in face `f`.
fn corner_index(level: &Level, f: u32, v: u32) -> usize {
    level.face(f).iter().position(|&x| x == v).unwrap_or(0)
}

/// The two neighbours of boundary vertex `v` along the boundary: the end of the boundary edge
/// leaving it, then of the one arriving (in the faces' direction).
pub fn boundary_neighbours(level: &Level, v: u32) -> [u32; 2] {
    let ring = level.ring(v);
    [
        ring.neighbours.first().copied().unwrap_or(v),
        ring.neighbours.last().copied().unwrap_or(v),
    ]
}

fn is_boundary_vertex(level: &Level, v: u32) -> bool {
    level
        .vertex_edges(v)
        .iter()
        .any(|&e| level.is_boundary_edge(e))
}

/// Builds a child level from its faces, with its boundary edges infinitely sharp (so the
/// shared limit-mask code sees the boundary as a crease).
fn child_level(count: usize, faces: &[Vec<u32>]) -> Result<Level, GeometryError> {
    let refs: Vec<&[u32]> = faces.iter().map(Vec::as_slice).collect();
    let mut level = Level::new(count, &refs, Vec::new())?;
    for e in 0..level.edges.len() {
        if level.is_boundary_edge(e as u32) {
            level.edge_sharpness[e] = INFINITE_SHARPNESS;
        }
    }
    Ok(level)
}

/// One Doo-Sabin step. Child vertices: for each face f and corner i (face by face) the point
/// Σⱼ α₍ⱼ₋ᵢ₎ vⱼ ([`doo_sabin_weight`]); then for each boundary edge (a, b) (in edge order)
/// the Chaikin points 3/4 a + 1/4 b and 1/4 a + 3/4 b. Child faces: one per face (its new
/// points), one quad per edge (the two faces' points at its ends, or one face's and the
/// edge's Chaikin points), one per vertex (its faces' points in ring order, between the
/// Chaikin points of its boundary edges on the boundary).
pub fn doo_sabin(level: &Level) -> Result<(Level, Stencils), GeometryError> {
    let layout = DooSabinLayout::new(level);
    let mut stencils = Stencils::new();
    for face in level.faces() {
        let n = face.len();
        for i in 0..n {
            let mut row = Row::default();
            for (j, &v) in face.iter().enumerate() {
                row.add(v, doo_sabin_weight(n, (j + n - i) % n));
            }
            stencils.push(row);
        }
    }
    for (e, &[a, b]) in level.edges.iter().enumerate() {
        if level.is_boundary_edge(e as u32) {
            stencils.push(Row(vec![(a, 0.75), (b, 0.25)]));
            stencils.push(Row(vec![(a, 0.25), (b, 0.75)]));
        }
    }
    let point = |f: u32, v: u32| layout.point(level, f, v);
    let chaikin = |e: u32, v: u32| layout.chaikin(level, e, v);

    let mut faces: Vec<Vec<u32>> = Vec::new();
    for (f, face) in level.faces().enumerate() {
        let start = layout.corner_start[f];
        faces.push((start..start + face.len() as u32).collect());
    }
    for e in 0..level.edges.len() as u32 {
        let [x, y] = directed_ends(level, e);
        let [f0, f1] = level.edge_faces[e as usize];
        if f1 == NONE {
            faces.push(vec![
                point(f0, y),
                point(f0, x),
                chaikin(e, x),
                chaikin(e, y),
            ]);
        } else {
            faces.push(vec![point(f0, y), point(f0, x), point(f1, x), point(f1, y)]);
        }
    }
    for v in 0..level.vertex_count as u32 {
        let ring = level.ring(v);
        if ring.faces.is_empty() {
            continue;
        }
        let mut polygon: Vec<u32> = ring.faces.iter().map(|&f| point(f, v)).collect();
        if ring.boundary {
            let Some([out, into]) = ring_boundary_edges(level, v, &ring) else {
                continue;
            };
            polygon.insert(0, chaikin(out, v));
            polygon.push(chaikin(into, v));
        }
        debug_assert_eq!(layout.vertex_face[v as usize], faces.len() as u32);
        faces.push(polygon);
    }
    let child = child_level(stencils.len(), &faces)?;
    Ok((child, stencils))
}

/// Where one Doo-Sabin step ([`doo_sabin`]) puts each child vertex and face of `level`: face
/// f's new points from `corner_start[f]` (corner by corner), boundary edge e's two Chaikin
/// points from `chaikin_start[e]`; child face f is face f's, face `face_count + e` edge e's,
/// and `vertex_face[v]` vertex v's (NONE for a vertex without faces or whose boundary
/// edges cannot be found).
#[derive(Debug, Clone)]
pub struct DooSabinLayout {
    pub corner_start: Vec<u32>,
    pub chaikin_start: Vec<u32>,
    pub vertex_face: Vec<u32>,
}

impl DooSabinLayout {
    pub fn new(level: &Level) -> Self {
        let mut corner_start = Vec::with_capacity(level.face_count());
        let mut next = 0u32;
        for face in level.faces() {
            corner_start.push(next);
            next += face.len() as u32;
        }
        let mut chaikin_start = vec![NONE; level.edges.len()];
        for (e, start) in chaikin_start.iter_mut().enumerate() {
            if level.is_boundary_edge(e as u32) {
                *start = next;
                next += 2;
            }
        }
        let mut vertex_face = vec![NONE; level.vertex_count];
        let mut face = (level.face_count() + level.edges.len()) as u32;
        for (v, slot) in vertex_face.iter_mut().enumerate() {
            let ring = level.ring(v as u32);
            if ring.faces.is_empty()
                || (ring.boundary && ring_boundary_edges(level, v as u32, &ring).is_none())
            {
                continue;
            }
            *slot = face;
            face += 1;
        }
        Self {
            corner_start,
            chaikin_start,
            vertex_face,
        }
    }

    /// The child vertex that face `f`'s corner `v` becomes.
    pub fn point(&self, level: &Level, f: u32, v: u32) -> u32 {
        self.corner_start[f as usize] + corner_index(level, f, v) as u32
    }

    /// The Chaikin point of boundary edge `e` nearer its end `v`.
    pub fn chaikin(&self, level: &Level, e: u32, v: u32) -> u32 {
        self.chaikin_start[e as usize] + u32::from(level.edges[e as usize][0] != v)
    }

    /// The child face of edge `e`.
    pub fn edge_face(&self, level: &Level, e: u32) -> u32 {
        (level.face_count() + e as usize) as u32
    }
}

/// One √3 step (Kobbelt 2000). Child vertices: the old ones (interior:
/// (1 − α(n)) v + α(n)/n Σ eⱼ; boundary: kept in the steps that do not refine the boundary,
/// (4, 19, 4)/27 over the boundary neighbours in those that do); the centroid of each
/// triangle; in boundary-refining steps, for each boundary edge (x, y) in edge order the
/// ternary cubic B-spline points (x₋ + 16 x + 10 y)/27 and (10 x + 16 y + y₊)/27. Child
/// faces, edge by edge: an interior edge (a, b) between centroids c₀ (on its side a → b) and
/// c₁ is flipped into (a, c₁, c₀) and (b, c₀, c₁); a boundary edge keeps its triangle with
/// the centroid, or splits it in three at its ternary points. `refine_boundary` is true in
/// every second step (the second, fourth, ...), so that two steps refine the boundary
/// polygon once by three.
pub fn sqrt3(level: &Level, refine_boundary: bool) -> Result<(Level, Stencils), GeometryError> {
    let v_count = level.vertex_count as u32;
    let mut stencils = Stencils::new();
    for v in 0..v_count {
        stencils.push(sqrt3_vertex_row(level, v, refine_boundary));
    }
    for face in level.faces() {
        let mut row = Row::default();
        row.add_centroid(face, 1.0);
        stencils.push(row);
    }
    let centroid = |f: u32| v_count + f;
    let ternary_start = sqrt3_ternary_starts(level);
    if refine_boundary {
        for e in 0..level.edges.len() as u32 {
            if !level.is_boundary_edge(e) {
                continue;
            }
            let [before_x, x, y, after_y] = boundary_run(level, e);
            debug_assert_eq!(ternary_start[e as usize], stencils.len() as u32);
            stencils.push(Row(vec![
                (before_x, 1.0 / 27.0),
                (x, 16.0 / 27.0),
                (y, 10.0 / 27.0),
            ]));
            stencils.push(Row(vec![
                (x, 10.0 / 27.0),
                (y, 16.0 / 27.0),
                (after_y, 1.0 / 27.0),
            ]));
        }
    }
    let mut faces: Vec<Vec<u32>> = Vec::new();
    for e in 0..level.edges.len() as u32 {
        let [a, b] = directed_ends(level, e);
        let [f0, f1] = level.edge_faces[e as usize];
        if f1 != NONE {
            faces.push(vec![a, centroid(f1), centroid(f0)]);
            faces.push(vec![b, centroid(f0), centroid(f1)]);
        } else if refine_boundary {
            let t = ternary_start[e as usize];
            let c = centroid(f0);
            faces.push(vec![a, t, c]);
            faces.push(vec![t, t + 1, c]);
            faces.push(vec![t + 1, b, c]);
        } else {
            faces.push(vec![a, b, centroid(f0)]);
        }
    }
    let child = child_level(stencils.len(), &faces)?;
    Ok((child, stencils))
}

/// Where a boundary-refining √3 step ([`sqrt3`]) puts boundary edge e's two ternary points
/// (the one nearer the edge's first end first): after the vertices and the centroids, two per
/// boundary edge in edge order; NONE for an interior edge.
pub fn sqrt3_ternary_starts(level: &Level) -> Vec<u32> {
    let mut next = (level.vertex_count + level.face_count()) as u32;
    (0..level.edges.len() as u32)
        .map(|e| {
            if level.is_boundary_edge(e) {
                next += 2;
                next - 2
            } else {
                NONE
            }
        })
        .collect()
}

/// `v` blended with the mean of its ring: (1 − w) v + w/n Σ eⱼ, with w = `weight(n)`.
fn ring_mean_row(level: &Level, v: u32, weight: fn(usize) -> f64) -> Row {
    let edges = level.vertex_edges(v);
    let n = edges.len();
    let w = weight(n);
    let mut row = Row(vec![(v, 1.0 - w)]);
    for &e in edges {
        row.add(level.other_end(e, v), w / n as f64);
    }
    row
}

/// `v` and its two boundary neighbours with weights `[side, centre, side]`.
fn boundary_row(level: &Level, v: u32, [side, centre]: [f64; 2]) -> Row {
    let [a, b] = boundary_neighbours(level, v);
    Row(vec![(v, centre), (a, side), (b, side)]).merged()
}

fn sqrt3_vertex_row(level: &Level, v: u32, refine_boundary: bool) -> Row {
    if level.vertex_faces(v).is_empty() || (is_boundary_vertex(level, v) && !refine_boundary) {
        Row(vec![(v, 1.0)])
    } else if is_boundary_vertex(level, v) {
        boundary_row(level, v, [4.0 / 27.0, 19.0 / 27.0])
    } else {
        ring_mean_row(level, v, sqrt3_alpha)
    }
}

/// The √3 limit position of `v`: interior (1 − β∞) v + β∞/n Σ eⱼ ([`sqrt3_limit_beta`]);
/// boundary (a + 4v + b)/6 over its boundary neighbours, the cubic B-spline's, since the
/// boundary polygon is refined by the ternary cubic B-spline rule alone.
pub fn sqrt3_limit_position(level: &Level, v: u32) -> Row {
    if level.vertex_faces(v).is_empty() {
        Row(vec![(v, 1.0)])
    } else if is_boundary_vertex(level, v) {
        boundary_row(level, v, [1.0 / 6.0, 4.0 / 6.0])
    } else {
        ring_mean_row(level, v, sqrt3_limit_beta)
    }
}

/// The vertex across edge (a, b) from triangle `f`: the far corner of the edge's other face.
fn across(level: &Level, f: u32, a: u32, b: u32) -> Option<u32> {
    let e = edge_between(level, a, b)?;
    let [x, y] = level.edge_faces[e as usize];
    let other = if x == f { y } else { x };
    (other != NONE).then(|| level.opposite(other, a, b))
}

/// The extraordinary rule around interior vertex `v` for its edge to `w`:
/// 3/4 v + Σ sⱼ eⱼ with the ring from e₀ = w ([`butterfly_ring_weights`]).
fn butterfly_ring_row(level: &Level, v: u32, w: u32) -> Row {
    let ring = level.ring(v);
    let k = ring.neighbours.len();
    let start = ring.neighbours.iter().position(|&x| x == w).unwrap_or(0);
    let mut row = Row(vec![(v, 0.75)]);
    for (j, s) in butterfly_ring_weights(k).into_iter().enumerate() {
        row.add(ring.neighbours[(start + j) % k], s);
    }
    row
}

/// The modified butterfly's new point on edge `e` (Zorin, Schröder & Sweldens 1996): both ends
/// interior of valence 6: the eight-point butterfly 1/2 (a + b) + 1/8 (c₀ + c₁) − 1/16 Σ wings;
/// one interior end extraordinary (or the only interior end): its ring rule
/// ([`butterfly_ring_weights`]); both extraordinary: the mean of the two ring rules; a
/// boundary edge: the four-point rule (−x₋ + 9 x + 9 y − y₊)/16 along the boundary; an
/// interior edge between two boundary vertices: Loop's 3/8 (a + b) + 1/8 (c₀ + c₁).
pub fn butterfly_edge_row(level: &Level, e: u32) -> Row {
    let [a, b] = level.edges[e as usize];
    let [f0, f1] = level.edge_faces[e as usize];
    if f1 == NONE {
        let [before_x, x, y, after_y] = boundary_run(level, e);
        return Row(vec![
            (before_x, -1.0 / 16.0),
            (x, 9.0 / 16.0),
            (y, 9.0 / 16.0),
            (after_y, -1.0 / 16.0),
        ])
        .merged();
    }
    let interior = |v: u32| !is_boundary_vertex(level, v);
    let valence = |v: u32| level.vertex_edges(v).len();
    let (c0, c1) = (level.opposite(f0, a, b), level.opposite(f1, a, b));
    match (interior(a), interior(b)) {
        (true, true) if valence(a) == 6 && valence(b) == 6 => {
            let wings = [
                across(level, f0, a, c0),
                across(level, f0, b, c0),
                across(level, f1, a, c1),
                across(level, f1, b, c1),
            ];
            let mut row = Row(vec![(a, 0.5), (b, 0.5), (c0, 0.125), (c1, 0.125)]);
            for w in wings.into_iter().flatten() {
                row.add(w, -1.0 / 16.0);
            }
            row.merged()
        }
        (true, true) if valence(b) == 6 => butterfly_ring_row(level, a, b),
        (true, true) if valence(a) == 6 => butterfly_ring_row(level, b, a),
        (true, true) => butterfly_ring_row(level, a, b).blend(butterfly_ring_row(level, b, a), 0.5),
        (true, false) => butterfly_ring_row(level, a, b),
        (false, true) => butterfly_ring_row(level, b, a),
        (false, false) => Row(vec![(a, 0.375), (b, 0.375), (c0, 0.125), (c1, 0.125)]),
    }
}
