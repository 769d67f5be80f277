//! Grid fill, as Blender's Grid Fill has it: a grid of quads over a hole whose rim is two
//! opposite chains of open edges (the grid's first and last rows) and the two paths of open
//! edges that join their ends (its first and last columns, the rails).
//!
//! It follows the conventions of [`super::cage_edit`]: vertices keep their indices, the grid's
//! inner points follow row by row, and the new quads follow the faces, column by column, wound
//! to agree with the faces already on the rim.

use std::collections::VecDeque;

use rustc_hash::{FxHashMap as HashMap, FxHashSet as HashSet};

use glam::DVec3;

use super::cage_edit::{Cage, CageEditError, invalid};

/// The grid's rim as four sides: `bottom` and `top` run the same way (the grid's x), `left`
/// from `bottom[0]` to `top[0]` and `right` from the last of `bottom` to the last of `top`.
struct Sides {
    bottom: Vec<u32>,
    top: Vec<u32>,
    left: Vec<u32>,
    right: Vec<u32>,
}

/// A triangle standing on the segment a–b of one row of the grid, its apex above the segment's
/// middle along the mean direction in which the grid's columns leave a and b (toward the next
/// row, averaged with the way they came from the previous one where there is one; reversed with
/// `flip`), as far as a is from b. Row points carried from one such triangle to another keep
/// their place relative to the rails.
fn row_frame(
    [a, b]: [DVec3; 2],
    [a_next, b_next]: [DVec3; 2],
    previous: Option<[DVec3; 2]>,
    flip: bool,
) -> [DVec3; 3] {
    let mean =
        |p: DVec3, q: DVec3| (p.normalize_or_zero() + q.normalize_or_zero()).normalize_or_zero();
    let mut up = mean(a_next - a, b_next - b);
    if let Some([a_prev, b_prev]) = previous {
        up = (up + mean(a - a_prev, b - b_prev)).normalize_or_zero();
    }
    if flip {
        up = -up;
    }
    [a, b, (a + b) * 0.5 + up * a.distance(b)]
}

/// Carries `p` from triangle `from` to triangle `to`: its projection's barycentric coordinates
/// on `from` applied to `to`'s corners, and its height over `from`'s plane scaled by the ratio
/// of the triangles' sizes (square roots of their areas) along `to`'s normal. None when either
/// triangle has no area.
fn carried(p: DVec3, from: [DVec3; 3], to: [DVec3; 3]) -> Option<DVec3> {
    let normal = |t: [DVec3; 3]| (t[0] - t[1]).cross(t[1] - t[2]);
    let (n_from, n_to) = (normal(from), normal(to));
    let (area_from, area_to) = (n_from.length(), n_to.length());
    if area_from <= f64::MIN_POSITIVE || area_to <= f64::MIN_POSITIVE {
        return None;
    }
    let (n_from, n_to) = (n_from / area_from, n_to / area_to);
    let height = (p - from[0]).dot(n_from);
    let q = p - n_from * height;
    let twice = |a: DVec3, b: DVec3| (a - q).cross(b - q).dot(n_from);
    let w = [
        twice(from[1], from[2]),
        twice(from[2], from[0]),
        twice(from[0], from[1]),
    ];
    let sum = w[0] + w[1] + w[2];
    let inside = (to[0] * w[0] + to[1] * w[1] + to[2] * w[2]) / sum;
    Some(inside + n_to * (height * (area_to / area_from).sqrt()))
}

impl Cage {
    /// Grid fill (Blender's Grid Fill, `bmesh.ops.grid_fill`) between two open chains of open
    /// edges with as many vertices each, named in order: the rails are the shortest paths of
    /// open edges joining the chains' ends (the first chain's first vertex to whichever end of
    /// the second is nearer along them), and must have as many vertices as each other. Each
    /// inner grid point is the blend, by its row's height, of the first and last rows' points
    /// carried by [`carried`] from their own [`row_frame`] to the row's.
    pub fn grid_fill(&self, first: &[u32], second: &[u32]) -> Result<Self, CageEditError> {
        if first.len() < 2 || first.len() != second.len() {
            return Err(invalid(format!(
                "grid fill needs two chains of the same number of vertices, at least 2 (got {} \
                 and {})",
                first.len(),
                second.len()
            )));
        }
        let half = self.half_edges();
        for chain in [first, second] {
            self.check_open_chain(&half, chain, false)?;
        }
        if let Some(v) = first.iter().find(|v| second.contains(v)) {
            return Err(invalid(format!("vertex {v} is in both chains")));
        }
        let open = open_neighbours(&half);
        let path = |from: u32, to: u32| {
            shortest_path(&open, from, to).ok_or_else(|| {
                invalid(format!(
                    "no path of open edges joins vertex {from} to vertex {to}: the chains must \
                     be two sides of one hole"
                ))
            })
        };
        let (a_first, a_last) = (first[0], first[first.len() - 1]);
        let to_first = path(a_first, second[0])?;
        let to_last = path(a_first, second[second.len() - 1])?;
        let mut top = second.to_vec();
        let left = if to_first.len() < to_last.len() {
            to_first
        } else {
            top.reverse();
            to_last
        };
        let right = path(a_last, top[top.len() - 1])?;
        self.fill_grid_sides(
            &half,
            Sides {
                bottom: first.to_vec(),
                top,
                left,
                right,
            },
        )
    }

    /// Grid fill over a whole hole (Blender's Grid Fill on one closed loop): the rim, a closed
    /// chain of an even number of open edges named in order, is cut into the grid's sides from
    /// its vertex `offset` (by default its sharpest corner, the one whose edges turn furthest
    /// from straight): the first `span` edges and as many from the middle of the rim on are the
    /// rails, the rest the chains [`Self::grid_fill`] fills between. By default `span` runs to
    /// the next of the rim's four sharpest corners within its first half.
    pub fn grid_fill_rim(
        &self,
        rim: &[u32],
        span: Option<u32>,
        offset: Option<usize>,
    ) -> Result<Self, CageEditError> {
        let n = rim.len();
        if n < 4 || n % 2 == 1 {
            return Err(invalid(format!(
                "a rim to grid fill needs an even number of edges, at least 4 (got {n})"
            )));
        }
        let half = self.half_edges();
        self.check_open_chain(&half, rim, true)?;
        let turn = |k: usize| -> f64 {
            let p = |i: usize| self.points[rim[i % n] as usize];
            let (a, b) = (p(k + n - 1) - p(k), p(k + 1) - p(k));
            (std::f64::consts::PI - a.angle_between(b)).abs()
        };
        let start = match offset {
            Some(o) => o % n,
            None => (0..n).fold(0, |best, k| if turn(k) > turn(best) { k } else { best }),
        };
        let rim: Vec<u32> = (0..=n).map(|k| rim[(start + k) % n]).collect();
        let span = match span {
            Some(s) => (s as usize).min(n / 2 - 1),
            None => {
                let mut order: Vec<usize> = (0..n).collect();
                order.sort_by(|&i, &j| turn(start + j).total_cmp(&turn(start + i)));
                let sharp: HashSet<usize> = order.into_iter().take(4).collect();
                (1..n / 2).find(|k| sharp.contains(k)).unwrap_or(n / 4)
            }
        };
        if span == 0 {
            return Err(invalid(
                "the span (edges along each rail) must be at least 1",
            ));
        }
        let h = n / 2;
        let mut top = rim[h + span..=n].to_vec();
        top.reverse();
        let mut left = rim[..=span].to_vec();
        left.reverse();
        self.fill_grid_sides(
            &half,
            Sides {
                bottom: rim[span..=h].to_vec(),
                top,
                left,
                right: rim[h..=h + span].to_vec(),
            },
        )
    }

    /// Refuses a chain (closed with `closed`) whose vertices repeat or whose steps are not open
    /// edges of the cage.
    fn check_open_chain(
        &self,
        half: &super::cage_edit::HalfEdges,
        chain: &[u32],
        closed: bool,
    ) -> Result<(), CageEditError> {
        let mut seen = HashSet::default();
        let steps = if closed { chain.len() } else { chain.len() - 1 };
        for (k, &a) in chain.iter().enumerate() {
            self.check_vertex(a)?;
            if !seen.insert(a) {
                return Err(invalid(format!("vertex {a} is named twice")));
            }
            if k < steps {
                let b = chain[(k + 1) % chain.len()];
                self.check_edge(half, a, b)?;
                if half.contains_key(&(a, b)) && half.contains_key(&(b, a)) {
                    return Err(invalid(format!(
                        "edge {a}-{b} already has a face on each side: grid fill needs open edges"
                    )));
                }
            }
        }
        Ok(())
    }

    /// The grid over `sides`: inner points placed as [`Self::grid_fill`] says, quads column by
    /// column wound against the faces on the rim (by a vote of its edges).
    fn fill_grid_sides(
        &self,
        half: &super::cage_edit::HalfEdges,
        sides: Sides,
    ) -> Result<Self, CageEditError> {
        let Sides {
            bottom,
            top,
            left,
            right,
        } = sides;
        let (xs, ys) = (bottom.len(), left.len());
        if ys < 2 || right.len() != ys {
            return Err(invalid(format!(
                "the rails joining the chains' ends differ in length ({} and {} vertices)",
                left.len(),
                right.len()
            )));
        }
        let mut grid = vec![u32::MAX; xs * ys];
        let at = |x: usize, y: usize| x + y * xs;
        for x in 0..xs {
            grid[at(x, 0)] = bottom[x];
            grid[at(x, ys - 1)] = top[x];
        }
        for y in 0..ys {
            grid[at(0, y)] = left[y];
            grid[at(xs - 1, y)] = right[y];
        }
        // The rim must be one loop: its corners shared, nothing else repeated.
        let rim: HashSet<u32> = bottom
            .iter()
            .chain(&top)
            .chain(&left)
            .chain(&right)
            .copied()
            .collect();
        let expected = 2 * (xs - 1) + 2 * (ys - 1);
        if rim.len() != expected
            || left[0] != bottom[0]
            || left[ys - 1] != top[0]
            || right[0] != bottom[xs - 1]
            || right[ys - 1] != top[xs - 1]
        {
            return Err(invalid(
                "the chains and the rails joining them overlap: they must make the rim of one \
                 hole",
            ));
        }
        // Only the rim's points are read: the inner ones are placed after.
        let point = |x: usize, y: usize| self.points[grid[at(x, y)] as usize];
        let row = |y: usize| [point(0, y), point(xs - 1, y)];
        let first_frame = row_frame(row(0), row(1), None, false);
        let last_frame = row_frame(row(ys - 1), row(ys - 2), None, true);
        let mut inner = Vec::with_capacity((xs - 2) * (ys - 2));
        for y in 1..ys - 1 {
            let frame = row_frame(row(y), row(y + 1), Some(row(y - 1)), false);
            let t = y as f64 / (ys - 1) as f64;
            for x in 1..xs - 1 {
                let from_first = carried(point(x, 0), first_frame, frame);
                let from_last = carried(point(x, ys - 1), last_frame, frame);
                match (from_first, from_last) {
                    (Some(a), Some(b)) if a.lerp(b, t).is_finite() => inner.push(a.lerp(b, t)),
                    _ => {
                        return Err(invalid(
                            "the rim is degenerate: two of its points coincide or its rows have \
                             no direction to grow in",
                        ));
                    }
                }
            }
        }
        let mut out = self.clone();
        for y in 1..ys - 1 {
            for x in 1..xs - 1 {
                grid[at(x, y)] = out.points.len() as u32;
                out.points.push(inner[(y - 1) * (xs - 2) + x - 1]);
            }
        }
        // Quad (x, y) wound x+1 → x+1, y+1 → x, y+1 → x runs from grid(x, 0) to grid(x + 1, 0)
        // along the bottom: count the rim edges whose face already runs that same way.
        let mut same = 0i64;
        let mut rim_edge = |a: u32, b: u32| {
            if half.contains_key(&(a, b)) {
                same += 1;
            } else if half.contains_key(&(b, a)) {
                same -= 1;
            }
        };
        for x in 0..xs - 1 {
            rim_edge(grid[at(x, 0)], grid[at(x + 1, 0)]);
            rim_edge(grid[at(x + 1, ys - 1)], grid[at(x, ys - 1)]);
        }
        for y in 0..ys - 1 {
            rim_edge(grid[at(xs - 1, y)], grid[at(xs - 1, y + 1)]);
            rim_edge(grid[at(0, y + 1)], grid[at(0, y)]);
        }
        let flip = same > 0;
        for x in 0..xs - 1 {
            for y in 0..ys - 1 {
                let mut quad = vec![
                    grid[at(x + 1, y)],
                    grid[at(x + 1, y + 1)],
                    grid[at(x, y + 1)],
                    grid[at(x, y)],
                ];
                if flip {
                    quad.reverse();
                }
                out.faces.push(quad);
            }
        }
        Ok(out)
    }
}

/// Each vertex's neighbours along open edges (edges with a face on one side only), in
/// ascending order.
fn open_neighbours(half: &super::cage_edit::HalfEdges) -> HashMap<u32, Vec<u32>> {
    let mut out: HashMap<u32, Vec<u32>> = HashMap::default();
    for (a, b) in half.keys() {
        if !half.contains_key(&(b, a)) {
            out.entry(a).or_default().push(b);
            out.entry(b).or_default().push(a);
        }
    }
    for list in out.values_mut() {
        list.sort_unstable();
    }
    out
}

/// A path of fewest edges from `from` to `to` over `neighbours` (breadth first), both ends
/// included.
fn shortest_path(neighbours: &HashMap<u32, Vec<u32>>, from: u32, to: u32) -> Option<Vec<u32>> {
    let mut came_from: HashMap<u32, u32> = HashMap::from_iter([(from, from)]);
    let mut queue = VecDeque::from([from]);
    while let Some(v) = queue.pop_front() {
        if v == to {
            let mut path = vec![to];
            let mut at = to;
            while at != from {
                at = *came_from.get(&at)?;
                path.push(at);
            }
            path.reverse();
            return Some(path);
        }
        for &n in neighbours.get(&v).into_iter().flatten() {
            if let std::collections::hash_map::Entry::Vacant(e) = came_from.entry(n) {
                e.insert(v);
                queue.push_back(n);
            }
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::subdiv::cage_edit::tests::{cage_of as placed, consistently_wound, euler, volume};
    use crate::subdiv::cages;
    use crate::test_support::{Xorshift, placement};
    use glam::{DAffine3, DMat3};

    /// A hole of random size cut anywhere in a flat grid that a random affine map (shear and
    /// uneven scale too) has moved: grid fill between its long or its short sides, or over its
    /// rim named from any point either way round, puts back each lost point where it was (the
    /// rows of an affine grid are straight and evenly spaced) and closes the disc (χ = 1).
    #[test]
    fn a_hole_in_an_affine_grid_is_filled_with_the_points_it_lost() {
        let cells = 9usize;
        let n = cells + 1;
        let mesh = cages::grid(DVec3::ZERO, 4.0, cells).unwrap();
        let id = |i: usize, j: usize| (i * n + j) as u32;
        for seed in 0..40u64 {
            let mut draw = Xorshift::new(seed + 77);
            let (motion, _) = placement(seed);
            let skew = DMat3::from_cols_array(&std::array::from_fn(|k| {
                (if k % 4 == 0 { 1.0 } else { 0.0 }) + 0.6 * (draw.unit() - 0.5)
            }));
            let map = motion * DAffine3::from_mat3(skew);
            let whole = Cage {
                points: mesh
                    .points()
                    .iter()
                    .map(|&p| map.transform_point3(p))
                    .collect(),
                faces: mesh.faces().map(<[u32]>::to_vec).collect(),
                ..Cage::default()
            };
            // The hole: cells i0..=i1 × j0..=j1, with at least one cell round it.
            let pick = |draw: &mut Xorshift| {
                let a = 1 + draw.below(cells as u64 - 2) as usize;
                let b = 1 + draw.below(cells as u64 - 2) as usize;
                (a.min(b), a.max(b))
            };
            let ((i0, i1), (j0, j1)) = (pick(&mut draw), pick(&mut draw));
            let inside = |i: usize, j: usize| (i0..=i1).contains(&i) && (j0..=j1).contains(&j);
            let mut holed = whole.clone();
            holed.faces = (0..cells)
                .flat_map(|i| (0..cells).map(move |j| (i, j)))
                .filter(|&(i, j)| !inside(i, j))
                .map(|(i, j)| whole.faces[i * cells + j].clone())
                .collect();
            let bottom: Vec<u32> = (i0..=i1 + 1).map(|i| id(i, j0)).collect();
            let top: Vec<u32> = (i0..=i1 + 1).map(|i| id(i, j1 + 1)).collect();
            let left: Vec<u32> = (j0..=j1 + 1).map(|j| id(i0, j)).collect();
            let right: Vec<u32> = (j0..=j1 + 1).map(|j| id(i1 + 1, j)).collect();
            let mut rim: Vec<u32> = bottom.clone();
            rim.extend(right[1..].iter());
            rim.extend(top.iter().rev().skip(1));
            rim.extend(left.iter().rev().skip(1).take(left.len() - 2));
            let start = draw.below(rim.len() as u64) as usize;
            rim.rotate_left(start);
            if draw.below(2) == 1 {
                rim.reverse();
            }
            let mut reversed_top = top.clone();
            reversed_top.reverse();
            let filled = [
                holed.grid_fill(&bottom, &top).unwrap(),
                holed.grid_fill(&right, &left).unwrap(),
                holed.grid_fill(&reversed_top, &bottom).unwrap(),
                holed.grid_fill_rim(&rim, None, None).unwrap(),
            ];
            let lost: Vec<DVec3> = (i0 + 1..=i1)
                .flat_map(|i| (j0 + 1..=j1).map(move |j| (i, j)))
                .map(|(i, j)| whole.points[id(i, j) as usize])
                .collect();
            for (k, out) in filled.iter().enumerate() {
                assert_eq!(out.faces.len(), whole.faces.len(), "seed {seed}, fill {k}");
                assert_eq!(
                    euler(out) - (out.points.len() - whole.points.len()) as i64,
                    1
                );
                assert!(consistently_wound(out), "seed {seed}, fill {k}");
                let new = &out.points[whole.points.len()..];
                assert_eq!(new.len(), lost.len(), "seed {seed}, fill {k}");
                for p in new {
                    let nearest = lost.iter().map(|q| q.distance(*p)).fold(f64::MAX, f64::min);
                    assert!(
                        nearest < 1e-9,
                        "seed {seed}, fill {k}: {nearest:e} off the grid"
                    );
                }
            }
        }
    }

    /// Both ends of a randomly placed tube, uneven rims of 2k edges, filled over the whole rim
    /// at every offset and span: the tube closes (χ = 2, consistently wound, the new quads
    /// facing out: positive volume) and each cap's inner points lie in its rim's plane.
    #[test]
    fn grid_fill_caps_a_tube_flat_in_every_orientation() {
        for (seed, around) in [(1u64, 8usize), (2, 10), (3, 12)] {
            let tube = cages::cylinder(DVec3::ZERO, 1.3, 2.0, around, 3).unwrap();
            let (cage, _) = placed(&tube, seed);
            let rows = 4u32;
            let rim = |j: u32| {
                (0..around as u32)
                    .map(|i| i * rows + j)
                    .collect::<Vec<u32>>()
            };
            for offset in 0..around {
                for span in 1..around as u32 / 2 {
                    let out = cage
                        .grid_fill_rim(&rim(0), Some(span), Some(offset))
                        .and_then(|c| c.grid_fill_rim(&rim(3), Some(span), Some(offset)))
                        .unwrap();
                    assert_eq!(
                        euler(&out),
                        2,
                        "around {around}, offset {offset}, span {span}"
                    );
                    assert!(consistently_wound(&out));
                    assert!(volume(&out) > 0.0);
                    for j in [0, 3] {
                        let plane = polygon_normal_of(&cage, &rim(j));
                        let p0 = cage.points[rim(j)[0] as usize];
                        let inner = (around / 2 - span as usize - 1) * (span as usize - 1);
                        let first = cage.points.len() + if j == 0 { 0 } else { inner };
                        for p in &out.points[first..first + inner] {
                            assert!((*p - p0).dot(plane).abs() < 1e-9, "{p} off the cap's plane");
                        }
                    }
                }
            }
        }
    }

    fn polygon_normal_of(cage: &Cage, face: &[u32]) -> DVec3 {
        crate::subdiv::cage_edit::polygon_normal(&cage.points, face)
    }

    #[test]
    fn grid_fill_refuses_what_is_not_two_sides_of_a_hole() {
        let grid = cages::grid(DVec3::ZERO, 2.0, 4).unwrap();
        let (mut cage, _) = placed(&grid, 5);
        // Without the middle 2 × 2 cells (points 6-8, 11-13, 16-18 round it).
        cage.faces.retain(|f| !f.contains(&12));
        let refused = |r: Result<Cage, CageEditError>| match r {
            Err(CageEditError::Invalid(m)) => m,
            other => panic!("expected a refusal, got {other:?}"),
        };
        let message = refused(cage.grid_fill(&[6, 7, 8], &[16, 17]));
        assert!(message.contains("same number"), "{message}");
        // 7-12 is no edge any face still has: the middle point is gone from the cage's faces.
        assert!(matches!(
            cage.grid_fill(&[6, 7, 12], &[16, 17, 18]),
            Err(CageEditError::NoEdge(7, 12))
        ));
        let message = refused(cage.grid_fill(&[1, 6, 11], &[16, 17, 18]));
        assert!(message.contains("face on each side"), "{message}");
        let message = refused(cage.grid_fill_rim(&[6, 7, 8, 13, 18, 17, 16], None, None));
        assert!(message.contains("even number"), "{message}");
        let message = refused(cage.grid_fill(&[6, 7, 8], &[8, 13, 18]));
        assert!(message.contains("both chains"), "{message}");
        // The outer border is another hole's rim: no open path joins it to the middle one.
        let message = refused(cage.grid_fill(&[6, 7, 8], &[0, 1, 2]));
        assert!(message.contains("no path"), "{message}");
    }
}
