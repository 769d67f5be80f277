//! STEP output (AP214, `AUTOMOTIVE_DESIGN`): each object with faces as one product whose shape
//! is a shell of `ADVANCED_FACE`s on `B_SPLINE_SURFACE_WITH_KNOTS` (rational where weighted)
//! with their knots, points and weights as they are. Every face is bounded by edge loops whose
//! edges are `SURFACE_CURVE`s: a 3D B-spline (a cubic through the edge's points, refined until
//! it lies within the tolerance of the edge, or the exact iso-curve where the trim is one) with
//! the exact p-curve of every face that uses it. Shared edges (the object's topology) are one
//! edge used by both faces, each vertex is one point where the corners the loops and shared
//! edges join meet, and every edge curve ends on its vertices; the uncertainty written is the
//! tolerance asked, or the widest gap the shape's corners and shared edges carry; faces are
//! turned so that they agree across them, and a shape whose every edge is shared is closed:
//! each of its shells outward by the sign of its volume, one solid per shell that is not a
//! cavity (a `MANIFOLD_SOLID_BREP`, or a `BREP_WITH_VOIDS` whose voids are the shells directly
//! inside it, written as `ORIENTED_CLOSED_SHELL`s turned over, as ISO 10303-42 has them);
//! otherwise it is open (a `SHELL_BASED_SURFACE_MODEL`). Lengths are in the document's unit (millimetres for a
//! unitless one).

use std::collections::HashMap;
use std::fmt::Write as _;

use glam::{DVec2, DVec3};

use crate::LengthUnit;
use crate::kernel::join::{EdgeId, Topology, face_loops};
use crate::kernel::{GeometryError, NurbsSurface, SpaceCurve, TrimCurve, TrimmedSurface};

/// The most samples an edge's 3D curve is interpolated through (the solve is banded: linear
/// in the count).
const MAX_EDGE_SAMPLES: usize = 1 << 16;

/// Stands for the uncertainty's measure until the shapes are written.
const UNCERTAINTY_MARK: &str = "LENGTH_MEASURE(<uncertainty>)";

/// One object to write.
pub struct StepShape<'a> {
    pub name: &'a str,
    pub faces: &'a [TrimmedSurface],
    /// The shared edges, where known.
    pub topology: Option<&'a Topology>,
    /// The shape's colour (sRGB, 0 to 1), written as a styled item of its solid or surface
    /// model.
    pub color: Option<[f32; 3]>,
}

struct Out {
    text: String,
    next: u64,
}

impl Out {
    fn add(&mut self, entity: impl AsRef<str>) -> u64 {
        let id = self.next;
        self.next += 1;
        let _ = writeln!(self.text, "#{id}={};", entity.as_ref());
        id
    }
}

fn real(x: f64) -> String {
    if x == 0.0 {
        return "0.".into();
    }
    let s = format!("{x:E}");
    // Part 21 reals need a decimal point in the mantissa: 1E-3 → 1.E-3.
    match s.split_once('E') {
        Some((m, e)) if !m.contains('.') => format!("{m}.E{e}"),
        _ => s,
    }
}

fn text(s: &str) -> String {
    let mut out = String::from("'");
    for c in s.chars() {
        match c {
            '\'' => out.push_str("''"),
            '\\' => out.push_str("\\\\"),
            c if c.is_ascii() && !c.is_ascii_control() => out.push(c),
            c => {
                let mut units = [0u16; 2];
                out.push_str("\\X2\\");
                for u in c.encode_utf16(&mut units) {
                    let _ = write!(out, "{u:04X}");
                }
                out.push_str("\\X0\\");
            }
        }
    }
    out.push('\'');
    out
}

fn refs(ids: &[u64]) -> String {
    let items: Vec<String> = ids.iter().map(|i| format!("#{i}")).collect();
    format!("({})", items.join(","))
}

/// Distinct knots and multiplicities.
fn knot_lists(knots: &[f64]) -> (String, String) {
    let mut values: Vec<f64> = Vec::new();
    let mut counts: Vec<usize> = Vec::new();
    for &k in knots {
        if values.last() == Some(&k) {
            if let Some(c) = counts.last_mut() {
                *c += 1;
            }
        } else {
            values.push(k);
            counts.push(1);
        }
    }
    (
        format!(
            "({})",
            counts
                .iter()
                .map(|c| c.to_string())
                .collect::<Vec<_>>()
                .join(",")
        ),
        format!(
            "({})",
            values
                .iter()
                .map(|&v| real(v))
                .collect::<Vec<_>>()
                .join(",")
        ),
    )
}

fn point3(out: &mut Out, p: DVec3) -> u64 {
    out.add(format!(
        "CARTESIAN_POINT('',({},{},{}))",
        real(p.x),
        real(p.y),
        real(p.z)
    ))
}

fn point2(out: &mut Out, p: DVec2) -> u64 {
    out.add(format!("CARTESIAN_POINT('',({},{}))", real(p.x), real(p.y)))
}

fn surface(out: &mut Out, s: &NurbsSurface) -> u64 {
    let [p, q] = s.degree();
    let [nu, nv] = s.count();
    let mut rows = Vec::with_capacity(nu);
    for i in 0..nu {
        let ids: Vec<u64> = (0..nv)
            .map(|j| point3(out, s.control_point(i, j)))
            .collect();
        rows.push(refs(&ids));
    }
    let [ku, kv] = s.knots();
    let (um, uk) = knot_lists(ku);
    let (vm, vk) = knot_lists(kv);
    let grid = format!("({})", rows.join(","));
    if s.is_polynomial() {
        out.add(format!(
            "B_SPLINE_SURFACE_WITH_KNOTS('',{p},{q},{grid},.UNSPECIFIED.,.F.,.F.,.F.,{um},{vm},{uk},{vk},.UNSPECIFIED.)"
        ))
    } else {
        let weights: Vec<String> = (0..nu)
            .map(|i| {
                format!(
                    "({})",
                    (0..nv)
                        .map(|j| real(s.weight(i, j)))
                        .collect::<Vec<_>>()
                        .join(",")
                )
            })
            .collect();
        out.add(format!(
            "(BOUNDED_SURFACE() B_SPLINE_SURFACE({p},{q},{grid},.UNSPECIFIED.,.F.,.F.,.F.) B_SPLINE_SURFACE_WITH_KNOTS({um},{vm},{uk},{vk},.UNSPECIFIED.) GEOMETRIC_REPRESENTATION_ITEM() RATIONAL_B_SPLINE_SURFACE(({})) REPRESENTATION_ITEM('') SURFACE())",
            weights.join(",")
        ))
    }
}

fn curve_entity(degree: usize, ids: &[u64], knots: &[f64], weights: Option<Vec<f64>>) -> String {
    let (m, k) = knot_lists(knots);
    match weights {
        None => format!(
            "B_SPLINE_CURVE_WITH_KNOTS('',{degree},{},.UNSPECIFIED.,.F.,.F.,{m},{k},.UNSPECIFIED.)",
            refs(ids)
        ),
        Some(w) => format!(
            "(BOUNDED_CURVE() B_SPLINE_CURVE({degree},{},.UNSPECIFIED.,.F.,.F.) B_SPLINE_CURVE_WITH_KNOTS({m},{k},.UNSPECIFIED.) CURVE() GEOMETRIC_REPRESENTATION_ITEM() RATIONAL_B_SPLINE_CURVE(({})) REPRESENTATION_ITEM(''))",
            refs(ids),
            w.iter().map(|&x| real(x)).collect::<Vec<_>>().join(",")
        ),
    }
}

fn curve3(out: &mut Out, c: &SpaceCurve) -> u64 {
    let ids: Vec<u64> = (0..c.count())
        .map(|i| point3(out, c.control_point(i)))
        .collect();
    let w = (!c.is_polynomial()).then(|| (0..c.count()).map(|i| c.weight(i)).collect());
    out.add(curve_entity(c.degree(), &ids, c.knots(), w))
}

fn curve2(out: &mut Out, c: &TrimCurve) -> u64 {
    let ids: Vec<u64> = (0..c.count())
        .map(|i| point2(out, c.control_point(i)))
        .collect();
    let w = (!c.is_polynomial()).then(|| (0..c.count()).map(|i| c.weight(i)).collect());
    out.add(curve_entity(c.degree(), &ids, c.knots(), w))
}

/// The affine map of a surface that is one: a polynomial bilinear patch whose four points
/// form a parallelogram (a plane face as knotwork builds it), S(u, v) = O + U·u + V·v.
fn affine_map(s: &NurbsSurface) -> Option<(DVec3, DVec3, DVec3)> {
    if s.degree() != [1, 1] || s.count() != [2, 2] || !s.is_polynomial() {
        return None;
    }
    let [(u0, u1), (v0, v1)] = s.domain();
    let (p00, p10, p01, p11) = (
        s.control_point(0, 0),
        s.control_point(1, 0),
        s.control_point(0, 1),
        s.control_point(1, 1),
    );
    let size = p00.distance(p11).max(p10.distance(p01));
    if (p00 + p11).distance(p10 + p01) > 1e-12 * size {
        return None;
    }
    let (du, dv) = ((p10 - p00) / (u1 - u0), (p01 - p00) / (v1 - v0));
    Some((p00 - du * u0 - dv * v0, du, dv))
}

/// The 3D curve of a trim curve on its surface: on a plane (an affine surface) the trim's
/// image exactly (its points mapped, its weights and knots kept); the exact iso-curve where
/// the trim is a straight iso-line; else a cubic through points of S(c(t)), doubled until its
/// middles lie within `tolerance`. Each has the trim's parameter.
/// The largest distance from the p-curve `trim` on `surface` to the edge curve `c3`, at
/// points half way between 16 evenly spaced parameters of the p-curve, each to its nearest
/// point of the curve (Newton's iteration from the nearest of as many samples of `c3`): what
/// the file's uncertainty must cover for a reader to find the p-curve on its edge (faces
/// read from other systems share edges that lie apart, the ends as well as between them).
fn pcurve_gap(
    surface: &NurbsSurface,
    trim: &TrimCurve,
    c3: &SpaceCurve,
) -> Result<f64, GeometryError> {
    const SAMPLES: usize = 16;
    let (d0, d1) = trim.domain();
    let (a, b) = c3.domain();
    let along: Vec<(f64, DVec3)> = (0..=SAMPLES)
        .map(|k| {
            let t = a + (b - a) * k as f64 / SAMPLES as f64;
            c3.point_at(t).map(|p| (t, p))
        })
        .collect::<Result<_, _>>()?;
    let mut gap: f64 = 0.0;
    for k in 0..SAMPLES {
        let s = (k as f64 + 0.5) / SAMPLES as f64;
        let p = surface.point_at_clamped(trim.point_at(d0 + (d1 - d0) * s)?)?;
        let start = along
            .iter()
            .min_by(|x, y| x.1.distance_squared(p).total_cmp(&y.1.distance_squared(p)))
            .map_or(a, |x| x.0);
        let t = c3.closest_parameter_from(p, start)?;
        gap = gap.max(c3.point_at(t)?.distance(p));
    }
    Ok(gap)
}

fn edge_curve(
    face: &TrimmedSurface,
    trim: &TrimCurve,
    tolerance: f64,
) -> Result<SpaceCurve, GeometryError> {
    let s = face.surface();
    if let Some((origin, du, dv)) = affine_map(s) {
        return trim.map_into(|q| origin + du * q.x + dv * q.y);
    }
    let (a, b) = trim.ends()?;
    if trim.degree() == 1 && trim.count() == 2 {
        let dir = if a.x == b.x {
            Some((crate::kernel::Direction::U, a.x, a.y, b.y))
        } else if a.y == b.y {
            Some((crate::kernel::Direction::V, a.y, a.x, b.x))
        } else {
            None
        };
        if let Some((d, fixed, t0, t1)) = dir {
            // The iso-curve at `fixed` runs along the other direction.
            if let Ok(iso) = s.isocurve(d, fixed, 0) {
                let (lo, hi) = (t0.min(t1), t0.max(t1));
                let (d0, d1) = iso.domain();
                let mut piece = iso;
                if hi < d1 {
                    piece = piece.split(hi)?.0;
                }
                if lo > d0 {
                    piece = piece.split(lo)?.1;
                }
                let piece = if t1 < t0 { piece.reverse() } else { piece };
                // On the p-curve's domain: the iso-curve's parameter is the line's, mapped
                // affinely, so the two agree at the same parameter.
                let (d0, d1) = trim.domain();
                return piece.reparametrized(d0, d1);
            }
        }
    }
    let (d0, d1) = trim.domain();
    let at = |t: f64| -> Result<DVec3, GeometryError> {
        s.point_at_clamped(trim.point_at(d0 + (d1 - d0) * t)?)
    };
    // Sampled at evenly spaced parameters of the p-curve and interpolated at the same
    // parameters on the p-curve's domain, so that the 3D curve and the p-curve agree at the
    // same parameter (OpenCASCADE's SameParameter), checked half way between samples.
    let mut n = 8usize.max(trim.count() * 2);
    loop {
        let points: Vec<DVec3> = (0..=n)
            .map(|k| at(k as f64 / n as f64))
            .collect::<Result<_, _>>()?;
        let fitted = crate::kernel::splines::interpolate_through(
            &points,
            3,
            crate::kernel::splines::Parametrization::Uniform,
            None,
        )?;
        let mut worst: f64 = 0.0;
        for k in 0..n {
            let t = (k as f64 + 0.5) / n as f64;
            worst = worst.max(fitted.point_at(t)?.distance(at(t)?));
        }
        if worst <= tolerance || n >= MAX_EDGE_SAMPLES {
            // The ends exactly on the corners.
            let last = fitted.count() - 1;
            let c = fitted
                .with_point(0, points[0])?
                .with_point(last, points[n])?;
            return c.reparametrized(d0, d1);
        }
        n *= 2;
    }
}

/// The vertices of a shape: every corner of every loop (where one trim curve ends and the
/// next starts) belongs to one vertex, found by joining the corners that the loops and the
/// shared edges say are one (union–find), so that each vertex is one point even where the
/// faces' own corners lie apart by more than the tolerance (files from other systems carry
/// gaps up to their own uncertainty). Each vertex lies at the mean of its corners.
struct Vertices {
    /// Index of the start corner of each curve (its end is the next index).
    first: HashMap<EdgeId, usize>,
    /// The class of each corner.
    class: Vec<usize>,
    /// The point of each class (indexed by class).
    point: Vec<DVec3>,
    /// Twice the largest distance of a corner from its vertex: a bound on how far apart the
    /// corners of one vertex lie.
    spread: f64,
}

impl Vertices {
    fn of(
        faces: &[TrimmedSurface],
        loops: &[Vec<Vec<TrimCurve>>],
        topology: &Topology,
    ) -> Result<Self, GeometryError> {
        let mut first = HashMap::new();
        let mut points = Vec::new();
        let mut parent: Vec<usize> = Vec::new();
        fn root(parent: &mut [usize], mut k: usize) -> usize {
            while parent[k] != k {
                parent[k] = parent[parent[k]];
                k = parent[k];
            }
            k
        }
        fn join(parent: &mut [usize], a: usize, b: usize) {
            let (ra, rb) = (root(parent, a), root(parent, b));
            if ra != rb {
                parent[ra.max(rb)] = ra.min(rb);
            }
        }
        for (f, face) in faces.iter().enumerate() {
            for (l, lp) in loops[f].iter().enumerate() {
                let start = points.len();
                for (c, trim) in lp.iter().enumerate() {
                    first.insert(
                        EdgeId {
                            face: f,
                            loop_index: l,
                            curve: c,
                        },
                        points.len(),
                    );
                    let (a, b) = trim.ends()?;
                    points.push(face.surface().point_at_clamped(a)?);
                    points.push(face.surface().point_at_clamped(b)?);
                    let k = parent.len();
                    parent.extend([k, k + 1]);
                }
                // Each curve's end is the next one's start.
                let n = lp.len();
                for c in 0..n {
                    join(&mut parent, start + 2 * c + 1, start + 2 * ((c + 1) % n));
                }
            }
        }
        for id in &topology.degenerate {
            if let Some(&k) = first.get(id) {
                join(&mut parent, k, k + 1);
            }
        }
        for e in &topology.shared {
            if let (Some(&a), Some(&b)) = (first.get(&e.a), first.get(&e.b)) {
                let (b0, b1) = if e.reversed { (b + 1, b) } else { (b, b + 1) };
                join(&mut parent, a, b0);
                join(&mut parent, a + 1, b1);
            }
        }
        let class: Vec<usize> = (0..parent.len()).map(|k| root(&mut parent, k)).collect();
        let mut sum = vec![(DVec3::ZERO, 0usize); parent.len()];
        for (k, &r) in class.iter().enumerate() {
            sum[r].0 += points[k];
            sum[r].1 += 1;
        }
        let point: Vec<DVec3> = sum
            .into_iter()
            .map(|(p, n)| if n > 0 { p / n as f64 } else { p })
            .collect();
        let spread = class
            .iter()
            .enumerate()
            .map(|(k, &r)| 2.0 * points[k].distance(point[r]))
            .fold(0.0, f64::max);
        Ok(Self {
            first,
            class,
            point,
            spread,
        })
    }

    /// The class of the start (or end) corner of a curve.
    fn corner(&self, id: &EdgeId, end: bool) -> Option<usize> {
        self.first
            .get(id)
            .map(|&k| self.class[k + usize::from(end)])
    }
}

/// The signed volume the faces of `shell` (indices into `faces`, within the box `lo`–`hi`)
/// enclose, with each face turned by `flip`: the divergence theorem with the field
/// ((p − c)·d) d, whose divergence is 1, over a coarse grid of each face's kept region, c the
/// box's centre. Its flux through a flat face parallel
/// to d is nil, so d is taken along the flat face with the most trim curves (a plate's face
/// with its holes), and along the next such face where the two are not parallel: those faces
/// are passed over, and with them the trim index their many loops would need. A face that
/// keeps a rectangle of its domain needs none either.
fn signed_volume(
    faces: &[TrimmedSurface],
    flip: &[bool],
    shell: &[usize],
    (lo, hi): (DVec3, DVec3),
) -> f64 {
    const N: usize = 24;
    let centre = 0.5 * (lo + hi);
    let flat = 1e-12 * lo.distance(hi);
    let normals: Vec<Option<DVec3>> = shell
        .iter()
        .map(|&k| faces[k].surface().plane(flat).map(|(_, n)| n))
        .collect();
    let curves = |k: usize| faces[k].loops().iter().map(Vec::len).sum::<usize>();
    let mut busiest: Vec<(usize, DVec3)> = shell
        .iter()
        .zip(&normals)
        .filter_map(|(&k, n)| n.map(|n| (curves(k), n)))
        .collect();
    busiest.sort_by_key(|b| std::cmp::Reverse(b.0));
    let direction = match busiest.as_slice() {
        [] => DVec3::X,
        [(_, n), rest @ ..] => rest
            .iter()
            .map(|(_, m)| n.cross(*m))
            .find(|d| d.length() > 1e-6)
            .map_or_else(|| n.any_orthonormal_vector(), DVec3::normalize),
    };
    let mut total = 0.0;
    for (&k, normal) in shell.iter().zip(&normals) {
        if normal.is_some_and(|n| n.dot(direction).abs() <= 1e-12) {
            continue;
        }
        let face = &faces[k];
        let s = face.surface();
        let kept = face.kept_rectangle();
        let [(u0, u1), (v0, v1)] = match kept {
            Some([u0, u1, v0, v1]) => [(u0, u1), (v0, v1)],
            None => s.domain(),
        };
        let (du, dv) = ((u1 - u0) / N as f64, (v1 - v0) / N as f64);
        for i in 0..N {
            for j in 0..N {
                let (u, v) = (u0 + du * (i as f64 + 0.5), v0 + dv * (j as f64 + 0.5));
                if kept.is_none() && !face.contains(u, v) {
                    continue;
                }
                if let Ok(d) = s.evaluate(u, v) {
                    let n = d.su.cross(d.sv) * (du * dv);
                    let c = (d.point - centre).dot(direction) * n.dot(direction);
                    total += if flip[k] { -c } else { c };
                }
            }
        }
    }
    total
}

/// The length unit entity of `unit`: an SI unit for the metric ones, a conversion-based unit
/// defined in millimetres for the inch and the foot (ISO 10303-41, `conversion_based_unit`),
/// so that coordinates are written as the document holds them.
fn length_unit(out: &mut Out, unit: LengthUnit) -> u64 {
    let prefix = match unit {
        LengthUnit::Millimetre => ".MILLI.",
        LengthUnit::Centimetre => ".CENTI.",
        LengthUnit::Metre => "$",
        LengthUnit::Inch | LengthUnit::Foot => {
            let mm = out.add("(LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.MILLI.,.METRE.))");
            let measure = out.add(format!(
                "LENGTH_MEASURE_WITH_UNIT(LENGTH_MEASURE({}),#{mm})",
                real(unit.metres() * 1e3)
            ));
            let exponents = out.add("DIMENSIONAL_EXPONENTS(1.,0.,0.,0.,0.,0.,0.)");
            let name = if unit == LengthUnit::Inch {
                "INCH"
            } else {
                "FOOT"
            };
            return out.add(format!(
                "(CONVERSION_BASED_UNIT('{name}',#{measure}) LENGTH_UNIT() NAMED_UNIT(#{exponents}))"
            ));
        }
    };
    out.add(format!(
        "(LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT({prefix},.METRE.))"
    ))
}

/// Colours `item` (AP214's presentation: a styled item whose surface style's fill area is the
/// colour, on both sides, listed in a presentation representation of the context).
fn styled_item(out: &mut Out, item: u64, [r, g, b]: [f32; 3], context: u64) {
    let c = |x: f32| real(f64::from(x.clamp(0.0, 1.0)));
    let colour = out.add(format!("COLOUR_RGB('',{},{},{})", c(r), c(g), c(b)));
    let fill_colour = out.add(format!("FILL_AREA_STYLE_COLOUR('',#{colour})"));
    let fill = out.add(format!("FILL_AREA_STYLE('',(#{fill_colour}))"));
    let area = out.add(format!("SURFACE_STYLE_FILL_AREA(#{fill})"));
    let side = out.add(format!("SURFACE_SIDE_STYLE('',(#{area}))"));
    let usage = out.add(format!("SURFACE_STYLE_USAGE(.BOTH.,#{side})"));
    let assignment = out.add(format!("PRESENTATION_STYLE_ASSIGNMENT((#{usage}))"));
    let styled = out.add(format!("STYLED_ITEM('color',(#{assignment}),#{item})"));
    out.add(format!(
        "MECHANICAL_DESIGN_GEOMETRIC_PRESENTATION_REPRESENTATION('',(#{styled}),#{context})"
    ));
}

/// A STEP file (AP214) of `shapes`, in `unit` (millimetres for a unitless document), named `file_name` in its header.
pub fn write(
    shapes: &[StepShape],
    file_name: &str,
    tolerance: f64,
    unit: Option<LengthUnit>,
) -> Result<String, GeometryError> {
    let mut out = Out {
        text: String::new(),
        next: 1,
    };
    let app =
        out.add("APPLICATION_CONTEXT('core data for automotive mechanical design processes')");
    out.add(format!(
        "APPLICATION_PROTOCOL_DEFINITION('international standard','automotive_design',2000,#{app})"
    ));
    let product_context = out.add(format!("PRODUCT_CONTEXT('',#{app},'mechanical')"));
    let definition_context = out.add(format!(
        "PRODUCT_DEFINITION_CONTEXT('part definition',#{app},'design')"
    ));
    let mm = length_unit(&mut out, unit.unwrap_or(LengthUnit::Millimetre));
    let rad = out.add("(NAMED_UNIT(*) PLANE_ANGLE_UNIT() SI_UNIT($,.RADIAN.))");
    let sr = out.add("(NAMED_UNIT(*) SI_UNIT($,.STERADIAN.) SOLID_ANGLE_UNIT())");
    // Written once the shapes are: the tolerance asked, or the gaps the shapes' edges and
    // vertices carry where those are wider (a model read from a file within its own
    // uncertainty keeps it).
    let uncertainty = out.add(format!(
        "UNCERTAINTY_MEASURE_WITH_UNIT({UNCERTAINTY_MARK},#{mm},'distance_accuracy_value','confusion accuracy')"
    ));
    let mut uncertain = tolerance;
    let context = out.add(format!(
        "(GEOMETRIC_REPRESENTATION_CONTEXT(3) GLOBAL_UNCERTAINTY_ASSIGNED_CONTEXT((#{uncertainty})) GLOBAL_UNIT_ASSIGNED_CONTEXT((#{mm},#{rad},#{sr})) REPRESENTATION_CONTEXT('Context #1','3D Context with UNIT and UNCERTAINTY'))"
    ));
    let context_2d = out.add("(GEOMETRIC_REPRESENTATION_CONTEXT(2) PARAMETRIC_REPRESENTATION_CONTEXT() REPRESENTATION_CONTEXT('2D SPACE',''))");
    for shape in shapes {
        let faces = shape.faces;
        let topology = match shape.topology {
            Some(t) => t.clone(),
            None => crate::kernel::join::find_topology(faces, tolerance)?,
        };
        let loops: Vec<Vec<Vec<TrimCurve>>> =
            faces.iter().map(face_loops).collect::<Result<_, _>>()?;
        let closed = topology.is_closed();
        let mut flip = crate::kernel::join::orientation(faces.len(), &topology);
        // Closed: each shell turned to enclose positive volume, as a solid is written; a void
        // is its shell written so and turned over where the solid refers to it.
        let shells = topology.components(faces.len());
        let mut nesting = vec![(None, false); shells.len()];
        if closed {
            let boxes: Vec<(DVec3, DVec3)> = shells
                .iter()
                .map(|shell| {
                    shell.iter().map(|&f| faces[f].surface().bounds()).fold(
                        (DVec3::INFINITY, DVec3::NEG_INFINITY),
                        |(lo, hi), (a, b)| (lo.min(a), hi.max(b)),
                    )
                })
                .collect();
            let mut volumes = Vec::with_capacity(shells.len());
            for (shell, &bounds) in shells.iter().zip(&boxes) {
                let volume = signed_volume(faces, &flip, shell, bounds);
                if volume < 0.0 {
                    for &f in shell {
                        flip[f] = !flip[f];
                    }
                }
                volumes.push(volume.abs());
            }
            nesting = crate::kernel::join::shell_nesting(&boxes, &volumes);
        }
        let surfaces: Vec<u64> = faces
            .iter()
            .map(|f| surface(&mut out, f.surface()))
            .collect();
        // Vertices: the corners the loops and shared edges join, and those within the
        // tolerance of each other.
        let corners = Vertices::of(faces, &loops, &topology)?;
        uncertain = topology
            .shared
            .iter()
            .map(|e| e.gap)
            .fold(uncertain.max(corners.spread), f64::max);
        let mut vertices: Vec<(DVec3, u64)> = Vec::new();
        let mut of_class: HashMap<usize, (DVec3, u64)> = HashMap::new();
        let mut vertex = |out: &mut Out, class: Option<usize>, p: DVec3| -> (DVec3, u64) {
            if let Some(&v) = class.and_then(|c| of_class.get(&c)) {
                return v;
            }
            let p = class.map_or(p, |c| corners.point[c]);
            let v = match vertices.iter().find(|(q, _)| q.distance(p) <= tolerance) {
                Some(&v) => v,
                None => {
                    let pid = point3(out, p);
                    let id = out.add(format!("VERTEX_POINT('',#{pid})"));
                    vertices.push((p, id));
                    (p, id)
                }
            };
            if let Some(c) = class {
                of_class.insert(c, v);
            }
            v
        };
        let partner: HashMap<EdgeId, (EdgeId, bool)> = topology
            .shared
            .iter()
            .flat_map(|s| [(s.a, (s.b, s.reversed)), (s.b, (s.a, s.reversed))])
            .collect();
        let degenerate: std::collections::HashSet<EdgeId> =
            topology.degenerate.iter().copied().collect();
        // Edge id and whether the use runs along it.
        let mut written: HashMap<EdgeId, (u64, bool)> = HashMap::new();
        let mut face_ids = Vec::new();
        for (f, face) in faces.iter().enumerate() {
            let mut bounds = Vec::new();
            // The outer bound: the loop enclosing the most.
            let outer_loop = (0..loops[f].len())
                .max_by(|&a, &b| {
                    let area = |k: usize| {
                        crate::kernel::trim::signed_area(&crate::kernel::trim::flatten_loop(
                            &loops[f][k],
                            1e-4,
                        ))
                        .abs()
                    };
                    area(a).total_cmp(&area(b))
                })
                .unwrap_or(0);
            for (l, lp) in loops[f].iter().enumerate() {
                let mut oriented = Vec::new();
                for (c, trim) in lp.iter().enumerate() {
                    let id = EdgeId {
                        face: f,
                        loop_index: l,
                        curve: c,
                    };
                    if degenerate.contains(&id) {
                        continue;
                    }
                    let (edge, along) = match written.get(&id) {
                        Some(&e) => e,
                        None => {
                            let c3 = edge_curve(face, trim, tolerance)?;
                            let (p0, p1) = c3.ends()?;
                            let (p0, v0) = vertex(&mut out, corners.corner(&id, false), p0);
                            let (p1, v1) = vertex(&mut out, corners.corner(&id, true), p1);
                            // The curve ends on its vertices exactly.
                            let last = c3.count() - 1;
                            let c3 = c3.with_point(0, p0)?.with_point(last, p1)?;
                            let cid = curve3(&mut out, &c3);
                            let mut pcurves = vec![(f, trim.clone())];
                            if let Some(&(other, reversed)) = partner.get(&id)
                                && let Some(t) = loops[other.face]
                                    .get(other.loop_index)
                                    .and_then(|l| l.get(other.curve))
                            {
                                pcurves.push((
                                    other.face,
                                    if reversed { t.reverse() } else { t.clone() },
                                ));
                            }
                            let mut pids = Vec::new();
                            for (k, (g, pc)) in pcurves.iter().enumerate() {
                                // The curve was fitted to the first (within the tolerance,
                                // its ends moved by the corners' spread): the other is measured.
                                if k > 0 {
                                    uncertain =
                                        uncertain.max(pcurve_gap(faces[*g].surface(), pc, &c3)?);
                                }
                                let c2 = curve2(&mut out, pc);
                                let rep = out.add(format!(
                                    "DEFINITIONAL_REPRESENTATION('',(#{c2}),#{context_2d})"
                                ));
                                pids.push(out.add(format!("PCURVE('',#{},#{rep})", surfaces[*g])));
                            }
                            let sc = out.add(format!(
                                "SURFACE_CURVE('',#{cid},{},.PCURVE_S1.)",
                                refs(&pids)
                            ));
                            let eid = out.add(format!("EDGE_CURVE('',#{v0},#{v1},#{sc},.T.)"));
                            written.insert(id, (eid, true));
                            if let Some(&(other, reversed)) = partner.get(&id) {
                                written.insert(other, (eid, !reversed));
                            }
                            (eid, true)
                        }
                    };
                    oriented.push(out.add(format!(
                        "ORIENTED_EDGE('',*,*,#{edge},{})",
                        if along { ".T." } else { ".F." }
                    )));
                }
                if oriented.is_empty() {
                    continue;
                }
                let lid = out.add(format!("EDGE_LOOP('',{})", refs(&oriented)));
                let outer = l == outer_loop;
                let sense = if flip[f] { ".F." } else { ".T." };
                bounds.push(out.add(format!(
                    "{}('',#{lid},{sense})",
                    if outer {
                        "FACE_OUTER_BOUND"
                    } else {
                        "FACE_BOUND"
                    }
                )));
            }
            face_ids.push(out.add(format!(
                "ADVANCED_FACE('',{},#{},{})",
                refs(&bounds),
                surfaces[f],
                if flip[f] { ".F." } else { ".T." }
            )));
        }
        let origin = point3(&mut out, DVec3::ZERO);
        let z = out.add("DIRECTION('',(0.,0.,1.))");
        let x = out.add("DIRECTION('',(1.,0.,0.))");
        let axis = out.add(format!("AXIS2_PLACEMENT_3D('',#{origin},#{z},#{x})"));
        let name = text(shape.name);
        let (rep, items) = if closed {
            // One solid per shell that is not a void: a MANIFOLD_SOLID_BREP, or a
            // BREP_WITH_VOIDS naming the voids directly inside it, turned over.
            let shell_ids: Vec<u64> = shells
                .iter()
                .map(|shell| {
                    let ids: Vec<u64> = shell.iter().map(|&f| face_ids[f]).collect();
                    out.add(format!("CLOSED_SHELL('',{})", refs(&ids)))
                })
                .collect();
            let mut solids = Vec::new();
            for (i, &shell) in shell_ids.iter().enumerate() {
                if nesting[i].1 {
                    continue;
                }
                let voids: Vec<u64> = (0..shells.len())
                    .filter(|&j| nesting[j] == (Some(i), true))
                    .map(|j| out.add(format!("ORIENTED_CLOSED_SHELL('',*,#{},.F.)", shell_ids[j])))
                    .collect();
                solids.push(if voids.is_empty() {
                    out.add(format!("MANIFOLD_SOLID_BREP({name},#{shell})"))
                } else {
                    out.add(format!("BREP_WITH_VOIDS({name},#{shell},{})", refs(&voids)))
                });
            }
            let items: Vec<u64> = std::iter::once(axis)
                .chain(solids.iter().copied())
                .collect();
            let rep = out.add(format!(
                "ADVANCED_BREP_SHAPE_REPRESENTATION({name},{},#{context})",
                refs(&items)
            ));
            (rep, solids)
        } else {
            let shell = out.add(format!("OPEN_SHELL('',{})", refs(&face_ids)));
            let model = out.add(format!("SHELL_BASED_SURFACE_MODEL({name},(#{shell}))"));
            let rep = out.add(format!(
                "MANIFOLD_SURFACE_SHAPE_REPRESENTATION({name},(#{axis},#{model}),#{context})"
            ));
            (rep, vec![model])
        };
        if let Some(color) = shape.color {
            for item in items {
                styled_item(&mut out, item, color, context);
            }
        }
        let product = out.add(format!("PRODUCT({name},{name},'',(#{product_context}))"));
        let formation = out.add(format!("PRODUCT_DEFINITION_FORMATION('','',#{product})"));
        let definition = out.add(format!(
            "PRODUCT_DEFINITION('design','',#{formation},#{definition_context})"
        ));
        let shape_def = out.add(format!("PRODUCT_DEFINITION_SHAPE('','',#{definition})"));
        out.add(format!(
            "SHAPE_DEFINITION_REPRESENTATION(#{shape_def},#{rep})"
        ));
    }
    let data = out.text.replacen(
        UNCERTAINTY_MARK,
        &format!("LENGTH_MEASURE({})", real(uncertain)),
        1,
    );
    let mut file = String::new();
    let _ = writeln!(file, "ISO-10303-21;");
    let _ = writeln!(file, "HEADER;");
    let _ = writeln!(file, "FILE_DESCRIPTION(('knotwork export'),'2;1');");
    let _ = writeln!(
        file,
        "FILE_NAME({},'',(''),(''),'knotwork {}','knotwork','');",
        text(file_name),
        env!("CARGO_PKG_VERSION")
    );
    let _ = writeln!(
        file,
        "FILE_SCHEMA(('AUTOMOTIVE_DESIGN {{ 1 0 10303 214 1 1 1 1 }}'));"
    );
    let _ = writeln!(file, "ENDSEC;");
    let _ = writeln!(file, "DATA;");
    file.push_str(&data);
    let _ = writeln!(file, "ENDSEC;");
    let _ = writeln!(file, "END-ISO-10303-21;");
    Ok(file)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernel::construct;

    #[test]
    fn a_plane_faces_edge_curve_is_its_trims_exact_image_at_the_same_parameter() {
        // A plane over [0, 1]² (u along 4x + y, v along z) with a rational circle trim of
        // radius 0.3: the 3D curve is S(c(t)) at every t, to rounding, with the trim's
        // knots and weights; a skewed bilinear patch (not a parallelogram) is not affine.
        let plane = construct::plane(
            DVec3::new(1.0, 2.0, 3.0),
            DVec3::new(4.0, 1.0, 0.0),
            DVec3::new(0.0, 0.0, 2.5),
        )
        .unwrap();
        let circle = construct::arc(
            DVec3::new(0.5, 0.5, 0.0),
            DVec3::X,
            DVec3::Y,
            0.3,
            0.0,
            std::f64::consts::TAU,
        )
        .unwrap();
        let trim = circle.map_into(|p| p.truncate()).unwrap();
        let face = TrimmedSurface::new(plane.clone(), vec![vec![trim.clone()]]).unwrap();
        let c3 = edge_curve(&face, &trim, 1e-9).unwrap();
        assert_eq!(c3.knots(), trim.knots());
        assert_eq!(c3.count(), trim.count());
        let (a, b) = trim.domain();
        for k in 0..=64 {
            let t = a + (b - a) * f64::from(k) / 64.0;
            let on = plane.point_at_clamped(trim.point_at(t).unwrap()).unwrap();
            assert!(c3.point_at(t).unwrap().distance(on) < 1e-12, "at {t}");
        }
        let skewed = construct::bilinear(
            DVec3::ZERO,
            DVec3::X,
            DVec3::new(0.0, 1.0, 0.5),
            DVec3::new(1.0, 1.0, 0.0),
        )
        .unwrap();
        assert!(affine_map(&skewed).is_none());
        assert!(affine_map(&plane).is_some());
    }

    /// The file of a shape of `faces` with `topology`, written at `tolerance`.
    fn two_faces_written(faces: &[TrimmedSurface], topology: &Topology, tolerance: f64) -> String {
        let shape = StepShape {
            name: "two faces",
            faces,
            topology: Some(topology),
            color: None,
        };
        write(&[shape], "two-faces.step", tolerance, None).unwrap()
    }

    /// Two faces whose shared edge's ends lie 3e-3 of their size apart (as files from other
    /// systems carry, within their own uncertainty), written at a tolerance of 1e-6 of the
    /// size: each corner the topology joins is one vertex, every edge ends on its vertices,
    /// and the file says how far apart its corners lie, so both faces read back, their loops
    /// closed and their edge shared. Before, the second face's loop ended 3e-3 from where it
    /// started and the face was skipped.
    #[test]
    fn faces_whose_shared_corners_lie_apart_read_back_with_their_edge_shared() {
        let size = 37.0;
        let turn = glam::DQuat::from_euler(glam::EulerRot::XYZ, 0.7, -1.1, 0.4);
        let place = |p: DVec3| turn * (p * size) + DVec3::new(-120.0, 45.0, 8.0);
        let gap = 3e-3;
        let plane = |o: DVec3, u: DVec3, v: DVec3| {
            let o = place(o);
            construct::plane(o, place(u) - o, place(v) - o).unwrap()
        };
        let a = plane(DVec3::ZERO, DVec3::X, DVec3::Y);
        let b = plane(
            DVec3::new(1.0, 0.0, gap),
            DVec3::new(2.0, 0.0, 0.3),
            DVec3::new(1.0, 1.0, gap),
        );
        let faces = [TrimmedSurface::untrimmed(a), TrimmedSurface::untrimmed(b)];
        let topology = crate::kernel::join::find_topology(&faces, 1e-2 * size).unwrap();
        assert_eq!(topology.shared.len(), 1);
        let text = two_faces_written(&faces, &topology, 1e-6 * size);
        // Four corners each, two of them shared.
        assert_eq!(text.matches("VERTEX_POINT(").count(), 6);
        let model = crate::read::read(text.as_bytes(), &mut |_, _| true).unwrap();
        assert!(model.warnings.is_empty(), "{:?}", model.warnings);
        let body = &model.bodies[0];
        assert_eq!(body.faces.len(), 2);
        assert_eq!(body.topology.shared.len(), 1, "{:?}", body.topology);
        assert!(
            model.tolerance >= gap * size,
            "read at {:e}, the corners {:e} apart",
            model.tolerance,
            gap * size
        );
    }

    /// Two faces whose shared edge meets at its ends but bows 3e-3 of their size apart half way
    /// (a file from another system read within its uncertainty, whose topology measured the
    /// ends alone), written at 1e-6 of the size: the file says how far the edge's p-curves lie
    /// from its curve, so both faces read back with the edge shared. Before, the bowed face's
    /// p-curve was refused ("its edges do not lie on its surface").
    #[test]
    fn faces_whose_shared_edge_bows_apart_read_back_with_their_edge_shared() {
        let size = 23.0;
        let turn = glam::DQuat::from_euler(glam::EulerRot::XYZ, -0.3, 0.9, 2.2);
        let place = |p: DVec3| turn * (p * size) + DVec3::new(64.0, -7.0, 310.0);
        let bow = 3e-3;
        let plane = construct::plane(
            place(DVec3::ZERO),
            place(DVec3::X) - place(DVec3::ZERO),
            place(DVec3::Y) - place(DVec3::ZERO),
        )
        .unwrap();
        // Quadratic along the edge (u = 0), its middle control point 2 bow off the plane.
        let bowed = NurbsSurface::bezier(
            [1, 2],
            [
                DVec3::new(1.0, 0.0, 0.0),
                DVec3::new(1.0, 0.5, 2.0 * bow),
                DVec3::new(1.0, 1.0, 0.0),
                DVec3::new(2.0, 0.0, 0.3),
                DVec3::new(2.0, 0.5, 0.3),
                DVec3::new(2.0, 1.0, 0.3),
            ]
            .map(place)
            .to_vec(),
            None,
        )
        .unwrap();
        let faces = [
            TrimmedSurface::untrimmed(plane),
            TrimmedSurface::untrimmed(bowed),
        ];
        let mut topology = crate::kernel::join::find_topology(&faces, 1e-2 * size).unwrap();
        assert_eq!(topology.shared.len(), 1);
        // As a reader's topology: the gap measured at the ends.
        topology.shared[0].gap = 0.0;
        let text = two_faces_written(&faces, &topology, 1e-6 * size);
        let model = crate::read::read(text.as_bytes(), &mut |_, _| true).unwrap();
        assert!(model.warnings.is_empty(), "{:?}", model.warnings);
        let body = &model.bodies[0];
        assert_eq!(body.faces.len(), 2);
        assert_eq!(body.topology.shared.len(), 1, "{:?}", body.topology);
        assert!(
            model.tolerance >= 0.99 * bow * size,
            "read at {:e}, the edge bows {:e} apart",
            model.tolerance,
            bow * size
        );
    }
}
