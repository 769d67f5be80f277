//! Bridge Edge Loops, as Blender's `bridge_loops` has it: quads between two loops of the same
//! length, and a strip of triangles between loops of different lengths, turned to bend as
//! little as they can across each edge between the loops.
//!
//! It follows the conventions of [`super::cage_edit`]: the vertices keep their indices and the
//! new faces follow the old ones, wound to agree with the faces already on the loops.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use rustc_hash::FxHashSet as HashSet;

use glam::DVec3;

use super::cage_edit::{Cage, CageEditError, HalfEdges, invalid, key};
use super::cage_faces::beauty_splits_1_3;

impl Cage {
    /// Bridge two edge loops (Blender's Bridge Edge Loops): each loop is a closed chain of open
    /// edges named by its vertices in order.
    ///
    /// The second loop is turned so that the faces already on the two loops use their edges
    /// in opposite senses (so the bridge agrees in winding with both, which Blender's normals
    /// along the line between the loops' centres decide too, and which they leave open for
    /// two holes side by side in a plane).
    ///
    /// Loops of the same length are joined by quads, the second loop rotated to the pairing
    /// with the least total length of the bridging edges; a quad the cage has already is not
    /// made again (bridging a tube's own two rims adds nothing, as in Blender).
    ///
    /// Loops of different lengths are joined by a strip of triangles ([`bridge_strip`]), one
    /// on each edge of either loop, as Blender joins them: the shorter loop's points are
    /// repeated, spread evenly round it, until it is as long as the other; it is rotated to
    /// the least total length; the pairs are joined by quads and triangles, the quads split
    /// along their better diagonal, and the edges between the loops are then turned where
    /// that makes the two triangles on them bend less (Blender's Beautify Fill by angle).
    ///
    /// Where faces join the loops already (two holes one face apart, a hole one face from
    /// the border), the pairing of least length lays the bridge's faces over them; the next
    /// pairing by length that uses no half-edge twice is taken instead (Blender lays them
    /// over), and where every pairing would, the bridge is refused.
    pub fn bridge_loops(&self, first: &[u32], second: &[u32]) -> Result<Self, CageEditError> {
        if first.len() < 3 || second.len() < 3 {
            return Err(invalid(format!(
                "each loop needs at least 3 vertices (got {} and {})",
                first.len(),
                second.len()
            )));
        }
        let half = self.half_edges();
        let mut seen = HashSet::default();
        for loop_ in [first, second] {
            for i in 0..loop_.len() {
                let (a, b) = (loop_[i], loop_[(i + 1) % loop_.len()]);
                self.check_edge(&half, a, b)?;
                if !seen.insert(a) {
                    return Err(invalid(format!("vertex {a} is named twice in the loops")));
                }
                if half.contains_key(&(a, b)) && half.contains_key(&(b, a)) {
                    return Err(invalid(format!(
                        "edge {a}-{b} already has a face on each side: bridge open edges"
                    )));
                }
            }
        }
        // The longer loop leads (the first where they are as long); the other follows it.
        let (lead, other) = if second.len() > first.len() {
            (second, first)
        } else {
            (first, second)
        };
        // The other loop runs so that the bridge's faces agree in winding with the faces on
        // both loops: their faces must use the two loops' edges in opposite senses (each
        // loop edge is open, so its one face decides).
        let along = |l: &[u32]| half.contains_key(&(l[0], l[1]));
        let mut out = self.clone();
        if lead.len() == other.len() {
            let mut other: Vec<u32> = other.to_vec();
            if along(lead) == along(&other) {
                other.reverse();
            }
            // Wind the new faces against the face already on the leading loop's edges.
            let forward = along(lead);
            let k = lead.len();
            let quads_at = |shift: usize| -> Vec<Vec<u32>> {
                let paired = |i: usize| other[(i + shift) % k];
                (0..k)
                    .filter_map(|i| {
                        let j = (i + 1) % k;
                        let quad = if forward {
                            vec![lead[j], lead[i], paired(i), paired(j)]
                        } else {
                            vec![lead[i], lead[j], paired(j), paired(i)]
                        };
                        // A quad the cage has already (the face on this loop edge, as where a
                        // tube's own rims are bridged) is not made again, as Blender does not.
                        let on_edge = half
                            .get(&(lead[i], lead[j]))
                            .or_else(|| half.get(&(lead[j], lead[i])));
                        let exists = on_edge.is_some_and(|&(f, _)| {
                            let face = &self.faces[f];
                            face.len() == 4 && quad.iter().all(|v| face.contains(v))
                        });
                        (!exists).then_some(quad)
                    })
                    .collect()
            };
            let quads = rotations_by_length(&self.points, lead, &other)
                .into_iter()
                .map(quads_at)
                .find(|quads| !lays_over(&half, quads.iter().map(Vec::as_slice)))
                .ok_or_else(joined_already)?;
            out.faces.extend(quads);
        } else {
            // Each loop starts where Blender's would and runs as Blender turns it (the
            // repeated points of the shorter one depend on where it starts): the leading
            // loop along the faces on it, the other against them.
            let mut lead = self.blender_loop_order(lead);
            if !along(&lead) {
                lead.reverse();
            }
            let mut other = self.blender_loop_order(other);
            if along(&other) {
                other.reverse();
            }
            let strip =
                bridge_strip(&self.points, &half, &lead, &other).ok_or_else(joined_already)?;
            out.faces.extend(strip.iter().map(|t| t.to_vec()));
        }
        Ok(out.compacted(self))
    }

    /// Closed loop `loop_` as Blender's edge-loop search lists it, for a mesh built face by
    /// face in the cage's order: each face makes its missing edges from its last corner to
    /// its first, then round (Blender's `BM_edges_from_verts_ensure`), so the loop's first
    /// edge is the first of its edges met that way, and the list starts at that edge's first
    /// point and runs away from its second, ending there (`BM_mesh_edgeloops_find`).
    fn blender_loop_order(&self, loop_: &[u32]) -> Vec<u32> {
        let k = loop_.len();
        let edges: HashSet<(u32, u32)> =
            (0..k).map(|i| key(loop_[i], loop_[(i + 1) % k])).collect();
        let first = self.faces.iter().find_map(|face| {
            let n = face.len();
            (0..n)
                .map(|i| (face[(i + n - 1) % n], face[i]))
                .find(|&(a, b)| edges.contains(&key(a, b)))
        });
        let Some((v1, v2)) = first else {
            return loop_.to_vec();
        };
        let Some(p) = loop_.iter().position(|&v| v == v1) else {
            return loop_.to_vec();
        };
        let backwards = loop_[(p + 1) % k] == v2;
        (0..k)
            .map(|i| {
                loop_[if backwards {
                    (p + k - i) % k
                } else {
                    (p + i) % k
                }]
            })
            .collect()
    }
}

/// The rotations s of `paired` (as long as `lead`) that pair `lead[i]` with
/// `paired[(i + s) % k]`, by the total distance of the pairs, least first; where several tie,
/// the first (Blender's best rotation of a bridge's second loop leads).
fn rotations_by_length(points: &[DVec3], lead: &[u32], paired: &[u32]) -> Vec<usize> {
    let k = lead.len();
    let at = |v: u32| points[v as usize];
    let cost: Vec<f64> = (0..k)
        .map(|shift| {
            (0..k)
                .map(|i| at(lead[i]).distance(at(paired[(i + shift) % k])))
                .sum()
        })
        .collect();
    let mut order: Vec<usize> = (0..k).collect();
    order.sort_by(|&s, &t| cost[s].total_cmp(&cost[t]));
    order
}

/// Whether new faces `faces` would use a half-edge twice, among themselves or with the cage
/// (`half`): a bridge between loops that faces join already (two holes one face apart, a hole
/// one face from the border), paired straight across, lays its faces over those faces, and
/// every edge between the loops would then have three or four faces.
fn lays_over<'a>(half: &HalfEdges, faces: impl Iterator<Item = &'a [u32]>) -> bool {
    let mut made = HashSet::default();
    faces
        .flat_map(|face| (0..face.len()).map(move |c| (face[c], face[(c + 1) % face.len()])))
        .any(|edge| half.contains_key(&edge) || !made.insert(edge))
}

/// The refusal where every pairing of a bridge's loops lays faces over the cage's.
fn joined_already() -> CageEditError {
    invalid(
        "every pairing of the two loops lays a face over the faces between them: \
         the loops are joined already"
            .to_string(),
    )
}

/// The positions at which Blender's edge-loop expansion repeats a point of a loop of `len`
/// points to reach `target` (> `len`) points: every point while doubling keeps it at most
/// half as long, then `target − len` points spread evenly, the k-th of n over m points being
/// ⌈(2k + 1)·m / 2n⌉ − 1 (Blender's `BLI_FOREACH_SPARSE_RANGE`: 19 over 4 gives 2, 7, 11,
/// 16). Returns the expanded loop as indices into the original.
fn expanded_loop(len: usize, target: usize) -> Vec<usize> {
    let mut loop_: Vec<usize> = (0..len).collect();
    while loop_.len() * 2 < target {
        loop_ = loop_.iter().flat_map(|&i| [i, i]).collect();
    }
    let (m, n) = (loop_.len(), target - loop_.len());
    let mut repeated = vec![false; m];
    for k in 0..n {
        let at = ((2 * k + 1) * m).div_ceil(2 * n) - 1;
        repeated[at.min(m - 1)] = true;
    }
    loop_
        .iter()
        .zip(&repeated)
        .flat_map(|(&i, &twice)| std::iter::repeat_n(i, 1 + usize::from(twice)))
        .collect()
}

/// Which way a triangle of the strip steps: along the leading loop (its base on it, its apex
/// on the other) or along the other.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Step {
    Lead,
    Other,
}

/// An edge between the loops as it stands: its ends and the apexes of its two triangles,
/// each pair sorted (Blender's `EdRotState`).
#[derive(Clone, Copy, PartialEq, Eq)]
struct TurnState {
    edge: (u32, u32),
    apexes: (u32, u32),
}

/// An edge between the loops that may turn, and what turning it gains (negative: better).
#[derive(PartialEq)]
struct Candidate {
    gain: f64,
    edge: usize,
    version: u32,
}

impl Eq for Candidate {}

impl Ord for Candidate {
    /// The heap pops the most negative gain first, then the lower edge.
    fn cmp(&self, other: &Self) -> Ordering {
        other
            .gain
            .total_cmp(&self.gain)
            .then(other.edge.cmp(&self.edge))
    }
}

impl PartialOrd for Candidate {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

/// The angle between the normals of triangles (p2, p3, p4) and (p2, p4, p1) less the angle
/// between those of (p1, p2, p3) and (p1, p3, p4): what turning the diagonal p2–p4 of the quad
/// p1 p2 p3 p4 into p1–p3 gains in bending (Blender's Beautify Fill by angle); `None` where
/// either new triangle has no area.
fn turn_gain(p1: DVec3, p2: DVec3, p3: DVec3, p4: DVec3) -> Option<f64> {
    let normal = |a: DVec3, b: DVec3, c: DVec3| (b - a).cross(c - a).try_normalize();
    let now = normal(p2, p3, p4)?.angle_between(normal(p2, p4, p1)?);
    let turned = normal(p1, p2, p3)?.angle_between(normal(p1, p3, p4)?);
    Some(turned - now)
}

/// The triangles joining loop `lead` to the shorter loop `other` (both closed, `other` running
/// the same way round), wound as [`Cage::bridge_loops`] winds its quads where the faces on
/// `lead` run along it: (lead[i + 1], lead[i], other[j]) for a step along the leading loop,
/// (lead[i], other[j], other[j + 1]) for a step along the other.
///
/// The strip is a closed path of edges between the loops; each triangle steps one point along
/// one loop. It is built as Blender builds it: [`expanded_loop`], the rotation of least total
/// length, the quads split by [`beauty_splits_1_3`]. Then each edge between the loops whose
/// two triangles step along different loops is turned where [`turn_gain`] is negative, the
/// best first, never back into a state it was in, until none gains (Blender's Beautify Fill,
/// restricted to edges between the loops). `half`: the cage's half-edges, so that no turn
/// makes an edge the cage has already.
///
/// Where the strip at the least length would lay faces over the cage's ([`lays_over`]), the
/// next rotation by length is taken; `None` where every rotation does.
pub(super) fn bridge_strip(
    points: &[DVec3],
    half: &HalfEdges,
    lead: &[u32],
    other: &[u32],
) -> Option<Vec<[u32; 3]>> {
    let expanded = expanded_loop(other.len(), lead.len());
    let expanded_points: Vec<u32> = expanded.iter().map(|&e| other[e]).collect();
    rotations_by_length(points, lead, &expanded_points)
        .into_iter()
        .map(|shift| strip_at(points, half, lead, other, &expanded, shift))
        .find(|strip| !lays_over(half, strip.iter().map(|t| t.as_slice())))
}

/// [`bridge_strip`] with the shorter loop's expanded points `expanded` rotated by `shift`.
fn strip_at(
    points: &[DVec3],
    half: &HalfEdges,
    lead: &[u32],
    other: &[u32],
    expanded: &[usize],
    shift: usize,
) -> Vec<[u32; 3]> {
    let (n, m) = (lead.len(), other.len());
    let at = |v: u32| points[v as usize];
    // The path: edge k joins lead[i_k] and other[j_k] (indices counted on, not wrapped), and
    // triangle k lies between edges k and k + 1, stepping along steps[k].
    let start = expanded[shift];
    let mut ends: Vec<(usize, usize)> = Vec::with_capacity(n + m);
    let mut steps: Vec<Step> = Vec::with_capacity(n + m);
    // Where the other loop's expanded points wrap past its end, count on past m.
    let mut j_of = Vec::with_capacity(n + 1);
    let mut j = start;
    j_of.push(j);
    for i in 1..=n {
        let next = expanded[(i + shift) % n];
        if next != expanded[(i - 1 + shift) % n] {
            j += 1;
        }
        j_of.push(j);
    }
    for i in 0..n {
        let (j0, j1) = (j_of[i], j_of[i + 1]);
        ends.push((i, j0));
        if j0 == j1 {
            steps.push(Step::Lead);
        } else {
            // Quad lead[i] lead[i+1] other[j1] other[j0]: split along lead[i]–other[j1] (a step
            // along the other loop first) or lead[i+1]–other[j0] (along the lead first).
            // Blender's quad is (other[j0], other[j1], lead[i+1], lead[i]): corners 1–3 are
            // other[j1]–lead[i].
            let quad = [other[j0 % m], other[j1 % m], lead[(i + 1) % n], lead[i]];
            if beauty_splits_1_3(points, quad) {
                steps.push(Step::Other);
                ends.push((i, j1));
                steps.push(Step::Lead);
            } else {
                steps.push(Step::Lead);
                ends.push((i + 1, j0));
                steps.push(Step::Other);
            }
        }
    }
    let count = ends.len();
    let lead_at = |i: usize| lead[i % n];
    let other_at = |j: usize| other[j % m];
    // The edges the strip has, to refuse a turn onto one it has already (sorted pairs).
    let mut existing: HashSet<(u32, u32)> = ends
        .iter()
        .map(|&(i, j)| key(lead_at(i), other_at(j)))
        .collect();
    // The quad round edge k: p1 the apex before it, p2 its lead end, p3 the apex after it,
    // p4 its other end; turnable only where the two apexes lie on different loops.
    let gain_of =
        |k: usize, ends: &[(usize, usize)], steps: &[Step]| -> Option<(f64, (u32, u32))> {
            let (i, j) = ends[k];
            let (before, after) = (steps[(k + count - 1) % count], steps[k]);
            if before == after {
                return None;
            }
            let p1 = match before {
                Step::Lead => lead_at(i + n - 1),
                Step::Other => other_at(j + m - 1),
            };
            let p3 = match after {
                Step::Lead => lead_at(i + 1),
                Step::Other => other_at(j + 1),
            };
            if p1 == p3 {
                return None;
            }
            let gain = turn_gain(at(p1), at(lead_at(i)), at(p3), at(other_at(j)))?;
            Some((gain, (p1, p3)))
        };
    // The states each edge has been turned into.
    let state = |edge: (u32, u32), apex: (u32, u32)| TurnState {
        edge: key(edge.0, edge.1),
        apexes: key(apex.0, apex.1),
    };
    let mut visited: Vec<Vec<TurnState>> = vec![Vec::new(); count];
    let mut version = vec![0u32; count];
    let mut heap = BinaryHeap::new();
    for k in 0..count {
        if let Some((gain, _)) = gain_of(k, &ends, &steps)
            && gain < 0.0
        {
            heap.push(Candidate {
                gain,
                edge: k,
                version: 0,
            });
        }
    }
    // Each turn enters a state not visited before, and the states are finite.
    while let Some(Candidate {
        edge: k,
        version: v,
        ..
    }) = heap.pop()
    {
        if v != version[k] {
            continue;
        }
        version[k] += 1;
        let Some((_, (p1, p3))) = gain_of(k, &ends, &steps) else {
            continue;
        };
        let new_edge = key(p1, p3);
        if existing.contains(&new_edge)
            || half.contains_key(&(p1, p3))
            || half.contains_key(&(p3, p1))
        {
            continue;
        }
        let (i, j) = ends[k];
        let old_edge = (lead_at(i), other_at(j));
        existing.remove(&key(old_edge.0, old_edge.1));
        existing.insert(new_edge);
        let before = (k + count - 1) % count;
        ends[k] = match steps[before] {
            Step::Lead => (i + n - 1, j + 1),
            Step::Other => (i + 1, j + m - 1),
        };
        steps.swap(before, k);
        visited[k].push(state((p1, p3), old_edge));
        // The two edges beside it see new quads.
        for e in [before, (k + 1) % count] {
            version[e] += 1;
            let Some((gain, (q1, q3))) = gain_of(e, &ends, &steps) else {
                continue;
            };
            let (i, j) = ends[e];
            let turned = state((q1, q3), (lead_at(i), other_at(j)));
            if gain < 0.0 && !visited[e].contains(&turned) {
                heap.push(Candidate {
                    gain,
                    edge: e,
                    version: version[e],
                });
            }
        }
    }
    (0..count)
        .map(|k| {
            let (i, j) = ends[k];
            match steps[k] {
                Step::Lead => [lead_at(i + 1), lead_at(i), other_at(j)],
                Step::Other => [lead_at(i), other_at(j), other_at(j + 1)],
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::subdiv::cage_edit::tests::{
        cage_of, check_cage, consistently_wound, euler, open_half_edges,
    };
    use crate::subdiv::cages;
    use crate::test_support::{Xorshift, placement};

    /// Two open tubes of quads one above the other, `n` and `m` points round, radii and
    /// heights drawn at random, each point jittered, under a random motion: the points of the
    /// first tube's top rim (n..2n) and the second's bottom rim (2n..2n+m), in order round.
    fn two_tubes(draw: &mut Xorshift, n: u32, m: u32) -> (Cage, Vec<u32>, Vec<u32>) {
        let (motion, _) = placement(draw.bits());
        let mut points = Vec::new();
        let mut faces = Vec::new();
        let mut base = 0u32;
        for (k, z) in [(n, 0.0), (m, 1.6 + draw.unit())] {
            let (r0, r1, turn) = (0.7 + draw.unit(), 0.7 + draw.unit(), 6.3 * draw.unit());
            for (r, h) in [(r0, z), (r1, z + 1.0)] {
                for i in 0..k {
                    let a = turn + std::f64::consts::TAU * i as f64 / k as f64;
                    let jitter = 0.05 * (draw.unit() - 0.5);
                    let p = DVec3::new((r + jitter) * a.cos(), r * a.sin(), h + jitter);
                    points.push(motion.transform_point3(p));
                }
            }
            for i in 0..k {
                let j = (i + 1) % k;
                faces.push(vec![base + i, base + j, base + k + j, base + k + i]);
            }
            base += 2 * k;
        }
        let top: Vec<u32> = (n..2 * n).collect();
        let bottom: Vec<u32> = (2 * n..2 * n + m).collect();
        let cage = Cage {
            points,
            faces,
            creases: Vec::new(),
            corners: Vec::new(),
        };
        (cage, top, bottom)
    }

    /// Loops of different lengths in general position (3 to 13 points, named either way
    /// round, from any point, longer first or second): one triangle on each loop edge, its
    /// apex on the other loop, wound against the face on the edge; the two tubes become one
    /// tube (a manifold annulus, χ = 0, every edge between faces of agreeing winding), and no
    /// edge is made twice.
    #[test]
    fn loops_of_different_lengths_are_joined_by_one_triangle_on_each_edge() {
        let mut draw = Xorshift::new(61);
        for round in 0..300 {
            let n = 3 + draw.below(11) as u32;
            let mut m = 3 + draw.below(11) as u32;
            if m == n {
                m += 1;
            }
            let (cage, mut top, mut bottom) = two_tubes(&mut draw, n, m);
            if draw.below(2) == 0 {
                top.reverse();
            }
            let start = draw.below(bottom.len() as u64) as usize;
            bottom.rotate_left(start);
            let (first, second) = if draw.below(2) == 0 {
                (top.clone(), bottom.clone())
            } else {
                (bottom.clone(), top.clone())
            };
            let out = cage.bridge_loops(&first, &second).unwrap();
            let new = &out.faces[cage.faces.len()..];
            assert_eq!(new.len() as u32, n + m, "round {round}");
            let on_top = |v: u32| (n..2 * n).contains(&v);
            let mut based = HashSet::default();
            for face in new {
                assert_eq!(face.len(), 3, "round {round}: {face:?}");
                let tops = face.iter().filter(|&&v| on_top(v)).count();
                assert!(tops == 1 || tops == 2, "round {round}: {face:?}");
                // Its base, the edge on one loop, runs against that edge's old face.
                let base = (0..3)
                    .map(|c| (face[c], face[(c + 1) % 3]))
                    .find(|&(a, b)| on_top(a) == on_top(b))
                    .unwrap();
                assert!(
                    cage.faces.iter().any(|f| {
                        (0..f.len()).any(|c| (f[c], f[(c + 1) % f.len()]) == (base.1, base.0))
                    }),
                    "round {round}: {face:?} runs with its old face"
                );
                assert!(based.insert(key(base.0, base.1)), "round {round}");
            }
            check_cage(&out);
            assert_eq!(euler(&out), 0, "round {round}");
        }
    }

    /// Bridging an open tube's own two rims pairs each point with the one above it, so every
    /// quad is one of the tube's: nothing is added (Blender adds nothing either).
    #[test]
    fn a_tubes_own_rims_bridged_add_no_face_twice() {
        let mut draw = Xorshift::new(7);
        for n in 3..9 {
            let (cage, top, _) = two_tubes(&mut draw, n, n + 1);
            let bottom: Vec<u32> = (0..n).collect();
            let out = cage.bridge_loops(&bottom, &top).unwrap();
            assert_eq!(out.faces, cage.faces, "{n} points round");
        }
    }

    /// Loops that faces join already, in a 6 × 6 grid jittered and placed at random (points
    /// i · 7 + j, face (i, j) = i · 6 + j): two holes with one face between them, of the same
    /// length and of different lengths, and a hole one face from the grid's rim bridged to the
    /// rim. Paired straight across, each bridge would lay its faces over the faces between the
    /// loops (every edge there with three or four faces); the next pairing by length is taken
    /// instead: every half-edge once, one handle (χ = −1, the rim open) or a closed torus.
    #[test]
    fn loops_joined_by_faces_are_bridged_without_laying_faces_over_them() {
        let rim: Vec<u32> = (0..6)
            .chain((0..6).map(|i| i * 7 + 6))
            .chain((0..6).map(|j| 48 - j))
            .chain((0..6).map(|i| 42 - i * 7))
            .collect();
        // (faces taken out, first loop, second loop, new faces, χ, open half-edges)
        type Case = (&'static [usize], Vec<u32>, Vec<u32>, usize, i64, usize);
        let cases: [Case; 3] = [
            (&[7, 9], vec![8, 15, 16, 9], vec![10, 17, 18, 11], 4, -1, 24),
            (
                &[7, 9, 10],
                vec![8, 15, 16, 9],
                vec![10, 17, 18, 19, 12, 11],
                10,
                -1,
                24,
            ),
            (&[7], vec![8, 15, 16, 9], rim, 28, 0, 0),
        ];
        let mut draw = Xorshift::new(62);
        for seed in 1..13u64 {
            for (holes, first, second, made, chi, open) in &cases {
                let (mut grid, scale) = cage_of(&cages::grid(DVec3::ZERO, 6.0, 6).unwrap(), seed);
                for p in &mut grid.points {
                    *p += 0.1 * scale * DVec3::new(draw.unit(), draw.unit(), draw.unit());
                }
                for &f in holes.iter().rev() {
                    grid.faces.remove(f);
                }
                let (mut first, mut second) = (first.clone(), second.clone());
                if draw.below(2) == 0 {
                    first.reverse();
                }
                let start = draw.below(second.len() as u64) as usize;
                second.rotate_left(start);
                let (a, b) = if draw.below(2) == 0 {
                    (&first, &second)
                } else {
                    (&second, &first)
                };
                let out = grid.bridge_loops(a, b).unwrap();
                let what = format!("seed {seed}, {a:?} to {b:?}");
                assert_eq!(out.faces.len() - grid.faces.len(), *made, "{what}");
                assert!(consistently_wound(&out), "{what}");
                assert_eq!(euler(&out), *chi, "{what}");
                assert_eq!(open_half_edges(&out), *open, "{what}");
            }
        }
    }

    /// Blender's documented spreads: 19 over 4 gives 2, 7, 11, 16; 100 over 5 gives 9, 29,
    /// 49, 69, 89; 100 over 3 gives 16, 49, 83.
    #[test]
    fn repeated_points_spread_as_blenders_sparse_range() {
        let repeats = |len: usize, target: usize| -> Vec<usize> {
            let e = expanded_loop(len, target);
            (1..e.len())
                .filter(|&k| e[k] == e[k - 1])
                .map(|k| e[k])
                .collect()
        };
        assert_eq!(repeats(19, 23), vec![2, 7, 11, 16]);
        assert_eq!(repeats(100, 105), vec![9, 29, 49, 69, 89]);
        assert_eq!(repeats(100, 103), vec![16, 49, 83]);
        // Doubling first: 3 → 6 → 7.
        assert_eq!(expanded_loop(3, 7).len(), 7);
        assert_eq!(expanded_loop(3, 6), vec![0, 0, 1, 1, 2, 2]);
    }
}
