//! The compute evaluator: uploads a [`BezierPatchSet`] and runs `shaders/eval_bezier.wgsl`, which
//! writes every tessellation vertex (position, normal, (u, v)) and the triangle indices straight
//! into buffers the render pass draws from. No CPU tessellation on this path.

use std::collections::BTreeSet;

use wgpu::util::DeviceExt;

use super::error::GpuError;
use super::records::{EVAL_WORKGROUP_SIZE, GPU_MAX_DEGREE, PatchRecord, SurfaceVertex};
use crate::kernel::BezierPatchSet;
use crate::shaders;

/// Highest tessellation level (segments per patch edge) the evaluator accepts; buffer limits may
/// refuse less (see [`GpuError::BufferTooLarge`]).
pub const MAX_SEGMENTS: u32 = 1024;

/// The compute pipelines; one per device, shared by every [`PatchGeometry`].
pub struct PatchEvaluator {
    /// `evaluate_vertices` specialized to bicubic patches (`BICUBIC_ONLY = true`).
    bicubic_pipeline: wgpu::ComputePipeline,
    /// `evaluate_vertices` for any degree up to [`GPU_MAX_DEGREE`].
    general_pipeline: wgpu::ComputePipeline,
    triangles_pipeline: wgpu::ComputePipeline,
}

impl PatchEvaluator {
    pub fn new(device: &wgpu::Device) -> Self {
        let module = shaders::create_module(device, "eval_bezier.wgsl", shaders::EVAL_BEZIER);
        let pipeline = |label: &str, entry_point: &str, constants: &[(&str, f64)]| {
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(label),
                layout: None,
                module: &module,
                entry_point: Some(entry_point),
                compilation_options: wgpu::PipelineCompilationOptions {
                    constants,
                    ..Default::default()
                },
                cache: None,
            })
        };
        Self {
            bicubic_pipeline: pipeline(
                "evaluate bicubic patches",
                "evaluate_vertices",
                &[("BICUBIC_ONLY", 1.0)],
            ),
            general_pipeline: pipeline(
                "evaluate patches",
                "evaluate_vertices",
                &[("BICUBIC_ONLY", 0.0)],
            ),
            triangles_pipeline: pipeline("write triangles", "write_triangles", &[]),
        }
    }

    fn eval_pipeline(&self, bicubic: bool) -> &wgpu::ComputePipeline {
        if bicubic {
            &self.bicubic_pipeline
        } else {
            &self.general_pipeline
        }
    }
}

/// The patches one evaluation pipeline handles: their records and bind groups.
struct PatchGroup {
    bicubic: bool,
    count: u32,
    eval_bind_group: wgpu::BindGroup,
    triangles_bind_group: wgpu::BindGroup,
}

/// GPU buffers of one patch set at one tessellation level.
pub struct PatchGeometry {
    control_points: wgpu::Buffer,
    vertices: wgpu::Buffer,
    triangle_indices: wgpu::Buffer,
    net_lines: wgpu::Buffer,
    /// Bicubic patches and the rest, each evaluated by its own pipeline.
    groups: Vec<PatchGroup>,
    patch_count: u32,
    control_point_count: u32,
    vertex_count: u32,
    index_count: u32,
    net_index_count: u32,
    vertex_groups_x: u32,
    quad_groups_x: u32,
    segments: u32,
    triangles_written: bool,
}

/// Homogeneous control points (wx, wy, wz, w) in f32, as the shaders read them.
fn homogeneous_points(set: &BezierPatchSet) -> Vec<[f32; 4]> {
    set.points()
        .iter()
        .zip(set.weights())
        .map(|(p, &w)| {
            let h = *p * w;
            [h.x as f32, h.y as f32, h.z as f32, w as f32]
        })
        .collect()
}

/// Index pairs of the control net's lines: each patch's rows and columns, shared edges once.
fn net_line_indices(set: &BezierPatchSet) -> Vec<u32> {
    let mut edges = BTreeSet::new();
    for patch in set.patches() {
        let (p, q) = (patch.degree_u(), patch.degree_v());
        for i in 0..=p {
            for j in 0..=q {
                let a = patch.index(i, j);
                let mut add = |b: u32| {
                    if a != b {
                        edges.insert((a.min(b), a.max(b)));
                    }
                };
                if i < p {
                    add(patch.index(i + 1, j));
                }
                if j < q {
                    add(patch.index(i, j + 1));
                }
            }
        }
    }
    edges.into_iter().flat_map(|(a, b)| [a, b]).collect()
}

impl PatchGeometry {
    /// Uploads `set` for evaluation at `segments` segments per patch edge (in both directions).
    /// Checks the degrees, the level and the device's buffer and dispatch limits.
    pub fn new(
        device: &wgpu::Device,
        evaluator: &PatchEvaluator,
        set: &BezierPatchSet,
        segments: u32,
    ) -> Result<Self, GpuError> {
        if !(1..=MAX_SEGMENTS).contains(&segments) {
            return Err(GpuError::SegmentsOutOfRange {
                segments,
                max: MAX_SEGMENTS,
            });
        }
        let limits = device.limits();
        let max_groups = limits.max_compute_workgroups_per_dimension;
        if set.patches().len() > max_groups as usize {
            return Err(GpuError::TooManyPatches {
                count: set.patches().len(),
                max: max_groups,
            });
        }

        let grid_vertices = u64::from(segments + 1).pow(2);
        let grid_quads = u64::from(segments).pow(2);
        let mut records = Vec::with_capacity(set.patches().len());
        let mut control_indices = Vec::new();
        let (mut vertex_offset, mut index_offset) = (0u64, 0u64);
        for (k, patch) in set.patches().iter().enumerate() {
            let (du, dv) = (patch.degree_u(), patch.degree_v());
            if du > GPU_MAX_DEGREE as usize || dv > GPU_MAX_DEGREE as usize {
                return Err(GpuError::DegreeTooHigh {
                    patch: k,
                    degree_u: du,
                    degree_v: dv,
                    max: GPU_MAX_DEGREE,
                });
            }
            records.push(PatchRecord {
                degree_u: du as u32,
                degree_v: dv as u32,
                control_offset: control_indices.len() as u32,
                vertex_offset: vertex_offset as u32,
                segments_u: segments,
                segments_v: segments,
                index_offset: index_offset as u32,
                flags: 0,
                domain: [0.0, 1.0, 0.0, 1.0],
            });
            control_indices.extend_from_slice(patch.indices());
            vertex_offset += grid_vertices;
            index_offset += 6 * grid_quads;
        }

        let vertex_bytes = vertex_offset * std::mem::size_of::<SurfaceVertex>() as u64;
        let index_bytes = index_offset * 4;
        let limit = limits
            .max_storage_buffer_binding_size
            .min(limits.max_buffer_size);
        for (what, bytes) in [("vertex", vertex_bytes), ("index", index_bytes)] {
            if bytes > limit || vertex_offset > u64::from(u32::MAX) {
                return Err(GpuError::BufferTooLarge { what, bytes, limit });
            }
        }
        let groups = |items: u64| items.div_ceil(u64::from(EVAL_WORKGROUP_SIZE)) as u32;
        let (vertex_groups_x, quad_groups_x) = (groups(grid_vertices), groups(grid_quads));
        if vertex_groups_x > max_groups {
            return Err(GpuError::SegmentsOutOfRange {
                segments,
                max: MAX_SEGMENTS,
            });
        }

        let points = homogeneous_points(set);
        let net = net_line_indices(set);
        let storage = wgpu::BufferUsages::STORAGE;
        let init = |label: &str, contents: &[u8], usage: wgpu::BufferUsages| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                // wgpu refuses zero-sized bindings; an empty set still gets 4 bytes.
                contents: if contents.is_empty() {
                    &[0; 4]
                } else {
                    contents
                },
                usage,
            })
        };
        let control_points = init(
            "control points",
            bytemuck::cast_slice(&points),
            storage | wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
        );
        let control_index_buffer = init(
            "control indices",
            bytemuck::cast_slice(&control_indices),
            storage,
        );
        let net_lines = init(
            "net lines",
            bytemuck::cast_slice(&net),
            wgpu::BufferUsages::INDEX,
        );
        let output = |label: &str, size: u64, usage: wgpu::BufferUsages| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: size.max(4),
                usage: storage | wgpu::BufferUsages::COPY_SRC | usage,
                mapped_at_creation: false,
            })
        };
        let vertices = output("surface vertices", vertex_bytes, wgpu::BufferUsages::VERTEX);
        let triangle_indices = output("triangle indices", index_bytes, wgpu::BufferUsages::INDEX);

        let bind = |pipeline: &wgpu::ComputePipeline, entries: &[(u32, &wgpu::Buffer)]| {
            let entries: Vec<_> = entries
                .iter()
                .map(|&(binding, buffer)| wgpu::BindGroupEntry {
                    binding,
                    resource: buffer.as_entire_binding(),
                })
                .collect();
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: None,
                layout: &pipeline.get_bind_group_layout(0),
                entries: &entries,
            })
        };
        let mut groups = Vec::new();
        for bicubic in [true, false] {
            let group_records: Vec<PatchRecord> = records
                .iter()
                .filter(|r| (r.degree_u == 3 && r.degree_v == 3) == bicubic)
                .copied()
                .collect();
            if group_records.is_empty() {
                continue;
            }
            let record_buffer = init(
                "patch records",
                bytemuck::cast_slice(&group_records),
                storage,
            );
            groups.push(PatchGroup {
                bicubic,
                count: group_records.len() as u32,
                eval_bind_group: bind(
                    evaluator.eval_pipeline(bicubic),
                    &[
                        (0, &control_points),
                        (1, &control_index_buffer),
                        (2, &record_buffer),
                        (3, &vertices),
                    ],
                ),
                triangles_bind_group: bind(
                    &evaluator.triangles_pipeline,
                    &[(2, &record_buffer), (4, &triangle_indices)],
                ),
            });
        }

        Ok(Self {
            control_points,
            vertices,
            triangle_indices,
            net_lines,
            groups,
            patch_count: records.len() as u32,
            control_point_count: points.len() as u32,
            vertex_count: vertex_offset as u32,
            index_count: index_offset as u32,
            net_index_count: net.len() as u32,
            vertex_groups_x,
            quad_groups_x,
            segments,
            triangles_written: false,
        })
    }

    /// Writes new control point positions and weights (same count as at creation); the next
    /// [`Self::encode`] re-evaluates the surface from them.
    pub fn update_control_points(
        &self,
        queue: &wgpu::Queue,
        set: &BezierPatchSet,
    ) -> Result<(), GpuError> {
        if set.points().len() != self.control_point_count as usize {
            return Err(GpuError::ControlPointCountChanged {
                expected: self.control_point_count as usize,
                found: set.points().len(),
            });
        }
        let points = homogeneous_points(set);
        queue.write_buffer(&self.control_points, 0, bytemuck::cast_slice(&points));
        Ok(())
    }

    /// Records one compute pass that evaluates every vertex (and, the first time, writes the
    /// triangle indices). `timestamps` brackets the pass for GPU timing.
    pub fn encode(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        evaluator: &PatchEvaluator,
        timestamps: Option<wgpu::ComputePassTimestampWrites<'_>>,
    ) {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("evaluate patches"),
            timestamp_writes: timestamps,
        });
        if !self.triangles_written {
            pass.set_pipeline(&evaluator.triangles_pipeline);
            for group in &self.groups {
                pass.set_bind_group(0, &group.triangles_bind_group, &[]);
                pass.dispatch_workgroups(self.quad_groups_x, group.count, 1);
            }
            self.triangles_written = true;
        }
        for group in &self.groups {
            pass.set_pipeline(evaluator.eval_pipeline(group.bicubic));
            pass.set_bind_group(0, &group.eval_bind_group, &[]);
            pass.dispatch_workgroups(self.vertex_groups_x, group.count, 1);
        }
    }

    pub fn control_points(&self) -> &wgpu::Buffer {
        &self.control_points
    }

    pub fn vertices(&self) -> &wgpu::Buffer {
        &self.vertices
    }

    pub fn triangle_indices(&self) -> &wgpu::Buffer {
        &self.triangle_indices
    }

    pub fn net_lines(&self) -> &wgpu::Buffer {
        &self.net_lines
    }

    pub fn patch_count(&self) -> u32 {
        self.patch_count
    }

    pub fn control_point_count(&self) -> u32 {
        self.control_point_count
    }

    pub fn vertex_count(&self) -> u32 {
        self.vertex_count
    }

    pub fn index_count(&self) -> u32 {
        self.index_count
    }

    pub fn net_index_count(&self) -> u32 {
        self.net_index_count
    }

    pub fn segments(&self) -> u32 {
        self.segments
    }

    /// Reads the evaluated vertices back (blocking; tests, benchmarks, CLI).
    #[cfg(not(target_arch = "wasm32"))]
    pub fn read_vertices(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
    ) -> Result<Vec<SurfaceVertex>, GpuError> {
        let size = u64::from(self.vertex_count) * std::mem::size_of::<SurfaceVertex>() as u64;
        let bytes = super::readback::read_buffer(device, queue, &self.vertices, size)?;
        Ok(bytemuck::pod_collect_to_vec(&bytes))
    }

    /// Reads the triangle indices back (blocking; tests, benchmarks, CLI).
    #[cfg(not(target_arch = "wasm32"))]
    pub fn read_triangle_indices(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
    ) -> Result<Vec<u32>, GpuError> {
        let size = u64::from(self.index_count) * 4;
        let bytes = super::readback::read_buffer(device, queue, &self.triangle_indices, size)?;
        Ok(bytemuck::pod_collect_to_vec(&bytes))
    }
}
