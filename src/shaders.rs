//! The WGSL sources in `shaders/`, embedded at compile time.
//!
//! WGSL has no include mechanism: every pipeline's file is compiled with `common.wgsl` (the
//! structs shared with Rust) and the modules it names prepended, by [`compose`]. A module holds
//! WGSL shared by several passes (`diffgeo.wgsl`: normals and curvature from derivatives).

/// Structs and helpers shared by every pipeline.
pub const COMMON: &str = include_str!("../shaders/common.wgsl");
/// Module: differential geometry from partial derivatives (normals, curvature).
pub const DIFFGEO: &str = include_str!("../shaders/diffgeo.wgsl");
/// Module: rational Bézier patch derivatives (the compute pass and the per-pixel analysis).
pub const BEZIER: &str = include_str!("../shaders/bezier.wgsl");
/// Module: the crack-free vertex and triangle layout of a view-adaptively tessellated patch.
pub const ADAPTIVE: &str = include_str!("../shaders/adaptive.wgsl");
/// Module: per-fragment trimming against the packed trim loops.
pub const TRIM: &str = include_str!("../shaders/trim.wgsl");
/// Lists the evaluator's part files once: [`EVAL_BEZIER`] joins them, [`EVAL_PARTS`] names them.
macro_rules! evaluator_parts {
    ($($file:literal),+ $(,)?) => {
        /// Compute: the evaluator's body (rational Bézier patch evaluation into vertices and
        /// triangle indices), its parts joined in order.
        pub const EVAL_BEZIER: &str =
            concat!($(include_str!(concat!("../shaders/", $file)), "\n"),+);
        /// The evaluator's parts by file name, in the order [`EVAL_BEZIER`] joins them.
        pub const EVAL_PARTS: &[(&str, &str)] =
            &[$(($file, include_str!(concat!("../shaders/", $file)))),+];
    };
}

// Patch evaluation and vertices, crack-free edges, the fixed grid, the view-adaptive passes.
evaluator_parts!(
    "eval_bezier.wgsl",
    "eval_edges.wgsl",
    "eval_grid.wgsl",
    "eval_adaptive.wgsl",
);

/// Module: displacement along the normal (patterns, height images, the displaced normal).
pub const DISPLACE: &str = include_str!("../shaders/displace.wgsl");
/// Module: free-form deformation by a trivariate Bézier lattice (its map and derivatives).
pub const LATTICE: &str = include_str!("../shaders/lattice.wgsl");
/// Module: the efficient substitutes of a subdivision surface (ACC, Gregory, PN triangles).
pub const SUBSTITUTES: &str = include_str!("../shaders/substitutes.wgsl");
/// Module: the surface's shading modes (both surface pipelines).
pub const SHADING: &str = include_str!("../shaders/shading.wgsl");
/// Render: the shaded surface (WebGPU: storage buffers, per-fragment analysis and trims).
pub const SURFACE: &str = include_str!("../shaders/surface.wgsl");
/// Render: the shaded surface on WebGL2 (no storage buffers).
pub const SURFACE_GL: &str = include_str!("../shaders/surface_gl.wgsl");
/// Compute: curve evaluation (rational Bézier segments into line-strip vertices).
pub const EVAL_CURVES: &str = include_str!("../shaders/eval_curves.wgsl");
/// Render: control net lines and control point dots.
pub const OVERLAY: &str = include_str!("../shaders/overlay.wgsl");

/// A pipeline's shader: its file, its body and the modules it uses (after `common.wgsl`).
#[derive(Debug, Clone, Copy)]
pub struct PipelineShader {
    pub name: &'static str,
    pub body: &'static str,
    pub modules: &'static [&'static str],
}

/// Every module by file name (each composed after `common.wgsl`).
pub const MODULES: [(&str, &str); 8] = [
    ("diffgeo.wgsl", DIFFGEO),
    ("substitutes.wgsl", SUBSTITUTES),
    ("bezier.wgsl", BEZIER),
    ("trim.wgsl", TRIM),
    ("adaptive.wgsl", ADAPTIVE),
    ("shading.wgsl", SHADING),
    ("displace.wgsl", DISPLACE),
    ("lattice.wgsl", LATTICE),
];

/// The evaluator's control point buffer, for modules that read blocks from it.
const CONTROL_POINTS_BINDING: &str =
    "@group(0) @binding(0) var<storage, read> control_points: array<vec4<f32>>;";

/// What a module needs from the pipeline that composes it, for validating the module on its
/// own: the modules before it and a stand-in for the functions the pipeline supplies.
pub fn module_host(name: &str) -> (&'static [&'static str], &'static str) {
    match name {
        "bezier.wgsl" => (
            &[DIFFGEO],
            "fn control_point(rec: PatchRecord, k: u32) -> vec4<f32> { return vec4<f32>(f32(k)); }",
        ),
        "substitutes.wgsl" => (&[DIFFGEO], ""),
        "displace.wgsl" => (&[DIFFGEO], CONTROL_POINTS_BINDING),
        "lattice.wgsl" => (&[], CONTROL_POINTS_BINDING),
        "shading.wgsl" => (
            &[],
            "@group(0) @binding(0) var<uniform> scene: SceneUniform;",
        ),
        _ => (&[], ""),
    }
}

/// The compute evaluator.
pub const EVAL_BEZIER_SHADER: PipelineShader = PipelineShader {
    name: "eval_bezier.wgsl",
    body: EVAL_BEZIER,
    modules: &[DIFFGEO, BEZIER, ADAPTIVE, SUBSTITUTES, DISPLACE, LATTICE],
};
/// The surface render pipeline.
pub const SURFACE_SHADER: PipelineShader = PipelineShader {
    name: "surface.wgsl",
    body: SURFACE,
    modules: &[DIFFGEO, BEZIER, TRIM, SHADING],
};
/// The surface render pipeline of devices without storage buffers (WebGL2).
pub const SURFACE_GL_SHADER: PipelineShader = PipelineShader {
    name: "surface_gl.wgsl",
    body: SURFACE_GL,
    modules: &[SHADING],
};
/// The control net overlay.
pub const OVERLAY_SHADER: PipelineShader = PipelineShader {
    name: "overlay.wgsl",
    body: OVERLAY,
    modules: &[],
};

/// The curve evaluator.
pub const EVAL_CURVES_SHADER: PipelineShader = PipelineShader {
    name: "eval_curves.wgsl",
    body: EVAL_CURVES,
    modules: &[],
};

/// Every pipeline shader.
pub const PIPELINE_SHADERS: [PipelineShader; 5] = [
    EVAL_BEZIER_SHADER,
    EVAL_CURVES_SHADER,
    SURFACE_SHADER,
    SURFACE_GL_SHADER,
    OVERLAY_SHADER,
];

/// The complete source of a pipeline shader: `common.wgsl`, its modules, then its body.
pub fn compose(shader: &PipelineShader) -> String {
    compose_parts(shader.modules, shader.body)
}

/// `common.wgsl`, then `modules`, then `body`.
pub fn compose_parts(modules: &[&str], body: &str) -> String {
    let mut source = String::from(COMMON);
    for module in modules {
        source.push('\n');
        source.push_str(module);
    }
    source.push('\n');
    source.push_str(body);
    source
}

/// A wgpu shader module of a pipeline shader.
pub fn create_module(device: &wgpu::Device, shader: &PipelineShader) -> wgpu::ShaderModule {
    device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(shader.name),
        source: wgpu::ShaderSource::Wgsl(compose(shader).into()),
    })
}
