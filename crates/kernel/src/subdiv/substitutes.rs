//! Efficient substitutes for a subdivision limit surface (seed 000): one fixed patch per face
//! of the cage, whose control points are computed from the cage by local averaging and which
//! is then evaluated in one pass, with no refinement.
//!
//! - **ACC** (Loop & Schaefer 2008, "Approximating Catmull-Clark subdivision surfaces with
//!   bicubic patches"): a bicubic Bézier patch per quad for the position, plus a u-tangent
//!   patch of degree (2, 3) and a v-tangent patch of degree (3, 2) whose cross product is a
//!   normal field that is continuous across the patches.
//! - **Gregory** (ACC-2; Loop, Schaefer, Ni & Castaño 2009, "Approximating subdivision
//!   surfaces with Gregory patches for hardware tessellation"): a bicubic Gregory patch per
//!   quad (20 points; each interior point a rational blend of two), tangent-plane continuous
//!   (G¹) along every edge, through the limit points with the limit tangent planes.
//! - **PN triangles** (Vlachos, Peters, Boyd & Mitchell 2001, "Curved PN triangles"): a cubic
//!   Bézier triangle per triangle of a Loop cage from its corners' limit positions and normals,
//!   with a quadratic normal triangle for shading.
//!
//! Catmull-Clark cages that are not all quads take their substitutes on level 1 (one patch per
//! quad of the first refinement). A face with a corner on the boundary, on a crease or at a
//! sharp corner keeps the exact limit (the substitutes are defined for smooth interior
//! vertices); a face whose four corners are regular is the bicubic B-spline, which every
//! construction here reproduces exactly.

use std::f64::consts::TAU;

use glam::DVec3;

use super::level::{Level, Ring};
use super::limit::{is_regular, limit_position, limit_tangents};
use super::pieces::{Display, LimitFeed, first_children};
pub use super::pieces::{ExactPiece, PlannedPatch, SubstituteKind, SubstitutePlan};
use super::stencil::Row;
use super::{Hierarchy, SubdivisionSurface};
use crate::diffgeo::SurfaceDerivatives;
use crate::{GeometryError, Location};

/// Whether the limit at `v` is smooth: inside the surface, nothing sharp at it or along its
/// edges, at least three faces.
fn is_smooth_interior(level: &Level, ring: &Ring, v: u32) -> bool {
    !ring.boundary
        && ring.faces.len() >= 3
        && level.vertex_sharpness[v as usize] <= 0.0
        && level.incident_sharpness(v).iter().all(|&s| s <= 0.0)
}

impl SubstitutePlan {
    /// The plan of `kind` for `surface` shown at `levels` (≥ 1) refinements per cage face;
    /// `regular_as_bspline`: regular quads of a quad cage stay bicubic B-spline patches.
    /// Refuses a scheme the substitute does not approximate.
    pub fn new(
        surface: &SubdivisionSurface,
        kind: SubstituteKind,
        levels: u32,
        regular_as_bspline: bool,
    ) -> Result<Self, GeometryError> {
        let scheme = surface.options.scheme;
        kind.check_scheme(scheme)?;
        if levels == 0 {
            return Err(GeometryError::Cage {
                at: Location::field("level"),
                problem: crate::CageProblem::Level {
                    level: 0,
                    max: super::MAX_LEVEL,
                },
            });
        }
        let cage = surface.base_level()?;
        let all_quads = cage.faces().all(|f| f.len() == 4);
        let on_cage = kind == SubstituteKind::PnTriangle || all_quads;
        let (base, to_base, first_children) = if on_cage {
            (cage, None, Vec::new())
        } else {
            let hierarchy = Hierarchy::new(cage, surface.options, 1)?;
            let starts = first_children(&hierarchy.levels[0], scheme)
                .into_iter()
                .zip(hierarchy.levels[0].faces().map(|f| f.len() as u32))
                .collect();
            let Hierarchy {
                levels: mut refined,
                stencils: mut steps,
                ..
            } = hierarchy;
            (refined.swap_remove(1), steps.pop(), starts)
        };
        let rings: Vec<Ring> = (0..base.vertex_count as u32)
            .map(|v| base.ring(v))
            .collect();
        let smooth: Vec<bool> = (0..base.vertex_count as u32)
            .map(|v| is_smooth_interior(&base, &rings[v as usize], v))
            .collect();
        let mut plan = Self {
            kind,
            regular: Vec::new(),
            exact: Vec::new(),
            patches: Vec::new(),
            base_level: usize::from(!on_cage),
            positions: Vec::new(),
            tangents: Vec::new(),
            corner_slots: Vec::new(),
            rings,
            to_base,
            base,
        };
        // (base face, cage face, depth below the base level) of every face.
        let faces: Vec<(u32, u32)> = if on_cage {
            (0..plan.base.face_count() as u32).map(|f| (f, f)).collect()
        } else {
            first_children
                .iter()
                .enumerate()
                .flat_map(|(f, &(first, count))| (first..first + count).map(move |c| (c, f as u32)))
                .collect()
        };
        let depth = levels - plan.base_level as u32;
        for (face, cage_face) in faces {
            let corners = plan.base.face(face).to_vec();
            if kind == SubstituteKind::PnTriangle {
                plan.patches.push(PlannedPatch {
                    base_face: face,
                    cage_face,
                });
                continue;
            }
            if on_cage
                && regular_as_bspline
                && corners.iter().all(|&v| is_regular(&plan.base, scheme, v))
            {
                plan.regular.push(face);
                continue;
            }
            if corners.iter().all(|&v| smooth[v as usize]) {
                let slots = std::array::from_fn(|a| {
                    let ring = &plan.rings[corners[a] as usize];
                    ring.faces.iter().position(|&g| g == face).unwrap_or(0)
                });
                plan.corner_slots.push(slots);
                plan.patches.push(PlannedPatch {
                    base_face: face,
                    cage_face,
                });
            } else {
                plan.exact.push(ExactPiece {
                    level: plan.base_level,
                    face,
                    cage_face,
                    depth,
                });
            }
        }
        let needed = |v: usize| match kind {
            SubstituteKind::PnTriangle => true,
            SubstituteKind::Gregory => smooth[v],
            SubstituteKind::Acc => false,
        };
        let base = &plan.base;
        plan.positions = (0..base.vertex_count)
            .map(|v| {
                if kind == SubstituteKind::PnTriangle {
                    limit_position(base, scheme, v as u32)
                } else {
                    Row::default()
                }
            })
            .collect();
        let positions = &plan.positions;
        plan.tangents = (0..base.vertex_count)
            .map(|v| {
                if needed(v) {
                    limit_tangents(base, scheme, v as u32, &|u| positions[u as usize].clone())
                } else {
                    [Row::default(), Row::default()]
                }
            })
            .collect();
        Ok(plan)
    }

    /// The base mesh's points from the cage's.
    pub fn base_points(&self, cage: &[DVec3]) -> Vec<DVec3> {
        match &self.to_base {
            Some(stencils) => stencils.apply(cage),
            None => cage.to_vec(),
        }
    }

    /// Every patch's control points, patch after patch ([`SubstituteKind::point_count`] each).
    pub fn control_points(&self, cage: &[DVec3]) -> Vec<DVec3> {
        let base = self.base_points(cage);
        let mut out = Vec::with_capacity(self.patches.len() * self.kind.point_count());
        for p in 0..self.patches.len() {
            self.patch_points(&base, p, &mut out);
        }
        out
    }

    /// The control points of patch `p` over the base points `base`, appended to `out`.
    pub fn patch_points(&self, base: &[DVec3], p: usize, out: &mut Vec<DVec3>) {
        match self.kind {
            SubstituteKind::PnTriangle => self.pn_points(base, p, out),
            SubstituteKind::Acc | SubstituteKind::Gregory => self.quad_points(base, p, out),
        }
    }

    /// Around vertex `v` (smooth, valence n, ring faces F_k between neighbours e_k and
    /// e_{k+1}, diagonals d_k): ACC's interior points (n v + 2(e_k + e_{k+1}) + d_k)/(n + 5),
    /// the corner (their mean, the Catmull-Clark limit point), the edge points (the mean of the
    /// two interior points beside each edge) and the corner tangents: the first Fourier mode
    /// (2/n) Σ_j cos(2π(j − k)/n) 3(e_j − corner) of the edge points, so that neighbouring
    /// tangents satisfy t_{k−1} + t_{k+1} = 2 cos(2π/n) t_k (Loop & Schaefer 2008, §3–4).
    fn corner_frame(&self, base: &[DVec3], v: u32) -> CornerFrame {
        let ring = &self.rings[v as usize];
        let n = ring.faces.len();
        let nf = n as f64;
        let pv = base[v as usize];
        let interior: Vec<DVec3> = (0..n)
            .map(|k| {
                let a = base[ring.neighbours[k] as usize];
                let b = base[ring.neighbours[(k + 1) % n] as usize];
                let d = base[self.base.diagonal(ring.faces[k], v) as usize];
                (pv * nf + (a + b) * 2.0 + d) / (nf + 5.0)
            })
            .collect();
        let point = interior.iter().sum::<DVec3>() / nf;
        let edge: Vec<DVec3> = (0..n)
            .map(|k| (interior[(k + n - 1) % n] + interior[k]) * 0.5)
            .collect();
        let raw: Vec<DVec3> = edge.iter().map(|&e| (e - point) * 3.0).collect();
        let tangent: Vec<DVec3> = (0..n)
            .map(|k| {
                (0..n)
                    .map(|j| raw[j] * (TAU * (j as f64 - k as f64) / nf).cos())
                    .sum::<DVec3>()
                    * (2.0 / nf)
            })
            .collect();
        CornerFrame {
            n,
            point,
            interior,
            edge,
            tangent,
        }
    }

    /// ACC's 40 or Gregory's 20 points of quad patch `p`.
    fn quad_points(&self, base: &[DVec3], p: usize, out: &mut Vec<DVec3>) {
        let face = self.patches[p].base_face;
        let q = self.base.face(face);
        let slots = self.corner_slots[p];
        let frames: [CornerFrame; 4] = std::array::from_fn(|a| self.corner_frame(base, q[a]));
        // Corner a of the patch in the 4 × 4 grid, and the steps toward corners a + 1 and a − 1.
        const CORNER: [(i32, i32); 4] = [(0, 0), (3, 0), (3, 3), (0, 3)];
        const NEXT: [(i32, i32); 4] = [(1, 0), (0, 1), (-1, 0), (0, -1)];
        const PREV: [(i32, i32); 4] = [(0, 1), (-1, 0), (0, -1), (1, 0)];
        let at = |(i, j): (i32, i32)| (i * 4 + j) as usize;
        let plus = |a: (i32, i32), b: (i32, i32)| (a.0 + b.0, a.1 + b.1);
        let next_slot = |a: usize| slots[a];
        let prev_slot = |a: usize| (slots[a] + 1) % frames[a].n;
        // ACC's edge points; Gregory's are ACC's corner tangents moved into the exact limit
        // tangent plane (p + t/3).
        let (edge_next, edge_prev): ([DVec3; 4], [DVec3; 4]) = if self.kind == SubstituteKind::Acc {
            (
                std::array::from_fn(|a| frames[a].edge[next_slot(a)]),
                std::array::from_fn(|a| frames[a].edge[prev_slot(a)]),
            )
        } else {
            let normals: [DVec3; 4] = std::array::from_fn(|a| {
                let [t0, t1] = &self.tangents[q[a] as usize];
                t0.apply(base).cross(t1.apply(base)).normalize_or_zero()
            });
            let edge_point = |a: usize, slot: usize| {
                let t = frames[a].tangent[slot];
                frames[a].point + (t - normals[a] * t.dot(normals[a])) / 3.0
            };
            (
                std::array::from_fn(|a| edge_point(a, next_slot(a))),
                std::array::from_fn(|a| edge_point(a, prev_slot(a))),
            )
        };
        let mut grid = [DVec3::ZERO; 16];
        for a in 0..4 {
            grid[at(CORNER[a])] = frames[a].point;
            grid[at(plus(CORNER[a], NEXT[a]))] = edge_next[a];
            grid[at(plus(CORNER[a], PREV[a]))] = edge_prev[a];
            grid[at(plus(plus(CORNER[a], NEXT[a]), PREV[a]))] = frames[a].interior[slots[a]];
        }
        if self.kind == SubstituteKind::Acc {
            out.extend_from_slice(&grid);
            out.extend(acc_tangent_patches(&grid, &frames, &slots));
            return;
        }
        let cos = |a: usize| (TAU / frames[a].n as f64).cos();
        let centroid = |g: u32| {
            let corners = self.base.face(g);
            corners.iter().map(|&v| base[v as usize]).sum::<DVec3>() / corners.len() as f64
        };
        let own = centroid(face);
        let mut extra = [DVec3::ZERO; 4];
        for a in 0..4 {
            let (b, z) = ((a + 1) % 4, (a + 3) % 4);
            let ring = &self.rings[q[a] as usize];
            let n = frames[a].n;
            let k = slots[a];
            let pa = frames[a].point;
            // Along the edge to corner a + 1 (its neighbour face F_{k−1}) and to corner a − 1
            // (F_{k+1}): the face point (1/3)[c_m p + (3 − 2c_n − c_m) e_A + 2c_n e_B + r],
            // r = (m⁺ − m⁻)/3 + 2(c_f − c_g)/3 (Loop et al. 2009, §3.4).
            let face_point = |e_a: DVec3, e_b: DVec3, m: f64, mine: u32, theirs: u32, g: u32| {
                let r = (base[mine as usize] - base[theirs as usize]) / 6.0
                    + (own - centroid(g)) * (2.0 / 3.0);
                (pa * m + e_a * (3.0 - 2.0 * cos(a) - m) + e_b * (2.0 * cos(a)) + r) / 3.0
            };
            let toward_next = face_point(
                edge_next[a],
                edge_prev[b],
                cos(b),
                q[z],
                ring.neighbours[(k + n - 1) % n],
                ring.faces[(k + n - 1) % n],
            );
            let toward_prev = face_point(
                edge_prev[a],
                edge_next[z],
                cos(z),
                q[b],
                ring.neighbours[(k + 2) % n],
                ring.faces[(k + 1) % n],
            );
            let corner = CORNER[a];
            // Even corners: the next edge runs along u (v = 0 or 1); odd: along v.
            let (along_u, along_v) = if a % 2 == 0 {
                (toward_next, toward_prev)
            } else {
                (toward_prev, toward_next)
            };
            grid[at(plus(plus(corner, NEXT[a]), PREV[a]))] = along_u;
            extra[GREGORY_EXTRA_OF_CORNER[a]] = along_v;
        }
        out.extend_from_slice(&grid);
        out.extend_from_slice(&extra);
    }

    /// The PN triangle of patch `p` from its corners' limit positions P_i and normals N_i
    /// (Vlachos et al. 2001): b210 = (2P₁ + P₂ − w₁₂N₁)/3 with w_ij = (P_j − P_i)·N_i (and the
    /// other five edge points alike), b111 = E + (E − V)/2 with E the mean of the six edge points
    /// and V of the corners; n110 = normalize(N₁ + N₂ − v₁₂(P₂ − P₁)) with
    /// v_ij = 2 (P_j − P_i)·(N_i + N_j) / |P_j − P_i|².
    fn pn_points(&self, base: &[DVec3], p: usize, out: &mut Vec<DVec3>) {
        let q = self.base.face(self.patches[p].base_face);
        let pos: [DVec3; 3] = std::array::from_fn(|i| self.positions[q[i] as usize].apply(base));
        let flat = (pos[1] - pos[0]).cross(pos[2] - pos[0]).normalize_or_zero();
        let nor: [DVec3; 3] = std::array::from_fn(|i| {
            let [t0, t1] = &self.tangents[q[i] as usize];
            let n = t0.apply(base).cross(t1.apply(base)).normalize_or_zero();
            if n == DVec3::ZERO { flat } else { n }
        });
        let edge = |i: usize, j: usize| {
            let w = (pos[j] - pos[i]).dot(nor[i]);
            (pos[i] * 2.0 + pos[j] - nor[i] * w) / 3.0
        };
        let mut b = [
            pos[0],
            pos[1],
            pos[2],
            edge(0, 1),
            edge(1, 0),
            edge(1, 2),
            edge(2, 1),
            edge(2, 0),
            edge(0, 2),
            DVec3::ZERO,
        ];
        let e = b[3..9].iter().sum::<DVec3>() / 6.0;
        let v = (pos[0] + pos[1] + pos[2]) / 3.0;
        b[9] = e + (e - v) * 0.5;
        let mid_normal = |i: usize, j: usize| {
            let d = pos[j] - pos[i];
            let l2 = d.length_squared();
            let v = if l2 > 0.0 {
                2.0 * d.dot(nor[i] + nor[j]) / l2
            } else {
                0.0
            };
            let n = (nor[i] + nor[j] - d * v).normalize_or_zero();
            if n == DVec3::ZERO {
                (nor[i] + nor[j]).normalize_or_zero()
            } else {
                n
            }
        };
        out.extend_from_slice(&b);
        out.extend_from_slice(&[
            nor[0],
            nor[1],
            nor[2],
            mid_normal(0, 1),
            mid_normal(1, 2),
            mid_normal(2, 0),
        ]);
    }
}

/// Which of the Gregory patch's four extra points belongs to corner a's interior point:
/// (1, 1), (2, 1), (2, 2), (1, 2) hold extras 0, 1, 3, 2.
const GREGORY_EXTRA_OF_CORNER: [usize; 4] = [0, 1, 3, 2];

/// What [`SubstitutePlan::corner_frame`] computes around one vertex.
struct CornerFrame {
    n: usize,
    point: DVec3,
    interior: Vec<DVec3>,
    edge: Vec<DVec3>,
    tangent: Vec<DVec3>,
}

/// ACC's tangent patches of the geometry patch `grid` (Loop & Schaefer 2008, §4): the
/// derivatives 3(b_{i+1,j} − b_{i,j}) and 3(b_{i,j+1} − b_{i,j}), with the corners replaced by
/// the corner tangents and, along each edge from A (valence n) to B (valence m), the two
/// middle cross-tangent points set so that the cross tangents L and R of the two faces add up
/// to λ(t) a(t), λ = 2cos(2π/n)(1 − t) − 2cos(2π/m) t, with a the tangent along the edge:
/// L₁ = (2c_n a₁ − c_m a₀)/3 + 3(interior_A − edge_A) and L₂ = (c_n a₂ − 2c_m a₁)/3 +
/// 3(interior_B − edge_B). Returns the u-tangent points (3 × 4) then the v-tangent points
/// (4 × 3).
fn acc_tangent_patches(
    grid: &[DVec3; 16],
    frames: &[CornerFrame; 4],
    slots: &[usize; 4],
) -> [DVec3; 24] {
    let b = |i: usize, j: usize| grid[i * 4 + j];
    let mut u = [DVec3::ZERO; 12];
    let mut v = [DVec3::ZERO; 12];
    for i in 0..3 {
        for j in 0..4 {
            u[i * 4 + j] = (b(i + 1, j) - b(i, j)) * 3.0;
        }
    }
    for i in 0..4 {
        for j in 0..3 {
            v[i * 3 + j] = (b(i, j + 1) - b(i, j)) * 3.0;
        }
    }
    let next = |a: usize| slots[a];
    let prev = |a: usize| (slots[a] + 1) % frames[a].n;
    for a in 0..4 {
        let bb = (a + 1) % 4;
        let (fa, fb) = (&frames[a], &frames[bb]);
        let cn = (TAU / fa.n as f64).cos();
        let cm = (TAU / fb.n as f64).cos();
        let along = [
            fa.tangent[next(a)],
            (fb.edge[prev(bb)] - fa.edge[next(a)]) * 3.0,
            -fb.tangent[prev(bb)],
        ];
        let cross = [
            fa.tangent[prev(a)],
            (along[1] * (2.0 * cn) - along[0] * cm) / 3.0
                + (fa.interior[slots[a]] - fa.edge[next(a)]) * 3.0,
            (along[2] * cn - along[1] * (2.0 * cm)) / 3.0
                + (fb.interior[slots[bb]] - fb.edge[prev(bb)]) * 3.0,
            fb.tangent[next(bb)],
        ];
        match a {
            0 => {
                for i in 0..3 {
                    u[i * 4] = along[i];
                }
                for i in 0..4 {
                    v[i * 3] = cross[i];
                }
            }
            1 => {
                v[9..12].copy_from_slice(&along);
                for j in 0..4 {
                    u[8 + j] = -cross[j];
                }
            }
            2 => {
                for i in 0..3 {
                    u[i * 4 + 3] = -along[2 - i];
                }
                for i in 0..4 {
                    v[i * 3 + 2] = -cross[3 - i];
                }
            }
            _ => {
                for j in 0..3 {
                    v[j] = -along[2 - j];
                }
                for j in 0..4 {
                    u[j] = cross[3 - j];
                }
            }
        }
    }
    let mut out = [DVec3::ZERO; 24];
    out[..12].copy_from_slice(&u);
    out[12..].copy_from_slice(&v);
    out
}

/// A substitute evaluated at one parameter: position and derivatives, the normal it shades
/// with (ACC: the tangent patches' cross product; PN: the quadratic normal triangle; Gregory:
/// its own), and whether its curvature is defined there.
#[derive(Debug, Clone, Copy)]
pub struct SubstituteSample {
    pub derivatives: SurfaceDerivatives,
    pub normal: DVec3,
    pub curvature_defined: bool,
}

/// Cubic Bernstein polynomials and their first and second derivatives at t.
fn cubic_basis(t: f64) -> [[f64; 4]; 3] {
    let s = 1.0 - t;
    [
        [s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t],
        [
            -3.0 * s * s,
            3.0 * s * s - 6.0 * t * s,
            6.0 * t * s - 3.0 * t * t,
            3.0 * t * t,
        ],
        [6.0 * s, 6.0 * t - 12.0 * s, 6.0 * s - 12.0 * t, 6.0 * t],
    ]
}

/// Quadratic Bernstein polynomials at t.
fn quadratic_basis(t: f64) -> [f64; 3] {
    let s = 1.0 - t;
    [s * s, 2.0 * t * s, t * t]
}

/// Where a PN triangle's grid point (s, t) is evaluated: the point itself inside the triangle,
/// scaled onto the hypotenuse outside it (the lattice's unused slots).
pub fn triangle_parameter(s: f64, t: f64) -> (f64, f64) {
    let sum = s + t;
    if sum > 1.0 {
        (s / sum, t / sum)
    } else {
        (s, t)
    }
}

/// The exponents (i, j, k) of a PN triangle's ten points, in [`SubstituteKind::PnTriangle`]'s
/// order, and of its six normal coefficients.
pub const PN_POSITION_EXPONENTS: [[u32; 3]; 10] = [
    [3, 0, 0],
    [0, 3, 0],
    [0, 0, 3],
    [2, 1, 0],
    [1, 2, 0],
    [0, 2, 1],
    [0, 1, 2],
    [1, 0, 2],
    [2, 0, 1],
    [1, 1, 1],
];
pub const PN_NORMAL_EXPONENTS: [[u32; 3]; 6] = [
    [2, 0, 0],
    [0, 2, 0],
    [0, 0, 2],
    [1, 1, 0],
    [0, 1, 1],
    [1, 0, 1],
];

/// x^k, 0 for negative k (the terms it multiplies vanish there).
fn power(x: f64, k: i32) -> f64 {
    if k < 0 { 0.0 } else { x.powi(k) }
}

/// The barycentric Bernstein term n!/(i! j! k!) w^i u^j v^k (w = 1 − u − v) and its
/// derivatives d/du, d/dv, d²/du², d²/dudv, d²/dv².
fn triangle_term([i, j, k]: [u32; 3], u: f64, v: f64) -> [f64; 6] {
    let fact = |n: u32| (1..=n).product::<u32>() as f64;
    let c = fact(i + j + k) / (fact(i) * fact(j) * fact(k));
    let w = 1.0 - u - v;
    let (i, j, k) = (i as i32, j as i32, k as i32);
    let (fi, fj, fk) = (i as f64, j as f64, k as f64);
    let m = |a: i32, b: i32, d: i32| power(w, a) * power(u, b) * power(v, d);
    [
        c * m(i, j, k),
        c * (-fi * m(i - 1, j, k) + fj * m(i, j - 1, k)),
        c * (-fi * m(i - 1, j, k) + fk * m(i, j, k - 1)),
        c * (fi * (fi - 1.0) * m(i - 2, j, k) - 2.0 * fi * fj * m(i - 1, j - 1, k)
            + fj * (fj - 1.0) * m(i, j - 2, k)),
        c * (fi * (fi - 1.0) * m(i - 2, j, k)
            - fi * fk * m(i - 1, j, k - 1)
            - fi * fj * m(i - 1, j - 1, k)
            + fj * fk * m(i, j - 1, k - 1)),
        c * (fi * (fi - 1.0) * m(i - 2, j, k) - 2.0 * fi * fk * m(i - 1, j, k - 1)
            + fk * (fk - 1.0) * m(i, j, k - 2)),
    ]
}

/// The bicubic Bézier patch `grid` (row-major, first index along u) at (u, v), with the
/// interior points' own derivatives `moving` (d/du, d/dv, d²/du², d²/dudv, d²/dv² of the
/// interior points (1, 1), (2, 1), (1, 2), (2, 2); zero for a plain Bézier patch).
fn bicubic(grid: &[DVec3; 16], moving: &[[DVec3; 5]; 4], u: f64, v: f64) -> SurfaceDerivatives {
    let [bu, du, ddu] = cubic_basis(u);
    let [bv, dv, ddv] = cubic_basis(v);
    let mut d = SurfaceDerivatives::default();
    for i in 0..4 {
        for j in 0..4 {
            let p = grid[i * 4 + j];
            d.point += p * (bu[i] * bv[j]);
            d.su += p * (du[i] * bv[j]);
            d.sv += p * (bu[i] * dv[j]);
            d.suu += p * (ddu[i] * bv[j]);
            d.suv += p * (du[i] * dv[j]);
            d.svv += p * (bu[i] * ddv[j]);
        }
    }
    for (k, &(i, j)) in INTERIOR.iter().enumerate() {
        let [pu, pv, puu, puv, pvv] = moving[k];
        d.su += pu * (bu[i] * bv[j]);
        d.sv += pv * (bu[i] * bv[j]);
        d.suu += pu * (2.0 * du[i] * bv[j]) + puu * (bu[i] * bv[j]);
        d.suv += pu * (bu[i] * dv[j]) + pv * (du[i] * bv[j]) + puv * (bu[i] * bv[j]);
        d.svv += pv * (2.0 * bu[i] * dv[j]) + pvv * (bu[i] * bv[j]);
    }
    d
}

/// The interior points (i, j) of a bicubic grid, in the Gregory extras' order.
const INTERIOR: [(usize, usize); 4] = [(1, 1), (2, 1), (1, 2), (2, 2)];

/// Evaluates one substitute patch from its control points at (u, v) (PN triangles: u weights
/// corner 1 and v corner 2, see [`triangle_parameter`]).
pub fn evaluate(kind: SubstituteKind, points: &[DVec3], u: f64, v: f64) -> SubstituteSample {
    let none = [[DVec3::ZERO; 5]; 4];
    match kind {
        SubstituteKind::Acc => {
            let mut grid = [DVec3::ZERO; 16];
            grid.copy_from_slice(&points[..16]);
            let d = bicubic(&grid, &none, u, v);
            let (qu, cv) = (quadratic_basis(u), cubic_basis(v)[0]);
            let (cu, qv) = (cubic_basis(u)[0], quadratic_basis(v));
            let mut tu = DVec3::ZERO;
            let mut tv = DVec3::ZERO;
            for i in 0..3 {
                for j in 0..4 {
                    tu += points[16 + i * 4 + j] * (qu[i] * cv[j]);
                }
            }
            for i in 0..4 {
                for j in 0..3 {
                    tv += points[28 + i * 3 + j] * (cu[i] * qv[j]);
                }
            }
            let normal = tu.cross(tv).normalize_or_zero();
            SubstituteSample {
                derivatives: d,
                normal,
                curvature_defined: true,
            }
        }
        SubstituteKind::Gregory => {
            let mut grid = [DVec3::ZERO; 16];
            grid.copy_from_slice(&points[..16]);
            let mut moving = none;
            let mut defined = true;
            for (k, &(i, j)) in INTERIOR.iter().enumerate() {
                // b = (α P_u + β P_v)/(α + β): α the distance from the edge u = 0 or 1 the
                // point is near, β from v = 0 or 1 (sα, sβ: d α/du, d β/dv).
                let (alpha, sa) = if i == 1 { (u, 1.0) } else { (1.0 - u, -1.0) };
                let (beta, sb) = if j == 1 { (v, 1.0) } else { (1.0 - v, -1.0) };
                let (pu, pv) = (points[i * 4 + j], points[16 + k]);
                let s = alpha + beta;
                if s <= 0.0 {
                    grid[i * 4 + j] = (pu + pv) * 0.5;
                    defined = false;
                    continue;
                }
                let diff = pu - pv;
                grid[i * 4 + j] = pv + diff * (alpha / s);
                let (s2, s3) = (s * s, s * s * s);
                moving[k] = [
                    diff * (sa * beta / s2),
                    diff * (-sb * alpha / s2),
                    diff * (-2.0 * beta / s3),
                    diff * (sa * sb * (alpha - beta) / s3),
                    diff * (2.0 * alpha / s3),
                ];
            }
            let d = bicubic(&grid, &moving, u, v);
            SubstituteSample {
                derivatives: d,
                normal: d.regular_normal().unwrap_or(DVec3::ZERO),
                curvature_defined: defined,
            }
        }
        SubstituteKind::PnTriangle => {
            let (u, v) = triangle_parameter(u, v);
            let mut out = [DVec3::ZERO; 6];
            for (p, &e) in points.iter().zip(PN_POSITION_EXPONENTS.iter()) {
                let t = triangle_term(e, u, v);
                for c in 0..6 {
                    out[c] += *p * t[c];
                }
            }
            let mut normal = DVec3::ZERO;
            for (n, &e) in points[10..16].iter().zip(PN_NORMAL_EXPONENTS.iter()) {
                normal += *n * triangle_term(e, u, v)[0];
            }
            SubstituteSample {
                derivatives: SurfaceDerivatives {
                    point: out[0],
                    su: out[1],
                    sv: out[2],
                    suu: out[3],
                    suv: out[4],
                    svv: out[5],
                },
                normal: normal.normalize_or_zero(),
                curvature_defined: true,
            }
        }
    }
}

/// How far a substitute lies from the exact limit surface, sampled where both are known at the
/// same parameter: every vertex of level `levels` on a substitute patch.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct SubstituteError {
    /// Substitute patches measured and vertices sampled on them.
    pub patches: usize,
    pub samples: usize,
    /// Distance to the exact limit point, over the cage's bounding-box diagonal.
    pub max_distance: f64,
    pub rms_distance: f64,
    /// Angle between the substitute's normal and the exact limit normal, in degrees.
    pub max_normal_degrees: f64,
    pub mean_normal_degrees: f64,
}

impl SubdivisionSurface {
    /// The surface substitute `kind` shows at level `levels`, in f64: the level's faces over
    /// its vertices, each vertex on a substitute patch at the substitute's point with its
    /// normal, the others (regular and exact faces) at their limit points with the limit
    /// normals. Vertices on a seam between a substitute and an exact face take the
    /// substitute's, so the mesh stays closed.
    pub fn substitute_mesh(
        &self,
        levels: u32,
        kind: SubstituteKind,
    ) -> Result<super::display::DisplayMesh, GeometryError> {
        let (feed, plan) = self.substitute_feed(levels, kind, true)?;
        self.substitute_mesh_from(levels, &feed, &plan)
    }

    /// [`Self::substitute_mesh`] from the feed and plan of [`Self::substitute_feed`] already
    /// built.
    pub fn substitute_mesh_from(
        &self,
        levels: u32,
        feed: &LimitFeed,
        plan: &SubstitutePlan,
    ) -> Result<super::display::DisplayMesh, GeometryError> {
        let mut shown = self.display_mesh(levels, Display::Limit)?;
        for_each_substitute_vertex(feed, plan, self.points(), |v, sample| {
            let v = v as usize;
            if let (Some(position), Some(normal)) =
                (shown.positions.get_mut(v), shown.normals.get_mut(v))
            {
                *position = sample.derivatives.point;
                if sample.normal != DVec3::ZERO {
                    *normal = sample.normal;
                }
            }
        });
        Ok(shown)
    }

    /// The error of substitute `kind` at level `levels` against the exact limit (positions and
    /// normals of [`SubdivisionSurface::limit`]) at the level's vertices on the substitute
    /// patches; `regular_as_bspline` as in [`Self::substitute_feed`]. The parametrizations
    /// differ near extraordinary vertices, so the distance bounds the geometric one from above.
    pub fn substitute_error(
        &self,
        kind: SubstituteKind,
        levels: u32,
        regular_as_bspline: bool,
    ) -> Result<SubstituteError, GeometryError> {
        let (feed, plan) = self.substitute_feed(levels, kind, regular_as_bspline)?;
        let limit = self.limit(levels)?;
        let diagonal = self
            .mesh()
            .bounds()
            .map_or(1.0, |(lo, hi)| (hi - lo).length().max(f64::MIN_POSITIVE));
        let mut error = SubstituteError {
            patches: feed.substitutes.len(),
            ..Default::default()
        };
        let (mut squares, mut angles) = (0.0, 0.0);
        for_each_substitute_vertex(&feed, &plan, self.points(), |v, sample| {
            let (Some(exact), Some(normal)) = (
                limit.positions.get(v as usize),
                limit.normals.get(v as usize),
            ) else {
                return;
            };
            let distance = sample.derivatives.point.distance(*exact) / diagonal;
            let angle = sample
                .normal
                .dot(*normal)
                .clamp(-1.0, 1.0)
                .acos()
                .to_degrees();
            error.samples += 1;
            error.max_distance = error.max_distance.max(distance);
            error.max_normal_degrees = error.max_normal_degrees.max(angle);
            squares += distance * distance;
            angles += angle;
        });
        if error.samples > 0 {
            error.rms_distance = (squares / error.samples as f64).sqrt();
            error.mean_normal_degrees = angles / error.samples as f64;
        }
        Ok(error)
    }
}

/// Calls `f` with every level vertex on a substitute patch of `feed` (built with `plan`) and the
/// substitute evaluated there, the patches' points computed from the cage `cage`.
fn for_each_substitute_vertex(
    feed: &LimitFeed,
    plan: &SubstitutePlan,
    cage: &[DVec3],
    mut f: impl FnMut(u32, SubstituteSample),
) {
    let base = plan.base_points(cage);
    let mut control = Vec::with_capacity(plan.kind.point_count());
    for (k, patch) in feed.substitutes.iter().enumerate() {
        control.clear();
        plan.patch_points(&base, k, &mut control);
        let n = patch.segments as usize;
        for i in 0..=n {
            for j in 0..=n {
                let v = feed.vertex[patch.first_slot as usize + i * (n + 1) + j];
                if v == super::level::NONE {
                    continue;
                }
                let (s, t) = (i as f64 / n as f64, j as f64 / n as f64);
                f(v, evaluate(plan.kind, &control, s, t));
            }
        }
    }
}
