//! Construct: a transfinite surface built from curves or corner data, or a curve through
//! points or from another curve — the operation `{"op": "construct", "construct": NAME, ...}`.
//! Every curve it reads is a curve object of the scene (`0`, its index, or `{"id": n}`) or a
//! curve given in full (a `nurbs_curve` record, what `knotwork construct` reads); with history
//! kept, a surface built from curve objects follows them. With `"replace": k` the result is
//! object k's new geometry (a curve rebuilt, fitted or extended in place) instead of a new
//! object. `knotwork construct` ([`crate::io::construct`]) builds a request on curves given in
//! full and prints the result.
//!
//! The requests, `c` standing for a curve:
//!
//! - `{"construct": "gordon", "u_curves": [c, ...], "v_curves": [...], "degree": 3}`:
//!   the Gordon surface of the network (u-curves in order of increasing v, v-curves in order of
//!   increasing u; `degree`, default 3, is the interpolation degree across the curves).
//! - `{"construct": "coons", "bottom": c, "top": c, "left": c, "right": c}`:
//!   the bilinearly blended Coons patch; with `"cross": {"bottom": c, "top": c,
//!   "left": c, "right": c}` (S_v along bottom and top, S_u along left and right, the curves'
//!   points read as vectors) the bicubically blended one.
//! - `{"construct": "hermite", "points": [p00, p10, p01, p11], "su": [...], "sv": [...],
//!   "twist": [...]}`: the bicubic Hermite patch (vectors as `[x, y, z]`, corners in the order
//!   (0, 0), (1, 0), (0, 1), (1, 1); `twist` defaults to zero vectors).
//! - `{"construct": "interpolate", "points": [[x, y, z], ...], "degree": 3, "closed": false}`:
//!   the B-spline through every point (The NURBS Book §9.2; `degree` lowered when there are
//!   too few points). Optional `"parametrization"`: `"chord_length"` (the default),
//!   `"centripetal"` or `"uniform"`; `"tangents": [start, end]` for an open curve's end
//!   derivatives. A closed interpolant does not repeat its first point and is C² (C^{p−1})
//!   at the seam.
//! - `{"construct": "catmull_rom", "points": [...], "alpha": 0.5}`: the Catmull-Rom spline
//!   (α = 0 uniform, 0.5 centripetal, the default, 1 chordal; Barry–Goldman) through
//!   points[1] … points[n−2], the first and last points serving as end controls.
//! - `{"construct": "loft", "curves": [...], "degree": 3, "closed": false, "style": "normal"}`:
//!   the loft through the curves (in any direction; closed curves with any seam), degree 1–3
//!   across; `style` `"normal"`, `"straight"` or `"loose"` ([`crate::kernel::loft`]).
//! - `{"construct": "network", "u_curves": [...], "v_curves": [...], "degree": 3}`: the
//!   surface through a network of crossing curves in any order and direction, rational or not
//!   ([`crate::kernel::network`]); the largest deviation from the curves is reported. With
//!   `"curves": [...]` instead, both families in one list, told apart by which curves cross.
//! - `{"construct": "sweep1", "rail": c, "profiles": [c, ...], "up": [x, y, z]}`: the profiles
//!   swept along the rail, in rotation-minimising frames or, with `up`, frames that keep that
//!   direction up; `{"construct": "sweep2", "rails": [c, c], "profiles": [...], "keep_height":
//!   false}`: between two rails ([`crate::kernel::sweep`]).
//! - `{"construct": "revolve", "profile": c, "axis": {"origin": [x, y, z], "direction": [x, y,
//!   z]}, "angle": 360}`: the exact rational surface of revolution, turning right-handed about
//!   `direction` by `angle` degrees (negative turns the other way).
//! - `{"construct": "planar", "boundary": [c, ...]}`: the plane trimmed by the closed planar
//!   chains of curves, in any order (inner loops make holes; [`crate::kernel::planar`]).
//! - `{"construct": "edge", "curves": [c, c(, c, c)]}`: the surface bounded by 2 to 4 edge
//!   curves ([`crate::kernel::edge`]).
//! - `{"construct": "extrude", "curve": c, "direction": [x, y, z]}` or `..., "path": c}`: the
//!   curve moved along a vector or along a path curve (exact).
//! - Curves, each printing an exact `nurbs_curve`: `{"construct": "circle", "center": [...],
//!   "normal": [0, 0, 1], "radius": r, "x_axis": [1, 0, 0]}`, `{"construct": "ellipse", "center",
//!   "normal", "radii": [a, b], "x_axis"}`, `{"construct": "arc", "points": [start, through,
//!   end]}`, `{"construct": "polyline", "points": [...], "closed": false}` and `{"construct":
//!   "hermite_spline", "points": [...], "tangents": [...], "parameters": [...]}` (parameters
//!   default to chord length).
//! - Curve edits, each printing a `nurbs_curve` ([`crate::kernel::fit`],
//!   [`crate::kernel::curve_edit`]): `{"construct": "rebuild", "curve": c, "points": 12,
//!   "degree": 3}`, `{"construct": "fit", "curve": c, "tolerance": 1e-4}` and
//!   `{"construct": "offset", "curve": c, "distance": d, "normal": [x, y, z], "tolerance": t}`
//!   (approximations; the largest deviation is reported), `{"construct": "project", "curve": c,
//!   "plane": {"origin": [...], "normal": [...]}}` and `{"construct": "extend", "curve": c,
//!   "length": l, "end": "end"}` (exact).

use glam::DVec3;
use serde::{Deserialize, Serialize};
use serde_json::Value;

use crate::kernel::curve_edit::{self, CurveEnd};
use crate::kernel::fit;
use crate::kernel::format::join_path;
use crate::kernel::loft::{LoftOptions, LoftStyle, loft_sections};
use crate::kernel::network::network_surface;
use crate::kernel::planar::planar_face;
use crate::kernel::splines::{self, Parametrization};
use crate::kernel::sweep::{SweepFrame, sweep_one_rail, sweep_two_rails};
use crate::kernel::transfinite::{self, HermiteData};
use crate::kernel::{NurbsSurface, SpaceCurve, construct};
use crate::scene::change::{Change, EditError};
use crate::scene::json::{
    FormatError, Geometry, NamedGeometry, object_from_value, object_to_value,
};
use crate::scene::operation::{
    ObjectRef, Operation, OperationEntry, OperationParams, Planned, entry,
};
use crate::scene::{ObjectGeometry, Scene, SceneObject, valid_name};

/// What to build, one variant per `"construct"` name; the fields are the request's.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase", deny_unknown_fields)]
pub enum Request {
    Gordon {
        u_curves: Vec<CurveInput>,
        v_curves: Vec<CurveInput>,
        #[serde(default = "default_degree")]
        degree: usize,
    },
    Coons {
        bottom: CurveInput,
        top: CurveInput,
        left: CurveInput,
        right: CurveInput,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        cross: Option<Sides>,
    },
    Hermite {
        points: Box<[[f64; 3]; 4]>,
        su: Box<[[f64; 3]; 4]>,
        sv: Box<[[f64; 3]; 4]>,
        #[serde(default)]
        twist: Box<[[f64; 3]; 4]>,
    },
    Interpolate {
        points: Vec<[f64; 3]>,
        #[serde(default = "default_degree")]
        degree: usize,
        #[serde(default)]
        closed: bool,
        #[serde(default)]
        parametrization: ParametrizationName,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        tangents: Option<[[f64; 3]; 2]>,
    },
    #[serde(rename = "catmull_rom")]
    CatmullRom {
        points: Vec<[f64; 3]>,
        #[serde(default = "default_alpha")]
        alpha: f64,
    },
    Loft {
        curves: Vec<CurveInput>,
        #[serde(default = "default_degree")]
        degree: usize,
        #[serde(default)]
        closed: bool,
        #[serde(default)]
        style: LoftStyleName,
    },
    Network {
        #[serde(default)]
        u_curves: Vec<CurveInput>,
        #[serde(default)]
        v_curves: Vec<CurveInput>,
        /// Both families in one list, in any order: told apart by which cross which.
        #[serde(default)]
        curves: Vec<CurveInput>,
        #[serde(default = "default_degree")]
        degree: usize,
    },
    Sweep1 {
        rail: CurveInput,
        profiles: Vec<CurveInput>,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        up: Option<[f64; 3]>,
    },
    Sweep2 {
        rails: [CurveInput; 2],
        profiles: Vec<CurveInput>,
        #[serde(default)]
        keep_height: bool,
    },
    Revolve {
        profile: CurveInput,
        axis: Axis,
        #[serde(default = "default_angle")]
        angle: f64,
    },
    Planar {
        boundary: Vec<CurveInput>,
    },
    Edge {
        curves: Vec<CurveInput>,
    },
    Extrude {
        curve: CurveInput,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        direction: Option<[f64; 3]>,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        path: Option<CurveInput>,
    },
    Circle {
        center: [f64; 3],
        #[serde(default = "default_normal")]
        normal: [f64; 3],
        radius: f64,
        #[serde(default = "default_x_axis")]
        x_axis: [f64; 3],
    },
    Ellipse {
        center: [f64; 3],
        #[serde(default = "default_normal")]
        normal: [f64; 3],
        radii: [f64; 2],
        #[serde(default = "default_x_axis")]
        x_axis: [f64; 3],
    },
    Arc {
        points: [[f64; 3]; 3],
    },
    Polyline {
        points: Vec<[f64; 3]>,
        #[serde(default)]
        closed: bool,
    },
    #[serde(rename = "hermite_spline")]
    HermiteSpline {
        points: Vec<[f64; 3]>,
        tangents: Vec<[f64; 3]>,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        parameters: Option<Vec<f64>>,
    },
    Rebuild {
        curve: CurveInput,
        points: usize,
        #[serde(default = "default_degree")]
        degree: usize,
    },
    Fit {
        curve: CurveInput,
        tolerance: f64,
    },
    Offset {
        curve: CurveInput,
        distance: f64,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        normal: Option<[f64; 3]>,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        tolerance: Option<f64>,
    },
    Project {
        curve: CurveInput,
        plane: Plane,
    },
    Extend {
        curve: CurveInput,
        length: f64,
        #[serde(default)]
        end: EndName,
    },
}

/// A plane: a point on it and its normal.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Plane {
    pub origin: [f64; 3],
    pub normal: [f64; 3],
}

/// Which end of a curve an extension grows from.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EndName {
    Start,
    #[default]
    End,
}

/// A loft's style, as a request names it.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LoftStyleName {
    #[default]
    Normal,
    Straight,
    Loose,
}

impl From<LoftStyleName> for LoftStyle {
    fn from(name: LoftStyleName) -> Self {
        match name {
            LoftStyleName::Normal => LoftStyle::Normal,
            LoftStyleName::Straight => LoftStyle::Straight,
            LoftStyleName::Loose => LoftStyle::Loose,
        }
    }
}

/// An axis of revolution.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Axis {
    pub origin: [f64; 3],
    pub direction: [f64; 3],
}

fn default_angle() -> f64 {
    360.0
}

fn default_normal() -> [f64; 3] {
    [0.0, 0.0, 1.0]
}

fn default_x_axis() -> [f64; 3] {
    [1.0, 0.0, 0.0]
}

/// How an interpolant's parameters are spaced, as a request names it.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ParametrizationName {
    #[default]
    ChordLength,
    Centripetal,
    Uniform,
}

impl From<ParametrizationName> for Parametrization {
    fn from(name: ParametrizationName) -> Self {
        match name {
            ParametrizationName::ChordLength => Parametrization::ChordLength,
            ParametrizationName::Centripetal => Parametrization::Centripetal,
            ParametrizationName::Uniform => Parametrization::Uniform,
        }
    }
}

fn default_alpha() -> f64 {
    0.5
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Sides {
    pub bottom: CurveInput,
    pub top: CurveInput,
    pub left: CurveInput,
    pub right: CurveInput,
}

fn default_degree() -> usize {
    3
}

/// A curve a construction reads: a curve object of the scene, or a curve given in full.
#[derive(Debug, Clone, PartialEq)]
pub enum CurveInput {
    /// A curve object: its index (`2`) or, in history, its id (`{"id": n}`).
    Object(ObjectRef),
    /// A curve given in full, as a `nurbs_curve` record.
    Given(Box<SpaceCurve>),
}

impl From<usize> for CurveInput {
    fn from(index: usize) -> Self {
        CurveInput::Object(index.into())
    }
}

impl Serialize for CurveInput {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        match self {
            CurveInput::Object(object) => object.serialize(serializer),
            CurveInput::Given(curve) => object_to_value(&NamedGeometry {
                name: None,
                geometry: Geometry::Curve((**curve).clone()),
            })
            .serialize(serializer),
        }
    }
}

impl<'de> Deserialize<'de> for CurveInput {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        read_curve_input("", Value::deserialize(deserializer)?).map_err(serde::de::Error::custom)
    }
}

/// Reads a curve input at JSON path `path`: a curve object's index, `{"id": n}`, or a
/// `nurbs_curve` record.
fn read_curve_input(path: &str, value: Value) -> Result<CurveInput, FormatError> {
    if value.is_number() || value.get("id").is_some() {
        return crate::scene::record::deserialize(path, value).map(CurveInput::Object);
    }
    if value.get("input").is_some() {
        return Err(FormatError::new(
            path,
            "{\"input\": k} names the k-th picked curve, which only the page's construct(request, \
             objects) takes: give the curve object's index here",
        ));
    }
    match object_from_value(path, value)?.geometry {
        Geometry::Curve(c) => Ok(CurveInput::Given(Box::new(c))),
        _ => Err(FormatError::new(
            join_path(path, "type"),
            "expected \"nurbs_curve\" or a curve object's index",
        )),
    }
}

/// The construct operation: the request, and the object whose geometry the result becomes
/// (`"replace": k`; it keeps its name and settings) or `None` for a new object named after
/// what was built.
#[derive(Debug, Clone, PartialEq)]
pub struct Construct {
    pub request: Request,
    pub replace: Option<ObjectRef>,
}

impl Construct {
    /// A new object built by `request`.
    pub fn new(request: Request) -> Self {
        Self {
            request,
            replace: None,
        }
    }

    /// Reads `{"construct": NAME, ...fields, "replace": k?}` (an `"op"` is ignored) at JSON path
    /// `path`; a refusal names the bad field's path.
    pub fn read(path: &str, value: Value) -> Result<Self, FormatError> {
        let expected = "expected a construction: {\"construct\": NAME, ...}";
        let Value::Object(mut map) = value else {
            return Err(FormatError::new(path, expected));
        };
        map.remove("op");
        let replace = match map.remove("replace") {
            None | Some(Value::Null) => None,
            Some(v) => Some(crate::scene::record::deserialize(
                &join_path(path, "replace"),
                v,
            )?),
        };
        let name = match map.remove("construct") {
            Some(Value::String(name)) => name,
            Some(other) => {
                return Err(FormatError::new(
                    join_path(path, "construct"),
                    format!("expected a construction's name, found {other}"),
                ));
            }
            None => return Err(FormatError::new(path, expected)),
        };
        // Read as the externally tagged enum, so that the path of an error inside a variant
        // is kept (an internally tagged one buffers its fields and loses it).
        let tagged = Value::Object(serde_json::Map::from_iter([(
            name.clone(),
            Value::Object(map),
        )]));
        let request = serde_path_to_error::deserialize(tagged).map_err(|e| {
            let at = e.path().to_string();
            let field = match at.strip_prefix(name.as_str()) {
                Some(rest) if !rest.trim_start_matches('.').is_empty() => {
                    join_path(path, rest.trim_start_matches('.'))
                }
                Some(_) => path.to_owned(),
                None => join_path(path, "construct"),
            };
            FormatError::new(field, e.into_inner().to_string())
        })?;
        Ok(Self { request, replace })
    }

    /// Reads a request whose curves are references `{"input": k}` to `objects[k]` (the page's
    /// `construct(request, objects)` and projects saved before constructions were
    /// operations); refused, at JSON path `path`, when a reference has no object or an object
    /// is not referred to.
    pub fn with_inputs(
        path: &str,
        request: Value,
        objects: &[ObjectRef],
    ) -> Result<Self, FormatError> {
        let mut request = request;
        let mut used = vec![false; objects.len()];
        let mut bad = None;
        replace_references(&mut request, &mut |k| match objects.get(k) {
            Some(object) => {
                used[k] = true;
                serde_json::to_value(object).ok()
            }
            None => {
                bad.get_or_insert(k);
                None
            }
        });
        if let Some(k) = bad {
            return Err(FormatError::new(
                path,
                format!("refers to input {k}; there are {}", objects.len()),
            ));
        }
        if let Some(k) = used.iter().position(|u| !u) {
            return Err(FormatError::new(
                path,
                format!("does not use input {k} (object {:?})", objects[k]),
            ));
        }
        Self::read(path, request)
    }

    /// The request's `"construct"` ("loft", "sweep1", …).
    pub fn name(&self) -> String {
        match serde_json::to_value(&self.request) {
            Ok(Value::Object(map)) => map.keys().next().cloned(),
            _ => None,
        }
        .unwrap_or_else(|| "construction".into())
    }

    /// The curves it reads, in the request's order.
    pub fn inputs(&self) -> Vec<CurveInput> {
        let mut copy = self.request.clone();
        copy.inputs_mut().into_iter().map(|c| c.clone()).collect()
    }

    /// Builds what the request describes, each curve it reads given by `curve` (called with
    /// the curve's JSON path in the request). A malformed request names the offending path;
    /// a construction that fails (curves that do not meet, …) gives the kernel's reason.
    pub fn build(
        &self,
        curve: &dyn Fn(&str, &CurveInput) -> Result<SpaceCurve, FormatError>,
    ) -> Result<Built, FormatError> {
        build_request(&self.request, &Inputs { curve })
    }
}

impl Serialize for Construct {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::Error;
        let tagged = serde_json::to_value(&self.request).map_err(S::Error::custom)?;
        let Value::Object(tagged) = tagged else {
            return Err(S::Error::custom("a request is written as an object"));
        };
        let mut map = serde_json::Map::new();
        for (name, fields) in tagged {
            map.insert("construct".into(), Value::String(name));
            if let Value::Object(fields) = fields {
                map.extend(fields);
            }
        }
        if let Some(replace) = &self.replace {
            map.insert(
                "replace".into(),
                serde_json::to_value(replace).map_err(S::Error::custom)?,
            );
        }
        Value::Object(map).serialize(serializer)
    }
}

impl<'de> Deserialize<'de> for Construct {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        Self::read("", Value::deserialize(deserializer)?).map_err(serde::de::Error::custom)
    }
}

impl OperationParams for Construct {
    const NAME: &'static str = "construct";

    /// "loft from 3 curve(s)", or the request's name alone for one in place or from points.
    fn label(&self) -> String {
        let count = self.inputs().len();
        match (self.replace, count) {
            (None, 1..) => format!("{} from {count} curve(s)", self.name()),
            _ => self.name(),
        }
    }

    fn title(&self) -> String {
        self.name()
    }

    fn objects_mut(&mut self) -> Vec<&mut ObjectRef> {
        let mut objects: Vec<&mut ObjectRef> = self
            .request
            .inputs_mut()
            .into_iter()
            .filter_map(|c| match c {
                CurveInput::Object(object) => Some(object),
                CurveInput::Given(_) => None,
            })
            .collect();
        objects.extend(self.replace.as_mut());
        objects
    }

    /// The built object added (named after what it is, made unique) or, with `replace`, put
    /// in that object's place; the report, where the construction measures how well it fits
    /// its input (a network's or a fit's largest deviation): `{"summary": line}`, also added
    /// to the label.
    fn plan_with_report(&self, scene: &Scene) -> Result<(Planned, Option<Value>), EditError> {
        let built = self
            .build(&|path, input| scene_curve(scene, path, input))
            .map_err(|e| EditError::Geometry {
                name: self.name(),
                source: crate::kernel::GeometryError::Construction {
                    what: "construction",
                    message: e.to_string(),
                },
            })?;
        let geometry = match built.geometry {
            Geometry::Surface(s) => ObjectGeometry::new(s),
            Geometry::TrimmedSurface(t) => ObjectGeometry::from_trimmed(t),
            Geometry::Curve(c) => ObjectGeometry::new(c),
            Geometry::Trim(_) => {
                return Err(EditError::Geometry {
                    name: self.name(),
                    source: crate::kernel::GeometryError::Construction {
                        what: "construction",
                        message: "a trim curve is not a scene object".into(),
                    },
                });
            }
        };
        let mut label = OperationParams::label(self);
        if let Some(report) = &built.report {
            label = format!("{label} — {report}");
        }
        let report = built
            .report
            .map(|line| serde_json::json!({ "summary": line }));
        let change = match self.replace {
            Some(object) => {
                let index = scene.resolve(object)?;
                let before = &scene.objects[index];
                let after = SceneObject {
                    geometry,
                    ..before.clone()
                };
                after
                    .decompose()
                    .map_err(crate::doc::geometry_error(before))?;
                Change::Replace {
                    index,
                    before: before.clone(),
                    after,
                }
            }
            None => {
                let base = if valid_name(built.name) {
                    built.name
                } else {
                    "surface"
                };
                let object = SceneObject::new(scene.unique_name(base), geometry);
                object
                    .decompose()
                    .map_err(crate::doc::geometry_error(&object))?;
                Change::Insert {
                    index: scene.objects.len(),
                    object,
                }
            }
        };
        Ok(((vec![change], label), report))
    }
}

/// Curve input `input` (at JSON path `path` of the request) from `scene`: a curve object's
/// curve as it is now, or the curve given in full.
fn scene_curve(scene: &Scene, path: &str, input: &CurveInput) -> Result<SpaceCurve, FormatError> {
    match input {
        CurveInput::Given(curve) => Ok((**curve).clone()),
        CurveInput::Object(object) => {
            let index = scene
                .resolve(*object)
                .map_err(|e| FormatError::new(path, e.to_string()))?;
            let found = &scene.objects[index];
            found.kind().space_curve().cloned().ok_or_else(|| {
                FormatError::new(
                    path,
                    format!(
                        "{} is {}, not a curve",
                        found.name,
                        found.kind().kind_name()
                    ),
                )
            })
        }
    }
}

/// Reads the operation's JSON value with the path of whatever is wrong ([`Construct::read`]).
fn read_entry(path: &str, value: Value) -> Result<Operation, FormatError> {
    Construct::read(path, value).map(Operation::new)
}

pub const ENTRY: OperationEntry = OperationEntry {
    read: read_entry,
    own_panel: true,
    ..entry::<Construct>(
        "a surface or curve built from curves (loft, sweep, network, revolve, …) or points",
        |scene, selection| {
            let curves = selection.iter().all(|&k| {
                scene
                    .objects
                    .get(k)
                    .is_some_and(|o| o.kind().space_curve().is_some())
            });
            (selection.len() >= 2 && curves).then(|| {
                Operation::new(Construct::new(Request::Loft {
                    curves: selection.iter().map(|&k| k.into()).collect(),
                    degree: default_degree(),
                    closed: false,
                    style: LoftStyleName::Normal,
                }))
            })
        },
    )
};

/// Replaces each `{"input": k}` in `value` by what `with` gives for k (left as it is on `None`).
fn replace_references(value: &mut Value, with: &mut dyn FnMut(usize) -> Option<Value>) {
    let reference = value.as_object().and_then(|map| match map.len() {
        1 => map.get("input")?.as_u64(),
        _ => None,
    });
    if let Some(k) = reference {
        if let Some(replacement) = with(k as usize) {
            *value = replacement;
        }
        return;
    }
    match value {
        Value::Array(items) => items.iter_mut().for_each(|v| replace_references(v, with)),
        Value::Object(map) => map.values_mut().for_each(|v| replace_references(v, with)),
        _ => {}
    }
}

impl Request {
    /// The curves the request reads, in the request's order.
    fn inputs_mut(&mut self) -> Vec<&mut CurveInput> {
        let mut all: Vec<&mut CurveInput> = Vec::new();
        match self {
            Request::Gordon {
                u_curves, v_curves, ..
            } => all.extend(u_curves.iter_mut().chain(v_curves)),
            Request::Coons {
                bottom,
                top,
                left,
                right,
                cross,
            } => {
                all.extend([bottom, top, left, right]);
                if let Some(s) = cross {
                    all.extend([&mut s.bottom, &mut s.top, &mut s.left, &mut s.right]);
                }
            }
            Request::Loft { curves, .. }
            | Request::Edge { curves }
            | Request::Planar { boundary: curves } => all.extend(curves),
            Request::Network {
                u_curves,
                v_curves,
                curves,
                ..
            } => all.extend(u_curves.iter_mut().chain(v_curves).chain(curves)),
            Request::Sweep1 { rail, profiles, .. } => {
                all.push(rail);
                all.extend(profiles);
            }
            Request::Sweep2 {
                rails, profiles, ..
            } => all.extend(rails.iter_mut().chain(profiles)),
            Request::Revolve { profile, .. } => all.push(profile),
            Request::Extrude { curve, path, .. } => {
                all.push(curve);
                all.extend(path);
            }
            Request::Rebuild { curve, .. }
            | Request::Fit { curve, .. }
            | Request::Offset { curve, .. }
            | Request::Project { curve, .. }
            | Request::Extend { curve, .. } => all.push(curve),
            Request::Hermite { .. }
            | Request::Interpolate { .. }
            | Request::CatmullRom { .. }
            | Request::Circle { .. }
            | Request::Ellipse { .. }
            | Request::Arc { .. }
            | Request::Polyline { .. }
            | Request::HermiteSpline { .. } => {}
        }
        all
    }
}

/// The curves a request reads, given by the caller: a document's curve objects, or curves
/// given in full.
struct Inputs<'a> {
    curve: &'a dyn Fn(&str, &CurveInput) -> Result<SpaceCurve, FormatError>,
}

impl Inputs<'_> {
    /// The curve at `path` of the request.
    fn one(&self, path: &str, input: CurveInput) -> Result<SpaceCurve, FormatError> {
        (self.curve)(path, &input)
    }

    /// The curves of the list at `path`.
    fn many(&self, path: &str, inputs: Vec<CurveInput>) -> Result<Vec<SpaceCurve>, FormatError> {
        inputs
            .into_iter()
            .enumerate()
            .map(|(k, c)| self.one(&format!("{path}[{k}]"), c))
            .collect()
    }

    /// The four sides (bottom, top, left, right) at `path`.
    fn sides(&self, path: &str, s: Sides) -> Result<[SpaceCurve; 4], FormatError> {
        let at = |name: &str| join_path(path, name);
        Ok([
            self.one(&at("bottom"), s.bottom)?,
            self.one(&at("top"), s.top)?,
            self.one(&at("left"), s.left)?,
            self.one(&at("right"), s.right)?,
        ])
    }
}

/// A construction's refusal as the request's error (it concerns the request as a whole).
fn geometry(e: crate::kernel::GeometryError) -> FormatError {
    FormatError::new("", e.to_string())
}

/// What a request built: the geometry, its name, and a line about how well it fits its input
/// (a network's largest deviation from its curves).
pub struct Built {
    pub geometry: Geometry,
    pub name: &'static str,
    pub report: Option<String>,
}

impl Built {
    fn plain((geometry, name): (Geometry, &'static str)) -> Self {
        Self {
            geometry,
            name,
            report: None,
        }
    }
}

/// Builds what `request` describes, its curves given by `inputs`.
fn build_request(request: &Request, inputs: &Inputs) -> Result<Built, FormatError> {
    let points = |raw: &[[f64; 3]]| -> Vec<DVec3> { raw.iter().map(|&p| DVec3::from(p)).collect() };
    match request.clone() {
        Request::Interpolate {
            points: raw,
            degree,
            closed,
            parametrization,
            tangents,
        } => {
            let q = points(&raw);
            let how = parametrization.into();
            let curve = match (closed, tangents) {
                (true, Some(_)) => {
                    return Err(FormatError::new(
                        "tangents",
                        "a closed interpolant has no end tangents",
                    ));
                }
                (true, None) => splines::interpolate_closed(&q, degree, how),
                (false, t) => {
                    let ends = t.map(|[a, b]| (DVec3::from(a), DVec3::from(b)));
                    splines::interpolate_through(&q, degree, how, ends)
                }
            };
            curve
                .map(|c| Built::plain((Geometry::Curve(c), "interpolated curve")))
                .map_err(geometry)
        }
        Request::CatmullRom { points: raw, alpha } => splines::catmull_rom(&points(&raw), alpha)
            .map(|c| Built::plain((Geometry::Curve(c), "Catmull-Rom spline")))
            .map_err(geometry),
        Request::Network {
            u_curves,
            v_curves,
            curves: mixed,
            degree,
        } => {
            let (us, vs) = if mixed.is_empty() {
                (
                    inputs.many("u_curves", u_curves)?,
                    inputs.many("v_curves", v_curves)?,
                )
            } else if u_curves.is_empty() && v_curves.is_empty() {
                let all = inputs.many("curves", mixed)?;
                let (u, v) = crate::kernel::network::families(&all).map_err(geometry)?;
                let pick = |ks: &[usize]| ks.iter().map(|&k| all[k].clone()).collect::<Vec<_>>();
                (pick(&u), pick(&v))
            } else {
                return Err(FormatError::new(
                    "curves",
                    "give either \"curves\" or \"u_curves\" and \"v_curves\"",
                ));
            };
            let network = network_surface(&us, &vs, degree).map_err(geometry)?;
            Ok(Built {
                geometry: Geometry::Surface(network.surface),
                name: "network surface",
                report: Some(format!("network: {}", network.deviation)),
            })
        }
        Request::Planar { boundary } => {
            let chain = inputs.many("boundary", boundary)?;
            planar_face(&chain)
                .map(|face| Built::plain((Geometry::TrimmedSurface(face), "planar face")))
                .map_err(geometry)
        }
        Request::Circle {
            center,
            normal,
            radius,
            x_axis,
        } => construct::circle(
            DVec3::from(center),
            DVec3::from(normal),
            DVec3::from(x_axis),
            radius,
        )
        .map(|c| Built::plain((Geometry::Curve(c), "circle")))
        .map_err(geometry),
        Request::Ellipse {
            center,
            normal,
            radii,
            x_axis,
        } => construct::ellipse(
            DVec3::from(center),
            DVec3::from(normal),
            DVec3::from(x_axis),
            radii,
        )
        .map(|c| Built::plain((Geometry::Curve(c), "ellipse")))
        .map_err(geometry),
        Request::Arc { points: [a, b, c] } => {
            construct::arc_through(DVec3::from(a), DVec3::from(b), DVec3::from(c))
                .map(|c| Built::plain((Geometry::Curve(c), "arc")))
                .map_err(geometry)
        }
        Request::Polyline {
            points: raw,
            closed,
        } => {
            let mut q = points(&raw);
            if closed && let Some(&first) = q.first() {
                q.push(first);
            }
            construct::polyline(&q)
                .map(|c| Built::plain((Geometry::Curve(c), "polyline")))
                .map_err(geometry)
        }
        Request::HermiteSpline {
            points: raw,
            tangents,
            parameters,
        } => {
            let q = points(&raw);
            let params = match parameters {
                Some(p) => p,
                None => splines::parameters(&q, Parametrization::ChordLength, "Hermite spline")
                    .map_err(geometry)?,
            };
            splines::hermite_spline(&q, &points(&tangents), &params)
                .map(|c| Built::plain((Geometry::Curve(c), "Hermite spline")))
                .map_err(geometry)
        }
        Request::Rebuild {
            curve: raw,
            points,
            degree,
        } => {
            let c = inputs.one("curve", raw)?;
            let rebuilt = fit::rebuild(&c, points, degree).map_err(geometry)?;
            Ok(rebuilt_curve(rebuilt, "rebuilt curve"))
        }
        Request::Fit {
            curve: raw,
            tolerance,
        } => {
            let c = inputs.one("curve", raw)?;
            let fitted = fit::fit(&c, tolerance).map_err(geometry)?;
            Ok(rebuilt_curve(fitted, "fitted curve"))
        }
        Request::Offset {
            curve: raw,
            distance,
            normal,
            tolerance,
        } => {
            let c = inputs.one("curve", raw)?;
            let size = crate::kernel::curve::control_box_size([&c]);
            let tolerance = tolerance.unwrap_or(1e-6 * (size + distance.abs()));
            let offset = fit::offset_planar(&c, distance, normal.map(DVec3::from), tolerance)
                .map_err(geometry)?;
            Ok(rebuilt_curve(offset, "offset curve"))
        }
        Request::Project { curve: raw, plane } => {
            let c = inputs.one("curve", raw)?;
            curve_edit::projected_onto_plane(
                &c,
                DVec3::from(plane.origin),
                DVec3::from(plane.normal),
            )
            .map(|c| Built::plain((Geometry::Curve(c), "projected curve")))
            .map_err(geometry)
        }
        Request::Extend {
            curve: raw,
            length,
            end,
        } => {
            let c = inputs.one("curve", raw)?;
            let end = match end {
                EndName::Start => CurveEnd::Start,
                EndName::End => CurveEnd::End,
            };
            curve_edit::extended(&c, length, end)
                .map(|c| Built::plain((Geometry::Curve(c), "extended curve")))
                .map_err(geometry)
        }
        surface => build_surface(surface, inputs)
            .map(|(s, name)| Built::plain((Geometry::Surface(s), name))),
    }
}

/// A rebuilt, fitted or offset curve, with its largest deviation as the report.
fn rebuilt_curve(rebuilt: fit::Rebuilt, name: &'static str) -> Built {
    let p = rebuilt.at;
    Built {
        report: Some(format!(
            "{name}: {} points, largest deviation {:.3e} near ({:.6}, {:.6}, {:.6})",
            rebuilt.curve.count(),
            rebuilt.deviation,
            p.x,
            p.y,
            p.z
        )),
        geometry: Geometry::Curve(rebuilt.curve),
        name,
    }
}

/// A surface request's surface and name.
fn build_surface(
    request: Request,
    inputs: &Inputs,
) -> Result<(NurbsSurface, &'static str), FormatError> {
    match request {
        Request::Gordon {
            u_curves,
            v_curves,
            degree,
        } => {
            let us = inputs.many("u_curves", u_curves)?;
            let vs = inputs.many("v_curves", v_curves)?;
            transfinite::gordon(&us, &vs, degree)
                .map(|s| (s, "Gordon surface"))
                .map_err(geometry)
        }
        Request::Coons {
            bottom,
            top,
            left,
            right,
            cross,
        } => {
            let [b, t, l, r] = inputs.sides(
                "",
                Sides {
                    bottom,
                    top,
                    left,
                    right,
                },
            )?;
            match cross {
                None => construct::coons(&b, &t, &l, &r)
                    .map(|s| (s, "Coons patch"))
                    .map_err(geometry),
                Some(cross) => {
                    let [db, dt, dl, dr] = inputs.sides("cross", cross)?;
                    transfinite::bicubic_coons([&b, &t, &l, &r], [&db, &dt, &dl, &dr])
                        .map(|s| (s, "bicubic Coons patch"))
                        .map_err(geometry)
                }
            }
        }
        Request::Hermite {
            points,
            su,
            sv,
            twist,
        } => {
            let v = |a: [[f64; 3]; 4]| a.map(DVec3::from);
            transfinite::hermite_patch(&HermiteData {
                points: v(*points),
                su: v(*su),
                sv: v(*sv),
                twist: v(*twist),
            })
            .map(|s| (s, "Hermite patch"))
            .map_err(geometry)
        }
        Request::Loft {
            curves: raw,
            degree,
            closed,
            style,
        } => {
            let sections = inputs.many("curves", raw)?;
            let options = LoftOptions {
                degree,
                closed,
                style: style.into(),
                align: true,
            };
            loft_sections(&sections, &options)
                .map(|s| (s, "loft"))
                .map_err(geometry)
        }
        Request::Extrude {
            curve: raw,
            direction,
            path,
        } => {
            let c = inputs.one("curve", raw)?;
            match (direction, path) {
                (Some(d), None) => construct::extrude(&c, DVec3::from(d)),
                (None, Some(p)) => construct::extrude_along(&c, &inputs.one("path", p)?),
                _ => {
                    return Err(FormatError::new(
                        "construct",
                        "an extrusion takes a \"direction\" or a \"path\", one of them",
                    ));
                }
            }
            .map(|s| (s, "extrusion"))
            .map_err(geometry)
        }
        Request::Edge { curves: raw } => {
            let edges = inputs.many("curves", raw)?;
            crate::kernel::edge::edge_surface(&edges)
                .map(|s| (s, "edge surface"))
                .map_err(geometry)
        }
        Request::Sweep1 { rail, profiles, up } => {
            let rail = inputs.one("rail", rail)?;
            let profiles = inputs.many("profiles", profiles)?;
            let frame = up.map_or(SweepFrame::RotationMinimizing, |u| {
                SweepFrame::FixedUp(DVec3::from(u))
            });
            sweep_one_rail(&rail, &profiles, frame)
                .map(|s| (s, "sweep"))
                .map_err(geometry)
        }
        Request::Sweep2 {
            rails,
            profiles,
            keep_height,
        } => {
            let [r0, r1] = rails;
            let rails = [inputs.one("rails[0]", r0)?, inputs.one("rails[1]", r1)?];
            let profiles = inputs.many("profiles", profiles)?;
            sweep_two_rails([&rails[0], &rails[1]], &profiles, keep_height)
                .map(|s| (s, "two-rail sweep"))
                .map_err(geometry)
        }
        Request::Revolve {
            profile,
            axis,
            angle,
        } => {
            let profile = inputs.one("profile", profile)?;
            if !(angle.is_finite() && angle != 0.0 && angle.abs() <= 360.0) {
                return Err(FormatError::new(
                    "angle",
                    format!("{angle} must be a number of degrees in [-360, 360], not 0"),
                ));
            }
            // A negative angle turns the other way: about the reversed axis.
            let direction = DVec3::from(axis.direction) * angle.signum();
            construct::revolve(
                &profile,
                DVec3::from(axis.origin),
                direction,
                angle.abs().to_radians(),
            )
            .map(|s| (s, "revolution"))
            .map_err(geometry)
        }
        Request::Interpolate { .. }
        | Request::CatmullRom { .. }
        | Request::Network { .. }
        | Request::Planar { .. }
        | Request::Rebuild { .. }
        | Request::Fit { .. }
        | Request::Offset { .. }
        | Request::Project { .. }
        | Request::Extend { .. }
        | Request::Circle { .. }
        | Request::Ellipse { .. }
        | Request::Arc { .. }
        | Request::Polyline { .. }
        | Request::HermiteSpline { .. } => Err(FormatError::new(
            "construct",
            "this request does not build an untrimmed surface",
        )),
    }
}
