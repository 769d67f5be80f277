//! Curves on the GPU: every curve object's rational Bézier segments ([`CurveFeed`]) in one
//! point pool, sampled by the compute pass `eval_curves` (`shaders/eval_curves.wgsl`) straight
//! into the curve vertex buffer the viewport draws as anti-aliased lines. Where the device has no
//! compute shaders (WebGL2) the CPU samples the same segments in f64 and uploads the vertices.
//! A drag re-uploads the moved curve's points and re-evaluates only the segments it names.

use std::collections::BTreeSet;

use bytemuck::Zeroable;
use wgpu::util::DeviceExt;

use super::error::GpuError;
use super::pipelines::{compute_pipeline, storage_layout};
use super::records::{CURVE_MAX_DEGREE, CurveRecord, CurveVertex};
use crate::scene::CurveFeed;
use crate::shaders;

/// Most line segments per Bézier segment of a curve.
pub const MAX_CURVE_SEGMENTS: u32 = 256;

/// Workgroups per row of a dispatch (WebGPU's per-dimension limit).
const DISPATCH_ROW: u32 = 65_535;

/// The bindings of `eval_curves`: points, records, the segments to evaluate, vertices.
const CURVE_BINDINGS: [(u32, bool); 4] = [(0, true), (1, true), (2, true), (3, false)];

/// The curve pass's pipeline; one per device.
pub struct CurveEvaluator {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::ComputePipeline,
}

impl CurveEvaluator {
    pub fn new(device: &wgpu::Device) -> Self {
        let module = shaders::create_module(device, &shaders::EVAL_CURVES_SHADER);
        let layout = storage_layout(device, "curve evaluator bindings", &CURVE_BINDINGS);
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("curve evaluator"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = compute_pipeline(
            device,
            &pipeline_layout,
            &module,
            "curve evaluation",
            "eval_curves",
            &[],
        );
        Self { layout, pipeline }
    }
}

/// One object's curve as the sync layer hands it over: its feed (`None` for an object that is
/// not a curve, or is hidden) and the line segments per Bézier segment.
pub struct ObjectCurve<'a> {
    pub feed: Option<&'a CurveFeed>,
    pub segments: u32,
}

/// Where one object's segments sit in the pool.
#[derive(Debug, Clone, Copy)]
struct ObjectRange {
    first_record: u32,
    records: u32,
    first_point: u32,
    points: u32,
}

/// The drawable curve vertices.
#[derive(Debug, Clone, Copy)]
pub struct CurveBuffers<'a> {
    pub vertices: &'a wgpu::Buffer,
    pub vertex_count: u32,
}

/// The GPU copy of every curve of a scene.
pub struct CurveGeometry {
    points: wgpu::Buffer,
    vertices: wgpu::Buffer,
    todo: wgpu::Buffer,
    bind_group: Option<wgpu::BindGroup>,
    records: Vec<CurveRecord>,
    objects: Vec<Option<ObjectRange>>,
    pending: BTreeSet<u32>,
    vertex_count: u32,
}

/// The homogeneous points of a feed as the shader reads them.
fn gpu_points(feed: &CurveFeed) -> Vec<[f32; 4]> {
    feed.points
        .iter()
        .map(|h| h.to_array().map(|c| c as f32))
        .collect()
}

impl CurveGeometry {
    /// Lays out every object's segments (one record each) and marks them all for evaluation.
    /// `evaluator` is the compute pass, or `None` where the CPU evaluates ([`Self::evaluate_on_cpu`]).
    /// Refused for a curve of a degree above [`CURVE_MAX_DEGREE`] and for buffers beyond the
    /// device's limits.
    pub fn new(
        device: &wgpu::Device,
        evaluator: Option<&CurveEvaluator>,
        inputs: &[ObjectCurve<'_>],
    ) -> Result<Self, GpuError> {
        let mut records = Vec::new();
        let mut points: Vec<[f32; 4]> = Vec::new();
        let mut objects = Vec::with_capacity(inputs.len());
        let mut vertex_count = 0u64;
        for (object, input) in inputs.iter().enumerate() {
            let Some(feed) = input.feed.filter(|f| f.segment_count() > 0) else {
                objects.push(None);
                continue;
            };
            if feed.degree as u32 > CURVE_MAX_DEGREE {
                return Err(GpuError::Geometry(format!(
                    "a curve of degree {} is above the GPU's {CURVE_MAX_DEGREE}",
                    feed.degree
                )));
            }
            let segments = input.segments.clamp(1, MAX_CURVE_SEGMENTS);
            let range = ObjectRange {
                first_record: records.len() as u32,
                records: feed.segment_count() as u32,
                first_point: points.len() as u32,
                points: feed.points.len() as u32,
            };
            for k in 0..feed.segment_count() {
                records.push(CurveRecord {
                    degree: feed.degree as u32,
                    control_offset: range.first_point + (k * (feed.degree + 1)) as u32,
                    vertex_offset: vertex_count as u32,
                    segments,
                    object: object as u32,
                    ..CurveRecord::zeroed()
                });
                vertex_count += u64::from(segments) + 1;
            }
            points.extend(gpu_points(feed));
            objects.push(Some(range));
        }
        let limits = device.limits();
        let limit = limits
            .max_storage_buffer_binding_size
            .min(limits.max_buffer_size);
        let vertex_bytes = vertex_count * std::mem::size_of::<CurveVertex>() as u64;
        for (what, bytes) in [
            ("curve vertex", vertex_bytes),
            ("curve point", (points.len() * 16) as u64),
        ] {
            if bytes > limit {
                return Err(GpuError::BufferTooLarge { what, bytes, limit });
            }
        }
        let compute = evaluator.is_some();
        let storage = if compute {
            wgpu::BufferUsages::STORAGE
        } else {
            wgpu::BufferUsages::empty()
        };
        let points_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("curve points"),
            contents: bytemuck::cast_slice(if points.is_empty() {
                &[[0.0f32; 4]][..]
            } else {
                &points
            }),
            usage: storage | wgpu::BufferUsages::COPY_DST,
        });
        let no_record = [CurveRecord::zeroed()];
        let records_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("curve records"),
            contents: bytemuck::cast_slice(if records.is_empty() {
                &no_record[..]
            } else {
                &records
            }),
            usage: storage | wgpu::BufferUsages::COPY_DST,
        });
        let todo = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("curve segments to evaluate"),
            size: 4 * (records.len() as u64 + 1),
            usage: storage | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let vertices = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("curve vertices"),
            size: vertex_bytes.max(std::mem::size_of::<CurveVertex>() as u64),
            usage: storage
                | wgpu::BufferUsages::VERTEX
                | wgpu::BufferUsages::COPY_DST
                | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let bind_group = evaluator.map(|e| {
            let entries: Vec<wgpu::BindGroupEntry<'_>> =
                [&points_buffer, &records_buffer, &todo, &vertices]
                    .iter()
                    .enumerate()
                    .map(|(k, buffer)| wgpu::BindGroupEntry {
                        binding: k as u32,
                        resource: buffer.as_entire_binding(),
                    })
                    .collect();
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("curve evaluator"),
                layout: &e.layout,
                entries: &entries,
            })
        });
        Ok(Self {
            points: points_buffer,
            vertices,
            todo,
            bind_group,
            pending: (0..records.len() as u32).collect(),
            records,
            objects,
            vertex_count: vertex_count as u32,
        })
    }

    /// The records, objects in order (tests compare each vertex with its segment).
    pub fn records(&self) -> &[CurveRecord] {
        &self.records
    }

    /// Record index of object `object`'s first segment, for a curve object.
    pub fn first_record(&self, object: usize) -> Option<usize> {
        self.objects
            .get(object)
            .copied()
            .flatten()
            .map(|r| r.first_record as usize)
    }

    pub fn vertex_count(&self) -> u32 {
        self.vertex_count
    }

    /// What the viewport draws (`None` when the scene has no curve).
    pub fn buffers(&self) -> Option<CurveBuffers<'_>> {
        (self.vertex_count > 1).then_some(CurveBuffers {
            vertices: &self.vertices,
            vertex_count: self.vertex_count,
        })
    }

    /// Object `object`'s curve moved (same layout): uploads its points and marks its segments
    /// `segments` (all of them for `None`) for the next evaluation. Returns the points uploaded.
    pub fn update_object(
        &mut self,
        queue: &wgpu::Queue,
        object: usize,
        feed: &CurveFeed,
        segments: Option<&[usize]>,
    ) -> Result<usize, GpuError> {
        let Some(range) = self.objects.get(object).copied().flatten() else {
            return Ok(0);
        };
        if feed.points.len() != range.points as usize {
            return Err(GpuError::ControlPointCountChanged {
                expected: range.points as usize,
                found: feed.points.len(),
            });
        }
        queue.write_buffer(
            &self.points,
            u64::from(range.first_point) * 16,
            bytemuck::cast_slice(&gpu_points(feed)),
        );
        match segments {
            Some(segments) => self.pending.extend(
                segments
                    .iter()
                    .filter(|&&k| (k as u32) < range.records)
                    .map(|&k| range.first_record + k as u32),
            ),
            None => self
                .pending
                .extend(range.first_record..range.first_record + range.records),
        }
        Ok(feed.points.len())
    }

    /// Marks every segment for evaluation.
    pub fn invalidate(&mut self) {
        self.pending = (0..self.records.len() as u32).collect();
    }

    pub fn needs_evaluation(&self) -> bool {
        !self.pending.is_empty()
    }

    /// Records the curve pass for the pending segments; returns how many.
    pub fn encode(
        &mut self,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        evaluator: &CurveEvaluator,
    ) -> u32 {
        let Some(bind_group) = &self.bind_group else {
            return 0;
        };
        if self.pending.is_empty() {
            return 0;
        }
        let count = self.pending.len() as u32;
        let mut todo = Vec::with_capacity(self.pending.len() + 1);
        todo.push(count);
        todo.extend(std::mem::take(&mut self.pending));
        queue.write_buffer(&self.todo, 0, bytemuck::cast_slice(&todo));
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("curve evaluation"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&evaluator.pipeline);
        pass.set_bind_group(0, bind_group, &[]);
        pass.dispatch_workgroups(count.min(DISPATCH_ROW), count.div_ceil(DISPATCH_ROW), 1);
        count
    }

    /// The CPU's evaluation of the pending segments (the WebGL2 path): the same samples in f64
    /// ([`CurveFeed::point`]), uploaded. `feeds` are each object's curve feed, in order.
    pub fn evaluate_on_cpu(&mut self, queue: &wgpu::Queue, feeds: &[Option<&CurveFeed>]) -> u32 {
        let pending = std::mem::take(&mut self.pending);
        for &index in &pending {
            let record = self.records[index as usize];
            let object = record.object as usize;
            let (Some(Some(range)), Some(Some(feed))) =
                (self.objects.get(object), feeds.get(object))
            else {
                continue;
            };
            let segment = (index - range.first_record) as usize;
            let vertices = sample_segment(feed, segment, &record, index);
            queue.write_buffer(
                &self.vertices,
                u64::from(record.vertex_offset) * std::mem::size_of::<CurveVertex>() as u64,
                bytemuck::cast_slice(&vertices),
            );
        }
        pending.len() as u32
    }

    /// The evaluated vertices (blocking; tests, benchmarks).
    #[cfg(not(target_arch = "wasm32"))]
    pub fn read_vertices(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
    ) -> Result<Vec<CurveVertex>, GpuError> {
        super::readback::read_elements(device, queue, &self.vertices, self.vertex_count)
    }
}

/// Segment `segment` of `feed` sampled as `record` says, in f64 (the CPU path, and the oracle
/// the shader is checked against).
pub fn sample_segment(
    feed: &CurveFeed,
    segment: usize,
    record: &CurveRecord,
    index: u32,
) -> Vec<CurveVertex> {
    let n = record.segments.max(1);
    (0..=n)
        .map(|k| {
            let s = f64::from(k) / f64::from(n);
            let p = feed.point(segment, s).unwrap_or_default();
            CurveVertex {
                position: [
                    p.x as f32,
                    p.y as f32,
                    p.z as f32,
                    if k == n { 0.0 } else { 1.0 },
                ],
                object: record.object,
                record: index,
                s: s as f32,
                reserved: 0,
            }
        })
        .collect()
}
