// Module: displacement along the normal (the Rust reference: kernel::displace). The object's
// displacement block lies in the control point buffer (DISPLACEMENT_HEADER in common.wgsl;
// Rust: gpu::packing::displacement_block): the pattern's code, amplitude, frequency and
// segments per cycle, the object's (u0, u1, v0, v1), then a height image's block. Needs
// diffgeo.wgsl and the pipeline's `control_points`.

// Codes of the displacement patterns (Rust: gpu::packing::pattern_code).
const DISPLACE_WAVES: u32 = 1u;
const DISPLACE_RIPPLES: u32 = 2u;
const DISPLACE_NOISE: u32 = 3u;
const DISPLACE_IMAGE: u32 = 4u;
const TAU: f32 = 6.28318530718;

// The uniform cubic B-spline's weights at t in [0, 1) for the points i - 1 .. i + 2, and their
// derivatives (kernel::displace::cubic_bspline).
fn cubic_bspline_weights(t: f32) -> vec4<f32> {
    let s = 1.0 - t;
    return vec4<f32>(
        s * s * s,
        3.0 * t * t * t - 6.0 * t * t + 4.0,
        -3.0 * t * t * t + 3.0 * t * t + 3.0 * t + 1.0,
        t * t * t,
    ) / 6.0;
}

fn cubic_bspline_slopes(t: f32) -> vec4<f32> {
    let s = 1.0 - t;
    return vec4<f32>(-s * s, 3.0 * t * t - 4.0 * t, -3.0 * t * t + 2.0 * t + 1.0, t * t) / 2.0;
}

// The grey of pixel (i, j) (column, row from the top) of the height image at `base` (header
// (width, height) as bits, then the values four to a word), the image repeating.
fn image_value(base: u32, width: i32, height: i32, i: i32, j: i32) -> f32 {
    let x = ((i % width) + width) % width;
    let y = ((j % height) + height) % height;
    let k = u32(y * width + x);
    return control_points[base + IMAGE_HEADER + k / 4u][k % 4u];
}

// The tiled height image's smooth grey and its derivatives (g, g_x, g_y) at tile coordinates
// (x, y) (kernel::displace::HeightImage::sample).
fn image_height(base: u32, x: f32, y: f32) -> vec3<f32> {
    let header = control_points[base];
    let width = i32(bitcast<u32>(header.x));
    let height = i32(bitcast<u32>(header.y));
    let px = fract(x) * f32(width);
    let py = fract(1.0 - y) * f32(height);
    let fi = floor(px);
    let fj = floor(py);
    let bx = cubic_bspline_weights(px - fi);
    let dx = cubic_bspline_slopes(px - fi);
    let by = cubic_bspline_weights(py - fj);
    let dy = cubic_bspline_slopes(py - fj);
    var out = vec3<f32>(0.0);
    for (var b = 0; b < 4; b++) {
        for (var a = 0; a < 4; a++) {
            let g = image_value(base, width, height, i32(fi) + a - 1, i32(fj) + b - 1);
            out += g * vec3<f32>(bx[a] * by[b], dx[a] * by[b], bx[a] * dy[b]);
        }
    }
    return vec3<f32>(out.x, out.y * f32(width), -out.z * f32(height));
}

// The noise lattice's value at (i, j) in [-1, 1]: the same integer hash as
// kernel::displace::lattice_value.
fn lattice_value(i: i32, j: i32) -> f32 {
    var h = (bitcast<u32>(i) * 0x8da6b343u) ^ (bitcast<u32>(j) * 0xd8163841u);
    h = h ^ (h >> 15u);
    h = h * 0x2c1b3c6du;
    h = h ^ (h >> 12u);
    h = h * 0x297a2d39u;
    h = h ^ (h >> 15u);
    return f32(h & 0xffffu) / 32767.5 - 1.0;
}

// The quintic fade 6t^5 - 15t^4 + 10t^3 and its derivative.
fn fade(t: f32) -> vec2<f32> {
    return vec2<f32>(t * t * t * (t * (t * 6.0 - 15.0) + 10.0), 30.0 * t * t * (t * (t - 2.0) + 1.0));
}

// The height h and (h_x, h_y) of pattern `code` at frequency f and normalized (x, y)
// (kernel::displace::Displacement::height); an image's words start at `image`.
fn displacement_height(code: u32, f: f32, x: f32, y: f32, image: u32) -> vec3<f32> {
    let w = TAU * f;
    if (code == DISPLACE_IMAGE) {
        let g = image_height(image, x * f, y * f);
        return vec3<f32>(2.0 * g.x - 1.0, 2.0 * g.y * f, 2.0 * g.z * f);
    }
    if (code == DISPLACE_WAVES) {
        let sx = sin(w * x);
        let cx = cos(w * x);
        let sy = sin(w * y);
        let cy = cos(w * y);
        return vec3<f32>(sx * sy, w * cx * sy, w * sx * cy);
    }
    if (code == DISPLACE_RIPPLES) {
        let dx = x - 0.5;
        let dy = y - 0.5;
        let r = sqrt(dx * dx + dy * dy);
        let c = cos(w * r);
        if (r == 0.0) {
            return vec3<f32>(c, 0.0, 0.0);
        }
        let s = sin(w * r);
        return vec3<f32>(c, -w * s * dx / r, -w * s * dy / r);
    }
    let px = x * f;
    let py = y * f;
    let fi = floor(px);
    let fj = floor(py);
    let i = i32(fi);
    let j = i32(fj);
    let a = lattice_value(i, j);
    let b = lattice_value(i + 1, j);
    let c = lattice_value(i, j + 1);
    let d = lattice_value(i + 1, j + 1);
    let sx = fade(px - fi);
    let sy = fade(py - fj);
    let bottom = a + (b - a) * sx.x;
    let top = c + (d - c) * sx.x;
    return vec3<f32>(
        bottom + (top - bottom) * sy.x,
        ((b - a) + ((d - c) - (b - a)) * sy.x) * sx.y * f,
        (top - bottom) * sy.y * f,
    );
}

// A displaced vertex: position and unit normal.
struct Displaced {
    position: vec3<f32>,
    normal: vec3<f32>,
}

// `position` moved along `normal` by the record's object's displacement at local (s, t), and
// the displaced surface's normal from the derivatives `d` (in (s, t)) with the normal's
// derivatives from the Weingarten equations (kernel::displace::Displacement::apply).
fn displace(rec: PatchRecord, d: Derivatives, position: vec3<f32>, normal: vec3<f32>, s: f32, t: f32) -> Displaced {
    let params = control_points[rec.displacement];
    let object = control_points[rec.displacement + 1u];
    let span = max(object.yw - object.xz, vec2<f32>(1e-30));
    let u = rec.domain.x * (1.0 - s) + rec.domain.y * s;
    let v = rec.domain.z * (1.0 - t) + rec.domain.w * t;
    let x = (u - object.x) / span.x;
    let y = (v - object.z) / span.y;
    let scale = (rec.domain.yw - rec.domain.xz) / span;
    let hh = displacement_height(u32(params.x), params.z, x, y, rec.displacement + DISPLACEMENT_HEADER);
    let a = params.y;
    let dn = normal_derivatives(d, normal);
    let pu = d.su + (normal * (hh.y * scale.x) + dn.nu * hh.x) * a;
    let pv = d.sv + (normal * (hh.z * scale.y) + dn.nv * hh.x) * a;
    let c = cross(pu, pv);
    var out_normal = normal;
    let length2 = dot(c, c);
    if (length2 > 0.0) {
        out_normal = c / sqrt(length2);
        if (dot(out_normal, normal) < 0.0) {
            out_normal = -out_normal;
        }
    }
    return Displaced(position + normal * (a * hh.x), out_normal);
}
