// Part of the evaluator (see eval_bezier.wgsl): the view-adaptive tessellation (Rust driver:
// gpu::adaptive_pass). Four passes, all recorded in one compute pass:
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
    vertices[slot.vertex_offset + local] = surface_vertex(
        out.position,
        vec2<f32>(
            rec.domain.x * (1.0 - v.st.x) + rec.domain.y * v.st.x,
            rec.domain.z * (1.0 - v.st.y) + rec.domain.w * v.st.y,
        ),
        out.normal,
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
