// Differential geometry of a parametric surface from its partial derivatives, in f32: the
// regular and collapsed-edge normals and the curvatures from the fundamental forms. A module
// shared by every pass that evaluates surfaces (composed after common.wgsl by src/shaders.rs);
// the f64 kernel's kernel::diffgeo is the reference.

const DEGENERATE_SIN2: f32 = 1e-10;  // Rust: kernel::bezier::DEGENERATE_SIN2

// Position and partial derivatives up to order 2 at one parameter.
struct Derivatives {
    point: vec3<f32>,
    su: vec3<f32>,
    sv: vec3<f32>,
    suu: vec3<f32>,
    suv: vec3<f32>,
    svv: vec3<f32>,
}

// Su x Sv normalized, or zero where sin^2(angle(Su, Sv)) <= DEGENERATE_SIN2 or one derivative
// vanishes against the other (kernel::diffgeo::SurfaceDerivatives::regular_normal).
fn regular_normal(d: Derivatives) -> vec3<f32> {
    let n = cross(d.su, d.sv);
    let n2 = dot(n, n);
    let a = dot(d.su, d.su);
    let b = dot(d.sv, d.sv);
    if (n2 > DEGENERATE_SIN2 * a * b && n2 > 0.0 && min(a, b) > DEGENERATE_SIN2 * max(a, b)) {
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

// Curvature from the fundamental forms (kernel::diffgeo::CurvatureValues::from_forms, with
// curvature positive toward n): E, F, G from Su, Sv; L, M, N from Suu, Suv, Svv and n. The
// Weingarten map W = I^-1 II = [[a, b], [c, d]] gives H = (a + d) / 2, K = (LN - M^2) / (EG - F^2)
// and k1,2 = H +- sqrt(((a - d) / 2)^2 + bc), which (unlike sqrt(H^2 - K)) stays accurate in f32
// near umbilics. EG - F^2 is taken as |Su x Sv|^2, which does not cancel. `values` is
// (K, H, k1, k2), all zero where `defined` is false (EG - F^2 = 0 or an overflow).
// The first fundamental form (E, F, G) and the second (L, M, N) of `d` about the unit normal n.
struct Forms {
    first: vec3<f32>,
    second: vec3<f32>,
}

fn fundamental_forms(d: Derivatives, n: vec3<f32>) -> Forms {
    return Forms(
        vec3<f32>(dot(d.su, d.su), dot(d.su, d.sv), dot(d.sv, d.sv)),
        vec3<f32>(dot(d.suu, n), dot(d.suv, n), dot(d.svv, n)),
    );
}

// The unit normal's derivatives along u and v by the Weingarten equations (do Carmo 3.3): with
// D = EG - F^2, N_u = ((MF - LG) S_u + (LF - ME) S_v) / D and N_v = ((NF - MG) S_u +
// (MF - NE) S_v) / D; zero where D <= 0 (Rust: SurfaceDerivatives::normal_derivatives).
struct NormalDerivatives {
    nu: vec3<f32>,
    nv: vec3<f32>,
}

fn normal_derivatives(d: Derivatives, n: vec3<f32>) -> NormalDerivatives {
    let forms = fundamental_forms(d, n);
    let i = forms.first;     // (E, F, G)
    let ii = forms.second;   // (L, M, N)
    let det = i.x * i.z - i.y * i.y;
    var out: NormalDerivatives;
    if (det > 0.0) {
        out.nu = (d.su * (ii.y * i.y - ii.x * i.z) + d.sv * (ii.x * i.y - ii.y * i.x)) / det;
        out.nv = (d.su * (ii.z * i.y - ii.y * i.z) + d.sv * (ii.y * i.y - ii.z * i.x)) / det;
    }
    return out;
}

struct CurvatureResult {
    values: vec4<f32>,
    defined: bool,
}

fn curvature(d: Derivatives, n: vec3<f32>) -> CurvatureResult {
    let forms = fundamental_forms(d, n);
    let e = forms.first.x;
    let f = forms.first.y;
    let g = forms.first.z;
    let l = forms.second.x;
    let m = forms.second.y;
    let nn = forms.second.z;
    let c = cross(d.su, d.sv);
    let det = dot(c, c);
    var out: CurvatureResult;
    if (!(det > 0.0) || det > 3.0e38) {
        return out;
    }
    let inv = 1.0 / det;
    let a = (g * l - f * m) * inv;
    let b = (g * m - f * nn) * inv;
    let cc = (e * m - f * l) * inv;
    let dd = (e * nn - f * m) * inv;
    let mean = 0.5 * (a + dd);
    let gaussian = (l * nn - m * m) * inv;
    let half = 0.5 * (a - dd);
    let disc = sqrt(max(half * half + b * cc, 0.0));
    out.values = vec4<f32>(gaussian, mean, mean + disc, mean - disc);
    out.defined = all(out.values == out.values) && all(abs(out.values) < vec4<f32>(3.0e38));
    if (!out.defined) {
        out.values = vec4<f32>(0.0);
    }
    return out;
}
