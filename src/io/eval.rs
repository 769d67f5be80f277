//! The `knotwork eval` request: evaluate a surface at a list of parameters.
//!
//! Request: `{"surface": <surface object>, "params": [[u, v], ...]}` (the surface in the format of
//! [`crate::scene::json`]). Response: `{"results": [...]}`, one entry per parameter pair, in order:
//! `{"u", "v", "point", "normal", "su", "sv", "suu", "suv", "svv", "gaussian", "mean", "k1", "k2",
//! "principal_directions", "regular"}` (vectors as arrays of 3 numbers; `principal_directions` is
//! null at umbilics; `regular` is false at a pole or collapsed edge, where the normal and the
//! curvatures are the limits from the interior), or `{"u", "v", "error": "..."}` for a parameter
//! outside the domain.

use glam::DVec3;
use serde::Deserialize;
use serde_json::{Value, json};

use crate::kernel::NurbsSurface;
use crate::kernel::surface::LocalGeometry;
use crate::scene::json::{FormatError, Geometry, object_from_value};

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Request {
    surface: Value,
    params: Vec<Vec<f64>>,
}

fn vector(v: DVec3) -> Value {
    json!([v.x, v.y, v.z])
}

/// A parsed request: the surface and the parameter entries (each should be a pair).
pub struct EvalRequest {
    pub surface: NurbsSurface,
    pub params: Vec<Vec<f64>>,
}

/// The result object of one parameter pair: the local geometry, or the error for that entry.
pub fn result_value(u: f64, v: f64, result: Result<LocalGeometry, String>) -> Value {
    match result {
        Ok(g) => {
            let d = g.derivatives;
            let c = g.curvature;
            json!({
                "u": u,
                "v": v,
                "point": vector(d.point),
                "normal": vector(g.normal),
                "su": vector(d.su),
                "sv": vector(d.sv),
                "suu": vector(d.suu),
                "suv": vector(d.suv),
                "svv": vector(d.svv),
                "gaussian": c.gaussian,
                "mean": c.mean,
                "k1": c.k1,
                "k2": c.k2,
                "principal_directions": c.directions.map(|[a, b]| json!([vector(a), vector(b)])),
                "regular": g.regular,
            })
        }
        Err(e) => json!({ "u": u, "v": v, "error": e }),
    }
}

/// Reads a request. Errors in the request itself (malformed JSON, a bad surface) are returned.
pub fn parse_request(text: &str) -> Result<EvalRequest, FormatError> {
    let value: Value = serde_json::from_str(text).map_err(|e| FormatError {
        path: String::new(),
        message: format!("not valid JSON: {e}"),
    })?;
    let request: Request = serde_path_to_error::deserialize(value).map_err(|e| FormatError {
        path: e.path().to_string(),
        message: e.into_inner().to_string(),
    })?;
    let surface = match object_from_value("surface", request.surface)?.geometry {
        Geometry::Surface(s) => s,
        Geometry::TrimmedSurface(t) => t.surface().clone(),
        _ => {
            return Err(FormatError {
                path: "surface.type".into(),
                message: "expected \"nurbs_surface\"".into(),
            });
        }
    };
    Ok(EvalRequest {
        surface,
        params: request.params,
    })
}

/// The response to `request`: entries that are not a pair become per-result errors, the pairs
/// are evaluated together by `evaluate` (one result per pair, in order).
pub fn respond(
    request: &EvalRequest,
    evaluate: impl FnOnce(&NurbsSurface, &[(f64, f64)]) -> Vec<Result<LocalGeometry, String>>,
) -> Value {
    let pairs: Vec<(f64, f64)> = request
        .params
        .iter()
        .filter_map(|p| match p[..] {
            [u, v] => Some((u, v)),
            _ => None,
        })
        .collect();
    let mut evaluated = evaluate(&request.surface, &pairs).into_iter();
    let results: Vec<Value> = request
        .params
        .iter()
        .map(|p| match p[..] {
            [u, v] => result_value(
                u,
                v,
                evaluated
                    .next()
                    .unwrap_or_else(|| Err("the evaluator returned too few results".into())),
            ),
            _ => json!({
                "error": format!("expected a parameter pair [u, v], found {} numbers", p.len())
            }),
        })
        .collect();
    json!({ "results": results })
}

/// Reads a request and evaluates it with the f64 kernel. Errors in the request itself are
/// returned; parameters outside the domain become per-result errors.
pub fn evaluate_request(text: &str) -> Result<Value, FormatError> {
    let request = parse_request(text)?;
    Ok(respond(&request, |surface, pairs| {
        pairs
            .iter()
            .map(|&(u, v)| surface.local_geometry(u, v).map_err(|e| e.to_string()))
            .collect()
    }))
}
