//! Document changes become GPU work here, and only here: the editor, `knotwork bench`, the CLI
//! and the tests all keep the GPU copy of a scene through [`SceneSync`].
//!
//! It holds each object's GPU feed (its Bézier patches, [`crate::scene::Decomposition`]), the
//! [`PatchGeometry`] built from them at the current tessellation, and the evaluator. An edit
//! reaches it as a [`Touched`] (from an undo step) or as [`PointsMoved`] (a drag step or a
//! move): points-only changes re-derive just the named patches and upload just the control
//! points that changed; structural changes rebuild the buffers, lowering the tessellation until
//! the device's limits accept it.

use super::adaptive_pass::{AdaptiveStats, AdaptiveTarget};
use super::cpu_eval::CpuGeometry;
use super::curve_eval::{CurveEvaluator, CurveGeometry, MAX_CURVE_SEGMENTS, ObjectCurve};
use super::error::GpuError;
use super::patch_eval::{MAX_SEGMENTS, ObjectPatches, PatchGeometry, SurfaceBuffers, Tessellation};
use super::pipelines::PatchEvaluator;
use crate::scene::change::{PointsMoved, Touched};
use crate::scene::{Decomposition, Scene, SceneObject};

/// Segments per span edge of an object at quality `quality`, within 1..=[`MAX_SEGMENTS`].
pub fn effective_segments(segments: u32, quality: f32) -> u32 {
    ((segments as f32 * quality).round() as u32).clamp(1, MAX_SEGMENTS)
}

/// Builds with `build(quality)`; while the device's limits refuse that (a buffer too large, a
/// level beyond the dispatch limits) halves the quality and tries again, at most 16 times.
/// Returns what was built, the quality used, and the first refusal (`None` when `quality`
/// fitted). Any other error is returned at once.
pub fn fit_to_device<T>(
    quality: f32,
    mut build: impl FnMut(f32) -> Result<T, GpuError>,
) -> Result<(T, f32, Option<GpuError>), GpuError> {
    let mut q = quality;
    let mut refusal = None;
    for _ in 0..16 {
        match build(q) {
            Ok(built) => return Ok((built, q, refusal)),
            Err(e @ (GpuError::BufferTooLarge { .. } | GpuError::SegmentsOutOfRange { .. })) => {
                refusal.get_or_insert(e);
                q *= 0.5;
            }
            Err(e) => return Err(e),
        }
    }
    Err(refusal.unwrap_or(GpuError::SegmentsOutOfRange {
        segments: 0,
        max: MAX_SEGMENTS,
    }))
}

/// What a hidden object feeds the GPU: nothing.
fn nothing() -> Decomposition {
    Decomposition::default()
}

/// The GPU feed of one object, with the object's name on a failure.
fn feed(object: &SceneObject) -> Result<Decomposition, GpuError> {
    if !object.visible {
        return Ok(nothing());
    }
    object
        .decompose()
        .map_err(|e| GpuError::Geometry(format!("{}: {e}", object.name)))
}

/// Whether `device` can run the compute evaluator: it has compute shaders and storage buffers
/// (a WebGL2 device has neither, and gets the CPU evaluator).
pub fn has_compute(device: &wgpu::Device) -> bool {
    let limits = device.limits();
    limits.max_compute_workgroups_per_dimension > 0
        && limits.max_storage_buffers_per_shader_stage >= 8
}

/// The buffers of a built scene: evaluated by compute shaders, or by the CPU. (One of them is
/// held per scene, so the difference in size does not matter.)
#[allow(clippy::large_enum_variant)]
enum Built {
    Compute(PatchGeometry),
    Cpu(CpuGeometry),
}

impl Built {
    /// Either evaluator, through what both answer.
    fn evaluator(&self) -> &dyn super::VertexEvaluator {
        match self {
            Built::Compute(g) => g,
            Built::Cpu(g) => g,
        }
    }

    fn evaluator_mut(&mut self) -> &mut dyn super::VertexEvaluator {
        match self {
            Built::Compute(g) => g,
            Built::Cpu(g) => g,
        }
    }
}

/// Sizes of the built scene, for the status.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct GeometryCounts {
    pub patches: u32,
    pub control_points: u32,
    pub vertices: u32,
    pub indices: u32,
}

/// The GPU copy of one scene: feeds, buffers and the evaluator.
pub struct SceneSync {
    device: wgpu::Device,
    queue: wgpu::Queue,
    /// The compute evaluator, or `None` where the CPU evaluates ([`CpuGeometry`]).
    evaluator: Option<PatchEvaluator>,
    /// The curve pass, beside the compute evaluator.
    curve_evaluator: Option<CurveEvaluator>,
    /// Every curve object's segments and vertices.
    curves: Option<CurveGeometry>,
    feeds: Vec<Decomposition>,
    geometry: Option<Built>,
    quality_used: f32,
    points_uploaded: usize,
    /// Room for adaptive vertices, or `None` for the fixed tessellation.
    adaptive_room: Option<u32>,
    /// Whether the Bézier patches' vertices carry their curvature.
    vertex_curvature: bool,
}

/// The adaptive vertex room a scene starts with (grown when the statistics ask for more).
pub const INITIAL_ADAPTIVE_ROOM: u32 = 1 << 16;

impl SceneSync {
    /// An empty GPU scene on `device` (its pipelines are created here), evaluated by compute
    /// shaders where the device has them ([`has_compute`]), else by the CPU.
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue) -> Self {
        Self::with_evaluator(device, queue, has_compute(device))
    }

    /// An empty scene whose surfaces the CPU evaluates, on any device (what a WebGL2 device
    /// gets; tests use it on others).
    pub fn on_cpu(device: &wgpu::Device, queue: &wgpu::Queue) -> Self {
        Self::with_evaluator(device, queue, false)
    }

    fn with_evaluator(device: &wgpu::Device, queue: &wgpu::Queue, compute: bool) -> Self {
        Self {
            evaluator: compute.then(|| PatchEvaluator::new(device)),
            curve_evaluator: compute.then(|| CurveEvaluator::new(device)),
            curves: None,
            device: device.clone(),
            queue: queue.clone(),
            feeds: Vec::new(),
            geometry: None,
            quality_used: 1.0,
            points_uploaded: 0,
            adaptive_room: None,
            vertex_curvature: true,
        }
    }

    /// Whether the vertices carry their curvature (see [`PatchGeometry::set_vertex_curvature`];
    /// on by default); kept across rebuilds.
    pub fn set_vertex_curvature(&mut self, on: bool) {
        self.vertex_curvature = on;
        if let Some(g) = &mut self.geometry {
            g.evaluator_mut().set_vertex_curvature(on);
        }
    }

    /// Whether compute shaders evaluate the surfaces (else the CPU does).
    pub fn evaluates_on_gpu(&self) -> bool {
        self.evaluator.is_some()
    }

    /// The compute geometry, mutably.
    fn compute_mut(&mut self) -> Option<&mut PatchGeometry> {
        match &mut self.geometry {
            Some(Built::Compute(g)) => Some(g),
            _ => None,
        }
    }

    /// The most adaptive vertices the device's binding limit holds (half of it: the fixed
    /// patches need room too).
    fn max_adaptive_room(&self) -> u32 {
        let limits = self.device.limits();
        let bytes = limits
            .max_storage_buffer_binding_size
            .min(limits.max_buffer_size);
        let per_vertex = std::mem::size_of::<super::SurfaceVertex>() as u64;
        (bytes / per_vertex / 2).min(u64::from(u32::MAX / 8)) as u32
    }

    /// Whether the Bézier patches are tessellated for the view.
    pub fn is_adaptive(&self) -> bool {
        self.adaptive_room.is_some()
    }

    /// Switches between the view-adaptive and the fixed tessellation, rebuilding the buffers
    /// when it changes (see [`Self::rebuild`]).
    pub fn set_adaptive(
        &mut self,
        scene: &Scene,
        adaptive: bool,
        quality: f32,
    ) -> Result<Option<String>, GpuError> {
        if adaptive == self.is_adaptive() {
            return Ok(None);
        }
        if adaptive && self.evaluator.is_none() {
            return Err(GpuError::NeedsCompute(
                "the view-adaptive tessellation; the fixed tessellation stays",
            ));
        }
        let before = self.adaptive_room;
        self.adaptive_room = adaptive.then(|| INITIAL_ADAPTIVE_ROOM.min(self.max_adaptive_room()));
        let rebuilt = self.rebuild(scene, quality);
        if rebuilt.is_err() {
            self.adaptive_room = before;
        }
        rebuilt
    }

    /// The view the adaptive tessellation is measured for in the next [`Self::encode`].
    pub fn set_view(&mut self, target: AdaptiveTarget) {
        if let Some(geometry) = self.compute_mut() {
            geometry.set_view(target);
        }
    }

    /// Keeps the adaptive levels while `frozen` (see [`PatchGeometry::freeze_levels`]).
    pub fn freeze_levels(&mut self, frozen: bool) {
        if let Some(geometry) = self.compute_mut() {
            geometry.freeze_levels(frozen);
        }
    }

    /// Call after submitting the encoder given to [`Self::encode`].
    pub fn after_submit(&mut self) {
        if let Some(geometry) = self.compute_mut() {
            geometry.after_submit();
        }
    }

    /// The adaptive tessellation's latest statistics, taking any that arrived.
    pub fn adaptive_stats(&mut self) -> Option<AdaptiveStats> {
        self.compute_mut().and_then(PatchGeometry::adaptive_stats)
    }

    /// After statistics that needed more room than the buffers have (the levels were then
    /// coarsened to fit), rebuilds with room for them, up to the device's limit. Returns
    /// whether it rebuilt.
    pub fn grow_adaptive_room(&mut self, scene: &Scene, quality: f32) -> Result<bool, GpuError> {
        let (Some(room), Some(stats)) = (self.adaptive_room, self.adaptive_stats()) else {
            return Ok(false);
        };
        let most = self.max_adaptive_room();
        if stats.shift == 0 || room >= most {
            return Ok(false);
        }
        let needed = u64::from(stats.needed_vertices) * 5 / 4 + 1024;
        self.adaptive_room = Some(needed.min(u64::from(most)) as u32);
        if let Err(e) = self.rebuild(scene, quality) {
            self.adaptive_room = Some(room);
            return Err(e);
        }
        Ok(true)
    }

    /// A GPU copy of `scene` at quality `quality` (see [`Self::rebuild`]).
    pub fn with_scene(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        scene: &Scene,
        quality: f32,
    ) -> Result<Self, GpuError> {
        let mut sync = Self::new(device, queue);
        sync.rebuild(scene, quality)?;
        Ok(sync)
    }

    /// The compute evaluator's buffers, once a scene was built (`None` on the CPU path).
    pub fn geometry(&self) -> Option<&PatchGeometry> {
        match &self.geometry {
            Some(Built::Compute(g)) => Some(g),
            _ => None,
        }
    }

    /// The built evaluator, compute or CPU, through what both answer.
    pub fn evaluator(&self) -> Option<&dyn super::VertexEvaluator> {
        self.geometry.as_ref().map(Built::evaluator)
    }

    /// The CPU evaluator's buffers, once a scene was built (`None` on the compute path).
    pub fn cpu_geometry(&self) -> Option<&CpuGeometry> {
        match &self.geometry {
            Some(Built::Cpu(g)) => Some(g),
            _ => None,
        }
    }

    /// Whether a scene was built (there is something to draw).
    pub fn is_built(&self) -> bool {
        self.geometry.is_some()
    }

    /// What the renderer draws, once a scene was built: the surfaces and the curves.
    pub fn surface_buffers(&self) -> Option<SurfaceBuffers<'_>> {
        let mut buffers = self.geometry.as_ref()?.evaluator().surface_buffers();
        buffers.curves = self.curves.as_ref().and_then(CurveGeometry::buffers);
        Some(buffers)
    }

    /// The curves' GPU copy, once a scene was built.
    pub fn curves(&self) -> Option<&CurveGeometry> {
        self.curves.as_ref()
    }

    /// Every patch record, objects in order, once a scene was built.
    pub fn records(&self) -> Option<&[super::PatchRecord]> {
        Some(self.geometry.as_ref()?.evaluator().records())
    }

    /// The record index of object `object`'s first patch.
    pub fn first_patch(&self, object: usize) -> Option<usize> {
        self.geometry.as_ref()?.evaluator().first_patch(object)
    }

    /// Patches, control points, vertices and triangle indices of the built scene.
    pub fn counts(&self) -> Option<GeometryCounts> {
        let g = self.geometry.as_ref()?.evaluator();
        Some(GeometryCounts {
            patches: g.patch_count(),
            control_points: g.control_point_count(),
            vertices: g.vertex_count(),
            indices: g.index_count(),
        })
    }

    /// Each object's Bézier patches as uploaded (empty for hidden objects).
    pub fn feeds(&self) -> &[Decomposition] {
        &self.feeds
    }

    /// The quality the device's limits allowed at the last rebuild.
    pub fn quality_used(&self) -> f32 {
        self.quality_used
    }

    /// Bézier control points uploaded by the last points-only update.
    pub fn points_uploaded(&self) -> usize {
        self.points_uploaded
    }

    /// Uploads every object of `scene` at `quality`; where the device's buffer or dispatch
    /// limits refuse that, halves the quality until they accept it and returns a notice saying
    /// so. On failure the previous GPU copy stays as it was.
    pub fn rebuild(&mut self, scene: &Scene, quality: f32) -> Result<Option<String>, GpuError> {
        let feeds: Vec<Decomposition> = scene.objects.iter().map(feed).collect::<Result<_, _>>()?;
        let before = std::mem::replace(&mut self.feeds, feeds);
        let built = self.build_from_feeds(scene, quality);
        if built.is_err() {
            self.feeds = before;
        }
        built
    }

    /// [`Self::rebuild`] after object `object` alone changed in structure
    /// ([`Touched::Object`]): only its patches are derived again, every other object's are the
    /// ones already held. Where the scene holds another number of objects than were built,
    /// everything is derived again. On failure the previous GPU copy stays as it was.
    pub fn rebuild_object(
        &mut self,
        scene: &Scene,
        object: usize,
        quality: f32,
    ) -> Result<Option<String>, GpuError> {
        let Some(target) = scene.objects.get(object) else {
            return self.rebuild(scene, quality);
        };
        if self.feeds.len() != scene.objects.len() || self.geometry.is_none() {
            return self.rebuild(scene, quality);
        }
        let before = std::mem::replace(&mut self.feeds[object], feed(target)?);
        let built = self.build_from_feeds(scene, quality);
        if built.is_err() {
            self.feeds[object] = before;
        }
        built
    }

    /// [`Self::rebuild`] after one object was inserted at `index` or removed from there
    /// ([`Touched::InsertedOrRemoved`]); the scene's number of objects against the patches held
    /// says which (one more: inserted, and only its patches are derived; one fewer: removed).
    /// Every other object's patches are the ones already held; any other count rebuilds
    /// everything. On failure the previous GPU copy stays as it was.
    pub fn rebuild_inserted_or_removed(
        &mut self,
        scene: &Scene,
        index: usize,
        quality: f32,
    ) -> Result<Option<String>, GpuError> {
        let (held, count) = (self.feeds.len(), scene.objects.len());
        if self.geometry.is_none() {
            return self.rebuild(scene, quality);
        }
        if count == held + 1
            && let Some(inserted) = scene.objects.get(index)
        {
            self.feeds.insert(index, feed(inserted)?);
            let built = self.build_from_feeds(scene, quality);
            if built.is_err() {
                self.feeds.remove(index);
            }
            built
        } else if count + 1 == held && index < held {
            let removed = self.feeds.remove(index);
            let built = self.build_from_feeds(scene, quality);
            if built.is_err() {
                self.feeds.insert(index, removed);
            }
            built
        } else {
            self.rebuild(scene, quality)
        }
    }

    /// The GPU copy of `scene` at `quality` from the patches held for its objects
    /// ([`Self::feeds`], one per object, in order), as [`Self::rebuild`] says; on failure the
    /// previous buffers stay.
    fn build_from_feeds(
        &mut self,
        scene: &Scene,
        quality: f32,
    ) -> Result<Option<String>, GpuError> {
        let feeds = &self.feeds;
        let (geometry, used, refusal) = fit_to_device(quality, |q| {
            let inputs: Vec<ObjectPatches<'_>> = scene
                .objects
                .iter()
                .zip(feeds)
                .map(|(object, d)| ObjectPatches {
                    set: &d.set,
                    domains: &d.domains,
                    stencils: d.stencils.as_deref(),
                    cage_points: d.cage_points,
                    trims: d.trims.as_ref(),
                    displacement: object.displacement.as_ref().and_then(|map| {
                        Some(crate::gpu::patch_eval::ObjectDisplacement {
                            map: map.clone(),
                            domain: object.geometry.displacement_domain()?,
                        })
                    }),
                    lattice: object.lattice.as_ref(),
                    segments: d
                        .fixed_segments
                        .unwrap_or_else(|| effective_segments(object.segments, q)),
                })
                .collect();
            let tessellation = match self.adaptive_room {
                Some(vertices) => Tessellation::Adaptive { vertices },
                None => Tessellation::Fixed,
            };
            Ok(match &self.evaluator {
                Some(evaluator) => Built::Compute(PatchGeometry::with_tessellation(
                    &self.device,
                    evaluator,
                    &inputs,
                    tessellation,
                )?),
                None => Built::Cpu(CpuGeometry::new(&self.device, &inputs)?),
            })
        })?;
        let curve_inputs: Vec<ObjectCurve<'_>> = scene
            .objects
            .iter()
            .zip(feeds)
            .map(|(object, d)| ObjectCurve {
                feed: d.curve.as_ref(),
                segments: effective_segments(object.segments, used).min(MAX_CURVE_SEGMENTS),
            })
            .collect();
        let curves =
            CurveGeometry::new(&self.device, self.curve_evaluator.as_ref(), &curve_inputs)?;
        let mut geometry = geometry;
        geometry
            .evaluator_mut()
            .set_vertex_curvature(self.vertex_curvature);
        self.geometry = Some(geometry);
        self.curves = Some(curves);
        self.quality_used = used;
        Ok(refusal.map(|e| {
            format!("tessellation lowered to quality {used:.2} (asked {quality:.2}): {e}")
        }))
    }

    /// Object `object`'s control points or weights changed (same layout): re-derives the
    /// Bézier patches `patches` of its feed (`None`: the whole object, re-evaluating the patches
    /// whose points changed), uploads the changed points and marks the patches for the next
    /// [`Self::encode`]. Returns how many points were uploaded. A drag step updates the feed in
    /// place (no copy of a large object's feed per mouse move).
    pub fn refresh_object(
        &mut self,
        scene: &Scene,
        object: usize,
        patches: Option<&[usize]>,
    ) -> Result<usize, GpuError> {
        let target = scene.objects.get(object).ok_or(GpuError::NoSuchObject {
            object,
            count: scene.objects.len(),
        })?;
        let slot = self.feeds.get_mut(object).ok_or(GpuError::NoSuchObject {
            object,
            count: scene.objects.len(),
        })?;
        if !target.visible {
            return Ok(0);
        }
        match patches {
            Some(patches) => target
                .update_decomposition(slot, patches)
                .map_err(|e| GpuError::Geometry(format!("{}: {e}", target.name)))?,
            None => *slot = feed(target)?,
        }
        let lattice = target.lattice.as_ref();
        // A curve's segments are not patches: its patch set is empty.
        let curve_segments = patches;
        let patches = if slot.curve.is_some() {
            Some(&[][..])
        } else {
            patches
        };
        let uploaded = match &mut self.geometry {
            Some(Built::Compute(g)) => {
                let points = g.update_object(&self.queue, object, &slot.set, patches)?;
                g.update_lattice(&self.queue, object, lattice)?;
                points
            }
            // The CPU path uploads vertices, not points.
            Some(Built::Cpu(g)) => {
                g.update_lattice(object, lattice)?;
                g.update_object(object, patches).map(|()| 0)?
            }
            None => 0,
        };
        let curve_points = match (&mut self.curves, &slot.curve) {
            (Some(curves), Some(feed)) => {
                curves.update_object(&self.queue, object, feed, curve_segments)?
            }
            _ => 0,
        };
        let uploaded = uploaded + curve_points;
        self.points_uploaded = uploaded;
        Ok(uploaded)
    }

    /// A drag step or a move ([`crate::doc::Document::drag_by`], `move_points`): only the
    /// moved points' support is re-derived and re-evaluated.
    /// Objects sharing a moved lattice upload their lattice again; objects built from a moved
    /// curve are re-derived whole.
    pub fn points_moved(&mut self, scene: &Scene, moved: &PointsMoved) -> Result<usize, GpuError> {
        let uploaded = self.refresh_object(scene, moved.object, Some(&moved.patches))?;
        for &other in &moved.linked {
            self.refresh_object(scene, other, Some(&[]))?;
        }
        // Objects built from the moved curve: re-derived whole, or (another layout) every
        // buffer built again.
        if moved.relaid && !moved.rebuilt.is_empty() {
            self.rebuild(scene, self.quality_used)?;
        } else {
            for &other in &moved.rebuilt {
                self.refresh_object(scene, other, None)?;
            }
        }
        self.points_uploaded = uploaded;
        Ok(uploaded)
    }

    /// Brings the GPU copy up to date after an edit of the document (a command, undo, redo);
    /// returns a notice when the tessellation had to be lowered.
    pub fn apply(
        &mut self,
        scene: &Scene,
        touched: Touched,
        quality: f32,
    ) -> Result<Option<String>, GpuError> {
        match touched {
            Touched::Nothing => Ok(None),
            Touched::Points(object) => self.refresh_object(scene, object, None).map(|_| None),
            Touched::Structure => self.rebuild(scene, quality),
            Touched::Object(object) => self.rebuild_object(scene, object, quality),
            Touched::InsertedOrRemoved(index) => {
                self.rebuild_inserted_or_removed(scene, index, quality)
            }
        }
    }

    /// Whether [`Self::encode`] has work to do.
    pub fn needs_evaluation(&self) -> bool {
        self.curves
            .as_ref()
            .is_some_and(CurveGeometry::needs_evaluation)
            || self
                .geometry
                .as_ref()
                .is_some_and(|g| g.evaluator().needs_evaluation())
    }

    /// Marks every patch and curve segment for re-evaluation (benchmarks).
    pub fn invalidate(&mut self) {
        if let Some(curves) = &mut self.curves {
            curves.invalidate();
        }
        if let Some(g) = &mut self.geometry {
            g.evaluator_mut().invalidate();
        }
    }

    /// Records the compute pass of the pending work into `encoder` (see
    /// [`PatchGeometry::encode`]); on the CPU path evaluates the pending patches here and
    /// queues their upload ([`CpuGeometry::evaluate`]); then the same for the pending curve
    /// segments. Returns the number of patches and curve segments evaluated.
    pub fn encode(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        timestamps: Option<wgpu::ComputePassTimestampWrites<'_>>,
    ) -> u32 {
        let curves = match (&mut self.curves, &self.curve_evaluator) {
            (Some(curves), Some(evaluator)) => curves.encode(&self.queue, encoder, evaluator),
            (Some(curves), None) => {
                let feeds: Vec<_> = self.feeds.iter().map(|f| f.curve.as_ref()).collect();
                curves.evaluate_on_cpu(&self.queue, &feeds)
            }
            (None, _) => 0,
        };
        curves
            + match (&mut self.geometry, &self.evaluator) {
                (Some(Built::Compute(g)), Some(evaluator)) => {
                    g.encode(&self.queue, encoder, evaluator, timestamps)
                }
                (Some(Built::Cpu(g)), _) => match g.evaluate(&self.queue, &self.feeds) {
                    Ok(evaluated) => evaluated,
                    Err(e) => {
                        // The feeds and the layout come from one rebuild: this is a bug, not input.
                        log::error!("CPU evaluation failed: {e}");
                        0
                    }
                },
                _ => 0,
            }
    }

    /// Submits the pending work and waits for the GPU (tests, benchmarks, the CLI); returns the
    /// number of patches evaluated.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn evaluate_blocking(&mut self) -> Result<u32, GpuError> {
        let mut encoder = self.device.create_command_encoder(&Default::default());
        let evaluated = self.encode(&mut encoder, None);
        self.queue.submit([encoder.finish()]);
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| GpuError::Readback(e.to_string()))?;
        Ok(evaluated)
    }

    /// The adaptive tessellation's statistics as the GPU last wrote them (blocking; tests,
    /// benchmarks); `None` for a fixed tessellation.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn read_adaptive_stats(&mut self) -> Result<Option<AdaptiveStats>, GpuError> {
        let Some(Built::Compute(geometry)) = &mut self.geometry else {
            return Ok(None);
        };
        match geometry.adaptive_pass() {
            Some(pass) => pass.read_stats(&self.device, &self.queue).map(Some),
            None => Ok(None),
        }
    }

    /// The evaluated curve vertices (blocking).
    #[cfg(not(target_arch = "wasm32"))]
    pub fn read_curve_vertices(&self) -> Result<Vec<super::records::CurveVertex>, GpuError> {
        match &self.curves {
            Some(curves) => curves.read_vertices(&self.device, &self.queue),
            None => Ok(Vec::new()),
        }
    }

    /// The evaluated vertices (blocking).
    #[cfg(not(target_arch = "wasm32"))]
    pub fn read_vertices(&self) -> Result<Vec<super::SurfaceVertex>, GpuError> {
        match &self.geometry {
            Some(g) => g.evaluator().read_vertices(&self.device, &self.queue),
            None => Ok(Vec::new()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_quality_is_lowered_until_the_device_accepts_it() {
        // A device that holds at most 1000 vertices per object of 10 patches at 16 segments.
        let build = |q: f32| {
            let segments = effective_segments(16, q);
            let bytes = 10 * u64::from(segments + 1).pow(2) * 64;
            if bytes > 64_000 {
                Err(GpuError::BufferTooLarge {
                    what: "vertex",
                    bytes,
                    limit: 64_000,
                })
            } else {
                Ok(segments)
            }
        };
        let (segments, used, refusal) = fit_to_device(2.0, build).unwrap();
        assert_eq!((segments, used), (8, 0.5));
        assert!(matches!(refusal, Some(GpuError::BufferTooLarge { .. })));
        let (_, used, refusal) = fit_to_device(0.25, build).unwrap();
        assert_eq!((used, refusal), (0.25, None));
        // Other errors are not retried.
        let mut calls = 0;
        let other = fit_to_device(1.0, |_| -> Result<(), GpuError> {
            calls += 1;
            Err(GpuError::NoSuchObject {
                object: 1,
                count: 0,
            })
        });
        assert!(matches!(other, Err(GpuError::NoSuchObject { .. })) && calls == 1);
        // A device that never fits gives up with the first refusal.
        let never = fit_to_device(1.0, |_| -> Result<(), GpuError> {
            Err(GpuError::BufferTooLarge {
                what: "index",
                bytes: 1,
                limit: 0,
            })
        });
        assert!(matches!(
            never,
            Err(GpuError::BufferTooLarge { what: "index", .. })
        ));
    }
}
