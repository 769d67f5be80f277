//! The project file: knotwork's JSON format ([`super::json`]) extended to a whole scene
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
//! The view is [`ViewSettings`] (`range` and `overlays` may be omitted: the automatic range,
//! everything shown).
//! Transforms are baked into the control points (as Rhino does), so an object needs no
//! transform field. `visible`, `segments`, `name` and `view` may be omitted. Version 1 files
//! (surfaces only, no view) open too; curves are refused with the path of the offending object.
//!
//! Reading is defensive: files above [`MAX_FILE_BYTES`], more than [`MAX_TOTAL_POINTS`]
//! control points, degrees above 32, segments above [`MAX_SEGMENTS`] and anything malformed give
//! a [`FormatError`] naming the JSON path, and nothing is allocated beyond the text itself.

use crate::kernel::subdiv::patches::Display;
use crate::kernel::subdiv::{
    Boundary, Corner, Crease, Creasing, Options, Scheme, SubdivisionSurface,
};
use crate::scene::SubdivObject;
use serde::{Deserialize, Serialize};

use super::json::{self, FormatError, Geometry, NamedGeometry};
use crate::kernel::{BezierPatch, BezierPatchSet, MAX_BEZIER_DEGREE, PolygonMesh};
use crate::scene::{DEFAULT_SEGMENTS, MAX_SEGMENTS, ObjectGeometry, Scene, SceneObject};
pub use crate::view::ViewSettings;

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

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawPatch {
    degree: [usize; 2],
    indices: Vec<u32>,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawPatches {
    #[serde(rename = "type")]
    kind: String,
    points: Vec<Vec<f64>>,
    patches: Vec<RawPatch>,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMesh {
    #[serde(rename = "type")]
    kind: String,
    points: Vec<[f64; 3]>,
    faces: Vec<Vec<u32>>,
}

/// A triangular Bézier patch: its degree and (n + 1)(n + 2)/2 points, row by row (row j holds
/// b_ij for i = 0..=n − j, k = n − i − j).
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawTriangle {
    #[serde(rename = "type")]
    kind: String,
    degree: usize,
    points: Vec<[f64; 3]>,
}

/// A subdivision surface: its cage, creases `[a, b, sharpness]`, corners `[vertex, sharpness]`,
/// rules, level, display and (the adaptive display's) flatness tolerance.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawCage {
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

fn read_cage(path: &str, value: serde_json::Value) -> Result<SubdivObject, FormatError> {
    let raw: RawCage = deserialize(path, value)?;
    let points = raw
        .points
        .iter()
        .map(|&p| glam::DVec3::from_array(p))
        .collect();
    let mesh = PolygonMesh::new(points, &raw.faces).map_err(|e| FormatError::geometry(path, e))?;
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
    let surface = SubdivisionSurface::new(mesh, creases, corners, options, raw.level)
        .map_err(|e| FormatError::geometry(path, e))?;
    let object =
        SubdivObject::checked(surface, raw.display).map_err(|e| FormatError::geometry(path, e))?;
    match raw.tolerance {
        Some(tolerance) => object
            .with_tolerance_checked(tolerance)
            .map_err(|e| FormatError::geometry(path, e)),
        None => Ok(object),
    }
}

fn cage_value(object: &SubdivObject) -> serde_json::Value {
    let surface = &object.surface;
    serde_json::to_value(RawCage {
        kind: "subdivision_surface".into(),
        points: surface.points().iter().map(|p| p.to_array()).collect(),
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
        display: object.display,
        tolerance: (object.display == Display::Adaptive).then_some(object.tolerance),
    })
    .unwrap_or(serde_json::Value::Null)
}

fn deserialize<T: serde::de::DeserializeOwned>(
    path: &str,
    value: serde_json::Value,
) -> Result<T, FormatError> {
    serde_path_to_error::deserialize(value).map_err(|e| json::serde_error(path, e))
}

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
    if let Some(key) = root.keys().next() {
        return Err(FormatError::new(key.clone(), "unknown field"));
    }
    let mut total = 0usize;
    let mut scene = Scene::default();
    for (i, value) in objects.into_iter().enumerate() {
        let path = format!("objects[{i}]");
        let object = read_object(&path, value)?;
        total = total.saturating_add(object.control_point_count());
        if total > MAX_TOTAL_POINTS {
            return Err(FormatError::new(
                path,
                format!("the project has more than {MAX_TOTAL_POINTS} control points"),
            ));
        }
        scene.objects.push(object);
    }
    Ok(Project { scene, view })
}

fn read_object(path: &str, value: serde_json::Value) -> Result<SceneObject, FormatError> {
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
    let kind = map.get("type").and_then(|t| t.as_str()).unwrap_or_default();
    if ![
        "nurbs_surface",
        "bezier_patches",
        "polygon_mesh",
        "subdivision_surface",
        "triangular_bezier",
        "nurbs_curve",
        "trim_curve",
    ]
    .contains(&kind)
    {
        return Err(FormatError::new(
            format!("{path}.type"),
            format!(
                "unknown object type {}: expected \"nurbs_surface\", \"bezier_patches\", \"polygon_mesh\", \"subdivision_surface\" or \"triangular_bezier\"",
                map.get("type")
                    .map_or("(missing)".to_string(), |t| t.to_string())
            ),
        ));
    }
    let is_patches = kind == "bezier_patches";
    let is_mesh = kind == "polygon_mesh";
    let is_cage = kind == "subdivision_surface";
    let is_triangle = kind == "triangular_bezier";
    let value = serde_json::Value::Object(map);
    let geometry = if is_triangle {
        let raw: RawTriangle = deserialize(path, value)?;
        let points = raw
            .points
            .iter()
            .map(|&p| glam::DVec3::from_array(p))
            .collect();
        ObjectGeometry::Triangle(Box::new(
            crate::kernel::triangle::TriangleBezier::new(raw.degree, points)
                .map_err(|e| FormatError::geometry(path, e))?,
        ))
    } else if is_cage {
        ObjectGeometry::Subdivision(Box::new(read_cage(path, value)?))
    } else if is_patches {
        ObjectGeometry::Patches(read_patches(path, value)?)
    } else if is_mesh {
        let raw: RawMesh = deserialize(path, value)?;
        let points = raw
            .points
            .iter()
            .map(|&p| glam::DVec3::from_array(p))
            .collect();
        ObjectGeometry::Mesh(
            PolygonMesh::new(points, &raw.faces)
                .map_err(|e| FormatError::new(path.to_string(), e.to_string()))?,
        )
    } else {
        match json::object_from_value(path, value)?.geometry {
            Geometry::Surface(s) => ObjectGeometry::Nurbs(s),
            Geometry::TrimmedSurface(t) => ObjectGeometry::from_trimmed(t),
            Geometry::Curve(_) | Geometry::Trim(_) => {
                return Err(FormatError::new(
                    format!("{path}.type"),
                    "a curve is not a scene object: knotwork projects hold surfaces",
                ));
            }
        }
    };
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
    Ok(object)
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

fn read_patches(path: &str, value: serde_json::Value) -> Result<BezierPatchSet, FormatError> {
    let raw: RawPatches = deserialize(path, value)?;
    let (cartesian, weights) = json::curve_points(path, &raw.points, 3)?;
    let points = cartesian
        .iter()
        .map(|c| glam::DVec3::new(c[0], c[1], c[2]))
        .collect();
    let mut patches = Vec::with_capacity(raw.patches.len());
    for (k, patch) in raw.patches.into_iter().enumerate() {
        let [du, dv] = patch.degree;
        if !(1..=MAX_BEZIER_DEGREE).contains(&du) || !(1..=MAX_BEZIER_DEGREE).contains(&dv) {
            return Err(FormatError::new(
                format!("{path}.patches[{k}].degree"),
                format!("degree ({du}, {dv}) is outside 1..={MAX_BEZIER_DEGREE}"),
            ));
        }
        patches.push(BezierPatch::new(du, dv, patch.indices));
    }
    BezierPatchSet::new(points, Some(weights), patches).map_err(|e| FormatError::geometry(path, e))
}

/// One scene object as a JSON value.
fn object_value(object: &SceneObject) -> serde_json::Value {
    let mut value = match &object.geometry {
        ObjectGeometry::Nurbs(s) => json::object_value(
            &NamedGeometry {
                name: None,
                geometry: Geometry::Surface(s.clone()),
            },
            true,
        ),
        ObjectGeometry::Trimmed(t) => json::object_value(
            &NamedGeometry {
                name: None,
                geometry: Geometry::TrimmedSurface(t.as_ref().clone()),
            },
            true,
        ),
        ObjectGeometry::Patches(set) => serde_json::to_value(RawPatches {
            kind: "bezier_patches".into(),
            points: set
                .points()
                .iter()
                .zip(set.weights())
                .map(|(p, &w)| vec![p.x, p.y, p.z, w])
                .collect(),
            patches: set
                .patches()
                .iter()
                .map(|p| RawPatch {
                    degree: [p.degree_u(), p.degree_v()],
                    indices: p.indices().to_vec(),
                })
                .collect(),
        })
        .unwrap_or(serde_json::Value::Null),
        ObjectGeometry::Mesh(mesh) => serde_json::to_value(RawMesh {
            kind: "polygon_mesh".into(),
            points: mesh.points().iter().map(|p| p.to_array()).collect(),
            faces: mesh.faces().map(<[u32]>::to_vec).collect(),
        })
        .unwrap_or(serde_json::Value::Null),
        ObjectGeometry::Subdivision(object) => cage_value(object),
        ObjectGeometry::Triangle(patch) => serde_json::to_value(RawTriangle {
            kind: "triangular_bezier".into(),
            degree: patch.degree(),
            points: patch.points().iter().map(|p| p.to_array()).collect(),
        })
        .unwrap_or(serde_json::Value::Null),
    };
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
    }
    value
}

/// The project as JSON text (version [`PROJECT_VERSION`]). f64 values are written in their
/// shortest exact form and surface points homogeneously, so reading gives back the same bits.
pub fn write(project: &Project) -> String {
    serde_json::to_string(&to_value(project)).unwrap_or_default()
}

/// The project as a JSON value (what [`write`] writes).
pub fn to_value(project: &Project) -> serde_json::Value {
    let mut file = serde_json::json!({
        "format": "knotwork",
        "version": PROJECT_VERSION,
        "objects": project.scene.objects.iter().map(object_value).collect::<Vec<_>>(),
    });
    if let (Some(view), serde_json::Value::Object(map)) = (&project.view, &mut file) {
        map.insert(
            "view".into(),
            serde_json::to_value(view).unwrap_or(serde_json::Value::Null),
        );
    }
    file
}
