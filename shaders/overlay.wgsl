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
