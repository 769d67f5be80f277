//! The one contract of the scene's two evaluators of patches into vertex buffers: the compute
//! shaders ([`super::PatchGeometry`]) and the f64 CPU fallback where the adapter has no compute
//! ([`super::CpuGeometry`]), which is also the shaders' oracle. Both lay out the same records
//! and vertices, so everything that only reads or invalidates them goes through this trait
//! ([`super::SceneSync`] holds either), as OpenSubdiv's CPU and GPU evaluators share one
//! signature.

use super::{CpuGeometry, PatchGeometry, PatchRecord, SurfaceBuffers};
#[cfg(not(target_arch = "wasm32"))]
use super::{GpuError, SurfaceVertex};

/// What every evaluator of a scene's patches into vertex buffers answers.
pub trait VertexEvaluator {
    /// Marks every vertex for evaluation on the next pass.
    fn invalidate(&mut self);
    /// Whether a pass has vertices to evaluate.
    fn needs_evaluation(&self) -> bool;
    /// Whether the vertices carry curvature (the next pass evaluates every vertex again).
    fn set_vertex_curvature(&mut self, on: bool);
    /// The buffers the viewport draws.
    fn surface_buffers(&self) -> SurfaceBuffers<'_>;
    /// The patch records, in layout order.
    fn records(&self) -> &[PatchRecord];
    /// The first patch of object `object`, if it has patches.
    fn first_patch(&self, object: usize) -> Option<usize>;
    fn patch_count(&self) -> u32;
    fn control_point_count(&self) -> u32;
    fn vertex_count(&self) -> u32;
    fn index_count(&self) -> u32;
    /// The bytes of every buffer it holds.
    fn buffer_bytes(&self) -> u64;
    /// The vertices, read back (tests and the benchmarks compare the two evaluators by them;
    /// natively, where reading back can block).
    #[cfg(not(target_arch = "wasm32"))]
    fn read_vertices(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
    ) -> Result<Vec<SurfaceVertex>, GpuError>;
    /// The triangle indices, read back.
    #[cfg(not(target_arch = "wasm32"))]
    fn read_triangle_indices(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
    ) -> Result<Vec<u32>, GpuError>;
}

/// Implements [`VertexEvaluator`] for a type whose inherent methods of the same names and
/// signatures do the work.
macro_rules! vertex_evaluator {
    ($type:ty) => {
        impl VertexEvaluator for $type {
            fn invalidate(&mut self) {
                <$type>::invalidate(self)
            }
            fn needs_evaluation(&self) -> bool {
                <$type>::needs_evaluation(self)
            }
            fn set_vertex_curvature(&mut self, on: bool) {
                <$type>::set_vertex_curvature(self, on)
            }
            fn surface_buffers(&self) -> SurfaceBuffers<'_> {
                <$type>::surface_buffers(self)
            }
            fn records(&self) -> &[PatchRecord] {
                <$type>::records(self)
            }
            fn first_patch(&self, object: usize) -> Option<usize> {
                <$type>::first_patch(self, object)
            }
            fn patch_count(&self) -> u32 {
                <$type>::patch_count(self)
            }
            fn control_point_count(&self) -> u32 {
                <$type>::control_point_count(self)
            }
            fn vertex_count(&self) -> u32 {
                <$type>::vertex_count(self)
            }
            fn index_count(&self) -> u32 {
                <$type>::index_count(self)
            }
            fn buffer_bytes(&self) -> u64 {
                <$type>::buffer_bytes(self)
            }
            #[cfg(not(target_arch = "wasm32"))]
            fn read_vertices(
                &self,
                device: &wgpu::Device,
                queue: &wgpu::Queue,
            ) -> Result<Vec<SurfaceVertex>, GpuError> {
                <$type>::read_vertices(self, device, queue)
            }
            #[cfg(not(target_arch = "wasm32"))]
            fn read_triangle_indices(
                &self,
                device: &wgpu::Device,
                queue: &wgpu::Queue,
            ) -> Result<Vec<u32>, GpuError> {
                <$type>::read_triangle_indices(self, device, queue)
            }
        }
    };
}

vertex_evaluator!(PatchGeometry);
vertex_evaluator!(CpuGeometry);
