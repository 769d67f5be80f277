// Module: exact per-fragment trimming (Rust: gpu::trim_buffer packs the data, kernel::trim
// defines the test). A fragment of a patch that a trim loop crosses is classified by the
// crossing parity of the L-shaped path from its (u, v) to its grid cell's reference point, whose
// side is known, against the cell's few monotone pieces; each crossing is found by bisection on
// the piece's own parameter (Schollmeyer & Fröhlich 2009; false position here). The cost does not grow with the
// number of curves. The crossings on the lines through the fragment also give its distance to
// the trim edge in pixels, which becomes a coverage for anti-aliasing.

// Read by the vertex stage (trim_varying) and the fragment stage (trim_coverage).
@group(1) @binding(0) var<storage, read> trim_records: array<PatchRecord>;
@group(1) @binding(1) var<storage, read> trim_words: array<u32>;

// The most steps of the crossing solve (false position converges in far fewer).
const TRIM_SOLVE_STEPS: u32 = 24u;

fn trim_float(i: u32) -> f32 {
    return bitcast<f32>(trim_words[i]);
}

// The point of the rational Bézier piece at word `piece` for t in [0, 1]: the Bernstein sum
// with the basis built by the ratio recurrence, from the nearer end (no private arrays).
fn trim_piece_point(piece: u32, t: f32) -> vec2<f32> {
    let n = trim_words[piece];
    let base = piece + TRIM_PIECE_HEADER_WORDS;
    let mirrored = t > 0.5;
    let a = select(t, 1.0 - t, mirrored);
    let s = 1.0 - a;
    let ratio = a / s;
    // s^n by multiplication (pow costs a log and an exp).
    var b = 1.0;
    for (var i = 0u; i < n; i++) {
        b *= s;
    }
    var sum = vec3<f32>(0.0);
    for (var i = 0u; i <= n; i++) {
        let k = select(i, n - i, mirrored);
        let w = base + 3u * k;
        sum += b * vec3<f32>(trim_float(w), trim_float(w + 1u), trim_float(w + 2u));
        b *= ratio * f32(n - i) / f32(i + 1u);
    }
    return sum.xy / sum.z;
}

// A cubic piece's control points, loaded once per solve (the packer raises lower degrees to 3).
struct TrimCubic {
    c0: vec3<f32>,
    c1: vec3<f32>,
    c2: vec3<f32>,
    c3: vec3<f32>,
}

// The point at t of the piece: from `cubic` in registers when the piece is cubic, else the
// Bernstein sum read from the buffer.
fn trim_eval(piece: u32, cubic: bool, c: TrimCubic, t: f32) -> vec2<f32> {
    if (!cubic) {
        return trim_piece_point(piece, t);
    }
    let s = 1.0 - t;
    let h = s * s * s * c.c0 + 3.0 * s * t * (s * c.c1 + t * c.c2) + t * t * t * c.c3;
    return h.xy / h.z;
}

// The coordinate 1 - `fixed` where coordinate `fixed` (0: u, 1: v) of the monotone piece equals
// `level` (inside the piece's range of it): false position with the Illinois modification
// (superlinear on a monotone function, bracketed so it cannot leave the piece).
fn trim_solve(piece: u32, fixed: u32, level: f32) -> f32 {
    let cubic = trim_words[piece] == 3u;
    var c: TrimCubic;
    if (cubic) {
        let w = piece + TRIM_PIECE_HEADER_WORDS;
        c.c0 = vec3<f32>(trim_float(w), trim_float(w + 1u), trim_float(w + 2u));
        c.c1 = vec3<f32>(trim_float(w + 3u), trim_float(w + 4u), trim_float(w + 5u));
        c.c2 = vec3<f32>(trim_float(w + 6u), trim_float(w + 7u), trim_float(w + 8u));
        c.c3 = vec3<f32>(trim_float(w + 9u), trim_float(w + 10u), trim_float(w + 11u));
    }
    var a = 0.0;
    var b = 1.0;
    var fa = trim_eval(piece, cubic, c, a)[fixed] - level;
    var fb = trim_eval(piece, cubic, c, b)[fixed] - level;
    var p = trim_eval(piece, cubic, c, b);
    let tolerance = 1e-7 * (abs(fa) + abs(fb) + abs(level));
    for (var k = 0u; k < TRIM_SOLVE_STEPS; k++) {
        let denominator = fb - fa;
        var t = 0.5 * (a + b);
        if (abs(denominator) > 0.0) {
            t = clamp((a * fb - b * fa) / denominator, min(a, b), max(a, b));
        }
        p = trim_eval(piece, cubic, c, t);
        let ft = p[fixed] - level;
        if (abs(ft) <= tolerance) {
            break;
        }
        if (ft * fb < 0.0) {
            a = b;
            fa = fb;
        } else {
            fa *= 0.5;
        }
        b = t;
        fb = ft;
    }
    return p[1u - fixed];
}

// The piece's range [min, max] of coordinate `axis`.
fn trim_range(piece: u32, axis: u32) -> vec2<f32> {
    return vec2<f32>(trim_float(piece + 1u + 2u * axis), trim_float(piece + 2u + 2u * axis));
}

// What the vertex stage hands the fragment stage about a vertex's patch, read once per vertex
// rather than per fragment: `grid` = (first cell word + 1, cells along u, cells along v), zero
// off trimmed patches; `cell` = the vertex's (u, v) in cell units (linear in (u, v), so its
// interpolation is exact).
struct TrimVarying {
    grid: vec3<u32>,
    cell: vec2<f32>,
}

fn trim_varying(record: u32, uv: vec2<f32>) -> TrimVarying {
    var out: TrimVarying;
    // Only the two trim fields are read, not the whole record.
    if (record >= arrayLength(&trim_records) || trim_records[record].trim_count != TRIM_PARTIAL) {
        return out;
    }
    let h = trim_records[record].trim_offset;
    let origin = vec2<f32>(trim_float(h), trim_float(h + 1u));
    let scale = vec2<f32>(trim_float(h + 2u), trim_float(h + 3u));
    out.grid = vec3<u32>(trim_words[h + 6u] + 1u, trim_words[h + 4u], trim_words[h + 5u]);
    out.cell = (uv - origin) * scale;
    return out;
}

// How much of the fragment at `uv` the kept region covers, in [0, 1]: 1 off trimmed patches.
// `grid` and `cell_uv` come from trim_varying; `grad_u` and `grad_v` are the screen-space
// gradients of u and v (per pixel).
fn trim_coverage(
    grid: vec3<u32>,
    cell_uv: vec2<f32>,
    uv: vec2<f32>,
    grad_u: vec2<f32>,
    grad_v: vec2<f32>,
) -> f32 {
    if (grid.x == 0u) {
        return 1.0;
    }
    let cells = grid.yz;
    let ij = vec2<u32>(clamp(cell_uv, vec2<f32>(0.0), vec2<f32>(cells - 1u)));
    let cell = grid.x - 1u + TRIM_CELL_WORDS * (ij.y * cells.x + ij.x);
    let reference = vec2<f32>(trim_float(cell), trim_float(cell + 1u));
    let bits = trim_words[cell + 2u];
    let list = trim_words[cell + 3u];
    // The anti-aliasing window: a pixel in u and in v.
    let window = vec2<f32>(length(grad_u), length(grad_v)) + vec2<f32>(1e-12);
    var inside = (bits & 1u) != 0u;
    // Signed offsets to the nearest crossing along u (at v = uv.y) and along v (at u = uv.x).
    var offset = vec2<f32>(3.0e38);
    for (var k = 0u; k < (bits >> 1u); k++) {
        let piece = trim_words[list + k];
        let ru = trim_range(piece, 0u);
        let rv = trim_range(piece, 1u);
        // Leg 1: from uv along u to (reference.u, uv.v); half-open in v.
        if (rv.x <= uv.y && uv.y < rv.y) {
            let lo = min(uv.x, reference.x);
            let hi = max(uv.x, reference.x);
            let near = ru.x <= uv.x + window.x && ru.y >= uv.x - window.x;
            let straddles = ru.x < reference.x && ru.y >= reference.x;
            if (near || straddles) {
                let u = trim_solve(piece, 1u, uv.y);
                inside = inside != (lo <= u && u < hi);
                if (abs(u - uv.x) < abs(offset.x)) {
                    offset.x = u - uv.x;
                }
            } else {
                inside = inside != (lo <= ru.x && ru.y < hi);
            }
        }
        // Leg 2: from (reference.u, uv.v) along v to the reference; half-open in u.
        if (ru.x <= reference.x && reference.x < ru.y) {
            let lo = min(uv.y, reference.y);
            let hi = max(uv.y, reference.y);
            if (lo <= rv.x && rv.y < hi) {
                inside = !inside;
            } else if (!(rv.y < lo || rv.x >= hi)) {
                let v = trim_solve(piece, 0u, reference.x);
                inside = inside != (lo <= v && v < hi);
            }
        }
        // The crossing on the line u = uv.x near the fragment, for the edge distance (not
        // needed where the line v = uv.y already met an edge within the window).
        if (abs(offset.x) > window.x && ru.x <= uv.x && uv.x < ru.y
            && rv.x <= uv.y + window.y && rv.y >= uv.y - window.y) {
            let v = trim_solve(piece, 0u, uv.x);
            if (abs(v - uv.y) < abs(offset.y)) {
                offset.y = v - uv.y;
            }
        }
    }
    // The edge as the line through the two crossings: g = du/offset.u + dv/offset.v - 1 is 0
    // there and -1 at the fragment, so the distance in pixels is 1 / |grad g|.
    var gradient = vec2<f32>(0.0);
    if (abs(offset.x) < 1.0e38) {
        gradient += grad_u / offset.x;
    }
    if (abs(offset.y) < 1.0e38) {
        gradient += grad_v / offset.y;
    }
    let g = length(gradient);
    let distance = select(1.0e6, 1.0 / g, g > 0.0);
    let signed = select(-distance, distance, inside);
    return clamp(0.5 + signed, 0.0, 1.0);
}
