//! GPU evaluation on wgpu: device setup, the compute evaluator that turns patches into vertex
//! buffers, and GPU timing. Depends on the kernel, never the other way round.

pub mod adaptive;
pub mod adaptive_pass;
pub mod async_readback;
pub mod context;
pub mod cpu_eval;
pub mod curve_eval;
pub mod error;
pub mod export_grids;
pub mod packing;
pub mod patch_eval;
pub mod pipelines;
#[cfg(not(target_arch = "wasm32"))]
pub mod point_eval;
#[cfg(not(target_arch = "wasm32"))]
pub mod readback;
pub mod records;
pub mod scene_sync;
mod stencil_pages;
#[cfg(not(target_arch = "wasm32"))]
pub mod subdiv_eval;
pub mod timing;
pub mod trim_buffer;
pub mod vertex_evaluator;

pub use context::{GpuContext, backend_name, check_adapter, choose_adapter, device_descriptor};
pub use cpu_eval::CpuGeometry;
pub use error::GpuError;
pub use patch_eval::{MAX_SEGMENTS, ObjectPatches, PatchBuffers, PatchGeometry, SurfaceBuffers};
pub use pipelines::PatchEvaluator;
pub use records::{PatchRecord, PointResult, PointSample, SceneUniform, SurfaceVertex};
pub use scene_sync::{GeometryCounts, SceneSync, effective_segments, fit_to_device, has_compute};
pub use vertex_evaluator::VertexEvaluator;
