//! Data shared by Rust and WGSL: one definition per side, checked against each other by
//! `tests/shader_layouts.rs` (naga reflection of `shaders/common.wgsl`).

use bytemuck::{Pod, Zeroable};

/// Highest degree per direction the WGSL Bézier evaluator accepts (`MAX_DEGREE` in
/// `shaders/eval_bezier.wgsl`; its basis arrays hold `GPU_MAX_DEGREE + 1` entries).
pub const GPU_MAX_DEGREE: u32 = 7;

/// Workgroup size of both compute entry points (`WORKGROUP_SIZE` in `shaders/eval_bezier.wgsl`).
pub const EVAL_WORKGROUP_SIZE: u32 = 64;

/// One patch to evaluate. WGSL: `struct PatchRecord` in `shaders/common.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct PatchRecord {
    pub degree_u: u32,
    pub degree_v: u32,
    /// First entry of this patch's (degree_u + 1)(degree_v + 1) indices in the control-index
    /// buffer, row-major with i along u.
    pub control_offset: u32,
    /// First output vertex; the patch writes (segments_u + 1)(segments_v + 1) vertices,
    /// vertex (i, j) at `vertex_offset + i * (segments_v + 1) + j`.
    pub vertex_offset: u32,
    pub segments_u: u32,
    pub segments_v: u32,
    /// First output triangle index; the patch writes 6 · segments_u · segments_v of them.
    pub index_offset: u32,
    /// Reserved (0).
    pub flags: u32,
    /// (u0, u1, v0, v1): the patch's parameter rectangle in its parent surface; the vertex (u, v)
    /// is written in these coordinates.
    pub domain: [f32; 4],
}

/// One tessellation vertex as the compute pass writes it and the render pass reads it.
/// WGSL: `struct SurfaceVertex` in `shaders/common.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct SurfaceVertex {
    pub position: [f32; 3],
    pub u: f32,
    pub normal: [f32; 3],
    pub v: f32,
}

impl SurfaceVertex {
    /// Vertex attributes: position (0), u (1), normal (2), v (3).
    pub const ATTRIBUTES: [wgpu::VertexAttribute; 4] = wgpu::vertex_attr_array![
        0 => Float32x3,
        1 => Float32,
        2 => Float32x3,
        3 => Float32,
    ];

    pub fn layout() -> wgpu::VertexBufferLayout<'static> {
        wgpu::VertexBufferLayout {
            array_stride: std::mem::size_of::<Self>() as wgpu::BufferAddress,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &Self::ATTRIBUTES,
        }
    }
}

/// Per-view uniforms of the render pipelines. WGSL: `struct SceneUniform` in
/// `shaders/common.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct SceneUniform {
    /// Column-major clip-from-world matrix (wgpu depth range 0..1).
    pub view_proj: [[f32; 4]; 4],
    /// Camera position in world space (w = 1).
    pub eye: [f32; 4],
    /// (width, height, control point radius, 0) in physical pixels.
    pub viewport: [f32; 4],
    /// Linear RGBA of the front side of the surface.
    pub surface_color: [f32; 4],
    /// Linear RGBA of the back side of the surface.
    pub back_color: [f32; 4],
    /// Linear RGBA of the control net lines.
    pub net_color: [f32; 4],
    /// Linear RGBA of the control point dots.
    pub point_color: [f32; 4],
}
