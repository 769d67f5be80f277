// Module: the crack-free layout of a view-adaptively tessellated patch (the Rust reference and
// its documentation: src/gpu/adaptive.rs, PatchLevels). `edges` = (e0, e1, e2, e3): segments
// of the edges t = 0 (along s), s = 1 (along t), t = 1 (along s), s = 0 (along t); `inner` =
// (nu, nv) >= 2: the interior grid. Vertices: the interior grid (i, j), 1 <= i < nu,
// 1 <= j < nv, row by row, then each edge's e + 1 vertices in increasing parameter. Triangles:
// the interior quads, then per edge a strip zipped by segment midpoints.

// A vertex of the layout: its (s, t) and, on an edge, which edge (else ADAPTIVE_INTERIOR), its
// index m and the edge's count e (the boundary curve is evaluated at m / e from its canonical end).
struct AdaptiveVertex {
    st: vec2<f32>,
    edge: u32,
    m: u32,
    e: u32,
}

const ADAPTIVE_INTERIOR: u32 = 4u;

fn adaptive_interior_vertices(inner: vec2<u32>) -> u32 {
    return (inner.x - 1u) * (inner.y - 1u);
}

fn adaptive_vertex_count(edges: vec4<u32>, inner: vec2<u32>) -> u32 {
    return adaptive_interior_vertices(inner) + edges.x + edges.y + edges.z + edges.w + 4u;
}

// Segments of the inner polyline facing edge k: nu - 2 for edges 0 and 2, nv - 2 for 1 and 3.
fn adaptive_inner_segments(inner: vec2<u32>, edge: u32) -> u32 {
    return select(inner.y, inner.x, edge % 2u == 0u) - 2u;
}

fn adaptive_triangle_count(edges: vec4<u32>, inner: vec2<u32>) -> u32 {
    let strips = edges.x + edges.y + edges.z + edges.w + 2u * (inner.x - 2u) + 2u * (inner.y - 2u);
    return 2u * (inner.x - 2u) * (inner.y - 2u) + strips;
}

fn adaptive_interior(inner: vec2<u32>, i: u32, j: u32) -> u32 {
    return (i - 1u) * (inner.y - 1u) + (j - 1u);
}

fn adaptive_edge_base(edges: vec4<u32>, inner: vec2<u32>, edge: u32) -> u32 {
    var base = adaptive_interior_vertices(inner);
    for (var k = 0u; k < edge; k++) {
        base += edges[k] + 1u;
    }
    return base;
}

// Vertex l of the inner polyline facing `edge`.
fn adaptive_inner_vertex(inner: vec2<u32>, edge: u32, l: u32) -> u32 {
    switch edge {
        case 0u: { return adaptive_interior(inner, l + 1u, 1u); }
        case 1u: { return adaptive_interior(inner, inner.x - 1u, l + 1u); }
        case 2u: { return adaptive_interior(inner, l + 1u, inner.y - 1u); }
        default: { return adaptive_interior(inner, 1u, l + 1u); }
    }
}

fn adaptive_vertex(edges: vec4<u32>, inner: vec2<u32>, k: u32) -> AdaptiveVertex {
    let interior = adaptive_interior_vertices(inner);
    if (k < interior) {
        let i = k / (inner.y - 1u) + 1u;
        let j = k % (inner.y - 1u) + 1u;
        return AdaptiveVertex(vec2<f32>(f32(i) / f32(inner.x), f32(j) / f32(inner.y)), ADAPTIVE_INTERIOR, 0u, 0u);
    }
    var rest = k - interior;
    for (var edge = 0u; edge < 4u; edge++) {
        let e = edges[edge];
        if (rest <= e) {
            let a = f32(rest) / f32(e);
            var st: vec2<f32>;
            switch edge {
                case 0u: { st = vec2<f32>(a, 0.0); }
                case 1u: { st = vec2<f32>(1.0, a); }
                case 2u: { st = vec2<f32>(a, 1.0); }
                default: { st = vec2<f32>(0.0, a); }
            }
            return AdaptiveVertex(st, edge, rest, e);
        }
        rest -= e + 1u;
    }
    return AdaptiveVertex(vec2<f32>(0.0), ADAPTIVE_INTERIOR, 0u, 0u);
}

// Inner segments of a strip whose midpoint comes strictly before boundary segment k's:
// #{l : (2l + 3) e < (2k + 1) n} (Rust: gpu::adaptive::inner_before).
fn adaptive_inner_before(k: u32, e: u32, n: u32) -> u32 {
    let x = (2u * k + 1u) * n;
    if (x <= 3u * e) {
        return 0u;
    }
    return (x - 1u - 3u * e) / (2u * e) + 1u;
}

// Boundary segments whose midpoint comes at or before inner segment l's:
// #{k : (2k + 1) n <= (2l + 3) e} (Rust: gpu::adaptive::boundary_until).
fn adaptive_boundary_until(l: u32, e: u32, n: u32) -> u32 {
    let y = (2u * l + 3u) * e;
    if (y < n) {
        return 0u;
    }
    return (y - n) / (2u * n) + 1u;
}

// Triangle k of edge `edge`'s strip: boundary segments' triangles, then inner segments'.
fn adaptive_strip_triangle(edges: vec4<u32>, inner: vec2<u32>, edge: u32, k: u32) -> vec3<u32> {
    let e = edges[edge];
    let m = adaptive_inner_segments(inner, edge);
    let n = select(inner.y, inner.x, edge % 2u == 0u);
    let base = adaptive_edge_base(edges, inner, edge);
    if (k < e) {
        let apex = min(adaptive_inner_before(k, e, n), m);
        return vec3<u32>(base + k, base + k + 1u, adaptive_inner_vertex(inner, edge, apex));
    }
    let l = k - e;
    let apex = min(adaptive_boundary_until(l, e, n), e);
    return vec3<u32>(adaptive_inner_vertex(inner, edge, l), adaptive_inner_vertex(inner, edge, l + 1u), base + apex);
}

// Local vertex indices of triangle k, counter-clockwise in (s, t); k < adaptive_triangle_count.
fn adaptive_triangle(edges: vec4<u32>, inner: vec2<u32>, k: u32) -> vec3<u32> {
    let quads = (inner.x - 2u) * (inner.y - 2u);
    if (k < 2u * quads) {
        let quad = k / 2u;
        let i = quad / (inner.y - 2u) + 1u;
        let j = quad % (inner.y - 2u) + 1u;
        let a = adaptive_interior(inner, i, j);
        let c = adaptive_interior(inner, i + 1u, j + 1u);
        if (k % 2u == 0u) {
            return vec3<u32>(a, adaptive_interior(inner, i + 1u, j), c);
        }
        return vec3<u32>(a, c, adaptive_interior(inner, i, j + 1u));
    }
    var rest = k - 2u * quads;
    var tri = vec3<u32>(0u);
    for (var edge = 0u; edge < 4u; edge++) {
        let count = edges[edge] + adaptive_inner_segments(inner, edge);
        if (rest < count) {
            tri = adaptive_strip_triangle(edges, inner, edge, rest);
            break;
        }
        rest -= count;
    }
    // Counter-clockwise in (s, t), as the interior's.
    let a = adaptive_vertex(edges, inner, tri.x).st;
    let b = adaptive_vertex(edges, inner, tri.y).st;
    let c = adaptive_vertex(edges, inner, tri.z).st;
    let ab = b - a;
    let ac = c - a;
    if (ab.x * ac.y - ab.y * ac.x < 0.0) {
        return tri.xzy;
    }
    return tri;
}
