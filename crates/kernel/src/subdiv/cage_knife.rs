//! The knife across faces, as Blender's Bisect (and its Knife with Cut Through) has it: a
//! plane cuts the faces it crosses, each crossed edge taking a new point where the plane meets
//! it and each crossed face splitting along the plane.
//!
//! It follows the conventions of [`super::cage_edit`]: vertices keep their indices, the new
//! points follow (in the order of the faces and their edges), a split face keeps its index
//! for the piece holding its first corner and the other pieces follow, all wound as the face
//! was; an edge split in two gives each half its crease.

use rustc_hash::{FxHashMap as HashMap, FxHashSet as HashSet};

use glam::DVec3;

use super::cage_edit::{
    Cage, CageEditError, grown_by_cuts, invalid, key, loop_between, polygon_normal,
};

/// Points nearer the knife's plane than this part of the cage's size lie on it, unless a
/// threshold is given.
pub const KNIFE_THRESHOLD: f64 = 1e-6;

impl Cage {
    /// Knife (Blender's `bisect_plane`): cuts `faces` (every face when empty) with the plane
    /// through `point` square to `normal`.
    ///
    /// Each point of the faces gets its side of the plane, 0 within `threshold` of it (by
    /// default [`KNIFE_THRESHOLD`] of the cage's bounding diagonal). Every edge of the faces
    /// whose ends lie on opposite sides is split where the plane meets it, at
    /// t = d₀ / (d₀ − d₁) of the signed distances; the new points and the faces' points on the
    /// plane are the cut's points; a face outside `faces` on a split edge takes the new point
    /// into its loop and is not split. A named face with points on both sides is then split
    /// between its cut points: two are joined straight;
    /// more are sorted along the cut (the plane's normal × the face's normal) and joined in
    /// pairs, passing over a point where the face only touches the plane (its neighbours
    /// round the face on the same side), so a concave face is cut only where the plane runs
    /// inside it.
    pub fn knife(
        &self,
        faces: &[usize],
        point: DVec3,
        normal: DVec3,
        threshold: Option<f64>,
    ) -> Result<Self, CageEditError> {
        if !point.is_finite() {
            return Err(invalid("the knife's plane needs a finite point"));
        }
        let Some(normal) = normal.try_normalize() else {
            return Err(invalid(
                "the knife's plane needs a normal of non-zero length",
            ));
        };
        let faces: Vec<usize> = if faces.is_empty() {
            (0..self.faces.len()).collect()
        } else {
            self.check_faces(faces)?
        };
        let threshold = match threshold {
            Some(t) if t.is_finite() && t >= 0.0 => t,
            Some(t) => {
                return Err(invalid(format!(
                    "the knife's threshold must be a distance ≥ 0, not {t}"
                )));
            }
            None => KNIFE_THRESHOLD * self.bounding_diagonal(),
        };
        let n = self.points.len();
        let mut distance = vec![0.0; n];
        let mut side = vec![0i8; n];
        let mut on_plane = vec![false; n];
        for &f in &faces {
            for &v in &self.faces[f] {
                let d = (self.points[v as usize] - point).dot(normal);
                distance[v as usize] = d;
                side[v as usize] = if d > threshold {
                    1
                } else if d < -threshold {
                    -1
                } else {
                    on_plane[v as usize] = true;
                    0
                };
            }
        }
        // The crossed edges, split where the plane meets them.
        let mut out = self.clone();
        let sharp = self.sharpness_of_edges();
        let mut inner: HashMap<(u32, u32), Vec<u32>> = HashMap::default();
        for &f in &faces {
            let face = &self.faces[f];
            for c in 0..face.len() {
                let (a, b) = key(face[c], face[(c + 1) % face.len()]);
                if side[a as usize] * side[b as usize] >= 0 || inner.contains_key(&(a, b)) {
                    continue;
                }
                let (da, db) = (distance[a as usize], distance[b as usize]);
                let (pa, pb) = (self.points[a as usize], self.points[b as usize]);
                let new = out.points.len() as u32;
                out.points.push(pa + (pb - pa) * (da / (da - db)));
                if let Some(&s) = sharp.get(&(a, b)) {
                    out.add_crease(a, new, s);
                    out.add_crease(new, b, s);
                }
                inner.insert((a, b), vec![new]);
            }
        }
        side.resize(out.points.len(), 0);
        on_plane.resize(out.points.len(), true);
        let mut split = false;
        let named: HashSet<usize> = faces.iter().copied().collect();
        for f in 0..self.faces.len() {
            let face = grown_by_cuts(&self.faces[f], &inner);
            out.faces[f].clone_from(&face);
            if !named.contains(&f) || face.iter().all(|&v| !on_plane[v as usize]) {
                continue;
            }
            let pieces = split_along_plane(&out.points, &face, &side, &on_plane, normal);
            if pieces.len() > 1 {
                split = true;
            }
            let mut pieces = pieces.into_iter();
            if let Some(first) = pieces.next() {
                out.faces[f] = first;
            }
            out.faces.extend(pieces);
        }
        if !split && inner.is_empty() {
            return Err(invalid("the knife's plane crosses none of these faces"));
        }
        // The split edges' creases are on their halves now.
        Ok(out.compacted(self))
    }

    /// The length of the diagonal of the box round the cage's points.
    pub fn bounding_diagonal(&self) -> f64 {
        let (lo, hi) = self
            .points
            .iter()
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &p| {
                (lo.min(p), hi.max(p))
            });
        if self.points.is_empty() {
            0.0
        } else {
            (hi - lo).length()
        }
    }
}

/// The pieces of `face` (its cut points taken in) split along the plane of `normal` between
/// the points on it, as [`Cage::knife`] describes; the first holds the face's first corner.
fn split_along_plane(
    points: &[DVec3],
    face: &[u32],
    side: &[i8],
    on_plane: &[bool],
    normal: DVec3,
) -> Vec<Vec<u32>> {
    let len = face.len();
    let both_sides =
        face.iter().any(|&v| side[v as usize] < 0) && face.iter().any(|&v| side[v as usize] > 0);
    // The points on the plane, each with whether the face only touches the plane there.
    let mut cut: Vec<(u32, bool)> = (0..len)
        .filter(|&c| on_plane[face[c] as usize])
        .map(|c| {
            let (prev, next) = (face[(c + len - 1) % len], face[(c + 1) % len]);
            (face[c], side[prev as usize] == side[next as usize])
        })
        .collect();
    if !both_sides || cut.len() < 2 {
        return vec![face.to_vec()];
    }
    let mut pieces = vec![face.to_vec()];
    if cut.len() == 2 {
        split_piece(&mut pieces, cut[0].0, cut[1].0);
        return pieces;
    }
    let along = normal.cross(polygon_normal(points, face));
    cut.sort_by(|a, b| {
        along
            .dot(points[a.0 as usize])
            .total_cmp(&along.dot(points[b.0 as usize]))
    });
    let mut inside = false;
    for w in cut.windows(2) {
        if !w[0].1 {
            inside = !inside;
        }
        if inside {
            split_piece(&mut pieces, w[0].0, w[1].0);
        }
    }
    pieces
}

/// Splits the piece holding both `a` and `b` between them, where they are not neighbours in
/// it; the part holding the piece's first corner stays in its place.
fn split_piece(pieces: &mut Vec<Vec<u32>>, a: u32, b: u32) {
    let found = pieces.iter().enumerate().find_map(|(k, piece)| {
        let i = piece.iter().position(|&v| v == a)?;
        let j = piece.iter().position(|&v| v == b)?;
        Some((k, i, j))
    });
    let Some((k, i, j)) = found else {
        return;
    };
    let len = pieces[k].len();
    if (i + 1) % len == j || (j + 1) % len == i {
        return;
    }
    let (i, j) = (i.min(j), i.max(j));
    let first = loop_between(&pieces[k], j, i);
    let second = loop_between(&pieces[k], i, j);
    pieces[k] = first;
    pieces.push(second);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::subdiv::cage_edit::tests::{cage_of as placed, euler, volume};
    use crate::subdiv::cages;
    use crate::test_support::{Xorshift, placement};
    use std::collections::HashSet;

    fn edges(cage: &Cage) -> HashSet<(u32, u32)> {
        cage.faces
            .iter()
            .flat_map(|f| (0..f.len()).map(move |c| key(f[c], f[(c + 1) % f.len()])))
            .collect()
    }

    /// The faces' areas (the Newell vectors' lengths, halved).
    fn area(cage: &Cage) -> f64 {
        cage.faces
            .iter()
            .map(|f| {
                let n: DVec3 = (0..f.len())
                    .map(|c| {
                        cage.points[f[c] as usize].cross(cage.points[f[(c + 1) % f.len()] as usize])
                    })
                    .sum();
                n.length() / 2.0
            })
            .sum()
    }

    fn random_direction(rng: &mut Xorshift) -> DVec3 {
        loop {
            let d = DVec3::new(rng.unit(), rng.unit(), rng.unit()) * 2.0 - 1.0;
            if let Some(d) = d.try_normalize() {
                return d;
            }
        }
    }

    #[test]
    fn a_plane_across_a_box_splits_every_crossed_edge_on_the_plane_and_keeps_the_box() {
        let cube = cages::cube(DVec3::ZERO, 2.0).unwrap();
        for seed in 0..40u64 {
            let (cage, scale) = placed(&cube, seed);
            let mut rng = Xorshift::new(seed + 100);
            let centre = cage.points.iter().sum::<DVec3>() / 8.0;
            let normal = random_direction(&mut rng);
            let point = centre + random_direction(&mut rng) * 0.5 * scale * rng.unit();
            let side = |p: DVec3| (p - point).dot(normal);
            let crossed = edges(&cage)
                .iter()
                .filter(|&&(a, b)| {
                    side(cage.points[a as usize]) * side(cage.points[b as usize]) < 0.0
                })
                .count();
            let cut = cage.knife(&[], point, normal * 3.0, None).unwrap();
            let tolerance = 1e-12 * scale * 100.0;
            // One point for each crossed edge, on the plane and on that edge.
            assert_eq!(cut.points.len(), 8 + crossed, "seed {seed}");
            for &p in &cut.points[8..] {
                assert!(side(p).abs() < tolerance, "seed {seed}: {}", side(p));
            }
            // Every face wholly on one side; the faces the plane crosses (a closed polygon of
            // the crossed edges' points) each split in two.
            let sides: Vec<f64> = cut.points.iter().map(|&p| side(p)).collect();
            for f in &cut.faces {
                let (lo, hi) = f.iter().fold((0.0f64, 0.0f64), |(lo, hi), &v| {
                    (lo.min(sides[v as usize]), hi.max(sides[v as usize]))
                });
                assert!(lo > -tolerance || hi < tolerance, "seed {seed}: {f:?}");
            }
            assert_eq!(cut.faces.len(), 6 + crossed, "seed {seed}");
            // Closed, one piece of surface as before: V − E + F = 2; the same solid.
            assert_eq!(euler(&cut), 2);
            let v = 8.0 * scale.powi(3);
            assert!((volume(&cut) - v).abs() < 1e-9 * v, "seed {seed}");
            assert!((area(&cut) - area(&cage)).abs() < 1e-9 * v / scale);
        }
    }

    #[test]
    fn a_plane_across_a_concave_face_cuts_it_only_where_it_runs_inside() {
        // A U with arms from y = 0.8 to 2: the line y = 1.4 crosses it four times, inside
        // between the first two and the last two crossings, outside across the gap.
        let u = [
            (0.0, 0.0),
            (3.0, 0.0),
            (3.0, 2.0),
            (2.0, 2.0),
            (2.0, 0.8),
            (1.0, 0.8),
            (1.0, 2.0),
            (0.0, 2.0),
        ];
        for seed in 0..20u64 {
            let (motion, scale) = placement(seed);
            let cage = Cage {
                points: u
                    .iter()
                    .map(|&(x, y)| motion.transform_point3(DVec3::new(x, y, 0.0)))
                    .collect(),
                faces: vec![(0..8).collect()],
                ..Cage::default()
            };
            let point = motion.transform_point3(DVec3::new(0.0, 1.4, 0.0));
            let normal = motion.transform_vector3(DVec3::new(0.1, 1.0, 0.3));
            let cut = cage.knife(&[], point, normal, None).unwrap();
            assert_eq!(cut.points.len(), 12, "seed {seed}");
            assert_eq!(cut.faces.len(), 3, "seed {seed}");
            let mut sizes: Vec<usize> = cut.faces.iter().map(Vec::len).collect();
            sizes.sort();
            // The two arms' tips (quads) and the U's base (the rest, with four new points).
            assert_eq!(sizes, [4, 4, 8], "seed {seed}");
            let a = 3.0 * 2.0 - 1.0 * 1.2;
            assert!((area(&cut) - a * scale * scale).abs() < 1e-9 * a * scale * scale);
        }
    }

    #[test]
    fn a_crease_on_a_split_edge_goes_to_both_halves() {
        let cube = cages::cube(DVec3::ZERO, 2.0).unwrap();
        let (mut cage, _) = placed(&cube, 3);
        let (a, b) = (cage.faces[0][0], cage.faces[0][1]);
        cage.creases.push(crate::subdiv::Crease {
            a,
            b,
            sharpness: 2.5,
        });
        let (pa, pb) = (cage.points[a as usize], cage.points[b as usize]);
        let cut = cage.knife(&[], (pa + pb) / 2.0, pb - pa, None).unwrap();
        let mut halves: Vec<(u32, u32)> = cut
            .creases
            .iter()
            .map(|c| {
                assert_eq!(c.sharpness, 2.5);
                key(c.a, c.b)
            })
            .collect();
        halves.sort();
        let new = cut
            .points
            .iter()
            .position(|&p| (p - (pa + pb) / 2.0).length() < 1e-9)
            .unwrap() as u32;
        assert_eq!(halves, [key(a, new), key(new, b)]);
    }

    #[test]
    fn bad_knives_are_refused_with_the_reason() {
        let cage = placed(&cages::cube(DVec3::ZERO, 2.0).unwrap(), 1).0;
        let centre = cage.points.iter().sum::<DVec3>() / 8.0;
        let refusal = |r: Result<Cage, CageEditError>| r.unwrap_err().to_string();
        assert!(refusal(cage.knife(&[], centre, DVec3::ZERO, None)).contains("normal"));
        assert!(refusal(cage.knife(&[], DVec3::NAN, DVec3::X, None)).contains("finite"));
        assert!(refusal(cage.knife(&[], centre, DVec3::X, Some(-1.0))).contains("threshold"));
        assert!(refusal(cage.knife(&[9], centre, DVec3::X, None)).contains("face 9"));
        let far = centre + DVec3::X * 1e3;
        assert!(refusal(cage.knife(&[], far, DVec3::X, None)).contains("crosses none"));
    }
}
