//! The line overlays, built on the CPU from the f64 kernel and drawn by the viewport's line
//! pipelines: the ground grid, curvature combs, the principal directions' line field and the
//! continuity hair.

use glam::DVec3;

use super::viewport::GuideLines;
use crate::kernel::Curvature;
use crate::kernel::ParametricSurface;
use crate::kernel::continuity::{Continuity, SharedEdge, Tolerances};
use crate::scene::SceneObject;
use crate::view::{AnalysisSettings, CombCurves, ContinuityTarget, OrbitCamera};

/// Linear RGBA of the grid's minor and major lines and the X and Y axes.
const GRID_MINOR: [f32; 4] = [0.30, 0.31, 0.34, 0.35];
const GRID_MAJOR: [f32; 4] = [0.40, 0.41, 0.45, 0.7];
const AXIS_X: [f32; 4] = [0.75, 0.12, 0.10, 0.9];
const AXIS_Y: [f32; 4] = [0.20, 0.62, 0.12, 0.9];
/// The most grid lines per direction.
const GRID_LINES: i64 = 200;

/// The grid's spacing for a view `height` model units tall at the target: the minor step is
/// the power of ten nearest below a tenth of the height, the major step ten of them.
pub fn grid_steps(height: f64) -> (f64, f64) {
    let minor = 10f64.powf((height.max(1e-300) / 10.0).log10().floor());
    (minor, 10.0 * minor)
}

/// The ground grid in the XY plane (model units) around the camera's target, with minor and
/// major lines that adapt to the zoom and the X and Y axes in red and green. Returns the lines
/// and the minor step.
pub fn ground_grid(camera: &OrbitCamera) -> (GuideLines, f64) {
    let height = 2.0 * f64::from(camera.distance) * (f64::from(camera.fov_y) * 0.5).tan();
    let (minor, major) = grid_steps(height);
    // Fade the minor lines as they get dense (the fraction of the decade the zoom is in).
    let fraction = (height / 10.0).log10() - (height / 10.0).log10().floor();
    let mut minor_color = GRID_MINOR;
    minor_color[3] *= (1.0 - fraction as f32).max(0.15);
    let centre = camera.target.as_dvec3();
    let extent = (4.0 * height).min(GRID_LINES as f64 * minor);
    let (cx, cy) = (
        (centre.x / major).round() * major,
        (centre.y / major).round() * major,
    );
    let n = (extent / minor).ceil() as i64;
    let mut lines = GuideLines::default();
    // Segments are cut to the part in front of the eye: some rasterizers (SwiftShader) drop
    // lines that cross the near plane instead of clipping them.
    let eye = camera.eye().as_dvec3();
    let forward = -camera.axes().2.as_dvec3();
    let near = if camera.orthographic {
        f64::NEG_INFINITY
    } else {
        0.02 * f64::from(camera.distance)
    };
    let mut add = |a: DVec3, b: DVec3, color: [f32; 4]| {
        let (da, db) = ((a - eye).dot(forward) - near, (b - eye).dot(forward) - near);
        if da < 0.0 && db < 0.0 {
            return;
        }
        let cut = |p: DVec3, q: DVec3, dp: f64, dq: f64| p + (q - p) * (dp / (dp - dq));
        let a2 = if da < 0.0 { cut(a, b, da, db) } else { a };
        let b2 = if db < 0.0 { cut(b, a, db, da) } else { b };
        lines.depth_tested(a2, b2, color);
    };
    let (x0, x1, y0, y1) = (cx - extent, cx + extent, cy - extent, cy + extent);
    let on_axis = |v: f64| v.abs() < 0.5 * minor;
    for k in -n..=n {
        // The centre lies on a major line, so every tenth line from it is one.
        let color = if k.rem_euclid(10) == 0 {
            GRID_MAJOR
        } else {
            minor_color
        };
        let (x, y) = (cx + k as f64 * minor, cy + k as f64 * minor);
        if !on_axis(x) {
            add(DVec3::new(x, y0, 0.0), DVec3::new(x, y1, 0.0), color);
        }
        if !on_axis(y) {
            add(DVec3::new(x0, y, 0.0), DVec3::new(x1, y, 0.0), color);
        }
    }
    if (y0..=y1).contains(&0.0) {
        add(DVec3::new(x0, 0.0, 0.0), DVec3::new(x1, 0.0, 0.0), AXIS_X);
    }
    if (x0..=x1).contains(&0.0) {
        add(DVec3::new(0.0, y0, 0.0), DVec3::new(0.0, y1, 0.0), AXIS_Y);
    }
    (lines, minor)
}

/// Linear RGBA of the comb's hair and envelope.
const COMB_HAIR: [f32; 4] = [0.55, 0.60, 0.85, 0.8];
const COMB_ENVELOPE: [f32; 4] = [0.95, 0.30, 0.25, 1.0];
/// Samples per comb curve.
const COMB_SAMPLES: usize = 64;

/// One sample of a curve on a surface: the point and its curvature vector κN (toward the
/// centre of curvature), or `None` where the curve leaves the kept region.
type CombSample = Option<(DVec3, DVec3)>;

/// The curvature vector of the space curve C at a point from C′ and C″:
/// κN = (C′ × C″) × C′ / |C′|⁴ (Farin, Curves and Surfaces for CAGD, §10.2).
pub fn curvature_vector(c1: DVec3, c2: DVec3) -> Option<DVec3> {
    let speed2 = c1.length_squared();
    let k = c1.cross(c2).cross(c1) / (speed2 * speed2);
    (speed2 > 0.0 && k.is_finite()).then_some(k)
}

/// The samples of the iso-curve of `face` at the fixed parameter `fixed` of the other direction
/// (`along_u`: v fixed, u runs).
fn iso_curve(face: &dyn ParametricSurface, along_u: bool, fixed: f64) -> Vec<CombSample> {
    let [(u0, u1), (v0, v1)] = face.domain();
    (0..COMB_SAMPLES)
        .map(|k| {
            let t = k as f64 / (COMB_SAMPLES - 1) as f64;
            let (u, v) = if along_u {
                (u0 + t * (u1 - u0), fixed)
            } else {
                (fixed, v0 + t * (v1 - v0))
            };
            if !face.keeps(u, v) {
                return None;
            }
            let d = face.derivatives(u, v)?;
            let (c1, c2) = if along_u {
                (d.su * (u1 - u0), d.suu * (u1 - u0) * (u1 - u0))
            } else {
                (d.sv * (v1 - v0), d.svv * (v1 - v0) * (v1 - v0))
            };
            Some((d.point, curvature_vector(c1, c2)?))
        })
        .collect()
}

/// The parameters of `count` iso-curves across [a, b] (at the ends too when `ends`).
fn iso_parameters(a: f64, b: f64, count: u32, ends: bool) -> Vec<f64> {
    let mut out: Vec<f64> = (0..count)
        .map(|k| a + (f64::from(k) + 0.5) / f64::from(count) * (b - a))
        .collect();
    if ends {
        out.push(a);
        out.push(b);
    }
    out
}

/// Curvature combs on the object's iso-curves (and boundary edges), or along a curve object:
/// hair from each sample
/// against its curvature vector, length proportional to the curvature (the longest a tenth of
/// `size` times the scale), and the envelope joining the hair tips.
pub fn curvature_combs(object: &SceneObject, settings: &AnalysisSettings, size: f64) -> GuideLines {
    let mut curves: Vec<Vec<CombSample>> = Vec::new();
    // A curve object's comb is its own: 8 samples per Bézier segment times the density.
    if let Some(curve) = object.kind().space_curve() {
        let breaks = curve.span_breaks();
        let per_span = (8 * settings.comb_density.max(1)) as usize;
        let mut samples = Vec::new();
        for span in breaks.windows(2) {
            for k in 0..per_span {
                let t = span[0] + (span[1] - span[0]) * k as f64 / per_span as f64;
                samples.push(
                    curve
                        .derivatives(t, 2)
                        .ok()
                        .and_then(|d| curvature_vector(d[1], d[2]).map(|kappa| (d[0], kappa))),
                );
            }
        }
        let end = breaks[breaks.len() - 1];
        samples.push(
            curve
                .derivatives(end, 2)
                .ok()
                .and_then(|d| curvature_vector(d[1], d[2]).map(|kappa| (d[0], kappa))),
        );
        curves.push(samples);
    }
    for (_, face) in object.faces() {
        let [(u0, u1), (v0, v1)] = face.domain();
        let density = settings.comb_density;
        let ends = settings.comb_boundary;
        if matches!(settings.combs, CombCurves::U | CombCurves::Both) {
            for v in iso_parameters(v0, v1, density, ends) {
                curves.push(iso_curve(face.as_ref(), true, v));
            }
        }
        if matches!(settings.combs, CombCurves::V | CombCurves::Both) {
            for u in iso_parameters(u0, u1, density, ends) {
                curves.push(iso_curve(face.as_ref(), false, u));
            }
        }
    }
    let largest = curves
        .iter()
        .flatten()
        .flatten()
        .map(|(_, k)| k.length())
        .fold(0.0, f64::max);
    let mut lines = GuideLines::default();
    if !(largest > 0.0) {
        return lines;
    }
    let factor = settings.comb_scale * 0.1 * size / largest;
    for curve in &curves {
        let tips: Vec<Option<DVec3>> = curve
            .iter()
            .map(|s| s.map(|(p, k)| p - factor * k))
            .collect();
        for (sample, tip) in curve.iter().zip(&tips) {
            if let (Some((p, _)), Some(tip)) = (sample, tip) {
                lines.on_top(*p, *tip, COMB_HAIR);
            }
        }
        for pair in tips.windows(2) {
            if let [Some(a), Some(b)] = pair {
                lines.on_top(*a, *b, COMB_ENVELOPE);
            }
        }
    }
    lines
}

/// Linear RGBA of the k1 and k2 directions.
const DIRECTION_K1: [f32; 4] = [0.95, 0.35, 0.20, 1.0];
const DIRECTION_K2: [f32; 4] = [0.25, 0.55, 1.0, 1.0];

/// The principal directions at `density` × `density` points of every face: a short segment
/// along the k1 direction (warm) and one along k2 (cool), each about a third of the sample
/// spacing; none at umbilics, where every direction is principal.
pub fn principal_directions(object: &SceneObject, density: u32) -> GuideLines {
    let mut lines = GuideLines::default();
    let n = f64::from(density.max(1));
    for (_, face) in object.faces() {
        let [(u0, u1), (v0, v1)] = face.domain();
        for i in 0..density {
            for j in 0..density {
                let u = u0 + (f64::from(i) + 0.5) / n * (u1 - u0);
                let v = v0 + (f64::from(j) + 0.5) / n * (v1 - v0);
                if !face.keeps(u, v) {
                    continue;
                }
                let Some(d) = face.derivatives(u, v) else {
                    continue;
                };
                let Some(normal) = d.regular_normal() else {
                    continue;
                };
                let forms = crate::kernel::FundamentalForms::new(&d, normal);
                let Some(Curvature {
                    directions: Some([d1, d2]),
                    ..
                }) = Curvature::from_forms(&d, &forms)
                else {
                    continue;
                };
                let spacing = (d.su.length() * (u1 - u0)).min(d.sv.length() * (v1 - v0)) / n;
                let half = 0.35 * spacing;
                let lift = d.point + 0.02 * spacing * normal;
                lines.on_top(lift - half * d1, lift + half * d1, DIRECTION_K1);
                lines.on_top(lift - half * d2, lift + half * d2, DIRECTION_K2);
            }
        }
    }
    lines
}

/// Linear RGBA of continuity hair that meets the target and that does not.
pub const HAIR_PASS: [f32; 4] = [0.15, 0.85, 0.25, 1.0];
pub const HAIR_FAIL: [f32; 4] = [0.95, 0.15, 0.12, 1.0];

/// Whether one sample meets `target` under `tolerances`.
pub fn sample_meets(
    sample: &crate::kernel::continuity::EdgeSample,
    tolerances: &Tolerances,
    target: ContinuityTarget,
) -> bool {
    let g0 = sample.gap <= tolerances.distance;
    let g1 = g0 && sample.angle_degrees <= tolerances.angle_degrees;
    match target {
        ContinuityTarget::G0 => g0,
        ContinuityTarget::G1 => g1,
        ContinuityTarget::G2 => {
            g1 && sample
                .relative_curvature_difference
                .is_none_or(|r| r <= tolerances.curvature)
        }
    }
}

/// Whether a verdict meets the target.
pub fn verdict_meets(verdict: Continuity, target: ContinuityTarget) -> bool {
    let needed = match target {
        ContinuityTarget::G0 => Continuity::G0,
        ContinuityTarget::G1 => Continuity::G1,
        ContinuityTarget::G2 => Continuity::G2,
    };
    verdict >= needed
}

/// Hair along the normal at every sample of every shared edge (a twenty-fifth of `size`),
/// green where the sample meets the target, red where it does not, and the edge itself.
pub fn continuity_hair(
    edges: &[SharedEdge],
    tolerances: &Tolerances,
    target: ContinuityTarget,
    size: f64,
) -> GuideLines {
    let mut lines = GuideLines::default();
    let length = 0.04 * size;
    for edge in edges {
        for sample in &edge.samples {
            let color = if sample_meets(sample, tolerances, target) {
                HAIR_PASS
            } else {
                HAIR_FAIL
            };
            lines.on_top(sample.point, sample.point + length * sample.normal, color);
        }
        let color = if verdict_meets(edge.verdict, target) {
            HAIR_PASS
        } else {
            HAIR_FAIL
        };
        for pair in edge.samples.windows(2) {
            lines.on_top(pair[0].point, pair[1].point, color);
        }
    }
    lines
}
