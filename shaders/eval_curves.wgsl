// Curve evaluation: every listed rational Bézier segment is sampled at evenly spaced parameters
// by de Casteljau's algorithm on its homogeneous points (The NURBS Book A1.5), then projected,
// straight into the curve vertex buffer that the viewport draws as anti-aliased lines.

@group(0) @binding(0) var<storage, read> curve_points: array<vec4<f32>>;
@group(0) @binding(1) var<storage, read> curve_records: array<CurveRecord>;
// [count, record, record, ...]: the segments to evaluate.
@group(0) @binding(2) var<storage, read> curve_todo: array<u32>;
@group(0) @binding(3) var<storage, read_write> curve_vertices: array<CurveVertex>;

// One workgroup per listed segment (rows of the dispatch continue the list); each invocation
// writes every CURVE_WORKGROUP_SIZE-th sample.
@compute @workgroup_size(CURVE_WORKGROUP_SIZE)
fn eval_curves(
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
    @builtin(local_invocation_index) lane: u32,
) {
    let slot = group.x + group.y * groups.x;
    if (slot >= curve_todo[0]) {
        return;
    }
    let index = curve_todo[slot + 1u];
    let rec = curve_records[index];
    let degree = min(rec.degree, CURVE_MAX_DEGREE);
    for (var k = lane; k <= rec.segments; k += CURVE_WORKGROUP_SIZE) {
        let s = f32(k) / f32(rec.segments);
        var q: array<vec4<f32>, 33>;
        for (var i = 0u; i <= degree; i++) {
            q[i] = curve_points[rec.control_offset + i];
        }
        for (var r = 1u; r <= degree; r++) {
            for (var i = 0u; i + r <= degree; i++) {
                q[i] = q[i] * (1.0 - s) + q[i + 1u] * s;
            }
        }
        var out: CurveVertex;
        out.position = vec4<f32>(q[0].xyz / q[0].w, select(1.0, 0.0, k == rec.segments));
        out.object = rec.object;
        out.record = index;
        out.s = s;
        out.reserved = 0u;
        curve_vertices[rec.vertex_offset + k] = out;
    }
}
