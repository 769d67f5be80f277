//! The topology of one subdivision level: faces, edges (numbered as OpenSubdiv's Vtr numbers
//! them), their adjacency and sharpness, with the manifold checks a cage must pass.

use crate::{CageProblem, GeometryError, Location};

/// No face on this side of an edge.
pub const NONE: u32 = u32::MAX;

/// Sharpness at or above which a crease is infinitely sharp (OpenSubdiv's `SHARPNESS_INFINITE`).
pub const INFINITE_SHARPNESS: f64 = 10.0;

/// One level of a subdivision hierarchy: the cage (level 0) or a refinement of it.
#[derive(Debug, Clone, PartialEq)]
pub struct Level {
    pub vertex_count: usize,
    face_starts: Vec<u32>,
    face_vertices: Vec<u32>,
    /// Parallel to `face_vertices`: the edge from corner j to corner j + 1.
    face_edges: Vec<u32>,
    /// Each edge's end vertices.
    pub edges: Vec<[u32; 2]>,
    /// The (up to two) faces of each edge; [`NONE`] where there is none.
    pub edge_faces: Vec<[u32; 2]>,
    pub edge_sharpness: Vec<f64>,
    pub vertex_sharpness: Vec<f64>,
    vertex_edge_starts: Vec<u32>,
    vertex_edges: Vec<u32>,
    vertex_face_starts: Vec<u32>,
    vertex_faces: Vec<u32>,
}

/// The faces and neighbours around a vertex in counter-clockwise order (seen from the side the
/// faces' orientation points to): face k lies between `neighbours[k]` and `neighbours[k + 1]`
/// (cyclically for an interior vertex; a boundary vertex has one more neighbour than faces).
#[derive(Debug, Clone, PartialEq)]
pub struct Ring {
    pub neighbours: Vec<u32>,
    pub faces: Vec<u32>,
    pub boundary: bool,
}

fn cage_error(at: Location, problem: CageProblem) -> GeometryError {
    GeometryError::Cage { at, problem }
}

impl Level {
    /// The vertex of triangle `f` that is not on edge (a, b).
    pub fn opposite(&self, f: u32, a: u32, b: u32) -> u32 {
        self.face(f)
            .iter()
            .copied()
            .find(|&x| x != a && x != b)
            .unwrap_or(a)
    }

    /// Builds the adjacency of `faces` over `vertex_count` vertices. `edges` lists edges known
    /// in advance (a refinement's child edges, in OpenSubdiv's order); the others are numbered
    /// in the order the faces first use them (face by face, corner j to j + 1), as OpenSubdiv
    /// numbers a base level's edges. Refuses repeated vertices in a face, faces with fewer
    /// than three corners, edges with more than two faces or used twice in one direction, and
    /// vertices whose faces do not form one fan, naming the face, edge or vertex.
    pub fn new(
        vertex_count: usize,
        faces: &[&[u32]],
        mut edges: Vec<[u32; 2]>,
    ) -> Result<Self, GeometryError> {
        // Edges given in advance (a refinement gives every edge, between vertices of the
        // level), found by their smaller end: a short scan, no hashing. The others are
        // numbered as the faces first use them.
        let (low_starts, low_edges) = group(
            vertex_count,
            edges
                .iter()
                .enumerate()
                .map(|(e, &[a, b])| (a.min(b), e as u32)),
        );
        // A new edge is found by its smaller end too: the newest new edge from each point
        // (made at the first new edge) and, per new edge, the one before it from the same point:
        // a list per point, no hashing.
        let given = edges.len();
        let mut newest_from: Vec<u32> = Vec::new();
        let mut older_from: Vec<u32> = Vec::new();
        let mut face_starts = Vec::with_capacity(faces.len() + 1);
        let corner_count: usize = faces.iter().map(|f| f.len()).sum();
        let mut face_vertices = Vec::with_capacity(corner_count);
        let mut face_edges = Vec::with_capacity(corner_count);
        // The corner (an index into `face_vertices`) whose face uses each edge in the
        // direction a -> b with a < b, and the other way: each half-edge's twin.
        let mut uses: Vec<[u32; 2]> = vec![[NONE; 2]; edges.len()];
        let mut corner_face = Vec::with_capacity(corner_count);
        if given == 0 {
            // A closed cage has half as many edges as corners, an open one a few more: room
            // made once rather than grown by doubling (and copying) as the edges come.
            let room = corner_count / 2 + corner_count / 8;
            edges.reserve(room);
            uses.reserve(room);
            older_from.reserve(room);
        }
        face_starts.push(0);
        for (f, face) in faces.iter().enumerate() {
            if face.len() < 3 {
                return Err(cage_error(Location::face(f), CageProblem::Degenerate));
            }
            for (j, &v) in face.iter().enumerate() {
                if v as usize >= vertex_count {
                    return Err(cage_error(
                        Location::face(f),
                        CageProblem::NoSuchVertex {
                            vertex: v,
                            count: vertex_count,
                        },
                    ));
                }
                if face[..j].contains(&v) {
                    return Err(cage_error(
                        Location::face(f),
                        CageProblem::RepeatedVertex { vertex: v },
                    ));
                }
            }
            for (j, &a) in face.iter().enumerate() {
                let b = face[(j + 1) % face.len()];
                let key = (a.min(b), a.max(b));
                let low = key.0 as usize;
                let found = low_edges[low_starts[low] as usize..low_starts[low + 1] as usize]
                    .iter()
                    .copied()
                    .find(|&e| {
                        let [x, y] = edges[e as usize];
                        x.max(y) == key.1
                    });
                let e = match found {
                    Some(e) => e,
                    None => {
                        if newest_from.is_empty() {
                            newest_from = vec![NONE; vertex_count];
                        }
                        let mut e = newest_from[low];
                        while e != NONE && edges[e as usize][0].max(edges[e as usize][1]) != key.1 {
                            e = older_from[e as usize - given];
                        }
                        if e == NONE {
                            e = edges.len() as u32;
                            edges.push([a, b]);
                            uses.push([NONE; 2]);
                            older_from.push(newest_from[low]);
                            newest_from[low] = e;
                        }
                        e
                    }
                };
                let side = usize::from(a > b);
                let slot = &mut uses[e as usize];
                if slot[side] != NONE {
                    let count = if slot[1 - side] != NONE { 3 } else { 2 };
                    let problem = if count > 2 {
                        CageProblem::NonManifoldEdge { faces: count }
                    } else {
                        CageProblem::Orientation
                    };
                    return Err(cage_error(Location::edge(a, b), problem));
                }
                slot[side] = face_vertices.len() as u32;
                face_vertices.push(a);
                face_edges.push(e);
                corner_face.push(f as u32);
            }
            face_starts.push(face_vertices.len() as u32);
        }
        let face_of = |c: u32| corner_face.get(c as usize).copied().unwrap_or(NONE);
        let edge_faces: Vec<[u32; 2]> = uses
            .iter()
            .map(|&[x, y]| {
                if x == NONE {
                    [face_of(y), NONE]
                } else {
                    [face_of(x), face_of(y)]
                }
            })
            .collect();
        let (vertex_edge_starts, vertex_edges) = group(
            vertex_count,
            edges
                .iter()
                .enumerate()
                .flat_map(|(e, &[a, b])| [(a, e as u32), (b, e as u32)]),
        );
        // Each vertex's corners in face order, and so its faces.
        let (vertex_face_starts, vertex_corners) = group(
            vertex_count,
            face_vertices
                .iter()
                .enumerate()
                .map(|(c, &v)| (v, c as u32)),
        );
        let vertex_faces = vertex_corners.iter().map(|&c| face_of(c)).collect();
        let level = Self {
            vertex_count,
            face_starts,
            face_vertices,
            face_edges,
            edge_sharpness: vec![0.0; edges.len()],
            edges,
            edge_faces,
            vertex_sharpness: vec![0.0; vertex_count],
            vertex_edge_starts,
            vertex_edges,
            vertex_face_starts,
            vertex_faces,
        };
        level.check_fans(&HalfEdges {
            vertex_corners: &vertex_corners,
            corner_face: &corner_face,
            uses: &uses,
        })?;
        Ok(level)
    }

    /// Every vertex with faces must have them in one fan: as many edges as faces (interior)
    /// or one more with exactly two boundary edges, and the ring walk must reach them all.
    /// The first such vertex by index is named, however many threads look (in parallel).
    fn check_fans(&self, half_edges: &HalfEdges<'_>) -> Result<(), GeometryError> {
        let fanned = |v: u32| {
            let faces = self.vertex_faces(v).len();
            if faces == 0 {
                return true;
            }
            let boundary = self
                .vertex_edges(v)
                .iter()
                .filter(|&&e| self.is_boundary_edge(e))
                .count();
            let edges = self.vertex_edges(v).len();
            let shaped = match boundary {
                0 => edges == faces,
                2 => edges == faces + 1,
                _ => false,
            };
            shaped && self.ring_face_count(v, half_edges) == faces
        };
        match crate::par::map(self.vertex_count, |v| fanned(v as u32))
            .into_iter()
            .position(|fanned| !fanned)
        {
            Some(v) => Err(cage_error(
                Location::point(v),
                CageProblem::NonManifoldVertex,
            )),
            None => Ok(()),
        }
    }

    pub fn face_count(&self) -> usize {
        self.face_starts.len() - 1
    }

    pub fn face(&self, f: u32) -> &[u32] {
        span(&self.face_starts, &self.face_vertices, f)
    }

    /// The edges of face `f`: edge j runs from corner j to corner j + 1.
    pub fn face_edges(&self, f: u32) -> &[u32] {
        span(&self.face_starts, &self.face_edges, f)
    }

    /// Every face's vertices.
    pub fn faces(&self) -> impl Iterator<Item = &[u32]> + '_ {
        (0..self.face_count() as u32).map(|f| self.face(f))
    }

    pub fn vertex_edges(&self, v: u32) -> &[u32] {
        span(&self.vertex_edge_starts, &self.vertex_edges, v)
    }

    pub fn vertex_faces(&self, v: u32) -> &[u32] {
        span(&self.vertex_face_starts, &self.vertex_faces, v)
    }

    /// The sharpness of each edge of [`Self::vertex_edges`], in that order.
    pub fn incident_sharpness(&self, v: u32) -> Vec<f64> {
        self.vertex_edges(v)
            .iter()
            .map(|&e| self.edge_sharpness[e as usize])
            .collect()
    }

    /// The corner of quad `f` diagonally opposite its corner `v`.
    pub fn diagonal(&self, f: u32, v: u32) -> u32 {
        let face = self.face(f);
        let j = face.iter().position(|&x| x == v).unwrap_or(0);
        face[(j + face.len() / 2) % face.len()]
    }

    pub fn is_boundary_edge(&self, e: u32) -> bool {
        self.edge_faces[e as usize][1] == NONE
    }

    /// The edge between points `a` and `b`, if there is one (a scan of `a`'s edges).
    pub fn edge_between(&self, a: u32, b: u32) -> Option<usize> {
        if a as usize >= self.vertex_count {
            return None;
        }
        self.vertex_edges(a)
            .iter()
            .find(|&&e| self.other_end(e, a) == b)
            .map(|&e| e as usize)
    }

    /// The end of edge `e` that is not `v`.
    pub fn other_end(&self, e: u32, v: u32) -> u32 {
        let [a, b] = self.edges[e as usize];
        if a == v { b } else { a }
    }

    /// The faces and neighbours of `v` in counter-clockwise order ([`Ring`]); a boundary
    /// vertex's ring starts at the boundary edge its first face leaves by.
    pub fn ring(&self, v: u32) -> Ring {
        let count = self.vertex_faces(v).len();
        let mut ring = Ring {
            neighbours: Vec::with_capacity(count + 1),
            faces: Vec::with_capacity(count),
            boundary: false,
        };
        ring.boundary = self.walk_ring(v, |f| ring.faces.push(f), |n| ring.neighbours.push(n));
        ring
    }

    /// The ring of an interior point with four faces ([`Self::ring`]'s neighbours and faces),
    /// without allocating; `None` for any other point.
    pub fn four_ring(&self, v: u32) -> Option<([u32; 4], [u32; 4])> {
        if self.vertex_faces(v).len() != 4 {
            return None;
        }
        let (mut neighbours, mut faces) = ([NONE; 4], [NONE; 4]);
        let (mut n, mut f) = (0usize, 0usize);
        let boundary = self.walk_ring(
            v,
            |x| {
                if let Some(slot) = faces.get_mut(f) {
                    *slot = x;
                }
                f += 1;
            },
            |x| {
                if let Some(slot) = neighbours.get_mut(n) {
                    *slot = x;
                }
                n += 1;
            },
        );
        (!boundary && n == 4 && f == 4).then_some((neighbours, faces))
    }

    /// How many faces the walk round `v` reaches ([`Self::ring`]'s faces, counted): the walk
    /// of [`Self::walk_ring`], from corner to corner at `v` by the twin of the half-edge
    /// entering it, with no search along a face.
    fn ring_face_count(&self, v: u32, half_edges: &HalfEdges<'_>) -> usize {
        let corners = span(&self.vertex_face_starts, half_edges.vertex_corners, v);
        // The corner before corner `c` along its face, and the other use of the edge that
        // leaves corner `c`.
        let previous = |c: u32| {
            let f = half_edges.corner_face[c as usize] as usize;
            let (start, end) = (self.face_starts[f], self.face_starts[f + 1]);
            if c == start { end - 1 } else { c - 1 }
        };
        let twin = |c: u32| {
            let [x, y] = half_edges.uses[self.face_edges[c as usize] as usize];
            if x == c { y } else { x }
        };
        // The first corner: one whose outgoing edge is a boundary edge, else any.
        let Some(first) = corners
            .iter()
            .copied()
            .find(|&c| twin(c) == NONE)
            .or_else(|| corners.first().copied())
        else {
            return 0;
        };
        let mut count = 0;
        let mut c = first;
        for _ in 0..corners.len() {
            count += 1;
            let next = twin(previous(c));
            if next == NONE || next == first {
                break;
            }
            c = next;
        }
        count
    }

    /// Walks the faces round `v` counter-clockwise as [`Self::ring`] orders them, handing each
    /// face to `face` and each neighbour to `neighbour` in ring order; returns whether the
    /// walk ended on a boundary. Each step reads the face's corner at `v` and the edge into
    /// it, with no search along the face.
    fn walk_ring(&self, v: u32, mut face: impl FnMut(u32), mut neighbour: impl FnMut(u32)) -> bool {
        let faces = self.vertex_faces(v);
        // Face f's corner at v and its corner count: edge j leaves v, edge j - 1 enters it.
        let corner = |f: u32| -> (usize, usize) {
            let corners = self.face(f);
            (
                corners.iter().position(|&x| x == v).unwrap_or(0),
                corners.len(),
            )
        };
        // The first face: one whose outgoing edge is a boundary edge, else any.
        let start = faces
            .iter()
            .copied()
            .find(|&f| self.is_boundary_edge(self.face_edges(f)[corner(f).0]))
            .or_else(|| faces.first().copied());
        let Some(first) = start else {
            return false;
        };
        let mut f = first;
        let (j, n) = corner(f);
        neighbour(self.face(f)[(j + 1) % n]);
        for _ in 0..faces.len() {
            face(f);
            let (j, n) = corner(f);
            let incoming = self.face(f)[(j + n - 1) % n];
            let [x, y] = self.edge_faces[self.face_edges(f)[(j + n - 1) % n] as usize];
            let next = if x == f { y } else { x };
            if next == NONE {
                neighbour(incoming);
                return true;
            }
            if next == first {
                break;
            }
            neighbour(incoming);
            f = next;
        }
        false
    }
}

/// What [`Level::new`] knows of its half-edges while it checks the fans: each vertex's
/// corners (indices into the face corners, rows as the vertex's faces), each corner's face,
/// and each edge's two uses by the corner each starts at.
struct HalfEdges<'a> {
    vertex_corners: &'a [u32],
    corner_face: &'a [u32],
    uses: &'a [[u32; 2]],
}

/// Item `k` of compressed rows: `values[starts[k]..starts[k + 1]]`.
fn span<'a>(starts: &[u32], values: &'a [u32], k: u32) -> &'a [u32] {
    let k = k as usize;
    &values[starts[k] as usize..starts[k + 1] as usize]
}

/// Groups `(key, value)` pairs by key (0..count) into offsets and values, values in order.
fn group(count: usize, pairs: impl Iterator<Item = (u32, u32)> + Clone) -> (Vec<u32>, Vec<u32>) {
    let mut starts = vec![0u32; count + 1];
    for (k, _) in pairs.clone() {
        starts[k as usize + 1] += 1;
    }
    for i in 0..count {
        starts[i + 1] += starts[i];
    }
    let mut fill = starts.clone();
    let mut values = vec![0u32; starts[count] as usize];
    for (k, v) in pairs {
        values[fill[k as usize] as usize] = v;
        fill[k as usize] += 1;
    }
    (starts, values)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::subdiv::{Options, Scheme, cages, refine};
    use glam::DVec3;

    fn level_of(faces: &[Vec<u32>]) -> Result<Level, GeometryError> {
        let count = faces.iter().flatten().map(|&v| v as usize + 1).max();
        let slices: Vec<&[u32]> = faces.iter().map(Vec::as_slice).collect();
        Level::new(count.unwrap_or(0), &slices, Vec::new())
    }

    /// The fan check's walk by half-edge twins reaches as many faces as the ring walk the
    /// level's users take, at every point of closed, open and mixed cages and of a refined
    /// level (whose edges come given).
    #[test]
    fn the_twin_walk_counts_the_ring_walks_faces() {
        let meshes = [
            cages::torus(DVec3::ZERO, 3.0, 1.0, 7, 5).unwrap(),
            cages::grid(DVec3::ZERO, 2.0, 4).unwrap(),
            cages::cube(DVec3::ZERO, 1.0).unwrap(),
            cages::icosahedron(DVec3::ZERO, 1.0).unwrap(),
            cages::cylinder(DVec3::ZERO, 1.0, 2.0, 6, 3).unwrap(),
        ];
        let mut levels = Vec::new();
        for mesh in meshes {
            let faces: Vec<Vec<u32>> = mesh.faces().map(<[u32]>::to_vec).collect();
            let level = level_of(&faces).unwrap();
            let scheme = if faces.iter().all(|f| f.len() == 3) {
                Scheme::Loop
            } else {
                Scheme::CatmullClark
            };
            let options = Options {
                scheme,
                ..Options::default()
            };
            levels.push(refine::refine(&level, &options, 0).unwrap().0);
            levels.push(level);
        }
        for level in levels {
            let corners: Vec<(u32, u32)> = (0..level.face_count() as u32)
                .flat_map(|f| level.face(f).iter().map(move |&v| (v, f)))
                .collect();
            let (starts, vertex_corners) = group(
                level.vertex_count,
                corners.iter().enumerate().map(|(c, &(v, _))| (v, c as u32)),
            );
            assert_eq!(starts, level.vertex_face_starts);
            let corner_face: Vec<u32> = corners.iter().map(|&(_, f)| f).collect();
            let mut uses = vec![[NONE; 2]; level.edges.len()];
            for (c, &(v, _)) in corners.iter().enumerate() {
                let e = level.face_edges[c] as usize;
                uses[e][usize::from(level.edges[e][0] != v)] = c as u32;
            }
            let half_edges = HalfEdges {
                vertex_corners: &vertex_corners,
                corner_face: &corner_face,
                uses: &uses,
            };
            for v in 0..level.vertex_count as u32 {
                let mut walked = 0;
                level.walk_ring(v, |_| walked += 1, |_| {});
                assert_eq!(level.ring_face_count(v, &half_edges), walked, "point {v}");
                assert_eq!(walked, level.vertex_faces(v).len(), "point {v}");
            }
        }
    }

    /// Two fans at one point pass the counts of edges and faces but not the walk: two closed
    /// tetrahedra sharing a corner, and an open fan beside a closed one.
    #[test]
    fn two_fans_at_a_point_are_refused_naming_it() {
        let tetrahedron = |a: u32, b: u32, c: u32, d: u32| {
            vec![vec![a, c, b], vec![a, b, d], vec![b, c, d], vec![a, d, c]]
        };
        let mut faces = tetrahedron(0, 1, 2, 3);
        assert!(level_of(&faces).is_ok());
        faces.extend(tetrahedron(0, 4, 5, 6));
        let error = level_of(&faces).unwrap_err();
        assert!(error.to_string().starts_with("points[0]"), "{error}");
        // An open fan of two triangles at point 0 beside the closed tetrahedron: two boundary
        // edges and one edge more than faces, as one open fan has.
        let mut mixed = tetrahedron(0, 1, 2, 3);
        mixed.extend([vec![0, 4, 5], vec![0, 5, 6]]);
        let error = level_of(&mixed).unwrap_err();
        assert!(error.to_string().starts_with("points[0]"), "{error}");
    }
}
