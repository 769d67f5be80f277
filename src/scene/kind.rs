//! The one interface every kind of scene object answers ([`ObjectKind`]): its control points
//! and net, how its points move, what it feeds the GPU, its faces, how it tessellates for
//! export, how it transforms, what it can do (be displaced, be trimmed, be subdivided) and its
//! record in a project file. The editor, the document's commands, the GPU sync layer and the
//! file formats ask these questions and never look at the kind itself, so a new kind of object
//! is one type implementing this trait plus one [`super::registry::KindEntry`] (which reads
//! its records back): the compiler lists every question the kind must answer, and no other
//! code changes.

use std::any::Any;
use std::fmt::Debug;

use glam::{DAffine3, DVec3};

use super::{Decomposition, ObjectGeometry};
use crate::kernel::tess::{GridPlan, GridSampler, Tessellation, TriangleMesh};
use crate::kernel::{GeometryError, NurbsSurface, ParametricSurface, PolygonMesh, TrimmedSurface};

/// A kind's faces for exchange ([`ObjectKind::exchange_faces`]).
#[derive(Debug, Clone)]
pub struct ExchangeFaces {
    pub faces: Vec<TrimmedSurface>,
    /// Their shared edges, where the kind knows them.
    pub topology: Option<crate::kernel::join::Topology>,
    /// How the faces approximate the kind, where they do.
    pub note: Option<String>,
}

/// The box (lowest, highest corner) around `points`; `None` for none: what a kind whose
/// control points contain its shape answers for [`ObjectKind::bounds`].
pub fn points_box(points: impl IntoIterator<Item = DVec3>) -> Option<(DVec3, DVec3)> {
    points
        .into_iter()
        .map(|p| (p, p))
        .reduce(|(lo, hi), (p, _)| (lo.min(p), hi.max(p)))
}

/// One face a kind offers to the analyses, in the kind's own parameters (before any
/// displacement or lattice: [`super::SceneObject::faces`] shows it as the viewport does).
pub struct KindFace<'a> {
    /// Which face of a kind with several (the patch of a patch set, the limit patch of a
    /// subdivision surface); `None` for a kind with one.
    pub patch: Option<usize>,
    pub surface: Box<dyn ParametricSurface + 'a>,
    /// The surface lives over the triangle u + v ≤ 1 (a triangular patch): the analyses see it
    /// over the square ([`crate::kernel::parametric::TriangleAsSquare`]).
    pub triangle: bool,
}

impl<'a> KindFace<'a> {
    /// The one face of a kind with one.
    pub fn whole(surface: impl ParametricSurface + 'a) -> Self {
        Self {
            patch: None,
            surface: Box::new(surface),
            triangle: false,
        }
    }
}

/// What an [`ObjectGeometry`] needs of its kind as a value (copying, comparing, looking at the
/// concrete type), for every `Clone + PartialEq + Debug` kind without writing it: the blanket
/// implementation below is the only one.
pub trait KindValue: Any + Debug + Send + Sync {
    /// A copy of the kind behind a new box.
    fn clone_kind(&self) -> Box<dyn ObjectKind>;
    /// Whether `other` is the same kind with equal data.
    fn equals(&self, other: &dyn ObjectKind) -> bool;
    fn as_any(&self) -> &dyn Any;
    fn as_any_mut(&mut self) -> &mut dyn Any;
}

impl<T: ObjectKind + Clone + PartialEq + Debug + Send + Sync + 'static> KindValue for T {
    fn clone_kind(&self) -> Box<dyn ObjectKind> {
        Box::new(self.clone())
    }

    fn equals(&self, other: &dyn ObjectKind) -> bool {
        other.as_any().downcast_ref::<T>() == Some(self)
    }

    fn as_any(&self) -> &dyn Any {
        self
    }

    fn as_any_mut(&mut self) -> &mut dyn Any {
        self
    }
}

/// What every kind of object answers.
pub trait ObjectKind: KindValue {
    /// "NURBS surface", "set of Bézier patches", "polygon mesh": for messages.
    fn kind_name(&self) -> &'static str;

    /// "B-spline degree (2, 5), 7 × 9 points" and the like, for the panel.
    fn describe(&self) -> String;

    /// How many control points [`Self::control_points`] has (without computing them).
    fn control_point_count(&self) -> usize;

    /// The control points the user sees and drags (Cartesian).
    fn control_points(&self) -> Vec<DVec3>;

    /// The weights of [`Self::control_points`], in the same order (1 where a kind has none).
    fn weights(&self) -> Vec<f64>;

    /// Index pairs of the control net's lines over [`Self::control_points`].
    fn net_lines(&self) -> Vec<u32>;

    /// Where the control net is a rectangular grid, its [rows, columns] (point `index` is at
    /// row `index / columns`): rows and columns can then be selected.
    fn net_grid(&self) -> Option<[usize; 2]> {
        None
    }

    /// The box of the control points (which contains the surface).
    fn bounds(&self) -> Option<(DVec3, DVec3)>;

    /// Moves control point `index` to `position` and returns the indices of the GPU feed's
    /// patches that changed (the point's local support). A bad index or a non-finite position
    /// is refused and changes nothing.
    fn move_control_point(
        &mut self,
        index: usize,
        position: DVec3,
    ) -> Result<Vec<usize>, GeometryError>;

    /// Sets the weight of control point `index`, keeping its position. Refused for a bad index,
    /// a weight that is not finite and > 0, or a kind whose points have no weights.
    fn set_weight(&mut self, index: usize, weight: f64) -> Result<(), GeometryError>;

    /// Whether its points carry weights that [`Self::set_weight`] can set (the panel shows the
    /// weight only then).
    fn weighted(&self) -> bool {
        true
    }

    /// What the object feeds the GPU evaluator: rational Bézier patches over a shared point
    /// pool, each with its parameter rectangle in the object's own domain.
    fn gpu_feed(&self) -> Result<Decomposition, GeometryError>;

    /// The point of the feed's patch `patch` at local (s, t) ∈ [0, 1]², computed from the
    /// object's own definition rather than from the feed: the f64 oracle that the feed and the
    /// GPU are checked against for every kind.
    fn surface_point(&self, patch: usize, s: f64, t: f64) -> Result<DVec3, GeometryError>;

    /// Brings `feed` (this object's [`Self::gpu_feed`] from before its control points moved)
    /// up to date for the feed's patches `patches` only; the rest is kept as it was.
    fn update_gpu_feed(
        &self,
        feed: &mut Decomposition,
        patches: &[usize],
    ) -> Result<(), GeometryError>;

    /// The object as triangle meshes for export (f64, [`crate::kernel::tess`]); `curvature`
    /// adds K, H, k1, k2 per vertex.
    fn tessellate(
        &self,
        tessellation: Tessellation,
        curvature: bool,
    ) -> Result<Vec<TriangleMesh>, GeometryError>;

    /// [`Self::tessellate`] with the parameter grids evaluated by `sampler` (the GPU's
    /// compute shaders in the editor), for kinds that tessellate on tensor grids of NURBS
    /// surfaces; the rest ignore it and tessellate as [`Self::tessellate`] does.
    fn tessellate_with(
        &self,
        tessellation: Tessellation,
        curvature: bool,
        sampler: &dyn GridSampler,
    ) -> Result<Vec<TriangleMesh>, GeometryError> {
        self.plan_tessellation(tessellation, curvature)?
            .run(sampler)
    }

    /// [`Self::tessellate`] up to the evaluation of its parameter grids ([`GridPlan`]), so
    /// that they can be evaluated where the caller cannot wait for them (the GPU in the web
    /// page). Kinds that tessellate on tensor grids of NURBS surfaces plan them; the rest are
    /// tessellated at once, into a plan with nothing left to evaluate.
    fn plan_tessellation(
        &self,
        tessellation: Tessellation,
        curvature: bool,
    ) -> Result<GridPlan, GeometryError> {
        Ok(GridPlan::done(self.tessellate(tessellation, curvature)?))
    }

    /// About how many triangles [`Self::tessellate`] makes at `tessellation`, in time that
    /// does not grow with the answer where the tolerance decides it (so a tiny tolerance is
    /// refused before the wait). By default the tessellation's own count: right for kinds
    /// whose mesh the tolerance does not change.
    fn estimated_triangles(
        &self,
        tessellation: Tessellation,
        _how: crate::kernel::tess::Estimate,
    ) -> Result<usize, GeometryError> {
        Ok(self
            .tessellate(tessellation, false)?
            .iter()
            .map(|m| m.triangles.len())
            .sum())
    }

    /// The surfaces the analyses sample (continuity, curvature combs, principal directions),
    /// through the one surface interface. A kind without a smooth surface says why in its
    /// implementation and offers none.
    fn faces(&self) -> Vec<KindFace<'_>>;

    /// The object mapped by an affine transformation (baked into its control points).
    fn transformed(&self, transform: &DAffine3) -> Result<ObjectGeometry, GeometryError>;

    /// When an edit of its points ends (a drag let go): the object with what depends on its
    /// shape rather than its structure worked out again (an adaptive refinement's depths),
    /// or `None` where nothing does. The result may differ in layout ([`Self::same_layout`]).
    fn resettled(&self) -> Option<ObjectGeometry> {
        None
    }

    /// The object with `lattice`'s deformation baked in ([`super::ffd`]): exactly where the
    /// result is representable, else refitted within `tolerance` (a distance), and how it
    /// turned out.
    fn bake_lattice(
        &self,
        lattice: &crate::kernel::ffd::Lattice,
        tolerance: f64,
    ) -> Result<(ObjectGeometry, crate::kernel::ffd::Baked), GeometryError>;

    /// Whether `other` is the same kind with the same structure (degrees, knots, counts,
    /// patch layout), so that only control point positions or weights differ and the GPU
    /// buffers keep their layout.
    fn same_layout(&self, other: &ObjectGeometry) -> bool;

    /// The (u0, u1, v0, v1) a displacement's height map spans, or `None` for a kind without
    /// one (u, v) domain to map heights on (a polygon mesh, a subdivision surface).
    fn displacement_domain(&self) -> Option<[f64; 4]>;

    /// The NURBS surface of a kind that is one (trimmed or not): what knot insertion, degree
    /// elevation, splitting and trimming work on.
    fn nurbs_surface(&self) -> Option<&NurbsSurface>;

    /// The NURBS curve of a kind that is one: what curve edits, the constructions of surfaces
    /// from curves and the line-strip export work on.
    fn space_curve(&self) -> Option<&crate::kernel::SpaceCurve> {
        None
    }

    /// [`Self::nurbs_surface`] with the kind's trim loops (none for an untrimmed surface).
    fn as_trimmed(&self) -> Option<TrimmedSurface> {
        self.nurbs_surface()
            .map(|surface| TrimmedSurface::untrimmed(surface.clone()))
    }

    /// The polygon cage a subdivision surface can be built on (a polygon mesh, or a
    /// subdivision surface's own cage), or `None`.
    fn cage(&self) -> Option<&PolygonMesh>;

    /// The triangular Bézier patch of a kind that is one (what its degree elevation and the
    /// triangle panel work on), or `None`.
    fn triangle_patch(&self) -> Option<&crate::kernel::triangle::TriangleBezier> {
        None
    }

    /// The kind's faces as trimmed NURBS surfaces for exchange (STEP writes them): exact for
    /// NURBS, trimmed surfaces, polysurfaces (with their shared edges), Bézier patch sets and
    /// triangular patches; a subdivision surface's limit within `tolerance` (model units, or
    /// finer where the kind asks for it), with a note saying how well. `None` for a kind that
    /// has no such faces (a curve, a polygon mesh).
    fn exchange_faces(&self, tolerance: f64) -> Option<Result<ExchangeFaces, GeometryError>> {
        let _ = tolerance;
        self.as_trimmed().map(|t| {
            Ok(ExchangeFaces {
                faces: vec![t],
                topology: None,
                note: None,
            })
        })
    }

    /// The kind's record in a project file: a JSON object with its `"type"` (the
    /// [`super::registry::KindEntry::record_type`] that reads it back) and its own fields. The
    /// object's name, visibility, segments, displacement and lattice are added around it.
    fn record(&self) -> serde_json::Value;
}
