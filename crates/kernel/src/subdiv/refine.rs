//! One uniform refinement step with OpenSubdiv's (Sdc) rules: Catmull-Clark or Loop masks,
//! semi-sharp creases after DeRose, Kass & Truong 1998 (the crease rule while sharpness ≥ 1, a
//! blend by the fractional part below 1, sharpness one less per level), and the smooth, dart,
//! crease and corner vertex rules by the count of sharp edges.

use super::level::{INFINITE_SHARPNESS, Level, NONE};
use super::schemes::{self, butterfly_edge_row};
use super::stencil::{Row, Stencils};
use super::{Creasing, Options, Scheme};
use crate::GeometryError;

/// The vertex rules of OpenSubdiv's `Sdc::Crease::Rule`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Rule {
    Smooth,
    Dart,
    Crease,
    Corner,
}

/// The rule of a vertex with sharpness `vertex_sharpness` and `sharp_edges` incident edges of
/// sharpness > 0 (`Crease::DetermineVertexVertexRule`).
pub fn vertex_rule(vertex_sharpness: f64, sharp_edges: usize) -> Rule {
    if vertex_sharpness > 0.0 {
        return Rule::Corner;
    }
    match sharp_edges {
        0 => Rule::Smooth,
        1 => Rule::Dart,
        2 => Rule::Crease,
        _ => Rule::Corner,
    }
}

/// Sharpness one level down under uniform creasing: infinite stays infinite, s > 1 becomes
/// s − 1, the rest 0.
pub fn decrement(s: f64) -> f64 {
    if s >= INFINITE_SHARPNESS {
        s
    } else if s > 1.0 {
        s - 1.0
    } else {
        0.0
    }
}

fn is_semi_sharp(s: f64) -> bool {
    s > 0.0 && s < INFINITE_SHARPNESS
}

/// The sharpness of edge `e`'s child at its end `v` (`Crease::SubdivideEdgeSharpnessAtVertex`):
/// uniform creasing decrements; Chaikin's rule first takes 3/4 of the edge's sharpness plus 1/4
/// of the mean of the other semi-sharp edges at `v`.
pub fn child_edge_sharpness(level: &Level, e: u32, v: u32, creasing: Creasing) -> f64 {
    let s = level.edge_sharpness[e as usize];
    let edges = level.vertex_edges(v);
    if creasing == Creasing::Uniform || edges.len() < 2 || !is_semi_sharp(s) {
        return decrement(s);
    }
    let (sum, count) = edges
        .iter()
        .map(|&x| level.edge_sharpness[x as usize])
        .filter(|&x| is_semi_sharp(x))
        .fold((0.0, 0usize), |(a, n), x| (a + x, n + 1));
    let mut sharp = s;
    if count > 1 {
        let mean_of_others = (sum - s) / (count - 1) as f64;
        sharp = 0.75 * s + 0.25 * mean_of_others;
    }
    sharp -= 1.0;
    if sharp > 0.0 { sharp } else { 0.0 }
}

/// The other ends of the first two edges at `v` whose sharpness (`sharpness`, in
/// [`Level::vertex_edges`] order) is > 0: a crease's ends.
pub fn crease_pair(level: &Level, v: u32, sharpness: &[f64]) -> [u32; 2] {
    let edges = level.vertex_edges(v);
    let mut pair = [v; 2];
    let mut k = 0;
    for (i, &s) in sharpness.iter().enumerate() {
        if s > 0.0 && k < 2 {
            pair[k] = level.other_end(edges[i], v);
            k += 1;
        }
    }
    pair
}

/// v' = 3/4 v + 1/8 (a + b): the crease vertex rule of both schemes.
fn crease_vertex_row(v: u32, [a, b]: [u32; 2]) -> Row {
    Row(vec![(v, 0.75), (a, 0.125), (b, 0.125)])
}

/// The smooth vertex rule. Catmull-Clark: v' = (n − 2)/n v + 1/n² Σ e_j + 1/n² Σ f_j with the
/// face points f_j (centroids); Loop (Loop 1987): v' = (1 − nβ) v + β Σ e_j with
/// β = (5/8 − (3/8 + cos(2π/n)/4)²)/n.
fn smooth_vertex_row(level: &Level, scheme: Scheme, v: u32) -> Row {
    let edges = level.vertex_edges(v);
    let mut row = Row::default();
    match scheme {
        Scheme::CatmullClark => {
            let faces = level.vertex_faces(v);
            let n = faces.len() as f64;
            row.add(v, (n - 2.0) / n);
            for &e in edges {
                row.add(level.other_end(e, v), 1.0 / (n * n));
            }
            for &f in faces {
                row.add_centroid(level.face(f), 1.0 / (n * n));
            }
        }
        _ => {
            let n = edges.len() as f64;
            let beta = loop_beta(edges.len());
            row.add(v, 1.0 - n * beta);
            for &e in edges {
                row.add(level.other_end(e, v), beta);
            }
        }
    }
    row
}

/// Loop's original weight β(n) = (5/8 − (3/8 + cos(2π/n)/4)²)/n.
pub fn loop_beta(n: usize) -> f64 {
    let n = n as f64;
    let c = 0.375 + 0.25 * (std::f64::consts::TAU / n).cos();
    (0.625 - c * c) / n
}

fn rule_row(level: &Level, scheme: Scheme, v: u32, rule: Rule, sharpness: &[f64]) -> Row {
    match rule {
        Rule::Smooth | Rule::Dart => smooth_vertex_row(level, scheme, v),
        Rule::Crease => crease_vertex_row(v, crease_pair(level, v, sharpness)),
        Rule::Corner => Row(vec![(v, 1.0)]),
    }
}

/// The child of vertex `v` (`Scheme::ComputeVertexVertexMask`): the mask of the parent's rule,
/// blended with the child's rule where sharpness runs out in this step by the mean of the
/// sharpness values that make the transition (`Crease::ComputeFractionalWeightAtVertex`).
fn vertex_row(level: &Level, options: &Options, v: u32) -> Row {
    if level.vertex_faces(v).is_empty() {
        return Row(vec![(v, 1.0)]);
    }
    let edges = level.vertex_edges(v);
    let parent = level.incident_sharpness(v);
    let child: Vec<f64> = edges
        .iter()
        .map(|&e| child_edge_sharpness(level, e, v, options.creasing))
        .collect();
    let pv = level.vertex_sharpness[v as usize];
    let cv = decrement(pv);
    let count = |s: &[f64]| s.iter().filter(|&&x| x > 0.0).count();
    let p_rule = vertex_rule(pv, count(&parent));
    let p_row = rule_row(level, options.scheme, v, p_rule, &parent);
    if matches!(p_rule, Rule::Smooth | Rule::Dart) {
        return p_row;
    }
    let c_rule = vertex_rule(cv, count(&child));
    if c_rule == p_rule {
        return p_row;
    }
    let mut transitions = 0usize;
    let mut sum = 0.0;
    if pv > 0.0 && cv <= 0.0 {
        transitions += 1;
        sum += pv;
    }
    for (&p, &c) in parent.iter().zip(&child) {
        if p > 0.0 && c <= 0.0 {
            transitions += 1;
            sum += p;
        }
    }
    let weight = if transitions == 0 {
        0.0
    } else {
        (sum / transitions as f64).min(1.0)
    };
    let c_row = rule_row(level, options.scheme, v, c_rule, &child);
    p_row.blend(c_row, weight)
}

/// The vertex of triangle `f` that is not on edge (a, b) ([`Level::opposite`]).
pub fn opposite(level: &Level, f: u32, a: u32, b: u32) -> u32 {
    level.opposite(f, a, b)
}

/// The child of edge `e` (`Scheme::ComputeEdgeVertexMask`). Smooth: Catmull-Clark
/// 1/4 (a + b + f0 + f1) with face points f0, f1; Loop 3/8 (a + b) + 1/8 (c0 + c1) with the
/// opposite corners. Sharp (the child still sharp): the midpoint. A crease whose sharpness
/// runs out in this step: the blend s · midpoint + (1 − s) · smooth.
fn edge_row(level: &Level, options: &Options, e: u32) -> Row {
    let [a, b] = level.edges[e as usize];
    let midpoint = Row(vec![(a, 0.5), (b, 0.5)]);
    let [f0, f1] = level.edge_faces[e as usize];
    let s = level.edge_sharpness[e as usize];
    if f1 == NONE || f0 == NONE {
        return midpoint;
    }
    let smooth = || {
        let mut row = Row::default();
        match options.scheme {
            Scheme::CatmullClark => {
                row.add(a, 0.25);
                row.add(b, 0.25);
                row.add_centroid(level.face(f0), 0.25);
                row.add_centroid(level.face(f1), 0.25);
            }
            _ => {
                row.add(a, 0.375);
                row.add(b, 0.375);
                row.add(opposite(level, f0, a, b), 0.125);
                row.add(opposite(level, f1, a, b), 0.125);
            }
        }
        row
    };
    if s <= 0.0 {
        return smooth();
    }
    let c0 = child_edge_sharpness(level, e, a, options.creasing);
    let c1 = child_edge_sharpness(level, e, b, options.creasing);
    if c0 > 0.0 && c1 > 0.0 {
        return midpoint;
    }
    midpoint.blend(smooth().merged(), s.min(1.0))
}

/// Refinement step `step` (0 for the first) of `level` by `options.scheme`: the child level
/// and the stencils giving each child vertex from the parent's vertices. Doo-Sabin and √3
/// are in [`super::schemes`]; the face-splitting schemes in [`split`].
pub fn refine(
    level: &Level,
    options: &Options,
    step: usize,
) -> Result<(Level, Stencils), GeometryError> {
    match options.scheme {
        Scheme::DooSabin => schemes::doo_sabin(level),
        Scheme::Sqrt3 => schemes::sqrt3(level, step % 2 == 1),
        Scheme::CatmullClark | Scheme::Loop | Scheme::Butterfly => split(level, options),
    }
}

/// One face-splitting refinement of `level` (Catmull-Clark, or the 1-to-4 triangle split of
/// Loop and the butterfly): the child level (vertices numbered as OpenSubdiv's uniform
/// refinement numbers them — children of vertices, then of faces (Catmull-Clark), then of
/// edges; child faces face by face) and the stencils giving each child vertex from the
/// parent's vertices.
fn split(level: &Level, options: &Options) -> Result<(Level, Stencils), GeometryError> {
    let v_count = level.vertex_count as u32;
    let f_count = level.face_count() as u32;
    let e_count = level.edges.len() as u32;
    let catmull = options.scheme == Scheme::CatmullClark;
    let face_child = |f: u32| v_count + f;
    let edge_child = |e: u32| {
        if catmull {
            v_count + f_count + e
        } else {
            v_count + e
        }
    };

    // The butterfly interpolates: old points stay, edge points take its own masks.
    let butterfly = options.scheme == Scheme::Butterfly;
    // Rows of the children of vertices, then of faces (Catmull-Clark), then of edges, each
    // built on its own (in parallel) and merged.
    let face_rows = if catmull { f_count } else { 0 };
    let rows: Vec<Row> = crate::par::map((v_count + face_rows + e_count) as usize, |r| {
        let r = r as u32;
        let row = if r < v_count {
            if butterfly {
                Row(vec![(r, 1.0)])
            } else {
                vertex_row(level, options, r)
            }
        } else if r < v_count + face_rows {
            let mut row = Row::default();
            row.add_centroid(level.face(r - v_count), 1.0);
            row
        } else {
            let e = r - v_count - face_rows;
            if butterfly {
                butterfly_edge_row(level, e)
            } else {
                edge_row(level, options, e)
            }
        };
        row.merged()
    });
    let mut stencils = Stencils::new();
    for row in rows {
        stencils.push_merged(row);
    }

    let mut faces: Vec<Vec<u32>> = Vec::new();
    let mut edges: Vec<[u32; 2]> = Vec::new();
    let mut sharpness: Vec<f64> = Vec::new();
    for f in 0..f_count {
        let verts = level.face(f);
        let fe = level.face_edges(f);
        let n = verts.len();
        if catmull {
            for &e in fe {
                edges.push([face_child(f), edge_child(e)]);
                sharpness.push(0.0);
            }
            for j in 0..n {
                let prev = (j + n - 1) % n;
                let corners = [
                    verts[j],
                    edge_child(fe[j]),
                    face_child(f),
                    edge_child(fe[prev]),
                ];
                if n == 4 {
                    // OpenSubdiv keeps a quad's children oriented as their parent: child j has
                    // the vertex's child at corner j.
                    let mut rotated = [0; 4];
                    for (k, &c) in corners.iter().enumerate() {
                        rotated[(j + k) % 4] = c;
                    }
                    faces.push(rotated.to_vec());
                } else {
                    faces.push(corners.to_vec());
                }
            }
        } else {
            let [e0, e1, e2] = [edge_child(fe[0]), edge_child(fe[1]), edge_child(fe[2])];
            for pair in [[e0, e1], [e1, e2], [e2, e0]] {
                edges.push(pair);
                sharpness.push(0.0);
            }
            faces.push(vec![verts[0], e0, e2]);
            faces.push(vec![e0, verts[1], e1]);
            faces.push(vec![e2, e1, verts[2]]);
            faces.push(vec![e1, e2, e0]);
        }
    }
    for e in 0..e_count {
        let [a, b] = level.edges[e as usize];
        edges.push([a, edge_child(e)]);
        sharpness.push(child_edge_sharpness(level, e, a, options.creasing));
        edges.push([edge_child(e), b]);
        sharpness.push(child_edge_sharpness(level, e, b, options.creasing));
    }
    let child_count = stencils.len();
    let face_refs: Vec<&[u32]> = faces.iter().map(Vec::as_slice).collect();
    let mut child = Level::new(child_count, &face_refs, edges)?;
    child.edge_sharpness = sharpness;
    for v in 0..level.vertex_count {
        child.vertex_sharpness[v] = decrement(level.vertex_sharpness[v]);
    }
    Ok((child, stencils))
}
