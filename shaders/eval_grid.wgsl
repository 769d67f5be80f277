// Part of the evaluator (see eval_bezier.wgsl): the fixed tessellation. Each record's
// (segments_u + 1) x (segments_v + 1) grid (evaluate_vertices; subdivision stencils and
// substitute patches have their own entry points), its triangles (write_triangles), and the
// point samples of `knotwork eval --backend gpu` (evaluate_samples).

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
        var point = bitcast<u32>(a.x);
        if (rec.point_list != POINT_LIST_NONE) {
            point = control_indices[rec.point_list + point];
        }
        let p = control_points[rec.first_point + point].xyz;
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
