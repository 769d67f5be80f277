//! The `knotwork construct` request: a transfinite surface built from curves or corner data,
//! written back as a `nurbs_surface`, or a curve through points written as a `nurbs_curve`, in
//! knotwork's JSON format ([`crate::scene::json`]).
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
use serde::Deserialize;
use serde_json::Value;

use crate::kernel::curve_edit::{self, CurveEnd};
use crate::kernel::fit;
use crate::kernel::loft::{LoftOptions, LoftStyle, loft_sections};
use crate::kernel::network::network_surface;
use crate::kernel::planar::planar_face;
use crate::kernel::splines::{self, Parametrization};
use crate::kernel::sweep::{SweepFrame, sweep_one_rail, sweep_two_rails};
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
    Interpolate {
        points: Vec<[f64; 3]>,
        #[serde(default = "default_degree")]
        degree: usize,
        #[serde(default)]
        closed: bool,
        #[serde(default)]
        parametrization: ParametrizationName,
        #[serde(default)]
        tangents: Option<[[f64; 3]; 2]>,
    },
    #[serde(rename = "catmull_rom")]
    CatmullRom {
        points: Vec<[f64; 3]>,
        #[serde(default = "default_alpha")]
        alpha: f64,
    },
    Loft {
        curves: Vec<Value>,
        #[serde(default = "default_degree")]
        degree: usize,
        #[serde(default)]
        closed: bool,
        #[serde(default)]
        style: LoftStyleName,
    },
    Network {
        #[serde(default)]
        u_curves: Vec<Value>,
        #[serde(default)]
        v_curves: Vec<Value>,
        /// Both families in one list, in any order: told apart by which cross which.
        #[serde(default)]
        curves: Vec<Value>,
        #[serde(default = "default_degree")]
        degree: usize,
    },
    Sweep1 {
        rail: Value,
        profiles: Vec<Value>,
        #[serde(default)]
        up: Option<[f64; 3]>,
    },
    Sweep2 {
        rails: [Value; 2],
        profiles: Vec<Value>,
        #[serde(default)]
        keep_height: bool,
    },
    Revolve {
        profile: Value,
        axis: Axis,
        #[serde(default = "default_angle")]
        angle: f64,
    },
    Planar {
        boundary: Vec<Value>,
    },
    Edge {
        curves: Vec<Value>,
    },
    Extrude {
        curve: Value,
        #[serde(default)]
        direction: Option<[f64; 3]>,
        #[serde(default)]
        path: Option<Value>,
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
        #[serde(default)]
        parameters: Option<Vec<f64>>,
    },
    Rebuild {
        curve: Value,
        points: usize,
        #[serde(default = "default_degree")]
        degree: usize,
    },
    Fit {
        curve: Value,
        tolerance: f64,
    },
    Offset {
        curve: Value,
        distance: f64,
        #[serde(default)]
        normal: Option<[f64; 3]>,
        #[serde(default)]
        tolerance: Option<f64>,
    },
    Project {
        curve: Value,
        plane: Plane,
    },
    Extend {
        curve: Value,
        length: f64,
        #[serde(default)]
        end: EndName,
    },
}

/// A plane: a point on it and its normal.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Plane {
    origin: [f64; 3],
    normal: [f64; 3],
}

/// Which end of a curve an extension grows from.
#[derive(Deserialize, Default, Clone, Copy)]
#[serde(rename_all = "snake_case")]
enum EndName {
    Start,
    #[default]
    End,
}

/// A loft's style, as a request names it.
#[derive(Deserialize, Default, Clone, Copy)]
#[serde(rename_all = "snake_case")]
enum LoftStyleName {
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
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Axis {
    origin: [f64; 3],
    direction: [f64; 3],
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
#[derive(Deserialize, Default, Clone, Copy)]
#[serde(rename_all = "snake_case")]
enum ParametrizationName {
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

/// Builds the surface (or curve) a request describes, and its name. A malformed request names
/// the offending JSON path; a construction that fails (curves that do not meet, …) gives the
/// kernel's reason.
pub fn build(text: &str) -> Result<Built, FormatError> {
    let value: Value = serde_json::from_str(text)
        .map_err(|e| FormatError::new("", format!("not valid JSON: {e}")))?;
    build_value(value)
}

/// [`build`] for a request already parsed (the editor's constructions, whose curves it fills
/// in from the document).
pub fn build_value(value: Value) -> Result<Built, FormatError> {
    let request: Request = serde_path_to_error::deserialize(value)
        .map_err(|e| FormatError::new(e.path().to_string(), e.into_inner().to_string()))?;
    let points = |raw: &[[f64; 3]]| -> Vec<DVec3> { raw.iter().map(|&p| DVec3::from(p)).collect() };
    match request {
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
                (curves("u_curves", u_curves)?, curves("v_curves", v_curves)?)
            } else if u_curves.is_empty() && v_curves.is_empty() {
                let all = curves("curves", mixed)?;
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
            let chain = curves("boundary", boundary)?;
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
            let c = curve("curve", raw)?;
            let rebuilt = fit::rebuild(&c, points, degree).map_err(geometry)?;
            Ok(rebuilt_curve(rebuilt, "rebuilt curve"))
        }
        Request::Fit {
            curve: raw,
            tolerance,
        } => {
            let c = curve("curve", raw)?;
            let fitted = fit::fit(&c, tolerance).map_err(geometry)?;
            Ok(rebuilt_curve(fitted, "fitted curve"))
        }
        Request::Offset {
            curve: raw,
            distance,
            normal,
            tolerance,
        } => {
            let c = curve("curve", raw)?;
            let size = crate::kernel::curve::control_box_size([&c]);
            let tolerance = tolerance.unwrap_or(1e-6 * (size + distance.abs()));
            let offset = fit::offset_planar(&c, distance, normal.map(DVec3::from), tolerance)
                .map_err(geometry)?;
            Ok(rebuilt_curve(offset, "offset curve"))
        }
        Request::Project { curve: raw, plane } => {
            let c = curve("curve", raw)?;
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
            let c = curve("curve", raw)?;
            let end = match end {
                EndName::Start => CurveEnd::Start,
                EndName::End => CurveEnd::End,
            };
            curve_edit::extended(&c, length, end)
                .map(|c| Built::plain((Geometry::Curve(c), "extended curve")))
                .map_err(geometry)
        }
        surface => {
            build_surface(surface).map(|(s, name)| Built::plain((Geometry::Surface(s), name)))
        }
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
fn build_surface(request: Request) -> Result<(NurbsSurface, &'static str), FormatError> {
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
        Request::Loft {
            curves: raw,
            degree,
            closed,
            style,
        } => {
            let sections = curves("curves", raw)?;
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
            let c = curve("curve", raw)?;
            match (direction, path) {
                (Some(d), None) => construct::extrude(&c, DVec3::from(d)),
                (None, Some(p)) => construct::extrude_along(&c, &curve("path", p)?),
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
            let edges = curves("curves", raw)?;
            crate::kernel::edge::edge_surface(&edges)
                .map(|s| (s, "edge surface"))
                .map_err(geometry)
        }
        Request::Sweep1 { rail, profiles, up } => {
            let rail = curve("rail", rail)?;
            let profiles = curves("profiles", profiles)?;
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
            let rails = [curve("rails[0]", r0)?, curve("rails[1]", r1)?];
            let profiles = curves("profiles", profiles)?;
            sweep_two_rails([&rails[0], &rails[1]], &profiles, keep_height)
                .map(|s| (s, "two-rail sweep"))
                .map_err(geometry)
        }
        Request::Revolve {
            profile,
            axis,
            angle,
        } => {
            let profile = curve("profile", profile)?;
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

/// The built object as the JSON object (`nurbs_surface` or `nurbs_curve`) that `knotwork
/// eval` and the file format read.
pub fn geometry_value(geometry: Geometry, name: &str) -> Value {
    object_to_value(&NamedGeometry {
        name: Some(name.to_string()),
        geometry,
    })
}
