//! The project file: knotwork's JSON format ([`crate::scene::json`]) extended to a whole scene
//! (version 2).
//!
//! ```json
//! {"format": "knotwork", "version": 2,
//!  "objects": [
//!    {"type": "nurbs_surface", "name": "Torus", "visible": true, "segments": 16,
//!     "homogeneous": true, "degree": [2, 2], "knots": [[...], [...]], "points": [[[wx, wy, wz, w], ...], ...]},
//!    {"type": "bezier_patches", "name": "Utah teapot", "visible": true, "segments": 12,
//!     "points": [[x, y, z, w], ...], "patches": [{"degree": [3, 3], "indices": [...]}, ...]},
//!    {"type": "polygon_mesh", "name": "Cage", "visible": true, "segments": 1,
//!     "points": [[x, y, z], ...], "faces": [[0, 1, 2, 3], [3, 2, 4], ...]}],
//!  "view": {"target": [x, y, z], "distance": d, "yaw": a, "pitch": b,
//!           "shading": "gaussian", "quality": 1.0, "range": [-0.5, 0.5],
//!           "overlays": {"surface": true, "net": true, "points": false}}}
//! ```
//! `"unit"` (`"mm"`, `"cm"`, `"m"`, `"in"` or `"ft"`) is the length unit of every coordinate;
//! without it a project is unitless. An object's `"color"` is `[r, g, b]` (sRGB, 0 to 1).
//! The view is [`ViewSettings`] (`range` and `overlays` may be omitted: the automatic range,
//! everything shown).
//! Transforms are baked into the control points (as Rhino does), so an object needs no
//! transform field. `visible`, `segments`, `name` and `view` may be omitted. Version 1 files
//! (surfaces only, no view) open too; curves are refused with the path of the offending object.
//!
//! An object made with history keeps `"history": {"operation": {"op": ..., its inputs by
//! their index in the file}, "output": k}` (a loft of curves 0 to 2 is `{"op": "construct",
//! "construct": "loft", "curves": [0, 1, 2]}`). Projects saved before constructions from
//! curves were operations keep `"construction": {"request": …{"input": k}…, "inputs":
//! [names]}` instead; they open as that `construct` history, on the first object of each name.
//!
//! Reading is defensive: files above [`MAX_FILE_BYTES`], more than [`MAX_TOTAL_POINTS`]
//! control points, degrees above 32, segments above [`MAX_SEGMENTS`] and anything malformed give
//! a [`FormatError`] naming the JSON path, and nothing is allocated beyond the text itself.

use crate::scene::json::{self, FormatError};
use crate::scene::registry;
use crate::scene::{
    DEFAULT_SEGMENTS, LengthUnit, MAX_SEGMENTS, ObjectGeometry, Scene, SceneObject,
};
use crate::view::ViewSettings;

/// The project format version this build writes and the newest it reads.
pub const PROJECT_VERSION: u32 = 2;
/// The largest project file opened (bytes): about 1.5 million rational control points, and a
/// bound on the memory a hostile file can make the reader use (about 1 GiB while parsing).
pub const MAX_FILE_BYTES: usize = 64 * 1024 * 1024;
/// The most control points in one project, over all objects.
pub const MAX_TOTAL_POINTS: usize = json::MAX_CONTROL_POINTS;

/// A project: the scene and, if saved with one, the view.
#[derive(Debug, Clone, PartialEq)]
pub struct Project {
    pub scene: Scene,
    pub view: Option<ViewSettings>,
}

use registry::deserialize;

/// Refuses a file of `bytes` bytes above [`MAX_FILE_BYTES`] (before it is read, where the
/// size is known first).
pub fn check_size(bytes: u64) -> Result<(), FormatError> {
    if bytes > MAX_FILE_BYTES as u64 {
        return Err(FormatError::new(
            "",
            format!(
                "the file is {} MiB; knotwork opens projects up to {} MiB",
                bytes / (1024 * 1024),
                MAX_FILE_BYTES / (1024 * 1024)
            ),
        ));
    }
    Ok(())
}

/// Reads a project from JSON text.
pub fn read(text: &str) -> Result<Project, FormatError> {
    check_size(text.len() as u64)?;
    let value: serde_json::Value = serde_json::from_str(text)
        .map_err(|e| FormatError::new("", format!("not valid JSON: {e}")))?;
    read_value(value)
}

/// Reads a project from a parsed JSON value (the text of [`read`], or the model embedded in a
/// glTF file).
pub fn read_value(value: serde_json::Value) -> Result<Project, FormatError> {
    let serde_json::Value::Object(mut root) = value else {
        return Err(FormatError::new(
            "",
            "expected a JSON object with \"format\": \"knotwork\"",
        ));
    };
    match root.remove("format") {
        Some(serde_json::Value::String(f)) if f == "knotwork" => {}
        Some(other) => {
            return Err(FormatError::new(
                "format",
                format!("expected \"knotwork\", found {other}"),
            ));
        }
        None => {
            return Err(FormatError::new(
                "format",
                "missing: this is not a knotwork project",
            ));
        }
    }
    let version = root
        .remove("version")
        .ok_or_else(|| FormatError::new("version", "missing"))?;
    let version = version.as_u64().ok_or_else(|| {
        FormatError::new(
            "version",
            format!("expected a whole number, found {version}"),
        )
    })?;
    if version == 0 || version > u64::from(PROJECT_VERSION) {
        return Err(FormatError::new(
            "version",
            format!(
                "version {version} is not supported: this build of knotwork reads versions 1 to {PROJECT_VERSION} (a newer knotwork wrote it?)"
            ),
        ));
    }
    let objects = match root.remove("objects") {
        Some(serde_json::Value::Array(objects)) => objects,
        Some(other) => {
            return Err(FormatError::new(
                "objects",
                format!("expected an array, found {other}"),
            ));
        }
        None => return Err(FormatError::new("objects", "missing")),
    };
    let view = match root.remove("view") {
        Some(v) if version >= 2 => Some(deserialize::<ViewSettings>("view", v)?),
        Some(_) => return Err(FormatError::new("view", "version 1 files have no view")),
        None => None,
    };
    let unit = match root.remove("unit") {
        None | Some(serde_json::Value::Null) => None,
        Some(serde_json::Value::String(symbol)) if LengthUnit::from_symbol(&symbol).is_some() => {
            LengthUnit::from_symbol(&symbol)
        }
        Some(other) => {
            let known: Vec<&str> = LengthUnit::ALL.iter().map(|u| u.symbol()).collect();
            return Err(FormatError::new(
                "unit",
                format!(
                    "expected one of \"{}\", found {other}",
                    known.join("\", \"")
                ),
            ));
        }
    };
    if let Some(key) = root.keys().next() {
        return Err(FormatError::new(key.clone(), "unknown field"));
    }
    let mut total = 0usize;
    let mut scene = Scene {
        unit,
        ..Scene::default()
    };
    let mut constructions = Vec::with_capacity(objects.len());
    for (i, value) in objects.into_iter().enumerate() {
        let path = format!("objects[{i}]");
        let (object, construction) = read_object(&path, value)?;
        constructions.push(construction);
        total = total.saturating_add(object.control_point_count());
        if total > MAX_TOTAL_POINTS {
            return Err(FormatError::new(
                path,
                format!("the project has more than {MAX_TOTAL_POINTS} control points"),
            ));
        }
        scene.objects.push(object);
    }
    for (k, construction) in constructions.into_iter().enumerate() {
        if let Some(construction) = construction {
            scene.objects[k].recipe = Some(saved_construction(&scene, k, construction)?);
        }
    }
    // Histories name their inputs by position in the file; the document keeps them by id.
    for k in 0..scene.objects.len() {
        if let Some(recipe) = &scene.objects[k].recipe {
            let operation = recipe.operation.by_id(&scene).map_err(|e| {
                FormatError::new(format!("objects[{k}].history.operation"), e.to_string())
            })?;
            if let Some(recipe) = &mut scene.objects[k].recipe {
                recipe.operation = operation;
            }
        }
    }
    Ok(Project { scene, view })
}

/// Object `k`'s construction as an earlier build saved it, as the `construct` operation's
/// history on the objects its input names name (the first of each name, as that build read it).
fn saved_construction(
    scene: &Scene,
    k: usize,
    construction: SavedConstruction,
) -> Result<crate::scene::operation::Recipe, FormatError> {
    let at = format!("objects[{k}].construction");
    let objects = construction
        .inputs
        .iter()
        .enumerate()
        .map(|(j, name)| {
            scene
                .objects
                .iter()
                .position(|o| &o.name == name)
                .map(crate::scene::operation::ObjectRef::Index)
                .ok_or_else(|| {
                    FormatError::new(
                        format!("{at}.inputs[{j}]"),
                        format!("no object is named \"{name}\""),
                    )
                })
        })
        .collect::<Result<Vec<_>, _>>()?;
    let operation = crate::ops::construct::Construct::with_inputs(
        &format!("{at}.request"),
        construction.request,
        &objects,
    )?;
    Ok(crate::scene::operation::Recipe {
        operation: crate::scene::operation::Operation::new(operation),
        output: 0,
    })
}

/// An operation's history as a project keeps it: `{"operation": {"op": ..., its inputs by
/// their index in the file}, "output": k}`.
#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct RecipeRecord {
    operation: serde_json::Value,
    #[serde(default)]
    output: usize,
}

fn read_recipe(
    path: &str,
    value: serde_json::Value,
) -> Result<crate::scene::operation::Recipe, FormatError> {
    let raw: RecipeRecord = deserialize(path, value)?;
    let operation = crate::ops::from_value(&format!("{path}.operation"), raw.operation)?;
    if let Some(bad) = operation
        .objects()
        .into_iter()
        .find(|r| matches!(r, crate::scene::operation::ObjectRef::Id(_)))
    {
        return Err(FormatError::new(
            format!("{path}.operation"),
            format!("names an object by {bad:?}; a file names objects by index"),
        ));
    }
    Ok(crate::scene::operation::Recipe {
        operation,
        output: raw.output,
    })
}

/// A construction from curve objects as projects saved it before constructions were operations:
/// `{"request": …{"input": k}…, "inputs": [names]}`, the k-th input being the first object of
/// that name. Read into the `construct` operation's history once every object is read.
#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct SavedConstruction {
    request: serde_json::Value,
    inputs: Vec<String>,
}

fn read_object(
    path: &str,
    value: serde_json::Value,
) -> Result<(SceneObject, Option<SavedConstruction>), FormatError> {
    let serde_json::Value::Object(mut map) = value else {
        return Err(FormatError::new(path, "expected an object"));
    };
    let visible = match map.remove("visible") {
        None => true,
        Some(serde_json::Value::Bool(b)) => b,
        Some(other) => {
            return Err(FormatError::new(
                format!("{path}.visible"),
                format!("expected true or false, found {other}"),
            ));
        }
    };
    let segments = match map.remove("segments") {
        None => DEFAULT_SEGMENTS,
        Some(s) => match s.as_u64() {
            Some(n) if (1..=u64::from(MAX_SEGMENTS)).contains(&n) => n as u32,
            _ => {
                return Err(FormatError::new(
                    format!("{path}.segments"),
                    format!("expected a whole number in 1..={MAX_SEGMENTS}, found {s}"),
                ));
            }
        },
    };
    let displacement = match map.remove("displacement") {
        None | Some(serde_json::Value::Null) => None,
        Some(mut value) => {
            let at = format!("{path}.displacement");
            // An image pattern's PNG, as base64 (`super::height_image`).
            let image = match value.as_object_mut().and_then(|m| m.remove("image")) {
                None => None,
                Some(serde_json::Value::String(text)) => Some(std::sync::Arc::new(
                    super::height_image::from_base64(&text)
                        .map_err(|e| FormatError::new(format!("{at}.image"), e))?,
                )),
                Some(other) => {
                    return Err(FormatError::new(
                        format!("{at}.image"),
                        format!("expected a base64 PNG, found {other}"),
                    ));
                }
            };
            let mut raw: crate::kernel::displace::Displacement = deserialize(&at, value)?;
            raw.image = image;
            Some(raw.checked().map_err(|e| FormatError::geometry(&at, e))?)
        }
    };
    let lattice = match map.remove("lattice") {
        None | Some(serde_json::Value::Null) => None,
        Some(value) => {
            let at = format!("{path}.lattice");
            let raw: LatticeRecord = deserialize(&at, value)?;
            Some(raw.lattice().map_err(|e| FormatError::geometry(&at, e))?)
        }
    };
    let construction = match map.remove("construction") {
        None | Some(serde_json::Value::Null) => None,
        Some(value) => Some(deserialize(&format!("{path}.construction"), value)?),
    };
    let recipe = match map.remove("history") {
        None | Some(serde_json::Value::Null) => None,
        Some(value) => Some(read_recipe(&format!("{path}.history"), value)?),
    };
    let color = match map.remove("color") {
        None | Some(serde_json::Value::Null) => None,
        Some(value) => Some(read_color(&format!("{path}.color"), value)?),
    };
    let name = match map.remove("name") {
        None => None,
        Some(serde_json::Value::String(n)) if crate::scene::valid_name(&n) => Some(n),
        Some(other) => {
            return Err(FormatError::new(
                format!("{path}.name"),
                format!(
                    "expected a name of 1 to {} characters, found {other}",
                    crate::scene::MAX_NAME_LENGTH
                ),
            ));
        }
    };
    let geometry = read_kind(path, map)?;
    if displacement.is_some() && geometry.displacement_domain().is_none() {
        return Err(FormatError::new(
            format!("{path}.displacement"),
            format!(
                "{} has no (u, v) domain to map heights on",
                geometry.kind().kind_name()
            ),
        ));
    }
    let mut object = SceneObject::new(name.unwrap_or_else(|| format!("Object {path}")), geometry);
    object.visible = visible;
    object.segments = segments;
    object.displacement = displacement;
    object.lattice = lattice;
    object.recipe = recipe;
    object.color = color;
    Ok((object, construction))
}

/// An object's colour: `[r, g, b]`, sRGB components from 0 to 1.
fn read_color(path: &str, value: serde_json::Value) -> Result<[f32; 3], FormatError> {
    let refuse = |found: &serde_json::Value| {
        FormatError::new(
            path,
            format!("expected [r, g, b] with each from 0 to 1, found {found}"),
        )
    };
    let serde_json::Value::Array(items) = &value else {
        return Err(refuse(&value));
    };
    if items.len() != 3 {
        return Err(refuse(&value));
    }
    let mut rgb = [0f32; 3];
    for (c, item) in rgb.iter_mut().zip(items) {
        match item.as_f64() {
            Some(x) if (0.0..=1.0).contains(&x) => *c = x as f32,
            _ => return Err(refuse(&value)),
        }
    }
    Ok(rgb)
}

/// An object's free-form deformation lattice in the project file: the box's corner and edges,
/// the degrees (l, m, n) and the (l + 1)(m + 1)(n + 1) points, P_ijk at (i (m + 1) + j)(n + 1) + k.
#[derive(serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct LatticeRecord {
    origin: [f64; 3],
    axes: [[f64; 3]; 3],
    degrees: [usize; 3],
    points: Vec<[f64; 3]>,
    /// Objects whose lattices are equal, group included, share one lattice.
    #[serde(default)]
    group: u64,
}

impl LatticeRecord {
    fn from_lattice(lattice: &crate::kernel::ffd::Lattice) -> Self {
        Self {
            origin: lattice.origin().to_array(),
            axes: lattice.axes().map(|a| a.to_array()),
            degrees: lattice.degrees(),
            points: lattice.points().iter().map(|p| p.to_array()).collect(),
            group: lattice.group(),
        }
    }

    /// The lattice, validated ([`crate::kernel::ffd::Lattice::new`]).
    fn lattice(&self) -> Result<crate::kernel::ffd::Lattice, crate::kernel::GeometryError> {
        crate::kernel::ffd::Lattice::new(
            glam::DVec3::from(self.origin),
            self.axes.map(glam::DVec3::from),
            self.degrees,
            self.points.iter().map(|&p| glam::DVec3::from(p)).collect(),
        )
        .map(|l| l.with_group(self.group))
    }
}

/// The kind's part of an object's record, read by the kind registered for its `"type"`
/// ([`crate::scene::registry`]).
fn read_kind(
    path: &str,
    map: serde_json::Map<String, serde_json::Value>,
) -> Result<ObjectGeometry, FormatError> {
    let record_type = map.get("type").and_then(|t| t.as_str()).unwrap_or_default();
    if let Some(kind) = registry::kind_of_record(record_type) {
        return (kind.read)(path, serde_json::Value::Object(map));
    }
    if record_type == "trim_curve" {
        return Err(FormatError::new(
            format!("{path}.type"),
            "a trim curve is not a scene object: it belongs in a surface's \"trims\"",
        ));
    }
    let known: Vec<String> = registry::kinds()
        .iter()
        .map(|k| format!("\"{}\"", k.record_type))
        .collect();
    Err(FormatError::new(
        format!("{path}.type"),
        format!(
            "unknown object type {}: expected one of {}",
            map.get("type")
                .map_or("(missing)".to_string(), |t| t.to_string()),
            known.join(", ")
        ),
    ))
}

/// One scene object as a JSON value: its kind's record ([`crate::scene::ObjectKind::record`])
/// with the object's name, visibility, segments, displacement, lattice, colour and history.
fn object_value(scene: &Scene, object: &SceneObject) -> serde_json::Value {
    let mut value = object.kind().record();
    if let serde_json::Value::Object(map) = &mut value {
        map.insert("name".into(), object.name.clone().into());
        map.insert("visible".into(), object.visible.into());
        map.insert("segments".into(), object.segments.into());
        if let Some(d) = &object.displacement {
            let mut value = serde_json::to_value(d).unwrap_or(serde_json::Value::Null);
            if let (Some(image), serde_json::Value::Object(fields)) = (&d.image, &mut value) {
                fields.insert("image".into(), super::height_image::to_base64(image).into());
            }
            map.insert("displacement".into(), value);
        }
        if let Some(lattice) = &object.lattice {
            map.insert(
                "lattice".into(),
                serde_json::to_value(LatticeRecord::from_lattice(lattice))
                    .unwrap_or(serde_json::Value::Null),
            );
        }
        if let Some(color) = object.color {
            map.insert("color".into(), serde_json::json!(color));
        }
        // An input gone from the scene has ended the history already (the document ends it
        // when one is removed); one that is not found is not written.
        if let Some(Ok(operation)) = object.recipe.as_ref().map(|r| r.operation.by_index(scene)) {
            map.insert(
                "history".into(),
                serde_json::json!({
                    "operation": operation.to_json(),
                    "output": object.recipe.as_ref().map_or(0, |r| r.output),
                }),
            );
        }
    }
    value
}

/// The project as JSON text (version [`PROJECT_VERSION`]). f64 values are written in their
/// shortest exact form and surface points homogeneously, so reading gives back the same bits.
pub fn write(project: &Project) -> String {
    write_scene(&project.scene, project.view.as_ref())
}

/// [`write`] for a scene and view held apart (the open document's, without copying them).
pub fn write_scene(scene: &Scene, view: Option<&ViewSettings>) -> String {
    serde_json::to_string(&scene_value(scene, view)).unwrap_or_default()
}

/// The project as a JSON value (what [`write`] writes).
pub fn to_value(project: &Project) -> serde_json::Value {
    scene_value(&project.scene, project.view.as_ref())
}

fn scene_value(scene: &Scene, view: Option<&ViewSettings>) -> serde_json::Value {
    let mut file = serde_json::json!({
        "format": "knotwork",
        "version": PROJECT_VERSION,
        "objects": scene
            .objects
            .iter()
            .map(|o| object_value(scene, o))
            .collect::<Vec<_>>(),
    });
    if let (Some(unit), serde_json::Value::Object(map)) = (scene.unit, &mut file) {
        map.insert("unit".into(), unit.symbol().into());
    }
    if let (Some(view), serde_json::Value::Object(map)) = (view, &mut file) {
        map.insert(
            "view".into(),
            serde_json::to_value(view).unwrap_or(serde_json::Value::Null),
        );
    }
    file
}
