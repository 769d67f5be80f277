//! Sweeps of a cage's faces or open edges, as Blender's edit mode has them: extrude edges
//! (the open edges pulled out into a strip of quads) and spin (faces or open edges turned
//! round an axis in steps, a ring of quads at each step, optionally advancing along the axis
//! as Blender's Screw does).
//!
//! They follow the conventions of [`super::cage_edit`]: vertices keep their indices, the new
//! ones follow step by step (each step's copies in index order), a swept face keeps its index
//! and winding, and the new quads are wound to agree with their neighbours.

use rustc_hash::{FxHashMap as HashMap, FxHashSet as HashSet};

use glam::{DAffine3, DQuat, DVec3};

use super::cage_edit::{Cage, CageEditError, SpinMotion, invalid, key, polygon_normal};

/// What a sweep moves: a region of faces (which leaves its place: Blender's Extrude Region)
/// or open edges (which stay, a strip growing from them).
enum Swept {
    Faces(Vec<usize>),
    Edges(Vec<(u32, u32)>),
}

impl Cage {
    /// Extrude edges (Blender's Extrude Edges): each named edge, which must be open (on one
    /// face only), gets a quad to a copy of it moved by `by`; the copies of the edges' points
    /// are new vertices, in index order.
    pub fn extrude_edges(&self, edges: &[(u32, u32)], by: DVec3) -> Result<Self, CageEditError> {
        if !by.is_finite() || by == DVec3::ZERO {
            return Err(invalid("the extrusion needs a finite, non-zero direction"));
        }
        self.swept(
            &Swept::Edges(edges.to_vec()),
            &[DAffine3::from_translation(by)],
            false,
        )
    }

    /// The open edges (on one face only) among `edges`.
    pub fn open_among(&self, edges: &[(u32, u32)]) -> Vec<(u32, u32)> {
        let half = self.half_edges();
        edges
            .iter()
            .copied()
            .filter(|&(a, b)| half.contains_key(&(a, b)) != half.contains_key(&(b, a)))
            .collect()
    }

    /// The way open edges are pulled out by default: away from their faces, in each face's
    /// plane (the mean of the unit directions square to each edge, pointing out of its face);
    /// `None` without open edges or where the directions cancel.
    pub fn outward_of(&self, open_edges: &[(u32, u32)]) -> Option<DVec3> {
        let half = self.half_edges();
        let mut sum = DVec3::ZERO;
        for &(a, b) in open_edges {
            // The face's half-edge runs x → y; its normal crossed with x → y points into it.
            let (&(f, _), x, y) = match (half.get(&(a, b)), half.get(&(b, a))) {
                (Some(h), None) => (h, a, b),
                (None, Some(h)) => (h, b, a),
                _ => return None,
            };
            let normal = polygon_normal(&self.points, &self.faces[f]);
            let along = self.points[y as usize] - self.points[x as usize];
            sum -= normal.cross(along).normalize_or_zero();
        }
        let unit = sum.normalize_or_zero();
        (unit != DVec3::ZERO && sum.length() > 1e-6 * open_edges.len() as f64).then_some(unit)
    }

    /// The region of faces lifted by `by`, with side quads on its border (see
    /// [`Cage::extrude_faces`]).
    pub(super) fn extrude_region(
        &self,
        region: &[usize],
        by: DVec3,
    ) -> Result<Self, CageEditError> {
        self.swept(
            &Swept::Faces(region.to_vec()),
            &[DAffine3::from_translation(by)],
            false,
        )
    }

    /// Extrude individual faces (Blender's Extrude Individual Faces): each face lifted on its
    /// own by `offset` along its own normal, with side quads on all its edges (two faces that
    /// shared an edge each get a side there). Faces keep their indices; each face's new
    /// vertices and sides follow, face by face.
    pub fn extrude_individual(&self, faces: &[usize], offset: f64) -> Result<Self, CageEditError> {
        let region = self.check_faces(faces)?;
        if !offset.is_finite() {
            return Err(invalid("the offset must be a finite number"));
        }
        let sharp = self.sharpness_of_edges();
        let mut out = self.clone();
        for &f in &region {
            let face = &self.faces[f];
            let normal = polygon_normal(&self.points, face);
            if normal == DVec3::ZERO {
                return Err(invalid(format!(
                    "face {f} has no area: it has no normal to extrude along"
                )));
            }
            // The face's corners lifted, in corner order; a side quad on every edge, its top
            // edge taking the edge's crease, and the copies the corners' sharpness.
            let first = out.points.len() as u32;
            for &v in face {
                out.points.push(self.points[v as usize] + normal * offset);
            }
            let k = face.len();
            let top: Vec<u32> = (0..k as u32).map(|c| first + c).collect();
            for c in 0..k {
                let d = (c + 1) % k;
                out.faces.push(vec![face[c], face[d], top[d], top[c]]);
                if let Some(&s) = sharp.get(&key(face[c], face[d])) {
                    out.add_crease(top[c], top[d], s);
                }
            }
            let copy: HashMap<u32, u32> = face.iter().copied().zip(top.iter().copied()).collect();
            out.copy_corners(&self.corners, &copy);
            out.faces[f] = top;
        }
        Ok(out.compacted(self))
    }

    /// Spin (Blender's Spin, and with an advance its Screw): the faces (as a region) or the
    /// open edges are turned through the [`SpinMotion`]'s steps, each step a ring of quads. A separate piece of faces (whose border edges are
    /// all open) spun a full turn without advance closes on itself, a lathe: the last ring
    /// joins the first, and the piece's faces go (Blender would keep them inside). Faces with
    /// neighbours, or open edges, spun a full turn would come back onto the cage, and are
    /// refused.
    pub fn spin(
        &self,
        faces: &[usize],
        edges: &[(u32, u32)],
        motion: &SpinMotion,
    ) -> Result<Self, CageEditError> {
        let SpinMotion {
            centre,
            axis,
            degrees,
            steps,
            advance,
        } = *motion;
        let what = match (faces.is_empty(), edges.is_empty()) {
            (false, true) => Swept::Faces(faces.to_vec()),
            (true, false) => Swept::Edges(edges.to_vec()),
            _ => return Err(invalid("spin takes faces or edges, one of the two")),
        };
        let axis = axis.normalize_or_zero();
        if !centre.is_finite() || !axis.is_finite() || axis == DVec3::ZERO {
            return Err(invalid(
                "the spin's axis needs a finite centre and a non-zero direction",
            ));
        }
        if !(degrees.is_finite() && degrees != 0.0 && degrees.abs() <= 360.0 * 64.0) {
            return Err(invalid(
                "the spin's angle must be finite, not 0, at most 64 turns",
            ));
        }
        if !advance.is_finite() {
            return Err(invalid("the spin's advance must be a finite number"));
        }
        if !(1..=1024).contains(&steps) {
            return Err(invalid(format!(
                "the spin's steps must be 1 to 1024, not {steps}"
            )));
        }
        let full_turn = (degrees.abs() - 360.0).abs() < 1e-9 && advance == 0.0;
        let step = DAffine3::from_translation(centre + axis * (advance / f64::from(steps)))
            * DAffine3::from_quat(DQuat::from_axis_angle(
                axis,
                degrees.to_radians() / f64::from(steps),
            ))
            * DAffine3::from_translation(-centre);
        let mut moves = Vec::with_capacity(steps as usize);
        let mut total = DAffine3::IDENTITY;
        for _ in 0..steps {
            total = step * total;
            moves.push(total);
        }
        self.swept(&what, &moves, full_turn)
    }

    /// The cage with `what` swept through `moves` (each the whole motion from the start to
    /// that step). With `close`, the last step lands on the start: for faces, the last
    /// step's copies are the original points and neither the start nor the end faces stay.
    fn swept(&self, what: &Swept, moves: &[DAffine3], close: bool) -> Result<Self, CageEditError> {
        let half = self.half_edges();
        // The half-edges each step's side quads hold, x → y: a side quad is x, y, y', x'.
        let mut sides: Vec<(u32, u32)> = Vec::new();
        let mut region: Vec<usize> = Vec::new();
        let mut points: Vec<u32> = Vec::new();
        match what {
            Swept::Faces(faces) => {
                region = self.check_faces(faces)?;
                let inside: HashSet<usize> = region.iter().copied().collect();
                for &f in &region {
                    let face = &self.faces[f];
                    points.extend(face.iter().copied());
                    for c in 0..face.len() {
                        let (a, b) = (face[c], face[(c + 1) % face.len()]);
                        match half.get(&(b, a)) {
                            Some(&(g, _)) if inside.contains(&g) => {}
                            Some(_) if close => {
                                return Err(invalid(format!(
                                    "a full turn would bring the faces back onto edge {a}-{b}, \
                                     where a face outside them is: spin a separate piece, or \
                                     less than a full turn"
                                )));
                            }
                            _ => sides.push((a, b)),
                        }
                    }
                }
            }
            Swept::Edges(edges) => {
                if edges.is_empty() {
                    return Err(invalid("no edges were named"));
                }
                let mut seen = HashSet::default();
                for &(a, b) in edges {
                    self.check_edge(&half, a, b)?;
                    if !seen.insert(key(a, b)) {
                        continue;
                    }
                    match (half.contains_key(&(a, b)), half.contains_key(&(b, a))) {
                        (true, false) => sides.push((b, a)),
                        (false, true) => sides.push((a, b)),
                        _ => {
                            return Err(invalid(format!(
                                "edge {a}-{b} has faces on both sides: only open edges can be \
                                 pulled out (a third face on it would make a fin)"
                            )));
                        }
                    }
                    points.extend([a, b]);
                }
                if close {
                    return Err(invalid(
                        "open edges spun a full turn would come back onto the faces they are on",
                    ));
                }
            }
        }
        points.sort_unstable();
        points.dedup();
        // Before the last step only the sides' points are copied (a region's inner points
        // move with its faces to the end in one go).
        let on_sides: HashSet<u32> = sides.iter().flat_map(|&(x, y)| [x, y]).collect();
        let mut out = self.clone();
        let sharp = self.sharpness_of_edges();
        // Where each point is after the step before (at the start: itself).
        let mut previous: HashMap<u32, u32> = points.iter().map(|&v| (v, v)).collect();
        let last = moves.len() - 1;
        for (k, motion) in moves.iter().enumerate() {
            let copy: HashMap<u32, u32> = if close && k == last {
                points.iter().map(|&v| (v, v)).collect()
            } else {
                points
                    .iter()
                    .filter(|v| k == last || on_sides.contains(v))
                    .map(|&v| {
                        out.points
                            .push(motion.transform_point3(self.points[v as usize]));
                        (v, out.points.len() as u32 - 1)
                    })
                    .collect()
            };
            for &(x, y) in &sides {
                out.faces
                    .push(vec![previous[&x], previous[&y], copy[&y], copy[&x]]);
                if let Some(&s) = sharp.get(&key(x, y))
                    && !(close && k == last)
                {
                    out.add_crease(copy[&x], copy[&y], s);
                }
            }
            if !(close && k == last) {
                out.copy_corners(&self.corners, &copy);
            }
            previous = copy;
        }
        // The region's faces move to the last step (inner edges' creases with them), or, closed,
        // go with the start they came back to.
        let inner: Vec<(u32, u32)> = region
            .iter()
            .flat_map(|&f| {
                let face = &self.faces[f];
                (0..face.len()).map(move |c| (face[c], face[(c + 1) % face.len()]))
            })
            .filter(|&(a, b)| !sides.contains(&(a, b)))
            .collect();
        for &(a, b) in &inner {
            if let Some(&s) = sharp.get(&key(a, b))
                && !close
            {
                out.add_crease(previous[&a], previous[&b], s);
            }
        }
        if close {
            let gone: HashSet<usize> = region.iter().copied().collect();
            let mut k = 0;
            out.faces.retain(|_| {
                k += 1;
                !gone.contains(&(k - 1))
            });
        } else {
            for &f in &region {
                out.faces[f] = self.faces[f].iter().map(|v| previous[v]).collect();
            }
        }
        Ok(out.compacted(self))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::subdiv::cage_edit::tests::{cage_of, consistently_wound, euler, volume};
    use crate::subdiv::cages;
    use crate::test_support::{Xorshift, placement};

    fn sm(centre: DVec3, axis: DVec3, degrees: f64, steps: u32, advance: f64) -> SpinMotion {
        SpinMotion {
            centre,
            axis,
            degrees,
            steps,
            advance,
        }
    }

    fn edge_uses(cage: &Cage) -> HashMap<(u32, u32), usize> {
        let mut uses = HashMap::default();
        for f in &cage.faces {
            for c in 0..f.len() {
                *uses.entry(key(f[c], f[(c + 1) % f.len()])).or_default() += 1;
            }
        }
        uses
    }

    /// One square of side `size` in general position: a separate piece, its four edges open.
    fn square(seed: u64) -> (Cage, DAffine3, f64) {
        let (motion, scale) = placement(seed);
        let corners = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        let cage = Cage {
            points: corners
                .iter()
                .map(|&[x, y]| motion.transform_point3(DVec3::new(x + 2.0, y, 0.0)))
                .collect(),
            faces: vec![vec![0, 1, 2, 3]],
            ..Cage::default()
        };
        (cage, motion, scale)
    }

    #[test]
    fn a_square_spun_a_full_turn_is_a_closed_torus_on_circles_round_the_axis() {
        for seed in 0..8 {
            let (cage, motion, scale) = square(seed);
            let steps = 3 + Xorshift::new(seed).below(20) as u32;
            // The axis: the square's plane's y axis through the origin, 2 to 3 away from it.
            let centre = motion.transform_point3(DVec3::ZERO);
            let axis = motion.transform_vector3(DVec3::Y);
            let out = cage
                .spin(&[0], &[], &sm(centre, axis, 360.0, steps, 0.0))
                .unwrap();
            assert_eq!(out.faces.len(), 4 * steps as usize);
            assert_eq!(out.points.len(), 4 * steps as usize);
            assert_eq!(euler(&out), 0, "a torus");
            assert!(edge_uses(&out).values().all(|&n| n == 2), "closed");
            assert!(consistently_wound(&out));
            // Every point keeps its distance from the axis and its height along it; each
            // ring is the first turned by a whole number of steps.
            let unit = axis.normalize();
            let radius = |p: DVec3| (p - centre).reject_from(unit).length();
            let height = |p: DVec3| (p - centre).dot(unit);
            let radii: Vec<f64> = cage.points.iter().map(|&p| radius(p)).collect();
            for &p in &out.points {
                let r = radius(p);
                assert!(
                    radii.iter().any(|&q| (q - r).abs() < 1e-9 * scale),
                    "radius {r} is no corner's"
                );
                assert!(
                    cage.points
                        .iter()
                        .any(|&q| (height(q) - height(p)).abs() < 1e-9 * scale)
                );
            }
            // The faces all face out of the swept solid or all into it: the volume (by the
            // divergence theorem over the quads' fans) is, step by step, the square's area
            // times its centroid's radius times sin θ (each point p moves straight to R p,
            // square to the square's plane by r sin θ), up to the quads' twist.
            let volume: f64 = out
                .faces
                .iter()
                .map(|f| {
                    let p = |k: usize| out.points[f[k] as usize];
                    (1..f.len() - 1)
                        .map(|k| p(0).dot(p(k).cross(p(k + 1))) / 6.0)
                        .sum::<f64>()
                })
                .sum();
            let centroid: DVec3 = cage.points.iter().sum::<DVec3>() / 4.0;
            let n = f64::from(steps);
            let pappus = scale * scale * n * radius(centroid) * (std::f64::consts::TAU / n).sin();
            assert!(
                (volume.abs() - pappus).abs() < 0.02 * pappus,
                "steps {steps}: volume {volume}, ring {pappus}"
            );
        }
    }

    #[test]
    fn a_screw_advances_each_ring_along_the_axis() {
        let (cage, motion, scale) = square(5);
        let centre = motion.transform_point3(DVec3::ZERO);
        let axis = motion.transform_vector3(DVec3::Y).normalize();
        let advance = 3.0 * scale;
        let out = cage
            .spin(&[], &[(0, 1)], &sm(centre, axis, 720.0, 8, advance))
            .unwrap();
        // The edge 0-1 (on the square's side) swept through 8 steps of 90°: 8 quads, 16 new
        // points, each ring 3/8 of the advance higher than the one before.
        assert_eq!(out.faces.len(), 9);
        assert_eq!(out.points.len(), 4 + 16);
        let height = |p: DVec3| (p - centre).dot(axis);
        for k in 0..8 {
            for (j, v) in [0usize, 1].into_iter().enumerate() {
                let p = out.points[4 + 2 * k + j];
                let rise = height(p) - height(cage.points[v]);
                assert!(
                    (rise - advance * (k + 1) as f64 / 8.0).abs() < 1e-9 * scale,
                    "ring {k}: {rise}"
                );
            }
        }
        assert!(consistently_wound(&out));
    }

    #[test]
    fn extruded_edges_make_parallelograms_wound_with_their_face() {
        let mut rng = Xorshift::new(3);
        for seed in 0..8 {
            let (cage, _, scale) = square(seed);
            let by = DVec3::new(rng.unit(), rng.unit(), rng.unit()) * scale;
            let out = cage.extrude_edges(&[(1, 2), (2, 3)], by).unwrap();
            assert_eq!((out.points.len(), out.faces.len()), (7, 3));
            assert!(consistently_wound(&out));
            for f in &out.faces[1..] {
                let p = |k: usize| out.points[f[k] as usize];
                // Opposite sides equal: a parallelogram of the edge and the move.
                assert!((p(1) - p(0)).distance(p(2) - p(3)) < 1e-12 * scale);
                assert!((p(3) - p(0)).distance(by).min((p(2) - p(1)).distance(by)) < 1e-9 * scale);
            }
            // The default way out of edge 1-2: square to it in the square's plane, away from
            // the square's centre.
            let out_dir = cage
                .outward_of(&cage.open_among(&[(1, 2), (0, 2)]))
                .unwrap();
            let (p1, p2) = (cage.points[1], cage.points[2]);
            let centre = cage.points.iter().sum::<DVec3>() / 4.0;
            assert!(out_dir.dot(p2 - p1).abs() < 1e-12);
            assert!(
                out_dir
                    .dot(polygon_normal(&cage.points, &cage.faces[0]))
                    .abs()
                    < 1e-12
            );
            assert!(out_dir.dot((p1 + p2) / 2.0 - centre) > 0.0);
        }
    }

    #[test]
    fn bad_sweeps_are_refused_with_the_reason() {
        let (cage, _, _) = square(1);
        let two = Cage {
            points: cage
                .points
                .iter()
                .copied()
                .chain([cage.points[1] * 2.0, cage.points[2] * 2.0])
                .collect(),
            faces: vec![vec![0, 1, 2, 3], vec![1, 4, 5, 2]],
            ..Cage::default()
        };
        let refusals = [
            cage.extrude_edges(&[], DVec3::X),
            cage.extrude_edges(&[(0, 1)], DVec3::ZERO),
            cage.extrude_edges(&[(0, 1)], DVec3::NAN),
            cage.extrude_edges(&[(0, 2)], DVec3::X),
            two.extrude_edges(&[(1, 2)], DVec3::X),
            cage.spin(&[], &[], &sm(DVec3::ZERO, DVec3::Z, 90.0, 4, 0.0)),
            cage.spin(&[0], &[(0, 1)], &sm(DVec3::ZERO, DVec3::Z, 90.0, 4, 0.0)),
            cage.spin(&[0], &[], &sm(DVec3::ZERO, DVec3::ZERO, 90.0, 4, 0.0)),
            cage.spin(&[0], &[], &sm(DVec3::NAN, DVec3::Z, 90.0, 4, 0.0)),
            cage.spin(&[0], &[], &sm(DVec3::ZERO, DVec3::Z, 0.0, 4, 0.0)),
            cage.spin(&[0], &[], &sm(DVec3::ZERO, DVec3::Z, f64::INFINITY, 4, 0.0)),
            cage.spin(&[0], &[], &sm(DVec3::ZERO, DVec3::Z, 90.0, 0, 0.0)),
            cage.spin(&[0], &[], &sm(DVec3::ZERO, DVec3::Z, 90.0, 5000, 0.0)),
            cage.spin(&[0], &[], &sm(DVec3::ZERO, DVec3::Z, 90.0, 4, f64::NAN)),
            cage.spin(&[], &[(0, 1)], &sm(DVec3::ZERO, DVec3::Z, 360.0, 4, 0.0)),
            two.spin(&[0], &[], &sm(DVec3::ZERO, DVec3::Z, 360.0, 4, 0.0)),
            cage.spin(&[3], &[], &sm(DVec3::ZERO, DVec3::Z, 90.0, 4, 0.0)),
        ];
        for (k, r) in refusals.into_iter().enumerate() {
            let e = r.expect_err(&format!("refusal {k} was accepted"));
            assert!(!e.to_string().is_empty());
        }
    }

    /// Two neighbouring faces of a randomly placed cube extruded each on its own by d: each
    /// adds its prism (area × d) to the volume, the cube stays closed (χ = 2, windings
    /// agreeing), the edge they shared takes a side of each, and every lifted corner is d
    /// from its face's plane; a face with no area is refused.
    #[test]
    fn individually_extruded_faces_each_raise_their_own_prism() {
        for seed in 1..7u64 {
            let (cage, scale) = cage_of(&cages::cube(DVec3::ZERO, 2.0).unwrap(), seed);
            let d = scale * 0.4 * if seed % 3 == 0 { -1.0 } else { 1.0 };
            // Face 0 and a neighbour, and the edge they share.
            let ring: Vec<(u32, u32)> = (0..4)
                .map(|c| key(cage.faces[0][c], cage.faces[0][(c + 1) % 4]))
                .collect();
            let (other, shared) = (1..6)
                .find_map(|g| {
                    ring.iter()
                        .find(|&&(a, b)| cage.faces[g].contains(&a) && cage.faces[g].contains(&b))
                        .map(|&e| (g, e))
                })
                .unwrap();
            let faces = [0, other];
            // A crease on face 0's first edge goes to the lifted copy of that edge too.
            let mut cage = cage;
            let (c0, c1) = (cage.faces[0][0], cage.faces[0][1]);
            cage.add_crease(c0, c1, 2.5);
            let out = cage.extrude_individual(&faces, d).unwrap();
            let area = (2.0 * scale).powi(2);
            let expected = volume(&cage) + 2.0 * area * d;
            assert!((volume(&out) - expected).abs() < 1e-9 * expected.abs());
            assert_eq!((euler(&out), out.faces.len()), (2, 6 + 8));
            assert!(consistently_wound(&out));
            assert_eq!(edge_uses(&out)[&shared], 2);
            let (t0, t1) = (out.faces[0][0], out.faces[0][1]);
            let creased: Vec<(u32, u32)> = out.creases.iter().map(|c| key(c.a, c.b)).collect();
            assert!(creased.contains(&key(c0, c1)) && creased.contains(&key(t0, t1)));
            for f in faces {
                let normal = polygon_normal(&cage.points, &cage.faces[f]);
                let on = cage.points[cage.faces[f][0] as usize];
                for &v in &out.faces[f] {
                    let height = (out.points[v as usize] - on).dot(normal);
                    assert!((height - d).abs() < 1e-9 * scale, "{height} against {d}");
                }
            }
        }
        let flat = Cage {
            points: vec![DVec3::ZERO, DVec3::X, DVec3::X * 2.0],
            faces: vec![vec![0, 1, 2]],
            ..Cage::default()
        };
        assert!(flat.extrude_individual(&[0], 1.0).is_err());
    }
}
