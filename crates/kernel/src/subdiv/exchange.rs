//! A subdivision limit surface as bicubic Bézier patches for exchange (STEP), one patch per
//! four-sided region of a refinement level k: Catmull-Clark's faces, Doo-Sabin's vertices
//! (the dual quad of a vertex's four faces, [`dual_corners`]); Loop's, the butterfly's and
//! √3's triangles become cubic triangles the same way ([`fit_triangle_regions`]).
//!
//! - **Exact** where the limit over the region is a B-spline: a regular Catmull-Clark face
//!   and one-ring ([`bspline_grid`], [`is_regular_face`]) or regular boundary quad
//!   ([`boundary_bspline_grid`]), bicubic; a Doo-Sabin vertex whose four faces are quads,
//!   biquadratic raised to degree 3.
//! - **Approximated** elsewhere (at extraordinary vertices, creases, corners, boundaries): a
//!   bicubic patch whose four boundary curves are shared with its neighbours (an exact
//!   neighbour's boundary row as it is; between two approximated regions the cubic that fits
//!   the side's five limit points of level k + 2, ends interpolated, fitted from the
//!   lower-keyed end, so the same bits from either side), and whose four inner points fit the
//!   nine inner limit points of level k + 2 over the region by least squares.
//!
//! So the patches meet along every edge (to the bit where one of them is approximated, to
//! rounding where both convert their own B-spline points). The deviation is the largest
//! distance from the limit points of level k + 3 over an approximated region to its patch
//! (each point's nearest point on the patch, [`distance_near`]). The level rises (past the
//! levels the editor draws, to `MAX_PATCH_LEVEL`) until that deviation is within the
//! tolerance asked for, or the refinement would pass a size limit, and the deviation reached
//! is returned with the patches.

use glam::DVec3;

use super::level::{Level, NONE};
use super::limit::limit_position;
use super::patches::{boundary_bspline_grid, bspline_grid, face_grid, is_regular_face};
use super::schemes::{
    DooSabinLayout, boundary_neighbours, directed_ends, edge_between, sqrt3_ternary_starts,
};
use super::{Hierarchy, Scheme, SubdivisionSurface};
use crate::GeometryError;

/// The most faces the finest level used for checking may have.
const MAX_CHECK_FACES: usize = 1 << 20;

/// The most faces the finest level checked may have on the first level tried.
const MAX_FIRST_CHECK_FACES: usize = 1 << 22;

/// The highest level whose faces become patches.
const MAX_PATCH_LEVEL: u32 = 6;

/// The Bézier points of the uniform cubic B-spline segment with points P0..P3 (rows: Bézier
/// point, columns: B-spline point).
const BSPLINE_TO_BEZIER: [[f64; 4]; 4] = [
    [1.0 / 6.0, 4.0 / 6.0, 1.0 / 6.0, 0.0],
    [0.0, 4.0 / 6.0, 2.0 / 6.0, 0.0],
    [0.0, 2.0 / 6.0, 4.0 / 6.0, 0.0],
    [0.0, 1.0 / 6.0, 4.0 / 6.0, 1.0 / 6.0],
];

/// The limit surface as bicubic Bézier patches (16 points each, row-major with the first index
/// along u, u from a face's corner 0 to corner 1 and v from corner 0 to corner 3).
#[derive(Debug, Clone, PartialEq)]
pub struct LimitPatches {
    pub patches: Vec<[DVec3; 16]>,
    /// How many of them are the limit exactly.
    pub exact: usize,
    /// The refinement level whose faces the patches are.
    pub level: u32,
    /// The largest distance found from an approximated patch to the limit (0 when every patch
    /// is exact).
    pub deviation: f64,
    /// Whether each patch is a cubic triangle (Loop, butterfly) written as the bicubic patch
    /// over the square collapsed onto it (its side u = 1 is one point).
    pub triangles: bool,
}

fn bernstein3(t: f64) -> [f64; 4] {
    let s = 1.0 - t;
    [s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t]
}

/// The point and first derivatives of bicubic Bézier patch `p` at (s, t).
fn patch_derivatives(p: &[DVec3; 16], s: f64, t: f64) -> (DVec3, DVec3, DVec3) {
    let (bu, bv) = (bernstein3(s), bernstein3(t));
    // Derivatives of the cubic Bernstein basis: 3 (B²ᵢ₋₁ − B²ᵢ).
    let d = |x: f64| {
        let y = 1.0 - x;
        let b2 = [y * y, 2.0 * x * y, x * x];
        [
            -3.0 * b2[0],
            3.0 * (b2[0] - b2[1]),
            3.0 * (b2[1] - b2[2]),
            3.0 * b2[2],
        ]
    };
    let (du, dv) = (d(s), d(t));
    let (mut at, mut su, mut sv) = (DVec3::ZERO, DVec3::ZERO, DVec3::ZERO);
    for i in 0..4 {
        for j in 0..4 {
            let q = p[i * 4 + j];
            at += q * (bu[i] * bv[j]);
            su += q * (du[i] * bv[j]);
            sv += q * (bu[i] * dv[j]);
        }
    }
    (at, su, sv)
}

/// The distance from `target` to a patch near parameter `start`: Gauss-Newton on
/// |S(u, v) − target|² from `start` (`eval` giving the point and first derivatives, `clamp`
/// keeping (u, v) in the domain), the least distance met. The limit's parametrization and the
/// patch's differ near extraordinary points and boundaries, so a limit point is compared with
/// the patch's nearest point, not with the point at the same parameter.
fn distance_near(
    eval: &dyn Fn(f64, f64) -> (DVec3, DVec3, DVec3),
    clamp: fn(f64, f64) -> (f64, f64),
    start: (f64, f64),
    target: DVec3,
) -> f64 {
    let (mut u, mut v) = start;
    let mut best = f64::INFINITY;
    for _ in 0..8 {
        let (at, su, sv) = eval(u, v);
        let r = target - at;
        best = best.min(r.length());
        let (a, b, c) = (su.dot(su), su.dot(sv), sv.dot(sv));
        let det = a * c - b * b;
        if !(det > 1e-24 * (a * c).max(f64::MIN_POSITIVE)) {
            break;
        }
        let (ru, rv) = (su.dot(r), sv.dot(r));
        let (du, dv) = ((c * ru - b * rv) / det, (a * rv - b * ru) / det);
        (u, v) = clamp(u + du, v + dv);
        if du.abs() + dv.abs() < 1e-14 {
            break;
        }
    }
    let (at, _, _) = eval(u, v);
    best.min(target.distance(at))
}

fn clamp_square(u: f64, v: f64) -> (f64, f64) {
    (u.clamp(0.0, 1.0), v.clamp(0.0, 1.0))
}

fn clamp_triangle(u: f64, v: f64) -> (f64, f64) {
    let (u, v) = (u.max(0.0), v.max(0.0));
    let sum = u + v;
    if sum > 1.0 {
        (u / sum, v / sum)
    } else {
        (u, v)
    }
}

/// Index in a patch of point `k` (0..4) along side `side` (from corner `side` to the next).
fn side_index(side: usize, k: usize) -> usize {
    match side {
        0 => k * 4,
        1 => 12 + k,
        2 => (3 - k) * 4 + 3,
        _ => 3 - k,
    }
}

/// Index in an (n + 1)² grid (first index along u) of point `k` along side `side`.
fn grid_side_index(n: usize, side: usize, k: usize) -> usize {
    let w = n + 1;
    match side {
        0 => k * w,
        1 => n * w + k,
        2 => (n - k) * w + n,
        _ => n - k,
    }
}

/// The cubic Bézier curve through the first and last of `points` (at t = 0 and 1) that fits
/// the others, at evenly spaced t, by least squares (symmetric: the reversed points give the
/// reversed curve, to rounding). At least four points.
fn fit_edge(points: &[DVec3]) -> [DVec3; 4] {
    let n = points.len() - 1;
    let (a, e) = (points[0], points[n]);
    // Normal equations for P1, P2: Σ [B1 B2]ᵀ [B1 B2] P = Σ [B1 B2]ᵀ (L − B0 a − B3 e).
    let (mut m11, mut m12, mut m22) = (0.0, 0.0, 0.0);
    let (mut r1, mut r2) = (DVec3::ZERO, DVec3::ZERO);
    for (k, &l) in points.iter().enumerate().take(n).skip(1) {
        let bt = bernstein3(k as f64 / n as f64);
        let rest = l - a * bt[0] - e * bt[3];
        m11 += bt[1] * bt[1];
        m12 += bt[1] * bt[2];
        m22 += bt[2] * bt[2];
        r1 += rest * bt[1];
        r2 += rest * bt[2];
    }
    let det = m11 * m22 - m12 * m12;
    let p1 = (r1 * m22 - r2 * m12) / det;
    let p2 = (r2 * m11 - r1 * m12) / det;
    [a, p1, p2, e]
}

/// [`fit_edge`] of the limit points `along` a side from the end keyed `a` to the end keyed
/// `b`, fitted from the lower-keyed end, so that the patches on both sides get the same bits.
fn fit_shared_edge(along: &[DVec3], a: u32, b: u32) -> [DVec3; 4] {
    if a < b {
        fit_edge(along)
    } else {
        let back: Vec<DVec3> = along.iter().rev().copied().collect();
        let mut curve = fit_edge(&back);
        curve.reverse();
        curve
    }
}

/// Solves the symmetric positive definite 4 × 4 system `m x = r` (three right-hand sides at
/// once) by Gaussian elimination.
fn solve4(mut m: [[f64; 4]; 4], mut r: [DVec3; 4]) -> [DVec3; 4] {
    for k in 0..4 {
        for i in k + 1..4 {
            let f = m[i][k] / m[k][k];
            let pivot = m[k];
            for (x, p) in m[i].iter_mut().zip(pivot).skip(k) {
                *x -= f * p;
            }
            r[i] -= r[k] * f;
        }
    }
    let mut x = [DVec3::ZERO; 4];
    for k in (0..4).rev() {
        let mut s = r[k];
        for j in k + 1..4 {
            s -= x[j] * m[k][j];
        }
        x[k] = s / m[k][k];
    }
    x
}

fn limit_patches_error(message: &str) -> GeometryError {
    GeometryError::Construction {
        what: "limit patches",
        message: message.into(),
    }
}

/// One side of a four-sided region: the region across it (NONE where there is none) and the
/// keys of its ends, in the region's order (two regions sharing the side see the same keys
/// the other way round).
#[derive(Debug, Clone, Copy)]
struct Side {
    across: u32,
    from: u32,
    to: u32,
}

/// The limit over four-sided regions that split into four from level to level (Catmull-Clark's
/// faces, Doo-Sabin's vertices): each region's patch is `exact[r]` where known, else a
/// bicubic patch whose four boundary curves are shared with its neighbours (an exact
/// neighbour's boundary row as it is, otherwise the cubic fitting the side's five limit points
/// of depth 2 from the lower-keyed end) and whose four inner points fit the nine inner limit
/// points of depth 2 by least squares. `limit_grid(r)` gives the 9 × 9 limit points of depth
/// 3 over region r (first index along u, from corner 0 to corner 1), whose even ones are
/// depth 2's. Returns the patches and the largest distance from an approximated patch to the
/// 81 limit points of depth 3 over its region.
fn fit_quad_regions(
    level: u32,
    exact: &[Option<[DVec3; 16]>],
    sides: &dyn Fn(u32) -> Result<[Side; 4], GeometryError>,
    limit_grid: &dyn Fn(u32) -> Result<Vec<DVec3>, GeometryError>,
) -> Result<LimitPatches, GeometryError> {
    let mut deviation = 0.0f64;
    let mut out = Vec::with_capacity(exact.len());
    for r in 0..exact.len() as u32 {
        if let Some(p) = exact[r as usize] {
            out.push(p);
            continue;
        }
        let check = limit_grid(r)?;
        // Depth 2's point (a, b), a, b in 0..=4.
        let fine = |a: usize, b: usize| check[2 * a * 9 + 2 * b];
        let mut p = [DVec3::ZERO; 16];
        for (side, here) in sides(r)?.into_iter().enumerate() {
            let shared = match exact.get(here.across as usize).copied().flatten() {
                Some(q) => {
                    // Their side m runs the other way: ours is it reversed.
                    let theirs = sides(here.across)?;
                    theirs
                        .iter()
                        .position(|s| s.from == here.to && s.to == here.from)
                        .map(|m| std::array::from_fn::<DVec3, 4, _>(|k| q[side_index(m, 3 - k)]))
                }
                None => None,
            };
            let row = shared.unwrap_or_else(|| {
                let along: [DVec3; 5] =
                    std::array::from_fn(|k| check[grid_side_index(8, side, 2 * k)]);
                fit_shared_edge(&along, here.from, here.to)
            });
            for (k, point) in row.into_iter().enumerate() {
                p[side_index(side, k)] = point;
            }
        }
        // The inner points: least squares over the nine inner limit points.
        let inner = [(1, 1), (1, 2), (2, 1), (2, 2)];
        let mut m = [[0.0; 4]; 4];
        let mut rhs = [DVec3::ZERO; 4];
        for a in 1..4 {
            for b in 1..4 {
                let (bu, bv) = (bernstein3(a as f64 / 4.0), bernstein3(b as f64 / 4.0));
                let mut rest = fine(a, b);
                for i in 0..4 {
                    for j in 0..4 {
                        if !inner.contains(&(i, j)) {
                            rest -= p[i * 4 + j] * (bu[i] * bv[j]);
                        }
                    }
                }
                let basis = inner.map(|(i, j)| bu[i] * bv[j]);
                for x in 0..4 {
                    for y in 0..4 {
                        m[x][y] += basis[x] * basis[y];
                    }
                    rhs[x] += rest * basis[x];
                }
            }
        }
        for ((i, j), point) in inner.into_iter().zip(solve4(m, rhs)) {
            p[i * 4 + j] = point;
        }
        // The deviation at depth 3's limit points over the region.
        let eval = |u: f64, v: f64| patch_derivatives(&p, u, v);
        for a in 0..=8 {
            for b in 0..=8 {
                let start = (a as f64 / 8.0, b as f64 / 8.0);
                let d = distance_near(&eval, clamp_square, start, check[a * 9 + b]);
                deviation = deviation.max(d);
            }
        }
        if !deviation.is_finite() {
            return Err(limit_patches_error("the limit is not finite"));
        }
        out.push(p);
    }
    Ok(LimitPatches {
        patches: out,
        exact: exact.iter().flatten().count(),
        level,
        deviation,
        triangles: false,
    })
}

/// The limit over triangles that split into s² from one depth to the next (Loop and the
/// butterfly: s = 2 per level; √3: s = 3 per two levels), as cubic triangles written as
/// collapsed bicubic patches: corners at the limit points, each side the cubic that fits the
/// side's limit points of the fitting grid (ends interpolated, fitted from the lower-numbered
/// corner so that both faces get the same bits), the inner point b₁₁₁ fitting the grid's inner
/// limit points by least squares. A grid of n segments per side holds point (a, b), a + b ≤ n,
/// at slot a·(n + 1) + b: the patch's (u, v) = (a, b)/n (corner 1 at u = 1, corner 2 at v = 1).
/// `limit(f)` gives face f's checking grid, of `check_n` segments a side (every point the
/// deviation is measured at), and the points it leaves out with the parameter to look for each
/// near; the fitting grid, of `fit_n` segments, is every (check_n / fit_n)-th of its points.
type CheckGrid<'a> = &'a dyn Fn(u32) -> Result<(Vec<Option<DVec3>>, ParamPoints), GeometryError>;
/// Limit points, each with the patch parameter to look for it near.
type ParamPoints = Vec<((f64, f64), DVec3)>;

/// The points of a triangle grid of `n` segments a side with their parameters (a, b)/n.
fn grid_points(grid: Vec<Option<DVec3>>, n: usize) -> ParamPoints {
    grid.into_iter()
        .enumerate()
        .filter_map(|(slot, p)| {
            let (a, b) = (slot / (n + 1), slot % (n + 1));
            let p = p.filter(|_| a + b <= n)?;
            Some(((a as f64 / n as f64, b as f64 / n as f64), p))
        })
        .collect()
}

fn fit_triangle_regions(
    (k, level): (u32, &Level),
    fit_n: usize,
    (check_n, limit): (usize, CheckGrid),
) -> Result<LimitPatches, GeometryError> {
    use crate::triangle::{TriangleBezier, lattice_index};
    let failed = limit_patches_error;
    let at = |grid: &[Option<DVec3>], n: usize, a: usize, b: usize| {
        grid.get(a * (n + 1) + b)
            .copied()
            .flatten()
            .ok_or_else(|| failed("a limit point is missing"))
    };
    // The lattice index (i, j) of point k along side `side` (corner 0 → 1 → 2 → 0).
    let side_lattice = |side: usize, k: usize| -> (usize, usize) {
        match side {
            0 => (k, 0),
            1 => (3 - k, k),
            _ => (0, 3 - k),
        }
    };
    let stride = check_n / fit_n;
    let mut triangles = Vec::with_capacity(level.face_count());
    let mut checks = Vec::with_capacity(level.face_count());
    for f in 0..level.face_count() as u32 {
        let corners = level.face(f);
        if corners.len() != 3 {
            return Err(failed("a face of the level is not a triangle"));
        }
        let (grid, extra) = limit(f)?;
        // The fitting grid's point (a, b).
        let fine = |a: usize, b: usize| at(&grid, check_n, stride * a, stride * b);
        let mut lattice = [DVec3::ZERO; 10];
        for side in 0..3 {
            let (a, b) = (corners[side], corners[(side + 1) % 3]);
            let along = (0..=fit_n)
                .map(|k| {
                    let slot = side_slot(side, fit_n, k);
                    fine(slot / (fit_n + 1), slot % (fit_n + 1))
                })
                .collect::<Result<Vec<_>, _>>()?;
            let row = fit_shared_edge(&along, a, b);
            for (k, point) in row.into_iter().enumerate() {
                let (i, j) = side_lattice(side, k);
                lattice[lattice_index(3, i, j)] = point;
            }
        }
        // b₁₁₁ by least squares over the inner points, its basis 6uvw.
        let centre = lattice_index(3, 1, 1);
        lattice[centre] = DVec3::ZERO;
        let rim = TriangleBezier::new(3, lattice.to_vec())?;
        let (mut num, mut den) = (DVec3::ZERO, 0.0);
        for a in 1..fit_n {
            for b in 1..fit_n - a {
                let (u, v) = (a as f64 / fit_n as f64, b as f64 / fit_n as f64);
                let basis = 6.0 * u * v * (1.0 - u - v);
                let rest = fine(a, b)? - rim.evaluate(u, v).point;
                num += rest * basis;
                den += basis * basis;
            }
        }
        lattice[centre] = num / den;
        triangles.push(TriangleBezier::new(3, lattice.to_vec())?);
        let mut points = grid_points(grid, check_n);
        points.extend(extra);
        checks.push(points);
    }
    // The distance from a limit point to the patches: its own patch's nearest point, or,
    // where that would raise the largest, the nearest point of the patches around its
    // triangle's corners (near a boundary vertex the limit's parametrization strays from the
    // triangle's, so a point of one triangle's grid may lie over its neighbour's patch).
    let nearest = |patch: &TriangleBezier, start: (f64, f64), limit: DVec3| {
        let eval = |u: f64, v: f64| {
            let d = patch.evaluate(u, v);
            (d.point, d.su, d.sv)
        };
        distance_near(&eval, clamp_triangle, start, limit)
    };
    let mut deviation = 0.0f64;
    for (f, (patch, points)) in triangles.iter().zip(checks).enumerate() {
        for (start, limit) in points {
            let mut d = nearest(patch, start, limit);
            if d > deviation {
                for &corner in level.face(f as u32) {
                    for &g in level.vertex_faces(corner) {
                        let other = &triangles[g as usize];
                        let start = (0..=3)
                            .flat_map(|i| {
                                (0..=3 - i).map(move |j| (i as f64 / 3.0, j as f64 / 3.0))
                            })
                            .min_by(|x, y| {
                                let dx = other.evaluate(x.0, x.1).point.distance(limit);
                                let dy = other.evaluate(y.0, y.1).point.distance(limit);
                                dx.total_cmp(&dy)
                            })
                            .unwrap_or((1.0 / 3.0, 1.0 / 3.0));
                        d = d.min(nearest(other, start, limit));
                    }
                }
            }
            deviation = deviation.max(d);
        }
        if !deviation.is_finite() {
            return Err(failed("the limit is not finite"));
        }
    }
    let out = triangles
        .iter()
        .map(|t| {
            let tensor = t.tensor_points();
            std::array::from_fn(|i| tensor[i])
        })
        .collect();
    Ok(LimitPatches {
        patches: out,
        exact: 0,
        level: k,
        deviation,
        triangles: true,
    })
}

/// The edge at vertex `w` of `level` between the grid nodes `p` and `q` of a Doo-Sabin region
/// (keys below `level.face_count()` are faces, the others boundary edges past them): the edge
/// the two faces share at `w`, or the boundary edge itself beside a face; None for two
/// boundary edges (the boundary side).
fn dual_edge(level: &Level, p: u32, q: u32, w: u32) -> Option<u32> {
    let faces = level.face_count() as u32;
    match (p < faces, q < faces) {
        (true, true) => level.vertex_edges(w).iter().copied().find(|&e| {
            let [x, y] = level.edge_faces[e as usize];
            (x == p && y == q) || (x == q && y == p)
        }),
        (true, false) => Some(q - faces),
        (false, true) => Some(p - faces),
        (false, false) => None,
    }
}

/// The corners of Doo-Sabin region `v` of `level` (the part of the limit nearest vertex v,
/// parametrized over the dual quad of its faces' centres), counter-clockwise: an interior
/// vertex's four faces in ring order, or a boundary vertex's leaving boundary edge, two faces
/// and arriving boundary edge (edges keyed past the faces). None for a vertex without faces;
/// an error for a vertex of another valence.
fn dual_corners(level: &Level, v: u32) -> Result<Option<[u32; 4]>, GeometryError> {
    let ring = level.ring(v);
    let faces = level.face_count() as u32;
    match (ring.boundary, ring.faces.as_slice()) {
        (_, []) => Ok(None),
        (false, &[a, b, c, d]) => Ok(Some([a, b, c, d])),
        (true, &[a, b]) => {
            let [out, into] = super::schemes::ring_boundary_edges(level, v, &ring)
                .ok_or_else(|| limit_patches_error("a boundary vertex has no boundary edges"))?;
            Ok(Some([faces + out, a, b, faces + into]))
        }
        _ => Err(limit_patches_error(
            "a vertex of the level is not of valence 4 (2 on the boundary)",
        )),
    }
}

/// The grid nodes of Doo-Sabin region `corners` around vertex `v` of level `k`, `depth`
/// levels down: (2^depth + 1)² keys of level k + depth (first index along u, from corner 0 to
/// corner 1). Each step splits every cell, around vertex w, into the cells of w's children:
/// a face node becomes its face's child face, a boundary edge node the child edge between its
/// Chaikin points; between two nodes lies the child face of the edge they share at w (or, on
/// the boundary, the child edge between w's Chaikin points); a cell's centre is w's child
/// face ([`DooSabinLayout`]; `layouts[d]` is level k + d's).
fn dual_grid(
    levels: &[Level],
    layouts: &[DooSabinLayout],
    k: usize,
    corners: [u32; 4],
    v: u32,
    depth: u32,
) -> Result<Vec<u32>, GeometryError> {
    let failed = limit_patches_error;
    let mut n = 1usize;
    let mut nodes = vec![corners[0], corners[3], corners[1], corners[2]];
    let mut cells = vec![v];
    for d in 0..depth as usize {
        let (level, child, layout) = (&levels[k + d], &levels[k + d + 1], &layouts[d]);
        let (faces, child_faces) = (level.face_count() as u32, child.face_count() as u32);
        let child_edge = |a: u32, b: u32| -> Result<u32, GeometryError> {
            edge_between(child, a, b)
                .map(|e| child_faces + e)
                .ok_or_else(|| failed("a child boundary edge is missing"))
        };
        let down = |key: u32| -> Result<u32, GeometryError> {
            if key < faces {
                return Ok(key);
            }
            let e = key - faces;
            let [x, y] = level.edges[e as usize];
            child_edge(layout.chaikin(level, e, x), layout.chaikin(level, e, y))
        };
        let between = |p: u32, q: u32, w: u32| -> Result<u32, GeometryError> {
            match dual_edge(level, p, q, w) {
                Some(e) => Ok(layout.edge_face(level, e)),
                None if p >= faces && q >= faces => child_edge(
                    layout.chaikin(level, p - faces, w),
                    layout.chaikin(level, q - faces, w),
                ),
                None => Err(failed("two faces of a region share no edge")),
            }
        };
        let corner_child = |key: u32, w: u32| {
            if key < faces {
                layout.point(level, key, w)
            } else {
                layout.chaikin(level, key - faces, w)
            }
        };
        let m = 2 * n;
        let node = |i: usize, j: usize| nodes[i * (n + 1) + j];
        let mut next = vec![NONE; (m + 1) * (m + 1)];
        let mut next_cells = vec![NONE; m * m];
        for i in 0..=n {
            for j in 0..=n {
                next[2 * i * (m + 1) + 2 * j] = down(node(i, j))?;
                if i < n {
                    let w = cells[i * n + j.min(n - 1)];
                    next[(2 * i + 1) * (m + 1) + 2 * j] = between(node(i, j), node(i + 1, j), w)?;
                }
                if j < n {
                    let w = cells[i.min(n - 1) * n + j];
                    next[2 * i * (m + 1) + 2 * j + 1] = between(node(i, j), node(i, j + 1), w)?;
                }
                if i < n && j < n {
                    let w = cells[i * n + j];
                    let centre = layout.vertex_face[w as usize];
                    if centre == NONE {
                        return Err(failed("a vertex of the level has no child face"));
                    }
                    next[(2 * i + 1) * (m + 1) + 2 * j + 1] = centre;
                    for (di, dj) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                        next_cells[(2 * i + di) * m + 2 * j + dj] =
                            corner_child(node(i + di, j + dj), w);
                    }
                }
            }
        }
        nodes = next;
        cells = next_cells;
        n = m;
    }
    Ok(nodes)
}

/// The grid of level-(k + 2·depth) vertices over √3 triangle `corners` of level k (k even, so
/// that its two steps refine the boundary once): two steps split a triangle into nine, its
/// sides in three, so the grid has n = 3^depth segments per side, point (a, b), a + b ≤ n, at
/// slot a·(n + 1) + b (corner 1 at (n, 0), corner 2 at (0, n)). Depth 1: the corners, the
/// centroid at (1, 1), and on each side the centroids of the two first-step triangles beside
/// it (the edge flipped between the centroids either side), or on the boundary its ternary
/// points. A triangle on the boundary does not split into nine (its strip along the boundary
/// holds the centroid of its first-step triangle there): the sub-triangles that are not faces
/// leave their points out (None), and so does a `corners` that is not a face. `ternary[l]` is
/// level l's [`sqrt3_ternary_starts`].
fn ternary_grid(
    levels: &[Level],
    ternary: &[Vec<u32>],
    k: usize,
    corners: [u32; 3],
    depth: u32,
) -> Result<Vec<Option<u32>>, GeometryError> {
    let failed = limit_patches_error;
    let n = 3usize.pow(depth);
    let mut grid = vec![None; (n + 1) * (n + 1)];
    if depth == 0 {
        grid[0] = Some(corners[0]);
        grid[n + 1] = Some(corners[1]);
        grid[1] = Some(corners[2]);
        return Ok(grid);
    }
    let (level, middle) = (&levels[k], &levels[k + 1]);
    // A face of `level` with all of `vertices`.
    let face_with = |level: &Level, vertices: &[u32]| -> Result<u32, GeometryError> {
        level
            .vertex_faces(vertices[0])
            .iter()
            .copied()
            .find(|&f| vertices.iter().all(|v| level.face(f).contains(v)))
            .ok_or_else(|| failed("a triangle of the level is missing"))
    };
    let Ok(f) = face_with(level, &corners) else {
        return Ok(grid);
    };
    let centroid = |level: &Level, f: u32| level.vertex_count as u32 + f;
    let c = centroid(level, f);
    let mut first = [None; 16];
    let mut put = |a: usize, b: usize, v: u32| first[a * 4 + b] = Some(v);
    put(0, 0, corners[0]);
    put(3, 0, corners[1]);
    put(0, 3, corners[2]);
    put(1, 1, c);
    for (side, slots) in [[(1, 0), (2, 0)], [(2, 1), (1, 2)], [(0, 2), (0, 1)]]
        .into_iter()
        .enumerate()
    {
        let (p, q) = (corners[side], corners[(side + 1) % 3]);
        let e = edge_between(level, p, q).ok_or_else(|| failed("a triangle side is missing"))?;
        let [x, y] = level.edge_faces[e as usize];
        let points = if y == NONE {
            let e =
                edge_between(middle, p, q).ok_or_else(|| failed("a boundary side is missing"))?;
            let t = ternary[k + 1][e as usize];
            if directed_ends(middle, e)[0] == p {
                [t, t + 1]
            } else {
                [t + 1, t]
            }
        } else {
            let across = centroid(level, if x == f { y } else { x });
            [
                centroid(middle, face_with(middle, &[c, across, p])?),
                centroid(middle, face_with(middle, &[c, across, q])?),
            ]
        };
        for ((a, b), v) in slots.into_iter().zip(points) {
            put(a, b, v);
        }
    }
    if depth == 1 {
        return Ok(first.to_vec());
    }
    let h = n / 3;
    let vertex =
        |a: usize, b: usize| first[a * 4 + b].ok_or_else(|| failed("a grid point is missing"));
    for a in 0..3 {
        for b in 0..3 - a {
            // Upward: (a, b), (a + 1, b), (a, b + 1); downward: (a + 1, b), (a + 1, b + 1),
            // (a, b + 1), where a + b ≤ 1.
            let up = [vertex(a, b)?, vertex(a + 1, b)?, vertex(a, b + 1)?];
            let sub = ternary_grid(levels, ternary, k + 2, up, depth - 1)?;
            for x in 0..=h {
                for y in 0..=h - x {
                    let slot = &mut grid[(a * h + x) * (n + 1) + b * h + y];
                    *slot = slot.or(sub[x * (h + 1) + y]);
                }
            }
            if a + b <= 1 {
                let down = [vertex(a + 1, b)?, vertex(a + 1, b + 1)?, vertex(a, b + 1)?];
                let sub = ternary_grid(levels, ternary, k + 2, down, depth - 1)?;
                for x in 0..=h {
                    for y in 0..=h - x {
                        let slot = &mut grid[((a + 1) * h - y) * (n + 1) + b * h + x + y];
                        *slot = slot.or(sub[x * (h + 1) + y]);
                    }
                }
            }
        }
    }
    Ok(grid)
}

impl SubdivisionSurface {
    /// The limit surface as bicubic Bézier patches within `tolerance` where it can (see the
    /// module's notes): Catmull-Clark's and Doo-Sabin's as four-sided patches, Loop's, the
    /// butterfly's and √3's as cubic triangles. The level rises until the deviation is within
    /// `tolerance` or the refinement would pass a size limit.
    pub fn limit_patches(&self, tolerance: f64) -> Result<LimitPatches, GeometryError> {
        let scheme = self.options.scheme;
        let base = self.base_level()?;
        // The first level tried, the step between levels, how many faces a face becomes per
        // level, and how many levels further the check refines.
        let (start, step, growth, check): (u32, u32, usize, u32) = match scheme {
            Scheme::CatmullClark => (u32::from(base.faces().any(|f| f.len() != 4)), 1, 4, 3),
            Scheme::Loop | Scheme::Butterfly => (0, 1, 4, 3),
            Scheme::DooSabin => {
                let four_sided = (0..base.vertex_count as u32)
                    .all(|v| dual_corners(&base, v).is_ok_and(|c| c.is_some()));
                (u32::from(!four_sided), 1, 4, 3)
            }
            Scheme::Sqrt3 => (0, 2, 3, 4),
        };
        let mut best: Option<LimitPatches> = None;
        let mut k = start;
        while k <= MAX_PATCH_LEVEL {
            let checked = base
                .face_count()
                .saturating_mul(growth.saturating_pow(k + check));
            if checked > MAX_CHECK_FACES && best.is_some() {
                break;
            }
            // The first level tried may refine further (a large cage gets its patches at
            // least), within MAX_FIRST_CHECK_FACES; past it, the finest level checked stays
            // within MAX_CHECK_FACES.
            let max_faces = if best.is_none() {
                MAX_FIRST_CHECK_FACES
            } else {
                MAX_CHECK_FACES
            };
            let patches = match scheme {
                Scheme::CatmullClark => self.limit_patches_at(k, max_faces)?,
                Scheme::Loop | Scheme::Butterfly => self.limit_triangles_at(k, max_faces)?,
                Scheme::DooSabin => self.limit_dual_patches_at(k, max_faces)?,
                Scheme::Sqrt3 => self.limit_sqrt3_at(k, max_faces)?,
            };
            let done = patches.deviation <= tolerance;
            best = Some(patches);
            if done {
                break;
            }
            k += step;
        }
        best.ok_or_else(|| GeometryError::Construction {
            what: "limit patches",
            message: "the cage is too large to refine".into(),
        })
    }

    /// The hierarchy to level `levels` (each level within `max_faces`) and the cage's points
    /// carried to every level.
    fn levels_to(
        &self,
        levels: u32,
        max_faces: usize,
    ) -> Result<(Hierarchy, Vec<Vec<DVec3>>), GeometryError> {
        let hierarchy = Hierarchy::deep(self.base_level()?, self.options, levels, max_faces)?;
        let mut points = vec![self.points().to_vec()];
        for stencils in &hierarchy.stencils {
            let next = stencils.apply(points.last().map_or(&[][..], |p| p.as_slice()));
            points.push(next);
        }
        Ok((hierarchy, points))
    }

    /// The patches of level `k`'s faces (refining to level k + 3, each level within `max_faces`).
    fn limit_patches_at(&self, k: u32, max_faces: usize) -> Result<LimitPatches, GeometryError> {
        let scheme = self.options.scheme;
        let (hierarchy, points) = self.levels_to(k + 3, max_faces)?;
        let failed = limit_patches_error;
        let kk = k as usize;
        let level = &hierarchy.levels[kk];
        let limit_grid = |f: u32| -> Result<Vec<DVec3>, GeometryError> {
            let l = kk + 3;
            face_grid(&hierarchy, kk, f, 3)
                .into_iter()
                .map(|v| {
                    let v = v.ok_or_else(|| failed("a face of the level is not a quad"))?;
                    Ok(limit_position(&hierarchy.levels[l], scheme, v).apply(&points[l]))
                })
                .collect()
        };
        let sides = |f: u32| -> Result<[Side; 4], GeometryError> {
            let corners = level.face(f);
            if corners.len() != 4 {
                return Err(failed("a face of the level is not a quad"));
            }
            Ok(std::array::from_fn(|side| {
                let e = level.face_edges(f)[side];
                let [x, y] = level.edge_faces[e as usize];
                Side {
                    across: if x == f { y } else { x },
                    from: corners[side],
                    to: corners[(side + 1) % 4],
                }
            }))
        };
        // Exact patches where the face is regular.
        let exact: Vec<Option<[DVec3; 16]>> = (0..level.face_count() as u32)
            .map(|f| {
                let control: Option<[DVec3; 16]> = if is_regular_face(level, scheme, f) {
                    bspline_grid(level, f).map(|g| g.map(|v| points[kk][v as usize]))
                } else {
                    None
                }
                .or_else(|| {
                    boundary_bspline_grid(level, scheme, f)
                        .map(|rows| std::array::from_fn(|i| rows[i].apply(&points[kk])))
                });
                control.map(|c| to_bezier(&BSPLINE_TO_BEZIER, &c))
            })
            .collect();
        fit_quad_regions(k, &exact, &sides, &limit_grid)
    }

    /// Doo-Sabin's limit as one four-sided patch per vertex of level `k` (every vertex of a
    /// level past the cage has four faces, or two and two boundary edges): the patch spans the
    /// dual quad of the vertex's faces' centres ([`dual_corners`]), whose limit points are
    /// the faces' centroids (a Doo-Sabin step keeps a face's centroid and shrinks the face
    /// about it) and boundary edges' midpoints (the boundary's limit is the quadratic B-spline
    /// of its polygon). Exact where the vertex's four faces are quads: the limit there is the
    /// biquadratic B-spline of its 3 × 3 points, raised to degree 3. Refines to level k + 3,
    /// each level within `max_faces`.
    fn limit_dual_patches_at(
        &self,
        k: u32,
        max_faces: usize,
    ) -> Result<LimitPatches, GeometryError> {
        let (hierarchy, points) = self.levels_to(k + 3, max_faces)?;
        let kk = k as usize;
        let levels = &hierarchy.levels;
        let level = &levels[kk];
        let layouts: Vec<DooSabinLayout> =
            levels[kk..kk + 3].iter().map(DooSabinLayout::new).collect();
        let mut regions: Vec<(u32, [u32; 4])> = Vec::new();
        let mut region_of = vec![NONE; level.vertex_count];
        for v in 0..level.vertex_count as u32 {
            if let Some(corners) = dual_corners(level, v)? {
                region_of[v as usize] = regions.len() as u32;
                regions.push((v, corners));
            }
        }
        // The limit point of a grid node of level k + 3.
        let (fine, at) = (&levels[kk + 3], &points[kk + 3]);
        let limit_point = |key: u32| -> DVec3 {
            let faces = fine.face_count() as u32;
            if key < faces {
                let face = fine.face(key);
                face.iter().map(|&v| at[v as usize]).sum::<DVec3>() / face.len() as f64
            } else {
                let [a, b] = fine.edges[(key - faces) as usize];
                (at[a as usize] + at[b as usize]) * 0.5
            }
        };
        let limit_grid = |r: u32| -> Result<Vec<DVec3>, GeometryError> {
            let (v, corners) = regions[r as usize];
            Ok(dual_grid(levels, &layouts, kk, corners, v, 3)?
                .into_iter()
                .map(limit_point)
                .collect())
        };
        let sides = |r: u32| -> Result<[Side; 4], GeometryError> {
            let (v, corners) = regions[r as usize];
            Ok(std::array::from_fn(|side| {
                let (from, to) = (corners[side], corners[(side + 1) % 4]);
                let across = dual_edge(level, from, to, v)
                    .map_or(NONE, |e| region_of[level.other_end(e, v) as usize]);
                Side { across, from, to }
            }))
        };
        let exact: Vec<Option<[DVec3; 16]>> = regions
            .iter()
            .map(|&(v, corners)| {
                let control = biquadratic_grid(level, v, corners)?;
                Some(to_bezier(
                    &BIQUADRATIC_TO_BEZIER,
                    &control.map(|p| points[kk][p as usize]),
                ))
            })
            .collect();
        fit_quad_regions(k, &exact, &sides, &limit_grid)
    }

    /// The cubic triangles of level `k`'s faces (Loop, butterfly), each as its collapsed
    /// bicubic patch ([`fit_triangle_regions`]), fitted to the limit points of level k + 2
    /// ([`face_grid`], four segments a side) and checked at those of level k + 3.
    fn limit_triangles_at(&self, k: u32, max_faces: usize) -> Result<LimitPatches, GeometryError> {
        let scheme = self.options.scheme;
        let (hierarchy, points) = self.levels_to(k + 3, max_faces)?;
        let kk = k as usize;
        let limit_grid = |f: u32| -> Result<Vec<Option<DVec3>>, GeometryError> {
            let (l, s) = (kk + 3, 8);
            Ok(face_grid(&hierarchy, kk, f, 3)
                .into_iter()
                .enumerate()
                .map(|(slot, v)| {
                    let (a, b) = (slot / (s + 1), slot % (s + 1));
                    let v = v.filter(|_| a + b <= s)?;
                    Some(limit_position(&hierarchy.levels[l], scheme, v).apply(&points[l]))
                })
                .collect())
        };
        fit_triangle_regions(
            (k, &hierarchy.levels[kk]),
            4,
            (8, &|f| Ok((limit_grid(f)?, Vec::new()))),
        )
    }

    /// √3's limit as cubic triangles of level `k` (even): fitted to the limit points of level
    /// k + 2 (three segments a side, [`ternary_grid`]) and checked at those of level k + 4
    /// (nine a side, the grid the first is every third point of).
    fn limit_sqrt3_at(&self, k: u32, max_faces: usize) -> Result<LimitPatches, GeometryError> {
        let (hierarchy, points) = self.levels_to(k + 4, max_faces)?;
        let kk = k as usize;
        let levels = &hierarchy.levels;
        let level = &levels[kk];
        let ternary: Vec<Vec<u32>> = levels.iter().map(sqrt3_ternary_starts).collect();
        let l = kk + 4;
        let fine = &levels[l];
        let limit = |v: u32| limit_position(fine, Scheme::Sqrt3, v).apply(&points[l]);
        // Face f's ternary grid of level k + 4 (nine segments a side; its every third point
        // is level k + 2's), with that level's boundary polygon along a boundary side; and,
        // beside a boundary side, the vertices of the strip the grid leaves out: those within
        // three edges of the side's points (the strip is three edges deep at that level),
        // each looked for near that point.
        let limit_grid = |f: u32| -> Result<(Vec<Option<DVec3>>, ParamPoints), GeometryError> {
            let corners: [u32; 3] = level
                .face(f)
                .try_into()
                .map_err(|_| limit_patches_error("a face of the level is not a triangle"))?;
            let mut grid = ternary_grid(levels, &ternary, kk, corners, 2)?;
            let boundary_sides: Vec<usize> = (0..3)
                .filter(|&side| {
                    edge_between(level, corners[side], corners[(side + 1) % 3])
                        .is_some_and(|e| level.is_boundary_edge(e))
                })
                .collect();
            for &side in &boundary_sides {
                let mut v = corners[side];
                for j in 0..=9 {
                    grid[side_slot(side, 9, j)] = Some(v);
                    v = boundary_neighbours(fine, v)[0];
                }
                if grid[side_slot(side, 9, 9)] != Some(corners[(side + 1) % 3]) {
                    return Err(limit_patches_error(
                        "a boundary side does not reach its corner",
                    ));
                }
            }
            let mut extra = Vec::new();
            let mut seen: std::collections::HashSet<u32> = grid.iter().flatten().copied().collect();
            for &side in &boundary_sides {
                for j in 0..=9 {
                    let slot = side_slot(side, 9, j);
                    let Some(root) = grid[slot] else { continue };
                    let start = ((slot / 10) as f64 / 9.0, (slot % 10) as f64 / 9.0);
                    let mut front = vec![root];
                    for _ in 0..3 {
                        let mut next = Vec::new();
                        for v in front {
                            for &e in fine.vertex_edges(v) {
                                let w = fine.other_end(e, v);
                                if seen.insert(w) {
                                    extra.push((start, limit(w)));
                                    next.push(w);
                                }
                            }
                        }
                        front = next;
                    }
                }
            }
            Ok((grid.into_iter().map(|v| v.map(limit)).collect(), extra))
        };
        fit_triangle_regions((k, level), 3, (9, &limit_grid))
    }
}

/// The slot of point `j` (0..=n) along triangle side `side` (corner 0 → 1 → 2 → 0) in a grid
/// of `n` segments a side.
fn side_slot(side: usize, n: usize, j: usize) -> usize {
    let (a, b) = match side {
        0 => (j, 0),
        1 => (n - j, j),
        _ => (0, n - j),
    };
    a * (n + 1) + b
}

/// The uniform quadratic B-spline segment with points P0..P2 as a cubic Bézier (its quadratic
/// Bézier points (P0 + P1)/2, P1, (P1 + P2)/2 raised to degree 3; rows: Bézier point,
/// columns: B-spline point).
const BIQUADRATIC_TO_BEZIER: [[f64; 3]; 4] = [
    [0.5, 0.5, 0.0],
    [1.0 / 6.0, 5.0 / 6.0, 0.0],
    [0.0, 5.0 / 6.0, 1.0 / 6.0],
    [0.0, 0.5, 0.5],
];

/// The tensor-product Bézier points of B-spline points `control` (N × N, row-major, first
/// index along u) through the segment matrix `m` (4 × N).
fn to_bezier<const N: usize, const M: usize>(
    m: &[[f64; N]; 4],
    control: &[DVec3; M],
) -> [DVec3; 16] {
    let mut out = [DVec3::ZERO; 16];
    for i in 0..4 {
        for j in 0..4 {
            for a in 0..N {
                for b in 0..N {
                    out[i * 4 + j] += control[a * N + b] * (m[i][a] * m[j][b]);
                }
            }
        }
    }
    out
}

/// The 3 × 3 biquadratic B-spline points of Doo-Sabin region `corners` around interior vertex
/// `v` (first index along u), when its four faces are quads: v in the middle, the neighbours
/// two faces share between them on the sides, each face's far corner on the diagonals.
fn biquadratic_grid(level: &Level, v: u32, corners: [u32; 4]) -> Option<[u32; 9]> {
    let faces = level.face_count() as u32;
    if corners
        .iter()
        .any(|&f| f >= faces || level.face(f).len() != 4)
    {
        return None;
    }
    let shared = |f: u32, g: u32| {
        level
            .face(f)
            .iter()
            .copied()
            .find(|&x| x != v && level.face(g).contains(&x))
    };
    let [f0, f1, f2, f3] = corners;
    let (s01, s12, s23, s30) = (
        shared(f0, f1)?,
        shared(f1, f2)?,
        shared(f2, f3)?,
        shared(f3, f0)?,
    );
    let diagonal = |f: u32| level.diagonal(f, v);
    // Grid (a, b) at a·3 + b: corner 0 (face f0) at (0, 0), f1 at (1, 0) along u, f3 along v.
    Some([
        diagonal(f0),
        s30,
        diagonal(f3),
        s01,
        v,
        s23,
        diagonal(f1),
        s12,
        diagonal(f2),
    ])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::NurbsSurface;
    use crate::subdiv::cages;

    fn surfaces(patches: &LimitPatches) -> Vec<NurbsSurface> {
        patches
            .patches
            .iter()
            .map(|p| NurbsSurface::bezier([3, 3], p.to_vec(), None).unwrap())
            .collect()
    }

    /// The largest distance from `points` to the nearest of `faces` (those whose box, grown
    /// by `margin`, holds the point).
    fn farthest(points: &[DVec3], faces: &[NurbsSurface], margin: f64) -> f64 {
        points
            .iter()
            .map(|p| {
                faces
                    .iter()
                    .filter(|s| {
                        let (lo, hi) = s.bounds();
                        p.cmpge(lo - margin).all() && p.cmple(hi + margin).all()
                    })
                    .filter_map(|s| s.closest_point(*p).ok())
                    .map(|c| c.distance)
                    .fold(f64::INFINITY, f64::min)
            })
            .fold(0.0, f64::max)
    }

    /// The 16 points on a bicubic patch's four sides.
    fn boundary(p: &[DVec3; 16]) -> Vec<DVec3> {
        (0..4)
            .flat_map(|s| (0..4).map(move |k| p[side_index(s, k)]))
            .collect()
    }

    #[test]
    fn a_regular_cage_is_exact_and_matches_its_limit_points() {
        // A torus of 8 × 6 quads: every vertex has valence 4.
        let cage = cages::torus(DVec3::ZERO, 3.0, 1.0, 8, 6).unwrap();
        let surface = SubdivisionSurface::from_mesh(cage, 1).unwrap();
        let patches = surface.limit_patches(1e-9).unwrap();
        assert_eq!(patches.level, 0);
        assert_eq!(patches.exact, patches.patches.len());
        assert_eq!(patches.deviation, 0.0);
        // The limit points of level 2 lie on the patches (independently: the limit mesh).
        let limit = surface.limit(2).unwrap();
        let worst = farthest(&limit.positions, &surfaces(&patches), 1e-6);
        assert!(worst < 1e-9, "a limit point {worst} from the patches");
    }

    #[test]
    fn a_cube_cage_is_approximated_within_the_tolerance_and_its_patches_meet_exactly() {
        let cage = cages::cube(DVec3::ZERO, 2.0).unwrap();
        let surface = SubdivisionSurface::from_mesh(cage, 1).unwrap();
        let tolerance = 2e-4;
        let patches = surface.limit_patches(tolerance).unwrap();
        assert!(patches.deviation <= tolerance, "{}", patches.deviation);
        assert!(patches.exact > 0 && patches.exact < patches.patches.len());
        // Every limit point of level 4 is within the deviation (and a little for the points
        // between the checked ones) of the patches.
        let limit = surface.limit(4).unwrap();
        let worst = farthest(&limit.positions, &surfaces(&patches), 0.1);
        println!(
            "cube: level {}, {} patches ({} exact), deviation {:.2e}, level-4 limit points within {worst:.2e}",
            patches.level,
            patches.patches.len(),
            patches.exact,
            patches.deviation
        );
        assert!(worst <= 1.5 * tolerance, "worst {worst}");
        // Neighbouring patches share their boundary rows (to rounding, where both are exact
        // and each converted its own B-spline points): every boundary point of a patch is a
        // boundary point of another.
        for (a, pa) in patches.patches.iter().enumerate() {
            for q in boundary(pa) {
                let shared =
                    patches.patches.iter().enumerate().any(|(b, pb)| {
                        b != a && boundary(pb).iter().any(|r| r.distance(q) < 1e-12)
                    });
                assert!(shared, "patch {a}: boundary point {q} is on no other patch");
            }
        }
    }
    #[test]
    fn loop_and_butterfly_cages_are_cubic_triangles_within_the_tolerance_that_meet_exactly() {
        // The butterfly's limit is only C¹ (less smooth than Loop's), so cubics approach it
        // more slowly: it is asked for less.
        for (scheme, tolerance) in [(Scheme::Loop, 2e-3), (Scheme::Butterfly, 5e-3)] {
            let cage = cages::icosahedron(DVec3::new(1.0, 0.0, -2.0), 2.0).unwrap();
            let options = super::super::Options {
                scheme,
                ..Default::default()
            };
            let surface = SubdivisionSurface::new(cage, vec![], vec![], options, 1).unwrap();
            let patches = surface.limit_patches(tolerance).unwrap();
            assert!(patches.triangles);
            assert!(patches.deviation <= tolerance, "{}", patches.deviation);
            assert_eq!(patches.patches.len(), 20 << (2 * patches.level));
            // Independently: every limit point of a finer level is within the tolerance (and
            // a little for the points between the checked ones) of the patches.
            let limit = surface.limit(patches.level + 4).unwrap();
            let worst = farthest(&limit.positions, &surfaces(&patches), 0.1);
            println!(
                "{scheme:?} icosahedron: level {}, {} triangles, deviation {:.2e}, level-{} limit points within {worst:.2e}",
                patches.level,
                patches.patches.len(),
                patches.deviation,
                patches.level + 4
            );
            assert!(worst <= 1.5 * tolerance, "{scheme:?}: worst {worst}");
            // Each patch's side u = 1 is its corner; the other sides are the triangle's, each
            // the same bits as a neighbour's side.
            for (a, pa) in patches.patches.iter().enumerate() {
                assert!(
                    (0..4).all(|k| pa[12 + k] == pa[12]),
                    "side u = 1 is not a point"
                );
                for q in boundary(pa) {
                    let shared =
                        patches.patches.iter().enumerate().any(|(b, pb)| {
                            b != a && boundary(pb).iter().any(|r| r.distance(q) == 0.0)
                        });
                    assert!(shared, "{scheme:?} patch {a}: {q} is on no other patch");
                }
            }
        }
    }

    fn with_scheme(cage: crate::mesh::PolygonMesh, scheme: Scheme) -> SubdivisionSurface {
        let options = super::super::Options {
            scheme,
            ..Default::default()
        };
        SubdivisionSurface::new(cage, vec![], vec![], options, 1).unwrap()
    }

    /// A 4 × 4 grid of quads over [−2, 2]², lifted onto the saddle z = (x² − y²)/4, its
    /// quads split into triangles when `triangles`.
    fn saddle(triangles: bool) -> crate::mesh::PolygonMesh {
        let id = |i: u32, j: u32| i * 5 + j;
        let points = (0..25)
            .map(|k| {
                let (x, y) = ((k / 5) as f64 - 2.0, (k % 5) as f64 - 2.0);
                DVec3::new(x, y, (x * x - y * y) / 4.0)
            })
            .collect();
        let mut faces = Vec::new();
        for i in 0..4 {
            for j in 0..4 {
                let q = [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)];
                if triangles {
                    faces.push(vec![q[0], q[1], q[2]]);
                    faces.push(vec![q[0], q[2], q[3]]);
                } else {
                    faces.push(q.to_vec());
                }
            }
        }
        crate::mesh::PolygonMesh::new(points, &faces).unwrap()
    }

    /// Points of Doo-Sabin's limit at `level`, independently of the patches: every face's
    /// centroid (a step keeps a face's centroid and shrinks the face about it) and every
    /// boundary edge's midpoint (the boundary's limit is the quadratic B-spline of its polygon).
    fn doo_sabin_limit_points(surface: &SubdivisionSurface, level: u32) -> Vec<DVec3> {
        let (hierarchy, points) = surface.levels_to(level, usize::MAX).unwrap();
        let (mesh, at) = (&hierarchy.levels[level as usize], &points[level as usize]);
        let mut out: Vec<DVec3> = mesh
            .faces()
            .map(|f| f.iter().map(|&v| at[v as usize]).sum::<DVec3>() / f.len() as f64)
            .collect();
        for (e, &[a, b]) in mesh.edges.iter().enumerate() {
            if mesh.is_boundary_edge(e as u32) {
                out.push((at[a as usize] + at[b as usize]) * 0.5);
            }
        }
        out
    }

    /// Every boundary point of a patch is a boundary point of another (within `within`).
    fn assert_sides_shared(patches: &LimitPatches, within: f64, what: &str) {
        for (a, pa) in patches.patches.iter().enumerate() {
            for q in boundary(pa) {
                let shared =
                    patches.patches.iter().enumerate().any(|(b, pb)| {
                        b != a && boundary(pb).iter().any(|r| r.distance(q) <= within)
                    });
                assert!(
                    shared,
                    "{what}: patch {a}'s boundary point {q} is on no other patch"
                );
            }
        }
    }

    /// On a closed surface about `centre`, every patch's normal at its middle points away
    /// from the centre.
    fn assert_outward(patches: &LimitPatches, centre: DVec3, what: &str) {
        for (k, surface) in surfaces(patches).iter().enumerate() {
            let (u, v) = if patches.triangles {
                (0.3, 0.3)
            } else {
                (0.5, 0.5)
            };
            let at = surface.evaluate(u, v).unwrap().point;
            assert!(
                surface.normal(u, v).unwrap().dot(at - centre) > 0.0,
                "{what}: patch {k} faces inwards"
            );
        }
    }

    #[test]
    fn doo_sabin_on_a_regular_cage_is_its_biquadratic_b_spline_exactly() {
        let cage = cages::torus(DVec3::ZERO, 3.0, 1.0, 8, 6).unwrap();
        let surface = with_scheme(cage, Scheme::DooSabin);
        let patches = surface.limit_patches(1e-9).unwrap();
        assert_eq!((patches.level, patches.patches.len()), (0, 48));
        assert_eq!(patches.exact, 48);
        assert_eq!(patches.deviation, 0.0);
        let worst = farthest(
            &doo_sabin_limit_points(&surface, 3),
            &surfaces(&patches),
            1e-6,
        );
        assert!(worst < 1e-9, "a limit point {worst} from the patches");
        assert_sides_shared(&patches, 1e-12, "torus");
    }

    #[test]
    fn doo_sabin_and_sqrt3_cages_are_patches_within_the_tolerance_that_meet_exactly() {
        let tolerance = 2e-3;
        let centre = DVec3::new(1.0, 0.0, -2.0);
        let cases = [
            (
                "Doo-Sabin cube",
                Scheme::DooSabin,
                cages::cube(centre, 2.0).unwrap(),
                true,
            ),
            ("Doo-Sabin saddle", Scheme::DooSabin, saddle(false), false),
            (
                "Doo-Sabin icosahedron",
                Scheme::DooSabin,
                cages::icosahedron(centre, 2.0).unwrap(),
                true,
            ),
            (
                "√3 icosahedron",
                Scheme::Sqrt3,
                cages::icosahedron(centre, 2.0).unwrap(),
                true,
            ),
            ("√3 saddle", Scheme::Sqrt3, saddle(true), false),
        ];
        for (what, scheme, cage, closed) in cases {
            let faces = cage.faces().count();
            let surface = with_scheme(cage, scheme);
            let patches = surface.limit_patches(tolerance).unwrap();
            assert!(
                patches.deviation <= tolerance,
                "{what}: {}",
                patches.deviation
            );
            // Independently: limit points of a finer level are within the tolerance (and a
            // little for the points between the checked ones) of the patches.
            let limit = if scheme == Scheme::DooSabin {
                doo_sabin_limit_points(&surface, patches.level + 3)
            } else {
                assert!(patches.triangles);
                if closed {
                    assert_eq!(patches.patches.len(), faces * 3usize.pow(patches.level));
                }
                surface.limit(patches.level + 4).unwrap().positions
            };
            let worst = farthest(&limit, &surfaces(&patches), 0.1);
            println!(
                "{what}: level {}, {} patches ({} exact), deviation {:.2e}, {} limit points of level {} within {worst:.2e}",
                patches.level,
                patches.patches.len(),
                patches.exact,
                patches.deviation,
                limit.len(),
                patches.level + if patches.triangles { 4 } else { 3 }
            );
            assert!(worst <= 1.5 * tolerance, "{what}: worst {worst}");
            if closed {
                // Exact neighbours each convert their own B-spline points: to rounding.
                let within = if patches.exact > 0 { 1e-12 } else { 0.0 };
                assert_sides_shared(&patches, within, what);
                assert_outward(&patches, centre, what);
            }
        }
    }

    #[test]
    fn small_and_open_cages_give_patches_or_a_reason_under_every_scheme() {
        use crate::mesh::PolygonMesh;
        let p = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
        // An open fan of five triangles round an apex (a pentagonal cone without its base),
        // a single triangle, a single quad, a pentagon, two triangles, and a quad strip.
        let ring: Vec<DVec3> = (0..5)
            .map(|k| {
                let a = std::f64::consts::TAU * k as f64 / 5.0;
                p(a.cos(), a.sin(), 0.0)
            })
            .collect();
        let mut fan_points = vec![p(0.0, 0.0, 1.0)];
        fan_points.extend(ring.iter().copied());
        let fan: Vec<Vec<u32>> = (0..5).map(|k| vec![0, 1 + k, 1 + (k + 1) % 5]).collect();
        let cages: Vec<(&str, PolygonMesh)> = vec![
            ("fan", PolygonMesh::new(fan_points, &fan).unwrap()),
            (
                "triangle",
                PolygonMesh::new(
                    vec![p(0.0, 0.0, 0.0), p(1.0, 0.0, 0.0), p(0.0, 1.0, 0.3)],
                    &[vec![0, 1, 2]],
                )
                .unwrap(),
            ),
            (
                "quad",
                PolygonMesh::new(
                    vec![
                        p(0.0, 0.0, 0.0),
                        p(1.0, 0.0, 0.2),
                        p(1.0, 1.0, 0.0),
                        p(0.0, 1.0, 0.2),
                    ],
                    &[vec![0, 1, 2, 3]],
                )
                .unwrap(),
            ),
            (
                "pentagon",
                PolygonMesh::new(ring.clone(), &[vec![0, 1, 2, 3, 4]]).unwrap(),
            ),
            (
                "two triangles",
                PolygonMesh::new(
                    vec![
                        p(0.0, 0.0, 0.0),
                        p(1.0, 0.0, 0.0),
                        p(1.0, 1.0, 0.5),
                        p(0.0, 1.0, 0.0),
                    ],
                    &[vec![0, 1, 2], vec![0, 2, 3]],
                )
                .unwrap(),
            ),
            ("strip", {
                let points = (0..8)
                    .map(|k| p((k / 2) as f64, (k % 2) as f64, ((k / 2) as f64).sin()))
                    .collect();
                let faces: Vec<Vec<u32>> = (0..3)
                    .map(|i| vec![2 * i, 2 * i + 2, 2 * i + 3, 2 * i + 1])
                    .collect();
                PolygonMesh::new(points, &faces).unwrap()
            }),
        ];
        for (what, cage) in cages {
            for scheme in [
                Scheme::CatmullClark,
                Scheme::Loop,
                Scheme::DooSabin,
                Scheme::Sqrt3,
                Scheme::Butterfly,
            ] {
                let triangles = cage.faces().all(|f| f.len() == 3);
                if scheme.needs_triangles() && !triangles {
                    continue;
                }
                let surface = with_scheme(cage.clone(), scheme);
                match surface.limit_patches(1e-3) {
                    Ok(patches) => {
                        assert!(!patches.patches.is_empty(), "{what} {scheme:?}");
                        assert!(patches.deviation.is_finite(), "{what} {scheme:?}");
                        assert!(
                            patches.patches.iter().flatten().all(|q| q.is_finite()),
                            "{what} {scheme:?}: a patch point is not finite"
                        );
                    }
                    Err(e) => println!("{what} {scheme:?}: {e}"),
                }
            }
        }
    }
}
