//! Subdivision surfaces as a scene object kind. The cage's points are the handles; the GPU
//! feed holds the regular cage quads as bicubic Bézier patches (the B-spline patch of their 16
//! points) and everything else as grids of limit stencils over the cage points
//! ([`LimitFeed`]), whose tables depend only on the topology and are built once per topology
//! change. Level 0 shows the cage itself, as a polygon mesh.

use std::sync::Arc;

use crate::kernel::par::RaceCell;

use glam::{DAffine3, DVec3};

use serde::{Deserialize, Serialize};

use super::json::FormatError;
use super::kind::KindFace;
use super::record::{self, KindEntry};
use super::{Decomposition, ObjectGeometry, ObjectKind, SceneObject};
use crate::kernel::parametric::PatchFace;
use crate::kernel::subdiv::adaptive::{AdaptiveLayout, DEFAULT_TOLERANCE};
use crate::kernel::subdiv::patches::{Display, LimitFeed, boundary_bspline_grid};
use crate::kernel::subdiv::stencil_cache::StencilCache;
use crate::kernel::subdiv::substitutes::{self, SubstitutePlan};
use crate::kernel::subdiv::{
    Boundary, Corner, Crease, Creasing, Options, Scheme, SubdivisionSurface,
};
use crate::kernel::tess::{Tessellation, TriangleMesh};
use crate::kernel::{BezierPatch, BezierPatchSet, GeometryError, PolygonMesh};

/// The topology-only part of the GPU feed, shared by every copy of the object until its
/// topology, sharpness, rules, level or display change.
#[derive(Debug)]
struct Prepared {
    /// Shared with every decomposition made from it (the GPU's stencil tables).
    feed: Arc<LimitFeed>,
    /// How the substitute's control points follow the cage (substitute displays).
    plan: Option<SubstitutePlan>,
    /// The depth each piece shows (the adaptive display), chosen for the points the object had
    /// when it was prepared.
    adaptive: Option<Arc<AdaptiveLayout>>,
    /// The feed patches of each cage face.
    face_patches: Vec<Vec<u32>>,
    /// The cage faces of each cage point.
    point_faces: Vec<Vec<u32>>,
    /// The irregular faces' limit stencils for the object a topology edit makes of this one
    /// ([`SubdivObject::reusing_stencils_of`]).
    stencils: Option<Arc<StencilCache>>,
}

/// What the subdivision properties set: rules, level, display, creases and corners.
#[derive(Debug, Clone, PartialEq)]
pub struct SubdivSettings {
    pub options: crate::kernel::subdiv::Options,
    pub level: u32,
    pub display: Display,
    /// The adaptive display's flatness tolerance, a fraction of the cage's diagonal.
    pub tolerance: f64,
    pub creases: Vec<crate::kernel::subdiv::Crease>,
    pub corners: Vec<crate::kernel::subdiv::Corner>,
}

impl SubdivSettings {
    /// The sharpness of the edge between points `a` and `b` (0: none).
    pub fn crease(&self, a: u32, b: u32) -> f64 {
        self.creases
            .iter()
            .find(|c| (c.a, c.b) == (a, b) || (c.a, c.b) == (b, a))
            .map_or(0.0, |c| c.sharpness)
    }

    /// Sets the sharpness of the edge between `a` and `b`; 0 removes the crease.
    pub fn set_crease(&mut self, a: u32, b: u32, sharpness: f64) {
        self.creases
            .retain(|c| (c.a, c.b) != (a, b) && (c.a, c.b) != (b, a));
        if sharpness != 0.0 {
            self.creases
                .push(crate::kernel::subdiv::Crease { a, b, sharpness });
        }
    }

    /// The sharpness of point `vertex` (0: none).
    pub fn corner(&self, vertex: u32) -> f64 {
        self.corners
            .iter()
            .find(|c| c.vertex == vertex)
            .map_or(0.0, |c| c.sharpness)
    }

    /// Sets the sharpness of point `vertex`; 0 removes it.
    pub fn set_corner(&mut self, vertex: u32, sharpness: f64) {
        self.corners.retain(|c| c.vertex != vertex);
        if sharpness != 0.0 {
            self.corners
                .push(crate::kernel::subdiv::Corner { vertex, sharpness });
        }
    }
}

/// A subdivision surface in the scene.
#[derive(Debug, Clone)]
pub struct SubdivObject {
    pub surface: SubdivisionSurface,
    pub display: Display,
    /// The adaptive display's flatness tolerance, a fraction of the cage's bounding-box
    /// diagonal ([`crate::kernel::subdiv::adaptive`]).
    pub tolerance: f64,
    prepared: Arc<RaceCell<Result<Arc<Prepared>, GeometryError>>>,
    /// The stencils of the object this one was edited from, for its feed to take those of
    /// the faces whose neighbourhoods the edit left alone.
    earlier_stencils: Option<Arc<StencilCache>>,
}

impl PartialEq for SubdivObject {
    fn eq(&self, other: &Self) -> bool {
        self.surface == other.surface
            && self.display == other.display
            && self.tolerance == other.tolerance
    }
}

impl From<SubdivisionSurface> for SubdivObject {
    fn from(surface: SubdivisionSurface) -> Self {
        Self::new(surface, Display::Limit)
    }
}

/// The uniform cubic B-spline basis on one span (The NURBS Book, eq. 2.5 for uniform knots).
fn cubic_bspline_basis(t: f64) -> [f64; 4] {
    let s = 1.0 - t;
    [
        s * s * s / 6.0,
        (3.0 * t * t * t - 6.0 * t * t + 4.0) / 6.0,
        (-3.0 * t * t * t + 3.0 * t * t + 3.0 * t + 1.0) / 6.0,
        t * t * t / 6.0,
    ]
}

/// The 16 Bézier points (row-major, first index along u) of the B-spline patch `grid`.
fn bezier_points(points: &[DVec3], grid: &[u32; 16]) -> [DVec3; 16] {
    bezier_from_bspline(&grid.map(|k| points[k as usize]))
}

/// The Bézier points of one uniform cubic B-spline span by knot insertion (Farin):
/// b0 = (P0 + 4P1 + P2)/6, b1 = (2P1 + P2)/3, b2 = (P1 + 2P2)/3, b3 = (P1 + 4P2 + P3)/6.
fn bspline_span_to_bezier([p0, p1, p2, p3]: [DVec3; 4]) -> [DVec3; 4] {
    let (third, sixth) = (1.0 / 3.0, 1.0 / 6.0);
    [
        (p0 + p1 * 4.0 + p2) * sixth,
        (p1 * 2.0 + p2) * third,
        (p1 + p2 * 2.0) * third,
        (p1 + p2 * 4.0 + p3) * sixth,
    ]
}

/// The Bézier points of the uniform bicubic B-spline patch with points `control` (row-major,
/// first index along u): each direction converted by [`bspline_span_to_bezier`], the rows
/// first and then the columns (the tensor product's two passes of four-point sums).
fn bezier_from_bspline(control: &[DVec3; 16]) -> [DVec3; 16] {
    // Along v within each row a (index a * 4 + b), then along u within each column.
    let mut rows = [DVec3::ZERO; 16];
    for a in 0..4 {
        let converted = bspline_span_to_bezier(std::array::from_fn(|b| control[a * 4 + b]));
        rows[a * 4..a * 4 + 4].copy_from_slice(&converted);
    }
    let mut out = [DVec3::ZERO; 16];
    for j in 0..4 {
        let converted = bspline_span_to_bezier(std::array::from_fn(|a| rows[a * 4 + j]));
        for (i, p) in converted.into_iter().enumerate() {
            out[i * 4 + j] = p;
        }
    }
    out
}

impl SubdivObject {
    /// Its settings, to edit and apply with [`Self::with_settings`].
    pub fn settings(&self) -> SubdivSettings {
        SubdivSettings {
            options: self.surface.options,
            level: self.surface.level(),
            display: self.display,
            tolerance: self.tolerance,
            creases: self.surface.creases().to_vec(),
            corners: self.surface.corners().to_vec(),
        }
    }

    /// The same cage with other settings (checked: a bad crease, a Loop cage with quads or a
    /// level out of range is refused).
    pub fn with_settings(
        mesh: &crate::kernel::PolygonMesh,
        settings: &SubdivSettings,
    ) -> Result<Self, GeometryError> {
        let surface = SubdivisionSurface::new(
            mesh.clone(),
            settings.creases.clone(),
            settings.corners.clone(),
            settings.options,
            settings.level,
        )?;
        Self::checked(surface, settings.display)?.with_tolerance_checked(settings.tolerance)
    }

    /// `surface` shown as `display`, refused where the display does not apply: a substitute
    /// for another scheme than the one it approximates, adaptive refinement for a scheme whose
    /// faces do not split into grids.
    pub fn checked(surface: SubdivisionSurface, display: Display) -> Result<Self, GeometryError> {
        if let Some(kind) = display.substitute() {
            kind.check_scheme(surface.options.scheme)?;
        }
        if display == Display::Adaptive {
            surface.check_adaptive(DEFAULT_TOLERANCE)?;
        }
        Ok(Self::new(surface, display))
    }

    /// The same with flatness tolerance `tolerance` (finite and > 0, else refused).
    pub fn with_tolerance_checked(self, tolerance: f64) -> Result<Self, GeometryError> {
        if self.display == Display::Adaptive {
            self.surface.check_adaptive(tolerance)?;
        } else if !(tolerance.is_finite() && tolerance > 0.0) {
            return Err(GeometryError::Construction {
                what: "subdivision display",
                message: format!("the flatness tolerance must be a number > 0, not {tolerance}"),
            });
        }
        Ok(Self {
            tolerance,
            prepared: Arc::new(RaceCell::new()),
            ..self
        })
    }

    pub fn new(surface: SubdivisionSurface, display: Display) -> Self {
        Self {
            surface,
            display,
            tolerance: DEFAULT_TOLERANCE,
            prepared: Arc::new(RaceCell::new()),
            earlier_stencils: None,
        }
    }

    /// The same object, its GPU feed taking the limit stencils of `earlier` (the object an
    /// edit of topology or sharpness made it from; [`crate::kernel::subdiv::stencil_cache`])
    /// for the faces whose neighbourhoods read as they did there, so that only the faces the
    /// edit changed are refined. Where `earlier` was never shown, nothing is taken.
    pub fn reusing_stencils_of(self, earlier: &SubdivObject) -> Self {
        let stencils = earlier.prepared.get().and_then(|prepared| {
            let prepared = prepared.as_ref().ok()?;
            prepared.stencils.clone()
        });
        Self {
            earlier_stencils: stencils,
            ..self
        }
    }

    /// Of the irregular faces shown as limit stencils, how many its feed refined and how many
    /// took their stencils from the object it was edited from
    /// ([`Self::reusing_stencils_of`]); `None` for displays that keep no stencils.
    pub fn stencil_faces(&self) -> Result<Option<(usize, usize)>, GeometryError> {
        let prepared = self.prepared()?;
        Ok(prepared
            .stencils
            .as_ref()
            .map(|s| s.faces_refined_and_taken()))
    }

    /// What the adaptive display chose for each piece when the object was prepared (`None`
    /// for the other displays).
    pub fn adaptive_layout(&self) -> Result<Option<Arc<AdaptiveLayout>>, GeometryError> {
        Ok(self.prepared()?.adaptive.clone())
    }

    fn prepared(&self) -> Result<Arc<Prepared>, GeometryError> {
        self.prepared
            .get_or_init(|| {
                let level = self.surface.level();
                let (mut plan, mut adaptive, mut stencils) = (None, None, None);
                let feed = match self.display.substitute() {
                    Some(kind) if level > 0 => {
                        let (feed, made) = self.surface.substitute_feed(level, kind, true)?;
                        plan = Some(made);
                        feed
                    }
                    _ if self.display == Display::Adaptive => {
                        let (feed, layout) = self.surface.adaptive_feed(level, self.tolerance)?;
                        adaptive = Some(Arc::new(layout));
                        feed
                    }
                    _ => {
                        let earlier = self.earlier_stencils.as_deref();
                        let (feed, kept) =
                            self.surface
                                .limit_feed_reusing(level, self.display, earlier)?;
                        stencils = kept.map(Arc::new);
                        feed
                    }
                };
                let mesh = self.surface.mesh();
                let mut face_patches = vec![Vec::new(); mesh.face_count()];
                if self.surface.level() == 0 {
                    let mut next = 0u32;
                    for (f, face) in mesh.faces().enumerate() {
                        let count = crate::kernel::PolygonMesh::patches_of_face(face) as u32;
                        face_patches[f] = (next..next + count).collect();
                        next += count;
                    }
                } else {
                    for (k, &(f, _)) in feed.regular.iter().enumerate() {
                        face_patches[f as usize].push(k as u32);
                    }
                    let first = feed.regular.len() as u32;
                    let faces = feed.patches.iter().map(|p| p.cage_face);
                    let faces = faces.chain(feed.substitutes.iter().map(|p| p.cage_face));
                    for (k, face) in faces.enumerate() {
                        // Patches of no single face (Doo-Sabin, √3) are updated as a whole.
                        if let Some(list) = face_patches.get_mut(face as usize) {
                            list.push(first + k as u32);
                        }
                    }
                }
                let mut point_faces = vec![Vec::new(); mesh.points().len()];
                for (f, face) in mesh.faces().enumerate() {
                    for &v in face {
                        point_faces[v as usize].push(f as u32);
                    }
                }
                Ok(Arc::new(Prepared {
                    feed: Arc::new(feed),
                    plan,
                    adaptive,
                    face_patches,
                    point_faces,
                    stencils,
                }))
            })
            .clone()
    }

    /// The feed patches that change when cage point `index` moves: the limit over a face reads
    /// the points of the faces around its corners, and where its normals come from neighbouring
    /// limit points (creases, boundaries) those of the next ring: every face within three
    /// vertex-rings of the point's faces is taken.
    ///
    /// The other schemes' stencils reach further (the butterfly's) or belong to no cage face
    /// (Doo-Sabin, √3): every patch is taken. Substitutes take the same rings as the limit.
    fn patches_near(&self, prepared: &Prepared, index: usize) -> Vec<usize> {
        let mesh = self.surface.mesh();
        let nested = matches!(
            self.surface.options.scheme,
            Scheme::CatmullClark | Scheme::Loop
        );
        if !nested && self.surface.level() > 0 {
            return (0..prepared.feed.regular.len() + prepared.feed.patches.len()).collect();
        }
        let mut faces: Vec<u32> = prepared.point_faces[index].clone();
        // A substitute patch reads the points of the faces around its corners (ACC's and
        // Gregory's corner frames, PN's limit masks), as the limit does; on level 1 (a cage
        // that is not all quads) one ring more, as level 1's points average the cage's.
        let rings = match (&prepared.plan, self.surface.level()) {
            (_, 0) => 0,
            (Some(plan), _) if plan.base_level > 0 => 3,
            _ => 2,
        };
        for _ in 0..rings {
            let mut next: Vec<u32> = Vec::new();
            for &f in &faces {
                for &v in mesh.face(f as usize) {
                    next.extend_from_slice(&prepared.point_faces[v as usize]);
                }
            }
            next.sort_unstable();
            next.dedup();
            faces = next;
        }
        let mut patches: Vec<usize> = faces
            .iter()
            .flat_map(|&f| {
                prepared.face_patches[f as usize]
                    .iter()
                    .map(|&p| p as usize)
            })
            .collect();
        patches.sort_unstable();
        patches
    }

    /// The limit (or refined) point of stencil patch `patch`'s grid vertex nearest (s, t): its
    /// slot's position weights over the cage points (unused triangle slots alias the first).
    fn stencil_point(
        &self,
        feed: &LimitFeed,
        patch: usize,
        s: f64,
        t: f64,
    ) -> Result<DVec3, GeometryError> {
        let p = feed.patches[patch];
        let n = p.segments as f64;
        let nearest = |x: f64| ((x * n).round().max(0.0) as usize).min(p.segments as usize);
        let (i, j) = (nearest(s), nearest(t));
        let slot = p.first_slot as usize + i * (p.segments as usize + 1) + j;
        let missing = || GeometryError::NoSuchPatch {
            patch,
            count: feed.patches.len(),
        };
        let entries = feed.slot_entries(&p, slot).ok_or_else(missing)?;
        let cage = self.surface.points();
        entries
            .into_iter()
            .try_fold(DVec3::ZERO, |sum, (point, weights)| {
                let q = cage.get(point as usize).ok_or_else(missing)?;
                Ok(sum + *q * weights[0])
            })
    }
}

/// How close to a subdivision surface's limit its exchanged patches are asked to be: this
/// fraction of its cage's bounding-box diagonal (or the export's tolerance where larger).
pub const SUBDIVISION_TOLERANCE: f64 = 1e-4;

impl SubdivObject {
    /// [`ObjectKind::exchange_faces`] of a subdivision surface.
    fn limit_faces(&self, tolerance: f64) -> Result<super::ExchangeFaces, GeometryError> {
        use crate::kernel::{NurbsSurface, TrimmedSurface};
        let no_points = || GeometryError::Construction {
            what: "subdivision limit",
            message: "its cage has no points".into(),
        };
        let (lo, hi) =
            super::points_box(self.surface.points().iter().copied()).ok_or_else(no_points)?;
        let asked = (SUBDIVISION_TOLERANCE * lo.distance(hi)).max(tolerance);
        let limit = self.surface.limit_patches(asked)?;
        let faces = limit
            .patches
            .iter()
            .map(|p| NurbsSurface::bezier([3, 3], p.to_vec(), None).map(TrimmedSurface::untrimmed))
            .collect::<Result<Vec<_>, _>>()?;
        // The patches meet along their edges to rounding.
        let topology = crate::kernel::join::find_topology(&faces, asked)?;
        let note = if limit.triangles {
            format!(
                "the limit surface as {} cubic triangles of level {} (each a bicubic patch with one side collapsed), within {:.2e} of the limit",
                faces.len(),
                limit.level,
                limit.deviation
            )
        } else if limit.exact == faces.len() {
            format!(
                "the limit surface as {} bicubic patches of level {}, every one exact",
                faces.len(),
                limit.level
            )
        } else {
            format!(
                "the limit surface as {} bicubic patches of level {}, {} exact, the others within {:.2e} of the limit",
                faces.len(),
                limit.level,
                limit.exact,
                limit.deviation
            )
        };
        Ok(super::ExchangeFaces {
            faces,
            topology: Some(topology),
            note: Some(note),
        })
    }
}

impl ObjectGeometry {
    /// The object as a subdivision surface (its rules, level, display and creases), or `None`.
    pub fn as_subdivision(&self) -> Option<&SubdivObject> {
        self.downcast_ref()
    }
}

impl ObjectKind for SubdivObject {
    fn kind_name(&self) -> &'static str {
        "a subdivision surface"
    }

    fn describe(&self) -> String {
        let scheme = self.surface.options.scheme.label();
        format!(
            "{scheme} subdivision, level {}, {} faces, {} points, {} creases",
            self.surface.level(),
            self.surface.mesh().face_count(),
            self.surface.points().len(),
            self.surface.creases().len()
        )
    }

    fn control_point_count(&self) -> usize {
        self.surface.points().len()
    }

    fn control_points(&self) -> Vec<DVec3> {
        self.surface.points().to_vec()
    }

    fn weights(&self) -> Vec<f64> {
        vec![1.0; self.surface.points().len()]
    }

    fn net_lines(&self) -> Vec<u32> {
        self.surface.mesh().edge_indices()
    }

    fn bounds(&self) -> Option<(DVec3, DVec3)> {
        self.surface.mesh().bounds()
    }

    fn move_control_point(
        &mut self,
        index: usize,
        position: DVec3,
    ) -> Result<Vec<usize>, GeometryError> {
        let prepared = self.prepared()?;
        self.surface.set_point(index, position)?;
        Ok(self.patches_near(&prepared, index))
    }

    fn weighted(&self) -> bool {
        false
    }

    fn set_weight(&mut self, _index: usize, _weight: f64) -> Result<(), GeometryError> {
        Err(GeometryError::Construction {
            what: "subdivision surface",
            message: "its cage points have no weights".into(),
        })
    }

    /// Level 0: the cage's bilinear patches. Otherwise the cage points, then a substitute's
    /// control points, then 16 Bézier points per regular face; stencil patches index the cage
    /// points, substitute patches their own points.
    fn gpu_feed(&self) -> Result<Decomposition, GeometryError> {
        if self.surface.level() == 0 {
            return self.surface.mesh().gpu_feed();
        }
        let prepared = self.prepared()?;
        let cage = self.surface.points();
        let extra = prepared
            .plan
            .as_ref()
            .map_or(0, |p| p.patches.len() * p.kind.point_count());
        let mut points = Vec::with_capacity(cage.len() + extra + 16 * prepared.feed.regular.len());
        points.extend_from_slice(cage);
        if let Some(plan) = &prepared.plan {
            points.extend(plan.control_points(cage));
        }
        let stencil_points = points.len();
        // Each regular face's 16 Bézier points on every core, written in face order after
        // the cage's (and a substitute's) points, and its patch naming them.
        let regular = &prepared.feed.regular;
        points.resize(stencil_points + 16 * regular.len(), DVec3::ZERO);
        knotwork_kernel::par::fill_chunks(&mut points[stencil_points..], 16, |k, grid| {
            grid.copy_from_slice(&bezier_points(cage, &regular[k].1));
        });
        let patches: Vec<BezierPatch> = knotwork_kernel::par::map(regular.len(), |k| {
            let first = (stencil_points + 16 * k) as u32;
            BezierPatch::new(3, 3, (first..first + 16).collect())
        });
        let domains = vec![[0.0, 1.0, 0.0, 1.0]; patches.len()];
        Ok(Decomposition {
            set: BezierPatchSet::new(points, None, patches)?,
            domains,
            stencils: Some(Arc::clone(&prepared.feed)),
            cage_points: stencil_points,
            fixed_segments: Some(1 << self.surface.level()),
            trims: None,
            curve: None,
        })
    }

    /// Regular patches: the uniform bicubic B-spline of the face's 16 cage points; stencil
    /// patches: the level's limit (or refined) point nearest (s, t); level 0: the cage's
    /// bilinear faces.
    fn surface_point(&self, patch: usize, s: f64, t: f64) -> Result<DVec3, GeometryError> {
        if self.surface.level() == 0 {
            return self.surface.mesh().surface_point(patch, s, t);
        }
        let prepared = self.prepared()?;
        let feed = &prepared.feed;
        let regular = feed.regular.len();
        if patch < regular {
            let grid = &feed.regular[patch].1;
            let (bu, bv) = (cubic_bspline_basis(s), cubic_bspline_basis(t));
            let mut p = DVec3::ZERO;
            for a in 0..4 {
                for b in 0..4 {
                    p += self.surface.points()[grid[a * 4 + b] as usize] * (bu[a] * bv[b]);
                }
            }
            return Ok(p);
        }
        let count = regular + feed.patches.len() + feed.substitutes.len();
        if patch >= count {
            return Err(GeometryError::NoSuchPatch { patch, count });
        }
        if let (Some(plan), Some(k)) = (
            &prepared.plan,
            (patch - regular).checked_sub(feed.patches.len()),
        ) {
            let base = plan.base_points(self.surface.points());
            let mut control = Vec::with_capacity(plan.kind.point_count());
            plan.patch_points(&base, k, &mut control);
            return Ok(substitutes::evaluate(plan.kind, &control, s, t)
                .derivatives
                .point);
        }
        self.stencil_point(feed, patch - regular, s, t)
    }

    fn update_gpu_feed(
        &self,
        feed: &mut Decomposition,
        patches: &[usize],
    ) -> Result<(), GeometryError> {
        let cage = self.surface.points();
        feed.sync_points(cage)?;
        if self.surface.level() == 0 {
            return Ok(());
        }
        let prepared = self.prepared()?;
        let mut first_regular = cage.len();
        if let Some(plan) = &prepared.plan {
            // The substitute patches among `patches`, their points recomputed.
            let first = prepared.feed.regular.len() + prepared.feed.patches.len();
            let count = plan.kind.point_count();
            let base = plan.base_points(cage);
            let mut control = Vec::with_capacity(count);
            for k in patches.iter().filter_map(|&p| p.checked_sub(first)) {
                if k >= plan.patches.len() {
                    continue;
                }
                control.clear();
                plan.patch_points(&base, k, &mut control);
                for (i, &q) in control.iter().enumerate() {
                    feed.set.set_point(cage.len() + k * count + i, q)?;
                }
            }
            first_regular += plan.patches.len() * count;
        }
        for &patch in patches {
            if let Some((_, grid)) = prepared.feed.regular.get(patch) {
                let first = first_regular + 16 * patch;
                for (k, q) in bezier_points(cage, grid).into_iter().enumerate() {
                    feed.set.set_point(first + k, q)?;
                }
            }
        }
        Ok(())
    }

    /// The surface as displayed at its level (level 0: the cage): the limit mesh or the
    /// refined one ([`SubdivisionSurface::display_mesh`]), polygons split into fans of
    /// triangles, with the limit normals. With `curvature`, the limit display takes the exact
    /// curvature wherever the limit at a vertex is one polynomial piece
    /// ([`crate::kernel::subdiv::LimitMesh::curvatures`]: Catmull-Clark's regular points,
    /// boundary and sharp corners; Loop's regular points and boundary) and the estimate on the
    /// mesh at the rest (extraordinary points, creases); every other display leaves them to
    /// [`crate::scene::SceneObject::tessellate`]'s estimate.
    fn tessellate(
        &self,
        tessellation: Tessellation,
        curvature: bool,
    ) -> Result<Vec<TriangleMesh>, GeometryError> {
        let level = self.surface.level();
        if level == 0 {
            return self.surface.mesh().tessellate(tessellation, curvature);
        }
        let prepared = self.prepared()?;
        let scheme = self.surface.options.scheme;
        let mut exact = None;
        let shown = match (&prepared.plan, &prepared.adaptive) {
            (Some(plan), _) => self
                .surface
                .substitute_mesh_from(level, &prepared.feed, plan)?,
            (None, Some(layout)) => self.surface.adaptive_mesh_from(level, layout)?,
            (None, None) if curvature && self.display == Display::Limit => {
                let limit = self.surface.limit(level)?;
                exact = Some(limit.curvatures(scheme));
                limit.into_display(Display::Limit)
            }
            (None, None) => self.surface.display_mesh(level, self.display)?,
        };
        let mut triangles = Vec::new();
        for face in &shown.polygons {
            for k in 1..face.len() - 1 {
                triangles.push([face[0], face[k], face[k + 1]]);
            }
        }
        let curvatures = match exact {
            Some(exact) => {
                let mut values = crate::kernel::mesh_curvature::estimate_vertex_curvatures(
                    &shown.positions,
                    &shown.normals,
                    &triangles,
                );
                for (value, exact) in values.iter_mut().zip(exact) {
                    if let Some(exact) = exact {
                        *value = exact;
                    }
                }
                values
            }
            None => Vec::new(),
        };
        Ok(vec![TriangleMesh {
            positions: shown.positions,
            normals: shown.normals,
            uvs: Vec::new(),
            curvatures,
            triangles,
        }])
    }

    /// The limit surface's exact bicubic patches: each regular face's B-spline (the feed's
    /// regular patches), and each stencil patch whose face (a Catmull-Clark cage face's child)
    /// has one side on the boundary, as the B-spline with the outer row extrapolated
    /// ([`crate::kernel::subdiv::patches::boundary_bspline_grid`]; numbered as that stencil
    /// patch, over the same (s, t)). None at level 0 (the cage is flat facets, as a polygon
    /// mesh). Faces around extraordinary vertices and at boundary corners are evaluated by
    /// stencils at grid points only, and are not offered yet.
    fn faces(&self) -> Vec<KindFace<'_>> {
        if self.surface.level() == 0 {
            return Vec::new();
        }
        let Ok(prepared) = self.prepared() else {
            return Vec::new();
        };
        let feed = &prepared.feed;
        let cage = self.surface.points();
        let mut points = Vec::new();
        let mut patches = Vec::new();
        let mut feed_index = Vec::new();
        let mut push = |control: [DVec3; 16], index: usize| {
            let first = points.len() as u32;
            points.extend(bezier_from_bspline(&control));
            patches.push(BezierPatch::new(3, 3, (first..first + 16).collect()));
            feed_index.push(index);
        };
        for (k, (_, grid)) in feed.regular.iter().enumerate() {
            push(grid.map(|i| cage[i as usize]), k);
        }
        // The pieces' levels (the cage's, or its first refinement's) and their points.
        let deepest = feed
            .patches
            .iter()
            .map(|p| p.piece[0])
            .filter(|&l| l <= 1)
            .max();
        let levels = deepest.and_then(|d| self.surface.hierarchy(d).ok());
        if let Some(hierarchy) = &levels {
            let scheme = self.surface.options.scheme;
            let refined: Vec<Vec<DVec3>> = (0..hierarchy.levels.len())
                .map(|l| hierarchy.refine_points_to(cage, l))
                .collect();
            for (k, stencil) in feed.patches.iter().enumerate() {
                let [level, face] = stencil.piece.map(|x| x as usize);
                let (Some(at), Some(level_points)) =
                    (hierarchy.levels.get(level), refined.get(level))
                else {
                    continue;
                };
                if stencil.triangle {
                    continue;
                }
                if let Some(rows) = boundary_bspline_grid(at, scheme, face as u32) {
                    let control = rows.each_ref().map(|row| row.apply(level_points));
                    push(control, feed.regular.len() + k);
                }
            }
        }
        let Ok(set) = BezierPatchSet::new(points, None, patches) else {
            return Vec::new();
        };
        let set = Arc::new(set);
        feed_index
            .into_iter()
            .enumerate()
            .map(|(patch, index)| KindFace {
                patch: Some(index),
                surface: Box::new(PatchFace {
                    set: Arc::clone(&set),
                    patch,
                }),
                triangle: false,
            })
            .collect()
    }

    fn transformed(&self, transform: &DAffine3) -> Result<ObjectGeometry, GeometryError> {
        let mut moved = Self::new(self.surface.transformed(transform)?, self.display);
        moved.tolerance = self.tolerance;
        Ok(ObjectGeometry::new(moved))
    }

    /// The adaptive display chooses its depths again for the points the cage has now.
    fn resettled(&self) -> Option<ObjectGeometry> {
        (self.display == Display::Adaptive && self.surface.level() > 0).then(|| {
            let mut fresh = Self::new(self.surface.clone(), self.display);
            fresh.tolerance = self.tolerance;
            ObjectGeometry::new(fresh)
        })
    }

    fn bake_lattice(
        &self,
        lattice: &crate::kernel::ffd::Lattice,
        tolerance: f64,
    ) -> Result<(ObjectGeometry, crate::kernel::ffd::Baked), GeometryError> {
        let (surface, baked) = super::ffd::bake_cage(&self.surface, lattice, tolerance)?;
        let mut moved = Self::new(surface, self.display);
        moved.tolerance = self.tolerance;
        Ok((ObjectGeometry::new(moved), baked))
    }

    fn same_layout(&self, other: &ObjectGeometry) -> bool {
        other.downcast_ref::<SubdivObject>().is_some_and(|b| {
            b.display == self.display
                && b.tolerance == self.tolerance
                && (self.display != Display::Adaptive
                    || matches!((self.adaptive_layout(), b.adaptive_layout()),
                        (Ok(x), Ok(y)) if x == y))
                && b.surface.level() == self.surface.level()
                && b.surface.options == self.surface.options
                && b.surface.creases() == self.surface.creases()
                && b.surface.corners() == self.surface.corners()
                && b.surface.points().len() == self.surface.points().len()
                && b.surface.mesh().faces().eq(self.surface.mesh().faces())
        })
    }

    /// No one (u, v) domain: the limit surface is a patchwork over the cage's faces.
    fn displacement_domain(&self) -> Option<[f64; 4]> {
        None
    }

    fn nurbs_surface(&self) -> Option<&crate::kernel::NurbsSurface> {
        None
    }

    fn cage(&self) -> Option<&PolygonMesh> {
        Some(self.surface.mesh())
    }

    /// The limit surface as bicubic (or collapsed-triangle) patches within `tolerance`, or
    /// [`SUBDIVISION_TOLERANCE`] of the cage's diagonal where that is larger, with their
    /// shared edges.
    fn exchange_faces(
        &self,
        tolerance: f64,
    ) -> Option<Result<super::ExchangeFaces, GeometryError>> {
        Some(self.limit_faces(tolerance))
    }

    fn record(&self) -> serde_json::Value {
        let surface = &self.surface;
        record::to_record(&CageRecord {
            kind: ENTRY.record_type.into(),
            points: record::point_records(surface.points()),
            faces: surface.mesh().faces().map(<[u32]>::to_vec).collect(),
            creases: surface
                .creases()
                .iter()
                .map(|c| (c.a, c.b, c.sharpness))
                .collect(),
            corners: surface
                .corners()
                .iter()
                .map(|c| (c.vertex, c.sharpness))
                .collect(),
            scheme: surface.options.scheme,
            boundary: surface.options.boundary,
            creasing: surface.options.creasing,
            level: surface.level(),
            display: self.display,
            tolerance: (self.display == Display::Adaptive).then_some(self.tolerance),
        })
    }
}

/// A subdivision surface: its cage, creases `[a, b, sharpness]`, corners `[vertex, sharpness]`,
/// rules, level, display and (the adaptive display's) flatness tolerance.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct CageRecord {
    #[serde(rename = "type")]
    kind: String,
    points: Vec<[f64; 3]>,
    faces: Vec<Vec<u32>>,
    #[serde(default)]
    creases: Vec<(u32, u32, f64)>,
    #[serde(default)]
    corners: Vec<(u32, f64)>,
    #[serde(default)]
    scheme: Scheme,
    #[serde(default)]
    boundary: Boundary,
    #[serde(default)]
    creasing: Creasing,
    #[serde(default)]
    level: u32,
    #[serde(default)]
    display: Display,
    /// A fraction of the cage's diagonal; written only for the adaptive display.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    tolerance: Option<f64>,
}

pub(super) const ENTRY: KindEntry = KindEntry {
    record_type: "subdivision_surface",
    read: read_record,
    examples,
};

fn read_record(path: &str, record: serde_json::Value) -> Result<ObjectGeometry, FormatError> {
    let raw: CageRecord = record::deserialize(path, record)?;
    let geometry = |e| FormatError::geometry(path, e);
    let points = record::points_of(&raw.points);
    let mesh = PolygonMesh::new(points, &raw.faces).map_err(geometry)?;
    let creases = raw
        .creases
        .iter()
        .map(|&(a, b, sharpness)| Crease { a, b, sharpness })
        .collect();
    let corners = raw
        .corners
        .iter()
        .map(|&(vertex, sharpness)| Corner { vertex, sharpness })
        .collect();
    let options = Options {
        scheme: raw.scheme,
        boundary: raw.boundary,
        creasing: raw.creasing,
    };
    let surface =
        SubdivisionSurface::new(mesh, creases, corners, options, raw.level).map_err(geometry)?;
    let object = SubdivObject::checked(surface, raw.display).map_err(geometry)?;
    match raw.tolerance {
        Some(tolerance) => object.with_tolerance_checked(tolerance).map_err(geometry),
        None => Ok(object),
    }
    .map(ObjectGeometry::new)
}

/// A 6 × 6 cage at level 2: its inner faces are bicubic patches, the rest (the boundary, a
/// crease, a pair of triangles) limit stencils.
fn examples() -> Vec<SceneObject> {
    let m = 6;
    let points: Vec<DVec3> = (0..m * m)
        .map(|k| {
            let (i, j) = ((k / m) as f64, (k % m) as f64);
            DVec3::new(i, j, 0.3 * (i * 0.9).sin() * j.cos())
        })
        .collect();
    let id = |i: usize, j: usize| (i * m + j) as u32;
    let mut faces = Vec::new();
    for i in 0..m - 1 {
        for j in 0..m - 1 {
            if (i, j) == (4, 4) {
                faces.push(vec![id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                faces.push(vec![id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            } else {
                faces.push(vec![id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
    }
    let crease = Crease {
        a: id(1, 1),
        b: id(1, 2),
        sharpness: 1.5,
    };
    PolygonMesh::new(points, &faces)
        .and_then(|mesh| {
            SubdivisionSurface::new(mesh, vec![crease], Vec::new(), Options::default(), 2)
        })
        .map(|surface| {
            SceneObject::new(
                "subdivision cage",
                ObjectGeometry::new(SubdivObject::from(surface)),
            )
        })
        .into_iter()
        .collect()
}
