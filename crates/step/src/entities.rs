//! Reading STEP's geometric entities (ISO 10303-42) from the instance table: points,
//! directions and placements, curves and surfaces, with every argument checked. A malformed
//! instance is refused with a message that names it (`#123 = ADVANCED_FACE: expected 4
//! arguments, found 3`).

use std::f64::consts::TAU;

use glam::{DAffine3, DMat3, DVec3};

use super::part21::{Exchange, Instance, Record, Value};
use crate::FormatError;
use crate::kernel::{NurbsSurface, SpaceCurve, construct};

/// The most control points of one B-spline curve or surface, and the most knots (after the
/// multiplicities are expanded): checked before anything is allocated.
pub const MAX_SPLINE_POINTS: usize = 1 << 20;

/// An error about instance `id`.
pub fn bad(x: &Exchange, id: u64, message: impl std::fmt::Display) -> FormatError {
    let ty = x.get(id).map(Instance::type_name).unwrap_or_default();
    FormatError::new("", format!("#{id} = {ty}: {message}"))
}

/// Checked access to the instance table, lengths scaled to millimetres.
pub struct Entities<'a> {
    pub x: &'a Exchange,
    /// Millimetres per file length unit.
    pub scale: f64,
}

/// An orthonormal frame: origin and axes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    pub origin: DVec3,
    pub x: DVec3,
    pub y: DVec3,
    pub z: DVec3,
}

impl Frame {
    pub const IDENTITY: Frame = Frame {
        origin: DVec3::ZERO,
        x: DVec3::X,
        y: DVec3::Y,
        z: DVec3::Z,
    };

    /// The map from the frame's coordinates to the world's.
    pub fn to_affine(&self) -> DAffine3 {
        DAffine3::from_mat3_translation(DMat3::from_cols(self.x, self.y, self.z), self.origin)
    }

    pub fn at(&self, local: DVec3) -> DVec3 {
        self.origin + self.x * local.x + self.y * local.y + self.z * local.z
    }

    pub fn local(&self, p: DVec3) -> DVec3 {
        let d = p - self.origin;
        DVec3::new(d.dot(self.x), d.dot(self.y), d.dot(self.z))
    }

    /// The direction in the xy-plane at `angle` from x toward y.
    pub fn radial(&self, angle: f64) -> DVec3 {
        self.x * angle.cos() + self.y * angle.sin()
    }
}

/// A curve of the file, in its own parametrization (so that a trim parameter means what the
/// file says).
#[derive(Debug, Clone)]
pub enum Curve3 {
    /// p + t·v
    Line { point: DVec3, vector: DVec3 },
    /// centre + r (cos t x + sin t y)
    Circle { frame: Frame, radius: f64 },
    /// centre + a cos t x + b sin t y
    Ellipse { frame: Frame, a: f64, b: f64 },
    /// A B-spline (possibly rational) curve, or a polyline as one of degree 1.
    Spline(SpaceCurve),
}

impl Curve3 {
    pub fn point(&self, t: f64) -> DVec3 {
        match self {
            Curve3::Line { point, vector } => *point + *vector * t,
            Curve3::Circle { frame, radius } => frame.origin + frame.radial(t) * *radius,
            Curve3::Ellipse { frame, a, b } => {
                frame.origin + frame.x * (a * t.cos()) + frame.y * (b * t.sin())
            }
            Curve3::Spline(c) => {
                let (lo, hi) = c.domain();
                c.point_at(t.clamp(lo, hi))
                    .unwrap_or_else(|_| c.control_point(0))
            }
        }
    }

    /// The period of a closed curve (circles and ellipses: 2π).
    pub fn period(&self) -> Option<f64> {
        matches!(self, Curve3::Circle { .. } | Curve3::Ellipse { .. }).then_some(TAU)
    }

    /// The parameter of the curve's point nearest `p` (closed form, except for splines).
    pub fn parameter_of(&self, p: DVec3) -> f64 {
        match self {
            Curve3::Line { point, vector } => (p - *point).dot(*vector) / vector.length_squared(),
            Curve3::Circle { frame, .. } => {
                let l = frame.local(p);
                l.y.atan2(l.x)
            }
            Curve3::Ellipse { frame, a, b } => {
                let l = frame.local(p);
                (l.y / b).atan2(l.x / a)
            }
            Curve3::Spline(c) => c.closest_parameter(p).unwrap_or(c.domain().0),
        }
    }

    /// The parameter of a point of the curve near `p`: [`Self::parameter_of`] for the
    /// analytic curves; for a spline Newton's iteration from `start` alone (The NURBS Book
    /// §6.1), a local minimum of the distance, without the global search's samples.
    pub fn parameter_near(&self, p: DVec3, start: f64) -> f64 {
        match self {
            Curve3::Spline(c) => c.closest_parameter_from(p, start).unwrap_or(start),
            _ => self.parameter_of(p),
        }
    }

    /// The piece from parameter `t0` to `t1` (t1 < t0: run backward) as an exact NURBS curve.
    pub fn piece(&self, t0: f64, t1: f64) -> Result<SpaceCurve, crate::kernel::GeometryError> {
        let (lo, hi) = (t0.min(t1), t0.max(t1));
        let forward = match self {
            Curve3::Line { .. } => construct::line(self.point(lo), self.point(hi))?,
            Curve3::Circle { frame, radius } => {
                construct::arc(frame.origin, frame.x, frame.y, *radius, lo, hi)?
            }
            Curve3::Ellipse { frame, a, b } => {
                let unit = construct::arc(DVec3::ZERO, DVec3::X, DVec3::Y, 1.0, lo, hi)?;
                let f = *frame;
                let (a, b) = (*a, *b);
                unit.map_points(move |p| f.origin + f.x * (p.x * a) + f.y * (p.y * b))?
            }
            Curve3::Spline(c) => {
                let (d0, d1) = c.domain();
                let span = (d1 - d0).max(1e-300);
                let mut piece = c.clone();
                if hi < d1 - 1e-12 * span {
                    piece = piece.split(hi)?.0;
                }
                if lo > d0 + 1e-12 * span {
                    piece = piece.split(lo)?.1;
                }
                piece
            }
        };
        Ok(if t1 < t0 { forward.reverse() } else { forward })
    }
}

/// Why a curve or a surface was not read: the file is wrong (the whole file is refused), or
/// the entity is well formed but knotwork does not read its kind or has no exact NURBS form
/// for it (the faces on it are left out with a warning and the rest of the model opens).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum EntityError {
    #[error("{0}")]
    Malformed(FormatError),
    #[error("{0}")]
    Unbuildable(FormatError),
}

impl From<FormatError> for EntityError {
    fn from(e: FormatError) -> Self {
        EntityError::Malformed(e)
    }
}

/// A surface of the file, in STEP's parametrization where it is analytic.
#[derive(Debug, Clone)]
pub enum Surface3 {
    Plane(Frame),
    Cylinder {
        frame: Frame,
        radius: f64,
    },
    /// Radius `radius + v tan(semi_angle)` at height v.
    Cone {
        frame: Frame,
        radius: f64,
        tan: f64,
    },
    Sphere {
        frame: Frame,
        radius: f64,
    },
    Torus {
        frame: Frame,
        major: f64,
        minor: f64,
    },
    /// The meridian `curve`, lying in the half-plane of the frame's x and z, turned about z.
    Revolution {
        frame: Frame,
        curve: SpaceCurve,
    },
    /// `curve` moved along `vector`.
    Extrusion {
        curve: SpaceCurve,
        vector: DVec3,
    },
    Spline(NurbsSurface),
}

impl Surface3 {
    pub fn type_name(&self) -> &'static str {
        match self {
            Surface3::Plane(_) => "plane",
            Surface3::Cylinder { .. } => "cylinder",
            Surface3::Cone { .. } => "cone",
            Surface3::Sphere { .. } => "sphere",
            Surface3::Torus { .. } => "torus",
            Surface3::Revolution { .. } => "revolution",
            Surface3::Extrusion { .. } => "extrusion",
            Surface3::Spline(_) => "b-spline",
        }
    }
}

pub fn real_of(v: &Value) -> Option<f64> {
    match v {
        Value::Real(x) => Some(*x),
        Value::Integer(i) => Some(*i as f64),
        Value::Typed(_, inner) => real_of(inner),
        _ => None,
    }
}

impl<'a> Entities<'a> {
    pub fn instance(&self, id: u64) -> Result<&'a Instance, FormatError> {
        self.x.get(id).ok_or_else(|| {
            FormatError::new(
                "",
                format!("#{id}: a reference to an instance the file does not have"),
            )
        })
    }

    /// The partial entity `name` of instance `id`, with at least `count` arguments.
    pub fn record(&self, id: u64, name: &str, count: usize) -> Result<&'a Record, FormatError> {
        let instance = self.instance(id)?;
        let record = instance
            .part(name)
            .ok_or_else(|| bad(self.x, id, format!("expected {name}")))?;
        if record.args.len() < count {
            return Err(bad(
                self.x,
                id,
                format!(
                    "expected {count} argument{}, found {}",
                    if count == 1 { "" } else { "s" },
                    record.args.len()
                ),
            ));
        }
        Ok(record)
    }

    pub fn arg<'r>(&self, id: u64, r: &'r Record, k: usize) -> Result<&'r Value, FormatError> {
        r.args
            .get(k)
            .ok_or_else(|| bad(self.x, id, format!("argument {} is missing", k + 1)))
    }

    pub fn real(&self, id: u64, r: &Record, k: usize) -> Result<f64, FormatError> {
        let v = self.arg(id, r, k)?;
        real_of(v).ok_or_else(|| {
            bad(
                self.x,
                id,
                format!("argument {} must be a number, not {}", k + 1, v.type_name()),
            )
        })
    }

    pub fn reference(&self, id: u64, r: &Record, k: usize) -> Result<u64, FormatError> {
        match self.arg(id, r, k)? {
            Value::Ref(to) => Ok(*to),
            v => Err(bad(
                self.x,
                id,
                format!(
                    "argument {} must be a reference, not {}",
                    k + 1,
                    v.type_name()
                ),
            )),
        }
    }

    pub fn optional_reference(
        &self,
        id: u64,
        r: &Record,
        k: usize,
    ) -> Result<Option<u64>, FormatError> {
        match self.arg(id, r, k)? {
            Value::Null | Value::Derived => Ok(None),
            _ => self.reference(id, r, k).map(Some),
        }
    }

    pub fn list<'r>(&self, id: u64, r: &'r Record, k: usize) -> Result<&'r [Value], FormatError> {
        match self.arg(id, r, k)? {
            Value::List(items) => Ok(items),
            v => Err(bad(
                self.x,
                id,
                format!("argument {} must be a list, not {}", k + 1, v.type_name()),
            )),
        }
    }

    pub fn references(&self, id: u64, r: &Record, k: usize) -> Result<Vec<u64>, FormatError> {
        self.list(id, r, k)?
            .iter()
            .map(|v| match v {
                Value::Ref(to) => Ok(*to),
                other => Err(bad(
                    self.x,
                    id,
                    format!(
                        "argument {} must list references, not {}",
                        k + 1,
                        other.type_name()
                    ),
                )),
            })
            .collect()
    }

    pub fn boolean(&self, id: u64, r: &Record, k: usize) -> Result<bool, FormatError> {
        match self.arg(id, r, k)? {
            Value::Enum(e) if e == "T" || e == "TRUE" => Ok(true),
            Value::Enum(e) if e == "F" || e == "FALSE" => Ok(false),
            Value::Enum(e) if e == "U" || e == "UNKNOWN" => Ok(true),
            v => Err(bad(
                self.x,
                id,
                format!(
                    "argument {} must be .T. or .F., not {}",
                    k + 1,
                    v.type_name()
                ),
            )),
        }
    }

    pub fn text(&self, r: &Record, k: usize) -> String {
        match r.args.get(k) {
            Some(Value::Str(s)) => s.clone(),
            _ => String::new(),
        }
    }

    fn reals(&self, id: u64, values: &[Value], what: &str) -> Result<Vec<f64>, FormatError> {
        values
            .iter()
            .map(|v| {
                real_of(v).ok_or_else(|| {
                    bad(
                        self.x,
                        id,
                        format!("{what} must be numbers, not {}", v.type_name()),
                    )
                })
            })
            .collect()
    }

    fn integers(&self, id: u64, values: &[Value], what: &str) -> Result<Vec<usize>, FormatError> {
        values
            .iter()
            .map(|v| match v {
                Value::Integer(i) if *i >= 0 => Ok(*i as usize),
                other => Err(bad(
                    self.x,
                    id,
                    format!("{what} must be whole numbers ≥ 0, not {}", describe(other)),
                )),
            })
            .collect()
    }

    /// A `CARTESIAN_POINT` in millimetres (a 2D point has z = 0).
    pub fn point(&self, id: u64) -> Result<DVec3, FormatError> {
        let r = self.record(id, "CARTESIAN_POINT", 2)?;
        let c = self.reals(id, self.list(id, r, 1)?, "the coordinates")?;
        if c.is_empty() || c.len() > 3 {
            return Err(bad(
                self.x,
                id,
                format!("expected 1 to 3 coordinates, found {}", c.len()),
            ));
        }
        Ok(DVec3::new(
            c[0],
            c.get(1).copied().unwrap_or(0.0),
            c.get(2).copied().unwrap_or(0.0),
        ) * self.scale)
    }

    /// A `DIRECTION`, normalized.
    pub fn direction(&self, id: u64) -> Result<DVec3, FormatError> {
        let r = self.record(id, "DIRECTION", 2)?;
        let c = self.reals(id, self.list(id, r, 1)?, "the direction ratios")?;
        if c.is_empty() || c.len() > 3 {
            return Err(bad(
                self.x,
                id,
                format!("expected 2 or 3 direction ratios, found {}", c.len()),
            ));
        }
        let d = DVec3::new(
            c[0],
            c.get(1).copied().unwrap_or(0.0),
            c.get(2).copied().unwrap_or(0.0),
        );
        if !(d.length() > 1e-300) {
            return Err(bad(self.x, id, "the direction has zero length"));
        }
        Ok(d.normalize())
    }

    /// `AXIS2_PLACEMENT_3D(name, location, axis, ref_direction)` (axis and reference
    /// optional: z and x), or `AXIS1_PLACEMENT` (an axis only).
    pub fn placement(&self, id: u64) -> Result<Frame, FormatError> {
        let instance = self.instance(id)?;
        let r = instance
            .part("AXIS2_PLACEMENT_3D")
            .or_else(|| instance.part("AXIS1_PLACEMENT"))
            .or_else(|| instance.part("AXIS2_PLACEMENT_2D"))
            .ok_or_else(|| bad(self.x, id, "expected AXIS2_PLACEMENT_3D"))?;
        if r.args.len() < 3 {
            return Err(bad(
                self.x,
                id,
                format!("expected 4 arguments, found {}", r.args.len()),
            ));
        }
        let origin = self.point(self.reference(id, r, 1)?)?;
        let (z, x_hint) = if r.name == "AXIS2_PLACEMENT_2D" {
            (DVec3::Z, self.optional_reference(id, r, 2)?)
        } else {
            let z = match self.optional_reference(id, r, 2)? {
                Some(d) => self.direction(d)?,
                None => DVec3::Z,
            };
            let x = if r.args.len() > 3 {
                self.optional_reference(id, r, 3)?
            } else {
                None
            };
            (z, x)
        };
        let x = match x_hint {
            Some(d) => self.direction(d)?,
            None => {
                if z.x.abs() < 0.9 {
                    DVec3::X
                } else {
                    DVec3::Y
                }
            }
        };
        let x = x - z * x.dot(z);
        let x = if x.length() > 1e-12 {
            x.normalize()
        } else {
            z.any_orthonormal_vector()
        };
        Ok(Frame {
            origin,
            x,
            y: z.cross(x),
            z,
        })
    }

    /// The curve `id`: line, circle, ellipse, B-spline (rational or not, simple or complex),
    /// polyline; a trimmed curve, a surface curve or a seam curve as its basis or 3D curve.
    pub fn curve(&self, id: u64) -> Result<Curve3, EntityError> {
        self.curve_at_depth(id, 0)
    }

    fn curve_at_depth(&self, id: u64, depth: usize) -> Result<Curve3, EntityError> {
        if depth > 8 {
            return Err(bad(self.x, id, "curves nested more than 8 deep").into());
        }
        let instance = self.instance(id)?;
        if let Some(r) = instance.part("LINE") {
            let r = self.record(id, &r.name, 3)?;
            let point = self.point(self.reference(id, r, 1)?)?;
            let vid = self.reference(id, r, 2)?;
            let vr = self.record(vid, "VECTOR", 3)?;
            let dir = self.direction(self.reference(vid, vr, 1)?)?;
            let magnitude = self.real(vid, vr, 2)? * self.scale;
            if !(magnitude > 0.0) {
                return Err(bad(self.x, vid, "the vector's magnitude must be above 0").into());
            }
            return Ok(Curve3::Line {
                point,
                vector: dir * magnitude,
            });
        }
        if instance.is("CIRCLE") {
            let r = self.record(id, "CIRCLE", 3)?;
            let frame = self.placement(self.reference(id, r, 1)?)?;
            let radius = self.real(id, r, 2)? * self.scale;
            if !(radius > 0.0) {
                return Err(bad(
                    self.x,
                    id,
                    format!("the radius must be above 0, not {radius}"),
                )
                .into());
            }
            return Ok(Curve3::Circle { frame, radius });
        }
        if instance.is("ELLIPSE") {
            let r = self.record(id, "ELLIPSE", 4)?;
            let frame = self.placement(self.reference(id, r, 1)?)?;
            let (a, b) = (
                self.real(id, r, 2)? * self.scale,
                self.real(id, r, 3)? * self.scale,
            );
            if !(a > 0.0 && b > 0.0) {
                return Err(bad(self.x, id, "the semi-axes must be above 0").into());
            }
            return Ok(Curve3::Ellipse { frame, a, b });
        }
        if instance.is("B_SPLINE_CURVE")
            || instance.is("B_SPLINE_CURVE_WITH_KNOTS")
            || ImpliedKnots::in_parts(instance, "CURVE").is_some()
        {
            return Ok(Curve3::Spline(self.spline_curve(id)?));
        }
        if instance.is("POLYLINE") {
            let r = self.record(id, "POLYLINE", 2)?;
            let ids = self.references(id, r, 1)?;
            let points: Vec<DVec3> = ids
                .iter()
                .map(|&p| self.point(p))
                .collect::<Result<_, _>>()?;
            if points.len() < 2 {
                return Err(bad(self.x, id, "a polyline needs at least 2 points").into());
            }
            let knots: Vec<f64> = std::iter::once(0.0)
                .chain((0..points.len()).map(|k| k as f64))
                .chain(std::iter::once((points.len() - 1) as f64))
                .collect();
            return SpaceCurve::new(1, knots, points, None)
                .map(Curve3::Spline)
                .map_err(|e| bad(self.x, id, e).into());
        }
        if instance.is("TRIMMED_CURVE") {
            let r = self.record(id, "TRIMMED_CURVE", 2)?;
            return self.curve_at_depth(self.reference(id, r, 1)?, depth + 1);
        }
        for name in [
            "SURFACE_CURVE",
            "SEAM_CURVE",
            "INTERSECTION_CURVE",
            "BOUNDED_SURFACE_CURVE",
        ] {
            if let Some(r) = instance.part(name) {
                let r = self.record(id, &r.name, 2)?;
                return self.curve_at_depth(self.reference(id, r, 1)?, depth + 1);
            }
        }
        Err(EntityError::Unbuildable(bad(
            self.x,
            id,
            "this kind of curve is not read (lines, circles, ellipses, B-splines, polylines and trimmed and surface curves are)",
        )))
    }

    /// The p-curves of the curve `id` (a `SURFACE_CURVE` or `SEAM_CURVE`, alone or in a
    /// complex instance): each `PCURVE`'s basis surface and its 2D curve in that surface's
    /// (u, v), as a [`Curve3`] in the plane z = 0 with its coordinates as written (parameters,
    /// not lengths). A p-curve that cannot be read is left out: the face's loops are then
    /// computed from its 3D edges instead.
    pub fn pcurves(&self, id: u64) -> Vec<(u64, Curve3)> {
        let Ok(instance) = self.instance(id) else {
            return Vec::new();
        };
        let Some(part) = instance
            .part("SURFACE_CURVE")
            .or_else(|| instance.part("SEAM_CURVE"))
        else {
            return Vec::new();
        };
        let Ok(r) = self.record(id, &part.name, 3) else {
            return Vec::new();
        };
        let Ok(geometry) = self.references(id, r, 2) else {
            return Vec::new();
        };
        let unscaled = Entities {
            x: self.x,
            scale: 1.0,
        };
        let mut out = Vec::new();
        for g in geometry {
            let Ok(pr) = self.record(g, "PCURVE", 3) else {
                continue;
            };
            let (Ok(surface), Ok(rep)) = (self.reference(g, pr, 1), self.reference(g, pr, 2))
            else {
                continue;
            };
            let Ok(rr) = self.record(rep, "DEFINITIONAL_REPRESENTATION", 3) else {
                continue;
            };
            let Some(&first) = self
                .references(rep, rr, 1)
                .ok()
                .and_then(|l| l.first().copied())
                .as_ref()
            else {
                continue;
            };
            if let Ok(curve) = unscaled.curve(first) {
                out.push((surface, curve));
            }
        }
        out
    }

    /// The knot vector from distinct knots and their multiplicities, its length checked
    /// before it is allocated.
    fn knot_vector(
        &self,
        id: u64,
        multiplicities: &[Value],
        knots: &[Value],
    ) -> Result<Vec<f64>, FormatError> {
        let m = self.integers(id, multiplicities, "the knot multiplicities")?;
        let k = self.reals(id, knots, "the knots")?;
        if m.len() != k.len() {
            return Err(bad(
                self.x,
                id,
                format!("{} knots but {} multiplicities", k.len(), m.len()),
            ));
        }
        let total = m.iter().try_fold(0usize, |a, &b| a.checked_add(b));
        match total {
            Some(t) if t <= MAX_SPLINE_POINTS + 64 => {}
            _ => {
                return Err(bad(
                    self.x,
                    id,
                    "the knot multiplicities add up to more knots than knotwork reads",
                ));
            }
        }
        let mut out = Vec::new();
        for (&knot, &times) in k.iter().zip(&m) {
            out.extend(std::iter::repeat_n(knot, times));
        }
        Ok(out)
    }

    /// The knot vector of a B-spline of `degree` with `count` control points in one
    /// direction: the file's, or the one its subtype implies.
    fn knots(
        &self,
        id: u64,
        spec: &KnotSpec<'_>,
        degree: usize,
        count: usize,
    ) -> Result<Vec<f64>, FormatError> {
        match spec {
            KnotSpec::Given(multiplicities, knots) => self.knot_vector(id, multiplicities, knots),
            KnotSpec::Implied(kind) => kind.knots(degree, count).ok_or_else(|| {
                bad(
                    self.x,
                    id,
                    format!(
                        "{count} control points do not make a {} B-spline of degree {degree}",
                        kind.name()
                    ),
                )
            }),
        }
    }

    fn spline_curve(&self, id: u64) -> Result<SpaceCurve, FormatError> {
        let instance = self.instance(id)?;
        // (degree, points, knots): one simple record or parts of a complex one. The knots are
        // the file's (multiplicities and distinct values) or implied by the curve's subtype.
        let (degree, points, knots) = match instance {
            Instance::Simple(r) if r.name == "B_SPLINE_CURVE_WITH_KNOTS" => {
                let r = self.record(id, "B_SPLINE_CURVE_WITH_KNOTS", 9)?;
                (
                    self.arg(id, r, 1)?,
                    self.list(id, r, 2)?,
                    KnotSpec::Given(self.list(id, r, 6)?, self.list(id, r, 7)?),
                )
            }
            Instance::Simple(r) => {
                let kind = ImpliedKnots::of(&r.name)
                    .ok_or_else(|| bad(self.x, id, "this kind of B-spline curve is not read"))?;
                let r = self.record(id, &r.name, 6)?;
                (
                    self.arg(id, r, 1)?,
                    self.list(id, r, 2)?,
                    KnotSpec::Implied(kind),
                )
            }
            Instance::Complex(_) => {
                let b = self.record(id, "B_SPLINE_CURVE", 5)?;
                let knots = match instance.part("B_SPLINE_CURVE_WITH_KNOTS") {
                    Some(_) => {
                        let k = self.record(id, "B_SPLINE_CURVE_WITH_KNOTS", 3)?;
                        KnotSpec::Given(self.list(id, k, 0)?, self.list(id, k, 1)?)
                    }
                    None => KnotSpec::Implied(
                        ImpliedKnots::in_parts(instance, "CURVE")
                            .ok_or_else(|| bad(self.x, id, "the B-spline curve has no knots"))?,
                    ),
                };
                (self.arg(id, b, 0)?, self.list(id, b, 1)?, knots)
            }
        };
        let Value::Integer(degree) = degree else {
            return Err(bad(self.x, id, "the degree must be a whole number"));
        };
        if !(1..=32).contains(degree) {
            return Err(bad(
                self.x,
                id,
                format!("the degree {degree} is not in 1 to 32"),
            ));
        }
        if points.len() > MAX_SPLINE_POINTS {
            return Err(bad(self.x, id, "too many control points"));
        }
        let cps: Vec<DVec3> = points
            .iter()
            .map(|v| match v {
                Value::Ref(p) => self.point(*p),
                other => Err(bad(
                    self.x,
                    id,
                    format!(
                        "the control points must be references, not {}",
                        other.type_name()
                    ),
                )),
            })
            .collect::<Result<_, _>>()?;
        let knots = self.knots(id, &knots, *degree as usize, cps.len())?;
        let weights = match instance.part("RATIONAL_B_SPLINE_CURVE") {
            Some(r) => {
                let list = r
                    .args
                    .last()
                    .and_then(|v| {
                        if let Value::List(l) = v {
                            Some(l)
                        } else {
                            None
                        }
                    })
                    .ok_or_else(|| bad(self.x, id, "the weights must be a list"))?;
                Some(self.reals(id, list, "the weights")?)
            }
            None => None,
        };
        let curve = SpaceCurve::new(*degree as usize, knots, cps, weights)
            .map_err(|e| bad(self.x, id, format!("the B-spline does not fit: {e}")))?;
        Ok(curve.clamped())
    }

    pub fn spline_surface(&self, id: u64) -> Result<NurbsSurface, FormatError> {
        let instance = self.instance(id)?;
        let (ud, vd, rows, knots) = match instance {
            Instance::Simple(r) if r.name == "B_SPLINE_SURFACE_WITH_KNOTS" => {
                let r = self.record(id, "B_SPLINE_SURFACE_WITH_KNOTS", 13)?;
                (
                    self.arg(id, r, 1)?,
                    self.arg(id, r, 2)?,
                    self.list(id, r, 3)?,
                    [
                        KnotSpec::Given(self.list(id, r, 8)?, self.list(id, r, 10)?),
                        KnotSpec::Given(self.list(id, r, 9)?, self.list(id, r, 11)?),
                    ],
                )
            }
            Instance::Simple(r) => {
                let kind = ImpliedKnots::of(&r.name)
                    .ok_or_else(|| bad(self.x, id, "this kind of B-spline surface is not read"))?;
                let r = self.record(id, &r.name, 8)?;
                (
                    self.arg(id, r, 1)?,
                    self.arg(id, r, 2)?,
                    self.list(id, r, 3)?,
                    [KnotSpec::Implied(kind), KnotSpec::Implied(kind)],
                )
            }
            Instance::Complex(_) => {
                let b = self.record(id, "B_SPLINE_SURFACE", 7)?;
                let knots = match instance.part("B_SPLINE_SURFACE_WITH_KNOTS") {
                    Some(_) => {
                        let k = self.record(id, "B_SPLINE_SURFACE_WITH_KNOTS", 5)?;
                        [
                            KnotSpec::Given(self.list(id, k, 0)?, self.list(id, k, 2)?),
                            KnotSpec::Given(self.list(id, k, 1)?, self.list(id, k, 3)?),
                        ]
                    }
                    None => {
                        let kind = ImpliedKnots::in_parts(instance, "SURFACE")
                            .ok_or_else(|| bad(self.x, id, "the B-spline surface has no knots"))?;
                        [KnotSpec::Implied(kind), KnotSpec::Implied(kind)]
                    }
                };
                (
                    self.arg(id, b, 0)?,
                    self.arg(id, b, 1)?,
                    self.list(id, b, 2)?,
                    knots,
                )
            }
        };
        let degree = |v: &Value| match v {
            Value::Integer(d) if (1..=32).contains(d) => Ok(*d as usize),
            _ => Err(bad(
                self.x,
                id,
                "the degrees must be whole numbers from 1 to 32",
            )),
        };
        let (p, q) = (degree(ud)?, degree(vd)?);
        let nu = rows.len();
        let mut nv = 0;
        let mut points = Vec::new();
        for (i, row) in rows.iter().enumerate() {
            let Value::List(row) = row else {
                return Err(bad(self.x, id, "the control points must be a list of rows"));
            };
            if i == 0 {
                nv = row.len();
                if nu.saturating_mul(nv) > MAX_SPLINE_POINTS {
                    return Err(bad(self.x, id, "too many control points"));
                }
            } else if row.len() != nv {
                return Err(bad(
                    self.x,
                    id,
                    format!(
                        "row {} has {} control points, row 1 has {nv}",
                        i + 1,
                        row.len()
                    ),
                ));
            }
            for v in row {
                let Value::Ref(pid) = v else {
                    return Err(bad(self.x, id, "the control points must be references"));
                };
                points.push(self.point(*pid)?);
            }
        }
        let knots = [
            self.knots(id, &knots[0], p, nu)?,
            self.knots(id, &knots[1], q, nv)?,
        ];
        let weights = match instance.part("RATIONAL_B_SPLINE_SURFACE") {
            Some(r) => {
                let Some(Value::List(wrows)) = r.args.last() else {
                    return Err(bad(self.x, id, "the weights must be a list of rows"));
                };
                let mut w = Vec::with_capacity(points.len());
                for row in wrows {
                    let Value::List(row) = row else {
                        return Err(bad(self.x, id, "the weights must be a list of rows"));
                    };
                    w.extend(self.reals(id, row, "the weights")?);
                }
                if w.len() != points.len() {
                    return Err(bad(
                        self.x,
                        id,
                        format!("{} weights for {} control points", w.len(), points.len()),
                    ));
                }
                Some(w)
            }
            None => None,
        };
        let surface = NurbsSurface::new([p, q], knots, [nu, nv], points, weights).map_err(|e| {
            bad(
                self.x,
                id,
                format!("the B-spline surface does not fit: {e}"),
            )
        })?;
        Ok(surface.clamped())
    }

    /// The surface `id`.
    pub fn surface(&self, id: u64) -> Result<Surface3, EntityError> {
        self.surface_at_depth(id, 0)
    }

    fn surface_at_depth(&self, id: u64, depth: usize) -> Result<Surface3, EntityError> {
        if depth > 8 {
            return Err(bad(self.x, id, "surfaces nested more than 8 deep").into());
        }
        let instance = self.instance(id)?;
        let length = |r: &Record, k: usize| -> Result<f64, FormatError> {
            let v = self.real(id, r, k)? * self.scale;
            if v > 0.0 {
                Ok(v)
            } else {
                Err(bad(
                    self.x,
                    id,
                    format!("argument {} must be a length above 0", k + 1),
                ))
            }
        };
        if instance.is("PLANE") {
            let r = self.record(id, "PLANE", 2)?;
            return Ok(Surface3::Plane(self.placement(self.reference(id, r, 1)?)?));
        }
        if instance.is("CYLINDRICAL_SURFACE") {
            let r = self.record(id, "CYLINDRICAL_SURFACE", 3)?;
            return Ok(Surface3::Cylinder {
                frame: self.placement(self.reference(id, r, 1)?)?,
                radius: length(r, 2)?,
            });
        }
        if instance.is("CONICAL_SURFACE") {
            let r = self.record(id, "CONICAL_SURFACE", 4)?;
            let radius = self.real(id, r, 2)? * self.scale;
            let angle = self.real(id, r, 3)?;
            // Degrees where the value cannot be radians.
            let angle = if angle.abs() >= std::f64::consts::FRAC_PI_2 {
                angle.to_radians()
            } else {
                angle
            };
            if !(radius >= 0.0 && angle.abs() > 1e-12 && angle.abs() < std::f64::consts::FRAC_PI_2)
            {
                return Err(bad(
                    self.x,
                    id,
                    "the radius must be ≥ 0 and the semi-angle between 0 and 90°",
                )
                .into());
            }
            return Ok(Surface3::Cone {
                frame: self.placement(self.reference(id, r, 1)?)?,
                radius,
                tan: angle.tan(),
            });
        }
        if instance.is("SPHERICAL_SURFACE") {
            let r = self.record(id, "SPHERICAL_SURFACE", 3)?;
            return Ok(Surface3::Sphere {
                frame: self.placement(self.reference(id, r, 1)?)?,
                radius: length(r, 2)?,
            });
        }
        if let Some(part) = instance
            .part("TOROIDAL_SURFACE")
            .or_else(|| instance.part("DEGENERATE_TOROIDAL_SURFACE"))
        {
            let r = self.record(id, &part.name.clone(), 4)?;
            return Ok(Surface3::Torus {
                frame: self.placement(self.reference(id, r, 1)?)?,
                major: length(r, 2)?,
                minor: length(r, 3)?,
            });
        }
        if instance.is("SURFACE_OF_REVOLUTION") {
            let r = self.record(id, "SURFACE_OF_REVOLUTION", 3)?;
            let curve = self.curve(self.reference(id, r, 1)?)?;
            let axis = self.placement(self.reference(id, r, 2)?)?;
            let spline = match &curve {
                Curve3::Spline(c) => c.clone(),
                other => {
                    let t0 = 0.0;
                    let t1 = other.period().unwrap_or(1.0);
                    other.piece(t0, t1).map_err(|e| bad(self.x, id, e))?
                }
            };
            // The frame's x: toward the meridian curve (its point farthest from the axis).
            let mut x = DVec3::ZERO;
            for k in 0..spline.count() {
                let d = spline.control_point(k) - axis.origin;
                let radial = d - axis.z * d.dot(axis.z);
                if radial.length() > x.length() {
                    x = radial;
                }
            }
            if x.length() <= 1e-12 {
                return Err(bad(self.x, id, "the meridian lies on the axis").into());
            }
            let x = x.normalize();
            let frame = Frame {
                origin: axis.origin,
                x,
                y: axis.z.cross(x),
                z: axis.z,
            };
            return Ok(Surface3::Revolution {
                frame,
                curve: spline,
            });
        }
        if instance.is("SURFACE_OF_LINEAR_EXTRUSION") {
            let r = self.record(id, "SURFACE_OF_LINEAR_EXTRUSION", 3)?;
            let curve = self.curve(self.reference(id, r, 1)?)?;
            let vid = self.reference(id, r, 2)?;
            let vr = self.record(vid, "VECTOR", 3)?;
            let vector = self.direction(self.reference(vid, vr, 1)?)?
                * (self.real(vid, vr, 2)? * self.scale);
            let spline = match &curve {
                Curve3::Spline(c) => c.clone(),
                other => {
                    let t1 = other.period().unwrap_or(1.0);
                    other.piece(0.0, t1).map_err(|e| bad(self.x, id, e))?
                }
            };
            return Ok(Surface3::Extrusion {
                curve: spline,
                vector,
            });
        }
        if instance.is("B_SPLINE_SURFACE")
            || instance.is("B_SPLINE_SURFACE_WITH_KNOTS")
            || ImpliedKnots::in_parts(instance, "SURFACE").is_some()
        {
            return Ok(Surface3::Spline(self.spline_surface(id)?));
        }
        if instance.is("OFFSET_SURFACE") {
            let r = self.record(id, "OFFSET_SURFACE", 4)?;
            let basis = self.surface_at_depth(self.reference(id, r, 1)?, depth + 1)?;
            let distance = self.real(id, r, 2)? * self.scale;
            return offset_surface(basis, distance)
                .map_err(|e| EntityError::Unbuildable(bad(self.x, id, e)));
        }
        Err(EntityError::Unbuildable(bad(
            self.x,
            id,
            "this kind of surface is not read",
        )))
    }
}

/// Where a B-spline's knots come from: the file's multiplicities and distinct values, or the
/// subtype that implies them.
enum KnotSpec<'a> {
    Given(&'a [Value], &'a [Value]),
    Implied(ImpliedKnots),
}

/// The B-spline subtypes whose knots are implied (ISO 10303-42, 4.3.4 and 4.3.5).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImpliedKnots {
    /// `UNIFORM_CURVE`, `UNIFORM_SURFACE`: knots −p, −p + 1, …, n + 1 (k = n + p + 2 of
    /// them, n + 1 control points), each once.
    Uniform,
    /// `QUASI_UNIFORM_CURVE`, `QUASI_UNIFORM_SURFACE`: 0, 1, …, n − p + 1, the ends p + 1
    /// times.
    QuasiUniform,
    /// `BEZIER_CURVE`, `BEZIER_SURFACE`: piecewise Bézier, 0, 1, …, n / p, the ends p + 1
    /// times and the rest p times.
    PiecewiseBezier,
}

impl ImpliedKnots {
    /// The subtype an entity name stands for.
    pub fn of(name: &str) -> Option<Self> {
        match name {
            "UNIFORM_CURVE" | "UNIFORM_SURFACE" => Some(Self::Uniform),
            "QUASI_UNIFORM_CURVE" | "QUASI_UNIFORM_SURFACE" => Some(Self::QuasiUniform),
            "BEZIER_CURVE" | "BEZIER_SURFACE" => Some(Self::PiecewiseBezier),
            _ => None,
        }
    }

    /// The subtype among an instance's parts whose names end in `kind` ("CURVE" or
    /// "SURFACE").
    fn in_parts(instance: &Instance, kind: &str) -> Option<Self> {
        let of = |name: &str| Self::of(name).filter(|_| name.ends_with(kind));
        match instance {
            Instance::Simple(r) => of(&r.name),
            Instance::Complex(parts) => parts.iter().find_map(|r| of(&r.name)),
        }
    }

    fn name(self) -> &'static str {
        match self {
            Self::Uniform => "uniform",
            Self::QuasiUniform => "quasi-uniform",
            Self::PiecewiseBezier => "piecewise Bézier",
        }
    }

    /// The knot vector for `count` control points of `degree` (count + degree + 1 knots), or
    /// `None` where the count does not fit the subtype.
    pub fn knots(self, degree: usize, count: usize) -> Option<Vec<f64>> {
        if degree == 0 || count <= degree || count > MAX_SPLINE_POINTS {
            return None;
        }
        let total = count + degree + 1;
        let knots: Vec<f64> = match self {
            Self::Uniform => (0..total).map(|k| k as f64 - degree as f64).collect(),
            Self::QuasiUniform => {
                let last = (count - degree) as f64;
                std::iter::repeat_n(0.0, degree + 1)
                    .chain((1..count - degree).map(|k| k as f64))
                    .chain(std::iter::repeat_n(last, degree + 1))
                    .collect()
            }
            Self::PiecewiseBezier => {
                if !(count - 1).is_multiple_of(degree) {
                    return None;
                }
                let segments = (count - 1) / degree;
                let mut k = vec![0.0; degree + 1];
                for s in 1..segments {
                    k.extend(std::iter::repeat_n(s as f64, degree));
                }
                k.extend(std::iter::repeat_n(segments as f64, degree + 1));
                k
            }
        };
        (knots.len() == total).then_some(knots)
    }
}

/// The surface `distance` along the unit normal S_u × S_v / |S_u × S_v| of `basis`, in the
/// same (u, v) (ISO 10303-42, offset_surface), where that is again a surface of the same kind:
/// - a plane moves along its z;
/// - a cylinder's, a sphere's and a torus's normal points away from the axis, the centre and
///   the tube's centre circle, so the radius (the minor radius) grows by `distance`;
/// - a cone's normal at height v is cos α·radial − sin α·z (α the semi-angle), so the point
///   at (u, v) lands on the cone of the same angle with radius R + d cos α at height
///   v − d sin α: the same parametrization with the origin moved by −d sin α along z.
///
/// Offsets of surfaces of revolution, extrusions and B-splines are not exact rational
/// surfaces, and an offset through an axis or a centre is not a surface of the kind: both are
/// refused.
pub fn offset_surface(basis: Surface3, distance: f64) -> Result<Surface3, String> {
    if !distance.is_finite() {
        return Err(format!("the offset distance {distance} is not a number"));
    }
    let positive = |value: f64, what: &str| {
        if value > 0.0 {
            Ok(value)
        } else {
            Err(format!(
                "an offset of {distance} leaves the {what} at {value}, not above 0"
            ))
        }
    };
    Ok(match basis {
        Surface3::Plane(frame) => Surface3::Plane(Frame {
            origin: frame.origin + frame.z * distance,
            ..frame
        }),
        Surface3::Cylinder { frame, radius } => Surface3::Cylinder {
            frame,
            radius: positive(radius + distance, "radius")?,
        },
        Surface3::Sphere { frame, radius } => Surface3::Sphere {
            frame,
            radius: positive(radius + distance, "radius")?,
        },
        Surface3::Torus {
            frame,
            major,
            minor,
        } => Surface3::Torus {
            frame,
            major,
            minor: positive(minor + distance, "minor radius")?,
        },
        Surface3::Cone { frame, radius, tan } => {
            let cos = 1.0 / (1.0 + tan * tan).sqrt();
            let sin = tan * cos;
            let radius = radius + distance * cos;
            if radius < 0.0 {
                return Err(format!(
                    "an offset of {distance} moves the cone's reference circle past its apex"
                ));
            }
            Surface3::Cone {
                frame: Frame {
                    origin: frame.origin - frame.z * (distance * sin),
                    ..frame
                },
                radius,
                tan,
            }
        }
        other => {
            return Err(format!(
                "the offset of a {} surface is not exact as a NURBS surface",
                other.type_name()
            ));
        }
    })
}

fn describe(v: &Value) -> String {
    match v {
        Value::Integer(i) => i.to_string(),
        Value::Real(x) => x.to_string(),
        other => other.type_name().to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The point at (u, v) of a surface in STEP's own parametrizations (ISO 10303-42).
    fn step_point(s: &Surface3, u: f64, v: f64) -> DVec3 {
        match s {
            Surface3::Plane(f) => f.origin + f.x * u + f.y * v,
            Surface3::Cylinder { frame, radius } => {
                frame.origin + frame.radial(u) * *radius + frame.z * v
            }
            Surface3::Cone { frame, radius, tan } => {
                frame.origin + frame.radial(u) * (radius + v * tan) + frame.z * v
            }
            Surface3::Sphere { frame, radius } => {
                frame.origin + (frame.radial(u) * v.cos() + frame.z * v.sin()) * *radius
            }
            Surface3::Torus {
                frame,
                major,
                minor,
            } => {
                frame.origin
                    + frame.radial(u) * (major + minor * v.cos())
                    + frame.z * (minor * v.sin())
            }
            _ => unreachable!("not analytic"),
        }
    }

    #[test]
    fn an_offset_analytic_surface_is_the_basis_moved_along_its_normal() {
        let z = DVec3::new(0.3, -0.2, 1.0).normalize();
        let x = z.any_orthonormal_vector();
        let frame = Frame {
            origin: DVec3::new(1.0, 2.0, -3.0),
            x,
            y: z.cross(x),
            z,
        };
        let surfaces = [
            Surface3::Plane(frame),
            Surface3::Cylinder { frame, radius: 2.0 },
            Surface3::Cone {
                frame,
                radius: 2.0,
                tan: 0.6,
            },
            Surface3::Cone {
                frame,
                radius: 3.0,
                tan: -0.4,
            },
            Surface3::Sphere { frame, radius: 2.0 },
            Surface3::Torus {
                frame,
                major: 5.0,
                minor: 1.5,
            },
        ];
        for basis in surfaces {
            for d in [0.7, -0.4] {
                let offset = offset_surface(basis.clone(), d).unwrap();
                for (u, v) in [(0.3, 0.2), (2.0, -0.7), (4.5, 1.1)] {
                    // The unit normal S_u × S_v by central differences.
                    let h = 1e-6;
                    let su = (step_point(&basis, u + h, v) - step_point(&basis, u - h, v)) / h;
                    let sv = (step_point(&basis, u, v + h) - step_point(&basis, u, v - h)) / h;
                    let n = su.cross(sv).normalize();
                    let expected = step_point(&basis, u, v) + d * n;
                    let got = step_point(&offset, u, v);
                    assert!(
                        got.distance(expected) < 1e-8,
                        "{} offset by {d} at ({u}, {v}): {got} vs {expected}",
                        basis.type_name()
                    );
                }
            }
        }
        let refused = offset_surface(Surface3::Sphere { frame, radius: 2.0 }, -2.0);
        assert!(refused.unwrap_err().contains("not above 0"));
        assert!(offset_surface(Surface3::Plane(frame), f64::NAN).is_err());
    }
}
