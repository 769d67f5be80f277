//! Topology tools on a subdivision cage, as Blender's edit mode has them: extrude and inset faces,
//! loop cut, bevel edges, bridge edge loops, merge vertices, dissolve edges and delete faces.
//!
//! Every tool takes a [`Cage`] (points, polygon faces, creases and corners) and returns the new
//! cage. The conventions are the same for all of them:
//! - a vertex that survives keeps its index, and the vertices a tool adds follow the old ones;
//!   vertices no face uses any more are dropped, the survivors keeping their order;
//! - a face keeps the winding of the face it came from, and new faces are wound to agree with
//!   their neighbours;
//! - creases and corners go with the edges and vertices they were on (an edge split in pieces
//!   gives each piece its sharpness; a copied edge, as the top of an extrusion, copies it).
//!
//! Where Blender's tool has options, the defaults of its edit-mode tool are taken: an inset is
//! even (its strip has the width asked for along every edge), dissolving edges also dissolves
//! the vertices left between only two edges, and a merge keeps the first vertex named.

use std::collections::BTreeMap;

use rustc_hash::{FxHashMap as HashMap, FxHashSet as HashSet};

use glam::DVec3;
use thiserror::Error;

use super::{Corner, Crease, bevel_corner};

/// Why a cage tool refused.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum CageEditError {
    #[error("face {0} is not in the cage ({1} faces)")]
    NoFace(usize, usize),
    #[error("vertex {0} is not in the cage ({1} vertices)")]
    NoVertex(u32, usize),
    #[error("the cage has no edge between vertices {0} and {1}")]
    NoEdge(u32, u32),
    /// A loop cut's ring comes back through face `face` across other edges than the two it
    /// first crossed (on a mesh like Blender's monkey, a ring may come back beside itself):
    /// the cut lines would cross there and no quads would be left.
    #[error(
        "the edge ring through {a}-{b} comes back across face {face}: its cut lines would \
         cross there"
    )]
    RingCrossesItself { a: u32, b: u32, face: usize },
    /// A loop cut's ring touches itself at vertex `vertex`: the sides of its quads meet there
    /// from more than two directions (as Blender's loop cut finds no pair of edge loops to
    /// cut between and leaves the mesh).
    #[error(
        "the edge ring through {a}-{b} touches itself at vertex {vertex}: its sides meet there \
         from more than two directions"
    )]
    RingTouchesItself { a: u32, b: u32, vertex: u32 },
    /// A loop cut's ring whose two sides join into one (a ring ending at both sides of one
    /// triangle, or going round a Möbius strip): Blender's loop cut finds no pair of edge
    /// loops to cut between and leaves the mesh.
    #[error(
        "the two sides of the edge ring through {a}-{b} join into one: there are no two edge \
         loops to cut between"
    )]
    RingSidesJoin { a: u32, b: u32 },
    /// A loop cut through an edge with no quad on either side: its ring is the edge alone,
    /// and Blender's loop cut finds no two edge loops to cut between and leaves the mesh.
    #[error(
        "edge {a}-{b} has no quad on either side: its edge ring is the edge alone, with no two \
         edge loops to cut between"
    )]
    RingWithoutQuads { a: u32, b: u32 },
    /// Every edge named to a bevel or a dissolve is on the cage's border (one face), which
    /// Blender's bevel and dissolve pass over: they leave the cage as it is.
    #[error(
        "every named edge is on the cage's border (edge {a}-{b} has one face), and a {tool} \
         leaves border edges as they are"
    )]
    EveryEdgeOnBorder { tool: &'static str, a: u32, b: u32 },
    /// A region inset whose faces enclose a closed piece of the cage: it has no border to
    /// inset, and Blender's inset leaves the cage as it is.
    #[error("the faces enclose a closed piece of the cage: the region has no border to inset")]
    RegionWithoutBorder,
    /// A merge by distance where no two of the points are within it: Blender's merge by
    /// distance leaves the mesh as it is.
    #[error("no two points are within {distance} of each other: nothing to merge")]
    NothingWithinDistance { distance: f64 },
    #[error("{0}")]
    Invalid(String),
}

impl CageEditError {
    /// Whether Blender's tool, asked the same, leaves the mesh as it is rather than failing:
    /// a loop cut whose ring crosses, touches or joins itself or has no quad, a bevel or
    /// dissolve of border edges alone, an inset of a region with no border, a merge by
    /// distance with no two points within it. The command line then writes the cage
    /// unchanged with the reason; the editor refuses, so that no step changes nothing.
    pub fn leaves_cage_unchanged(&self) -> bool {
        matches!(
            self,
            Self::RingCrossesItself { .. }
                | Self::RingTouchesItself { .. }
                | Self::RingWithoutQuads { .. }
                | Self::RingSidesJoin { .. }
                | Self::EveryEdgeOnBorder { .. }
                | Self::RegionWithoutBorder
                | Self::NothingWithinDistance { .. }
        )
    }
}

/// Whether a tool's optional amount is left at 0 (and so not written).
fn is_zero(value: &f64) -> bool {
    *value == 0.0
}

pub(super) fn invalid(message: impl Into<String>) -> CageEditError {
    CageEditError::Invalid(message.into())
}

/// A polygon cage being edited: points, faces (each a loop of point indices, counter-clockwise
/// seen from its front), and the sharp edges and vertices.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Cage {
    pub points: Vec<DVec3>,
    pub faces: Vec<Vec<u32>>,
    pub creases: Vec<Crease>,
    pub corners: Vec<Corner>,
}

pub(super) fn key(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

/// The Newell normal of a polygon (unit; zero when the polygon has no area).
pub fn polygon_normal(points: &[DVec3], face: &[u32]) -> DVec3 {
    let mut n = DVec3::ZERO;
    for c in 0..face.len() {
        let p = points[face[c] as usize];
        let q = points[face[(c + 1) % face.len()] as usize];
        n += DVec3::new(
            (p.y - q.y) * (p.z + q.z),
            (p.z - q.z) * (p.x + q.x),
            (p.x - q.x) * (p.y + q.y),
        );
    }
    n.normalize_or_zero()
}

/// The root of `x` in a union-find forest (`parent[r] == r` at a root), halving the path.
fn root(parent: &mut [usize], mut x: usize) -> usize {
    while parent[x] != x {
        parent[x] = parent[parent[x]];
        x = parent[x];
    }
    x
}

/// The points joined to each of `vertices` by an edge of `faces` (empty for one on none);
/// the rest of the cage is not asked about.
fn neighbours_in(
    faces: &[Vec<u32>],
    vertices: impl Iterator<Item = u32>,
) -> HashMap<u32, HashSet<u32>> {
    let mut neighbours: HashMap<u32, HashSet<u32>> =
        vertices.map(|v| (v, HashSet::default())).collect();
    for face in faces {
        for c in 0..face.len() {
            let (a, b) = (face[c], face[(c + 1) % face.len()]);
            for (v, other) in [(a, b), (b, a)] {
                if let Some(n) = neighbours.get_mut(&v) {
                    n.insert(other);
                }
            }
        }
    }
    neighbours
}

/// One more than the largest point index `faces` name (0 for none): the length of a table
/// indexed by their points.
fn points_named<'a>(faces: impl Iterator<Item = &'a Vec<u32>>) -> usize {
    faces.flatten().map(|&v| v as usize + 1).max().unwrap_or(0)
}

/// `faces` with each face over the same corners as an earlier one left out (the first
/// stays). Such faces share their least corner, so each face is compared only with the
/// faces kept before it that share it: a list per corner, no hashing of every face.
fn without_repeated_faces(faces: Vec<Vec<u32>>) -> Vec<Vec<u32>> {
    let same_corners = |a: &[u32], b: &[u32]| {
        if a.len() != b.len() || !a.iter().all(|v| b.contains(v)) {
            return false;
        }
        let (mut a, mut b) = (a.to_vec(), b.to_vec());
        a.sort_unstable();
        b.sort_unstable();
        a == b
    };
    let size = points_named(faces.iter());
    // The newest kept face by least corner, and per kept face the one before it.
    let mut newest = vec![usize::MAX; size];
    let mut older = vec![usize::MAX; faces.len()];
    let mut keep = vec![false; faces.len()];
    let mut empty_kept = false;
    for (f, face) in faces.iter().enumerate() {
        let Some(&least) = face.iter().min() else {
            keep[f] = !std::mem::replace(&mut empty_kept, true);
            continue;
        };
        let least = least as usize;
        let mut g = newest[least];
        while g != usize::MAX && !same_corners(&faces[g], face) {
            g = older[g];
        }
        if g == usize::MAX {
            keep[f] = true;
            older[f] = newest[least];
            newest[least] = f;
        }
    }
    faces
        .into_iter()
        .zip(keep)
        .filter_map(|(face, kept)| kept.then_some(face))
        .collect()
}

/// Whether a face's corner at `v`, between its next corner `next` and its previous corner
/// `prev`, is reflex about the face's `normal` (the face turns back on itself there), as
/// Blender's bevel tells which side of an edge is inside the face.
fn reflex_corner(v: DVec3, next: DVec3, prev: DVec3, normal: DVec3) -> bool {
    (next - v).cross(prev - v).dot(normal) < 0.0
}

/// The factor by which a step along the bisector of two unit directions must grow to be `1`
/// along each of them: 1 / cos(θ/2) for the angle θ between them.
fn even_offset_factor(a: DVec3, b: DVec3) -> f64 {
    let half = (a + b).normalize_or_zero();
    let cos = half.dot(a);
    if cos > 1e-4 { 1.0 / cos } else { 1.0 }
}

/// A cage's half-edges, (from, to) ↦ (face, corner of `from`), grouped by their first point:
/// built with two counting passes over the faces and looked up by a scan of one point's
/// outgoing half-edges (four on a regular quad cage), with no hashing. Where a half-edge
/// appears twice (a cage with a flipped face), the later face's wins.
pub(super) struct HalfEdges {
    /// Where each point's half-edges start in `ends` and `corners` (one more entry than points).
    starts: Vec<u32>,
    /// The second point of each half-edge, grouped by the first, in face order.
    ends: Vec<u32>,
    /// The (face, corner) of each half-edge.
    corners: Vec<(usize, usize)>,
}

impl HalfEdges {
    fn new(faces: &[Vec<u32>]) -> Self {
        let points = points_named(faces.iter());
        let mut starts = vec![0u32; points + 1];
        for &v in faces.iter().flatten() {
            starts[v as usize + 1] += 1;
        }
        for k in 1..starts.len() {
            starts[k] += starts[k - 1];
        }
        let count = starts[points] as usize;
        let mut next = starts.clone();
        let (mut ends, mut corners) = (vec![0u32; count], vec![(0usize, 0usize); count]);
        for (f, face) in faces.iter().enumerate() {
            for (c, &from) in face.iter().enumerate() {
                let slot = &mut next[from as usize];
                ends[*slot as usize] = face[(c + 1) % face.len()];
                corners[*slot as usize] = (f, c);
                *slot += 1;
            }
        }
        Self {
            starts,
            ends,
            corners,
        }
    }

    /// The (face, corner) of half-edge `from` → `to`.
    pub(super) fn get(&self, &(from, to): &(u32, u32)) -> Option<&(usize, usize)> {
        let from = from as usize;
        if from + 1 >= self.starts.len() {
            return None;
        }
        let range = self.starts[from] as usize..self.starts[from + 1] as usize;
        self.ends[range.clone()]
            .iter()
            .rposition(|&end| end == to)
            .map(|k| &self.corners[range.start + k])
    }

    pub(super) fn contains_key(&self, edge: &(u32, u32)) -> bool {
        self.get(edge).is_some()
    }

    /// Every half-edge (from, to), grouped by `from`.
    pub(super) fn keys(&self) -> impl Iterator<Item = (u32, u32)> + '_ {
        self.iter().map(|(edge, _)| edge)
    }

    /// Every half-edge (from, to) with its (face, corner), grouped by `from`; once each, as
    /// [`Self::get`] answers for it.
    pub(super) fn iter(&self) -> impl Iterator<Item = ((u32, u32), (usize, usize))> + '_ {
        self.starts
            .windows(2)
            .enumerate()
            .flat_map(move |(from, range)| {
                let ends = &self.ends[range[0] as usize..range[1] as usize];
                let corners = &self.corners[range[0] as usize..range[1] as usize];
                (0..ends.len())
                    .filter(move |&k| !ends[k + 1..].contains(&ends[k]))
                    .map(move |k| ((from as u32, ends[k]), corners[k]))
            })
    }
}

impl Cage {
    /// The cage of subdivision surface `surface`: its points, faces, creases and corners.
    pub fn of_surface(surface: &super::SubdivisionSurface) -> Self {
        let mesh = surface.mesh();
        Self {
            points: mesh.points().to_vec(),
            faces: mesh.faces().map(<[u32]>::to_vec).collect(),
            creases: surface.creases().to_vec(),
            corners: surface.corners().to_vec(),
        }
    }

    /// The half-edges: (from, to) ↦ (face, corner of `from`).
    pub(super) fn half_edges(&self) -> HalfEdges {
        HalfEdges::new(&self.faces)
    }

    pub(super) fn check_faces(&self, faces: &[usize]) -> Result<Vec<usize>, CageEditError> {
        let mut out: Vec<usize> = Vec::with_capacity(faces.len());
        let mut seen = vec![false; self.faces.len()];
        for &f in faces {
            if f >= self.faces.len() {
                return Err(CageEditError::NoFace(f, self.faces.len()));
            }
            if !std::mem::replace(&mut seen[f], true) {
                out.push(f);
            }
        }
        if out.is_empty() {
            return Err(invalid("no faces were named"));
        }
        Ok(out)
    }

    pub(super) fn check_vertex(&self, v: u32) -> Result<(), CageEditError> {
        if (v as usize) < self.points.len() {
            Ok(())
        } else {
            Err(CageEditError::NoVertex(v, self.points.len()))
        }
    }

    /// Refuses a vertex outside the cage, or a pair of vertices no face joins (`half`: the
    /// cage's [`Self::half_edges`]).
    pub(super) fn check_edge(&self, half: &HalfEdges, a: u32, b: u32) -> Result<(), CageEditError> {
        self.check_vertex(a)?;
        self.check_vertex(b)?;
        if half.contains_key(&(a, b)) || half.contains_key(&(b, a)) {
            Ok(())
        } else {
            Err(CageEditError::NoEdge(a, b))
        }
    }

    pub(super) fn sharpness_of_edges(&self) -> HashMap<(u32, u32), f64> {
        self.creases
            .iter()
            .map(|c| (key(c.a, c.b), c.sharpness))
            .collect()
    }

    /// Adds a crease on edge a–b (the larger sharpness where one is there already).
    pub(super) fn add_crease(&mut self, a: u32, b: u32, sharpness: f64) {
        if let Some(c) = self.creases.iter_mut().find(|c| key(c.a, c.b) == key(a, b)) {
            c.sharpness = c.sharpness.max(sharpness);
        } else {
            self.creases.push(Crease { a, b, sharpness });
        }
    }

    /// Gives each copied vertex (`copy`: original ↦ copy) the sharpness its original has among
    /// `corners`.
    pub(super) fn copy_corners(&mut self, corners: &[Corner], copy: &HashMap<u32, u32>) {
        for corner in corners {
            if let Some(&c) = copy.get(&corner.vertex) {
                self.corners.push(Corner {
                    vertex: c,
                    ..*corner
                });
            }
        }
    }

    /// Drops the vertices the tool left unused that a face of `before` used (the survivors keep
    /// their order; a vertex no face used before stays), faces of fewer than 3 corners, and the
    /// creases and corners whose edges or vertices are gone.
    pub(super) fn compacted(mut self, before: &Self) -> Self {
        self.faces.retain(|f| f.len() >= 3);
        let mut used = vec![true; self.points.len()];
        for face in &before.faces {
            for &v in face {
                used[v as usize] = false;
            }
        }
        for face in &self.faces {
            for &v in face {
                used[v as usize] = true;
            }
        }
        let mut map = vec![u32::MAX; self.points.len()];
        let mut points = Vec::with_capacity(self.points.len());
        for (v, &p) in self.points.iter().enumerate() {
            if used[v] {
                map[v] = points.len() as u32;
                points.push(p);
            }
        }
        for face in &mut self.faces {
            for v in face.iter_mut() {
                *v = map[*v as usize];
            }
        }
        // The edges, for the creases to keep (none to find without creases).
        let edges: HashSet<(u32, u32)> = if self.creases.is_empty() {
            HashSet::default()
        } else {
            self.faces
                .iter()
                .flat_map(|f| (0..f.len()).map(move |c| key(f[c], f[(c + 1) % f.len()])))
                .collect()
        };
        let mut seen = HashSet::default();
        let creases =
            self.creases
                .iter()
                .filter_map(|c| {
                    let (a, b) = (*map.get(c.a as usize)?, *map.get(c.b as usize)?);
                    (a != u32::MAX && b != u32::MAX && edges.contains(&key(a, b)))
                        .then_some(Crease { a, b, ..*c })
                })
                .filter(|c| seen.insert(key(c.a, c.b)))
                .collect();
        let mut seen = HashSet::default();
        let corners = self
            .corners
            .iter()
            .filter_map(|c| {
                let vertex = *map.get(c.vertex as usize)?;
                (vertex != u32::MAX).then_some(Corner { vertex, ..*c })
            })
            .filter(|c| seen.insert(c.vertex))
            .collect();
        Self {
            points,
            faces: self.faces,
            creases,
            corners,
        }
    }

    /// Region extrude (Blender's Extrude Region): the faces are lifted by `offset` along the
    /// region's average normal (the sum of the faces' unit normals, normalized, as Blender's
    /// Normal orientation has it), and every edge on the region's border (an edge the region
    /// shares with a face outside it, or an open edge of the cage) gets a side quad. Each
    /// region vertex gets a copy, in index order; originals no face uses any more (the region's
    /// inner vertices) are dropped. The lifted faces keep their indices; the sides follow.
    pub fn extrude_faces(&self, faces: &[usize], offset: f64) -> Result<Self, CageEditError> {
        let region = self.check_faces(faces)?;
        if !offset.is_finite() {
            return Err(invalid("the offset must be a finite number"));
        }
        let mut normal = DVec3::ZERO;
        for &f in &region {
            normal += polygon_normal(&self.points, &self.faces[f]);
        }
        // Unit normals summing to (almost) nothing leave no direction.
        let cancelled = normal.length() < 1e-9 * region.len() as f64;
        let normal = normal.normalize_or_zero();
        if cancelled || normal.length_squared() < 0.5 {
            return Err(invalid(
                "the faces' normals cancel out: the region has no direction to extrude along",
            ));
        }
        // A region bordering no other face (a whole piece of the cage, closed or open) is
        // copied, as Blender's extrude keeps such faces: the originals stay, turned over.
        let half = self.half_edges();
        let in_region: HashSet<usize> = region.iter().copied().collect();
        let bordered = region.iter().any(|&f| {
            let face = &self.faces[f];
            (0..face.len()).any(|c| {
                let (a, b) = (face[c], face[(c + 1) % face.len()]);
                half.get(&(b, a))
                    .is_some_and(|&(g, _)| !in_region.contains(&g))
            })
        });
        if bordered {
            self.extrude_region(&region, normal * offset)
        } else {
            Ok(self.extrude_copy(&region, &half, normal * offset))
        }
    }

    /// A region bordering no other face extruded by `by` (Blender's extrude with the
    /// originals kept): the region's faces stay, turned over, and a copy of them moved by
    /// `by` (its vertices appended in index order, its faces after the cage's) is joined to
    /// them by a side quad on every open edge. The copies keep the edges' and points'
    /// sharpness.
    fn extrude_copy(&self, region: &[usize], half: &HalfEdges, by: DVec3) -> Self {
        let mut out = self.clone();
        let mut used: Vec<u32> = region
            .iter()
            .flat_map(|&f| self.faces[f].iter().copied())
            .collect();
        used.sort_unstable();
        used.dedup();
        let mut copy: HashMap<u32, u32> = HashMap::default();
        for &v in &used {
            copy.insert(v, out.points.len() as u32);
            out.points.push(self.points[v as usize] + by);
        }
        let sharp = self.sharpness_of_edges();
        let mut sides = Vec::new();
        for &f in region {
            let face = &self.faces[f];
            out.faces.push(face.iter().map(|v| copy[v]).collect());
            for c in 0..face.len() {
                let (a, b) = (face[c], face[(c + 1) % face.len()]);
                if let Some(&s) = sharp.get(&key(a, b)) {
                    out.add_crease(copy[&a], copy[&b], s);
                }
                if !half.contains_key(&(b, a)) {
                    sides.push(vec![a, b, copy[&b], copy[&a]]);
                }
            }
            out.faces[f].reverse();
        }
        out.faces.extend(sides);
        out.copy_corners(&self.corners, &copy);
        out
    }

    /// The inward directions of a face's edges in its plane: for corner c, the unit vector
    /// square to edge (c, c + 1) pointing into the face.
    fn inward_directions(&self, face: &[u32]) -> Vec<DVec3> {
        let n = polygon_normal(&self.points, face);
        (0..face.len())
            .map(|c| {
                let a = self.points[face[c] as usize];
                let b = self.points[face[(c + 1) % face.len()] as usize];
                n.cross(b - a).normalize_or_zero()
            })
            .collect()
    }

    /// Inset of each face on its own (Blender's Inset Faces, Individual, even offset): a face's
    /// corners move into it so that each edge moves `thickness` square to itself in the
    /// face's plane; the moved corners are new vertices (appended face by face, in corner
    /// order), the face keeps its index and becomes the inner face, and a strip of quads joins
    /// it to the old border.
    pub fn inset_individual(&self, faces: &[usize], thickness: f64) -> Result<Self, CageEditError> {
        let region = self.check_faces(faces)?;
        check_thickness(thickness)?;
        let mut out = self.clone();
        for &f in &region {
            let face = self.faces[f].clone();
            let inward = self.inward_directions(&face);
            let k = face.len();
            let first = out.points.len() as u32;
            for c in 0..k {
                let (a, b) = (inward[(c + k - 1) % k], inward[c]);
                let step = (a + b).normalize_or_zero() * even_offset_factor(a, b) * thickness;
                out.points.push(self.points[face[c] as usize] + step);
            }
            let inner: Vec<u32> = (0..k as u32).map(|c| first + c).collect();
            for c in 0..k {
                let d = (c + 1) % k;
                out.faces.push(vec![face[c], face[d], inner[d], inner[c]]);
            }
            out.faces[f] = inner;
        }
        Ok(out.compacted(self))
    }

    /// Inset with depth (Blender's Inset Faces, Depth): [`Self::inset_region`] (or
    /// [`Self::inset_individual`] with `individual`), then the inner faces moved `depth` out
    /// of the surface. Each inset face on its own moves along its normal. A region's points
    /// move along their normals, scaled by Blender's shell factor (the mean over the faces
    /// round the point, weighted by their angles there, of 1 / cos of the angle between the
    /// point's normal and the face's) so that flat parts move `depth` square to themselves: a
    /// point on the region's border takes the normalized sum of the normals of the region's
    /// faces on its border edges, one inside the region its angle-weighted normal; the faces
    /// keep the normals they had before the inset (a strip quad the normal of the region face
    /// beside it).
    pub fn inset(
        &self,
        faces: &[usize],
        thickness: f64,
        depth: f64,
        individual: bool,
    ) -> Result<Self, CageEditError> {
        if !depth.is_finite() {
            return Err(invalid("the depth must be a finite number"));
        }
        let mut out = if individual {
            self.inset_individual(faces, thickness)?
        } else {
            self.inset_region(faces, thickness)?
        };
        if depth == 0.0 {
            return Ok(out);
        }
        let region = self.check_faces(faces)?;
        let normal_of = |f: usize| polygon_normal(&self.points, &self.faces[f]);
        if individual {
            for &f in &region {
                let step = normal_of(f) * depth;
                for k in 0..out.faces[f].len() {
                    let v = out.faces[f][k] as usize;
                    out.points[v] += step;
                }
            }
            return Ok(out);
        }
        // The region's half-edges (after the inset) and the faces they belong to.
        let mut region_half: HashMap<(u32, u32), usize> = HashMap::default();
        for &f in &region {
            let face = &out.faces[f];
            for c in 0..face.len() {
                region_half.insert((face[c], face[(c + 1) % face.len()]), f);
            }
        }
        // Border points: the sum of the normals of the region's faces on their border edges.
        let mut border: BTreeMap<u32, DVec3> = BTreeMap::new();
        let mut points: Vec<u32> = Vec::new();
        for &f in &region {
            let face = &out.faces[f];
            for c in 0..face.len() {
                let (a, b) = (face[c], face[(c + 1) % face.len()]);
                points.push(a);
                if !region_half.contains_key(&(b, a)) {
                    *border.entry(a).or_default() += normal_of(f);
                    *border.entry(b).or_default() += normal_of(f);
                }
            }
        }
        points.sort_unstable();
        points.dedup();
        let angle_at = |cage: &Cage, face: &[u32], c: usize| {
            let n = face.len();
            let p = |k: usize| cage.points[face[k % n] as usize];
            (p(c + n - 1) - p(c)).angle_between(p(c + 1) - p(c))
        };
        // Each moved point's faces (index, corner) after the inset and before it.
        let moving: HashSet<u32> = points.iter().copied().collect();
        let corners_of = |cage: &Cage| {
            let mut map: HashMap<u32, Vec<(usize, usize)>> = HashMap::default();
            for (f, face) in cage.faces.iter().enumerate() {
                for (c, v) in face.iter().enumerate() {
                    if moving.contains(v) {
                        map.entry(*v).or_default().push((f, c));
                    }
                }
            }
            map
        };
        let (after, before) = (corners_of(&out), corners_of(self));
        // The normal Blender keeps for a face round a region point: a region face's own, a
        // strip quad's the region face's across one of its edges at the point.
        let face_normal = |g: usize, c: usize| -> DVec3 {
            if region.contains(&g) {
                return normal_of(g);
            }
            let face = &out.faces[g];
            let n = face.len();
            let (v, next, prev) = (face[c], face[(c + 1) % n], face[(c + n - 1) % n]);
            match region_half
                .get(&(next, v))
                .or_else(|| region_half.get(&(v, prev)))
            {
                Some(&f) => normal_of(f),
                None => polygon_normal(&out.points, face),
            }
        };
        let mut moved = Vec::with_capacity(points.len());
        for &v in &points {
            let normal = match border.get(&v) {
                Some(sum) => sum.normalize_or_zero(),
                None => before
                    .get(&v)
                    .into_iter()
                    .flatten()
                    .map(|&(f, c)| normal_of(f) * angle_at(self, &self.faces[f], c))
                    .sum::<DVec3>()
                    .normalize_or_zero(),
            };
            let (mut shell, mut angles) = (0.0, 0.0);
            for &(g, c) in after.get(&v).into_iter().flatten() {
                let angle = angle_at(&out, &out.faces[g], c);
                let cos = normal.dot(face_normal(g, c)).abs();
                shell += angle * if cos < 1e-8 { 1.0 } else { 1.0 / cos };
                angles += angle;
            }
            let factor = if angles > 0.0 { shell / angles } else { 1.0 };
            moved.push(out.points[v as usize] + normal * (depth * factor));
        }
        for (&v, p) in points.iter().zip(moved) {
            out.points[v as usize] = p;
        }
        Ok(out)
    }

    /// Inset of a region (Blender's Inset Faces, even offset, boundary on): the region's border
    /// moves into the region by `thickness` (each border edge square to itself in its face's
    /// plane, the corners where two border edges meet moved along their bisector by the even
    /// factor). The region keeps its vertices, moved; new vertices take the border's old
    /// places, the faces outside are joined to them, and a strip of quads lies between.
    pub fn inset_region(&self, faces: &[usize], thickness: f64) -> Result<Self, CageEditError> {
        let region = self.check_faces(faces)?;
        check_thickness(thickness)?;
        let in_region: HashSet<usize> = region.iter().copied().collect();
        let half = self.half_edges();
        // Border half-edges of region faces: (from, to) ↦ (face, inward direction).
        let mut border: BTreeMap<(u32, u32), (usize, DVec3)> = BTreeMap::new();
        for &f in &region {
            let face = &self.faces[f];
            let inward = self.inward_directions(face);
            for c in 0..face.len() {
                let (a, b) = (face[c], face[(c + 1) % face.len()]);
                let on_border = half
                    .get(&(b, a))
                    .is_none_or(|&(g, _)| !in_region.contains(&g));
                if on_border {
                    border.insert((a, b), (f, inward[c]));
                }
            }
        }
        if border.is_empty() {
            return Err(CageEditError::RegionWithoutBorder);
        }
        // Each border vertex's sectors: the runs of region faces round it from a border edge
        // arriving to the border edge leaving, with the vertex moved along their bisector.
        let mut sectors: BTreeMap<u32, Vec<(Vec<usize>, DVec3)>> = BTreeMap::new();
        for (&(_, v), &(f, arriving)) in &border {
            let mut faces = vec![f];
            let mut at = f;
            let leaving = loop {
                let face = &self.faces[at];
                let Some(c) = face.iter().position(|&x| x == v) else {
                    return Err(invalid(format!("vertex {v} cannot be inset")));
                };
                let w = face[(c + 1) % face.len()];
                if let Some(&(_, d)) = border.get(&(v, w)) {
                    break d;
                }
                match half.get(&(w, v)) {
                    Some(&(g, _)) if in_region.contains(&g) && faces.len() <= region.len() => {
                        faces.push(g);
                        at = g;
                    }
                    _ => return Err(invalid(format!("vertex {v} cannot be inset"))),
                }
            };
            let step = (arriving + leaving).normalize_or_zero()
                * even_offset_factor(arriving, leaving)
                * thickness;
            sectors.entry(v).or_default().push((faces, step));
        }
        let mut out = self.clone();
        let mut copy: HashMap<u32, u32> = HashMap::default();
        let mut inner: HashMap<(u32, usize), u32> = HashMap::default();
        for (&v, list) in &mut sectors {
            // The original vertex goes with the sector of the last face; the others are new.
            list.sort_by_key(|(faces, _)| std::cmp::Reverse(faces.iter().max().copied()));
            copy.insert(v, out.points.len() as u32);
            out.points.push(self.points[v as usize]);
            for (k, (faces, step)) in list.iter().enumerate() {
                let moved = self.points[v as usize] + *step;
                let id = if k == 0 {
                    out.points[v as usize] = moved;
                    v
                } else {
                    out.points.push(moved);
                    (out.points.len() - 1) as u32
                };
                for &f in faces {
                    inner.insert((v, f), id);
                }
            }
        }
        for (f, face) in out.faces.iter_mut().enumerate() {
            for v in face.iter_mut() {
                let to = if in_region.contains(&f) {
                    inner.get(&(*v, f))
                } else {
                    copy.get(v)
                };
                if let Some(&c) = to {
                    *v = c;
                }
            }
        }
        let sharp = self.sharpness_of_edges();
        for (&(a, b), &(f, _)) in &border {
            let (ia, ib) = (inner[&(a, f)], inner[&(b, f)]);
            out.faces.push(vec![copy[&a], copy[&b], ib, ia]);
            // The outer edge keeps the crease the border had.
            if let Some(&s) = sharp.get(&key(a, b)) {
                out.add_crease(copy[&a], copy[&b], s);
            }
        }
        out.copy_corners(&self.corners, &copy);
        Ok(out.compacted(self))
    }

    /// The edge ring through edge a–b: from quad to quad across opposite edges, both ways,
    /// until an open edge, a face that is not a quad, or the ring closes. Each entry is an edge
    /// (as the directed pair of the first quad that reached it) and the quads it was crossed
    /// through are returned beside.
    pub(super) fn edge_ring(&self, a: u32, b: u32) -> (Vec<(u32, u32)>, Vec<usize>) {
        self.edge_ring_in(&self.half_edges(), a, b)
    }

    /// [`Self::edge_ring`] with the cage's [`Self::half_edges`] already at hand.
    fn edge_ring_in(&self, half: &HalfEdges, a: u32, b: u32) -> (Vec<(u32, u32)>, Vec<usize>) {
        let mut edges = vec![(a, b)];
        let mut quads = Vec::new();
        let mut seen_edges: HashSet<(u32, u32)> = HashSet::from_iter([key(a, b)]);
        let mut seen_faces = HashSet::default();
        // Walk each way: first through the face holding a→b, then through the one holding b→a.
        let mut backward = Vec::new();
        for (start, list) in [((a, b), 0), ((b, a), 1)] {
            let mut at = start;
            while let Some(&(f, c)) = half.get(&at) {
                let face = &self.faces[f];
                if face.len() != 4 || !seen_faces.insert(f) {
                    break;
                }
                quads.push(f);
                // The opposite edge, in the same direction along the ring's cut lines.
                let (p, q) = (face[(c + 3) % 4], face[(c + 2) % 4]);
                if !seen_edges.insert(key(p, q)) {
                    break;
                }
                if list == 0 {
                    edges.push((p, q));
                } else {
                    backward.push((p, q));
                }
                at = (p, q);
            }
        }
        backward.reverse();
        backward.extend(edges);
        (backward, quads)
    }

    /// Loop cut (Blender's Loop Cut, even): the edge ring through edge a–b is cut `cuts` times at
    /// equal fractions, and every quad of the ring becomes `cuts + 1` quads across it. A face at
    /// an end of an open ring that is not a quad takes the new points into its edge. A crease
    /// on a ring edge goes to each of its pieces. An edge with no quad on either side has no
    /// ring to cut ([`CageEditError::RingWithoutQuads`]).
    pub fn loop_cut(&self, a: u32, b: u32, cuts: u32) -> Result<Self, CageEditError> {
        self.loop_cut_slid(a, b, cuts, 0.0)
    }

    /// [`Self::loop_cut`], its new loops slid together along the ring (Blender's Loop Cut and
    /// Slide with its edge slide factor `slide`, −1 < slide < 1): each cut edge's new points
    /// lie at the fractions (i + slide) / (cuts + 1), i = 1 … cuts, of the way from its end on
    /// a's side of the ring to its end on b's side, so that one cut moves from the middle
    /// towards b's side by `slide` of the half edge, and several move by `slide` of their
    /// spacing. Slid, the ring's two sides must part (as they do for every ring a loop cut
    /// accepts but ones whose rim breaks into more than two pieces, which are refused).
    pub fn loop_cut_slid(
        &self,
        a: u32,
        b: u32,
        cuts: u32,
        slide: f64,
    ) -> Result<Self, CageEditError> {
        let half = self.half_edges();
        self.check_edge(&half, a, b)?;
        if cuts == 0 || cuts > 1000 {
            return Err(invalid(format!("cuts must be 1 to 1000 (got {cuts})")));
        }
        if !(slide > -1.0 && slide < 1.0) {
            return Err(invalid(format!(
                "the slide must lie between -1 and 1, not {slide}"
            )));
        }
        let (ring, quads) = self.edge_ring_in(&half, a, b);
        if quads.is_empty() {
            return Err(CageEditError::RingWithoutQuads { a, b });
        }
        // Each quad of the ring is crossed through one pair of opposite edges and no other
        // edge of it is cut: else the ring came back across it.
        let cut: HashSet<(u32, u32)> = ring.iter().map(|&(p, q)| key(p, q)).collect();
        for &f in &quads {
            let face = &self.faces[f];
            let crossed: Vec<bool> = (0..4)
                .map(|c| cut.contains(&key(face[c], face[(c + 1) % 4])))
                .collect();
            let opposite_pair =
                crossed == [true, false, true, false] || crossed == [false, true, false, true];
            if !opposite_pair {
                return Err(CageEditError::RingCrossesItself { a, b, face: f });
            }
        }
        // Blender's rim: the edges other than ring edges of every face of at most four sides
        // holding two ring edges. Its loop cut pairs the rim's edge loops, and a rim vertex
        // of more than two rim edges breaks them.
        let mut sides: HashSet<usize> = HashSet::default();
        let mut rim: HashSet<(u32, u32)> = HashSet::default();
        for &(p, q) in &ring {
            for f in [half.get(&(p, q)), half.get(&(q, p))].into_iter().flatten() {
                let face = &self.faces[f.0];
                let edges: Vec<(u32, u32)> = (0..face.len())
                    .map(|c| key(face[c], face[(c + 1) % face.len()]))
                    .collect();
                let ring_edges = edges.iter().filter(|e| cut.contains(e)).count();
                if face.len() <= 4 && ring_edges >= 2 && sides.insert(f.0) {
                    rim.extend(edges.into_iter().filter(|e| !cut.contains(e)));
                }
            }
        }
        let mut rim_edges_at: HashMap<u32, usize> = HashMap::default();
        for &(p, q) in &rim {
            *rim_edges_at.entry(p).or_default() += 1;
            *rim_edges_at.entry(q).or_default() += 1;
        }
        if let Some(vertex) = rim_edges_at
            .iter()
            .filter(|&(_, &n)| n > 2)
            .map(|(&v, _)| v)
            .min()
        {
            return Err(CageEditError::RingTouchesItself { a, b, vertex });
        }
        // The rim's two sides; where they join into one, Blender finds no pair to cut between.
        let mut side_of: Vec<usize> = (0..self.points.len()).collect();
        for &(p, q) in &rim {
            let (rp, rq) = (
                root(&mut side_of, p as usize),
                root(&mut side_of, q as usize),
            );
            side_of[rp.max(rq)] = rp.min(rq);
        }
        let sides_found: HashSet<usize> = rim_edges_at
            .keys()
            .map(|&v| root(&mut side_of, v as usize))
            .collect();
        if sides_found.len() == 1 {
            return Err(CageEditError::RingSidesJoin { a, b });
        }
        // Blender cuts every edge from one side to the other, not only the ring's: an edge
        // across that is no ring edge gives its faces the new points.
        let mut cut_list = ring.clone();
        if sides_found.len() == 2 {
            let mut across: Vec<(u32, u32)> = half
                .keys()
                .map(|(p, q)| key(p, q))
                .filter(|&(p, q)| {
                    !cut.contains(&(p, q))
                        && rim_edges_at.contains_key(&p)
                        && rim_edges_at.contains_key(&q)
                        && root(&mut side_of, p as usize) != root(&mut side_of, q as usize)
                })
                .collect();
            across.sort_unstable();
            across.dedup();
            cut_list.extend(across);
        }
        let mut out = self.clone();
        let inner = self.cut_edges(&mut out, &cut_list, cuts);
        if slide != 0.0 {
            // Each cut edge's end on a's side, found by the rim's side it lies on.
            let (side_a, side_b) = (
                root(&mut side_of, a as usize),
                root(&mut side_of, b as usize),
            );
            if sides_found.len() != 2 || side_a == side_b {
                return Err(invalid(format!(
                    "the ring through {a}-{b} does not part into two sides to slide along"
                )));
            }
            let step = 1.0 / f64::from(cuts + 1);
            for (&(lo, hi), list) in &inner {
                let (from, to) = if root(&mut side_of, lo as usize) == side_a {
                    (lo, hi)
                } else if root(&mut side_of, hi as usize) == side_a {
                    (hi, lo)
                } else {
                    return Err(invalid(format!(
                        "edge {lo}-{hi} of the ring through {a}-{b} has no end on {a}'s side"
                    )));
                };
                let (p, q) = (self.points[from as usize], self.points[to as usize]);
                // The list runs from the lower-numbered end.
                for (k, &v) in list.iter().enumerate() {
                    let i = if from == lo { k + 1 } else { list.len() - k };
                    let t = (i as f64 + slide) * step;
                    out.points[v as usize] = p + (q - p) * t;
                }
            }
        }
        let along = |p: u32, q: u32| chain_along(&inner, p, q);
        let quad_set: HashSet<usize> = quads.iter().copied().collect();
        let mut added = Vec::new();
        for (f, face) in self.faces.iter().enumerate() {
            if quad_set.contains(&f) {
                // Rotate so the ring crosses edges (c0, c1) and (c2, c3).
                let r = (0..4)
                    .find(|&r| {
                        inner.contains_key(&key(face[r], face[(r + 1) % 4]))
                            && inner.contains_key(&key(face[(r + 2) % 4], face[(r + 3) % 4]))
                    })
                    .unwrap_or(0);
                let c = |k: usize| face[(r + k) % 4];
                let (Some(x), Some(y)) = (along(c(0), c(1)), along(c(3), c(2))) else {
                    continue;
                };
                let pieces: Vec<Vec<u32>> = (0..x.len() - 1)
                    .map(|i| vec![x[i], x[i + 1], y[i + 1], y[i]])
                    .collect();
                let mut pieces = pieces.into_iter();
                if let Some(first) = pieces.next() {
                    out.faces[f] = first;
                }
                added.extend(pieces);
            } else {
                // A face beside the ring's end takes the new points into its edge.
                out.faces[f] = grown_by_cuts(face, &inner);
            }
        }
        out.faces.extend(added);
        Ok(out.compacted(self))
    }

    /// Cuts each edge into `cuts + 1` equal pieces: the new points, listed from the edge's
    /// lower-numbered end, are added to `out`, and each piece keeps the edge's sharpness.
    fn cut_edges(
        &self,
        out: &mut Cage,
        edges: &[(u32, u32)],
        cuts: u32,
    ) -> HashMap<(u32, u32), Vec<u32>> {
        let sharp = self.sharpness_of_edges();
        let mut inner: HashMap<(u32, u32), Vec<u32>> = HashMap::default();
        for &(p, q) in edges {
            let (lo, hi) = key(p, q);
            if inner.contains_key(&(lo, hi)) {
                continue;
            }
            let (pl, ph) = (self.points[lo as usize], self.points[hi as usize]);
            let first = out.points.len() as u32;
            for i in 1..=cuts {
                let t = f64::from(i) / f64::from(cuts + 1);
                out.points.push(pl + (ph - pl) * t);
            }
            let list: Vec<u32> = (first..first + cuts).collect();
            if let Some(&s) = sharp.get(&(lo, hi)) {
                let chain: Vec<u32> = std::iter::once(lo)
                    .chain(list.iter().copied())
                    .chain(std::iter::once(hi))
                    .collect();
                for w in chain.windows(2) {
                    out.add_crease(w[0], w[1], s);
                }
            }
            inner.insert((lo, hi), list);
        }
        inner
    }

    /// Subdivide faces (Blender's Subdivide with grid fill, smoothness 0): every edge of the
    /// named faces is cut into `cuts + 1` equal pieces, and every triangle and quad all of
    /// whose edges are cut (the named ones, and any other the cut edges close round) is
    /// filled with the grid of (cuts + 1)² quads or triangles whose inner points lie evenly
    /// on the lines between its sides' points (bilinear on a quad, barycentric on a
    /// triangle). Any other face with two cut edges is split by straight lines between their
    /// points ([`straight_cuts`]: strips across a quad cut on opposite sides, the corner cut
    /// off where they meet), as is a triangle or quad with more; faces with one cut edge, and
    /// polygons of five or more sides with three or more, take the new points into them; a
    /// quad with three cut sides is split by Blender's pattern for it
    /// ([`quad_three_cut_sides`]). The first piece takes the face's index; the rest
    /// follow.
    pub fn subdivide_faces(&self, faces: &[usize], cuts: u32) -> Result<Self, CageEditError> {
        let faces = self.check_faces(faces)?;
        if cuts == 0 || cuts > 100 {
            return Err(invalid(format!("cuts must be 1 to 100 (got {cuts})")));
        }
        let mut edges = Vec::new();
        for &f in &faces {
            let face = &self.faces[f];
            edges.extend((0..face.len()).map(|c| (face[c], face[(c + 1) % face.len()])));
        }
        let mut out = self.clone();
        let inner = self.cut_edges(&mut out, &edges, cuts);
        let along = |p: u32, q: u32| chain_along(&inner, p, q);
        let n = cuts as usize + 1;
        let mut added = Vec::new();
        for (f, face) in self.faces.iter().enumerate() {
            let all_cut = (0..face.len())
                .all(|c| inner.contains_key(&key(face[c], face[(c + 1) % face.len()])));
            let mut pieces: Vec<Vec<u32>> = Vec::new();
            match (all_cut, face.as_slice()) {
                (true, &[c0, c1, c2, c3]) => {
                    let (Some(top), Some(bottom), Some(left), Some(right)) =
                        (along(c0, c1), along(c3, c2), along(c0, c3), along(c1, c2))
                    else {
                        continue;
                    };
                    // grid[i][j]: i from side c0–c1 towards c3–c2, j from c0–c3 towards c1–c2.
                    let mut grid = vec![vec![0u32; n + 1]; n + 1];
                    for i in 0..=n {
                        for j in 0..=n {
                            grid[i][j] = match (i, j) {
                                (0, _) => top[j],
                                (_, 0) => left[i],
                                _ if i == n => bottom[j],
                                _ if j == n => right[i],
                                _ => {
                                    let (a, b) = (
                                        out.points[left[i] as usize],
                                        out.points[right[i] as usize],
                                    );
                                    out.points.push(a.lerp(b, j as f64 / n as f64));
                                    (out.points.len() - 1) as u32
                                }
                            };
                        }
                    }
                    for i in 0..n {
                        for j in 0..n {
                            pieces.push(vec![
                                grid[i][j],
                                grid[i][j + 1],
                                grid[i + 1][j + 1],
                                grid[i + 1][j],
                            ]);
                        }
                    }
                }
                (true, &[a, b, c]) => {
                    let (Some(ab), Some(ac), Some(bc)) = (along(a, b), along(a, c), along(b, c))
                    else {
                        continue;
                    };
                    // rows[r][s]: r steps from a towards b–c, s from side a–b towards a–c.
                    let mut rows: Vec<Vec<u32>> = Vec::with_capacity(n + 1);
                    for r in 0..=n {
                        let row: Vec<u32> = (0..=r)
                            .map(|s| match s {
                                0 => ab[r],
                                _ if s == r => ac[r],
                                _ if r == n => bc[s],
                                _ => {
                                    let (p, q) =
                                        (out.points[ab[r] as usize], out.points[ac[r] as usize]);
                                    out.points.push(p.lerp(q, s as f64 / r as f64));
                                    (out.points.len() - 1) as u32
                                }
                            })
                            .collect();
                        rows.push(row);
                    }
                    for r in 0..n {
                        for s in 0..=r {
                            pieces.push(vec![rows[r][s], rows[r + 1][s], rows[r + 1][s + 1]]);
                            if s < r {
                                pieces.push(vec![rows[r][s], rows[r + 1][s + 1], rows[r][s + 1]]);
                            }
                        }
                    }
                }
                _ => pieces = straight_cuts(face, &inner, n - 1),
            }
            if pieces.is_empty() {
                pieces.push(grown_by_cuts(face, &inner));
            }
            let mut pieces = pieces.into_iter();
            if let Some(first) = pieces.next() {
                out.faces[f] = first;
            }
            added.extend(pieces);
        }
        out.faces.extend(added);
        Ok(out.compacted(self))
    }

    /// Delete faces (Blender's Delete Faces): the faces go, and so do the vertices only they
    /// used.
    pub fn delete_faces(&self, faces: &[usize]) -> Result<Self, CageEditError> {
        let region: HashSet<usize> = self.check_faces(faces)?.into_iter().collect();
        let mut out = self.clone();
        out.faces = self
            .faces
            .iter()
            .enumerate()
            .filter(|(f, _)| !region.contains(f))
            .map(|(_, face)| face.clone())
            .collect();
        if out.faces.is_empty() {
            return Err(invalid("deleting every face would leave an empty cage"));
        }
        Ok(out.compacted(self))
    }

    /// Merge vertices (Blender's Merge, at centre or at first): every named vertex becomes the
    /// first one named, placed at their centroid or where the first is, by Blender's weld
    /// ([`Self::welded`]): a face holding the first and another named vertex apart splits
    /// between them, faces lose the corners that fall together, and a face left with fewer
    /// than three, or passing a vertex twice, goes.
    pub fn merge_vertices(&self, vertices: &[u32], at_first: bool) -> Result<Self, CageEditError> {
        let mut named: Vec<u32> = Vec::with_capacity(vertices.len());
        let mut seen = HashSet::default();
        for &v in vertices {
            self.check_vertex(v)?;
            if seen.insert(v) {
                named.push(v);
            }
        }
        let Some(&keep) = named.first() else {
            return Err(invalid("no vertices were named"));
        };
        let mut out = self.clone();
        if !at_first {
            let sum: DVec3 = named.iter().map(|&v| self.points[v as usize]).sum();
            out.points[keep as usize] = sum / named.len() as f64;
        }
        let gone: HashSet<u32> = named[1..].iter().copied().collect();
        out.welded(self, |v| if gone.contains(&v) { keep } else { v })
    }

    /// The cage (`self`, its points already moved) with every vertex `v` replaced by `to(v)`
    /// (Blender's Weld Verts): a face holding a merged vertex and, not beside it, the vertex
    /// it merges into is first split between the two ([`split_at_targets`]); then each face
    /// loses the corners that fall together, and goes where it would pass a corner twice or
    /// keep fewer than three ([`welded_face`]); of two faces over the same corners the first
    /// stays. `to` maps a vertex that stays to itself. `before` is the cage the tool started
    /// from.
    pub(super) fn welded(
        mut self,
        before: &Self,
        to: impl Fn(u32) -> u32,
    ) -> Result<Self, CageEditError> {
        let mut faces = Vec::with_capacity(self.faces.len());
        for face in &self.faces {
            let mut pieces = Vec::new();
            split_at_targets(face.clone(), &to, &mut pieces);
            faces.extend(
                pieces
                    .into_iter()
                    .filter_map(|piece| welded_face(&piece, &to)),
            );
        }
        // Two faces over the same corners after the merge are one face twice: keep the first.
        let mut seen = HashSet::default();
        faces.retain(|f: &Vec<u32>| {
            let mut sorted = f.clone();
            sorted.sort_unstable();
            seen.insert(sorted)
        });
        self.faces = faces;
        for c in &mut self.creases {
            (c.a, c.b) = (to(c.a), to(c.b));
        }
        self.creases.retain(|c| c.a != c.b);
        for c in &mut self.corners {
            c.vertex = to(c.vertex);
        }
        if self.faces.is_empty() {
            return Err(invalid("merging these vertices would leave no face"));
        }
        Ok(self.compacted(before))
    }

    /// Dissolve faces (Blender's Dissolve Faces, dissolving vertices too): each region of
    /// named faces joined by edges becomes one face, the edges between two named faces
    /// dissolved, and every end of those edges then left between two edges (and not so
    /// before) is dissolved too. Named faces that share no edge are refused.
    pub fn dissolve_faces(&self, faces: &[usize]) -> Result<Self, CageEditError> {
        let faces = self.check_faces(faces)?;
        let named: HashSet<usize> = faces.iter().copied().collect();
        let half = self.half_edges();
        let mut inner = Vec::new();
        for &f in &faces {
            let face = &self.faces[f];
            for c in 0..face.len() {
                let (a, b) = (face[c], face[(c + 1) % face.len()]);
                if a < b && half.get(&(b, a)).is_some_and(|&(g, _)| named.contains(&g)) {
                    inner.push((a, b));
                }
            }
        }
        if inner.is_empty() {
            return Err(invalid(
                "the named faces share no edge: there is nothing to dissolve",
            ));
        }
        let gone: HashSet<(u32, u32)> = inner.iter().copied().collect();
        let new_faces = self.joined_across(&half, &gone)?;
        // Blender's dissolve of faces (unlike its dissolve of edges) takes out every end of
        // a dissolved edge that is left between two edges, unless it was already.
        let ends = inner.iter().flat_map(|&(a, b)| [a, b]);
        let marked = neighbours_in(&self.faces, ends)
            .into_iter()
            .filter(|(_, n)| n.len() != 2)
            .map(|(v, _)| v)
            .collect();
        let faces: Vec<Vec<u32>> = new_faces.into_iter().flatten().collect();
        self.with_faces_lone_removed(faces, marked)
    }

    /// The named edges that have a face on each side, in the order named, each once (an
    /// edge named again, either way round, is the same edge): border edges (one face) are
    /// passed over, as Blender's bevel and dissolve pass over them. Every edge must be in the
    /// cage; where every one is on the border, the `tool` would leave the cage as it is
    /// ([`CageEditError::EveryEdgeOnBorder`]).
    fn inner_edges(
        &self,
        half: &HalfEdges,
        edges: &[(u32, u32)],
        tool: &'static str,
    ) -> Result<Vec<(u32, u32)>, CageEditError> {
        let mut inner = Vec::with_capacity(edges.len());
        let mut seen = HashSet::default();
        for &(a, b) in edges {
            self.check_edge(half, a, b)?;
            if half.contains_key(&(a, b)) && half.contains_key(&(b, a)) && seen.insert(key(a, b)) {
                inner.push((a, b));
            }
        }
        match (inner.is_empty(), edges.first()) {
            (true, Some(&(a, b))) => Err(CageEditError::EveryEdgeOnBorder { tool, a, b }),
            _ => Ok(inner),
        }
    }

    /// Dissolve edges (Blender's Dissolve Edges, dissolving vertices too): the faces on both
    /// sides of each edge become one face (the lowest-numbered of them keeps its index and its
    /// winding), and each end of a dissolved edge that is left between only two edges is
    /// dissolved as well. A dissolve that would leave a face with a hole is refused. Named
    /// border edges (one face) are passed over, as Blender's dissolve passes over them.
    pub fn dissolve_edges(&self, edges: &[(u32, u32)]) -> Result<Self, CageEditError> {
        if edges.is_empty() {
            return Err(invalid("no edges were named"));
        }
        let half = self.half_edges();
        let inner = self.inner_edges(&half, edges, "dissolve")?;
        let gone: HashSet<(u32, u32)> = inner.iter().map(|&(a, b)| key(a, b)).collect();
        let new_faces = self.joined_across(&half, &gone)?;
        // Which ends of the dissolved edges go too, decided on the cage before the dissolve
        // (Blender's rules): not a corner between two triangles being joined into a quad, and
        // not a vertex where several named edges meet beside a face that keeps both its
        // edges there; of those, the ones left between only two edges. Named border edges
        // count here as Blender counts them, though no faces join across them.
        let named: HashSet<(u32, u32)> = edges.iter().map(|&(a, b)| key(a, b)).collect();
        let dissolved_at = |v: u32| named.iter().filter(|&&(a, b)| a == v || b == v).count();
        let keeps_a_face = |v: u32| {
            self.faces.iter().any(|face| {
                let k = face.len();
                (0..k).any(|c| {
                    face[c] == v
                        && !named.contains(&key(face[(c + k - 1) % k], v))
                        && !named.contains(&key(v, face[(c + 1) % k]))
                })
            })
        };
        let mut marked = HashSet::default();
        for &(a, b) in &inner {
            let (Some(&(f, _)), Some(&(g, _))) = (half.get(&(a, b)), half.get(&(b, a))) else {
                continue;
            };
            let triangles = self.faces[f].len() == 3 && self.faces[g].len() == 3;
            for v in [a, b] {
                let count = dissolved_at(v);
                if (triangles && count == 1) || (count != 1 && keeps_a_face(v)) {
                    continue;
                }
                marked.insert(v);
            }
        }
        let faces: Vec<Vec<u32>> = new_faces.into_iter().flatten().collect();
        self.with_faces_lone_removed(faces, marked)
    }

    /// The cage with `faces` (a dissolve's joined faces), each of the `candidates` left
    /// between only two edges taken out of its faces (Blender's dissolve of the vertices
    /// between two edges). A face left with fewer than three corners goes, as Blender's
    /// vertex collapse folds its two sides into one edge (a cone's side triangle when the
    /// base edge beside it is dissolved), and of two faces left over the same corners the
    /// first stays; a dissolve leaving no face is refused.
    pub(super) fn with_faces_lone_removed(
        &self,
        mut faces: Vec<Vec<u32>>,
        candidates: HashSet<u32>,
    ) -> Result<Self, CageEditError> {
        let lone: HashSet<u32> = neighbours_in(&faces, candidates.into_iter())
            .into_iter()
            .filter(|(_, n)| n.len() == 2)
            .map(|(v, _)| v)
            .collect();
        if !lone.is_empty() {
            for face in &mut faces {
                face.retain(|v| !lone.contains(v));
            }
        }
        faces.retain(|face| face.len() >= 3);
        // Two faces left over the same corners (a tetrahedron's edge dissolved) are one
        // face, as Blender's collapse leaves one: the first stays.
        let faces = without_repeated_faces(faces);
        if faces.is_empty() {
            return Err(invalid("the dissolve would leave no face"));
        }
        let out = Self {
            points: self.points.clone(),
            faces,
            creases: self.creases.clone(),
            corners: self.corners.clone(),
        };
        Ok(out.compacted(self))
    }

    /// The faces after joining the faces on both sides of every edge in `gone` (each an
    /// interior edge, as `(low, high)`; `half`: the cage's [`Self::half_edges`]): each group
    /// of faces so joined becomes one face, its border walked from the lowest-numbered face's
    /// first kept corner, in that face's place; the others of the group become `None`. Every
    /// edge between two faces of a group goes, named or not, as Blender's face join takes it
    /// out (a cone's side triangles joined through the base lose the spoke between them). A
    /// group whose border still touches itself at a vertex or has a hole is refused.
    pub(super) fn joined_across(
        &self,
        half: &HalfEdges,
        gone: &HashSet<(u32, u32)>,
    ) -> Result<Vec<Option<Vec<u32>>>, CageEditError> {
        // Union-find over faces; only the faces on a dissolved edge can join others.
        let mut parent: Vec<usize> = (0..self.faces.len()).collect();
        let mut touched: Vec<usize> = Vec::new();
        for &(a, b) in gone {
            if let (Some(&(f, _)), Some(&(g, _))) = (half.get(&(a, b)), half.get(&(b, a))) {
                let (rf, rg) = (root(&mut parent, f), root(&mut parent, g));
                parent[rf.max(rg)] = rf.min(rg);
                touched.extend([f, g]);
            }
        }
        touched.sort_unstable();
        touched.dedup();
        let mut groups: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
        for f in touched {
            let r = root(&mut parent, f);
            groups.entry(r).or_default().push(f);
        }
        let mut new_faces: Vec<Option<Vec<u32>>> = self.faces.iter().cloned().map(Some).collect();
        for (group, members) in groups.into_iter().filter(|(_, m)| m.len() > 1) {
            // The group's border: its half-edges that are not dissolved and whose other side
            // is not in the group (Blender's join takes out every edge between two of the
            // faces it joins, named or not, and the points left on no edge with them).
            let mut next: HashMap<u32, u32> = HashMap::default();
            let mut start = None;
            for &f in &members {
                let face = &self.faces[f];
                for c in 0..face.len() {
                    let (a, b) = (face[c], face[(c + 1) % face.len()]);
                    let inside = half
                        .get(&(b, a))
                        .is_some_and(|&(g, _)| root(&mut parent, g) == group);
                    if inside || gone.contains(&key(a, b)) {
                        continue;
                    }
                    if next.insert(a, b).is_some() {
                        return Err(invalid(format!(
                            "the faces joined would make one face that touches itself at vertex {a}"
                        )));
                    }
                    if start.is_none() && f == members[0] {
                        start = Some(a);
                    }
                }
            }
            let Some(start) = start.or_else(|| next.keys().next().copied()) else {
                return Err(invalid("the faces joined would leave no face"));
            };
            let mut merged = vec![start];
            let mut at = start;
            while let Some(&b) = next.get(&at) {
                if b == start {
                    break;
                }
                merged.push(b);
                at = b;
                if merged.len() > next.len() {
                    break;
                }
            }
            if merged.len() != next.len() {
                return Err(invalid(
                    "the faces joined would make one face with a hole in it",
                ));
            }
            new_faces[members[0]] = Some(merged);
            for &f in &members[1..] {
                new_faces[f] = None;
            }
        }
        Ok(new_faces)
    }
}

/// The faces around a cage vertex in order: each face, the vertex's corner in it, and its
/// neighbours before and after it there; `None` where the vertex is on the border or its faces
/// do not close into one fan.
fn fan(
    faces: &[Vec<u32>],
    half: &HalfEdges,
    v: u32,
    start: (usize, usize),
) -> Option<Vec<(usize, u32, u32)>> {
    let mut out = Vec::new();
    let (mut f, mut c) = start;
    loop {
        let face = &faces[f];
        let k = face.len();
        let (prev, next) = (face[(c + k - 1) % k], face[(c + 1) % k]);
        out.push((f, prev, next));
        // The next face round holds next→v.
        let &(g, d) = half.get(&(next, v))?;
        let (g, d) = (g, (d + 1) % faces[g].len());
        if g == start.0 {
            return Some(out);
        }
        if out.len() > faces.len() {
            return None;
        }
        (f, c) = (g, d);
    }
}

/// A bevel band's end: the arc from side point `a` to side point `b` around the beveled edge.
/// Its middle m is the point of the edge's line nearest the line a–b (the vertex itself where
/// they are parallel), and the arc is the affine image of a quarter circle in the
/// parallelogram a, m, b: c + (a − c)·cos φ + (b − c)·sin φ with c = a + b − m. At an edge's
/// end where no other beveled edge meets it, the arc is then carried along the edge onto the
/// plane through a, b and the vertex (Blender's profile, superellipse exponent 2).
pub(super) struct Profile {
    a: DVec3,
    b: DVec3,
    centre: DVec3,
    /// The edge's direction and the plane's normal, where the arc is carried onto it.
    carry: Option<(DVec3, DVec3)>,
    /// A straight profile: points evenly spaced from a to b.
    straight: bool,
}

impl Profile {
    fn new(a: DVec3, b: DVec3, vertex: DVec3, along: DVec3, terminal: bool) -> Self {
        // The nearest points of the lines vertex + s·along and a + t·(b − a).
        let u = b - a;
        let w = vertex - a;
        let (dd, du, uu) = (along.dot(along), along.dot(u), u.dot(u));
        let denominator = dd * uu - du * du;
        let mut middle = if denominator > 1e-12 * dd * uu {
            vertex + along * ((du * u.dot(w) - uu * along.dot(w)) / denominator)
        } else {
            vertex
        };
        // Where a and b lie within 2° of one line through that point (either side of it, or
        // the same side, as where a and b coincide), Blender takes the vertex.
        let nearly_straight = std::f64::consts::PI - 2f64.to_radians();
        let in_line = |m: DVec3| {
            let angle = (a - m).angle_between(b - m);
            !(angle >= 2f64.to_radians() && angle <= nearly_straight)
        };
        if in_line(middle) {
            middle = vertex;
        }
        // Blender moves the profile's plane only where the plane through a, b and the vertex
        // is well defined and not (within 1e-4 in the cosine) the plane of the edge and
        // either a or b: else the arc stays where it is, in its own plane.
        let carry = terminal
            .then(|| {
                let (da, db) = (
                    (vertex - a).normalize_or_zero(),
                    (vertex - b).normalize_or_zero(),
                );
                let normal = da.cross(db);
                let (with_a, with_b) = (da.cross(along), db.cross(along));
                let defined = [normal, with_a, with_b].iter().all(|n| n.length() > 1e-4);
                let apart = |n: DVec3| {
                    normal.normalize_or_zero().dot(n.normalize_or_zero()).abs() < 1.0 - 1e-4
                };
                (defined && apart(with_a) && apart(with_b))
                    .then(|| (along, normal.normalize_or_zero()))
            })
            .flatten();
        // Blender draws a straight profile where a and b lie within 2° of a line through the
        // middle (its unit-square map is then degenerate): evenly spaced points.
        let straight = in_line(middle);
        Self {
            a,
            b,
            centre: a + b - middle,
            carry: if straight { None } else { carry },
            straight,
        }
    }

    /// The profile of a side of a corner of three or more beveled edges, from `a` to `b`
    /// across the edge along `along` from the vertex. Its middle is the edge line's point
    /// nearest the line a–b; where that lies within 2° of the line a–b, it is where the lines
    /// through a and b along the edges before and after round the vertex meet where both are
    /// beveled (`sides`), else the vertex, and the profile is straight where those lines are
    /// parallel or the middle still lies on the line (Blender's profile for a corner's side).
    fn corner_side(
        a: DVec3,
        b: DVec3,
        vertex: DVec3,
        along: DVec3,
        sides: Option<(DVec3, DVec3)>,
    ) -> Self {
        let nearly_straight = std::f64::consts::PI - 2f64.to_radians();
        let flat = |m: DVec3| {
            let angle = (a - m).angle_between(b - m);
            !(angle < nearly_straight && angle > 2f64.to_radians())
        };
        let straight = Self {
            a,
            b,
            centre: a,
            carry: None,
            straight: true,
        };
        let mut middle = nearest_on_line(vertex, along, a, b - a).unwrap_or(vertex);
        if flat(middle) {
            middle = vertex;
            if let Some((before, after)) = sides {
                let parallel = before.angle_between(after);
                if parallel < 2f64.to_radians() || parallel > nearly_straight {
                    return straight;
                }
                match nearest_on_line(a, before, b, after) {
                    Some(meet) => middle = meet,
                    None => return straight,
                }
            }
            if flat(middle) {
                return straight;
            }
        }
        Self {
            a,
            b,
            centre: a + b - middle,
            carry: None,
            straight: false,
        }
    }

    /// A vertex bevel's side: the arc from `a` to `b` in the parallelogram a, `vertex`, b (its
    /// middle the vertex), straight where a and b lie within 2° of a line through the vertex.
    pub(super) fn round_corner(a: DVec3, b: DVec3, vertex: DVec3) -> Self {
        let angle = (a - vertex).angle_between(b - vertex);
        let straight =
            !(angle < std::f64::consts::PI - 2f64.to_radians() && angle > 2f64.to_radians());
        Self {
            a,
            b,
            centre: if straight { a } else { a + b - vertex },
            carry: None,
            straight,
        }
    }

    /// The corner of the parallelogram the arc is drawn in (its middle's control point), or
    /// the midpoint of a straight profile.
    fn middle(&self) -> DVec3 {
        if self.straight {
            self.a.midpoint(self.b)
        } else {
            self.a + self.b - self.centre
        }
    }

    /// The arc's point at `t` in [0, 1] (φ = π/2 · t).
    pub(super) fn at(&self, t: f64) -> DVec3 {
        if self.straight {
            return self.a.lerp(self.b, t);
        }
        let phi = std::f64::consts::FRAC_PI_2 * t;
        let q =
            self.centre + (self.a - self.centre) * phi.cos() + (self.b - self.centre) * phi.sin();
        match self.carry {
            Some((along, normal)) => q + along * ((self.a - q).dot(normal) / along.dot(normal)),
            None => q,
        }
    }
}

/// The points of edge p→q in that direction, its ends included, where it was cut (`inner`:
/// each cut edge's new points from its lower-numbered end).
fn chain_along(inner: &HashMap<(u32, u32), Vec<u32>>, p: u32, q: u32) -> Option<Vec<u32>> {
    let list = inner.get(&key(p, q))?;
    let mut chain = Vec::with_capacity(list.len() + 2);
    chain.push(p);
    if p < q {
        chain.extend(list.iter().copied());
    } else {
        chain.extend(list.iter().rev().copied());
    }
    chain.push(q);
    Some(chain)
}

/// The pieces of a face two or more of whose edges are cut and no grid fills (Blender's
/// Subdivide with straight-cut corners): the face, its cut points taken in, is split by
/// straight lines from the points of its first cut edge (in its order) to those of the next,
/// the first point to the last, the second to the one before, and so on. Empty where fewer
/// than two edges are cut, or more than two of a polygon of five or more sides.
fn straight_cuts(
    face: &[u32],
    inner: &HashMap<(u32, u32), Vec<u32>>,
    cuts: usize,
) -> Vec<Vec<u32>> {
    let is_cut =
        |c: usize| inner.contains_key(&key(face[c % face.len()], face[(c + 1) % face.len()]));
    let cut_edges = (0..face.len()).filter(|&c| is_cut(c)).count();
    if cut_edges < 2 {
        return Vec::new();
    }
    if face.len() == 4 && cut_edges == 3 {
        return quad_three_cut_sides(face, inner, cuts);
    }
    // Blender splits a polygon of five or more sides only where exactly two of its edges
    // are cut; with more it takes the points into its edges.
    if face.len() > 4 && cut_edges > 2 {
        return Vec::new();
    }
    let ring = grown_by_cuts(face, inner);
    let original: HashSet<u32> = face.iter().copied().collect();
    let len = ring.len();
    let is_new = |k: usize| !original.contains(&ring[k % len]);
    let starts = |k: usize| !is_new(k + len - 1) && is_new(k);
    let Some(mut a) = (1..len).find(|&k| starts(k)) else {
        return Vec::new();
    };
    let mut b = if is_new(a + cuts + 1) {
        (a + cuts + 1) % len
    } else {
        match (0..len)
            .map(|j| (j + a + cuts + 1) % len)
            .find(|&k| starts(k))
        {
            Some(k) => k,
            None => return Vec::new(),
        }
    };
    b = (b + cuts - 1) % len;
    let mut chords = Vec::with_capacity(cuts);
    for _ in 0..cuts {
        chords.push((a, b));
        a = (a + 1) % len;
        b = (b + len - 1) % len;
    }
    let walk = |from: usize, to: usize| loop_between(&ring, from, to);
    let (first, last) = (chords[0], chords[cuts - 1]);
    let mut pieces = vec![walk(first.1, first.0)];
    for w in chords.windows(2) {
        pieces.push(vec![ring[w[0].0], ring[w[1].0], ring[w[1].1], ring[w[0].1]]);
    }
    pieces.push(walk(last.0, last.1));
    pieces
}

/// The pieces of a quad three of whose sides are cut (Blender's Subdivide pattern for it):
/// with the sides taken from the one after the uncut side, points v listed as side 0's cuts,
/// its end corner, side 1's cuts, its end corner, side 2's cuts and the two corners left,
/// straight lines join side 1's points to side 0's and side 2's (the middle one, for an odd
/// number of cuts, to both) and side 0's to side 2's, each splitting the smallest piece that
/// holds both ends.
fn quad_three_cut_sides(
    face: &[u32],
    inner: &HashMap<(u32, u32), Vec<u32>>,
    n: usize,
) -> Vec<Vec<u32>> {
    let Some(uncut) = (0..4).find(|&c| !inner.contains_key(&key(face[c], face[(c + 1) % 4])))
    else {
        return Vec::new();
    };
    let corner = |k: usize| face[(uncut + 1 + k) % 4];
    let mut v: Vec<u32> = Vec::with_capacity(3 * n + 4);
    for side in 0..3 {
        let Some(chain) = chain_along(inner, corner(side), corner(side + 1)) else {
            return Vec::new();
        };
        v.extend_from_slice(&chain[1..]);
    }
    v.push(corner(0));
    let mut lines = Vec::new();
    let mut add = 0;
    for i in 0..n {
        if i == n / 2 {
            if n % 2 == 1 {
                lines.push((v[n - i - 1 + add], v[i + n + 1]));
            }
            add = 2 * n + 2;
        }
        lines.push((v[n - i - 1 + add], v[i + n + 1]));
    }
    for i in 0..n / 2 + 1 {
        lines.push((v[i], v[(n - i) + 2 * n + 1]));
    }
    let mut pieces = vec![grown_by_cuts(face, inner)];
    for (a, b) in lines {
        // The smallest piece holding both ends, where they are not already neighbours.
        let found = pieces
            .iter()
            .enumerate()
            .filter_map(|(k, piece)| {
                let i = piece.iter().position(|&x| x == a)?;
                let j = piece.iter().position(|&x| x == b)?;
                let len = piece.len();
                let neighbours = (i + 1) % len == j || (j + 1) % len == i;
                (!neighbours).then_some((k, i, j, len))
            })
            .min_by_key(|&(.., len)| len);
        let Some((k, i, j, _)) = found else {
            continue;
        };
        let piece = pieces[k].clone();
        pieces[k] = loop_between(&piece, i, j);
        pieces.push(loop_between(&piece, j, i));
    }
    pieces
}

/// The part of a closed loop from position `from` forward to position `to`, both included.
pub(super) fn loop_between(ring: &[u32], from: usize, to: usize) -> Vec<u32> {
    let mut out = vec![ring[from]];
    let mut at = from;
    while at != to {
        at = (at + 1) % ring.len();
        out.push(ring[at]);
    }
    out
}

/// A face with the new points of its cut edges taken into its loop.
pub(super) fn grown_by_cuts(face: &[u32], inner: &HashMap<(u32, u32), Vec<u32>>) -> Vec<u32> {
    let mut grown = Vec::with_capacity(face.len());
    for c in 0..face.len() {
        let (p, q) = (face[c], face[(c + 1) % face.len()]);
        grown.push(p);
        if let Some(chain) = chain_along(inner, p, q) {
            grown.extend_from_slice(&chain[1..chain.len() - 1]);
        }
    }
    grown
}

/// The point of the line p + s·d nearest the line q + t·e, or `None` where they are parallel.
fn nearest_on_line(p: DVec3, d: DVec3, q: DVec3, e: DVec3) -> Option<DVec3> {
    let w = p - q;
    let (dd, de, ee) = (d.dot(d), d.dot(e), e.dot(e));
    let denominator = dd * ee - de * de;
    (denominator > 1e-12 * dd * ee).then(|| p + d * ((de * e.dot(w) - ee * d.dot(w)) / denominator))
}

/// Where the offset lines of two beveled edges meet at vertex v when no edge lies between
/// them, or only edges that lie flat with their faces (Blender's offset meet with no edges
/// between): `first` and `second` are the far ends of the edges in Blender's order round v
/// (the first runs into v, the second out of it) and `normal` is the normal of the face
/// after the first. Each line
/// lies `width` from its edge, square to it in the plane of the two edges (the face's plane
/// where they turn by less than 10°); the point is the first line's point nearest the
/// second. Edges in one line (within 2°) put it `width / cos(θ/2)` from v square to both in
/// the face; edges turning straight back put it `width` along the second.
fn offset_meet_flat(v: DVec3, first: DVec3, second: DVec3, normal: DVec3, width: f64) -> DVec3 {
    let (d1, d2) = (v - first, second - v);
    let turn = d1.angle_between(d2);
    let (nearly, small) = (2f64.to_radians(), 10f64.to_radians());
    if turn < nearly {
        let across = (d1 + d2).cross(normal).normalize_or_zero();
        return v + across * (width / (turn / 2.0).cos());
    }
    if std::f64::consts::PI - turn < nearly {
        let length = d2.length();
        return v + d2.normalize_or_zero() * if width > length { length - 5e-5 } else { width };
    }
    let plane = if turn < small {
        normal
    } else {
        let n = d2.cross(d1).normalize_or_zero();
        if n.dot(normal) < 0.0 { -n } else { n }
    };
    let p1 = v + d1.cross(plane).normalize_or_zero() * width;
    let p2 = v + d2.cross(plane).normalize_or_zero() * width;
    nearest_on_line(p1, d1, p2, d2).unwrap_or(p1)
}

/// Where the offset lines of two beveled edges meet across the unbeveled edges between them
/// round vertex v. `corners` are the faces from the first beveled edge to the second, each
/// with its normal and the far ends of its two edges at v in that order. Each line lies
/// `width` from its edge in the plane of that edge and the next edge towards the other, on
/// that edge's side; the point is the middle of their nearest points, dropped onto the plane
/// of the first face whose corner at v it then lies in, passing over faces within 10° of
/// parallel to `in_plane`. Where the two beveled edges run on in one line (within 2°, as
/// Blender's bevel tests), their offset lines do not meet: the point lies `width / cos(θ/2)`
/// from v (θ the turn between the edges) square to both edges and to the mean normal of the
/// faces between, on their side, as Blender's offset meet puts it.
fn offset_meet_between(
    v: DVec3,
    corners: &[(DVec3, DVec3, DVec3)],
    in_plane: Option<DVec3>,
    width: f64,
) -> DVec3 {
    // The offset line of the edge to x, towards the edge to y; where the face between them
    // turns back on itself at v (reflex about its normal), Blender's offset, taken on the
    // face's inner side, goes the other way.
    let line = |x: DVec3, y: DVec3, reflex: bool| {
        let d = (x - v).normalize_or_zero();
        let dm = (y - v).normalize_or_zero();
        let inward = (dm - d * dm.dot(d)).normalize_or_zero();
        let inward = if reflex { -inward } else { inward };
        (v + inward * width, d)
    };
    let (Some(&(n1, x1, y1)), Some(&(n2, y2, x2))) = (corners.first(), corners.last()) else {
        return v;
    };
    // Each corner is (normal, next corner, previous corner) of its face.
    let [(p1, d1), (p2, d2)] = [
        line(x1, y1, reflex_corner(v, x1, y1, n1)),
        line(x2, y2, reflex_corner(v, y2, x2, n2)),
    ];
    let turn = (v - x1).angle_between(x2 - v);
    if turn < 2f64.to_radians() {
        let normal = corners.iter().map(|c| c.0).sum::<DVec3>() / corners.len() as f64;
        let mut across = ((v - x1) + (x2 - v)).cross(normal).normalize_or_zero();
        if across.dot(p1 - v) < 0.0 {
            across = -across;
        }
        return v + across * (width / (turn / 2.0).cos());
    }
    // The nearest points of p1 + s·d1 and p2 + t·d2.
    let w = p1 - p2;
    let (a, b, c) = (d1.dot(d1), d1.dot(d2), d2.dot(d2));
    let (d, e) = (d1.dot(w), d2.dot(w));
    let denominator = a * c - b * b;
    // Blender's line intersection calls the lines coplanar where (p2 − p1)·(e1 × e2), with
    // the edges' own vectors, is within 1e-6 (an absolute test), and then takes the first
    // line's point, not the middle.
    let coplanar = (p2 - p1).dot((v - x1).cross(x2 - v)).abs() <= 1e-6;
    let meet = if denominator > 1e-12 {
        let s = (b * e - c * d) / denominator;
        let t = (a * e - b * d) / denominator;
        if coplanar {
            p1 + d1 * s
        } else {
            ((p1 + d1 * s) + (p2 + d2 * t)) / 2.0
        }
    } else {
        (p1 + p2) / 2.0
    };
    let angle = |p: DVec3, q: DVec3| {
        p.normalize_or_zero()
            .dot(q.normalize_or_zero())
            .clamp(-1.0, 1.0)
            .acos()
    };
    // Blender's test of a point between two edges of a face, sweeping from the first to the
    // second: not behind the first, and at most 2° past the second.
    let slack = 2f64.to_radians();
    let small = 10f64.to_radians();
    for &(normal, from, to) in corners {
        if let Some(plane) = in_plane {
            let turn = angle(normal, plane);
            if turn < small || turn > std::f64::consts::PI - small {
                continue;
            }
        }
        let dropped = meet - normal * normal.dot(meet - v);
        let (u, from, to) = (dropped - v, from - v, to - v);
        // Angles swept about the face's normal from `from` (a point on `from` itself, where
        // Blender's f32 rounding decides, is taken as not swept at all).
        let swept = |q: DVec3| {
            if angle(from, q) > 1e-7 && from.cross(q).dot(normal) < 0.0 {
                std::f64::consts::TAU - angle(from, q)
            } else {
                angle(from, q)
            }
        };
        if swept(to) - swept(u) > -slack {
            return dropped;
        }
    }
    meet
}

impl Cage {
    /// Bevel edges (Blender's Bevel of edges: offset width, profile 0.5, that is a circular arc
    /// where the faces meet square). Each beveled edge becomes a band of `segments` quads
    /// whose sides lie `width` from the edge in its two faces (measured square to the edge, in
    /// each face's plane). At each end, every face takes a new corner: where two beveled edges
    /// of the face meet, the point `width` from both; where a beveled edge meets one that is
    /// not, the point on that edge `width` from the beveled one (or the edge's far end, where
    /// the edge is shorter, as in Blender); where an unbeveled edge lies
    /// between two beveled ones, where their offset lines meet ([`offset_meet_between`], or
    /// [`offset_meet_flat`] where every edge between lies flat with its faces). The band's
    /// end is the arc between its two side points ([`Profile`]); two bands ending on the same
    /// two points share the mean of their arcs, and three or more at one corner close it
    /// with a polygon (one segment) or Blender's corner mesh ([`bevel_corner`]).
    ///
    /// Where one beveled edge ends at a vertex of four or more edges, the other edges take
    /// the point `width` along them and the vertex opens into a polygon of its edges' points
    /// and the band's arc (a fan of triangles from the point across where that is a
    /// triangle), as Blender's terminal edge does; where it ends on the border between two
    /// border edges, its arc takes the vertex's place on the border.
    ///
    /// Where it ends at a vertex of two edges, each face takes the point `width` from it
    /// square to it and a made-up point on the other edge closes a fan (Blender's terminal
    /// edge of two edges).
    ///
    /// On the border every case is built as inside, the two border edges at a vertex and
    /// the unbeveled edges next to them taking one point between the beveled edges on either
    /// side (so the border runs through it), as Blender does. A vertex on the border twice
    /// (its faces meeting only there) is refused by name. Named border edges (one face) are
    /// passed over, as Blender's bevel passes over them.
    pub fn bevel_edges(
        &self,
        edges: &[(u32, u32)],
        width: f64,
        segments: u32,
    ) -> Result<Self, CageEditError> {
        if edges.is_empty() {
            return Err(invalid("no edges were named"));
        }
        if !(width.is_finite() && width > 0.0) {
            return Err(invalid("the width must be a finite number > 0"));
        }
        if segments == 0 || segments > 1000 {
            return Err(invalid(format!(
                "segments must be 1 to 1000 (got {segments})"
            )));
        }
        let half = self.half_edges();
        // Each beveled edge once, in the order named.
        let inner = self.inner_edges(&half, edges, "bevel")?;
        let beveled: HashSet<(u32, u32)> = inner.iter().map(|&(a, b)| key(a, b)).collect();
        let mut ends: Vec<u32> = beveled.iter().flat_map(|&(a, b)| [a, b]).collect();
        ends.sort_unstable();
        ends.dedup();
        let p = |v: u32| self.points[v as usize];
        let dir = |v: u32, x: u32| (p(x) - p(v)).normalize_or_zero();
        let is_beveled = |v: u32, x: u32| beveled.contains(&key(v, x));
        // Blender's order of the edges round a vertex starts at the beveled edge created
        // first (edges are created face by face, each face's from its closing edge on) and
        // runs counter-clockwise when the edge after it was created before the edge before
        // it; otherwise it runs the other way and is turned round, starting at the edge after
        // it. Its corner mesh takes the cube corner only where that first edge is beveled (it
        // compares every beveled edge's offset with that edge's), and its first side is the
        // one across the first beveled edge after the first beveled edge of that order.
        let created: std::cell::OnceCell<HashMap<(u32, u32), usize>> = std::cell::OnceCell::new();
        let blender_first_edge = |v: u32, around: &[(usize, u32, u32)]| -> Option<u32> {
            let created = created.get_or_init(|| {
                let mut order = HashMap::default();
                for face in &self.faces {
                    for c in 0..face.len() {
                        let next = order.len();
                        order
                            .entry(key(face[(c + face.len() - 1) % face.len()], face[c]))
                            .or_insert(next);
                    }
                }
                order
            });
            let rank = |x: u32| created.get(&key(v, x)).copied().unwrap_or(usize::MAX);
            let n = around.len();
            let m = (0..n)
                .filter(|&m| is_beveled(v, around[m].2))
                .min_by_key(|&m| rank(around[m].2))?;
            let (after, before) = (around[m].1, around[(m + 1) % n].2);
            Some(if rank(after) < rank(before) {
                around[m].2
            } else {
                after
            })
        };
        let mut out = self.clone();
        let sharpness = self.sharpness_of_edges();
        // The arcs that take an end's place in a face with no beveled edge there, and the
        // sharpness they take.
        let mut arc_creases: Vec<(u32, u32, f64)> = Vec::new();
        // Each end's new corner points: per face (a meet point) or per edge (a point on it).
        let mut face_point: HashMap<(u32, usize), u32> = HashMap::default();
        let mut edge_point: HashMap<(u32, u32), u32> = HashMap::default();
        // Each face corner's replacement.
        let mut replace: HashMap<(usize, u32), Vec<u32>> = HashMap::default();
        // The arcs: between two corner points (lower id first), ends included.
        let mut arcs: HashMap<(u32, u32), Vec<u32>> = HashMap::default();
        let mut corner_faces = Vec::new();
        // The faces of corner meshes.
        let mut mesh_faces: Vec<Vec<u32>> = Vec::new();
        let mut terminals = Vec::new();
        // A face's point at a band's end where the face holds more than that point there.
        let mut band_end: HashMap<(usize, u32), u32> = HashMap::default();
        for &v in &ends {
            let Some(&start) = self
                .faces
                .iter()
                .enumerate()
                .find_map(|(f, face)| face.iter().position(|&x| x == v).map(|c| (f, c)))
                .as_ref()
            else {
                continue;
            };
            // A vertex on the border: its faces from the border edge before them round to
            // the one after (the first face's incoming edge has no face before it).
            let open = |start: (usize, usize)| {
                let mut first = start;
                for _ in 0..self.faces.len() {
                    let (f, c) = first;
                    let k = self.faces[f].len();
                    let prev = self.faces[f][(c + k - 1) % k];
                    match half.get(&(v, prev)) {
                        Some(&(g, d)) if g != start.0 => first = (g, d),
                        _ => break,
                    }
                }
                let mut out = Vec::new();
                let (mut f, mut c) = first;
                loop {
                    let face = &self.faces[f];
                    let k = face.len();
                    let (prev, next) = (face[(c + k - 1) % k], face[(c + 1) % k]);
                    out.push((f, prev, next));
                    match half.get(&(next, v)) {
                        Some(&(g, d)) if out.len() <= self.faces.len() => {
                            (f, c) = (g, (d + 1) % self.faces[g].len());
                        }
                        _ => return out,
                    }
                }
            };
            let (around, closed) = match fan(&self.faces, &half, v, start) {
                Some(around) => (around, true),
                None => (open(start), false),
            };
            let valence = around.len();
            // The vertex's edges in the fan's order; on the border, from the first face's
            // incoming edge to the last face's outgoing one (both border edges).
            let round: Vec<u32> = (!closed)
                .then_some(around[0].1)
                .into_iter()
                .chain(around.iter().map(|&(_, _, b)| b))
                .collect();
            let count = round.iter().filter(|&&b| is_beveled(v, b)).count();
            if !closed && self.faces.iter().filter(|face| face.contains(&v)).count() != valence {
                return Err(invalid(format!(
                    "vertex {v} is on the cage's border twice (its faces meet only there): \
                     a bevel cannot end there"
                )));
            }
            // One beveled edge ending at a vertex of four or more edges, on the border or
            // not: the vertex opens into a polygon (Blender's terminal edge). On the border
            // between two border edges its arc takes the vertex's place there.
            let terminal = count == 1 && round.len() >= 4;
            // One beveled edge ending at a vertex of two edges (both faces there hold both):
            // as Blender's terminal edge of two edges, each face takes the point `width`
            // from the beveled edge in its plane, square to the edge, and a made-up point
            // `width` along the other edge; the vertex opens into a fan of triangles from
            // that point to the band's arc between the faces' points (no carried profile).
            let normal_of = |f: usize| polygon_normal(&self.points, &self.faces[f]);
            if closed && valence == 2 && count == 1 {
                let (e, y) = if is_beveled(v, round[0]) {
                    (round[0], round[1])
                } else {
                    (round[1], round[0])
                };
                let length = (p(y) - p(v)).length();
                let along = if width > length { length - 5e-5 } else { width };
                let made_up = out.points.len() as u32;
                out.points.push(p(v) + dir(v, y) * along);
                edge_point.insert((v, y), made_up);
                // Each face's point, in the fan's order; where the beveled edge leaves v in
                // the face, the face runs from the made-up point to its own.
                let mut own = Vec::new();
                for &(f, _, b) in &around {
                    let normal = normal_of(f);
                    let leaving = b == e;
                    let inward = if leaving {
                        normal.cross(dir(v, e))
                    } else {
                        dir(v, e).cross(normal)
                    };
                    let q = out.points.len() as u32;
                    out.points.push(p(v) + inward.normalize_or_zero() * width);
                    replace.insert(
                        (f, v),
                        if leaving {
                            vec![made_up, q]
                        } else {
                            vec![q, made_up]
                        },
                    );
                    band_end.insert((f, v), q);
                    own.push((q, leaving));
                }
                let [(first, first_leaving), (second, _)] = own[..] else {
                    continue;
                };
                // The arc from the point of the face the beveled edge leaves v in to the
                // other's, the fan running made-up point, other's point, arc, back.
                let (from, to) = if first_leaving {
                    (first, second)
                } else {
                    (second, first)
                };
                let profile = Profile::new(
                    out.points[from as usize],
                    out.points[to as usize],
                    p(v),
                    dir(v, e),
                    false,
                );
                let mut chain = vec![to];
                for s in (1..segments).rev() {
                    chain.push(out.points.len() as u32);
                    out.points
                        .push(profile.at(f64::from(s) / f64::from(segments)));
                }
                chain.push(from);
                let mut stored = chain.clone();
                if from < to {
                    stored.reverse();
                }
                arcs.insert(key(from, to), stored);
                for pair in chain.windows(2) {
                    mesh_faces.push(vec![made_up, pair[0], pair[1]]);
                }
                continue;
            }
            // Points for unbeveled edges. With one beveled edge: on each edge beside it, where
            // its offset line in their face meets that edge. Between two beveled edges round
            // the vertex: one point for all the unbeveled edges between them, where the two
            // offset lines, each in the plane of its edge and the next edge towards the other,
            // come nearest, dropped onto the first face between them whose corner holds it
            // (Blender's offset meet with edges between).
            if count == 1 {
                // Each edge beside the beveled one, the face between them, whether that face
                // turns back on itself at v (its corner there reflex about its normal), and
                // whether the edge comes first of the two in Blender's order round v (against
                // the fan's).
                let mut beside: Vec<(u32, u32, usize, bool, bool)> = Vec::new();
                for &(f, a, b) in &around {
                    let reflex = reflex_corner(p(v), p(b), p(a), normal_of(f));
                    if is_beveled(v, a) && !is_beveled(v, b) {
                        beside.push((b, a, f, reflex, true));
                    }
                    if is_beveled(v, b) && !is_beveled(v, a) {
                        beside.push((a, b, f, reflex, false));
                    }
                }
                let nearly = 2f64.to_radians();
                for (y, x, f, reflex, y_first) in beside {
                    let (d, e) = (dir(v, y), dir(v, x));
                    edge_point.insert((v, y), out.points.len() as u32);
                    // Blender meets the edges' offset lines taking the first edge into v and
                    // the second out of it; where those run on in line (within 2°), the
                    // point lies square to both, in the face; where they turn straight back
                    // (the two edges within 2° of one direction), it lies `width` along the
                    // second edge (5e-5 short of its end where that is nearer).
                    let (first, second) = if y_first { (d, e) } else { (e, d) };
                    let turn = (-first).angle_between(second);
                    let slid = if turn < nearly {
                        let across = (second - first).cross(normal_of(f)).normalize_or_zero();
                        p(v) + across * (width / (turn / 2.0).cos())
                    } else if std::f64::consts::PI - turn < nearly {
                        let far = if y_first { x } else { y };
                        let length = (p(far) - p(v)).length();
                        p(v) + second * if width > length { length - 5e-5 } else { width }
                    } else {
                        // No farther than the edge's far end, where Blender stops it too (a
                        // width beyond a short edge leaves the new point on that end). At a
                        // reflex corner the beveled edge's offset line, on the face's inner
                        // side, meets the edge's line behind v, and Blender stops the point
                        // at v.
                        let along = width / d.cross(e).length().max(1e-12);
                        if reflex {
                            p(v)
                        } else if along >= (p(y) - p(v)).length() {
                            p(y)
                        } else {
                            p(v) + d * along
                        }
                    };
                    out.points.push(slid);
                }
            } else {
                let n = round.len();
                // The face between edge j and the next one round (none across the border).
                let face_after = |j: usize| -> Option<usize> {
                    if closed {
                        Some((j + 1) % n)
                    } else {
                        (j < valence).then_some(j)
                    }
                };
                for i in (0..n).filter(|&i| is_beveled(v, round[i])) {
                    let run: Vec<u32> = (1..n)
                        .map(|m| round[(i + m) % n])
                        .take_while(|&y| !is_beveled(v, y))
                        .collect();
                    if run.is_empty() {
                        continue;
                    }
                    // The faces from the later beveled edge back to this one, each with its
                    // edges in that order (on the border, the faces there are).
                    let corners: Vec<(DVec3, DVec3, DVec3)> = (0..=run.len())
                        .rev()
                        .filter_map(|m| face_after((i + m) % n))
                        .map(|k| {
                            let (f, a, b) = around[k];
                            (normal_of(f), p(b), p(a))
                        })
                        .collect();
                    // Each edge between that lies in one plane with its two faces (Blender's
                    // in-plane edges; never a border edge), with the normal of the face after
                    // it in Blender's order.
                    let flat: Vec<Option<DVec3>> = (1..=run.len())
                        .map(|m| (i + m) % n)
                        .map(|m| {
                            let after = normal_of(around[face_after((m + n - 1) % n)?].0);
                            let before = normal_of(around[face_after(m)?].0);
                            let dot = after.dot(before);
                            ((dot + 1.0).abs() <= 1e-4 || (dot - 1.0).abs() <= 1e-4)
                                .then_some(after)
                        })
                        .collect();
                    let id = out.points.len() as u32;
                    let meet = if flat.iter().all(Option::is_some) {
                        // Every edge between lies flat: the offset lines meet as if there
                        // were none, in the face after the later beveled edge.
                        let later = round[(i + run.len() + 1) % n];
                        let (normal, _, _) = corners[0];
                        offset_meet_flat(p(v), p(later), p(round[i]), normal, width)
                    } else {
                        // Else the meet point is not dropped onto faces parallel to the face
                        // after the last in-plane edge.
                        let in_plane = flat.iter().flatten().next().copied();
                        offset_meet_between(p(v), &corners, in_plane, width)
                    };
                    out.points.push(meet);
                    for y in run {
                        edge_point.insert((v, y), id);
                    }
                }
            }
            if terminal {
                // The edges not beside the beveled one: the point `width` along each, or on
                // an edge shorter than that 5e-5 short of its far end (Blender's slide).
                for &y in &round {
                    if !is_beveled(v, y) && !edge_point.contains_key(&(v, y)) {
                        let length = (p(y) - p(v)).length();
                        let along = if width > length { length - 5e-5 } else { width };
                        edge_point.insert((v, y), out.points.len() as u32);
                        out.points.push(p(v) + dir(v, y) * along);
                    }
                }
            }
            // Two beveled edges of one face at v: where their offset lines meet in it (the
            // edge after v in the face comes first in Blender's order).
            for &(f, a, b) in &around {
                if is_beveled(v, a) && is_beveled(v, b) {
                    face_point.insert((v, f), out.points.len() as u32);
                    out.points
                        .push(offset_meet_flat(p(v), p(b), p(a), normal_of(f), width));
                }
            }
            // The point a face at v shows: its meet point, or the point on its unbeveled edge.
            let point_of = |f: usize, a: u32, b: u32| -> Option<u32> {
                match (is_beveled(v, a), is_beveled(v, b)) {
                    (true, true) => face_point.get(&(v, f)).copied(),
                    (true, false) => edge_point.get(&(v, b)).copied(),
                    (false, true) => edge_point.get(&(v, a)).copied(),
                    (false, false) => None,
                }
            };
            // Three or more beveled edges with more than one segment: Blender's corner mesh,
            // whose border gives the bands' arcs at this end. On the border one of its corners
            // is the point the border edges share.
            let mut corner_mesh = false;
            if count >= 3 && segments > 1 {
                let n = valence;
                // The crossings of the beveled edges, against the fan's order (Blender's
                // counter-clockwise order): from the point of the face after the edge to the
                // point of the face before it, with the edge's far end and the fan index.
                let mut crossings: Vec<(u32, u32, u32, usize)> = Vec::new();
                for m in (0..n).rev() {
                    let (f, a, b) = around[m];
                    if !is_beveled(v, b) {
                        continue;
                    }
                    let (g, ga, gb) = around[(m + 1) % n];
                    let (Some(from), Some(to)) = (point_of(g, ga, gb), point_of(f, a, b)) else {
                        return Err(invalid(format!("vertex {v} cannot be beveled")));
                    };
                    crossings.push((from, to, b, m));
                }
                let sides = crossings.len();
                if (0..sides).any(|i| crossings[i].1 != crossings[(i + 1) % sides].0) {
                    return Err(invalid(format!(
                        "vertex {v}: its beveled edges do not close a corner"
                    )));
                }
                let boundary: Vec<DVec3> =
                    crossings.iter().map(|c| out.points[c.0 as usize]).collect();
                // Each side's profile; its neighbouring edges round the vertex are the beveled
                // edges before and after it there.
                let profiles: Vec<Profile> = crossings
                    .iter()
                    .map(|&(from, to, b, m)| {
                        let before = around[(m + 1) % n].2;
                        let after = around[m].1;
                        let sides = (is_beveled(v, before) && is_beveled(v, after))
                            .then(|| (p(before) - p(v), p(after) - p(v)));
                        Profile::corner_side(
                            out.points[from as usize],
                            out.points[to as usize],
                            p(v),
                            p(b) - p(v),
                            sides,
                        )
                    })
                    .collect();
                let side = |i: usize, t: f64| profiles[i].at(t);
                let ns = segments as usize;
                // Each edge's signed dihedral angle (positive where convex): between the
                // normals of the face before it and the face after it in the fan.
                let dihedral = |m: usize| {
                    let (f, _, b) = around[m];
                    let (n1, n2) = (normal_of(f), normal_of(around[(m + 1) % n].0));
                    let angle = n1.angle_between(n2);
                    if n1.cross(n2).dot(p(b) - p(v)) >= 0.0 {
                        angle
                    } else {
                        -angle
                    }
                };
                // Blender's first side: across the beveled edge after the first beveled one
                // of its order (the crossings run counter-clockwise).
                let first = blender_first_edge(v, &around);
                let ccw: Vec<u32> = (0..n).rev().map(|m| around[m].2).collect();
                let start = first
                    .and_then(|x| ccw.iter().position(|&y| y == x))
                    .and_then(|at| {
                        let beveled = (0..n)
                            .map(|k| ccw[(at + k) % n])
                            .filter(|&y| is_beveled(v, y))
                            .nth(1)?;
                        crossings.iter().position(|c| c.2 == beveled)
                    })
                    .unwrap_or(0);
                // Blender's pipe: two beveled edges in line with one between, every face
                // parallel to them; the first such side from the first side.
                let pipe = (sides == 3 || sides == 4)
                    .then(|| {
                        (0..sides).map(|k| (start + k) % sides).find(|&i| {
                            let d1 = p(v) - p(crossings[i].2);
                            let d3 = p(crossings[(i + 2) % sides].2) - p(v);
                            d1.angle_between(d3) < 2f64.to_radians()
                        })
                    })
                    .flatten()
                    .filter(|&i| {
                        let d = (p(v) - p(crossings[i].2)).normalize_or_zero();
                        around
                            .iter()
                            .all(|&(f, _, _)| normal_of(f).dot(d).abs() <= 1e-4)
                    });
                let grid = if let Some(i) = pipe {
                    let profile = &profiles[i];
                    let along = p(crossings[i].2) - p(v);
                    let section = (profile.a, profile.middle(), profile.b, along);
                    bevel_corner::pipe_corner(p(v), &boundary, &side, ns, section)
                } else {
                    // Blender's cube corner: three sides whose faces meet nearly square, every
                    // other edge nearly flat (not on the border, where Blender's test counts
                    // more edges than three).
                    let angles: Vec<f64> = (0..n).map(dihedral).collect();
                    let square = closed
                        && sides == 3
                        && (sides == n || first.is_some_and(|x| is_beveled(v, x)))
                        && angles.iter().all(|a| a.abs() < 0.75 * std::f64::consts::PI)
                        && angles
                            .iter()
                            .filter(|a| a.abs() <= std::f64::consts::FRAC_PI_4)
                            .count()
                            == n - 3
                        && (angles.iter().sum::<f64>().abs() - 1.5 * std::f64::consts::PI).abs()
                            <= std::f64::consts::FRAC_PI_4;
                    if square {
                        bevel_corner::cube_corner(p(v), [boundary[0], boundary[1], boundary[2]], ns)
                    } else {
                        bevel_corner::general_corner(p(v), &boundary, &side, ns)
                    }
                };
                let corners: Vec<u32> = crossings.iter().map(|c| c.0).collect();
                let (faces, borders) = bevel_corner::corner_faces(&grid, &corners, &mut out.points);
                for (crossing, mut border) in crossings.iter().zip(borders) {
                    if crossing.0 > crossing.1 {
                        border.reverse();
                    }
                    arcs.insert(key(crossing.0, crossing.1), border);
                }
                mesh_faces.extend(faces);
                corner_mesh = true;
            }
            let mut corner_edges: Vec<(u32, u32)> = Vec::new();
            for (i, &(f, a, b)) in around.iter().enumerate() {
                match point_of(f, a, b) {
                    Some(q) => {
                        replace.insert((f, v), vec![q]);
                    }
                    None => {
                        // A face with no beveled edge at v (one beveled edge at a vertex of
                        // three): the arc from the point on its incoming edge to the one on
                        // its outgoing edge.
                        let (Some(&qa), Some(&qb)) =
                            (edge_point.get(&(v, a)), edge_point.get(&(v, b)))
                        else {
                            return Err(invalid(format!("vertex {v} cannot be beveled")));
                        };
                        // (The same point where both edges are between two beveled ones.)
                        replace.insert((f, v), if qa == qb { vec![qa] } else { vec![qa, qb] });
                        // Blender's arc there takes the crease of the face's edge leaving v.
                        if let (true, Some(&s)) = (qa != qb, sharpness.get(&key(v, b))) {
                            arc_creases.push((qa, qb, s));
                        }
                    }
                }
                // The band of the beveled edge v–b leaving this face: its arc runs from this
                // face's point to the next face's.
                if is_beveled(v, b) {
                    let (g, ga, gb) = around[(i + 1) % valence];
                    let (Some(from), Some(to)) = (point_of(f, a, b), point_of(g, ga, gb)) else {
                        return Err(invalid(format!("vertex {v} cannot be beveled")));
                    };
                    corner_edges.push((to, from));
                    let k = key(from, to);
                    if let std::collections::hash_map::Entry::Vacant(slot) = arcs.entry(k) {
                        let (pa, pb) = (out.points[k.0 as usize], out.points[k.1 as usize]);
                        // Two beveled edges through v share the arc: the mean of both
                        // edges' profiles, each carried onto the plane through its ends and v.
                        let others: Vec<DVec3> = around
                            .iter()
                            .filter(|&&(_, _, x)| x != b && is_beveled(v, x))
                            .map(|&(_, _, x)| dir(v, x))
                            .collect();
                        let mut shapes = vec![Profile::new(pa, pb, p(v), dir(v, b), count <= 2)];
                        if count == 2 {
                            shapes.extend(
                                others.iter().map(|&d| Profile::new(pa, pb, p(v), d, true)),
                            );
                        }
                        let mut arc = vec![k.0];
                        for s in 1..segments {
                            let t = f64::from(s) / f64::from(segments);
                            let sum: DVec3 = shapes.iter().map(|shape| shape.at(t)).sum();
                            arc.push(out.points.len() as u32);
                            out.points.push(sum / shapes.len() as f64);
                        }
                        arc.push(k.1);
                        slot.insert(arc);
                    }
                }
            }
            if count >= 3 && !corner_mesh {
                corner_faces.push(corner_edges);
            }
            if terminal {
                terminals.push((v, round));
            }
        }
        let arc = |from: u32, to: u32| -> Vec<u32> {
            match arcs.get(&key(from, to)) {
                Some(list) if from < to => list.clone(),
                Some(list) => list.iter().rev().copied().collect(),
                None => vec![from, to],
            }
        };
        // The polygon a terminal end opens into: its edges' points against the fan's order,
        // the band's arc in place of the beveled edge. Where that is a triangle with an arc of
        // more than one segment it is a fan of triangles from the point across from the arc.
        // On the border the polygon's side from the last edge's point to the first's is
        // border too (the beveled edge is never first or last there).
        for (v, round) in terminals {
            let mut polygon = Vec::new();
            let mut apex = None;
            let n = round.len();
            for (i, &b) in round.iter().enumerate().rev() {
                if is_beveled(v, b) {
                    let before = edge_point.get(&(v, round[(i + n - 1) % n]));
                    let after = edge_point.get(&(v, round[(i + 1) % n]));
                    if let (Some(&from), Some(&to)) = (before, after) {
                        let arc = arc(to, from);
                        polygon.extend_from_slice(&arc[1..arc.len() - 1]);
                    }
                    if n == 4 {
                        apex = edge_point.get(&(v, round[(i + 2) % n])).copied();
                    }
                } else if let Some(&q) = edge_point.get(&(v, b)) {
                    polygon.push(q);
                }
            }
            match apex {
                Some(apex) if segments > 1 => {
                    // The polygon starts after the apex (it is the last edge round before the
                    // beveled one, or the first after it).
                    let at = polygon.iter().position(|&q| q == apex).unwrap_or(0);
                    polygon.rotate_left(at);
                    for k in 1..polygon.len() - 1 {
                        out.faces.push(vec![polygon[k], polygon[k + 1], apex]);
                    }
                }
                _ => out.faces.push(polygon),
            }
        }
        for (f, face) in out.faces.iter_mut().enumerate() {
            if !face.iter().any(|v| ends.binary_search(v).is_ok()) {
                continue;
            }
            let mut grown = Vec::with_capacity(face.len() + segments as usize);
            for &v in face.iter() {
                match replace.get(&(f, v)).map(Vec::as_slice) {
                    Some(&[q]) => grown.push(q),
                    Some(&[qa, qb]) => grown.extend(arc(qa, qb)),
                    _ => grown.push(v),
                }
            }
            *face = grown;
        }
        // The bands: along each beveled edge a→b, between the arcs at its ends. Face X holds
        // a→b and face Y b→a; at each end the arc runs from X's point to Y's.
        for &(a, b) in &inner {
            let (Some(&(fx, _)), Some(&(fy, _))) = (half.get(&(a, b)), half.get(&(b, a))) else {
                continue;
            };
            let ends_of = |v: u32| -> Option<Vec<u32>> {
                let x = match band_end.get(&(fx, v)) {
                    Some(&x) => x,
                    None => replace.get(&(fx, v))?.first().copied()?,
                };
                let y = match band_end.get(&(fy, v)) {
                    Some(&y) => y,
                    None => replace.get(&(fy, v))?.last().copied()?,
                };
                Some(arc(x, y))
            };
            let (Some(at_a), Some(at_b)) = (ends_of(a), ends_of(b)) else {
                continue;
            };
            for k in 0..segments as usize {
                out.faces
                    .push(vec![at_b[k], at_a[k], at_a[k + 1], at_b[k + 1]]);
            }
            // A creased edge's sharpness goes to the band's two rails along the faces beside
            // it; the rails between stay smooth (as Blender's bevel carries edge creases).
            if let Some(&s) = sharpness.get(&key(a, b)) {
                let last = segments as usize;
                out.add_crease(at_a[0], at_b[0], s);
                out.add_crease(at_a[last], at_b[last], s);
            }
        }
        // An unbeveled creased edge keeps its sharpness on what is left of it (from the point
        // that took a beveled end's place on it), and an arc in a face with no beveled edge
        // at the end it replaces takes that of the face's edge leaving the end (Blender's
        // choice). `compacted` drops the creases of edges that are gone.
        for c in &self.creases {
            if beveled.contains(&key(c.a, c.b)) {
                continue;
            }
            let a = edge_point.get(&(c.a, c.b)).copied().unwrap_or(c.a);
            let b = edge_point.get(&(c.b, c.a)).copied().unwrap_or(c.b);
            if (a, b) != (c.a, c.b) {
                out.add_crease(a, b, c.sharpness);
            }
        }
        for (qa, qb, s) in arc_creases {
            for pair in arc(qa, qb).windows(2) {
                out.add_crease(pair[0], pair[1], s);
            }
        }
        // Corners of three or more beveled edges: the polygon their arcs leave.
        for corner in corner_faces {
            let next: HashMap<u32, u32> = corner.iter().copied().collect();
            let Some(&(first, _)) = corner.first() else {
                continue;
            };
            let mut polygon = vec![first];
            while let Some(&n) = next.get(polygon.last().unwrap_or(&first)) {
                if n == first || polygon.len() > corner.len() {
                    break;
                }
                polygon.push(n);
            }
            out.faces.push(polygon);
        }
        out.faces.extend(mesh_faces);
        Ok(out.compacted(self))
    }
}

/// One cage tool and its arguments, as the editor's operation and the command line name it
/// (`{"extrude": {"faces": [0, 1], "offset": 0.5}}` in JSON).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case", deny_unknown_fields)]
pub enum Tool {
    /// [`Cage::extrude_faces`], or [`Cage::extrude_individual`] with `individual`.
    Extrude {
        faces: Vec<usize>,
        offset: f64,
        #[serde(default)]
        individual: bool,
    },
    /// [`Cage::inset`].
    Inset {
        faces: Vec<usize>,
        thickness: f64,
        /// How far the inner faces then move out of the surface (negative: in).
        #[serde(default)]
        depth: f64,
        #[serde(default)]
        individual: bool,
    },
    /// [`Cage::loop_cut_slid`] through the edge between the two vertices (`slide` 0: the
    /// cuts evenly spaced, [`Cage::loop_cut`]).
    LoopCut {
        edge: [u32; 2],
        cuts: u32,
        #[serde(default, skip_serializing_if = "is_zero")]
        slide: f64,
    },
    /// [`Cage::bevel_edges`].
    Bevel {
        edges: Vec<[u32; 2]>,
        width: f64,
        segments: u32,
    },
    /// [`Cage::bevel_vertices`].
    BevelVertices {
        vertices: Vec<u32>,
        width: f64,
        #[serde(default = "one_segment")]
        segments: u32,
    },
    /// [`Cage::bridge_loops`].
    Bridge { loop1: Vec<u32>, loop2: Vec<u32> },
    /// [`Cage::merge_vertices`], at the first vertex's place with `at_first`.
    Merge {
        vertices: Vec<u32>,
        #[serde(default)]
        at_first: bool,
    },
    /// [`Cage::dissolve_edges`].
    Dissolve { edges: Vec<[u32; 2]> },
    /// [`Cage::dissolve_faces`].
    DissolveFaces { faces: Vec<usize> },
    /// [`Cage::delete_faces`].
    Delete { faces: Vec<usize> },
    /// [`Cage::delete_vertices`].
    DeleteVertices { vertices: Vec<u32> },
    /// [`Cage::delete_edges`].
    DeleteEdges { edges: Vec<[u32; 2]> },
    /// [`Cage::dissolve_vertices`].
    DissolveVertices { vertices: Vec<u32> },
    /// [`Cage::merge_by_distance`] (all vertices when `vertices` is empty).
    MergeByDistance {
        #[serde(default)]
        vertices: Vec<u32>,
        distance: f64,
    },
    /// [`Cage::triangulate_faces`].
    Triangulate { faces: Vec<usize> },
    /// [`Cage::tris_to_quads`], with Blender's limits of 40° by default.
    TrisToQuads {
        faces: Vec<usize>,
        #[serde(default = "forty_degrees")]
        face_degrees: f64,
        #[serde(default = "forty_degrees")]
        shape_degrees: f64,
    },
    /// [`Cage::fill_loop`].
    Fill { r#loop: Vec<u32> },
    /// [`Cage::grid_fill`] between two chains, or [`Cage::grid_fill_rim`] over a whole rim
    /// (when `rim` is not empty).
    GridFill {
        #[serde(default)]
        loop1: Vec<u32>,
        #[serde(default)]
        loop2: Vec<u32>,
        #[serde(default)]
        rim: Vec<u32>,
        #[serde(default)]
        span: Option<u32>,
        #[serde(default)]
        offset: Option<usize>,
    },
    /// [`Cage::connect_vertices`].
    Connect { vertices: Vec<u32> },
    /// [`Cage::extrude_edges`].
    ExtrudeEdges { edges: Vec<[u32; 2]>, by: [f64; 3] },
    /// [`Cage::spin`] of faces or edges (one list empty).
    Spin {
        #[serde(default)]
        faces: Vec<usize>,
        #[serde(default)]
        edges: Vec<[u32; 2]>,
        centre: [f64; 3],
        axis: [f64; 3],
        degrees: f64,
        steps: u32,
        #[serde(default)]
        advance: f64,
    },
    /// [`Cage::poke_faces`].
    Poke { faces: Vec<usize> },
    /// [`Cage::subdivide_faces`].
    Subdivide { faces: Vec<usize>, cuts: u32 },
    /// [`Cage::knife`] along the plane through `point` square to `normal` (every face when
    /// `faces` is empty).
    Knife {
        #[serde(default)]
        faces: Vec<usize>,
        point: [f64; 3],
        normal: [f64; 3],
        #[serde(default)]
        threshold: Option<f64>,
    },
    /// [`Cage::mirror`] across the plane through the origin square to axis 0, 1 or 2 (x, y,
    /// z).
    Mirror {
        axis: u8,
        #[serde(default = "default_merge_distance")]
        merge_distance: f64,
    },
}

/// A spin's motion: `degrees` round the axis through `centre` along `axis` (the right-hand
/// rule) in `steps` equal steps, moving `advance` along the axis over the whole of it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpinMotion {
    pub centre: DVec3,
    pub axis: DVec3,
    pub degrees: f64,
    pub steps: u32,
    pub advance: f64,
}

/// Blender's Mirror default: points within 0.001 of the plane are welded to their image.
pub const DEFAULT_MERGE_DISTANCE: f64 = 0.001;

fn one_segment() -> u32 {
    1
}

fn forty_degrees() -> f64 {
    40.0
}

fn default_merge_distance() -> f64 {
    DEFAULT_MERGE_DISTANCE
}

impl Tool {
    /// Its name, for an undo step ("Extrude", "Loop cut", …).
    pub fn label(&self) -> &'static str {
        match self {
            Self::Extrude { .. } => "Extrude",
            Self::Inset { .. } => "Inset",
            Self::LoopCut { .. } => "Loop cut",
            Self::Bevel { .. } => "Bevel",
            Self::BevelVertices { .. } => "Bevel vertices",
            Self::Bridge { .. } => "Bridge",
            Self::Merge { .. } => "Merge",
            Self::Dissolve { .. } => "Dissolve",
            Self::DissolveFaces { .. } => "Dissolve faces",
            Self::Delete { .. } => "Delete",
            Self::DeleteVertices { .. } => "Delete vertices",
            Self::DeleteEdges { .. } => "Delete edges",
            Self::DissolveVertices { .. } => "Dissolve vertices",
            Self::MergeByDistance { .. } => "Merge by distance",
            Self::Triangulate { .. } => "Triangulate",
            Self::ExtrudeEdges { .. } => "Extrude edges",
            Self::Fill { .. } => "Fill",
            Self::GridFill { .. } => "Grid fill",
            Self::TrisToQuads { .. } => "Tris to quads",
            Self::Connect { .. } => "Connect",
            Self::Spin { advance, .. } if *advance != 0.0 => "Screw",
            Self::Spin { .. } => "Spin",
            Self::Mirror { .. } => "Mirror",
            Self::Poke { .. } => "Poke",
            Self::Subdivide { .. } => "Subdivide",
            Self::Knife { .. } => "Knife",
        }
    }
}

impl Cage {
    /// The cage after `tool`.
    pub fn apply(&self, tool: &Tool) -> Result<Self, CageEditError> {
        let pairs = |edges: &[[u32; 2]]| -> Vec<(u32, u32)> {
            edges.iter().map(|&[a, b]| (a, b)).collect()
        };
        match tool {
            Tool::Extrude {
                faces,
                offset,
                individual: true,
            } => self.extrude_individual(faces, *offset),
            Tool::Extrude { faces, offset, .. } => self.extrude_faces(faces, *offset),
            Tool::Inset {
                faces,
                thickness,
                depth,
                individual,
            } => self.inset(faces, *thickness, *depth, *individual),
            Tool::LoopCut {
                edge: [a, b],
                cuts,
                slide,
            } => self.loop_cut_slid(*a, *b, *cuts, *slide),
            Tool::Bevel {
                edges,
                width,
                segments,
            } => self.bevel_edges(&pairs(edges), *width, *segments),
            Tool::BevelVertices {
                vertices,
                width,
                segments,
            } => self.bevel_vertices(vertices, *width, *segments),
            Tool::Bridge { loop1, loop2 } => self.bridge_loops(loop1, loop2),
            Tool::Merge { vertices, at_first } => self.merge_vertices(vertices, *at_first),
            Tool::Dissolve { edges } => self.dissolve_edges(&pairs(edges)),
            Tool::DissolveFaces { faces } => self.dissolve_faces(faces),
            Tool::Delete { faces } => self.delete_faces(faces),
            Tool::DeleteVertices { vertices } => self.delete_vertices(vertices),
            Tool::DeleteEdges { edges } => self.delete_edges(&pairs(edges)),
            Tool::DissolveVertices { vertices } => self.dissolve_vertices(vertices),
            Tool::MergeByDistance { vertices, distance } => {
                self.merge_by_distance(vertices, *distance)
            }
            Tool::Triangulate { faces } => self.triangulate_faces(faces),
            Tool::Fill { r#loop } => self.fill_loop(r#loop),
            Tool::GridFill {
                loop1,
                loop2,
                rim,
                span,
                offset,
            } => {
                if rim.is_empty() {
                    self.grid_fill(loop1, loop2)
                } else {
                    self.grid_fill_rim(rim, *span, *offset)
                }
            }
            Tool::TrisToQuads {
                faces,
                face_degrees,
                shape_degrees,
            } => self.tris_to_quads(faces, *face_degrees, *shape_degrees),
            Tool::Connect { vertices } => self.connect_vertices(vertices),
            Tool::ExtrudeEdges { edges, by } => {
                self.extrude_edges(&pairs(edges), DVec3::from_array(*by))
            }
            Tool::Spin {
                faces,
                edges,
                centre,
                axis,
                degrees,
                steps,
                advance,
            } => self.spin(
                faces,
                &pairs(edges),
                &SpinMotion {
                    centre: DVec3::from_array(*centre),
                    axis: DVec3::from_array(*axis),
                    degrees: *degrees,
                    steps: *steps,
                    advance: *advance,
                },
            ),
            Tool::Mirror {
                axis,
                merge_distance,
            } => self.mirror(usize::from(*axis), *merge_distance),
            Tool::Poke { faces } => self.poke_faces(faces),
            Tool::Subdivide { faces, cuts } => self.subdivide_faces(faces, *cuts),
            Tool::Knife {
                faces,
                point,
                normal,
                threshold,
            } => self.knife(
                faces,
                DVec3::from_array(*point),
                DVec3::from_array(*normal),
                *threshold,
            ),
        }
    }
}

impl Cage {
    /// Poke faces (Blender's Poke Faces, weighted mean centre): each face becomes a fan of
    /// triangles round a new point at its corners' mean weighted by the lengths of each
    /// corner's two edges. Triangle k runs from corner k to corner k + 1 and the centre; the
    /// first takes the face's index, the others and the centres follow in face order.
    pub fn poke_faces(&self, faces: &[usize]) -> Result<Self, CageEditError> {
        let faces = self.check_faces(faces)?;
        let mut out = self.clone();
        for &f in &faces {
            let face = &self.faces[f];
            let n = face.len();
            let p = |k: usize| self.points[face[k % n] as usize];
            let (mut sum, mut total) = (DVec3::ZERO, 0.0);
            for k in 0..n {
                let weight = p(k).distance(p(k + n - 1)) + p(k).distance(p(k + 1));
                sum += p(k) * weight;
                total += weight;
            }
            let centre = if total > 0.0 { sum / total } else { p(0) };
            let c = out.points.len() as u32;
            out.points.push(centre);
            out.faces[f] = vec![face[0], face[1 % n], c];
            for k in 1..n {
                out.faces.push(vec![face[k], face[(k + 1) % n], c]);
            }
        }
        Ok(out)
    }

    /// Mirror (Blender's Mirror modifier applied, with Merge): the whole cage is copied
    /// across the plane through the origin square to `axis` (0, 1, 2: x, y, z), the copies'
    /// faces turned so that the two halves agree, and each point within `merge_distance` of
    /// the plane is welded to its image (it stays where it is, and serves both halves). The
    /// copies follow the original points and faces in their order; creases and sharp points
    /// are copied with their edges and points.
    pub fn mirror(&self, axis: usize, merge_distance: f64) -> Result<Self, CageEditError> {
        if axis > 2 {
            return Err(invalid(format!(
                "the axis must be 0, 1 or 2 (x, y, z), not {axis}"
            )));
        }
        if !(merge_distance.is_finite() && merge_distance >= 0.0) {
            return Err(invalid("the merge distance must be a finite number ≥ 0"));
        }
        let mut out = self.clone();
        out.points.reserve(self.points.len());
        out.faces.reserve(self.faces.len());
        // Each point's image by index: itself within the merge distance of the plane, else its
        // new copy (a table, not a map: every point has one).
        let mut image: Vec<u32> = Vec::with_capacity(self.points.len());
        for (v, &p) in self.points.iter().enumerate() {
            if p[axis].abs() <= merge_distance {
                image.push(v as u32);
            } else {
                let mut q = p;
                q[axis] = -q[axis];
                image.push(out.points.len() as u32);
                out.points.push(q);
            }
        }
        let copied = |v: u32| image[v as usize] != v;
        // (A face lying in the plane would come back onto itself: it has no image.)
        for face in self.faces.iter().filter(|f| f.iter().any(|&v| copied(v))) {
            out.faces
                .push(face.iter().rev().map(|&v| image[v as usize]).collect());
        }
        for c in &self.creases {
            let (a, b) = (image[c.a as usize], image[c.b as usize]);
            if key(a, b) != key(c.a, c.b) {
                out.add_crease(a, b, c.sharpness);
            }
        }
        let copy: HashMap<u32, u32> = self
            .corners
            .iter()
            .filter(|c| copied(c.vertex))
            .map(|c| (c.vertex, image[c.vertex as usize]))
            .collect();
        out.copy_corners(&self.corners, &copy);
        Ok(out.compacted(self))
    }
}

/// Blender's split of a face before a weld: the first corner (in the face's order) whose
/// vertex merges into another that is also a corner of the face, not beside it, splits the
/// face along the chord between the two, and each piece is split again the same way.
fn split_at_targets(face: Vec<u32>, to: &impl Fn(u32) -> u32, out: &mut Vec<Vec<u32>>) {
    let n = face.len();
    let chord = (0..n).find_map(|i| {
        let target = to(face[i]);
        if target == face[i] {
            return None;
        }
        let j = face.iter().position(|&v| v == target)?;
        let beside = (i + 1) % n == j || (j + 1) % n == i;
        (!beside).then_some((i.min(j), i.max(j)))
    });
    match chord {
        Some((i, j)) => {
            let inner = face[i..=j].to_vec();
            let outer: Vec<u32> = face[j..].iter().chain(&face[..=i]).copied().collect();
            split_at_targets(inner, to, out);
            split_at_targets(outer, to, out);
        }
        None => out.push(face),
    }
}

/// A face after a weld, as Blender's weld makes it again: its corners mapped by `to`, those
/// that fall on the corner before them dropped (round the loop); none where a vertex is
/// then passed twice or fewer than three corners are left.
fn welded_face(face: &[u32], to: &impl Fn(u32) -> u32) -> Option<Vec<u32>> {
    let mut merged: Vec<u32> = face.iter().map(|&v| to(v)).collect();
    merged.dedup();
    while merged.len() > 1 && merged.first() == merged.last() {
        merged.pop();
    }
    let mut sorted = merged.clone();
    sorted.sort_unstable();
    let repeats = sorted.windows(2).any(|w| w[0] == w[1]);
    (merged.len() >= 3 && !repeats).then_some(merged)
}

fn check_thickness(thickness: f64) -> Result<(), CageEditError> {
    if thickness.is_finite() && thickness >= 0.0 {
        Ok(())
    } else {
        Err(invalid("the thickness must be a finite number ≥ 0"))
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::subdiv::cages;
    use crate::subdiv::{Options, SubdivisionSurface};
    use crate::test_support::{Xorshift, placement};

    pub(in crate::subdiv) fn cage_of(mesh: &crate::PolygonMesh, seed: u64) -> (Cage, f64) {
        let (motion, scale) = placement(seed);
        let points = mesh
            .points()
            .iter()
            .map(|&p| motion.transform_point3(p))
            .collect();
        let faces = mesh.faces().map(<[u32]>::to_vec).collect();
        (
            Cage {
                points,
                faces,
                creases: Vec::new(),
                corners: Vec::new(),
            },
            scale,
        )
    }

    /// A slid loop cut: on a 4 × 3 grid of quads (point (i, j) numbered 5j + i) in random
    /// position, the ring through the edge from (1, 0) to (2, 0) crosses every quad between
    /// columns 1 and 2; its new points lie, back in the grid's frame, at x = 1 + (k + slide) /
    /// (cuts + 1) on each row, with the faces of the evenly spaced cut, for cuts 1 to 3 and
    /// slides of either sign; a slide from b to a is the opposite slide. 0 is the even cut,
    /// and a slide of ±1 or beyond, or not a number, is refused.
    #[test]
    fn a_slid_loop_cut_moves_its_loops_together_towards_one_side() {
        let points: Vec<DVec3> = (0..4)
            .flat_map(|j| (0..5).map(move |i| DVec3::new(f64::from(i), f64::from(j), 0.0)))
            .collect();
        let faces: Vec<Vec<u32>> = (0..3u32)
            .flat_map(|j| {
                (0..4u32).map(move |i| vec![5 * j + i, 5 * j + i + 1, 5 * j + i + 6, 5 * j + i + 5])
            })
            .collect();
        let mut draw = Xorshift::new(0x511d);
        for round in 0..12 {
            let (motion, _) = placement(draw.bits());
            let cage = Cage {
                points: points.iter().map(|&p| motion.transform_point3(p)).collect(),
                faces: faces.clone(),
                creases: Vec::new(),
                corners: Vec::new(),
            };
            let cuts = 1 + round % 3;
            let slide = 1.8 * draw.unit() - 0.9;
            let even = cage.loop_cut(1, 2, cuts).unwrap();
            let slid = cage.loop_cut_slid(1, 2, cuts, slide).unwrap();
            assert_eq!(slid.faces, even.faces);
            assert_eq!(slid.points.len(), 20 + 4 * cuts as usize);
            assert_eq!(cage.loop_cut_slid(1, 2, cuts, 0.0).unwrap(), even);
            let back = motion.inverse();
            for row in 0..4 {
                let mut xs: Vec<f64> = slid.points[20..]
                    .iter()
                    .map(|&p| back.transform_point3(p))
                    .filter(|p| (p.y - f64::from(row)).abs() < 1e-9)
                    .map(|p| p.x)
                    .collect();
                xs.sort_by(f64::total_cmp);
                assert_eq!(xs.len(), cuts as usize, "round {round} row {row}");
                for (k, x) in xs.iter().enumerate() {
                    let want = 1.0 + (k as f64 + 1.0 + slide) / f64::from(cuts + 1);
                    assert!((x - want).abs() < 1e-9, "round {round}: {x} against {want}");
                }
            }
            // The same ring named from b to a slides the other way.
            let reversed = cage.loop_cut_slid(2, 1, cuts, -slide).unwrap();
            assert_eq!(reversed.points.len(), slid.points.len());
            for p in &reversed.points[20..] {
                let nearest = slid.points[20..].iter().map(|q| p.distance(*q));
                assert!(
                    nearest.fold(f64::INFINITY, f64::min) < 1e-9,
                    "round {round}"
                );
            }
        }
        let cage = Cage {
            points: points.clone(),
            faces: faces.clone(),
            creases: Vec::new(),
            corners: Vec::new(),
        };
        for bad in [1.0, -1.0, 2.5, f64::NAN, f64::INFINITY] {
            let refused = cage.loop_cut_slid(1, 2, 1, bad).unwrap_err().to_string();
            assert!(refused.contains("slide"), "{refused}");
        }
        // A tool without a slide reads and writes as it did before slides.
        let tool: Tool =
            serde_json::from_str(r#"{"loop-cut": {"edge": [1, 2], "cuts": 2}}"#).unwrap();
        assert_eq!(
            tool,
            Tool::LoopCut {
                edge: [1, 2],
                cuts: 2,
                slide: 0.0
            }
        );
        assert!(!serde_json::to_string(&tool).unwrap().contains("slide"));
    }

    /// Repeated faces are left out as a set of sorted corners would tell them (the first
    /// stays), on random faces over few points, so that many repeat in some order.
    #[test]
    fn repeated_faces_are_left_out_as_a_set_of_sorted_corners_would() {
        let mut random = Xorshift::new(5);
        for round in 0..200 {
            let points = 4 + round % 5;
            let faces: Vec<Vec<u32>> = (0..1 + random.below(30))
                .map(|_| {
                    let mut corners: Vec<u32> = (0..points as u32).collect();
                    // A random arrangement's first 3 or 4 corners (2 at times: a bad face).
                    for k in (1..corners.len()).rev() {
                        corners.swap(k, random.below(k as u64 + 1) as usize);
                    }
                    corners.truncate(2 + random.below(3) as usize);
                    corners
                })
                .collect();
            let mut seen = std::collections::HashSet::new();
            let expected: Vec<Vec<u32>> = faces
                .iter()
                .filter(|face| {
                    let mut corners = face.to_vec();
                    corners.sort_unstable();
                    seen.insert(corners)
                })
                .cloned()
                .collect();
            assert_eq!(without_repeated_faces(faces), expected, "round {round}");
        }
        assert!(without_repeated_faces(Vec::new()).is_empty());
        assert_eq!(
            without_repeated_faces(vec![vec![], vec![]]),
            vec![Vec::<u32>::new()]
        );
    }

    /// The half-edges answer as a map filled with every face's corners in face order would:
    /// on random tools' cages, and with faces flipped (their half-edges then appear twice,
    /// and the later face's win).
    #[test]
    fn half_edges_answer_as_a_map_of_every_corner() {
        let mesh = cages::torus(DVec3::ZERO, 3.0, 1.0, 8, 6).unwrap();
        let (torus, _) = cage_of(&mesh, 11);
        let mut random = Xorshift::new(23);
        let mut cages = vec![torus.clone()];
        for _ in 0..6 {
            let faces: Vec<usize> = (0..3)
                .map(|_| random.below(torus.faces.len() as u64) as usize)
                .collect();
            let extruded = torus.extrude_faces(&faces, 0.1).unwrap();
            let mut flipped = extruded.clone();
            let f = random.below(flipped.faces.len() as u64) as usize;
            flipped.faces[f].reverse();
            cages.extend([extruded, flipped]);
        }
        for cage in &cages {
            let mut map = std::collections::HashMap::new();
            for (f, face) in cage.faces.iter().enumerate() {
                for c in 0..face.len() {
                    map.insert((face[c], face[(c + 1) % face.len()]), (f, c));
                }
            }
            let half = cage.half_edges();
            for (edge, corner) in &map {
                assert_eq!(half.get(edge), Some(corner));
                let (a, b) = *edge;
                assert_eq!(half.contains_key(&(b, a)), map.contains_key(&(b, a)));
            }
            let listed: std::collections::HashMap<_, _> = half.iter().collect();
            assert_eq!(listed, map);
            assert_eq!(half.iter().count(), map.len(), "an edge listed twice");
            let n = cage.points.len() as u32;
            assert_eq!(half.get(&(n, 0)), None);
            assert_eq!(half.get(&(0, n + 5)), None);
        }
    }

    /// The cage as a subdivision surface: manifold, every edge between faces of agreeing
    /// winding.
    pub(in crate::subdiv) fn check_cage(cage: &Cage) {
        let mesh = crate::PolygonMesh::new(cage.points.clone(), &cage.faces).unwrap();
        SubdivisionSurface::new(
            mesh,
            cage.creases.clone(),
            cage.corners.clone(),
            Options::default(),
            0,
        )
        .unwrap();
    }

    /// V − E + F.
    pub(in crate::subdiv) fn euler(cage: &Cage) -> i64 {
        let edges: HashSet<(u32, u32)> = cage
            .faces
            .iter()
            .flat_map(|f| (0..f.len()).map(move |c| key(f[c], f[(c + 1) % f.len()])))
            .collect();
        cage.points.len() as i64 - edges.len() as i64 + cage.faces.len() as i64
    }

    /// Every half-edge once: the faces agree in winding (and no edge has three faces).
    pub(in crate::subdiv) fn consistently_wound(cage: &Cage) -> bool {
        let mut seen = HashSet::default();
        cage.faces
            .iter()
            .all(|f| (0..f.len()).all(|c| seen.insert((f[c], f[(c + 1) % f.len()]))))
    }

    /// The half-edges whose twin no face has: the cage's open rim, each rim edge once.
    pub(in crate::subdiv) fn open_half_edges(cage: &Cage) -> usize {
        let half: HashSet<(u32, u32)> = cage
            .faces
            .iter()
            .flat_map(|f| (0..f.len()).map(move |c| (f[c], f[(c + 1) % f.len()])))
            .collect();
        half.iter()
            .filter(|&&(a, b)| !half.contains(&(b, a)))
            .count()
    }

    /// The enclosed volume (divergence theorem over the faces' fans).
    pub(in crate::subdiv) fn volume(cage: &Cage) -> f64 {
        let p = |v: u32| cage.points[v as usize];
        cage.faces
            .iter()
            .map(|f| {
                (1..f.len() - 1)
                    .map(|k| p(f[0]).dot(p(f[k]).cross(p(f[k + 1]))) / 6.0)
                    .sum::<f64>()
            })
            .sum()
    }

    fn area(cage: &Cage, face: &[u32]) -> f64 {
        let p = |v: u32| cage.points[v as usize];
        (1..face.len() - 1)
            .map(|k| (p(face[k]) - p(face[0])).cross(p(face[k + 1]) - p(face[0])))
            .sum::<DVec3>()
            .length()
            / 2.0
    }

    #[test]
    fn extruding_a_flat_face_adds_its_area_times_the_offset_to_the_volume() {
        for seed in 1..6 {
            let (cage, scale) = cage_of(&cages::cube(DVec3::ZERO, 2.0).unwrap(), seed);
            let d = 0.37 * scale * seed as f64;
            let out = cage.extrude_faces(&[2], d).unwrap();
            check_cage(&out);
            let expected = volume(&cage) + area(&cage, &cage.faces[2]) * d;
            assert!(
                (volume(&out) - expected).abs() < 1e-10 * expected.abs(),
                "{} against {expected}",
                volume(&out)
            );
            // The eight corners keep their indices and places.
            assert_eq!(&out.points[..8], &cage.points[..8]);
        }
    }

    /// A whole closed cage extruded as a region is copied (Blender keeps faces that border no
    /// other): the originals stay turned over and the copy is the cage moved by d along the
    /// faces' mean normal, enclosing the same volume; a whole open grid extruded closes into
    /// a slab of volume area × d.
    #[test]
    fn extruding_a_whole_piece_keeps_its_faces_turned_over() {
        for seed in 1..6u64 {
            let (mut cube, scale) = cage_of(&cages::cube(DVec3::ZERO, 2.0).unwrap(), seed);
            // One corner pulled out, so that the faces' unit normals do not cancel.
            let centre = cube.points.iter().sum::<DVec3>() / 8.0;
            let corner = cube.points[0];
            cube.points[0] = corner + (corner - centre) * 0.4;
            let all: Vec<usize> = (0..cube.faces.len()).collect();
            let d = 0.3 * scale;
            let out = cube.extrude_faces(&all, d).unwrap();
            assert_eq!((out.points.len(), out.faces.len()), (16, 12));
            assert!(consistently_wound(&out));
            assert_eq!(euler(&out), 4, "two closed shells");
            // The copy encloses the cube's volume wherever it is moved.
            let copy = Cage {
                faces: out.faces[6..].to_vec(),
                ..out.clone()
            };
            assert!((volume(&copy) - volume(&cube)).abs() < 1e-9 * volume(&cube).abs());
            let step = out.points[8] - cube.points[0];
            for k in 0..8 {
                assert!((out.points[8 + k] - cube.points[k] - step).length() < 1e-12 * scale);
            }
            assert!((step.length() - d).abs() < 1e-12 * scale);
            for f in 0..6 {
                let mut turned = cube.faces[f].clone();
                turned.reverse();
                assert_eq!(out.faces[f], turned);
            }

            let (grid, scale) = cage_of(&cages::grid(DVec3::ZERO, 2.0, 3).unwrap(), seed);
            let all: Vec<usize> = (0..grid.faces.len()).collect();
            let d = -0.4 * scale;
            let slab = grid.extrude_faces(&all, d).unwrap();
            check_cage(&slab);
            assert_eq!(euler(&slab), 2, "a closed slab");
            let open = slab
                .faces
                .iter()
                .flat_map(|f| (0..f.len()).map(move |c| (f[(c + 1) % f.len()], f[c])));
            let half: HashSet<(u32, u32)> = slab
                .faces
                .iter()
                .flat_map(|f| (0..f.len()).map(move |c| (f[c], f[(c + 1) % f.len()])))
                .collect();
            assert!(open.into_iter().all(|e| half.contains(&e)), "no open edge");
            let flat: f64 = grid.faces.iter().map(|f| area(&grid, f)).sum();
            assert!(
                (volume(&slab).abs() - flat * d.abs()).abs() < 1e-9 * flat * d.abs(),
                "{} against {}",
                volume(&slab),
                flat * d
            );
        }
    }

    /// Two square holes side by side in a grid (in general position, so their loops' normals
    /// lie square to the line between them) bridged: a handle, every quad wound with its
    /// neighbours, the grid's rim the only open edges, χ = −1 (one handle, one rim), each
    /// loop named either way round.
    #[test]
    fn a_bridge_between_two_holes_in_a_plane_agrees_in_winding() {
        for seed in 1..9u64 {
            let (mut grid, _) = cage_of(&cages::grid(DVec3::ZERO, 6.0, 6).unwrap(), seed);
            // Faces (1, 2) and (4, 2) of the 6 × 6 grid; points i · 7 + j.
            grid.faces.remove(26);
            grid.faces.remove(8);
            let mut first = vec![9, 16, 17, 10];
            let mut second = vec![30, 37, 38, 31];
            if seed % 2 == 0 {
                first.reverse();
            }
            if seed % 3 == 0 {
                second.reverse();
            }
            // (The bridge's quads lie in the grid's plane, some with their corners in one
            // line: a valid topology of degenerate faces, so only the topology is checked.)
            let out = grid.bridge_loops(&first, &second).unwrap();
            assert!(consistently_wound(&out), "seed {seed}");
            assert_eq!(euler(&out), -1);
            assert_eq!(open_half_edges(&out), 24, "only the grid's rim is open");
        }
    }

    /// A cone's base edge dissolved: its side triangle joins the base, the two base points
    /// left between two edges go, and the side triangle beside the dissolved edge's other
    /// neighbour, left with two corners, folds into the edge it shares (as Blender's
    /// dissolve): a closed cage of one point fewer per side gone.
    #[test]
    fn a_dissolve_folds_a_triangle_left_with_two_corners_into_an_edge() {
        let n = 6u32;
        let mut points: Vec<DVec3> = (0..n)
            .map(|k| {
                let a = std::f64::consts::TAU * f64::from(k) / f64::from(n);
                DVec3::new(a.cos(), a.sin(), 0.0)
            })
            .collect();
        points.push(DVec3::new(0.1, -0.05, 1.5));
        let mut faces: Vec<Vec<u32>> = (0..n).map(|k| vec![k, (k + 1) % n, n]).collect();
        faces.push((0..n).rev().collect());
        let cone = Cage {
            points,
            faces,
            creases: Vec::new(),
            corners: Vec::new(),
        };
        check_cage(&cone);
        let out = cone.dissolve_edges(&[(3, 4)]).unwrap();
        check_cage(&out);
        assert_eq!((out.points.len(), out.faces.len()), (5, 4));
        assert_eq!(euler(&out), 2);
        let sizes: Vec<usize> = out.faces.iter().map(Vec::len).collect();
        assert_eq!(sizes.iter().filter(|&&k| k == 3).count(), 3, "{sizes:?}");
        assert!(sizes.contains(&5), "{sizes:?}");
    }

    /// A square face of a randomly placed cube inset by t with depth d (as a region, or each
    /// of two opposite faces on its own) adds a frustum of height d on each, between the face
    /// (side s) and the inner square (side s − 2t): d/3 (A₁ + A₂ + √(A₁A₂)) each; a negative
    /// depth takes it away. The inner face lies d from the face's plane, and a depth of 0 is
    /// the plain inset.
    #[test]
    fn an_inset_with_depth_raises_a_frustum_on_each_face() {
        for seed in 1..9u64 {
            let (cage, scale) = cage_of(&cages::cube(DVec3::ZERO, 2.0).unwrap(), seed);
            let side = 2.0 * scale;
            let t = side * (0.05 + 0.04 * seed as f64);
            let d = side * 0.3 * if seed % 2 == 0 { 1.0 } else { -0.7 };
            let (a1, a2) = (side * side, (side - 2.0 * t).powi(2));
            let frustum = d / 3.0 * (a1 + a2 + (a1 * a2).sqrt());
            for (faces, individual) in [(vec![2], false), (vec![0, 2], true)] {
                let out = cage.inset(&faces, t, d, individual).unwrap();
                check_cage(&out);
                let expected = volume(&cage) + frustum * faces.len() as f64;
                assert!(
                    (volume(&out) - expected).abs() < 1e-9 * expected.abs(),
                    "seed {seed}: {} against {expected}",
                    volume(&out)
                );
                for &f in &faces {
                    let normal = polygon_normal(&cage.points, &cage.faces[f]);
                    let on_face = cage.points[cage.faces[f][0] as usize];
                    for &v in &out.faces[f] {
                        let height = (out.points[v as usize] - on_face).dot(normal);
                        assert!((height - d).abs() < 1e-9 * side, "{height} against {d}");
                    }
                }
                assert_eq!(
                    cage.inset(&faces, t, 0.0, individual).unwrap(),
                    cage.apply(&Tool::Inset {
                        faces: faces.clone(),
                        thickness: t,
                        depth: 0.0,
                        individual
                    })
                    .unwrap()
                );
            }
        }
        let (cage, _) = cage_of(&cages::cube(DVec3::ZERO, 2.0).unwrap(), 3);
        assert!(cage.inset(&[0], 0.1, f64::NAN, false).is_err());
    }

    #[test]
    fn an_inset_strip_has_the_width_asked_for_along_every_edge() {
        for seed in 1..4 {
            let (cage, scale) = cage_of(&cages::cube(DVec3::ZERO, 2.0).unwrap(), seed);
            let t = 0.13 * scale * seed as f64;
            for individual in [false, true] {
                let out = if individual {
                    cage.inset_individual(&[0], t)
                } else {
                    cage.inset_region(&[0], t)
                }
                .unwrap();
                check_cage(&out);
                // The inner face is face 0; each of its edges lies t from the outer edge's
                // line, in the face's plane.
                let inner = &out.faces[0];
                let outer = &cage.faces[0];
                for c in 0..4 {
                    let (a, b) = (
                        cage.points[outer[c] as usize],
                        cage.points[outer[(c + 1) % 4] as usize],
                    );
                    let dir = (b - a).normalize();
                    for k in [c, (c + 1) % 4] {
                        let q = out.points[inner[k] as usize];
                        let off = (q - a) - dir * (q - a).dot(dir);
                        assert!((off.length() - t).abs() < 1e-12 * scale, "{}", off.length());
                    }
                }
            }
        }
    }

    /// A beveled creased edge of a cube in general position leaves its sharpness on two
    /// edges of the same length parallel to it (the band's outer rails), whatever the
    /// segments, and an unbeveled creased edge at its end keeps its sharpness on what is left
    /// of it: the edge shortened by the width, its far end where it was.
    #[test]
    fn a_bevel_carries_the_creases_to_the_rails_and_the_pieces_left() {
        let cube = cages::cube(DVec3::ZERO, 2.0).unwrap();
        for seed in 0..9u64 {
            let (mut cage, scale) = cage_of(&cube, seed);
            let (a, b, c) = (cage.faces[0][0], cage.faces[0][1], cage.faces[0][2]);
            cage.creases = vec![
                Crease {
                    a,
                    b,
                    sharpness: 3.5,
                },
                Crease {
                    a: b,
                    b: c,
                    sharpness: 1.25,
                },
            ];
            let p = |cage: &Cage, v: u32| cage.points[v as usize];
            let (along, side) = (p(&cage, b) - p(&cage, a), p(&cage, c) - p(&cage, b));
            let width = 0.2 * scale;
            let segments = 1 + (seed % 3) as u32;
            let out = cage.bevel_edges(&[(a, b)], width, segments).unwrap();
            check_cage(&out);
            let edge = |c: &Crease| p(&out, c.b) - p(&out, c.a);
            let rails: Vec<&Crease> = out.creases.iter().filter(|c| c.sharpness == 3.5).collect();
            assert_eq!(rails.len(), 2, "seed {seed}");
            for rail in rails {
                let e = edge(rail);
                assert!(e.cross(along).length() <= 1e-9 * along.length_squared());
                assert!((e.length() - along.length()).abs() <= 1e-9 * scale);
            }
            let far = p(&cage, c);
            let piece = out
                .creases
                .iter()
                .find(|k| {
                    k.sharpness == 1.25
                        && (p(&out, k.a) - far)
                            .length()
                            .min((p(&out, k.b) - far).length())
                            <= 1e-12 * scale
                })
                .unwrap_or_else(|| panic!("seed {seed}: the piece lost its crease"));
            let e = edge(piece);
            assert!(e.cross(side).length() <= 1e-9 * side.length_squared());
            assert!((e.length() - (side.length() - width)).abs() <= 1e-9 * scale);
        }
    }

    #[test]
    fn creases_follow_their_edges_through_the_tools() {
        let (mut cage, scale) = cage_of(&cages::cube(DVec3::ZERO, 2.0).unwrap(), 9);
        let (a, b) = (cage.faces[0][0], cage.faces[0][1]);
        cage.creases.push(Crease {
            a,
            b,
            sharpness: 2.5,
        });
        cage.corners.push(Corner {
            vertex: a,
            sharpness: 1.0,
        });
        // A loop cut splits the creased edge into three creased pieces.
        let cut = cage.loop_cut(a, b, 2).unwrap();
        check_cage(&cut);
        assert_eq!(cut.creases.len(), 3);
        assert!(cut.creases.iter().all(|c| c.sharpness == 2.5));
        let chain: f64 = cut
            .creases
            .iter()
            .map(|c| cut.points[c.a as usize].distance(cut.points[c.b as usize]))
            .sum();
        let length = cage.points[a as usize].distance(cage.points[b as usize]);
        assert!((chain - length).abs() < 1e-12 * scale);
        // An extrusion of the face copies the crease to the lifted edge.
        let lifted = cage.extrude_faces(&[0], 0.5 * scale).unwrap();
        assert_eq!(lifted.creases.len(), 2);
        assert_eq!(lifted.corners.len(), 2);
        // Deleting the faces on both sides drops it.
        let faces: Vec<usize> = (0..cage.faces.len())
            .filter(|&f| {
                let face = &cage.faces[f];
                (0..face.len()).any(|c| key(face[c], face[(c + 1) % face.len()]) == key(a, b))
            })
            .collect();
        assert!(cage.delete_faces(&faces).unwrap().creases.is_empty());
    }

    #[test]
    fn random_tool_sequences_keep_a_torus_a_closed_oriented_torus() {
        let mut random = Xorshift::new(61);
        let (mut cage, scale) = cage_of(&cages::torus(DVec3::ZERO, 2.0, 0.7, 8, 6).unwrap(), 61);
        for step in 0..40 {
            let faces = cage.faces.len() as u64;
            let face = random.below(faces) as usize;
            let f = cage.faces[face].clone();
            let result = match step % 5 {
                0 => cage.extrude_faces(&[face], (random.unit() - 0.3) * 0.2 * scale),
                1 => cage.inset_region(&[face], 0.05 * scale),
                2 => cage.inset_individual(&[face], 0.05 * scale),
                3 => cage.loop_cut(f[0], f[1], 1 + random.below(3) as u32),
                _ => cage.bevel_edges(&[(f[0], f[1])], 0.02 * scale, 2),
            };
            // A bevel may meet a corner it does not build, and a loop cut an edge with no quad
            // beside it (a bevel's end): each says so and changes nothing.
            let Ok(next) = result else {
                assert!(
                    step % 5 == 4
                        || (step % 5 == 3
                            && matches!(result, Err(CageEditError::RingWithoutQuads { .. }))),
                    "step {step}: {result:?}"
                );
                continue;
            };
            check_cage(&next);
            assert_eq!(euler(&next), 0, "step {step}");
            cage = next;
        }
        assert!(cage.faces.len() > 48);
    }

    /// A box with every edge beveled by w into s segments is the box rounded by w: every
    /// point lies w from the box shrunk by w (arcs about its edges, sphere octants about its
    /// corners), and the cage stays a closed sphere.
    #[test]
    fn a_box_beveled_at_every_edge_lies_on_the_rounded_box() {
        for seed in 1..5 {
            let (cage, scale) = cage_of(&cages::cube(DVec3::ZERO, 2.0).unwrap(), seed);
            let (motion, _) = placement(seed);
            let back = motion.inverse();
            let edges: Vec<(u32, u32)> = cage
                .faces
                .iter()
                .flat_map(|f| (0..4).map(move |c| key(f[c], f[(c + 1) % 4])))
                .collect::<HashSet<_>>()
                .into_iter()
                .collect();
            let w = 0.1 + 0.05 * seed as f64;
            for segments in 2..7 {
                let beveled = cage.bevel_edges(&edges, w * scale, segments).unwrap();
                check_cage(&beveled);
                assert_eq!(euler(&beveled), 2);
                // Every point is a corner's: three sides of (⌊s/2⌋ + 1) × (⌊s/2⌋ + 1) points
                // for odd s; for even s three of ⌊s/2⌋ × (⌊s/2⌋ + 1) and the centre.
                let h = segments as usize / 2;
                let corner_points = if segments % 2 == 1 {
                    3 * (h + 1) * (h + 1)
                } else {
                    3 * h * (h + 1) + 1
                };
                assert_eq!(
                    beveled.points.len(),
                    8 * corner_points,
                    "{segments} segments"
                );
                for &p in &beveled.points {
                    let local = back.transform_point3(p);
                    let inner = local.clamp(DVec3::splat(w - 1.0), DVec3::splat(1.0 - w));
                    let distance = local.distance(inner);
                    assert!((distance - w).abs() < 1e-9, "{segments}: {distance} vs {w}");
                }
            }
        }
    }

    /// Corners of three and four beveled edges on a torus, where no face meets another
    /// square: the general corner mesh and the pipe keep the torus closed and oriented.
    #[test]
    fn corners_of_several_beveled_edges_keep_a_torus_closed_and_oriented() {
        let mut random = Xorshift::new(7);
        let (cage, scale) = cage_of(&cages::torus(DVec3::ZERO, 2.0, 0.7, 8, 6).unwrap(), 7);
        let half = cage.half_edges();
        for _ in 0..12 {
            let v = random.below(cage.points.len() as u64) as u32;
            let around: Vec<u32> = half.keys().filter(|e| e.0 == v).map(|e| e.1).collect();
            let take = 3 + random.below(2) as usize;
            let edges: Vec<(u32, u32)> = around.iter().take(take).map(|&x| (v, x)).collect();
            let segments = 2 + random.below(4) as u32;
            let beveled = cage.bevel_edges(&edges, 0.05 * scale, segments).unwrap();
            check_cage(&beveled);
            assert_eq!(euler(&beveled), 0);
        }
    }

    /// Subdividing every face of a box with n cuts makes each face (n + 1)² quads of equal
    /// area, keeps its volume and χ = 2, and gives a creased edge's pieces its sharpness;
    /// subdividing random faces of a torus (straight cuts and three-sided patterns beside
    /// them) keeps it a closed oriented torus.
    #[test]
    fn subdivided_faces_keep_the_shape_and_split_evenly() {
        for seed in 1..4 {
            let (mut cage, _) = cage_of(&cages::cube(DVec3::ZERO, 2.0).unwrap(), seed);
            let (a, b) = (cage.faces[0][0], cage.faces[0][1]);
            cage.creases.push(Crease {
                a,
                b,
                sharpness: 2.5,
            });
            let all: Vec<usize> = (0..6).collect();
            for cuts in 1..5u32 {
                let out = cage.subdivide_faces(&all, cuts).unwrap();
                let n = cuts as usize + 1;
                assert_eq!(out.faces.len(), 6 * n * n);
                assert_eq!(euler(&out), 2);
                check_cage(&out);
                assert!((volume(&out) - volume(&cage)).abs() < 1e-9 * volume(&cage).abs());
                let piece = area(&cage, &cage.faces[0]) / (n * n) as f64;
                for face in &out.faces {
                    assert!((area(&out, face) - piece).abs() < 1e-9 * piece);
                }
                assert_eq!(out.creases.len(), n);
                assert!(out.creases.iter().all(|c| c.sharpness == 2.5));
            }
        }
        let mut random = Xorshift::new(5);
        let (mut torus, _) = cage_of(&cages::torus(DVec3::ZERO, 2.0, 0.7, 8, 6).unwrap(), 5);
        for _ in 0..6 {
            let faces: Vec<usize> = (0..3)
                .map(|_| random.below(torus.faces.len() as u64) as usize)
                .collect();
            torus = torus
                .subdivide_faces(&faces, 1 + random.below(3) as u32)
                .unwrap();
            check_cage(&torus);
            assert_eq!(euler(&torus), 0);
        }
    }

    #[test]
    fn a_mirrored_box_has_twice_the_volume_and_one_touching_the_plane_welds_into_one_box() {
        // A box from x = 1 to 3: its mirror is a second box, closed and as large.
        let cube = super::super::cages::cube(DVec3::new(2.0, 0.0, 0.0), 2.0).unwrap();
        let boxed = Cage {
            points: cube.points().to_vec(),
            faces: cube.faces().map(<[u32]>::to_vec).collect(),
            ..Cage::default()
        };
        let v = volume(&boxed);
        assert!((v - 8.0).abs() < 1e-12, "{v}");
        let twice = boxed.mirror(0, 1e-3).unwrap();
        check_cage(&twice);
        assert_eq!((twice.points.len(), twice.faces.len()), (16, 12));
        assert!((volume(&twice) - 2.0 * v).abs() < 1e-12);
        // Open the box at x = 1 (the face of its points 0, 2, 4, 6) and move that side onto
        // the plane: the mirror closes it into one box from x = -3 to 3 (its seam points
        // welded, its χ = 2).
        let mut open = boxed.clone();
        open.faces.retain(|f| !f.iter().all(|v| v % 2 == 0));
        for p in &mut open.points {
            if p.x == 1.0 {
                p.x = 0.0;
            }
        }
        let closed = open.mirror(0, 1e-3).unwrap();
        check_cage(&closed);
        assert_eq!((closed.points.len(), closed.faces.len()), (12, 10));
        assert_eq!(euler(&closed), 2);
        assert!(
            (volume(&closed) - 24.0).abs() < 1e-12,
            "{}",
            volume(&closed)
        );
        assert!(boxed.mirror(3, 0.0).is_err() && boxed.mirror(0, f64::NAN).is_err());
    }

    #[test]
    fn poking_every_face_of_a_box_keeps_its_volume_and_makes_four_triangles_a_face() {
        let cube = super::super::cages::cube(DVec3::new(0.3, -2.0, 5.0), 1.7).unwrap();
        let boxed = Cage {
            points: cube.points().to_vec(),
            faces: cube.faces().map(<[u32]>::to_vec).collect(),
            ..Cage::default()
        };
        let poked = boxed.poke_faces(&[0, 1, 2, 3, 4, 5]).unwrap();
        check_cage(&poked);
        assert_eq!((poked.points.len(), poked.faces.len()), (14, 24));
        assert!(poked.faces.iter().all(|f| f.len() == 3));
        assert_eq!(euler(&poked), 2);
        assert!((volume(&poked) - 1.7f64.powi(3)).abs() < 1e-12);
        // Each centre is its square face's middle (equal weights).
        let middle = (0..4).map(|k| cube.points()[cube.faces().next().unwrap()[k] as usize]);
        assert!((poked.points[8] - middle.sum::<DVec3>() / 4.0).length() < 1e-12);
    }

    #[test]
    fn bad_requests_are_refused_with_a_reason() {
        let (cage, _) = cage_of(&cages::cube(DVec3::ZERO, 2.0).unwrap(), 3);
        let normal = |f: usize| polygon_normal(&cage.points, &cage.faces[f]);
        let opposite = (1..6).find(|&f| normal(f).dot(normal(0)) < -0.99).unwrap();
        let mut around: Vec<u32> = cage
            .faces
            .iter()
            .filter_map(|f| f.iter().position(|&v| v == 0).map(|c| f[(c + 1) % f.len()]))
            .collect();
        around.sort_unstable();
        let corner: Vec<(u32, u32)> = around.iter().map(|&n| (0, n)).collect();
        assert_eq!(corner.len(), 3);
        let refusals = [
            cage.extrude_faces(&[6], 1.0).err(),
            cage.extrude_faces(&[0], f64::NAN).err(),
            cage.extrude_faces(&[0, opposite], 1.0).err(), // the normals cancel
            cage.inset_region(&[0], -1.0).err(),
            cage.inset_individual(&[], 0.1).err(),
            cage.loop_cut(0, 7, 1).err(),
            cage.loop_cut(0, 1, 0).err(),
            cage.loop_cut(0, 99, 1).err(),
            cage.bevel_edges(&[(0, 1)], 0.0, 1).err(),
            // Too many segments; no cuts; a face that is not there.
            cage.bevel_edges(&corner, 0.1, 1001).err(),
            cage.subdivide_faces(&[0], 0).err(),
            cage.subdivide_faces(&[6], 1).err(),
            cage.dissolve_faces(&[0, opposite]).err(), // they share no edge
            cage.bridge_loops(&[0, 1, 3], &[4, 5]).err(),
            cage.bridge_loops(&[0, 1, 3, 2], &[4, 5, 7, 6]).err(),
            cage.merge_vertices(&[], false).err(),
            cage.merge_vertices(&[8], false).err(),
            cage.dissolve_edges(&[(0, 7)]).err(),
            cage.delete_faces(&[0, 1, 2, 3, 4, 5]).err(),
        ];
        for (k, refusal) in refusals.iter().enumerate() {
            let message = refusal.as_ref().map(ToString::to_string);
            assert!(
                message.is_some_and(|m| !m.is_empty()),
                "request {k} was taken"
            );
        }
    }

    /// An edge, face or point named twice (an edge either way round) is the same as named
    /// once, for every tool that takes a list: before, a bevel built the band of an edge
    /// named twice twice over. Cubes, tori and icosahedra in general position, each edge's
    /// neighbour round a point named again reversed.
    #[test]
    fn an_element_named_twice_is_taken_once() {
        let meshes = [
            cages::cube(DVec3::ZERO, 2.0).unwrap(),
            cages::torus(DVec3::ZERO, 2.0, 0.7, 8, 6).unwrap(),
            cages::icosahedron(DVec3::ZERO, 1.5).unwrap(),
        ];
        for (m, mesh) in meshes.iter().enumerate() {
            for seed in 0..3u64 {
                let (cage, scale) = cage_of(mesh, 90 + 7 * m as u64 + seed);
                let face = &cage.faces[(seed as usize * 5) % cage.faces.len()];
                let (a, b, c) = (face[0], face[1], face[2]);
                let once = [(a, b), (b, c)];
                let twice = [(a, b), (b, c), (b, a), (a, b)];
                let w = 0.05 * scale;
                assert_eq!(
                    cage.bevel_edges(&twice, w, 2).unwrap(),
                    cage.bevel_edges(&once, w, 2).unwrap(),
                    "bevel, mesh {m} seed {seed}"
                );
                assert_eq!(
                    cage.dissolve_edges(&twice[..3]).ok(),
                    cage.dissolve_edges(&once).ok(),
                    "dissolve, mesh {m} seed {seed}"
                );
                assert_eq!(
                    cage.bevel_vertices(&[b, a, b], w, 2).unwrap(),
                    cage.bevel_vertices(&[b, a], w, 2).unwrap()
                );
                assert_eq!(
                    cage.merge_vertices(&[a, c, a, c], false).ok(),
                    cage.merge_vertices(&[a, c], false).ok()
                );
                let faces = [0, 1, 0, 1];
                assert_eq!(
                    cage.extrude_faces(&faces, w).ok(),
                    cage.extrude_faces(&faces[..2], w).ok()
                );
                assert_eq!(
                    cage.inset(&faces, w, 0.0, false).ok(),
                    cage.inset(&faces[..2], w, 0.0, false).ok()
                );
            }
        }
    }

    /// Border edges named to a bevel or a dissolve are passed over, as Blender's bevel and
    /// dissolve pass over them: beside inner edges the result is the inner edges' alone, and
    /// border edges alone are refused by a typed error naming one (the CLI then writes the
    /// cage unchanged, as Blender leaves it). A grid in general position.
    #[test]
    fn border_edges_named_to_a_bevel_or_dissolve_are_passed_over() {
        for seed in 0..4 {
            let (grid, _) = cage_of(&cages::grid(DVec3::ZERO, 2.0, 3).unwrap(), 40 + seed);
            let half = grid.half_edges();
            let mut border = Vec::new();
            let mut inner = Vec::new();
            for face in &grid.faces {
                for c in 0..face.len() {
                    let (a, b) = (face[c], face[(c + 1) % face.len()]);
                    match half.get(&(b, a)) {
                        None => border.push((a, b)),
                        Some(_) if a < b => inner.push((a, b)),
                        Some(_) => {}
                    }
                }
            }
            // An inner edge with a border edge at one of its ends.
            let &(a, b) = inner
                .iter()
                .find(|&&(a, b)| {
                    border
                        .iter()
                        .any(|&(c, d)| [c, d].contains(&a) || [c, d].contains(&b))
                })
                .unwrap();
            let &side = border
                .iter()
                .find(|&&(c, d)| [c, d].contains(&a) || [c, d].contains(&b))
                .unwrap();
            assert_eq!(
                grid.bevel_edges(&[side, (a, b)], 0.1, 2).unwrap(),
                grid.bevel_edges(&[(a, b)], 0.1, 2).unwrap()
            );
            let far = *border
                .iter()
                .find(|&&(c, d)| ![c, d].contains(&a) && ![c, d].contains(&b))
                .unwrap();
            assert_eq!(
                grid.dissolve_edges(&[(a, b), far]).unwrap(),
                grid.dissolve_edges(&[(a, b)]).unwrap()
            );
            for refusal in [
                grid.bevel_edges(&[side, far], 0.1, 1),
                grid.dissolve_edges(&[far]),
            ] {
                match refusal {
                    Err(CageEditError::EveryEdgeOnBorder { a, b, .. }) => {
                        assert!(border.contains(&(a, b)) || border.contains(&(b, a)));
                    }
                    other => panic!("border edges alone: {other:?}"),
                }
            }
        }
    }

    /// Every tool with random arguments (indices past the cage, NaN, infinite, negative and
    /// huge numbers, absurd counts) on cages grown by earlier tools: each either refuses or
    /// gives a cage whose faces name its points, with three or more corners each and finite
    /// points. Nothing panics.
    #[test]
    fn no_tool_panics_on_random_arguments() {
        let mut draw = Xorshift::new(2026);
        let starts = [
            cages::cube(DVec3::ZERO, 2.0).unwrap(),
            cages::torus(DVec3::ZERO, 2.0, 0.6, 6, 4).unwrap(),
            cages::grid(DVec3::ZERO, 2.0, 3).unwrap(),
            cages::cylinder(DVec3::ZERO, 1.0, 2.0, 6, 2).unwrap(),
            cages::icosahedron(DVec3::ZERO, 1.0).unwrap(),
        ];
        let numbers = [
            0.0,
            0.1,
            -0.3,
            0.45,
            1.0,
            3.0,
            1e-12,
            1e9,
            -1e9,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ];
        let counts = [0u32, 1, 2, 3, 7, 65, 100_000, u32::MAX];
        let mut applied = 0;
        for round in 0..600 {
            let (mut cage, _) = cage_of(&starts[round % starts.len()], round as u64);
            for _ in 0..6 {
                let n = cage.points.len() as u64 + 2;
                let m = cage.faces.len() as u64 + 2;
                let mut vertex = || draw.below(n) as u32;
                let vertices: Vec<u32> = (0..1 + round % 4).map(|_| vertex()).collect();
                let edges: Vec<[u32; 2]> = (0..1 + round % 3)
                    .map(|_| {
                        // An edge of a face where there is one, else any pair.
                        let f = draw.below(m) as usize;
                        match cage.faces.get(f) {
                            Some(face) if draw.below(4) > 0 => {
                                let c = draw.below(face.len() as u64) as usize;
                                [face[c], face[(c + 1) % face.len()]]
                            }
                            _ => [draw.below(n) as u32, draw.below(n) as u32],
                        }
                    })
                    .collect();
                let faces: Vec<usize> =
                    (0..1 + round % 5).map(|_| draw.below(m) as usize).collect();
                let number =
                    |draw: &mut Xorshift| numbers[draw.below(numbers.len() as u64) as usize];
                let (x, y, z) = (number(&mut draw), number(&mut draw), number(&mut draw));
                let (spin_degrees, spin_advance) = (number(&mut draw) * 100.0, number(&mut draw));
                let count = counts[draw.below(counts.len() as u64) as usize];
                let flag = draw.below(2) == 1;
                let tool = match draw.below(27) {
                    0 => Tool::Extrude {
                        faces,
                        offset: x,
                        individual: flag,
                    },
                    1 => Tool::Inset {
                        faces,
                        thickness: x,
                        depth: y,
                        individual: flag,
                    },
                    2 => Tool::LoopCut {
                        edge: edges[0],
                        cuts: count,
                        slide: y,
                    },
                    3 => Tool::Bevel {
                        edges,
                        width: x,
                        segments: count,
                    },
                    4 => Tool::BevelVertices {
                        vertices,
                        width: x,
                        segments: count,
                    },
                    5 => Tool::Bridge {
                        loop1: vertices.clone(),
                        loop2: vertices.iter().rev().copied().collect(),
                    },
                    6 => Tool::Merge {
                        vertices,
                        at_first: flag,
                    },
                    7 => Tool::Dissolve { edges },
                    8 => Tool::DissolveFaces { faces },
                    9 => Tool::Delete { faces },
                    10 => Tool::DeleteVertices { vertices },
                    11 => Tool::DeleteEdges { edges },
                    12 => Tool::DissolveVertices { vertices },
                    13 => Tool::MergeByDistance {
                        vertices: if flag { vertices } else { Vec::new() },
                        distance: x,
                    },
                    14 => Tool::Triangulate { faces },
                    15 => Tool::TrisToQuads {
                        faces,
                        face_degrees: x,
                        shape_degrees: y,
                    },
                    16 => Tool::Fill { r#loop: vertices },
                    17 => Tool::GridFill {
                        loop1: vertices.clone(),
                        loop2: vertices.iter().map(|v| v + 1).collect(),
                        rim: if flag { vertices } else { Vec::new() },
                        span: Some(count),
                        offset: Some(count as usize),
                    },
                    18 => Tool::Connect { vertices },
                    19 => Tool::ExtrudeEdges {
                        edges,
                        by: [x, y, z],
                    },
                    20 => Tool::Spin {
                        faces: if flag { faces } else { Vec::new() },
                        edges: if flag { Vec::new() } else { edges },
                        centre: [x, 0.0, y],
                        axis: [z, 1.0, 0.0],
                        degrees: spin_degrees,
                        steps: count,
                        advance: spin_advance,
                    },
                    21 => Tool::Poke { faces },
                    22 => Tool::Subdivide { faces, cuts: count },
                    23 => Tool::Knife {
                        faces: if flag { faces } else { Vec::new() },
                        point: [x, y, 0.0],
                        normal: [z, 1.0, x],
                        threshold: flag.then_some(y),
                    },
                    24 => Tool::Mirror {
                        axis: (count % 4) as u8,
                        merge_distance: x,
                    },
                    25 => Tool::GridFill {
                        loop1: Vec::new(),
                        loop2: Vec::new(),
                        rim: vertices,
                        span: None,
                        offset: None,
                    },
                    _ => Tool::LoopCut {
                        edge: edges[0],
                        cuts: count.min(3),
                        slide: 0.0,
                    },
                };
                if let Ok(out) = cage.apply(&tool) {
                    applied += 1;
                    for face in &out.faces {
                        assert!(
                            face.len() >= 3,
                            "{tool:?}: a face of {} corners",
                            face.len()
                        );
                        assert!(
                            face.iter().all(|&v| (v as usize) < out.points.len()),
                            "{tool:?}: a face names a point past the cage"
                        );
                    }
                    assert!(
                        out.points.iter().all(|p| p.is_finite()),
                        "{tool:?}: a point is not finite"
                    );
                    if out.points.len() < 4000 {
                        cage = out;
                    }
                }
            }
        }
        assert!(applied > 600, "only {applied} tools applied");
    }
}
