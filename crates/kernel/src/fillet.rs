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
//!
//! A **variable radius** runs linearly, by length along the spine, from `radius` to
//! `radius_end`. The spine is first found for the mean radius; then each of its centres is
//! solved again for its own radius r by Newton's method on A(u, v) + σ_A r N_A = B(s, t) +
//! σ_B r N_B with the centre kept in the plane normal to the spine there (four equations in
//! u, v, s, t; the offsets' exact derivatives), so every section is still a circular arc of
//! radius r tangent to both surfaces.

use glam::{DVec2, DVec3};

use crate::curve::SpaceCurve;
use crate::diffgeo::SurfaceDerivatives;
use crate::error::GeometryError;
use crate::error::construction;
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
    /// A radius that varies: `radius` where the contact curve on A starts (its end of lower u,
    /// then lower v), this at its other end, linearly by length in between.
    pub radius_end: Option<f64>,
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
    for r in [Some(options.radius), options.radius_end]
        .into_iter()
        .flatten()
    {
        if !(r.is_finite() && r > 0.0) {
            return Err(construction(
                WHAT,
                format!("the radius must be a number above 0 (got {r})"),
            ));
        }
    }
    let ends = (options.radius, options.radius_end.unwrap_or(options.radius));
    let r = 0.5 * (ends.0 + ends.1);
    if !(options.tolerance.is_finite() && options.tolerance > 0.0) {
        return Err(construction(WHAT, "the tolerance must be a number above 0"));
    }
    let (offset_a, offset_b) = offsets(a, b, options, r);
    let size = options.size.max(options.tolerance);
    let intersect = IntersectOptions {
        tolerance: 1e-2 * options.tolerance,
        chord: (4.0 * options.tolerance).min(1e-3 * size),
        smallest: (1e-2 * size).max(r * 0.5),
        cell_pairs: crate::intersect::MAX_CELL_PAIRS,
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
    let spine = if ends.0 != ends.1 {
        vary_radius(a, b, spine, ends, options)?
    } else {
        spine
    };
    build(a, b, &spine, branches)
}

/// The spine ordered to start where the contact curve on A has the lower (u, then v).
fn oriented(mut spine: IntersectionCurve) -> IntersectionCurve {
    let (first, last) = (spine.uv_a[0], spine.uv_a[spine.uv_a.len() - 1]);
    if (last.x, last.y) < (first.x, first.y) {
        spine.points.reverse();
        spine.uv_a.reverse();
        spine.uv_b.reverse();
        spine.ends.reverse();
    }
    spine
}

/// The spine with each centre solved again for the radius that runs linearly by length from
/// `ends.0` to `ends.1` (see the module documentation), the contact parameters with it.
fn vary_radius(
    a: &dyn ParametricSurface,
    b: &dyn ParametricSurface,
    spine: IntersectionCurve,
    ends: (f64, f64),
    options: &FilletOptions,
) -> Result<IntersectionCurve, GeometryError> {
    const WHAT: &str = "fillet";
    if spine.closed {
        return Err(construction(
            WHAT,
            "the ball rolls all the way round: a closed fillet takes one radius",
        ));
    }
    let spine = oriented(spine);
    let n = spine.points.len();
    let mut along = vec![0.0; n];
    for k in 1..n {
        along[k] = along[k - 1] + spine.points[k].distance(spine.points[k - 1]);
    }
    let total = along[n - 1].max(f64::MIN_POSITIVE);
    // The constant-radius spine: each centre's plane and tangent come from it.
    let original = &spine.points;
    let mut solved_points = Vec::with_capacity(n);
    let (da, db) = (a.domain(), b.domain());
    let clamp = |x: f64, (lo, hi): (f64, f64)| x.clamp(lo, hi);
    for (k, length) in along.iter().enumerate() {
        let r = ends.0 + (ends.1 - ends.0) * length / total;
        let (oa, ob) = offsets(a, b, options, r);
        let spine_point = original[k];
        let tangent =
            (original[(k + 1).min(n - 1)] - original[k.saturating_sub(1)]).normalize_or_zero();
        let (mut x, mut y) = (spine.uv_a[k], spine.uv_b[k]);
        let mut solved = None;
        for _ in 0..40 {
            let (Some((pa, au, av)), Some((pb, bu, bv))) = (oa.first(x.x, x.y), ob.first(y.x, y.y))
            else {
                break;
            };
            let gap = pa - pb;
            let plane = (pa - spine_point).dot(tangent);
            if gap.length() <= 1e-3 * options.tolerance && plane.abs() <= 1e-3 * options.tolerance {
                solved = Some(pa);
                break;
            }
            let j = glam::DMat4::from_cols(
                au.extend(au.dot(tangent)),
                av.extend(av.dot(tangent)),
                (-bu).extend(0.0),
                (-bv).extend(0.0),
            );
            if j.determinant().abs() < 1e-300 {
                break;
            }
            let step = j.inverse() * -gap.extend(plane);
            x = DVec2::new(clamp(x.x + step.x, da[0]), clamp(x.y + step.y, da[1]));
            y = DVec2::new(clamp(y.x + step.z, db[0]), clamp(y.y + step.w, db[1]));
        }
        solved_points.push(solved.map(|centre| (centre, x, y)));
    }
    // The ball may stop fitting near the spine's ends (a larger one would touch past a
    // surface's edge): the fillet stops there. Anywhere else, or over more than half of it,
    // the radius cannot vary so.
    let kept: Vec<usize> = (0..n).filter(|&k| solved_points[k].is_some()).collect();
    let (first, last) = (
        kept.first().copied().unwrap_or(n),
        kept.last().copied().unwrap_or(0),
    );
    let gapless = first <= last && kept.len() == last - first + 1;
    if !gapless || 2 * kept.len() < n || kept.len() < 2 {
        let k = (0..n)
            .find(|&k| solved_points[k].is_none() && (k > first || !gapless))
            .unwrap_or(0);
        let r = ends.0 + (ends.1 - ends.0) * along[k] / total;
        let p = original[k];
        return Err(construction(
            WHAT,
            format!(
                "no ball of radius {r:.6} touches both surfaces near the spine's point \
                 ({:.4}, {:.4}, {:.4}): the radius cannot run from {} to {} here",
                p.x, p.y, p.z, ends.0, ends.1
            ),
        ));
    }
    let solved: Vec<(DVec3, DVec2, DVec2)> = solved_points.into_iter().flatten().collect();
    Ok(IntersectionCurve {
        points: solved.iter().map(|s| s.0).collect(),
        uv_a: solved.iter().map(|s| s.1).collect(),
        uv_b: solved.iter().map(|s| s.2).collect(),
        ..spine
    })
}

/// A and B offset by `r` to the sides of `options`: where the ball's centres lie.
fn offsets<'a>(
    a: &'a dyn ParametricSurface,
    b: &'a dyn ParametricSurface,
    options: &FilletOptions,
    r: f64,
) -> (OffsetFace<'a>, OffsetFace<'a>) {
    (
        OffsetFace {
            face: a,
            distance: options.side_a.signum() * r,
        },
        OffsetFace {
            face: b,
            distance: options.side_b.signum() * r,
        },
    )
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
    let surface = oriented_like(surface, a, contact_a[m])?;
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

/// `fillet` facing the way face `a` faces where they touch (at `a`'s point `contact`), its
/// v direction reversed where it did not: the fillet continues A's orientation across their
/// shared edge, so that it is drawn from the same side as A and a join of the two is
/// consistently oriented (whichever side of A the ball rolls on).
fn oriented_like(
    fillet: NurbsSurface,
    a: &dyn ParametricSurface,
    contact: DVec2,
) -> Result<NurbsSurface, GeometryError> {
    let undefined = || construction("fillet", "a contact normal is undefined");
    let at = contact_point(a, contact)?;
    let on_fillet = fillet.closest_point(at)?;
    let fillet_normal = fillet.normal(on_fillet.u, on_fillet.v)?;
    let a_normal = a.normal(contact.x, contact.y).ok_or_else(undefined)?;
    Ok(if fillet_normal.dot(a_normal) < 0.0 {
        fillet.reverse(crate::surface::Direction::V)
    } else {
        fillet
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

    /// How far section `k`'s contact points on the planes `a` and `b` (each with its unit
    /// normal toward the ball) are from the feet of its centre, the centre less `r` along each
    /// normal: the larger of the two.
    fn contacts_off_feet(
        fillet: &Fillet,
        k: usize,
        a: (&NurbsSurface, DVec3),
        b: (&NurbsSurface, DVec3),
        r: f64,
    ) -> f64 {
        let c = fillet.centres[k];
        let on = |s: &NurbsSurface, uv: DVec2| s.point_at(uv.x, uv.y).unwrap();
        let pa = on(a.0, fillet.contact_a[k]);
        let pb = on(b.0, fillet.contact_b[k]);
        pa.distance(c - a.1 * r).max(pb.distance(c - b.1 * r))
    }

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
                radius_end: None,
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

    /// Two planes at a right angle in general position (rotated about a skew axis, moved,
    /// scaled, parametrized along other edges and lengths), radius 0.75 on the scale of
    /// the first planes: every ball centre is the radius from both planes, each contact is
    /// the centre's foot, the fillet leaves each plane tangentially, and its area is the
    /// quarter cylinder's, π r L / 2.
    #[test]
    fn two_planes_at_a_right_angle_in_general_position_get_a_tangent_quarter_cylinder() {
        let cases = [
            (
                DVec3::new(0.3, -0.8, 0.5),
                1.1,
                DVec3::new(3.0, -7.0, 2.5),
                1.0,
            ),
            (
                DVec3::new(-0.2, 0.1, 0.9),
                2.7,
                DVec3::new(-120.0, 40.0, 9.0),
                37.0,
            ),
            (
                DVec3::new(1.0, 1.0, 0.2),
                0.4,
                DVec3::new(0.01, 0.02, -0.03),
                0.013,
            ),
            (
                DVec3::new(0.0, 1.0, 0.0),
                0.7,
                DVec3::new(1e3, -2e3, 5e2),
                950.0,
            ),
        ];
        for (seed, &(axis, angle, shift, scale)) in cases.iter().enumerate() {
            let place = glam::DAffine3::from_translation(shift)
                * glam::DAffine3::from_axis_angle(axis.normalize(), angle)
                * glam::DAffine3::from_scale(DVec3::splat(scale));
            let at = |p: DVec3| place.transform_point3(p);
            let along = |v: DVec3| place.transform_vector3(v);
            // The floor z = 0 (x from −2 to 2, y from 0 to 3) and the wall y = 0 (z from 0 to
            // 3): their corner is the x axis, the ball on the front sides (+z, +y)...
            let floor = construct::plane(
                at(DVec3::new(2.0, 0.0, 0.0)),
                along(DVec3::new(0.0, 3.0, 0.0)),
                along(DVec3::new(-4.0, 0.0, 0.0)),
            )
            .unwrap();
            let wall = construct::plane(
                at(DVec3::new(-2.0, 0.0, 0.0)),
                along(DVec3::new(4.0, 0.0, 0.0)),
                along(DVec3::new(0.0, 0.0, 3.0)),
            )
            .unwrap();
            let (nf, nw) = (along(DVec3::Z).normalize(), along(DVec3::Y).normalize());
            let side = |s: &NurbsSurface, n: DVec3| s.normal(0.5, 0.5).unwrap().dot(n).signum();
            let r = 0.75 * scale;
            let options = FilletOptions {
                radius: r,
                radius_end: None,
                side_a: side(&floor, nf),
                side_b: side(&wall, nw),
                tolerance: 1e-4 * 6.0 * scale,
                size: 6.0 * scale,
            };
            let fillet = fillet_surfaces(&floor, &wall, &options).unwrap();
            let origin = at(DVec3::ZERO);
            for (k, c) in fillet.centres.iter().enumerate() {
                let (df, dw) = ((*c - origin).dot(nf), (*c - origin).dot(nw));
                assert!(
                    (df - r).abs() < 1e-6 * scale && (dw - r).abs() < 1e-6 * scale,
                    "seed {seed}, centre {k}: {df} and {dw} from the planes, radius {r}"
                );
                assert!(
                    contacts_off_feet(&fillet, k, (&floor, nf), (&wall, nw), r) < 1e-6 * scale,
                    "seed {seed}"
                );
            }
            // Tangency: the fillet's cross tangent at each side lies in that plane.
            let s = &fillet.surface;
            let [(u0, u1), (v0, v1)] = s.domain();
            let mut area = 0.0;
            let (nu, nv) = (16, 64);
            for j in 0..=8 {
                let v = v0 + (v1 - v0) * j as f64 / 8.0;
                for (u, n) in [(u0, nf), (u1, nw)] {
                    let d = s.evaluate(u, v).unwrap();
                    let t = d.su.normalize();
                    let degrees = t.dot(n).abs().asin().to_degrees();
                    assert!(degrees < 1e-4, "seed {seed}: meets at {degrees}°");
                }
            }
            // The area by the midpoint rule on |S_u × S_v|.
            for i in 0..nu {
                for j in 0..nv {
                    let u = u0 + (u1 - u0) * (i as f64 + 0.5) / nu as f64;
                    let v = v0 + (v1 - v0) * (j as f64 + 0.5) / nv as f64;
                    let d = s.evaluate(u, v).unwrap();
                    area += d.su.cross(d.sv).length() * (u1 - u0) * (v1 - v0) / (nu * nv) as f64;
                }
            }
            let exact = std::f64::consts::FRAC_PI_2 * r * 4.0 * scale;
            assert!(
                (area - exact).abs() < 1e-3 * exact,
                "seed {seed}: area {area}, exact {exact}"
            );
        }
    }

    #[test]
    fn a_radius_too_large_for_the_gap_is_refused() {
        let (floor, wall) = right_angle();
        let e = fillet_surfaces(
            &floor,
            &wall,
            &FilletOptions {
                radius: 5.0,
                radius_end: None,
                side_a: 1.0,
                side_b: 1.0,
                tolerance: 1e-6,
                size: 6.0,
            },
        )
        .unwrap_err();
        assert!(e.to_string().contains("no ball"), "{e}");
    }

    #[test]
    fn a_radius_from_0_2_to_0_6_along_two_planes_touches_both_at_its_own_radius() {
        let (floor, wall) = right_angle();
        let options = FilletOptions {
            radius: 0.2,
            radius_end: Some(0.6),
            side_a: 1.0,
            side_b: 1.0,
            tolerance: 1e-6,
            size: 6.0,
        };
        let fillet = fillet_surfaces(&floor, &wall, &options).unwrap();
        let (nf, nw) = (
            floor.normal(0.5, 0.5).unwrap(),
            wall.normal(0.5, 0.5).unwrap(),
        );
        // The contact on the floor starts at its lower u, x = −1: the radius there is 0.2 and
        // grows linearly with x to 0.6 at x = 1.
        let n = fillet.centres.len();
        for (k, c) in fillet.centres.iter().enumerate() {
            let r = 0.2 + 0.4 * (c.x + 1.0) / 2.0;
            // The centre is r from both planes on their front sides.
            assert!((c.dot(nf) - r).abs() < 1e-6, "{k}/{n}: {c} {r}");
            assert!((c.dot(nw) - r).abs() < 1e-6, "{k}/{n}: {c} {r}");
            // The contacts are the feet of the centre on each plane.
            assert!(contacts_off_feet(&fillet, k, (&floor, nf), (&wall, nw), r) < 1e-6);
        }
        assert!(
            (fillet.centres[0].x + 1.0).abs() < 1e-6
                && (fillet.centres[n - 1].x - 1.0).abs() < 1e-6
        );
        // A radius that outgrows the planes over most of the way (contact past their edges)
        // is refused.
        let grown = FilletOptions {
            radius_end: Some(9.0),
            ..options
        };
        let e = fillet_surfaces(&floor, &wall, &grown).unwrap_err();
        assert!(e.to_string().contains("no ball"), "{e}");
    }

    #[test]
    fn a_varying_radius_between_two_bicubics_keeps_each_ball_touching_both() {
        let (floor, wall) = crate::samples::floor_and_wall().unwrap();
        let size = floor.size().max(wall.size());
        let options = FilletOptions {
            radius: 0.3,
            radius_end: Some(0.5),
            side_a: 1.0,
            side_b: 1.0,
            tolerance: 1e-6 * size,
            size,
        };
        let fillet = fillet_surfaces(&floor, &wall, &options).unwrap();
        let mut last = 0.0;
        for (k, c) in fillet.centres.iter().enumerate() {
            // The ball at this centre touches both: its distance to each is its radius, and
            // the contacts lie at that distance.
            let (to_a, to_b) = (
                floor.closest_point(*c).unwrap().distance,
                wall.closest_point(*c).unwrap().distance,
            );
            assert!((to_a - to_b).abs() < 1e-5, "{k}: {to_a} {to_b}");
            let pa = floor
                .point_at(fillet.contact_a[k].x, fillet.contact_a[k].y)
                .unwrap();
            let pb = wall
                .point_at(fillet.contact_b[k].x, fillet.contact_b[k].y)
                .unwrap();
            assert!((pa.distance(*c) - to_a).abs() < 1e-5 && (pb.distance(*c) - to_a).abs() < 1e-5);
            // The radius grows from 0.3 to 0.5 along the fillet.
            assert!(
                to_a >= last - 1e-9 && (0.3 - 1e-6..=0.5 + 1e-6).contains(&to_a),
                "{k}: {to_a}"
            );
            last = to_a;
        }
        // From 0.3 where it starts; the ball may stop fitting before it reaches 0.5 at the far
        // end (the spine ends on a surface's edge), but it has grown well on the way.
        let n = fillet.centres.len();
        let first = floor.closest_point(fillet.centres[0]).unwrap().distance;
        assert!(
            (first - 0.3).abs() < 1e-6 && last > 0.45,
            "{first} {last} ({n})"
        );
    }
}
