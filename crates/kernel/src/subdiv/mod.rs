//! Subdivision surfaces with OpenSubdiv's semantics (Sdc): Catmull-Clark on any polygons, Loop
//! on triangles with Loop's original weights, semi-sharp creases (uniform or Chaikin),
//! corner vertices, and the `edge-only` / `edge-and-corner` boundary modes.
//!
//! The topology of each level ([`level::Level`]) is built once per topology change; each
//! refinement step yields stencils ([`stencil::Stencils`]) giving the child vertices from the
//! parent's, and the limit masks ([`limit`]) give positions, tangents and second derivatives on
//! the limit surface. The GPU applies the same tables ([`patches`]); this f64 path is its
//! oracle and the export path.

pub mod adaptive;
mod bevel_corner;
pub mod cage_bridge;
pub mod cage_corners;
pub mod cage_edit;
pub mod cage_faces;
pub mod cage_grid;
pub mod cage_knife;
pub mod cage_select;
pub mod cage_sweep;
pub mod cages;
pub mod display;
pub mod exchange;
pub mod level;
pub mod limit;
pub mod patches;
pub mod pieces;
pub mod refine;
pub mod region;
pub mod schemes;
pub mod stencil;
pub mod stencil_cache;
pub mod substitutes;
pub mod templates;

use glam::{DAffine3, DVec3};
use std::sync::Arc;

use self::level::{INFINITE_SHARPNESS, Level};
use self::stencil::Stencils;
use super::{CageProblem, GeometryError, Location, PolygonMesh, diffgeo};

/// The highest subdivision level a cage may ask for.
pub const MAX_LEVEL: u32 = 6;

/// The most faces a cage's level may have (the tables grow with them).
pub const MAX_REFINED_FACES: u64 = 4_000_000;

/// The most faces a Doo-Sabin or √3 level may have: they reach the GPU as one stencil patch
/// per face, and one compute dispatch evaluates at most 65,535 patches.
pub const MAX_POLYGON_FEED_FACES: u64 = 65_535;

/// The subdivision rules.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Scheme {
    /// Catmull-Clark, on any polygons.
    #[default]
    CatmullClark,
    /// Loop, on triangles.
    Loop,
    /// Doo-Sabin (dual corner cutting), on any polygons: biquadratic B-spline limit on
    /// regular regions.
    DooSabin,
    /// Kobbelt's √3, on triangles: each triangle split in three and the old edges flipped.
    Sqrt3,
    /// The modified butterfly, on triangles: interpolating (the cage's points stay on the
    /// surface).
    Butterfly,
}

impl Scheme {
    /// Whether the scheme takes triangles only.
    pub fn needs_triangles(self) -> bool {
        matches!(self, Self::Loop | Self::Sqrt3 | Self::Butterfly)
    }

    /// Whether the scheme applies the cage's creases and corners.
    pub fn has_creases(self) -> bool {
        matches!(self, Self::CatmullClark | Self::Loop)
    }

    /// Its name as the editor shows it.
    pub fn label(self) -> &'static str {
        match self {
            Self::CatmullClark => "Catmull-Clark",
            Self::Loop => "Loop",
            Self::DooSabin => "Doo-Sabin",
            Self::Sqrt3 => "√3 (Kobbelt)",
            Self::Butterfly => "modified butterfly",
        }
    }
}

/// How the boundary is treated (OpenSubdiv's `VtxBoundaryInterpolation`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Boundary {
    /// Boundary edges are infinitely sharp creases; corners are smoothed by the crease rule.
    #[default]
    EdgeOnly,
    /// As `EdgeOnly`, and boundary vertices with one face (valence 2) are sharp corners.
    EdgeAndCorner,
}

/// How semi-sharp creases lose sharpness from level to level.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Creasing {
    /// One less per level.
    #[default]
    Uniform,
    /// Chaikin's rule: 3/4 of the edge's own plus 1/4 of its semi-sharp neighbours', less 1.
    Chaikin,
}

/// The rules a cage is refined by.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Options {
    pub scheme: Scheme,
    pub boundary: Boundary,
    pub creasing: Creasing,
}

/// A sharp edge of a cage.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Crease {
    pub a: u32,
    pub b: u32,
    pub sharpness: f64,
}

/// A sharp vertex of a cage.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Corner {
    pub vertex: u32,
    pub sharpness: f64,
}

/// A subdivision surface: the cage (points and faces), its creases and corners, the rules and
/// the level shown.
#[derive(Debug, Clone, PartialEq)]
pub struct SubdivisionSurface {
    mesh: PolygonMesh,
    creases: Vec<Crease>,
    corners: Vec<Corner>,
    pub options: Options,
    level: u32,
    base: BaseLevelCache,
}

/// The base level [`SubdivisionSurface::new`] built while checking the cage, with the options
/// it was built under: a later feed reuses it while `options` (a public field) still match.
/// Equal and shown as nothing, being derived from the surface's other fields.
#[derive(Clone, Default)]
struct BaseLevelCache(Option<(Options, Arc<Level>)>);

impl PartialEq for BaseLevelCache {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl std::fmt::Debug for BaseLevelCache {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("BaseLevelCache")
    }
}

/// The levels of a refinement and the stencils between them: `stencils[k]` gives level k + 1
/// from level k.
#[derive(Debug, Clone)]
pub struct Hierarchy {
    pub levels: Vec<Level>,
    pub stencils: Vec<Stencils>,
    pub options: Options,
}

fn check_sharpness(at: Location, sharpness: f64) -> Result<(), GeometryError> {
    if sharpness.is_finite() && sharpness >= 0.0 {
        Ok(())
    } else {
        Err(GeometryError::Cage {
            at,
            problem: CageProblem::Sharpness { sharpness },
        })
    }
}

impl SubdivisionSurface {
    /// A subdivision surface over `mesh`; checks the cage (manifold, oriented, triangles for
    /// Loop), the creases (existing edges, sharpness finite and ≥ 0), the corners and the level.
    pub fn new(
        mesh: PolygonMesh,
        creases: Vec<Crease>,
        corners: Vec<Corner>,
        options: Options,
        level: u32,
    ) -> Result<Self, GeometryError> {
        let mut surface = Self {
            mesh,
            creases,
            corners,
            options,
            level,
            base: BaseLevelCache::default(),
        };
        let base = Arc::new(surface.base_level()?);
        surface.base = BaseLevelCache(Some((options, Arc::clone(&base))));
        let corners: u64 = surface.mesh.faces().map(|f| f.len() as u64).sum();
        let face_count = surface.mesh.face_count() as u64;
        let power = |base: u64| base.checked_pow(level.min(31)).unwrap_or(u64::MAX);
        let faces = match (level, options.scheme) {
            (0, _) => face_count,
            (_, Scheme::CatmullClark) => corners.saturating_mul(power(4) / 4),
            (_, Scheme::Loop | Scheme::Butterfly) => face_count.saturating_mul(power(4)),
            // One face per face, edge and vertex after the first step; then four per vertex.
            (_, Scheme::DooSabin) => {
                let used = (0..base.vertex_count as u32)
                    .filter(|&v| !base.vertex_faces(v).is_empty())
                    .count() as u64;
                (face_count + base.edges.len() as u64 + used).saturating_mul(power(4) / 4)
            }
            (_, Scheme::Sqrt3) => face_count.saturating_mul(power(3)),
        };
        // Doo-Sabin and √3 reach the GPU as one stencil patch per polygon, and one dispatch
        // evaluates at most 65,535 of them.
        let max = match options.scheme {
            Scheme::DooSabin | Scheme::Sqrt3 => MAX_POLYGON_FEED_FACES,
            _ => MAX_REFINED_FACES,
        };
        if level <= MAX_LEVEL && faces > max {
            return Err(GeometryError::Cage {
                at: Location::field("level"),
                problem: CageProblem::TooManyFaces { level, faces, max },
            });
        }
        if level > MAX_LEVEL {
            return Err(GeometryError::Cage {
                at: Location::field("level"),
                problem: CageProblem::Level {
                    level,
                    max: MAX_LEVEL,
                },
            });
        }
        Ok(surface)
    }

    /// A smooth Catmull-Clark surface over `mesh` at `level`.
    pub fn from_mesh(mesh: PolygonMesh, level: u32) -> Result<Self, GeometryError> {
        Self::new(mesh, Vec::new(), Vec::new(), Options::default(), level)
    }

    pub fn mesh(&self) -> &PolygonMesh {
        &self.mesh
    }

    pub fn points(&self) -> &[DVec3] {
        self.mesh.points()
    }

    pub fn creases(&self) -> &[Crease] {
        &self.creases
    }

    pub fn corners(&self) -> &[Corner] {
        &self.corners
    }

    pub fn level(&self) -> u32 {
        self.level
    }

    /// The same surface with other rules, level, creases or corners, checked as [`Self::new`].
    pub fn with(
        &self,
        options: Options,
        level: u32,
        creases: Vec<Crease>,
        corners: Vec<Corner>,
    ) -> Result<Self, GeometryError> {
        Self::new(self.mesh.clone(), creases, corners, options, level)
    }

    /// Moves cage point `index`.
    pub fn set_point(&mut self, index: usize, position: DVec3) -> Result<(), GeometryError> {
        self.mesh.set_point(index, position)
    }

    /// The surface mapped by `transform` (creases, corners and rules kept).
    pub fn transformed(&self, transform: &DAffine3) -> Result<Self, GeometryError> {
        Ok(Self {
            mesh: self.mesh.transformed(transform)?,
            ..self.clone()
        })
    }

    /// [`Self::base_level`], shared: the level built when the surface was made while its
    /// options are still those it was made with, else built anew.
    pub fn shared_base_level(&self) -> Result<Arc<Level>, GeometryError> {
        match &self.base.0 {
            Some((options, level)) if *options == self.options => Ok(Arc::clone(level)),
            _ => self.base_level().map(Arc::new),
        }
    }

    /// The cage's topology with its sharpness: user creases and corners, boundary edges
    /// infinitely sharp, and under [`Boundary::EdgeAndCorner`] boundary vertices with one face
    /// infinitely sharp corners (as OpenSubdiv's factory tags them).
    pub fn base_level(&self) -> Result<Level, GeometryError> {
        let faces: Vec<&[u32]> = self.mesh.faces().collect();
        let not_triangle = faces.iter().enumerate().find(|(_, f)| f.len() != 3);
        if let (true, Some((f, face))) = (self.options.scheme.needs_triangles(), not_triangle) {
            return Err(GeometryError::Cage {
                at: Location::face(f),
                problem: CageProblem::NotTriangle {
                    corners: face.len(),
                    scheme: self.options.scheme.label(),
                },
            });
        }
        let mut level = Level::new(self.mesh.points().len(), &faces, Vec::new())?;
        for (k, crease) in self.creases.iter().enumerate() {
            let at = Location::field("creases").index(k);
            check_sharpness(at.clone(), crease.sharpness)?;
            let e = level
                .edge_between(crease.a, crease.b)
                .ok_or(GeometryError::Cage {
                    at,
                    problem: CageProblem::NoSuchEdge {
                        a: crease.a,
                        b: crease.b,
                    },
                })?;
            level.edge_sharpness[e] = crease.sharpness;
        }
        for (k, corner) in self.corners.iter().enumerate() {
            let at = Location::field("corners").index(k);
            check_sharpness(at.clone(), corner.sharpness)?;
            let count = level.vertex_count;
            let slot = level
                .vertex_sharpness
                .get_mut(corner.vertex as usize)
                .ok_or(GeometryError::Cage {
                    at,
                    problem: CageProblem::NoSuchVertex {
                        vertex: corner.vertex,
                        count,
                    },
                })?;
            *slot = corner.sharpness;
        }
        for e in 0..level.edges.len() {
            if level.is_boundary_edge(e as u32) {
                level.edge_sharpness[e] = INFINITE_SHARPNESS;
            }
        }
        if self.options.boundary == Boundary::EdgeAndCorner {
            for v in 0..level.vertex_count as u32 {
                if level.vertex_faces(v).len() == 1 {
                    level.vertex_sharpness[v as usize] = INFINITE_SHARPNESS;
                }
            }
        }
        Ok(level)
    }

    /// The topology refined `levels` times, with the stencils between levels.
    pub fn hierarchy(&self, levels: u32) -> Result<Hierarchy, GeometryError> {
        Hierarchy::new(self.base_level()?, self.options, levels)
    }

    /// The cage refined `levels` times: the points and the level's topology.
    pub fn refined(&self, levels: u32) -> Result<(Vec<DVec3>, Level), GeometryError> {
        let mut hierarchy = self.hierarchy(levels)?;
        let points = hierarchy.refine_points(self.points());
        // The hierarchy holds levels 0..=levels.
        Ok((points, hierarchy.levels.swap_remove(levels as usize)))
    }

    /// The limit surface at the vertices of level `levels`: positions, unit normals and the
    /// level's topology.
    pub fn limit(&self, levels: u32) -> Result<LimitMesh, GeometryError> {
        let mut hierarchy = self.hierarchy(levels)?;
        hierarchy.ensure_quads()?;
        // The level's refined points, and those of the level the masks run on (one further
        // where Catmull-Clark needed quads).
        let refined = hierarchy.refine_points_to(self.points(), levels as usize);
        let points = match hierarchy.stencils.get(levels as usize) {
            Some(stencils) => stencils.apply(&refined),
            None => refined.clone(),
        };
        let last = hierarchy.levels.len() - 1;
        let level = &hierarchy.levels[last];
        let scheme = self.options.scheme;
        let count = hierarchy.levels[levels as usize].vertex_count;
        let position_rows: Vec<stencil::Row> = (0..level.vertex_count as u32)
            .map(|v| limit::limit_position(level, scheme, v))
            .collect();
        let positions: Vec<DVec3> = position_rows.iter().map(|r| r.apply(&points)).collect();
        let normal = |[t1, t2]: [stencil::Row; 2]| {
            t1.apply(&points)
                .cross(t2.apply(&points))
                .normalize_or_zero()
        };
        let normals = (0..count as u32)
            .map(|v| {
                // At a sharp point each quad has its own limit normal: one normal per point is
                // their mean, exact where they agree (a sector of up to four quads: the
                // boundary, a crease's one side).
                let sharp: Option<DVec3> = level
                    .vertex_faces(v)
                    .iter()
                    .map(|&f| limit::sharp_corner_tangents(level, scheme, v, f).map(normal))
                    .sum();
                match sharp {
                    Some(sum) if sum != DVec3::ZERO => sum.normalize_or_zero(),
                    _ => normal(limit::limit_tangents(level, scheme, v, &|u| {
                        position_rows[u as usize].clone()
                    })),
                }
            })
            .collect();
        Ok(LimitMesh {
            positions: positions[..count].to_vec(),
            normals,
            refined,
            level: hierarchy.levels.swap_remove(levels as usize),
        })
    }
}

/// The limit surface sampled at a level's vertices.
#[derive(Debug, Clone)]
pub struct LimitMesh {
    pub positions: Vec<DVec3>,
    pub normals: Vec<DVec3>,
    /// The level's points where refinement put them.
    pub refined: Vec<DVec3>,
    pub level: Level,
}

impl LimitMesh {
    /// The exact curvature of the limit at each vertex of the level where the limit there is
    /// one polynomial piece: under Catmull-Clark a regular point ([`limit::regular_weights`] on
    /// its 3 × 3 neighbourhood) and a point on the boundary or at a sharp corner whose faces
    /// all lie in one sector between infinitely sharp edges ([`limit::sided_weights`]); under
    /// Loop a regular point (the box spline, [`limit::loop_regular_weights`]) and a point on
    /// the boundary whose three triangles follow the crease rule
    /// ([`limit::loop_sided_weights`]) or a corner of one triangle that follows the corner
    /// rule ([`limit::loop_corner_weights`], a flat point). `None` elsewhere: extraordinary
    /// points, either side of a crease (a point shared by two sides has two curvatures),
    /// semi-sharp features, other corners and the other schemes. K
    /// and H are taken about the normal Su × Sv of the counter-clockwise faces, as
    /// [`Self::normals`].
    pub fn curvatures(&self, scheme: Scheme) -> Vec<Option<diffgeo::CurvatureValues>> {
        let level = &self.level;
        let points = &self.refined;
        let values = |weights: &mut dyn Iterator<Item = (u32, [f64; 6])>| {
            diffgeo::SurfaceDerivatives::from_weights(points, weights)?.curvature_values()
        };
        let same = |a: &diffgeo::CurvatureValues, b: &diffgeo::CurvatureValues| {
            let scale = a.k1.abs().max(a.k2.abs()).max(f64::MIN_POSITIVE);
            (a.mean - b.mean).abs() <= 1e-9 * scale
                && (a.gaussian - b.gaussian).abs() <= 1e-9 * scale * scale
        };
        crate::par::map(self.positions.len(), |v| {
            let v = v as u32;
            if scheme == Scheme::Loop {
                let towards = *level.ring(v).neighbours.first()?;
                if let Some(weights) = limit::loop_regular_weights(level, v, towards, 0, 1.0) {
                    return values(&mut weights.into_iter());
                }
            } else if scheme != Scheme::CatmullClark {
                return None;
            } else if limit::is_regular(level, scheme, v) {
                let (neighbours, _) = level.four_ring(v)?;
                let grid = limit::regular_grid(level, v, neighbours[0], false)?;
                let weights = limit::regular_weights(1.0);
                return values(&mut grid.iter().zip(weights).map(|(&p, w)| (p, w)));
            }
            // One value from every face's side, or none where the sides differ.
            let mut found: Option<diffgeo::CurvatureValues> = None;
            for &f in level.vertex_faces(v) {
                let face = level.face(f);
                let at = face.iter().position(|&x| x == v)?;
                let towards = face[(at + 1) % face.len()];
                let weights = match scheme {
                    Scheme::Loop => limit::loop_sided_weights(level, v, towards, 0, f, 1.0)
                        .or_else(|| limit::loop_corner_weights(level, v, towards, 0, 1.0)),
                    _ => limit::sided_weights(level, v, towards, false, f, 1.0),
                }?;
                let c = values(&mut weights.into_iter())?;
                match &found {
                    Some(first) if !same(first, &c) => return None,
                    Some(_) => {}
                    None => found = Some(c),
                }
            }
            found
        })
    }
}

impl Hierarchy {
    /// `base` refined `levels` times by `options`.
    pub fn new(base: Level, options: Options, levels: u32) -> Result<Self, GeometryError> {
        if levels > MAX_LEVEL {
            return Err(GeometryError::Cage {
                at: Location::field("level"),
                problem: CageProblem::Level {
                    level: levels,
                    max: MAX_LEVEL,
                },
            });
        }
        let mut hierarchy = Self {
            levels: vec![base],
            stencils: Vec::new(),
            options,
        };
        for _ in 0..levels {
            hierarchy.refine_once()?;
        }
        Ok(hierarchy)
    }

    /// `base` refined `levels` times by `options`, past [`MAX_LEVEL`] (for exchange, where a
    /// small cage is refined further than it is drawn), while the finest level has at most
    /// `max_faces` faces.
    pub(crate) fn deep(
        base: Level,
        options: Options,
        levels: u32,
        max_faces: usize,
    ) -> Result<Self, GeometryError> {
        let mut hierarchy = Self {
            levels: vec![base],
            stencils: Vec::new(),
            options,
        };
        for level in 1..=levels {
            let faces = hierarchy.levels[hierarchy.levels.len() - 1].face_count();
            if faces.saturating_mul(4) > max_faces {
                return Err(GeometryError::Cage {
                    at: Location::field("level"),
                    problem: CageProblem::TooManyFaces {
                        level,
                        faces: faces.saturating_mul(4) as u64,
                        max: max_faces as u64,
                    },
                });
            }
            hierarchy.refine_once()?;
        }
        Ok(hierarchy)
    }

    fn refine_once(&mut self) -> Result<(), GeometryError> {
        let last = self.levels.len() - 1;
        let (child, stencils) = refine::refine(&self.levels[last], &self.options, last)?;
        self.levels.push(child);
        self.stencils.push(stencils);
        Ok(())
    }

    /// Catmull-Clark's limit masks take quads: a level with other faces is refined once more
    /// (its vertices keep their numbers and their limit points).
    pub fn ensure_quads(&mut self) -> Result<(), GeometryError> {
        let last = &self.levels[self.levels.len() - 1];
        if self.options.scheme == Scheme::CatmullClark && last.faces().any(|f| f.len() != 4) {
            self.refine_once()?;
        }
        Ok(())
    }

    /// The cage points `cage` carried through every level: the last level's points.
    pub fn refine_points(&self, cage: &[DVec3]) -> Vec<DVec3> {
        self.refine_points_to(cage, self.stencils.len())
    }

    /// The cage points `cage` carried to level `level` (at most the last).
    pub fn refine_points_to(&self, cage: &[DVec3], level: usize) -> Vec<DVec3> {
        let mut points = cage.to_vec();
        for stencils in self.stencils.iter().take(level) {
            points = stencils.apply(&points);
        }
        points
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The base level kept from `new` is the one `base_level` builds, and options changed
    /// after `new` (a public field) are not answered from it.
    #[test]
    fn the_kept_base_level_follows_the_options() {
        let sheet = cages::grid(DVec3::new(0.3, -1.0, 2.0), 2.0, 3).unwrap();
        let mut surface = SubdivisionSurface::from_mesh(sheet, 2).unwrap();
        let kept = surface.shared_base_level().unwrap();
        assert_eq!(*kept, surface.base_level().unwrap());
        assert!(kept.vertex_sharpness.iter().all(|&s| s == 0.0));
        surface.options.boundary = Boundary::EdgeAndCorner;
        let cornered = surface.shared_base_level().unwrap();
        assert_eq!(*cornered, surface.base_level().unwrap());
        let corners = cornered.vertex_sharpness.iter();
        assert_eq!(corners.filter(|&&s| s == INFINITE_SHARPNESS).count(), 4);
        surface.options.scheme = Scheme::Loop;
        assert!(surface.shared_base_level().is_err());
    }
}
