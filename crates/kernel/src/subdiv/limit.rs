//! Limit masks: where a vertex of a refined level lands on the limit surface, and the surface's
//! tangents and (at regular vertices) second derivatives there, as rows over the level's
//! vertices (OpenSubdiv's `Scheme::ComputeVertexLimitMask`).

use std::f64::consts::{PI, TAU};

use super::Scheme;
use super::level::Level;
use super::refine::{Rule, crease_pair, vertex_rule};
use super::stencil::Row;

/// The vertex's rule from the level's remaining sharpness (the rule its limit mask follows).
pub fn limit_rule(level: &Level, v: u32) -> Rule {
    let sharp = level
        .incident_sharpness(v)
        .iter()
        .filter(|&&s| s > 0.0)
        .count();
    vertex_rule(level.vertex_sharpness[v as usize], sharp)
}

/// The limit position of vertex `v`. Catmull-Clark, smooth, valence n (all faces quads):
/// (n² v + 4 Σ e_j + Σ d_j) / (n (n + 5)) with edge neighbours e_j and diagonal corners d_j
/// (Halstead, Kass & DeRose 1993); Loop, smooth: (1 − nχ) v + χ Σ e_j with
/// χ = 1 / (n + 3/(8β(n))); a crease: 2/3 v + 1/6 (a + b); a corner stays.
///
/// The butterfly interpolates, so its points are their own limit; √3 takes
/// [`super::schemes::sqrt3_limit_position`]; Doo-Sabin's limit points are the faces' centroids,
/// not at vertices (see [`super::display`]), and a vertex row is the vertex itself.
pub fn limit_position(level: &Level, scheme: Scheme, v: u32) -> Row {
    match scheme {
        Scheme::Butterfly | Scheme::DooSabin => return Row(vec![(v, 1.0)]),
        Scheme::Sqrt3 => return super::schemes::sqrt3_limit_position(level, v),
        Scheme::CatmullClark | Scheme::Loop => {}
    }
    let faces = level.vertex_faces(v);
    let rule = limit_rule(level, v);
    match rule {
        _ if faces.is_empty() => Row(vec![(v, 1.0)]),
        Rule::Smooth | Rule::Dart => match scheme {
            Scheme::CatmullClark => {
                let n = faces.len() as f64;
                if faces.len() == 2 {
                    return Row(vec![(v, 1.0)]);
                }
                let mut row = Row(vec![(v, n / (n + 5.0))]);
                for &e in level.vertex_edges(v) {
                    row.add(level.other_end(e, v), 4.0 / (n * (n + 5.0)));
                }
                for &f in faces {
                    row.add(level.diagonal(f, v), 1.0 / (n * (n + 5.0)));
                }
                row
            }
            _ => {
                let edges = level.vertex_edges(v);
                let n = edges.len() as f64;
                let chi = 1.0 / (n + 3.0 / (8.0 * super::refine::loop_beta(edges.len())));
                let mut row = Row(vec![(v, 1.0 - n * chi)]);
                for &e in edges {
                    row.add(level.other_end(e, v), chi);
                }
                row
            }
        },
        Rule::Crease => {
            let [a, b] = crease_pair(level, v, &level.incident_sharpness(v));
            Row(vec![(v, 2.0 / 3.0), (a, 1.0 / 6.0), (b, 1.0 / 6.0)])
        }
        Rule::Corner => Row(vec![(v, 1.0)]),
    }
}

/// Two tangents of the limit surface at `v` whose cross product is the outward normal, as rows
/// over the level's vertices; `position(u)` is the limit position row of vertex `u`.
///
/// Smooth vertices take the eigenvector masks: Catmull-Clark
/// t = Σ A_n cos(2πj/n) e_j + (cos(2πj/n) + cos(2π(j+1)/n)) d_j with
/// A_n = 1 + cos(2π/n) + cos(π/n) √(2 (9 + cos(2π/n))) and its sine twin (Halstead et al. 1993);
/// Loop Σ cos(2πj/n) e_j and Σ sin(2πj/n) e_j. Creases, corners and boundaries, where the
/// surface has no single tangent plane, take the same masks over the neighbours' limit
/// positions (interior) or the chord of the boundary and the sine-weighted mean of the
/// interior neighbours (Hoppe et al. 1994's boundary mask, over limit positions): a one-sided
/// normal close to the surface's.
pub fn limit_tangents(
    level: &Level,
    scheme: Scheme,
    v: u32,
    position: &dyn Fn(u32) -> Row,
) -> [Row; 2] {
    let ring = level.ring(v);
    let n = ring.faces.len();
    if n == 0 {
        return [Row::default(), Row::default()];
    }
    if ring.boundary {
        return boundary_tangents(level, scheme, v, &ring, position);
    }
    let smooth = matches!(limit_rule(level, v), Rule::Smooth | Rule::Dart);
    let at = |u: u32| -> Row {
        if smooth {
            Row(vec![(u, 1.0)])
        } else {
            position(u)
        }
    };
    let mut t = [Row::default(), Row::default()];
    let nf = n as f64;
    for j in 0..n {
        let a = TAU * j as f64 / nf;
        let b = TAU * (j + 1) as f64 / nf;
        match scheme {
            Scheme::CatmullClark => {
                let c = (TAU / nf).cos();
                let big_a = 1.0 + c + (PI / nf).cos() * (2.0 * (9.0 + c)).sqrt();
                let e = at(ring.neighbours[j]);
                let d = at(level.diagonal(ring.faces[j], v));
                t[0].add_row(&e, big_a * a.cos());
                t[0].add_row(&d, a.cos() + b.cos());
                t[1].add_row(&e, big_a * a.sin());
                t[1].add_row(&d, a.sin() + b.sin());
            }
            _ => {
                let e = at(ring.neighbours[j]);
                t[0].add_row(&e, a.cos());
                t[1].add_row(&e, a.sin());
            }
        }
    }
    merged(t)
}

fn merged([a, b]: [Row; 2]) -> [Row; 2] {
    [a.merged(), b.merged()]
}

/// Tangents at a boundary vertex: along the boundary and into the surface (their cross product
/// points out of the front). Where the boundary is a crease (not a corner): along it
/// (a − b)/2, the cubic B-spline's; across it, for Loop Hoppe et al. 1994's masks (one face:
/// e0 + e1 − 2v; two: e1 − v; k ≥ 3: −(sin θ (e0 + ek) + (2 cos θ − 2) Σ sin(iθ) e_i),
/// θ = π/k), for Catmull-Clark with two quads the bicubic B-spline's with the boundary's
/// mirrored phantom row: (d0 − e0)/6 + 2(e1 − v)/3 + (d1 − e2)/6. Otherwise the chord of the
/// boundary neighbours' limit points and the sine-weighted mean of the interior ones'.
fn boundary_tangents(
    level: &Level,
    scheme: Scheme,
    v: u32,
    ring: &super::level::Ring,
    position: &dyn Fn(u32) -> Row,
) -> [Row; 2] {
    let k = ring.faces.len();
    let e = &ring.neighbours;
    let crease = limit_rule(level, v) == Rule::Crease;
    let quads = ring.faces.iter().all(|&f| level.face(f).len() == 4);
    let mut t = [Row::default(), Row::default()];
    if crease {
        t[0] = Row(vec![(e[0], 0.5), (e[k], -0.5)]);
        match scheme {
            Scheme::CatmullClark if k == 2 && quads => {
                let d0 = level.diagonal(ring.faces[0], v);
                let d1 = level.diagonal(ring.faces[1], v);
                t[1] = Row(vec![
                    (d0, 1.0 / 6.0),
                    (e[0], -1.0 / 6.0),
                    (e[1], 4.0 / 6.0),
                    (v, -4.0 / 6.0),
                    (d1, 1.0 / 6.0),
                    (e[2], -1.0 / 6.0),
                ]);
                return merged(t);
            }
            Scheme::CatmullClark => {}
            _ => {
                if k == 1 {
                    t[1] = Row(vec![(e[0], 1.0), (e[1], 1.0), (v, -2.0)]);
                } else if k == 2 {
                    t[1] = Row(vec![(e[1], 1.0), (v, -1.0)]);
                } else {
                    let theta = PI / k as f64;
                    t[1].add(e[0], -theta.sin());
                    t[1].add(e[k], -theta.sin());
                    for (i, &n) in e.iter().enumerate().take(k).skip(1) {
                        t[1].add(n, -(2.0 * theta.cos() - 2.0) * (theta * i as f64).sin());
                    }
                }
                return merged(t);
            }
        }
    }
    let centre = position(v);
    t = [Row::default(), Row::default()];
    if k == 1 {
        t[0].add_row(&position(e[0]), 1.0);
        t[0].add_row(&centre, -1.0);
        t[1].add_row(&position(e[1]), 1.0);
        t[1].add_row(&centre, -1.0);
    } else {
        t[0].add_row(&position(e[0]), 1.0);
        t[0].add_row(&position(e[k]), -1.0);
        for (i, &n) in e.iter().enumerate().take(k).skip(1) {
            let w = (PI * i as f64 / k as f64).sin();
            t[1].add_row(&position(n), w);
            t[1].add_row(&centre, -w);
        }
    }
    merged(t)
}

/// Whether the limit surface at `v` is the bicubic B-spline of its 3 × 3 neighbourhood: a
/// Catmull-Clark vertex inside the surface with four quads and nothing sharp at it.
pub fn is_regular(level: &Level, scheme: Scheme, v: u32) -> bool {
    scheme == Scheme::CatmullClark
        && level.vertex_sharpness[v as usize] <= 0.0
        && level.vertex_faces(v).len() == 4
        && level.vertex_edges(v).len() == 4
        && level
            .vertex_edges(v)
            .iter()
            .all(|&e| level.edge_sharpness[e as usize] <= 0.0 && !level.is_boundary_edge(e))
        && level
            .vertex_faces(v)
            .iter()
            .all(|&f| level.face(f).len() == 4)
}

/// The 3 × 3 neighbourhood of a regular vertex `v` (see [`is_regular`]) with u pointing to
/// neighbour `plus_u` (or away from it when `reversed`): entry 3a + b is the point a − 1 steps
/// along u and b − 1 along v from `v`.
pub fn regular_grid(level: &Level, v: u32, plus_u: u32, reversed: bool) -> Option<[u32; 9]> {
    let (neighbours, faces) = level.four_ring(v)?;
    let start = neighbours.iter().position(|&x| x == plus_u)?;
    let start = if reversed { (start + 2) % 4 } else { start };
    let e = |k: usize| neighbours[(start + k) % 4];
    let d = |k: usize| level.diagonal(faces[(start + k) % 4], v);
    Some([d(2), e(2), d(1), e(3), v, e(1), d(3), e(0), d(0)])
}

/// The weights of position, Su, Sv, Suu, Suv, Svv of the limit at a regular vertex on its
/// [`regular_grid`], per `1/scale` of knot spacing (derivatives by a parameter in which the
/// knots are `1/scale` apart): the tensor products of the cubic B-spline's values
/// (1, 4, 1)/6, first derivatives (−1, 0, 1)/2 and second derivatives (1, −2, 1) at a knot.
pub fn regular_weights(scale: f64) -> [[f64; 6]; 9] {
    let value = [1.0 / 6.0, 4.0 / 6.0, 1.0 / 6.0];
    let first = [-0.5 * scale, 0.0, 0.5 * scale];
    let second = [scale * scale, -2.0 * scale * scale, scale * scale];
    let mut weights = [[0.0; 6]; 9];
    for a in 0..3 {
        for b in 0..3 {
            weights[3 * a + b] = [
                value[a] * value[b],
                first[a] * value[b],
                value[a] * first[b],
                second[a] * value[b],
                first[a] * first[b],
                value[a] * second[b],
            ];
        }
    }
    weights
}
