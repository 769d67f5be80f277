// Module: free-form deformation by a trivariate Bézier lattice (the Rust reference:
// kernel::ffd). The lattice block lies in the control point buffer (LATTICE_HEADER in
// common.wgsl; Rust: gpu::packing::lattice_block). Needs the pipeline's `control_points`.

// A lattice's map at a point, in local coordinates (kernel::ffd::LatticeJet): F, the first
// derivatives as the columns of `first`, the second ones.
struct LatticeJet {
    value: vec3<f32>,
    first: mat3x3<f32>,
    ss: vec3<f32>,
    tt: vec3<f32>,
    uu: vec3<f32>,
    st: vec3<f32>,
    su: vec3<f32>,
    tu: vec3<f32>,
}

// The lattice at `base` of the control point buffer: its inverse box matrix A (local = A (X -
// origin)).
fn lattice_inverse_axes(base: u32) -> mat3x3<f32> {
    return transpose(mat3x3<f32>(
        control_points[base + 1u].xyz,
        control_points[base + 2u].xyz,
        control_points[base + 3u].xyz,
    ));
}

// The degrees (l, m, n) of the lattice at `base`, packed l | m << 8 | n << 16 in the bits of its
// header's w (gpu::packing::lattice_block).
fn lattice_degrees(base: u32) -> vec3<u32> {
    let packed = bitcast<u32>(control_points[base].w);
    return vec3<u32>(packed & 0xFFu, (packed >> 8u) & 0xFFu, (packed >> 16u) & 0xFFu);
}

// The Bernstein basis of degree n <= 4 at x: the five values B_{0..4,n} as (xyzw, last), and
// their first and second derivatives (kernel::ffd::bernstein_jet), by the triangular
// recurrence B_{i,k+1} = (1 - x) B_{i,k} + x B_{i-1,k} on vectors, so everything stays in
// registers (a CPU driver keeps indexed arrays in memory).
struct LatticeBasis {
    value: vec4<f32>,
    value4: f32,
    d1: vec4<f32>,
    d1_4: f32,
    d2: vec4<f32>,
    d2_4: f32,
}

fn lattice_basis(n: u32, x: f32) -> LatticeBasis {
    var b = vec4<f32>(1.0, 0.0, 0.0, 0.0);
    var b4 = 0.0;
    var lower1 = b;
    var lower1_4 = 0.0;
    var lower2 = b;
    var lower2_4 = 0.0;
    let s = 1.0 - x;
    for (var k = 0u; k < n; k++) {
        if (k + 2u == n) {
            lower2 = b;
            lower2_4 = b4;
        }
        if (k + 1u == n) {
            lower1 = b;
            lower1_4 = b4;
        }
        b4 = s * b4 + x * b.w;
        b = s * b + x * vec4<f32>(0.0, b.xyz);
    }
    let nf = f32(n);
    let nn = nf * (nf - 1.0);
    // B' = n (B_{i-1,n-1} - B_{i,n-1}), B'' = n (n - 1) (B_{i-2,n-2} - 2 B_{i-1,n-2} + B_{i,n-2}).
    let d1 = nf * (vec4<f32>(0.0, lower1.xyz) - lower1);
    let d2 = nn * (vec4<f32>(0.0, 0.0, lower2.xy) - 2.0 * vec4<f32>(0.0, lower2.xyz) + lower2);
    return LatticeBasis(
        b,
        b4,
        d1,
        nf * (lower1.w - lower1_4),
        d2,
        nn * (lower2.z - 2.0 * lower2.w + lower2_4),
    );
}

// Entry i (0..=4) of a basis vector held as (xyzw, last), by selects rather than indexing.
fn basis_entry(v: vec4<f32>, last: f32, i: u32) -> f32 {
    return select(select(select(select(last, v.w, i == 3u), v.z, i == 2u), v.y, i == 1u), v.x, i == 0u);
}

// (B_i, B'_i, B''_i) of a lattice basis.
fn basis_triple(b: LatticeBasis, i: u32) -> vec3<f32> {
    return vec3<f32>(
        basis_entry(b.value, b.value4, i),
        basis_entry(b.d1, b.d1_4, i),
        basis_entry(b.d2, b.d2_4, i),
    );
}

// The trivariate Bézier sum and its derivatives at local coordinates `x` (Sederberg & Parry
// 1986; kernel::ffd::Lattice::jet), contracted one direction at a time: along u for each
// (i, j) the value and two derivatives, along t the six products the jet needs, then along s.
fn lattice_jet(base: u32, x: vec3<f32>) -> LatticeJet {
    let degrees = lattice_degrees(base);
    let l = degrees.x;
    let m = degrees.y;
    let n = degrees.z;
    let bs = lattice_basis(l, x.x);
    let bt = lattice_basis(m, x.y);
    let bu = lattice_basis(n, x.z);
    var jet: LatticeJet;
    var fs = vec3<f32>(0.0);
    var ft = vec3<f32>(0.0);
    var fu = vec3<f32>(0.0);
    var at = base + LATTICE_HEADER;
    for (var i = 0u; i <= l; i++) {
        // Along t: S, S_u, S_uu, S_t, S_tu, S_tt for this i.
        var s0 = vec3<f32>(0.0);
        var s_u = vec3<f32>(0.0);
        var s_uu = vec3<f32>(0.0);
        var s_t = vec3<f32>(0.0);
        var s_tu = vec3<f32>(0.0);
        var s_tt = vec3<f32>(0.0);
        for (var j = 0u; j <= m; j++) {
            // Along u: R, R_u, R_uu for this (i, j).
            var r0 = vec3<f32>(0.0);
            var r_u = vec3<f32>(0.0);
            var r_uu = vec3<f32>(0.0);
            for (var k = 0u; k <= n; k++) {
                let c = basis_triple(bu, k);
                let p = control_points[at].xyz;
                at += 1u;
                r0 += p * c.x;
                r_u += p * c.y;
                r_uu += p * c.z;
            }
            let b = basis_triple(bt, j);
            s0 += r0 * b.x;
            s_u += r_u * b.x;
            s_uu += r_uu * b.x;
            s_t += r0 * b.y;
            s_tu += r_u * b.y;
            s_tt += r0 * b.z;
        }
        let a = basis_triple(bs, i);
        jet.value += s0 * a.x;
        fu += s_u * a.x;
        jet.uu += s_uu * a.x;
        ft += s_t * a.x;
        jet.tu += s_tu * a.x;
        jet.tt += s_tt * a.x;
        fs += s0 * a.y;
        jet.su += s_u * a.y;
        jet.st += s_t * a.y;
        jet.ss += s0 * a.z;
    }
    jet.first = mat3x3<f32>(fs, ft, fu);
    return jet;
}

// The lattice's second derivative H[x, y] for local directions x, y.
fn lattice_hessian(jet: LatticeJet, x: vec3<f32>, y: vec3<f32>) -> vec3<f32> {
    return jet.ss * (x.x * y.x) + jet.tt * (x.y * y.y) + jet.uu * (x.z * y.z)
        + jet.st * (x.x * y.y + x.y * y.x) + jet.su * (x.x * y.z + x.z * y.x)
        + jet.tu * (x.y * y.z + x.z * y.y);
}
