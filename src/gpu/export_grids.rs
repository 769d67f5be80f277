//! Export grids evaluated on the GPU: a [`crate::kernel::tess::GridSampler`] whose points, normals and curvatures
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
//!
//! Natively the export waits for them ([`crate::kernel::tess::GridSampler`]). The web page cannot wait for a
//! readback inside a frame, so there the export asks for an object's grids
//! ([`GpuGrids::request`]), draws frames while they come back, and collects them when their
//! copies are mapped ([`PendingGrids::poll`]); both ways dispatch the same work and get the
//! same values.

use std::sync::atomic::{AtomicUsize, Ordering};

use super::async_readback::AsyncReadback;

use glam::{DAffine3, DVec3, Vec3};

use super::error::GpuError;
use super::patch_eval::{ObjectPatches, PatchGeometry};
use super::pipelines::PatchEvaluator;
use super::records::{PointResult, PointSample, VERTEX_NO_CURVATURE};
use crate::kernel::diffgeo::CurvatureValues;
use crate::kernel::surface::GridSample;
use crate::kernel::tess::{
    DeferredGridSampler, GridValues, ParameterGrid, PendingGridValues, rounding_slack,
};
#[cfg(not(target_arch = "wasm32"))]
use crate::kernel::tess::{GridSampler, KernelGrids};
use crate::kernel::{BezierPatchSet, Direction, GeometryError, NurbsSurface};

/// The most samples one dispatch evaluates, whatever the device allows: 64 Mi of results.
const MAX_SAMPLES_PER_DISPATCH: usize = (64 << 20) / std::mem::size_of::<PointResult>();

/// Export grids on the GPU ([`crate::kernel::tess::GridSampler`]).
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

    /// Its patches as the evaluator takes them.
    fn patches(&self) -> ObjectPatches<'_> {
        ObjectPatches {
            set: &self.set,
            domains: &[],
            segments: 1,
            stencils: None,
            cage_points: 0,
            trims: None,
            displacement: None,
            lattice: None,
        }
    }
}

/// The Bézier span of `breaks` containing `x` (the last span at the domain's end) and the local
/// parameter in it; `None` outside [breaks[0], breaks[last]].
pub(super) fn locate(breaks: &[f64], x: f64) -> Option<(usize, f64)> {
    let (first, last) = (*breaks.first()?, *breaks.last()?);
    if !(x >= first && x <= last) || breaks.len() < 2 {
        return None;
    }
    let span = breaks[1..breaks.len() - 1]
        .iter()
        .take_while(|&&b| b <= x)
        .count();
    let (a, b) = (breaks[span], breaks[span + 1]);
    Some((span, ((x - a) / (b - a)).clamp(0.0, 1.0)))
}

/// For each of `values`, the span of `breaks` it falls in and its local parameter there
/// ([`locate`]); an error for a value outside the breaks.
fn locate_all(breaks: &[f64], values: &[f64]) -> Result<Vec<(u32, f32)>, GeometryError> {
    values
        .iter()
        .map(|&x| {
            locate(breaks, x)
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

    /// Every `(surface, grid)` of `jobs` evaluated on the GPU, in order (blocking: each
    /// dispatch is waited for before the next, so at most one dispatch's results are held).
    #[cfg(not(target_arch = "wasm32"))]
    pub fn evaluate(
        &self,
        jobs: &[(&NurbsSurface, &ParameterGrid)],
        curvature: bool,
    ) -> Result<Vec<GridValues>, GpuError> {
        let mut out = Vec::with_capacity(jobs.len());
        let mut results: Vec<PointResult> = Vec::new();
        self.dispatch(jobs, |batch, readback| {
            let mut readback = readback?;
            self.device
                .poll(wgpu::PollType::wait_indefinitely())
                .map_err(|e| GpuError::Readback(e.to_string()))?;
            let bytes = readback
                .take()
                .ok_or_else(|| GpuError::Readback("a grid's copy was not mapped".into()))?;
            results.extend(bytemuck::pod_collect_to_vec::<u8, PointResult>(&bytes));
            if let Some(batch) = batch {
                out.extend(grid_values(
                    std::mem::take(&mut results),
                    &batch,
                    curvature,
                )?);
            }
            Ok(())
        })?;
        Ok(out)
    }

    /// Starts evaluating every `(surface, grid)` of `jobs` without waiting: the values arrive
    /// through [`PendingGrids::poll`] once the GPU is done and the copies are mapped (a frame
    /// or more later in the page).
    pub fn request(
        &self,
        jobs: &[(&NurbsSurface, &ParameterGrid)],
        curvature: bool,
    ) -> Result<PendingGrids, GpuError> {
        let mut pending = PendingGrids {
            device: self.device.clone(),
            readbacks: Vec::new(),
            batches: Vec::new(),
            curvature,
        };
        self.dispatch(jobs, |batch, readback| {
            pending.readbacks.push((readback?, None));
            if let Some(batch) = batch {
                pending.batches.push((pending.readbacks.len(), batch));
            }
            Ok(())
        })?;
        Ok(pending)
    }

    /// Dispatches the evaluation of `jobs` in batches (as many surfaces as one geometry takes
    /// patches) and dispatches (as many samples as one binding holds results), handing each
    /// dispatch's copy on its way back to `each`, in order, with the batch's grids (sample
    /// count and centre) after its last dispatch.
    fn dispatch(
        &self,
        jobs: &[(&NurbsSurface, &ParameterGrid)],
        mut each: impl FnMut(
            Option<Vec<(usize, DVec3)>>,
            Result<AsyncReadback, GpuError>,
        ) -> Result<(), GpuError>,
    ) -> Result<(), GpuError> {
        let prepared = jobs
            .iter()
            .map(|&(surface, grid)| Prepared::new(surface, grid))
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| GpuError::Geometry(e.to_string()))?;
        let limits = self.device.limits();
        let max_patches = limits.max_compute_workgroups_per_dimension as usize;
        let per_dispatch = (limits
            .max_storage_buffer_binding_size
            .min(limits.max_buffer_size)
            / std::mem::size_of::<PointResult>() as u64)
            .min(u64::from(limits.max_compute_workgroups_per_dimension) * 64)
            .min(MAX_SAMPLES_PER_DISPATCH as u64)
            .max(1) as usize;
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
            let batch = &prepared[start..end];
            let grids: Vec<(usize, DVec3)> =
                batch.iter().map(|p| (p.sample_count(), p.centre)).collect();
            let samples = batch_samples(batch);
            if samples.is_empty() {
                // A kernel grid has two lines each way at least.
                return Err(GpuError::Readback("a grid without samples".into()));
            }
            let objects: Vec<ObjectPatches<'_>> = batch.iter().map(Prepared::patches).collect();
            let geometry = PatchGeometry::new(&self.device, &self.evaluator, &objects)?;
            let chunks = samples.len().div_ceil(per_dispatch);
            for (k, chunk) in samples.chunks(per_dispatch).enumerate() {
                let readback = self.submit_chunk(&geometry, chunk);
                let last = k + 1 == chunks;
                each(last.then(|| grids.clone()), readback)?;
            }
            start = end;
        }
        Ok(())
    }

    /// Submits one dispatch of `chunk` on `geometry` and the copy of its results.
    fn submit_chunk(
        &self,
        geometry: &PatchGeometry,
        chunk: &[PointSample],
    ) -> Result<AsyncReadback, GpuError> {
        let (results, size) =
            geometry.dispatch_points(&self.device, &self.queue, &self.evaluator, chunk)?;
        let mut readback = AsyncReadback::new(&self.device, "export grid results", size);
        let mut encoder = self.device.create_command_encoder(&Default::default());
        readback.record(&mut encoder, &results, 0, size);
        self.queue.submit([encoder.finish()]);
        readback.after_submit();
        Ok(readback)
    }
}

/// The samples of `batch`'s grids, in order: each grid's crossings row by row, with the index
/// of the patch holding it among the batch's patches.
fn batch_samples(batch: &[Prepared]) -> Vec<PointSample> {
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
    samples
}

/// The values of grids (`grids`: each one's sample count and centre) from their `results`, in
/// order; an error where the counts disagree.
fn grid_values(
    results: Vec<PointResult>,
    grids: &[(usize, DVec3)],
    curvature: bool,
) -> Result<Vec<GridValues>, GpuError> {
    let expected: usize = grids.iter().map(|&(count, _)| count).sum();
    if results.len() != expected {
        return Err(GpuError::Readback(format!(
            "{} results for {expected} samples",
            results.len()
        )));
    }
    let mut results = results.into_iter();
    Ok(grids
        .iter()
        .map(|&(count, centre)| {
            let mut values = GridValues {
                samples: Vec::with_capacity(count),
                curvatures: Vec::new(),
            };
            if curvature {
                values.curvatures.reserve(count);
            }
            for r in results.by_ref().take(count) {
                values.samples.push(GridSample {
                    point: to_dvec3(r.point) + centre,
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

/// Grids asked of the GPU ([`GpuGrids::request`]) on their way back: each dispatch's copy (and
/// its bytes once taken), and after which dispatch each batch of grids is complete.
pub struct PendingGrids {
    device: wgpu::Device,
    readbacks: Vec<(AsyncReadback, Option<Vec<u8>>)>,
    /// (dispatches up to and including the batch's last, the batch's grids).
    batches: Vec<(usize, Vec<(usize, DVec3)>)>,
    curvature: bool,
}

impl PendingGrids {
    /// The grids' values once every copy is mapped, `None` while some are still on their way,
    /// an error where a copy failed. Natively this also lets wgpu run the map callbacks; in
    /// the page the browser runs them between frames.
    pub fn poll(&mut self) -> Option<Result<Vec<GridValues>, GpuError>> {
        let _ = self.device.poll(wgpu::PollType::Poll);
        for (readback, bytes) in &mut self.readbacks {
            if bytes.is_none() {
                *bytes = readback.take();
                if bytes.is_none() {
                    if readback.pending() {
                        return None;
                    }
                    return Some(Err(GpuError::Readback(
                        "a grid's copy could not be mapped".into(),
                    )));
                }
            }
        }
        let mut out = Vec::new();
        let mut first = 0;
        for (end, grids) in &self.batches {
            let results: Vec<PointResult> = self.readbacks[first..*end]
                .iter_mut()
                .flat_map(|(_, bytes)| {
                    bytemuck::pod_collect_to_vec::<u8, PointResult>(
                        &bytes.take().unwrap_or_default(),
                    )
                })
                .collect();
            match grid_values(results, grids, self.curvature) {
                Ok(values) => out.extend(values),
                Err(e) => return Some(Err(e)),
            }
            first = *end;
        }
        Some(Ok(out))
    }
}

#[cfg(not(target_arch = "wasm32"))]
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

    fn position_slack(&self, surface: &NurbsSurface) -> f64 {
        gpu_position_slack(surface)
    }
}

/// How far the GPU's rounding may move a position on `surface`: f32 rounding around the
/// surface's centre (16 units in the last place of half its size; the tests measure about
/// 1e-7 of the size), and f64's in adding the centre back.
fn gpu_position_slack(surface: &NurbsSurface) -> f64 {
    16.0 * f64::from(f32::EPSILON) * 0.5 * surface.size() + rounding_slack(surface)
}

impl DeferredGridSampler for GpuGrids {
    /// [`GpuGrids::request`]; a refusal (a buffer over the device's limits) is counted in
    /// [`Self::fallbacks`], and the caller evaluates those grids on the CPU.
    fn request(
        &self,
        jobs: &[(&NurbsSurface, &ParameterGrid)],
        curvature: bool,
    ) -> Result<Box<dyn PendingGridValues>, GeometryError> {
        GpuGrids::request(self, jobs, curvature)
            .map(|pending| Box::new(pending) as Box<dyn PendingGridValues>)
            .map_err(|e| {
                self.fallbacks.fetch_add(1, Ordering::Relaxed);
                gpu_failure(e)
            })
    }

    fn position_slack(&self, surface: &NurbsSurface) -> f64 {
        gpu_position_slack(surface)
    }
}

impl PendingGridValues for PendingGrids {
    fn poll(&mut self) -> Option<Result<Vec<GridValues>, GeometryError>> {
        PendingGrids::poll(self).map(|values| values.map_err(gpu_failure))
    }
}

/// A GPU error as the kernel's error for a failed grid evaluation.
fn gpu_failure(e: GpuError) -> GeometryError {
    GeometryError::Construction {
        what: "grid evaluation on the GPU",
        message: e.to_string(),
    }
}
