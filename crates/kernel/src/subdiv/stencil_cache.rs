//! Limit stencils kept from one cage to the next, so that after a topology edit only the faces
//! whose neighbourhoods changed are refined again.
//!
//! A face's limit stencils depend only on the topology and sharpness within
//! [`REGION_RINGS`](super::region::REGION_RINGS) rings of it, never on where the points are
//! ([`super::templates`]). A cage tool changes a few faces and leaves every other
//! neighbourhood as it was, though it may renumber the faces (a deleted face moves the ones
//! after it). So each irregular face's stencil patches are kept over its neighbourhood's own
//! point numbers, keyed by the neighbourhood as its topology reads it (its
//! [`Neighbourhood::key`] and the corner it is read from), and the feed of the next cage takes
//! the patches of every face whose neighbourhood reads the same from there, reading their
//! entries through the face's own points. Faces whose neighbourhoods read alike share one kept
//! value and one run of entries in the feed.

use std::sync::Arc;

use rustc_hash::FxHashMap;

use super::Options;
use super::level::{Level, NONE};
use super::pieces::{Display, Entry, LimitFeed, StencilPatch, first_children};
use super::templates::Neighbourhood;

/// One face's stencil patches over its neighbourhood's point numbers.
#[derive(Debug, Default, PartialEq)]
pub(super) struct FaceStencils {
    /// Its patches from slot 0 of `slots`, `cage_face` 0, `points` [`NONE`]; `piece` is
    /// `[0, 0]` for the face itself, `[1, k]` for its child k one level down.
    patches: Vec<StencilPatch>,
    /// Per slot, its first entry in `entries` and their count.
    slots: Vec<[u32; 2]>,
    no_curvature: Vec<bool>,
    /// Entries whose points are the neighbourhood's numbers ([`Neighbourhood::points`]).
    entries: Vec<Entry>,
}

/// The limit stencils of a cage's irregular faces kept for the next cage: what the feed was
/// built for (rules, level, display) and each face's patches by its neighbourhood's reading.
pub struct StencilCache {
    stamp: (Options, u32, Display),
    /// The faces of the feed it was kept after that were refined, and that took their
    /// stencils from the cache before it.
    refined: usize,
    taken: usize,
    /// Per neighbourhood key, the stencils of the faces read from each corner.
    faces: FxHashMap<Vec<u64>, Vec<(u32, Arc<FaceStencils>)>>,
}

impl std::fmt::Debug for StencilCache {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("StencilCache")
            .field("stamp", &self.stamp)
            .field("neighbourhoods", &self.len())
            .field("refined", &self.refined)
            .field("taken", &self.taken)
            .finish()
    }
}

/// A face of the new cage whose neighbourhood was read.
pub(super) struct ReadFace {
    pub face: u32,
    pub neighbourhood: Neighbourhood,
}

impl StencilCache {
    /// An empty cache for feeds of `options` at level `levels` showing `display`.
    pub(super) fn new(options: Options, levels: u32, display: Display) -> Self {
        Self {
            stamp: (options, levels, display),
            refined: 0,
            taken: 0,
            faces: FxHashMap::default(),
        }
    }

    /// The irregular faces of the feed it was kept after: how many were refined, and how
    /// many took their stencils from the cache before.
    pub fn faces_refined_and_taken(&self) -> (usize, usize) {
        (self.refined, self.taken)
    }

    /// How many neighbourhood readings it keeps stencils for.
    pub fn len(&self) -> usize {
        self.faces.values().map(Vec::len).sum()
    }

    /// Whether it keeps none.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Whether it was kept for feeds of `options` at `levels` showing `display`.
    pub(super) fn serves(&self, options: Options, levels: u32, display: Display) -> bool {
        self.stamp == (options, levels, display)
    }

    fn find(&self, neighbourhood: &Neighbourhood) -> Option<&Arc<FaceStencils>> {
        let readings = self.faces.get(neighbourhood.key())?;
        let turn = neighbourhood.turn();
        readings.iter().find(|(t, _)| *t == turn).map(|(_, s)| s)
    }

    fn keep(&mut self, neighbourhood: &Neighbourhood, stencils: Arc<FaceStencils>) {
        let readings = self.faces.entry(neighbourhood.key().to_vec()).or_default();
        if !readings.iter().any(|(t, _)| *t == neighbourhood.turn()) {
            readings.push((neighbourhood.turn(), stencils));
        }
    }

    /// Splits `faces` into those whose stencils this cache keeps (with them) and the rest.
    pub(super) fn split(
        &self,
        faces: Vec<ReadFace>,
    ) -> (Vec<(ReadFace, Arc<FaceStencils>)>, Vec<ReadFace>) {
        let mut kept = Vec::new();
        let mut rest = Vec::new();
        for face in faces {
            match self.find(&face.neighbourhood) {
                Some(stencils) => kept.push((face, Arc::clone(stencils))),
                None => rest.push(face),
            }
        }
        (kept, rest)
    }

    /// The cache after `feed`: `made`'s stencils read out of its patches (their entries
    /// renumbered over each face's neighbourhood; a face with an entry outside it is not
    /// kept), then `kept`'s appended to `feed` (each value's entries once, each face its
    /// patches and its point list) and kept again. `whole` is the cage the feed shows.
    pub(super) fn after(
        mut self,
        feed: &mut LimitFeed,
        whole: &Level,
        made: &[ReadFace],
        kept: Vec<(ReadFace, Arc<FaceStencils>)>,
    ) -> Self {
        let children = first_children(whole, self.stamp.0.scheme);
        let mut patches_of: FxHashMap<u32, Vec<usize>> = FxHashMap::default();
        for (k, patch) in feed.patches.iter().enumerate() {
            patches_of.entry(patch.cage_face).or_default().push(k);
        }
        self.refined = patches_of.len();
        self.taken = kept.len();
        for face in made {
            if self.find(&face.neighbourhood).is_some() {
                continue;
            }
            let Some(patches) = patches_of.get(&face.face) else {
                continue;
            };
            let first_child = children.get(face.face as usize).copied().unwrap_or(NONE);
            if let Some(stencils) = read_out(
                feed,
                patches,
                face.neighbourhood.points(),
                (face.face, first_child),
            ) {
                self.keep(&face.neighbourhood, Arc::new(stencils));
            }
        }
        let mut placed: FxHashMap<*const FaceStencils, u32> = FxHashMap::default();
        for (face, stencils) in kept {
            let first_entry = *placed.entry(Arc::as_ptr(&stencils)).or_insert_with(|| {
                let first = feed.entries.len() as u32;
                feed.entries.extend_from_slice(&stencils.entries);
                first
            });
            let points = feed.point_lists.len() as u32;
            feed.point_lists
                .extend_from_slice(face.neighbourhood.points());
            let first_slot = feed.slots.len() as u32;
            let first_child = children.get(face.face as usize).copied().unwrap_or(NONE);
            feed.patches
                .extend(stencils.patches.iter().map(|p| StencilPatch {
                    cage_face: face.face,
                    first_slot: p.first_slot + first_slot,
                    piece: match p.piece[0] {
                        0 => [0, face.face],
                        1 => [1, first_child + p.piece[1]],
                        _ => p.piece,
                    },
                    points,
                    ..*p
                }));
            feed.push_slots(&stencils.slots, &stencils.no_curvature, first_entry);
            self.keep(&face.neighbourhood, stencils);
        }
        in_face_order(feed);
        self
    }
}

/// Puts `feed`'s stencil patches in the order of their cage faces (each face's in the order
/// they came), their slots with them, as a feed built afresh lists them.
fn in_face_order(feed: &mut LimitFeed) {
    if feed.patches.is_sorted_by_key(|p| p.cage_face) {
        return;
    }
    let mut order: Vec<usize> = (0..feed.patches.len()).collect();
    order.sort_by_key(|&k| feed.patches[k].cage_face);
    let mut slots = Vec::with_capacity(feed.slots.len());
    let mut no_curvature = Vec::with_capacity(feed.no_curvature.len());
    let mut vertex = Vec::with_capacity(feed.vertex.len());
    let patches = order
        .into_iter()
        .map(|k| {
            let patch = feed.patches[k];
            let first = patch.first_slot as usize;
            let run = first..first + (patch.segments as usize + 1).pow(2);
            let first_slot = slots.len() as u32;
            slots.extend_from_slice(&feed.slots[run.clone()]);
            no_curvature.extend_from_slice(&feed.no_curvature[run.clone()]);
            vertex.extend_from_slice(&feed.vertex[run]);
            StencilPatch {
                first_slot,
                ..patch
            }
        })
        .collect();
    feed.patches = patches;
    feed.slots = slots;
    feed.no_curvature = no_curvature;
    feed.vertex = vertex;
}

/// The stencil patches `patches` of `feed` (those of cage face `face`, whose first child one
/// level down is `first_child`) over `points`' numbers; `None` where an entry's point is not
/// among them or a patch shows no piece of the face.
fn read_out(
    feed: &LimitFeed,
    patches: &[usize],
    points: &[u32],
    (face, first_child): (u32, u32),
) -> Option<FaceStencils> {
    let local: FxHashMap<u32, u32> = points
        .iter()
        .enumerate()
        .map(|(k, &v)| (v, k as u32))
        .collect();
    let mut out = FaceStencils::default();
    // Slots that read the same run of entries (a triangle's unused slots alias its first)
    // keep reading one run.
    let mut runs: FxHashMap<([u32; 2], u32), [u32; 2]> = FxHashMap::default();
    for &k in patches {
        let patch = feed.patches[k];
        let count = (patch.segments as usize + 1).pow(2);
        let first_slot = out.slots.len() as u32;
        for slot in patch.first_slot as usize..patch.first_slot as usize + count {
            let range = *feed.slots.get(slot)?;
            let run = match runs.get(&(range, patch.points)) {
                Some(&run) => run,
                None => {
                    let begin = out.entries.len() as u32;
                    for (point, weights) in feed.slot_entries(&patch, slot)? {
                        out.entries.push((*local.get(&point)?, weights));
                    }
                    let run = [begin, out.entries.len() as u32 - begin];
                    runs.insert((range, patch.points), run);
                    run
                }
            };
            out.slots.push(run);
            out.no_curvature.push(*feed.no_curvature.get(slot)?);
        }
        let piece = match patch.piece[0] {
            0 if patch.piece[1] == face => [0, 0],
            1 if patch.piece[1] >= first_child => [1, patch.piece[1] - first_child],
            NONE => patch.piece,
            _ => return None,
        };
        out.patches.push(StencilPatch {
            cage_face: 0,
            first_slot,
            piece,
            points: NONE,
            ..patch
        });
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::PolygonMesh;
    use crate::subdiv::cage_edit::{Cage, Tool};
    use crate::subdiv::patches::tests::slot_values;
    use crate::subdiv::region::tests::{growing_tool, random_cage};
    use crate::subdiv::{Crease, Scheme, SubdivisionSurface};
    use crate::test_support::Xorshift;
    use glam::DVec3;

    /// Each stencil patch of `feed` by (cage face, piece), with its kind and its slots'
    /// values (position, first and second derivatives) and curvature flags.
    type Shown = Vec<((u32, [u32; 2]), (bool, u32, u32), Vec<([DVec3; 6], bool)>)>;

    fn shown(feed: &LimitFeed, points: &[DVec3]) -> Shown {
        let mut out: Shown = feed
            .patches
            .iter()
            .map(|p| {
                let count = (p.segments as usize + 1).pow(2);
                let slots = (p.first_slot as usize..p.first_slot as usize + count)
                    .map(|s| (slot_values(feed, points, s), feed.no_curvature[s]))
                    .collect();
                (
                    (p.cage_face, p.piece),
                    (p.triangle, p.segments, p.level),
                    slots,
                )
            })
            .collect();
        out.sort_by_key(|(key, _, _)| *key);
        out
    }

    /// The largest difference between two feeds' stencil patches over the cage's size
    /// (second derivatives at the level's scale); at a slot of undefined curvature, whose
    /// two tangents are any pair spanning the tangent plane, the position and unit normal.
    /// Infinite where the patches differ in kind.
    fn difference(surface: &SubdivisionSurface, a: &LimitFeed, b: &LimitFeed) -> f64 {
        let (lo, hi) = surface.mesh().bounds().unwrap();
        let size = (hi - lo).length();
        let levels = surface.level() as i32;
        let (a, b) = (shown(a, surface.points()), shown(b, surface.points()));
        if a.len() != b.len() {
            return f64::INFINITY;
        }
        let mut worst = 0.0f64;
        for (pa, pb) in a.iter().zip(&b) {
            if (pa.0, pa.1) != (pb.0, pb.1) {
                return f64::INFINITY;
            }
            for (&(va, fa), &(vb, fb)) in pa.2.iter().zip(&pb.2) {
                if fa != fb {
                    return f64::INFINITY;
                }
                if fa {
                    let normal = |v: [DVec3; 6]| v[1].cross(v[2]).normalize_or_zero();
                    worst = worst.max((va[0] - vb[0]).length() / size);
                    worst = worst.max((normal(va) - normal(vb)).length());
                    continue;
                }
                for c in 0..6 {
                    let scale = if c < 3 { 1.0 } else { 0.25f64.powi(levels) };
                    worst = worst.max((va[c] - vb[c]).length() * scale / size);
                }
            }
        }
        worst
    }

    /// One random tool on `cage` (a random face or edge of it), or a crease set on a random
    /// edge; `None` where the tool refuses.
    fn random_edit(cage: &Cage, draw: &mut Xorshift, triangles: bool) -> Option<Cage> {
        let face = draw.below(cage.faces.len() as u64) as usize;
        let corners = &cage.faces[face];
        let edge = [corners[0], corners[1]];
        let tool = match draw.below(7) {
            which @ 0..3 => growing_tool(face, which),
            3 => Tool::Delete { faces: vec![face] },
            4 => Tool::Subdivide {
                faces: vec![face],
                cuts: 1,
            },
            5 => Tool::Dissolve { edges: vec![edge] },
            _ => {
                let mut creased = cage.clone();
                creased
                    .creases
                    .retain(|c| [c.a, c.b] != edge && [c.b, c.a] != edge);
                creased.creases.push(Crease {
                    a: edge[0],
                    b: edge[1],
                    sharpness: 0.5 + 3.0 * draw.unit(),
                });
                return Some(creased);
            }
        };
        let edited = cage.apply(&tool).ok()?;
        if !triangles {
            return Some(edited);
        }
        let all = (0..edited.faces.len()).collect();
        edited.apply(&Tool::Triangulate { faces: all }).ok()
    }

    /// A feed that takes the stencils of faces whose neighbourhoods a tool left alone from the
    /// last cage's cache shows what a feed built afresh shows (positions, first and second
    /// derivatives within 1e-9 of the cage's size; at points of undefined curvature the
    /// position and the normal), on random cages (creases, corners, boundaries, both
    /// boundary and crease rules, in general position) edited by random sequences of pokes,
    /// insets, extrusions, deletions, subdivisions, dissolves and creases, under
    /// Catmull-Clark and Loop, showing the limit and the refined mesh, at levels 1 to 3.
    /// Its patches come in the fresh feed's order. Over the steps after the first, more than
    /// twice as many patches are taken as made, and a cage fed its own cache refines none.
    #[test]
    fn a_feed_reusing_the_last_cages_stencils_shows_what_a_fresh_one_shows() {
        let mut draw = Xorshift::new(0x57e0_c11c_ac4e);
        let (mut reused, mut made) = (0usize, 0usize);
        for round in 0..8 {
            let start = random_cage(&mut draw);
            let triangles = round % 4 == 3;
            let mut cage = Cage::of_surface(&start);
            let mut options = start.options;
            if triangles {
                let all = (0..cage.faces.len()).collect();
                cage = cage.apply(&Tool::Triangulate { faces: all }).unwrap();
                options.scheme = Scheme::Loop;
            }
            let levels = 1 + draw.below(3) as u32;
            let display = if round % 2 == 0 {
                Display::Limit
            } else {
                Display::Refined
            };
            let mut cache: Option<StencilCache> = None;
            for step in 0..5 {
                if step > 0 {
                    match random_edit(&cage, &mut draw, triangles) {
                        Some(edited) => cage = edited,
                        None => continue,
                    }
                }
                let mesh = PolygonMesh::new(cage.points.clone(), &cage.faces).unwrap();
                let surface = SubdivisionSurface::new(
                    mesh,
                    cage.creases.clone(),
                    cage.corners.clone(),
                    options,
                    levels,
                )
                .unwrap();
                let fresh = surface.limit_feed(levels, display).unwrap();
                let (feed, kept) = surface
                    .limit_feed_reusing(levels, display, cache.as_ref())
                    .unwrap();
                let error = difference(&surface, &fresh, &feed);
                let listed = |f: &LimitFeed| -> Vec<_> {
                    let patches = f.patches.iter();
                    patches
                        .map(|p| (p.cage_face, p.piece, p.segments))
                        .collect()
                };
                assert_eq!(listed(&feed), listed(&fresh), "round {round} step {step}");
                assert!(
                    error < 1e-9,
                    "round {round} step {step}: {error:.3e} ({display:?}, level {levels})"
                );
                let kept = kept.unwrap();
                // Fed its own cache, the same cage refines nothing and shows the same.
                let (again, _) = surface
                    .limit_feed_reusing(levels, display, Some(&kept))
                    .unwrap();
                assert_eq!(again.patches.len(), feed.patches.len());
                let from_cache = again.patches.iter().filter(|p| p.points != NONE).count();
                assert_eq!(from_cache, again.patches.len(), "round {round} step {step}");
                assert!(difference(&surface, &fresh, &again) < 1e-9);
                if step > 0 {
                    // Some of the faces shown as stencils came from the cache, not all.
                    let from_cache = feed.patches.iter().filter(|p| p.points != NONE).count();
                    reused += from_cache;
                    made += feed.patches.len() - from_cache;
                }
                cache = Some(kept);
            }
        }
        assert!(
            reused > 2 * made,
            "{reused} patches taken from the cache, {made} made"
        );
    }

    /// A cache kept for other rules, another level or another display is not read.
    #[test]
    fn a_cache_of_other_rules_level_or_display_is_not_read() {
        let mut draw = Xorshift::new(0x0dd5_eed5);
        let surface = random_cage(&mut draw);
        let (_, kept) = surface.limit_feed_reusing(2, Display::Limit, None).unwrap();
        let kept = kept.unwrap();
        assert!(!kept.is_empty());
        for (levels, display) in [(3, Display::Limit), (2, Display::Refined)] {
            let (feed, _) = surface
                .limit_feed_reusing(levels, display, Some(&kept))
                .unwrap();
            let fresh = surface.limit_feed(levels, display).unwrap();
            assert_eq!(feed, fresh);
        }
    }
}
