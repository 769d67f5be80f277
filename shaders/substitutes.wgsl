// Efficient substitutes of a subdivision limit surface, one patch per face: ACC (a bicubic patch
// and its two tangent patches), Gregory (ACC-2: a bicubic patch whose interior points blend two
// each) and PN triangles (a cubic triangle with a quadratic normal triangle). Pure functions of
// the patch's control points; the f64 reference is kernel::subdiv::substitutes::evaluate, with
// the same formulas. A module composed after common.wgsl and diffgeo.wgsl (src/shaders.rs).

// One substitute at one parameter: position and derivatives, the normal it shades with, and
// whether its curvature is defined there (a Gregory patch's corners: its twist is not).
struct SubstituteSample {
    d: Derivatives,
    normal: vec3<f32>,
    curvature_defined: bool,
}

// Cubic Bernstein polynomials at t: values, first and second derivatives.
struct SubstituteCubic {
    value: vec4<f32>,
    first: vec4<f32>,
    second: vec4<f32>,
}

fn substitute_cubic(t: f32) -> SubstituteCubic {
    let s = 1.0 - t;
    return SubstituteCubic(
        vec4<f32>(s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t),
        vec4<f32>(-3.0 * s * s, 3.0 * s * s - 6.0 * t * s, 6.0 * t * s - 3.0 * t * t, 3.0 * t * t),
        vec4<f32>(6.0 * s, 6.0 * t - 12.0 * s, 6.0 * s - 12.0 * t, 6.0 * t),
    );
}

fn substitute_quadratic(t: f32) -> vec3<f32> {
    let s = 1.0 - t;
    return vec3<f32>(s * s, 2.0 * t * s, t * t);
}

// The bicubic Bézier patch `grid` (row-major, first index along u) at (u, v), plus the interior
// points' own derivatives `moving[k]` = (d/du, d/dv, d2/du2, d2/dudv, d2/dv2) for the interior
// points (1, 1), (2, 1), (1, 2), (2, 2) (zero for a plain Bézier patch).
fn substitute_bicubic(
    grid_in: array<vec3<f32>, 16>,
    moving_in: array<array<vec3<f32>, 5>, 4>,
    u: f32,
    v: f32,
) -> Derivatives {
    var grid = grid_in;
    var moving = moving_in;
    let bu = substitute_cubic(u);
    let bv = substitute_cubic(v);
    var d: Derivatives;
    for (var i = 0u; i < 4u; i++) {
        for (var j = 0u; j < 4u; j++) {
            let p = grid[i * 4u + j];
            d.point += p * (bu.value[i] * bv.value[j]);
            d.su += p * (bu.first[i] * bv.value[j]);
            d.sv += p * (bu.value[i] * bv.first[j]);
            d.suu += p * (bu.second[i] * bv.value[j]);
            d.suv += p * (bu.first[i] * bv.first[j]);
            d.svv += p * (bu.value[i] * bv.second[j]);
        }
    }
    for (var k = 0u; k < 4u; k++) {
        let i = 1u + (k & 1u);
        let j = 1u + (k >> 1u);
        let m = moving[k];
        let b = bu.value[i] * bv.value[j];
        d.su += m[0] * b;
        d.sv += m[1] * b;
        d.suu += m[0] * (2.0 * bu.first[i] * bv.value[j]) + m[2] * b;
        d.suv += m[0] * (bu.value[i] * bv.first[j]) + m[1] * (bu.first[i] * bv.value[j]) + m[3] * b;
        d.svv += m[1] * (2.0 * bu.value[i] * bv.first[j]) + m[4] * b;
    }
    return d;
}

// ACC (Loop & Schaefer 2008): the geometry patch's position and derivatives, the normal of the
// u-tangent patch (degree (2, 3), points 16..27) crossed with the v-tangent patch ((3, 2),
// points 28..39).
fn acc_sample(points_in: array<vec3<f32>, 40>, u: f32, v: f32) -> SubstituteSample {
    var points = points_in;
    var grid: array<vec3<f32>, 16>;
    for (var k = 0u; k < 16u; k++) {
        grid[k] = points[k];
    }
    var still: array<array<vec3<f32>, 5>, 4>;
    let d = substitute_bicubic(grid, still, u, v);
    let qu = substitute_quadratic(u);
    let qv = substitute_quadratic(v);
    let cu = substitute_cubic(u).value;
    let cv = substitute_cubic(v).value;
    var tu = vec3<f32>(0.0);
    var tv = vec3<f32>(0.0);
    for (var i = 0u; i < 3u; i++) {
        for (var j = 0u; j < 4u; j++) {
            tu += points[16u + i * 4u + j] * (qu[i] * cv[j]);
        }
    }
    for (var i = 0u; i < 4u; i++) {
        for (var j = 0u; j < 3u; j++) {
            tv += points[28u + i * 3u + j] * (cu[i] * qv[j]);
        }
    }
    let n = cross(tu, tv);
    let n2 = dot(n, n);
    var normal = vec3<f32>(0.0);
    if (n2 > 0.0) {
        normal = n * inverseSqrt(n2);
    }
    return SubstituteSample(d, normal, true);
}

// Gregory (ACC-2): interior point (i, j) is (a P_u + b P_v) / (a + b), a the distance from the
// edge u = 0 or 1 beside it, b from v = 0 or 1; its derivatives enter the patch's.
fn gregory_sample(points_in: array<vec3<f32>, 20>, u: f32, v: f32) -> SubstituteSample {
    var points = points_in;
    var grid: array<vec3<f32>, 16>;
    for (var k = 0u; k < 16u; k++) {
        grid[k] = points[k];
    }
    var moving: array<array<vec3<f32>, 5>, 4>;
    var defined = true;
    for (var k = 0u; k < 4u; k++) {
        let i = 1u + (k & 1u);
        let j = 1u + (k >> 1u);
        let near_u0 = i == 1u;
        let near_v0 = j == 1u;
        let a = select(1.0 - u, u, near_u0);
        let b = select(1.0 - v, v, near_v0);
        let sa = select(-1.0, 1.0, near_u0);
        let sb = select(-1.0, 1.0, near_v0);
        let pu = points[i * 4u + j];
        let pv = points[16u + k];
        let s = a + b;
        if (s <= 0.0) {
            grid[i * 4u + j] = 0.5 * (pu + pv);
            defined = false;
            continue;
        }
        let diff = pu - pv;
        grid[i * 4u + j] = pv + diff * (a / s);
        let s2 = s * s;
        let s3 = s2 * s;
        moving[k] = array<vec3<f32>, 5>(
            diff * (sa * b / s2),
            diff * (-sb * a / s2),
            diff * (-2.0 * b / s3),
            diff * (sa * sb * (a - b) / s3),
            diff * (2.0 * a / s3),
        );
    }
    let d = substitute_bicubic(grid, moving, u, v);
    return SubstituteSample(d, regular_normal(d), defined);
}

// The index of the PN triangle's point b_ijk (k = 3 - i - j) in its control points.
fn pn_index(i: u32, j: u32) -> u32 {
    var table = array<u32, 16>(2u, 6u, 5u, 1u, 7u, 9u, 4u, 0u, 8u, 3u, 0u, 0u, 0u, 0u, 0u, 0u);
    return table[i * 4u + j];
}

// The index of the PN triangle's normal coefficient n_ijk (k = 2 - i - j), after the points.
fn pn_normal_index(i: u32, j: u32) -> u32 {
    var table = array<u32, 9>(2u, 4u, 1u, 5u, 3u, 0u, 0u, 0u, 0u);
    return 10u + table[i * 3u + j];
}

// PN triangle (Vlachos et al. 2001): the cubic triangle's position (Bernstein form) and its
// derivatives by differences of the points (hodographs: S_u = 3 sum (b_{a+e_u} - b_{a+e_w})
// B2_a, S_uu = 6 sum (b_{a+2e_u} - 2 b_{a+e_u+e_w} + b_{a+2e_w}) B1_a and so on, with u weighting
// corner 1, v corner 2 and w = 1 - u - v corner 0; a point past the hypotenuse is scaled onto
// it), and the quadratic normal triangle, normalized.
fn pn_triangle_sample(points_in: array<vec3<f32>, 16>, u_in: f32, v_in: f32) -> SubstituteSample {
    var b = points_in;
    var u = u_in;
    var v = v_in;
    if (u + v > 1.0) {
        let sum = u + v;
        u = u / sum;
        v = v / sum;
    }
    let w = 1.0 - u - v;
    let pw = vec4<f32>(1.0, w, w * w, w * w * w);
    let pu = vec4<f32>(1.0, u, u * u, u * u * u);
    let pv = vec4<f32>(1.0, v, v * v, v * v * v);
    var d: Derivatives;
    var normal = vec3<f32>(0.0);
    // Degree 3: the position; degree 2: first derivatives and the normal; degree 1: second.
    for (var i = 0u; i <= 3u; i++) {
        for (var j = 0u; j + i <= 3u; j++) {
            let k = 3u - i - j;
            let c = 6.0 / (FACTORIALS[i] * FACTORIALS[j] * FACTORIALS[k]);
            d.point += b[pn_index(i, j)] * (c * pw[i] * pu[j] * pv[k]);
        }
    }
    for (var i = 0u; i <= 2u; i++) {
        for (var j = 0u; j + i <= 2u; j++) {
            let k = 2u - i - j;
            let basis = 2.0 / (FACTORIALS[i] * FACTORIALS[j] * FACTORIALS[k]) * pw[i] * pu[j] * pv[k];
            let bw = b[pn_index(i + 1u, j)];
            d.su += 3.0 * basis * (b[pn_index(i, j + 1u)] - bw);
            d.sv += 3.0 * basis * (b[pn_index(i, j)] - bw);
            normal += b[pn_normal_index(i, j)] * basis;
        }
    }
    let linear = vec3<f32>(w, u, v);
    for (var a = 0u; a < 3u; a++) {
        let i = select(0u, 1u, a == 0u);
        let j = select(0u, 1u, a == 1u);
        // b_{a + e_x + e_y} for x, y among w (i + 1), u (j + 1), v (k + 1).
        let ww = b[pn_index(i + 2u, j)];
        let wu = b[pn_index(i + 1u, j + 1u)];
        let wv = b[pn_index(i + 1u, j)];
        let uu = b[pn_index(i, j + 2u)];
        let uv = b[pn_index(i, j + 1u)];
        let vv = b[pn_index(i, j)];
        d.suu += 6.0 * linear[a] * (uu - 2.0 * wu + ww);
        d.suv += 6.0 * linear[a] * (uv - wu - wv + ww);
        d.svv += 6.0 * linear[a] * (vv - 2.0 * wv + ww);
    }
    let n2 = dot(normal, normal);
    var unit = vec3<f32>(0.0);
    if (n2 > 0.0) {
        unit = normal * inverseSqrt(n2);
    }
    return SubstituteSample(d, unit, true);
}

// 0!, 1!, 2!, 3!.
const FACTORIALS = vec4<f32>(1.0, 1.0, 2.0, 6.0);
