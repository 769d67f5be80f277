// Control net overlay: the net's lines and a round dot per control point, drawn on top of the
// surface. Both read the control point buffer (homogeneous (wx, wy, wz, w)) as vertex data.

@group(0) @binding(0) var<uniform> scene: SceneUniform;

@vertex
fn vs_net(@location(0) homogeneous: vec4<f32>) -> @builtin(position) vec4<f32> {
    return scene.view_proj * vec4<f32>(homogeneous.xyz / homogeneous.w, 1.0);
}

@fragment
fn fs_net() -> @location(0) vec4<f32> {
    return vec4<f32>(srgb_from_linear(scene.net_color.rgb), scene.net_color.a);
}

struct DotOut {
    @builtin(position) clip: vec4<f32>,
    // Offset from the dot's centre in pixels.
    @location(0) offset: vec2<f32>,
    // 1 for a selected point (written with w = 2 by ControlNet), else 0.
    @location(1) selected: f32,
}

// Selected control points: orange, as in Blender.
const SELECTED_POINT_COLOR: vec3<f32> = vec3<f32>(1.0, 0.45, 0.05);

// One instance per control point, four vertices (a triangle strip) per instance.
@vertex
fn vs_dot(@builtin(vertex_index) corner: u32, @location(0) homogeneous: vec4<f32>) -> DotOut {
    let radius = scene.viewport.z * select(1.0, 1.4, homogeneous.w > 1.5);
    let unit = vec2<f32>(f32(corner & 1u), f32(corner >> 1u)) * 2.0 - 1.0;
    let offset = unit * (radius + 1.0);
    var out: DotOut;
    let centre = scene.view_proj * vec4<f32>(homogeneous.xyz / homogeneous.w, 1.0);
    out.clip = centre + vec4<f32>(offset * 2.0 / scene.viewport.xy * centre.w, 0.0, 0.0);
    out.offset = offset;
    out.selected = select(0.0, 1.0, homogeneous.w > 1.5);
    return out;
}

@fragment
fn fs_dot(in: DotOut) -> @location(0) vec4<f32> {
    let radius = scene.viewport.z * mix(1.0, 1.4, in.selected);
    let r = length(in.offset);
    // Anti-aliased disc with a dark rim.
    let coverage = clamp(radius + 0.5 - r, 0.0, 1.0);
    if (coverage <= 0.0) {
        discard;
    }
    let rim = smoothstep(radius - 1.5, radius - 0.5, r);
    let base = mix(scene.point_color.rgb, SELECTED_POINT_COLOR, in.selected);
    let rgb = mix(base, vec3<f32>(0.02), rim);
    return vec4<f32>(srgb_from_linear(rgb), coverage * scene.point_color.a);
}

// Guide and analysis lines (Rust: render::LineVertex): the ground grid (depth tested), curvature
// combs, principal directions and continuity hair (on top), each vertex with its own colour.
struct LineOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) color: vec4<f32>,
}

@vertex
fn vs_lines(@location(0) position: vec4<f32>, @location(1) color: vec4<f32>) -> LineOut {
    var out: LineOut;
    out.clip = scene.view_proj * vec4<f32>(position.xyz, 1.0);
    out.color = color;
    return out;
}

@fragment
fn fs_lines(in: LineOut) -> @location(0) vec4<f32> {
    return vec4<f32>(srgb_from_linear(in.color.rgb), in.color.a);
}

// Curves (Rust: gpu::records::CurveVertex, evaluated by eval_curves.wgsl): one instance per
// pair of consecutive curve vertices, a screen-aligned quad of CURVE_HALF_WIDTH pixels each side
// of the line plus one pixel of anti-aliasing, drawn depth tested and pulled slightly toward the
// viewer (so that a curve lying on a surface stays visible). A pair whose first vertex ends a
// segment (w = 0) draws nothing.
struct CurveOut {
    @builtin(position) clip: vec4<f32>,
    // Signed distance from the centre line in pixels.
    @location(0) across: f32,
    @location(1) @interpolate(flat) selected: u32,
}

// Half the line width in pixels.
const CURVE_HALF_WIDTH: f32 = 1.1;
// The curve's ink (linear RGB): light, over the dark background.
const CURVE_COLOR: vec3<f32> = vec3<f32>(0.78, 0.82, 0.9);
// How far toward the viewer a curve is pulled, in clip-space depth per unit of w.
const CURVE_DEPTH_PULL: f32 = 0.0004;

@vertex
fn vs_curve(
    @builtin(vertex_index) corner: u32,
    @location(0) a: vec4<f32>,
    @location(1) object: u32,
    @location(2) b: vec4<f32>,
) -> CurveOut {
    var out: CurveOut;
    // Outside the clip volume: nothing is drawn.
    out.clip = vec4<f32>(2.0, 2.0, 2.0, 1.0);
    out.across = 0.0;
    out.selected = 0u;
    let ca = scene.view_proj * vec4<f32>(a.xyz, 1.0);
    let cb = scene.view_proj * vec4<f32>(b.xyz, 1.0);
    if (a.w < 0.5 || ca.w <= 1e-6 || cb.w <= 1e-6) {
        return out;
    }
    let half_size = scene.viewport.xy * 0.5;
    let sa = ca.xy / ca.w * half_size;
    let sb = cb.xy / cb.w * half_size;
    let chord = sb - sa;
    let length_px = length(chord);
    let along = select(vec2<f32>(1.0, 0.0), chord / length_px, length_px > 1e-6);
    let normal = vec2<f32>(-along.y, along.x);
    let reach = CURVE_HALF_WIDTH + 1.0;
    let side = f32(corner & 1u) * 2.0 - 1.0;
    let at_b = (corner >> 1u) == 1u;
    let c = select(ca, cb, at_b);
    // Each end reaches half a width past its vertex, so consecutive quads overlap at a joint.
    let offset = normal * side * reach + along * select(-0.5, 0.5, at_b) * reach;
    out.clip = vec4<f32>(
        c.xy + offset / half_size * c.w,
        c.z - CURVE_DEPTH_PULL * c.w,
        c.w,
    );
    out.across = side * reach;
    out.selected = select(0u, 1u, object + 1u == scene.shading.y);
    return out;
}

@fragment
fn fs_curve(in: CurveOut) -> @location(0) vec4<f32> {
    let coverage = clamp(CURVE_HALF_WIDTH + 0.5 - abs(in.across), 0.0, 1.0);
    if (coverage <= 0.0) {
        discard;
    }
    let rgb = select(CURVE_COLOR, SELECTED_POINT_COLOR, in.selected == 1u);
    return vec4<f32>(srgb_from_linear(rgb), coverage);
}
