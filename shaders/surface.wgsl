// Draws the evaluated surface from the vertex buffer the compute pass wrote (SurfaceVertex), in
// one of the shading modes of gpu::records::ShadingMode. Two-sided: back faces are flipped and
// tinted in the lit modes, so the inside of an open surface reads as such.
//
// The analysis modes (curvature K, H, k1, k2, zebra, isophotes, reflection, draft angle) do not
// interpolate the vertices: each fragment evaluates its own Bézier patch at its (u, v)
// (bezier.wgsl, the same formulas as the compute pass) and takes the normal and curvature from
// those derivatives, so stripes and colours are exact at any zoom and independent of the
// tessellation. Fragments of subdivision stencil patches, and the rare degenerate point where
// Su x Sv vanishes, fall back to the vertices' interpolated limit values.

@group(0) @binding(0) var<uniform> scene: SceneUniform;

// Group 1 (with trim.wgsl's bindings 0 and 1): the control point pool and the patches' control
// indices, as the compute pass reads them.
@group(1) @binding(2) var<storage, read> surface_points: array<vec4<f32>>;
@group(1) @binding(3) var<storage, read> surface_indices: array<u32>;

fn control_point(rec: PatchRecord, k: u32) -> vec4<f32> {
    return surface_points[surface_indices[rec.control_offset + k]];
}

// One bit per patch record: the patches a drag is changing, drawn tinted (Rust:
// ViewportRenderer::set_highlight).
@group(0) @binding(1) var<storage, read> highlight: array<u32>;

// Per scene object: its own colour (linear RGB, w = 1) or none (w = 0) (Rust:
// ViewportRenderer::set_object_colors).
@group(0) @binding(2) var<storage, read> object_colors: array<vec4<f32>>;

fn object_color(object: u32) -> vec4<f32> {
    if (object < arrayLength(&object_colors)) {
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
    // The patch's trim grid and the (u, v) in its cell units (trim.wgsl).
    @location(7) @interpolate(flat) trim_grid: vec3<u32>,
    @location(8) trim_cell: vec2<f32>,
    // The patch record the vertex came from.
    @location(9) @interpolate(flat) record: u32,
    // 1 + the subdivision level of the patch (0: none).
    @location(10) @interpolate(flat) level: u32,
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
    out.curvature = vertex_curvature(in.gaussian_mean);
    out.record = in.record;
    out.level = vertex_level(in);
    out.defined = vertex_defined(in);
    out.object = vertex_object(in);
    if (TRIMMED) {
        let trim = trim_varying(in.record, out.uv);
        out.trim_grid = trim.grid;
        out.trim_cell = trim.cell;
    }
    let word = in.record >> 5u;
    if (word < arrayLength(&highlight)) {
        out.highlighted = (highlight[word] >> (in.record & 31u)) & 1u;
    }
    return out;
}

// Samples per pixel of the viewport: set per pipeline to the target's, 1 or 4 (Rust:
// render::ViewTarget::samples; the default is render::SAMPLE_COUNT).
override SAMPLE_COUNT: u32 = 4u;

// Set per pipeline (render::viewport): whether the pipeline evaluates the patches per fragment
// (the analysis modes) and whether it trims. A pipeline compiled without them is the plain
// shader: on software rasterizers (lavapipe, SwiftShader) the code of those paths slows every
// fragment even where it never runs.
override PER_PIXEL: bool = true;
override TRIMMED: bool = true;

// Whether the mode evaluates the surface per fragment.
fn per_pixel(mode: u32) -> bool {
    return mode >= MODE_GAUSSIAN && mode <= MODE_DRAFT;
}

// The fragment's shape: in the analysis modes, from its Bézier patch's derivatives at its
// (u, v); else (and where that fails) interpolated from the vertices.
fn pixel_shape(in: VertexOut) -> PixelShape {
    var out: PixelShape;
    out.point = in.world;
    out.normal = normalize(in.normal);
    out.curvature = in.curvature;
    out.defined = in.defined > 0.999;
    if (!PER_PIXEL || !per_pixel(scene.shading.x)) {
        return out;
    }
    let rec = trim_records[in.record];
    // Stencil and substitute patches and displaced objects: the vertices' values.
    if (rec.kind != PATCH_KIND_BEZIER || rec.displacement != DISPLACEMENT_NONE || rec.lattice != LATTICE_NONE) {
        return out;
    }
    let span = rec.domain.yw - rec.domain.xz;
    let local = select(vec2<f32>(0.0), (in.uv - rec.domain.xz) / span, span != vec2<f32>(0.0));
    let st = clamp(local, vec2<f32>(0.0), vec2<f32>(1.0));
    let d = evaluate_bezier_patch(rec, st.x, st.y);
    let n = regular_normal(d);
    if (all(n == vec3<f32>(0.0))) {
        return out;
    }
    out.point = d.point;
    out.normal = n;
    let k = curvature(d, n);
    out.curvature = k.values;
    out.defined = k.defined;
    return out;
}

// Trims the fragment (trim.wgsl): discarded outside the kept region, along a trim edge only the
// covered share of the samples is written. Then shades it.
@fragment
fn fs_surface(in: VertexOut, @builtin(front_facing) front: bool) -> FragmentOut {
    // Derivatives first, in uniform control flow.
    let grad_u = vec2<f32>(dpdx(in.uv.x), dpdy(in.uv.x));
    let grad_v = vec2<f32>(dpdx(in.uv.y), dpdy(in.uv.y));
    let shape = pixel_shape(in);
    let coordinates = analysis_coordinates(shape, front);
    let widths = vec2<f32>(fwidth(coordinates.x), fwidth(coordinates.y));
    var coverage = 1.0;
    if (TRIMMED) {
        coverage = trim_coverage(in.trim_grid, in.trim_cell, in.uv, grad_u, grad_v);
    }
    let samples = u32(round(coverage * f32(SAMPLE_COUNT)));
    if (samples == 0u) {
        discard;
    }
    var out: FragmentOut;
    out.mask = (1u << samples) - 1u;
    out.color = shade_fragment(
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
    return out;
}
