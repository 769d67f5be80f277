//! Vertex bevel, as Blender's Bevel with Affect: Vertices has it: each named vertex cut off,
//! a face where it was.
//!
//! It follows the conventions of [`super::cage_edit`]: surviving vertices keep their indices,
//! the new points follow (each named vertex's, in the order its edges go round it), faces keep
//! their indices and windings, the new faces follow; an edge shortened at an end keeps its
//! crease.

use rustc_hash::{FxHashMap as HashMap, FxHashSet as HashSet};

use glam::DVec3;

use super::bevel_corner;
use super::cage_edit::{Cage, CageEditError, Profile, invalid, key};

impl Cage {
    /// Vertex bevel (Blender's Bevel of vertices, offset along the edges): every named vertex v
    /// gets a point on each of its edges v–w at `width` from v along it, and each face round v
    /// takes the two points of its edges at v in v's place. With one segment, where v has
    /// three or more edges, a new face joins its points round it, wound against the faces
    /// round it (on the border its open side becomes an edge between the first and the last).
    /// With more, each face takes instead the arc between its two points (a quarter ellipse in
    /// the parallelogram of the points and v, in the face's plane), and the hole they leave is
    /// filled by Blender's corner mesh over those arcs ([`bevel_corner::general_corner`]; on
    /// the border its last side runs across the open side and becomes border, and a corner of
    /// two edges only takes the arc). The vertex goes, with its sharpness.
    /// Widths past an edge's other end are not clamped, as in Blender.
    pub fn bevel_vertices(
        &self,
        vertices: &[u32],
        width: f64,
        segments: u32,
    ) -> Result<Self, CageEditError> {
        let named = self.check_vertices(vertices)?;
        if !(width.is_finite() && width > 0.0) {
            return Err(invalid("the bevel's width must be a finite number > 0"));
        }
        if !(1..=64).contains(&segments) {
            return Err(invalid(format!(
                "a vertex bevel takes 1 to 64 segments, not {segments}"
            )));
        }
        let mut out = self.clone();
        // The point on edge v–w near v, for each named v, made in the order of v's name and
        // of the faces round it.
        let mut point: HashMap<(u32, u32), u32> = HashMap::default();
        // Round v: the new face's edges, from the point on the edge a face leaves v along to
        // the point on the edge it came in on.
        let mut next: HashMap<u32, HashMap<u32, u32>> = HashMap::default();
        let mut order: Vec<u32> = Vec::with_capacity(named.len());
        let mut seen = HashSet::default();
        for &v in vertices {
            if seen.insert(v) {
                order.push(v);
            }
        }
        let corners_of: HashMap<u32, Vec<(usize, usize)>> = {
            let mut map: HashMap<u32, Vec<(usize, usize)>> = HashMap::default();
            for (f, face) in self.faces.iter().enumerate() {
                for (c, &v) in face.iter().enumerate() {
                    if named.contains(&v) {
                        map.entry(v).or_default().push((f, c));
                    }
                }
            }
            map
        };
        for &v in &order {
            let Some(corners) = corners_of.get(&v) else {
                return Err(invalid(format!("vertex {v} is on no face")));
            };
            let pv = self.points[v as usize];
            for &(f, c) in corners {
                let face = &self.faces[f];
                let n = face.len();
                let (u, w) = (face[(c + n - 1) % n], face[(c + 1) % n]);
                for x in [u, w] {
                    point.entry((v, x)).or_insert_with(|| {
                        let towards = self.points[x as usize] - pv;
                        out.points.push(pv + towards.normalize_or_zero() * width);
                        (out.points.len() - 1) as u32
                    });
                }
                next.entry(v)
                    .or_default()
                    .insert(point[&(v, w)], point[&(v, u)]);
            }
        }
        let ns = segments as usize;
        let pv_of = |v: u32| self.points[v as usize];
        // Each corner mesh's sides, from one ring point to the next, and the new faces.
        let mut arc: HashMap<(u32, u32), Vec<u32>> = HashMap::default();
        let mut new_faces: Vec<Vec<u32>> = Vec::new();
        for &v in &order {
            let Some(links) = next.get(&v) else {
                continue;
            };
            // One chain round v: closed, or open from the point no link comes to.
            let not_one_fan = || {
                invalid(format!(
                    "vertex {v}'s faces do not make one fan round it: it cannot be beveled"
                ))
            };
            let targets: HashSet<u32> = links.values().copied().collect();
            let mut starts: Vec<u32> = links
                .keys()
                .filter(|k| !targets.contains(k))
                .copied()
                .collect();
            starts.sort_unstable();
            let open = !starts.is_empty();
            let start = match starts[..] {
                [] => links.keys().copied().min().ok_or_else(not_one_fan)?,
                [s] => s,
                _ => return Err(not_one_fan()),
            };
            let mut ring = vec![start];
            let mut at = start;
            while let Some(&to) = links.get(&at) {
                if to == start || ring.len() > links.len() {
                    break;
                }
                ring.push(to);
                at = to;
            }
            if ring.len() != links.len() + usize::from(open) {
                return Err(not_one_fan());
            }
            if segments == 1 {
                if ring.len() >= 3 {
                    new_faces.push(ring);
                }
                continue;
            }
            if ring.len() == 2 && open {
                // A border corner of two edges: its face takes the arc, nothing else.
                let (from, to) = (ring[0], ring[1]);
                let profile = Profile::round_corner(
                    out.points[from as usize],
                    out.points[to as usize],
                    pv_of(v),
                );
                let mut side = vec![from];
                for k in 1..ns {
                    out.points.push(profile.at(k as f64 / ns as f64));
                    side.push((out.points.len() - 1) as u32);
                }
                side.push(to);
                arc.insert((from, to), side);
                continue;
            }
            if ring.len() < 3 {
                return Err(not_one_fan());
            }
            // The corner mesh over the ring, its sides arcs in the faces' planes bulging
            // towards v (Blender's vertex mesh); on the border its last side runs across the
            // open side, from the last point to the first, and becomes border.
            let boundary: Vec<DVec3> = ring.iter().map(|&q| out.points[q as usize]).collect();
            let k = ring.len();
            let profiles: Vec<Profile> = (0..k)
                .map(|i| Profile::round_corner(boundary[i], boundary[(i + 1) % k], pv_of(v)))
                .collect();
            let side = |i: usize, t: f64| profiles[i].at(t);
            let grid = bevel_corner::general_corner(pv_of(v), &boundary, &side, ns);
            let (faces, borders) = bevel_corner::corner_faces(&grid, &ring, &mut out.points);
            for (i, border) in borders.into_iter().enumerate() {
                arc.insert((ring[i], ring[(i + 1) % k]), border);
            }
            new_faces.extend(faces);
        }
        let sharp = self.sharpness_of_edges();
        // The sides that take a corner's place in a face, and the crease each takes: that of
        // the face's edge leaving the corner (as Blender's bevel carries it).
        let mut creased_sides: Vec<(Vec<u32>, f64)> = Vec::new();
        for (f, face) in self.faces.iter().enumerate() {
            let n = face.len();
            if !face.iter().any(|v| named.contains(v)) {
                continue;
            }
            let mut grown = Vec::with_capacity(n + 4);
            for c in 0..n {
                let v = face[c];
                if named.contains(&v) {
                    let (u, w) = (face[(c + n - 1) % n], face[(c + 1) % n]);
                    let (a, b) = (point[&(v, u)], point[&(v, w)]);
                    let start = grown.len();
                    // The corner mesh's side runs from b to a: its points in reverse.
                    match arc.get(&(b, a)) {
                        Some(side) => grown.extend(side.iter().rev()),
                        None => grown.extend([a, b]),
                    }
                    if let Some(&s) = sharp.get(&key(v, w)) {
                        creased_sides.push((grown[start..].to_vec(), s));
                    }
                } else {
                    grown.push(v);
                }
            }
            out.faces[f] = grown;
        }
        out.faces.extend(new_faces);
        for (side, s) in creased_sides {
            for pair in side.windows(2) {
                out.add_crease(pair[0], pair[1], s);
            }
        }
        // Creases on the edges' remaining parts.
        let mut cut: Vec<((u32, u32), u32)> = point.iter().map(|(&e, &p)| (e, p)).collect();
        cut.sort_unstable();
        for ((v, w), p) in cut {
            if let Some(&s) = sharp.get(&key(v, w)) {
                let other = point.get(&(w, v)).copied().unwrap_or(w);
                out.add_crease(p, other, s);
            }
        }
        out.corners.retain(|c| !named.contains(&c.vertex));
        Ok(out.compacted(self))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::subdiv::cage_edit::tests::{cage_of as placed, euler, volume};
    use crate::subdiv::cages;
    use glam::DVec3;

    #[test]
    fn beveled_box_corners_each_lose_a_right_tetrahedron() {
        let cube = cages::cube(DVec3::ZERO, 2.0).unwrap();
        for seed in 0..12u64 {
            let (cage, scale) = placed(&cube, seed);
            let count = 1 + (seed % 8) as usize;
            let corners: Vec<u32> = (0..count as u32).collect();
            let w = 0.3 * scale;
            let cut = cage.bevel_vertices(&corners, w, 1).unwrap();
            // Each corner: three points for one, a triangle more, three edges more.
            assert_eq!(cut.points.len(), 8 + 2 * count, "seed {seed}");
            assert_eq!(cut.faces.len(), 6 + count);
            assert_eq!(euler(&cut), 2);
            // The cut-off corner is the right tetrahedron of legs w: w³/6.
            let expected = 8.0 * scale.powi(3) - count as f64 * w.powi(3) / 6.0;
            assert!(
                (volume(&cut) - expected).abs() < 1e-9 * expected,
                "seed {seed}"
            );
            // The new triangles are equilateral of side w√2, wound outward.
            for face in &cut.faces[6..] {
                assert_eq!(face.len(), 3);
                for c in 0..3 {
                    let d = cut.points[face[c] as usize]
                        .distance(cut.points[face[(c + 1) % 3] as usize]);
                    assert!((d - w * 2f64.sqrt()).abs() < 1e-9 * scale);
                }
            }
        }
    }

    #[test]
    fn on_the_border_a_vertex_of_three_edges_becomes_a_triangle_and_a_corner_a_cut() {
        let grid = cages::grid(DVec3::ZERO, 4.0, 4).unwrap();
        let (cage, scale) = placed(&grid, 5);
        let edges_of = |v: u32| {
            cage.faces
                .iter()
                .flat_map(|f| (0..f.len()).map(move |c| key(f[c], f[(c + 1) % f.len()])))
                .filter(|&(a, b)| a == v || b == v)
                .collect::<HashSet<_>>()
                .len()
        };
        let corner = (0..cage.points.len() as u32)
            .find(|&v| edges_of(v) == 2)
            .unwrap();
        let side = (0..cage.points.len() as u32)
            .find(|&v| edges_of(v) == 3)
            .unwrap();
        let cut = cage.bevel_vertices(&[corner], 0.2 * scale, 1).unwrap();
        assert_eq!((cut.points.len(), cut.faces.len()), (26, 16));
        assert_eq!(cut.faces.iter().filter(|f| f.len() == 5).count(), 1);
        let cut = cage.bevel_vertices(&[side], 0.2 * scale, 1).unwrap();
        assert_eq!((cut.points.len(), cut.faces.len()), (27, 17));
        assert_eq!(euler(&cut), 1);
    }

    #[test]
    fn bad_vertex_bevels_are_refused_with_the_reason() {
        let cage = placed(&cages::cube(DVec3::ZERO, 2.0).unwrap(), 1).0;
        let refusal = |r: Result<Cage, CageEditError>| r.unwrap_err().to_string();
        assert!(refusal(cage.bevel_vertices(&[0], 0.0, 1)).contains("width"));
        assert!(refusal(cage.bevel_vertices(&[0], f64::NAN, 1)).contains("width"));
        assert!(refusal(cage.bevel_vertices(&[0], 0.1, 0)).contains("1 to 64 segments"));
        assert!(refusal(cage.bevel_vertices(&[99], 0.1, 1)).contains("vertex 99"));
        assert!(refusal(cage.bevel_vertices(&[], 0.1, 1)).contains("no vertices"));
    }

    /// Box corners beveled with 2 to 6 segments: each corner mesh has the counts of its rings
    /// (three sides of s − 2j points on ring j, and the centre point for even s; 3 ⌊s/2⌋⌈s/2⌉
    /// quads and the centre triangle for odd s), the box stays closed and consistently wound, every face of the box stays flat (the arcs
    /// lie in its plane), and each corner loses less than the flat cut's w³/6 but something:
    /// the rounded corner bulges towards the vertex. Border points are rounded too.
    #[test]
    fn rounded_box_corners_keep_the_faces_flat_and_lose_less_than_the_flat_cut() {
        use crate::subdiv::cage_edit::polygon_normal;
        use crate::subdiv::cage_edit::tests::consistently_wound;
        let cube = cages::cube(DVec3::ZERO, 2.0).unwrap();
        for seed in 0..10u64 {
            let (cage, scale) = placed(&cube, seed);
            let ns = 2 + (seed % 5) as usize;
            let count = 1 + (seed % 3) as usize;
            // Corners 0, 7 and 3 (7 and 3 share an edge, far longer than twice the width).
            let corners: Vec<u32> = [0u32, 7, 3][..count].to_vec();
            let w = 0.35 * scale;
            let out = cage.bevel_vertices(&corners, w, ns as u32).unwrap();
            let (half, odd) = (ns / 2, ns % 2);
            let points_per_corner =
                3 * (0..half + odd).map(|j| ns - 2 * j).sum::<usize>() + (1 - odd);
            let faces_per_corner = 3 * half * (half + odd) + odd;
            assert_eq!(
                out.points.len(),
                8 - count + count * points_per_corner,
                "seed {seed}"
            );
            assert_eq!(out.faces.len(), 6 + count * faces_per_corner, "seed {seed}");
            assert_eq!(euler(&out), 2);
            assert!(consistently_wound(&out));
            for f in 0..6 {
                let normal = polygon_normal(&cage.points, &cage.faces[f]);
                let on = cage.points[cage.faces[f][0] as usize];
                for &v in &out.faces[f] {
                    let off = (out.points[v as usize] - on).dot(normal);
                    assert!(
                        off.abs() < 1e-9 * scale,
                        "seed {seed}: face {f} bent by {off:e}"
                    );
                }
            }
            let lost = volume(&cage) - volume(&out);
            let flat = count as f64 * w.powi(3) / 6.0;
            assert!(
                lost > 0.0 && lost < flat,
                "seed {seed}: lost {lost}, flat cut {flat}"
            );
        }
        // On a grid's border: a point of three edges takes the corner mesh of three sides,
        // its third across the open side (12 points for the one it loses, 7 faces more), and
        // a corner of two edges only the arc in its face (two edge points and two on the arc).
        let grid = cages::grid(DVec3::ZERO, 2.0, 3).unwrap();
        let (cage, scale) = placed(&grid, 1);
        let side = cage.bevel_vertices(&[1], 0.1 * scale, 3).unwrap();
        assert_eq!((side.points.len(), side.faces.len()), (16 + 11, 9 + 7));
        let corner = cage.bevel_vertices(&[0], 0.1 * scale, 3).unwrap();
        assert_eq!((corner.points.len(), corner.faces.len()), (16 + 3, 9));
        for out in [side, corner] {
            assert_eq!(euler(&out), 1);
            assert!(consistently_wound(&out));
        }
        assert!(cage.bevel_vertices(&[5], 0.1, 65).is_err());
    }
}
