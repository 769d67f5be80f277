//! Polysurfaces as a scene object kind: trimmed NURBS faces joined along shared edges
//! ([`crate::kernel::join`]). The GPU sees every face's Bézier patches in one feed, each patch
//! with its own face's trim grid; the export is one mesh, watertight across the shared edges.
//! The shared and naked edges are worked out from the faces when asked (so an edit that opens
//! a shared edge shows it as naked), at the tolerance the faces were joined with.

use std::sync::Arc;

use crate::kernel::par::RaceCell;

use glam::{DAffine3, DVec3};
use serde::{Deserialize, Serialize};

use super::json::FormatError;
use super::kind::{KindFace, points_box};
use super::record::{KindEntry, deserialize, to_record};
use super::{Decomposition, ObjectGeometry, ObjectKind, SceneObject, TrimFeed};
use crate::kernel::bezier::{BezierPatch, BezierPatchSet};
use crate::kernel::join::{Topology, edge_polyline, find_topology, tessellate_joined};
use crate::kernel::tess::{Estimate, Tessellation, TriangleMesh};
use crate::kernel::trim::index::Coverage;
use crate::kernel::{GeometryError, TrimmedSurface};

/// The most faces one polysurface may have.
pub const MAX_FACES: usize = 10_000;

/// Trimmed NURBS faces joined along shared edges.
#[derive(Clone)]
pub struct Polysurface {
    faces: Vec<TrimmedSurface>,
    /// The join tolerance (model units).
    tolerance: f64,
    topology: Arc<RaceCell<Result<Topology, GeometryError>>>,
    /// The naked edges drawn (at 1/500 of the size), worked out once per shape.
    naked: Arc<RaceCell<Arc<Vec<Vec<DVec3>>>>>,
}

impl PartialEq for Polysurface {
    fn eq(&self, other: &Self) -> bool {
        self.faces == other.faces && self.tolerance == other.tolerance
    }
}

impl std::fmt::Debug for Polysurface {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.debug_struct("Polysurface")
            .field("faces", &self.faces.len())
            .field("tolerance", &self.tolerance)
            .finish()
    }
}

fn refuse(message: impl Into<String>) -> GeometryError {
    GeometryError::Construction {
        what: "polysurface",
        message: message.into(),
    }
}

impl Polysurface {
    /// `faces` joined at `tolerance` (model units, > 0); at least one face.
    pub fn new(faces: Vec<TrimmedSurface>, tolerance: f64) -> Result<Self, GeometryError> {
        if faces.is_empty() || faces.len() > MAX_FACES {
            return Err(refuse(format!(
                "a polysurface has 1 to {MAX_FACES} faces, not {}",
                faces.len()
            )));
        }
        if !(tolerance.is_finite() && tolerance > 0.0) {
            return Err(refuse(format!(
                "the join tolerance must be a number above 0 (got {tolerance})"
            )));
        }
        Ok(Self {
            faces,
            tolerance,
            topology: Arc::default(),
            naked: Arc::default(),
        })
    }

    /// `faces` joined at `tolerance` whose shared, naked and degenerate edges are already
    /// known (a STEP file's topology); an edit works them out again from the faces.
    pub fn with_topology(
        faces: Vec<TrimmedSurface>,
        tolerance: f64,
        topology: Topology,
    ) -> Result<Self, GeometryError> {
        let out = Self::new(faces, tolerance)?;
        let _ = out.topology.set(Ok(topology));
        Ok(out)
    }

    pub fn faces(&self) -> &[TrimmedSurface] {
        &self.faces
    }

    pub fn tolerance(&self) -> f64 {
        self.tolerance
    }

    /// The shared, naked and degenerate edges (worked out once per shape).
    pub fn topology(&self) -> Result<&Topology, GeometryError> {
        self.topology
            .get_or_init(|| find_topology(&self.faces, self.tolerance))
            .as_ref()
            .map_err(Clone::clone)
    }

    /// The naked edges as polylines within 1/500 of the polysurface's size of them (what the
    /// viewport draws).
    pub fn naked_edges(&self) -> Arc<Vec<Vec<DVec3>>> {
        self.naked
            .get_or_init(|| {
                let Ok(topology) = self.topology() else {
                    return Arc::default();
                };
                let size = self.bounds().map_or(1.0, |(lo, hi)| lo.distance(hi));
                let chord = (size / 500.0).max(self.tolerance);
                Arc::new(
                    topology
                        .naked
                        .iter()
                        .filter_map(|&id| edge_polyline(&self.faces, id, chord).ok())
                        .collect(),
                )
            })
            .clone()
    }

    /// Face `f` and the index within it of the polysurface's control point `index`.
    fn locate(&self, index: usize) -> Option<(usize, usize)> {
        let mut rest = index;
        for (f, face) in self.faces.iter().enumerate() {
            let n = face.surface().control_point_count();
            if rest < n {
                return Some((f, rest));
            }
            rest -= n;
        }
        None
    }

    /// The first feed patch of each face, and the total.
    fn patch_offsets(&self) -> Vec<usize> {
        let mut out = Vec::with_capacity(self.faces.len() + 1);
        let mut total = 0;
        for face in &self.faces {
            out.push(total);
            let [bu, bv] = [
                face.surface().span_breaks(crate::kernel::Direction::U),
                face.surface().span_breaks(crate::kernel::Direction::V),
            ];
            total += (bu.len().saturating_sub(1)) * (bv.len().saturating_sub(1));
        }
        out.push(total);
        out
    }

    fn with_faces(&self, faces: Vec<TrimmedSurface>) -> Result<Self, GeometryError> {
        Self::new(faces, self.tolerance)
    }

    fn changed(&mut self) {
        self.topology = Arc::default();
        self.naked = Arc::default();
    }
}

/// The largest singular value of `m` (how far it stretches a unit vector at most): the square
/// root of MᵀM's largest eigenvalue, by power iteration.
fn largest_singular_value(m: glam::DMat3) -> f64 {
    let mtm = m.transpose() * m;
    let mut v = DVec3::new(0.577, 0.578, 0.576);
    let mut value = 0.0;
    for _ in 0..64 {
        let w = mtm * v;
        let length = w.length();
        if !(length > 0.0) {
            return 0.0;
        }
        value = length;
        v = w / length;
    }
    value.sqrt()
}

impl ObjectGeometry {
    /// The object as faces joined along shared edges (what join makes and explode takes
    /// apart; its naked edges are where it is open), or `None`.
    pub fn as_polysurface(&self) -> Option<&Polysurface> {
        self.downcast_ref()
    }
}

/// An object's faces as one body: what its mass properties are measured on.
pub struct Body {
    pub faces: Vec<TrimmedSurface>,
    /// Their naked, non-manifold and misoriented edges and the orientation that makes them
    /// agree ([`crate::kernel::join::validity`]), where the edges could be worked out.
    pub validity: Option<crate::kernel::join::Validity>,
    /// The shared and naked edges the validity was found from.
    pub topology: Option<Topology>,
}

impl Body {
    /// Whether the faces close it (no naked edge).
    pub fn closed(&self) -> bool {
        self.validity.as_ref().is_some_and(|v| v.naked.is_empty())
    }

    /// The area, and for a closed body the mass properties ([`crate::kernel::mass`]).
    pub fn measure(
        &self,
    ) -> Result<(f64, Option<crate::kernel::mass::MassProperties>), GeometryError> {
        match (&self.validity, &self.topology) {
            (Some(v), Some(topology)) if v.naked.is_empty() => {
                // Each shell outward, a void's volume taken away.
                let m = crate::kernel::mass::solid_mass_properties(&self.faces, topology)?;
                Ok((m.area, Some(m)))
            }
            _ => Ok((crate::kernel::mass::area(&self.faces)?, None)),
        }
    }
}

impl SceneObject {
    /// The object's faces as one body: a polysurface's faces with the topology of its join
    /// tolerance, or a NURBS surface's face alone (a sphere, a torus) at 1e-6 of its size;
    /// `None` for a kind without trimmed NURBS faces.
    pub fn body(&self) -> Option<Body> {
        let (faces, topology) = match self.geometry.as_polysurface() {
            Some(p) => (p.faces().to_vec(), p.topology().ok().cloned()),
            None => {
                let face = self.geometry.as_trimmed()?;
                let tolerance = 1e-6 * face.surface().size();
                let topology = find_topology(std::slice::from_ref(&face), tolerance).ok();
                (vec![face], topology)
            }
        };
        let validity = topology
            .as_ref()
            .map(|t| crate::kernel::join::validity(faces.len(), t));
        Some(Body {
            faces,
            validity,
            topology,
        })
    }
}

impl ObjectKind for Polysurface {
    fn kind_name(&self) -> &'static str {
        "a polysurface"
    }

    fn describe(&self) -> String {
        let n = self.faces.len();
        match self.topology() {
            Ok(t) => format!(
                "{n} face{}, {} shared edge{}, {} naked",
                if n == 1 { "" } else { "s" },
                t.shared.len(),
                if t.shared.len() == 1 { "" } else { "s" },
                t.naked.len()
            ),
            Err(e) => format!("{n} faces ({e})"),
        }
    }

    fn control_point_count(&self) -> usize {
        self.faces
            .iter()
            .map(|f| f.surface().control_point_count())
            .sum()
    }

    fn control_points(&self) -> Vec<DVec3> {
        self.faces
            .iter()
            .flat_map(|f| f.surface().control_points())
            .collect()
    }

    fn weights(&self) -> Vec<f64> {
        self.faces
            .iter()
            .flat_map(|f| ObjectKind::weights(f.surface()))
            .collect()
    }

    fn net_lines(&self) -> Vec<u32> {
        let mut out = Vec::new();
        let mut offset = 0u32;
        for face in &self.faces {
            out.extend(face.surface().net_lines().into_iter().map(|k| k + offset));
            offset += face.surface().control_point_count() as u32;
        }
        out
    }

    fn bounds(&self) -> Option<(DVec3, DVec3)> {
        points_box(
            self.faces
                .iter()
                .filter_map(|f| ObjectKind::bounds(f.surface()))
                .flat_map(|(lo, hi)| [lo, hi]),
        )
    }

    fn move_control_point(
        &mut self,
        index: usize,
        position: DVec3,
    ) -> Result<Vec<usize>, GeometryError> {
        let (f, local) = self.locate(index).ok_or(GeometryError::NoSuchPoint {
            index,
            count: self.control_point_count(),
        })?;
        let offset = self.patch_offsets()[f];
        let patches = self.faces[f]
            .surface_mut()
            .move_control_point(local, position)?;
        self.changed();
        Ok(patches.into_iter().map(|p| p + offset).collect())
    }

    fn set_weight(&mut self, index: usize, weight: f64) -> Result<(), GeometryError> {
        let (f, local) = self.locate(index).ok_or(GeometryError::NoSuchPoint {
            index,
            count: self.control_point_count(),
        })?;
        ObjectKind::set_weight(self.faces[f].surface_mut(), local, weight)?;
        self.changed();
        Ok(())
    }

    /// Every face's Bézier patches over one pool, each trimmed patch with its face's grid. The
    /// faces' feeds (their trims' grids the most of it, on a model's first upload) are built on
    /// every core, then laid end to end in face order: the same pool on any number of threads.
    fn gpu_feed(&self) -> Result<Decomposition, GeometryError> {
        let feeds =
            crate::kernel::par::map(self.faces.len(), |f| ObjectKind::gpu_feed(&self.faces[f]));
        let mut points = Vec::new();
        let mut weights = Vec::new();
        let mut patches = Vec::new();
        let mut domains = Vec::new();
        let mut indices = Vec::new();
        let mut coverage = Vec::new();
        let mut patch_index = Vec::new();
        for feed in feeds {
            let feed = feed?;
            let base = points.len() as u32;
            points.extend_from_slice(feed.set.points());
            weights.extend_from_slice(feed.set.weights());
            for patch in feed.set.patches() {
                patches.push(BezierPatch::new(
                    patch.degree_u(),
                    patch.degree_v(),
                    patch.indices().iter().map(|&k| k + base).collect(),
                ));
            }
            let n = feed.domains.len();
            domains.extend(feed.domains);
            match feed.trims {
                Some(trims) => {
                    let slot = indices.len() as u32;
                    indices.extend(trims.indices);
                    coverage.extend(trims.coverage);
                    patch_index.extend(trims.patch_index.iter().map(|&k| k + slot));
                }
                None => {
                    coverage.extend(std::iter::repeat_n(Coverage::Inside, n));
                    patch_index.extend(std::iter::repeat_n(0, n));
                }
            }
        }
        let trims = (!indices.is_empty()).then_some(TrimFeed {
            indices,
            coverage,
            patch_index,
        });
        Ok(Decomposition {
            set: BezierPatchSet::new(points, Some(weights), patches)?,
            domains,
            trims,
            ..Default::default()
        })
    }

    fn surface_point(&self, patch: usize, s: f64, t: f64) -> Result<DVec3, GeometryError> {
        let offsets = self.patch_offsets();
        let f = offsets
            .windows(2)
            .position(|w| (w[0]..w[1]).contains(&patch))
            .ok_or(GeometryError::NoSuchPatch {
                patch,
                count: offsets.last().copied().unwrap_or(0),
            })?;
        self.faces[f]
            .surface()
            .surface_point(patch - offsets[f], s, t)
    }

    /// The whole feed again (the faces' layouts are unchanged by a move).
    fn update_gpu_feed(
        &self,
        feed: &mut Decomposition,
        _patches: &[usize],
    ) -> Result<(), GeometryError> {
        *feed = self.gpu_feed()?;
        Ok(())
    }

    /// One mesh, watertight across the shared edges ([`tessellate_joined`]); by segments, at
    /// a tolerance of 1/(200 · segments) of the polysurface's size.
    fn tessellate(
        &self,
        tessellation: Tessellation,
        curvature: bool,
    ) -> Result<Vec<TriangleMesh>, GeometryError> {
        let tolerance = match tessellation {
            Tessellation::Tolerance(t) => t,
            Tessellation::Segments(n) => {
                let size = self.bounds().map_or(1.0, |(lo, hi)| lo.distance(hi));
                size / (200.0 * f64::from(n.max(1)))
            }
        };
        let topology = self.topology()?;
        Ok(vec![tessellate_joined(
            &self.faces,
            topology,
            tolerance,
            curvature,
        )?])
    }

    /// The faces' own estimates, summed.
    fn estimated_triangles(
        &self,
        tessellation: Tessellation,
        how: Estimate,
    ) -> Result<usize, GeometryError> {
        self.faces
            .iter()
            .map(|f| f.estimated_triangles(tessellation, how))
            .sum()
    }

    fn faces(&self) -> Vec<KindFace<'_>> {
        self.faces
            .iter()
            .enumerate()
            .map(|(k, f)| KindFace {
                patch: Some(k),
                surface: Box::new(f),
                triangle: false,
            })
            .collect()
    }

    fn transformed(&self, transform: &DAffine3) -> Result<ObjectGeometry, GeometryError> {
        let faces = self
            .faces
            .iter()
            .map(|f| f.with_surface(f.surface().transformed(transform)?))
            .collect::<Result<_, _>>()?;
        // An affine map keeps which edges coincide: the shared edges carry over (their gaps
        // stretched by at most the map's largest singular value), not worked out again.
        let moved = match self.topology.get() {
            Some(Ok(topology)) => {
                let stretch = largest_singular_value(transform.matrix3);
                let mut topology = topology.clone();
                for s in &mut topology.shared {
                    s.gap *= stretch;
                }
                Self::with_topology(faces, self.tolerance, topology)?
            }
            _ => self.with_faces(faces)?,
        };
        Ok(ObjectGeometry::new(moved))
    }

    fn bake_lattice(
        &self,
        lattice: &crate::kernel::ffd::Lattice,
        tolerance: f64,
    ) -> Result<(ObjectGeometry, crate::kernel::ffd::Baked), GeometryError> {
        let mut faces = Vec::with_capacity(self.faces.len());
        let mut worst: Option<crate::kernel::ffd::Baked> = None;
        for face in &self.faces {
            let (surface, baked) = super::ffd::bake_nurbs(face.surface(), lattice, tolerance)?;
            faces.push(face.with_surface(surface)?);
            // The face furthest from exact speaks for the whole.
            let error = |b: &crate::kernel::ffd::Baked| match b {
                crate::kernel::ffd::Baked::Exact { .. } => -1.0,
                crate::kernel::ffd::Baked::Refit { error, .. } => *error,
                _ => f64::INFINITY,
            };
            worst = Some(match worst {
                Some(w) if error(&w) >= error(&baked) => w,
                _ => baked,
            });
        }
        let baked = worst.ok_or_else(|| refuse("no faces to bake"))?;
        Ok((ObjectGeometry::new(self.with_faces(faces)?), baked))
    }

    fn same_layout(&self, other: &ObjectGeometry) -> bool {
        other.downcast_ref::<Polysurface>().is_some_and(|b| {
            self.faces.len() == b.faces.len()
                && self.faces.iter().zip(&b.faces).all(|(x, y)| {
                    super::nurbs::same_net(x.surface(), y.surface()) && x.loops() == y.loops()
                })
        })
    }

    fn displacement_domain(&self) -> Option<[f64; 4]> {
        None
    }

    fn nurbs_surface(&self) -> Option<&crate::kernel::NurbsSurface> {
        None
    }

    fn cage(&self) -> Option<&crate::kernel::PolygonMesh> {
        None
    }

    fn exchange_faces(
        &self,
        _tolerance: f64,
    ) -> Option<Result<super::ExchangeFaces, GeometryError>> {
        Some(Ok(super::ExchangeFaces {
            faces: self.faces().to_vec(),
            topology: self.topology().ok().cloned(),
            note: None,
        }))
    }

    fn record(&self) -> serde_json::Value {
        let faces = self
            .faces
            .iter()
            .map(|f| super::nurbs::surface_record(super::json::Geometry::TrimmedSurface(f.clone())))
            .collect();
        to_record(&PolysurfaceRecord {
            kind: "polysurface".into(),
            tolerance: self.tolerance,
            faces,
        })
    }
}

/// A polysurface's record: its join tolerance and faces (each a `nurbs_surface` record).
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct PolysurfaceRecord {
    #[serde(rename = "type")]
    kind: String,
    tolerance: f64,
    faces: Vec<serde_json::Value>,
}

fn read_record(path: &str, record: serde_json::Value) -> Result<ObjectGeometry, FormatError> {
    let r: PolysurfaceRecord = deserialize(path, record)?;
    let mut faces = Vec::with_capacity(r.faces.len());
    for (k, face) in r.faces.into_iter().enumerate() {
        let at = format!("{path}.faces[{k}]");
        let geometry = (super::nurbs::ENTRY.read)(&at, face)?;
        let trimmed = geometry.as_trimmed().ok_or_else(|| {
            FormatError::new(at.clone(), "a polysurface's face must be a NURBS surface")
        })?;
        faces.push(trimmed);
    }
    Polysurface::new(faces, r.tolerance)
        .map(ObjectGeometry::new)
        .map_err(|e| FormatError::new(path.to_string(), e.to_string()))
}

/// A box of six planes (closed), and a cylinder with one cap (open at the top).
fn examples() -> Vec<SceneObject> {
    use crate::kernel::construct;
    let plane =
        |o: DVec3, u: DVec3, v: DVec3| construct::plane(o, u, v).map(TrimmedSurface::untrimmed);
    let (x, y, z) = (DVec3::X * 2.0, DVec3::Y, DVec3::Z * 1.5);
    let faces: Result<Vec<_>, _> = [
        plane(DVec3::ZERO, y, x),
        plane(z, x, y),
        plane(DVec3::ZERO, x, z),
        plane(y, z, x),
        plane(DVec3::ZERO, z, y),
        plane(x, y, z),
    ]
    .into_iter()
    .collect();
    let mut out = Vec::new();
    if let Ok(b) = faces.and_then(|f| Polysurface::new(f, 1e-9)) {
        let mut object = SceneObject::new("box", ObjectGeometry::new(b));
        object.segments = 2;
        out.push(object);
    }
    let cup = construct::cylinder(DVec3::ZERO, DVec3::Z, 0.8).and_then(|side| {
        let circle = construct::circle(DVec3::ZERO, DVec3::Z, DVec3::X, 0.8)?;
        let cap = crate::kernel::planar::planar_face(&[circle])?;
        Polysurface::new(vec![TrimmedSurface::untrimmed(side), cap], 1e-7)
    });
    if let Ok(cup) = cup {
        let mut object = SceneObject::new("cup", ObjectGeometry::new(cup));
        object.segments = 4;
        out.push(object);
    }
    out
}

/// Polysurfaces: joined trimmed NURBS faces.
pub(super) const ENTRY: KindEntry = KindEntry {
    record_type: "polysurface",
    read: read_record,
    examples,
};
