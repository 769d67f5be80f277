//! Export tessellation of a trimmed surface: a constrained Delaunay triangulation in (u, v)
//! (spade). The trim loops are flattened so that every boundary chord stays within a quarter of
//! the tolerance of the trim curve on the surface; the interior takes the points of the untrimmed
//! surface's tolerance grid ([`crate::tess::tolerance_grid`]) that lie in the kept
//! region away from the boundary; a triangle whose deviation from the surface exceeds the
//! tolerance gets a vertex at its worst interior edge's midpoint (or its centroid) until none
//! does. Every vertex is the surface at its
//! stored (u, v); triangles outside the kept region are dropped.

use glam::{DVec2, DVec3};
use spade::{ConstrainedDelaunayTriangulation, Point2, Triangulation};

use super::piece::distance_to_segment;
use super::{TrimmedSurface, domain_rect, flatten_loop_mapped};
use crate::tess::{self, MAX_TRIANGLES, Tessellation, TriangleMesh};
use crate::{GeometryError, NurbsSurface};

/// Rounds of centroid insertion before the triangulation is taken as it is.
const REFINE_ROUNDS: usize = 10;
/// The share of the tolerance the boundary chords keep to.
const BOUNDARY_SHARE: f64 = 0.25;
/// The least and most halvings of a trim piece flattened on the surface.
const SURFACE_DEPTHS: (usize, usize) = (2, 30);

fn failed(message: String) -> GeometryError {
    GeometryError::Construction {
        what: "trimmed tessellation",
        message,
    }
}

/// The loops flattened for the surface: each chord's midpoint on the surface within
/// `tolerance` of the chord in space (checked at t = 1/4, 1/2, 3/4 of every chord).
pub fn flatten_on_surface(
    trimmed: &TrimmedSurface,
    tolerance: f64,
) -> Result<Vec<Vec<DVec2>>, GeometryError> {
    let surface = trimmed.surface();
    let on_surface = |p: DVec2| {
        let p = clamp_to(surface, p);
        surface.point_at(p.x, p.y)
    };
    let mut out = Vec::new();
    for lp in trimmed.loops() {
        let (polygon, _) = flatten_loop_mapped(lp, tolerance, SURFACE_DEPTHS, on_surface)?;
        if polygon.len() > MAX_TRIANGLES {
            return Err(failed(
                "the trim loops need too many points at this tolerance".into(),
            ));
        }
        out.push(polygon);
    }
    Ok(out)
}

fn clamp_to(surface: &NurbsSurface, p: DVec2) -> DVec2 {
    let [(u0, u1), (v0, v1)] = surface.domain();
    DVec2::new(p.x.clamp(u0, u1), p.y.clamp(v0, v1))
}

/// Buckets the boundary chords for distance queries.
struct ChordGrid {
    origin: DVec2,
    cell: DVec2,
    side: usize,
    buckets: Vec<Vec<(DVec2, DVec2)>>,
}

impl ChordGrid {
    fn new(rect: [f64; 4], polygons: &[Vec<DVec2>]) -> Self {
        let count: usize = polygons.iter().map(Vec::len).sum();
        let side = ((count as f64).sqrt().ceil() as usize).clamp(1, 1024);
        let origin = DVec2::new(rect[0], rect[2]);
        let cell = DVec2::new(
            ((rect[1] - rect[0]) / side as f64).max(1e-300),
            ((rect[3] - rect[2]) / side as f64).max(1e-300),
        );
        let mut grid = Self {
            origin,
            cell,
            side,
            buckets: vec![Vec::new(); side * side],
        };
        for poly in polygons {
            for k in 0..poly.len() {
                let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
                let (i0, j0) = grid.cell_of(a.min(b));
                let (i1, j1) = grid.cell_of(a.max(b));
                for j in j0..=j1 {
                    for i in i0..=i1 {
                        grid.buckets[j * side + i].push((a, b));
                    }
                }
            }
        }
        grid
    }

    fn cell_of(&self, p: DVec2) -> (usize, usize) {
        let q = (p - self.origin) / self.cell;
        let max = (self.side - 1) as f64;
        (
            q.x.floor().clamp(0.0, max) as usize,
            q.y.floor().clamp(0.0, max) as usize,
        )
    }

    /// Whether some chord passes within `r` of p.
    fn near(&self, p: DVec2, r: f64) -> bool {
        let (i0, j0) = self.cell_of(p - DVec2::splat(r));
        let (i1, j1) = self.cell_of(p + DVec2::splat(r));
        (j0..=j1).any(|j| {
            (i0..=i1).any(|i| {
                self.buckets[j * self.side + i]
                    .iter()
                    .any(|&(a, b)| distance_to_segment(p, a, b) < r)
            })
        })
    }
}

/// The trimmed surface as a triangle mesh within `tessellation` (a tolerance, or segments per
/// span for the interior grid with the loops flattened to 1/1000 of the surface's size).
pub fn tessellate_trimmed(
    trimmed: &TrimmedSurface,
    tessellation: Tessellation,
    curvature: bool,
) -> Result<TriangleMesh, GeometryError> {
    let surface = trimmed.surface();
    let tolerance = match tessellation {
        Tessellation::Tolerance(t) => t,
        Tessellation::Segments(_) => 1e-3 * surface.size(),
    };
    if !(tolerance > 0.0 && tolerance.is_finite()) {
        return Err(failed(format!(
            "the tolerance must be finite and > 0, got {tolerance}"
        )));
    }
    let grid = tess::grid_for(surface, tessellation)?;
    // The boundary at a quarter of the tolerance: the area lost between the chords and the trim
    // curve grows with the perimeter, so a small trimmed face would otherwise lose a larger
    // share of its area than the interior's error.
    let polygons = flatten_on_surface(trimmed, BOUNDARY_SHARE * tolerance)?;
    let rect = domain_rect(surface);
    let chords = ChordGrid::new(rect, &polygons);

    let mut points: Vec<DVec2> = Vec::new();
    let mut edges: Vec<[usize; 2]> = Vec::new();
    for poly in &polygons {
        let base = points.len();
        let n = poly.len();
        points.extend_from_slice(poly);
        edges.extend((0..n).map(|k| [base + k, base + (k + 1) % n]));
    }
    for (i, &u) in grid.us.iter().enumerate() {
        for (j, &v) in grid.vs.iter().enumerate() {
            let hu = spacing(&grid.us, i);
            let hv = spacing(&grid.vs, j);
            let p = DVec2::new(u, v);
            if trimmed.contains(u, v) && !chords.near(p, 0.3 * hu.min(hv)) {
                points.push(p);
            }
        }
    }

    // Surface points of `points`, computed once each; triangles found within the tolerance.
    let mut positions: Vec<DVec3> = points
        .iter()
        .map(|p| surface.point_at(p.x, p.y))
        .collect::<Result<_, _>>()?;
    let mut checked: std::collections::HashSet<[u32; 3]> = std::collections::HashSet::new();
    // The boundary chords (flattened against the trim curve already, so not refined here).
    let chord_edges: std::collections::HashSet<[usize; 2]> =
        edges.iter().map(|&[a, b]| [a.min(b), a.max(b)]).collect();
    let mut rounds = 0;
    let mut cdt = build_cdt(&points, &edges)?;
    let (vertices, triangles) = loop {
        let (vertices, triangles) = kept_triangles(&cdt);
        if triangles.len() > MAX_TRIANGLES {
            return Err(failed(format!(
                "more than {MAX_TRIANGLES} triangles: choose a larger tolerance"
            )));
        }
        rounds += 1;
        if rounds > REFINE_ROUNDS {
            break (vertices, triangles);
        }
        // The triangulation keeps the input order unless points coincided.
        let same_order = vertices.len() == points.len();
        let vertex_positions: Vec<DVec3> = if same_order {
            positions.clone()
        } else {
            vertices
                .iter()
                .map(|p| surface.point_at(p.x, p.y))
                .collect::<Result<_, _>>()?
        };
        let mut added = Vec::new();
        let mut split_edges = std::collections::HashSet::new();
        for t in &triangles {
            let mut key = *t;
            key.sort_unstable();
            if same_order && checked.contains(&key) {
                continue;
            }
            let [a, b, c] = t.map(|k| k as usize);
            let centroid = (vertices[a] + vertices[b] + vertices[c]) / 3.0;
            let flat = (vertex_positions[a] + vertex_positions[b] + vertex_positions[c]) / 3.0;
            // The worst of the centroid and the interior edges' midpoints gets a vertex: an
            // edge's midpoint splits the edge (a centroid alone would leave a long edge as it
            // was).
            // A triangle on a boundary chord is judged by its other edges: the chord's own
            // sag is the flattening's (within the tolerance of the trim curve).
            let on_boundary = same_order
                && [(a, b), (b, c), (c, a)]
                    .iter()
                    .any(|&(x, y)| chord_edges.contains(&[x.min(y), x.max(y)]));
            let mut worst = if on_boundary {
                0.0
            } else {
                (surface.point_at(centroid.x, centroid.y)? - flat).length()
            };
            let mut split = centroid;
            let mut split_edge = None;
            for (x, y) in [(a, b), (b, c), (c, a)] {
                if same_order && chord_edges.contains(&[x.min(y), x.max(y)]) {
                    continue;
                }
                let m = 0.5 * (vertices[x] + vertices[y]);
                let on_surface = surface.point_at(m.x, m.y)?;
                let chord = 0.5 * (vertex_positions[x] + vertex_positions[y]);
                let deviation = (on_surface - chord).length();
                if deviation > worst {
                    worst = deviation;
                    split = m;
                    split_edge = Some([x.min(y), x.max(y)]);
                }
            }
            // A point that would land right by a boundary chord only makes slivers along it.
            let reach = [(a, b), (b, c), (c, a)]
                .iter()
                .map(|&(x, y)| vertices[x].distance(vertices[y]))
                .fold(0.0, f64::max);
            if worst > tolerance && !chords.near(split, 0.05 * reach) {
                if split_edge.is_none_or(|e| split_edges.insert(e)) {
                    added.push(split);
                }
            } else if same_order {
                checked.insert(key);
            }
        }
        if added.is_empty() {
            break (vertices, triangles);
        }
        // New points go into the triangulation one by one (no rebuild).
        for p in &added {
            positions.push(surface.point_at(p.x, p.y)?);
            cdt.insert(Point2::new(p.x, p.y))
                .map_err(|e| failed(format!("the triangulation failed: {e:?}")))?;
        }
        points.extend(added);
    };
    mesh_from(surface, &vertices, triangles, curvature)
}

/// The grid spacing around index i.
fn spacing(values: &[f64], i: usize) -> f64 {
    let before = if i > 0 {
        values[i] - values[i - 1]
    } else {
        f64::INFINITY
    };
    let after = if i + 1 < values.len() {
        values[i + 1] - values[i]
    } else {
        f64::INFINITY
    };
    let h = before.min(after);
    if h.is_finite() { h } else { 0.0 }
}

/// The vertices and the triangles of `cdt` inside the loops, counter-clockwise in (u, v). Inside-ness is found by a flood fill from the
/// outside that flips at every constraint edge (each loop's chords), so classifying every
/// triangle costs O(triangles) whatever the number of loops.
fn kept_triangles(cdt: &Cdt) -> (Vec<DVec2>, Vec<[u32; 3]>) {
    let vertices: Vec<DVec2> = cdt
        .vertices()
        .map(|v| {
            let p = v.position();
            DVec2::new(p.x, p.y)
        })
        .collect();
    // Parity per face (index of the face handle); the outer face is outside.
    let mut kept: Vec<Option<bool>> = vec![None; cdt.num_all_faces()];
    let mut queue = std::collections::VecDeque::new();
    for face in cdt.inner_faces() {
        for edge in face.adjacent_edges() {
            if edge.rev().face().is_outer() {
                kept[face.fix().index()] = Some(edge.is_constraint_edge());
                queue.push_back(face);
                break;
            }
        }
    }
    while let Some(face) = queue.pop_front() {
        let inside = kept[face.fix().index()].unwrap_or(false);
        for edge in face.adjacent_edges() {
            if let Some(next) = edge.rev().face().as_inner()
                && kept[next.fix().index()].is_none()
            {
                kept[next.fix().index()] = Some(inside != edge.is_constraint_edge());
                queue.push_back(next);
            }
        }
    }
    let mut triangles = Vec::new();
    for face in cdt.inner_faces() {
        if kept[face.fix().index()] != Some(true) {
            continue;
        }
        let [a, b, c] = face.vertices().map(|v| v.fix().index());
        let (pa, pb, pc) = (vertices[a], vertices[b], vertices[c]);
        let area = (pb - pa).perp_dot(pc - pa);
        if area == 0.0 {
            continue;
        }
        triangles.push(if area > 0.0 {
            [a as u32, b as u32, c as u32]
        } else {
            [a as u32, c as u32, b as u32]
        });
    }
    (vertices, triangles)
}

type Cdt = ConstrainedDelaunayTriangulation<Point2<f64>>;

/// The constrained Delaunay triangulation of `points` with `edges` fixed (bulk loaded; the
/// vertex order is kept unless points coincide).
fn build_cdt(points: &[DVec2], edges: &[[usize; 2]]) -> Result<Cdt, GeometryError> {
    let input = points.iter().map(|p| Point2::new(p.x, p.y)).collect();
    Cdt::try_bulk_load_cdt(input, edges.to_vec(), |_| {})
        .map_err(|e| failed(format!("the triangulation failed: {e:?}")))
}

/// Positions, normals, normalised (u, v) and curvatures at `vertices`; unused vertices dropped.
fn mesh_from(
    surface: &NurbsSurface,
    vertices: &[DVec2],
    triangles: Vec<[u32; 3]>,
    curvature: bool,
) -> Result<TriangleMesh, GeometryError> {
    let mut used = vec![u32::MAX; vertices.len()];
    let mut order = Vec::new();
    for t in &triangles {
        for &k in t {
            if used[k as usize] == u32::MAX {
                used[k as usize] = order.len() as u32;
                order.push(k as usize);
            }
        }
    }
    let [(u0, u1), (v0, v1)] = surface.domain();
    let mut mesh = TriangleMesh::default();
    for &k in &order {
        let p = vertices[k];
        let (u, v) = (p.x.clamp(u0, u1), p.y.clamp(v0, v1));
        if curvature {
            let local = surface.local_geometry(u, v)?;
            mesh.positions.push(local.derivatives.point);
            mesh.normals.push(local.normal);
            mesh.curvatures.push(local.curvature.values());
        } else {
            let d = surface.evaluate(u, v)?;
            mesh.normals.push(surface.normal_from(&d, u, v));
            mesh.positions.push(d.point);
        }
        mesh.uvs.push([(u - u0) / (u1 - u0), (v - v0) / (v1 - v0)]);
    }
    for t in triangles {
        let t = t.map(|k| used[k as usize]);
        let [a, b, c] = t.map(|k| mesh.positions[k as usize]);
        let (e1, e2) = (b - a, c - a);
        let scale = e1.length_squared().max(e2.length_squared());
        if e1.cross(e2).length() > 1e-12 * scale {
            mesh.triangles.push(t);
        }
    }
    Ok(mesh)
}
