// Module: rational tensor-product Bézier patch derivatives up to order 2 (the CPU reference
// is crates/kernel/src/bezier.rs): derivatives in hodograph (difference) form and the rational
// quotient rule of The NURBS Book, eq. 4.20. The pipeline that composes this module supplies
// `fn control_point(rec: PatchRecord, k: u32) -> vec4<f32>`: control point k of the patch,
// homogeneous (wx, wy, wz, w), row-major with i along u. Needs diffgeo.wgsl (Derivatives).

// A Bézier sum and its first two derivatives, the derivatives in difference form:
// C' = n sum B_{i,n-1} (P_{i+1} - P_i), C'' = n(n-1) sum B_{i,n-2} (P_{i+2} - 2 P_{i+1} + P_i).
struct Sums {
    value: vec4<f32>,
    d1: vec4<f32>,
    d2: vec4<f32>,
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

// A bicubic patch's 16 control points: row i holds points 4i .. 4i + 3 (fixed u index i, v index
// j in column j). Matrices with constant column indices, not an array, so they stay in
// registers.
struct BicubicNet {
    row0: mat4x4<f32>,
    row1: mat4x4<f32>,
    row2: mat4x4<f32>,
    row3: mat4x4<f32>,
}

fn bicubic_net(rec: PatchRecord) -> BicubicNet {
    return BicubicNet(
        mat4x4<f32>(control_point(rec, 0u), control_point(rec, 1u), control_point(rec, 2u), control_point(rec, 3u)),
        mat4x4<f32>(control_point(rec, 4u), control_point(rec, 5u), control_point(rec, 6u), control_point(rec, 7u)),
        mat4x4<f32>(control_point(rec, 8u), control_point(rec, 9u), control_point(rec, 10u), control_point(rec, 11u)),
        mat4x4<f32>(control_point(rec, 12u), control_point(rec, 13u), control_point(rec, 14u), control_point(rec, 15u)),
    );
}

// The v-direction sums of a bicubic patch's four rows of control points at t (row i: the
// homogeneous isoparametric curve's control point i and its first two v-derivatives). Every
// vertex of one grid column (one t) shares them, so a column is evaluated from these alone.
struct CubicRows {
    r0: Sums,
    r1: Sums,
    r2: Sums,
    r3: Sums,
}

fn bicubic_rows(net: BicubicNet, t: f32) -> CubicRows {
    let bv = cubic_basis(t);
    var rows: CubicRows;
    rows.r0 = cubic_sums(bv, net.row0[0], net.row0[1], net.row0[2], net.row0[3]);
    rows.r1 = cubic_sums(bv, net.row1[0], net.row1[1], net.row1[2], net.row1[3]);
    rows.r2 = cubic_sums(bv, net.row2[0], net.row2[1], net.row2[2], net.row2[3]);
    rows.r3 = cubic_sums(bv, net.row3[0], net.row3[1], net.row3[2], net.row3[3]);
    return rows;
}

// The derivatives at (s, t) from the rows at t: the u-direction sums of the row sums.
fn bicubic_at(rows: CubicRows, s: f32) -> Derivatives {
    let bu = cubic_basis(s);
    let a0 = cubic_sums(bu, rows.r0.value, rows.r1.value, rows.r2.value, rows.r3.value);
    let a1 = cubic_sums(bu, rows.r0.d1, rows.r1.d1, rows.r2.d1, rows.r3.d1);
    let a_vv = bu.full.x * rows.r0.d2 + bu.full.y * rows.r1.d2 + bu.full.z * rows.r2.d2 + bu.full.w * rows.r3.d2;
    return rational_derivatives(a0, a1, a_vv);
}

// evaluate_patch for bicubic patches (the teapot's, and every Bézier patch of a bicubic
// B-spline): the same formulas with constant indices only, so no private arrays.
fn evaluate_bicubic(rec: PatchRecord, s: f32, t: f32) -> Derivatives {
    return bicubic_at(bicubic_rows(bicubic_net(rec), t), s);
}

// (B, B', B'') of the Bernstein polynomial B_{i,n} at t: B'_{i,n} = n (B_{i-1,n-1} - B_{i,n-1}),
// B''_{i,n} = n (n - 1) (B_{i-2,n-2} - 2 B_{i-1,n-2} + B_{i,n-2}) (The NURBS Book, eq. 1.9 and
// its derivative), each value by multiplication, so nothing here needs a private array.
fn bernstein_value(n: i32, i: i32, t: f32) -> f32 {
    if (i < 0 || i > n) {
        return 0.0;
    }
    let s = 1.0 - t;
    var b = 1.0;
    // C(n, i) t^i s^(n-i), the binomial built as a running product.
    for (var k = 0; k < i; k++) {
        b *= t * f32(n - k) / f32(k + 1);
    }
    for (var k = 0; k < n - i; k++) {
        b *= s;
    }
    return b;
}

fn bernstein_derivatives(n: i32, i: i32, t: f32) -> vec3<f32> {
    var out = vec3<f32>(bernstein_value(n, i, t), 0.0, 0.0);
    if (n >= 1) {
        out.y = f32(n) * (bernstein_value(n - 1, i - 1, t) - bernstein_value(n - 1, i, t));
    }
    if (n >= 2) {
        out.z = f32(n * (n - 1)) * (bernstein_value(n - 2, i - 2, t)
            - 2.0 * bernstein_value(n - 2, i - 1, t) + bernstein_value(n - 2, i, t));
    }
    return out;
}

// Position and derivatives of a patch of any degree at local (s, t), as the double sum
// sum_ij B_i(s) B_j(t) P_ij and its derivatives, with no private arrays (the fragment shader's
// path for non-bicubic patches; the compute pass has faster per-degree pipelines).
fn evaluate_patch_direct(rec: PatchRecord, s: f32, t: f32) -> Derivatives {
    let p = i32(rec.degree_u);
    let q = i32(rec.degree_v);
    var a0: Sums;   // A, A_u, A_uu
    var a1: Sums;   // A_v, A_uv
    var a_vv = vec4<f32>(0.0);
    for (var i = 0; i <= p; i++) {
        let bu = bernstein_derivatives(p, i, s);
        var row: Sums;  // sum over j of B_j(t) P_ij, B'_j(t) P_ij, B''_j(t) P_ij
        for (var j = 0; j <= q; j++) {
            let bv = bernstein_derivatives(q, j, t);
            let c = control_point(rec, u32(i * (q + 1) + j));
            row.value += bv.x * c;
            row.d1 += bv.y * c;
            row.d2 += bv.z * c;
        }
        a0.value += bu.x * row.value;
        a0.d1 += bu.y * row.value;
        a0.d2 += bu.z * row.value;
        a1.value += bu.x * row.d1;
        a1.d1 += bu.y * row.d1;
        a_vv += bu.x * row.d2;
    }
    return rational_derivatives(a0, a1, a_vv);
}

// The patch's derivatives at local (s, t): the register-only bicubic path or the general one.
fn evaluate_bezier_patch(rec: PatchRecord, s: f32, t: f32) -> Derivatives {
    if (rec.degree_u == 3u && rec.degree_v == 3u) {
        return evaluate_bicubic(rec, s, t);
    }
    return evaluate_patch_direct(rec, s, t);
}
