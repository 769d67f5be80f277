//! Stencil templates: faces whose neighbourhoods are alike share one refinement.
//!
//! A face's limit stencils depend only on the topology and sharpness of the faces within
//! [`REGION_RINGS`] rings of it ([`super::region`]), never on where the points are. A cage
//! that repeats a pattern (a triangulated torus, a regular mesh split into triangles, the
//! same extraordinary point many times over) has many faces whose neighbourhoods are the same
//! up to the numbering of their points. Each face's neighbourhood is written out in an order
//! that depends only on its topology seen from the face: its faces in the order a walk across
//! edges from the face meets them, its points numbered as those faces first meet them, with
//! every edge's and point's sharpness. Faces whose neighbourhoods read the same are refined
//! once, through one of them, and the others take its stencils over their own points. At an
//! extraordinary or sharp point the two tangents are any pair spanning the tangent plane,
//! chosen by where the point's ring starts, so they may differ from the whole cage's there;
//! the position and the normal do not.

use rustc_hash::FxHashMap;

use super::Options;
use super::level::{Level, NONE};
use super::pieces::{LimitFeed, first_children};
use super::region::{RegionCage, face_region};
use crate::GeometryError;

/// Fewer faces than this are not worth naming their neighbourhoods for.
pub const FEWEST_FACES: usize = 16;

/// One face's neighbourhood in the order its topology gives ([`neighbourhood`]).
struct Neighbourhood {
    /// Its faces (the face first) and points in that order.
    cut: RegionCage,
    /// The faces' corner counts and points, then every face edge's sharpness and every
    /// point's: equal keys give equal refinements.
    key: Vec<u64>,
}

impl Neighbourhood {
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

/// The faces within `rings` rings of `face` of `level` ([`face_region`]): `face`, then the
/// others as a breadth-first walk across edges meets them (each face's edges in its own
/// order), their points numbered as the faces in that order first use them. `None` where the
/// walk does not reach every face of the region.
fn neighbourhood(level: &Level, face: u32, rings: u32) -> Option<Neighbourhood> {
    let region = face_region(level, &[face], rings);
    let place = |g: u32| region.binary_search(&g).ok();
    let mut met = vec![false; region.len()];
    met[place(face)?] = true;
    let mut order = Vec::with_capacity(region.len());
    order.push(face);
    let mut next = 0;
    while next < order.len() {
        let g = order[next];
        next += 1;
        for &e in level.face_edges(g) {
            let [a, b] = level.edge_faces[e as usize];
            let h = if a == g { b } else { a };
            if h == NONE {
                continue;
            }
            if let Some(k) = place(h)
                && !std::mem::replace(&mut met[k], true)
            {
                order.push(h);
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
    for &g in &order {
        let corners = level.face(g);
        key.push(corners.len() as u64);
        for &v in corners {
            let local = *numbers.entry(v).or_insert_with(|| {
                points.push(v);
                points.len() as u32 - 1
            });
            key.push(u64::from(local));
        }
    }
    for &g in &order {
        let edges = level.face_edges(g);
        key.extend(
            edges
                .iter()
                .map(|&e| level.edge_sharpness[e as usize].to_bits()),
        );
    }
    key.extend(
        points
            .iter()
            .map(|&v| level.vertex_sharpness[v as usize].to_bits()),
    );
    Some(Neighbourhood {
        cut: RegionCage {
            faces: order,
            points,
        },
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
    /// one's cannot be walked across its edges.
    pub fn new(level: &Level, faces: &[u32], rings: u32) -> Option<Self> {
        let found = crate::par::map(faces.len(), |k| neighbourhood(level, faces[k], rings));
        let faces: Vec<Neighbourhood> = found.into_iter().collect::<Option<_>>()?;
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
        Some(Self {
            faces,
            group,
            first,
        })
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
        let whole_children = first_children(whole, options.scheme);
        let first_entries: Vec<u32> = refined
            .iter()
            .map(|(_, local)| {
                let first = feed.entries.len() as u32;
                feed.entries.extend_from_slice(&local.entries);
                first
            })
            .collect();
        let slots: usize = self
            .group
            .iter()
            .map(|&g| refined[g as usize].1.slots.len())
            .sum();
        feed.slots.reserve(slots);
        feed.no_curvature.reserve(slots);
        feed.vertex.reserve(slots);
        for (face, &g) in self.faces.iter().zip(&self.group) {
            let (children, local) = &refined[g as usize];
            let points = feed.point_lists.len() as u32;
            feed.point_lists.extend_from_slice(&face.cut.points);
            face.cut.append_patches(
                feed,
                local,
                (&whole_children, children),
                (first_entries[g as usize], points),
            );
        }
        Ok(())
    }
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
        for round in 0..8 {
            let cage = random_cage(&mut draw);
            let split = split_quads(&cage, round % 2 == 1);
            let mut looped = split.clone();
            looped.options.scheme = crate::subdiv::Scheme::Loop;
            for (split, surface) in [(false, cage.clone()), (true, split), (true, looped)] {
                let base = surface.base_level().unwrap();
                let faces = irregular_faces(&base);
                let templates = Templates::new(&base, &faces, REGION_RINGS).unwrap();
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
            let a = neighbourhood(&level, f, REGION_RINGS).unwrap();
            let b = neighbourhood(&other, count - 1 - f, REGION_RINGS).unwrap();
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
        // each, two kinds of face.
        let all: Vec<u32> = (0..count).collect();
        let templates = Templates::new(&level, &all, REGION_RINGS).unwrap();
        assert_eq!(templates.group_count(), 1);
        let split = split_quads(&surface, false);
        let level = split.base_level().unwrap();
        let all: Vec<u32> = (0..level.face_count() as u32).collect();
        let templates = Templates::new(&level, &all, REGION_RINGS).unwrap();
        assert_eq!(templates.group_count(), 2);
    }
}
