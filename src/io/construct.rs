//! The `knotwork construct` request: a transfinite surface built from curves or corner data,
//! written back as a `nurbs_surface` in knotwork's JSON format ([`crate::scene::json`]).
//!
//! - `{"construct": "gordon", "u_curves": [<nurbs_curve>, ...], "v_curves": [...], "degree": 3}`:
//!   the Gordon surface of the network (u-curves in order of increasing v, v-curves in order of
//!   increasing u; `degree`, default 3, is the interpolation degree across the curves).
//! - `{"construct": "coons", "bottom": <nurbs_curve>, "top": ..., "left": ..., "right": ...}`:
//!   the bilinearly blended Coons patch; with `"cross": {"bottom": <nurbs_curve>, "top": ...,
//!   "left": ..., "right": ...}` (S_v along bottom and top, S_u along left and right, the curves'
//!   points read as vectors) the bicubically blended one.
//! - `{"construct": "hermite", "points": [p00, p10, p01, p11], "su": [...], "sv": [...],
//!   "twist": [...]}`: the bicubic Hermite patch (vectors as `[x, y, z]`, corners in the order
//!   (0, 0), (1, 0), (0, 1), (1, 1); `twist` defaults to zero vectors).

use glam::DVec3;
use serde::Deserialize;
use serde_json::Value;

use crate::kernel::transfinite::{self, HermiteData};
use crate::kernel::{NurbsSurface, SpaceCurve, construct};
use crate::scene::json::{
    FormatError, Geometry, NamedGeometry, object_from_value, object_to_value,
};

#[derive(Deserialize)]
#[serde(tag = "construct", rename_all = "lowercase", deny_unknown_fields)]
enum Request {
    Gordon {
        u_curves: Vec<Value>,
        v_curves: Vec<Value>,
        #[serde(default = "default_degree")]
        degree: usize,
    },
    Coons {
        bottom: Value,
        top: Value,
        left: Value,
        right: Value,
        #[serde(default)]
        cross: Option<Sides>,
    },
    Hermite {
        points: [[f64; 3]; 4],
        su: [[f64; 3]; 4],
        sv: [[f64; 3]; 4],
        #[serde(default)]
        twist: [[f64; 3]; 4],
    },
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Sides {
    bottom: Value,
    top: Value,
    left: Value,
    right: Value,
}

fn default_degree() -> usize {
    3
}

/// The curve at `path` of the request.
fn curve(path: &str, value: Value) -> Result<SpaceCurve, FormatError> {
    match object_from_value(path, value)?.geometry {
        Geometry::Curve(c) => Ok(c),
        _ => Err(FormatError::new(
            format!("{path}.type"),
            "expected \"nurbs_curve\"",
        )),
    }
}

fn curves(path: &str, values: Vec<Value>) -> Result<Vec<SpaceCurve>, FormatError> {
    values
        .into_iter()
        .enumerate()
        .map(|(k, v)| curve(&format!("{path}[{k}]"), v))
        .collect()
}

fn sides(path: &str, s: Sides) -> Result<[SpaceCurve; 4], FormatError> {
    let at = |name: &str| {
        if path.is_empty() {
            name.to_string()
        } else {
            format!("{path}.{name}")
        }
    };
    Ok([
        curve(&at("bottom"), s.bottom)?,
        curve(&at("top"), s.top)?,
        curve(&at("left"), s.left)?,
        curve(&at("right"), s.right)?,
    ])
}

/// Builds the surface a request describes. A malformed request names the offending JSON path;
/// a construction that fails (curves that do not meet, …) gives the kernel's reason.
pub fn build(text: &str) -> Result<(NurbsSurface, &'static str), FormatError> {
    let value: Value = serde_json::from_str(text)
        .map_err(|e| FormatError::new("", format!("not valid JSON: {e}")))?;
    let request: Request = serde_path_to_error::deserialize(value)
        .map_err(|e| FormatError::new(e.path().to_string(), e.into_inner().to_string()))?;
    let geometry = |e: crate::kernel::GeometryError| FormatError::new("", e.to_string());
    match request {
        Request::Gordon {
            u_curves,
            v_curves,
            degree,
        } => {
            let us = curves("u_curves", u_curves)?;
            let vs = curves("v_curves", v_curves)?;
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
            let [b, t, l, r] = sides(
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
                    let [db, dt, dl, dr] = sides("cross", cross)?;
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
                points: v(points),
                su: v(su),
                sv: v(sv),
                twist: v(twist),
            })
            .map(|s| (s, "Hermite patch"))
            .map_err(geometry)
        }
    }
}

/// The built surface as the `nurbs_surface` JSON object `knotwork eval` and the file format
/// read.
pub fn surface_value(surface: NurbsSurface, name: &str) -> Value {
    object_to_value(&NamedGeometry {
        name: Some(name.to_string()),
        geometry: Geometry::Surface(surface),
    })
}
