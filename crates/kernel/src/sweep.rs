//! Sweeps through profiles along one rail or between two rails. A general sweep has no exact
//! NURBS form, so both place copies of the profiles in moving frames at many parameters of the
//! rail(s) and loft them ([`super::loft`]): the profiles themselves are among the sections, so
//! they lie on the surface exactly, and more sections follow the rails more closely.
//!
//! Between two profiles a section is a blend of the two, in the moving frame: each profile is
//! written in the frame at its own place (its local coordinates), the local coordinates are
//! blended linearly in the rail parameter, and the blend is placed in the frame at the section.
//! Before and after the outermost profiles the nearest profile is carried unchanged.

use glam::{DMat3, DVec3, DVec4};

use super::curve::SpaceCurve;
use super::error::GeometryError;
use super::error::construction;
use super::interpolation::make_compatible;
use super::loft::{LoftOptions, LoftStyle, align_sections, loft_sections};
use super::surface::NurbsSurface;
use super::vector::CurvePoint;

/// How the frame of a one-rail sweep turns along the rail.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum SweepFrame {
    /// The rotation-minimising frame (double reflection: Wang, Jüttler, Zheng and Liu,
    /// "Computation of rotation minimizing frames", ACM TOG 2008): no twist about the rail.
    #[default]
    RotationMinimizing,
    /// The frame keeps this direction up (the profile does not roll); the rail must never run
    /// along it.
    FixedUp(DVec3),
}

/// The most sections a sweep lofts.
const MAX_SECTIONS: usize = 400;
/// Reflection steps between two consecutive sections of a rotation-minimising frame.
const FRAME_SUBSTEPS: usize = 8;

/// An orthonormal frame at a point: `axes` maps local coordinates to space.
#[derive(Debug, Clone, Copy)]
pub(super) struct Frame {
    origin: DVec3,
    axes: DMat3,
    /// Local coordinates are scaled by this, per axis, before the axes apply (1 for one rail;
    /// the distance between the rails for two, along the chord only where the height is
    /// kept).
    scale: DVec3,
}

impl Frame {
    /// The local coordinates of the point `p`.
    pub(super) fn local(self, p: DVec3) -> DVec3 {
        self.axes.transpose() * (p - self.origin) / self.scale
    }

    /// The point at local coordinates `local`.
    pub(super) fn placed(self, local: DVec3) -> DVec3 {
        self.origin + self.axes * (local * self.scale)
    }
}

/// A polygon's homogeneous points with their Cartesian part mapped by `f` (weights kept).
fn mapped(points: &[DVec4], f: impl Fn(DVec3) -> DVec3) -> Vec<DVec4> {
    points
        .iter()
        .map(|h| (f(DVec3::project(*h)) * h.w).extend(h.w))
        .collect()
}

/// The section parameters: `count` evenly spaced over [0, 1], with the profiles' parameters
/// `fixed` put in (and even ones closer than a quarter step to them left out).
fn section_parameters(fixed: &[f64], count: usize) -> Vec<f64> {
    let step = 1.0 / count as f64;
    let mut params: Vec<f64> = (0..=count)
        .map(|i| i as f64 * step)
        .filter(|t| fixed.iter().all(|f| (f - t).abs() > 0.25 * step))
        .chain(fixed.iter().copied())
        .collect();
    params.sort_by(f64::total_cmp);
    params.dedup_by(|a, b| (*a - *b).abs() <= 1e-12);
    params
}

/// The profiles' local control points blended at `t` (profile k at `at[k]`, sorted).
fn blended(local: &[Vec<DVec4>], at: &[f64], t: f64) -> Vec<DVec4> {
    let last = at.len() - 1;
    if last == 0 || !(t > at[0]) {
        return local[0].clone();
    }
    if t >= at[last] {
        return local[last].clone();
    }
    let k = at[1..last].iter().take_while(|&&a| a <= t).count();
    let s = (t - at[k]) / (at[k + 1] - at[k]);
    local[k]
        .iter()
        .zip(&local[k + 1])
        .map(|(a, b)| *a * (1.0 - s) + *b * s)
        .collect()
}

/// The sections at `params`: the profiles written in the frames at their places, aligned there (so
/// that closed profiles' seams and directions match in the moving frame, not in space) and
/// made compatible, then blended at each parameter and placed in `frame(t)`.
fn sections_in_frames(
    profiles: &[SpaceCurve],
    frames_at_profiles: &[Frame],
    at: &[f64],
    params: &[f64],
    frame: impl Fn(f64) -> Result<Frame, GeometryError>,
) -> Result<Vec<SpaceCurve>, GeometryError> {
    let local = profiles
        .iter()
        .zip(frames_at_profiles)
        .map(|(p, f)| p.map_points(|x| f.local(x)))
        .collect::<Result<Vec<_>, _>>()?;
    let polys = make_compatible(&align_sections(&local)?)?;
    let local: Vec<Vec<DVec4>> = polys.iter().map(|p| p.points.clone()).collect();
    let sections = params
        .iter()
        .map(|&t| {
            let f = frame(t)?;
            let points = mapped(&blended(&local, at, t), |x| f.placed(x));
            SpaceCurve::from_homogeneous(polys[0].degree, polys[0].knots.clone(), points)
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(sections)
}

/// How far (a fraction of the rails' size) a sweep may stray from its exact sections between
/// the ones it lofts: well inside the 1e-4 of the size that the editor's constructions keep.
const SWEEP_TOLERANCE: f64 = 3e-5;

/// Points of each section between two lofted ones compared with the surface.
const CHECKS_PER_SECTION: usize = 9;

/// The sweep lofted through the exact `sections` at `count` evenly spaced parameters (with
/// the profiles' `fixed` ones), the count doubled while the exact section half-way between
/// two lofted ones strays from the surface by more than [`SWEEP_TOLERANCE`] of `size` (its
/// points' distances, by point inversion from the same u and the v of its rail parameter),
/// up to [`MAX_SECTIONS`].
fn refined_sweep(
    fixed: &[f64],
    mut count: usize,
    size: f64,
    sections: impl Fn(&[f64]) -> Result<Vec<SpaceCurve>, GeometryError>,
) -> Result<NurbsSurface, GeometryError> {
    let loft = |curves: &[SpaceCurve]| {
        loft_sections(
            curves,
            &LoftOptions {
                degree: 3,
                closed: false,
                style: LoftStyle::Normal,
                align: false,
            },
        )
    };
    let mut params = section_parameters(fixed, count);
    let mut curves = sections(&params)?;
    loop {
        let surface = loft(&curves)?;
        if 2 * count > MAX_SECTIONS {
            return Ok(surface);
        }
        let finer_params = section_parameters(fixed, 2 * count);
        let finer = sections(&finer_params)?;
        // The sections share the surface's u; its v runs with the rail parameter, near
        // enough for Newton to start from.
        let [_, (v0, v1)] = surface.domain();
        let mut worst = 0.0f64;
        for (t, curve) in finer_params.iter().zip(&finer) {
            if params.contains(t) {
                continue;
            }
            let (t0, t1) = curve.domain();
            for i in 0..CHECKS_PER_SECTION {
                let u = t0 + (t1 - t0) * i as f64 / (CHECKS_PER_SECTION - 1) as f64;
                let p = curve.point_at(u)?;
                let near = surface.closest_point_from(p, u, v0 + (v1 - v0) * t);
                worst = worst.max(near.distance);
            }
        }
        if worst <= SWEEP_TOLERANCE * size {
            return Ok(surface);
        }
        count *= 2;
        (params, curves) = (finer_params, finer);
    }
}

/// The diagonal of the box round the curves' control points.
fn size_of(curves: &[&SpaceCurve]) -> f64 {
    let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
    for c in curves {
        for h in c.homogeneous_points() {
            let p = DVec3::project(*h);
            lo = lo.min(p);
            hi = hi.max(p);
        }
    }
    lo.distance(hi)
}

/// The number of evenly spaced sections for rails: four per Bézier span of the busiest rail,
/// at least 16.
fn section_count(rails: &[&SpaceCurve]) -> usize {
    let spans = rails
        .iter()
        .map(|r| r.bezier_segments().len())
        .max()
        .unwrap_or(1);
    (4 * spans).clamp(16, MAX_SECTIONS / 2)
}

/// The profiles with their keys, sorted by the rail parameter `at(key)`; the parameters must differ.
fn sorted_profiles<K>(
    profiles: Vec<SpaceCurve>,
    keys: Vec<K>,
    at: impl Fn(&K) -> f64,
    what: &'static str,
) -> Result<(Vec<SpaceCurve>, Vec<K>), GeometryError> {
    let mut pairs: Vec<(SpaceCurve, K)> = profiles.into_iter().zip(keys).collect();
    pairs.sort_by(|a, b| at(&a.1).total_cmp(&at(&b.1)));
    for w in pairs.windows(2) {
        if !(at(&w[1].1) - at(&w[0].1) > 1e-9) {
            return Err(construction(
                what,
                "two profiles sit at the same place on the rail",
            ));
        }
    }
    Ok(pairs.into_iter().unzip())
}

/// The tangent of a curve on [0, 1] at `t`, unit length.
fn unit_tangent(curve: &SpaceCurve, t: f64, what: &'static str) -> Result<DVec3, GeometryError> {
    let d = curve.derivatives(t, 1)?[1];
    if !(d.length() > 1e-300) {
        return Err(construction(what, "a rail has a point with zero tangent"));
    }
    Ok(d.normalize())
}

/// The frame with tangent `t` (its third axis) and `r` (projected off `t`) as its first axis.
fn frame_from(origin: DVec3, t: DVec3, r: DVec3) -> Frame {
    let r = (r - t * r.dot(t)).normalize();
    Frame {
        origin,
        axes: DMat3::from_cols(r, t.cross(r), t),
        scale: DVec3::ONE,
    }
}

/// A vector perpendicular to `t`.
fn perpendicular(t: DVec3) -> DVec3 {
    let helper = if t.x.abs() < 0.9 { DVec3::X } else { DVec3::Y };
    t.cross(helper).normalize()
}

/// A sweep of `profiles` along `rail` (see the module documentation). Each profile sits at
/// the rail parameter nearest to it; the frame turns by `frame`. u runs along the profiles,
/// v along the rail. Every profile lies on the surface.
pub fn sweep_one_rail(
    rail: &SpaceCurve,
    profiles: &[SpaceCurve],
    frame: SweepFrame,
) -> Result<NurbsSurface, GeometryError> {
    const WHAT: &str = "sweep1";
    if profiles.is_empty() {
        return Err(construction(WHAT, "needs at least one profile"));
    }
    let rail = rail.reparametrized(0.0, 1.0)?;
    let at = profiles
        .iter()
        .map(|p| nearest_rail_parameter(&rail, p))
        .collect::<Result<Vec<_>, _>>()?;
    let (profiles, at) = sorted_profiles(profiles.to_vec(), at, |&t| t, WHAT)?;
    if let SweepFrame::FixedUp(up) = frame
        && (!(up.length() > 1e-300) || !up.is_finite())
    {
        return Err(construction(WHAT, "the up direction has zero length"));
    }
    // The sections at `params` (the profiles' parameters among them), in the frames there.
    let sections = |params: &[f64]| -> Result<Vec<SpaceCurve>, GeometryError> {
        let frames = match frame {
            SweepFrame::FixedUp(up) => params
                .iter()
                .map(|&t| {
                    let tangent = unit_tangent(&rail, t, WHAT)?;
                    let side = up.cross(tangent);
                    if !(side.length() > 1e-9 * up.length()) {
                        return Err(construction(
                            WHAT,
                            format!("the rail runs along the up direction at t = {t:.4}"),
                        ));
                    }
                    Ok(frame_from(rail.point_at(t)?, tangent, side))
                })
                .collect::<Result<Vec<_>, _>>()?,
            SweepFrame::RotationMinimizing => rotation_minimizing_frames(&rail, params, WHAT)?,
        };
        let frame_at = |t: f64| -> Result<Frame, GeometryError> {
            let i = params
                .iter()
                .position(|&p| p == t)
                .ok_or_else(|| construction(WHAT, "a section without a frame"))?;
            Ok(frames[i])
        };
        let profile_frames = at
            .iter()
            .map(|&t| frame_at(t))
            .collect::<Result<Vec<_>, _>>()?;
        sections_in_frames(&profiles, &profile_frames, &at, params, frame_at)
    };
    let mut curves: Vec<&SpaceCurve> = profiles.iter().collect();
    curves.push(&rail);
    refined_sweep(&at, section_count(&[&rail]), size_of(&curves), sections)
}

/// The rail parameter (on [0, 1]) nearest to a profile: where the profile and the rail come
/// closest (each end of the profile and the point of the profile nearest the rail's middle
/// are tried, and the closest pair wins).
fn nearest_rail_parameter(rail: &SpaceCurve, profile: &SpaceCurve) -> Result<f64, GeometryError> {
    let profile = profile.reparametrized(0.0, 1.0)?;
    let (rs, ps) = (
        super::transfinite::samples(rail)?,
        super::transfinite::samples(&profile)?,
    );
    let (t, _, _) = super::transfinite::crossing((rail, &rs), (&profile, &ps))?;
    Ok(t)
}

/// Rotation-minimising frames at `params` (increasing, on [0, 1]) by double reflection with
/// [`FRAME_SUBSTEPS`] steps between consecutive parameters, starting from a frame whose first
/// axis is perpendicular to the start tangent.
pub(super) fn rotation_minimizing_frames(
    rail: &SpaceCurve,
    params: &[f64],
    what: &'static str,
) -> Result<Vec<Frame>, GeometryError> {
    let t0 = unit_tangent(rail, params[0], what)?;
    let mut r = perpendicular(t0);
    let mut x0 = rail.point_at(params[0])?;
    let mut tangent = t0;
    let mut frames = vec![frame_from(x0, t0, r)];
    for w in params.windows(2) {
        for j in 1..=FRAME_SUBSTEPS {
            let t = w[0] + (w[1] - w[0]) * j as f64 / FRAME_SUBSTEPS as f64;
            let x1 = rail.point_at(t)?;
            let t1 = unit_tangent(rail, t, what)?;
            let v1 = x1 - x0;
            let c1 = v1.dot(v1);
            let (rl, tl) = if c1 > 0.0 {
                (
                    r - v1 * (2.0 / c1 * v1.dot(r)),
                    tangent - v1 * (2.0 / c1 * v1.dot(tangent)),
                )
            } else {
                (r, tangent)
            };
            let v2 = t1 - tl;
            let c2 = v2.dot(v2);
            r = if c2 > 0.0 {
                rl - v2 * (2.0 / c2 * v2.dot(rl))
            } else {
                rl
            };
            r = (r - t1 * r.dot(t1)).normalize();
            (x0, tangent) = (x1, t1);
        }
        frames.push(frame_from(x0, tangent, r));
    }
    Ok(frames)
}

/// A sweep of `profiles` between two rails (see the module documentation). Each profile runs
/// from the first rail to the second (a profile given the other way round is reversed; the
/// second rail is reversed if it runs against the first). At a section the frame's first axis
/// is the chord from rail 0 to rail 1, the third is the rails' mean tangent made
/// perpendicular to it, and local coordinates scale with the chord's length (only along the
/// chord with `keep_height`, so that the profiles keep their height), so a profile whose
/// ends lie on the rails gives sections whose ends lie on them too. u runs along the profiles,
/// v along the rails.
pub fn sweep_two_rails(
    rails: [&SpaceCurve; 2],
    profiles: &[SpaceCurve],
    keep_height: bool,
) -> Result<NurbsSurface, GeometryError> {
    const WHAT: &str = "sweep2";
    if profiles.is_empty() {
        return Err(construction(WHAT, "needs at least one profile"));
    }
    let r0 = rails[0].reparametrized(0.0, 1.0)?;
    let mut r1 = rails[1].reparametrized(0.0, 1.0)?;
    let (a0, b0) = (r0.point_at(0.0)?, r0.point_at(1.0)?);
    let (a1, b1) = (r1.point_at(0.0)?, r1.point_at(1.0)?);
    if a0.distance(b1) + b0.distance(a1) < a0.distance(a1) + b0.distance(b1) {
        r1 = r1.reverse();
    }
    // Each profile from rail 0 to rail 1, with its parameter on each: the ends are matched to
    // the rails both ways round, and the nearer way wins.
    let on_rails_from = |a: DVec3, b: DVec3| -> Result<((f64, f64), f64), GeometryError> {
        let (s0, s1) = (r0.closest_parameter(a)?, r1.closest_parameter(b)?);
        let gap = r0.point_at(s0)?.distance(a) + r1.point_at(s1)?.distance(b);
        Ok(((s0, s1), gap))
    };
    let mut oriented = Vec::with_capacity(profiles.len());
    let mut on_rails: Vec<(f64, f64)> = Vec::with_capacity(profiles.len());
    for (k, p) in profiles.iter().enumerate() {
        let (start, end) = p.ends()?;
        if start.distance(end) <= 1e-12 * (1.0 + start.length()) {
            return Err(construction(
                WHAT,
                format!("profile {k} is closed; a two-rail profile runs from rail to rail"),
            ));
        }
        let (forward, forward_gap) = on_rails_from(start, end)?;
        let (backward, backward_gap) = on_rails_from(end, start)?;
        if backward_gap < forward_gap {
            oriented.push(p.reverse());
            on_rails.push(backward);
        } else {
            oriented.push(p.clone());
            on_rails.push(forward);
        }
    }
    let (profiles, on_rails) = sorted_profiles(oriented, on_rails, |&(s0, _)| s0, WHAT)?;
    for w in on_rails.windows(2) {
        if !(w[1].1 > w[0].1) {
            return Err(construction(
                WHAT,
                "the profiles meet the two rails in different orders",
            ));
        }
    }
    let at: Vec<f64> = on_rails.iter().map(|&(s0, _)| s0).collect();
    // Rail 1's parameter as a piecewise linear function of rail 0's, through the profiles and
    // the ends.
    let mut anchors = vec![(0.0, 0.0)];
    anchors.extend(
        on_rails
            .iter()
            .filter(|(s, _)| *s > 1e-12 && *s < 1.0 - 1e-12),
    );
    anchors.push((1.0, 1.0));
    let second = |t: f64| -> f64 {
        let k = anchors[1..anchors.len() - 1]
            .iter()
            .take_while(|a| a.0 <= t)
            .count();
        let ((x0, y0), (x1, y1)) = (anchors[k], anchors[k + 1]);
        if x1 - x0 <= 0.0 {
            y0
        } else {
            y0 + (y1 - y0) * (t - x0) / (x1 - x0)
        }
    };
    let frame = |t: f64| -> Result<Frame, GeometryError> {
        let u = second(t);
        let (p0, p1) = (r0.point_at(t)?, r1.point_at(u)?);
        let chord = p1 - p0;
        let length = chord.length();
        if !(length > 1e-12 * (1.0 + p0.length())) {
            return Err(construction(
                WHAT,
                format!(
                    "the rails meet (at rail 0's t = {t:.4}); a two-rail sweep needs them apart"
                ),
            ));
        }
        let x = chord / length;
        let along = unit_tangent(&r0, t, WHAT)? + unit_tangent(&r1, u, WHAT)?;
        let z = along - x * along.dot(x);
        if !(z.length() > 1e-9 * along.length().max(1e-300)) {
            return Err(construction(
                WHAT,
                format!("the rails run along the chord between them at rail 0's t = {t:.4}"),
            ));
        }
        let z = z.normalize();
        Ok(Frame {
            origin: p0,
            axes: DMat3::from_cols(x, z.cross(x), z),
            scale: if keep_height {
                DVec3::new(length, 1.0, 1.0)
            } else {
                DVec3::splat(length)
            },
        })
    };
    let profile_frames = at
        .iter()
        .map(|&t| frame(t))
        .collect::<Result<Vec<_>, _>>()?;
    let mut curves: Vec<&SpaceCurve> = profiles.iter().collect();
    curves.extend([&r0, &r1]);
    refined_sweep(
        &at,
        section_count(&[&r0, &r1]),
        size_of(&curves),
        |params| sections_in_frames(&profiles, &profile_frames, &at, params, frame),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::construct::{arc, circle, interpolate, line};
    use std::f64::consts::FRAC_PI_2;

    /// The largest distance from the curve's points to the surface.
    fn distance_from(surface: &NurbsSurface, curve: &SpaceCurve) -> f64 {
        crate::test_support::curve_to_surface(surface, curve, 40)
    }

    #[test]
    fn a_circle_swept_along_a_straight_rail_is_a_cylinder() {
        let rail = line(DVec3::ZERO, DVec3::new(0.0, 0.0, 3.0)).unwrap();
        let profile = circle(DVec3::ZERO, DVec3::Z, DVec3::X, 1.0).unwrap();
        let s =
            sweep_one_rail(&rail, std::slice::from_ref(&profile), SweepFrame::default()).unwrap();
        assert!(distance_from(&s, &profile) < 1e-9);
        for i in 0..=10 {
            for j in 0..=10 {
                let p = s.point_at(i as f64 / 10.0, j as f64 / 10.0).unwrap();
                assert!((p.x.hypot(p.y) - 1.0).abs() < 1e-9, "{p}");
            }
        }
    }

    #[test]
    fn profiles_along_a_bent_rail_lie_on_the_sweep_and_sections_keep_their_shape() {
        // A quarter circle rail of radius 5 in the xz-plane; a small circle profile at each end
        // (radius 0.5 and 1, in the planes normal to the rail).
        let rail = arc(DVec3::ZERO, DVec3::X, DVec3::Z, 5.0, 0.0, FRAC_PI_2).unwrap();
        let start = circle(DVec3::new(5.0, 0.0, 0.0), DVec3::Z, DVec3::X, 0.5).unwrap();
        let end = circle(DVec3::new(0.0, 0.0, 5.0), DVec3::X, DVec3::Y, 1.0).unwrap();
        for frame in [
            SweepFrame::RotationMinimizing,
            SweepFrame::FixedUp(DVec3::Y),
        ] {
            let s = sweep_one_rail(&rail, &[end.clone(), start.clone()], frame).unwrap();
            assert!(distance_from(&s, &start) < 1e-9);
            assert!(distance_from(&s, &end) < 1e-9);
            // Halfway along, the section is a circle of radius 0.75 around the rail's middle.
            let centre = DVec3::new(5.0, 0.0, 5.0) * std::f64::consts::FRAC_1_SQRT_2;
            let [(u0, u1), (v0, v1)] = s.domain();
            let v = 0.5 * (v0 + v1);
            for i in 0..8 {
                let p = s.point_at(u0 + (u1 - u0) * i as f64 / 8.0, v).unwrap();
                let r = p.distance(centre);
                assert!((r - 0.75).abs() < 0.02, "radius {r} at {p}");
            }
        }
    }

    #[test]
    fn a_two_rail_sweep_follows_both_rails_through_its_profiles() {
        // Two straight rails that spread apart; profiles are arcs from rail to rail.
        let r0 = line(DVec3::ZERO, DVec3::new(0.0, 4.0, 0.0)).unwrap();
        let r1 = line(DVec3::new(6.0, 4.0, 0.0), DVec3::new(2.0, 0.0, 0.0)).unwrap();
        let bump = |y: f64, width: f64| {
            interpolate(
                &[
                    DVec3::new(0.0, y, 0.0),
                    DVec3::new(width * 0.5, y, width * 0.3),
                    DVec3::new(width, y, 0.0),
                ],
                2,
            )
            .unwrap()
        };
        let profiles = [bump(0.0, 2.0), bump(4.0, 6.0).reverse(), bump(2.0, 4.0)];
        let s = sweep_two_rails([&r0, &r1], &profiles, false).unwrap();
        for p in &profiles {
            assert!(distance_from(&s, p) < 1e-9);
        }
        assert!(distance_from(&s, &r0) < 1e-6, "{}", distance_from(&s, &r0));
        assert!(distance_from(&s, &r1) < 1e-6, "{}", distance_from(&s, &r1));
    }

    /// A rotation and a move of general position.
    fn placement() -> glam::DAffine3 {
        glam::DAffine3::from_scale_rotation_translation(
            DVec3::splat(3.3),
            glam::DQuat::from_euler(glam::EulerRot::YXZ, 0.8, -0.5, 2.2),
            DVec3::new(-4.0, 9.0, 1.5),
        )
    }

    /// The largest `error` over an (nu + 1) × (nv + 1) grid of the surface's domain.
    fn worst_over_grid(
        s: &NurbsSurface,
        nu: usize,
        nv: usize,
        error: impl Fn(DVec3) -> f64,
    ) -> f64 {
        let [(u0, u1), (v0, v1)] = s.domain();
        let mut worst = 0.0_f64;
        for i in 0..=nu {
            for j in 0..=nv {
                let u = u0 + (u1 - u0) * i as f64 / nu as f64;
                let v = v0 + (v1 - v0) * j as f64 / nv as f64;
                worst = worst.max(error(s.point_at(u, v).unwrap()));
            }
        }
        worst
    }

    /// The size the sweeps keep their tolerance against: the box round the curves.
    fn size(curves: &[&SpaceCurve]) -> f64 {
        super::size_of(curves)
    }

    /// A pipe (a circle swept along a wavy cubic rail in general position, rotation-minimising
    /// frames): every point of it lies the circle's radius from the rail, within 1e-4 of the
    /// size, between the lofted sections as well as on them.
    #[test]
    fn a_pipe_along_a_wavy_rail_keeps_its_radius() {
        let place = placement();
        let rail: Vec<DVec3> = (0..7)
            .map(|i| {
                let t = i as f64;
                DVec3::new(t, 0.8 * (1.3 * t).sin(), 0.5 * (0.9 * t).cos())
            })
            .collect();
        let rail = interpolate(&rail, 3).unwrap().transformed(&place).unwrap();
        let start = rail.point_at(rail.domain().0).unwrap();
        let tangent = rail.derivatives(rail.domain().0, 1).unwrap()[1].normalize();
        let radius = 0.3 * 3.3;
        let x = super::perpendicular(tangent);
        let profile = circle(start, tangent, x, radius).unwrap();
        let s =
            sweep_one_rail(&rail, std::slice::from_ref(&profile), SweepFrame::default()).unwrap();
        let tolerance = 1e-4 * size(&[&rail, &profile]);
        let worst = worst_over_grid(&s, 16, 97, |p| {
            let t = rail.closest_parameter(p).unwrap();
            (rail.point_at(t).unwrap().distance(p) - radius).abs()
        });
        assert!(
            worst <= tolerance,
            "radius off by {worst:e} (tolerance {tolerance:e})"
        );
    }

    /// A two-rail sweep between a cubic rail and a rational cubic rail, through a rational
    /// arc, in general position: both rails lie on the surface within 1e-4 of the size.
    #[test]
    fn a_two_rail_sweep_of_an_arc_between_a_cubic_and_a_rational_rail_holds_both() {
        let place = placement();
        let r0: Vec<DVec3> = (0..6)
            .map(|i| DVec3::new(0.3 * (i as f64).sin(), i as f64, 0.2 * i as f64))
            .collect();
        let r0 = interpolate(&r0, 3).unwrap().transformed(&place).unwrap();
        let r1 = crate::curve::NurbsCurve::new(
            3,
            vec![0.0, 0.0, 0.0, 0.0, 0.4, 1.0, 1.0, 1.0, 1.0],
            vec![
                DVec3::new(2.0, 0.0, 0.0),
                DVec3::new(3.0, 1.5, 0.5),
                DVec3::new(2.5, 3.0, 1.2),
                DVec3::new(3.5, 4.0, 0.4),
                DVec3::new(2.6, 5.0, 1.0),
            ],
            Some(vec![1.0, 1.7, 0.6, 1.3, 1.0]),
        )
        .unwrap()
        .transformed(&place)
        .unwrap();
        let (a, b) = (r0.point_at(0.0).unwrap(), r1.point_at(0.0).unwrap());
        let middle = 0.5 * (a + b);
        let half = 0.5 * a.distance(b);
        let x = (a - middle).normalize();
        let up = place.transform_vector3(DVec3::Z).normalize();
        let y = (up - x * up.dot(x)).normalize();
        // Half a circle from A over the top to B: a rational arc.
        let arch = arc(middle, x, y, half, 0.0, std::f64::consts::PI).unwrap();
        let s = sweep_two_rails([&r0, &r1], std::slice::from_ref(&arch), false).unwrap();
        let tolerance = 1e-4 * size(&[&r0, &r1, &arch]);
        assert!(distance_from(&s, &arch) < 1e-9);
        for rail in [&r0, &r1] {
            let d = crate::test_support::curve_to_surface(&s, rail, 200);
            assert!(
                d <= tolerance,
                "rail off by {d:e} (tolerance {tolerance:e})"
            );
        }
    }

    #[test]
    fn a_two_rail_sweep_keeps_the_profile_height_when_asked() {
        // Rails 2 apart at the start and 6 at the end; one arch 2 wide and 0.6 high.
        let r0 = line(DVec3::ZERO, DVec3::new(0.0, 4.0, 0.0)).unwrap();
        let r1 = line(DVec3::new(2.0, 0.0, 0.0), DVec3::new(6.0, 4.0, 0.0)).unwrap();
        let arch = interpolate(
            &[
                DVec3::ZERO,
                DVec3::new(1.0, 0.0, 0.6),
                DVec3::new(2.0, 0.0, 0.0),
            ],
            2,
        )
        .unwrap();
        let height_at_end = |keep: bool| {
            let s = sweep_two_rails([&r0, &r1], std::slice::from_ref(&arch), keep).unwrap();
            let [(u0, u1), (_, v1)] = s.domain();
            (0..=100)
                .map(|i| s.point_at(u0 + (u1 - u0) * i as f64 / 100.0, v1).unwrap().z)
                .fold(f64::NEG_INFINITY, f64::max)
        };
        let scaled = height_at_end(false);
        let kept = height_at_end(true);
        assert!((kept - 0.6).abs() < 1e-9, "kept height {kept}");
        // The chord at the end is |(6, 4) − (0, 4)| = 6, three times the start's.
        assert!((scaled - 1.8).abs() < 1e-9, "scaled height {scaled}");
    }

    #[test]
    fn a_rail_along_the_up_direction_is_refused() {
        let rail = line(DVec3::ZERO, DVec3::Z).unwrap();
        let profile = circle(DVec3::ZERO, DVec3::Z, DVec3::X, 1.0).unwrap();
        let e = sweep_one_rail(&rail, &[profile], SweepFrame::FixedUp(DVec3::Z)).unwrap_err();
        assert!(e.to_string().contains("up direction"), "{e}");
    }

    #[test]
    fn a_circle_swept_along_an_arc_lies_on_the_torus() {
        // Radius 0.5 along a quarter circle of radius 5 about y: the torus
        // (√(x² + z²) − 5)² + y² = 0.25, which a sweep of 17 lofted sections follows within
        // 2e-5 (the sections themselves exactly).
        let rail = arc(DVec3::ZERO, DVec3::X, DVec3::Z, 5.0, 0.0, FRAC_PI_2).unwrap();
        let profile = circle(DVec3::new(5.0, 0.0, 0.0), DVec3::Z, DVec3::X, 0.5).unwrap();
        let s = sweep_one_rail(&rail, &[profile], SweepFrame::default()).unwrap();
        let worst = worst_over_grid(&s, 60, 60, |p| {
            (((p.x.hypot(p.z) - 5.0).powi(2) + p.y * p.y).sqrt() - 0.5).abs()
        });
        assert!(worst < 2e-5, "{worst:e} off the torus");
    }
}
