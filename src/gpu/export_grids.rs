//! Export grids evaluated on the GPU: a [`GridSampler`] whose points, normals and curvatures
//! come from the compute shaders (`evaluate_samples` in `shaders/eval_grid.wgsl`, the same
//! patch evaluation that draws the viewport) instead of the f64 kernel.
//!
//! The CPU still chooses everything else: each grid is sized by the kernel's tolerance
//! estimate and check, its cells are triangulated by the kernel, trimmed cells are clipped on
//! the CPU. So a file exported this way has the CPU's topology exactly, and its positions,
//! normals and curvatures agree with the f64 reference within f32 precision. To keep that
//! precision relative to the object and not to its distance from the origin, each surface is
//! moved to its bounding box's centre before its points become f32, and the centre is added
//! back in f64.
//!
//! Grids are evaluated in batches: as many surfaces as one dispatch takes patches, and as many
//! samples per dispatch as one storage binding holds results.

use std::sync::atomic::{AtomicUsize, Ordering};

use glam::{DAffine3, DVec3, Vec3};

use super::error::GpuError;
use super::patch_eval::{ObjectPatches, PatchGeometry};
use super::pipelines::PatchEvaluator;
use super::records::{PointResult, PointSample, VERTEX_NO_CURVATURE};
use crate::kernel::diffgeo::CurvatureValues;
use crate::kernel::surface::GridSample;
use crate::kernel::tess::{GridSampler, GridValues, KernelGrids, ParameterGrid, rounding_slack};
use crate::kernel::{BezierPatchSet, Direction, GeometryError, NurbsSurface};

/// The most samples one dispatch evaluates, whatever the device allows: 64 Mi of results.
const MAX_SAMPLES_PER_DISPATCH: usize = (64 << 20) / std::mem::size_of::<PointResult>();

/// Export grids on the GPU ([`GridSampler`]).
pub struct GpuGrids {
    device: wgpu::Device,
    queue: wgpu::Queue,
    evaluator: PatchEvaluator,
    /// How many calls fell back to the kernel.
    fallbacks: AtomicUsize,
}

/// One surface prepared for the GPU: its Bézier patches around its centre, where each grid
/// line falls among them, and the centre.
struct Prepared {
    set: BezierPatchSet,
    centre: DVec3,
    /// Per grid u: (span, local s); per grid v: (span, local t).
    us: Vec<(u32, f32)>,
    vs: Vec<(u32, f32)>,
    /// Spans along v (the patch index is span_u × this + span_v).
    spans_v: u32,
}

impl Prepared {
    fn new(surface: &NurbsSurface, grid: &ParameterGrid) -> Result<Self, GeometryError> {
        let (lo, hi) = surface.bounds();
        let centre = 0.5 * (lo + hi);
        let centre = if centre.is_finite() {
            centre
        } else {
            DVec3::ZERO
        };
        let moved = surface.transformed(&DAffine3::from_translation(-centre))?;
        let set = moved.to_bezier_patch_set()?;
        let bu = surface.span_breaks(Direction::U);
        let bv = surface.span_breaks(Direction::V);
        Ok(Self {
            set,
            centre,
            us: locate_all(&bu, &grid.us)?,
            vs: locate_all(&bv, &grid.vs)?,
            spans_v: (bv.len() - 1) as u32,
        })
    }

    fn sample_count(&self) -> usize {
        self.us.len() * self.vs.len()
    }
}

/// For each of `values`, the span of `breaks` it falls in and its local parameter there
/// ([`super::point_eval::locate`]); an error for a value outside the breaks.
fn locate_all(breaks: &[f64], values: &[f64]) -> Result<Vec<(u32, f32)>, GeometryError> {
    values
        .iter()
        .map(|&x| {
            super::point_eval::locate(breaks, x)
                .map(|(span, t)| (span as u32, t as f32))
                .ok_or_else(|| GeometryError::OutsideDomain {
                    parameter: "grid",
                    value: x,
                    start: breaks.first().copied().unwrap_or(f64::NAN),
                    end: breaks.last().copied().unwrap_or(f64::NAN),
                })
        })
        .collect()
}

fn to_dvec3(v: [f32; 4]) -> DVec3 {
    Vec3::new(v[0], v[1], v[2]).as_dvec3()
}

impl GpuGrids {
    /// Export grids on `device` (its compute pipelines are built here, once).
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue) -> Self {
        Self {
            device: device.clone(),
            queue: queue.clone(),
            evaluator: PatchEvaluator::new(device),
            fallbacks: AtomicUsize::new(0),
        }
    }

    /// How many grid requests the GPU refused and the kernel answered instead.
    pub fn fallbacks(&self) -> usize {
        self.fallbacks.load(Ordering::Relaxed)
    }

    /// Every `(surface, grid)` of `jobs` evaluated on the GPU, in order.
    pub fn evaluate(
        &self,
        jobs: &[(&NurbsSurface, &ParameterGrid)],
        curvature: bool,
    ) -> Result<Vec<GridValues>, GpuError> {
        let prepared = jobs
            .iter()
            .map(|&(surface, grid)| Prepared::new(surface, grid))
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| GpuError::Geometry(e.to_string()))?;
        let max_patches = self.device.limits().max_compute_workgroups_per_dimension as usize;
        let mut out = Vec::with_capacity(jobs.len());
        let mut start = 0;
        while start < prepared.len() {
            // As many surfaces as one geometry takes patches (at least one).
            let mut end = start + 1;
            let mut patches = prepared[start].set.patches().len();
            while end < prepared.len() && patches + prepared[end].set.patches().len() <= max_patches
            {
                patches += prepared[end].set.patches().len();
                end += 1;
            }
            out.extend(self.evaluate_batch(&prepared[start..end], curvature)?);
            start = end;
        }
        Ok(out)
    }

    /// The surfaces of `batch` in one patch geometry, their samples in dispatches of at most
    /// one binding of results.
    fn evaluate_batch(
        &self,
        batch: &[Prepared],
        curvature: bool,
    ) -> Result<Vec<GridValues>, GpuError> {
        let objects: Vec<ObjectPatches<'_>> = batch
            .iter()
            .map(|p| ObjectPatches {
                set: &p.set,
                domains: &[],
                segments: 1,
                stencils: None,
                cage_points: 0,
                trims: None,
                displacement: None,
                lattice: None,
            })
            .collect();
        let geometry = PatchGeometry::new(&self.device, &self.evaluator, &objects)?;
        let limits = self.device.limits();
        let per_dispatch = (limits
            .max_storage_buffer_binding_size
            .min(limits.max_buffer_size)
            / std::mem::size_of::<PointResult>() as u64)
            .min(u64::from(limits.max_compute_workgroups_per_dimension) * 64)
            .min(MAX_SAMPLES_PER_DISPATCH as u64)
            .max(1) as usize;
        let mut first_patch = 0u32;
        let mut samples = Vec::with_capacity(batch.iter().map(Prepared::sample_count).sum());
        for p in batch {
            for &(a, s) in &p.us {
                for &(b, t) in &p.vs {
                    samples.push(PointSample {
                        patch_index: first_patch + a * p.spans_v + b,
                        s,
                        t,
                        reserved: 0,
                    });
                }
            }
            first_patch += p.set.patches().len() as u32;
        }
        let mut results: Vec<PointResult> = Vec::with_capacity(samples.len());
        for chunk in samples.chunks(per_dispatch) {
            results.extend(geometry.evaluate_points(
                &self.device,
                &self.queue,
                &self.evaluator,
                chunk,
            )?);
        }
        if results.len() != samples.len() {
            return Err(GpuError::Readback(format!(
                "{} results for {} samples",
                results.len(),
                samples.len()
            )));
        }
        let mut results = results.into_iter();
        Ok(batch
            .iter()
            .map(|p| {
                let mut values = GridValues {
                    samples: Vec::with_capacity(p.sample_count()),
                    curvatures: Vec::new(),
                };
                if curvature {
                    values.curvatures.reserve(p.sample_count());
                }
                for r in results.by_ref().take(p.sample_count()) {
                    values.samples.push(GridSample {
                        point: to_dvec3(r.point) + p.centre,
                        normal: to_dvec3(r.normal).normalize_or_zero(),
                    });
                    if curvature {
                        let [gaussian, mean, k1, k2] = if r.flags[0] & VERTEX_NO_CURVATURE != 0 {
                            [0.0; 4]
                        } else {
                            r.curvature.map(f64::from)
                        };
                        values.curvatures.push(CurvatureValues {
                            gaussian,
                            mean,
                            k1,
                            k2,
                        });
                    }
                }
                values
            })
            .collect())
    }
}

impl GridSampler for GpuGrids {
    /// The GPU's grids; where the GPU refuses a batch (a buffer over the device's limits, a
    /// lost device), the f64 kernel's, with a warning, counted in [`Self::fallbacks`].
    fn sample_grids(
        &self,
        jobs: &[(&NurbsSurface, &ParameterGrid)],
        curvature: bool,
    ) -> Result<Vec<GridValues>, GeometryError> {
        match self.evaluate(jobs, curvature) {
            Ok(values) => Ok(values),
            Err(e) => {
                log::warn!("the GPU could not evaluate export grids ({e}); the CPU does");
                self.fallbacks.fetch_add(1, Ordering::Relaxed);
                KernelGrids.sample_grids(jobs, curvature)
            }
        }
    }

    /// f32 rounding around the surface's centre (16 units in the last place of half its
    /// size; the tests measure about 1e-7 of the size), and f64's in adding the centre back.
    fn position_slack(&self, surface: &NurbsSurface) -> f64 {
        16.0 * f64::from(f32::EPSILON) * 0.5 * surface.size() + rounding_slack(surface)
    }
}
