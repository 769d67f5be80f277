//! STEP in the editor: the `knotwork-step` crate (`crates/step`: the Part 21 tokenizer, the
//! entities, faces, reading and writing, on the kernel alone) re-exported here, and the glue
//! between its bodies and the scene's objects.
//!
//! A body opens as a polysurface whose shared edges are the file's
//! ([`Polysurface::with_topology`]), so its export is watertight across them, coloured as the
//! file colours it, in a scene whose unit is the millimetre.

pub use knotwork_step::{entities, faces, part21, read, write};

use crate::io::project::Project;
use crate::scene::json::FormatError;
use crate::scene::polysurface::{MAX_FACES, Polysurface};
use crate::scene::{LengthUnit, ObjectGeometry, Scene, SceneObject};

pub use read::{Stage, StepModel};

/// The join tolerance of a body read: edges within it are shared (mm).
fn join_tolerance(model: &StepModel) -> f64 {
    (model.tolerance * 100.0).max(1e-7)
}

/// An object name from a product's: control characters dropped, at most
/// [`crate::scene::MAX_NAME_LENGTH`] characters, "Body" when nothing is left.
fn object_name(name: &str) -> String {
    let clean: String = name
        .chars()
        .filter(|c| !c.is_control())
        .take(crate::scene::MAX_NAME_LENGTH)
        .collect();
    let clean = clean.trim();
    if clean.is_empty() {
        "Body".into()
    } else {
        clean.to_string()
    }
}

/// Body `body` of a model as scene objects, pushed onto `scene`: one polysurface (a body of
/// more than [`MAX_FACES`] faces in parts of that many), named after its product, in its
/// colour.
fn push_body(scene: &mut Scene, body: &read::StepBody, tolerance: f64) -> Result<(), FormatError> {
    let name = object_name(&body.name);
    if body.faces.len() <= MAX_FACES {
        let p = Polysurface::with_topology(body.faces.clone(), tolerance, body.topology.clone())
            .map_err(|e| FormatError::new(name.clone(), e.to_string()))?;
        let mut object = SceneObject::new(name, ObjectGeometry::new(p));
        object.color = body.color;
        scene.objects.push(object);
    } else {
        for (k, chunk) in body.faces.chunks(MAX_FACES).enumerate() {
            let p = Polysurface::new(chunk.to_vec(), tolerance)
                .map_err(|e| FormatError::new(name.clone(), e.to_string()))?;
            let mut object = SceneObject::new(
                object_name(&format!("{name} part {}", k + 1)),
                ObjectGeometry::new(p),
            );
            object.color = body.color;
            scene.objects.push(object);
        }
    }
    Ok(())
}

/// A STEP model's bodies as scene objects ([`push_body`] each), in millimetres.
pub fn to_scene(model: &StepModel) -> Result<Scene, FormatError> {
    let mut scene = empty_scene();
    let tolerance = join_tolerance(model);
    for body in &model.bodies {
        push_body(&mut scene, body, tolerance)?;
    }
    some_faces(model, &scene)?;
    Ok(scene)
}

/// Refuses a scene with no objects, with the model's first warning.
fn some_faces(model: &StepModel, scene: &Scene) -> Result<(), FormatError> {
    if !scene.objects.is_empty() {
        return Ok(());
    }
    if model.bodies.is_empty() && !model.external_files.is_empty() {
        return Err(FormatError::new(
            "",
            format!(
                "the STEP file holds no geometry of its own: its parts are in other files \
                 ({}); open those",
                model.external_files.join(", ")
            ),
        ));
    }
    let why = model
        .warnings
        .first()
        .map(|w| format!(" ({w})"))
        .unwrap_or_default();
    Err(FormatError::new(
        "",
        format!("the STEP file has no faces knotwork could build{why}"),
    ))
}

fn empty_scene() -> Scene {
    Scene {
        unit: Some(LengthUnit::Millimetre),
        ..Scene::default()
    }
}

/// Where an [`OpenJob`] is.
enum Phase {
    /// Parsing the text, [`PARSE_STEP_INSTANCES`] instances a step.
    Parsing {
        bytes: Vec<u8>,
        parsing: Box<part21::Parsing>,
    },
    /// Parsed: the instances surveyed, [`SURVEY_STEP_INSTANCES`] a step, then the units,
    /// assembly and colours read.
    Surveying(Box<read::Survey>),
    /// Building the placed bodies' faces.
    Reading(Box<read::ReadJob>),
    /// Joining each body's faces into a polysurface.
    Joining {
        model: StepModel,
        scene: Scene,
        next: usize,
        /// The parsed file's instances, still to be freed.
        instances: Vec<(u64, part21::Instance)>,
    },
    /// Between the two, for a moment.
    Empty,
}

/// Instances parsed per step of an [`OpenJob`] (a few milliseconds of a native build's time),
/// on each thread ([`part21::Parsing::step`]).
pub const PARSE_STEP_INSTANCES: usize = 2048;
/// Instances surveyed per step of an [`OpenJob`], on each thread ([`read::Survey::step`]).
const SURVEY_STEP_INSTANCES: usize = 1 << 17;
/// Faces built per step of an [`OpenJob`], on each thread ([`read::ReadJob::step_faces`]).
const FACES_A_STEP: usize = 4;
/// Instances freed per joining step of an [`OpenJob`].
const FREE_STEP_INSTANCES: usize = 65536;

/// A STEP file opened a step at a time, so that the editor can show a progress bar, stay
/// responsive and cancel: the text parsed [`PARSE_STEP_INSTANCES`] instances a thread at a
/// time (the first of them in [`Self::new`], so that a file that is not STEP at all is refused
/// at once), the instances surveyed [`SURVEY_STEP_INSTANCES`] a thread at a time and the
/// units, assembly and colours read, then [`FACES_A_STEP`] faces a thread built and one body
/// joined into a polysurface per [`Self::step`].
pub struct OpenJob {
    phase: Phase,
}

impl OpenJob {
    /// Starts on `bytes` (kept, not copied: a large model's text is tens of megabytes): the
    /// first instances parsed.
    pub fn new(bytes: Vec<u8>) -> Result<Self, FormatError> {
        let mut parsing = Box::new(part21::Parsing::default());
        let done = parsing
            .step(&bytes, PARSE_STEP_INSTANCES)
            .map_err(read::syntax_error)?;
        let phase = if done {
            Phase::Reading(Box::new(read::ReadJob::from_exchange(parsing.finish())?))
        } else {
            Phase::Parsing { bytes, parsing }
        };
        Ok(Self { phase })
    }

    /// What is under way, for the progress bar.
    pub fn stage(&self) -> &'static str {
        match self.phase {
            Phase::Parsing { .. } | Phase::Surveying(_) => "reading the file",
            Phase::Reading(_) => "building faces",
            Phase::Joining { .. } | Phase::Empty => "joining faces along shared edges",
        }
    }

    /// The share done, 0 to 1: parsing and the survey of the instances count for a fifth,
    /// building for three fifths, joining for the rest.
    pub fn progress(&self) -> f64 {
        match &self.phase {
            Phase::Parsing { bytes, parsing } => 0.19 * parsing.fraction(bytes),
            Phase::Surveying(survey) => 0.19 + 0.01 * survey.progress(),
            Phase::Reading(job) => 0.2 + 0.6 * job.progress(),
            Phase::Joining { model, next, .. } => {
                0.8 + 0.2 * *next as f64 / model.bodies.len().max(1) as f64
            }
            Phase::Empty => 0.8,
        }
    }

    /// Some instances parsed, or some faces built, or one body joined; true when every one is
    /// done.
    pub fn step(&mut self) -> Result<bool, FormatError> {
        match &mut self.phase {
            Phase::Parsing { bytes, parsing } => {
                if !parsing
                    .step(bytes, PARSE_STEP_INSTANCES)
                    .map_err(read::syntax_error)?
                {
                    return Ok(false);
                }
                let Phase::Parsing { parsing, .. } =
                    std::mem::replace(&mut self.phase, Phase::Empty)
                else {
                    return Ok(false);
                };
                self.phase = Phase::Surveying(Box::new(read::Survey::new(parsing.finish())));
                Ok(false)
            }
            Phase::Surveying(survey) => {
                if !survey.step(SURVEY_STEP_INSTANCES * crate::kernel::par::threads()) {
                    return Ok(false);
                }
                let Phase::Surveying(survey) = std::mem::replace(&mut self.phase, Phase::Empty)
                else {
                    return Ok(false);
                };
                self.phase = Phase::Reading(Box::new(survey.finish()?));
                Ok(false)
            }
            Phase::Reading(job) => {
                if !job.step_faces(FACES_A_STEP * crate::kernel::par::threads())? {
                    return Ok(false);
                }
                let Phase::Reading(job) = std::mem::replace(&mut self.phase, Phase::Empty) else {
                    return Ok(false);
                };
                let (model, instances) = job.finish_keeping_instances();
                for w in &model.warnings {
                    log::warn!("STEP: {w}");
                }
                self.phase = Phase::Joining {
                    model,
                    scene: empty_scene(),
                    next: 0,
                    instances,
                };
                Ok(false)
            }
            Phase::Empty => Ok(false),
            Phase::Joining {
                model,
                scene,
                next,
                instances,
            } => {
                if let Some(body) = model.bodies.get(*next) {
                    push_body(scene, body, join_tolerance(model))?;
                    *next += 1;
                }
                // The file's instances, freed a share at a time.
                instances.truncate(instances.len().saturating_sub(FREE_STEP_INSTANCES));
                Ok(*next >= model.bodies.len() && instances.is_empty())
            }
        }
    }

    /// What the file could not give (faces skipped, each kind of entity that cost faces with
    /// their count first), once every face is built; empty before.
    pub fn warnings(&self) -> &[String] {
        match &self.phase {
            Phase::Joining { model, .. } => &model.warnings,
            _ => &[],
        }
    }

    /// The document: every body's objects, in millimetres; refused when no face could be
    /// built (with the first warning) or the job was not run to the end.
    pub fn finish(self) -> Result<Project, FormatError> {
        let Phase::Joining {
            model, scene, next, ..
        } = self.phase
        else {
            return Err(FormatError::new("", "cancelled"));
        };
        if next < model.bodies.len() {
            return Err(FormatError::new("", "cancelled"));
        }
        some_faces(&model, &scene)?;
        Ok(Project { scene, view: None })
    }
}

/// How long reading a file and meshing every body took ([`timed_read_and_mesh`]).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct MeshTiming {
    /// Reading the file into bodies of trimmed faces, in milliseconds.
    pub read_ms: f64,
    /// Every body's watertight mesh at `tolerance`.
    pub mesh_ms: f64,
    /// 1e-4 of the diagonal of the faces' box (the benchmark's tolerance).
    pub tolerance: f64,
    pub triangles: usize,
    pub faces: usize,
}

/// Reads `bytes` and meshes every body watertight at 1e-4 of the faces' diagonal, timed by
/// `now_ms`: the figures `knotwork bench --only step` compares with OpenCASCADE, and the
/// page's `benchStepMesh`.
pub fn timed_read_and_mesh(
    bytes: &[u8],
    now_ms: &dyn Fn() -> f64,
) -> Result<MeshTiming, FormatError> {
    let started = now_ms();
    let model = read::read(bytes, &mut |_, _| true)?;
    let read_ms = now_ms() - started;
    let (lo, hi) = model
        .bodies
        .iter()
        .flat_map(|b| b.faces.iter().map(|f| f.surface().bounds()))
        .fold(
            (glam::DVec3::INFINITY, glam::DVec3::NEG_INFINITY),
            |(a, b), (c, d)| (a.min(c), b.max(d)),
        );
    let tolerance = 1e-4 * lo.distance(hi);
    let started = now_ms();
    let mut triangles = 0;
    for b in &model.bodies {
        triangles +=
            crate::kernel::join::tessellate_joined(&b.faces, &b.topology, tolerance, false)
                .map_err(|e| FormatError::new("", format!("{}: {e}", b.name)))?
                .triangles
                .len();
    }
    Ok(MeshTiming {
        read_ms,
        mesh_ms: now_ms() - started,
        tolerance,
        triangles,
        faces: model.bodies.iter().map(|b| b.faces.len()).sum(),
    })
}

/// How long opening a file as the editor does took ([`timed_open`]).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct OpenTiming {
    /// The first step ([`OpenJob::new`]: the first instances parsed), in milliseconds.
    pub first_step_ms: f64,
    /// Every step after it.
    pub steps_ms: f64,
    /// The longest single step: how long the editor's frame can be held up.
    pub longest_step_ms: f64,
    pub steps: usize,
    pub faces: usize,
}

/// Opens `bytes` through an [`OpenJob`] to the end, timed by `now_ms` (the benchmark's and
/// the page's clock), for the figures of `knotwork bench --only step` and the page's
/// `benchStep`.
pub fn timed_open(bytes: Vec<u8>, now_ms: &dyn Fn() -> f64) -> Result<OpenTiming, FormatError> {
    let started = now_ms();
    let mut job = OpenJob::new(bytes)?;
    let parsed = now_ms();
    let (mut steps, mut longest) = (0, 0.0f64);
    loop {
        let before = now_ms();
        let done = job.step()?;
        longest = longest.max(now_ms() - before);
        steps += 1;
        if done {
            break;
        }
    }
    let project = job.finish()?;
    let faces = project
        .scene
        .objects
        .iter()
        .map(|o| o.kind().faces().len())
        .sum();
    Ok(OpenTiming {
        first_step_ms: parsed - started,
        steps_ms: now_ms() - parsed,
        longest_step_ms: longest,
        steps,
        faces,
    })
}

/// Reads a STEP file as a project (lengths in millimetres); `progress(stage, fraction)` now
/// and then, and where it returns false, reading stops with "cancelled".
pub fn read_project(
    bytes: &[u8],
    progress: &mut dyn FnMut(Stage, f64) -> bool,
) -> Result<Project, FormatError> {
    let model = read::read(bytes, progress)?;
    for w in &model.warnings {
        log::warn!("STEP: {w}");
    }
    Ok(Project {
        scene: to_scene(&model)?,
        view: None,
    })
}

/// `knotwork info`: the bodies, faces per surface type, unit, bounding box and warnings as
/// JSON.
pub fn info(bytes: &[u8], self_intersections: bool) -> Result<serde_json::Value, FormatError> {
    let model = read::read(bytes, &mut |_, _| true)?;
    let mut lo = glam::DVec3::splat(f64::INFINITY);
    let mut hi = glam::DVec3::splat(f64::NEG_INFINITY);
    let mut bodies = Vec::new();
    let mut totals: std::collections::BTreeMap<&str, usize> = Default::default();
    for b in &model.bodies {
        let mut types: std::collections::BTreeMap<&str, usize> = Default::default();
        for t in &b.surface_types {
            *types.entry(t).or_insert(0) += 1;
            *totals.entry(t).or_insert(0) += 1;
        }
        for f in &b.faces {
            let (a, c) = f.surface().bounds();
            lo = lo.min(a);
            hi = hi.max(c);
        }
        let mut body = serde_json::json!({
            "name": b.name,
            "faces": b.faces.len(),
            "surfaces": types,
            "closed": b.closed,
            "shared_edges": b.topology.shared.len(),
            "naked_edges": b.topology.naked.len(),
            "color": b.color,
        });
        body["area"] = crate::kernel::mass::area(&b.faces)
            .map_or(serde_json::Value::Null, serde_json::Value::from);
        // Volume and centroid for a closed body (exact: the divergence theorem over the faces).
        let validity = crate::kernel::join::validity(b.faces.len(), &b.topology);
        if b.closed
            && let Ok(m) = crate::kernel::mass::solid_mass_properties(&b.faces, &b.topology)
        {
            body["volume"] = m.volume.into();
            body["centroid"] = serde_json::json!(m.centroid.to_array());
        }
        body["validity"] = super::validity_value(&b.faces, &validity, self_intersections);
        bodies.push(body);
    }
    let faces: usize = model.bodies.iter().map(|b| b.faces.len()).sum();
    Ok(serde_json::json!({
        "schema": model.schema,
        "unit": "mm",
        "file_unit": model.unit_name,
        "millimetres_per_file_unit": model.millimetres_per_unit,
        "bodies": bodies,
        "faces": faces,
        "surfaces": totals,
        "bounding_box": if lo.x.is_finite() {
            serde_json::json!({"min": lo.to_array(), "max": hi.to_array()})
        } else {
            serde_json::Value::Null
        },
        "warnings": model.warnings,
    }))
}

pub use crate::scene::SUBDIVISION_TOLERANCE;

/// The faces of one object as STEP writes them ([`crate::scene::ObjectKind::exchange_faces`]),
/// its note naming the object, or why it is left out.
fn object_faces(
    object: &SceneObject,
    tolerance: f64,
) -> Result<crate::scene::ExchangeFaces, String> {
    if object.displacement.is_some() || object.lattice.is_some() {
        return Err("it is displaced or deformed (bake it first)".into());
    }
    if let Some(faces) = object.kind().exchange_faces(tolerance) {
        let mut faces = faces.map_err(|e| e.to_string())?;
        faces.note = faces.note.map(|note| format!("{}: {note}", object.name));
        return Ok(faces);
    }
    Err(format!(
        "STEP export takes NURBS, trimmed surfaces, polysurfaces, Bézier patch sets, \
         triangular patches and subdivision surfaces, not {}",
        object.kind().kind_name()
    ))
}

/// The STEP writer's default tolerance for `scene`: 1e-6 of its bounding box's diagonal
/// (corners closer than this are one vertex; edge curves are fitted within it).
pub fn default_tolerance(scene: &Scene) -> f64 {
    crate::io::gltf::default_tolerance(scene) * 1e-3
}

/// What [`export_scene`] wrote.
#[derive(Debug, Clone, PartialEq)]
pub struct StepExport {
    /// The STEP file.
    pub text: String,
    /// The objects not written, each with why.
    pub left_out: Vec<String>,
    /// The objects written as an approximation, each with how close it is.
    pub approximated: Vec<String>,
}

/// The visible objects with faces as a STEP file (AP214, in the scene's unit; millimetres
/// for a unitless scene): what was written, and
/// the objects left out with why.
pub fn export_scene(
    scene: &Scene,
    file_name: &str,
    tolerance: f64,
) -> Result<StepExport, FormatError> {
    let mut kept = Vec::new();
    let mut left_out = Vec::new();
    let mut approximated = Vec::new();
    for object in scene.objects.iter().filter(|o| o.visible) {
        if object.kind().space_curve().is_some() {
            continue;
        }
        match object_faces(object, tolerance) {
            Ok(faces) => {
                approximated.extend(faces.note);
                kept.push((
                    object.name.clone(),
                    faces.faces,
                    faces.topology,
                    object.color,
                ))
            }
            Err(why) => left_out.push(format!("{}: {why}", object.name)),
        }
    }
    if kept.is_empty() {
        return Err(FormatError::new(
            "",
            format!(
                "nothing to write as STEP{}",
                if left_out.is_empty() {
                    String::new()
                } else {
                    format!(" ({})", left_out.join("; "))
                }
            ),
        ));
    }
    let shapes: Vec<write::StepShape> = kept
        .iter()
        .map(|(name, faces, topology, color)| write::StepShape {
            name,
            faces,
            topology: topology.as_ref(),
            color: *color,
        })
        .collect();
    let text = write::write(&shapes, file_name, tolerance, scene.unit)
        .map_err(|e| FormatError::new("", e.to_string()))?;
    Ok(StepExport {
        text,
        left_out,
        approximated,
    })
}
