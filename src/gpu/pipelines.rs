//! The compute pipelines of `shaders/eval_bezier.wgsl`, one set per device: the evaluation
//! pipelines specialized per patch kind and degrees ([`PipelineKey`], override constants,
//! compiled on first use), the bind group layouts they share, and the adaptive passes'
//! pipelines. Both the fixed-grid evaluator ([`super::patch_eval`]) and the view-adaptive one
//! ([`super::adaptive_pass`]) take them from here, so neither imports the other.

use std::collections::HashMap;
use std::sync::Mutex;

use super::records::{DISPLACEMENT_NONE, LATTICE_NONE, PATCH_KIND_BEZIER, PatchRecord};
use crate::shaders;

/// What an evaluation pipeline is specialized for: the patch kind and the degrees.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct PipelineKey {
    /// [`PatchRecord::kind`].
    pub kind: u32,
    pub degree_u: u32,
    pub degree_v: u32,
    /// Whether the patch's object is displaced (`DISPLACES` in the shader) and whether it is
    /// deformed by a lattice (`DEFORMS`): the other patches get pipelines without that code,
    /// which a CPU driver would otherwise pay for in registers on every vertex.
    pub displaces: bool,
    pub deforms: bool,
}

impl PipelineKey {
    pub(super) fn of(record: &PatchRecord) -> Self {
        Self {
            kind: record.kind,
            degree_u: record.degree_u,
            degree_v: record.degree_v,
            displaces: record.displacement != DISPLACEMENT_NONE,
            deforms: record.lattice != LATTICE_NONE,
        }
    }
}

/// The bindings of `shaders/eval_bezier.wgsl`'s group 0, shared by every entry point:
/// (binding, read-only).
const EVAL_BINDINGS: [(u32, bool); 8] = [
    (0, true),  // control points
    (1, true),  // control indices
    (2, true),  // patch records
    (3, false), // vertices
    (4, false), // triangle indices
    (5, true),  // patch list
    (6, true),  // point samples
    (7, false), // point results
];

/// The bindings of `evaluate_adaptive_vertices` and `evaluate_adaptive_slots`: (binding,
/// read-only).
const ADAPTIVE_EVAL_BINDINGS: [(u32, bool); 6] = [
    (0, true),  // control points
    (1, true),  // control indices
    (2, true),  // patch records
    (3, false), // vertices
    (5, true),  // the group's range, or the slots a drag step changed
    (8, false), // adaptive slots
];

/// A bind group layout of storage buffers visible to compute: (binding, read-only) each.
pub(super) fn storage_layout(
    device: &wgpu::Device,
    label: &str,
    bindings: &[(u32, bool)],
) -> wgpu::BindGroupLayout {
    let entries: Vec<wgpu::BindGroupLayoutEntry> = bindings
        .iter()
        .map(|&(binding, read_only)| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        })
        .collect();
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(label),
        entries: &entries,
    })
}

/// Bytes of a stand-in buffer for a binding an entry point does not use: at least one element
/// of the largest record bound there.
const STAND_IN_BYTES: u64 = 256;

/// The compute pipelines; one per device, shared by every [`super::PatchGeometry`]. Every entry point
/// uses one explicit bind group layout ([`EVAL_BINDINGS`]); the evaluation pipelines are
/// specialized per [`PipelineKey`] (override constants), created on first use.
pub struct PatchEvaluator {
    device: wgpu::Device,
    module: wgpu::ShaderModule,
    layout: wgpu::BindGroupLayout,
    pipeline_layout: wgpu::PipelineLayout,
    /// Small buffers bound where an entry point does not use a binding, one per binding.
    stand_ins: Vec<wgpu::Buffer>,
    /// The evaluation pipelines per (key, entry point, vertex curvature); bicubic Bézier
    /// patches take the array-free path.
    specialized: Mutex<HashMap<(PipelineKey, &'static str, bool), wgpu::ComputePipeline>>,
    /// The adaptive passes that are not specialized by degree.
    pub(super) adaptive: AdaptivePipelines,
    /// The bindings of the adaptive evaluation entry points ([`ADAPTIVE_EVAL_BINDINGS`]), so
    /// that one bind group serves the pipelines with and without vertex curvature.
    pub(super) adaptive_eval_layout: wgpu::BindGroupLayout,
    adaptive_eval_pipeline_layout: wgpu::PipelineLayout,
    pub(super) triangles_pipeline: wgpu::ComputePipeline,
    /// Point evaluation (native only: the `eval --backend gpu` command).
    #[cfg_attr(target_arch = "wasm32", allow(dead_code))]
    pub(super) samples_pipeline: wgpu::ComputePipeline,
}

pub(super) fn compute_pipeline(
    device: &wgpu::Device,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
    label: &str,
    entry_point: &str,
    constants: &[(&str, f64)],
) -> wgpu::ComputePipeline {
    device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(label),
        layout: Some(layout),
        module,
        entry_point: Some(entry_point),
        compilation_options: wgpu::PipelineCompilationOptions {
            constants,
            ..Default::default()
        },
        cache: None,
    })
}

impl PatchEvaluator {
    pub fn new(device: &wgpu::Device) -> Self {
        let module = shaders::create_module(device, &shaders::EVAL_BEZIER_SHADER);
        let layout = storage_layout(device, "evaluator bindings", &EVAL_BINDINGS);
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("evaluator"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let adaptive_eval_layout = storage_layout(
            device,
            "adaptive evaluation bindings",
            &ADAPTIVE_EVAL_BINDINGS,
        );
        let adaptive_eval_pipeline_layout =
            device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("adaptive evaluation"),
                bind_group_layouts: &[Some(&adaptive_eval_layout)],
                immediate_size: 0,
            });
        let stand_ins = EVAL_BINDINGS
            .iter()
            .map(|_| {
                device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("unused binding"),
                    size: STAND_IN_BYTES,
                    usage: wgpu::BufferUsages::STORAGE,
                    mapped_at_creation: false,
                })
            })
            .collect();
        Self {
            triangles_pipeline: compute_pipeline(
                device,
                &pipeline_layout,
                &module,
                "write triangles",
                "write_triangles",
                &[],
            ),
            samples_pipeline: compute_pipeline(
                device,
                &pipeline_layout,
                &module,
                "evaluate points",
                "evaluate_samples",
                &[("BICUBIC_ONLY", 0.0)],
            ),
            specialized: Mutex::new(HashMap::new()),
            adaptive: AdaptivePipelines::new(device, &module),
            adaptive_eval_layout,
            adaptive_eval_pipeline_layout,
            layout,
            pipeline_layout,
            stand_ins,
            device: device.clone(),
            module,
        }
    }

    /// The pipeline of entry point `entry` (`evaluate_vertices`, or one of the adaptive ones)
    /// for `key`'s patches, writing the vertices' curvature or not (`curvature`), compiled on
    /// first use.
    pub(super) fn eval_pipeline(
        &self,
        key: PipelineKey,
        entry: &'static str,
        curvature: bool,
    ) -> wgpu::ComputePipeline {
        let mut cache = self
            .specialized
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner());
        cache
            .entry((key, entry, curvature))
            .or_insert_with(|| {
                let PipelineKey {
                    kind,
                    degree_u: p,
                    degree_v: q,
                    displaces,
                    deforms,
                } = key;
                let flag = |on: bool| if on { 1.0 } else { 0.0 };
                if kind != PATCH_KIND_BEZIER {
                    return compute_pipeline(
                        &self.device,
                        &self.pipeline_layout,
                        &self.module,
                        "evaluate subdivision limit stencils",
                        "evaluate_stencil_vertices",
                        &[("DISPLACES", flag(displaces)), ("DEFORMS", flag(deforms))],
                    );
                }
                let bicubic = (p, q) == (3, 3);
                let fixed_grid = entry == "evaluate_vertices";
                let constants = [
                    ("BICUBIC_ONLY", flag(bicubic)),
                    ("NET_IN_REGISTERS", flag(bicubic && fixed_grid)),
                    ("DEGREE_U", f64::from(p)),
                    ("DEGREE_V", f64::from(q)),
                    ("VERTEX_CURVATURE", flag(curvature)),
                    ("DISPLACES", flag(displaces)),
                    ("DEFORMS", flag(deforms)),
                ];
                let layout = if fixed_grid {
                    &self.pipeline_layout
                } else {
                    &self.adaptive_eval_pipeline_layout
                };
                compute_pipeline(
                    &self.device,
                    layout,
                    &self.module,
                    &format!("{entry}, degree ({p}, {q})"),
                    entry,
                    &constants,
                )
            })
            .clone()
    }

    /// A bind group of the shared layout with whole buffers at the given bindings and a
    /// stand-in at every other.
    pub(super) fn bind_group(&self, buffers: &[(u32, &wgpu::Buffer)]) -> wgpu::BindGroup {
        let entries: Vec<_> = EVAL_BINDINGS
            .iter()
            .zip(&self.stand_ins)
            .map(|(&(binding, _), stand_in)| {
                let buffer = buffers
                    .iter()
                    .find(|(b, _)| *b == binding)
                    .map_or(stand_in, |(_, buffer)| *buffer);
                wgpu::BindGroupEntry {
                    binding,
                    resource: buffer.as_entire_binding(),
                }
            })
            .collect();
        self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout: &self.layout,
            entries: &entries,
        })
    }
}

/// The pipelines of the passes that are not specialized by degree (one set per device).
pub struct AdaptivePipelines {
    pub(super) levels: wgpu::ComputePipeline,
    pub(super) scan: wgpu::ComputePipeline,
    pub(super) triangles: wgpu::ComputePipeline,
}

impl AdaptivePipelines {
    pub fn new(device: &wgpu::Device, module: &wgpu::ShaderModule) -> Self {
        let make = |label: &str, entry_point: &str| {
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(label),
                layout: None,
                module,
                entry_point: Some(entry_point),
                compilation_options: Default::default(),
                cache: None,
            })
        };
        Self {
            levels: make("measure adaptive levels", "measure_levels"),
            scan: make("place adaptive patches", "scan_levels"),
            triangles: make("write adaptive triangles", "write_adaptive_triangles"),
        }
    }
}
