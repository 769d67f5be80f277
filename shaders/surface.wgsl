// Draws the evaluated surface from the vertex buffer the compute pass wrote (SurfaceVertex), in
// one of the shading modes of gpu::records::ShadingMode. Two-sided: back faces are flipped and
// tinted in the lit modes, so the inside of an open surface reads as such. The curvature modes
// colour the per-vertex values of the compute pass (not screen-space derivatives), unlit, so a
// constant curvature reads as one flat colour.

@group(0) @binding(0) var<uniform> scene: SceneUniform;

// Rust: gpu::records::ShadingMode.
const MODE_PLAIN: u32 = 0u;
const MODE_NORMALS: u32 = 1u;
const MODE_CHECKER: u32 = 2u;
const MODE_GAUSSIAN: u32 = 3u;
const MODE_MEAN: u32 = 4u;
const MODE_K1: u32 = 5u;
const MODE_K2: u32 = 6u;

// Rust: gpu::records::VERTEX_NO_CURVATURE.
const VERTEX_NO_CURVATURE: u32 = 2u;

struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) u: f32,
    @location(2) normal: vec3<f32>,
    @location(3) v: f32,
    @location(4) curvature: vec4<f32>,
    @location(5) object: u32,
    @location(6) flags: u32,
    @location(7) record: u32,
}

// One bit per patch record: the patches a drag is changing, drawn tinted (Rust:
// ViewportRenderer::set_highlight).
@group(0) @binding(1) var<storage, read> highlight: array<u32>;
const HIGHLIGHT_COLOR: vec3<f32> = vec3<f32>(0.3, 0.85, 0.45);

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    // The curvature value the mode shows; `defined` is 0 where it is undefined.
    @location(3) value: f32,
    @location(4) defined: f32,
    @location(5) @interpolate(flat) object: u32,
    // 1 on a highlighted patch.
    @location(6) @interpolate(flat) highlighted: u32,
    // The patch's trim grid and the (u, v) in its cell units (trim.wgsl).
    @location(7) @interpolate(flat) trim_grid: vec3<u32>,
    @location(8) trim_cell: vec2<f32>,
}

struct FragmentOut {
    @location(0) color: vec4<f32>,
    // The samples the kept region covers along a trim edge (all of them elsewhere).
    @builtin(sample_mask) mask: u32,
}

@vertex
fn vs_surface(in: VertexIn) -> VertexOut {
    var out: VertexOut;
    out.clip = scene.view_proj * vec4<f32>(in.position, 1.0);
    out.world = in.position;
    out.normal = in.normal;
    out.uv = vec2<f32>(in.u, in.v);
    let mode = scene.shading.x;
    if (mode >= MODE_GAUSSIAN && mode <= MODE_K2) {
        out.value = in.curvature[mode - MODE_GAUSSIAN];
    }
    out.defined = select(1.0, 0.0, (in.flags & VERTEX_NO_CURVATURE) != 0u);
    out.object = in.object;
    let trim = trim_varying(in.record, out.uv);
    out.trim_grid = trim.grid;
    out.trim_cell = trim.cell;
    let word = in.record >> 5u;
    if (word < arrayLength(&highlight)) {
        out.highlighted = (highlight[word] >> (in.record & 31u)) & 1u;
    }
    return out;
}

// Blinn-Phong with a key light that follows the camera, a fill light and a sky/ground ambient.
fn shade(base: vec3<f32>, n: vec3<f32>, view_dir: vec3<f32>) -> vec3<f32> {
    let up = vec3<f32>(0.0, 0.0, 1.0);
    let key = normalize(view_dir + 0.6 * up);
    let fill = normalize(vec3<f32>(-0.5, 0.8, -0.2));
    let ambient = mix(vec3<f32>(0.16, 0.15, 0.14), vec3<f32>(0.30, 0.32, 0.36), 0.5 + 0.5 * n.z);
    let diffuse = 0.75 * max(dot(n, key), 0.0) + 0.2 * max(dot(n, fill), 0.0);
    let h = normalize(key + view_dir);
    let specular = 0.35 * pow(max(dot(n, h), 0.0), 48.0);
    return base * (ambient + diffuse) + vec3<f32>(specular);
}

// The colour ramp at x in [0, 1] (clamped), linear between its evenly spaced stops.
fn ramp_color(x: f32) -> vec3<f32> {
    let f = clamp(x, 0.0, 1.0) * f32(RAMP_STOPS - 1u);
    let k = min(u32(f), RAMP_STOPS - 2u);
    return mix(scene.ramp[k].rgb, scene.ramp[k + 1u].rgb, f - f32(k));
}

// Samples per pixel of the viewport (Rust: render::SAMPLE_COUNT).
const SAMPLE_COUNT: u32 = 4u;

// Trims the fragment (trim.wgsl): discarded outside the kept region, along a trim edge only the
// covered share of the samples is written. Then shades it.
@fragment
fn fs_surface(in: VertexOut, @builtin(front_facing) front: bool) -> FragmentOut {
    // Derivatives first, in uniform control flow.
    let grad_u = vec2<f32>(dpdx(in.uv.x), dpdy(in.uv.x));
    let grad_v = vec2<f32>(dpdx(in.uv.y), dpdy(in.uv.y));
    let coverage = trim_coverage(in.trim_grid, in.trim_cell, in.uv, grad_u, grad_v);
    let samples = u32(round(coverage * f32(SAMPLE_COUNT)));
    if (samples == 0u) {
        discard;
    }
    var out: FragmentOut;
    out.mask = (1u << samples) - 1u;
    out.color = shade_fragment(in, front);
    return out;
}

fn shade_fragment(in: VertexOut, front: bool) -> vec4<f32> {
    let mode = scene.shading.x;
    if (mode >= MODE_GAUSSIAN && mode <= MODE_K2) {
        // Undefined curvature (a degenerate point and its surroundings) is neutral grey.
        if (in.defined < 0.999) {
            return vec4<f32>(srgb_from_linear(vec3<f32>(0.18)), 1.0);
        }
        let span = scene.range.y - scene.range.x;
        let x = select(0.5, (in.value - scene.range.x) / span, span > 0.0);
        return vec4<f32>(srgb_from_linear(ramp_color(x)), 1.0);
    }
    let view_dir = normalize(scene.eye.xyz - in.world);
    var n = normalize(in.normal);
    if (mode == MODE_NORMALS) {
        // The unit normal's components mapped from [-1, 1] to [0, 1] (as the side facing us).
        let facing = select(-n, n, front);
        return vec4<f32>(facing * 0.5 + 0.5, 1.0);
    }
    var base = scene.surface_color.rgb;
    if (in.object + 1u == scene.shading.y) {
        base = mix(base, vec3<f32>(0.95, 0.62, 0.25), 0.35);
    }
    if (in.highlighted != 0u) {
        base = mix(base, HIGHLIGHT_COLOR, 0.45);
    }
    if (mode == MODE_CHECKER) {
        let cell = floor(in.uv * scene.range.zw);
        let odd = (i32(cell.x) + i32(cell.y)) & 1;
        base = select(vec3<f32>(0.85), vec3<f32>(0.12), odd != 0);
    }
    if (!front) {
        n = -n;
        if (mode != MODE_CHECKER) {
            base = scene.back_color.rgb;
        }
    }
    return vec4<f32>(srgb_from_linear(shade(base, n, view_dir)), 1.0);
}
