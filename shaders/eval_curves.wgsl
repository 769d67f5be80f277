// Curve evaluation: every listed rational Bézier segment is sampled at evenly spaced parameters
// as the Bernstein sum of its homogeneous points (The NURBS Book eq. 1.7, in Horner's form), then
// projected, straight into the curve vertex buffer that the viewport draws as anti-aliased lines.

@group(0) @binding(0) var<storage, read> curve_points: array<vec4<f32>>;
@group(0) @binding(1) var<storage, read> curve_records: array<CurveRecord>;
// [count, record, record, ...]: the segments to evaluate.
@group(0) @binding(2) var<storage, read> curve_todo: array<u32>;
@group(0) @binding(3) var<storage, read_write> curve_vertices: array<CurveVertex>;

// The homogeneous point of segment `rec` at s in [0, 1]: the Bernstein sum in Horner's form in
// t = s / (1 − s) (or, past the middle, in (1 − s) / s from the other end), times (1 − s)^p
// (or s^p); C(p, i) is carried along. No array, so nothing spills to scratch memory; the
// rounding stays near that of de Casteljau's algorithm because (1 + t)(1 − s) = 1.
fn segment_point(rec: CurveRecord, degree: u32, s: f32) -> vec4<f32> {
    let p = f32(degree);
    if (s < 0.5) {
        let t = s / (1.0 - s);
        var binomial = 1.0;
        var acc = curve_points[rec.control_offset + degree];
        for (var k = 1u; k <= degree; k++) {
            // C(p, p − k) from C(p, p − k + 1).
            binomial = binomial * (p - f32(k) + 1.0) / f32(k);
            acc = acc * t + binomial * curve_points[rec.control_offset + degree - k];
        }
        return acc * pow(1.0 - s, p);
    }
    let t = (1.0 - s) / s;
    var binomial = 1.0;
    var acc = curve_points[rec.control_offset];
    for (var k = 1u; k <= degree; k++) {
        binomial = binomial * (p - f32(k) + 1.0) / f32(k);
        acc = acc * t + binomial * curve_points[rec.control_offset + k];
    }
    return acc * pow(s, p);
}

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
        let h = segment_point(rec, degree, s);
        var out: CurveVertex;
        out.position = vec4<f32>(h.xyz / h.w, select(1.0, 0.0, k == rec.segments));
        out.object = rec.object;
        out.record = index;
        out.s = s;
        out.reserved = 0u;
        curve_vertices[rec.vertex_offset + k] = out;
    }
}
