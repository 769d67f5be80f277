// Evaluates rational tensor-product Bézier patches into a vertex buffer (position, normal,
// (u, v), curvature), and writes their triangle indices. The CPU reference is
// crates/kernel/src/bezier.rs and crates/kernel/src/diffgeo.rs; both use the same formulas:
// Bernstein basis by The NURBS Book A1.3, derivatives in hodograph (difference) form, the
// rational quotient rule of The NURBS Book eq. 4.20, the same normal rule at collapsed edges,
// and curvature from the fundamental forms. Displacement and lattices are the modules
// displace.wgsl and lattice.wgsl.

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

// -1, 0 or 1 as a is lexicographically (x, y, z, w) before, equal to or after b. Without
// branches (the first differing component decides, found from the last one forward), as
// boundary vertices of every patch run it.
fn compare_points(a: vec4<f32>, b: vec4<f32>) -> i32 {
    let after = a > b;
    let differs = (a < b) | after;
    var order = 0;
    order = select(order, select(-1, 1, after.w), differs.w);
    order = select(order, select(-1, 1, after.z), differs.z);
    order = select(order, select(-1, 1, after.y), differs.y);
    order = select(order, select(-1, 1, after.x), differs.x);
    return order;
}

// One de Casteljau step (The NURBS Book, A1.5) written so that t = 0 gives a, t = 1 gives b and
// equal points give that point, each exactly.
fn lerp_exact(a: vec4<f32>, b: vec4<f32>, t: f32) -> vec4<f32> {
    return select(b + (1.0 - t) * (a - b), a + t * (b - a), t <= 0.5);
}

// A patch boundary: control points first, first + stride, ..., first + degree * stride (entries
// of the patch's control index block), sampled at k / n.
struct Edge {
    first: u32,
    stride: u32,
    degree: u32,
    k: u32,
    n: u32,
}

fn edge_control(rec: PatchRecord, edge: Edge, m: u32) -> vec4<f32> {
    return control_point(rec, edge.first + m * edge.stride);
}

// Whether to walk the edge backwards so that every patch sharing it runs the same computation:
// the direction whose control point sequence is lexicographically smaller; for a palindrome,
// the one in which the sample is nearer the start.
fn edge_reversed(rec: PatchRecord, edge: Edge) -> bool {
    var order = 0;
    for (var m = 0u; 2u * m < edge.degree && order == 0; m++) {
        order = compare_points(edge_control(rec, edge, m), edge_control(rec, edge, edge.degree - m));
    }
    return reversed_by(order, edge);
}

// edge_reversed's rule given the order of the control point sequence against its reverse (one
// definition for every pipeline: shared seams are bit-identical only if all agree).
fn reversed_by(order: i32, edge: Edge) -> bool {
    return order > 0 || (order == 0 && 2u * edge.k > edge.n);
}

// The four control points of a bicubic patch's boundary `edge` from NET: a row of the net
// (stride 1, first 0 or 12) or a column (stride 4, first 0 or 3).
fn net_edge_points(edge: Edge) -> mat4x4<f32> {
    let last = edge.first != 0u;
    let row = edge.stride == 1u;
    return mat4x4<f32>(
        select(select(NET.row0[0], NET.row0[3], last), select(NET.row0[0], NET.row3[0], last), row),
        select(select(NET.row1[0], NET.row1[3], last), select(NET.row0[1], NET.row3[1], last), row),
        select(select(NET.row2[0], NET.row2[3], last), select(NET.row0[2], NET.row3[2], last), row),
        select(select(NET.row3[0], NET.row3[3], last), select(NET.row0[3], NET.row3[3], last), row),
    );
}

// A cubic edge's point, in registers (the bicubic pipeline has no private arrays): edge_reversed
// unrolled for degree 3.
fn cubic_edge_point(rec: PatchRecord, edge: Edge) -> vec3<f32> {
    var p0: vec4<f32>;
    var p1: vec4<f32>;
    var p2: vec4<f32>;
    var p3: vec4<f32>;
    if (NET_IN_REGISTERS) {
        let e = net_edge_points(edge);
        p0 = e[0];
        p1 = e[1];
        p2 = e[2];
        p3 = e[3];
    } else {
        p0 = edge_control(rec, edge, 0u);
        p1 = edge_control(rec, edge, 1u);
        p2 = edge_control(rec, edge, 2u);
        p3 = edge_control(rec, edge, 3u);
    }
    var order = compare_points(p0, p3);
    if (order == 0) {
        order = compare_points(p1, p2);
    }
    var k = edge.k;
    if (reversed_by(order, edge)) {
        let q0 = p0;
        let q1 = p1;
        p0 = p3;
        p1 = p2;
        p2 = q1;
        p3 = q0;
        k = edge.n - edge.k;
    }
    let t = f32(k) / f32(edge.n);
    let a0 = lerp_exact(p0, p1, t);
    let a1 = lerp_exact(p1, p2, t);
    let a2 = lerp_exact(p2, p3, t);
    let b0 = lerp_exact(a0, a1, t);
    let b1 = lerp_exact(a1, a2, t);
    let h = lerp_exact(b0, b1, t);
    return h.xyz / h.w;
}

// Any degree: de Casteljau over a private array (the general pipeline only).
fn general_edge_point(rec: PatchRecord, edge: Edge) -> vec3<f32> {
    if (edge.degree == 3u) {
        return cubic_edge_point(rec, edge);
    }
    let reversed = edge_reversed(rec, edge);
    var p: array<vec4<f32>, 10>;
    for (var m = 0u; m <= edge.degree; m++) {
        p[m] = edge_control(rec, edge, select(m, edge.degree - m, reversed));
    }
    let t = f32(select(edge.k, edge.n - edge.k, reversed)) / f32(edge.n);
    for (var r = 1u; r <= edge.degree; r++) {
        for (var m = 0u; m + r <= edge.degree; m++) {
            p[m] = lerp_exact(p[m], p[m + 1u], t);
        }
    }
    return p[0].xyz / p[0].w;
}

fn edge_point(rec: PatchRecord, edge: Edge) -> vec3<f32> {
    if (BICUBIC_ONLY) {
        return cubic_edge_point(rec, edge);
    }
    return general_edge_point(rec, edge);
}

// The position of grid vertex (i, j). On the patch boundary it is the boundary curve's point,
// computed in the canonical direction of edge_reversed, so that neighbouring patches (of one
// surface, or of two objects whose boundary control points are equal) write bit-identical
// vertices along their shared edge: no cracks. Elsewhere it is the tensor-product value.
fn grid_position(rec: PatchRecord, i: u32, j: u32, interior: vec3<f32>) -> vec3<f32> {
    let p = degree_u(rec);
    let q = degree_v(rec);
    let on_row = i == 0u || i == rec.segments_u;
    if (!on_row && j != 0u && j != rec.segments_v) {
        return interior;
    }
    // The row at u = 0 or 1 (entries r (q + 1) .. r (q + 1) + q, along v) takes precedence over
    // the column at v = 0 or 1 (entries c, c + (q + 1), ..., along u): one edge, chosen without
    // branching, so the edge is evaluated once even where branches run masked.
    let r = select(0u, p, i != 0u);
    let c = select(0u, q, j != 0u);
    return edge_point(rec, Edge(
        select(c, r * (q + 1u), on_row),
        select(q + 1u, 1u, on_row),
        select(p, q, on_row),
        select(i, j, on_row),
        select(rec.segments_u, rec.segments_v, on_row),
    ));
}

// Vertex `local` of a record's (segments_u + 1) x (segments_v + 1) grid: its (i, j) and local
// (s, t) in [0, 1]^2.
struct GridPoint {
    i: u32,
    j: u32,
    s: f32,
    t: f32,
}

fn grid_point(rec: PatchRecord, local: u32) -> GridPoint {
    let nv = rec.segments_v + 1u;
    return grid_point_at(rec, local / nv, local % nv);
}

fn grid_point_at(rec: PatchRecord, i: u32, j: u32) -> GridPoint {
    return GridPoint(i, j, f32(i) / f32(rec.segments_u), f32(j) / f32(rec.segments_v));
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
    vertices[rec.vertex_offset + local] = SurfaceVertex(
        v.position,
        rec.domain.x * (1.0 - g.s) + rec.domain.y * g.s,
        v.normal,
        rec.domain.z * (1.0 - g.t) + rec.domain.w * g.t,
        v.curvature,
        rec.object,
        v.flags,
        record,
        rec.level,
    );
}

// Grid vertex (i, j) of record `record` from its derivatives there: normal, curvature, the
// crack-free boundary position, stored.
fn write_grid_vertex(rec: PatchRecord, record: u32, i: u32, j: u32, d: Derivatives, shape: Shape) {
    let g = grid_point_at(rec, i, j);
    let position = grid_position(rec, i, j, d.point);
    store_vertex(rec, record, i * (rec.segments_v + 1u) + j, g, d, position, shape.normal, shape.curvature, shape.flags);
}

// The derivatives at row i of the column whose rows the invocation holds.
fn column_point(rec: PatchRecord, rows_cubic: CubicRows, rows: PatchRows, i: u32) -> Derivatives {
    let s = f32(i) / f32(rec.segments_u);
    if (BICUBIC_ONLY) {
        return bicubic_at(rows_cubic, s);
    }
    return patch_at(rec, rows, s);
}

// One invocation per run of up to GRID_ROWS (at most 32) vertices of one grid column (fixed j,
// so fixed t): the v-direction sums of the control point rows are formed once for the column,
// and each vertex of the run adds only the u-direction sums. workgroup_id.y indexes patch_list;
// item k of a record is column k % (segments_v + 1), rows from GRID_ROWS * (k / (segments_v + 1)).
//
// Shaped for CPU drivers too, where a storage read is a gather, lane by lane, and a branch runs
// masked rather than skipped: the control points are read once per run (into NET, bicubic), and
// the rare degenerate points (poles, collapsed edges) are only marked in the loop and finished
// in a second loop over the marked rows, which runs as often as its lanes need instead of
// costing every vertex.
@compute @workgroup_size(WORKGROUP_SIZE)
fn evaluate_vertices(
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(local_invocation_index) lane: u32,
) {
    if (group.y >= arrayLength(&patch_list)) {
        return;
    }
    let record = patch_list[group.y];
    let rec = patches[record];
    let item = group.x * WORKGROUP_SIZE + lane;
    let nv = rec.segments_v + 1u;
    let j = item % nv;
    let first = (item / nv) * GRID_ROWS;
    if (first > rec.segments_u) {
        return;
    }
    let last = min(first + GRID_ROWS, rec.segments_u + 1u);
    let t = f32(j) / f32(rec.segments_v);
    var rows_cubic: CubicRows;
    var rows: PatchRows;
    if (BICUBIC_ONLY) {
        NET = bicubic_net(rec);
        rows_cubic = bicubic_rows(NET, t);
    } else {
        rows = patch_rows(rec, t);
    }
    var irregular = 0u;  // bit i - first: row i is a degenerate point
    for (var i = first; i < last; i++) {
        let d = column_point(rec, rows_cubic, rows, i);
        let n = regular_normal(d);
        if (all(n == vec3<f32>(0.0))) {
            irregular |= 1u << (i - first);
            continue;
        }
        write_grid_vertex(rec, record, i, j, d, regular_shape(d, n));
    }
    while (irregular != 0u) {
        let i = first + firstTrailingBit(irregular);
        irregular &= irregular - 1u;
        let d = column_point(rec, rows_cubic, rows, i);
        write_grid_vertex(rec, record, i, j, d, irregular_shape(rec, d, f32(i) / f32(rec.segments_u), t));
    }
}

// Subdivision limit stencils: one invocation per slot of a stencil patch (workgroup_id.y indexes
// patch_list). Gathers the position and derivatives from the cage points (no atomics), then the
// normal and, where the stencils define them, the curvatures.
@compute @workgroup_size(WORKGROUP_SIZE)
fn evaluate_stencil_vertices(
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(local_invocation_index) lane: u32,
) {
    if (group.y >= arrayLength(&patch_list)) {
        return;
    }
    let rec = patches[patch_list[group.y]];
    let local = group.x * WORKGROUP_SIZE + lane;
    if (local >= (rec.segments_u + 1u) * (rec.segments_v + 1u)) {
        return;
    }
    if (rec.kind >= PATCH_KIND_ACC) {
        write_substitute_vertex(rec, patch_list[group.y], local);
        return;
    }
    let start = control_indices[rec.control_offset + 2u * local];
    let packed = control_indices[rec.control_offset + 2u * local + 1u];
    let count = packed & ~STENCIL_NO_CURVATURE;
    var d: Derivatives;
    for (var k = 0u; k < count; k++) {
        let a = control_points[start + 2u * k];
        let b = control_points[start + 2u * k + 1u];
        let p = control_points[bitcast<u32>(a.x)].xyz;
        d.point += a.y * p;
        d.su += a.z * p;
        d.sv += a.w * p;
        d.suu += b.x * p;
        d.suv += b.y * p;
        d.svv += b.z * p;
    }
    var normal = regular_normal(d);
    var flags = 0u;
    var values = vec4<f32>(0.0);
    if (all(normal == vec3<f32>(0.0))) {
        normal = vec3<f32>(0.0, 0.0, 1.0);
        flags = VERTEX_IRREGULAR | VERTEX_NO_CURVATURE;
    } else if ((packed & STENCIL_NO_CURVATURE) != 0u) {
        flags = VERTEX_NO_CURVATURE;
    } else {
        let k = curvature(d, normal);
        values = k.values;
        if (!k.defined) {
            flags = VERTEX_NO_CURVATURE;
        }
    }
    let g = grid_point(rec, local);
    store_vertex(rec, patch_list[group.y], local, g, d, d.point, normal, values, flags);
}

// Control point k of a substitute patch (its weight is 1).
fn substitute_point(rec: PatchRecord, k: u32) -> vec3<f32> {
    return control_points[control_indices[rec.control_offset + k]].xyz;
}

// Slot `local` of a substitute patch (ACC, Gregory, PN triangle; substitutes.wgsl) evaluated
// from its control points: the position, the substitute's own normal and the curvature of its
// geometry (from the fundamental forms with the geometric normal Su x Sv).
fn write_substitute_vertex(rec: PatchRecord, record: u32, local: u32) {
    let g = grid_point(rec, local);
    var sample: SubstituteSample;
    if (rec.kind == PATCH_KIND_ACC) {
        var points: array<vec3<f32>, 40>;
        for (var k = 0u; k < 40u; k++) {
            points[k] = substitute_point(rec, k);
        }
        sample = acc_sample(points, g.s, g.t);
    } else if (rec.kind == PATCH_KIND_GREGORY) {
        var points: array<vec3<f32>, 20>;
        for (var k = 0u; k < 20u; k++) {
            points[k] = substitute_point(rec, k);
        }
        sample = gregory_sample(points, g.s, g.t);
    } else {
        var points: array<vec3<f32>, 16>;
        for (var k = 0u; k < 16u; k++) {
            points[k] = substitute_point(rec, k);
        }
        sample = pn_triangle_sample(points, g.s, g.t);
    }
    let geometric = regular_normal(sample.d);
    var normal = sample.normal;
    if (all(normal == vec3<f32>(0.0))) {
        normal = geometric;
    }
    var flags = 0u;
    var values = vec4<f32>(0.0);
    if (all(geometric == vec3<f32>(0.0))) {
        flags = VERTEX_NO_CURVATURE;
        if (all(normal == vec3<f32>(0.0))) {
            normal = vec3<f32>(0.0, 0.0, 1.0);
            flags |= VERTEX_IRREGULAR;
        }
    } else if (!sample.curvature_defined) {
        flags = VERTEX_NO_CURVATURE;
    } else {
        let k = curvature(sample.d, geometric);
        values = k.values;
        if (!k.defined) {
            flags = VERTEX_NO_CURVATURE;
        }
    }
    store_vertex(rec, record, local, g, sample.d, sample.d.point, normal, values, flags);
}

// One invocation per grid quad: two counter-clockwise triangles (seen from the side Su x Sv
// points to). workgroup_id.y is the patch record.
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
    // A patch wholly trimmed away has no triangles.
    if (rec.trim_count == TRIM_CULLED || quad >= rec.segments_u * rec.segments_v) {
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
    if (rec.kind == PATCH_KIND_STENCIL_TRIANGLE || rec.kind == PATCH_KIND_PN_TRIANGLE) {
        // The lattice i + j <= segments: the cell's lower triangle, and its upper one inside.
        let inside = i + j + 1u <= rec.segments_u;
        let upper = i + j + 2u <= rec.segments_u;
        triangle_indices[o] = a;
        triangle_indices[o + 1u] = select(a, b, inside);
        triangle_indices[o + 2u] = select(a, d, inside);
        triangle_indices[o + 3u] = select(a, b, upper);
        triangle_indices[o + 4u] = select(a, c, upper);
        triangle_indices[o + 5u] = select(a, d, upper);
        return;
    }
    triangle_indices[o] = a;
    triangle_indices[o + 1u] = b;
    triangle_indices[o + 2u] = c;
    triangle_indices[o + 3u] = a;
    triangle_indices[o + 4u] = c;
    triangle_indices[o + 5u] = d;
}

// Point evaluation for `knotwork eval --backend gpu`: one invocation per sample, with the
// derivatives in the patch's local (s, t); the caller scales them to the surface's domain.
@compute @workgroup_size(WORKGROUP_SIZE)
fn evaluate_samples(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= arrayLength(&samples)) {
        return;
    }
    let sample = samples[id.x];
    let rec = patches[sample.patch_index];
    let d = evaluate(rec, sample.s, sample.t);
    let shape = shape_at(rec, d, sample.s, sample.t);
    sample_results[id.x] = PointResult(
        vec4<f32>(d.point, 1.0),
        vec4<f32>(shape.normal, 0.0),
        vec4<f32>(d.su, 0.0),
        vec4<f32>(d.sv, 0.0),
        vec4<f32>(d.suu, 0.0),
        vec4<f32>(d.suv, 0.0),
        vec4<f32>(d.svv, 0.0),
        shape.curvature,
        vec4<u32>(shape.flags, 0u, 0u, 0u),
    );
}

// ---------------------------------------------------------------------------------------------
// View-adaptive tessellation (Rust driver: gpu::patch_eval, Tessellation::Adaptive). Four
// passes, all recorded in one compute pass:
//   measure_levels     one invocation per slot: frustum culling of the control hull and the
//                      edge and interior segment counts for the screen-space error;
//   scan_levels        one workgroup: coarsens every level alike while the total would overflow
//                      the buffers, then the prefix sums that place each patch, and the indirect
//                      dispatch and draw arguments;
//   evaluate_adaptive_vertices (one pipeline per degree pair, as evaluate_vertices) and
//   write_adaptive_triangles, dispatched indirectly.

@group(0) @binding(8) var<storage, read_write> adaptive_slots: array<AdaptiveSlot>;
@group(0) @binding(9) var<uniform> adaptive_view: AdaptiveView;
@group(0) @binding(10) var<storage, read_write> adaptive_args: array<u32>;

// Words of adaptive_args (Rust: gpu::adaptive_pass::ADAPTIVE_ARGS_*): the draw_indexed_indirect
// arguments, the triangles' dispatch, the statistics, then per pipeline group its slot range
// (written by the CPU), its dispatch, and the dispatch of evaluate_adaptive_slots (x from the
// scan, y from the CPU).
const ARGS_DRAW: u32 = 0u;
const ARGS_TRIANGLES: u32 = 5u;
// (coarsening shift, vertices needed unshifted, indices needed unshifted, visible slots,
// vertices written, indices written, slots dropped for want of room, 0).
const ARGS_STATS: u32 = 8u;
const ARGS_GROUPS: u32 = 16u;
const ARGS_GROUP_WORDS: u32 = 8u;
// Workgroups per row of a flat indirect dispatch (the rest go to y).
const FLAT_ROW: u32 = 32768u;
const SCAN_SIZE: u32 = 256u;

// The invocation's index in a flat dispatch of FLAT_ROW-wide rows.
fn flat_index(group: vec3<u32>, groups: vec3<u32>, lane: u32) -> u32 {
    return (group.y * groups.x + group.x) * WORKGROUP_SIZE + lane;
}

// Segments for the Bézier curve through the patch's control entries first + m * stride,
// m = 0..degree, so that its polyline stays within the tolerance on screen (the rule of
// gpu::adaptive::ScreenError::curve_segments: chord error <= d (d - 1) max |Δ²P| / (8 n²),
// rational curves scaled by (w_max / w_min)², plus the longest-edge rule). Walked in the
// canonical direction of edge_reversed, so that two patches sharing the edge get the same
// count bit for bit.
fn adaptive_curve_segments(rec: PatchRecord, first: u32, stride: u32, degree: u32) -> u32 {
    let most = max(adaptive_view.counts.y, 1u);
    if (degree == 0u) {
        return 1u;
    }
    var order = 0;
    for (var m = 0u; 2u * m < degree && order == 0; m++) {
        order = compare_points(
            control_point(rec, first + m * stride),
            control_point(rec, first + (degree - m) * stride),
        );
    }
    let reversed = order > 0;
    var depth = 3.0e38;
    var w_min = 3.0e38;
    var w_max = 0.0;
    var second = 0.0;
    var chord = 0.0;
    var previous = vec3<f32>(0.0);
    var before = vec3<f32>(0.0);
    for (var m = 0u; m <= degree; m++) {
        let h = control_point(rec, first + select(m, degree - m, reversed) * stride);
        let p = h.xyz / h.w;
        depth = min(depth, dot(p - adaptive_view.eye.xyz, adaptive_view.forward.xyz));
        w_min = min(w_min, h.w);
        w_max = max(w_max, h.w);
        if (m >= 1u) {
            chord += length(p - previous);
        }
        if (m >= 2u) {
            second = max(second, length(p - 2.0 * previous + before));
        }
        before = previous;
        previous = p;
    }
    var pixel = adaptive_view.error.x;
    if (adaptive_view.counts.x == 0u) {
        pixel = max(depth, adaptive_view.error.y) * adaptive_view.error.x;
    }
    let ratio = (w_max / w_min) * (w_max / w_min);
    let bound = f32(degree * (degree - 1u)) * second * ratio;
    let sag = ceil(sqrt(bound / (8.0 * adaptive_view.error.z * pixel)));
    let long = ceil(chord / (adaptive_view.error.w * pixel));
    let n = max(max(sag, long), 1.0);
    // Not finite, or beyond the cap: the cap.
    if (!(n <= f32(most))) {
        return most;
    }
    return u32(n);
}

// Whether every control point of the patch lies outside one plane of the view frustum (clip
// space of the homogeneous points: the weights are positive, so the signs are those of the
// Euclidean points). The patch lies in its control hull, so it is then out of view.
fn hull_outside_view(rec: PatchRecord) -> bool {
    // A deformed patch is not where its control points are.
    if (rec.lattice != LATTICE_NONE) {
        return false;
    }
    let count = (rec.degree_u + 1u) * (rec.degree_v + 1u);
    var outside = 63u;
    for (var k = 0u; k < count && outside != 0u; k++) {
        let c = adaptive_view.view_proj * control_point(rec, k);
        var code = 0u;
        code |= select(0u, 1u, c.x < -c.w);
        code |= select(0u, 2u, c.x > c.w);
        code |= select(0u, 4u, c.y < -c.w);
        code |= select(0u, 8u, c.y > c.w);
        code |= select(0u, 16u, c.z < 0.0);
        code |= select(0u, 32u, c.z > c.w);
        outside &= code;
    }
    return outside != 0u;
}

// The least segments (along s, along t) a displaced record's pattern needs: its segments per cycle
// (params.w: 8, or an image's pixels) times its frequency over the share of the object's domain
// the record spans (the export's rule).
// Neighbours along an edge span the same share of it, so they agree on its count.
fn displacement_segments(rec: PatchRecord) -> vec2<u32> {
    if (rec.displacement == DISPLACEMENT_NONE) {
        return vec2<u32>(1u);
    }
    let params = control_points[rec.displacement];
    let object = control_points[rec.displacement + 1u];
    let share = (rec.domain.yw - rec.domain.xz) / max(object.yw - object.xz, vec2<f32>(1e-30));
    let most = f32(max(adaptive_view.counts.y, 1u));
    return vec2<u32>(clamp(ceil(params.w * params.z * share), vec2<f32>(1.0), vec2<f32>(most)));
}

// The levels of every slot's patch: each edge from its own curve, each interior direction the
// most any row of the net along it needs (gpu::adaptive::ScreenError::patch_levels); a
// displaced patch at least what its pattern needs (displacement_segments).
@compute @workgroup_size(WORKGROUP_SIZE)
fn measure_levels(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= adaptive_view.counts.z) {
        return;
    }
    var slot = adaptive_slots[id.x];
    let rec = patches[slot.record];
    let p = rec.degree_u;
    let q = rec.degree_v;
    slot.culled = select(0u, 1u, hull_outside_view(rec));
    if (slot.culled == 0u) {
        slot.edges = vec4<u32>(
            adaptive_curve_segments(rec, 0u, q + 1u, p),
            adaptive_curve_segments(rec, p * (q + 1u), 1u, q),
            adaptive_curve_segments(rec, q, q + 1u, p),
            adaptive_curve_segments(rec, 0u, 1u, q),
        );
        // The boundary rows are the edges just measured; only the inner rows remain.
        // nu (along s) from edges 0 and 2, nv (along t) from edges 1 and 3.
        var inner = max(vec2<u32>(2u), max(slot.edges.xy, slot.edges.zw));
        for (var j = 1u; j < q; j++) {
            inner.x = max(inner.x, adaptive_curve_segments(rec, j, q + 1u, p));
        }
        for (var i = 1u; i < p; i++) {
            inner.y = max(inner.y, adaptive_curve_segments(rec, i * (q + 1u), 1u, q));
        }
        var least = displacement_segments(rec);
        if (rec.lattice != LATTICE_NONE) {
            // The hull measures the undeformed patch: at least 2 segments per degree of the
            // lattice's map.
            let degrees = lattice_degrees(rec.lattice);
            let total = degrees.x + degrees.y + degrees.z;
            least = max(least, vec2<u32>(min(2u * total, max(adaptive_view.counts.y, 1u))));
        }
        slot.edges = max(slot.edges, least.xyxy);
        slot.inner = max(inner, least);
    }
    adaptive_slots[id.x] = slot;
}

// A level halved `shift` times (rounding up), at least `least`.
fn coarsened(level: u32, shift: u32, least: u32) -> u32 {
    return max(least, (level + (1u << shift) - 1u) >> shift);
}

fn coarsened_edges(slot: AdaptiveSlot, shift: u32) -> vec4<u32> {
    return vec4<u32>(
        coarsened(slot.edges.x, shift, 1u),
        coarsened(slot.edges.y, shift, 1u),
        coarsened(slot.edges.z, shift, 1u),
        coarsened(slot.edges.w, shift, 1u),
    );
}

fn coarsened_inner(slot: AdaptiveSlot, shift: u32) -> vec2<u32> {
    return vec2<u32>(coarsened(slot.inner.x, shift, 2u), coarsened(slot.inner.y, shift, 2u));
}

// a + b, saturating at the largest u32.
fn add_saturating(a: u32, b: u32) -> u32 {
    let sum = a + b;
    return select(sum, 0xFFFFFFFFu, sum < a);
}

var<workgroup> scan_vertices: array<u32, SCAN_SIZE>;
var<workgroup> scan_indices: array<u32, SCAN_SIZE>;
var<workgroup> scan_fits: u32;
var<workgroup> scan_end_vertex: atomic<u32>;
var<workgroup> scan_end_index: atomic<u32>;
var<workgroup> scan_dropped: atomic<u32>;
var<workgroup> scan_most: atomic<u32>;

// Sums this lane's share of the slots' vertex and index counts at `shift` into the workgroup
// arrays and reduces them into element 0 (saturating).
fn scan_totals(lane: u32, shift: u32) {
    let n = adaptive_view.counts.z;
    var vertices_needed = 0u;
    var indices_needed = 0u;
    for (var k = lane; k < n; k += SCAN_SIZE) {
        let slot = adaptive_slots[k];
        if (slot.culled == 0u) {
            let edges = coarsened_edges(slot, shift);
            let inner = coarsened_inner(slot, shift);
            vertices_needed = add_saturating(vertices_needed, adaptive_vertex_count(edges, inner));
            indices_needed = add_saturating(indices_needed, 3u * adaptive_triangle_count(edges, inner));
        }
    }
    scan_vertices[lane] = vertices_needed;
    scan_indices[lane] = indices_needed;
    workgroupBarrier();
    for (var stride = SCAN_SIZE / 2u; stride > 0u; stride >>= 1u) {
        if (lane < stride) {
            scan_vertices[lane] = add_saturating(scan_vertices[lane], scan_vertices[lane + stride]);
            scan_indices[lane] = add_saturating(scan_indices[lane], scan_indices[lane + stride]);
        }
        workgroupBarrier();
    }
}

// Writes the indirect arguments of a flat dispatch over `items` invocations at `word`.
fn write_flat_dispatch(word: u32, items: u32) {
    let groups = (items + WORKGROUP_SIZE - 1u) / WORKGROUP_SIZE;
    let x = min(groups, FLAT_ROW);
    adaptive_args[word] = x;
    adaptive_args[word + 1u] = select(0u, (groups + x - 1u) / max(x, 1u), groups > 0u);
    adaptive_args[word + 2u] = 1u;
}

// One workgroup. Finds the smallest coarsening shift at which every visible patch fits the
// buffers (each level halved `shift` times alike, so shared edges still agree), places the
// patches by prefix sums, and writes the dispatch and draw arguments. Should even the coarsest
// levels not fit, the patches past the room are dropped (counted in the statistics).
@compute @workgroup_size(SCAN_SIZE)
fn scan_levels(@builtin(local_invocation_index) lane: u32) {
    let n = adaptive_view.counts.z;
    let vertex_room = adaptive_view.counts.w;
    let index_room = adaptive_view.bases.x;
    let first_vertex = adaptive_view.bases.y;
    let first_index = adaptive_view.bases.z;
    if (lane == 0u) {
        atomicStore(&scan_end_vertex, first_vertex);
        atomicStore(&scan_end_index, first_index);
        atomicStore(&scan_dropped, 0u);
        atomicStore(&scan_most, 0u);
    }
    // The totals unshifted (what the buffers would need), then shifted until they fit.
    scan_totals(lane, 0u);
    let needed_vertices = add_saturating(scan_vertices[0], first_vertex);
    let needed_indices = add_saturating(scan_indices[0], first_index);
    workgroupBarrier();
    var shift = 0u;
    loop {
        if (lane == 0u) {
            let fits = add_saturating(scan_vertices[0], first_vertex) <= vertex_room
                && add_saturating(scan_indices[0], first_index) <= index_room;
            scan_fits = select(0u, 1u, fits);
        }
        if (workgroupUniformLoad(&scan_fits) == 1u || shift >= 16u) {
            break;
        }
        shift += 1u;
        scan_totals(lane, shift);
    }
    // Prefix sums, SCAN_SIZE slots at a time (Hillis-Steele within the chunk).
    var carry_vertices = first_vertex;
    var carry_indices = first_index;
    var visible = 0u;
    for (var chunk = 0u; chunk < n; chunk += SCAN_SIZE) {
        let k = chunk + lane;
        var slot: AdaptiveSlot;
        var own_vertices = 0u;
        var own_indices = 0u;
        if (k < n) {
            slot = adaptive_slots[k];
            if (slot.culled == 0u) {
                slot.edges = coarsened_edges(slot, shift);
                slot.inner = coarsened_inner(slot, shift);
                own_vertices = adaptive_vertex_count(slot.edges, slot.inner);
                own_indices = 3u * adaptive_triangle_count(slot.edges, slot.inner);
                visible += 1u;
            }
        }
        workgroupBarrier();
        scan_vertices[lane] = own_vertices;
        scan_indices[lane] = own_indices;
        workgroupBarrier();
        for (var offset = 1u; offset < SCAN_SIZE; offset <<= 1u) {
            var add_vertices = 0u;
            var add_indices = 0u;
            if (lane >= offset) {
                add_vertices = scan_vertices[lane - offset];
                add_indices = scan_indices[lane - offset];
            }
            workgroupBarrier();
            scan_vertices[lane] = add_saturating(scan_vertices[lane], add_vertices);
            scan_indices[lane] = add_saturating(scan_indices[lane], add_indices);
            workgroupBarrier();
        }
        if (k < n) {
            let vertex_end = add_saturating(carry_vertices, scan_vertices[lane]);
            let index_end = add_saturating(carry_indices, scan_indices[lane]);
            slot.vertex_offset = vertex_end - own_vertices;
            slot.index_offset = index_end - own_indices;
            if (vertex_end <= vertex_room && index_end <= index_room) {
                slot.vertex_count = own_vertices;
                slot.triangle_count = own_indices / 3u;
                atomicMax(&scan_end_vertex, vertex_end);
                atomicMax(&scan_end_index, index_end);
                atomicMax(&scan_most, own_vertices);
            } else {
                slot.vertex_count = 0u;
                slot.triangle_count = 0u;
                if (own_vertices > 0u) {
                    atomicAdd(&scan_dropped, 1u);
                }
            }
            adaptive_slots[k] = slot;
        }
        carry_vertices = add_saturating(carry_vertices, scan_vertices[SCAN_SIZE - 1u]);
        carry_indices = add_saturating(carry_indices, scan_indices[SCAN_SIZE - 1u]);
    }
    // Visible slots, summed over the lanes.
    workgroupBarrier();
    scan_vertices[lane] = visible;
    workgroupBarrier();
    for (var stride = SCAN_SIZE / 2u; stride > 0u; stride >>= 1u) {
        if (lane < stride) {
            scan_vertices[lane] += scan_vertices[lane + stride];
        }
        workgroupBarrier();
    }
    storageBarrier();
    if (lane != 0u) {
        return;
    }
    let end_vertex = atomicLoad(&scan_end_vertex);
    let end_index = atomicLoad(&scan_end_index);
    adaptive_args[ARGS_DRAW] = end_index;
    adaptive_args[ARGS_DRAW + 1u] = 1u;
    adaptive_args[ARGS_DRAW + 2u] = 0u;
    adaptive_args[ARGS_DRAW + 3u] = 0u;
    adaptive_args[ARGS_DRAW + 4u] = 0u;
    write_flat_dispatch(ARGS_TRIANGLES, (end_index - first_index) / 3u);
    adaptive_args[ARGS_STATS] = shift;
    adaptive_args[ARGS_STATS + 1u] = needed_vertices;
    adaptive_args[ARGS_STATS + 2u] = needed_indices;
    adaptive_args[ARGS_STATS + 3u] = scan_vertices[0];
    adaptive_args[ARGS_STATS + 4u] = end_vertex;
    adaptive_args[ARGS_STATS + 5u] = end_index;
    adaptive_args[ARGS_STATS + 6u] = atomicLoad(&scan_dropped);
    let group_count = adaptive_view.bases.w;
    for (var g = 0u; g < group_count; g++) {
        let word = ARGS_GROUPS + g * ARGS_GROUP_WORDS;
        let first = adaptive_args[word];
        let count = adaptive_args[word + 1u];
        var items = 0u;
        if (count > 0u) {
            let start = adaptive_slots[first].vertex_offset;
            let last = adaptive_slots[first + count - 1u];
            let end = min(last.vertex_offset + last.vertex_count, end_vertex);
            items = select(0u, end - start, end > start);
        }
        write_flat_dispatch(word + 2u, items);
        // The dispatch of evaluate_adaptive_slots while the levels are frozen: wide enough for
        // the largest patch; the CPU writes the slot count (y) before each.
        adaptive_args[word + 5u] = (atomicLoad(&scan_most) + WORKGROUP_SIZE - 1u) / WORKGROUP_SIZE;
        adaptive_args[word + 7u] = 1u;
    }
}

// The slot in [first, first + count) holding vertex `wanted` (by_index false) or index
// `wanted` (true): the last one whose offset is at most `wanted` (offsets never decrease).
fn find_slot(first: u32, count: u32, wanted: u32, by_index: bool) -> u32 {
    var lo = first;
    var hi = first + count;
    while (hi - lo > 1u) {
        let mid = (lo + hi) / 2u;
        let slot = adaptive_slots[mid];
        let offset = select(slot.vertex_offset, slot.index_offset, by_index);
        if (offset <= wanted) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    return lo;
}

// The boundary curve under an edge vertex of the adaptive layout, as grid_position's Edge.
fn adaptive_boundary(rec: PatchRecord, v: AdaptiveVertex) -> Edge {
    let p = degree_u(rec);
    let q = degree_v(rec);
    switch v.edge {
        case 0u: { return Edge(0u, q + 1u, p, v.m, v.e); }          // t = 0, along s
        case 1u: { return Edge(p * (q + 1u), 1u, q, v.m, v.e); }    // s = 1, along t
        case 2u: { return Edge(q, q + 1u, p, v.m, v.e); }           // t = 1, along s
        default: { return Edge(0u, 1u, q, v.m, v.e); }              // s = 0, along t
    }
}

// Writes vertex `local` of a slot's layout. Boundary vertices come from the boundary curve in
// its canonical direction, as in the fixed tessellation: neighbours that give an edge the same
// count write the same vertices on it.
fn write_adaptive_vertex(slot: AdaptiveSlot, local: u32) {
    let rec = patches[slot.record];
    let v = adaptive_vertex(slot.edges, slot.inner, local);
    let d = evaluate(rec, v.st.x, v.st.y);
    let shape = shape_at(rec, d, v.st.x, v.st.y);
    var position = d.point;
    if (v.edge != ADAPTIVE_INTERIOR) {
        position = edge_point(rec, adaptive_boundary(rec, v));
    }
    let out = finish_vertex(rec, d, position, shape.normal, shape.curvature, shape.flags, v.st.x, v.st.y);
    vertices[slot.vertex_offset + local] = SurfaceVertex(
        out.position,
        rec.domain.x * (1.0 - v.st.x) + rec.domain.y * v.st.x,
        out.normal,
        rec.domain.z * (1.0 - v.st.y) + rec.domain.w * v.st.y,
        out.curvature,
        rec.object,
        out.flags,
        slot.record,
        0u,
    );
}

// One invocation per vertex of a pipeline group's patches (patch_list = (first slot, slot
// count) of the group), dispatched indirectly by scan_levels.
@compute @workgroup_size(WORKGROUP_SIZE)
fn evaluate_adaptive_vertices(
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
    @builtin(local_invocation_index) lane: u32,
) {
    let first = patch_list[0];
    let count = patch_list[1];
    if (count == 0u) {
        return;
    }
    let wanted = adaptive_slots[first].vertex_offset + flat_index(group, groups, lane);
    let slot = adaptive_slots[find_slot(first, count, wanted, false)];
    if (wanted < slot.vertex_offset || wanted - slot.vertex_offset >= slot.vertex_count) {
        return;
    }
    write_adaptive_vertex(slot, wanted - slot.vertex_offset);
}

// One invocation per vertex of the slots patch_list names (workgroup_id.y), at the levels the
// last measure gave them: while a drag lasts only the patches it changes are re-evaluated, and
// nothing moves in the buffers.
@compute @workgroup_size(WORKGROUP_SIZE)
fn evaluate_adaptive_slots(
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(local_invocation_index) lane: u32,
) {
    if (group.y >= arrayLength(&patch_list)) {
        return;
    }
    let slot = adaptive_slots[patch_list[group.y]];
    let local = group.x * WORKGROUP_SIZE + lane;
    if (local >= slot.vertex_count) {
        return;
    }
    write_adaptive_vertex(slot, local);
}

// One invocation per triangle of every adaptive patch, dispatched indirectly by scan_levels.
@compute @workgroup_size(WORKGROUP_SIZE)
fn write_adaptive_triangles(
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
    @builtin(local_invocation_index) lane: u32,
) {
    let n = adaptive_view.counts.z;
    if (n == 0u) {
        return;
    }
    let wanted = adaptive_view.bases.z + 3u * flat_index(group, groups, lane);
    let slot = adaptive_slots[find_slot(0u, n, wanted, true)];
    if (wanted < slot.index_offset) {
        return;
    }
    let local = (wanted - slot.index_offset) / 3u;
    if (local >= slot.triangle_count) {
        return;
    }
    let tri = adaptive_triangle(slot.edges, slot.inner, local);
    triangle_indices[wanted] = slot.vertex_offset + tri.x;
    triangle_indices[wanted + 1u] = slot.vertex_offset + tri.y;
    triangle_indices[wanted + 2u] = slot.vertex_offset + tri.z;
}
