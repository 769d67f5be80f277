// Evaluates rational tensor-product Bézier patches into a vertex buffer, and writes their
// triangle indices. The CPU reference is src/kernel/bezier.rs; both use the same formulas:
// Bernstein basis by The NURBS Book A1.3, derivatives in hodograph (difference) form, the
// rational quotient rule of The NURBS Book eq. 4.20, and the same normal rule at collapsed edges.

const MAX_DEGREE: u32 = 7u;          // Rust: gpu::records::GPU_MAX_DEGREE
const WORKGROUP_SIZE: u32 = 64u;     // Rust: gpu::records::EVAL_WORKGROUP_SIZE
const DEGENERATE_SIN2: f32 = 1e-10;  // Rust: kernel::bezier::DEGENERATE_SIN2
const NORMAL_NUDGE: f32 = 1e-3;      // Rust: kernel::bezier::NORMAL_NUDGE

@group(0) @binding(0) var<storage, read> control_points: array<vec4<f32>>;  // (wx, wy, wz, w)
@group(0) @binding(1) var<storage, read> control_indices: array<u32>;
@group(0) @binding(2) var<storage, read> patches: array<PatchRecord>;
@group(0) @binding(3) var<storage, read_write> vertices: array<SurfaceVertex>;
@group(0) @binding(4) var<storage, read_write> triangle_indices: array<u32>;

// Bernstein polynomials of degrees n, n-1, n-2 at one parameter.
struct Basis {
    full: array<f32, 8>,
    lower1: array<f32, 8>,
    lower2: array<f32, 8>,
}

// All Bernstein polynomials of degree n at t (The NURBS Book, A1.3); entries past n are 0.
fn bernstein_all(t: f32, n: u32) -> array<f32, 8> {
    var b: array<f32, 8>;
    b[0] = 1.0;
    let s = 1.0 - t;
    for (var j = 1u; j <= n; j++) {
        var saved = 0.0;
        for (var k = 0u; k < j; k++) {
            let temp = b[k];
            b[k] = saved + s * temp;
            saved = t * temp;
        }
        b[j] = saved;
    }
    return b;
}

fn make_basis(n: u32, t: f32) -> Basis {
    var basis: Basis;
    basis.full = bernstein_all(t, n);
    if (n >= 1u) {
        basis.lower1 = bernstein_all(t, n - 1u);
    }
    if (n >= 2u) {
        basis.lower2 = bernstein_all(t, n - 2u);
    }
    return basis;
}

// A Bézier sum and its first two derivatives, the derivatives in difference form:
// C' = n sum B_{i,n-1} (P_{i+1} - P_i), C'' = n(n-1) sum B_{i,n-2} (P_{i+2} - 2 P_{i+1} + P_i).
struct Sums {
    value: vec4<f32>,
    d1: vec4<f32>,
    d2: vec4<f32>,
}

fn bezier_sums(basis: Basis, n: u32, p: array<vec4<f32>, 8>) -> Sums {
    var out: Sums;
    for (var i = 0u; i <= n; i++) {
        out.value += basis.full[i] * p[i];
    }
    if (n >= 1u) {
        for (var i = 0u; i < n; i++) {
            out.d1 += basis.lower1[i] * (p[i + 1u] - p[i]);
        }
        out.d1 *= f32(n);
    }
    if (n >= 2u) {
        for (var i = 0u; i + 1u < n; i++) {
            out.d2 += basis.lower2[i] * ((p[i + 2u] - p[i + 1u]) - (p[i + 1u] - p[i]));
        }
        out.d2 *= f32(n * (n - 1u));
    }
    return out;
}

struct Derivatives {
    point: vec3<f32>,
    su: vec3<f32>,
    sv: vec3<f32>,
    suu: vec3<f32>,
    suv: vec3<f32>,
    svv: vec3<f32>,
}

// Position and partial derivatives up to order 2 of a patch of any degree up to MAX_DEGREE at
// local (s, t) in [0, 1]^2.
fn evaluate_patch(rec: PatchRecord, s: f32, t: f32) -> Derivatives {
    let p = rec.degree_u;
    let q = rec.degree_v;
    let bu = make_basis(p, s);
    let bv = make_basis(q, t);
    var rows0: array<vec4<f32>, 8>;
    var rows1: array<vec4<f32>, 8>;
    var rows2: array<vec4<f32>, 8>;
    for (var i = 0u; i <= p; i++) {
        var row: array<vec4<f32>, 8>;
        for (var j = 0u; j <= q; j++) {
            row[j] = control_points[control_indices[rec.control_offset + i * (q + 1u) + j]];
        }
        let r = bezier_sums(bv, q, row);
        rows0[i] = r.value;
        rows1[i] = r.d1;
        rows2[i] = r.d2;
    }
    let a0 = bezier_sums(bu, p, rows0);  // A, A_u, A_uu
    let a1 = bezier_sums(bu, p, rows1);  // A_v, A_uv
    let a2 = bezier_sums(bu, p, rows2);  // A_vv
    return rational_derivatives(a0, a1, a2.value);
}

// Cartesian derivatives of S = A / w from the homogeneous sums (The NURBS Book, eq. 4.20):
// a0 = (A, A_u, A_uu), a1 = (A_v, A_uv, -), a_vv = A_vv.
fn rational_derivatives(a0: Sums, a1: Sums, a_vv: vec4<f32>) -> Derivatives {
    let w = a0.value.w;
    var d: Derivatives;
    d.point = a0.value.xyz / w;
    d.su = (a0.d1.xyz - a0.d1.w * d.point) / w;
    d.sv = (a1.value.xyz - a1.value.w * d.point) / w;
    d.suu = (a0.d2.xyz - 2.0 * a0.d1.w * d.su - a0.d2.w * d.point) / w;
    d.svv = (a_vv.xyz - 2.0 * a1.value.w * d.sv - a_vv.w * d.point) / w;
    d.suv = (a1.d1.xyz - a0.d1.w * d.sv - a1.value.w * d.su - a1.d1.w * d.point) / w;
    return d;
}

// The cubic Bernstein polynomials of degrees 3, 2 and 1 at t, in registers. Exact 0 and 1 at
// t = 0 and t = 1, as the general recurrence.
struct CubicBasis {
    full: vec4<f32>,
    lower1: vec3<f32>,
    lower2: vec2<f32>,
}

fn cubic_basis(t: f32) -> CubicBasis {
    let s = 1.0 - t;
    var b: CubicBasis;
    b.full = vec4<f32>(s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t);
    b.lower1 = vec3<f32>(s * s, 2.0 * t * s, t * t);
    b.lower2 = vec2<f32>(s, t);
    return b;
}

// bezier_sums for degree 3, unrolled: value, first and second derivative in difference form.
fn cubic_sums(b: CubicBasis, c0: vec4<f32>, c1: vec4<f32>, c2: vec4<f32>, c3: vec4<f32>) -> Sums {
    let d0 = c1 - c0;
    let d1 = c2 - c1;
    let d2 = c3 - c2;
    var out: Sums;
    out.value = b.full.x * c0 + b.full.y * c1 + b.full.z * c2 + b.full.w * c3;
    out.d1 = 3.0 * (b.lower1.x * d0 + b.lower1.y * d1 + b.lower1.z * d2);
    out.d2 = 6.0 * (b.lower2.x * (d1 - d0) + b.lower2.y * (d2 - d1));
    return out;
}

fn control_point(rec: PatchRecord, k: u32) -> vec4<f32> {
    return control_points[control_indices[rec.control_offset + k]];
}

// evaluate_patch for bicubic patches (the teapot's, and every Bézier patch of a bicubic
// B-spline): the same formulas with constant indices only, so no private arrays.
fn evaluate_bicubic(rec: PatchRecord, s: f32, t: f32) -> Derivatives {
    let bu = cubic_basis(s);
    let bv = cubic_basis(t);
    let r0 = cubic_sums(bv, control_point(rec, 0u), control_point(rec, 1u), control_point(rec, 2u), control_point(rec, 3u));
    let r1 = cubic_sums(bv, control_point(rec, 4u), control_point(rec, 5u), control_point(rec, 6u), control_point(rec, 7u));
    let r2 = cubic_sums(bv, control_point(rec, 8u), control_point(rec, 9u), control_point(rec, 10u), control_point(rec, 11u));
    let r3 = cubic_sums(bv, control_point(rec, 12u), control_point(rec, 13u), control_point(rec, 14u), control_point(rec, 15u));
    let a0 = cubic_sums(bu, r0.value, r1.value, r2.value, r3.value);
    let a1 = cubic_sums(bu, r0.d1, r1.d1, r2.d1, r3.d1);
    let a_vv = bu.full.x * r0.d2 + bu.full.y * r1.d2 + bu.full.z * r2.d2 + bu.full.w * r3.d2;
    return rational_derivatives(a0, a1, a_vv);
}

// Set per pipeline (gpu::patch_eval): true in the pipeline that evaluates the bicubic patches,
// which is then compiled without the general-degree path. That path's private arrays slow the
// whole kernel on some drivers (8x on lavapipe) even where it never runs.
override BICUBIC_ONLY: bool = false;

fn evaluate(rec: PatchRecord, s: f32, t: f32) -> Derivatives {
    if (BICUBIC_ONLY) {
        return evaluate_bicubic(rec, s, t);
    }
    return evaluate_patch(rec, s, t);
}

// Su x Sv normalized, or zero where sin^2(angle(Su, Sv)) <= DEGENERATE_SIN2.
fn regular_normal(d: Derivatives) -> vec3<f32> {
    let n = cross(d.su, d.sv);
    let n2 = dot(n, n);
    let scale = dot(d.su, d.su) * dot(d.sv, d.sv);
    if (n2 > DEGENERATE_SIN2 * scale && n2 > 0.0) {
        return n * inverseSqrt(n2);
    }
    return vec3<f32>(0.0);
}

// The limit normal at a collapsed edge: Sv ~ (u - u0) Suv near an edge u = u0 where Sv = 0,
// and likewise for Su = 0; zero if that fails too.
fn collapsed_edge_normal(d: Derivatives, s: f32, t: f32) -> vec3<f32> {
    var n: vec3<f32>;
    if (dot(d.sv, d.sv) <= dot(d.su, d.su)) {
        n = select(-1.0, 1.0, s < 0.5) * cross(d.su, d.suv);
    } else {
        n = select(-1.0, 1.0, t < 0.5) * cross(d.suv, d.sv);
    }
    let n2 = dot(n, n);
    if (n2 > 0.0) {
        return n * inverseSqrt(n2);
    }
    return vec3<f32>(0.0);
}

// The normal of kernel::bezier::BezierPatchSet::normal: regular, else the collapsed-edge limit,
// else the same rules at a parameter nudged toward the patch centre, else +z. Never NaN.
fn surface_normal(rec: PatchRecord, d: Derivatives, s: f32, t: f32) -> vec3<f32> {
    var n = regular_normal(d);
    if (all(n == vec3<f32>(0.0))) {
        n = collapsed_edge_normal(d, s, t);
    }
    if (all(n == vec3<f32>(0.0))) {
        let sn = s + (0.5 - s) * NORMAL_NUDGE;
        let tn = t + (0.5 - t) * NORMAL_NUDGE;
        let nudged = evaluate(rec, sn, tn);
        n = regular_normal(nudged);
        if (all(n == vec3<f32>(0.0))) {
            n = collapsed_edge_normal(nudged, sn, tn);
        }
    }
    if (all(n == vec3<f32>(0.0))) {
        n = vec3<f32>(0.0, 0.0, 1.0);
    }
    return n;
}

// One invocation per output vertex; workgroup_id.y is the patch.
@compute @workgroup_size(WORKGROUP_SIZE)
fn evaluate_vertices(
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(local_invocation_index) lane: u32,
) {
    if (group.y >= arrayLength(&patches)) {
        return;
    }
    let rec = patches[group.y];
    let local = group.x * WORKGROUP_SIZE + lane;
    let nv = rec.segments_v + 1u;
    if (local >= (rec.segments_u + 1u) * nv) {
        return;
    }
    let i = local / nv;
    let j = local % nv;
    let s = f32(i) / f32(rec.segments_u);
    let t = f32(j) / f32(rec.segments_v);
    let d = evaluate(rec, s, t);
    let n = surface_normal(rec, d, s, t);
    let u = rec.domain.x * (1.0 - s) + rec.domain.y * s;
    let v = rec.domain.z * (1.0 - t) + rec.domain.w * t;
    vertices[rec.vertex_offset + local] = SurfaceVertex(d.point, u, n, v);
}

// One invocation per grid quad: two counter-clockwise triangles (seen from the side Su x Sv
// points to). workgroup_id.y is the patch.
@compute @workgroup_size(WORKGROUP_SIZE)
fn write_triangles(
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(local_invocation_index) lane: u32,
) {
    if (group.y >= arrayLength(&patches)) {
        return;
    }
    let rec = patches[group.y];
    let quad = group.x * WORKGROUP_SIZE + lane;
    if (quad >= rec.segments_u * rec.segments_v) {
        return;
    }
    let nv = rec.segments_v + 1u;
    let i = quad / rec.segments_v;
    let j = quad % rec.segments_v;
    let a = rec.vertex_offset + i * nv + j;   // (i, j)
    let b = a + nv;                           // (i + 1, j)
    let c = b + 1u;                           // (i + 1, j + 1)
    let d = a + 1u;                           // (i, j + 1)
    let o = rec.index_offset + quad * 6u;
    triangle_indices[o] = a;
    triangle_indices[o + 1u] = b;
    triangle_indices[o + 2u] = c;
    triangle_indices[o + 3u] = a;
    triangle_indices[o + 4u] = c;
    triangle_indices[o + 5u] = d;
}
