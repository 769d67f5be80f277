//! Cage tools that take geometry away or re-split faces, as Blender's edit mode has them:
//! delete vertices and edges, dissolve vertices, merge by distance, and triangulate faces.
//!
//! They follow the conventions of [`super::cage_edit`]: surviving vertices keep their indices,
//! a face keeps the winding of the face it came from, and creases and corners stay with their
//! edges and vertices. A cage is its faces, so an edge or vertex no face uses any more goes
//! (Blender would leave it loose).

use rustc_hash::{FxHashMap as HashMap, FxHashSet as HashSet};

use std::f64::consts::FRAC_PI_2;

use glam::{DVec2, DVec3};

use super::cage_edit::{Cage, CageEditError, invalid, key, polygon_normal};

impl Cage {
    pub(super) fn check_vertices(&self, vertices: &[u32]) -> Result<HashSet<u32>, CageEditError> {
        for &v in vertices {
            self.check_vertex(v)?;
        }
        if vertices.is_empty() {
            return Err(invalid("no vertices were named"));
        }
        Ok(vertices.iter().copied().collect())
    }

    /// The cage without the faces `keep` refuses, and the vertices only they used.
    fn without_faces(&self, keep: impl Fn(&[u32]) -> bool) -> Result<Self, CageEditError> {
        let mut out = self.clone();
        out.faces.retain(|face| keep(face));
        if out.faces.is_empty() {
            return Err(invalid("deleting these would leave an empty cage"));
        }
        Ok(out.compacted(self))
    }

    /// Delete vertices (Blender's Delete Vertices): the vertices go, with every face that uses
    /// one of them.
    pub fn delete_vertices(&self, vertices: &[u32]) -> Result<Self, CageEditError> {
        let named = self.check_vertices(vertices)?;
        self.without_faces(|face| !face.iter().any(|v| named.contains(v)))
    }

    /// Delete edges (Blender's Delete Edges): the edges go, with the faces on them.
    pub fn delete_edges(&self, edges: &[(u32, u32)]) -> Result<Self, CageEditError> {
        if edges.is_empty() {
            return Err(invalid("no edges were named"));
        }
        let half = self.half_edges();
        for &(a, b) in edges {
            self.check_edge(&half, a, b)?;
        }
        let named: HashSet<(u32, u32)> = edges.iter().map(|&(a, b)| key(a, b)).collect();
        self.without_faces(|face| {
            !(0..face.len()).any(|c| named.contains(&key(face[c], face[(c + 1) % face.len()])))
        })
    }

    /// Dissolve vertices (Blender's Dissolve Vertices, without splitting faces or tearing the
    /// border): the faces round each vertex become one face (the lowest-numbered keeps its
    /// index and winding), and a named vertex left between two edges goes from its faces.
    pub fn dissolve_vertices(&self, vertices: &[u32]) -> Result<Self, CageEditError> {
        let named = self.check_vertices(vertices)?;
        let half = self.half_edges();
        let gone: HashSet<(u32, u32)> = half
            .keys()
            .filter(|&(a, b)| {
                (named.contains(&a) || named.contains(&b)) && half.contains_key(&(b, a))
            })
            .map(|(a, b)| key(a, b))
            .collect();
        let faces: Vec<Vec<u32>> = self
            .joined_across(&half, &gone)?
            .into_iter()
            .flatten()
            .collect();
        self.with_faces_lone_removed(faces, named)
    }

    /// Merge by distance (Blender's Merge by Distance): among `vertices` (all of the cage's
    /// when empty), each group of points within `distance` of one is welded into one of them,
    /// which keeps its place (the faces then lose the corners that fall together, as in
    /// [`Cage::merge_vertices`]). As Blender does it: the points are visited in the order of a
    /// k-d tree balanced over their single-precision coordinates ([`kd_tree_order`]); each
    /// point not yet merged gathers the unmerged points within `distance` (itself among
    /// them), and the one kept is the point nearest the group's centroid with the visited
    /// point counted twice (so of a pair, the visited one; ties go to the lower index).
    pub fn merge_by_distance(
        &self,
        vertices: &[u32],
        distance: f64,
    ) -> Result<Self, CageEditError> {
        if !(distance.is_finite() && distance >= 0.0) {
            return Err(invalid("the merge distance must be a finite number ≥ 0"));
        }
        let mut chosen: Vec<u32> = if vertices.is_empty() {
            (0..self.points.len() as u32).collect()
        } else {
            self.check_vertices(vertices)?.into_iter().collect()
        };
        chosen.sort_unstable();
        // A hash grid of cells `distance` wide: a point's neighbours lie in the 27 cells round
        // its own.
        let cell = |p: DVec3| -> [i64; 3] {
            let scaled = p / distance.max(f64::MIN_POSITIVE);
            [scaled.x, scaled.y, scaled.z].map(|c| c.floor().clamp(-1e15, 1e15) as i64)
        };
        let mut grid: HashMap<[i64; 3], Vec<u32>> = HashMap::default();
        for &v in &chosen {
            grid.entry(cell(self.points[v as usize]))
                .or_default()
                .push(v);
        }
        let single: Vec<[f32; 3]> = chosen
            .iter()
            .map(|&v| self.points[v as usize].as_vec3().to_array())
            .collect();
        let mut target: HashMap<u32, u32> = HashMap::default();
        let mut cluster = Vec::new();
        for k in kd_tree_order(&single) {
            let v = chosen[k];
            if target.contains_key(&v) {
                continue;
            }
            let p = self.points[v as usize];
            let [x, y, z] = cell(p);
            cluster.clear();
            for dx in -1..=1 {
                for dy in -1..=1 {
                    for dz in -1..=1 {
                        let Some(list) = grid.get(&[x + dx, y + dy, z + dz]) else {
                            continue;
                        };
                        cluster.extend(list.iter().copied().filter(|&w| {
                            w != v
                                && !target.contains_key(&w)
                                && self.points[w as usize].distance(p) <= distance
                        }));
                    }
                }
            }
            if cluster.is_empty() {
                continue;
            }
            cluster.push(v);
            let centroid = (cluster
                .iter()
                .map(|&w| self.points[w as usize])
                .sum::<DVec3>()
                + p)
                / (cluster.len() + 1) as f64;
            let mut keep = v;
            for &w in &cluster {
                let (dw, dk) = (
                    self.points[w as usize].distance_squared(centroid),
                    self.points[keep as usize].distance_squared(centroid),
                );
                if dw < dk || (dw == dk && w < keep) {
                    keep = w;
                }
            }
            for &w in &cluster {
                target.insert(w, keep);
            }
        }
        if target.iter().all(|(a, b)| a == b) {
            return Err(CageEditError::NothingWithinDistance { distance });
        }
        self.clone()
            .welded(self, |v| target.get(&v).copied().unwrap_or(v))
    }

    /// Fill (Blender's Fill, F, on a closed loop of open edges): a new face over the loop
    /// named by its vertices in order, wound to agree with the faces already on its edges,
    /// appended after the others.
    pub fn fill_loop(&self, lp: &[u32]) -> Result<Self, CageEditError> {
        if lp.len() < 3 {
            return Err(invalid("a loop to fill needs three or more vertices"));
        }
        let half = self.half_edges();
        let mut seen = HashSet::default();
        // +1 where the face on an edge runs along the loop (the new face must run against
        // it), −1 where against.
        let mut along = 0i64;
        for k in 0..lp.len() {
            let (a, b) = (lp[k], lp[(k + 1) % lp.len()]);
            if !seen.insert(a) {
                return Err(invalid(format!("vertex {a} is named twice in the loop")));
            }
            self.check_edge(&half, a, b)?;
            along += match (half.contains_key(&(a, b)), half.contains_key(&(b, a))) {
                (true, false) => 1,
                (false, true) => -1,
                _ => {
                    return Err(invalid(format!(
                        "edge {a}-{b} has faces on both sides: the loop must be of open edges"
                    )));
                }
            };
        }
        if along.unsigned_abs() != lp.len() as u64 {
            return Err(invalid(
                "the faces round the loop disagree in winding: no face over it can agree \
                 with all of them",
            ));
        }
        let mut face = lp.to_vec();
        if along > 0 {
            face.reverse();
        }
        let mut out = self.clone();
        out.faces.push(face);
        Ok(out)
    }

    /// Connect vertices (Blender's Connect Vertex Pairs, J): every face holding two or more
    /// of the vertices is split by straight edges between those of them that follow each
    /// other round it (corners next to each other already share an edge): the pieces are
    /// each cut-off run of corners and, with three or more vertices in the face, the polygon
    /// of the vertices. The first piece keeps the face's index; the others follow.
    pub fn connect_vertices(&self, vertices: &[u32]) -> Result<Self, CageEditError> {
        let named = self.check_vertices(vertices)?;
        let mut out = self.clone();
        let mut split = false;
        for (f, face) in self.faces.iter().enumerate() {
            let n = face.len();
            let corners: Vec<usize> = (0..n).filter(|&c| named.contains(&face[c])).collect();
            let k = corners.len();
            if k < 2 {
                continue;
            }
            // Each run of corners from one vertex to the next round the face is cut off by a
            // new edge where the two are not neighbours either way round.
            let mut pieces: Vec<Vec<u32>> = Vec::new();
            for i in 0..k {
                let (from, to) = (corners[i], corners[(i + 1) % k]);
                let run = (to + n - from) % n;
                if run >= 2 && n - run >= 2 {
                    pieces.push((0..=run).map(|j| face[(from + j) % n]).collect());
                }
            }
            if pieces.is_empty() {
                continue;
            }
            if k >= 3 {
                pieces.push(corners.iter().map(|&c| face[c]).collect());
            }
            split = true;
            let mut pieces = pieces.into_iter();
            if let Some(first) = pieces.next() {
                out.faces[f] = first;
            }
            out.faces.extend(pieces);
        }
        if !split {
            return Err(invalid(
                "no face holds two of these vertices apart from each other: nothing to connect",
            ));
        }
        Ok(out)
    }

    /// Tris to quads (Blender's Tris to Quads, with no topology influence): every edge
    /// between two of the named triangles is a candidate, unless the triangles' normals
    /// differ by more than `face_degrees` or the quad they would make folds over or has a
    /// corner more than `shape_degrees` off square; the candidates are joined best first by
    /// [`quad_error`], each while both its triangles are still triangles (and no face over
    /// the same four corners is there). The quad takes the lower index of its two triangles.
    pub fn tris_to_quads(
        &self,
        faces: &[usize],
        face_degrees: f64,
        shape_degrees: f64,
    ) -> Result<Self, CageEditError> {
        let faces = self.check_faces(faces)?;
        for angle in [face_degrees, shape_degrees] {
            if !(0.0..=180.0).contains(&angle) {
                return Err(invalid("the angle limits must be 0° to 180°"));
            }
        }
        let triangles: HashSet<usize> = faces
            .iter()
            .copied()
            .filter(|&f| self.faces[f].len() == 3)
            .collect();
        let half = self.half_edges();
        let point = |v: u32| self.points[v as usize];
        let normal = |a: u32, b: u32, c: u32| (point(b) - point(a)).cross(point(c) - point(a));
        // (error, quad corners, the two triangles), the quad wound as the first triangle.
        let mut candidates: Vec<(f64, [u32; 4], usize, usize)> = Vec::new();
        for ((a, b), (f, c)) in half.iter() {
            let Some(&(g, d)) = half.get(&(b, a)) else {
                continue;
            };
            if f > g || !triangles.contains(&f) || !triangles.contains(&g) {
                continue;
            }
            let across_f = self.faces[f][(c + 2) % 3];
            let across_g = self.faces[g][(d + 2) % 3];
            let (nf, ng) = (normal(a, b, across_f), normal(b, a, across_g));
            if face_degrees < 180.0
                && nf.normalize_or_zero().dot(ng.normalize_or_zero())
                    < face_degrees.to_radians().cos()
            {
                continue;
            }
            let quad = [a, across_g, b, across_f];
            let corners = quad.map(point);
            if shape_degrees < 180.0
                && (quad_folds(corners)
                    || corner_angles_off_square(corners)
                        .iter()
                        .any(|&off| off > shape_degrees.to_radians()))
            {
                continue;
            }
            candidates.push((quad_error(corners), quad, f, g));
        }
        candidates.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.2.cmp(&y.2)).then(x.3.cmp(&y.3)));
        let mut out = self.clone();
        let mut joined: HashSet<usize> = HashSet::default();
        let mut gone: HashSet<usize> = HashSet::default();
        let mut existing: HashSet<Vec<u32>> = self
            .faces
            .iter()
            .map(|f| {
                let mut sorted = f.clone();
                sorted.sort_unstable();
                sorted
            })
            .collect();
        for (_, quad, f, g) in candidates {
            if joined.contains(&f) || joined.contains(&g) {
                continue;
            }
            let mut sorted = quad.to_vec();
            sorted.sort_unstable();
            if !existing.insert(sorted) {
                continue;
            }
            joined.extend([f, g]);
            out.faces[f] = quad.to_vec();
            gone.insert(g);
        }
        if joined.is_empty() {
            return Err(invalid(
                "no two of these triangles share an edge within the angle limits: nothing to \
                 join",
            ));
        }
        let mut k = 0;
        out.faces.retain(|_| {
            k += 1;
            !gone.contains(&(k - 1))
        });
        Ok(out.compacted(self))
    }

    /// Triangulate faces (Blender's Triangulate Faces, Beauty for quads and polygons): a quad
    /// is split along the diagonal whose two triangles have the larger sum of area over
    /// perimeter in the face's plane (Blender's `polyfill_beautify` measure; a diagonal that
    /// would fold a triangle over is never taken); a larger polygon is cut into ears in its
    /// plane and its inner edges then flipped, best gain first, while a flip raises that sum.
    /// The first triangle keeps the face's index; the others follow in face order.
    pub fn triangulate_faces(&self, faces: &[usize]) -> Result<Self, CageEditError> {
        let faces = self.check_faces(faces)?;
        let mut out = self.clone();
        for &f in &faces {
            let face = &self.faces[f];
            if face.len() == 3 {
                continue;
            }
            let normal = polygon_normal(&self.points, face);
            if normal == DVec3::ZERO {
                return Err(invalid(format!(
                    "face {f} has no area: it has no plane to split in"
                )));
            }
            let triangles = beauty_triangles(&flattened(&self.points, face, normal));
            let mut pieces = triangles
                .into_iter()
                .map(|[a, b, c]| vec![face[a], face[b], face[c]]);
            if let Some(first) = pieces.next() {
                out.faces[f] = first;
            }
            out.faces.extend(pieces);
        }
        Ok(out)
    }
}

/// The order of the points in a k-d tree balanced over them (Blender's `BLI_kdtree_3d`):
/// each range is partitioned round its middle place (a quickselect on the coordinate along
/// the range's axis, x, y, z in turn by depth, pivoting on the range's last point), the point
/// that lands there splits it, and the two sides are balanced in turn. Returns the positions
/// in `points`, in the tree's array order.
fn kd_tree_order(points: &[[f32; 3]]) -> Vec<usize> {
    fn balance(points: &[[f32; 3]], nodes: &mut [usize], axis: usize) {
        let len = nodes.len();
        if len <= 1 {
            return;
        }
        let at = |nodes: &[usize], k: usize| points[nodes[k]][axis];
        let median = len / 2;
        let (mut left, mut right) = (0usize, len - 1);
        while right > left {
            let pivot = at(nodes, right);
            let (mut i, mut j) = (left, right);
            loop {
                while at(nodes, i) < pivot {
                    i += 1;
                }
                loop {
                    j -= 1;
                    if !(at(nodes, j) > pivot && j > left) {
                        break;
                    }
                }
                if i >= j {
                    break;
                }
                nodes.swap(i, j);
                i += 1;
            }
            nodes.swap(i, right);
            if i >= median {
                right = i.saturating_sub(1);
            }
            if i <= median {
                left = i + 1;
            }
        }
        let next = (axis + 1) % 3;
        let (below, above) = nodes.split_at_mut(median);
        balance(points, below, next);
        balance(points, &mut above[1..], next);
    }
    let mut nodes: Vec<usize> = (0..points.len()).collect();
    balance(points, &mut nodes, 0);
    nodes
}

/// How far a quad is from a flat rectangle, as Blender's Tris to Quads weighs it (each term
/// 0 at best): the angles between the normals of the two triangles either diagonal makes,
/// over 2π; each corner's angle off 90°, summed over 2π; and 1 − the ratio of the smaller to
/// the larger of the two diagonals' triangle areas (a concave quad's differ).
pub fn quad_error([v1, v2, v3, v4]: [DVec3; 4]) -> f64 {
    let unit_normal = |a: DVec3, b: DVec3, c: DVec3| (b - a).cross(c - a).normalize_or_zero();
    let angle = |a: DVec3, b: DVec3| {
        if (a - b).abs().max_element() <= f64::from(f32::EPSILON) {
            0.0
        } else {
            a.angle_between(b)
        }
    };
    let bend = angle(unit_normal(v1, v2, v3), unit_normal(v1, v3, v4))
        + angle(unit_normal(v2, v3, v4), unit_normal(v4, v1, v2));
    let square: f64 = corner_angles_off_square([v1, v2, v3, v4]).iter().sum();
    let area = |a: DVec3, b: DVec3, c: DVec3| (b - a).cross(c - a).length() / 2.0;
    let (across_13, across_24) = (
        area(v1, v2, v3) + area(v1, v3, v4),
        area(v2, v3, v4) + area(v4, v1, v2),
    );
    let larger = across_13.max(across_24);
    let concave = if larger > 0.0 {
        1.0 - across_13.min(across_24) / larger
    } else {
        1.0
    };
    (bend + square) / std::f64::consts::TAU + concave
}

/// Each corner's angle's distance from 90° (radians), from the angles between consecutive
/// sides.
fn corner_angles_off_square(corners: [DVec3; 4]) -> [f64; 4] {
    let sides: [DVec3; 4] =
        std::array::from_fn(|k| (corners[k] - corners[(k + 1) % 4]).normalize_or_zero());
    std::array::from_fn(|k| (sides[k].angle_between(sides[(k + 1) % 4]) - FRAC_PI_2).abs())
}

/// The points of `face` in a plane square to `normal` (any orthonormal pair of axes in it).
fn flattened(points: &[DVec3], face: &[u32], normal: DVec3) -> Vec<DVec2> {
    let (u, v) = normal.any_orthonormal_pair();
    face.iter()
        .map(|&i| {
            let p = points[i as usize];
            DVec2::new(p.dot(u), p.dot(v))
        })
        .collect()
}

/// Whether Blender's Beauty splits quad `quad` along its corners 1–3 rather than 0–2, as
/// [`Cage::triangulate_faces`] splits it: by [`rotate_gain`] in the quad's plane (1–3 where
/// the quad has no plane).
pub(super) fn beauty_splits_1_3(points: &[DVec3], quad: [u32; 4]) -> bool {
    let normal = polygon_normal(points, &quad);
    if normal == DVec3::ZERO {
        return true;
    }
    splits_1_3(&flattened(points, &quad, normal))
}

/// Whether Blender's Beauty splits the flat quad `flat` along its corners 1–3 rather than
/// 0–2 ([`rotate_gain`]; a tie, as a square, goes to 1–3 as in Blender).
fn splits_1_3(flat: &[DVec2]) -> bool {
    rotate_gain(flat[1], flat[2], flat[3], flat[0]) <= 0.0
}

/// Whether either diagonal splits the quad into triangles facing away from each other (a
/// bow tie or a fold).
fn quad_folds([v1, v2, v3, v4]: [DVec3; 4]) -> bool {
    let normal = |a: DVec3, b: DVec3, c: DVec3| (b - a).cross(c - a);
    normal(v1, v2, v3).dot(normal(v1, v3, v4)) < 0.0
        || normal(v2, v3, v4).dot(normal(v2, v4, v1)) < 0.0
}

/// Twice the signed area of triangle a, b, c.
fn cross(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    (b - a).perp_dot(c - a)
}

/// How much better the quad v1 v2 v3 v4 is split along 1–3 than along 2–4 (negative: 1–3 is
/// better), by the sum over the two triangles of area over perimeter (Blender's
/// `BLI_polyfill_beautify_quad_rotate_calc`): `+∞` when 1–3 would give triangles of opposite
/// sides or no area, `−∞` when 2–4 does and 1–3 does not.
fn rotate_gain(v1: DVec2, v2: DVec2, v3: DVec2, v4: DVec2) -> f64 {
    const ZERO_AREA: f64 = 1e-12;
    let (a234, a241) = (cross(v2, v3, v4), cross(v2, v4, v1));
    let (a123, a134) = (cross(v1, v2, v3), cross(v1, v3, v4));
    if (a123 >= 0.0) != (a134 >= 0.0) || a123.abs() <= ZERO_AREA || a134.abs() <= ZERO_AREA {
        return f64::INFINITY;
    }
    if (a234 >= 0.0) != (a241 >= 0.0) || a234.abs() <= ZERO_AREA || a241.abs() <= ZERO_AREA {
        return f64::NEG_INFINITY;
    }
    let (l12, l23, l34, l41) = (
        v1.distance(v2),
        v2.distance(v3),
        v3.distance(v4),
        v4.distance(v1),
    );
    let (l13, l24) = (v1.distance(v3), v2.distance(v4));
    let along_24 = a234.abs() / (l23 + l34 + l24) + a241.abs() / (l41 + l12 + l24);
    let along_13 = a123.abs() / (l12 + l23 + l13) + a134.abs() / (l34 + l41 + l13);
    along_24 - along_13
}

/// A polygon (counter-clockwise or clockwise, simple) cut into triangles by ear clipping, the
/// result improved by edge flips as [`rotate_gain`] judges, best first (Blender's
/// `BLI_polyfill_beautify`). The triangles are wound as the polygon and index its corners.
fn beauty_triangles(points: &[DVec2]) -> Vec<[usize; 3]> {
    let n = points.len();
    if n == 4 {
        return if splits_1_3(points) {
            vec![[1, 2, 3], [1, 3, 0]]
        } else {
            vec![[0, 1, 2], [0, 2, 3]]
        };
    }
    let area: f64 = (0..n)
        .map(|i| points[i].perp_dot(points[(i + 1) % n]))
        .sum();
    let sign = if area < 0.0 { -1.0 } else { 1.0 };
    let mut triangles = ear_clipping(points, sign);
    beautify(points, &mut triangles);
    triangles
}

/// Ear clipping: the first convex corner (in the polygon's turning sense `sign`) whose
/// triangle holds no other corner is cut off, until three corners are left. A polygon with
/// no such ear (it crosses itself) has its first convex corner cut.
fn ear_clipping(points: &[DVec2], sign: f64) -> Vec<[usize; 3]> {
    let mut ring: Vec<usize> = (0..points.len()).collect();
    let mut triangles = Vec::with_capacity(points.len().saturating_sub(2));
    while ring.len() > 3 {
        let m = ring.len();
        let corner = |k: usize| [ring[(k + m - 1) % m], ring[k], ring[(k + 1) % m]];
        let convex = |[a, b, c]: [usize; 3]| sign * cross(points[a], points[b], points[c]) > 0.0;
        let is_ear = |k: usize| {
            let [a, b, c] = corner(k);
            convex([a, b, c])
                && ring.iter().all(|&o| {
                    o == a
                        || o == b
                        || o == c
                        || !(sign * cross(points[a], points[b], points[o]) >= 0.0
                            && sign * cross(points[b], points[c], points[o]) >= 0.0
                            && sign * cross(points[c], points[a], points[o]) >= 0.0)
                })
        };
        let k = (0..m)
            .find(|&k| is_ear(k))
            .or_else(|| (0..m).find(|&k| convex(corner(k))))
            .unwrap_or(0);
        triangles.push(corner(k));
        ring.remove(k);
    }
    if let [a, b, c] = ring[..] {
        triangles.push([a, b, c]);
    }
    triangles
}

/// Flips the inner edges of a polygon's triangulation while a flip gains (Blender's
/// `BLI_polyfill_beautify`): the edge of largest gain first, then its neighbours again.
fn beautify(points: &[DVec2], triangles: &mut [[usize; 3]]) {
    let n = points.len();
    let border = |a: usize, b: usize| (a + 1) % n == b || (b + 1) % n == a;
    // Each inner edge's two triangles, found afresh after every flip (polygons are small).
    let shared = |triangles: &[[usize; 3]]| -> HashMap<(usize, usize), Vec<(usize, usize)>> {
        let mut map: HashMap<(usize, usize), Vec<(usize, usize)>> = HashMap::default();
        for (t, tri) in triangles.iter().enumerate() {
            for c in 0..3 {
                let (a, b) = (tri[c], tri[(c + 1) % 3]);
                if !border(a, b) {
                    map.entry((a.min(b), a.max(b))).or_default().push((t, c));
                }
            }
        }
        map
    };
    // The gain of flipping an inner edge: its triangles t (a → b at corner c) and s.
    let gain = |triangles: &[[usize; 3]], (t, c): (usize, usize), (s, d): (usize, usize)| {
        let (a, b) = (triangles[t][c], triangles[t][(c + 1) % 3]);
        let opposite_t = triangles[t][(c + 2) % 3];
        let opposite_s = triangles[s][(d + 2) % 3];
        rotate_gain(points[opposite_t], points[a], points[opposite_s], points[b])
    };
    let extent = points
        .iter()
        .fold(0.0f64, |m, p| m.max(p.distance(points[0])));
    let tiny = 1e-12 * extent.max(f64::MIN_POSITIVE);
    for _ in 0..n * n {
        // The flip of largest gain (ties to the lowest edge, for a stable result).
        // (gain, edge, one side, the other), each side a triangle and the edge's corner in it.
        type Flip = (f64, (usize, usize), (usize, usize), (usize, usize));
        let mut best: Option<Flip> = None;
        for (edge, sides) in shared(triangles) {
            if let [t, s] = sides[..] {
                let g = gain(triangles, t, s);
                if g < -tiny && best.is_none_or(|(h, e, ..)| g < h || (g == h && edge < e)) {
                    best = Some((g, edge, t, s));
                }
            }
        }
        let Some((_, _, (t, c), (s, d))) = best else {
            return;
        };
        let (a, b) = (triangles[t][c], triangles[t][(c + 1) % 3]);
        let (x, y) = (triangles[t][(c + 2) % 3], triangles[s][(d + 2) % 3]);
        // Triangle a b x and b a y become x a y and y b x, wound as before.
        triangles[t] = [x, a, y];
        triangles[s] = [y, b, x];
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::subdiv::cages;
    use crate::test_support::{Xorshift, placement};

    /// A torus cage (all quads, closed) under a random motion.
    fn placed_torus(seed: u64) -> Cage {
        let mesh = cages::torus(DVec3::ZERO, 3.0, 1.0, 8, 6).unwrap();
        let (motion, _) = placement(seed);
        Cage {
            points: mesh
                .points()
                .iter()
                .map(|&p| motion.transform_point3(p))
                .collect(),
            faces: mesh.faces().map(<[u32]>::to_vec).collect(),
            creases: Vec::new(),
            corners: Vec::new(),
        }
    }

    fn edge_count(cage: &Cage) -> usize {
        cage.faces
            .iter()
            .flat_map(|f| (0..f.len()).map(move |c| key(f[c], f[(c + 1) % f.len()])))
            .collect::<HashSet<_>>()
            .len()
    }

    /// Twice the area of a polygon in the plane, signed by its turning.
    fn signed_area(points: &[DVec2]) -> f64 {
        (0..points.len())
            .map(|i| points[i].perp_dot(points[(i + 1) % points.len()]))
            .sum()
    }

    #[test]
    fn deleting_vertices_or_edges_takes_exactly_the_faces_on_them() {
        for seed in 0..10 {
            let cage = placed_torus(seed);
            let mut rng = Xorshift::new(seed);
            let v = rng.below(48) as u32;
            // A vertex of a closed quad cage has four faces; the four quads round it go, and
            // with them it and nothing else (its neighbours keep other faces).
            let out = cage.delete_vertices(&[v]).unwrap();
            assert_eq!(out.faces.len(), cage.faces.len() - 4);
            assert_eq!(out.points.len(), cage.points.len() - 1);
            assert!(!out.points.contains(&cage.points[v as usize]));
            // An edge has two faces: both go, and no vertex (each keeps two other faces).
            let face = &cage.faces[rng.below(48) as usize];
            let out = cage.delete_edges(&[(face[1], face[2])]).unwrap();
            assert_eq!(out.faces.len(), cage.faces.len() - 2);
            assert_eq!(out.points.len(), cage.points.len());
            // Six open edges: the two faces' border.
            assert_eq!(edge_count(&out), edge_count(&cage) - 1);
        }
    }

    #[test]
    fn dissolving_a_vertex_makes_one_face_of_its_ring() {
        for seed in 0..10 {
            let cage = placed_torus(seed);
            let v = Xorshift::new(seed).below(48) as u32;
            let out = cage.dissolve_vertices(&[v]).unwrap();
            // Four quads round a valence-4 vertex become one octagon through its 8 neighbours.
            assert_eq!(out.faces.len(), cage.faces.len() - 3);
            assert_eq!(out.points.len(), cage.points.len() - 1);
            let octagons: Vec<&Vec<u32>> = out.faces.iter().filter(|f| f.len() == 8).collect();
            assert_eq!(octagons.len(), 1);
            let ring: HashSet<[u64; 3]> = cage
                .faces
                .iter()
                .filter(|f| f.contains(&v))
                .flatten()
                .filter(|&&w| w != v)
                .map(|&w| cage.points[w as usize].to_array().map(f64::to_bits))
                .collect();
            let octagon: HashSet<[u64; 3]> = octagons[0]
                .iter()
                .map(|&w| out.points[w as usize].to_array().map(f64::to_bits))
                .collect();
            assert_eq!(ring, octagon);
            // The Euler characteristic of the torus stays 0: V − 1, E − 4, F − 3.
            assert_eq!(edge_count(&out), edge_count(&cage) - 4);
        }
    }

    #[test]
    fn triangulation_covers_the_polygon_once_and_no_flip_gains() {
        let mut rng = Xorshift::new(61);
        for case in 0..200 {
            // A polygon star-shaped about the origin (its corners in turn round it, each in
            // its own sector, at random distances: simple, often not convex) of 4 to 14
            // corners, either turning.
            let n = 4 + rng.below(11) as usize;
            let mut points: Vec<DVec2> = (0..n)
                .map(|k| {
                    let angle = (k as f64 + 0.9 * rng.unit()) * std::f64::consts::TAU / n as f64;
                    DVec2::from_angle(angle) * (0.3 + rng.unit())
                })
                .collect();
            if case % 2 == 1 {
                points.reverse();
            }
            let area = signed_area(&points);
            if area.abs() < 1e-3 {
                continue;
            }
            let sign = if area < 0.0 { -1.0 } else { 1.0 };
            for &[a, b, c] in &ear_clipping(&points, sign) {
                let t = cross(points[a], points[b], points[c]);
                assert!(
                    t * area > 0.0,
                    "case {case}: ear {a} {b} {c} turns over {points:?}"
                );
            }
            let triangles = beauty_triangles(&points);
            assert_eq!(triangles.len(), n - 2, "case {case}");
            // Every triangle turns as the polygon does, and their areas add up to its area:
            // they cover it once.
            let mut sum = 0.0;
            for &[a, b, c] in &triangles {
                let t = cross(points[a], points[b], points[c]);
                assert!(
                    t * area > 0.0,
                    "case {case}: triangle {a} {b} {c} turns over"
                );
                sum += t;
            }
            assert!(
                (sum - area).abs() < 1e-9 * area.abs(),
                "case {case}: {sum} vs {area}"
            );
            // Every inner edge is used twice, in opposite directions; no flip of one would
            // raise the area-over-perimeter sum (a quad is split by the better diagonal).
            let mut half: HashMap<(usize, usize), (usize, usize)> = HashMap::default();
            for (t, tri) in triangles.iter().enumerate() {
                for c in 0..3 {
                    assert!(half.insert((tri[c], tri[(c + 1) % 3]), (t, c)).is_none());
                }
            }
            for (&(a, b), &(t, c)) in &half {
                let Some(&(s, d)) = half.get(&(b, a)) else {
                    assert!((a + 1) % n == b, "case {case}: open edge {a}-{b} inside");
                    continue;
                };
                let x = triangles[t][(c + 2) % 3];
                let y = triangles[s][(d + 2) % 3];
                let gain = rotate_gain(points[x], points[a], points[y], points[b]);
                assert!(
                    n == 4 || gain >= -1e-9,
                    "case {case}: flipping {a}-{b} gains {gain}"
                );
            }
        }
    }

    #[test]
    fn a_quad_is_split_by_the_diagonal_of_rounder_triangles() {
        // A kite: both splits have the same area, but the long diagonal 0–2 makes the
        // triangles' perimeters far longer than the short 1–3, turned and rolled or not.
        let kite = [
            DVec2::new(0.0, 0.0),
            DVec2::new(2.0, -0.4),
            DVec2::new(4.0, 0.0),
            DVec2::new(2.0, 0.4),
        ];
        assert_eq!(beauty_triangles(&kite), vec![[1, 2, 3], [1, 3, 0]]);
        let turned: Vec<DVec2> = kite.iter().map(|p| p.perp()).collect();
        let rolled = [turned[1], turned[2], turned[3], turned[0]];
        assert_eq!(beauty_triangles(&rolled), vec![[0, 1, 2], [0, 2, 3]]);
        // A square ties: Blender's choice, 1–3.
        let square = [DVec2::ZERO, DVec2::X, DVec2::ONE, DVec2::Y];
        assert_eq!(beauty_triangles(&square), vec![[1, 2, 3], [1, 3, 0]]);
    }

    #[test]
    fn the_k_d_order_splits_every_range_at_its_median() {
        let mut rng = Xorshift::new(7);
        for len in [1usize, 2, 3, 7, 64, 257] {
            let points: Vec<[f32; 3]> = (0..len)
                .map(|_| [0; 3].map(|_: i32| (rng.below(20) as f32) * 0.5))
                .collect();
            let order = kd_tree_order(&points);
            let mut sorted = order.clone();
            sorted.sort_unstable();
            assert_eq!(sorted, (0..len).collect::<Vec<_>>());
            fn check(points: &[[f32; 3]], nodes: &[usize], axis: usize) {
                if nodes.len() <= 1 {
                    return;
                }
                let m = nodes.len() / 2;
                let split = points[nodes[m]][axis];
                assert!(nodes[..m].iter().all(|&i| points[i][axis] <= split));
                assert!(nodes[m + 1..].iter().all(|&i| points[i][axis] >= split));
                check(points, &nodes[..m], (axis + 1) % 3);
                check(points, &nodes[m + 1..], (axis + 1) % 3);
            }
            check(&points, &order, 0);
        }
    }

    #[test]
    fn merging_by_distance_welds_a_cage_torn_into_faces_back_together() {
        for seed in 0..6 {
            let cage = placed_torus(seed);
            let mut rng = Xorshift::new(seed + 100);
            // Every face gets its own copies of its corners, each moved by up to 1e-9.
            let mut torn = Cage::default();
            for face in &cage.faces {
                let mut copy = Vec::new();
                for &v in face {
                    copy.push(torn.points.len() as u32);
                    let jitter = DVec3::new(rng.unit(), rng.unit(), rng.unit()) - 0.5;
                    torn.points.push(cage.points[v as usize] + jitter * 2e-9);
                }
                torn.faces.push(copy);
            }
            let out = torn.merge_by_distance(&[], 1e-6).unwrap();
            assert_eq!(out.points.len(), cage.points.len());
            assert_eq!(out.faces.len(), cage.faces.len());
            assert_eq!(edge_count(&out), edge_count(&cage));
            // Each face is over the points of the face it was torn from, in the same order.
            for (a, b) in out.faces.iter().zip(&cage.faces) {
                for (&p, &q) in a.iter().zip(b) {
                    assert!(out.points[p as usize].distance(cage.points[q as usize]) < 1e-8);
                }
            }
            // Merging only some of the points leaves the others apart.
            let first: Vec<u32> = (0..4).collect();
            let out = torn.merge_by_distance(&first, 1e-6).unwrap_err();
            assert!(out.to_string().contains("nothing to merge"), "{out}");
        }
    }

    #[test]
    fn filling_the_hole_a_deleted_face_left_restores_the_closed_cage() {
        for seed in 0..6 {
            let cage = placed_torus(seed);
            let f = Xorshift::new(seed).below(48) as usize;
            let holed = cage.delete_faces(&[f]).unwrap();
            // No vertex went (each has three other faces): the loop is the face's corners,
            // named in either turning.
            let mut lp = cage.faces[f].clone();
            if seed % 2 == 1 {
                lp.reverse();
            }
            let filled = holed.fill_loop(&lp).unwrap();
            assert_eq!(filled.points, cage.points);
            // The new face is the old one, wound as it was (its corners from some start).
            let new = filled.faces.last().unwrap();
            let at = new.iter().position(|&v| v == cage.faces[f][0]).unwrap();
            let turned: Vec<u32> = (0..4).map(|k| new[(at + k) % 4]).collect();
            assert_eq!(turned, cage.faces[f]);
            assert_eq!(edge_count(&filled), edge_count(&cage));
        }
    }

    #[test]
    fn connecting_opposite_corners_splits_each_quad_into_two_triangles() {
        for seed in 0..6 {
            let cage = placed_torus(seed);
            // A diagonal chain 0, 7, 14 … crosses one quad per step.
            let chain: Vec<u32> = (0..4).map(|k| k * 7).collect();
            let out = cage.connect_vertices(&chain).unwrap();
            assert_eq!(out.faces.len(), cage.faces.len() + 3);
            assert_eq!(out.faces.iter().filter(|f| f.len() == 3).count(), 6);
            assert_eq!(edge_count(&out), edge_count(&cage) + 3);
            // The area is kept: each quad's two triangles (its corners in the quad's plane up
            // to the torus's slight twist) cover it.
            let area = |c: &Cage| -> f64 {
                c.faces
                    .iter()
                    .map(|f| {
                        let p = |k: usize| c.points[f[k] as usize];
                        (1..f.len() - 1)
                            .map(|k| (p(k) - p(0)).cross(p(k + 1) - p(0)).length() / 2.0)
                            .sum::<f64>()
                    })
                    .sum()
            };
            assert!((area(&out) - area(&cage)).abs() < 0.05 * area(&cage));
        }
        // A heptagon's corners 0, 2 and 4: two triangles cut off, the triangle 0 2 4, and the
        // rest, 4 5 6 0.
        let heptagon = Cage {
            points: (0..7)
                .map(|k| DVec3::new((k as f64).cos(), (k as f64).sin(), 0.0))
                .collect(),
            faces: vec![(0..7).collect()],
            ..Cage::default()
        };
        let out = heptagon.connect_vertices(&[4, 0, 2]).unwrap();
        let mut sizes: Vec<usize> = out.faces.iter().map(Vec::len).collect();
        sizes.sort_unstable();
        assert_eq!(sizes, [3, 3, 3, 4]);
    }

    #[test]
    fn the_quad_error_is_zero_for_rectangles_and_counts_a_parallelogram_s_corners() {
        let (motion, _) = placement(11);
        let place = |p: [f64; 2]| motion.transform_point3(DVec3::new(p[0], p[1], 0.0));
        let rectangle = [[0.0, 0.0], [2.0, 0.0], [2.0, 0.5], [0.0, 0.5]].map(place);
        assert!(quad_error(rectangle) < 1e-7, "{}", quad_error(rectangle));
        // 60° and 120° corners: each 30° off square, 4 × (π/6) / 2π = 1/3; flat and convex.
        let (c, s60) = (0.5, 3f64.sqrt() / 2.0);
        let rhombus = [[0.0, 0.0], [1.0, 0.0], [1.0 + c, s60], [c, s60]].map(place);
        assert!((quad_error(rhombus) - 1.0 / 3.0).abs() < 1e-7);
        // A dart (one corner pushed past the diagonal): the two diagonals' areas differ.
        let dart = [[0.0, 0.0], [2.0, 0.0], [0.7, 0.7], [0.0, 2.0]].map(place);
        assert!(quad_error(dart) > 0.5);
        assert!(quad_folds([
            rectangle[0],
            rectangle[2],
            rectangle[1],
            rectangle[3]
        ]));
        assert!(!quad_folds(rectangle));
    }

    #[test]
    fn triangulated_quads_join_back_into_the_same_quads() {
        for seed in 0..6 {
            let cage = placed_torus(seed);
            let all: Vec<usize> = (0..cage.faces.len()).collect();
            let triangles = cage.triangulate_faces(&all).unwrap();
            let every: Vec<usize> = (0..triangles.faces.len()).collect();
            // Neighbouring cells of the 8 × 6 torus meet at 45° or 60°, past the 40° limit:
            // only each cell's own two triangles may join.
            let out = triangles.tris_to_quads(&every, 40.0, 40.0).unwrap();
            assert_eq!(out.points, cage.points);
            let as_sets = |c: &Cage| {
                let mut faces: Vec<Vec<u32>> = c
                    .faces
                    .iter()
                    .map(|f| {
                        let mut f = f.clone();
                        f.sort_unstable();
                        f
                    })
                    .collect();
                faces.sort();
                faces
            };
            assert_eq!(as_sets(&out), as_sets(&cage));
            // Each quad is wound as the cell was (same turning on the same corners).
            for f in &out.faces {
                let cell = cage
                    .faces
                    .iter()
                    .find(|g| {
                        let mut a = g.to_vec();
                        let mut b = f.clone();
                        a.sort_unstable();
                        b.sort_unstable();
                        a == b
                    })
                    .unwrap();
                let at = cell.iter().position(|&v| v == f[0]).unwrap();
                assert_eq!(cell[(at + 1) % 4], f[1]);
            }
        }
    }

    #[test]
    fn bad_requests_are_refused_with_the_reason() {
        let cage = placed_torus(3);
        let refusals = [
            cage.delete_vertices(&[]),
            cage.delete_vertices(&[48]),
            cage.delete_vertices(&(0..48).collect::<Vec<_>>()),
            cage.delete_edges(&[]),
            cage.delete_edges(&[(0, 47)]),
            cage.dissolve_vertices(&[]),
            cage.dissolve_vertices(&[99]),
            cage.merge_by_distance(&[], f64::NAN),
            cage.merge_by_distance(&[], -1.0),
            cage.merge_by_distance(&[], f64::INFINITY),
            cage.merge_by_distance(&[50], 1.0),
            cage.merge_by_distance(&[], 1e-9),
            cage.triangulate_faces(&[]),
            cage.triangulate_faces(&[48]),
            cage.fill_loop(&[0, 1]),
            cage.fill_loop(&cage.faces[0].clone()),
            cage.delete_faces(&[0]).unwrap().fill_loop(&[0, 6, 6, 1]),
            cage.connect_vertices(&[]),
            cage.connect_vertices(&[0, 1]),
            cage.connect_vertices(&[0, 100]),
            cage.tris_to_quads(&[0, 1], 40.0, 40.0),
            cage.tris_to_quads(&[0], -1.0, 40.0),
            cage.tris_to_quads(&[0], 40.0, f64::NAN),
        ];
        for (k, r) in refusals.into_iter().enumerate() {
            let e = r.expect_err(&format!("refusal {k} was accepted"));
            assert!(!e.to_string().is_empty());
        }
        // A face with no area has no plane to split in.
        let mut flat = cage.clone();
        let f = flat.faces[0].clone();
        for &v in &f {
            flat.points[v as usize] = DVec3::ONE;
        }
        assert!(flat.triangulate_faces(&[0]).is_err());
    }
}
