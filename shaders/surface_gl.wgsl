// Draws the surface where the device has no storage buffers and no compute shaders (WebGL2,
// wgpu's GL backend): the CPU evaluator wrote the vertex buffer (gpu::cpu_eval), in the layout
// the compute pass writes. The shading modes are those of surface.wgsl (shading.wgsl), with the
// normal and curvature interpolated from the vertices in every mode: no per-fragment patch
// evaluation (it needs the control points in storage buffers) and no per-fragment trimming (the
// CPU evaluator drops the trimmed triangles). No sample mask either (GLSL ES 3.0 has none).

@group(0) @binding(0) var<uniform> scene: SceneUniform;

// One bit per patch record, the first 32768 records (Rust: render::GL_HIGHLIGHT_WORDS): the
// patches a drag is changing, drawn tinted. A uniform: WebGL2 has no storage buffers.
@group(0) @binding(1) var<uniform> highlight: array<vec4<u32>, 256>;

// The first 256 scene objects' own colours (linear RGB, w = 1) or none (w = 0) (Rust:
// ViewportRenderer::set_object_colors, GL_OBJECT_COLORS).
@group(0) @binding(2) var<uniform> object_colors: array<vec4<f32>, 256>;

fn object_color(object: u32) -> vec4<f32> {
    if (object < 256u) {
        return object_colors[object];
    }
    return vec4<f32>(0.0);
}

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    // The vertices' (K, H, k1, k2); `defined` is 0 where it is undefined.
    @location(3) curvature: vec4<f32>,
    @location(4) defined: f32,
    @location(5) @interpolate(flat) object: u32,
    // 1 on a highlighted patch.
    @location(6) @interpolate(flat) highlighted: u32,
    // 1 + the subdivision level of the patch (0: none).
    @location(7) @interpolate(flat) level: u32,
}

@vertex
fn vs_surface_gl(in: VertexIn) -> VertexOut {
    var out: VertexOut;
    out.clip = scene.view_proj * vec4<f32>(in.position, 1.0);
    out.world = in.position;
    out.normal = in.normal;
    out.uv = vec2<f32>(in.u, in.v);
    out.curvature = vertex_curvature(in.gaussian_mean);
    out.defined = vertex_defined(in);
    out.object = vertex_object(in);
    out.level = vertex_level(in);
    let word = in.record >> 5u;
    if (word < 1024u) {
        let bits = highlight[word >> 2u][word & 3u];
        out.highlighted = (bits >> (in.record & 31u)) & 1u;
    }
    return out;
}

@fragment
fn fs_surface_gl(in: VertexOut, @builtin(front_facing) front: bool) -> @location(0) vec4<f32> {
    var shape: PixelShape;
    shape.point = in.world;
    shape.normal = normalize(in.normal);
    shape.curvature = in.curvature;
    shape.defined = in.defined > 0.999;
    let coordinates = analysis_coordinates(shape, front);
    let widths = vec2<f32>(fwidth(coordinates.x), fwidth(coordinates.y));
    return shade_fragment(
        shape,
        in.normal,
        in.uv,
        in.object,
        object_color(in.object),
        in.level,
        in.highlighted != 0u,
        coordinates.x,
        min(widths.x, widths.y),
        front,
    );
}
