//! A closed shell of flat faces read as a polyhedron: its vertices (trim loop corners merged
//! within the tolerance, points where a boundary runs straight on dropped), its faces (plane,
//! and loops of vertices with the face on their left seen from the outward normal) and its
//! edges (each between two faces, once each way).

use std::collections::HashMap;

use glam::DVec3;

use crate::boolean::outward_faces;
use crate::curve::SpaceCurve;
use crate::error::{GeometryError, construction};
use crate::join::face_loops;
use crate::trim::TrimmedSurface;

use super::{WHAT, point};

/// A flat face: its plane `normal · x = offset` (outward unit normal) and its loops.
#[derive(Debug, Clone, PartialEq)]
pub struct Facet {
    pub normal: DVec3,
    pub offset: f64,
    /// Vertex indices, each loop with the face on its left seen from the normal's tip (the
    /// outer loop counter-clockwise, holes clockwise).
    pub loops: Vec<Vec<usize>>,
    /// Loops with a curved edge (a round hole), kept as they are: their edges in space.
    pub kept: Vec<Vec<SpaceCurve>>,
}

/// An edge: from vertex `a` to `b` in face `left`'s loop, from `b` to `a` in face `right`'s.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PolyEdge {
    pub a: usize,
    pub b: usize,
    pub left: usize,
    pub right: usize,
}

/// A closed polyhedron.
#[derive(Debug, Clone, PartialEq)]
pub struct Polyhedron {
    pub vertices: Vec<DVec3>,
    pub faces: Vec<Facet>,
    pub edges: Vec<PolyEdge>,
    /// The faces that are not flat (a round hole's wall), kept as they are: a feature takes
    /// none of their edges.
    pub kept: Vec<TrimmedSurface>,
    /// The edge of each directed pair (a, b) as some face's loop runs it.
    directed: HashMap<(usize, usize), usize>,
}

impl Polyhedron {
    /// The polyhedron of the closed shell `faces` (turned outward first), or why it is not
    /// one: a face that is not flat, a boundary that is not straight, an edge not shared by
    /// exactly two faces.
    pub fn from_faces(faces: &[TrimmedSurface], tolerance: f64) -> Result<Self, GeometryError> {
        Self::read(faces, tolerance, false)
    }

    /// [`Self::from_faces`] where curved faces, and loops of flat faces with a curved edge
    /// (round holes), may be kept as they are: the edges between flat faces are the
    /// polyhedron's.
    pub fn with_curved(faces: &[TrimmedSurface], tolerance: f64) -> Result<Self, GeometryError> {
        Self::read(faces, tolerance, true)
    }

    fn read(
        faces: &[TrimmedSurface],
        tolerance: f64,
        allow_curved: bool,
    ) -> Result<Self, GeometryError> {
        let (faces, _) = outward_faces(faces, tolerance, "the solid")?;
        let mut vertices: Vec<DVec3> = Vec::new();
        let mut vertex_of = |p: DVec3| -> usize {
            if let Some(k) = vertices.iter().position(|q| q.distance(p) <= tolerance) {
                k
            } else {
                vertices.push(p);
                vertices.len() - 1
            }
        };
        let mut facets = Vec::with_capacity(faces.len());
        let mut kept_faces = Vec::new();
        for (k, face) in faces.iter().enumerate() {
            let surface = face.surface();
            let Some((origin, _)) = surface.plane(tolerance) else {
                if !allow_curved {
                    return Err(construction(
                        WHAT,
                        format!(
                            "face {k} is curved; edge features are built on solids whose \
                             faces are all flat"
                        ),
                    ));
                }
                kept_faces.push(face.clone());
                continue;
            };
            let [(u0, u1), (v0, v1)] = surface.domain();
            let normal = surface.normal(0.5 * (u0 + u1), 0.5 * (v0 + v1))?;
            let mut loops = Vec::new();
            let mut kept = Vec::new();
            'rings: for trim_loop in face_loops(face)? {
                if allow_curved && !trim_loop.iter().all(|c| straight(surface, c, tolerance)) {
                    kept.push(in_space(surface, &trim_loop, tolerance).ok_or_else(|| {
                        construction(
                            WHAT,
                            format!("face {k}'s plane is not an affine image of its domain"),
                        )
                    })??);
                    continue 'rings;
                }
                let mut ring = Vec::new();
                for curve in &trim_loop {
                    let (t0, t1) = curve.domain();
                    let at = |t: f64| -> Result<DVec3, GeometryError> {
                        surface.point_at_clamped(curve.point_at(t)?)
                    };
                    if !straight(surface, curve, tolerance) {
                        return Err(construction(
                            WHAT,
                            format!(
                                "the edge of face {k} at {} is curved; edge features are built \
                                 on solids whose edges are all straight",
                                point(at(0.5 * (t0 + t1))?)
                            ),
                        ));
                    }
                    let a = at(t0)?;
                    ring.push(vertex_of(a));
                }
                ring.dedup();
                while ring.len() > 1 && ring.first() == ring.last() {
                    ring.pop();
                }
                if ring.len() >= 3 {
                    loops.push(ring);
                }
            }
            facets.push(Facet {
                normal,
                offset: normal.dot(origin),
                loops,
                kept,
            });
        }
        // A vertex lying on another face's edge (a fused body: a side face whose edge
        // runs past the corner where a face above starts) splits that edge, so the faces on
        // either side run the same pieces.
        split_at_vertices(&mut facets, &vertices, tolerance);
        // Faces in one plane that share an edge (a face a file split in two) are one face.
        let facets = merged_coplanar(facets, tolerance)?;
        let mut facets = facets;
        straighten(&mut facets, &vertices, tolerance);
        let mut directed = HashMap::new();
        for (f, facet) in facets.iter().enumerate() {
            for ring in &facet.loops {
                for i in 0..ring.len() {
                    let (a, b) = (ring[i], ring[(i + 1) % ring.len()]);
                    if directed.insert((a, b), f).is_some() {
                        return Err(construction(
                            WHAT,
                            format!(
                                "the edge from {} to {} is used twice the same way; the solid \
                                 is not a manifold",
                                point(vertices[a]),
                                point(vertices[b])
                            ),
                        ));
                    }
                }
            }
        }
        let mut edges = Vec::new();
        let mut edge_of = HashMap::new();
        for (&(a, b), &left) in &directed {
            let Some(&right) = directed.get(&(b, a)) else {
                return Err(construction(
                    WHAT,
                    format!(
                        "the edge from {} to {} has a face on one side only; the solid is \
                         open there",
                        point(vertices[a]),
                        point(vertices[b])
                    ),
                ));
            };
            if a < b {
                edge_of.insert((a, b), edges.len());
                edge_of.insert((b, a), edges.len());
                edges.push(PolyEdge { a, b, left, right });
            }
        }
        // A fixed order, whatever the hash map's.
        let mut order: Vec<usize> = (0..edges.len()).collect();
        order.sort_by_key(|&k| (edges[k].a, edges[k].b));
        let edges: Vec<PolyEdge> = order.iter().map(|&k| edges[k]).collect();
        let directed = edges
            .iter()
            .enumerate()
            .flat_map(|(k, e)| [((e.a, e.b), k), ((e.b, e.a), k)])
            .collect();
        Ok(Self {
            vertices,
            faces: facets,
            edges,
            kept: kept_faces,
            directed,
        })
    }

    /// The edge between vertices `a` and `b`, either way.
    pub fn edge_between(&self, a: usize, b: usize) -> Option<usize> {
        self.directed.get(&(a, b)).copied()
    }

    /// The edges at vertex `v`.
    pub fn edges_at(&self, v: usize) -> Vec<usize> {
        (0..self.edges.len())
            .filter(|&k| self.edges[k].a == v || self.edges[k].b == v)
            .collect()
    }

    /// The edge nearest `p` (its segment's distance).
    pub fn nearest_edge(&self, p: DVec3) -> Option<usize> {
        (0..self.edges.len()).min_by(|&i, &j| {
            self.edge_distance(i, p)
                .total_cmp(&self.edge_distance(j, p))
        })
    }

    /// The face nearest `p`: its plane's distance where `p` lies over the face, else the
    /// distance to its boundary.
    pub fn nearest_face(&self, p: DVec3) -> Option<usize> {
        (0..self.faces.len()).min_by(|&i, &j| {
            self.face_distance(i, p)
                .total_cmp(&self.face_distance(j, p))
        })
    }

    /// The faces nearest `points` (one each), sorted, without repeats; refused for a point
    /// that is not finite.
    pub fn nearest_faces(&self, points: &[DVec3]) -> Result<Vec<usize>, GeometryError> {
        let mut faces = Vec::with_capacity(points.len());
        for &p in points {
            if !p.is_finite() {
                return Err(construction(WHAT, "a picking point is not a finite number"));
            }
            faces.extend(self.nearest_face(p));
        }
        faces.sort_unstable();
        faces.dedup();
        Ok(faces)
    }

    /// The distance from `p` to face `f` (its kept curved loops, a round hole's rim, taken
    /// as polygons through 64 points of each curve).
    pub fn face_distance(&self, f: usize, p: DVec3) -> f64 {
        let facet = &self.faces[f];
        let n = facet.normal;
        let x = n.any_orthonormal_vector();
        let y = n.cross(x);
        let flat = |q: DVec3| glam::DVec2::new(q.dot(x), q.dot(y));
        let mut rings: Vec<Vec<DVec3>> = facet
            .loops
            .iter()
            .map(|ring| ring.iter().map(|&v| self.vertices[v]).collect())
            .collect();
        for ring in &facet.kept {
            let mut points = Vec::new();
            for curve in ring {
                let (t0, t1) = curve.domain();
                points.extend(
                    (0..64).filter_map(|i| curve.point_at(t0 + (t1 - t0) * i as f64 / 64.0).ok()),
                );
            }
            rings.push(points);
        }
        let inside = rings
            .iter()
            .map(|ring| {
                let polygon: Vec<glam::DVec2> = ring.iter().map(|&q| flat(q)).collect();
                usize::from(crate::trim::polygon_contains(&polygon, flat(p)))
            })
            .sum::<usize>()
            % 2
            == 1;
        if inside {
            return (n.dot(p) - facet.offset).abs();
        }
        let mut best = f64::INFINITY;
        for ring in &rings {
            for i in 0..ring.len() {
                best = best.min(segment_distance(ring[i], ring[(i + 1) % ring.len()], p));
            }
        }
        best
    }

    /// The distance from `p` to edge `k`'s segment.
    pub fn edge_distance(&self, k: usize, p: DVec3) -> f64 {
        segment_distance(
            self.vertices[self.edges[k].a],
            self.vertices[self.edges[k].b],
            p,
        )
    }

    /// The unit direction of edge `k` from `a` to `b`.
    pub fn direction(&self, k: usize) -> DVec3 {
        let e = self.edges[k];
        (self.vertices[e.b] - self.vertices[e.a]).normalize()
    }

    /// The unit vector in face `f`'s plane, perpendicular to edge `k`, pointing into `f`.
    pub fn inward(&self, k: usize, f: usize) -> DVec3 {
        let t = self.direction(k);
        let n = self.faces[f].normal;
        if self.edges[k].left == f {
            n.cross(t)
        } else {
            n.cross(-t)
        }
    }

    /// Whether edge `k` is convex (the faces' material makes an angle below 180° there).
    pub fn is_convex(&self, k: usize) -> bool {
        let e = self.edges[k];
        self.inward(k, e.left).dot(self.faces[e.right].normal) < 0.0
    }
}

/// The distance from `p` to the segment from `a` to `b`.
pub fn segment_distance(a: DVec3, b: DVec3, p: DVec3) -> f64 {
    let d = b - a;
    let t = ((p - a).dot(d) / d.length_squared().max(f64::MIN_POSITIVE)).clamp(0.0, 1.0);
    p.distance(a + d * t)
}

/// Each loop edge with vertices lying on it (within `tolerance`, strictly between its ends)
/// split at them, in order along it.
fn split_at_vertices(facets: &mut [Facet], vertices: &[DVec3], tolerance: f64) {
    for facet in facets {
        for ring in &mut facet.loops {
            let mut split = Vec::with_capacity(ring.len());
            for i in 0..ring.len() {
                let (a, b) = (ring[i], ring[(i + 1) % ring.len()]);
                split.push(a);
                let (p, q) = (vertices[a], vertices[b]);
                let d = q - p;
                let length = d.length();
                if length <= tolerance {
                    continue;
                }
                let mut inner: Vec<(f64, usize)> = vertices
                    .iter()
                    .enumerate()
                    .filter(|&(v, &x)| {
                        v != a
                            && v != b
                            && x.distance(p) > tolerance
                            && x.distance(q) > tolerance
                            && segment_distance(p, q, x) <= tolerance
                    })
                    .map(|(v, &x)| ((x - p).dot(d) / length, v))
                    .collect();
                inner.sort_by(|x, y| x.0.total_cmp(&y.0));
                split.extend(inner.into_iter().map(|(_, v)| v));
            }
            *ring = split;
        }
    }
}

/// Drops the points where a loop runs straight on (not corners).
fn straighten(facets: &mut [Facet], vertices: &[DVec3], tolerance: f64) {
    for facet in facets {
        for ring in &mut facet.loops {
            let mut changed = true;
            while changed && ring.len() > 3 {
                changed = false;
                for i in 0..ring.len() {
                    let n = ring.len();
                    let (p, q, r) = (
                        vertices[ring[(i + n - 1) % n]],
                        vertices[ring[i]],
                        vertices[ring[(i + 1) % n]],
                    );
                    let (d0, d1) = (q - p, r - q);
                    if d0.cross(d1).length() <= tolerance * d0.length().max(d1.length())
                        && d0.dot(d1) > 0.0
                    {
                        ring.remove(i);
                        changed = true;
                        break;
                    }
                }
            }
        }
    }
}

/// The faces with each group of faces in one plane that share edges made one face: their
/// loops' edges less the ones they share, traced into loops again.
fn merged_coplanar(facets: Vec<Facet>, tolerance: f64) -> Result<Vec<Facet>, GeometryError> {
    let mut owner: HashMap<(usize, usize), usize> = HashMap::new();
    for (f, facet) in facets.iter().enumerate() {
        for ring in &facet.loops {
            for i in 0..ring.len() {
                owner.insert((ring[i], ring[(i + 1) % ring.len()]), f);
            }
        }
    }
    let coplanar = |f: usize, g: usize| {
        facets[f].normal.dot(facets[g].normal) > 1.0 - 1e-9
            && (facets[f].offset - facets[g].offset).abs() <= tolerance
    };
    let links: Vec<(usize, usize)> = owner
        .iter()
        .filter_map(|(&(a, b), &f)| {
            let g = *owner.get(&(b, a))?;
            (f != g && coplanar(f, g)).then_some((f, g))
        })
        .collect();
    if links.is_empty() {
        return Ok(facets);
    }
    let groups = crate::join::connected_groups(facets.len(), links);
    let mut out = Vec::with_capacity(groups.len());
    for group in groups {
        if group.len() == 1 {
            out.push(facets[group[0]].clone());
            continue;
        }
        // The group's edges that no other face of it runs back along.
        let mut next: HashMap<usize, Vec<usize>> = HashMap::new();
        for &f in &group {
            for ring in &facets[f].loops {
                for i in 0..ring.len() {
                    let (a, b) = (ring[i], ring[(i + 1) % ring.len()]);
                    let inner = owner.get(&(b, a)).is_some_and(|g| group.contains(g));
                    if !inner {
                        next.entry(a).or_default().push(b);
                    }
                }
            }
        }
        let mut loops = Vec::new();
        while let Some(&start) = next.keys().min() {
            let mut ring = vec![start];
            let mut at = start;
            loop {
                let Some(outs) = next.get_mut(&at) else {
                    return Err(construction(
                        WHAT,
                        "faces in one plane do not close into loops",
                    ));
                };
                if outs.len() > 1 {
                    return Err(construction(
                        WHAT,
                        "faces in one plane touch at a corner only; that is not built yet",
                    ));
                }
                let Some(to) = outs.pop() else {
                    return Err(construction(
                        WHAT,
                        "faces in one plane do not close into loops",
                    ));
                };
                next.remove(&at);
                if to == start {
                    break;
                }
                ring.push(to);
                at = to;
            }
            loops.push(ring);
        }
        out.push(Facet {
            loops,
            kept: group
                .iter()
                .flat_map(|&f| facets[f].kept.iter().cloned())
                .collect(),
            ..facets[group[0]].clone()
        });
    }
    Ok(out)
}

/// Whether the trim curve's image on `surface` is straight (three inner points within
/// `tolerance` of its chord).
fn straight(surface: &crate::NurbsSurface, curve: &crate::TrimCurve, tolerance: f64) -> bool {
    let (t0, t1) = curve.domain();
    let at = |t: f64| {
        curve
            .point_at(t)
            .and_then(|uv| surface.point_at_clamped(uv))
            .ok()
    };
    let (Some(a), Some(b)) = (at(t0), at(t1)) else {
        return false;
    };
    [0.25, 0.5, 0.75].iter().all(|&s| {
        at(t0 + s * (t1 - t0)).is_some_and(|m| {
            let chord = b - a;
            let off = if chord.length() > 0.0 {
                (m - a).reject_from(chord).length()
            } else {
                m.distance(a)
            };
            off <= tolerance
        })
    })
}

/// The loop's edges in space on the flat `surface`, exact where the plane is an affine image
/// of its domain (a parallelogram of degree one: each trim curve's control points mapped,
/// its weights kept); None where it is not one.
pub(crate) fn in_space(
    surface: &crate::NurbsSurface,
    trim_loop: &[crate::TrimCurve],
    tolerance: f64,
) -> Option<Result<Vec<SpaceCurve>, GeometryError>> {
    let [n, m] = surface.count();
    if surface.degree() != [1, 1] || n != 2 || m != 2 || !surface.is_polynomial() {
        return None;
    }
    let p = |i, j| surface.control_point(i, j);
    if (p(0, 0) + p(1, 1) - p(0, 1) - p(1, 0)).length() > tolerance {
        return None;
    }
    Some(
        trim_loop
            .iter()
            .map(|c| {
                let points = (0..c.count())
                    .map(|i| {
                        let uv = c.control_point(i);
                        surface.point_at(uv.x, uv.y)
                    })
                    .collect::<Result<Vec<DVec3>, _>>()?;
                let weights = (0..c.count()).map(|i| c.weight(i)).collect();
                SpaceCurve::new(c.degree(), c.knots().to_vec(), points, Some(weights))
            })
            .collect(),
    )
}
