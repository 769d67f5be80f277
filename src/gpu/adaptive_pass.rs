//! The view-adaptive tessellation on the GPU: the passes of `shaders/eval_adaptive.wgsl` that
//! measure every Bézier patch's levels for the current view ([`super::adaptive::ScreenError`]'s
//! rule), place the patches in the vertex and index buffers by a prefix sum, and evaluate and
//! triangulate them by indirect dispatches, with one indirect draw for the renderer. Nothing
//! comes back to the CPU on the way; a small statistics block is read asynchronously for the
//! status line and to grow the buffers after an overflow.
//!
//! Each patch gets the [`super::adaptive::PatchLevels`] layout: shared edges take one count on
//! both sides, computed from the edge's control points in their canonical order, and their
//! vertices are evaluated on the boundary curve from its canonical end, so there are no cracks
//! and no T-junctions whatever the two interiors are. Patches whose control hull lies outside
//! the view frustum are neither evaluated nor drawn. Should the levels need more room than the
//! buffers have, every level is halved alike (shared edges still agree) until they fit, and
//! the statistics ask for bigger buffers.

use bytemuck::Zeroable;
use glam::Mat4;
use wgpu::util::DeviceExt;

use super::adaptive::ScreenError;
use super::async_readback::AsyncReadback;
use super::pipelines::{PatchEvaluator, PipelineKey};
use super::records::{AdaptiveSlot, AdaptiveView, EVAL_WORKGROUP_SIZE};

/// Words of the arguments buffer (WGSL: `ARGS_*` in `shaders/eval_adaptive.wgsl`).
pub const ADAPTIVE_ARGS_DRAW: u32 = 0;
pub const ADAPTIVE_ARGS_TRIANGLES: u32 = 5;
pub const ADAPTIVE_ARGS_STATS: u32 = 8;
pub const ADAPTIVE_ARGS_GROUPS: u32 = 16;
pub const ADAPTIVE_ARGS_GROUP_WORDS: u32 = 8;
/// Most segments per patch edge in the adaptive mode.
pub const ADAPTIVE_MAX_SEGMENTS: u32 = 128;
/// The longest triangle edge, in pixels, that the adaptive levels allow (smooth shading on
/// large flat patches).
pub const ADAPTIVE_MAX_EDGE_PX: f64 = 24.0;

/// What the scan reports about the last adaptive tessellation.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct AdaptiveStats {
    /// How many times every level was halved to fit the buffers (0: as measured).
    pub shift: u32,
    /// Vertices and triangle indices the measured levels need (fixed patches included).
    pub needed_vertices: u32,
    pub needed_indices: u32,
    /// Patches inside the view.
    pub visible_patches: u32,
    /// Vertices and indices written (fixed patches included).
    pub vertices: u32,
    pub indices: u32,
    /// Patches left out for want of room even at the coarsest levels.
    pub dropped: u32,
}

impl AdaptiveStats {
    fn from_words(w: &[u32]) -> Self {
        Self {
            shift: w[0],
            needed_vertices: w[1],
            needed_indices: w[2],
            visible_patches: w[3],
            vertices: w[4],
            indices: w[5],
            dropped: w[6],
        }
    }
}

/// The camera and error a view-adaptive tessellation is measured against.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AdaptiveTarget {
    pub error: ScreenError,
    /// Clip from world, for culling the patches outside the view.
    pub view_proj: Mat4,
}

const STATS_BYTES: u64 = 32;

/// One pipeline group's evaluation: the key of its specialized pipelines and where its
/// dispatch lives.
pub(super) struct AdaptiveGroup {
    pub key: PipelineKey,
    pub bind_group: wgpu::BindGroup,
    /// (first slot, slot count) of the group, bound as the pipeline's patch list.
    pub range: wgpu::Buffer,
    /// Byte offset of the group's dispatch arguments.
    pub args_offset: u64,
    /// Re-evaluation of listed slots at their measured levels (drag steps).
    pub slots_bind_group: wgpu::BindGroup,
    /// The slots the next partial dispatch evaluates.
    pub dirty_list: wgpu::Buffer,
    /// The group's records (global indices), slot `first_slot + k` holding `records[k]`.
    pub records: Vec<u32>,
    pub first_slot: u32,
}

/// The buffers the adaptive passes share with the rest of a [`super::PatchGeometry`].
pub(super) struct SharedBuffers<'a> {
    pub control_points: &'a wgpu::Buffer,
    pub control_indices: &'a wgpu::Buffer,
    pub records: &'a wgpu::Buffer,
    pub vertices: &'a wgpu::Buffer,
    pub triangle_indices: &'a wgpu::Buffer,
}

/// A geometry's adaptive state: the slots, the view, the arguments and the bind groups.
pub struct AdaptivePass {
    slots: wgpu::Buffer,
    view: wgpu::Buffer,
    args: wgpu::Buffer,
    slot_count: u32,
    /// (vertex room, index room, first adaptive vertex, first adaptive index).
    room: [u32; 4],
    groups: Vec<AdaptiveGroup>,
    levels_bind_group: wgpu::BindGroup,
    scan_bind_group: wgpu::BindGroup,
    triangles_bind_group: wgpu::BindGroup,
    /// The view the buffers hold and the one asked for next.
    evaluated: Option<AdaptiveTarget>,
    pub(super) wanted: Option<AdaptiveTarget>,
    /// The statistics block, read back without waiting.
    readback: AsyncReadback,
    latest: Option<AdaptiveStats>,
    /// While set (a drag), edits re-evaluate their patches at the measured levels.
    frozen: bool,
    /// Patches were re-evaluated at frozen levels: measure again once unfrozen.
    remeasure: bool,
}

fn entire(binding: u32, buffer: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
    wgpu::BindGroupEntry {
        binding,
        resource: buffer.as_entire_binding(),
    }
}

impl AdaptivePass {
    /// `groups`: per pipeline key (patch kind and degrees), the records it evaluates (global
    /// indices; the slots follow this order). `room`: (vertex room, index room, first adaptive
    /// vertex, first adaptive index), where the rooms count the fixed part too.
    pub(super) fn new(
        device: &wgpu::Device,
        evaluator: &PatchEvaluator,
        buffers: SharedBuffers<'_>,
        groups: Vec<(PipelineKey, Vec<u32>)>,
        room: [u32; 4],
    ) -> Self {
        let mut slots = Vec::new();
        let mut args = vec![
            0u32;
            (ADAPTIVE_ARGS_GROUPS + ADAPTIVE_ARGS_GROUP_WORDS * groups.len() as u32)
                as usize
        ];
        // Until the first view, the draw covers the fixed patches only, and so do the
        // statistics (a scene of subdivision surfaces alone never runs the scan).
        args[ADAPTIVE_ARGS_DRAW as usize] = room[3];
        args[ADAPTIVE_ARGS_DRAW as usize + 1] = 1;
        let stats = ADAPTIVE_ARGS_STATS as usize;
        args[stats + 1] = room[2];
        args[stats + 2] = room[3];
        args[stats + 4] = room[2];
        args[stats + 5] = room[3];
        let mut ranges = Vec::new();
        let pipelines = &evaluator.adaptive;
        for (g, (_, records)) in groups.iter().enumerate() {
            let word = (ADAPTIVE_ARGS_GROUPS + ADAPTIVE_ARGS_GROUP_WORDS * g as u32) as usize;
            let range = [slots.len() as u32, records.len() as u32];
            args[word] = range[0];
            args[word + 1] = range[1];
            ranges.push(range);
            slots.extend(records.iter().map(|&record| AdaptiveSlot {
                record,
                ..Zeroable::zeroed()
            }));
        }
        let slot_count = slots.len() as u32;
        if slots.is_empty() {
            // wgpu refuses empty bindings.
            slots.push(Zeroable::zeroed());
        }
        let storage = wgpu::BufferUsages::STORAGE;
        let slots_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("adaptive slots"),
            contents: bytemuck::cast_slice(&slots),
            usage: storage | wgpu::BufferUsages::COPY_SRC,
        });
        let view = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("adaptive view"),
            size: std::mem::size_of::<AdaptiveView>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let args_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("adaptive arguments"),
            contents: bytemuck::cast_slice(&args),
            usage: storage
                | wgpu::BufferUsages::INDIRECT
                | wgpu::BufferUsages::COPY_SRC
                | wgpu::BufferUsages::COPY_DST,
        });
        let bind_layout = |layout: &wgpu::BindGroupLayout, entries: &[wgpu::BindGroupEntry<'_>]| {
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: None,
                layout,
                entries,
            })
        };
        let bind = |pipeline: &wgpu::ComputePipeline, entries: &[wgpu::BindGroupEntry<'_>]| {
            bind_layout(&pipeline.get_bind_group_layout(0), entries)
        };
        let groups = groups
            .into_iter()
            .zip(ranges)
            .enumerate()
            .map(|(g, ((key, records), range))| {
                let first_slot = range[0];
                let range = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("adaptive group range"),
                    contents: bytemuck::cast_slice(&range),
                    usage: storage,
                });
                let dirty_list = device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("adaptive dirty slots"),
                    size: records.len().max(1) as u64 * 4,
                    usage: storage | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                });
                // Both evaluation entry points read the patches and write the vertices; their
                // patch list is the group's range or the slots a drag step changed.
                let evaluation = |list: &wgpu::Buffer| {
                    bind_layout(
                        &evaluator.adaptive_eval_layout,
                        &[
                            entire(0, buffers.control_points),
                            entire(1, buffers.control_indices),
                            entire(2, buffers.records),
                            entire(3, buffers.vertices),
                            entire(5, list),
                            entire(8, &slots_buffer),
                        ],
                    )
                };
                let slots_bind_group = evaluation(&dirty_list);
                let bind_group = evaluation(&range);
                let word = ADAPTIVE_ARGS_GROUPS + ADAPTIVE_ARGS_GROUP_WORDS * g as u32 + 2;
                AdaptiveGroup {
                    key,
                    bind_group,
                    range,
                    args_offset: u64::from(word) * 4,
                    slots_bind_group,
                    dirty_list,
                    records,
                    first_slot,
                }
            })
            .collect();
        Self {
            levels_bind_group: bind(
                &pipelines.levels,
                &[
                    entire(0, buffers.control_points),
                    entire(1, buffers.control_indices),
                    entire(2, buffers.records),
                    entire(8, &slots_buffer),
                    entire(9, &view),
                ],
            ),
            scan_bind_group: bind(
                &pipelines.scan,
                &[
                    entire(8, &slots_buffer),
                    entire(9, &view),
                    entire(10, &args_buffer),
                ],
            ),
            triangles_bind_group: bind(
                &pipelines.triangles,
                &[
                    entire(4, buffers.triangle_indices),
                    entire(8, &slots_buffer),
                    entire(9, &view),
                ],
            ),
            slots: slots_buffer,
            view,
            args: args_buffer,
            slot_count,
            room,
            groups,
            evaluated: None,
            wanted: None,
            readback: AsyncReadback::new(device, "adaptive statistics readback", STATS_BYTES),
            latest: None,
            frozen: false,
            remeasure: false,
        }
    }

    /// Keeps every patch's levels and place while `frozen` (a drag lasts): an edit then
    /// re-evaluates only its patches, as the fixed tessellation does. The first encode after
    /// unfreezing measures everything again.
    pub fn freeze_levels(&mut self, frozen: bool) {
        self.frozen = frozen;
    }

    /// Whether the next encode has work: a new view, or `dirty` (an edit) with a view known.
    pub fn needs_evaluation(&self, dirty: bool) -> bool {
        self.wanted.is_some()
            && (dirty || self.wanted != self.evaluated || (self.remeasure && !self.frozen))
    }

    /// The uniform of `target` for this geometry.
    fn uniform(&self, target: &AdaptiveTarget) -> AdaptiveView {
        let e = &target.error;
        AdaptiveView {
            view_proj: target.view_proj.to_cols_array_2d(),
            eye: e.eye.as_vec3().extend(1.0).to_array(),
            forward: e.forward.as_vec3().extend(0.0).to_array(),
            error: [
                e.pixel_scale as f32,
                e.near as f32,
                e.tolerance_px as f32,
                e.max_edge_px as f32,
            ],
            counts: [
                u32::from(e.orthographic),
                e.max_segments.clamp(1, ADAPTIVE_MAX_SEGMENTS),
                self.slot_count,
                self.room[0],
            ],
            bases: [
                self.room[1],
                self.room[2],
                self.room[3],
                self.groups.len() as u32,
            ],
        }
    }

    /// Records the adaptive passes into `pass` for the wanted view (the caller checked
    /// [`Self::needs_evaluation`]); `dirty` marks the records an edit changed. Returns the
    /// number of patches evaluated: all of them, or with frozen levels and an unchanged view
    /// the changed ones.
    pub(super) fn encode(
        &mut self,
        queue: &wgpu::Queue,
        pass: &mut wgpu::ComputePass<'_>,
        evaluator: &PatchEvaluator,
        curvature: bool,
        dirty: &[bool],
    ) -> u32 {
        let pipelines = &evaluator.adaptive;
        let Some(target) = self.wanted else {
            return 0;
        };
        if self.frozen && self.evaluated == Some(target) {
            return self.encode_changed(queue, pass, evaluator, curvature, dirty);
        }
        self.remeasure = false;
        queue.write_buffer(&self.view, 0, bytemuck::bytes_of(&self.uniform(&target)));
        self.evaluated = Some(target);
        if self.slot_count == 0 {
            return 0;
        }
        pass.set_pipeline(&pipelines.levels);
        pass.set_bind_group(0, &self.levels_bind_group, &[]);
        pass.dispatch_workgroups(self.slot_count.div_ceil(EVAL_WORKGROUP_SIZE), 1, 1);
        pass.set_pipeline(&pipelines.scan);
        pass.set_bind_group(0, &self.scan_bind_group, &[]);
        pass.dispatch_workgroups(1, 1, 1);
        for group in &self.groups {
            let pipeline =
                evaluator.eval_pipeline(group.key, "evaluate_adaptive_vertices", curvature);
            pass.set_pipeline(&pipeline);
            pass.set_bind_group(0, &group.bind_group, &[]);
            pass.dispatch_workgroups_indirect(&self.args, group.args_offset);
        }
        pass.set_pipeline(&pipelines.triangles);
        pass.set_bind_group(0, &self.triangles_bind_group, &[]);
        pass.dispatch_workgroups_indirect(&self.args, u64::from(ADAPTIVE_ARGS_TRIANGLES) * 4);
        self.slot_count
    }

    /// The changed records' slots at their measured levels.
    fn encode_changed(
        &mut self,
        queue: &wgpu::Queue,
        pass: &mut wgpu::ComputePass<'_>,
        evaluator: &PatchEvaluator,
        curvature: bool,
        dirty: &[bool],
    ) -> u32 {
        let mut evaluated = 0;
        for group in &self.groups {
            let list: Vec<u32> = group
                .records
                .iter()
                .enumerate()
                .filter(|&(_, &r)| dirty.get(r as usize).copied().unwrap_or(false))
                .map(|(k, _)| group.first_slot + k as u32)
                .collect();
            if list.is_empty() {
                continue;
            }
            queue.write_buffer(&group.dirty_list, 0, bytemuck::cast_slice(&list));
            // x, as wide as the largest patch, was written by the last scan; y is the list.
            let y = group.args_offset + 4 * 4;
            queue.write_buffer(&self.args, y, bytemuck::bytes_of(&(list.len() as u32)));
            let pipeline = evaluator.eval_pipeline(group.key, "evaluate_adaptive_slots", curvature);
            pass.set_pipeline(&pipeline);
            pass.set_bind_group(0, &group.slots_bind_group, &[]);
            pass.dispatch_workgroups_indirect(&self.args, group.args_offset + 3 * 4);
            evaluated += list.len() as u32;
        }
        self.remeasure |= evaluated > 0;
        evaluated
    }

    /// After the compute pass: the copy of the statistics for the asynchronous readback.
    pub(super) fn record_readback(&mut self, encoder: &mut wgpu::CommandEncoder) {
        self.readback.record(
            encoder,
            &self.args,
            u64::from(ADAPTIVE_ARGS_STATS) * 4,
            STATS_BYTES,
        );
    }

    /// Call after submitting: starts mapping the statistics.
    pub fn after_submit(&mut self) {
        self.readback.after_submit();
    }

    /// The latest statistics that arrived (taking any that just did).
    pub fn stats(&mut self) -> Option<AdaptiveStats> {
        if let Some(bytes) = self.readback.take() {
            let words: Vec<u32> = bytemuck::pod_collect_to_vec(&bytes);
            self.latest = Some(AdaptiveStats::from_words(&words));
        }
        self.latest
    }

    /// The latest statistics, without collecting.
    pub fn latest_stats(&self) -> Option<AdaptiveStats> {
        self.latest
    }

    /// The indirect draw arguments (`draw_indexed_indirect` at offset 0).
    pub fn draw_arguments(&self) -> &wgpu::Buffer {
        &self.args
    }

    /// The slots (levels and places) as last written (blocking; tests).
    #[cfg(not(target_arch = "wasm32"))]
    pub fn read_slots(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
    ) -> Result<Vec<AdaptiveSlot>, super::GpuError> {
        let size = u64::from(self.slot_count) * std::mem::size_of::<AdaptiveSlot>() as u64;
        let bytes = super::readback::read_buffer(device, queue, &self.slots, size)?;
        Ok(bytemuck::pod_collect_to_vec(&bytes))
    }

    /// The statistics as last written (blocking; tests, benchmarks).
    #[cfg(not(target_arch = "wasm32"))]
    pub fn read_stats(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
    ) -> Result<AdaptiveStats, super::GpuError> {
        let bytes = super::readback::read_buffer(device, queue, &self.args, 64)?;
        let words: Vec<u32> = bytemuck::pod_collect_to_vec(&bytes);
        let stats = AdaptiveStats::from_words(&words[ADAPTIVE_ARGS_STATS as usize..]);
        self.latest = Some(stats);
        Ok(stats)
    }

    /// Bytes of GPU memory the adaptive state holds.
    pub fn buffer_bytes(&self) -> u64 {
        self.slots.size()
            + self.view.size()
            + self.args.size()
            + self
                .groups
                .iter()
                .map(|g| g.range.size() + g.dirty_list.size())
                .sum::<u64>()
    }
}
