// Draws the evaluated surface from the vertex buffer the compute pass wrote (SurfaceVertex).
// Two-sided: back faces are flipped and tinted, so the inside of an open surface reads as such.

@group(0) @binding(0) var<uniform> scene: SceneUniform;

struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) u: f32,
    @location(2) normal: vec3<f32>,
    @location(3) v: f32,
}

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
}

@vertex
fn vs_surface(in: VertexIn) -> VertexOut {
    var out: VertexOut;
    out.clip = scene.view_proj * vec4<f32>(in.position, 1.0);
    out.world = in.position;
    out.normal = in.normal;
    out.uv = vec2<f32>(in.u, in.v);
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

@fragment
fn fs_surface(in: VertexOut, @builtin(front_facing) front: bool) -> @location(0) vec4<f32> {
    let view_dir = normalize(scene.eye.xyz - in.world);
    var n = normalize(in.normal);
    var base = scene.surface_color.rgb;
    if (!front) {
        n = -n;
        base = scene.back_color.rgb;
    }
    return vec4<f32>(srgb_from_linear(shade(base, n, view_dir)), 1.0);
}
