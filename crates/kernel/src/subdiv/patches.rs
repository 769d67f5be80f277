//! What a subdivision surface feeds the GPU: regular cage quads as bicubic B-spline patches
//! (converted to Bézier by the caller), everything else as grids of limit stencils — for every
//! vertex of the chosen level inside an irregular face, its limit position, tangents and (at
//! regular vertices) second derivatives as weighted sums of cage points.

use super::display::{DisplayRows, VertexRows, display_rows};
use super::level::{Level, NONE};
use super::limit::{
    is_regular, loop_corner_weights, loop_regular_weights, loop_sided_weights, regular_grid,
    regular_weights, sided_weights,
};
use super::pieces::{
    DEFAULT_TOLERANCE, ExactPiece, ShownPiece, SubstituteKind, SubstitutePlan, first_children,
};
pub use super::pieces::{Display, Entry, LimitFeed, StencilPatch, SubstitutePatch};
use super::region::{MOST_OF_THE_CAGE, REGION_RINGS, RegionCage, face_region};
use super::stencil::{Accumulator, Row, WideRows, build_rows};
use super::stencil_cache::{ReadFace, StencilCache};
use super::{Hierarchy, Scheme, SubdivisionSurface, templates};
use crate::GeometryError;
use std::sync::Arc;

/// A valence-4 point's four neighbours and its four faces ([`Level::four_ring`]) or diagonals.
type FourRing = ([u32; 4], [u32; 4]);

/// The four neighbours and the four diagonals (the far corners of its four quads) of valence-4
/// vertex `v` in ring order ([`Level::four_ring`]), if it has such a ring.
fn neighbours_and_diagonals(level: &Level, v: u32) -> Option<FourRing> {
    let (neighbours, faces) = level.four_ring(v)?;
    Some((neighbours, faces.map(|f| level.diagonal(f, v))))
}

/// The four neighbours and four diagonals of a valence-4 vertex counter-clockwise from its
/// neighbour `start`, from its ring `ring` ([`neighbours_and_diagonals`]).
fn quad_ring(ring: Option<FourRing>, start: u32) -> Option<FourRing> {
    let (neighbours, diagonals) = ring?;
    let s = neighbours.iter().position(|&x| x == start)?;
    let e = std::array::from_fn(|k| neighbours[(s + k) % 4]);
    let d = std::array::from_fn(|k| diagonals[(s + k) % 4]);
    Some((e, d))
}

/// The 4 × 4 B-spline points around regular quad `f` (corners q0..q3, u from q0 to q1, v from
/// q0 to q3), index `a * 4 + b` for the point a steps along u and b along v from the corner
/// before q0.
pub fn bspline_grid(level: &Level, f: u32) -> Option<[u32; 16]> {
    bspline_grid_from_rings(level, f, |v| neighbours_and_diagonals(level, v))
}

/// [`bspline_grid`] with each corner's neighbours and diagonals from `ring_of`
/// ([`neighbours_and_diagonals`], or a table of it).
fn bspline_grid_from_rings(
    level: &Level,
    f: u32,
    ring_of: impl Fn(u32) -> Option<FourRing>,
) -> Option<[u32; 16]> {
    let ring_from = |v: u32, start: u32| quad_ring(ring_of(v), start);
    let q = level.face(f);
    if q.len() != 4 {
        return None;
    }
    let mut g = [u32::MAX; 16];
    let mut set = |a: usize, b: usize, v: u32| g[a * 4 + b] = v;
    let (e, d) = ring_from(q[0], q[1])?;
    set(1, 1, q[0]);
    set(2, 1, q[1]);
    set(2, 2, q[2]);
    set(1, 2, q[3]);
    set(0, 1, e[2]);
    set(1, 0, e[3]);
    set(0, 2, d[1]);
    set(0, 0, d[2]);
    set(2, 0, d[3]);
    let (e, d) = ring_from(q[2], q[3])?;
    set(3, 2, e[2]);
    set(2, 3, e[3]);
    set(3, 1, d[1]);
    set(3, 3, d[2]);
    set(1, 3, d[3]);
    let (_, d) = ring_from(q[1], q[0])?;
    set(3, 0, d[1]);
    let (_, d) = ring_from(q[3], q[0])?;
    set(0, 3, d[2]);
    g.iter().all(|&x| x != u32::MAX).then_some(g)
}

/// The 16 B-spline points, as rows over the level's vertices (index `a * 4 + b` as in
/// [`bspline_grid`]), of a Catmull-Clark quad `f` with one side on the boundary whose limit is
/// exactly the bicubic B-spline with that side's outer row extrapolated, P₀ = 2 P₁ − P₂ (the
/// boundary patch of OpenSubdiv's regular patches). The boundary rules (vertex (1, 6, 1) / 8,
/// edge midpoint) are the B-spline rules with that row, and the reflection survives uniform
/// refinement, so the limit's boundary is the cubic B-spline of the boundary polygon with a
/// natural end condition across it. `None` unless the quad has exactly one boundary side, its
/// two boundary corners have two quads and three edges, its two inner corners four quads and
/// four inner edges, and nothing at its corners is sharp.
pub fn boundary_bspline_grid(level: &Level, scheme: Scheme, f: u32) -> Option<[Row; 16]> {
    let q: [u32; 4] = level.face(f).try_into().ok()?;
    if scheme != Scheme::CatmullClark {
        return None;
    }
    let edges = level.face_edges(f);
    // The quad across side j (from corner j to j + 1), if any.
    let across: Vec<Option<u32>> = (0..4)
        .map(|j| {
            let [x, y] = level.edge_faces[edges[j] as usize];
            let g = if x == f { y } else { x };
            (g != NONE).then_some(g)
        })
        .collect();
    let sides: Vec<usize> = (0..4).filter(|&j| across[j].is_none()).collect();
    let [side] = sides[..] else {
        return None;
    };
    // The inner corners regular; the boundary corners two quads, two boundary edges (stored
    // infinitely sharp, OpenSubdiv's rule) and one smooth inner edge, nothing else sharp.
    let regular_boundary_corner = |v: u32| {
        let (faces, edges) = (level.vertex_faces(v), level.vertex_edges(v));
        let boundary = edges.iter().filter(|&&e| level.is_boundary_edge(e)).count();
        level.vertex_sharpness[v as usize] <= 0.0
            && faces.len() == 2
            && edges.len() == 3
            && boundary == 2
            && faces.iter().all(|&g| level.face(g).len() == 4)
            && edges
                .iter()
                .all(|&e| level.is_boundary_edge(e) || level.edge_sharpness[e as usize] <= 0.0)
    };
    for (k, &v) in q.iter().enumerate() {
        let on_boundary = k == side || k == (side + 1) % 4;
        let fits = if on_boundary {
            regular_boundary_corner(v)
        } else {
            is_regular(level, scheme, v)
        };
        if !fits {
            return None;
        }
    }
    let mut grid: [Option<Row>; 16] = Default::default();
    let single = |v: u32| Row(vec![(v, 1.0)]);
    let at = |a: usize, b: usize| a * 4 + b;
    for (k, (a, b)) in [(1, 1), (2, 1), (2, 2), (1, 2)].into_iter().enumerate() {
        grid[at(a, b)] = Some(single(q[k]));
    }
    // Beyond side j: the points next to corner j, then next to corner j + 1.
    let beyond = [
        [(1, 0), (2, 0)],
        [(3, 1), (3, 2)],
        [(2, 3), (1, 3)],
        [(0, 2), (0, 1)],
    ];
    for j in 0..4 {
        if let Some(g) = across[j] {
            if level.face(g).len() != 4 {
                return None;
            }
            let [(a0, b0), (a1, b1)] = beyond[j];
            grid[at(a0, b0)] = Some(single(level.diagonal(g, q[(j + 1) % 4])));
            grid[at(a1, b1)] = Some(single(level.diagonal(g, q[j])));
        }
    }
    // The diagonal corners of the inner corners: across the fourth quad around them.
    let corner_points = [(0, 0), (3, 0), (3, 3), (0, 3)];
    for k in 0..4 {
        let (before, after) = (across[(k + 3) % 4], across[k]);
        if let (Some(g0), Some(g1)) = (before, after) {
            let h = level
                .vertex_faces(q[k])
                .iter()
                .copied()
                .find(|&h| h != f && h != g0 && h != g1)?;
            let (a, b) = corner_points[k];
            grid[at(a, b)] = Some(single(level.diagonal(h, q[k])));
        }
    }
    // The extrapolated row beyond the boundary side: outer = 2 inner − next. Point i of the
    // row `depth` steps in from the boundary side (0 the outer row).
    let index = |i: usize, depth: usize| match side {
        0 => i * 4 + depth,
        1 => (3 - depth) * 4 + i,
        2 => i * 4 + 3 - depth,
        _ => depth * 4 + i,
    };
    for i in 0..4 {
        let mut row = Row::default();
        row.add_row(grid[index(i, 1)].as_ref()?, 2.0);
        row.add_row(grid[index(i, 2)].as_ref()?, -1.0);
        grid[index(i, 0)] = Some(row.merged());
    }
    let rows: Vec<Row> = grid.into_iter().collect::<Option<Vec<Row>>>()?;
    rows.try_into().ok()
}

/// Whether the limit over cage quad `f` is exactly the bicubic B-spline of its 16 points: all
/// four corners regular ([`is_regular`]).
pub fn is_regular_face(level: &Level, scheme: Scheme, f: u32) -> bool {
    let face = level.face(f);
    face.len() == 4 && face.iter().all(|&v| is_regular(level, scheme, v))
}

/// Every face's B-spline points ([`bspline_grid`]) where its limit is that bicubic
/// ([`is_regular_face`]), on every core: each point's regularity and ring found once, not
/// once for each face at it.
pub(super) fn regular_bspline_grids(level: &Level, scheme: Scheme) -> Vec<Option<[u32; 16]>> {
    let rings: Vec<Option<FourRing>> = crate::par::map(level.vertex_count, |v| {
        let v = v as u32;
        is_regular(level, scheme, v)
            .then(|| neighbours_and_diagonals(level, v))
            .flatten()
    });
    crate::par::map(level.face_count(), |f| {
        let f = f as u32;
        let face = level.face(f);
        let regular = face.len() == 4 && face.iter().all(|&v| rings[v as usize].is_some());
        regular
            .then(|| bspline_grid_from_rings(level, f, |v| rings[v as usize]))
            .flatten()
    })
}

/// The level-`depth` vertices over face `face` of level `k` of `hierarchy` as a grid of
/// `(2^depth + 1)²` slots (see [`StencilPatch`]); triangle slots past the diagonal are `None`.
pub(super) fn face_grid(
    hierarchy: &Hierarchy,
    k: usize,
    face: u32,
    depth: u32,
) -> Vec<Option<u32>> {
    let level = &hierarchy.levels[k];
    let corners = level.face(face);
    let triangle = corners.len() == 3;
    let s = 1usize << depth;
    let mut grid = vec![None; (s + 1) * (s + 1)];
    if depth == 0 {
        grid[0] = Some(corners[0]);
        grid[s + 1] = Some(corners[1]);
        if triangle {
            grid[1] = Some(corners[2]);
        } else {
            grid[s + 2] = Some(corners[2]);
            grid[1] = Some(corners[3]);
        }
        return grid;
    }
    let h = s / 2;
    // Children of a level's face f (every face at level ≥ 1 of a quad or triangle mesh) are
    // 4f..4f + 3 one level down, placed as refine() orders them.
    let first_child = 4 * face;
    let placements: [(usize, usize, bool); 4] = if triangle {
        [(0, 0, false), (h, 0, false), (0, h, false), (h, h, true)]
    } else {
        std::array::from_fn(|c| {
            let (i, j) = quad_child_origin(c, h);
            (i, j, false)
        })
    };
    for (c, &(oi, oj, inverted)) in placements.iter().enumerate() {
        let sub = face_grid(hierarchy, k + 1, first_child + c as u32, depth - 1);
        for a in 0..=h {
            for b in 0..=h {
                let Some(v) = sub[a * (h + 1) + b] else {
                    continue;
                };
                let (i, j) = if inverted {
                    (h - a, h - b)
                } else {
                    (oi + a, oj + b)
                };
                grid[i * (s + 1) + j] = Some(v);
            }
        }
    }
    grid
}

/// Where child `c` of a quad's refinement starts on the quad's grid, `h` steps being half its
/// side: refine() orders a quad's children from its corners 0, 1, 2, 3, each with the quad's
/// own axes.
fn quad_child_origin(c: usize, h: usize) -> (usize, usize) {
    [(0, 0), (h, 0), (h, h), (0, h)][c % 4]
}

/// The uniform cubic B-spline's four basis functions on one knot span, t ∈ [0, 1], and their
/// first and second derivatives: rows value, d/dt, d²/dt² (the segment polynomials
/// (1 − t)³/6, (3t³ − 6t² + 4)/6, (−3t³ + 3t² + 3t + 1)/6, t³/6; The NURBS Book, eq. 2.5
/// evaluated on unit knot spacing).
fn uniform_cubic_basis(t: f64) -> [[f64; 4]; 3] {
    let s = 1.0 - t;
    [
        [
            s * s * s / 6.0,
            (3.0 * t * t * t - 6.0 * t * t + 4.0) / 6.0,
            (-3.0 * t * t * t + 3.0 * t * t + 3.0 * t + 1.0) / 6.0,
            t * t * t / 6.0,
        ],
        [
            -0.5 * s * s,
            1.5 * t * t - 2.0 * t,
            -1.5 * t * t + t + 0.5,
            0.5 * t * t,
        ],
        [s, 3.0 * t - 2.0, 1.0 - 3.0 * t, t],
    ]
}

/// Adds to `sum` the weights of the bicubic B-spline over `grid` ([`bspline_grid`]) at
/// (u, v) of its quad: position, Su, Sv, Suu, Suv, Svv, the derivatives per `1/scale` of the
/// quad's parameter.
fn add_bspline_weights(grid: &[u32; 16], u: f64, v: f64, scale: f64, sum: &mut Accumulator<6>) {
    let (bu, bv) = (uniform_cubic_basis(u), uniform_cubic_basis(v));
    let s2 = scale * scale;
    for a in 0..4 {
        for b in 0..4 {
            let weights = [
                bu[0][a] * bv[0][b],
                scale * bu[1][a] * bv[0][b],
                scale * bu[0][a] * bv[1][b],
                s2 * bu[2][a] * bv[0][b],
                s2 * bu[1][a] * bv[1][b],
                s2 * bu[0][a] * bv[2][b],
            ];
            // On the quad's edges a row of basis functions vanishes with its derivatives.
            if weights.iter().any(|&w| w != 0.0) {
                sum.add_scaled(grid[a * 4 + b], 1.0, &weights);
            }
        }
    }
}

/// Marks in `needed` the vertices `rows` reach.
fn mark_reached<'a>(needed: &mut [bool], rows: impl Iterator<Item = &'a Row>) {
    for row in rows {
        for &(i, _) in &row.0 {
            needed[i as usize] = true;
        }
    }
}

/// Rows over level `k`'s vertices expressed over the cage's points: composes the stencils of
/// the levels below, level by level as OpenSubdiv's Far factorises its tables, for the level-k
/// vertices `needed_at_k` marks (and only those; the others' rows are empty). Each level's
/// rows are gathered in a flat sparse accumulator over the cage, in blocks on every core.
fn compose_to_cage(hierarchy: &Hierarchy, k: usize, needed_at_k: Vec<bool>) -> WideRows<1> {
    // needed[level]: which vertices of each level the rows reach.
    let mut needed: Vec<Vec<bool>> = hierarchy.levels[..k]
        .iter()
        .map(|l| vec![false; l.vertex_count])
        .collect();
    needed.push(needed_at_k);
    for level in (1..=k).rev() {
        let stencils = &hierarchy.stencils[level - 1];
        let (upper, lower) = needed.split_at_mut(level);
        for (v, _) in lower[0].iter().enumerate().filter(|(_, n)| **n) {
            let (s, e) = (
                stencils.offsets[v] as usize,
                stencils.offsets[v + 1] as usize,
            );
            for &i in &stencils.indices[s..e] {
                upper[level - 1][i as usize] = true;
            }
        }
    }
    let cage = hierarchy.levels[0].vertex_count;
    let mut composed = WideRows {
        offsets: (0..=cage as u32).collect(),
        entries: (0..cage as u32).map(|v| (v, [1.0])).collect(),
    };
    for level in 1..=k {
        let stencils = &hierarchy.stencils[level - 1];
        let below = &composed;
        let needed = &needed[level];
        composed = build_rows(hierarchy.levels[level].vertex_count, cage, |v, sum| {
            if !needed[v] {
                return;
            }
            let (s, e) = (
                stencils.offsets[v] as usize,
                stencils.offsets[v + 1] as usize,
            );
            for t in s..e {
                for (i, w) in below.row(stencils.indices[t] as usize) {
                    sum.add_scaled(*i, stencils.weights[t], w);
                }
            }
        });
    }
    composed
}

/// Gathers the rows of one slot (up to six: position, Su, Sv, Suu, Suv, Svv, each over a
/// level's vertices) over the cage's points into `sum`, given each level vertex's row over the
/// cage (`composed`).
fn gather_over_cage<'a>(
    composed: &WideRows<1>,
    rows: impl Iterator<Item = &'a Row>,
    sum: &mut Accumulator<6>,
) {
    for (c, row) in rows.enumerate() {
        for &(i, w) in &row.0 {
            for &(j, [x]) in composed.row(i as usize) {
                sum.add(j, c, w * x);
            }
        }
    }
}

/// The GPU feed of a display given as polygons over rows ([`DisplayRows`]) on level `k`:
/// each quad one stencil patch of one segment, each triangle one triangle patch, larger
/// polygons fans of triangles; slots of the same display point share its entries. The
/// patches belong to no single cage face (`cage_face` is [`NONE`]).
fn polygon_feed(hierarchy: &Hierarchy, k: usize, display: &DisplayRows) -> LimitFeed {
    let mut needed = vec![false; hierarchy.levels[k].vertex_count];
    mark_reached(&mut needed, display.rows.iter().flatten());
    let composed = compose_to_cage(hierarchy, k, needed);
    let cage = hierarchy.levels[0].vertex_count;
    let point_entries = build_rows(display.rows.len(), cage, |p, sum| {
        gather_over_cage(&composed, display.rows[p].iter(), sum);
    });
    let mut feed = LimitFeed::default();
    let mut entries: Vec<Option<[u32; 2]>> = vec![None; display.rows.len()];
    let mut slot_of = |feed: &mut LimitFeed, point: u32| -> [u32; 2] {
        *entries[point as usize].get_or_insert_with(|| {
            let start = feed.entries.len() as u32;
            feed.entries
                .extend_from_slice(point_entries.row(point as usize));
            [start, feed.entries.len() as u32 - start]
        })
    };
    for polygon in &display.polygons {
        let pieces: Vec<Vec<u32>> = if polygon.len() <= 4 {
            vec![polygon.clone()]
        } else {
            (1..polygon.len() - 1)
                .map(|j| vec![polygon[0], polygon[j], polygon[j + 1]])
                .collect()
        };
        for piece in pieces {
            let triangle = piece.len() == 3;
            let first_slot = feed.slots.len() as u32;
            feed.patches.push(StencilPatch {
                cage_face: NONE,
                triangle,
                segments: 1,
                first_slot,
                level: k as u32,
                piece: [NONE; 2],
                points: NONE,
            });
            // Slot (i, j) at i · 2 + j, i along the first edge: corners 0, 3 (2), 1, 2 (-).
            let order: [Option<u32>; 4] = if triangle {
                [Some(piece[0]), Some(piece[2]), Some(piece[1]), None]
            } else {
                [
                    Some(piece[0]),
                    Some(piece[3]),
                    Some(piece[1]),
                    Some(piece[2]),
                ]
            };
            for corner in order {
                match corner {
                    Some(point) => {
                        let slot = slot_of(&mut feed, point);
                        feed.slots.push(slot);
                        feed.vertex.push(point);
                    }
                    None => {
                        let alias = feed.slots[first_slot as usize];
                        feed.slots.push(alias);
                        feed.vertex.push(u32::MAX);
                    }
                }
                feed.no_curvature.push(true);
            }
        }
    }
    feed
}

/// The feed's B-spline patches of `base`'s regular faces under `scheme` (with
/// `regular_as_bspline`, showing the limit) and its other faces, in order.
fn regular_feed(
    base: &Level,
    scheme: Scheme,
    display: Display,
    regular_as_bspline: bool,
) -> (LimitFeed, Vec<u32>) {
    let mut feed = LimitFeed::default();
    let mut irregular = Vec::new();
    // Each face's B-spline points where it is regular, on every core, in face order.
    let grids = if regular_as_bspline && display == Display::Limit {
        regular_bspline_grids(base, scheme)
    } else {
        vec![None; base.face_count()]
    };
    for (f, grid) in grids.into_iter().enumerate() {
        match grid {
            Some(g) => feed.regular.push((f as u32, g)),
            None => irregular.push(f as u32),
        }
    }
    (feed, irregular)
}

impl SubdivisionSurface {
    /// The GPU feed at level `levels` (≥ 1) showing `display`, regular faces as B-spline
    /// patches.
    pub fn limit_feed(&self, levels: u32, display: Display) -> Result<LimitFeed, GeometryError> {
        self.limit_feed_with(levels, display, true)
    }

    /// [`Self::limit_feed`], with every face as stencil patches when `regular_as_bspline` is
    /// false (so that every vertex of the level appears in a slot).
    pub fn limit_feed_with(
        &self,
        levels: u32,
        display: Display,
        regular_as_bspline: bool,
    ) -> Result<LimitFeed, GeometryError> {
        if let Some(kind) = display.substitute() {
            if levels == 0 {
                return Ok(LimitFeed::default());
            }
            return Ok(self.substitute_feed(levels, kind, regular_as_bspline)?.0);
        }
        if display == Display::Adaptive {
            return Ok(self.adaptive_feed(levels, DEFAULT_TOLERANCE)?.0);
        }
        let base = self.shared_base_level()?;
        let (mut feed, irregular) =
            regular_feed(&base, self.options.scheme, display, regular_as_bspline);
        if irregular.is_empty() || levels == 0 {
            return Ok(feed);
        }
        let scheme = self.options.scheme;
        if regular_as_bspline && matches!(scheme, Scheme::CatmullClark | Scheme::Loop) {
            // Faces whose neighbourhoods are alike share one refinement of one of them, where
            // that refines at most half the region round them all (Catmull-Clark's and
            // Loop's stencils reach two rings; the butterfly's reach further).
            let templates = (irregular.len() >= templates::FEWEST_FACES)
                .then(|| {
                    templates::Templates::new(
                        &base,
                        &irregular,
                        REGION_RINGS,
                        display == Display::Limit,
                    )
                })
                .flatten();
            self.push_nested_stencils(&mut feed, &base, &irregular, templates, levels, display)?;
            return Ok(feed);
        }
        let hierarchy = Hierarchy::new(Arc::unwrap_or_clone(base), self.options, levels)?;
        let k = levels as usize;
        if matches!(scheme, Scheme::DooSabin | Scheme::Sqrt3) {
            let rows = display_rows(&hierarchy.levels[k], scheme, display);
            return Ok(polygon_feed(&hierarchy, k, &rows));
        }
        push_face_patches(&mut feed, &hierarchy, &irregular, levels, display);
        Ok(feed)
    }

    /// [`Self::limit_feed`] (B-spline patches for the regular faces), taking the stencils of
    /// the faces whose neighbourhoods read as in `previous` (the cache an earlier feed of this
    /// object kept, [`super::stencil_cache`]) from there and refining only the others; with the
    /// cache of this feed for the next. Catmull-Clark and Loop showing the limit or the
    /// refined mesh keep a cache; other schemes and displays are built as
    /// [`Self::limit_feed`] builds them, with none.
    pub fn limit_feed_reusing(
        &self,
        levels: u32,
        display: Display,
        previous: Option<&StencilCache>,
    ) -> Result<(LimitFeed, Option<StencilCache>), GeometryError> {
        let scheme = self.options.scheme;
        let keeps = matches!(scheme, Scheme::CatmullClark | Scheme::Loop)
            && matches!(display, Display::Limit | Display::Refined);
        if !keeps {
            return Ok((self.limit_feed(levels, display)?, None));
        }
        let base = self.shared_base_level()?;
        let (mut feed, irregular) = regular_feed(&base, scheme, display, true);
        let cache = StencilCache::new(self.options, levels, display);
        if irregular.is_empty() || levels == 0 {
            return Ok((feed, Some(cache)));
        }
        let read = crate::par::map(irregular.len(), |k| {
            templates::Neighbourhood::read(
                &base,
                irregular[k],
                REGION_RINGS,
                display == Display::Limit,
            )
        });
        // Faces whose neighbourhoods cannot be walked are refined every time.
        let mut unread = Vec::new();
        let mut faces = Vec::with_capacity(irregular.len());
        for (&face, neighbourhood) in irregular.iter().zip(read) {
            match neighbourhood {
                Some(neighbourhood) => faces.push(ReadFace {
                    face,
                    neighbourhood,
                }),
                None => unread.push(face),
            }
        }
        let (kept, mut made) = match previous.filter(|c| c.serves(self.options, levels, display)) {
            Some(previous) => previous.split(faces),
            None => (Vec::new(), faces),
        };
        let mut asked: Vec<u32> = made.iter().map(|f| f.face).chain(unread).collect();
        asked.sort_unstable();
        if !asked.is_empty() {
            // The templates need every asked face's neighbourhood, in the faces' order (then
            // `asked` and `made` name the same faces).
            made.sort_unstable_by_key(|f| f.face);
            let templates = (asked.len() == made.len() && asked.len() >= templates::FEWEST_FACES)
                .then(|| {
                    let neighbourhoods = std::mem::take(&mut made)
                        .into_iter()
                        .map(|f| f.neighbourhood)
                        .collect();
                    templates::Templates::of(neighbourhoods)
                });
            let templates =
                self.push_nested_stencils(&mut feed, &base, &asked, templates, levels, display)?;
            if let Some(templates) = templates {
                made = asked
                    .iter()
                    .zip(templates.into_neighbourhoods())
                    .map(|(&face, neighbourhood)| ReadFace {
                        face,
                        neighbourhood,
                    })
                    .collect();
            }
        }
        let cache = cache.after(&mut feed, &base, &made, kept);
        Ok((feed, Some(cache)))
    }

    /// Appends the stencil patches of faces `faces` (increasing) of `base` under Catmull-Clark
    /// or Loop: through `templates` (the faces' neighbourhoods grouped) where they refine at
    /// most half the region round the faces, else from a refinement of that region
    /// (Catmull-Clark), else of the whole cage. Gives `templates` back.
    fn push_nested_stencils(
        &self,
        feed: &mut LimitFeed,
        base: &Arc<Level>,
        faces: &[u32],
        templates: Option<templates::Templates>,
        levels: u32,
        display: Display,
    ) -> Result<Option<templates::Templates>, GeometryError> {
        let region = face_region(base, faces, REGION_RINGS);
        if let Some(shared) = &templates
            && 2 * shared.refined_faces() <= region.len()
        {
            let options = self.options;
            let refine = |cage| first_face_patches(cage, options, levels, display);
            shared.push(feed, base, options, refine)?;
            return Ok(templates);
        }
        // Beside regular B-spline quads, the few faces left take their stencils from a
        // refinement of their neighbourhood only.
        if self.options.scheme == Scheme::CatmullClark
            && push_region_stencil_patches(
                feed,
                base,
                self.options,
                faces,
                region,
                levels,
                display,
                MOST_OF_THE_CAGE,
            )?
        {
            return Ok(templates);
        }
        let hierarchy = Hierarchy::new((**base).clone(), self.options, levels)?;
        push_face_patches(feed, &hierarchy, faces, levels, display);
        Ok(templates)
    }

    /// The GPU feed of substitute `kind` at level `levels` (≥ 1) and the plan that computes its
    /// control points: regular quads of a quad cage as B-spline patches (with
    /// `regular_as_bspline`), faces at boundaries, creases and sharp corners as limit stencils,
    /// every other face one substitute patch of 2^levels segments per edge (2^(levels − 1) on
    /// level 1), whose slots name the level's vertices they correspond to.
    pub fn substitute_feed(
        &self,
        levels: u32,
        kind: SubstituteKind,
        regular_as_bspline: bool,
    ) -> Result<(LimitFeed, SubstitutePlan), GeometryError> {
        let plan = SubstitutePlan::new(self, kind, levels, regular_as_bspline)?;
        let base = self.base_level()?;
        let mut feed = LimitFeed::default();
        let mut exact = plan.exact.clone();
        for &f in &plan.regular {
            match bspline_grid(&base, f) {
                Some(g) => feed.regular.push((f, g)),
                None => exact.push(ExactPiece {
                    level: 0,
                    face: f,
                    cage_face: f,
                    depth: levels,
                }),
            }
        }
        let hierarchy = Hierarchy::new(base, self.options, levels)?;
        let exact: Vec<ShownPiece> = exact.into_iter().map(ShownPiece::uniform).collect();
        push_stencil_patches(&mut feed, &hierarchy, levels, &exact, Display::Limit);
        let depth = levels - plan.base_level as u32;
        for (p, planned) in plan.patches.iter().enumerate() {
            let grid = face_grid(&hierarchy, plan.base_level, planned.base_face, depth);
            let first_slot = feed.vertex.len() as u32;
            for v in grid {
                feed.vertex.push(v.unwrap_or(NONE));
                feed.slots.push([0, 0]);
                feed.no_curvature.push(true);
            }
            feed.substitutes.push(SubstitutePatch {
                cage_face: planned.cage_face,
                kind,
                segments: 1 << depth,
                first_point: (self.points().len() + p * kind.point_count()) as u32,
                first_slot,
            });
        }
        Ok((feed, plan))
    }
}

/// The stencil patches showing face 0 of `cage` (a face's neighbourhood cut out as a cage of
/// its own, [`templates`]) at level `levels` as `display`, over `cage`'s points.
pub(super) fn first_face_patches(
    cage: Level,
    options: super::Options,
    levels: u32,
    display: Display,
) -> Result<LimitFeed, GeometryError> {
    let hierarchy = Hierarchy::new(cage, options, levels)?;
    let mut feed = LimitFeed::default();
    push_face_patches(&mut feed, &hierarchy, &[0], levels, display);
    Ok(feed)
}

/// Appends to `feed` the stencil patches showing faces `faces` of `hierarchy`'s cage, each at
/// level `levels` as `display` ([`exact_pieces`], [`push_stencil_patches`]).
fn push_face_patches(
    feed: &mut LimitFeed,
    hierarchy: &Hierarchy,
    faces: &[u32],
    levels: u32,
    display: Display,
) {
    let pieces = exact_pieces(hierarchy, faces, levels);
    let shown: Vec<ShownPiece> = pieces.into_iter().map(ShownPiece::uniform).collect();
    push_stencil_patches(feed, hierarchy, levels, &shown, display);
}

/// Appends to `feed` the stencil patches showing cage faces `faces` (increasing) of `base` at
/// level `levels` as `display`, refining only the faces of `region`, the faces within some
/// rings of them ([`face_region`]; [`REGION_RINGS`] give the same stencils as refining the
/// whole cage, up to the order of the sums). Their slots name no level vertex (`u32::MAX`):
/// the region's levels are not the cage's. Returns false, appending nothing, where the region
/// is more than `most` of the cage's faces ([`MOST_OF_THE_CAGE`]).
#[allow(clippy::too_many_arguments)]
pub(super) fn push_region_stencil_patches(
    feed: &mut LimitFeed,
    base: &Level,
    options: super::Options,
    faces: &[u32],
    region: Vec<u32>,
    levels: u32,
    display: Display,
    most: f64,
) -> Result<bool, GeometryError> {
    if region.len() as f64 > most * base.face_count() as f64 {
        return Ok(false);
    }
    let (cut, topology) = RegionCage::new(base, region, options)?;
    let asked = cut.region_faces(faces);
    let hierarchy = Hierarchy::new(topology, options, levels)?;
    let mut local = LimitFeed::default();
    push_face_patches(&mut local, &hierarchy, &asked, levels, display);
    cut.append(feed, &local, (base, &hierarchy.levels[0]), options);
    Ok(true)
}

/// A slot of a shown grid: the level's vertex there, its neighbour along the full grid's i
/// (`towards`) and whether that neighbour lies backwards (`reversed`, the grid's last row),
/// and the corner diagonally opposite it in the piece's quad at the slot (Catmull-Clark),
/// which names the quad whose side of a crease the slot shows.
#[derive(Debug, Clone, Copy)]
struct ShownSlot {
    vertex: u32,
    towards: Option<u32>,
    reversed: bool,
    opposite: Option<u32>,
    /// On a triangle: a neighbour in the face and how many sixths of a turn counter-clockwise
    /// from the slot's u it lies (the lattice directions (1, 0), (0, 1), (−1, 0), (0, −1) are
    /// 0, 1, 3 and 4, tried in that order), so that a slot on the face's diagonal, whose
    /// neighbour along u lies outside the face, still has one.
    lattice: Option<(u32, usize)>,
    /// On a Loop slot at a sharp or boundary edge: a triangle of the level inside the piece at
    /// the slot, which names the side of a crease the slot shows.
    lattice_face: Option<u32>,
}

/// The pieces that show cage faces `faces` exactly at level `levels` (≥ 1): Catmull-Clark's
/// faces split into their level-1 quads (every face of a level ≥ 1 is a quad), the other
/// schemes' faces themselves.
pub(super) fn exact_pieces(hierarchy: &Hierarchy, faces: &[u32], levels: u32) -> Vec<ExactPiece> {
    let scheme = hierarchy.options.scheme;
    let starts = first_children(&hierarchy.levels[0], scheme);
    let mut pieces = Vec::new();
    for &f in faces {
        match scheme {
            Scheme::CatmullClark => {
                let n = hierarchy.levels[0].face(f).len() as u32;
                pieces.extend((0..n).map(|c| ExactPiece {
                    level: 1,
                    face: starts[f as usize] + c,
                    cage_face: f,
                    depth: levels - 1,
                }));
            }
            _ => pieces.push(ExactPiece {
                level: 0,
                face: f,
                cage_face: f,
                depth: levels,
            }),
        }
    }
    pieces
}

/// The rows of one shown slot over its level's vertices: a regular Catmull-Clark vertex's
/// 3 × 3 neighbourhood ([`regular_grid`]) with its derivatives' scale, whose weights
/// ([`regular_weights`]) give the position and every first and second derivative; any other
/// vertex's limit position and two tangents (the curvature undefined).
enum SlotRows {
    Regular([u32; 9], f64),
    /// A regular vertex on a crease or the boundary: the weights of its side's extended 3 × 3
    /// neighbourhood ([`sided_weights`]), every derivative exact.
    Sided(Vec<(u32, [f64; 6])>),
    Rows([Row; 3]),
    /// On a regular cage quad: that quad and (u, v) on it, the bicubic's values in closed form.
    BSpline {
        face: u32,
        u: f64,
        v: f64,
    },
}

/// Appends the stencil patches of `pieces` (faces of the hierarchy's levels refined to level
/// `levels`, each shown on its own grid, [`ShownPiece`]) showing `display`. Every slot shows a
/// vertex of level `levels`, with its derivatives taken on that level's grid.
pub(super) fn push_stencil_patches(
    feed: &mut LimitFeed,
    hierarchy: &Hierarchy,
    levels: u32,
    pieces: &[ShownPiece],
    display: Display,
) {
    push_stencil_patches_with(feed, hierarchy, levels, pieces, display, true);
}

/// [`push_stencil_patches`], with the slots on regular cage quads in closed form
/// (`closed_form`) or, as on any other face, composed from the refinement's rows (the tests'
/// reference).
fn push_stencil_patches_with(
    feed: &mut LimitFeed,
    hierarchy: &Hierarchy,
    levels: u32,
    pieces: &[ShownPiece],
    display: Display,
    closed_form: bool,
) {
    if pieces.is_empty() {
        return;
    }
    let scheme = hierarchy.options.scheme;
    let k = levels as usize;
    let level = &hierarchy.levels[k];
    let triangle = scheme != Scheme::CatmullClark;
    // Per piece: its patch and, per shown slot, the vertex of level k there (the full grid's,
    // at the position the piece shows) and its neighbour along the full grid's i.
    let mut grids: Vec<(StencilPatch, Vec<Option<ShownSlot>>)> = pieces
        .iter()
        .map(|shown| {
            let piece = shown.piece;
            let full = face_grid(hierarchy, piece.level, piece.face, piece.depth);
            let big = 1usize << piece.depth;
            let at = |i: usize, j: usize| full[i * (big + 1) + j];
            let s = shown.segments();
            let mut slots = Vec::with_capacity((s as usize + 1).pow(2));
            for a in 0..=s {
                for b in 0..=s {
                    slots.push(shown.full_position(triangle, a, b).and_then(|(i, j)| {
                        let (i, j) = (i as usize, j as usize);
                        let (towards, reversed) = if i < big {
                            (at(i + 1, j), false)
                        } else {
                            (at(i - 1, j), true)
                        };
                        // The piece's quad at this slot: the grid cell beside it, found by
                        // its corner opposite the slot's.
                        let (ci, cj) = (i.min(big - 1), j.min(big - 1));
                        let opposite = if triangle {
                            None
                        } else {
                            at(2 * ci + 1 - i, 2 * cj + 1 - j)
                        };
                        let lattice = if triangle {
                            let step = |di: isize, dj: isize| {
                                let (a, b) = (i.checked_add_signed(di)?, j.checked_add_signed(dj)?);
                                if a > big || b > big {
                                    return None;
                                }
                                at(a, b)
                            };
                            [((1, 0), 0), ((0, 1), 1), ((-1, 0), 3), ((0, -1), 4)]
                                .into_iter()
                                .find_map(|((di, dj), turns)| Some((step(di, dj)?, turns)))
                        } else {
                            None
                        };
                        // On a Loop slot at a sharp edge (the only ones with a side): the
                        // first lattice triangle round the slot (between two directions a
                        // sixth of a turn apart) whose corners all lie in the piece.
                        let on_sharp_edge = |v: u32| {
                            level.vertex_edges(v).iter().any(|&e| {
                                level.is_boundary_edge(e) || level.edge_sharpness[e as usize] > 0.0
                            })
                        };
                        let lattice_face = at(i, j)
                            .filter(|&v| scheme == Scheme::Loop && on_sharp_edge(v))
                            .and_then(|v| {
                                const AROUND: [(isize, isize); 6] =
                                    [(1, 0), (0, 1), (-1, 1), (-1, 0), (0, -1), (1, -1)];
                                let step = |(di, dj): (isize, isize)| {
                                    let a = i.checked_add_signed(di)?;
                                    let b = j.checked_add_signed(dj)?;
                                    if a + b > big {
                                        return None;
                                    }
                                    at(a, b)
                                };
                                (0..6).find_map(|k| {
                                    let (p, q) = (step(AROUND[k])?, step(AROUND[(k + 1) % 6])?);
                                    level.vertex_faces(v).iter().copied().find(|&f| {
                                        let corners = level.face(f);
                                        corners.contains(&p) && corners.contains(&q)
                                    })
                                })
                            });
                        at(i, j).map(|v| ShownSlot {
                            vertex: v,
                            towards,
                            reversed,
                            opposite,
                            lattice,
                            lattice_face,
                        })
                    }));
                }
            }
            (
                StencilPatch {
                    cage_face: piece.cage_face,
                    triangle,
                    segments: s,
                    first_slot: 0,
                    level: piece.level as u32 + shown.depth,
                    piece: [piece.level as u32, piece.face],
                    points: NONE,
                },
                slots,
            )
        })
        .collect();
    // The slots already in the feed.
    let before = feed.slots.len();
    // Per slot over level-k vertices: a regular vertex's 3 × 3 grid and its scale, or the
    // rows of its limit position and tangents (no curvature).
    let vertex_rows = VertexRows::new(level, scheme, display);
    // Catmull-Clark's limit over a regular cage quad is the bicubic B-spline of its 16 points
    // ([`is_regular_face`]): a slot of one of its level-1 quads takes the B-spline's values at
    // its parameter on the cage quad in closed form (as OpenSubdiv's limit stencils evaluate a
    // regular patch's basis), with no refinement rows composed.
    let base = &hierarchy.levels[0];
    let closed_form = closed_form && scheme == Scheme::CatmullClark && display == Display::Limit;
    let (starts, bspline_faces): (Vec<u32>, Vec<Option<[u32; 16]>>) = if closed_form {
        (
            first_children(base, scheme),
            regular_bspline_grids(base, scheme),
        )
    } else {
        Default::default()
    };
    // Catmull-Clark's limit beside a regular crease or boundary point is one side's bicubic;
    // Loop's at a regular point is the box spline.
    let sided_display =
        matches!(scheme, Scheme::CatmullClark | Scheme::Loop) && display != Display::Refined;
    let per_piece: Vec<Vec<Option<SlotRows>>> =
        crate::par::map(grids.len().min(pieces.len()), |k| {
            let (grid, shown) = (&grids[k].1, &pieces[k]);
            let piece = shown.piece;
            if piece.level == 1
                && bspline_faces
                    .get(piece.cage_face as usize)
                    .is_some_and(Option::is_some)
            {
                // The piece's full grid (2^depth segments) is one quarter of the cage quad's,
                // with the quad's axes.
                let c = (piece.face - starts[piece.cage_face as usize]) as usize;
                let full = 1usize << piece.depth;
                let (oi, oj) = quad_child_origin(c, full);
                let side = (2 * full) as f64;
                let s = shown.segments();
                return (0..grid.len() as u32)
                    .map(|slot| {
                        grid[slot as usize]?;
                        let (a, b) = (slot / (s + 1), slot % (s + 1));
                        let (i, j) = shown.full_position(false, a, b)?;
                        Some(SlotRows::BSpline {
                            face: piece.cage_face,
                            u: (oi + i as usize) as f64 / side,
                            v: (oj + j as usize) as f64 / side,
                        })
                    })
                    .collect();
            }
            // Derivatives per unit of the piece's parameter: level k's step is 2^-depth of it.
            let scale = f64::from(1u32 << shown.piece.depth);
            grid.iter()
                .map(|slot| {
                    let ShownSlot {
                        vertex: v,
                        towards,
                        reversed,
                        opposite,
                        lattice,
                        lattice_face,
                    } = (*slot)?;
                    let regular = display != Display::Refined && is_regular(level, scheme, v);
                    let neighbourhood = if regular {
                        towards.and_then(|n| regular_grid(level, v, n, reversed))
                    } else {
                        None
                    };
                    Some(match neighbourhood {
                        Some(points) => SlotRows::Regular(points, scale),
                        None => {
                            let face = opposite.and_then(|o| {
                                level.vertex_faces(v).iter().copied().find(|&f| {
                                    level.face(f).len() == 4 && level.diagonal(f, v) == o
                                })
                            });
                            let sided = (sided_display && !regular)
                                .then(|| match scheme {
                                    Scheme::Loop => {
                                        let (n, turns) = lattice?;
                                        loop_regular_weights(level, v, n, turns, scale)
                                            .or_else(|| {
                                                let face = lattice_face?;
                                                loop_sided_weights(level, v, n, turns, face, scale)
                                            })
                                            .or_else(|| {
                                                loop_corner_weights(level, v, n, turns, scale)
                                            })
                                    }
                                    _ => sided_weights(level, v, towards?, reversed, face?, scale),
                                })
                                .flatten();
                            match sided {
                                Some(weights) => SlotRows::Sided(weights),
                                None => SlotRows::Rows(vertex_rows.rows_in_face(v, face)),
                            }
                        }
                    })
                })
                .collect()
        });
    let mut slot_rows: Vec<Option<SlotRows>> = Vec::new();
    for ((patch, _), rows) in grids.iter_mut().zip(per_piece) {
        patch.first_slot = (before + slot_rows.len()) as u32;
        slot_rows.extend(rows);
        feed.patches.push(*patch);
    }
    let mut needed = vec![false; level.vertex_count];
    for slot in slot_rows.iter().flatten() {
        match slot {
            SlotRows::Regular(points, _) => {
                for &p in points {
                    needed[p as usize] = true;
                }
            }
            SlotRows::Sided(weights) => {
                for &(p, _) in weights {
                    needed[p as usize] = true;
                }
            }
            SlotRows::Rows(rows) => mark_reached(&mut needed, rows.iter()),
            SlotRows::BSpline { .. } => {}
        }
    }
    let composed = compose_to_cage(hierarchy, k, needed);
    let cage = hierarchy.levels[0].vertex_count;
    let slot_entries = build_rows(slot_rows.len(), cage, |slot, sum| match &slot_rows[slot] {
        Some(SlotRows::Regular(points, scale)) => {
            for (&p, weights) in points.iter().zip(regular_weights(*scale).iter()) {
                for &(j, [x]) in composed.row(p as usize) {
                    sum.add_scaled(j, x, weights);
                }
            }
        }
        Some(SlotRows::Sided(weights)) => {
            for (p, weights) in weights {
                for &(j, [x]) in composed.row(*p as usize) {
                    sum.add_scaled(j, x, weights);
                }
            }
        }
        Some(SlotRows::Rows(rows)) => gather_over_cage(&composed, rows.iter(), sum),
        // A level-1 quad's parameter is half the cage quad's.
        Some(SlotRows::BSpline { face, u, v }) => {
            if let Some(grid) = &bspline_faces[*face as usize] {
                add_bspline_weights(grid, *u, *v, 0.5, sum);
            }
        }
        None => {}
    });
    let base = feed.entries.len() as u32;
    for (patch, grid) in &grids {
        let first = patch.first_slot as usize;
        for slot in first..first + (patch.segments as usize + 1).pow(2) {
            let Some(rows) = &slot_rows[slot - before] else {
                // Unused triangle slots alias the patch's first slot.
                let alias = feed.slots[first];
                feed.slots.push(alias);
                feed.no_curvature.push(true);
                feed.vertex.push(u32::MAX);
                continue;
            };
            let [start, end] = [slot - before, slot - before + 1].map(|r| slot_entries.offsets[r]);
            feed.slots.push([base + start, end - start]);
            feed.no_curvature.push(matches!(rows, SlotRows::Rows(_)));
            feed.vertex
                .push(grid[slot - first].map_or(u32::MAX, |slot| slot.vertex));
        }
    }
    // The slots' entries follow the feed's, in slot order.
    if feed.entries.is_empty() {
        feed.entries = slot_entries.entries;
    } else {
        feed.entries.extend(slot_entries.entries);
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::mesh::PolygonMesh;
    use crate::subdiv::limit::limit_rule;
    use crate::subdiv::refine::Rule;
    use crate::subdiv::{Crease, Options, cages};
    use crate::test_support::{Xorshift, placement};
    use glam::DVec3;

    /// Cages with regular quads beside extraordinary vertices, triangles, a crease and a
    /// boundary, their points jittered and the whole under a random rotation, scale and
    /// translation.
    fn general_cages(seed: u64) -> Vec<SubdivisionSurface> {
        let mut draw = Xorshift::new(seed);
        let torus = cages::torus(DVec3::ZERO, 2.0, 0.7, 9, 7).unwrap();
        // One quad split into two triangles: valence-5 and valence-3 corners.
        let mut faces: Vec<Vec<u32>> = torus.faces().map(|f| f.to_vec()).collect();
        let q = faces.remove(10);
        faces.push(vec![q[0], q[1], q[2]]);
        faces.push(vec![q[0], q[2], q[3]]);
        let split = PolygonMesh::new(torus.points().to_vec(), &faces).unwrap();
        let cylinder = cages::cylinder(DVec3::ZERO, 1.0, 3.0, 8, 6).unwrap();
        let grid = cages::grid(DVec3::ZERO, 2.0, 6).unwrap();
        let crease = vec![Crease {
            a: 3,
            b: 4,
            sharpness: 1.5,
        }];
        let mut out = Vec::new();
        for (mesh, creases) in [
            (split, Vec::new()),
            (torus, crease),
            (cylinder, Vec::new()),
            (grid, Vec::new()),
        ] {
            let (motion, _) = placement(draw.bits());
            let points: Vec<DVec3> = mesh
                .points()
                .iter()
                .map(|&p| {
                    let jitter = DVec3::new(draw.unit(), draw.unit(), draw.unit()) * 0.3 - 0.15;
                    motion.transform_point3(p + jitter)
                })
                .collect();
            let faces: Vec<Vec<u32>> = mesh.faces().map(|f| f.to_vec()).collect();
            let mesh = PolygonMesh::new(points, &faces).unwrap();
            out.push(
                SubdivisionSurface::new(mesh, creases, Vec::new(), Options::default(), 3).unwrap(),
            );
        }
        out
    }

    /// Every face as stencil patches at `levels`, the regular quads' slots in closed form or
    /// composed from the refinement's rows.
    fn all_stencils(surface: &SubdivisionSurface, levels: u32, closed_form: bool) -> LimitFeed {
        let base = surface.base_level().unwrap();
        let faces: Vec<u32> = (0..base.face_count() as u32).collect();
        let hierarchy = Hierarchy::new(base, surface.options, levels).unwrap();
        let pieces = exact_pieces(&hierarchy, &faces, levels);
        let shown: Vec<ShownPiece> = pieces.into_iter().map(ShownPiece::uniform).collect();
        let mut feed = LimitFeed::default();
        push_stencil_patches_with(
            &mut feed,
            &hierarchy,
            levels,
            &shown,
            Display::Limit,
            closed_form,
        );
        feed
    }

    /// Position, Su, Sv, Suu, Suv, Svv of `slot` (of the last patch starting at or before it;
    /// the patches' slots follow each other).
    pub(in crate::subdiv) fn slot_values(
        feed: &LimitFeed,
        points: &[DVec3],
        slot: usize,
    ) -> [DVec3; 6] {
        let after = feed
            .patches
            .partition_point(|p| p.first_slot as usize <= slot);
        let patch = &feed.patches[after - 1];
        let mut out = [DVec3::ZERO; 6];
        for (i, w) in feed.slot_entries(patch, slot).unwrap() {
            for c in 0..6 {
                out[c] += points[i as usize] * w[c];
            }
        }
        out
    }

    /// The closed-form B-spline slots on regular cage quads give what composing the
    /// refinement's masks level by level gives (position, first and second derivatives), and
    /// the positions and normals of the level's limit.
    #[test]
    fn regular_quads_in_closed_form_match_the_composed_refinement() {
        for seed in [0x9e37_79b9_7f4a_7c15, 0x2545_f491_4f6c_dd1d] {
            for (c, surface) in general_cages(seed).iter().enumerate() {
                let (lo, hi) = surface.mesh().bounds().unwrap();
                let size = (hi - lo).length();
                let points = surface.points();
                let base = surface.base_level().unwrap();
                let regular = (0..base.face_count() as u32)
                    .filter(|&f| is_regular_face(&base, Scheme::CatmullClark, f))
                    .count();
                assert!(
                    regular > 0 && regular < base.face_count(),
                    "cage {c}: {regular} regular quads"
                );
                for levels in 1..=3 {
                    let closed = all_stencils(surface, levels, true);
                    let composed = all_stencils(surface, levels, false);
                    assert_eq!(closed.vertex, composed.vertex);
                    assert_eq!(closed.no_curvature, composed.no_curvature);
                    let limit = surface.limit(levels).unwrap();
                    let hierarchy = surface.hierarchy(levels).unwrap();
                    let level = &hierarchy.levels[levels as usize];
                    let mut worst = [0.0f64; 3];
                    for slot in 0..closed.slots.len() {
                        let vertex = closed.vertex[slot];
                        if vertex == u32::MAX {
                            continue;
                        }
                        let a = slot_values(&closed, points, slot);
                        let b = slot_values(&composed, points, slot);
                        for k in 0..6 {
                            worst[0] = worst[0].max((a[k] - b[k]).length() / size);
                        }
                        let v = vertex as usize;
                        worst[1] = worst[1].max((a[0] - limit.positions[v]).length() / size);
                        // A sharp point's slot shows its own quad's normal (the limit mesh
                        // has one per point).
                        if matches!(limit_rule(level, vertex), Rule::Smooth | Rule::Dart) {
                            let normal = a[1].cross(a[2]);
                            worst[2] = worst[2].max(normal.angle_between(limit.normals[v]));
                        }
                    }
                    assert!(
                        worst[0] < 1e-12 && worst[1] < 1e-12 && worst[2] < 1e-7,
                        "seed {seed:x} cage {c} level {levels}: {worst:?}"
                    );
                }
            }
        }
    }
}
