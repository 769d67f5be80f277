//! A Catmull-Clark limit surface as bicubic Bézier patches for exchange (STEP), one patch per
//! face of a refinement level k:
//!
//! - **Exact** where the limit over the face is a bicubic B-spline: the face and its one-ring
//!   are regular ([`bspline_grid`], [`is_regular_face`]), or it is a regular boundary quad
//!   ([`boundary_bspline_grid`]). The B-spline's 16 points are converted to Bézier form.
//! - **Approximated** elsewhere (at extraordinary vertices, creases and corners): a bicubic
//!   patch whose four boundary curves are shared with its neighbours (an exact neighbour's
//!   boundary row as it is; between two approximated faces the cubic that fits the edge's five
//!   limit points at level k + 2, ends interpolated, the same from either side because the
//!   fit is symmetric), and whose four inner points fit the nine inner limit points of level
//!   k + 2 over the face by least squares.
//!
//! So the patches meet along every edge (to the bit where one of them is approximated, to
//! rounding where both convert their own B-spline points), and the deviation from the limit surface is
//! measured at the 81 limit points of level k + 3 over each approximated face (against the
//! patch at the same dyadic parameters, an upper bound of their distance to the patch). The
//! level rises (past the levels the editor draws, to `MAX_PATCH_LEVEL`) until that deviation is
//! within the tolerance asked for, or the refinement would pass a size limit, and the deviation
//! reached is returned with the patches. Loop and butterfly surfaces take cubic triangles the
//! same way ([`SubdivisionSurface::limit_patches`]).

use glam::DVec3;

use super::limit::limit_position;
use super::patches::{boundary_bspline_grid, bspline_grid, face_grid, is_regular_face};
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

fn patch_point(p: &[DVec3; 16], s: f64, t: f64) -> DVec3 {
    let (bu, bv) = (bernstein3(s), bernstein3(t));
    let mut out = DVec3::ZERO;
    for i in 0..4 {
        for j in 0..4 {
            out += p[i * 4 + j] * (bu[i] * bv[j]);
        }
    }
    out
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

/// The cubic Bézier curve through `a` and `e` that fits b, c, d at t = 1/4, 1/2, 3/4 by least
/// squares (symmetric: the reversed points give the reversed curve).
fn fit_edge(points: [DVec3; 5]) -> [DVec3; 4] {
    let [a, b, c, d, e] = points;
    let ts = [0.25, 0.5, 0.75];
    let targets = [b, c, d];
    // Normal equations for P1, P2: Σ [B1 B2]ᵀ [B1 B2] P = Σ [B1 B2]ᵀ (L − B0 a − B3 e).
    let (mut m11, mut m12, mut m22) = (0.0, 0.0, 0.0);
    let (mut r1, mut r2) = (DVec3::ZERO, DVec3::ZERO);
    for (t, l) in ts.into_iter().zip(targets) {
        let bt = bernstein3(t);
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

/// [`fit_edge`] of the five limit points `along` an edge from vertex `a` to vertex `b`, fitted
/// from the lower-numbered end, so that the faces on both sides get the same bits.
fn fit_shared_edge(along: [DVec3; 5], a: u32, b: u32) -> [DVec3; 4] {
    if a < b {
        fit_edge(along)
    } else {
        let mut back = along;
        back.reverse();
        let mut curve = fit_edge(back);
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

impl SubdivisionSurface {
    /// The limit surface as bicubic Bézier patches within `tolerance` where it can (see the
    /// module's notes): Catmull-Clark only.
    pub fn limit_patches(&self, tolerance: f64) -> Result<LimitPatches, GeometryError> {
        let triangles = match self.options.scheme {
            Scheme::CatmullClark => false,
            Scheme::Loop | Scheme::Butterfly => true,
            Scheme::DooSabin | Scheme::Sqrt3 => {
                return Err(GeometryError::Construction {
                    what: "limit patches",
                    message: format!(
                        "{} surfaces are not written as patches (their faces do not nest \
                         from level to level)",
                        self.options.scheme.label()
                    ),
                });
            }
        };
        let base = self.base_level()?;
        let start = u32::from(!triangles && base.faces().any(|f| f.len() != 4));
        let mut best: Option<LimitPatches> = None;
        for k in start..=MAX_PATCH_LEVEL {
            if base.face_count().saturating_mul(1 << (2 * (k + 3))) > MAX_CHECK_FACES
                && best.is_some()
            {
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
            let patches = if triangles {
                self.limit_triangles_at(k, max_faces)?
            } else {
                self.limit_patches_at(k, max_faces)?
            };
            let done = patches.deviation <= tolerance;
            best = Some(patches);
            if done {
                break;
            }
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
        let limit_grid = |f: u32, depth: u32| -> Result<Vec<DVec3>, GeometryError> {
            let l = kk + depth as usize;
            face_grid(&hierarchy, kk, f, depth)
                .into_iter()
                .map(|v| {
                    let v = v.ok_or_else(|| failed("a face of the level is not a quad"))?;
                    Ok(limit_position(&hierarchy.levels[l], scheme, v).apply(&points[l]))
                })
                .collect()
        };
        let count = level.face_count();
        // Exact patches first.
        let mut patches: Vec<Option<[DVec3; 16]>> = vec![None; count];
        for (f, slot) in patches.iter_mut().enumerate() {
            let f = f as u32;
            let control: Option<[DVec3; 16]> = if is_regular_face(level, scheme, f) {
                bspline_grid(level, f).map(|g| g.map(|v| points[kk][v as usize]))
            } else {
                None
            }
            .or_else(|| {
                boundary_bspline_grid(level, scheme, f)
                    .map(|rows| std::array::from_fn(|i| rows[i].apply(&points[kk])))
            });
            *slot = control.map(|c| {
                let mut out = [DVec3::ZERO; 16];
                for i in 0..4 {
                    for j in 0..4 {
                        for a in 0..4 {
                            for b in 0..4 {
                                out[i * 4 + j] += c[a * 4 + b]
                                    * (BSPLINE_TO_BEZIER[i][a] * BSPLINE_TO_BEZIER[j][b]);
                            }
                        }
                    }
                }
                out
            });
        }
        let exact = patches.iter().filter(|p| p.is_some()).count();
        // Then the others, with the exact neighbours' boundary rows.
        let mut deviation = 0.0f64;
        let mut out = Vec::with_capacity(count);
        for f in 0..count as u32 {
            if let Some(p) = patches[f as usize] {
                out.push(p);
                continue;
            }
            let corners = level.face(f);
            if corners.len() != 4 {
                return Err(failed("a face of the level is not a quad"));
            }
            let fine = limit_grid(f, 2)?;
            let mut p = [DVec3::ZERO; 16];
            for side in 0..4 {
                let (a, b) = (corners[side], corners[(side + 1) % 4]);
                let e = level.face_edges(f)[side];
                let [x, y] = level.edge_faces[e as usize];
                let across = if x == f { y } else { x };
                let shared = patches
                    .get(across as usize)
                    .copied()
                    .flatten()
                    .and_then(|q| {
                        let theirs = level.face(across);
                        let m = (0..theirs.len())
                            .find(|&m| theirs[m] == b && theirs[(m + 1) % theirs.len()] == a)?;
                        // Their side m runs from b to a: ours is it reversed.
                        Some(std::array::from_fn::<DVec3, 4, _>(|k| {
                            q[side_index(m, 3 - k)]
                        }))
                    });
                // Fitted from the lower-numbered end, so both faces get the same bits.
                let row = shared.unwrap_or_else(|| {
                    let along: [DVec3; 5] =
                        std::array::from_fn(|k| fine[grid_side_index(4, side, k)]);
                    fit_shared_edge(along, a, b)
                });
                for (k, point) in row.into_iter().enumerate() {
                    p[side_index(side, k)] = point;
                }
            }
            // The inner points: least squares over the nine inner limit points.
            let inner = [(1, 1), (1, 2), (2, 1), (2, 2)];
            let mut m = [[0.0; 4]; 4];
            let mut r = [DVec3::ZERO; 4];
            for a in 1..4 {
                for b in 1..4 {
                    let (bu, bv) = (bernstein3(a as f64 / 4.0), bernstein3(b as f64 / 4.0));
                    let mut rest = fine[a * 5 + b];
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
                        r[x] += rest * basis[x];
                    }
                }
            }
            for ((i, j), point) in inner.into_iter().zip(solve4(m, r)) {
                p[i * 4 + j] = point;
            }
            // The deviation at level k + 3's limit points over the face.
            let check = limit_grid(f, 3)?;
            for a in 0..=8 {
                for b in 0..=8 {
                    let at = patch_point(&p, a as f64 / 8.0, b as f64 / 8.0);
                    deviation = deviation.max(at.distance(check[a * 9 + b]));
                }
            }
            if !deviation.is_finite() {
                return Err(failed("the limit is not finite"));
            }
            out.push(p);
        }
        Ok(LimitPatches {
            patches: out,
            exact,
            level: k,
            deviation,
            triangles: false,
        })
    }

    /// The cubic triangles of level `k`'s faces (Loop, butterfly), each as its collapsed
    /// bicubic patch: corners at the limit points, each side the cubic that fits the side's
    /// five limit points of level k + 2 (ends interpolated, fitted from the lower-numbered
    /// end so that both faces get the same bits), the inner point b₁₁₁ fitting the three
    /// inner limit points of level k + 2 by least squares. A triangle's grid point (a, b) of
    /// [`face_grid`] is the patch's (u, v) = (a, b) / 2^depth (corner 1 at u = 1, corner 2 at
    /// v = 1). The deviation is measured at the 45 limit points of level k + 3.
    fn limit_triangles_at(&self, k: u32, max_faces: usize) -> Result<LimitPatches, GeometryError> {
        use crate::triangle::{TriangleBezier, lattice_index};
        let scheme = self.options.scheme;
        let (hierarchy, points) = self.levels_to(k + 3, max_faces)?;
        let failed = limit_patches_error;
        let kk = k as usize;
        let level = &hierarchy.levels[kk];
        // The limit points over face f at depth d: slot (a, b) at a·(2^d + 1) + b, a + b ≤ 2^d.
        let limit_grid = |f: u32, depth: u32| -> Result<Vec<Option<DVec3>>, GeometryError> {
            let l = kk + depth as usize;
            let s = 1usize << depth;
            face_grid(&hierarchy, kk, f, depth)
                .into_iter()
                .enumerate()
                .map(|(slot, v)| {
                    let (a, b) = (slot / (s + 1), slot % (s + 1));
                    if a + b > s {
                        return Ok(None);
                    }
                    let v = v.ok_or_else(|| failed("a face of the level is not a triangle"))?;
                    Ok(Some(
                        limit_position(&hierarchy.levels[l], scheme, v).apply(&points[l]),
                    ))
                })
                .collect()
        };
        let at = |grid: &[Option<DVec3>], s: usize, a: usize, b: usize| {
            grid[a * (s + 1) + b].ok_or_else(|| failed("a limit point is missing"))
        };
        // The lattice index (i, j) of point k along side `side` (corner 0 → 1 → 2 → 0).
        let side_lattice = |side: usize, k: usize| -> (usize, usize) {
            match side {
                0 => (k, 0),
                1 => (3 - k, k),
                _ => (0, 3 - k),
            }
        };
        let side_slot = |side: usize, k: usize| -> (usize, usize) {
            match side {
                0 => (k, 0),
                1 => (4 - k, k),
                _ => (0, 4 - k),
            }
        };
        let mut deviation = 0.0f64;
        let mut out = Vec::with_capacity(level.face_count());
        for f in 0..level.face_count() as u32 {
            let corners = level.face(f);
            if corners.len() != 3 {
                return Err(failed("a face of the level is not a triangle"));
            }
            let fine = limit_grid(f, 2)?;
            let mut lattice = [DVec3::ZERO; 10];
            for side in 0..3 {
                let (a, b) = (corners[side], corners[(side + 1) % 3]);
                let along: [DVec3; 5] = {
                    let mut row = [DVec3::ZERO; 5];
                    for (k, slot) in row.iter_mut().enumerate() {
                        let (x, y) = side_slot(side, k);
                        *slot = at(&fine, 4, x, y)?;
                    }
                    row
                };
                let row = fit_shared_edge(along, a, b);
                for (k, point) in row.into_iter().enumerate() {
                    let (i, j) = side_lattice(side, k);
                    lattice[lattice_index(3, i, j)] = point;
                }
            }
            // b₁₁₁ by least squares over the inner points (1, 1), (2, 1), (1, 2) of depth 2,
            // its basis 6uvw.
            let centre = lattice_index(3, 1, 1);
            let (mut num, mut den) = (DVec3::ZERO, 0.0);
            for (a, b) in [(1, 1), (2, 1), (1, 2)] {
                let (u, v) = (a as f64 / 4.0, b as f64 / 4.0);
                let basis = 6.0 * u * v * (1.0 - u - v);
                lattice[centre] = DVec3::ZERO;
                let rest = at(&fine, 4, a, b)?
                    - TriangleBezier::new(3, lattice.to_vec())?
                        .evaluate(u, v)
                        .point;
                num += rest * basis;
                den += basis * basis;
            }
            lattice[centre] = num / den;
            let patch = TriangleBezier::new(3, lattice.to_vec())?;
            let check = limit_grid(f, 3)?;
            for a in 0..=8 {
                for b in 0..=8 - a {
                    let p = patch.evaluate(a as f64 / 8.0, b as f64 / 8.0).point;
                    deviation = deviation.max(p.distance(at(&check, 8, a, b)?));
                }
            }
            if !deviation.is_finite() {
                return Err(failed("the limit is not finite"));
            }
            let tensor = patch.tensor_points();
            out.push(std::array::from_fn(|i| tensor[i]));
        }
        Ok(LimitPatches {
            patches: out,
            exact: 0,
            level: k,
            deviation,
            triangles: true,
        })
    }
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
        let tolerance = 2e-3;
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
}
