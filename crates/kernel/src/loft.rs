//! Lofts through section curves a person drew: sections in any direction and, for closed
//! sections, with the seam anywhere, lofted open or closed across, in three styles (The NURBS
//! Book §10.3 for the skinning itself).
//!
//! Before lofting, each section is aligned with the one before it ([`align_sections`]): an open
//! section is reversed when its ends are nearer the previous section's opposite ends; a closed
//! section gets its seam moved to the point nearest the previous seam and is reversed when that
//! brings it closer to the previous section (compared at evenly spaced parameters). Then the
//! sections are made compatible (one degree, one knot vector).

use glam::{DVec3, DVec4};

use super::basis::uniform_clamped_knots;
use super::curve::{SpaceCurve, control_box_size};
use super::error::GeometryError;
use super::error::construction;
use super::interpolation::{averaged_knots, interpolate_points, make_compatible};
use super::ops::Polygon;
use super::splines::{
    Parametrization, parameters, periodic_control, periodic_knots, polynomial_approximation,
};
use super::surface::NurbsSurface;
use super::vector::CurvePoint;

/// How a loft runs across its sections (Rhino's loft styles).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LoftStyle {
    /// Through every section, C^{q−1} across (interpolation with averaged chord lengths).
    #[default]
    Normal,
    /// Straight (ruled) between consecutive sections: degree 1 across.
    Straight,
    /// The sections' control points are the surface's control points across: smoother, and
    /// only the first and last sections (of an open loft) lie on it.
    Loose,
}

/// The options of [`loft_sections`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoftOptions {
    /// The degree across the sections, 1 to 3 (lowered where there are too few sections).
    pub degree: usize,
    /// Back from the last section to the first (at least 3 sections).
    pub closed: bool,
    pub style: LoftStyle,
    /// Reverse sections and move closed sections' seams to line them up.
    pub align: bool,
}

impl Default for LoftOptions {
    fn default() -> Self {
        Self {
            degree: 3,
            closed: false,
            style: LoftStyle::Normal,
            align: true,
        }
    }
}

/// The largest degree across a loft's sections.
pub const MAX_LOFT_DEGREE: usize = 3;

/// The size of the box around the curves' control points (at least 1e-300).
fn size_of(curves: &[SpaceCurve]) -> f64 {
    control_box_size(curves).max(1e-300)
}

/// Whether a curve ends where it starts, within `tolerance`.
pub fn is_closed(curve: &SpaceCurve, tolerance: f64) -> Result<bool, GeometryError> {
    let (a, b) = curve.ends()?;
    Ok(a.distance(b) <= tolerance)
}

/// `count` + 1 points at evenly spaced parameters of the curve.
fn sample(curve: &SpaceCurve, count: usize) -> Result<Vec<DVec3>, GeometryError> {
    (0..=count)
        .map(|i| curve.point_at(curve.parameter_at(i as f64 / count as f64)))
        .collect()
}

/// The closed curve with its start moved to parameter `t` (the piece after `t`, then the piece
/// before it).
pub fn with_seam_at(curve: &SpaceCurve, t: f64) -> Result<SpaceCurve, GeometryError> {
    let (a, b) = curve.domain();
    if t - a <= 1e-12 * (b - a) || b - t <= 1e-12 * (b - a) {
        return Ok(curve.clone());
    }
    let (before, after) = curve.split(t)?;
    after.join(&before)
}

/// The sum of distances between two curves at evenly spaced parameters.
fn spacing(a: &[DVec3], b: &[DVec3]) -> f64 {
    a.iter().zip(b).map(|(p, q)| p.distance(*q)).sum()
}

/// The sections reversed and (closed ones) re-seamed to line up with the section before each
/// (see the module documentation); the first keeps its direction and seam.
pub fn align_sections(sections: &[SpaceCurve]) -> Result<Vec<SpaceCurve>, GeometryError> {
    const SAMPLES: usize = 32;
    let tolerance = 1e-9 * size_of(sections);
    let mut aligned: Vec<SpaceCurve> = Vec::with_capacity(sections.len());
    for section in sections {
        let Some(previous) = aligned.last() else {
            aligned.push(section.clone());
            continue;
        };
        let (p0, p1) = previous.ends()?;
        let next = if is_closed(section, tolerance)? {
            let t = section.closest_parameter(p0)?;
            let forward = with_seam_at(section, t)?;
            let backward = forward.reverse();
            let reference = sample(previous, SAMPLES)?;
            if spacing(&sample(&backward, SAMPLES)?, &reference)
                < spacing(&sample(&forward, SAMPLES)?, &reference)
            {
                backward
            } else {
                forward
            }
        } else {
            let (q0, q1) = section.ends()?;
            if q0.distance(p1) + q1.distance(p0) < q0.distance(p0) + q1.distance(p1) {
                section.reverse()
            } else {
                section.clone()
            }
        };
        aligned.push(next);
    }
    Ok(aligned)
}

/// The parameters of the sections across the loft: the chord-length parameters of each column
/// of control points (back to the first for a closed loft), averaged over the columns (The
/// NURBS Book eq. 10.8).
fn averaged_parameters(polys: &[Polygon<DVec4>], closed: bool) -> Result<Vec<f64>, GeometryError> {
    let n = polys[0].points.len();
    let count = polys.len() + usize::from(closed);
    let mut params = vec![0.0; count];
    let mut columns = 0;
    for i in 0..n {
        let mut column: Vec<DVec3> = polys.iter().map(|p| DVec3::project(p.points[i])).collect();
        if closed {
            column.push(column[0]);
        }
        // A column whose points coincide (an apex shared by all sections) says nothing.
        if let Ok(t) = parameters(&column, Parametrization::ChordLength, "loft") {
            params.iter_mut().zip(t).for_each(|(a, b)| *a += b);
            columns += 1;
        }
    }
    if columns == 0 {
        return Err(construction(
            "loft",
            "two consecutive sections coincide at every control point",
        ));
    }
    params.iter_mut().for_each(|a| *a /= columns as f64);
    for w in params.windows(2) {
        if !(w[1] > w[0]) {
            return Err(construction("loft", "two consecutive sections coincide"));
        }
    }
    Ok(params)
}

/// A loft through `sections` (see the module documentation and [`LoftOptions`]): u runs along
/// the sections, v across them. Every section lies on a normal or straight loft exactly (at
/// v = the section's parameter); rational sections give a rational surface, except where
/// their weights differ so much that blending them gives a weight ≤ 0: then non-rational
/// cubics within [`APPROXIMATION_TOLERANCE`] of the sections' size stand in for them.
pub fn loft_sections(
    sections: &[SpaceCurve],
    options: &LoftOptions,
) -> Result<NurbsSurface, GeometryError> {
    const WHAT: &str = "loft";
    let least = if options.closed { 3 } else { 2 };
    if sections.len() < least {
        return Err(construction(
            WHAT,
            format!(
                "needs at least {least} sections{}, found {}",
                if options.closed { " to close" } else { "" },
                sections.len()
            ),
        ));
    }
    if !(1..=MAX_LOFT_DEGREE).contains(&options.degree) {
        return Err(construction(
            WHAT,
            format!(
                "the degree across the sections is {}; it must be 1 to {MAX_LOFT_DEGREE}",
                options.degree
            ),
        ));
    }
    let aligned = if options.align {
        align_sections(sections)?
    } else {
        sections.to_vec()
    };
    if let Some(surface) = skinned(&aligned, options)? {
        return Ok(surface);
    }
    // Rational sections whose weights differ too much for their homogeneous points to be
    // blended: follow them with non-rational cubics instead.
    let tolerance = APPROXIMATION_TOLERANCE * size_of(&aligned);
    let polynomial = aligned
        .iter()
        .map(|c| polynomial_approximation(c, tolerance))
        .collect::<Result<Vec<_>, _>>()?;
    skinned(&polynomial, options)?
        .ok_or_else(|| construction(WHAT, "the interpolated weights are not all positive"))
}

/// How far the non-rational stand-ins of rational sections may be from them, as a fraction of
/// the sections' size (used only where the rational loft has non-positive weights).
pub const APPROXIMATION_TOLERANCE: f64 = 1e-8;

/// The loft of aligned sections, or `None` where the blended homogeneous points get a weight
/// that is not positive.
fn skinned(
    aligned: &[SpaceCurve],
    options: &LoftOptions,
) -> Result<Option<NurbsSurface>, GeometryError> {
    const WHAT: &str = "loft";
    let polys = make_compatible(aligned)?;
    let k = polys.len();
    let degree = match options.style {
        LoftStyle::Straight => 1,
        _ => options.degree,
    };
    let n = polys[0].points.len();
    let (knots_v, columns): (Vec<f64>, Vec<Vec<DVec4>>) = match (options.style, options.closed) {
        (LoftStyle::Loose, false) => {
            let q = degree.min(k - 1);
            let knots = uniform_clamped_knots(q, k);
            let columns = (0..n)
                .map(|i| polys.iter().map(|p| p.points[i]).collect())
                .collect();
            (knots, columns)
        }
        (LoftStyle::Loose, true) => {
            let q = degree.min(k - 1);
            // Uniform periodic knots: the control polygon closed by repeating q points.
            let knots: Vec<f64> = (0..=k + 2 * q).map(|i| i as f64 / k as f64).collect();
            let columns = (0..n)
                .map(|i| (0..k + q).map(|j| polys[j % k].points[i]).collect())
                .collect();
            (knots, columns)
        }
        (_, closed) => {
            // Through every section: interpolation across, periodic when closed.
            let q = degree.min(k - 1);
            let params = averaged_parameters(&polys, closed)?;
            let knots = if closed {
                periodic_knots(&params, q)
            } else {
                averaged_knots(&params, q)
            };
            let columns = (0..n)
                .map(|i| {
                    let column: Vec<DVec4> = polys.iter().map(|p| p.points[i]).collect();
                    if closed {
                        periodic_control(&column, &params, q, &knots, WHAT)
                    } else {
                        interpolate_points(&column, &params, q, &knots, WHAT)
                    }
                })
                .collect::<Result<_, _>>()?;
            (knots, columns)
        }
    };
    let m = columns[0].len();
    let q = knots_v.len() - m - 1;
    let mut points = vec![DVec4::ZERO; n * m];
    for (i, column) in columns.into_iter().enumerate() {
        for (j, h) in column.into_iter().enumerate() {
            if !(h.w > 0.0) {
                return Ok(None);
            }
            points[i * m + j] = h;
        }
    }
    NurbsSurface::from_homogeneous(
        [polys[0].degree, q],
        [polys[0].knots.clone(), knots_v],
        [n, m],
        points,
    )
    .map(Some)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::construct::{circle, line};

    fn circle_at(z: f64, r: f64) -> SpaceCurve {
        circle(DVec3::new(0.0, 0.0, z), DVec3::Z, DVec3::X, r).unwrap()
    }

    /// The largest distance from the curve's points to the surface.
    fn distance_from(surface: &NurbsSurface, curve: &SpaceCurve) -> f64 {
        crate::test_support::curve_to_surface(surface, curve, 40)
    }

    #[test]
    fn a_closed_loft_of_circles_with_turned_seams_is_a_smooth_ring_through_each() {
        // Three circles on the sides of a triangle would make a torus-like ring; here circles
        // about z at heights 0, 1, 2, 1.5 (closed back to the first), the third reversed and the
        // second with its seam turned by 100°.
        let second = circle_at(1.0, 1.5);
        let (a, b) = second.domain();
        let turned = with_seam_at(&second, a + (b - a) * 100.0 / 360.0).unwrap();
        assert!(turned.point_at(turned.domain().0).unwrap().y > 1.0);
        let sections = vec![
            circle_at(0.0, 1.0),
            turned,
            circle_at(2.0, 1.2).reverse(),
            circle_at(1.5, 0.5),
        ];
        let options = LoftOptions {
            closed: true,
            ..LoftOptions::default()
        };
        let s = loft_sections(&sections, &options).unwrap();
        for c in &sections {
            let d = distance_from(&s, c);
            assert!(d < 1e-9, "a section is {d} from the loft");
        }
        // Closed across: v's two ends are the same curve, with the same tangent.
        let [(u0, u1), (v0, v1)] = s.domain();
        for i in 0..=8 {
            let u = u0 + (u1 - u0) * i as f64 / 8.0;
            let a = s.evaluate(u, v0).unwrap();
            let b = s.evaluate(u, v1).unwrap();
            assert!(a.point.distance(b.point) < 1e-9);
            assert!((a.sv - b.sv).length() < 1e-6 * a.sv.length());
        }
        // Aligned: every seam was moved to the xz-plane, so the u = u0 line stays in it.
        for j in 0..=16 {
            let p = s.point_at(u0, v0 + (v1 - v0) * j as f64 / 16.0).unwrap();
            assert!(p.y.abs() < 1e-9 && p.x > 0.0, "{p}");
        }
    }

    #[test]
    fn reversed_open_sections_are_turned_round() {
        let a = line(DVec3::ZERO, DVec3::X).unwrap();
        let b = line(DVec3::new(1.0, 1.0, 0.0), DVec3::new(0.0, 1.0, 0.0)).unwrap();
        let s = loft_sections(&[a, b], &LoftOptions::default()).unwrap();
        // Not twisted: the middle of the surface is the middle of the square.
        let p = s.point_at(0.5, 0.5).unwrap();
        assert!(p.distance(DVec3::new(0.5, 0.5, 0.0)) < 1e-12, "{p}");
    }

    #[test]
    fn loose_lofts_keep_the_end_sections_and_straight_ones_every_section() {
        let sections: Vec<SpaceCurve> = [(0.0, 1.0), (1.0, 2.0), (2.0, 0.7), (3.0, 1.3)]
            .iter()
            .map(|&(z, r)| circle_at(z, r))
            .collect();
        for style in [LoftStyle::Loose, LoftStyle::Straight] {
            let s = loft_sections(
                &sections,
                &LoftOptions {
                    style,
                    ..LoftOptions::default()
                },
            )
            .unwrap();
            assert!(distance_from(&s, &sections[0]) < 1e-9);
            assert!(distance_from(&s, &sections[3]) < 1e-9);
            let inner = distance_from(&s, &sections[1]);
            match style {
                LoftStyle::Straight => assert!(inner < 1e-9),
                _ => assert!(inner > 1e-3, "a loose loft does not pass through {inner}"),
            }
        }
    }

    #[test]
    fn too_few_sections_and_bad_degrees_are_refused() {
        let c = circle_at(0.0, 1.0);
        let closed = LoftOptions {
            closed: true,
            ..LoftOptions::default()
        };
        let e = loft_sections(&[c.clone(), circle_at(1.0, 1.0)], &closed).unwrap_err();
        assert!(e.to_string().contains("at least 3 sections"), "{e}");
        let e = loft_sections(std::slice::from_ref(&c), &LoftOptions::default()).unwrap_err();
        assert!(e.to_string().contains("at least 2 sections"), "{e}");
        let degree = LoftOptions {
            degree: 4,
            ..LoftOptions::default()
        };
        assert!(loft_sections(&[c.clone(), circle_at(1.0, 1.0)], &degree).is_err());
        assert!(loft_sections(&[c.clone(), c], &LoftOptions::default()).is_err());
    }

    #[test]
    fn a_closed_loft_of_three_lines_folds_tightly_and_still_contains_them() {
        // Degree 2 across three sections, closed: the surface turns sharply at each section,
        // where point inversion's Newton step alone stalls (the gradient step takes over).
        let a = line(DVec3::ZERO, DVec3::new(4.0, 0.0, 0.0)).unwrap();
        let b = line(DVec3::new(0.0, 0.3, 2.0), DVec3::new(4.0, 0.0, 2.0)).unwrap();
        let c = line(DVec3::new(0.0, 0.0, 4.0), DVec3::new(4.0, 0.2, 4.0)).unwrap();
        let options = LoftOptions {
            closed: true,
            ..LoftOptions::default()
        };
        let s = loft_sections(&[a.clone(), b.clone(), c.clone()], &options).unwrap();
        assert_eq!(s.degree()[1], 2);
        for section in [&a, &b, &c] {
            let d = distance_from(&s, section);
            assert!(d < 1e-9, "a section is {d:e} from the loft");
        }
    }
}
