// Records shared by Rust and WGSL. The Rust side is src/gpu/records.rs; tests/shader_layouts.rs
// checks, by naga reflection, that both agree member by member. Every other shader in this
// folder is compiled with this file prepended (src/shaders.rs).

// One patch to evaluate (Rust: gpu::records::PatchRecord).
struct PatchRecord {
    degree_u: u32,
    degree_v: u32,
    // First of the patch's (degree_u + 1)(degree_v + 1) entries in control_indices,
    // row-major with i along u.
    control_offset: u32,
    // Vertex (i, j) goes to vertices[vertex_offset + i * (segments_v + 1) + j].
    vertex_offset: u32,
    segments_u: u32,
    segments_v: u32,
    // First of the patch's 6 * segments_u * segments_v triangle indices.
    index_offset: u32,
    // The scene object the patch belongs to (written into every vertex).
    object: u32,
    // (u0, u1, v0, v1): parameter rectangle in the parent surface, used for the written (u, v).
    domain: vec4<f32>,
    // PATCH_KIND_*: what the patch is; pipelines are specialized by it and the degrees.
    kind: u32,
    // The patch's trim loops in a trim buffer: first entry and count (0, 0: untrimmed).
    trim_offset: u32,
    trim_count: u32,
    // 1 + the subdivision level a stencil patch's vertices come from (0: a patch of no level),
    // written into every vertex.
    level: u32,
    // Where the object's displacement block lies in the control point buffer (see
    // DISPLACEMENT_HEADER), or DISPLACEMENT_NONE.
    displacement: u32,
    // Where the object's free-form deformation lattice block lies in the control point buffer
    // (see LATTICE_HEADER), or LATTICE_NONE.
    lattice: u32,
    // A stencil patch whose entries number points of its own: the first of its list of point
    // numbers in control_indices (entry point k is point control_indices[point_list + k]), or
    // POINT_LIST_NONE where the entries number the object's points.
    point_list: u32,
    // A stencil patch's point k is control_points[first_point + k] (its object's first point).
    first_point: u32,
}

// PatchRecord.lattice of a patch whose object has no lattice (Rust: LATTICE_NONE).
const LATTICE_NONE: u32 = 0xFFFFFFFFu;

// PatchRecord.displacement of a patch whose object is not displaced (Rust: DISPLACEMENT_NONE).
const DISPLACEMENT_NONE: u32 = 0xFFFFFFFFu;

// The blocks among the control points (Rust: gpu::packing), in vec4s. A lattice block: the
// header (origin, degrees packed l | m << 8 | n << 16 in the bits of w), the three rows of the
// inverse box, then the points. A displacement block: (pattern code, amplitude, frequency,
// segments per cycle), the object's (u0, u1, v0, v1), then an image's block if it has one. An
// image block: (width, height) as bits, then the grey values four to a vec4.
const LATTICE_HEADER: u32 = 4u;
const DISPLACEMENT_HEADER: u32 = 2u;
const IMAGE_HEADER: u32 = 1u;

// PatchRecord.kind of a rational tensor-product Bézier patch (Rust: PATCH_KIND_BEZIER).
const PATCH_KIND_BEZIER: u32 = 0u;
// PatchRecord.kind of a grid of subdivision limit stencils (Rust: PATCH_KIND_STENCIL_QUAD): slot
// k's (first entry, count) at control_indices[control_offset + 2k], the entries in the control
// point buffer as two vec4 each: (bitcast point, w_p, w_su, w_sv), (w_suu, w_suv, w_svv, 0), the
// point numbered in the object (first_point) or, with a point_list, in the patch's list.
const PATCH_KIND_STENCIL_QUAD: u32 = 1u;
// The same on a triangle: slots (i, j) with i + j <= segments (Rust: PATCH_KIND_STENCIL_TRIANGLE).
const PATCH_KIND_STENCIL_TRIANGLE: u32 = 2u;
// Substitutes of the limit surface (Rust: kernel::subdiv::substitutes), one patch per face, their
// control indices at control_indices[control_offset..]: an ACC patch (16 geometry points, 12 of
// the u-tangent patch, 12 of the v-tangent patch), a Gregory patch (16 grid points, then the
// interior points the edges u = 0 and u = 1 determine for (1, 1), (2, 1), (1, 2), (2, 2)), a PN
// triangle (10 points, 6 normals; on the triangular lattice). Rust: PATCH_KIND_ACC and so on.
const PATCH_KIND_ACC: u32 = 3u;
const PATCH_KIND_GREGORY: u32 = 4u;
const PATCH_KIND_PN_TRIANGLE: u32 = 5u;
// PatchRecord.trim_count of a patch a trim loop crosses (Rust: gpu::trim_buffer::TRIM_PARTIAL)
// and of a patch wholly trimmed away, neither evaluated nor drawn (Rust: TRIM_CULLED).
const TRIM_PARTIAL: u32 = 1u;
const TRIM_CULLED: u32 = 0xFFFFFFFFu;
// Word counts of the packed trim loops (Rust: gpu::trim_buffer).
const TRIM_HEADER_WORDS: u32 = 8u;
const TRIM_CELL_WORDS: u32 = 4u;
const TRIM_PIECE_HEADER_WORDS: u32 = 5u;
// Bit of a stencil slot's count: the curvature is not defined there (Rust: STENCIL_NO_CURVATURE).
const STENCIL_NO_CURVATURE: u32 = 0x80000000u;
// PatchRecord.point_list of a patch whose stencil entries name control points (Rust:
// POINT_LIST_NONE).
const POINT_LIST_NONE: u32 = 0xFFFFFFFFu;

// One tessellation vertex (Rust: gpu::records::SurfaceVertex). 48 bytes: position at 0, u at 12,
// normal at 16, v at 28, (K, H) at 32, record at 40, tag at 44.
struct SurfaceVertex {
    position: vec3<f32>,
    // (u, v) in the parent surface's own domain.
    u: f32,
    normal: vec3<f32>,
    v: f32,
    // (Gaussian K, mean H), positive toward the normal; vertex_curvature gives k1 and k2.
    gaussian_mean: vec2<f32>,
    // The patch record that wrote the vertex (Rust: SurfaceVertex::record).
    record: u32,
    // The scene object (VERTEX_OBJECT_MASK), the record's level (4 bits at VERTEX_LEVEL_SHIFT,
    // for the refinement-level colours) and the flags (4 bits at VERTEX_FLAGS_SHIFT):
    // VERTEX_IRREGULAR (1), the normal is a limit; VERTEX_NO_CURVATURE (2), curvature undefined.
    tag: u32,
}

// Rust: gpu::records::VERTEX_OBJECT_MASK, VERTEX_LEVEL_SHIFT, VERTEX_FLAGS_SHIFT.
const VERTEX_OBJECT_MASK: u32 = 0xFFFFFFu;
const VERTEX_LEVEL_SHIFT: u32 = 24u;
const VERTEX_FLAGS_SHIFT: u32 = 28u;

// A vertex from its parts, `curvature` (K, H, k1, k2) kept as (K, H) (Rust: SurfaceVertex::new).
fn surface_vertex(
    position: vec3<f32>,
    uv: vec2<f32>,
    normal: vec3<f32>,
    curvature: vec4<f32>,
    object: u32,
    flags: u32,
    record: u32,
    level: u32,
) -> SurfaceVertex {
    let tag = (object & VERTEX_OBJECT_MASK) | (min(level, 15u) << VERTEX_LEVEL_SHIFT)
        | ((flags & 15u) << VERTEX_FLAGS_SHIFT);
    return SurfaceVertex(position, uv.x, normal, uv.y, curvature.xy, record, tag);
}

// (K, H, k1, k2) from a vertex's (K, H): k1,2 = H +- sqrt(max(H^2 - K, 0)), within sqrt(eps) |H|
// of the evaluator's near umbilics (Rust: SurfaceVertex::curvature).
fn vertex_curvature(gaussian_mean: vec2<f32>) -> vec4<f32> {
    let k = gaussian_mean.x;
    let h = gaussian_mean.y;
    let root = sqrt(max(h * h - k, 0.0));
    return vec4<f32>(k, h, h + root, h - root);
}

// One parameter for point evaluation (Rust: gpu::records::PointSample): local (s, t) of a patch.
struct PointSample {
    patch_index: u32,
    s: f32,
    t: f32,
    reserved: u32,
}

// What point evaluation writes (Rust: gpu::records::PointResult); derivatives with respect to
// the patch's local (s, t).
struct PointResult {
    point: vec4<f32>,
    normal: vec4<f32>,
    su: vec4<f32>,
    sv: vec4<f32>,
    suu: vec4<f32>,
    suv: vec4<f32>,
    svv: vec4<f32>,
    curvature: vec4<f32>,
    flags: vec4<u32>,
}

// Per-view uniforms of the render pipelines (Rust: gpu::records::SceneUniform).
struct SceneUniform {
    view_proj: mat4x4<f32>,
    eye: vec4<f32>,
    // (width, height, control point radius, 0) in physical pixels.
    viewport: vec4<f32>,
    surface_color: vec4<f32>,
    back_color: vec4<f32>,
    net_color: vec4<f32>,
    point_color: vec4<f32>,
    // (shading mode, selected object + 1 or 0, 0, 0); modes in gpu::records::ShadingMode.
    shading: vec4<u32>,
    // (low, high) of the colour ramp's range, (checker cells per unit of u and v, 0).
    range: vec4<f32>,
    // The colour ramp: RAMP_STOPS linear RGB stops, evenly spaced from low to high.
    ramp: array<vec4<f32>, 5>,
    // The camera's frame in world space: right, up, and back (toward the viewer; w = 1 for an
    // orthographic view, whose view direction is `back` everywhere).
    view_right: vec4<f32>,
    view_up: vec4<f32>,
    view_back: vec4<f32>,
    // (zebra stripe pairs per half turn, zebra stripe angle in radians, isophote spacing in
    // degrees, draft angle threshold in degrees).
    analysis: vec4<f32>,
    // The isophotes' light direction and the draft's pull direction (unit, world; w unused).
    isophote_direction: vec4<f32>,
    pull_direction: vec4<f32>,
    // (zebra frame: 0 the view, 1 the world; zebra source: 0 the reflected view ray, 1 the
    // normal; 0, 0).
    analysis_flags: vec4<u32>,
}

// What the view-adaptive tessellation measures its levels against (Rust:
// gpu::records::AdaptiveView; the rule of gpu::adaptive::ScreenError).
struct AdaptiveView {
    // Clip from world (frustum culling of the control hulls).
    view_proj: mat4x4<f32>,
    // The eye and the unit view direction, world space (w unused).
    eye: vec4<f32>,
    forward: vec4<f32>,
    // (world units per pixel at unit depth or, orthographic, anywhere; the near depth;
    // tolerated error in pixels; longest triangle edge in pixels).
    error: vec4<f32>,
    // (orthographic 0/1, most segments per edge, slot count, vertex capacity).
    counts: vec4<u32>,
    // (index capacity, first adaptive vertex, first adaptive index, 0).
    bases: vec4<u32>,
}

// One view-adaptively tessellated patch (Rust: gpu::records::AdaptiveSlot): its levels as the
// levels pass measures them and, after the scan, as drawn, with its place in the buffers.
struct AdaptiveSlot {
    // Segments of the edges t = 0, s = 1, t = 1, s = 0 (the layout of adaptive.wgsl).
    edges: vec4<u32>,
    // (nu, nv) of the interior grid.
    inner: vec2<u32>,
    // The patch record.
    record: u32,
    // 1 when the control hull lies outside the view: no vertices, no triangles.
    culled: u32,
    vertex_offset: u32,
    index_offset: u32,
    vertex_count: u32,
    triangle_count: u32,
}

const RAMP_STOPS: u32 = 5u;  // Rust: gpu::records::RAMP_STOPS

// 0-1 sRGB-encoded from 0-1 linear (the viewport texture holds encoded values, as egui expects).
fn srgb_from_linear(rgb: vec3<f32>) -> vec3<f32> {
    let c = clamp(rgb, vec3<f32>(0.0), vec3<f32>(1.0));
    let lower = c * 12.92;
    let higher = 1.055 * pow(c, vec3<f32>(1.0 / 2.4)) - 0.055;
    return select(higher, lower, c < vec3<f32>(0.0031308));
}

// One rational Bézier segment of a curve (Rust: gpu::records::CurveRecord): its degree + 1
// homogeneous points from `control_offset` in the curve point pool, sampled at `segments` + 1
// evenly spaced parameters into the curve vertices from `vertex_offset`.
struct CurveRecord {
    degree: u32,
    control_offset: u32,
    vertex_offset: u32,
    segments: u32,
    object: u32,
    reserved0: u32,
    reserved1: u32,
    reserved2: u32,
}

// One sample of a curve (Rust: gpu::records::CurveVertex). `position.w` is 1, or 0 at a
// segment's last sample: no line joins it to the next vertex (the next segment starts at the
// same point, or another curve starts).
struct CurveVertex {
    position: vec4<f32>,
    object: u32,
    // The segment's record and the sample's parameter s in [0, 1] along it.
    record: u32,
    s: f32,
    reserved: u32,
}

const CURVE_MAX_DEGREE: u32 = 32u;  // Rust: gpu::records::CURVE_MAX_DEGREE
const CURVE_WORKGROUP_SIZE: u32 = 64u;  // Rust: gpu::records::CURVE_WORKGROUP_SIZE
