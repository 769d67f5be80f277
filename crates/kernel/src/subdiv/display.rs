//! What a subdivision surface shows at a level as polygons over display points, each point a
//! position and two tangents given as rows over the level's vertices. The GPU evaluates the
//! same rows (composed onto the cage) for the schemes without a face-nested grid (Doo-Sabin,
//! √3); the f64 [`DisplayMesh`] applies them as the oracle and the export path.

use std::f64::consts::TAU;

use glam::DVec3;

use super::level::{Level, NONE};
use super::limit::{limit_position, limit_tangents, sharp_corner_tangents};
use super::pieces::{DEFAULT_TOLERANCE, Display};
use super::schemes::{directed_ends, ring_boundary_edges};
use super::stencil::Row;
use super::{Scheme, SubdivisionSurface};
use crate::GeometryError;

/// Display points as rows over one level's vertices, and the polygons over them.
#[derive(Debug, Clone, Default)]
pub struct DisplayRows {
    /// Per display point: position, and two tangents whose cross product is the outward
    /// normal.
    pub rows: Vec<[Row; 3]>,
    /// Counter-clockwise seen from the front.
    pub polygons: Vec<Vec<u32>>,
}

/// A level as shown: positions, unit normals and polygons.
#[derive(Debug, Clone, PartialEq)]
pub struct DisplayMesh {
    pub positions: Vec<DVec3>,
    pub normals: Vec<DVec3>,
    pub polygons: Vec<Vec<u32>>,
}

/// The display of `level` refined by `scheme`: for Doo-Sabin's limit the dual mesh
/// ([`doo_sabin_limit_rows`]); otherwise the level's own faces over its vertices, at their
/// limit positions ([`limit_position`]) or where refinement put them, with the limit tangents
/// ([`limit_tangents`]).
pub fn display_rows(level: &Level, scheme: Scheme, display: Display) -> DisplayRows {
    if scheme == Scheme::DooSabin && display != Display::Refined {
        return doo_sabin_limit_rows(level);
    }
    let vertex_rows = VertexRows::new(level, scheme, display);
    let rows = (0..level.vertex_count as u32)
        .map(|v| vertex_rows.rows(v))
        .collect();
    DisplayRows {
        rows,
        polygons: level.faces().map(<[u32]>::to_vec).collect(),
    }
}

/// Each vertex's display rows on one level: position (limit or refined) and the limit
/// tangents, with every limit row computed once (neighbouring vertices' tangents read the same
/// ones).
pub struct VertexRows<'a> {
    level: &'a Level,
    scheme: Scheme,
    display: Display,
    limit: Vec<crate::par::RaceCell<Row>>,
}

impl<'a> VertexRows<'a> {
    pub fn new(level: &'a Level, scheme: Scheme, display: Display) -> Self {
        Self {
            level,
            scheme,
            display,
            limit: (0..level.vertex_count)
                .map(|_| Default::default())
                .collect(),
        }
    }

    fn limit(&self, u: u32) -> Row {
        self.limit[u as usize]
            .get_or_init(|| limit_position(self.level, self.scheme, u))
            .clone()
    }

    /// Vertex `v`'s position ([`limit_position`] or where refinement put it) and two limit
    /// tangents ([`limit_tangents`]) whose cross product is the outward normal.
    pub fn rows(&self, v: u32) -> [Row; 3] {
        let position = match self.display {
            Display::Refined => Row(vec![(v, 1.0)]),
            _ => self.limit(v),
        };
        let [t1, t2] = limit_tangents(self.level, self.scheme, v, &|u| self.limit(u));
        [position, t1, t2]
    }

    /// [`Self::rows`] for the corner `v` of `face`: where `v` is sharp (a crease, a corner,
    /// the boundary) on the limit of Catmull-Clark, the tangents are that face's own
    /// ([`sharp_corner_tangents`]), so each side of a crease shows its own normal.
    pub fn rows_in_face(&self, v: u32, face: Option<u32>) -> [Row; 3] {
        let sharp = match (self.display, face) {
            (Display::Refined, _) | (_, None) => None,
            (_, Some(f)) => sharp_corner_tangents(self.level, self.scheme, v, f),
        };
        match sharp {
            Some([t1, t2]) => [self.limit(v), t1, t2],
            None => self.rows(v),
        }
    }
}

/// Doo-Sabin's limit surface sampled where it is known exactly: each face shrinks to its
/// centroid under the scheme (the face's new points are a circulant average of its own, which
/// keeps the centroid), with the tangent plane spanned by the first Fourier mode of its
/// corners Σ cos(2πi/n) vᵢ and Σ sin(2πi/n) vᵢ (the face's points evolve on their own, so this
/// eigenvector pair is the limit's tangent plane); on the boundary the midpoints of the
/// boundary edges, where the Chaikin limit (the quadratic B-spline of the boundary polygon)
/// passes, with the edge as tangent. The polygons are the dual of the level: one per vertex,
/// through its faces' centroids in ring order (and its boundary edges' midpoints).
pub fn doo_sabin_limit_rows(level: &Level) -> DisplayRows {
    let mut rows = Vec::with_capacity(level.face_count());
    for face in level.faces() {
        let n = face.len() as f64;
        let mut centroid = Row::default();
        centroid.add_centroid(face, 1.0);
        let mut t1 = Row::default();
        let mut t2 = Row::default();
        for (i, &v) in face.iter().enumerate() {
            let a = TAU * i as f64 / n;
            t1.add(v, a.cos());
            t2.add(v, a.sin());
        }
        rows.push([centroid, t1.merged(), t2.merged()]);
    }
    let mut midpoint = vec![NONE; level.edges.len()];
    for e in 0..level.edges.len() as u32 {
        if !level.is_boundary_edge(e) {
            continue;
        }
        let face = level.face(level.edge_faces[e as usize][0]);
        let [x, y] = directed_ends(level, e);
        let mid = Row(vec![(x, 0.5), (y, 0.5)]);
        let mut inward = Row::default();
        inward.add_centroid(face, 1.0);
        inward.add_row(&mid, -1.0);
        midpoint[e as usize] = rows.len() as u32;
        rows.push([mid, Row(vec![(y, 1.0), (x, -1.0)]), inward.merged()]);
    }
    let mut polygons = Vec::new();
    for v in 0..level.vertex_count as u32 {
        let ring = level.ring(v);
        if ring.faces.is_empty() {
            continue;
        }
        let mut polygon: Vec<u32> = ring.faces.clone();
        if ring.boundary {
            let Some([out, into]) = ring_boundary_edges(level, v, &ring) else {
                continue;
            };
            polygon.insert(0, midpoint[out as usize]);
            polygon.push(midpoint[into as usize]);
        }
        if polygon.len() >= 3 {
            polygons.push(polygon);
        }
    }
    DisplayRows { rows, polygons }
}

impl DisplayMesh {
    /// The mesh of `triangles` over the points `positions` (with `normals`, where given per
    /// point), keeping only the points the triangles use, in the order they first appear.
    pub fn from_triangles(positions: &[DVec3], normals: &[DVec3], triangles: &[[u32; 3]]) -> Self {
        let mut index = vec![NONE; positions.len()];
        let mut mesh = Self {
            positions: Vec::new(),
            normals: Vec::new(),
            polygons: Vec::with_capacity(triangles.len()),
        };
        for triangle in triangles {
            let mut polygon = Vec::with_capacity(3);
            for &v in triangle {
                let Some(slot) = index.get_mut(v as usize) else {
                    continue;
                };
                if *slot == NONE {
                    *slot = mesh.positions.len() as u32;
                    mesh.positions.push(positions[v as usize]);
                    if let Some(&n) = normals.get(v as usize) {
                        mesh.normals.push(n);
                    }
                }
                polygon.push(*slot);
            }
            if polygon.len() == 3 {
                mesh.polygons.push(polygon);
            }
        }
        mesh
    }
}

impl DisplayRows {
    /// The rows applied to the level's points `points` (f64).
    pub fn apply(&self, points: &[DVec3]) -> DisplayMesh {
        let (positions, normals) = self
            .rows
            .iter()
            .map(|[p, t1, t2]| {
                (
                    p.apply(points),
                    t1.apply(points).cross(t2.apply(points)).normalize_or_zero(),
                )
            })
            .unzip();
        DisplayMesh {
            positions,
            normals,
            polygons: self.polygons.clone(),
        }
    }
}

impl super::LimitMesh {
    /// The level's faces over the limit points (the refined points for
    /// [`Display::Refined`]), with the limit normals: Catmull-Clark's and Loop's display.
    pub fn into_display(self, display: Display) -> DisplayMesh {
        let polygons = self.level.faces().map(<[u32]>::to_vec).collect();
        let positions = match display {
            Display::Refined => self.refined,
            _ => self.positions,
        };
        DisplayMesh {
            positions,
            normals: self.normals,
            polygons,
        }
    }
}

impl SubdivisionSurface {
    /// The surface at level `levels` as `display` shows it, in f64: Catmull-Clark and Loop
    /// from [`Self::limit`] (its limit or refined points, with the limit normals); the
    /// other schemes from [`display_rows`] on the refined level; the adaptive display at the
    /// default tolerance ([`Self::adaptive_mesh`]).
    pub fn display_mesh(
        &self,
        levels: u32,
        display: Display,
    ) -> Result<DisplayMesh, GeometryError> {
        if display == Display::Adaptive {
            return self.adaptive_mesh(levels, DEFAULT_TOLERANCE);
        }
        let scheme = self.options.scheme;
        if matches!(scheme, Scheme::CatmullClark | Scheme::Loop) {
            return Ok(self.limit(levels)?.into_display(display));
        }
        let hierarchy = self.hierarchy(levels)?;
        let points = hierarchy.refine_points(self.points());
        let level = &hierarchy.levels[levels as usize];
        Ok(display_rows(level, scheme, display).apply(&points))
    }
}
