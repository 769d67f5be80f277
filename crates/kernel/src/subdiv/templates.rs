//! Stencil templates: faces whose neighbourhoods are alike share one refinement.
//!
//! A face's limit stencils depend only on the topology and sharpness of the faces within
//! [`REGION_RINGS`] rings of it ([`super::region`]), never on where the points are. A cage
//! that repeats a pattern (a triangulated torus, a regular mesh split into triangles, the
//! same extraordinary point many times over) has many faces whose neighbourhoods are the same
//! up to the numbering of their points. Each face's neighbourhood is written out in an order
//! that depends only on its topology seen from the face: its faces in the order a walk across
//! edges from the face meets them (each read from the edge the walk entered it by, the face
//! itself from its least corner where the limit is shown, [`turned_feed`]), its points
//! numbered as those faces first meet them, with every edge's and point's sharpness. Faces whose neighbourhoods read the same are refined
//! once, through one of them, and the others take its stencils over their own points. At an
//! extraordinary or sharp point the two tangents are any pair spanning the tangent plane,
//! chosen by where the point's ring starts, so they may differ from the whole cage's there;
//! the position and the normal do not.

use rustc_hash::FxHashMap;

use super::Options;
use super::level::{Level, NONE};
use super::pieces::{LimitFeed, StencilPatch, first_children};
use super::region::{RegionCage, face_region};
use crate::GeometryError;

/// Fewer faces than this are not worth naming their neighbourhoods for.
pub const FEWEST_FACES: usize = 16;

/// One face's neighbourhood in the order its topology gives ([`neighbourhood`]).
pub(super) struct Neighbourhood {
    /// Its faces (the face first) and points in that order.
    cut: RegionCage,
    /// The face's corner the walk starts from: the face reads as its corners from this one
    /// on (the face's own first corner where [`Templates::new`] is not asked to turn faces).
    turn: u32,
    /// The faces' corner counts and points, then every face edge's sharpness and every
    /// point's: equal keys give equal refinements.
    key: Vec<u64>,
}

impl Neighbourhood {
    /// The neighbourhood of `face` of `level` within `rings` rings, read from its
    /// [`least_corner`] with `turn`, else from its first corner; `None` where it cannot be
    /// walked across its edges.
    pub fn read(level: &Level, face: u32, rings: u32, turn: bool) -> Option<Self> {
        let corner = if turn { least_corner(level, face) } else { 0 };
        neighbourhood(level, face, rings, corner)
    }

    /// Its faces' corner counts and points and its sharpness, in the order its topology
    /// gives: faces with equal keys and equal [`Self::turn`]s have the same stencils over
    /// their [`Self::points`].
    pub fn key(&self) -> &[u64] {
        &self.key
    }

    /// The face's corner the reading starts from.
    pub fn turn(&self) -> u32 {
        self.turn
    }

    /// Its cage points, numbered as the key numbers them.
    pub fn points(&self) -> &[u32] {
        &self.cut.points
    }

    /// Its faces over its own point numbers, as its key lists them.
    fn local_faces(&self) -> Vec<Vec<u32>> {
        let mut faces = Vec::with_capacity(self.cut.faces.len());
        let mut at = 1;
        for _ in 0..self.cut.faces.len() {
            let n = self.key[at] as usize;
            faces.push(
                self.key[at + 1..at + 1 + n]
                    .iter()
                    .map(|&v| v as u32)
                    .collect(),
            );
            at += 1 + n;
        }
        faces
    }
}

/// The corner of `face` of `level` from which its corners' (valence, point sharpness, next
/// edge's sharpness) read least, the first such corner where several do: faces that differ
/// only by where their corner numbering starts then read alike.
fn least_corner(level: &Level, face: u32) -> u32 {
    let corners = level.face(face);
    let edges = level.face_edges(face);
    let mark = |c: usize| {
        let v = corners[c];
        (
            level.vertex_edges(v).len(),
            level.vertex_sharpness[v as usize].to_bits(),
            level.edge_sharpness[edges[c] as usize].to_bits(),
        )
    };
    let n = corners.len();
    let reading = |r: usize| (0..n).map(move |k| mark((r + k) % n));
    (1..n).fold(0, |best, r| {
        if reading(r).lt(reading(best)) {
            r
        } else {
            best
        }
    }) as u32
}

/// `items` (a face's corners or edges) from place `start` on, round to the start.
fn from(items: &[u32], start: usize) -> impl Iterator<Item = u32> + '_ {
    let (head, tail) = items.split_at(start.min(items.len()));
    tail.iter().chain(head).copied()
}

/// The faces within `rings` rings of `face` of `level` ([`face_region`]): `face`, then the
/// others as a breadth-first walk across edges meets them, their points numbered as the faces
/// in that order first use them. Each face is read from a corner its place in the walk gives,
/// not from its own first corner: `face` from corner `turn`, every other face from the edge
/// the walk entered it by (its corners from that edge's first, its edges from that edge on).
/// `None` where the walk does not reach every face of the region.
fn neighbourhood(level: &Level, face: u32, rings: u32, turn: u32) -> Option<Neighbourhood> {
    let region = face_region(level, &[face], rings);
    let place = |g: u32| region.binary_search(&g).ok();
    let mut met = vec![false; region.len()];
    met[place(face)?] = true;
    // The faces in walk order, each with the corner it is read from.
    let mut order: Vec<(u32, usize)> = Vec::with_capacity(region.len());
    order.push((face, turn as usize));
    let mut next = 0;
    while next < order.len() {
        let (g, start) = order[next];
        next += 1;
        let edges = level.face_edges(g);
        for k in 0..edges.len() {
            let e = edges[(start + k) % edges.len()];
            let [a, b] = level.edge_faces[e as usize];
            let h = if a == g { b } else { a };
            if h == NONE {
                continue;
            }
            if let Some(p) = place(h)
                && !std::mem::replace(&mut met[p], true)
            {
                let entered = level.face_edges(h).iter().position(|&x| x == e)?;
                order.push((h, entered));
            }
        }
    }
    if order.len() != region.len() {
        return None;
    }
    let mut numbers: FxHashMap<u32, u32> = FxHashMap::default();
    numbers.reserve(2 * region.len());
    let mut points = Vec::new();
    let mut key = vec![order.len() as u64];
    for &(g, start) in &order {
        let corners = level.face(g);
        key.push(corners.len() as u64);
        for v in from(corners, start) {
            let local = *numbers.entry(v).or_insert_with(|| {
                points.push(v);
                points.len() as u32 - 1
            });
            key.push(u64::from(local));
        }
    }
    for &(g, start) in &order {
        key.extend(
            from(level.face_edges(g), start).map(|e| level.edge_sharpness[e as usize].to_bits()),
        );
    }
    key.extend(
        points
            .iter()
            .map(|&v| level.vertex_sharpness[v as usize].to_bits()),
    );
    Some(Neighbourhood {
        cut: RegionCage {
            faces: order.into_iter().map(|(g, _)| g).collect(),
            points,
        },
        turn,
        key,
    })
}

/// Faces of a level grouped by their neighbourhoods ([`neighbourhood`]).
pub(super) struct Templates {
    faces: Vec<Neighbourhood>,
    /// Per face, its group.
    group: Vec<u32>,
    /// Per group, the face refined for it (the group's first).
    first: Vec<usize>,
}

impl Templates {
    /// `faces` of `level` grouped by their neighbourhoods within `rings` rings; `None` where
    /// one's cannot be walked across its edges. With `turn`, each face is read from its
    /// [`least_corner`], so that faces alike but for where their numbering starts share
    /// (the limit patches of Catmull-Clark and Loop only: [`turned_feed`] turns the
    /// refinement back).
    pub fn new(level: &Level, faces: &[u32], rings: u32, turn: bool) -> Option<Self> {
        let found = crate::par::map(faces.len(), |k| {
            Neighbourhood::read(level, faces[k], rings, turn)
        });
        Some(Self::of(found.into_iter().collect::<Option<_>>()?))
    }

    /// Faces grouped by their neighbourhoods `faces` (read by [`Neighbourhood::read`]).
    pub fn of(faces: Vec<Neighbourhood>) -> Self {
        let mut groups: FxHashMap<&[u64], u32> = FxHashMap::default();
        let mut first = Vec::new();
        let mut group = Vec::with_capacity(faces.len());
        for (k, face) in faces.iter().enumerate() {
            let g = *groups.entry(&face.key).or_insert_with(|| {
                first.push(k);
                first.len() as u32 - 1
            });
            group.push(g);
        }
        Self {
            faces,
            group,
            first,
        }
    }

    /// The faces' neighbourhoods, in the faces' order.
    pub fn into_neighbourhoods(self) -> Vec<Neighbourhood> {
        self.faces
    }

    /// How many faces of `corners` corners are read from another corner than their first.
    #[cfg(test)]
    pub fn turned_faces(&self, corners: usize) -> usize {
        let faces = self
            .faces
            .iter()
            .filter(|f| f.local_faces()[0].len() == corners);
        faces.filter(|f| f.turn != 0).count()
    }

    /// How many groups the faces form.
    #[cfg(test)]
    pub fn group_count(&self) -> usize {
        self.first.len()
    }

    /// The faces refined: the neighbourhoods of each group's first face.
    pub fn refined_faces(&self) -> usize {
        self.first
            .iter()
            .map(|&k| self.faces[k].cut.faces.len())
            .sum()
    }

    /// Appends the faces' stencil patches to `feed` (`whole`'s numbers, in the faces'
    /// order): each group's first face's neighbourhood, cut out as a cage of its own whose
    /// face 0 is that face, refined alone by `refine` (its stencil patches over the cut's
    /// points). The group's entries go into the table once, over the neighbourhood's own
    /// point numbers; every face of the group gets the patches and slots, reading those
    /// entries through its own point list ([`StencilPatch::points`]: its neighbourhood's
    /// points in the order the key numbers them). Their slots name no level vertex, as
    /// [`RegionCage::append`]'s.
    ///
    /// [`StencilPatch::points`]: super::pieces::StencilPatch::points
    pub fn push(
        &self,
        feed: &mut LimitFeed,
        whole: &Level,
        options: Options,
        refine: impl Fn(Level) -> Result<LimitFeed, GeometryError> + Sync + Send,
    ) -> Result<(), GeometryError> {
        let refined = crate::par::map(self.first.len(), |g| {
            let face = &self.faces[self.first[g]];
            let topology = face.cut.topology(whole, &face.local_faces(), options)?;
            let children = first_children(&topology, options.scheme);
            Ok((children, refine(topology)?))
        });
        let refined: Vec<(Vec<u32>, LimitFeed)> = refined.into_iter().collect::<Result<_, _>>()?;
        // Each group's refinement as each of its faces' turns sees it, with its entries.
        let mut turns: FxHashMap<(u32, u32), (LimitFeed, u32)> = FxHashMap::default();
        for (face, &g) in self.faces.iter().zip(&self.group) {
            if let std::collections::hash_map::Entry::Vacant(place) = turns.entry((g, face.turn)) {
                let (children, local) = &refined[g as usize];
                let corners = face.local_faces()[0].len() as u32;
                let local = turned_feed(local, children[0], corners, face.turn);
                let first = feed.entries.len() as u32;
                feed.entries.extend_from_slice(&local.entries);
                place.insert((local, first));
            }
        }
        let whole_children = first_children(whole, options.scheme);
        let slots: usize = self
            .faces
            .iter()
            .zip(&self.group)
            .map(|(face, &g)| turns[&(g, face.turn)].0.slots.len())
            .sum();
        feed.slots.reserve(slots);
        feed.no_curvature.reserve(slots);
        feed.vertex.reserve(slots);
        for (face, &g) in self.faces.iter().zip(&self.group) {
            let children = &refined[g as usize].0;
            let (local, first_entry) = &turns[&(g, face.turn)];
            let points = feed.point_lists.len() as u32;
            feed.point_lists.extend_from_slice(&face.cut.points);
            face.cut.append_patches(
                feed,
                local,
                (&whole_children, children),
                (*first_entry, points),
            );
        }
        Ok(())
    }
}

/// A face's limit patches, refined with the face read from corner `turn` of its `corners`
/// (`local`), as the face read from its own first corner shows them. Catmull-Clark: a patch
/// per child, the children of local face 0 numbered from `first_child`; child k of the turned
/// face is the face's child k + turn, and of a quad the child itself is turned as its parent
/// (OpenSubdiv keeps a quad's children oriented as the quad, [`super::refine`]). A quad
/// patch turned by one corner has its slot (i, j) at the turned slot (j, s − i), and
/// S_u = −S'_v, S_v = S'_u, S_uu = S'_vv, S_uv = −S'_uv, S_vv = S'_uu. Loop: one triangle
/// patch, (u, v) = (1 − u' − v', u') a turn, so slot (i, j) at (j, s − i − j), and
/// S_u = −S'_v, S_v = S'_u − S'_v, S_uu = S'_vv, S_uv = S'_vv − S'_uv,
/// S_vv = S'_uu − 2 S'_uv + S'_vv; its slots past the diagonal alias its first, as
/// [`super::patches`] writes them. The patches come in the order of the face's children,
/// each slot with entries of its own.
fn turned_feed(local: &LimitFeed, first_child: u32, corners: u32, turn: u32) -> LimitFeed {
    if turn == 0 {
        return local.clone();
    }
    let child_of = |p: &StencilPatch| match p.piece[0] {
        1 => (p.piece[1] - first_child + turn) % corners,
        _ => 0,
    };
    let mut patches: Vec<&StencilPatch> = local.patches.iter().collect();
    patches.sort_by_key(|p| child_of(p));
    let mut feed = LimitFeed::default();
    for patch in patches {
        let s = patch.segments as usize;
        let turns = if patch.triangle || corners == 4 {
            turn
        } else {
            0
        };
        let first = feed.slots.len();
        for i in 0..=s {
            for j in 0..=s {
                if patch.triangle && i + j > s {
                    let alias = feed.slots[first];
                    feed.slots.push(alias);
                    feed.no_curvature.push(true);
                    feed.vertex.push(u32::MAX);
                    continue;
                }
                // The slot this one reads, and the derivatives' signs and order there.
                let (mut a, mut b) = (i, j);
                for _ in 0..turns {
                    (a, b) = if patch.triangle {
                        (b, s - a - b)
                    } else {
                        (b, s - a)
                    };
                }
                let slot = patch.first_slot as usize + a * (s + 1) + b;
                let [start, count] = local.slots[slot];
                let begin = feed.entries.len() as u32;
                let run = &local.entries[start as usize..(start + count) as usize];
                feed.entries.extend(run.iter().map(|&(point, mut w)| {
                    for _ in 0..turns {
                        let [p, su, sv, suu, suv, svv] = w;
                        w = if patch.triangle {
                            [p, -sv, su - sv, svv, svv - suv, suu - 2.0 * suv + svv]
                        } else {
                            [p, -sv, su, svv, -suv, suu]
                        };
                    }
                    (point, w)
                }));
                feed.slots.push([begin, count]);
                feed.no_curvature.push(local.no_curvature[slot]);
                feed.vertex.push(local.vertex[slot]);
            }
        }
        let piece = match patch.piece[0] {
            1 => [1, first_child + child_of(patch)],
            _ => patch.piece,
        };
        feed.patches.push(StencilPatch {
            first_slot: first as u32,
            piece,
            ..*patch
        });
    }
    feed
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::subdiv::SubdivisionSurface;
    use crate::subdiv::cages;
    use crate::subdiv::patches::first_face_patches;
    use crate::subdiv::pieces::Display;
    use crate::subdiv::region::REGION_RINGS;
    use crate::subdiv::region::tests::{error_against_whole, irregular_faces, random_cage};
    use crate::test_support::Xorshift;
    use glam::DVec3;

    /// `surface` with every quad split into two triangles along its first diagonal (or, by
    /// `other`, along its second), creases and corners kept.
    fn split_quads(surface: &SubdivisionSurface, other: bool) -> SubdivisionSurface {
        let mut faces = Vec::new();
        for face in surface.mesh().faces() {
            match *face {
                [a, b, c, d] if other => faces.extend([vec![b, c, d], vec![b, d, a]]),
                [a, b, c, d] => faces.extend([vec![a, b, c], vec![a, c, d]]),
                _ => faces.push(face.to_vec()),
            }
        }
        let mesh = crate::mesh::PolygonMesh::new(surface.points().to_vec(), &faces).unwrap();
        SubdivisionSurface::new(
            mesh,
            surface.creases().to_vec(),
            surface.corners().to_vec(),
            surface.options,
            surface.level(),
        )
        .unwrap()
    }

    /// The stencils of faces that share a neighbourhood's refinement are the whole cage's
    /// (positions, first and second derivatives, within 1e-10 of the cage's size; at points
    /// of undefined curvature the position and the normal, the tangents being any pair in
    /// the tangent plane, chosen by where the point's ring starts), on random
    /// cages (pokes, insets, extrusions, semi-sharp creases, corners, both boundary rules)
    /// as they are and with their quads split into triangles, every face not a regular quad
    /// asked for, at levels 1 to 3; and some of the split cages' faces do share.
    #[test]
    fn faces_sharing_a_refinement_get_the_whole_cages_stencils() {
        let mut draw = Xorshift::new(0x7e3b_1a7e_5eed);
        // Quads under Catmull-Clark, triangles under Loop, read from another corner.
        let mut turned = [0, 0];
        for round in 0..8 {
            let cage = random_cage(&mut draw);
            let split = split_quads(&cage, round % 2 == 1);
            let mut looped = split.clone();
            looped.options.scheme = crate::subdiv::Scheme::Loop;
            for (split, surface) in [(false, cage.clone()), (true, split), (true, looped)] {
                let base = surface.base_level().unwrap();
                let faces = irregular_faces(&base);
                let templates = Templates::new(&base, &faces, REGION_RINGS, true).unwrap();
                if surface.options.scheme == crate::subdiv::Scheme::Loop {
                    turned[1] += templates.turned_faces(3);
                } else {
                    turned[0] += templates.turned_faces(4);
                }
                if split {
                    assert!(
                        templates.group_count() < faces.len(),
                        "round {round}: {} groups of {} faces",
                        templates.group_count(),
                        faces.len()
                    );
                }
                for levels in 1..=3 {
                    let mut feed = LimitFeed::default();
                    let options = surface.options;
                    let refine = |cage| first_face_patches(cage, options, levels, Display::Limit);
                    templates.push(&mut feed, &base, options, refine).unwrap();
                    assert!(feed.patches.iter().all(|p| p.points != NONE));
                    let error = error_against_whole(&surface, &faces, levels, &feed, true);
                    let scheme = surface.options.scheme;
                    assert!(
                        error < 1e-10,
                        "round {round} split {split} {scheme:?} L{levels}: {error:e}"
                    );
                }
            }
        }
        assert!(turned[0] > 0 && turned[1] > 0, "turned faces: {turned:?}");
    }

    /// A face's neighbourhood lists the region's faces once each, the face first, over points
    /// numbered from 0 in order of first use, and its key does not depend on how the cage
    /// numbers its points and faces.
    #[test]
    fn a_neighbourhood_reads_the_same_under_any_numbering() {
        let torus = cages::torus(DVec3::ZERO, 3.0, 1.0, 12, 8).unwrap();
        let surface = SubdivisionSurface::from_mesh(torus.clone(), 2).unwrap();
        let level = surface.base_level().unwrap();
        // The same torus with its points and faces renumbered.
        let n = torus.points().len() as u32;
        let relabel = |v: u32| (v * 7 + 3) % n;
        let mut points = vec![DVec3::ZERO; n as usize];
        for (v, &p) in torus.points().iter().enumerate() {
            points[relabel(v as u32) as usize] = p;
        }
        let mut faces: Vec<Vec<u32>> = torus
            .faces()
            .map(|f| f.iter().map(|&v| relabel(v)).collect())
            .collect();
        faces.reverse();
        let mesh = crate::mesh::PolygonMesh::new(points, &faces).unwrap();
        let other = SubdivisionSurface::from_mesh(mesh, 2)
            .unwrap()
            .base_level()
            .unwrap();
        let count = level.face_count() as u32;
        for f in 0..count {
            let a = neighbourhood(&level, f, REGION_RINGS, 0).unwrap();
            let b = neighbourhood(&other, count - 1 - f, REGION_RINGS, 0).unwrap();
            assert_eq!(a.key, b.key, "face {f}");
            assert_eq!(a.cut.faces[0], f);
            let mut sorted = a.cut.faces.clone();
            sorted.sort_unstable();
            assert_eq!(sorted, face_region(&level, &[f], REGION_RINGS));
            let mut used: Vec<u32> = a.local_faces().concat();
            let first_uses: Vec<u32> = used
                .iter()
                .enumerate()
                .filter(|&(k, v)| !used[..k].contains(v))
                .map(|(_, &v)| v)
                .collect();
            assert_eq!(
                first_uses,
                (0..a.cut.points.len() as u32).collect::<Vec<_>>()
            );
            used.sort_unstable();
            used.dedup();
            assert_eq!(used.len(), a.cut.points.len());
        }
        // Every face of a torus of quads looks alike; split into triangles along one diagonal
        // each, it is a lattice of triangles, six at every point, where a sixth of a turn about
        // a quad's first point takes one of its triangles to the other from the same first
        // corner: alike too, once the other faces are read from where the walk enters them.
        let all: Vec<u32> = (0..count).collect();
        let templates = Templates::new(&level, &all, REGION_RINGS, false).unwrap();
        assert_eq!(templates.group_count(), 1);
        let split = split_quads(&surface, false);
        let level = split.base_level().unwrap();
        let all: Vec<u32> = (0..level.face_count() as u32).collect();
        let templates = Templates::new(&level, &all, REGION_RINGS, false).unwrap();
        assert_eq!(templates.group_count(), 1);
    }

    /// Read from its least corner, a face's key does not depend on where its corner list
    /// starts: the cube's cage refined twice, with every face's corners renumbered from a
    /// different corner, gives each face next to a point of three quads the same key as
    /// before; and the 24 such faces form one group read so (several read from their own
    /// first corners).
    #[test]
    fn a_face_read_from_its_least_corner_reads_the_same_from_any_start() {
        let cube = cages::cube(DVec3::ZERO, 2.0).unwrap();
        let (points, refined) = SubdivisionSurface::from_mesh(cube, 2)
            .unwrap()
            .refined(2)
            .unwrap();
        let faces: Vec<Vec<u32>> = refined.faces().map(<[u32]>::to_vec).collect();
        let shifted: Vec<Vec<u32>> = faces
            .iter()
            .enumerate()
            .map(|(f, face)| {
                let mut face = face.clone();
                let shift = (f * 7 + f / 3) % face.len();
                face.rotate_left(shift);
                face
            })
            .collect();
        let level_of = |faces: &[Vec<u32>]| {
            let mesh = crate::mesh::PolygonMesh::new(points.clone(), faces).unwrap();
            SubdivisionSurface::from_mesh(mesh, 2)
                .unwrap()
                .base_level()
                .unwrap()
        };
        let (level, other) = (level_of(&faces), level_of(&shifted));
        let irregular = irregular_faces(&level);
        assert_eq!(irregular.len(), 24);
        for &f in &irregular {
            let a = neighbourhood(&level, f, REGION_RINGS, least_corner(&level, f)).unwrap();
            let b = neighbourhood(&other, f, REGION_RINGS, least_corner(&other, f)).unwrap();
            assert_eq!(a.key, b.key, "face {f}");
        }
        let turned = Templates::new(&other, &irregular, REGION_RINGS, true).unwrap();
        assert_eq!(turned.group_count(), 1);
        let unturned = Templates::new(&other, &irregular, REGION_RINGS, false).unwrap();
        assert!(unturned.group_count() > 1);
    }
}
