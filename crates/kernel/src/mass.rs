//! Mass properties of a body bounded by trimmed NURBS faces: area, volume, centroid and the
//! inertia tensor about the centroid (unit density), from integrals over the faces alone.
//!
//! - **Divergence theorem.** For a closed, consistently oriented boundary ∂B with outward normal
//!   n, ∫_B div F dV = ∮_∂B F · n dA. With F = x/3, (x²/2, 0, 0), (x³/3, 0, 0) and (x²y/2, 0, 0)
//!   (and their cyclic versions) the volume, the first moments ∫x dV, the second moments ∫x² dV
//!   and the products ∫xy dV become face integrals. On a face S(u, v), n dA = (S_u × S_v) du dv.
//! - **Gauss–Legendre quadrature** per Bézier span of the surface (the integrands are smooth
//!   inside a span: polynomial for a polynomial surface, and integrated exactly when the order
//!   is high enough; rational otherwise, where the error falls exponentially with the order).
//! - **Trimmed faces by Green's theorem.** Over a trimmed domain D whose loops keep it on their
//!   left, ∫∫_D f du dv = ∮_∂D F(u, v) dv with F(u, v) = ∫_{u₀}^{u} f(s, v) ds: a line
//!   integral along the trim curves of an inner integral along u, both by Gauss–Legendre, each
//!   split where the integrand is less smooth (the trim curve's knots, and where it crosses a
//!   knot line of the surface).
//!
//! Gonzalez-Ochoa, McCammon and Peters, "Computing moments of objects enclosed by piecewise
//! polynomial surfaces" (ACM Transactions on Graphics 17(3), 1998), compute moments through the
//! divergence theorem in the same way.
//!
//! Coordinates are taken about the centre of the faces' bounding box, so that a body far from
//! the origin keeps its digits.

use std::ops::{Add, AddAssign, Mul, Neg};

use glam::{DMat3, DVec3};

use crate::diffgeo::SurfaceDerivatives;
use crate::error::GeometryError;
use crate::trim::TrimmedSurface;
use crate::{Direction, NurbsSurface, TrimCurve};

/// The n nodes and weights of Gauss–Legendre quadrature on [−1, 1]: the roots of the Legendre
/// polynomial P_n by Newton's iteration from cos(π(i − 1/4)/(n + 1/2)), the weights
/// 2 / ((1 − x²) P_n′(x)²) (Abramowitz and Stegun 25.4.29; the three-term recurrence
/// (k + 1) P_{k+1} = (2k + 1) x P_k − k P_{k−1}).
pub fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    let n = n.max(1);
    let legendre = |x: f64| {
        let (mut p0, mut p1) = (1.0, x);
        for k in 1..n {
            let k = k as f64;
            let p2 = ((2.0 * k + 1.0) * x * p1 - k * p0) / (k + 1.0);
            p0 = p1;
            p1 = p2;
        }
        // P_n, and P_n′ = n (x P_n − P_{n−1}) / (x² − 1).
        let derivative = n as f64 * (x * p1 - p0) / (x * x - 1.0);
        (p1, derivative)
    };
    (1..=n)
        .map(|i| {
            let mut x = (std::f64::consts::PI * (i as f64 - 0.25) / (n as f64 + 0.5)).cos();
            for _ in 0..100 {
                let (p, dp) = legendre(x);
                let step = p / dp;
                x -= step;
                if step.abs() < 1e-16 {
                    break;
                }
            }
            let (_, dp) = legendre(x);
            (x, 2.0 / ((1.0 - x * x) * dp * dp))
        })
        .collect()
}

/// The face integrals a body's mass properties are made of, about some origin: ∫dA, and over
/// the enclosed volume ∫dV, ∫(x, y, z) dV, ∫(x², y², z²) dV and ∫(xy, yz, zx) dV (signed: the
/// volume terms change sign with the faces' orientation).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Moments {
    pub area: f64,
    /// ∮ n dA: zero for a closed surface; how far from zero says how open it is.
    pub vector_area: DVec3,
    pub volume: f64,
    pub first: DVec3,
    pub second: DVec3,
    pub products: DVec3,
}

impl Moments {
    /// The integrands at a point `p` (about the origin) with n dA = `normal` du dv.
    fn at(p: DVec3, normal: DVec3) -> Self {
        Self {
            area: normal.length(),
            vector_area: normal,
            volume: p.dot(normal) / 3.0,
            first: p * p * normal / 2.0,
            second: p * p * p * normal / 3.0,
            products: DVec3::new(p.x * p.x * p.y, p.y * p.y * p.z, p.z * p.z * p.x) * normal / 2.0,
        }
    }

    /// The same with the orientation reversed (the area stays).
    fn flipped(self) -> Self {
        Self {
            area: self.area,
            ..-self
        }
    }
}

impl Add for Moments {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        Self {
            area: self.area + o.area,
            vector_area: self.vector_area + o.vector_area,
            volume: self.volume + o.volume,
            first: self.first + o.first,
            second: self.second + o.second,
            products: self.products + o.products,
        }
    }
}

impl AddAssign for Moments {
    fn add_assign(&mut self, o: Self) {
        *self = *self + o;
    }
}

impl Mul<f64> for Moments {
    type Output = Self;
    fn mul(self, s: f64) -> Self {
        Self {
            area: self.area * s,
            vector_area: self.vector_area * s,
            volume: self.volume * s,
            first: self.first * s,
            second: self.second * s,
            products: self.products * s,
        }
    }
}

impl Neg for Moments {
    type Output = Self;
    fn neg(self) -> Self {
        self * -1.0
    }
}

/// Area, volume, centroid and inertia of a closed body (unit density).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MassProperties {
    pub area: f64,
    pub volume: f64,
    pub centroid: DVec3,
    /// The inertia tensor about the centroid: I_xx = ∫(y² + z²) dV on the diagonal, −∫xy dV
    /// off it (coordinates from the centroid).
    pub inertia: DMat3,
    /// How much the volume depends on where it is measured from, because the faces do not
    /// quite close (gaps between faces that a file's tolerance allows): the volume about o is
    /// V − o · ∮n dA / 3, so over the body's bounding box it varies by up to its diagonal times
    /// |∮n dA| / 3. Zero, to rounding, for a closed body.
    pub volume_uncertainty: f64,
}

/// The quadrature order for integrands on `surface`: exact for a polynomial surface's
/// integrands (degree up to 5p − 1 in u for the products, so n ≥ 5p/2), and for rational
/// ones (a sphere's or a torus's spans) enough that the inertia is within 1e-12 relative.
fn order(surface: &NurbsSurface) -> usize {
    let [p, q] = surface.degree();
    let p = p.max(q);
    if surface.is_polynomial() {
        (5 * p).div_ceil(2).clamp(1, 30)
    } else {
        (3 * p + 10).min(30)
    }
}

/// Σ w_i w_j f(u_i, v_j) of the integrands of `surface` about `origin` over the grid `us` ×
/// `vs` with weights `wu` and `wv` (first derivatives only, by the surface's grid evaluation).
fn grid_sum(
    surface: &NurbsSurface,
    (us, wu): (&[f64], &[f64]),
    (vs, wv): (&[f64], &[f64]),
    origin: DVec3,
) -> Result<Moments, GeometryError> {
    let mut total = Moments::default();
    surface.evaluate_grid(us, vs, false, |i, j, d: &SurfaceDerivatives| {
        total += Moments::at(d.point - origin, d.su.cross(d.sv)) * (wu[i] * wv[j]);
    })?;
    Ok(total)
}

/// The nodes and weights of `rule` mapped to [a, b], appended to `nodes` and `weights`.
fn nodes_on(a: f64, b: f64, rule: &[(f64, f64)], nodes: &mut Vec<f64>, weights: &mut Vec<f64>) {
    let (mid, half) = (0.5 * (a + b), 0.5 * (b - a));
    for &(x, w) in rule {
        nodes.push(mid + half * x);
        weights.push(w * half);
    }
}

/// Gauss–Legendre over [a, b] with `rule` ([`gauss_legendre`]).
fn integrate(
    a: f64,
    b: f64,
    rule: &[(f64, f64)],
    mut f: impl FnMut(f64) -> Result<Moments, GeometryError>,
) -> Result<Moments, GeometryError> {
    let (mid, half) = (0.5 * (a + b), 0.5 * (b - a));
    let mut total = Moments::default();
    for &(x, w) in rule {
        total += f(mid + half * x)? * (w * half);
    }
    Ok(total)
}

/// The moments of face `face` about `origin`, with its normal S_u × S_v as the orientation.
pub fn face_moments(face: &TrimmedSurface, origin: DVec3) -> Result<Moments, GeometryError> {
    let surface = face.surface();
    let rule = gauss_legendre(order(surface));
    let us = surface.span_breaks(Direction::U);
    let vs = surface.span_breaks(Direction::V);
    if let Some([u0, u1, v0, v1]) = face.kept_rectangle() {
        // The whole domain or a rectangle of it: a tensor rule on every Bézier span, cut to
        // the rectangle.
        let within = crate::tess::values_within;
        let (mut nu, mut wu, mut nv, mut wv) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        for u in within(&us, u0, u1).windows(2) {
            nodes_on(u[0], u[1], &rule, &mut nu, &mut wu);
        }
        for v in within(&vs, v0, v1).windows(2) {
            nodes_on(v[0], v[1], &rule, &mut nv, &mut wv);
        }
        return grid_sum(surface, (&nu, &wu), (&nv, &wv), origin);
    }
    // Green's theorem (∫∫ f du dv = ∮ F dv = −∮ G du) with the inner integral F(u, v) =
    // ∫_{u₀}^{u} f(s, v) ds, split at the u knots below u; or, on a surface swept straight
    // along v (degree 1 and one span in v, the weights constant along it: an extrusion such
    // as a cylinder) with more spans in u, G(u, v) = ∫_{v₀}^{v} f(u, s) ds, one short rule.
    let along_v = vs.len() == 2 && us.len() > 2 && surface.degree()[1] == 1 && {
        let [n, m] = surface.count();
        (0..n).all(|i| (1..m).all(|j| surface.weight(i, j) == surface.weight(i, 0)))
    };
    let inner = |u: f64, v: f64| -> Result<Moments, GeometryError> {
        let (breaks, to) = if along_v { (&vs, v) } else { (&us, u) };
        let (mut nodes, mut weights) = (Vec::new(), Vec::new());
        for w in breaks.windows(2) {
            let (a, b) = (w[0], w[1].min(to));
            if b <= a {
                break;
            }
            nodes_on(a, b, &rule, &mut nodes, &mut weights);
        }
        if nodes.is_empty() {
            return Ok(Moments::default());
        }
        if along_v {
            grid_sum(surface, (&[u], &[1.0]), (&nodes, &weights), origin)
        } else {
            grid_sum(surface, (&nodes, &weights), (&[v], &[1.0]), origin)
        }
    };
    // The boundary integrand's factor: v′ for F, −u′ for G.
    let (axis, sign) = if along_v { (0, -1.0) } else { (1, 1.0) };
    // Loops may stray outside the domain by their validation's tolerance: clamped.
    let [(u0, u1), (v0, v1)] = surface.domain();
    let mut total = Moments::default();
    for trim_loop in face.loops() {
        for curve in trim_loop {
            // A curve along which that coordinate is constant (all its control points
            // share it) adds nothing.
            let first = curve.control_point(0)[axis];
            if (1..curve.count()).all(|i| curve.control_point(i)[axis] == first) {
                continue;
            }
            // The boundary integrand is F along the curve times v′: polynomial of a degree
            // the surface's and the curve's give, or rational (arcs), which needs more.
            let extra = if curve.is_polynomial() { 0 } else { 12 };
            let boundary = gauss_legendre((rule.len() + 2 * curve.degree() + extra).min(40));
            for (a, b) in smooth_pieces(curve, &us, &vs)? {
                total += integrate(a, b, &boundary, |t| {
                    let d = curve.derivatives(t, 1)?;
                    let (u, v) = (d[0].x.clamp(u0, u1), d[0].y.clamp(v0, v1));
                    Ok(inner(u, v)? * (sign * d[1][axis]))
                })?;
            }
        }
    }
    Ok(total)
}

/// The parameter intervals of `curve` on which it is one polynomial (or rational) piece and
/// stays inside one knot span of the surface in u and in v: its own spans, cut where it crosses
/// an interior knot line `us` or `vs` (found by bisection between samples).
fn smooth_pieces(
    curve: &TrimCurve,
    us: &[f64],
    vs: &[f64],
) -> Result<Vec<(f64, f64)>, GeometryError> {
    const SAMPLES: usize = 16;
    let inner_us = &us[1..us.len().saturating_sub(1).max(1)];
    let inner_vs = &vs[1..vs.len().saturating_sub(1).max(1)];
    let mut pieces = Vec::new();
    for span in curve.span_breaks().windows(2) {
        let (t0, t1) = (span[0], span[1]);
        let mut cuts = vec![t0];
        let mut previous = (t0, curve.point_at(t0)?);
        for k in 1..=SAMPLES {
            let t = t0 + (t1 - t0) * k as f64 / SAMPLES as f64;
            let p = curve.point_at(t)?;
            for (lines, coordinate) in [(inner_us, 0), (inner_vs, 1)] {
                for &line in lines {
                    let side = |q: glam::DVec2| (q[coordinate] - line).signum();
                    if side(previous.1) * side(p) < 0.0 {
                        let (mut lo, mut hi) = (previous.0, t);
                        for _ in 0..60 {
                            let mid = 0.5 * (lo + hi);
                            if side(curve.point_at(mid)?) == side(previous.1) {
                                lo = mid;
                            } else {
                                hi = mid;
                            }
                        }
                        cuts.push(0.5 * (lo + hi));
                    }
                }
            }
            previous = (t, p);
        }
        cuts.push(t1);
        cuts.sort_by(f64::total_cmp);
        pieces.extend(
            cuts.windows(2)
                .filter(|w| w[1] > w[0])
                .map(|w| (w[0], w[1])),
        );
    }
    Ok(pieces)
}

/// The centre of the faces' control boxes (the origin the moments are taken about) and the
/// boxes' diagonal.
fn centre(faces: &[TrimmedSurface]) -> (DVec3, f64) {
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for face in faces {
        let (a, b) = face.surface().bounds();
        lo = lo.min(a);
        hi = hi.max(b);
    }
    if lo.is_finite() && hi.is_finite() {
        (0.5 * (lo + hi), lo.distance(hi))
    } else {
        (DVec3::ZERO, 0.0)
    }
}

/// The total area of `faces` (an open body has an area but no volume).
pub fn area(faces: &[TrimmedSurface]) -> Result<f64, GeometryError> {
    let (origin, _) = centre(faces);
    faces
        .iter()
        .map(|f| face_moments(f, origin).map(|m| m.area))
        .sum()
}

/// The volume that `faces` enclose with their normals as they are: positive where they point
/// out of it, negative where they point in (the divergence theorem, as
/// [`mass_properties`]).
pub fn signed_volume(faces: &[TrimmedSurface]) -> Result<f64, GeometryError> {
    let (origin, _) = centre(faces);
    faces
        .iter()
        .map(|f| face_moments(f, origin).map(|m| m.volume))
        .sum()
}

/// The mass properties of the body that `faces` bound: closed, and consistently oriented once
/// the faces marked in `flipped` are turned over (every normal outward, or every one inward,
/// which the sign of the volume tells; [`crate::join::orientation`] finds the flips from the
/// shared edges; an empty `flipped` turns none). Refused when they enclose no volume.
pub fn mass_properties(
    faces: &[TrimmedSurface],
    flipped: &[bool],
) -> Result<MassProperties, GeometryError> {
    let (origin, _) = centre(faces);
    let moments = faces
        .iter()
        .map(|f| face_moments(f, origin))
        .collect::<Result<Vec<_>, _>>()?;
    properties_of(faces, &moments, flipped)
}

/// The faces of a closed body (`faces`, joined by `topology` into one or more closed shells)
/// to turn over so that every normal points out of the material: each shell agrees across its
/// shared edges ([`crate::join::orientation`]) and encloses positive volume, unless it is a
/// void ([`crate::join::shell_nesting`]), which encloses negative volume; and each face's
/// moments about the centre of the faces' boxes, as they are.
pub fn outward_flips(
    faces: &[TrimmedSurface],
    topology: &crate::join::Topology,
) -> Result<(Vec<bool>, Vec<Moments>), GeometryError> {
    let (origin, _) = centre(faces);
    let moments = faces
        .iter()
        .map(|f| face_moments(f, origin))
        .collect::<Result<Vec<_>, _>>()?;
    let mut flipped = crate::join::orientation(faces.len(), topology);
    let shells = topology.components(faces.len());
    let volumes: Vec<f64> = shells
        .iter()
        .map(|shell| {
            shell
                .iter()
                .map(|&k| moments[k].volume * if flipped[k] { -1.0 } else { 1.0 })
                .sum()
        })
        .collect();
    let boxes: Vec<(DVec3, DVec3)> = shells
        .iter()
        .map(|shell| {
            shell.iter().map(|&k| faces[k].surface().bounds()).fold(
                (DVec3::INFINITY, DVec3::NEG_INFINITY),
                |(lo, hi), (a, b)| (lo.min(a), hi.max(b)),
            )
        })
        .collect();
    let nesting = crate::join::shell_nesting(&boxes, &volumes);
    for ((shell, volume), (_, void)) in shells.iter().zip(&volumes).zip(&nesting) {
        if (*volume > 0.0) == *void {
            for &k in shell {
                flipped[k] = !flipped[k];
            }
        }
    }
    Ok((flipped, moments))
}

/// The mass properties of a closed body of one or more shells, a void's volume taken away
/// ([`outward_flips`], then [`mass_properties`]).
pub fn solid_mass_properties(
    faces: &[TrimmedSurface],
    topology: &crate::join::Topology,
) -> Result<MassProperties, GeometryError> {
    let (flipped, moments) = outward_flips(faces, topology)?;
    properties_of(faces, &moments, &flipped)
}

/// [`mass_properties`] from each face's `moments` about the centre of the faces' boxes.
fn properties_of(
    faces: &[TrimmedSurface],
    moments: &[Moments],
    flipped: &[bool],
) -> Result<MassProperties, GeometryError> {
    let (origin, diagonal) = centre(faces);
    let mut m = Moments::default();
    for (k, &moments) in moments.iter().enumerate() {
        m += if flipped.get(k).copied().unwrap_or(false) {
            moments.flipped()
        } else {
            moments
        };
    }
    if m.volume < 0.0 {
        m = m.flipped();
    }
    let size = faces.iter().map(|f| f.surface().size()).fold(0.0, f64::max);
    if !(m.volume > 1e-12 * size.powi(3)) {
        return Err(GeometryError::Construction {
            what: "mass properties",
            message: "the faces enclose no volume".into(),
        });
    }
    let v = m.volume;
    let c = m.first / v;
    // Second moments and products about the centroid (the parallel-axis theorem).
    let s = m.second - v * c * c;
    let p = m.products - v * DVec3::new(c.x * c.y, c.y * c.z, c.z * c.x);
    let inertia = DMat3::from_cols(
        DVec3::new(s.y + s.z, -p.x, -p.z),
        DVec3::new(-p.x, s.x + s.z, -p.y),
        DVec3::new(-p.z, -p.y, s.x + s.y),
    );
    Ok(MassProperties {
        area: m.area,
        volume: v,
        centroid: origin + c,
        inertia,
        volume_uncertainty: diagonal * m.vector_area.length() / 3.0,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::construct;
    use glam::DVec2;

    use crate::test_support::placement;

    fn relative(a: f64, b: f64) -> f64 {
        (a - b).abs() / b.abs().max(1e-300)
    }

    #[test]
    fn gauss_legendre_integrates_polynomials_of_degree_2n_minus_1_exactly() {
        for n in 1..=20 {
            let rule = gauss_legendre(n);
            let weights: f64 = rule.iter().map(|(_, w)| w).sum();
            assert!((weights - 2.0).abs() < 1e-14, "n = {n}: {weights}");
            for k in 0..2 * n {
                let exact = if k % 2 == 1 {
                    0.0
                } else {
                    2.0 / (k as f64 + 1.0)
                };
                let sum: f64 = rule.iter().map(|(x, w)| w * x.powi(k as i32)).sum();
                assert!((sum - exact).abs() < 1e-13, "n = {n}, x^{k}: {sum}");
            }
        }
    }

    /// A sphere and a torus in general position: the closed forms of their area, volume,
    /// centroid and inertia (sphere: 2/5 M r²; torus about its axis M (R² + 3r²/4), across it
    /// M (R²/2 + 5r²/8)).
    #[test]
    fn a_sphere_and_a_torus_have_their_closed_form_mass_properties() {
        use std::f64::consts::PI;
        for seed in 1..6 {
            let (motion, scale) = placement(seed);
            let r = 1.3;
            let sphere = construct::sphere(DVec3::new(0.2, -0.4, 0.7), r)
                .unwrap()
                .transformed(&motion)
                .unwrap();
            let m = mass_properties(&[TrimmedSurface::untrimmed(sphere)], &[]).unwrap();
            let rs = r * scale;
            let volume = 4.0 / 3.0 * PI * rs.powi(3);
            assert!(relative(m.area, 4.0 * PI * rs * rs) < 1e-9, "{}", m.area);
            assert!(relative(m.volume, volume) < 1e-9, "{} {volume}", m.volume);
            let centre = motion.transform_point3(DVec3::new(0.2, -0.4, 0.7));
            assert!(m.centroid.distance(centre) < 1e-9 * rs, "{}", m.centroid);
            let i = 0.4 * volume * rs * rs;
            let expected = DMat3::from_diagonal(DVec3::splat(i));
            assert!(
                (m.inertia - expected)
                    .to_cols_array()
                    .iter()
                    .all(|e| e.abs() < 1e-9 * i),
                "{:?}",
                m.inertia
            );

            let (big, small) = (2.0, 0.6);
            let axis = DVec3::new(0.3, 0.5, 1.0).normalize();
            let torus = construct::torus(DVec3::ZERO, axis, big, small)
                .unwrap()
                .transformed(&motion)
                .unwrap();
            let m = mass_properties(&[TrimmedSurface::untrimmed(torus)], &[]).unwrap();
            let (big, small) = (big * scale, small * scale);
            let volume = 2.0 * PI * PI * big * small * small;
            assert!(relative(m.area, 4.0 * PI * PI * big * small) < 1e-9);
            assert!(relative(m.volume, volume) < 1e-9, "{} {volume}", m.volume);
            assert!(m.centroid.distance(motion.translation) < 1e-9 * big);
            let along = volume * (big * big + 0.75 * small * small);
            let across = volume * (0.5 * big * big + 0.625 * small * small);
            let a = motion.matrix3.mul_vec3(axis).normalize();
            let moment = |d: DVec3| d.dot(m.inertia * d);
            assert!(relative(moment(a), along) < 1e-9, "{} {along}", moment(a));
            let b = a.any_orthonormal_vector();
            assert!(relative(moment(b), across) < 1e-9, "{} {across}", moment(b));
        }
    }

    /// A trimmed face by Green's theorem against the closed form: a plane's square region
    /// with a circular hole (rational trim curves) has the square's area less the disc's; the
    /// same region on a plane refined so that knot lines cross the hole gives the same.
    #[test]
    fn a_plane_with_a_round_hole_has_the_area_of_its_region() {
        use std::f64::consts::PI;
        let plane = construct::plane(DVec3::ZERO, DVec3::X * 4.0, DVec3::Y * 3.0).unwrap();
        let refined = plane
            .refine(Direction::U, &[0.3, 0.55])
            .unwrap()
            .refine(Direction::V, &[0.45])
            .unwrap();
        let radius = 0.2;
        for surface in [plane, refined] {
            let outer =
                crate::trim::shapes::rectangle(DVec2::splat(0.05), DVec2::splat(0.95)).unwrap();
            let hole =
                crate::trim::shapes::ellipse(DVec2::new(0.5, 0.45), DVec2::splat(radius)).unwrap();
            let face = TrimmedSurface::new(surface, vec![outer, hole]).unwrap();
            let m = face_moments(&face, DVec3::ZERO).unwrap();
            // (u, v) ↦ (4u, 3v): areas scale by 12.
            let expected = (0.81 - PI * radius * radius) * 12.0;
            assert!(relative(m.area, expected) < 1e-11, "{} {expected}", m.area);
        }
    }

    /// A face kept on a rectangle of its domain (a STEP cylinder trimmed to its height) is
    /// integrated on the rectangle's tensor rule; its moments are those of the same rectangle
    /// cut along a diagonal into two triangles (integrated along their boundaries, another
    /// path: on the cylinder with the inner integral along its axis, elsewhere along u), on a
    /// rational cylinder, a refined bicubic patch and a plane, in general position
    /// (the area within 1e-9: its integrand, a square root, is no polynomial for either rule).
    #[test]
    fn a_face_kept_on_a_rectangle_has_the_moments_of_its_two_triangles() {
        let cylinder = construct::cylinder(DVec3::ZERO, DVec3::Z * 2.0, 0.8).unwrap();
        let wavy = construct::plane(DVec3::ZERO, DVec3::X * 3.0, DVec3::Y * 2.0)
            .unwrap()
            .elevate_degree(Direction::U, 2)
            .unwrap()
            .elevate_degree(Direction::V, 2)
            .unwrap()
            .refine(Direction::U, &[0.4])
            .unwrap();
        let [n, m] = wavy.count();
        let mut bumped = wavy.clone();
        for i in 0..n {
            for j in 0..m {
                let p = bumped.control_point(i, j);
                bumped
                    .set_point(i, j, p + DVec3::Z * (0.3 * ((i * 7 + j * 3) % 5) as f64))
                    .unwrap();
            }
        }
        let plane = construct::plane(DVec3::ZERO, DVec3::X, DVec3::Y * 1.5).unwrap();
        let (lo, hi) = (DVec2::new(0.13, 0.21), DVec2::new(0.77, 0.9));
        let (ll, lr, ur, ul) = (lo, DVec2::new(hi.x, lo.y), hi, DVec2::new(lo.x, hi.y));
        for (seed, surface) in [cylinder, bumped, plane].into_iter().enumerate() {
            let (motion, _) = placement(seed as u64 + 3);
            let surface = surface.transformed(&motion).unwrap();
            let face = TrimmedSurface::new(
                surface.clone(),
                vec![crate::trim::shapes::rectangle(lo, hi).unwrap()],
            )
            .unwrap();
            assert_eq!(face.kept_rectangle(), Some([lo.x, hi.x, lo.y, hi.y]));
            let triangle = |points: &[DVec2]| {
                let face = TrimmedSurface::new(
                    surface.clone(),
                    vec![crate::trim::shapes::polygon(points).unwrap()],
                )
                .unwrap();
                assert_eq!(face.kept_rectangle(), None);
                face_moments(&face, DVec3::ONE).unwrap()
            };
            let whole = face_moments(&face, DVec3::ONE).unwrap();
            let halves = triangle(&[ll, lr, ur]) + triangle(&[ll, ur, ul]);
            assert!(
                relative(whole.area, halves.area) < 1e-9,
                "{seed}: {} {}",
                whole.area,
                halves.area
            );
            assert!(whole.first.distance(halves.first) < 1e-10 * whole.area.powf(1.5));
            assert!(
                (whole.volume - halves.volume).abs() < 1e-10 * whole.area.powf(1.5),
                "{seed}: {} {}",
                whole.volume,
                halves.volume
            );
        }
    }

    /// A closed body with trimmed faces: a cylinder capped by two planes trimmed to discs, in
    /// general position, has the closed forms' volume πr²h, area 2πr(r + h), centroid half way
    /// up, and inertia ½Mr² about its axis and M(3r² + h²)/12 across it.
    #[test]
    fn a_capped_cylinder_of_trimmed_faces_has_its_closed_form_mass_properties() {
        use std::f64::consts::PI;
        let (r, h) = (0.7, 2.3);
        let centre = DVec3::new(0.3, 0.1, -0.2);
        let side = construct::cylinder(centre, DVec3::Z * h, r).unwrap();
        let disc = |z: f64| {
            let plane = construct::plane(
                centre + DVec3::new(-2.0 * r, -2.0 * r, z),
                DVec3::X * 4.0 * r,
                DVec3::Y * 4.0 * r,
            )
            .unwrap();
            let circle =
                crate::trim::shapes::ellipse(DVec2::splat(0.5), DVec2::splat(0.25)).unwrap();
            TrimmedSurface::new(plane, vec![circle]).unwrap()
        };
        let middle = centre + DVec3::Z * (0.5 * h);
        // Each face turned so that its normal points away from the middle.
        let outward = |face: TrimmedSurface| {
            let s = face.surface();
            let [(u0, u1), (v0, v1)] = s.domain();
            let (u, v) = (0.5 * (u0 + u1), 0.5 * (v0 + v1));
            let d = s.evaluate(u, v).unwrap();
            if d.su.cross(d.sv).dot(d.point - middle) < 0.0 {
                face.reverse(Direction::U).unwrap()
            } else {
                face
            }
        };
        let faces: Vec<TrimmedSurface> = [TrimmedSurface::untrimmed(side), disc(0.0), disc(h)]
            .into_iter()
            .map(outward)
            .collect();
        for seed in 1..5 {
            let (motion, scale) = placement(seed);
            let moved: Vec<TrimmedSurface> = faces
                .iter()
                .map(|f| {
                    f.with_surface(f.surface().transformed(&motion).unwrap())
                        .unwrap()
                })
                .collect();
            let m = mass_properties(&moved, &[]).unwrap();
            let (r, h) = (r * scale, h * scale);
            let volume = PI * r * r * h;
            assert!(relative(m.volume, volume) < 1e-9, "{} {volume}", m.volume);
            assert!(
                m.volume_uncertainty < 1e-10 * volume,
                "{}",
                m.volume_uncertainty
            );
            assert!(
                relative(m.area, 2.0 * PI * r * (r + h)) < 1e-9,
                "{}",
                m.area
            );
            assert!(m.centroid.distance(motion.transform_point3(middle)) < 1e-9 * h);
            let axis = motion.matrix3.mul_vec3(DVec3::Z).normalize();
            let moment = |d: DVec3| d.dot(m.inertia * d);
            assert!(relative(moment(axis), 0.5 * volume * r * r) < 1e-9);
            let across = volume * (3.0 * r * r + h * h) / 12.0;
            assert!(relative(moment(axis.any_orthonormal_vector()), across) < 1e-9);
        }
    }
}
