//! The document the editor shows: named objects, each of one kind — a NURBS surface (any
//! degree, knots and weights, trimmed or not), a set of Bézier patches over shared points (the
//! Utah teapot), a polygon mesh, a subdivision surface, a triangular Bézier patch, or any kind
//! registered in [`registry`] — with its own tessellation. Every kind answers the same
//! questions through [`ObjectKind`] (one module per kind) and writes its own project record;
//! the rest of the editor asks those and never names a kind. Pure kernel data: no GPU and no
//! UI. The GPU evaluator takes each object's feed ([`SceneObject::decompose`]).

pub mod change;
pub mod continuity;
mod curve;
mod demo;
pub mod ffd;
pub mod json;
mod kind;
mod mesh;
mod nurbs;
pub mod operation;
mod patch_set;
pub mod polysurface;
pub mod record;
pub mod registry;
mod subdiv;
mod triangle;
mod trimmed;

pub use curve::{CurveFeed, periodic_twin};
pub use kind::{ExchangeFaces, KindFace, KindValue, ObjectKind, points_box};
pub use subdiv::{SUBDIVISION_TOLERANCE, SubdivObject, SubdivSettings};
pub use triangle::viewport_segments;
pub use trimmed::TrimFeed;

/// The length unit (the kernel's), where the scene's users have always found it.
pub use crate::kernel::LengthUnit;

use glam::DVec3;

use crate::kernel::diffgeo::{CurvatureValues, FundamentalForms};
use crate::kernel::ffd::{Baked, Lattice};
use crate::kernel::parametric::{FaceDisplacement, ParametricSurface, ShownFace, TriangleAsSquare};
use crate::kernel::tess;
use crate::kernel::{BezierPatchSet, GeometryError, NurbsSurface, TrimmedSurface};

/// Segments per Bézier span edge a new object gets.
pub const DEFAULT_SEGMENTS: u32 = 16;

/// Highest tessellation level (segments per patch edge) a document may ask for; the GPU's
/// buffer limits may allow less.
pub const MAX_SEGMENTS: u32 = 1024;

/// Curvature samples per patch edge for the automatic colour range.
pub const RANGE_SAMPLES: usize = 6;

/// The longest object name accepted.
pub const MAX_NAME_LENGTH: usize = 200;

/// Whether `name` is acceptable for an object: 1 to [`MAX_NAME_LENGTH`] characters, no control
/// characters.
pub fn valid_name(name: &str) -> bool {
    let length = name.chars().count();
    (1..=MAX_NAME_LENGTH).contains(&length) && !name.chars().any(char::is_control)
}

/// What an object is made of: one kind of object ([`ObjectKind`]: a NURBS surface, a trimmed
/// surface, a set of Bézier patches, a polygon mesh, a subdivision surface, a triangular
/// patch, or any kind registered in [`registry`]) behind the one interface.
pub struct ObjectGeometry(Box<dyn ObjectKind>);

impl Clone for ObjectGeometry {
    fn clone(&self) -> Self {
        Self(self.0.clone_kind())
    }
}

impl PartialEq for ObjectGeometry {
    fn eq(&self, other: &Self) -> bool {
        self.0.equals(other.0.as_ref())
    }
}

impl std::fmt::Debug for ObjectGeometry {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.0.fmt(f)
    }
}

/// What an object feeds the GPU evaluator: rational Bézier patches over one point pool, each
/// with its parameter rectangle in the object's own domain.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Decomposition {
    pub set: BezierPatchSet,
    /// Each patch's parameter rectangle (u0, u1, v0, v1) in the object's own domain.
    pub domains: Vec<[f64; 4]>,
    /// A subdivision surface's stencil patches (after the Bézier patches), over the first
    /// [`Self::cage_points`] points of the set.
    pub stencils: Option<std::sync::Arc<crate::kernel::subdiv::patches::LimitFeed>>,
    pub cage_points: usize,
    /// Segments per patch edge the feed needs whatever the object's tessellation (a
    /// subdivision level's 2^level), or `None` to follow the object's segments.
    pub fixed_segments: Option<u32>,
    /// A trimmed surface's classification grid and each Bézier patch's coverage.
    pub trims: Option<TrimFeed>,
    /// A curve's rational Bézier segments (a curve feeds no patches).
    pub curve: Option<CurveFeed>,
}

/// One object of the scene.
#[derive(Debug, Clone)]
pub struct SceneObject {
    /// The object's identity while the program runs (not part of its equality: an object
    /// read back from a file equals the one written).
    pub id: operation::ObjectId,
    pub name: String,
    pub geometry: ObjectGeometry,
    /// Segments per Bézier span edge (before the global quality factor).
    pub segments: u32,
    /// Hidden objects are kept in the document but neither drawn nor picked.
    pub visible: bool,
    /// A height map applied along the normal (kinds with a (u, v) domain only).
    pub displacement: Option<crate::kernel::displace::Displacement>,
    /// A free-form deformation lattice around the object ([`crate::kernel::ffd`]): while it
    /// is there, the object is shown deformed and its handles are the lattice's points.
    pub lattice: Option<Lattice>,
    /// How an operation made the object, where its history is kept: it is made again when the
    /// operation's inputs change ([`operation::Recipe`]).
    pub recipe: Option<operation::Recipe>,
    /// The object's own colour (sRGB, 0 to 1, as CAD files and colour pickers give it): the
    /// viewport's lit shading and the glTF material use it; `None` is the editor's grey.
    pub color: Option<[f32; 3]>,
}

impl PartialEq for SceneObject {
    /// Equal in everything but their ids; a recipe's inputs are compared by id, so objects of
    /// two scenes whose recipes read the same places compare equal only through
    /// [`Scene`]'s equality.
    fn eq(&self, other: &Self) -> bool {
        self.eq_apart_from_recipe(other) && self.recipe == other.recipe
    }
}

impl SceneObject {
    fn eq_apart_from_recipe(&self, other: &Self) -> bool {
        let Self {
            id: _,
            name,
            geometry,
            segments,
            visible,
            displacement,
            lattice,
            recipe: _,
            color,
        } = self;
        *name == other.name
            && *geometry == other.geometry
            && *segments == other.segments
            && *visible == other.visible
            && *displacement == other.displacement
            && *lattice == other.lattice
            && *color == other.color
    }
}

impl Decomposition {
    /// Copies `points` into the set's first points where they differ (a kind whose feed holds
    /// its control points as they are, first).
    pub fn sync_points(&mut self, points: &[DVec3]) -> Result<(), GeometryError> {
        for (index, &p) in points.iter().enumerate() {
            if self.set.points().get(index) != Some(&p) {
                self.set.set_point(index, p)?;
            }
        }
        Ok(())
    }
}

impl ObjectGeometry {
    /// An object of kind `kind`.
    pub fn new(kind: impl ObjectKind) -> Self {
        Self(Box::new(kind))
    }

    /// An object of a boxed kind.
    pub fn boxed<K: ObjectKind>(kind: Box<K>) -> Self {
        Self(kind)
    }

    /// The object's kind behind the one interface.
    pub fn kind(&self) -> &dyn ObjectKind {
        self.0.as_ref()
    }

    /// [`Self::kind`], mutable.
    pub fn kind_mut(&mut self) -> &mut dyn ObjectKind {
        self.0.as_mut()
    }

    /// The kind as the concrete type `K`, where it is one (for what only that kind offers,
    /// such as a subdivision surface's settings).
    pub fn downcast_ref<K: ObjectKind>(&self) -> Option<&K> {
        self.0.as_any().downcast_ref()
    }

    /// [`Self::downcast_ref`], mutable.
    pub fn downcast_mut<K: ObjectKind>(&mut self) -> Option<&mut K> {
        self.0.as_any_mut().downcast_mut()
    }

    /// A trimmed surface as geometry: a plain NURBS surface when it has no loops.
    pub fn from_trimmed(trimmed: TrimmedSurface) -> Self {
        if trimmed.is_trimmed() {
            Self::new(trimmed)
        } else {
            Self::new(trimmed.surface().clone())
        }
    }

    /// The NURBS surface of a NURBS or trimmed object, with its loops ([`ObjectKind::as_trimmed`]).
    pub fn as_trimmed(&self) -> Option<TrimmedSurface> {
        self.kind().as_trimmed()
    }

    /// The (u0, u1, v0, v1) a displacement's height map spans ([`ObjectKind::displacement_domain`]).
    pub fn displacement_domain(&self) -> Option<[f64; 4]> {
        self.kind().displacement_domain()
    }

    /// The NURBS surface of a NURBS or trimmed object ([`ObjectKind::nurbs_surface`]).
    pub fn nurbs_surface(&self) -> Option<&NurbsSurface> {
        self.kind().nurbs_surface()
    }
}

impl SceneObject {
    pub fn new(name: impl Into<String>, geometry: ObjectGeometry) -> Self {
        Self {
            id: operation::ObjectId::fresh(),
            name: name.into(),
            geometry,
            segments: DEFAULT_SEGMENTS,
            visible: true,
            displacement: None,
            lattice: None,
            recipe: None,
            color: None,
        }
    }

    /// Whether the object keeps history of how it was made (from curves or by an operation).
    pub fn has_history(&self) -> bool {
        self.recipe.is_some()
    }

    /// The object's kind ([`ObjectKind`]).
    pub fn kind(&self) -> &dyn ObjectKind {
        self.geometry.kind()
    }

    /// The object's faces as the viewport shows them ([`ObjectKind::faces`], displaced along
    /// the normal and deformed by the lattice where the object has them; a triangular patch
    /// over the square), with the index of each face of a kind with several.
    pub fn faces(&self) -> Vec<(Option<usize>, Box<dyn ParametricSurface + '_>)> {
        self.kind()
            .faces()
            .into_iter()
            .map(|face| {
                // Nothing to show differently: the kind's face itself (no second dispatch and
                // copy on every evaluation).
                let shown: Box<dyn ParametricSurface + '_> =
                    if self.displacement.is_none() && self.lattice.is_none() {
                        face.surface
                    } else {
                        let [(u0, u1), (v0, v1)] = face.surface.domain();
                        Box::new(ShownFace {
                            displacement: self.displacement.as_ref().map(|map| FaceDisplacement {
                                map,
                                domain: [u0, u1, v0, v1],
                            }),
                            lattice: self.lattice.as_ref(),
                            face: face.surface,
                        })
                    };
                let surface: Box<dyn ParametricSurface + '_> = if face.triangle {
                    Box::new(TriangleAsSquare(shown))
                } else {
                    shown
                };
                (face.patch, surface)
            })
            .collect()
    }

    /// What the object feeds the GPU: its Bézier patches and their parameter rectangles
    /// ([`ObjectKind::gpu_feed`]; The NURBS Book A5.7 for a NURBS surface).
    pub fn decompose(&self) -> Result<Decomposition, GeometryError> {
        self.kind().gpu_feed()
    }

    /// Brings `decomposition` (this object's, from [`Self::decompose`] before its control points
    /// moved) up to date for the Bézier patches `patches` only ([`ObjectKind::update_gpu_feed`]).
    pub fn update_decomposition(
        &self,
        decomposition: &mut Decomposition,
        patches: &[usize],
    ) -> Result<(), GeometryError> {
        self.kind().update_gpu_feed(decomposition, patches)
    }

    /// How many control points [`Self::control_points`] has (without computing them).
    pub fn control_point_count(&self) -> usize {
        match &self.lattice {
            Some(lattice) => lattice.points().len(),
            None => self.kind().control_point_count(),
        }
    }

    /// The control points the user sees and drags: the NURBS net (Cartesian), the patch pool,
    /// or the lattice's points while the object has a lattice.
    pub fn control_points(&self) -> Vec<DVec3> {
        match &self.lattice {
            Some(lattice) => lattice.points().to_vec(),
            None => self.kind().control_points(),
        }
    }

    /// Index pairs of the control net's lines over [`Self::control_points`].
    pub fn net_lines(&self) -> Vec<u32> {
        match &self.lattice {
            Some(lattice) => lattice.net_lines(),
            None => self.kind().net_lines(),
        }
    }

    /// Where the control net is a rectangular grid, its [rows, columns] (not a lattice's).
    pub fn net_grid(&self) -> Option<[usize; 2]> {
        match &self.lattice {
            Some(_) => None,
            None => self.kind().net_grid(),
        }
    }

    /// The box of the control points (which contains the surface), and of the lattice's.
    pub fn bounds(&self) -> Option<(DVec3, DVec3)> {
        let own = self.kind().bounds();
        let Some(lattice) = &self.lattice else {
            return own;
        };
        lattice
            .points()
            .iter()
            .map(|&p| (p, p))
            .chain(own)
            .reduce(|(lo, hi), (a, b)| (lo.min(a), hi.max(b)))
    }

    /// The object with its lattice baked in ([`ObjectKind::bake_lattice`]; `tolerance` a
    /// fraction of the object's bounding-box diagonal) and no lattice, and how the bake turned
    /// out. Refused for an object without a lattice and for a displaced one (its height map
    /// would then follow the deformed surface's normal rather than the original's).
    pub fn baked_lattice(&self, tolerance: f64) -> Result<(SceneObject, Baked), GeometryError> {
        let refuse = |message: &str| GeometryError::Construction {
            what: "apply lattice",
            message: message.into(),
        };
        let Some(lattice) = &self.lattice else {
            return Err(refuse("the object has no lattice"));
        };
        if self.displacement.is_some() {
            return Err(refuse(
                "the object is displaced: remove the displacement first (or keep the lattice live)",
            ));
        }
        if !(tolerance > 0.0 && tolerance.is_finite()) {
            return Err(refuse("the tolerance must be a number > 0"));
        }
        let size = self
            .kind()
            .bounds()
            .map_or(1.0, |(lo, hi)| (hi - lo).length().max(1e-12));
        let (geometry, baked) = self.kind().bake_lattice(lattice, tolerance * size)?;
        Ok((
            SceneObject {
                geometry,
                lattice: None,
                ..self.clone()
            },
            baked,
        ))
    }

    /// "NURBS (2, 5), 7 × 9 points, rational" and the like, for the panel.
    pub fn describe(&self) -> String {
        self.kind().describe()
    }

    /// Moves control point `index` (of [`Self::control_points`]) to `position` and returns the
    /// indices of the Bézier patches that changed ([`ObjectKind::move_control_point`]). A bad
    /// index or a non-finite position is refused and changes nothing.
    /// A lattice point's move changes no patch of the feed (the lattice itself is uploaded).
    pub fn move_control_point(
        &mut self,
        index: usize,
        position: DVec3,
    ) -> Result<Vec<usize>, GeometryError> {
        match &mut self.lattice {
            Some(lattice) => lattice.set_point(index, position).map(|()| Vec::new()),
            None => self.geometry.kind_mut().move_control_point(index, position),
        }
    }

    /// Sets the weight of control point `index` (of [`Self::control_points`]), keeping its
    /// position ([`ObjectKind::set_weight`]).
    pub fn set_weight(&mut self, index: usize, weight: f64) -> Result<(), GeometryError> {
        if self.lattice.is_some() {
            return Err(GeometryError::Construction {
                what: "lattice",
                message: "its points have no weights".into(),
            });
        }
        self.geometry.kind_mut().set_weight(index, weight)
    }

    /// Whether its control points have weights to set (not a lattice's, a mesh's, a cage's or a
    /// polynomial triangle's).
    pub fn has_weights(&self) -> bool {
        self.lattice.is_none() && self.kind().weighted()
    }

    /// The weights of [`Self::control_points`], in the same order.
    pub fn weights(&self) -> Vec<f64> {
        match &self.lattice {
            Some(lattice) => vec![1.0; lattice.points().len()],
            None => self.kind().weights(),
        }
    }

    /// Curvature at an n × n grid of parameters in every Bézier patch, from the f64 kernel, each
    /// with the area it stands for (|Su × Sv| in the patch's own parameters, so that a small
    /// patch such as the teapot's spout tip does not weigh as much as the body). The automatic
    /// colour range is taken from these.
    pub fn curvature_samples(
        &self,
        n: usize,
    ) -> Result<Vec<(CurvatureValues, f64)>, GeometryError> {
        let decomposition = self.decompose()?;
        let set = &decomposition.set;
        let mut values = Vec::new();
        let n = n.max(2);
        for k in 0..set.patches().len() {
            for a in 0..n {
                for b in 0..n {
                    let (u, v) = (a as f64 / (n - 1) as f64, b as f64 / (n - 1) as f64);
                    let d = set.evaluate(k, u, v)?;
                    if d.regular_normal().is_none() {
                        continue;
                    }
                    let normal = set.normal_from(&set.patches()[k], &d, u, v);
                    if let Some(c) = CurvatureValues::from_forms(&FundamentalForms::new(&d, normal))
                    {
                        values.push((c, d.su.cross(d.sv).length()));
                    }
                }
            }
        }
        Ok(values)
    }

    /// The object as triangle meshes for export ([`ObjectKind::tessellate`]): one for a NURBS
    /// surface or a polygon mesh, one per patch for a patch set (each with the patch's own
    /// (u, v)). A displaced object is tessellated for its pattern rather than the tolerance.
    ///
    /// An object with a lattice is tessellated as the viewport shows it (its own segments per
    /// span) and every vertex mapped through the lattice, its normal by the cofactor of the
    /// lattice's Jacobian ([`Lattice::deform_vertex`]).
    ///
    /// `curvature` adds K, H, k1, k2 to every vertex of every mesh: the kind's exact values
    /// where it has them, else (subdivision surfaces, displaced and deformed objects) the
    /// estimate from the mesh and its normals ([`crate::kernel::mesh_curvature`]).
    pub fn tessellate(
        &self,
        tessellation: tess::Tessellation,
        curvature: bool,
    ) -> Result<Vec<tess::TriangleMesh>, GeometryError> {
        self.tessellate_with(tessellation, curvature, &tess::KernelGrids)
    }

    /// [`Self::tessellate`] with the kind's parameter grids evaluated by `sampler`
    /// ([`ObjectKind::tessellate_with`]); displacement, lattices and estimated curvatures are
    /// applied on the CPU as there.
    pub fn tessellate_with(
        &self,
        tessellation: tess::Tessellation,
        curvature: bool,
        sampler: &dyn tess::GridSampler,
    ) -> Result<Vec<tess::TriangleMesh>, GeometryError> {
        self.plan_tessellation(tessellation, curvature)?
            .run(sampler)
    }

    /// [`Self::tessellate`] up to the evaluation of the kind's parameter grids
    /// ([`ObjectKind::plan_tessellation`]); displacement, lattices and estimated curvatures
    /// are applied when the plan is finished.
    pub fn plan_tessellation(
        &self,
        tessellation: tess::Tessellation,
        curvature: bool,
    ) -> Result<tess::GridPlan, GeometryError> {
        let lattice = self.lattice.clone();
        let plan = match &lattice {
            None => self.plan_undeformed(tessellation, curvature)?,
            Some(_) => self.plan_undeformed(tess::Tessellation::Segments(self.segments), false)?,
        };
        Ok(plan.then(move |mut meshes| {
            if let Some(lattice) = &lattice {
                for mesh in &mut meshes {
                    for (p, n) in mesh.positions.iter_mut().zip(&mut mesh.normals) {
                        (*p, *n) = lattice.deform_vertex(*p, *n);
                    }
                }
            }
            if curvature {
                for mesh in &mut meshes {
                    if mesh.curvatures.len() != mesh.positions.len() {
                        mesh.curvatures = crate::kernel::mesh_curvature::estimate_vertex_curvatures(
                            &mesh.positions,
                            &mesh.normals,
                            &mesh.triangles,
                        );
                    }
                }
            }
            Ok(meshes)
        }))
    }

    /// [`Self::plan_tessellation`] without the lattice.
    fn plan_undeformed(
        &self,
        tessellation: tess::Tessellation,
        curvature: bool,
    ) -> Result<tess::GridPlan, GeometryError> {
        let Some(map) = &self.displacement else {
            return self.kind().plan_tessellation(tessellation, curvature);
        };
        let plan = self
            .kind()
            .plan_tessellation(self.displacement_tessellation(map), false)?;
        let map = map.clone();
        Ok(plan.then(move |mut meshes| {
            for mesh in &mut meshes {
                crate::kernel::displace::displace_mesh(mesh, &map);
            }
            Ok(meshes)
        }))
    }

    /// A displaced object's tessellation: enough vertices for the pattern (8 per cycle across
    /// the domain, shared among a NURBS surface's spans; at least 4 per span), which are then
    /// moved along the normal ([`crate::kernel::displace::displace_mesh`]).
    fn displacement_tessellation(
        &self,
        map: &crate::kernel::displace::Displacement,
    ) -> tess::Tessellation {
        let spans = self.geometry.nurbs_surface().map_or(1, |s| {
            s.span_breaks(crate::kernel::Direction::U)
                .len()
                .max(s.span_breaks(crate::kernel::Direction::V).len())
                .saturating_sub(1)
                .max(1)
        });
        let segments = ((map.segments_per_cycle() * map.frequency / spans as f64).ceil() as u32)
            .clamp(4, MAX_SEGMENTS);
        tess::Tessellation::Segments(segments)
    }

    /// About how many triangles [`Self::tessellate`] makes, without making them
    /// ([`ObjectKind::estimated_triangles`], on the tessellation the lattice or the
    /// displacement chooses where the object has one).
    pub fn estimated_triangles(
        &self,
        tessellation: tess::Tessellation,
        how: tess::Estimate,
    ) -> Result<usize, GeometryError> {
        let tessellation = match (&self.displacement, &self.lattice) {
            (Some(map), _) => self.displacement_tessellation(map),
            (None, Some(_)) => tess::Tessellation::Segments(self.segments),
            (None, None) => tessellation,
        };
        self.kind().estimated_triangles(tessellation, how)
    }
}

/// The objects of one document.
#[derive(Debug, Clone, Default)]
pub struct Scene {
    pub objects: Vec<SceneObject>,
    /// The length unit of every coordinate; `None` (a project without one) is unitless, and
    /// exports keep its numbers as they are.
    pub unit: Option<LengthUnit>,
}

impl PartialEq for Scene {
    /// The same objects in the same order and the same unit; histories are equal when their
    /// operations read the objects at the same places (ids differ between two scenes: a
    /// project read back, a scene built twice).
    fn eq(&self, other: &Self) -> bool {
        let by_place = |scene: &Scene, object: &SceneObject| {
            object
                .recipe
                .as_ref()
                .map(|r| (r.operation.by_index(scene).ok(), r.output))
        };
        self.unit == other.unit
            && self.objects.len() == other.objects.len()
            && self
                .objects
                .iter()
                .zip(&other.objects)
                .all(|(a, b)| a.eq_apart_from_recipe(b) && by_place(self, a) == by_place(other, b))
    }
}

/// An sRGB component (0 to 1) as linear light (IEC 61966-2-1: c/12.92 up to 0.04045,
/// ((c + 0.055)/1.055)^2.4 above).
pub fn srgb_to_linear(c: f32) -> f32 {
    let c = c.clamp(0.0, 1.0);
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

impl Scene {
    /// The objects that share object `object`'s lattice (equal lattices: the same group and
    /// the same points), `object` among them, by increasing index; just `object` when it has
    /// no lattice (what a lattice edit of it applies to).
    pub fn linked_lattices(&self, object: usize) -> Vec<usize> {
        let Some(lattice) = self.objects.get(object).and_then(|o| o.lattice.as_ref()) else {
            return vec![object];
        };
        self.objects
            .iter()
            .enumerate()
            .filter(|(_, o)| o.lattice.as_ref() == Some(lattice))
            .map(|(k, _)| k)
            .collect()
    }

    /// A lattice group number no object's lattice uses yet.
    pub fn new_lattice_group(&self) -> u64 {
        self.objects
            .iter()
            .filter_map(|o| o.lattice.as_ref().map(Lattice::group))
            .max()
            .map_or(1, |g| g + 1)
    }

    /// `base`, or where an object already has that name, `base 2`, `base 3`, … (the first
    /// that is free).
    pub fn unique_name(&self, base: &str) -> String {
        let taken = |name: &str| self.objects.iter().any(|o| o.name == name);
        if !taken(base) {
            return base.to_owned();
        }
        (2..)
            .map(|k| format!("{base} {k}"))
            .find(|name| !taken(name))
            .unwrap_or_else(|| base.to_owned())
    }

    /// Where a new object reaching `reach` from its centre can go: `wanted` if no object's box
    /// comes within that reach of it, else just beyond the scene's box along +x (on the
    /// ground, level with the scene's middle in y), on a half-unit grid.
    pub fn free_spot(&self, wanted: DVec3, reach: f64) -> DVec3 {
        let reach = reach.abs().max(1e-6);
        let clear = |c: DVec3| {
            self.objects
                .iter()
                .filter_map(SceneObject::bounds)
                .all(|(lo, hi)| (0..3).any(|a| c[a] + reach < lo[a] || c[a] - reach > hi[a]))
        };
        if clear(wanted) {
            return wanted;
        }
        let Some((lo, hi)) = self.bounds() else {
            return wanted;
        };
        let spot = DVec3::new(hi.x + 1.25 * reach, 0.5 * (lo.y + hi.y), lo.z.max(0.0));
        (spot * 2.0).round() * 0.5 + DVec3::X * 0.5
    }

    /// The box around every object.
    pub fn bounds(&self) -> Option<(DVec3, DVec3)> {
        self.objects
            .iter()
            .filter_map(SceneObject::bounds)
            .reduce(|(lo, hi), (a, b)| (lo.min(a), hi.max(b)))
    }

    /// The automatic colour range of curvature component `component` (0 K, 1 H, 2 k1, 3 k2):
    /// [`robust_range`] over the f64 kernel's samples ([`SceneObject::curvature_samples`], an
    /// [`RANGE_SAMPLES`]² per Bézier patch) of every visible object: the range the viewport's
    /// colour ramp and the glTF export's colours use unless the user sets one.
    pub fn curvature_range(&self, component: usize) -> Option<(f64, f64)> {
        let mut values = Vec::new();
        for object in self.objects.iter().filter(|o| o.visible) {
            if let Ok(samples) = object.curvature_samples(RANGE_SAMPLES) {
                values.extend(
                    samples.iter().map(|(c, area)| {
                        ([c.gaussian, c.mean, c.k1, c.k2][component.min(3)], *area)
                    }),
                );
            }
        }
        robust_range(values)
    }
}

/// The weighted (2 %, 98 %) percentiles of `(value, weight)` pairs (non-finite values and
/// weights ≤ 0 ignored): a colour range that small regions of extreme values (a pole, a cusp, a
/// spout's tip) do not wash out. A range narrower than [`NARROWEST_RANGE`] of its values'
/// size (a constant, up to rounding: the exact sphere's K) is widened around its middle, by
/// 10 % of it or 1e-9, so a constant reads as the ramp's middle instead of spreading the GPU's
/// f32 rounding (about 1e-7 of the value) over the whole ramp. `None` when nothing is left.
pub fn robust_range(values: impl IntoIterator<Item = (f64, f64)>) -> Option<(f64, f64)> {
    let mut sorted: Vec<(f64, f64)> = values
        .into_iter()
        .filter(|(v, w)| v.is_finite() && w.is_finite() && *w > 0.0)
        .collect();
    if sorted.is_empty() {
        return None;
    }
    sorted.sort_by(|a, b| a.0.total_cmp(&b.0));
    let total: f64 = sorted.iter().map(|(_, w)| w).sum();
    let at = |q: f64| {
        let mut acc = 0.0;
        for &(v, w) in &sorted {
            acc += w;
            if acc >= q * total {
                return v;
            }
        }
        sorted[sorted.len() - 1].0
    };
    let (lo, hi) = (at(0.02), at(0.98));
    let size = lo.abs().max(hi.abs());
    if hi - lo > NARROWEST_RANGE * size {
        Some((lo, hi))
    } else {
        let middle = 0.5 * (lo + hi);
        let pad = (0.1 * middle.abs()).max(1e-9);
        Some((middle - pad, middle + pad))
    }
}

/// The narrowest automatic colour range, as a share of its values' size: curvature that
/// varies less than this is shown as constant.
pub const NARROWEST_RANGE: f64 = 1e-3;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_robust_range_ignores_a_few_extremes_and_widens_a_constant() {
        let mut values: Vec<(f64, f64)> = (0..1000).map(|k| (k as f64 / 999.0, 1.0)).collect();
        values.extend([
            (1e9, 1.0),
            (-1e9, 1.0),
            (f64::NAN, 1.0),
            (f64::INFINITY, 1.0),
        ]);
        // Many samples over a tiny area count for little.
        values.extend((0..500).map(|_| (1e6, 1e-6)));
        let (lo, hi) = robust_range(values).unwrap();
        assert!(
            lo > -0.01 && lo < 0.05 && hi > 0.95 && hi < 1.01,
            "({lo}, {hi})"
        );
        let (lo, hi) = robust_range([(0.25, 1.0); 10]).unwrap();
        assert!(lo < 0.25 && hi > 0.25 && (lo + hi - 0.5).abs() < 1e-12);
        // A constant up to rounding (the exact sphere's K in f64) is a constant too: the
        // range is 10 % wide, not 1e-15, which would colour the GPU's f32 rounding.
        let sphere = (0..100).map(|k| (0.25 + 1e-16 * f64::from(k % 7) - 3e-16, 1.0));
        let (lo, hi) = robust_range(sphere).unwrap();
        assert!(
            hi - lo > 0.04 && (0.5 * (lo + hi) - 0.25).abs() < 1e-12,
            "({lo}, {hi})"
        );
        // The exact sphere of the sample scene shades as one colour in Gaussian mode.
        let demo = Scene {
            objects: vec![Scene::demo().unwrap().objects[2].clone()],
            unit: None,
        };
        let (lo, hi) = demo.curvature_range(0).unwrap();
        assert!(hi - lo > 0.01, "({lo}, {hi})");
        assert_eq!(robust_range([(f64::NAN, 1.0)]), None);
    }

    #[test]
    fn the_demo_scene_decomposes_and_editing_reports_the_local_support() {
        let mut scene = Scene::demo().unwrap();
        let counts: Vec<usize> = scene
            .objects
            .iter()
            .map(|o| o.decompose().unwrap().set.patches().len())
            .collect();
        assert_eq!(counts, [32, 16, 8, 16, 4, 8]);
        // The (2, 5) sheet, point (4, 4): N_{4,2} lives on [u_4, u_7) = [0.45, 1), two of the
        // four u-spans; N_{4,5} on [v_4, v_10) = [0, 1), all four v-spans.
        let sheet = &mut scene.objects[3];
        let patches = sheet.move_control_point(4 * 9 + 4, DVec3::ONE).unwrap();
        assert_eq!(patches, [8, 9, 10, 11, 12, 13, 14, 15]);
        let before = sheet.clone();
        assert!(sheet.move_control_point(0, DVec3::NAN).is_err());
        assert!(sheet.move_control_point(10_000, DVec3::ONE).is_err());
        assert_eq!(*sheet, before);
    }

    #[test]
    fn updating_only_the_moved_patches_matches_a_full_decomposition() {
        // Every object of the demo scene: move one point, re-derive only its support, and compare
        // with decomposing the whole moved object.
        let scene = Scene::demo().unwrap();
        for object in &scene.objects {
            let mut moved = object.clone();
            let mut decomposition = moved.decompose().unwrap();
            let index = moved.control_points().len() / 2;
            let target = moved.control_points()[index] + DVec3::new(0.3, -0.2, 0.5);
            let patches = moved.move_control_point(index, target).unwrap();
            moved
                .update_decomposition(&mut decomposition, &patches)
                .unwrap();
            let full = moved.decompose().unwrap();
            let scale = moved.bounds().map_or(1.0, |(lo, hi)| (hi - lo).length());
            for (k, (a, b)) in decomposition
                .set
                .points()
                .iter()
                .zip(full.set.points())
                .enumerate()
            {
                assert!(
                    a.distance(*b) <= 1e-12 * scale,
                    "{}: point {k} {a} vs {b}",
                    object.name
                );
            }
            for (a, b) in decomposition.set.weights().iter().zip(full.set.weights()) {
                assert!((a - b).abs() <= 1e-12 * b);
            }
        }
    }
}
