// Module: exact per-fragment trimming (Rust: gpu::trim_buffer packs the data, kernel::trim
// defines the test). A fragment of a patch that a trim loop crosses is classified by the
// crossing parity of the L-shaped path from its (u, v) to its grid cell's reference point, whose
// side is known, against the cell's few monotone pieces; each crossing is found by bisection on
// the piece's own parameter (Schollmeyer & Fröhlich 2009; false position here). The cost does not grow with the
// number of curves. The crossings on the lines through the fragment also give its distance to
// the trim edge in pixels, which becomes a coverage for anti-aliasing.

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
    var b = pow(s, f32(n));
    var sum = vec3<f32>(0.0);
    for (var i = 0u; i <= n; i++) {
        let k = select(i, n - i, mirrored);
        let w = base + 3u * k;
        sum += b * vec3<f32>(trim_float(w), trim_float(w + 1u), trim_float(w + 2u));
        b *= ratio * f32(n - i) / f32(i + 1u);
    }
    return sum.xy / sum.z;
}

// The coordinate 1 - `fixed` where coordinate `fixed` (0: u, 1: v) of the monotone piece equals
// `level` (inside the piece's range of it): false position with the Illinois modification
// (superlinear on a monotone function, bracketed so it cannot leave the piece).
fn trim_solve(piece: u32, fixed: u32, level: f32) -> f32 {
    var a = 0.0;
    var b = 1.0;
    var fa = trim_piece_point(piece, a)[fixed] - level;
    var fb = trim_piece_point(piece, b)[fixed] - level;
    var p = trim_piece_point(piece, b);
    let tolerance = 1e-7 * (abs(fa) + abs(fb) + abs(level));
    for (var k = 0u; k < TRIM_SOLVE_STEPS; k++) {
        let denominator = fb - fa;
        var c = 0.5 * (a + b);
        if (abs(denominator) > 0.0) {
            c = clamp((a * fb - b * fa) / denominator, min(a, b), max(a, b));
        }
        p = trim_piece_point(piece, c);
        let fc = p[fixed] - level;
        if (abs(fc) <= tolerance) {
            break;
        }
        if (fc * fb < 0.0) {
            a = b;
            fa = fb;
        } else {
            fa *= 0.5;
        }
        b = c;
        fb = fc;
    }
    return p[1u - fixed];
}

// The piece's range [min, max] of coordinate `axis`.
fn trim_range(piece: u32, axis: u32) -> vec2<f32> {
    return vec2<f32>(trim_float(piece + 1u + 2u * axis), trim_float(piece + 2u + 2u * axis));
}

// How much of the fragment at `uv` the kept region covers, in [0, 1]: 1 off trimmed patches.
// `grad_u` and `grad_v` are the screen-space gradients of u and v (per pixel).
fn trim_coverage(record: u32, uv: vec2<f32>, grad_u: vec2<f32>, grad_v: vec2<f32>) -> f32 {
    if (record >= arrayLength(&trim_records)) {
        return 1.0;
    }
    let rec = trim_records[record];
    if (rec.trim_count != TRIM_PARTIAL) {
        return 1.0;
    }
    let h = rec.trim_offset;
    let origin = vec2<f32>(trim_float(h), trim_float(h + 1u));
    let scale = vec2<f32>(trim_float(h + 2u), trim_float(h + 3u));
    let cells = vec2<u32>(trim_words[h + 4u], trim_words[h + 5u]);
    let ij = vec2<u32>(clamp((uv - origin) * scale, vec2<f32>(0.0), vec2<f32>(cells - 1u)));
    let cell = trim_words[h + 6u] + TRIM_CELL_WORDS * (ij.y * cells.x + ij.x);
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
        // The crossing on the line u = uv.x near the fragment, for the edge distance.
        if (ru.x <= uv.x && uv.x < ru.y && rv.x <= uv.y + window.y && rv.y >= uv.y - window.y) {
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
