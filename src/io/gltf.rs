//! glTF 2.0 export: `.glb` (one binary file) or `.gltf` with its `.bin`, and the editable model
//! inside it. The document is built from the `gltf` crate's typed JSON structures (`gltf::json`)
//! and the GLB container written by its `binary` module; what is left here is what glTF does
//! not say: the tessellation, the axes, the vertex data and the embedded model.
//!
//! - One node and one mesh per visible object, named after it, with a PBR metallic-roughness
//!   material (double-sided: knotwork's surfaces are open sheets). A NURBS surface or a polygon
//!   mesh is one primitive; a set of Bézier patches (the teapot) is one primitive per patch, so
//!   that each primitive's TEXCOORD_0 is one patch's (u, v).
//! - Attributes: POSITION, NORMAL (unit), TEXCOORD_0 (the surface's (u, v) normalized to
//!   [0, 1], not flipped; absent for polygon meshes), optionally COLOR_0 (the curvature colours
//!   of a shading mode, linear RGB, with `KHR_materials_unlit` so viewers show them as the
//!   editor does) and `_CURVATURE` (VEC4 float: K, H, k1, k2 in the file's length unit).
//! - **Units.** glTF's unit is the metre: a document with a length unit (a STEP file's
//!   millimetres, say) is written in metres, positions and curvatures scaled; a unitless
//!   document's numbers are written as they are. The embedded model keeps its own unit.
//! - **Colours.** An object with a colour has it as its material's base colour.
//! - Indexed triangles (unsigned short where a primitive has < 65 536 vertices), counter-clockwise
//!   seen from the normal side; vertices are shared within a surface.
//! - **Axes.** knotwork is Z-up, glTF is Y-up (+Z toward the viewer). Every position and normal
//!   is rotated −90° about X: (x, y, z)_knotwork ↦ (x, z, −y)_glTF, a rotation (so winding and
//!   handedness are kept). Each node's translation is its object's box centre in glTF axes and
//!   the positions are relative to it, so other tools put the pivot at the object.
//! - **The model.** `scenes[0].extras.knotwork` holds the whole project (every object, hidden
//!   ones too, and the view) in knotwork's project format ([`super::project`]). knotwork opens its
//!   own exports from it; other viewers ignore `extras` and see the meshes.

use std::borrow::Cow;
use std::collections::BTreeMap;

use glam::{DVec3, Vec3};
use gltf::json;
use gltf::json::accessor::{ComponentType, GenericComponentType, Type};
use gltf::json::buffer::Target;
use gltf::json::mesh::{Mode, Semantic};
use gltf::json::validation::Checked::Valid;
use serde_json::Value;
use serde_json::value::RawValue;
use thiserror::Error;

use super::project::{self, Project};
use crate::kernel::GeometryError;
use crate::kernel::tess::{
    DeferredGridSampler, Estimate, GridPlan, GridSampler, KernelGrids, PendingGridValues,
    Tessellation, TriangleMesh,
};

/// What went wrong in an export.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ExportError {
    #[error("nothing to export: no object is visible")]
    NothingVisible,
    #[error("{name}: {source}")]
    Geometry {
        name: String,
        #[source]
        source: GeometryError,
    },
    #[error(
        "the export would need {bytes} bytes of buffer data; glTF buffers are limited to 4 GiB"
    )]
    TooLarge { bytes: usize },
    #[error(
        "the export would have {about}{count} triangles, more than the {limit} one export may have{where_}: {advice}",
        about = if *estimated { "about " } else { "over " },
        where_ = if usize::BITS < 64 { " in a page (the desktop app exports up to 20000000)" } else { "" }
    )]
    TooManyTriangles {
        limit: usize,
        /// The estimate, or (`estimated` false) the count when the limit was passed.
        count: usize,
        estimated: bool,
        /// What would fit: a larger tolerance or fewer segments.
        advice: String,
    },
    #[error("the export was cancelled")]
    Cancelled,
    #[error("another export is running: wait for it or cancel it")]
    Busy,
}

impl ExportError {
    /// [`ExportError::TooManyTriangles`] for `count` triangles (estimated or counted) at
    /// `tessellation`, with the tolerance or segment count that would fit `limit`: the count
    /// falls as 1/tolerance and as 1/segments².
    pub fn too_many(
        limit: usize,
        count: usize,
        estimated: bool,
        tessellation: Tessellation,
    ) -> Self {
        let ratio = count as f64 / limit.max(1) as f64;
        let advice = match tessellation {
            Tessellation::Tolerance(t) => {
                format!(
                    "choose a tolerance of {:.2e} or more, or hide objects",
                    t * ratio * 1.1
                )
            }
            Tessellation::Segments(n) => {
                let fits = ((f64::from(n) / ratio.sqrt()).floor() as u32).max(1);
                format!("choose {fits} segments or fewer, or hide objects")
            }
        };
        Self::TooManyTriangles {
            limit,
            count,
            estimated,
            advice,
        }
    }
}

/// Curvature colours for COLOR_0: the component (0 K, 1 H, 2 k1, 3 k2), the values at the
/// ramp's ends and the ramp's evenly spaced stops (linear RGB), as the viewport shows them.
#[derive(Debug, Clone, PartialEq)]
pub struct CurvatureColors {
    pub component: usize,
    pub range: (f64, f64),
    pub ramp: Vec<[f32; 3]>,
}

impl CurvatureColors {
    /// The ramp's colour for `value`: linear between the stops, clamped at the ends; the middle
    /// for a range of zero width (the viewport's `ramp_color`).
    pub fn color(&self, value: f64) -> [f32; 3] {
        let (lo, hi) = self.range;
        let x = if hi > lo {
            (value - lo) / (hi - lo)
        } else {
            0.5
        };
        let x = if x.is_finite() {
            x.clamp(0.0, 1.0)
        } else {
            0.5
        };
        let stops = self.ramp.len();
        if stops < 2 {
            return self.ramp.first().copied().unwrap_or([0.5; 3]);
        }
        let f = x * (stops - 1) as f64;
        let k = (f as usize).min(stops - 2);
        let t = (f - k as f64) as f32;
        let (a, b) = (self.ramp[k], self.ramp[k + 1]);
        [0, 1, 2].map(|c| a[c] + (b[c] - a[c]) * t)
    }
}

impl CurvatureColors {
    /// Colours for component `component` (0 K, 1 H, 2 k1, 3 k2) over the scene's automatic
    /// range ([`crate::scene::Scene::curvature_range`]), on `ramp`.
    pub fn automatic(scene: &crate::scene::Scene, component: usize, ramp: Vec<[f32; 3]>) -> Self {
        Self {
            component,
            range: scene.curvature_range(component).unwrap_or((-1.0, 1.0)),
            ramp,
        }
    }
}

/// The curvature component a name stands for: "gaussian" 0, "mean" 1, "k1" 2, "k2" 3.
pub fn curvature_component(name: &str) -> Option<usize> {
    ["gaussian", "mean", "k1", "k2"]
        .iter()
        .position(|&n| n == name)
}

/// Export options from JSON (the web page's `exportGlb`): `{"tolerance": t}` or
/// `{"segments": n}` (neither: the default tolerance), `"curvature": true` for `_CURVATURE`,
/// `"colors": "gaussian" | "mean" | "k1" | "k2"` for COLOR_0 on `ramp`.
pub fn options_from_json(
    text: &str,
    scene: &crate::scene::Scene,
    ramp: Vec<[f32; 3]>,
) -> Result<ExportOptions, String> {
    let value: Value = serde_json::from_str(text).map_err(|e| format!("export options: {e}"))?;
    let tessellation = match (value.get("tolerance"), value.get("segments")) {
        (Some(t), None) => Tessellation::Tolerance(
            t.as_f64()
                .filter(|t| *t > 0.0 && t.is_finite())
                .ok_or_else(|| {
                    format!("export options: tolerance must be a number > 0, got {t}")
                })?,
        ),
        (None, Some(n)) => {
            let max = crate::kernel::tess::MAX_SPAN_SEGMENTS as u64;
            Tessellation::Segments(
                n.as_u64()
                    .filter(|n| (1..=max).contains(n))
                    .and_then(|n| u32::try_from(n).ok())
                    .ok_or_else(|| {
                        format!(
                            "export options: segments must be a whole number from 1 to {max}, got {n}"
                        )
                    })?,
            )
        }
        (None, None) => Tessellation::Tolerance(default_tolerance(scene)),
        (Some(_), Some(_)) => {
            return Err("export options: give tolerance or segments, not both".into());
        }
    };
    let colors = match value.get("colors") {
        None | Some(Value::Null) => None,
        Some(name) => {
            let component = name
                .as_str()
                .and_then(curvature_component)
                .ok_or("export options: colors must be gaussian, mean, k1 or k2")?;
            Some(CurvatureColors::automatic(scene, component, ramp))
        }
    };
    Ok(ExportOptions {
        tessellation,
        curvature: value
            .get("curvature")
            .and_then(Value::as_bool)
            .unwrap_or(false),
        colors,
    })
}

/// How to export.
#[derive(Debug, Clone, PartialEq)]
pub struct ExportOptions {
    pub tessellation: Tessellation,
    /// Write `_CURVATURE` (K, H, k1, k2).
    pub curvature: bool,
    /// Write COLOR_0 with these colours.
    pub colors: Option<CurvatureColors>,
}

/// An export in memory: the glTF document (the `gltf` crate's typed JSON) and its binary
/// buffer.
#[derive(Debug, Clone)]
pub struct Export {
    pub root: json::Root,
    pub bin: Vec<u8>,
    pub triangles: usize,
    /// Curves written as line strips.
    pub lines: usize,
    pub vertices: usize,
}

/// knotwork's axes to glTF's: (x, y, z) ↦ (x, z, −y).
pub fn to_gltf_axes(p: DVec3) -> DVec3 {
    DVec3::new(p.x, p.z, -p.y)
}

/// glTF's axes to knotwork's: (x, y, z) ↦ (x, −z, y).
pub fn from_gltf_axes(p: DVec3) -> DVec3 {
    DVec3::new(p.x, -p.z, p.y)
}

/// The binary buffer, with the bufferViews and accessors that describe it pushed onto the
/// document as they are written.
struct Builder {
    root: json::Root,
    bin: Vec<u8>,
}

impl Builder {
    /// Appends `bytes` as a new bufferView (4-byte aligned).
    fn view(&mut self, bytes: &[u8], target: Target) -> json::Index<json::buffer::View> {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let offset = self.bin.len();
        self.bin.extend_from_slice(bytes);
        self.root.push(json::buffer::View {
            buffer: json::Index::new(0),
            byte_length: bytes.len().into(),
            byte_offset: Some(offset.into()),
            byte_stride: None,
            name: None,
            target: Some(Valid(target)),
            extensions: None,
            extras: None,
        })
    }

    /// An accessor of `count` elements of `kind` in `component` over the bytes just written.
    fn accessor(
        &mut self,
        view: json::Index<json::buffer::View>,
        count: usize,
        component: ComponentType,
        kind: Type,
        bounds: Option<(Value, Value)>,
    ) -> json::Index<json::Accessor> {
        let (min, max) = bounds.unzip();
        self.root.push(json::Accessor {
            buffer_view: Some(view),
            byte_offset: None,
            count: count.into(),
            component_type: Valid(GenericComponentType(component)),
            extensions: None,
            extras: None,
            type_: Valid(kind),
            min,
            max,
            name: None,
            normalized: false,
            sparse: None,
        })
    }

    /// A float accessor of `N` components per element; POSITION gets its min and max.
    fn floats<const N: usize>(
        &mut self,
        data: &[[f32; N]],
        bounds: bool,
    ) -> json::Index<json::Accessor> {
        let bytes: Vec<u8> = data
            .iter()
            .flatten()
            .flat_map(|x| x.to_le_bytes())
            .collect();
        let view = self.view(&bytes, Target::ArrayBuffer);
        let kind = match N {
            2 => Type::Vec2,
            3 => Type::Vec3,
            _ => Type::Vec4,
        };
        let bounds = bounds.then(|| {
            let mut lo = [f32::INFINITY; N];
            let mut hi = [f32::NEG_INFINITY; N];
            for e in data {
                for c in 0..N {
                    lo[c] = lo[c].min(e[c]);
                    hi[c] = hi[c].max(e[c]);
                }
            }
            (Value::from(lo.to_vec()), Value::from(hi.to_vec()))
        });
        self.accessor(view, data.len(), ComponentType::F32, kind, bounds)
    }

    /// An index accessor: unsigned short where every index fits, unsigned int otherwise.
    fn indices(&mut self, triangles: &[[u32; 3]], vertices: usize) -> json::Index<json::Accessor> {
        let flat = triangles.iter().flatten();
        let (bytes, component): (Vec<u8>, _) = if vertices <= usize::from(u16::MAX) {
            (
                flat.flat_map(|&i| (i as u16).to_le_bytes()).collect(),
                ComponentType::U16,
            )
        } else {
            (
                flat.flat_map(|&i| i.to_le_bytes()).collect(),
                ComponentType::U32,
            )
        };
        let view = self.view(&bytes, Target::ElementArrayBuffer);
        self.accessor(view, triangles.len() * 3, component, Type::Scalar, None)
    }
}

/// One primitive's attributes from a tessellated piece, relative to `origin` (glTF axes).
fn primitive(
    builder: &mut Builder,
    piece: &TriangleMesh,
    (origin, scale): (DVec3, f64),
    material: json::Index<json::Material>,
    options: &ExportOptions,
) -> json::mesh::Primitive {
    let positions: Vec<[f32; 3]> = piece
        .positions
        .iter()
        .map(|&p| (to_gltf_axes(p) * scale - origin).as_vec3().to_array())
        .collect();
    let normals: Vec<[f32; 3]> = piece
        .normals
        .iter()
        .map(|&n| {
            let n = to_gltf_axes(n).normalize_or_zero().as_vec3();
            // Renormalize in f32 so the stored vector is unit to f32 precision.
            n.try_normalize().unwrap_or(Vec3::Y).to_array()
        })
        .collect();
    let mut attributes = BTreeMap::new();
    attributes.insert(Valid(Semantic::Positions), builder.floats(&positions, true));
    attributes.insert(Valid(Semantic::Normals), builder.floats(&normals, false));
    if !piece.uvs.is_empty() {
        let uvs: Vec<[f32; 2]> = piece.uvs.iter().map(|uv| uv.map(|t| t as f32)).collect();
        attributes.insert(Valid(Semantic::TexCoords(0)), builder.floats(&uvs, false));
    }
    if let Some(colors) = &options.colors {
        let rgb: Vec<[f32; 3]> = piece
            .curvatures
            .iter()
            .map(|c| colors.color([c.gaussian, c.mean, c.k1, c.k2][colors.component.min(3)]))
            .collect();
        attributes.insert(Valid(Semantic::Colors(0)), builder.floats(&rgb, false));
    }
    if options.curvature {
        let values: Vec<[f32; 4]> = piece
            .curvatures
            .iter()
            .map(|c| {
                // Curvatures in the file's unit, the metre: a length scaled by s divides
                // k1, k2 and H by s and K by s².
                [
                    c.gaussian / (scale * scale),
                    c.mean / scale,
                    c.k1 / scale,
                    c.k2 / scale,
                ]
                .map(|x| x as f32)
            })
            .collect();
        attributes.insert(
            Valid(Semantic::Extras("CURVATURE".into())),
            builder.floats(&values, false),
        );
    }
    let indices = builder.indices(&piece.triangles, piece.positions.len());
    json::mesh::Primitive {
        attributes,
        extensions: None,
        extras: None,
        indices: Some(indices),
        material: Some(material),
        mode: Valid(Mode::Triangles),
        targets: None,
    }
}

/// Tessellates every visible object of `project.scene` and builds the glTF document and
/// buffer, with the project embedded in `scenes[0].extras.knotwork`.
pub fn export(project: &Project, options: &ExportOptions) -> Result<Export, ExportError> {
    export_within(project, options, crate::kernel::tess::MAX_TRIANGLES)
}

/// [`export`] with the objects' parameter grids evaluated by `sampler` (the GPU's, where
/// the caller has one: [`crate::gpu::export_grids`]).
pub fn export_with(
    project: &Project,
    options: &ExportOptions,
    sampler: std::sync::Arc<dyn GridSampler + Send>,
) -> Result<Export, ExportError> {
    let mut job = ExportJob::new(
        project.clone(),
        options.clone(),
        crate::kernel::tess::MAX_TRIANGLES,
    )?;
    job.sample_grids_with(sampler);
    while !job.step()? {}
    job.finish()
}

/// [`export`], refused with [`ExportError::TooManyTriangles`] when the estimate, or the count
/// of the objects tessellated so far, passes `max_triangles`.
pub fn export_within(
    project: &Project,
    options: &ExportOptions,
    max_triangles: usize,
) -> Result<Export, ExportError> {
    let mut job = ExportJob::new(project.clone(), options.clone(), max_triangles)?;
    while !job.step()? {}
    job.finish()
}

/// About how many triangles the visible objects of `scene` make at `tessellation`
/// ([`crate::scene::SceneObject::estimated_triangles`], quick however small the tolerance),
/// per visible object in order; [`ExportError::TooManyTriangles`] when they pass
/// `max_triangles` together.
pub fn estimate_triangles(
    scene: &crate::scene::Scene,
    tessellation: Tessellation,
    max_triangles: usize,
    how: Estimate,
) -> Result<Vec<usize>, ExportError> {
    let mut total = 0usize;
    let mut counts = Vec::new();
    for object in scene.objects.iter().filter(|o| o.visible) {
        let count = object
            .estimated_triangles(tessellation, how)
            .map_err(|source| ExportError::Geometry {
                name: object.name.clone(),
                source,
            })?;
        total = total.saturating_add(count);
        counts.push(count);
    }
    if total > max_triangles {
        return Err(ExportError::too_many(
            max_triangles,
            total,
            true,
            tessellation,
        ));
    }
    Ok(counts)
}

/// An export built one object at a time ([`Self::step`]), so that the editor can show its
/// progress, stay responsive and cancel it between objects. The estimate is checked before
/// the first object, and the count after each one.
pub struct ExportJob {
    project: Project,
    options: ExportOptions,
    max_triangles: usize,
    /// The visible objects' indices and estimated triangle counts.
    visible: Vec<(usize, usize)>,
    /// How many of them are done.
    done: usize,
    builder: Builder,
    /// Metres per document unit (1 for a unitless document): glTF's positions are metres.
    scale: f64,
    nodes: Vec<json::Index<json::Node>>,
    triangles: usize,
    vertices: usize,
    lines: usize,
    /// Who evaluates the objects' parameter grids: the f64 kernel unless told otherwise.
    sampler: std::sync::Arc<dyn GridSampler + Send>,
    /// Who evaluates them without the job waiting (the GPU in the web page), if anyone: it
    /// takes precedence over `sampler`.
    deferred: Option<std::rc::Rc<dyn DeferredGridSampler>>,
    /// The tessellations of the next objects, in order, planned and with their grids asked
    /// of `deferred` (`None`: nothing to ask, or refused: the kernel evaluates them).
    in_flight: std::collections::VecDeque<(GridPlan, Option<Box<dyn PendingGridValues>>)>,
    /// Whether the last step found the next object's grids on their way and nothing else to
    /// do.
    waiting: bool,
}

/// How many objects' grids an export asks for ahead of the one it writes next.
const OBJECTS_IN_FLIGHT: usize = 8;

impl ExportJob {
    /// A job for the visible objects of `project`; refused at once when none is visible or
    /// the estimate passes `max_triangles` ([`estimate_triangles`]: the derivative bound, and
    /// only where that passes the limit the closer estimate, so that an export well inside the
    /// limit pays a few derivative samples per span for the check).
    pub fn new(
        project: Project,
        options: ExportOptions,
        max_triangles: usize,
    ) -> Result<Self, ExportError> {
        let scene = &project.scene;
        let tessellation = options.tessellation;
        let mut counts = estimate_triangles(scene, tessellation, usize::MAX, Estimate::Bound)?;
        if counts.iter().fold(0usize, |a, &n| a.saturating_add(n)) > max_triangles {
            counts = estimate_triangles(scene, tessellation, max_triangles, Estimate::Close)?;
        }
        let indices =
            (0..project.scene.objects.len()).filter(|&k| project.scene.objects[k].visible);
        let visible: Vec<(usize, usize)> = indices.zip(counts).collect();
        if visible.is_empty() {
            return Err(ExportError::NothingVisible);
        }
        let scale = project.scene.unit.map_or(1.0, |u| u.metres());
        Ok(Self {
            scale,
            project,
            options,
            max_triangles,
            visible,
            done: 0,
            builder: Builder {
                root: json::Root::default(),
                bin: Vec::new(),
            },
            nodes: Vec::new(),
            triangles: 0,
            lines: 0,
            vertices: 0,
            sampler: std::sync::Arc::new(KernelGrids),
            deferred: None,
            in_flight: Default::default(),
            waiting: false,
        })
    }

    /// Has `sampler` evaluate the parameter grids of the objects still to come (the GPU's
    /// compute shaders, [`crate::gpu::export_grids::GpuGrids`]); the triangles are the
    /// kernel's either way.
    pub fn sample_grids_with(&mut self, sampler: std::sync::Arc<dyn GridSampler + Send>) {
        self.sampler = sampler;
    }

    /// Has `sampler` evaluate the parameter grids of the objects still to come without the job
    /// waiting for them (the GPU's compute shaders in the page, which cannot wait for a
    /// readback inside a frame): [`Self::step`] asks for the grids of up to
    /// [`OBJECTS_IN_FLIGHT`] objects ahead, and writes the next object once its grids are
    /// back, a frame or more later. Where the sampler refuses or fails, the kernel evaluates
    /// those grids. The triangles are the kernel's either way.
    pub fn sample_grids_deferred(&mut self, sampler: std::rc::Rc<dyn DeferredGridSampler>) {
        self.deferred = Some(sampler);
    }

    /// Whether the next object waits for its grids ([`Self::sample_grids_deferred`]): until
    /// they arrive, [`Self::step`] does nothing, so the caller should come back in a later
    /// frame rather than call it again at once.
    pub fn is_waiting(&self) -> bool {
        self.waiting
    }

    /// The share of the estimated triangles written so far, 0 to 1.
    pub fn progress(&self) -> f64 {
        let total: usize = self.visible.iter().map(|&(_, n)| n.max(1)).sum();
        let done: usize = self.visible[..self.done]
            .iter()
            .map(|&(_, n)| n.max(1))
            .sum();
        done as f64 / total.max(1) as f64
    }

    /// The next object to tessellate, if any.
    pub fn next_name(&self) -> Option<&str> {
        let &(k, _) = self.visible.get(self.done)?;
        Some(&self.project.scene.objects[k].name)
    }

    /// Tessellates the next visible object into the document; true when every one is done.
    /// With a deferred sampler, a step may instead plan a later object and ask for its grids,
    /// or find the next object's grids still on their way with nothing else to do
    /// ([`Self::is_waiting`]), and return false having written nothing.
    pub fn step(&mut self) -> Result<bool, ExportError> {
        self.waiting = false;
        let Some(&(k, _)) = self.visible.get(self.done) else {
            return Ok(true);
        };
        let object = &self.project.scene.objects[k];
        let options = &self.options;
        let curvature = options.curvature || options.colors.is_some();
        let tessellated = match &self.deferred {
            None => object.tessellate_with(options.tessellation, curvature, self.sampler.as_ref()),
            Some(deferred) => {
                // The next object's grids, once back (`Some(None)`: the kernel evaluates them).
                let values = match self.in_flight.front_mut() {
                    None => None,
                    Some((_, None)) => Some(None),
                    Some((_, Some(pending))) => match pending.poll() {
                        None => None,
                        Some(Ok(values)) => Some(Some(values)),
                        Some(Err(e)) => {
                            log::warn!("{e}; the CPU evaluates {}", object.name);
                            Some(None)
                        }
                    },
                };
                match (values, self.in_flight.len()) {
                    (Some(values), _) => match (self.in_flight.pop_front(), values) {
                        (Some((plan, _)), Some(values)) => {
                            plan.finish(Ok(values), &|surface| deferred.position_slack(surface))
                        }
                        (Some((plan, _)), None) => plan.run(&KernelGrids),
                        (None, _) => return Ok(false),
                    },
                    // Meanwhile the next object not yet in flight is planned and its grids
                    // asked for.
                    (None, flying) => {
                        match self.visible.get(self.done + flying) {
                            Some(&(later, _)) if flying < OBJECTS_IN_FLIGHT => {
                                let later = &self.project.scene.objects[later];
                                let plan = later
                                    .plan_tessellation(options.tessellation, curvature)
                                    .map_err(|source| ExportError::Geometry {
                                        name: later.name.clone(),
                                        source,
                                    })?;
                                let pending = if plan.jobs().is_empty() {
                                    None
                                } else {
                                    deferred
                                        .request(&plan.jobs(), plan.curvature())
                                        .inspect_err(|e| {
                                            log::warn!("{e}; the CPU evaluates {}", later.name);
                                        })
                                        .ok()
                                };
                                self.in_flight.push_back((plan, pending));
                            }
                            _ => self.waiting = true,
                        }
                        return Ok(false);
                    }
                }
            }
        };
        self.done += 1;
        let builder = &mut self.builder;
        let pieces = tessellated.map_err(|source| ExportError::Geometry {
            name: object.name.clone(),
            source,
        })?;
        // A curve is a line strip.
        let strip = match object.kind().space_curve() {
            Some(curve) => crate::kernel::tess::curve_polyline(curve, options.tessellation)
                .map_err(|source| ExportError::Geometry {
                    name: object.name.clone(),
                    source,
                })?,
            None => Vec::new(),
        };
        let scale = self.scale;
        let (lo, hi) = pieces
            .iter()
            .flat_map(|p| &p.positions)
            .chain(&strip)
            .map(|&p| to_gltf_axes(p) * scale)
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(p), hi.max(p))
            });
        let origin = if lo.is_finite() && hi.is_finite() {
            0.5 * (lo + hi)
        } else {
            DVec3::ZERO
        };
        let material = builder.root.push(material(
            &object.name,
            options.colors.is_some(),
            object.color,
        ));
        let mut primitives = Vec::new();
        for p in pieces.iter().filter(|p| !p.triangles.is_empty()) {
            self.triangles += p.triangles.len();
            self.vertices += p.positions.len();
            primitives.push(primitive(builder, p, (origin, scale), material, options));
        }
        if strip.len() >= 2 {
            let positions: Vec<[f32; 3]> = strip
                .iter()
                .map(|&p| (to_gltf_axes(p) * scale - origin).as_vec3().to_array())
                .collect();
            self.vertices += positions.len();
            self.lines += 1;
            let mut attributes = BTreeMap::new();
            attributes.insert(Valid(Semantic::Positions), builder.floats(&positions, true));
            primitives.push(json::mesh::Primitive {
                attributes,
                extensions: None,
                extras: None,
                indices: None,
                material: Some(material),
                mode: Valid(Mode::LineStrip),
                targets: None,
            });
        }
        if self.triangles > self.max_triangles {
            return Err(ExportError::too_many(
                self.max_triangles,
                self.triangles,
                false,
                options.tessellation,
            ));
        }
        if !primitives.is_empty() {
            let mesh = builder.root.push(json::Mesh {
                extensions: None,
                extras: None,
                name: Some(object.name.clone()),
                primitives,
                weights: None,
            });
            self.nodes.push(builder.root.push(json::Node {
                name: Some(object.name.clone()),
                mesh: Some(mesh),
                translation: Some(origin.as_vec3().to_array()),
                ..Default::default()
            }));
        }
        Ok(self.done == self.visible.len())
    }

    /// The finished document: the buffer, the scene with the embedded project and the asset.
    /// [`ExportError::Cancelled`] if objects are left ([`Self::step`] was not run to the end).
    pub fn finish(self) -> Result<Export, ExportError> {
        if self.done < self.visible.len() {
            return Err(ExportError::Cancelled);
        }
        let Builder { mut root, mut bin } = self.builder;
        if bin.len() > u32::MAX as usize {
            return Err(ExportError::TooLarge { bytes: bin.len() });
        }
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        root.push(json::Buffer {
            byte_length: bin.len().into(),
            name: None,
            uri: None,
            extensions: None,
            extras: None,
        });
        let model = serde_json::json!({ "knotwork": project::to_value(&self.project) });
        let scene = root.push(json::Scene {
            extensions: None,
            extras: RawValue::from_string(model.to_string()).ok(),
            name: Some("knotwork".into()),
            nodes: self.nodes,
        });
        root.scene = Some(scene);
        root.asset = json::Asset {
            version: "2.0".into(),
            generator: Some(concat!("knotwork ", env!("CARGO_PKG_VERSION")).into()),
            ..Default::default()
        };
        if self.options.colors.is_some() {
            root.extensions_used = vec!["KHR_materials_unlit".into()];
        }
        Ok(Export {
            root,
            bin,
            triangles: self.triangles,
            vertices: self.vertices,
            lines: self.lines,
        })
    }
}

/// An object's material: PBR metallic-roughness, double-sided, in the object's colour
/// (`color`, sRGB, made linear as glTF's base colour factor is) or the editor's grey; white
/// and unlit (`KHR_materials_unlit`) when the vertex colours carry the shading.
fn material(name: &str, unlit: bool, color: Option<[f32; 3]>) -> json::Material {
    let base = match (unlit, color) {
        (true, _) => [1.0, 1.0, 1.0, 1.0],
        (false, Some([r, g, b])) => [
            crate::scene::srgb_to_linear(r),
            crate::scene::srgb_to_linear(g),
            crate::scene::srgb_to_linear(b),
            1.0,
        ],
        (false, None) => [0.72, 0.74, 0.78, 1.0],
    };
    json::Material {
        name: Some(name.to_owned()),
        pbr_metallic_roughness: json::material::PbrMetallicRoughness {
            base_color_factor: json::material::PbrBaseColorFactor(base),
            metallic_factor: json::material::StrengthFactor(0.0),
            roughness_factor: json::material::StrengthFactor(0.45),
            ..Default::default()
        },
        double_sided: true,
        extensions: unlit.then_some(json::extensions::material::Material {
            unlit: Some(json::extensions::material::Unlit {}),
        }),
        ..Default::default()
    }
}

/// A `.glb` file from its JSON text and binary buffer, written by the `gltf` crate: the
/// 12-byte header, the JSON chunk (padded with spaces) and the BIN chunk (padded with zeros)
/// (glTF 2.0 specification, section 4.4 "GLB File Format").
pub fn glb_bytes(json: &[u8], bin: &[u8]) -> Vec<u8> {
    let glb = gltf::binary::Glb {
        header: gltf::binary::Header {
            magic: *b"glTF",
            version: 2,
            // The writer computes the length itself.
            length: 0,
        },
        json: Cow::Borrowed(json),
        bin: (!bin.is_empty()).then_some(Cow::Borrowed(bin)),
    };
    glb.to_vec().unwrap_or_default()
}

/// The export as one `.glb` file.
pub fn to_glb(export: &Export) -> Vec<u8> {
    glb_bytes(&export.root.to_vec().unwrap_or_default(), &export.bin)
}

/// The `.glb` of a project given as project-file text, with options as in
/// [`options_from_json`]: the whole of the web page's `exportGlb` (the page holds the document
/// as that text), so the benchmark can time natively exactly what the page runs as WebAssembly.
pub fn glb_from_json(
    project_text: &str,
    options: &str,
    ramp: Vec<[f32; 3]>,
) -> Result<Vec<u8>, String> {
    let project = project::read(project_text).map_err(|e| e.to_string())?;
    let options = options_from_json(options, &project.scene, ramp)?;
    let export = export(&project, &options).map_err(|e| e.to_string())?;
    Ok(to_glb(&export))
}

/// The export as `.gltf` text whose buffer is the file `bin_name` beside it (written by the
/// caller with [`Export::bin`]). The name is percent-encoded as a relative URI.
pub fn to_gltf_text(export: &Export, bin_name: &str) -> String {
    let mut root = export.root.clone();
    if let Some(buffer) = root.buffers.first_mut() {
        buffer.uri = Some(uri_encode(bin_name));
    }
    root.to_string_pretty().unwrap_or_default()
}

/// Whether a file name asks for the `.gltf` + `.bin` pair rather than a `.glb`.
pub fn wants_gltf_text(path: &str) -> bool {
    path.to_ascii_lowercase().ends_with(".gltf")
}

/// The files of an export to `path`: the `.glb`, or the `.gltf` and its `.bin` beside it (same
/// stem), as (path, bytes) pairs.
pub fn files(export: &Export, path: &str) -> Vec<(String, Vec<u8>)> {
    if !wants_gltf_text(path) {
        return vec![(path.to_owned(), to_glb(export))];
    }
    let stem = &path[..path.len() - ".gltf".len()];
    let bin_path = format!("{stem}.bin");
    let bin_name = bin_path
        .rsplit(['/', '\\'])
        .next()
        .unwrap_or(&bin_path)
        .to_owned();
    vec![
        (
            path.to_owned(),
            to_gltf_text(export, &bin_name).into_bytes(),
        ),
        (bin_path, export.bin.clone()),
    ]
}

/// The default export tolerance: 1e-3 of the diagonal of the visible objects' box (0.001 for
/// an empty scene).
pub fn default_tolerance(scene: &crate::scene::Scene) -> f64 {
    let bounds = scene
        .objects
        .iter()
        .filter(|o| o.visible)
        .filter_map(crate::scene::SceneObject::bounds)
        .reduce(|(lo, hi), (a, b)| (lo.min(a), hi.max(b)));
    match bounds {
        Some((lo, hi)) if (hi - lo).length() > 0.0 => 1e-3 * (hi - lo).length(),
        _ => 1e-3,
    }
}

/// Percent-encodes everything but unreserved URI characters (RFC 3986, section 2.3).
fn uri_encode(name: &str) -> String {
    name.bytes()
        .map(|b| {
            if b.is_ascii_alphanumeric() || b"-._~".contains(&b) {
                (b as char).to_string()
            } else {
                format!("%{b:02X}")
            }
        })
        .collect()
}

/// Percent-decodes a relative URI (the inverse of [`uri_encode`]); `None` if malformed.
pub(crate) fn uri_decode(uri: &str) -> Option<String> {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut k = 0;
    while k < bytes.len() {
        if bytes[k] == b'%' {
            let hex = std::str::from_utf8(bytes.get(k + 1..k + 3)?).ok()?;
            out.push(u8::from_str_radix(hex, 16).ok()?);
            k += 3;
        } else {
            out.push(bytes[k]);
            k += 1;
        }
    }
    String::from_utf8(out).ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_axis_change_is_a_rotation_and_its_inverse_undoes_it() {
        let (a, b) = (DVec3::new(1.0, 2.0, 3.0), DVec3::new(-0.5, 0.25, 4.0));
        assert_eq!(from_gltf_axes(to_gltf_axes(a)), a);
        // Lengths and the cross product (handedness) are kept: a rotation, not a reflection.
        assert_eq!(to_gltf_axes(a).length(), a.length());
        let cross = to_gltf_axes(a).cross(to_gltf_axes(b));
        assert!(cross.distance(to_gltf_axes(a.cross(b))) < 1e-12);
        // knotwork's up (+z) is glTF's up (+y).
        assert_eq!(to_gltf_axes(DVec3::Z), DVec3::Y);
    }

    #[test]
    fn the_colour_ramp_interpolates_between_stops_and_clamps() {
        let colors = CurvatureColors {
            component: 0,
            range: (-1.0, 1.0),
            ramp: vec![[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]],
        };
        assert_eq!(colors.color(-5.0), [0.0, 0.0, 1.0]);
        assert_eq!(colors.color(0.0), [0.0, 1.0, 0.0]);
        assert_eq!(colors.color(0.5), [0.5, 0.5, 0.0]);
        assert_eq!(colors.color(9.0), [1.0, 0.0, 0.0]);
        assert_eq!(colors.color(f64::NAN), [0.0, 1.0, 0.0]);
    }

    #[test]
    fn uris_round_trip_through_percent_encoding() {
        for name in ["model.bin", "my model (2).bin", "größe.bin"] {
            let encoded = uri_encode(name);
            assert!(!encoded.contains(' '));
            assert_eq!(uri_decode(&encoded).as_deref(), Some(name));
        }
        assert_eq!(uri_decode("bad%zz"), None);
    }
}
