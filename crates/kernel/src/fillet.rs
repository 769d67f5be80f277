//! Rolling-ball fillets between two surfaces, on the one surface interface.
//!
//! A ball of radius R touching A on side σ_A (+1: the side A's normal points to) and B on side
//! σ_B has its centre on both offsets, C = A(u, v) + σ_A R N_A = B(s, t) + σ_B R N_B, and
//! touches A at A(u, v) and B at B(s, t). So the spine of centres is the intersection of the
//! two offset surfaces ([`OffsetFace`], evaluated exactly: S + d N with N's derivatives from
//! the Weingarten equations), found by marching ([`crate::intersect`]), and each of its points
//! carries both contact parameters. Each section of the fillet is the circular arc from the
//! contact point on A to the one on B about the centre, the shorter way: a rational quadratic
//! with its middle point where the end tangents meet, at R / cos(θ/2) from the centre, weight
//! cos(θ/2) (The NURBS Book §7.3). The sections are lofted (the homogeneous control points
//! interpolated across them; [`crate::loft`]), so every section at a spine point is exact.
//! (Choi and Ju, "Constant-radius blending in surface modelling", 1989: the spine as the
//! intersection of offsets.)

use glam::{DVec2, DVec3};

use crate::construct::construction;
use crate::curve::SpaceCurve;
use crate::diffgeo::SurfaceDerivatives;
use crate::error::GeometryError;
use crate::intersect::{IntersectOptions, IntersectionCurve, intersect_surfaces};
use crate::loft::{LoftOptions, LoftStyle, loft_sections};
use crate::offset::face_normal;
use crate::parametric::ParametricSurface;
use crate::surface::NurbsSurface;
use crate::trim::cut::Keep;

/// A face moved by `distance` along its normal, evaluated exactly: S + d N, its first
/// derivatives S_u + d N_u and S_v + d N_v (Weingarten), and second derivatives by central
/// differences of those (what the intersection's cell boxes and steps need).
pub struct OffsetFace<'a> {
    pub face: &'a dyn ParametricSurface,
    pub distance: f64,
}

impl OffsetFace<'_> {
    fn first(&self, u: f64, v: f64) -> Option<(DVec3, DVec3, DVec3)> {
        let d = self.face.derivatives(u, v)?;
        let n = face_normal(self.face, u, v)?;
        let (nu, nv) = d.normal_derivatives(n);
        let k = self.distance;
        Some((d.point + n * k, d.su + nu * k, d.sv + nv * k))
    }
}

impl ParametricSurface for OffsetFace<'_> {
    fn domain(&self) -> [(f64, f64); 2] {
        self.face.domain()
    }

    fn derivatives(&self, u: f64, v: f64) -> Option<SurfaceDerivatives> {
        let (point, su, sv) = self.first(u, v)?;
        let [(u0, u1), (v0, v1)] = self.domain();
        let (hu, hv) = (1e-5 * (u1 - u0), 1e-5 * (v1 - v0));
        let (ua, ub) = ((u - hu).max(u0), (u + hu).min(u1));
        let (va, vb) = ((v - hv).max(v0), (v + hv).min(v1));
        let (_, su_a, sv_a) = self.first(ua, v)?;
        let (_, su_b, sv_b) = self.first(ub, v)?;
        let (_, _, sv_c) = self.first(u, va)?;
        let (_, _, sv_d) = self.first(u, vb)?;
        Some(SurfaceDerivatives {
            point,
            su,
            sv,
            suu: (su_b - su_a) / (ub - ua).max(f64::MIN_POSITIVE),
            suv: (sv_b - sv_a) / (ub - ua).max(f64::MIN_POSITIVE),
            svv: (sv_d - sv_c) / (vb - va).max(f64::MIN_POSITIVE),
        })
    }

    fn keeps(&self, u: f64, v: f64) -> bool {
        self.face.keeps(u, v)
    }
}

/// What a fillet needs: the radius, the sides, and the tolerance (model units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FilletOptions {
    pub radius: f64,
    /// +1: the ball lies on the side A's normal points to; −1: the other side.
    pub side_a: f64,
    pub side_b: f64,
    /// Contact points and centres lie within this of where they belong.
    pub tolerance: f64,
    /// The size of the scene (what the seeds' smallest loop and the chords scale by).
    pub size: f64,
}

/// A rolling-ball fillet.
#[derive(Debug, Clone, PartialEq)]
pub struct Fillet {
    /// The fillet: u across (the arcs, from A to B), v along the spine.
    pub surface: NurbsSurface,
    /// The ball's centres, one per section.
    pub centres: Vec<DVec3>,
    /// The contact curves in A's and B's parameters, one point per section.
    pub contact_a: Vec<DVec2>,
    pub contact_b: Vec<DVec2>,
    /// Whether the spine is a closed loop (the last section is the first again).
    pub closed: bool,
    /// The side of each contact curve (looking along it) away from the fillet: what trimming
    /// back keeps.
    pub keep_a: Keep,
    pub keep_b: Keep,
    /// How many spine branches there were (the longest is filleted).
    pub branches: usize,
}

/// The rolling-ball fillet of radius `options.radius` between faces `a` and `b`.
pub fn fillet_surfaces(
    a: &dyn ParametricSurface,
    b: &dyn ParametricSurface,
    options: &FilletOptions,
) -> Result<Fillet, GeometryError> {
    const WHAT: &str = "fillet";
    let r = options.radius;
    if !(r.is_finite() && r > 0.0) {
        return Err(construction(
            WHAT,
            format!("the radius must be a number above 0 (got {r})"),
        ));
    }
    if !(options.tolerance.is_finite() && options.tolerance > 0.0) {
        return Err(construction(WHAT, "the tolerance must be a number above 0"));
    }
    let offset_a = OffsetFace {
        face: a,
        distance: options.side_a.signum() * r,
    };
    let offset_b = OffsetFace {
        face: b,
        distance: options.side_b.signum() * r,
    };
    let size = options.size.max(options.tolerance);
    let intersect = IntersectOptions {
        tolerance: 1e-2 * options.tolerance,
        chord: (4.0 * options.tolerance).min(1e-3 * size),
        smallest: (1e-2 * size).max(r * 0.5),
    };
    let found = intersect_surfaces(&offset_a, &offset_b, &intersect)?;
    let branches = found.curves.len();
    let Some(spine) = found
        .curves
        .into_iter()
        .filter(|c| c.points.len() >= 2)
        .max_by(|x, y| length(&x.points).total_cmp(&length(&y.points)))
    else {
        return Err(construction(
            WHAT,
            format!(
                "no ball of radius {r} touches both surfaces on the chosen sides (the radius may \
                 be too large, the sides wrong, or the surfaces do not meet)"
            ),
        ));
    };
    build(a, b, &spine, branches)
}

fn length(points: &[DVec3]) -> f64 {
    points.windows(2).map(|w| w[0].distance(w[1])).sum()
}

fn build(
    a: &dyn ParametricSurface,
    b: &dyn ParametricSurface,
    spine: &IntersectionCurve,
    branches: usize,
) -> Result<Fillet, GeometryError> {
    const WHAT: &str = "fillet";
    let mut count = spine.points.len();
    if spine.closed {
        count -= 1;
    }
    let mut sections = Vec::with_capacity(count);
    let mut centres = Vec::with_capacity(count);
    let mut contact_a = Vec::with_capacity(count);
    let mut contact_b = Vec::with_capacity(count);
    for i in 0..count {
        let (ua, ub) = (spine.uv_a[i], spine.uv_b[i]);
        let pa = a.point(ua.x, ua.y).ok_or_else(|| {
            construction(WHAT, "a contact point on the first surface is undefined")
        })?;
        let pb = b.point(ub.x, ub.y).ok_or_else(|| {
            construction(WHAT, "a contact point on the second surface is undefined")
        })?;
        let c = spine.points[i];
        sections.push(arc_section(c, pa, pb)?);
        centres.push(c);
        contact_a.push(ua);
        contact_b.push(ub);
    }
    let closed = spine.closed && count >= 3;
    if sections.len() < 2 {
        return Err(construction(WHAT, "the spine is a single point"));
    }
    let surface = loft_sections(
        &sections,
        &LoftOptions {
            degree: 3,
            closed,
            style: LoftStyle::Normal,
            align: false,
        },
    )?;
    // The side of each contact curve away from the fillet, from the middle section.
    let m = count / 2;
    let keep_a = away_side(
        a,
        &contact_a,
        m,
        centres[m],
        contact_point(b, contact_b[m])?,
    )?;
    let keep_b = away_side(
        b,
        &contact_b,
        m,
        centres[m],
        contact_point(a, contact_a[m])?,
    )?;
    Ok(Fillet {
        surface,
        centres,
        contact_a,
        contact_b,
        closed,
        keep_a,
        keep_b,
        branches,
    })
}

fn contact_point(face: &dyn ParametricSurface, uv: DVec2) -> Result<DVec3, GeometryError> {
    face.point(uv.x, uv.y)
        .ok_or_else(|| construction("fillet", "a contact point is undefined"))
}

/// The arc about `c` from `pa` to `pb` (the shorter way) as a rational quadratic, its radius
/// the mean of their distances from `c`.
fn arc_section(c: DVec3, pa: DVec3, pb: DVec3) -> Result<SpaceCurve, GeometryError> {
    let (x, y) = (pa - c, pb - c);
    let cos = (x.dot(y) / (x.length() * y.length())).clamp(-1.0, 1.0);
    let theta = cos.acos();
    if !(theta < std::f64::consts::PI - 1e-6) {
        return Err(construction(
            "fillet",
            "the ball touches the two surfaces at opposite points (they face each other); no \
             fillet arc between them",
        ));
    }
    let half = 0.5 * theta;
    let bisector = (x + y).normalize_or_zero();
    let radius = 0.5 * (x.length() + y.length());
    let middle = if bisector == DVec3::ZERO || half < 1e-12 {
        0.5 * (pa + pb)
    } else {
        c + bisector * (radius / half.cos())
    };
    SpaceCurve::new(
        2,
        vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
        vec![pa, middle, pb],
        Some(vec![1.0, half.cos().max(1e-12), 1.0]),
    )
}

/// The side (looking along the contact curve `uv`) of `face` away from the fillet at point
/// `m`: the arc leaves the contact point toward the other contact point `other`, tangent to
/// the face; the kept side is the opposite one.
fn away_side(
    face: &dyn ParametricSurface,
    uv: &[DVec2],
    m: usize,
    centre: DVec3,
    other: DVec3,
) -> Result<Keep, GeometryError> {
    let p = uv[m];
    let d = face
        .derivatives(p.x, p.y)
        .ok_or_else(|| construction("fillet", "a contact point is undefined"))?;
    let x = d.point - centre;
    let y = other - centre;
    // The arc's tangent at the contact point, toward the other one.
    let t = y - x * (x.dot(y) / x.length_squared().max(f64::MIN_POSITIVE));
    // In the face's parameters: the least-squares (du, dv) with Su du + Sv dv = t.
    let (e, f, g) = (d.su.dot(d.su), d.su.dot(d.sv), d.sv.dot(d.sv));
    let (bu, bv) = (d.su.dot(t), d.sv.dot(t));
    let det = e * g - f * f;
    let into = DVec2::new(g * bu - f * bv, e * bv - f * bu) / det;
    let along = uv[(m + 1).min(uv.len() - 1)] - uv[m.saturating_sub(1)];
    Ok(if along.perp_dot(into) > 0.0 {
        // The fillet is on the left: keep the right.
        Keep::Right
    } else {
        Keep::Left
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::construct;

    /// Two planes meeting at a right angle along the x axis: z = 0 (y from −2 to 2) and y = 0
    /// (z from −2 to 2).
    fn right_angle() -> (NurbsSurface, NurbsSurface) {
        let floor = construct::plane(
            DVec3::new(-1.0, -2.0, 0.0),
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(0.0, 4.0, 0.0),
        )
        .unwrap();
        let wall = construct::plane(
            DVec3::new(-1.0, 0.0, -2.0),
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(0.0, 0.0, 4.0),
        )
        .unwrap();
        (floor, wall)
    }

    #[test]
    fn two_planes_at_a_right_angle_get_a_quarter_cylinder() {
        let (floor, wall) = right_angle();
        let nf = floor.normal(0.5, 0.5).unwrap();
        let nw = wall.normal(0.5, 0.5).unwrap();
        let r = 0.3;
        let fillet = fillet_surfaces(
            &floor,
            &wall,
            &FilletOptions {
                radius: r,
                side_a: 1.0,
                side_b: 1.0,
                tolerance: 1e-6,
                size: 6.0,
            },
        )
        .unwrap();
        // The axis runs along x at (y, z) = r (nf + nw) restricted to the yz plane.
        let axis = r * (nf + nw);
        for i in 0..=10 {
            for j in 0..=10 {
                let p = fillet
                    .surface
                    .point_at(i as f64 / 10.0, j as f64 / 10.0)
                    .unwrap();
                let d = DVec2::new(p.y - axis.y, p.z - axis.z).length();
                assert!((d - r).abs() < 1e-9, "{d}");
            }
        }
        let c = fillet.centres[fillet.centres.len() / 2];
        assert!((c.y - axis.y).abs() < 1e-9 && (c.z - axis.z).abs() < 1e-9);
        // Contact lines: on the floor at y = axis.y, on the wall at z = axis.z.
        let pa = floor
            .point_at(fillet.contact_a[0].x, fillet.contact_a[0].y)
            .unwrap();
        assert!((pa.y - axis.y).abs() < 1e-9 && pa.z.abs() < 1e-12);
    }

    #[test]
    fn a_radius_too_large_for_the_gap_is_refused() {
        let (floor, wall) = right_angle();
        let e = fillet_surfaces(
            &floor,
            &wall,
            &FilletOptions {
                radius: 5.0,
                side_a: 1.0,
                side_b: 1.0,
                tolerance: 1e-6,
                size: 6.0,
            },
        )
        .unwrap_err();
        assert!(e.to_string().contains("no ball"), "{e}");
    }
}
