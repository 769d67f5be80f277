//! Selection on a subdivision cage, as Blender's edit mode has it: the faces and edges a set of
//! selected vertices covers, edge loops and rings, select more and less, select linked, and the
//! closed loops a set of edges makes (what Bridge Edge Loops takes).
//!
//! A selection is a set of vertices, as in Blender's vertex mode: an edge is selected when both
//! its ends are, a face when all its corners are.

use std::collections::BTreeSet;

use rustc_hash::{FxHashMap as HashMap, FxHashSet as HashSet};

use super::cage_edit::{Cage, CageEditError};

fn key(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

impl Cage {
    /// Every edge once, as (lower, higher) vertex, in the order the faces first name them.
    pub fn edges(&self) -> Vec<(u32, u32)> {
        let mut seen = HashSet::default();
        let mut out = Vec::new();
        for face in &self.faces {
            for c in 0..face.len() {
                let e = key(face[c], face[(c + 1) % face.len()]);
                if seen.insert(e) {
                    out.push(e);
                }
            }
        }
        out
    }

    /// The faces all of whose corners are selected.
    pub fn faces_within(&self, selected: &BTreeSet<u32>) -> Vec<usize> {
        (0..self.faces.len())
            .filter(|&f| self.faces[f].iter().all(|v| selected.contains(v)))
            .collect()
    }

    /// The edges both of whose ends are selected.
    pub fn edges_within(&self, selected: &BTreeSet<u32>) -> Vec<(u32, u32)> {
        self.edges()
            .into_iter()
            .filter(|(a, b)| selected.contains(a) && selected.contains(b))
            .collect()
    }

    /// Each vertex's neighbours along edges.
    fn neighbours(&self) -> HashMap<u32, Vec<u32>> {
        let mut out: HashMap<u32, Vec<u32>> = HashMap::default();
        for (a, b) in self.edges() {
            out.entry(a).or_default().push(b);
            out.entry(b).or_default().push(a);
        }
        out
    }

    /// The faces that hold each edge.
    fn edge_faces(&self) -> HashMap<(u32, u32), Vec<usize>> {
        let mut out: HashMap<(u32, u32), Vec<usize>> = HashMap::default();
        for (f, face) in self.faces.iter().enumerate() {
            for c in 0..face.len() {
                out.entry(key(face[c], face[(c + 1) % face.len()]))
                    .or_default()
                    .push(f);
            }
        }
        out
    }

    /// The edge loop through edge a–b (Blender's Select Edge Loop), as its edges. Through a
    /// vertex of four edges, all inner, the loop goes on along the edge that shares no face
    /// with the one it came by; a loop of border edges goes on along the border through
    /// vertices with two border edges. It stops at any other vertex, or where it closes.
    pub fn edge_loop(&self, a: u32, b: u32) -> Result<Vec<(u32, u32)>, CageEditError> {
        let faces = self.edge_faces();
        let Some(first) = faces.get(&key(a, b)) else {
            return Err(CageEditError::NoEdge(a, b));
        };
        let border = first.len() == 1;
        let neighbours = self.neighbours();
        let count = |p: u32, q: u32| faces.get(&key(p, q)).map_or(0, Vec::len);
        let no_faces = Vec::new();
        let faces_of_edge = |p: u32, q: u32| faces.get(&key(p, q)).unwrap_or(&no_faces);
        // The edge after p→v: the one at v that carries the loop on, if v lets it.
        let next = |p: u32, v: u32| -> Option<u32> {
            let around = neighbours.get(&v)?;
            if border {
                let on_border: Vec<u32> = around
                    .iter()
                    .copied()
                    .filter(|&x| count(v, x) == 1)
                    .collect();
                return match on_border[..] {
                    [x, y] => Some(if x == p { y } else { x }),
                    _ => None,
                };
            }
            if around.len() != 4 || around.iter().any(|&x| count(v, x) != 2) {
                return None;
            }
            let came = faces_of_edge(p, v);
            around
                .iter()
                .copied()
                .find(|&x| x != p && faces_of_edge(v, x).iter().all(|f| !came.contains(f)))
        };
        let mut edges = vec![key(a, b)];
        let mut seen: HashSet<(u32, u32)> = HashSet::from_iter([key(a, b)]);
        for (mut p, mut v) in [(a, b), (b, a)] {
            while let Some(x) = next(p, v) {
                if !seen.insert(key(v, x)) {
                    break;
                }
                edges.push(key(v, x));
                (p, v) = (v, x);
            }
        }
        Ok(edges)
    }

    /// The edge ring through edge a–b (Blender's Select Edge Ring): the edges across from it in
    /// each quad, on and on.
    pub fn edge_ring_through(&self, a: u32, b: u32) -> Result<Vec<(u32, u32)>, CageEditError> {
        if !self.edge_faces().contains_key(&key(a, b)) {
            return Err(CageEditError::NoEdge(a, b));
        }
        Ok(self
            .edge_ring(a, b)
            .0
            .into_iter()
            .map(|(p, q)| key(p, q))
            .collect())
    }

    /// Select More (Blender's, with face steps): every vertex of a face that holds a selected
    /// vertex.
    pub fn grown(&self, selected: &BTreeSet<u32>) -> BTreeSet<u32> {
        let mut out = selected.clone();
        for face in &self.faces {
            if face.iter().any(|v| selected.contains(v)) {
                out.extend(face.iter().copied());
            }
        }
        out
    }

    /// Select Less (Blender's, with face steps): the selected vertices all of whose faces are
    /// wholly selected.
    pub fn shrunk(&self, selected: &BTreeSet<u32>) -> BTreeSet<u32> {
        let mut out = selected.clone();
        for face in &self.faces {
            if !face.iter().all(|v| selected.contains(v)) {
                for v in face {
                    out.remove(v);
                }
            }
        }
        out
    }

    /// Select Linked: every vertex joined to a selected one by a path of edges.
    pub fn linked(&self, selected: &BTreeSet<u32>) -> BTreeSet<u32> {
        let neighbours = self.neighbours();
        let mut out = selected.clone();
        let mut stack: Vec<u32> = selected.iter().copied().collect();
        while let Some(v) = stack.pop() {
            for &x in neighbours.get(&v).map_or(&[][..], Vec::as_slice) {
                if out.insert(x) {
                    stack.push(x);
                }
            }
        }
        out
    }

    /// The closed loops the edges make, each as its vertices in order (every vertex must have
    /// exactly two of the edges).
    pub fn closed_loops(&self, edges: &[(u32, u32)]) -> Result<Vec<Vec<u32>>, CageEditError> {
        let mut links: HashMap<u32, Vec<u32>> = HashMap::default();
        for &(a, b) in edges {
            links.entry(a).or_default().push(b);
            links.entry(b).or_default().push(a);
        }
        if let Some((v, l)) = links.iter().find(|(_, l)| l.len() != 2) {
            return Err(CageEditError::Invalid(format!(
                "the edges do not make closed loops: vertex {v} has {} of them",
                l.len()
            )));
        }
        let mut starts: Vec<u32> = links.keys().copied().collect();
        starts.sort_unstable();
        let mut done = HashSet::default();
        let mut loops = Vec::new();
        for start in starts {
            if done.contains(&start) {
                continue;
            }
            let mut lp = vec![start];
            done.insert(start);
            let mut prev = start;
            let mut at = links[&start][0];
            while at != start {
                lp.push(at);
                done.insert(at);
                let l = &links[&at];
                let nxt = if l[0] == prev { l[1] } else { l[0] };
                (prev, at) = (at, nxt);
            }
            loops.push(lp);
        }
        Ok(loops)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    /// A torus of n × m quads (vertex i·m + j).
    fn torus(n: u32, m: u32) -> Cage {
        let mut points = Vec::new();
        for i in 0..n {
            for j in 0..m {
                let (a, b) = (
                    std::f64::consts::TAU * f64::from(i) / f64::from(n),
                    std::f64::consts::TAU * f64::from(j) / f64::from(m),
                );
                let r = 2.0 + 0.6 * b.cos();
                points.push(DVec3::new(r * a.cos(), r * a.sin(), 0.6 * b.sin()));
            }
        }
        let faces = (0..n)
            .flat_map(|i| {
                (0..m).map(move |j| {
                    vec![
                        i * m + j,
                        ((i + 1) % n) * m + j,
                        ((i + 1) % n) * m + (j + 1) % m,
                        i * m + (j + 1) % m,
                    ]
                })
            })
            .collect();
        Cage {
            points,
            faces,
            ..Cage::default()
        }
    }

    #[test]
    fn loops_and_rings_on_a_torus_go_all_the_way_round() {
        let (n, m) = (7, 5);
        let cage = torus(n, m);
        // Round the small circle: m edges; round the big one: n.
        let small = cage.edge_loop(0, 1).unwrap();
        assert_eq!(small.len(), m as usize);
        assert!(small.iter().all(|&(a, b)| a / m == 0 && b / m == 0));
        let big = cage.edge_loop(0, m).unwrap();
        assert_eq!(big.len(), n as usize);
        assert!(big.iter().all(|&(a, b)| a % m == 0 && b % m == 0));
        // The ring across edge 0–1 is the n edges j = 0 → 1 of every i.
        let ring = cage.edge_ring_through(0, 1).unwrap();
        assert_eq!(ring.len(), n as usize);
        assert!(ring.iter().all(|&(a, b)| a % m == 0 && b % m == 1));
        // A loop is a closed loop; the loop's vertices grown once make a band three wide.
        let loops = cage.closed_loops(&small).unwrap();
        assert_eq!(loops.len(), 1);
        assert_eq!(loops[0].len(), m as usize);
        let selected: BTreeSet<u32> = loops[0].iter().copied().collect();
        let grown = cage.grown(&selected);
        assert_eq!(grown.len(), 3 * m as usize);
        assert_eq!(cage.shrunk(&grown), selected.iter().copied().collect());
        assert_eq!(cage.faces_within(&grown).len(), 2 * m as usize);
        assert_eq!(cage.edges_within(&selected).len(), m as usize);
        assert_eq!(cage.linked(&[3].into()).len(), (n * m) as usize);
        assert!(cage.edge_loop(0, 7).is_err());
        assert!(cage.closed_loops(&[(0, 1)]).is_err());
    }

    #[test]
    fn a_loop_stops_at_a_vertex_that_is_not_of_four_edges_and_follows_a_border() {
        // A 3 × 2 grid of quads: inner loops stop at the border; a border loop goes round.
        let points = (0..12)
            .map(|k| DVec3::new(f64::from(k % 4), f64::from(k / 4), 0.0))
            .collect();
        let faces = (0..2)
            .flat_map(|j| {
                (0..3).map(move |i| vec![j * 4 + i, j * 4 + i + 1, j * 4 + i + 5, j * 4 + i + 4])
            })
            .collect();
        let grid = Cage {
            points,
            faces,
            ..Cage::default()
        };
        // The inner row through 4–5–6–7: from border to border.
        assert_eq!(grid.edge_loop(5, 6).unwrap().len(), 3);
        // The border: all 10 edges.
        assert_eq!(grid.edge_loop(0, 1).unwrap().len(), 10);
    }
}
