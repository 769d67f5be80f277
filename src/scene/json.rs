//! knotwork's JSON format for curves and surfaces (version 1), the seed of the project format.
//!
//! A surface:
//! ```json
//! {"type": "nurbs_surface", "degree": [p, q], "knots": [[u0, ...], [v0, ...]],
//!  "points": [[[x, y, z, w], ...], ...]}
//! ```
//! `points[i][j]` has i along u and j along v; x, y, z are Cartesian (not multiplied by w); the
//! knot vectors are complete (count + degree + 1 entries each). A point may omit w (`[x, y, z]`
//! means w = 1). A space curve is `{"type": "nurbs_curve", "degree": p, "knots": [...],
//! "points": [[x, y, z, w], ...]}` and a trim curve (in a surface's (u, v) plane)
//! `{"type": "trim_curve", "degree": p, "knots": [...], "points": [[u, v, w], ...]}`.
//!
//! A surface may carry trim loops in its (u, v) domain: `"trims": [[<trim_curve>, ...], ...]`,
//! each loop a list of trim curves joined end to end (the kept region is inside an odd number of
//! loops; see [`crate::kernel::trim`]).
//!
//! A file is `{"format": "knotwork", "version": 1, "objects": [<object>, ...]}`; each object
//! may carry a `"name"`. Readers accept a bare object too. Every error names the JSON path of
//! the offending value (`objects[0].knots[1][4]: ...`) and nothing panics.

use glam::DVec3;
use serde::{Deserialize, Serialize};

use crate::kernel::vector::{CurvePoint, Vector};
use crate::kernel::{NurbsCurve, NurbsSurface, SpaceCurve, TrimCurve, TrimmedSurface};

/// The format version this build writes and the newest it reads.
pub const FORMAT_VERSION: u32 = 1;

/// The most control points one object may have (a hostile file cannot make knotwork allocate
/// without bound beyond what the JSON text itself holds).
pub const MAX_CONTROL_POINTS: usize = 10_000_000;

pub use crate::kernel::FormatError;
use crate::kernel::format::join_path as join;

/// One geometric object of a file.
#[derive(Debug, Clone, PartialEq)]
pub enum Geometry {
    Surface(NurbsSurface),
    /// A surface with trim loops (a file's surface without `"trims"` reads as [`Self::Surface`]).
    TrimmedSurface(TrimmedSurface),
    Curve(SpaceCurve),
    Trim(TrimCurve),
}

/// An object with its (optional) name.
#[derive(Debug, Clone, PartialEq)]
pub struct NamedGeometry {
    pub name: Option<String>,
    pub geometry: Geometry,
}

/// A surface as written in a file (`"type": "nurbs_surface"`).
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSurface {
    #[serde(rename = "type")]
    kind: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    name: Option<String>,
    degree: [usize; 2],
    knots: [Vec<f64>; 2],
    /// `true`: points are `[wx, wy, wz, w]` (already multiplied by w), so rational surfaces
    /// round-trip bit for bit; project files write this form.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    homogeneous: bool,
    points: Vec<Vec<Vec<f64>>>,
    /// Trim loops: lists of `trim_curve` objects.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    trims: Vec<Vec<RawCurve>>,
}

/// A curve as written in a file (`"type": "nurbs_curve"` or `"trim_curve"`).
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawCurve {
    #[serde(rename = "type")]
    kind: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    name: Option<String>,
    degree: usize,
    knots: Vec<f64>,
    /// `true`: points are `[w·x, w·y, (w·z,) w]`, so rational curves round-trip bit for bit;
    /// project files write trim curves this way.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    homogeneous: bool,
    points: Vec<Vec<f64>>,
}

enum RawObject {
    NurbsSurface(RawSurface),
    NurbsCurve(RawCurve),
    TrimCurve(RawCurve),
}

const TYPES: &str = "\"nurbs_surface\", \"nurbs_curve\" or \"trim_curve\"";

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawFile {
    format: String,
    version: u32,
    objects: Vec<serde_json::Value>,
}

/// Splits `[x, y, (z,) w?]` into coordinates and weight; `dim` Cartesian coordinates.
fn split_point(path: &str, values: &[f64], dim: usize) -> Result<(Vec<f64>, f64), FormatError> {
    let names = if dim == 3 {
        "[x, y, z, w]"
    } else {
        "[u, v, w]"
    };
    match values.len() {
        n if n == dim => Ok((values.to_vec(), 1.0)),
        n if n == dim + 1 => Ok((values[..dim].to_vec(), values[dim])),
        n => Err(FormatError::new(
            path,
            format!(
                "expected {} numbers {names} (w may be omitted), found {n}",
                dim + 1
            ),
        )),
    }
}

fn convert(path: &str, raw: RawObject) -> Result<NamedGeometry, FormatError> {
    match raw {
        RawObject::NurbsSurface(RawSurface {
            name,
            degree,
            knots,
            points,
            homogeneous,
            trims,
            ..
        }) => {
            let count = [points.len(), points.first().map_or(0, Vec::len)];
            if count[0].saturating_mul(count[1]) > MAX_CONTROL_POINTS {
                return Err(FormatError::new(
                    join(path, "points"),
                    format!("more than {MAX_CONTROL_POINTS} control points"),
                ));
            }
            let mut cartesian = Vec::with_capacity(count[0] * count[1]);
            let mut weights = Vec::with_capacity(count[0] * count[1]);
            for (i, row) in points.iter().enumerate() {
                if row.len() != count[1] {
                    return Err(FormatError::new(
                        join(path, &format!("points[{i}]")),
                        format!(
                            "row has {} points but row 0 has {}; the net must be rectangular",
                            row.len(),
                            count[1]
                        ),
                    ));
                }
                for (j, p) in row.iter().enumerate() {
                    let (c, w) = split_point(&join(path, &format!("points[{i}][{j}]")), p, 3)?;
                    cartesian.push(DVec3::new(c[0], c[1], c[2]));
                    weights.push(w);
                }
            }
            let surface = if homogeneous {
                let points = cartesian
                    .iter()
                    .zip(&weights)
                    .map(|(p, &w)| p.extend(w))
                    .collect();
                NurbsSurface::from_homogeneous(degree, knots, count, points)
            } else {
                NurbsSurface::new(degree, knots, count, cartesian, Some(weights))
            }
            .map_err(|e| FormatError::geometry(path, e))?;
            if trims.is_empty() {
                return Ok(NamedGeometry {
                    name,
                    geometry: Geometry::Surface(surface),
                });
            }
            let mut loops = Vec::with_capacity(trims.len());
            for (l, raw_loop) in trims.into_iter().enumerate() {
                let mut curves = Vec::with_capacity(raw_loop.len());
                for (c, raw) in raw_loop.into_iter().enumerate() {
                    let at = join(path, &format!("trims[{l}][{c}]"));
                    if raw.kind != "trim_curve" {
                        return Err(FormatError::new(
                            join(&at, "type"),
                            format!("expected \"trim_curve\", found {:?}", raw.kind),
                        ));
                    }
                    curves.push(curve_from(&at, raw)?);
                }
                loops.push(curves);
            }
            let trimmed =
                TrimmedSurface::new(surface, loops).map_err(|e| FormatError::geometry(path, e))?;
            Ok(NamedGeometry {
                name,
                geometry: Geometry::TrimmedSurface(trimmed),
            })
        }
        RawObject::NurbsCurve(raw) => Ok(NamedGeometry {
            name: raw.name.clone(),
            geometry: Geometry::Curve(curve_from(path, raw)?),
        }),
        RawObject::TrimCurve(raw) => Ok(NamedGeometry {
            name: raw.name.clone(),
            geometry: Geometry::Trim(curve_from(path, raw)?),
        }),
    }
}

/// A 2D or 3D curve from its raw form; points are `[x, y, (z,) w?]`.
fn curve_from<P: CurvePoint>(path: &str, raw: RawCurve) -> Result<NurbsCurve<P>, FormatError> {
    let (cartesian, weights) = curve_points(path, &raw.points, P::DIMENSION)?;
    let points = cartesian
        .iter()
        .map(|c| P::from_coordinates(c).ok_or_else(|| FormatError::new(path, "bad point")))
        .collect::<Result<Vec<P>, _>>()?;
    if raw.homogeneous {
        let homogeneous = points
            .iter()
            .zip(&weights)
            .map(|(p, &w)| {
                let mut c = p.coordinates();
                c.push(w);
                P::Homogeneous::from_coordinates(&c)
                    .ok_or_else(|| FormatError::new(path, "bad point"))
            })
            .collect::<Result<Vec<_>, _>>()?;
        return NurbsCurve::from_homogeneous(raw.degree, raw.knots, homogeneous)
            .map_err(|e| FormatError::geometry(path, e));
    }
    NurbsCurve::new(raw.degree, raw.knots, points, Some(weights))
        .map_err(|e| FormatError::geometry(path, e))
}

pub type PointsAndWeights = (Vec<Vec<f64>>, Vec<f64>);

pub fn curve_points(
    path: &str,
    points: &[Vec<f64>],
    dim: usize,
) -> Result<PointsAndWeights, FormatError> {
    if points.len() > MAX_CONTROL_POINTS {
        return Err(FormatError::new(
            join(path, "points"),
            format!("more than {MAX_CONTROL_POINTS} control points"),
        ));
    }
    let mut cartesian = Vec::with_capacity(points.len());
    let mut weights = Vec::with_capacity(points.len());
    for (i, p) in points.iter().enumerate() {
        let (c, w) = split_point(&join(path, &format!("points[{i}]")), p, dim)?;
        cartesian.push(c);
        weights.push(w);
    }
    Ok((cartesian, weights))
}

pub fn serde_error(
    prefix: &str,
    error: serde_path_to_error::Error<serde_json::Error>,
) -> FormatError {
    let inner = error.path().to_string();
    let path = if inner == "." { String::new() } else { inner };
    let full = match (prefix.is_empty(), path.is_empty()) {
        (_, true) => prefix.to_string(),
        (true, false) => path,
        (false, false) => join(prefix, &path),
    };
    FormatError::new(full, error.into_inner().to_string())
}

/// Reads one object from a parsed JSON value; `path` names it in errors.
pub fn object_from_value(
    path: &str,
    value: serde_json::Value,
) -> Result<NamedGeometry, FormatError> {
    if !value.is_object() {
        return Err(FormatError::new(
            path,
            format!(
                "expected an object with a \"type\" field, found {}",
                json_kind(&value)
            ),
        ));
    }
    let kind = match value.get("type") {
        Some(serde_json::Value::String(kind)) => kind.clone(),
        Some(other) => {
            return Err(FormatError::new(
                join(path, "type"),
                format!("expected {TYPES}, found {}", json_kind(other)),
            ));
        }
        None => {
            return Err(FormatError::new(
                path,
                format!("missing field `type` ({TYPES})"),
            ));
        }
    };
    let surface = |v| serde_path_to_error::deserialize(v).map_err(|e| serde_error(path, e));
    let curve = |v| serde_path_to_error::deserialize(v).map_err(|e| serde_error(path, e));
    let raw = match kind.as_str() {
        "nurbs_surface" => RawObject::NurbsSurface(surface(value)?),
        "nurbs_curve" => RawObject::NurbsCurve(curve(value)?),
        "trim_curve" => RawObject::TrimCurve(curve(value)?),
        other => {
            return Err(FormatError::new(
                join(path, "type"),
                format!("unknown object type {other:?}: expected {TYPES}"),
            ));
        }
    };
    convert(path, raw)
}

/// Reads a file (or a bare object) from JSON text.
pub fn read(text: &str) -> Result<Vec<NamedGeometry>, FormatError> {
    let value: serde_json::Value = serde_json::from_str(text)
        .map_err(|e| FormatError::new("", format!("not valid JSON: {e}")))?;
    let is_file = value.get("format").is_some() || value.get("objects").is_some();
    if !is_file {
        return Ok(vec![object_from_value("", value)?]);
    }
    let file: RawFile = serde_path_to_error::deserialize(value).map_err(|e| serde_error("", e))?;
    if file.format != "knotwork" {
        return Err(FormatError::new(
            "format",
            format!("expected \"knotwork\", found {:?}", file.format),
        ));
    }
    if file.version == 0 || file.version > FORMAT_VERSION {
        return Err(FormatError::new(
            "version",
            format!(
                "version {} is not supported: this build of knotwork reads versions 1 to {FORMAT_VERSION}",
                file.version
            ),
        ));
    }
    file.objects
        .into_iter()
        .enumerate()
        .map(|(i, value)| object_from_value(&format!("objects[{i}]"), value))
        .collect()
}

fn raw_from(object: &NamedGeometry, homogeneous: bool) -> RawObject {
    let name = object.name.clone();
    let (surface, trims) = match &object.geometry {
        Geometry::Surface(s) => (s, Vec::new()),
        Geometry::TrimmedSurface(t) => (
            t.surface(),
            t.loops()
                .iter()
                .map(|l| {
                    l.iter()
                        .map(|c| raw_curve_in("trim_curve", None, c, homogeneous))
                        .collect()
                })
                .collect(),
        ),
        Geometry::Curve(c) => return RawObject::NurbsCurve(raw_curve("nurbs_curve", name, c)),
        Geometry::Trim(c) => return RawObject::TrimCurve(raw_curve("trim_curve", name, c)),
    };
    let s = surface;
    let [cu, cv] = s.count();
    let h = s.homogeneous_points();
    let points = (0..cu)
        .map(|i| {
            (0..cv)
                .map(|j| {
                    if homogeneous {
                        h[i * cv + j].to_array().to_vec()
                    } else {
                        let p = s.control_point(i, j);
                        vec![p.x, p.y, p.z, s.weight(i, j)]
                    }
                })
                .collect()
        })
        .collect();
    let [ku, kv] = s.knots();
    RawObject::NurbsSurface(RawSurface {
        kind: "nurbs_surface".into(),
        name,
        degree: s.degree(),
        knots: [ku.to_vec(), kv.to_vec()],
        homogeneous,
        points,
        trims,
    })
}

/// A 2D or 3D curve in its raw form: points `[x, y, (z,) w]`.
fn raw_curve<P: CurvePoint>(kind: &str, name: Option<String>, c: &NurbsCurve<P>) -> RawCurve {
    raw_curve_in(kind, name, c, false)
}

/// [`raw_curve`]; `homogeneous` writes `[w·x, ..., w]`.
fn raw_curve_in<P: CurvePoint>(
    kind: &str,
    name: Option<String>,
    c: &NurbsCurve<P>,
    homogeneous: bool,
) -> RawCurve {
    RawCurve {
        kind: kind.into(),
        name,
        degree: c.degree(),
        knots: c.knots().to_vec(),
        homogeneous,
        points: (0..c.count())
            .map(|i| {
                if homogeneous {
                    c.homogeneous_points()[i].coordinates()
                } else {
                    let mut v = c.control_point(i).coordinates();
                    v.push(c.weight(i));
                    v
                }
            })
            .collect(),
    }
}

/// One object as a JSON value (the `"surface"` of an eval request, an entry of a file).
pub fn object_to_value(object: &NamedGeometry) -> serde_json::Value {
    object_value(object, false)
}

/// One object as a JSON value; `homogeneous` writes surface points as `[wx, wy, wz, w]`.
pub fn object_value(object: &NamedGeometry, homogeneous: bool) -> serde_json::Value {
    let value = match raw_from(object, homogeneous) {
        RawObject::NurbsSurface(s) => serde_json::to_value(s),
        RawObject::NurbsCurve(c) | RawObject::TrimCurve(c) => serde_json::to_value(c),
    };
    value.unwrap_or(serde_json::Value::Null)
}

/// A whole file, pretty-printed. f64 values are written with the shortest representation that
/// reads back to the same bits, so a round trip is exact.
pub fn write(objects: &[NamedGeometry]) -> String {
    let file = serde_json::json!({
        "format": "knotwork",
        "version": FORMAT_VERSION,
        "objects": objects.iter().map(object_to_value).collect::<Vec<_>>(),
    });
    serde_json::to_string_pretty(&file).unwrap_or_default()
}

fn json_kind(value: &serde_json::Value) -> &'static str {
    match value {
        serde_json::Value::Null => "null",
        serde_json::Value::Bool(_) => "a boolean",
        serde_json::Value::Number(_) => "a number",
        serde_json::Value::String(_) => "a string",
        serde_json::Value::Array(_) => "an array",
        serde_json::Value::Object(_) => "an object",
    }
}
