//! Stencil patches of a few cage faces from a refinement of their neighbourhood only.
//!
//! Catmull-Clark is local: the limit over a cage face, its tangents included, depends only on
//! the cage points near it, and each refinement step computes a vertex from its parent's
//! one-ring (a face point from its face, an edge point from the edge's two faces, a vertex
//! point from the faces around the vertex). So the stencils of the faces that are not regular
//! B-spline quads (near extraordinary vertices, creases, boundaries) come out the same when
//! only the faces within a few vertex-rings of them are refined (OpenSubdiv's feature-adaptive
//! refinement rests on the same fact). A tool that adds a few extraordinary vertices to a
//! 10,000-face cage then refines a few hundred faces, not 160,000.
//!
//! The region is cut out as a cage of its own: its faces in the cage's order, its points
//! numbered in the cage's order, each edge and point with the sharpness it has in the whole
//! cage. Where the cut leaves an edge on the region's rim, that edge becomes a boundary
//! (infinitely sharp) and its points follow the boundary rules; that changes the points the
//! rim reaches, [`REGION_RINGS`] rings away from the faces asked for, never theirs.

use rustc_hash::FxHashSet;

use super::level::{INFINITE_SHARPNESS, Level, NONE};
use super::pieces::{LimitFeed, first_children};
use super::{Boundary, Options};
use crate::GeometryError;

/// How many vertex-rings of faces around the faces asked for are refined with them. A slot's
/// rows read its level vertex's one-ring at that level (the limit masks, a regular vertex's
/// 3 × 3 neighbourhood, a sharp point's sector masks); refined back to the cage, those reach
/// the faces sharing a point with the face, and every refined point they read is computed from
/// faces of the region only, never from its rim, whose points follow boundary rules. Where a
/// sharp point's tangents have no sector masks (a semi-sharp corner with no sharp edge, a
/// crease sector of one quad), they come from the neighbours' limit points, the ring beyond:
/// one ring more.
pub const REGION_RINGS: u32 = 2;

/// Above this share of the cage's faces, the region is refined as the whole cage is (the cut
/// would cost more than it saves).
pub const MOST_OF_THE_CAGE: f64 = 0.5;

/// The faces within `rings` vertex-rings of `faces` (faces sharing a point with them, `rings`
/// times over), `faces` included, in increasing order; where the region's faces round one of
/// its points would form two fans or more (regions touching at a point), every face round
/// that point joins, so that the region is a manifold cage.
pub fn face_region(level: &Level, faces: &[u32], rings: u32) -> Vec<u32> {
    // A few faces' region is marked in a set: a flag per face of a large cage would cost
    // more than the region.
    let mut inside = if faces.len() * 64 < level.face_count() {
        Marks::Few(FxHashSet::with_capacity_and_hasher(
            64 * faces.len(),
            Default::default(),
        ))
    } else {
        Marks::All(vec![false; level.face_count()])
    };
    let mut frontier: Vec<u32> = Vec::with_capacity(faces.len());
    for &f in faces {
        if inside.mark(f) {
            frontier.push(f);
        }
    }
    let mut region = frontier.clone();
    let grow = |from: &[u32], inside: &mut Marks| {
        let mut next = Vec::new();
        for &f in from {
            for &v in level.face(f) {
                for &g in level.vertex_faces(v) {
                    if inside.mark(g) {
                        next.push(g);
                    }
                }
            }
        }
        next
    };
    for _ in 0..rings {
        let next = grow(&frontier, &mut inside);
        region.extend_from_slice(&next);
        frontier = next;
    }
    // Points where the region's faces form several fans take all their faces, until none is
    // left (each pass only adds faces).
    let mut check = region.clone();
    while !check.is_empty() {
        // Each point of the faces to check once.
        let mut points: Vec<u32> = check.iter().flat_map(|&f| level.face(f)).copied().collect();
        points.sort_unstable();
        points.dedup();
        let snapshot = inside.clone();
        let mut next = Vec::new();
        for v in points {
            if fan_count(level, &snapshot, v) > 1 {
                next.extend(level.vertex_faces(v).iter().filter(|&&g| inside.mark(g)));
            }
        }
        region.extend_from_slice(&next);
        check = next;
    }
    region.sort_unstable();
    region
}

/// The faces marked as in a region: a set of a few, or a flag per face.
#[derive(Clone)]
enum Marks {
    Few(FxHashSet<u32>),
    All(Vec<bool>),
}

impl Marks {
    /// Marks face `f`; true where it was not marked before.
    fn mark(&mut self, f: u32) -> bool {
        match self {
            Self::Few(set) => set.insert(f),
            Self::All(flags) => !std::mem::replace(&mut flags[f as usize], true),
        }
    }

    fn has(&self, f: u32) -> bool {
        match self {
            Self::Few(set) => set.contains(&f),
            Self::All(flags) => flags[f as usize],
        }
    }
}

/// How many separate fans the faces marked `inside` form round point `v` (0 where none): round
/// a manifold point each edge between two faces inside joins two of them into one fan.
fn fan_count(level: &Level, inside: &Marks, v: u32) -> usize {
    let faces = level.vertex_faces(v);
    let count = faces.iter().filter(|&&f| inside.has(f)).count();
    if count <= 1 || count == faces.len() {
        return count.min(1);
    }
    let joined = level
        .vertex_edges(v)
        .iter()
        .filter(|&&e| {
            let [a, b] = level.edge_faces[e as usize];
            a != NONE && b != NONE && inside.has(a) && inside.has(b)
        })
        .count();
    count - joined
}

/// A region of a level cut out as a cage of its own ([`face_region`]): which of the level's
/// faces and points it holds.
pub(super) struct RegionCage {
    /// The region's faces, as indices of the level's faces (increasing, but for a face's
    /// neighbourhood in [`super::templates`]: that face first, the rest as met from it).
    pub faces: Vec<u32>,
    /// The region's points, as indices of the level's points (increasing, but in a face's
    /// neighbourhood: as its faces first use them).
    pub points: Vec<u32>,
}

impl RegionCage {
    /// The region of `level` made of `faces` (increasing), and its topology over its own point
    /// numbers with the level's sharpness (its rim a boundary).
    pub fn new(
        level: &Level,
        faces: Vec<u32>,
        options: Options,
    ) -> Result<(Self, Level), GeometryError> {
        let mut local = vec![NONE; level.vertex_count];
        for &f in &faces {
            for &v in level.face(f) {
                local[v as usize] = 0;
            }
        }
        let mut points = Vec::new();
        for (v, slot) in local.iter_mut().enumerate() {
            if *slot != NONE {
                *slot = points.len() as u32;
                points.push(v as u32);
            }
        }
        let cut: Vec<Vec<u32>> = faces
            .iter()
            .map(|&f| level.face(f).iter().map(|&v| local[v as usize]).collect())
            .collect();
        let region = Self { faces, points };
        let topology = region.topology(level, &cut, options)?;
        Ok((region, topology))
    }

    /// The topology of the region's faces `cut` (each of [`Self::faces`] over the region's
    /// point numbers) with the level's sharpness: the rim's edges boundaries, and under
    /// [`Boundary::EdgeAndCorner`] its points of one face corners.
    pub fn topology(
        &self,
        level: &Level,
        cut: &[Vec<u32>],
        options: Options,
    ) -> Result<Level, GeometryError> {
        let points = &self.points;
        let slices: Vec<&[u32]> = cut.iter().map(Vec::as_slice).collect();
        let mut region = Level::new(points.len(), &slices, Vec::new())?;
        for (e, &[a, b]) in region.edges.iter().enumerate() {
            let (a, b) = (points[a as usize], points[b as usize]);
            let whole = level
                .edge_between(a, b)
                .map_or(0.0, |g| level.edge_sharpness[g]);
            region.edge_sharpness[e] = whole;
        }
        for e in 0..region.edges.len() {
            if region.is_boundary_edge(e as u32) {
                region.edge_sharpness[e] = INFINITE_SHARPNESS;
            }
        }
        for (v, &whole) in points.iter().enumerate() {
            region.vertex_sharpness[v] = level.vertex_sharpness[whole as usize];
            if options.boundary == Boundary::EdgeAndCorner
                && region.vertex_faces(v as u32).len() == 1
            {
                region.vertex_sharpness[v] = INFINITE_SHARPNESS;
            }
        }
        Ok(region)
    }

    /// The region's numbers of the level's faces `faces` (increasing, all in the region).
    pub fn region_faces(&self, faces: &[u32]) -> Vec<u32> {
        let mut out = Vec::with_capacity(faces.len());
        let mut k = 0;
        for &f in faces {
            while self.faces[k] != f {
                k += 1;
            }
            out.push(k as u32);
        }
        out
    }

    /// Appends `local`, stencil patches over the refinement of the region's topology
    /// `region`, to `feed` by the level `whole`'s numbers: cage points, cage faces, and level-1
    /// pieces (a face's children are numbered face by face in both). Slots name no level
    /// vertex (`u32::MAX`).
    pub fn append(
        &self,
        feed: &mut LimitFeed,
        local: &LimitFeed,
        (whole, region): (&Level, &Level),
        options: Options,
    ) {
        let children = (
            first_children(whole, options.scheme),
            first_children(region, options.scheme),
        );
        let first_entry = feed.entries.len() as u32;
        self.append_patches(feed, local, (&children.0, &children.1), (first_entry, NONE));
        feed.entries.extend(
            local
                .entries
                .iter()
                .map(|&(p, w)| (self.points[p as usize], w)),
        );
    }

    /// [`Self::append`] but for the entries, with each face's first child one level down
    /// already found in the whole level and in the region ([`first_children`]): the slots
    /// read their entries from `first_entry` on, where the caller puts them, and their
    /// points through `points` ([`StencilPatch::points`](super::pieces::StencilPatch::points):
    /// [`NONE`] where the caller writes the entries over the level's points).
    pub fn append_patches(
        &self,
        feed: &mut LimitFeed,
        local: &LimitFeed,
        (whole_children, region_children): (&[u32], &[u32]),
        (first_entry, points): (u32, u32),
    ) {
        let slot_offset = feed.slots.len() as u32;
        for patch in &local.patches {
            let mut patch = *patch;
            let region_face = patch.cage_face as usize;
            patch.cage_face = self.faces[region_face];
            patch.first_slot += slot_offset;
            patch.points = points;
            patch.piece[1] = match patch.piece[0] {
                0 => self.faces[patch.piece[1] as usize],
                1 => {
                    whole_children[patch.cage_face as usize]
                        + (patch.piece[1] - region_children[region_face])
                }
                _ => NONE,
            };
            feed.patches.push(patch);
        }
        feed.push_slots(&local.slots, &local.no_curvature, first_entry);
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::mesh::PolygonMesh;
    use crate::subdiv::Hierarchy;
    use crate::subdiv::cage_edit::{Cage, Tool};
    use crate::subdiv::patches::is_regular_face;
    use crate::subdiv::patches::tests::slot_values;
    use crate::subdiv::patches::{exact_pieces, push_region_stencil_patches, push_stencil_patches};
    use crate::subdiv::pieces::{Display, ShownPiece, StencilPatch};
    use crate::subdiv::{Corner, Crease, Creasing, Scheme, SubdivisionSurface, cages};
    use crate::test_support::{Xorshift, placement};
    use glam::DVec3;

    /// A tool that grows a cage at `face`: a poke (`which` 0), an inset (1) or an extrusion.
    pub(in crate::subdiv) fn growing_tool(face: usize, which: u64) -> Tool {
        match which {
            0 => Tool::Poke { faces: vec![face] },
            1 => Tool::Inset {
                faces: vec![face],
                thickness: 0.05,
                depth: 0.0,
                individual: false,
            },
            _ => Tool::Extrude {
                faces: vec![face],
                offset: 0.2,
                individual: false,
            },
        }
    }

    /// A torus or an open grid grown by random tools (pokes, insets, extrusions: triangles,
    /// extraordinary points, n-gons), with a random semi-sharp crease along an edge loop and a
    /// random corner, its points jittered, under a random rotation, scale and shift, with
    /// random boundary and crease rules.
    pub(in crate::subdiv) fn random_cage(draw: &mut Xorshift) -> SubdivisionSurface {
        let mesh = if draw.below(2) == 0 {
            cages::torus(DVec3::ZERO, 3.0, 1.0, 16, 12).unwrap()
        } else {
            cages::grid(DVec3::ZERO, 4.0, 14).unwrap()
        };
        let mut cage = Cage {
            points: mesh.points().to_vec(),
            faces: mesh.faces().map(<[u32]>::to_vec).collect(),
            creases: Vec::new(),
            corners: Vec::new(),
        };
        for _ in 0..1 + draw.below(3) {
            let face = draw.below(cage.faces.len() as u64) as usize;
            cage = cage.apply(&growing_tool(face, draw.below(3))).unwrap();
        }
        // A crease along (part of) a loop of edges, and a corner.
        let a = cage.faces[draw.below(cage.faces.len() as u64) as usize].clone();
        if let Ok(chain) = cage.edge_loop(a[0], a[1]) {
            let sharpness = 0.5 + 3.0 * draw.unit();
            let take = 1 + draw.below(chain.len() as u64) as usize;
            cage.creases = chain[..take]
                .iter()
                .map(|&(a, b)| Crease { a, b, sharpness })
                .collect();
        }
        let v = draw.below(cage.points.len() as u64) as u32;
        cage.corners = vec![Corner {
            vertex: v,
            sharpness: 4.0 * draw.unit(),
        }];
        let (motion, _) = placement(draw.bits());
        let points: Vec<DVec3> = cage
            .points
            .iter()
            .map(|&p| {
                let jitter = DVec3::new(draw.unit(), draw.unit(), draw.unit()) * 0.1 - 0.05;
                motion.transform_point3(p + jitter)
            })
            .collect();
        let options = Options {
            scheme: Scheme::CatmullClark,
            boundary: if draw.below(2) == 0 {
                Boundary::EdgeOnly
            } else {
                Boundary::EdgeAndCorner
            },
            creasing: if draw.below(2) == 0 {
                Creasing::Uniform
            } else {
                Creasing::Chaikin
            },
        };
        let mesh = PolygonMesh::new(points, &cage.faces).unwrap();
        SubdivisionSurface::new(mesh, cage.creases, cage.corners, options, 3).unwrap()
    }

    /// The faces that are not regular B-spline quads: the ones the feed shows as stencils.
    pub(in crate::subdiv) fn irregular_faces(base: &Level) -> Vec<u32> {
        (0..base.face_count() as u32)
            .filter(|&f| !is_regular_face(base, Scheme::CatmullClark, f))
            .collect()
    }

    /// The largest difference, over the cage's size, between any slot's position, first or
    /// second derivative from the region's refinement (`rings` rings) and from the whole
    /// cage's, at `levels`; infinite where the patches or the slots' kinds differ.
    fn region_error(surface: &SubdivisionSurface, faces: &[u32], levels: u32, rings: u32) -> f64 {
        let base = surface.base_level().unwrap();
        let mut region = LimitFeed::default();
        let cut = push_region_stencil_patches(
            &mut region,
            &base,
            surface.options,
            faces,
            face_region(&base, faces, rings),
            levels,
            Display::Limit,
            1.0,
        )
        .unwrap();
        assert!(cut, "{} of {} faces", faces.len(), base.face_count());
        error_against_whole(surface, faces, levels, &region, false)
    }

    /// The largest difference, over the cage's size, between any slot's position, first or
    /// second derivative in `feed` (stencil patches of cage faces `faces` at `levels`) and
    /// from the whole cage's refinement; infinite where the patches or the slots' kinds differ.
    /// With `plane_at_irregular`, a slot whose curvature is undefined (an extraordinary or
    /// sharp point, whose two tangents are any two spanning its tangent plane, found from
    /// where its ring starts) compares its position and unit normal only.
    pub(in crate::subdiv) fn error_against_whole(
        surface: &SubdivisionSurface,
        faces: &[u32],
        levels: u32,
        region: &LimitFeed,
        plane_at_irregular: bool,
    ) -> f64 {
        let base = surface.base_level().unwrap();
        let hierarchy = Hierarchy::new(base, surface.options, levels).unwrap();
        let pieces = exact_pieces(&hierarchy, faces, levels);
        let shown: Vec<ShownPiece> = pieces.into_iter().map(ShownPiece::uniform).collect();
        let mut whole = LimitFeed::default();
        push_stencil_patches(&mut whole, &hierarchy, levels, &shown, Display::Limit);
        let over_cage = |feed: &LimitFeed| -> Vec<StencilPatch> {
            let patches = feed.patches.iter();
            patches
                .map(|&p| StencilPatch { points: NONE, ..p })
                .collect()
        };
        if over_cage(region) != whole.patches || region.no_curvature != whole.no_curvature {
            return f64::INFINITY;
        }
        let points = surface.points();
        let (lo, hi) = surface.mesh().bounds().unwrap();
        let size = (hi - lo).length();
        let values = |feed: &LimitFeed, slot: usize| slot_values(feed, points, slot);
        let mut worst = 0.0f64;
        for slot in 0..whole.slots.len() {
            let (a, b) = (values(region, slot), values(&whole, slot));
            if plane_at_irregular && whole.no_curvature[slot] {
                let normal = |v: [DVec3; 6]| v[1].cross(v[2]).normalize_or_zero();
                worst = worst.max((a[0] - b[0]).length() / size);
                worst = worst.max((normal(a) - normal(b)).length());
                continue;
            }
            for c in 0..6 {
                // Second derivatives grow by 4 per level: compare at the level's scale.
                let scale = if c < 3 {
                    1.0
                } else {
                    0.25f64.powi(levels as i32)
                };
                worst = worst.max((a[c] - b[c]).length() * scale / size);
            }
        }
        worst
    }

    /// Refining only the faces within [`REGION_RINGS`] rings gives the whole cage's stencils
    /// (positions, first and second derivatives) on random cages: pokes, insets, extrusions,
    /// semi-sharp creases (uniform and Chaikin), corners, boundaries of both rules. One ring
    /// is too few: the rim's boundary rules reach the slots.
    #[test]
    fn a_region_refined_alone_gives_the_whole_cages_stencils() {
        let mut draw = Xorshift::new(0x5eed_0f2e_610a);
        let mut too_few = 0;
        for round in 0..12 {
            let surface = random_cage(&mut draw);
            let base = surface.base_level().unwrap();
            // Every irregular face (as the feed asks), and a random few of them alone.
            let all = irregular_faces(&base);
            let few: Vec<u32> = all.iter().copied().filter(|_| draw.below(4) == 0).collect();
            for faces in [&all, &few] {
                for levels in 1..=3 {
                    let error = region_error(&surface, faces, levels, REGION_RINGS);
                    assert!(error < 1e-12, "round {round} level {levels}: {error:e}");
                }
            }
            if region_error(&surface, &few, 2, 1) > 1e-6 {
                too_few += 1;
            }
        }
        assert!(too_few > 0, "one ring matched on every cage");
    }

    /// The region of one face of a 16 × 12 torus: itself, its 8 neighbours, then 24 and 48
    /// faces more (squares of 3, 5, 7 faces a side).
    #[test]
    fn the_region_of_a_face_grows_by_rings() {
        let torus = cages::torus(DVec3::ZERO, 3.0, 1.0, 16, 12).unwrap();
        let surface = SubdivisionSurface::from_mesh(torus, 1).unwrap();
        let base = surface.base_level().unwrap();
        for (rings, count) in [(0, 1), (1, 9), (2, 25), (3, 49)] {
            assert_eq!(face_region(&base, &[40], rings).len(), count);
        }
    }
}
