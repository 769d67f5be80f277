// Part of the evaluator (see eval_bezier.wgsl): patch boundaries evaluated along the boundary
// curve in one canonical direction, so that every patch sharing an edge writes bit-identical
// vertices along it (no cracks), whichever side it is on.

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
