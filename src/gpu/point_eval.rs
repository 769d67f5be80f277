//! Point evaluation on the GPU (`knotwork eval --backend gpu`): the surface is decomposed into
//! its Bézier patches as for drawing, each (u, v) is mapped to a patch and its local (s, t), and
//! the `evaluate_samples` entry of `shaders/eval_grid.wgsl` computes point, derivatives,
//! normal and curvature in f32. The derivatives are rescaled from (s, t) to the surface's own
//! (u, v); the principal directions (a direction field, not a value the shaders store) are
//! derived on the CPU from the GPU's derivatives and normal.

use glam::{DVec3, Vec3};

use super::error::GpuError;
use super::patch_eval::{ObjectPatches, PatchGeometry};
use super::pipelines::PatchEvaluator;
use super::records::{PointSample, VERTEX_IRREGULAR};
use crate::kernel::diffgeo::{Curvature, FundamentalForms, SurfaceDerivatives};
use crate::kernel::surface::LocalGeometry;
use crate::kernel::{Direction, GeometryError, NurbsSurface};

use super::export_grids::locate;

fn vector(v: [f32; 4]) -> DVec3 {
    Vec3::new(v[0], v[1], v[2]).as_dvec3()
}

/// Evaluates `surface` at every (u, v) of `params` on the GPU of `device`: one result per
/// parameter, an error for one outside the domain.
pub fn evaluate_points(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    surface: &NurbsSurface,
    params: &[(f64, f64)],
) -> Result<Vec<Result<LocalGeometry, GeometryError>>, GpuError> {
    let set = surface
        .to_bezier_patch_set()
        .map_err(|e| GpuError::Geometry(e.to_string()))?;
    let bu = surface.span_breaks(Direction::U);
    let bv = surface.span_breaks(Direction::V);
    let evaluator = PatchEvaluator::new(device);
    let geometry = PatchGeometry::new(
        device,
        &evaluator,
        &[ObjectPatches {
            stencils: None,
            cage_points: 0,
            trims: None,
            displacement: None,
            lattice: None,
            set: &set,
            domains: &[],
            segments: 1,
        }],
    )?;
    let [(u0, u1), (v0, v1)] = surface.domain();
    let mut located = Vec::with_capacity(params.len());
    let mut samples = Vec::new();
    for &(u, v) in params {
        let spot = match (locate(&bu, u), locate(&bv, v)) {
            (Some(a), Some(b)) => Ok((a, b)),
            (None, _) => Err(GeometryError::OutsideDomain {
                parameter: "u",
                value: u,
                start: u0,
                end: u1,
            }),
            (_, None) => Err(GeometryError::OutsideDomain {
                parameter: "v",
                value: v,
                start: v0,
                end: v1,
            }),
        };
        if let Ok(((a, s), (b, t))) = spot {
            samples.push(PointSample {
                patch_index: (a * (bv.len() - 1) + b) as u32,
                s: s as f32,
                t: t as f32,
                reserved: 0,
            });
        }
        located.push(spot);
    }
    let mut results = geometry
        .evaluate_points(device, queue, &evaluator, &samples)?
        .into_iter();
    Ok(located
        .into_iter()
        .map(|spot| {
            let ((a, _), (b, _)) = spot?;
            let r = results.next().ok_or(GeometryError::Construction {
                what: "evaluate_points",
                message: "the GPU returned too few results".into(),
            })?;
            let (du, dv) = (bu[a + 1] - bu[a], bv[b + 1] - bv[b]);
            let derivatives = SurfaceDerivatives {
                point: vector(r.point),
                su: vector(r.su) / du,
                sv: vector(r.sv) / dv,
                suu: vector(r.suu) / (du * du),
                suv: vector(r.suv) / (du * dv),
                svv: vector(r.svv) / (dv * dv),
            };
            let normal = vector(r.normal).normalize_or_zero();
            let [gaussian, mean, k1, k2] = r.curvature.map(f64::from);
            let directions =
                Curvature::from_forms(&derivatives, &FundamentalForms::new(&derivatives, normal))
                    .and_then(|c| c.directions);
            Ok(LocalGeometry {
                derivatives,
                normal,
                curvature: Curvature {
                    gaussian,
                    mean,
                    k1,
                    k2,
                    directions,
                },
                regular: r.flags[0] & VERTEX_IRREGULAR == 0,
            })
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::locate;

    #[test]
    fn parameters_find_their_span() {
        let breaks = [0.0, 0.25, 0.5, 1.0];
        assert_eq!(locate(&breaks, 0.0), Some((0, 0.0)));
        assert_eq!(locate(&breaks, 0.25), Some((1, 0.0)));
        assert_eq!(locate(&breaks, 0.75), Some((2, 0.5)));
        assert_eq!(locate(&breaks, 1.0), Some((2, 1.0)));
        assert_eq!(locate(&breaks, 1.5), None);
        assert_eq!(locate(&breaks, f64::NAN), None);
    }
}
