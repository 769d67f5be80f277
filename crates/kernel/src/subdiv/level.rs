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
        // Which face uses each edge in the direction a -> b with a < b, and the other way.
        let mut uses: Vec<[u32; 2]> = vec![[NONE; 2]; edges.len()];
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
                slot[side] = f as u32;
                face_vertices.push(a);
                face_edges.push(e);
            }
            face_starts.push(face_vertices.len() as u32);
        }
        let edge_faces: Vec<[u32; 2]> = uses
            .iter()
            .map(|&[x, y]| if x == NONE { [y, NONE] } else { [x, y] })
            .collect();
        let (vertex_edge_starts, vertex_edges) = group(
            vertex_count,
            edges
                .iter()
                .enumerate()
                .flat_map(|(e, &[a, b])| [(a, e as u32), (b, e as u32)]),
        );
        let (vertex_face_starts, vertex_faces) = group(
            vertex_count,
            (0..faces.len()).flat_map(|f| faces[f].iter().map(move |&v| (v, f as u32))),
        );
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
        level.check_fans()?;
        Ok(level)
    }

    /// Every vertex with faces must have them in one fan: as many edges as faces (interior)
    /// or one more with exactly two boundary edges, and the ring walk must reach them all.
    /// The first such vertex by index is named, however many threads look (in parallel).
    fn check_fans(&self) -> Result<(), GeometryError> {
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
            shaped && self.ring_face_count(v) == faces
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

    /// How many faces the walk round `v` reaches ([`Self::ring`]'s faces, counted).
    fn ring_face_count(&self, v: u32) -> usize {
        let mut count = 0;
        self.walk_ring(v, |_| count += 1, |_| {});
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
