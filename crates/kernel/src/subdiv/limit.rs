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

/// The weights of position, Su, Sv, Suu, Suv, Svv (as [`regular_weights`], per `1/scale` of
/// knot spacing) at a Catmull-Clark vertex `v` on an infinitely sharp crease or the boundary,
/// on the side of quad `face`, where the limit there is the bicubic B-spline of that side's
/// 3 × 3 neighbourhood with the missing row (and, at a corner, column) extrapolated linearly,
/// P₋₁ = 2 P₀ − P₁: the boundary and corner patches of OpenSubdiv's regular patches.
///
/// The infinitely sharp edges at `v` (boundary edges among them) cut its ring into sectors.
/// Two cases are exact: a sector of two quads with a smooth edge between them at a point of
/// the crease rule (two sharp edges, the point not sharp), and a sector of one quad at a point
/// of the corner rule (a sharp point, or three or more sharp edges). The crease rules
/// (vertex (1, 6, 1) / 8, edge midpoint, a corner fixed) are the B-spline's rules on the net
/// so extended, and the sector's ring refines into its own ring, so the values are exact
/// whatever lies beyond the sector (Biermann, Levin & Zorin 2000 use the same boundary and
/// corner masks). A semi-sharp edge or point at `v` makes it `None`, as does any other sector.
///
/// u points to `towards` (a neighbour along one of `face`'s edges at `v`), or away from it
/// when `reversed`; v a quarter turn counter-clockwise from u, as [`regular_grid`].
pub fn sided_weights(
    level: &Level,
    v: u32,
    towards: u32,
    reversed: bool,
    face: u32,
    scale: f64,
) -> Option<Vec<(u32, [f64; 6])>> {
    use super::level::INFINITE_SHARPNESS;
    let ring = level.ring(v);
    let (neighbours, faces) = (&ring.neighbours, &ring.faces);
    let sharp = sharp_edges_to(level, v, neighbours)?;
    let point_sharpness = level.vertex_sharpness[v as usize];
    if point_sharpness > 0.0 && point_sharpness < INFINITE_SHARPNESS {
        return None;
    }
    // Distinct edges (an interior ring repeats none; a boundary ring neither).
    let sharp_edges = sharp.iter().filter(|&&s| s).count();
    let corner = point_sharpness >= INFINITE_SHARPNESS || sharp_edges >= 3;
    let crease = !corner && sharp_edges == 2;
    // Face q lies between neighbours q and q + 1 (wrapping round an interior point).
    let count = neighbours.len();
    let next = |i: usize| {
        if ring.boundary {
            i + 1
        } else {
            (i + 1) % count
        }
    };
    let q = faces.iter().position(|&f| f == face)?;
    // The sector's first neighbour: back from face q to a sharp edge.
    let mut start = q;
    for _ in 0..count {
        if sharp[start] {
            break;
        }
        start = if start == 0 { count - 1 } else { start - 1 };
    }
    let sector = |k: usize| (0..k).fold(start, |i, _| next(i));
    let quad = |f: u32| level.face(f).len() == 4;
    let mut cells: Vec<((i32, i32), u32)> = vec![((0, 0), v)];
    let (h0, f0) = (neighbours[start], faces[start]);
    if crease && sharp[start] && !sharp[sector(1)] && sharp.get(sector(2)) == Some(&true) {
        let f1 = faces[sector(1)];
        if !(quad(f0) && quad(f1)) {
            return None;
        }
        cells.extend([
            ((1, 0), h0),
            ((0, 1), neighbours[sector(1)]),
            ((-1, 0), neighbours[sector(2)]),
            ((1, 1), level.diagonal(f0, v)),
            ((-1, 1), level.diagonal(f1, v)),
        ]);
    } else if corner && sharp[start] && sharp.get(sector(1)) == Some(&true) && quad(f0) {
        cells.extend([
            ((1, 0), h0),
            ((0, 1), neighbours[sector(1)]),
            ((1, 1), level.diagonal(f0, v)),
        ]);
    } else {
        return None;
    }
    let &(du, _) = cells
        .iter()
        .find(|&&(d, p)| p == towards && (d.0 == 0) != (d.1 == 0))?;
    let du = if reversed { (-du.0, -du.1) } else { du };
    let dv = (-du.1, du.0);
    let weights = regular_weights(scale);
    let mut out: Vec<(u32, [f64; 6])> = Vec::with_capacity(6);
    let mut parts = Vec::with_capacity(4);
    for a in 0..3 {
        for b in 0..3 {
            let (i, j) = (a as i32 - 1, b as i32 - 1);
            parts.clear();
            extended_cell(
                &cells,
                (i * du.0 + j * dv.0, i * du.1 + j * dv.1),
                1.0,
                &mut parts,
            )?;
            for &(p, w) in &parts {
                add_weights(&mut out, p, w, &weights[3 * a + b]);
            }
        }
    }
    Some(out)
}

/// The weights of position, Su, Sv, Suu, Suv, Svv (per `1/scale` of the lattice step, as
/// [`regular_weights`]) of Loop's limit at a regular point `v` (six triangles, nothing sharp:
/// the quartic box spline), over `v` and its ring e₀ … e₅ counter-clockwise from e₀ along u.
/// In the triangle lattice's coordinates, with
/// e₀ = (1, 0), e₁ = (0, 1), e₂ = (−1, 1), …: the position v/2 + Σ e_j/12 (the smooth limit
/// mask at valence six); the derivatives are the left eigenvectors of the ring's subdivision
/// matrix for 1/2 (Σ cos(2πj/6) e_j, Σ sin(2πj/6) e_j) and 1/4 (the Laplacian −6v + Σ e_j,
/// Σ cos(4πj/6) e_j, Σ sin(4πj/6) e_j), combined to be exact on linear and quadratic
/// functions of the lattice: S_u = (e₀ − e₃)/3 + (e₁ − e₂ − e₄ + e₅)/6,
/// S_v = (e₁ − e₄)/3 + (e₀ + e₂ − e₃ − e₅)/6, S_uu = e₀ + e₃ − 2v, S_vv = e₁ + e₄ − 2v and
/// S_uv = (e₀ + e₁ + e₃ + e₄ − e₂ − e₅)/2 − v. An eigenvector mask scales by its eigenvalue
/// under refinement, so each is the limit's derivative exactly. `neighbour` lies `turns`
/// sixths of a turn counter-clockwise from u. `None` unless `v` is such a point and
/// `neighbour` one of its neighbours.
pub fn loop_regular_weights(
    level: &Level,
    v: u32,
    neighbour: u32,
    turns: usize,
    scale: f64,
) -> Option<Vec<(u32, [f64; 6])>> {
    let faces = level.vertex_faces(v);
    let edges = level.vertex_edges(v);
    if faces.len() != 6
        || edges.len() != 6
        || level.vertex_sharpness[v as usize] > 0.0
        || faces.iter().any(|&f| level.face(f).len() != 3)
        || edges
            .iter()
            .any(|&e| level.is_boundary_edge(e) || level.edge_sharpness[e as usize] > 0.0)
    {
        return None;
    }
    let ring = level.ring(v);
    if ring.boundary || ring.neighbours.len() != 6 {
        return None;
    }
    let c = ring.neighbours.iter().position(|&n| n == neighbour)?;
    let cycle: [[(u32, f64); 3]; 6] =
        std::array::from_fn(|j| [(ring.neighbours[j], 1.0), (v, 0.0), (v, 0.0)]);
    Some(turned_box_spline_weights(v, &cycle, c, turns, scale))
}

/// The weights of position, Su, Sv, Suu, Suv, Svv (per `1/scale` of the lattice step) of
/// Loop's limit at a point `v` of an infinitely sharp crease or the boundary, on the side of
/// triangle `face`, where that side is a regular half: three triangles between the two sharp
/// edges, the point following the crease rule (exactly two sharp edges at it, the others
/// smooth, the point itself not sharp).
///
/// There the limit is the quartic box spline of the side's net extended across the sharp edge
/// by phantom points, each the reflection of a side triangle's far corner through the midpoint
/// of its sharp edge: with the side's ring e₀ … e₃ counter-clockwise from one sharp edge to
/// the other, e₄ = v + e₃ − e₂ and e₅ = v + e₀ − e₁. On the net so extended the box spline's
/// rules give the crease rules (the vertex (1, 6, 1)/8 along the crease, the sharp edge's
/// midpoint) and a new phantom row that is again the reflection of the new points, so the
/// side refines into its own extended ring at every level and the masks of
/// [`loop_regular_weights`] over it are the limit's derivatives exactly, whatever lies on the
/// other side. Along the crease they reduce to the cubic B-spline of the crease polygon
/// (S_u = (e₀ − e₃)/2, S_uu = e₀ + e₃ − 2v), which is Loop's limit curve there.
///
/// `neighbour` (a point of the side's ring) lies `turns` sixths of a turn counter-clockwise
/// from u. `None` for any other case: a smooth or semi-sharp point, a corner, a side of other
/// than three triangles.
pub fn loop_sided_weights(
    level: &Level,
    v: u32,
    neighbour: u32,
    turns: usize,
    face: u32,
    scale: f64,
) -> Option<Vec<(u32, [f64; 6])>> {
    if level.vertex_sharpness[v as usize] > 0.0 {
        return None;
    }
    let ring = level.ring(v);
    let (neighbours, faces) = (&ring.neighbours, &ring.faces);
    let sharp = sharp_edges_to(level, v, neighbours)?;
    if sharp.iter().filter(|&&s| s).count() != 2 {
        return None;
    }
    // Face q lies between neighbours q and q + 1 (wrapping round an interior point); the
    // side's first neighbour is the sharp one back from `face`.
    let count = neighbours.len();
    let step = |i: usize, k: usize| {
        if ring.boundary {
            Some(i + k).filter(|&j| j < count)
        } else {
            Some((i + k) % count)
        }
    };
    let q = faces.iter().position(|&f| f == face)?;
    let mut start = q;
    while !sharp[start] {
        start = if start == 0 { count - 1 } else { start - 1 };
    }
    let side: Vec<usize> = (0..4).map(|k| step(start, k)).collect::<Option<_>>()?;
    if !(sharp[side[3]] && !sharp[side[1]] && !sharp[side[2]])
        || side[..3]
            .iter()
            .any(|&i| faces.get(i).is_none_or(|&f| level.face(f).len() != 3))
    {
        return None;
    }
    let e = |k: usize| neighbours[side[k]];
    let c = (0..4).find(|&k| e(k) == neighbour)?;
    let cycle: [[(u32, f64); 3]; 6] = [
        [(e(0), 1.0), (v, 0.0), (v, 0.0)],
        [(e(1), 1.0), (v, 0.0), (v, 0.0)],
        [(e(2), 1.0), (v, 0.0), (v, 0.0)],
        [(e(3), 1.0), (v, 0.0), (v, 0.0)],
        [(v, 1.0), (e(3), 1.0), (e(2), -1.0)],
        [(v, 1.0), (e(0), 1.0), (e(1), -1.0)],
    ];
    Some(turned_box_spline_weights(v, &cycle, c, turns, scale))
}

/// The weights of position, Su, Sv, Suu, Suv, Svv (per `1/scale` of the lattice step) of
/// Loop's limit at a corner of one triangle that follows the corner rule (a boundary point of
/// one face under the boundary rule "edge and corner", or one tagged infinitely sharp): the
/// point itself, the steps to its two neighbours along the sharp edges, and no second
/// derivative.
///
/// Near such a corner the refined nets are the regular 60° wedge of the triangle lattice, the
/// corner fixed and each sharp edge refined by the crease rule (a cubic B-spline whose end
/// point stays, i.e. whose phantom point is 2 v − e, so its second derivative there is zero).
/// The wedge's subdivision matrix has the eigenvalues 1, 1/2, 1/2, 1/8, 1/8, 1/8 and 0 for the
/// rest, with the linear functions of the lattice as the eigenvectors for 1/2 and cubics for
/// 1/8: there is no eigenvalue 1/4, so the limit there is the point, a linear map of the
/// wedge and terms of third degree. Its masks are [`loop_regular_weights`]'s over the ring
/// extended linearly (e₂ = v + e₁ − e₀, e₃ = 2 v − e₀, e₄ = 2 v − e₁, e₅ = v + e₀ − e₁),
/// which give exactly that: the point, S along e₀ = e₀ − v and along e₁ = e₁ − v, and zero
/// for every second derivative. The curvature there is zero (a flat point).
///
/// A corner of one triangle under the crease rule (boundary rule "edge only") has a single
/// eigenvalue 1/2 and one of 1/4 (the limit's tangent plane degenerates there), and a corner
/// of two triangles an eigenvalue 3/8 above 1/4 (its curvature is unbounded): both are
/// `None`, as is any other point. `neighbour` (one of the two) lies `turns` sixths of a turn
/// counter-clockwise from u.
pub fn loop_corner_weights(
    level: &Level,
    v: u32,
    neighbour: u32,
    turns: usize,
    scale: f64,
) -> Option<Vec<(u32, [f64; 6])>> {
    use super::level::INFINITE_SHARPNESS;
    if level.vertex_sharpness[v as usize] < INFINITE_SHARPNESS {
        return None;
    }
    let ring = level.ring(v);
    let (neighbours, faces) = (&ring.neighbours, &ring.faces);
    if !ring.boundary
        || neighbours.len() != 2
        || faces.len() != 1
        || level.face(faces[0]).len() != 3
        || sharp_edges_to(level, v, neighbours)? != [true, true]
    {
        return None;
    }
    let (e0, e1) = (neighbours[0], neighbours[1]);
    let c = neighbours.iter().position(|&n| n == neighbour)?;
    let cycle: [[(u32, f64); 3]; 6] = [
        [(e0, 1.0), (v, 0.0), (v, 0.0)],
        [(e1, 1.0), (v, 0.0), (v, 0.0)],
        [(v, 1.0), (e1, 1.0), (e0, -1.0)],
        [(v, 2.0), (e0, -1.0), (v, 0.0)],
        [(v, 2.0), (e1, -1.0), (v, 0.0)],
        [(v, 1.0), (e0, 1.0), (e1, -1.0)],
    ];
    Some(turned_box_spline_weights(v, &cycle, c, turns, scale))
}

/// [`box_spline_weights`] over the lattice ring `cycle` turned so that its entry `neighbour`
/// lies `turns` sixths of a turn counter-clockwise from u.
fn turned_box_spline_weights(
    v: u32,
    cycle: &[[(u32, f64); 3]; 6],
    neighbour: usize,
    turns: usize,
    scale: f64,
) -> Vec<(u32, [f64; 6])> {
    let u = (neighbour + 6 - turns % 6) % 6;
    let entries: [[(u32, f64); 3]; 6] = std::array::from_fn(|j| cycle[(u + j) % 6]);
    box_spline_weights(v, &entries, scale)
}

/// The masks of [`loop_regular_weights`] at `v` over its lattice ring e₀ … e₅ (counter-
/// clockwise from u), each entry a combination of points (a phantom point of
/// [`loop_sided_weights`], or one point with weight 1), summed per point.
fn box_spline_weights(v: u32, ring: &[[(u32, f64); 3]; 6], scale: f64) -> Vec<(u32, [f64; 6])> {
    let (s, t) = (scale, scale * scale);
    // Per ring point j: [position, S_u, S_v, S_uu, S_uv, S_vv] (before the scale).
    const RING: [[f64; 6]; 6] = [
        [1.0 / 12.0, 1.0 / 3.0, 1.0 / 6.0, 1.0, 0.5, 0.0],
        [1.0 / 12.0, 1.0 / 6.0, 1.0 / 3.0, 0.0, 0.5, 1.0],
        [1.0 / 12.0, -1.0 / 6.0, 1.0 / 6.0, 0.0, -0.5, 0.0],
        [1.0 / 12.0, -1.0 / 3.0, -1.0 / 6.0, 1.0, 0.5, 0.0],
        [1.0 / 12.0, -1.0 / 6.0, -1.0 / 3.0, 0.0, 0.5, 1.0],
        [1.0 / 12.0, 1.0 / 6.0, -1.0 / 6.0, 0.0, -0.5, 0.0],
    ];
    let scaled = |w: [f64; 6]| [w[0], w[1] * s, w[2] * s, w[3] * t, w[4] * t, w[5] * t];
    let mut out = Vec::with_capacity(7);
    add_weights(&mut out, v, 1.0, &scaled([0.5, 0.0, 0.0, -2.0, -1.0, -2.0]));
    for (entry, mask) in ring.iter().zip(RING) {
        for &(p, w) in entry.iter().filter(|&&(_, w)| w != 0.0) {
            add_weights(&mut out, p, w, &scaled(mask));
        }
    }
    out
}

/// Adds `weight` times `mask` to point `p`'s weights in `out` (a new entry where it has none).
fn add_weights(out: &mut Vec<(u32, [f64; 6])>, p: u32, weight: f64, mask: &[f64; 6]) {
    let k = match out.iter().position(|&(x, _)| x == p) {
        Some(k) => k,
        None => {
            out.push((p, [0.0; 6]));
            out.len() - 1
        }
    };
    for (sum, &c) in out[k].1.iter_mut().zip(mask) {
        *sum += weight * c;
    }
}

/// Per neighbour of `v`: whether the edge to it is infinitely sharp (a boundary edge counts as
/// one); `None` where one is semi-sharp.
fn sharp_edges_to(level: &Level, v: u32, neighbours: &[u32]) -> Option<Vec<bool>> {
    use super::level::INFINITE_SHARPNESS;
    neighbours
        .iter()
        .map(|&n| {
            let e = level.edge_between(v, n)?;
            let s = level.edge_sharpness[e];
            if level.is_boundary_edge(e as u32) || s >= INFINITE_SHARPNESS {
                Some(true)
            } else if s <= 0.0 {
                Some(false)
            } else {
                None
            }
        })
        .collect()
}

/// Lattice point `at` of a sector's [`sided_weights`] net as `weight` times points, pushed to
/// `out`: a point of `cells`, or one missing below y = 0 (then left of x = 0) extrapolated from
/// the two inward of it, P₋₁ = 2 P₀ − P₁.
fn extended_cell(
    cells: &[((i32, i32), u32)],
    at: (i32, i32),
    weight: f64,
    out: &mut Vec<(u32, f64)>,
) -> Option<()> {
    if let Some(&(_, p)) = cells.iter().find(|&&(d, _)| d == at) {
        out.push((p, weight));
        return Some(());
    }
    let (x, y) = at;
    let (inner, next) = if y < 0 {
        ((x, 0), (x, 1))
    } else if x < 0 {
        ((0, y), (1, y))
    } else {
        return None;
    };
    extended_cell(cells, inner, 2.0 * weight, out)?;
    extended_cell(cells, next, -weight, out)
}

/// Most faces in one sector whose corner tangents are found by [`sector_corner_masks`]; a
/// wider fan keeps [`limit_tangents`]' one-sided estimate.
const MOST_SECTOR_FACES: usize = 32;

/// Catmull-Clark's subdivision matrix S of one sector at a sharp vertex: `k` quads around the
/// vertex between two sharp edges, over the points [v, e₀ … e_k, d₀ … d_{k−1}] (v the vertex,
/// e_j its neighbours in ring order, e₀ and e_k along the sharp edges, d_i the corner of quad
/// i = (v, e_i, d_i, e_{i+1}) opposite v), row-major: row r gives the child of point r (v's
/// vertex point, each edge (v, e_j)'s edge point, each quad's face point) from the parent
/// sector's points. The vertex follows the crease rule 3/4 v + 1/8 (e₀ + e_k), or stays where
/// `corner`; the sharp edges' points are their midpoints; the others take the smooth rules.
/// The sector's children are again such a sector, so the sector evolves on its own.
fn sector_matrix(k: usize, corner: bool) -> Vec<f64> {
    let n = 2 * k + 2;
    let (e, d) = (|j: usize| 1 + j, |i: usize| k + 2 + i);
    let mut s = vec![0.0; n * n];
    let face = |s: &mut [f64], row: usize, i: usize, w: f64| {
        for p in [0, e(i), d(i), e(i + 1)] {
            s[row * n + p] += w / 4.0;
        }
    };
    if corner {
        s[0] = 1.0;
    } else {
        s[0] = 0.75;
        s[e(0)] += 0.125;
        s[e(k)] += 0.125;
    }
    for j in [0, k] {
        s[e(j) * n] = 0.5;
        s[e(j) * n + e(j)] = 0.5;
    }
    for j in 1..k {
        let row = e(j);
        s[row * n] += 0.25;
        s[row * n + e(j)] += 0.25;
        face(&mut s, row, j - 1, 0.25);
        face(&mut s, row, j, 0.25);
    }
    for i in 0..k {
        face(&mut s, d(i), i, 1.0);
    }
    s
}

/// For each quad i of a sector of `k` quads ([`sector_matrix`]): two masks over the sector's
/// points whose cross product, applied to them, is the limit of quad i's normal at its corner
/// v (the normal the limit surface tends to inside that quad as it nears v). Quad i's corner
/// at level m spans (d_i − v) and (e_{i+1} − e_i), the rows r S^m of those differences over
/// the sector's points; the plane of the two rows converges to the span of the two slowest
/// decaying modes of S present in them (block power iteration, the rows re-orthonormalised at
/// each step, which keeps their plane and its orientation). This is Stam's eigenanalysis
/// ("Exact evaluation of Catmull-Clark subdivision surfaces at arbitrary parameter values",
/// 1998) applied at the corner, and it holds where the standard crease rules leave the surface
/// without one tangent plane at v (more than three quads in the sector): each quad then gets
/// its own.
fn sector_corner_masks(k: usize, corner: bool) -> Vec<[Vec<f64>; 2]> {
    let n = 2 * k + 2;
    let s = sector_matrix(k, corner);
    let times = |r: &[f64]| -> Vec<f64> {
        (0..n)
            .map(|c| (0..n).map(|p| r[p] * s[p * n + c]).sum())
            .collect()
    };
    let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
    // The limit position's mask, the left eigenvector of eigenvalue 1 (its right one is all
    // ones): rounding leaves a trace of it in the rows, which would grow against the others.
    let mut limit = vec![0.0; n];
    if corner {
        limit[0] = 1.0;
    } else {
        limit[0] = 2.0 / 3.0;
        limit[1] = 1.0 / 6.0;
        limit[k + 1] += 1.0 / 6.0;
    }
    let unit = |mut a: Vec<f64>| {
        let trace: f64 = a.iter().sum();
        a.iter_mut().zip(&limit).for_each(|(x, l)| *x -= trace * l);
        let length = dot(&a, &a).sqrt();
        a.iter_mut().for_each(|x| *x /= length);
        a
    };
    (0..k)
        .map(|i| {
            let mut a = vec![0.0; n];
            let mut b = vec![0.0; n];
            a[k + 2 + i] = 1.0;
            a[0] = -1.0;
            b[2 + i] = 1.0;
            b[1 + i] = -1.0;
            // Rows of differences sum to zero, so the mode of eigenvalue 1 is not in them; the
            // next modes' ratios are at most about 0.95 for fans of up to 32 quads.
            for _ in 0..600 {
                a = unit(times(&a));
                let c = times(&b);
                let along = dot(&c, &a);
                b = unit(c.iter().zip(&a).map(|(x, y)| x - along * y).collect());
            }
            // Where the second mode's eigenvalue λ is defective (a Jordan block, as for four
            // or eight quads at a crease), b still leans on the generalised eigenvector by
            // about 1/iterations: inverse iteration with (S − λI) settles it on the
            // eigenvector, and leaves a semisimple mode's direction as it is.
            let lambda = dot(&times(&b), &b);
            let shifted: Vec<f64> = (0..n * n)
                .map(|x| s[x] - if x / n == x % n { lambda } else { 0.0 })
                .collect();
            for _ in 0..3 {
                match solve_left(&shifted, &b, n) {
                    Some(x) if x.iter().all(|v| v.is_finite()) => {
                        // 1/(λ − μ) may be negative: keep the plane's orientation.
                        let sign = dot(&x, &b).signum();
                        b = unit(x.into_iter().map(|v| sign * v).collect());
                    }
                    _ => break,
                }
            }
            [a, b]
        })
        .collect()
}

/// The row x with x M = b for the n × n row-major `m` (Gaussian elimination with partial
/// pivoting on Mᵀ); `None` where M is singular to working precision.
fn solve_left(m: &[f64], b: &[f64], n: usize) -> Option<Vec<f64>> {
    // Mᵀ augmented with b: row r is column r of M.
    let mut a: Vec<Vec<f64>> = (0..n)
        .map(|r| (0..n).map(|c| m[c * n + r]).chain([b[r]]).collect())
        .collect();
    let scale = m.iter().fold(0.0f64, |x, y| x.max(y.abs()));
    for col in 0..n {
        let pivot = (col..n).max_by(|&x, &y| a[x][col].abs().total_cmp(&a[y][col].abs()))?;
        if a[pivot][col].abs() <= 1e-14 * scale {
            return None;
        }
        a.swap(col, pivot);
        let (upper, lower) = a.split_at_mut(col + 1);
        let pivot_row = &upper[col];
        for row in lower {
            let f = row[col] / pivot_row[col];
            if f != 0.0 {
                for (x, p) in row[col..].iter_mut().zip(&pivot_row[col..]) {
                    *x -= f * p;
                }
            }
        }
    }
    let mut x = vec![0.0; n];
    for r in (0..n).rev() {
        let tail: f64 = (r + 1..n).map(|c| a[r][c] * x[c]).sum();
        x[r] = (a[r][n] - tail) / a[r][r];
    }
    Some(x)
}

/// [`sector_corner_masks`] of a sector of `k` quads, found once per (k, corner) and thread and
/// kept. Each thread keeps its own: no lock, which the web page's main thread could not wait
/// for (the masks are the same on every thread).
fn cached_sector_masks(k: usize, corner: bool) -> std::rc::Rc<Vec<[Vec<f64>; 2]>> {
    use std::cell::RefCell;
    use std::collections::HashMap;
    use std::rc::Rc;
    type Masks = Rc<Vec<[Vec<f64>; 2]>>;
    thread_local! {
        static CACHE: RefCell<HashMap<(usize, bool), Masks>> = RefCell::new(HashMap::new());
    }
    CACHE.with(|cache| {
        Rc::clone(
            cache
                .borrow_mut()
                .entry((k, corner))
                .or_insert_with(|| Rc::new(sector_corner_masks(k, corner))),
        )
    })
}

/// Catmull-Clark's limit tangents at the corner `v` of quad `face` where `v` is a crease or a
/// corner (by its remaining sharpness) or lies on the boundary: two rows over the level's
/// vertices whose cross product points along the limit normal inside that quad at v, outward
/// (by the quad's winding), from the eigenanalysis of the sector of quads between the sharp
/// edges around v that holds `face` ([`sector_corner_masks`]). Each side of a crease thus gets
/// its own normal, and a boundary point of any valence its exact one. `None` where this does
/// not apply: another scheme, a smooth or dart vertex, a corner with no sharp edge, faces that
/// are not quads (a level below the first), or a fan wider than [`MOST_SECTOR_FACES`].
pub fn sharp_corner_tangents(level: &Level, scheme: Scheme, v: u32, face: u32) -> Option<[Row; 2]> {
    if scheme != Scheme::CatmullClark {
        return None;
    }
    let corner = match limit_rule(level, v) {
        Rule::Crease => false,
        Rule::Corner => true,
        Rule::Smooth | Rule::Dart => return None,
    };
    let ring = level.ring(v);
    let faces = ring.faces.len();
    if ring.faces.iter().any(|&f| level.face(f).len() != 4) {
        return None;
    }
    let at = ring.faces.iter().position(|&f| f == face)?;
    let ring_len = ring.neighbours.len();
    // Whether the edge from v to neighbour j (cyclically on an interior ring) is sharp; a
    // boundary ring's first and last edges are the boundary.
    let sharp = |j: usize| -> bool {
        if ring.boundary && (j == 0 || j == faces) {
            return true;
        }
        let w = ring.neighbours[j % ring_len];
        level
            .edge_between(v, w)
            .is_some_and(|e| level.edge_sharpness[e] > 0.0 || level.is_boundary_edge(e as u32))
    };
    // The sector: from the nearest sharp edge at or before the face's first side (neighbour
    // `start`) to the nearest after its second (`count` faces on); cyclic on an interior ring.
    let (start, count) = if ring.boundary {
        let start = (0..=at).rev().find(|&j| sharp(j))?;
        let end = (at + 1..=faces).find(|&j| sharp(j))?;
        (start, end - start)
    } else {
        let start = (0..faces)
            .map(|back| (at + faces - back) % faces)
            .find(|&j| sharp(j))?;
        let back = (at + faces - start) % faces;
        let count = (back + 1..=faces).find(|&c| sharp(start + c))?;
        (start, count)
    };
    // One quad between two creases: the crease rule's curve and the quad's face point decay
    // alike (both 1/4), a Jordan block that power iteration does not settle. Two or four
    // quads at a corner: the two crease curves' modes (1/2) meet an interior one of the same
    // eigenvalue in a Jordan block that reaches the first mode too.
    let settled = if corner {
        !matches!(count, 2 | 4)
    } else {
        count >= 2
    };
    if count > MOST_SECTOR_FACES || !settled {
        return None;
    }
    let i = (at + faces - start) % faces;
    let masks = cached_sector_masks(count, corner);
    let point = |p: usize| -> u32 {
        match p {
            0 => v,
            p if p <= count + 1 => ring.neighbours[(start + p - 1) % ring_len],
            p => level.diagonal(ring.faces[(start + p - count - 2) % faces], v),
        }
    };
    let [a, b] = &masks[i];
    let row = |m: &[f64]| -> Row {
        let mut row = Row::default();
        for (p, &w) in m.iter().enumerate() {
            if w != 0.0 {
                row.add(point(p), w);
            }
        }
        row.merged()
    };
    Some([row(a), row(b)])
}

#[cfg(test)]
mod tests {
    use glam::DVec3;

    use super::*;
    use crate::mesh::PolygonMesh;
    use crate::subdiv::level::INFINITE_SHARPNESS;
    use crate::subdiv::refine::refine;
    use crate::subdiv::{Boundary, Corner, Crease, Options, SubdivisionSurface};
    use crate::test_support::{Xorshift, placement};

    /// A fan of `faces` quads around point 0 over `turn` of a full turn (a boundary fan when
    /// less than 1, a closed wheel at 1), on a random saddle-like height field with jittered
    /// points, placed at random: the corners 1..=spokes on the spokes, then the outer corners.
    fn fan(seed: u64, faces: usize, turn: f64) -> (Vec<DVec3>, Vec<Vec<u32>>) {
        let mut random = Xorshift::new(seed);
        let mut next = || random.unit() - 0.5;
        let [a, b, c] = [4.0 * next(), 4.0 * next(), 4.0 * next()];
        let height = |x: f64, y: f64, noise: f64| a * x * x + b * x * y + c * y * y + noise;
        let closed = turn >= 1.0;
        let spokes = if closed { faces } else { faces + 1 };
        let angle = |t: f64| std::f64::consts::TAU * turn * t / faces as f64;
        let mut points = vec![DVec3::new(0.0, 0.0, 0.1 * next())];
        for j in 0..spokes {
            let (r, t) = (1.0 + 0.3 * next(), angle(j as f64 + 0.3 * next()));
            let (x, y) = (r * t.cos(), r * t.sin());
            points.push(DVec3::new(x, y, height(x, y, 0.1 * next())));
        }
        for i in 0..faces {
            let (r, t) = (1.5 + 0.3 * next(), angle(i as f64 + 0.5 + 0.2 * next()));
            let (x, y) = (r * t.cos(), r * t.sin());
            points.push(DVec3::new(x, y, height(x, y, 0.1 * next())));
        }
        let (motion, _) = placement(seed ^ 0x5eed);
        let points = points
            .into_iter()
            .map(|p| motion.transform_point3(p))
            .collect();
        let spoke = |j: usize| 1 + (j % spokes) as u32;
        let quads = (0..faces)
            .map(|i| vec![0, spoke(i), (1 + spokes + i) as u32, spoke(i + 1)])
            .collect();
        (points, quads)
    }

    /// The normals inside each quad around `v` near its corner v, found with no masks: the
    /// quads around v cut out and refined by the refinement's own rules again and again (the
    /// ring of v's children depends on the ring alone), each time moved back to v and scaled
    /// up (subdivision commutes with both), with the corner quad's normal
    /// (d − v) × (next − previous) taken at each of `steps` depths. Keyed by the quad's index
    /// at `level`.
    fn deep_corner_normals(
        level: &Level,
        points: &[DVec3],
        v: u32,
        steps: usize,
    ) -> Vec<(u32, Vec<DVec3>)> {
        let options = Options::default();
        let mut out = Vec::new();
        for &start in level.vertex_faces(v) {
            let (mut at, mut pts, mut face, mut centre) =
                (level.clone(), points.to_vec(), start, v);
            let mut normals = Vec::with_capacity(steps);
            for _ in 0..steps {
                // The ring of `centre` as its own cage, renumbered, with the sharpness kept.
                let ring: Vec<u32> = at.vertex_faces(centre).to_vec();
                let mut index = std::collections::HashMap::new();
                let mut local_points = Vec::new();
                let mut number = |x: u32, local_points: &mut Vec<DVec3>| -> u32 {
                    *index.entry(x).or_insert_with(|| {
                        local_points.push(pts[x as usize]);
                        local_points.len() as u32 - 1
                    })
                };
                number(centre, &mut local_points);
                let quads: Vec<Vec<u32>> = ring
                    .iter()
                    .map(|&f| {
                        at.face(f)
                            .iter()
                            .map(|&x| number(x, &mut local_points))
                            .collect()
                    })
                    .collect();
                let refs: Vec<&[u32]> = quads.iter().map(Vec::as_slice).collect();
                let mut cut = Level::new(local_points.len(), &refs, Vec::new()).unwrap();
                for (e, ends) in cut.edges.clone().iter().enumerate() {
                    let [a, b] = ends.map(|x| {
                        index
                            .iter()
                            .find(|&(_, &l)| l == x)
                            .map(|(&g, _)| g)
                            .unwrap()
                    });
                    let original = at.edge_between(a, b).unwrap();
                    cut.edge_sharpness[e] = if cut.is_boundary_edge(e as u32) {
                        INFINITE_SHARPNESS
                    } else {
                        at.edge_sharpness[original]
                    };
                }
                cut.vertex_sharpness[0] = at.vertex_sharpness[centre as usize];
                let position = ring.iter().position(|&f| f == face).unwrap() as u32;
                let (child, stencils) = refine(&cut, &options, 0).unwrap();
                let mut next = stencils.apply(&local_points);
                // Centre on v and scale up.
                let origin = next[0];
                let size = next.iter().map(|p| p.distance(origin)).fold(0.0, f64::max);
                next.iter_mut().for_each(|p| *p = (*p - origin) / size);
                // The child quad at v inside the quad followed: it holds that quad's face point.
                let face_point = cut.vertex_count as u32 + position;
                face = child
                    .vertex_faces(0)
                    .iter()
                    .copied()
                    .find(|&f| child.face(f).contains(&face_point))
                    .unwrap();
                (at, pts, centre) = (child, next, 0);
                let corners = at.face(face);
                let c = corners.iter().position(|&x| x == centre).unwrap();
                let p = |k: usize| pts[corners[(c + k) % 4] as usize];
                normals.push((p(2) - p(0)).cross(p(3) - p(1)).normalize());
            }
            out.push((start, normals));
        }
        out
    }

    /// Checks [`sharp_corner_tangents`] at point 0 of `surface` refined `levels` times against
    /// [`deep_corner_normals`] in every quad around it. The deep normals near the limit as the
    /// slower modes fade, then drift as rounding loses the weaker tangent against the
    /// stronger (their sizes part geometrically): where the modes part geometrically, the
    /// closest of the first 160 must be within 1e-6 rad of the masks' normal. Where the second
    /// mode is a Jordan block (four quads on a side), the deep normals near it only as 1/depth:
    /// their distance to the masks' normal must then shrink by 0.7 from depth 60 to 120 (as
    /// 1/(depth + c); a high-precision run of one such case went on shrinking, to 6e-4 rad at
    /// depth 1600).
    fn check_corner_normals(
        surface: &SubdivisionSurface,
        levels: u32,
        what: &str,
        checked: &mut usize,
    ) {
        let hierarchy = surface.hierarchy(levels).unwrap();
        let level = &hierarchy.levels[levels as usize];
        let points = hierarchy.refine_points(surface.points());
        let apply = |row: &Row| {
            row.0
                .iter()
                .map(|&(i, w)| w * points[i as usize])
                .sum::<DVec3>()
        };
        let mut sum = Some(DVec3::ZERO);
        for (face, deep) in deep_corner_normals(level, &points, 0, 160) {
            // Corners of two or four quads keep the one-sided estimate.
            let Some([a, b]) = sharp_corner_tangents(level, Scheme::CatmullClark, 0, face) else {
                sum = None;
                continue;
            };
            *checked += 1;
            let normal = apply(&a).cross(apply(&b)).normalize();
            sum = sum.map(|s| s + normal);
            let distance: Vec<f64> = deep.iter().map(|n| normal.angle_between(*n)).collect();
            let closest = distance.iter().copied().fold(f64::INFINITY, f64::min);
            let (d60, d120) = (distance[59], distance[119]);
            assert!(
                closest < 1e-6 || (d120 < 0.7 * d60 && d60 < 0.2),
                "{what}, quad {face}: the deep normals come within {closest} rad of the \
                 masks' normal ({d60} at depth 60, {d120} at 120)"
            );
        }
        // The limit mesh's one normal there: the mean of its quads' own.
        if let Some(sum) = sum {
            let one = surface.limit(levels).unwrap().normals[0];
            let angle = one.angle_between(sum.normalize());
            assert!(
                angle < 1e-9,
                "{what}: the limit mesh's normal is {angle} rad off"
            );
        }
    }

    #[test]
    fn sharp_corner_normals_are_the_limits_of_each_quads_normal() {
        let mut checked = 0;
        for seed in 0..3u64 {
            // A boundary point with 1 to 6 quads (the crease rule on the boundary; one quad
            // makes it a corner).
            for faces in 1..=6 {
                let (points, quads) = fan(100 * seed + faces as u64, faces, 0.5);
                let mesh = PolygonMesh::new(points, &quads).unwrap();
                let options = Options {
                    boundary: Boundary::EdgeAndCorner,
                    ..Options::default()
                };
                let surface = SubdivisionSurface::new(mesh, vec![], vec![], options, 1).unwrap();
                check_corner_normals(
                    &surface,
                    1 + (seed % 2) as u32,
                    &format!("seed {seed}, boundary of {faces}"),
                    &mut checked,
                );
            }
            // An interior crease through point 0 splitting a wheel of 5 to 8 quads unevenly,
            // and the same wheel with a third sharp edge (a corner).
            for faces in 5..=8usize {
                let (points, quads) = fan(1000 + 100 * seed + faces as u64, faces, 1.0);
                let split = 1 + (seed as usize + faces) % (faces - 2);
                let crease = |j: usize| Crease {
                    a: 0,
                    b: 1 + j as u32,
                    sharpness: INFINITE_SHARPNESS,
                };
                let mesh = PolygonMesh::new(points, &quads).unwrap();
                let surface = SubdivisionSurface::new(
                    mesh.clone(),
                    vec![crease(0), crease(split)],
                    vec![],
                    Options::default(),
                    1,
                )
                .unwrap();
                check_corner_normals(
                    &surface,
                    1,
                    &format!("seed {seed}, crease {split}/{faces}"),
                    &mut checked,
                );
                let third = split + 1 + (faces - split - 1) / 2;
                let creases = vec![crease(0), crease(split), crease(third)];
                let surface =
                    SubdivisionSurface::new(mesh.clone(), creases, vec![], Options::default(), 1)
                        .unwrap();
                check_corner_normals(
                    &surface,
                    1,
                    &format!("seed {seed}, corner {split}, {third}/{faces}"),
                    &mut checked,
                );
                let corner = vec![Corner {
                    vertex: 0,
                    sharpness: INFINITE_SHARPNESS,
                }];
                let surface = SubdivisionSurface::new(
                    mesh,
                    vec![crease(0), crease(split)],
                    corner,
                    Options::default(),
                    1,
                )
                .unwrap();
                check_corner_normals(
                    &surface,
                    1,
                    &format!("seed {seed}, sharp vertex on crease {split}/{faces}"),
                    &mut checked,
                );
            }
        }
        assert!(checked > 80, "{checked} quads checked");
    }

    #[test]
    fn a_regular_boundary_points_masks_match_the_bicubic_b_splines_tangents() {
        // Two quads at a boundary point: the B-spline's cross-boundary derivative
        // (d0 − e0)/6 + 2(e1 − v)/3 + (d1 − e2)/6 and the chord (e0 − e2)/2 along it, up to
        // scale, against the sector masks of quad 0.
        let masks = sector_corner_masks(2, false);
        for [a, b] in &masks {
            // Points [v, e0, e1, e2, d0, d1] of a generic sector.
            let mut random = Xorshift::new(7);
            let points: Vec<DVec3> = (0..6)
                .map(|_| DVec3::new(random.unit(), random.unit(), random.unit()))
                .collect();
            let apply = |m: &[f64]| m.iter().zip(&points).map(|(&w, &p)| w * p).sum::<DVec3>();
            let [v, e0, e1, e2, d0, d1] = points[..] else {
                unreachable!()
            };
            let along = (e0 - e2) / 2.0;
            let across = (d0 - e0) / 6.0 + 2.0 * (e1 - v) / 3.0 + (d1 - e2) / 6.0;
            let expected = along.cross(across).normalize();
            let normal = apply(a).cross(apply(b)).normalize();
            assert!(
                normal.angle_between(expected) < 1e-9,
                "{normal} against {expected}"
            );
        }
    }
}
