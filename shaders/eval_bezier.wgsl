// Evaluates rational tensor-product Bézier patches into a vertex buffer (position, normal,
// (u, v), curvature), and writes their triangle indices. The CPU reference is
// crates/kernel/src/bezier.rs and crates/kernel/src/diffgeo.rs; both use the same formulas:
// Bernstein basis by The NURBS Book A1.3, derivatives in hodograph (difference) form, the
// rational quotient rule of The NURBS Book eq. 4.20, the same normal rule at collapsed edges,
// and curvature from the fundamental forms. Displacement and lattices are the modules
// displace.wgsl and lattice.wgsl.
//
// The evaluator is one pipeline file in four parts, composed in this order (src/shaders.rs,
// EVAL_PARTS; WGSL declarations may come in any order): this one (the bindings, patch
// evaluation, a vertex's shape, finishing and storing a vertex), eval_edges.wgsl (crack-free
// boundary curves), eval_grid.wgsl (the fixed grid's entry points, triangles, point samples)
// and eval_adaptive.wgsl (the view-adaptive passes).

const MAX_DEGREE: u32 = 9u;          // Rust: gpu::records::GPU_MAX_DEGREE
const WORKGROUP_SIZE: u32 = 64u;     // Rust: gpu::records::EVAL_WORKGROUP_SIZE
const GRID_ROWS: u32 = 32u;           // Rust: gpu::records::EVAL_GRID_ROWS
// How far toward the patch centre curvature at a degenerate point is sampled (Rust:
// gpu::records::GPU_CURVATURE_NUDGE). Farther than the kernel's f64 CURVATURE_NUDGE: in f32 the
// fundamental forms lose about eps / nudge^2 of relative accuracy (measured on the sphere's
// poles: 10 % off at 1e-3, 0.4 % at 1e-2, 0.05 % at 3e-2).
const CURVATURE_NUDGE: f32 = 3e-2;

@group(0) @binding(0) var<storage, read> control_points: array<vec4<f32>>;  // (wx, wy, wz, w)
@group(0) @binding(1) var<storage, read> control_indices: array<u32>;
@group(0) @binding(2) var<storage, read> patches: array<PatchRecord>;
@group(0) @binding(3) var<storage, read_write> vertices: array<SurfaceVertex>;
@group(0) @binding(4) var<storage, read_write> triangle_indices: array<u32>;
// The records evaluate_vertices works on this dispatch: workgroup_id.y indexes this list, so an
// edit re-evaluates only the patches it changed.
@group(0) @binding(5) var<storage, read> patch_list: array<u32>;
@group(0) @binding(6) var<storage, read> samples: array<PointSample>;
@group(0) @binding(7) var<storage, read_write> sample_results: array<PointResult>;

// Bernstein polynomials of degrees n, n-1, n-2 at one parameter.
struct Basis {
    full: array<f32, 10>,
    lower1: array<f32, 10>,
    lower2: array<f32, 10>,
}

// All Bernstein polynomials of degree n at t (The NURBS Book, A1.3); entries past n are 0.
fn bernstein_all(t: f32, n: u32) -> array<f32, 10> {
    var b: array<f32, 10>;
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

fn bezier_sums(basis: Basis, n: u32, p: array<vec4<f32>, 10>) -> Sums {
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

// The v-direction sums of every row of a patch's control points at t (row i: the homogeneous
// isoparametric curve's control point i and its first two v-derivatives), for any degree up to
// MAX_DEGREE: what every vertex of one grid column shares.
struct PatchRows {
    value: array<vec4<f32>, 10>,
    d1: array<vec4<f32>, 10>,
    d2: array<vec4<f32>, 10>,
}

fn patch_rows(rec: PatchRecord, t: f32) -> PatchRows {
    let p = degree_u(rec);
    let q = degree_v(rec);
    let bv = make_basis(q, t);
    var rows: PatchRows;
    for (var i = 0u; i <= p; i++) {
        var row: array<vec4<f32>, 10>;
        for (var j = 0u; j <= q; j++) {
            row[j] = control_points[control_indices[rec.control_offset + i * (q + 1u) + j]];
        }
        let r = bezier_sums(bv, q, row);
        rows.value[i] = r.value;
        rows.d1[i] = r.d1;
        rows.d2[i] = r.d2;
    }
    return rows;
}

// Position and partial derivatives up to order 2 at local (s, t) from the rows at t.
fn patch_at(rec: PatchRecord, rows: PatchRows, s: f32) -> Derivatives {
    let p = degree_u(rec);
    let bu = make_basis(p, s);
    let a0 = bezier_sums(bu, p, rows.value);  // A, A_u, A_uu
    let a1 = bezier_sums(bu, p, rows.d1);  // A_v, A_uv
    let a2 = bezier_sums(bu, p, rows.d2);  // A_vv
    return rational_derivatives(a0, a1, a2.value);
}

// Position and partial derivatives up to order 2 of a patch of any degree up to MAX_DEGREE at
// local (s, t) in [0, 1]^2.
fn evaluate_patch(rec: PatchRecord, s: f32, t: f32) -> Derivatives {
    return patch_at(rec, patch_rows(rec, t), s);
}

// The patch's control point k (row-major, i along u); the bezier.wgsl module reads points
// through it.
fn control_point(rec: PatchRecord, k: u32) -> vec4<f32> {
    return control_points[control_indices[rec.control_offset + k]];
}

// Set per pipeline (gpu::patch_eval): the degrees of every patch the pipeline evaluates, or 0
// for "read them from the record". With constant degrees every loop has a constant trip count,
// so the driver can unroll it and keep the basis and row arrays in registers; on lavapipe that
// made the demo scene's pass about 10 times faster than one general pipeline.
override DEGREE_U: u32 = 0u;
override DEGREE_V: u32 = 0u;

fn degree_u(rec: PatchRecord) -> u32 {
    return select(rec.degree_u, DEGREE_U, DEGREE_U != 0u);
}

fn degree_v(rec: PatchRecord) -> u32 {
    return select(rec.degree_v, DEGREE_V, DEGREE_V != 0u);
}

// Set per pipeline (gpu::patch_eval): true in the pipeline that evaluates the bicubic patches,
// which is then compiled without the general-degree path. That path's private arrays slow the
// whole kernel on some drivers (8x on lavapipe) even where it never runs.
override BICUBIC_ONLY: bool = false;

// Set per pipeline (gpu::patch_eval): true only in evaluate_vertices' bicubic pipeline, where
// each invocation loads its patch's 16 control points into NET once and every later read (the
// column's rows, the nudged evaluation at degenerate points, the boundary curves) comes from
// there. On CPU drivers a storage read is a gather, lane by lane, and branches run masked
// rather than skipped, so reads in rarely taken branches cost every vertex: on lavapipe they
// were most of the teapot's pass.
override NET_IN_REGISTERS: bool = false;
var<private> NET: BicubicNet;

fn evaluate(rec: PatchRecord, s: f32, t: f32) -> Derivatives {
    if (BICUBIC_ONLY) {
        if (NET_IN_REGISTERS) {
            return bicubic_at(bicubic_rows(NET, t), s);
        }
        return evaluate_bicubic(rec, s, t);
    }
    return evaluate_patch(rec, s, t);
}

// Bits of SurfaceVertex.flags (Rust: gpu::records::VERTEX_IRREGULAR, VERTEX_NO_CURVATURE).
const VERTEX_IRREGULAR: u32 = 1u;     // Su x Sv vanishes: the normal is a limit (pole, collapsed edge)
const VERTEX_NO_CURVATURE: u32 = 2u;  // curvature undefined here and nearby: shown neutrally

// Normal, curvature and flags of a patch at local (s, t), given its derivatives there.
// Regular points: Su x Sv and the curvature from the fundamental forms. Degenerate points (the
// rules of kernel::bezier::BezierPatchSet::normal): the collapsed-edge limit normal; one more
// evaluation CURVATURE_NUDGE of the way to the patch centre gives the limit curvature (the
// kernel samples closer, in f64) and, where the collapsed-edge rule fails too, the normal (the
// kernel nudges NORMAL_NUDGE for that); +z as the last resort. Never NaN.
struct Shape {
    normal: vec3<f32>,
    curvature: vec4<f32>,
    flags: u32,
}

// Set per pipeline (gpu::patch_eval): false where no shading mode reads the vertices'
// curvature (the analysis modes evaluate their own per pixel and fall back to the vertices' only
// at degenerate points): the vertices then carry 0 and VERTEX_NO_CURVATURE, and the driver drops
// the second derivatives and the fundamental forms.
override VERTEX_CURVATURE: bool = true;

// Set per pipeline (gpu::patch_eval::PipelineKey): false for the patches of objects without a
// displacement (DISPLACES) or without a lattice (DEFORMS), whose pipelines then carry none of
// that code (a CPU driver would keep its registers and run its masked branches on every
// vertex).
override DISPLACES: bool = true;
override DEFORMS: bool = true;

// A vertex's shape: its normal and flags, and the curvature of `d` about `curvature_normal`
// where `measured` (else undefined, flagged VERTEX_NO_CURVATURE).
fn make_shape(normal: vec3<f32>, flags: u32, d: Derivatives, curvature_normal: vec3<f32>, measured: bool) -> Shape {
    var out: Shape;
    var k: CurvatureResult;
    out.normal = normal;
    out.flags = flags;
    if (VERTEX_CURVATURE && measured) {
        k = curvature(d, curvature_normal);
    }
    if (!k.defined) {
        out.flags |= VERTEX_NO_CURVATURE;
    }
    out.curvature = k.values;
    return out;
}

// The shape at a regular point, `n` its unit normal (regular_normal, non-zero).
fn regular_shape(d: Derivatives, n: vec3<f32>) -> Shape {
    return make_shape(n, 0u, d, n, true);
}

// The shape at a degenerate point (regular_normal is zero there).
fn irregular_shape(rec: PatchRecord, d: Derivatives, s: f32, t: f32) -> Shape {
    let sn = s + (0.5 - s) * CURVATURE_NUDGE;
    let tn = t + (0.5 - t) * CURVATURE_NUDGE;
    let nd = evaluate(rec, sn, tn);
    var inside = regular_normal(nd);
    if (all(inside == vec3<f32>(0.0))) {
        inside = collapsed_edge_normal(nd, sn, tn);
    }
    var n = collapsed_edge_normal(d, s, t);
    if (all(n == vec3<f32>(0.0))) {
        n = inside;
    }
    if (all(n == vec3<f32>(0.0))) {
        n = vec3<f32>(0.0, 0.0, 1.0);
    }
    // Keep the orientation of the limit normal at the point itself.
    if (dot(inside, n) < 0.0) {
        inside = -inside;
    }
    return make_shape(n, VERTEX_IRREGULAR, nd, inside, any(inside != vec3<f32>(0.0)));
}

fn shape_at(rec: PatchRecord, d: Derivatives, s: f32, t: f32) -> Shape {
    let regular = regular_normal(d);
    if (any(regular != vec3<f32>(0.0))) {
        return regular_shape(d, regular);
    }
    return irregular_shape(rec, d, s, t);
}

// A vertex as written: position, unit normal, curvature and flags.
struct FinishedVertex {
    position: vec3<f32>,
    normal: vec3<f32>,
    curvature: vec4<f32>,
    flags: u32,
}

// The vertex of a record with derivatives `d` at local (s, t), its `position` (crack-free on
// boundaries), normal, curvature and flags as evaluated, finished by the object's
// displacement (moved along the normal, no curvature; displace) and then its lattice
// (lattice_deform).
fn finish_vertex(
    rec: PatchRecord,
    d: Derivatives,
    position: vec3<f32>,
    normal: vec3<f32>,
    values: vec4<f32>,
    flags: u32,
    s: f32,
    t: f32,
) -> FinishedVertex {
    var out = FinishedVertex(position, normal, values, flags);
    if (DISPLACES && rec.displacement != DISPLACEMENT_NONE) {
        let moved = displace(rec, d, position, normal, s, t);
        out = FinishedVertex(moved.position, moved.normal, vec4<f32>(0.0), flags | VERTEX_NO_CURVATURE);
    }
    if (DEFORMS && rec.lattice != LATTICE_NONE) {
        out = lattice_deform(rec.lattice, d, out);
    }
    return out;
}

// A vertex `v` of a surface with derivatives `d` mapped through the lattice at `base`: the
// point, the normal by the cofactor of the Jacobian J = F' A (which is J Su x J Sv and stays
// defined at poles), the curvature from the deformed derivatives by the chain rule
// (kernel::ffd::Lattice::deform) where the vertex had one.
fn lattice_deform(base: u32, d: Derivatives, v: FinishedVertex) -> FinishedVertex {
    let a = lattice_inverse_axes(base);
    let jet = lattice_jet(base, a * (v.position - control_points[base].xyz));
    let j = jet.first * a;
    let cofactor = mat3x3<f32>(cross(j[1], j[2]), cross(j[2], j[0]), cross(j[0], j[1]));
    let mapped = cofactor * v.normal;
    var n = v.normal;
    if (dot(mapped, mapped) > 0.0) {
        n = normalize(mapped);
    }
    var k = vec4<f32>(0.0);
    var f = v.flags | VERTEX_NO_CURVATURE;
    if (VERTEX_CURVATURE && (v.flags & VERTEX_NO_CURVATURE) == 0u) {
        let lu = a * d.su;
        let lv = a * d.sv;
        let deformed = Derivatives(
            jet.value,
            jet.first * lu,
            jet.first * lv,
            jet.first * (a * d.suu) + lattice_hessian(jet, lu, lu),
            jet.first * (a * d.suv) + lattice_hessian(jet, lu, lv),
            jet.first * (a * d.svv) + lattice_hessian(jet, lv, lv),
        );
        let result = curvature(deformed, n);
        if (result.defined) {
            k = result.values;
            f = v.flags;
        }
    }
    return FinishedVertex(jet.value, n, k, f);
}

// Writes grid vertex `g` of record `record`, its (u, v) mapped into the record's domain,
// finished by the object's displacement and lattice (finish_vertex).
fn store_vertex(
    rec: PatchRecord,
    record: u32,
    local: u32,
    g: GridPoint,
    d: Derivatives,
    position: vec3<f32>,
    normal: vec3<f32>,
    curvature: vec4<f32>,
    flags: u32,
) {
    let v = finish_vertex(rec, d, position, normal, curvature, flags, g.s, g.t);
    vertices[rec.vertex_offset + local] = surface_vertex(
        v.position,
        vec2<f32>(
            rec.domain.x * (1.0 - g.s) + rec.domain.y * g.s,
            rec.domain.z * (1.0 - g.t) + rec.domain.w * g.t,
        ),
        v.normal,
        v.curvature,
        rec.object,
        v.flags,
        record,
        rec.level,
    );
}
