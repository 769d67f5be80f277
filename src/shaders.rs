//! The WGSL sources in `shaders/`, embedded at compile time.
//!
//! WGSL has no include mechanism: every pipeline's file is compiled with `common.wgsl` (the
//! structs shared with Rust) prepended, by [`compose`].

/// Structs and helpers shared by every pipeline.
pub const COMMON: &str = include_str!("../shaders/common.wgsl");
/// Compute: rational Bézier patch evaluation and triangle indices.
pub const EVAL_BEZIER: &str = include_str!("../shaders/eval_bezier.wgsl");
/// Render: the shaded surface.
pub const SURFACE: &str = include_str!("../shaders/surface.wgsl");
/// Render: control net lines and control point dots.
pub const OVERLAY: &str = include_str!("../shaders/overlay.wgsl");

/// Every pipeline shader by file name (without `common.wgsl`, which each of them includes).
pub const PIPELINE_SHADERS: [(&str, &str); 3] = [
    ("eval_bezier.wgsl", EVAL_BEZIER),
    ("surface.wgsl", SURFACE),
    ("overlay.wgsl", OVERLAY),
];

/// The complete source of a pipeline shader: `common.wgsl` followed by `body`.
pub fn compose(body: &str) -> String {
    format!("{COMMON}\n{body}")
}

/// A wgpu shader module from a pipeline shader's body.
pub fn create_module(device: &wgpu::Device, label: &str, body: &str) -> wgpu::ShaderModule {
    device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(label),
        source: wgpu::ShaderSource::Wgsl(compose(body).into()),
    })
}
