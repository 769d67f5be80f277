// Module: the shading modes of the surface, shared by the WebGPU pipeline (surface.wgsl) and the
// WebGL2 one (surface_gl.wgsl). The pipeline declares `scene` (group 0, binding 0).

// Rust: gpu::records::ShadingMode.
const MODE_PLAIN: u32 = 0u;
const MODE_NORMALS: u32 = 1u;
const MODE_CHECKER: u32 = 2u;
const MODE_GAUSSIAN: u32 = 3u;
const MODE_MEAN: u32 = 4u;
const MODE_K1: u32 = 5u;
const MODE_K2: u32 = 6u;
const MODE_ZEBRA: u32 = 7u;
const MODE_ISOPHOTES: u32 = 8u;
const MODE_REFLECTION: u32 = 9u;
const MODE_DRAFT: u32 = 10u;
const MODE_LEVEL: u32 = 11u;

// Rust: gpu::records::VERTEX_NO_CURVATURE.
const VERTEX_NO_CURVATURE: u32 = 2u;

const PI: f32 = 3.14159265358979;

// The draft analysis's colours (linear RGB; Rust: render::DRAFT_COLORS): enough draft, too
// little, undercut.
const DRAFT_ENOUGH: vec3<f32> = vec3<f32>(0.10, 0.55, 0.16);
const DRAFT_LITTLE: vec3<f32> = vec3<f32>(0.90, 0.72, 0.08);
const DRAFT_UNDERCUT: vec3<f32> = vec3<f32>(0.80, 0.08, 0.06);

// The refinement-level colours (linear RGB; Rust: render::LEVEL_COLORS): level k in colour k,
// levels past the last in the last.
const LEVEL_COUNT: u32 = 7u;
const LEVEL_COLORS: array<vec3<f32>, 7> = array<vec3<f32>, 7>(
    vec3<f32>(0.55, 0.55, 0.58),
    vec3<f32>(0.10, 0.25, 0.80),
    vec3<f32>(0.05, 0.60, 0.75),
    vec3<f32>(0.15, 0.62, 0.18),
    vec3<f32>(0.85, 0.75, 0.10),
    vec3<f32>(0.90, 0.42, 0.08),
    vec3<f32>(0.80, 0.08, 0.08),
);

// The patch highlight's tint (Rust: ViewportRenderer::set_highlight).
const HIGHLIGHT_COLOR: vec3<f32> = vec3<f32>(0.3, 0.85, 0.45);

// The vertex buffer's layout (Rust: gpu::records::SurfaceVertex::ATTRIBUTES).
struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) u: f32,
    @location(2) normal: vec3<f32>,
    @location(3) v: f32,
    // (K, H): vertex_curvature gives (K, H, k1, k2).
    @location(4) gaussian_mean: vec2<f32>,
    @location(5) record: u32,
    // Object, level (1 + the subdivision level the vertex comes from; 0 for none) and flags
    // (SurfaceVertex::tag in common.wgsl).
    @location(6) tag: u32,
}

fn vertex_object(in: VertexIn) -> u32 {
    return in.tag & VERTEX_OBJECT_MASK;
}

fn vertex_level(in: VertexIn) -> u32 {
    return (in.tag >> VERTEX_LEVEL_SHIFT) & 15u;
}

// 1 where the vertex's curvature is defined, 0 where it is not.
fn vertex_defined(in: VertexIn) -> f32 {
    return select(1.0, 0.0, ((in.tag >> VERTEX_FLAGS_SHIFT) & VERTEX_NO_CURVATURE) != 0u);
}

// The surface at a fragment: point, unit normal (the surface's own orientation) and curvature
// (K, H, k1, k2), `defined` false where the curvature is not.
struct PixelShape {
    point: vec3<f32>,
    normal: vec3<f32>,
    curvature: vec4<f32>,
    defined: bool,
}

// The unit direction from the point toward the eye (the camera's back axis when orthographic).
fn toward_eye(point: vec3<f32>) -> vec3<f32> {
    if (scene.view_back.w > 0.5) {
        return scene.view_back.xyz;
    }
    return normalize(scene.eye.xyz - point);
}

// The stripe coordinate of direction d in the zebra's tube light: the tubes run along
// a = cos(angle) e1 + sin(angle) e2 in the frame (e1, e2, e3) (the view's right, up, back, or
// the world's X, Z, -Y), and the coordinate is d's angle about a, from e3, in units of one
// black and white pair (`pairs` per half turn). The second value cuts the angle on the other
// side (it differs by a whole number of pairs), so that one of the two is smooth everywhere for
// the anti-aliasing width.
fn zebra_coordinates(d: vec3<f32>) -> vec2<f32> {
    var e1 = scene.view_right.xyz;
    var e2 = scene.view_up.xyz;
    var e3 = scene.view_back.xyz;
    if (scene.analysis_flags.x == 1u) {
        e1 = vec3<f32>(1.0, 0.0, 0.0);
        e2 = vec3<f32>(0.0, 0.0, 1.0);
        e3 = vec3<f32>(0.0, -1.0, 0.0);
    }
    let c = cos(scene.analysis.y);
    let s = sin(scene.analysis.y);
    let b = -s * e1 + c * e2;
    let y = dot(d, b);
    let x = dot(d, e3);
    let pairs = scene.analysis.x / PI;
    return vec2<f32>(atan2(y, x) * pairs, atan2(-y, -x) * pairs);
}

// The coordinate whose level lines the mode draws, twice (see zebra_coordinates): zebra the
// stripe coordinate, isophotes the angle between the normal and the light direction in
// spacings, draft the draft angle in degrees.
fn analysis_coordinates(shape: PixelShape, front: bool) -> vec2<f32> {
    let mode = scene.shading.x;
    let facing = select(-shape.normal, shape.normal, front);
    if (mode == MODE_ZEBRA) {
        var d = facing;
        if (scene.analysis_flags.y == 0u) {
            d = reflect(-toward_eye(shape.point), facing);
        }
        return zebra_coordinates(d);
    }
    if (mode == MODE_ISOPHOTES) {
        let cosine = clamp(dot(shape.normal, scene.isophote_direction.xyz), -1.0, 1.0);
        let f = degrees(acos(cosine)) / max(scene.analysis.z, 1e-3);
        return vec2<f32>(f);
    }
    if (mode == MODE_DRAFT) {
        return vec2<f32>(draft_angle(shape.normal));
    }
    return vec2<f32>(0.0);
}

// The draft angle in degrees: 90 minus the angle between the normal and the pull direction
// (positive: the face releases along the pull; negative: undercut).
fn draft_angle(n: vec3<f32>) -> f32 {
    return degrees(asin(clamp(dot(n, scene.pull_direction.xyz), -1.0, 1.0)));
}

// How much of a line about one pixel wide covers a fragment `distance` from it, in a coordinate
// whose screen width (change per pixel) is w.
fn line_coverage(distance: f32, w: f32) -> f32 {
    return clamp(1.0 - distance / max(w, 1e-6), 0.0, 1.0);
}

// line_coverage for the level lines (whole numbers) of coordinate x.
fn level_line(x: f32, w: f32) -> f32 {
    return line_coverage(abs(fract(x + 0.5) - 0.5), w);
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

// `value` on the ramp between scene.range's low and high.
fn ramp_value(value: f32) -> vec3<f32> {
    let span = scene.range.y - scene.range.x;
    return ramp_color(select(0.5, (value - scene.range.x) / span, span > 0.0));
}

// One soft box of the studio: a rectangle of half sizes `half` (in tangents of the angle from
// its centre direction `centre`, along `across` and centre x across) and brightness `power`,
// seen in direction r, with soft edges.
fn soft_box(r: vec3<f32>, centre: vec3<f32>, across: vec3<f32>, half: vec2<f32>, power: f32) -> f32 {
    let facing = dot(r, centre);
    if (facing <= 0.0) {
        return 0.0;
    }
    let a = normalize(across - dot(across, centre) * centre);
    let b = cross(centre, a);
    let p = vec2<f32>(dot(r, a), dot(r, b)) / facing;
    let q = abs(p) - half;
    return power * (1.0 - smoothstep(-0.06, 0.03, max(q.x, q.y)));
}

// A procedural photo studio, fixed to the world (Z up), seen in direction r: a dark floor, a
// graded backdrop and three soft boxes (overhead, key, a strip light behind).
fn studio(r: vec3<f32>) -> vec3<f32> {
    let above = smoothstep(-0.015, 0.015, r.z);
    let floor = vec3<f32>(0.05, 0.048, 0.045) * (1.0 + 0.8 * r.z);
    let backdrop = mix(vec3<f32>(0.42, 0.43, 0.45), vec3<f32>(0.10, 0.11, 0.12), sqrt(max(r.z, 0.0)));
    var c = mix(floor, backdrop, above);
    c += vec3<f32>(soft_box(r, vec3<f32>(0.0, 0.0, 1.0), vec3<f32>(1.0, 0.0, 0.0), vec2<f32>(0.35, 0.9), 3.0));
    c += vec3<f32>(soft_box(r, normalize(vec3<f32>(0.6, -0.7, 0.4)), vec3<f32>(0.0, 0.0, 1.0), vec2<f32>(0.55, 0.3), 2.0));
    c += vec3<f32>(soft_box(r, normalize(vec3<f32>(-0.7, 0.6, 0.25)), vec3<f32>(0.0, 0.0, 1.0), vec2<f32>(0.8, 0.08), 2.5));
    return c;
}

// The colour of a fragment of the surface in the scene's shading mode: `shape` at the fragment,
// `vertex_normal` the vertices' interpolated normal, `uv` its (u, v) in the object's domain,
// `coordinate` and `width` the mode's level coordinate and its change per pixel
// (analysis_coordinates), `front` whether the front face is seen, `level` 1 + the subdivision
// level the vertices come from (0: none), `own_color` the object's own colour (linear RGB; w = 0
// where it has none, and the scene's surface colour is used).
fn shade_fragment(
    shape: PixelShape,
    vertex_normal: vec3<f32>,
    uv: vec2<f32>,
    object: u32,
    own_color: vec4<f32>,
    level: u32,
    highlighted: bool,
    coordinate: f32,
    width: f32,
    front: bool,
) -> vec4<f32> {
    let mode = scene.shading.x;
    if (mode >= MODE_GAUSSIAN && mode <= MODE_K2) {
        // Undefined curvature (a degenerate point and its surroundings) is neutral grey.
        if (!shape.defined) {
            return vec4<f32>(srgb_from_linear(vec3<f32>(0.18)), 1.0);
        }
        return vec4<f32>(srgb_from_linear(ramp_value(shape.curvature[mode - MODE_GAUSSIAN])), 1.0);
    }
    let view_dir = toward_eye(shape.point);
    let facing = select(-shape.normal, shape.normal, front);
    if (mode == MODE_ZEBRA) {
        // White where the stripe coordinate's fraction is within a quarter of a half.
        let distance = 0.25 - abs(fract(coordinate) - 0.5);
        let white = clamp(distance / max(width, 1e-6) + 0.5, 0.0, 1.0);
        let lit = 0.8 + 0.2 * abs(dot(facing, view_dir));
        return vec4<f32>(srgb_from_linear(vec3<f32>(mix(0.02, 0.92, white) * lit)), 1.0);
    }
    if (mode == MODE_ISOPHOTES) {
        let angle = coordinate * scene.analysis.z;
        let band = ramp_value(angle);
        let line = level_line(coordinate, width);
        let lit = shade(band, facing, view_dir);
        return vec4<f32>(srgb_from_linear(mix(lit, vec3<f32>(0.01), line)), 1.0);
    }
    if (mode == MODE_REFLECTION) {
        let r = reflect(-view_dir, facing);
        let env = studio(r);
        let fresnel = 0.35 + 0.65 * pow(1.0 - max(dot(facing, view_dir), 0.0), 5.0);
        let base = 0.35 * shade(scene.surface_color.rgb * 0.6, facing, view_dir);
        let c = base + mix(0.55, 1.0, fresnel) * env;
        return vec4<f32>(srgb_from_linear(c / (1.0 + 0.25 * c)), 1.0);
    }
    if (mode == MODE_DRAFT) {
        let threshold = scene.analysis.w;
        var base = DRAFT_ENOUGH;
        if (coordinate < threshold) {
            base = DRAFT_LITTLE;
        }
        if (coordinate < 0.0) {
            base = DRAFT_UNDERCUT;
        }
        let lit = shade(base, facing, view_dir);
        // Lines at 0 degrees (the parting line) and at the threshold.
        let zero = line_coverage(abs(coordinate), width);
        let at_threshold = line_coverage(abs(coordinate - threshold), width);
        return vec4<f32>(srgb_from_linear(mix(lit, vec3<f32>(0.01), max(zero, at_threshold))), 1.0);
    }
    var n = normalize(vertex_normal);
    if (mode == MODE_NORMALS) {
        // The unit normal's components mapped from [-1, 1] to [0, 1] (as the side facing us).
        let facing_n = select(-n, n, front);
        return vec4<f32>(facing_n * 0.5 + 0.5, 1.0);
    }
    var base = scene.surface_color.rgb;
    if (own_color.w > 0.5) {
        base = own_color.rgb;
    }
    if (object + 1u == scene.shading.y) {
        base = mix(base, vec3<f32>(0.95, 0.62, 0.25), 0.35);
    }
    if (highlighted) {
        base = mix(base, HIGHLIGHT_COLOR, 0.45);
    }
    if (mode == MODE_CHECKER) {
        let cell = floor(uv * scene.range.zw);
        let odd = (i32(cell.x) + i32(cell.y)) & 1;
        base = select(vec3<f32>(0.85), vec3<f32>(0.12), odd != 0);
    }
    if (mode == MODE_LEVEL && level > 0u) {
        base = LEVEL_COLORS[min(level - 1u, LEVEL_COUNT - 1u)];
    }
    if (!front) {
        n = -n;
        if (mode != MODE_CHECKER) {
            base = scene.back_color.rgb;
        }
    }
    return vec4<f32>(srgb_from_linear(shade(base, n, view_dir)), 1.0);
}
