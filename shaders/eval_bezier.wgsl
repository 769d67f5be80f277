// Evaluates rational tensor-product Bézier patches into a vertex buffer (position, normal, (u, v),
// curvature), and writes their triangle indices. The CPU reference is src/kernel/bezier.rs and
// src/kernel/diffgeo.rs; both use the same formulas: Bernstein basis by The NURBS Book A1.3,
// derivatives in hodograph (difference) form, the rational quotient rule of The NURBS Book
// eq. 4.20, the same normal rule at collapsed edges, and curvature from the fundamental forms.

const MAX_DEGREE: u32 = 9u;          // Rust: gpu::records::GPU_MAX_DEGREE
const WORKGROUP_SIZE: u32 = 64u;     // Rust: gpu::records::EVAL_WORKGROUP_SIZE
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

// Position and partial derivatives up to order 2 of a patch of any degree up to MAX_DEGREE at
// local (s, t) in [0, 1]^2.
fn evaluate_patch(rec: PatchRecord, s: f32, t: f32) -> Derivatives {
    let p = degree_u(rec);
    let q = degree_v(rec);
    let bu = make_basis(p, s);
    let bv = make_basis(q, t);
    var rows0: array<vec4<f32>, 10>;
    var rows1: array<vec4<f32>, 10>;
    var rows2: array<vec4<f32>, 10>;
    for (var i = 0u; i <= p; i++) {
        var row: array<vec4<f32>, 10>;
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

fn evaluate(rec: PatchRecord, s: f32, t: f32) -> Derivatives {
    if (BICUBIC_ONLY) {
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

fn shape_at(rec: PatchRecord, d: Derivatives, s: f32, t: f32) -> Shape {
    var out: Shape;
    var k: CurvatureResult;
    let regular = regular_normal(d);
    if (any(regular != vec3<f32>(0.0))) {
        out.normal = regular;
        k = curvature(d, regular);
    } else {
        out.flags = VERTEX_IRREGULAR;
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
        out.normal = n;
        // Keep the orientation of the limit normal at the point itself.
        if (dot(inside, n) < 0.0) {
            inside = -inside;
        }
        if (any(inside != vec3<f32>(0.0))) {
            k = curvature(nd, inside);
        }
    }
    if (!k.defined) {
        out.flags |= VERTEX_NO_CURVATURE;
    }
    out.curvature = k.values;
    return out;
}

// -1, 0 or 1 as a is lexicographically (x, y, z, w) before, equal to or after b.
fn compare_points(a: vec4<f32>, b: vec4<f32>) -> i32 {
    for (var k = 0; k < 4; k++) {
        if (a[k] < b[k]) {
            return -1;
        }
        if (a[k] > b[k]) {
            return 1;
        }
    }
    return 0;
}

// One de Casteljau step (The NURBS Book, A1.5) written so that t = 0 gives a, t = 1 gives b and
// equal points give that point, each exactly.
fn lerp_exact(a: vec4<f32>, b: vec4<f32>, t: f32) -> vec4<f32> {
    if (t <= 0.5) {
        return a + t * (b - a);
    }
    return b + (1.0 - t) * (a - b);
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
    return order > 0 || (order == 0 && 2u * edge.k > edge.n);
}

// A cubic edge's point, in registers (the bicubic pipeline has no private arrays).
fn cubic_edge_point(rec: PatchRecord, edge: Edge) -> vec3<f32> {
    let reversed = edge_reversed(rec, edge);
    var p0 = edge_control(rec, edge, 0u);
    var p1 = edge_control(rec, edge, 1u);
    var p2 = edge_control(rec, edge, 2u);
    var p3 = edge_control(rec, edge, 3u);
    var k = edge.k;
    if (reversed) {
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
    if (i == 0u || i == rec.segments_u) {
        // The row at u = 0 or 1: entries r (q + 1) .. r (q + 1) + q, along v.
        let r = select(0u, p, i != 0u);
        return edge_point(rec, Edge(r * (q + 1u), 1u, q, j, rec.segments_v));
    }
    if (j == 0u || j == rec.segments_v) {
        // The column at v = 0 or 1: entries c, c + (q + 1), ..., along u.
        let c = select(0u, q, j != 0u);
        return edge_point(rec, Edge(c, q + 1u, p, i, rec.segments_u));
    }
    return interior;
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
    let i = local / nv;
    let j = local % nv;
    return GridPoint(i, j, f32(i) / f32(rec.segments_u), f32(j) / f32(rec.segments_v));
}

// Writes grid vertex `g` of record `record`, its (u, v) mapped into the record's domain.
fn store_vertex(
    rec: PatchRecord,
    record: u32,
    local: u32,
    g: GridPoint,
    position: vec3<f32>,
    normal: vec3<f32>,
    curvature: vec4<f32>,
    flags: u32,
) {
    vertices[rec.vertex_offset + local] = SurfaceVertex(
        position,
        rec.domain.x * (1.0 - g.s) + rec.domain.y * g.s,
        normal,
        rec.domain.z * (1.0 - g.t) + rec.domain.w * g.t,
        curvature,
        rec.object,
        flags,
        record,
        0u,
    );
}

// One invocation per output vertex; workgroup_id.y indexes patch_list.
@compute @workgroup_size(WORKGROUP_SIZE)
fn evaluate_vertices(
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
    let g = grid_point(rec, local);
    let d = evaluate(rec, g.s, g.t);
    let shape = shape_at(rec, d, g.s, g.t);
    let position = grid_position(rec, g.i, g.j, d.point);
    store_vertex(rec, patch_list[group.y], local, g, position, shape.normal, shape.curvature, shape.flags);
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
    store_vertex(rec, patch_list[group.y], local, g, d.point, normal, values, flags);
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
    if (rec.kind == PATCH_KIND_STENCIL_TRIANGLE) {
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
