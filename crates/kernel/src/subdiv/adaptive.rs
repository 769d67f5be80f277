//! Adaptive subdivision: each piece of the surface (a cage face, or for Catmull-Clark each
//! quad of level 1) is refined only as deep as a flatness test asks, up to the surface's level,
//! and the pieces meet without cracks.
//!
//! # Flatness
//! A piece shown at depth d (2^d segments per edge) is a grid of its level-L limit points
//! (L the surface's level) taken every 2^(D − d) steps, D the piece's full depth, triangulated
//! as the GPU triangulates it (quads split along the diagonal (i, j)–(i + 1, j + 1), triangle
//! lattices into their lower and upper triangles). Its error is the largest distance between a
//! level-L limit point of the piece and the triangles of the coarse cell it lies in and of the
//! cells around that one; the piece takes the smallest d whose error is within the tolerance.
//! A distance to some of the triangles bounds the distance to the whole triangulation from
//! above, so the test is conservative; a flat region with an uneven parametrization counts as
//! flat.
//!
//! # No cracks
//! Two pieces that share an edge show it at the smaller of their two depths (transition
//! faces). The finer piece keeps its interior grid and moves the vertices of that edge which
//! the coarser one does not have onto the nearest vertex it does have (ties toward the edge's
//! start), so the strip along the edge becomes a fan of triangles into the coarse edge's
//! vertices, some of them degenerate (zero area, skipped by the rasterizer and dropped by the
//! export). Both pieces then show the same vertices of level L along the edge, with the same
//! stencils: the edge is closed exactly, not only up to rounding. Every shown vertex is a
//! vertex of level L, so vertices shared at corners are the same too.
//!
//! This is the "transition faces" way of the adaptive subdivision of Kobbelt's √3 paper
//! (2000, section 5) applied to the limit grids rather than to the refined mesh.

use glam::DVec3;

use super::display::DisplayMesh;
use super::patches::{exact_pieces, face_grid, push_stencil_patches};
pub use super::pieces::{DEFAULT_TOLERANCE, ShownPiece};
use super::pieces::{Display, ExactPiece, LimitFeed};
use super::{Hierarchy, Scheme, SubdivisionSurface};
use crate::GeometryError;
use crate::vector::distance_to_triangle;

/// `x` moved to the nearest multiple of `stride`, ties toward 0.
fn snap(x: u32, stride: u32) -> u32 {
    let (q, r) = (x / stride, x % stride);
    if 2 * r > stride {
        (q + 1) * stride
    } else {
        q * stride
    }
}

impl ShownPiece {
    /// The piece at its full depth everywhere (uniform refinement).
    pub fn uniform(piece: ExactPiece) -> Self {
        Self {
            piece,
            depth: piece.depth,
            edge_depths: [piece.depth; 4],
        }
    }

    /// Segments per edge of the shown grid.
    pub fn segments(&self) -> u32 {
        1 << self.depth
    }

    /// The position (i, j) on the piece's full grid (2^piece.depth segments) that slot (a, b)
    /// of the shown grid shows: (a, b) scaled up, then, on an edge shown coarser, moved to the
    /// nearest vertex that edge has. `None` past a triangle's diagonal.
    pub fn full_position(&self, triangle: bool, a: u32, b: u32) -> Option<(u32, u32)> {
        let s = self.segments();
        if triangle && a + b > s {
            return None;
        }
        let full = 1u32 << self.piece.depth;
        let r = full / s;
        let (mut i, mut j) = (a * r, b * r);
        let stride = |k: usize| 1u32 << (self.piece.depth - self.edge_depths[k].min(self.depth));
        if triangle {
            if b == 0 {
                i = snap(i, stride(0));
            } else if a + b == s {
                j = snap(j, stride(1));
                i = full - j;
            } else if a == 0 {
                j = snap(j, stride(2));
            }
        } else if b == 0 {
            i = snap(i, stride(0));
        } else if a == s {
            j = snap(j, stride(1));
        } else if b == s {
            i = snap(i, stride(2));
        } else if a == 0 {
            j = snap(j, stride(3));
        }
        Some((i, j))
    }

    /// The shown grid's triangles as full-grid positions, as the GPU writes them (two per
    /// cell; a triangle lattice's cells past the diagonal give none), degenerate ones
    /// included.
    pub fn triangles(&self, triangle: bool) -> Vec<[(u32, u32); 3]> {
        let s = self.segments();
        let at = |a: u32, b: u32| self.full_position(triangle, a, b);
        let mut out = Vec::new();
        for a in 0..s {
            for b in 0..s {
                let cell = if triangle {
                    [
                        (a + b < s).then_some([(a, b), (a + 1, b), (a, b + 1)]),
                        (a + b + 2 <= s).then_some([(a + 1, b), (a + 1, b + 1), (a, b + 1)]),
                    ]
                } else {
                    [
                        Some([(a, b), (a + 1, b), (a + 1, b + 1)]),
                        Some([(a, b), (a + 1, b + 1), (a, b + 1)]),
                    ]
                };
                for corners in cell.into_iter().flatten() {
                    if let [Some(p), Some(q), Some(r)] = corners.map(|(x, y)| at(x, y)) {
                        out.push([p, q, r]);
                    }
                }
            }
        }
        out
    }
}

/// The largest distance between the points `full` (a piece's grid of 2^depth_full segments,
/// [`face_grid`] order, positions looked up in `positions`) and the triangles of its sub-grid
/// every 2^(depth_full − depth) steps: each point against the triangles of the cell it lies in
/// and of its neighbours (see the module doc).
fn flatness_error(
    full: &[Option<u32>],
    depth_full: u32,
    depth: u32,
    triangle: bool,
    positions: &[DVec3],
) -> f64 {
    let n = 1usize << depth_full;
    let r = 1usize << (depth_full - depth);
    let s = n / r;
    let p = |i: usize, j: usize| full[i * (n + 1) + j].map(|v| positions[v as usize]);
    let mut worst: f64 = 0.0;
    for i in 0..=n {
        for j in 0..=n {
            let Some(point) = p(i, j) else {
                continue;
            };
            let (ci, cj) = ((i / r).min(s - 1), (j / r).min(s - 1));
            // The triangles of the cell and of the cells around it (where the parametrization
            // is uneven a point may lie over a neighbouring cell).
            let mut nearest = f64::INFINITY;
            for ni in ci.saturating_sub(1)..(ci + 2).min(s) {
                for nj in cj.saturating_sub(1)..(cj + 2).min(s) {
                    let corner = |a: usize, b: usize| p((ni + a) * r, (nj + b) * r);
                    let cell: [[Option<DVec3>; 3]; 2] = if triangle {
                        [
                            [corner(0, 0), corner(1, 0), corner(0, 1)],
                            [corner(1, 0), corner(1, 1), corner(0, 1)],
                        ]
                    } else {
                        [
                            [corner(0, 0), corner(1, 0), corner(1, 1)],
                            [corner(0, 0), corner(1, 1), corner(0, 1)],
                        ]
                    };
                    for t in cell {
                        if let [Some(a), Some(b), Some(c)] = t {
                            nearest = nearest.min(distance_to_triangle(point, a, b, c));
                        }
                    }
                }
            }
            if nearest.is_finite() {
                worst = worst.max(nearest);
            }
        }
    }
    worst
}

/// Each piece's depth by the flatness test against `tolerance` (a distance), and each edge's
/// depth as the smaller of the two pieces' that share it.
fn choose_depths(
    hierarchy: &Hierarchy,
    pieces: &[ExactPiece],
    positions: &[DVec3],
    tolerance: f64,
) -> Vec<ShownPiece> {
    let triangle = hierarchy.options.scheme != Scheme::CatmullClark;
    let depths: Vec<u32> = pieces
        .iter()
        .map(|piece| {
            let full = face_grid(hierarchy, piece.level, piece.face, piece.depth);
            (0..piece.depth)
                .find(|&d| flatness_error(&full, piece.depth, d, triangle, positions) <= tolerance)
                .unwrap_or(piece.depth)
        })
        .collect();
    // The smallest depth of the pieces around each edge, keyed by its level and ends.
    let mut edge_depth: std::collections::HashMap<(usize, u32, u32), u32> = Default::default();
    let edges = |piece: &ExactPiece| -> Vec<(usize, u32, u32)> {
        let face = hierarchy.levels[piece.level].face(piece.face);
        (0..face.len())
            .map(|k| {
                let (a, b) = (face[k], face[(k + 1) % face.len()]);
                (piece.level, a.min(b), a.max(b))
            })
            .collect()
    };
    for (piece, &d) in pieces.iter().zip(&depths) {
        for key in edges(piece) {
            let e = edge_depth.entry(key).or_insert(d);
            *e = (*e).min(d);
        }
    }
    pieces
        .iter()
        .zip(&depths)
        .map(|(piece, &depth)| {
            let mut edge_depths = [depth; 4];
            for (k, key) in edges(piece).into_iter().enumerate() {
                edge_depths[k] = edge_depth.get(&key).copied().unwrap_or(depth).min(depth);
            }
            ShownPiece {
                piece: *piece,
                depth,
                edge_depths,
            }
        })
        .collect()
}

/// What an adaptive refinement chose.
#[derive(Debug, Clone, PartialEq)]
pub struct AdaptiveLayout {
    /// Per piece, how it is shown.
    pub pieces: Vec<ShownPiece>,
    /// The tolerance as a distance (the relative tolerance times the cage's diagonal).
    pub tolerance: f64,
}

impl AdaptiveLayout {
    /// "level 1: 110, level 2: 30": the pieces per level, levels with none left out.
    pub fn describe(&self) -> String {
        let counts: Vec<String> = self
            .histogram()
            .iter()
            .enumerate()
            .filter(|(_, n)| **n > 0)
            .map(|(level, n)| format!("level {level}: {n}"))
            .collect();
        counts.join(", ")
    }

    /// How many pieces show each level (index: level).
    pub fn histogram(&self) -> Vec<usize> {
        let mut counts = Vec::new();
        for p in &self.pieces {
            let level = p.piece.level + p.depth as usize;
            if counts.len() <= level {
                counts.resize(level + 1, 0);
            }
            counts[level] += 1;
        }
        counts
    }
}

impl SubdivisionSurface {
    /// Checks that adaptive refinement applies: a scheme whose faces split into nested grids
    /// (Catmull-Clark, Loop, butterfly) and a tolerance that is finite and > 0.
    pub fn check_adaptive(&self, tolerance: f64) -> Result<(), GeometryError> {
        if matches!(self.options.scheme, Scheme::DooSabin | Scheme::Sqrt3) {
            return Err(GeometryError::Construction {
                what: "subdivision display",
                message: format!(
                    "adaptive refinement needs faces that split into grids (Catmull-Clark, \
                     Loop or butterfly); this cage uses {}",
                    self.options.scheme.label()
                ),
            });
        }
        if !(tolerance.is_finite() && tolerance > 0.0) {
            return Err(GeometryError::Construction {
                what: "subdivision display",
                message: format!("the flatness tolerance must be a number > 0, not {tolerance}"),
            });
        }
        Ok(())
    }

    /// The pieces of an adaptive refinement up to level `levels` (≥ 1) with flatness
    /// tolerance `tolerance` (a fraction of the cage's bounding-box diagonal), the hierarchy
    /// they live on and the level's limit positions.
    fn adaptive_pieces(
        &self,
        levels: u32,
        tolerance: f64,
    ) -> Result<(Hierarchy, AdaptiveLayout, DisplayMesh), GeometryError> {
        self.check_adaptive(tolerance)?;
        let hierarchy = self.hierarchy(levels)?;
        let faces: Vec<u32> = (0..hierarchy.levels[0].face_count() as u32).collect();
        let pieces = exact_pieces(&hierarchy, &faces, levels);
        let limit = self.display_mesh(levels, Display::Limit)?;
        let diagonal = self
            .mesh()
            .bounds()
            .map_or(1.0, |(lo, hi)| lo.distance(hi).max(f64::MIN_POSITIVE));
        let distance = tolerance * diagonal;
        let pieces = choose_depths(&hierarchy, &pieces, &limit.positions, distance);
        Ok((
            hierarchy,
            AdaptiveLayout {
                pieces,
                tolerance: distance,
            },
            limit,
        ))
    }

    /// The GPU feed of the adaptive limit at level `levels` (≥ 1) with flatness tolerance
    /// `tolerance` (a fraction of the cage's diagonal): every piece a stencil patch at its own
    /// depth (see the module doc), and the layout chosen.
    pub fn adaptive_feed(
        &self,
        levels: u32,
        tolerance: f64,
    ) -> Result<(LimitFeed, AdaptiveLayout), GeometryError> {
        self.check_adaptive(tolerance)?;
        if levels == 0 {
            return Ok((
                LimitFeed::default(),
                AdaptiveLayout {
                    pieces: Vec::new(),
                    tolerance,
                },
            ));
        }
        let (hierarchy, layout, _) = self.adaptive_pieces(levels, tolerance)?;
        let mut feed = LimitFeed::default();
        push_stencil_patches(
            &mut feed,
            &hierarchy,
            levels,
            &layout.pieces,
            Display::Limit,
        );
        Ok((feed, layout))
    }

    /// The adaptive limit of [`Self::adaptive_feed`] as a triangle mesh in f64 (the export and
    /// the GPU's oracle): the level's limit points the pieces show, with their limit normals,
    /// and the pieces' triangles without the degenerate ones.
    pub fn adaptive_mesh(&self, levels: u32, tolerance: f64) -> Result<DisplayMesh, GeometryError> {
        let layout = self.adaptive_layout(levels, tolerance)?;
        self.adaptive_mesh_from(levels, &layout)
    }

    /// [`Self::adaptive_mesh`] of a layout chosen before (for the points the surface has now).
    pub fn adaptive_mesh_from(
        &self,
        levels: u32,
        layout: &AdaptiveLayout,
    ) -> Result<DisplayMesh, GeometryError> {
        if levels == 0 {
            return self.display_mesh(0, Display::Limit);
        }
        let triangles = self.adaptive_triangles(levels, layout)?;
        let limit = self.display_mesh(levels, Display::Limit)?;
        Ok(DisplayMesh::from_triangles(
            &limit.positions,
            &limit.normals,
            &triangles,
        ))
    }

    /// The triangles the pieces of `layout` show, over the vertices of level `levels` (≥ 1),
    /// without the degenerate ones.
    pub fn adaptive_triangles(
        &self,
        levels: u32,
        layout: &AdaptiveLayout,
    ) -> Result<Vec<[u32; 3]>, GeometryError> {
        let hierarchy = self.hierarchy(levels)?;
        let triangle = self.options.scheme != Scheme::CatmullClark;
        let mut out = Vec::new();
        for shown in &layout.pieces {
            let piece = shown.piece;
            let level = hierarchy
                .levels
                .get(piece.level)
                .ok_or(GeometryError::NoSuchPatch {
                    patch: piece.level,
                    count: hierarchy.levels.len(),
                })?;
            if piece.face as usize >= level.face_count() {
                return Err(GeometryError::NoSuchPatch {
                    patch: piece.face as usize,
                    count: level.face_count(),
                });
            }
            let full = face_grid(&hierarchy, piece.level, piece.face, piece.depth);
            let n = (1usize << piece.depth) + 1;
            for corners in shown.triangles(triangle) {
                let vertices = corners.map(|(i, j)| full[i as usize * n + j as usize]);
                if let [Some(a), Some(b), Some(c)] = vertices
                    && a != b
                    && b != c
                    && a != c
                {
                    out.push([a, b, c]);
                }
            }
        }
        Ok(out)
    }

    /// The adaptive layout alone (for reports): what [`Self::adaptive_feed`] chooses.
    pub fn adaptive_layout(
        &self,
        levels: u32,
        tolerance: f64,
    ) -> Result<AdaptiveLayout, GeometryError> {
        if levels == 0 {
            self.check_adaptive(tolerance)?;
            return Ok(AdaptiveLayout {
                pieces: Vec::new(),
                tolerance,
            });
        }
        Ok(self.adaptive_pieces(levels, tolerance)?.1)
    }
}
