//! Fillets and chamfers of a polyhedron's edges (see the module documentation of
//! [`super`]): each face cut back to lines set back from its picked edges, each picked edge
//! a cylinder (fillet) or a flat strip (chamfer) between them, and each corner of three picked
//! edges closed by a spherical or flat triangle.

use std::collections::HashMap;
use std::f64::consts::FRAC_PI_2;

use glam::{DVec2, DVec3};

use crate::construct::{arc, bilinear, extrude, line, revolve, ruled};
use crate::curve::{SpaceCurve, TrimCurve};
use crate::error::{GeometryError, construction};
use crate::planar::planar_face;
use crate::trim::TrimmedSurface;

use super::polyhedron::Polyhedron;
use super::{EdgePick, FeatureResult, WHAT, closed_result, facing, point};

/// What is made of each picked edge.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum EdgeFeature {
    /// A rolling-ball fillet of this radius.
    Fillet { radius: f64 },
    /// A chamfer set back `distance` on the edge's left face (the face its loop runs the edge
    /// from its lower vertex) and `other` on the right one.
    Chamfer { distance: f64, other: f64 },
}

/// A line: a point and a unit direction.
#[derive(Debug, Clone, Copy)]
struct Line {
    origin: DVec3,
    direction: DVec3,
}

impl Line {
    /// The distance from `p` to the line.
    fn distance(&self, p: DVec3) -> f64 {
        (p - self.origin)
            .reject_from_normalized(self.direction)
            .length()
    }
}

/// A plane `normal · x = offset`.
#[derive(Debug, Clone, Copy)]
struct Plane {
    normal: DVec3,
    offset: f64,
}

/// What a face's corner becomes.
#[derive(Debug, Clone)]
enum Corner {
    Point(DVec3),
    /// The corner cut off by a curve from `from` to `to` (an end face's corner under a
    /// fillet or chamfer that ends on it).
    Cut {
        from: DVec3,
        curve: SpaceCurve,
        to: DVec3,
    },
}

impl Corner {
    fn first(&self) -> DVec3 {
        match self {
            Corner::Point(p) => *p,
            Corner::Cut { from, .. } => *from,
        }
    }

    fn last(&self) -> DVec3 {
        match self {
            Corner::Point(p) => *p,
            Corner::Cut { to, .. } => *to,
        }
    }
}

/// One picked edge's lines.
#[derive(Debug, Clone, Copy)]
struct Round {
    /// Unit direction from vertex a to b.
    t: DVec3,
    /// −1 where the ball lies inside the material (a convex edge), +1 outside.
    side: f64,
    /// Set-back distances on the left and right faces at vertex a.
    set_left: f64,
    set_right: f64,
    /// A fillet's radius at vertex a (0 for a chamfer).
    radius: f64,
    /// The radius at vertex b over the radius at a: 1 but for a fillet whose radius varies
    /// along the edge, where the set-backs grow by the same factor.
    grow: f64,
}

impl Round {
    /// Whether the fillet's radius varies along its edge: by more than 1e-9 of itself (less
    /// puts the cone's apex so far off that its sections lose more than they would gain).
    fn varies(&self) -> bool {
        (self.grow - 1.0).abs() > 1e-9
    }
}

/// A corner of two chamfers ([`Builder::find_two_chamfers`]): the dominant edge, the other,
/// the face the dominant strip also cuts, the unpicked edge's new end and where the cut meets
/// the other strip.
type TwoChamfers = (usize, usize, usize, DVec3, DVec3);

struct Builder<'a> {
    solid: &'a Polyhedron,
    feature: EdgeFeature,
    rounds: HashMap<usize, Round>,
    tolerance: f64,
    /// Each vertex's quadrilateral or torus corner and its corner of two chamfers, found once
    /// ([`Builder::classify_corners`]).
    mixed: HashMap<usize, (usize, usize)>,
    two: HashMap<usize, TwoChamfers>,
}

/// The intersection of two lines in one plane.
fn meet(a: Line, b: Line) -> Option<DVec3> {
    let n = a.direction.cross(b.direction);
    let nn = n.length_squared();
    if nn < 1e-20 {
        return None;
    }
    let alpha = (b.origin - a.origin).cross(b.direction).dot(n) / nn;
    Some(a.origin + a.direction * alpha)
}

/// Where a line crosses a plane.
fn pierce(l: Line, p: Plane) -> Option<DVec3> {
    let d = p.normal.dot(l.direction);
    if d.abs() < 1e-12 {
        return None;
    }
    Some(l.origin + l.direction * ((p.offset - p.normal.dot(l.origin)) / d))
}

/// The curve σ ↦ (u, v(u)) over a rational quadratic basis (knots `knots`, weights `w`,
/// Bézier segments joined at double knots, as [`arc`] makes them) whose v carries the values
/// `y`: v(u) = Σ wᵢ Nᵢ(u) yᵢ / Σ wᵢ Nᵢ(u). Exact as a rational cubic: on each segment, with
/// u = k₀ + σΔ, the homogeneous coordinates are (u·W, Σ wᵢyᵢBᵢ², W) with W = Σ wᵢBᵢ², and
/// σBᵢ² = (i+1)/3 · B³ᵢ₊₁ and degree elevation (The NURBS Book §5.5) give their cubic
/// Bernstein coefficients.
fn graph_curve(knots: &[f64], w: &[f64], y: &[f64]) -> Result<TrimCurve, GeometryError> {
    let mut breaks: Vec<f64> = knots.to_vec();
    breaks.dedup();
    let segments = breaks.len() - 1;
    if w.len() != 2 * segments + 1 || y.len() != w.len() {
        return Err(construction(
            WHAT,
            "a fillet's arc is not piecewise quadratic",
        ));
    }
    let elevate = |x: [f64; 3]| {
        [
            x[0],
            (x[0] + 2.0 * x[1]) / 3.0,
            (2.0 * x[1] + x[2]) / 3.0,
            x[2],
        ]
    };
    let shifted = |x: [f64; 3]| [0.0, x[0] / 3.0, 2.0 * x[1] / 3.0, x[2]];
    let mut points = Vec::new();
    let mut weights = Vec::new();
    let mut cubic_knots = vec![breaks[0]; 4];
    for j in 0..segments {
        let (k0, k1) = (breaks[j], breaks[j + 1]);
        let ws = [w[2 * j], w[2 * j + 1], w[2 * j + 2]];
        let qs = [ws[0] * y[2 * j], ws[1] * y[2 * j + 1], ws[2] * y[2 * j + 2]];
        let (hw, hq, hs) = (elevate(ws), elevate(qs), shifted(ws));
        for i in usize::from(j > 0)..4 {
            let hu = k0 * hw[i] + (k1 - k0) * hs[i];
            points.push(DVec2::new(hu / hw[i], hq[i] / hw[i]));
            weights.push(hw[i]);
        }
        if j + 1 < segments {
            cubic_knots.extend([k1; 3]);
        }
    }
    cubic_knots.extend([breaks[segments]; 4]);
    TrimCurve::new(3, cubic_knots, points, Some(weights))
}

impl Builder<'_> {
    fn plane(&self, f: usize) -> Plane {
        let facet = &self.solid.faces[f];
        Plane {
            normal: facet.normal,
            offset: facet.offset,
        }
    }

    /// Edge `k`'s line.
    fn edge_line(&self, k: usize) -> Line {
        Line {
            origin: self.solid.vertices[self.solid.edges[k].a],
            direction: self.solid.direction(k),
        }
    }

    /// The line in face `f` that bounds it along edge `k`: the edge, or where the face is cut
    /// back for the edge's fillet or chamfer.
    fn bound(&self, k: usize, f: usize) -> Line {
        let line = self.edge_line(k);
        match self.rounds.get(&k) {
            None => line,
            Some(r) => {
                let back = if self.solid.edges[k].left == f {
                    r.set_left
                } else {
                    r.set_right
                };
                let inward = self.solid.inward(k, f);
                let origin = line.origin + inward * back;
                if !r.varies() {
                    return Line { origin, ..line };
                }
                // A varying fillet's contact runs from its set-back at a to the grown one
                // at b.
                let e = self.solid.edges[k];
                let end = self.solid.vertices[e.b] + inward * (back * r.grow);
                Line {
                    origin,
                    direction: (end - origin).normalize(),
                }
            }
        }
    }

    /// Edge `k`'s fillet arc at vertex a, from its left contact to its right one, and its
    /// centre there.
    fn arc(&self, k: usize) -> Result<(SpaceCurve, DVec3), GeometryError> {
        let e = self.solid.edges[k];
        let r = self.rounds[&k];
        let radius = r.radius;
        let (nl, nr) = (
            self.solid.faces[e.left].normal,
            self.solid.faces[e.right].normal,
        );
        let contact = self.bound(k, e.left).origin;
        let centre = contact + nl * (r.side * radius);
        let (x, y) = (nl * -r.side, nr * -r.side);
        let sweep = x.angle_between(y);
        Ok((arc(centre, x, y, radius, 0.0, sweep)?, centre))
    }

    /// Where edge `k`'s cut (the plane `p` through its fillet or strip) lies along the edge,
    /// for each of its arc's control points: λᵢ with the ruling through control point Pᵢ
    /// meeting the plane at Pᵢ + λᵢ t.
    fn lambdas(&self, k: usize, p: Plane) -> Result<(SpaceCurve, Vec<f64>), GeometryError> {
        let (arc, _) = self.arc(k)?;
        let t = self.rounds[&k].t;
        let d = p.normal.dot(t);
        if d.abs() < 1e-9 {
            return Err(construction(
                WHAT,
                format!(
                    "the fillet of the edge along {} runs parallel to the face it must end on",
                    point(t)
                ),
            ));
        }
        let lambdas = (0..arc.count())
            .map(|i| (p.offset - p.normal.dot(arc.control_point(i))) / d)
            .collect();
        Ok((arc, lambdas))
    }

    /// The point of a varying fillet's edge line where its radius would be 0:
    /// r(s) = r_a (1 + (grow − 1) s / L) vanishes at s = L / (1 − grow).
    fn apex(&self, k: usize) -> DVec3 {
        let e = self.solid.edges[k];
        let (a, b) = (self.solid.vertices[e.a], self.solid.vertices[e.b]);
        a + (b - a) / (1.0 - self.rounds[&k].grow)
    }

    /// A fillet whose radius varies linearly along its edge from r_a at vertex a to r_b at
    /// b: each section square to the edge is the arc of the ball of radius r(s) there, its
    /// centre and contacts r(s)-proportional offsets of the edge point, so every section is
    /// the arc at a scaled about the point O of the edge line where r would be 0. The fillet
    /// is the cone from O over the arc at a, and a plane n·x = c cuts the ruling through
    /// the arc's control point Qᵢ at scale μᵢ = (c − n·O) / n·(Qᵢ − O). Projected from O, a
    /// rational curve stays rational of its degree: its control points go to
    /// O + μᵢ(Qᵢ − O) and its weights to wᵢ/μᵢ (the section is exact).
    ///
    /// The arc at a, the apex O, and the scales μᵢ, refused where the plane misses a
    /// ruling on the fillet's side of O.
    fn cone_scales(
        &self,
        k: usize,
        p: Plane,
    ) -> Result<(SpaceCurve, DVec3, Vec<f64>), GeometryError> {
        let (arc, _) = self.arc(k)?;
        let e = self.solid.edges[k];
        let (a, b) = (self.solid.vertices[e.a], self.solid.vertices[e.b]);
        let apex = self.apex(k);
        let reach = p.offset - p.normal.dot(apex);
        let scales: Vec<f64> = (0..arc.count())
            .map(|i| reach / p.normal.dot(arc.control_point(i) - apex))
            .collect();
        if scales.iter().any(|m| !(m.is_finite() && *m > 1e-9)) {
            return Err(construction(
                WHAT,
                format!(
                    "the varying fillet of the edge from {} to {} does not reach the face it \
                     must end on",
                    point(a),
                    point(b)
                ),
            ));
        }
        Ok((arc, apex, scales))
    }

    /// The fillet of edge `k` cut by plane `p`: a conic, exact (its arc's control points
    /// moved along the edge onto the plane, the weights kept), from the left contact to the
    /// right one.
    fn section(&self, k: usize, p: Plane) -> Result<SpaceCurve, GeometryError> {
        if self.rounds[&k].varies() {
            let (arc, apex, scales) = self.cone_scales(k, p)?;
            let points = (0..arc.count())
                .map(|i| apex + (arc.control_point(i) - apex) * scales[i])
                .collect();
            let weights = (0..arc.count())
                .map(|i| arc.weight(i) / scales[i])
                .collect();
            return SpaceCurve::new(2, arc.knots().to_vec(), points, Some(weights));
        }
        let (arc, lambdas) = self.lambdas(k, p)?;
        let t = self.rounds[&k].t;
        let points = (0..arc.count())
            .map(|i| arc.control_point(i) + t * lambdas[i])
            .collect();
        let weights = (0..arc.count()).map(|i| arc.weight(i)).collect();
        SpaceCurve::new(2, arc.knots().to_vec(), points, Some(weights))
    }

    /// A corner of three picked edges closed by a quadrilateral rather than a triangle or a
    /// ball: the pivot edge and the face the other two share, or None.
    ///
    /// Chamfers, as OpenCASCADE's `BRepFilletAPI_MakeChamfer` closes them: where one edge
    /// differs in convexity from the other two (a concave upright edge under two convex cap
    /// edges, a convex one over two concave base edges) it is the pivot; where all three are
    /// alike, the pivot is the edge whose strip each other strip meets no nearer the vertex
    /// than it meets the third one. The other two strips end square to their edges where
    /// the pivot's strip meets their other faces, and the face they share is cut straight
    /// between those ends; for alike edges the corner stays the flat triangle through the
    /// three faces' corners where that cut is shorter than 0.3 times the longer diagonal of
    /// the quadrilateral (a right-angled corner's cut has no length).
    ///
    /// Fillets only where one edge differs in convexity and stands square to the shared face
    /// (a prism's upright edge, a boss's or a pocket's): the like fillets' ball then rolls
    /// round the odd fillet on a torus about its axis, as OpenCASCADE's
    /// `BRepFilletAPI_MakeFillet` rounds it.
    fn find_mixed_corner(&self, v: usize) -> Option<(usize, usize)> {
        let solid = self.solid;
        let at_v = solid.edges_at(v);
        if at_v.len() != 3 {
            return None;
        }
        let sides: Vec<f64> = at_v
            .iter()
            .map(|k| self.rounds.get(k).map(|r| r.side))
            .collect::<Option<_>>()?;
        let shared = |j: usize, k: usize| {
            let (a, b) = (solid.edges[j], solid.edges[k]);
            [a.left, a.right]
                .into_iter()
                .find(|&f| f == b.left || f == b.right)
        };
        let odd = (0..3).find(|&i| sides.iter().filter(|&&s| s == sides[i]).count() == 1);
        if let EdgeFeature::Fillet { .. } = self.feature {
            let odd = odd?;
            let face = shared(at_v[(odd + 1) % 3], at_v[(odd + 2) % 3])?;
            let square = self.rounds[&at_v[odd]]
                .t
                .cross(solid.faces[face].normal)
                .length()
                <= 1e-9;
            return square.then_some((at_v[odd], face));
        }
        if let Some(odd) = odd {
            let face = shared(at_v[(odd + 1) % 3], at_v[(odd + 2) % 3])?;
            return Some((at_v[odd], face));
        }
        // Where strips j and k meet: the corner of their shared face; how far along j
        // from the vertex that lies.
        let meeting = |j: usize, k: usize| -> Option<DVec3> {
            let f = shared(j, k)?;
            meet(self.bound(j, f), self.bound(k, f))
        };
        let along = |j: usize, p: DVec3| {
            let e = solid.edges[j];
            let d = if e.a == v {
                solid.direction(j)
            } else {
                -solid.direction(j)
            };
            (p - solid.vertices[v]).dot(d)
        };
        let slack = 1e-9 * (1.0 + solid.vertices[v].length()) + self.tolerance;
        for i in 0..3 {
            let (pivot, j, k) = (at_v[i], at_v[(i + 1) % 3], at_v[(i + 2) % 3]);
            let (q_ij, q_ik, q_jk) = (meeting(pivot, j)?, meeting(pivot, k)?, meeting(j, k)?);
            if along(j, q_ij) < along(j, q_jk) - slack || along(k, q_ik) < along(k, q_jk) - slack {
                continue;
            }
            let face = shared(j, k)?;
            let end_j = self.square_end(j, face, pivot, v).ok()?;
            let end_k = self.square_end(k, face, pivot, v).ok()?;
            let diagonal = end_j.distance(q_ik).max(end_k.distance(q_ij));
            return (end_j.distance(end_k) >= 0.3 * diagonal).then_some((pivot, face));
        }
        None
    }

    /// At vertex `v` where two convex chamfered edges meet and the third edge, convex too,
    /// is not picked, with their set-back lines meeting that edge at different points: the
    /// chamfered body there is the solid cut by both strips' planes (as OpenCASCADE's is).
    /// The strip that cuts the unpicked edge further from the vertex (the dominant one) also
    /// cuts the other picked edge's far face, along the line where its plane meets that
    /// face, up to the other strip; returns (dominant, other, that face, the unpicked edge's
    /// new end, where the cut meets the other strip's set-back line).
    fn find_two_chamfers(&self, v: usize) -> Option<TwoChamfers> {
        if !matches!(self.feature, EdgeFeature::Chamfer { .. }) {
            return None;
        }
        let solid = self.solid;
        let at_v = solid.edges_at(v);
        if at_v.len() != 3 || at_v.iter().any(|&k| !solid.is_convex(k)) {
            return None;
        }
        let picked: Vec<usize> = at_v
            .iter()
            .copied()
            .filter(|k| self.rounds.contains_key(k))
            .collect();
        let &[p, q] = picked.as_slice() else {
            return None;
        };
        let unpicked = at_v.iter().copied().find(|k| !picked.contains(k))?;
        let (ep, eq) = (solid.edges[p], solid.edges[q]);
        let shared = [ep.left, ep.right]
            .into_iter()
            .find(|&f| f == eq.left || f == eq.right)?;
        let (face_p, face_q) = (self.other_face(p, shared), self.other_face(q, shared));
        let on_p = meet(self.bound(p, face_p), self.edge_line(unpicked))?;
        let on_q = meet(self.bound(q, face_q), self.edge_line(unpicked))?;
        let (dp, dq) = (
            on_p.distance(solid.vertices[v]),
            on_q.distance(solid.vertices[v]),
        );
        if (dp - dq).abs() <= 10.0 * self.tolerance {
            return None;
        }
        let (dominant, other, face, far) = if dp > dq {
            (p, q, face_q, on_p)
        } else {
            (q, p, face_p, on_q)
        };
        // The dominant strip's plane: through its edge and both set-back lines.
        let e = solid.edges[dominant];
        let (l, r) = (self.bound(dominant, e.left), self.bound(dominant, e.right));
        let normal = self.rounds[&dominant].t.cross(r.origin - l.origin);
        let along = normal.cross(solid.faces[face].normal);
        let cut = meet(
            Line {
                origin: far,
                direction: along.normalize_or_zero(),
            },
            self.bound(other, face),
        )?;
        Some((dominant, other, face, far, cut))
    }

    /// Finds each vertex's special corner once: [`Self::find_mixed_corner`] and
    /// [`Self::find_two_chamfers`], read back by [`Self::mixed_corner`] and
    /// [`Self::two_chamfers`] wherever a face, strip, fillet or patch meets the vertex.
    fn classify_corners(&mut self) {
        let vertices = 0..self.solid.vertices.len();
        self.mixed = vertices
            .clone()
            .filter_map(|v| self.find_mixed_corner(v).map(|m| (v, m)))
            .collect();
        self.two = vertices
            .filter_map(|v| self.find_two_chamfers(v).map(|t| (v, t)))
            .collect();
    }

    /// The pivot and shared face of vertex `v`'s quadrilateral or torus corner, if it has one.
    fn mixed_corner(&self, v: usize) -> Option<(usize, usize)> {
        self.mixed.get(&v).copied()
    }

    /// Vertex `v`'s corner of two chamfers, if it has one.
    fn two_chamfers(&self, v: usize) -> Option<TwoChamfers> {
        self.two.get(&v).copied()
    }

    /// The foot on the shared face `f` of odd edge `odd`'s fillet axis: the centre of the
    /// mixed corner's torus on that face.
    fn odd_axis_foot(&self, odd: usize, f: usize) -> Result<DVec3, GeometryError> {
        let (_, centre) = self.arc(odd)?;
        pierce(
            Line {
                origin: centre,
                direction: self.rounds[&odd].t,
            },
            self.plane(f),
        )
        .ok_or_else(|| construction(WHAT, "a fillet runs parallel to the face it ends on"))
    }

    /// Where like edge `k`'s strip ends on the shared face `f` at a mixed chamfer corner
    /// with odd edge `odd`: on its bound line in `f`, square to the edge through the corner
    /// of its other face.
    fn square_end(&self, k: usize, f: usize, odd: usize, v: usize) -> Result<DVec3, GeometryError> {
        let w = self.other_face(k, f);
        let corner = meet(self.bound(odd, w), self.bound(k, w)).ok_or_else(|| {
            construction(
                WHAT,
                format!(
                    "the chamfers at {} run parallel on a face",
                    point(self.solid.vertices[v])
                ),
            )
        })?;
        let l = self.bound(k, f);
        Ok(l.origin + l.direction * (corner - l.origin).dot(l.direction))
    }

    fn other_face(&self, k: usize, f: usize) -> usize {
        let e = self.solid.edges[k];
        if e.left == f { e.right } else { e.left }
    }

    /// Face `f`'s corner at vertex `v`, between the edges from `previous` and to `next`.
    fn corner(
        &self,
        f: usize,
        previous: usize,
        v: usize,
        next: usize,
    ) -> Result<Corner, GeometryError> {
        let solid = self.solid;
        let (Some(e_in), Some(e_out)) =
            (solid.edge_between(previous, v), solid.edge_between(v, next))
        else {
            return Err(construction(WHAT, "a face's loop runs along no edge"));
        };
        let (picked_in, picked_out) = (
            self.rounds.contains_key(&e_in),
            self.rounds.contains_key(&e_out),
        );
        if let Some((_, other, face, far, cut)) = self.two_chamfers(v)
            && face == f
        {
            let (from, to) = if e_out == other {
                (far, cut)
            } else {
                (cut, far)
            };
            return Ok(Corner::Cut {
                from,
                curve: line(from, to)?,
                to,
            });
        }
        if let Some((odd, shared)) = self.mixed_corner(v)
            && shared == f
        {
            let from = self.square_end(e_in, f, odd, v)?;
            let to = self.square_end(e_out, f, odd, v)?;
            let curve = match self.feature {
                EdgeFeature::Chamfer { .. } => line(from, to)?,
                EdgeFeature::Fillet { .. } => {
                    let c = self.odd_axis_foot(odd, f)?;
                    let (x, y) = (from - c, to - c);
                    if (x.length() - y.length()).abs() > 10.0 * self.tolerance {
                        return Err(construction(
                            WHAT,
                            format!(
                                "the fillets at {} do not roll round one another",
                                point(solid.vertices[v])
                            ),
                        ));
                    }
                    arc(c, x, y, x.length(), 0.0, x.angle_between(y))?
                }
            };
            return Ok(Corner::Cut { from, curve, to });
        }
        if picked_in || picked_out {
            return meet(self.bound(e_in, f), self.bound(e_out, f))
                .map(Corner::Point)
                .ok_or_else(|| {
                    construction(
                        WHAT,
                        format!(
                            "the face at {} runs straight on at a corner",
                            point(solid.vertices[v])
                        ),
                    )
                });
        }
        let third: Vec<usize> = solid
            .edges_at(v)
            .into_iter()
            .filter(|&k| k != e_in && k != e_out && self.rounds.contains_key(&k))
            .collect();
        let Some(&e3) = third.first() else {
            return Ok(Corner::Point(solid.vertices[v]));
        };
        // The picked edge's fillet or strip ends on this face.
        let (h, g) = (self.other_face(e_in, f), self.other_face(e_out, f));
        let plane = self.plane(f);
        let missing = || {
            construction(
                WHAT,
                format!(
                    "the feature of the edge at {} does not reach the face it ends on",
                    point(solid.vertices[v])
                ),
            )
        };
        let from = pierce(self.bound(e3, h), plane).ok_or_else(missing)?;
        let to = pierce(self.bound(e3, g), plane).ok_or_else(missing)?;
        let curve = match self.feature {
            EdgeFeature::Chamfer { .. } => line(from, to)?,
            EdgeFeature::Fillet { .. } => {
                let c = self.section(e3, plane)?;
                if solid.edges[e3].left == h {
                    c
                } else {
                    c.reverse()
                }
            }
        };
        Ok(Corner::Cut { from, curve, to })
    }
}

/// `feature` made of the edges of the polyhedral solid `faces` that `pick` names (see the
/// module documentation), joined and checked at `tolerance`.
pub fn round_edges(
    faces: &[TrimmedSurface],
    pick: &EdgePick,
    feature: EdgeFeature,
    tolerance: f64,
) -> Result<FeatureResult, GeometryError> {
    round_edges_varying(faces, pick, feature, &[], tolerance)
}

/// [`round_edges`] with fillet radii set at vertices: each `(point, radius)` of `radii` sets
/// the radius at the picked edges' end nearest the point, and each picked edge's radius runs
/// linearly from its value at one end to that at the other (the feature's radius where none
/// is set; OpenCASCADE's `SetRadius(R, IC, V)` sets a radius at a vertex the same way). A
/// fillet whose radius varies is exact: the section square to the edge at each point is the
/// rolling-ball arc of the radius there (as OpenCASCADE's evolving fillets are defined), and
/// the linear law makes these arcs one cone ([`Builder::cone_scales`]). For now it is built
/// on solids with flat faces only, ending at corners where no other edge is filleted.
pub fn round_edges_varying(
    faces: &[TrimmedSurface],
    pick: &EdgePick,
    feature: EdgeFeature,
    radii: &[(DVec3, f64)],
    tolerance: f64,
) -> Result<FeatureResult, GeometryError> {
    for &(p, r) in radii {
        if !(r.is_finite() && r > 0.0 && p.is_finite()) {
            return Err(construction(
                WHAT,
                format!("a radius at a point must be a number above 0 at a finite point, got {r}"),
            ));
        }
        if let EdgeFeature::Chamfer { .. } = feature {
            return Err(construction(
                WHAT,
                "radii at points are for fillets; a chamfer's distances are the same along its \
                 edge",
            ));
        }
    }
    let varying = |what: &str| {
        construction(
            WHAT,
            format!("a fillet whose radius varies is built on {what} for now"),
        )
    };
    let what = match feature {
        EdgeFeature::Fillet { radius } => {
            if !(radius.is_finite() && radius > 0.0) {
                return Err(construction(
                    WHAT,
                    format!("the radius must be a number above 0, got {radius}"),
                ));
            }
            "fillet"
        }
        EdgeFeature::Chamfer { distance, other } => {
            for d in [distance, other] {
                if !(d.is_finite() && d > 0.0) {
                    return Err(construction(
                        WHAT,
                        format!("the distance must be a number above 0, got {d}"),
                    ));
                }
            }
            "chamfer"
        }
    };
    if !(tolerance.is_finite() && tolerance > 0.0) {
        return Err(construction(
            WHAT,
            format!("the tolerance must be a number above 0, got {tolerance}"),
        ));
    }
    // A solid of revolution; else flat faces, curved ones (round holes) kept as they are.
    let mut solid = if faces.iter().any(|f| f.surface().plane(tolerance).is_none()) {
        if !radii.is_empty() {
            return Err(varying("solids with flat faces only"));
        }
        match super::revolved::round_revolved(faces, pick, feature, tolerance, what) {
            Ok(made) => return Ok(made),
            Err(revolved) => match Polyhedron::with_curved(faces, tolerance) {
                Ok(solid) if !solid.edges.is_empty() => solid,
                // A prism whose outline has arcs: its rims as tangent chains.
                _ => match super::extruded::round_curved_prism(faces, pick, feature, tolerance) {
                    Some(made) => {
                        let (made, picked) = made?;
                        return closed_result(made, tolerance * 10.0, picked, what);
                    }
                    None => return Err(revolved),
                },
            },
        }
    } else {
        Polyhedron::from_faces(faces, tolerance)?
    };
    // Round holes' and bosses' walls: their rims are edges too.
    let walls = super::rims::take_walls(&mut solid, tolerance)?;
    let (picked, rims) = super::rims::picked_with_rims(&solid, &walls, pick)?;
    if !radii.is_empty() && !walls.is_empty() {
        return Err(varying("solids without round walls"));
    }
    // The radius set at each vertex: at the picked edges' end nearest each point.
    let mut vertex_radius: HashMap<usize, f64> = HashMap::new();
    for &(p, r) in radii {
        let nearest = picked
            .iter()
            .flat_map(|&k| [solid.edges[k].a, solid.edges[k].b])
            .min_by(|&i, &j| {
                solid.vertices[i]
                    .distance(p)
                    .total_cmp(&solid.vertices[j].distance(p))
            });
        if let Some(v) = nearest {
            vertex_radius.insert(v, r);
        }
    }
    // Every edge of a right prism with a concave edge: the rims' fillets run on round the
    // concave fillets' tops ([`super::extruded`]).
    if let EdgeFeature::Fillet { radius } = feature {
        let concave = (0..solid.edges.len()).any(|k| !solid.is_convex(k));
        if picked.len() == solid.edges.len()
            && radii.is_empty()
            && concave
            && walls.is_empty()
            && let Some(made) = super::extruded::fillet_prism(&solid, radius)
        {
            return closed_result(made?, tolerance * 10.0, picked.len(), what);
        }
    }
    let mut rounds = HashMap::new();
    for &k in &picked {
        let e = solid.edges[k];
        let (ml, mr) = (solid.inward(k, e.left), solid.inward(k, e.right));
        let psi = ml.angle_between(mr);
        let at = || {
            format!(
                "from {} to {}",
                point(solid.vertices[e.a]),
                point(solid.vertices[e.b])
            )
        };
        if !(psi > 1e-6 && psi < std::f64::consts::PI - 1e-6) {
            return Err(construction(
                WHAT,
                format!(
                    "the faces at the edge {} meet flat or fold back; it has no {what}",
                    at()
                ),
            ));
        }
        let side = if solid.is_convex(k) { -1.0 } else { 1.0 };
        let (set_left, set_right, radius, grow) = match feature {
            EdgeFeature::Fillet { radius } => {
                let at = |v: usize| vertex_radius.get(&v).copied().unwrap_or(radius);
                let (ra, rb) = (at(e.a), at(e.b));
                let c = ra / (0.5 * psi).tan();
                (c, c, ra, rb / ra)
            }
            EdgeFeature::Chamfer { distance, other } => (distance, other, 0.0, 1.0),
        };
        let round = Round {
            t: solid.direction(k),
            side,
            set_left,
            set_right,
            radius,
            grow,
        };
        rounds.insert(k, round);
        for v in [e.a, e.b] {
            let at_v = solid.edges_at(v);
            let faces_at: std::collections::BTreeSet<usize> = at_v
                .iter()
                .flat_map(|&j| [solid.edges[j].left, solid.edges[j].right])
                .collect();
            if at_v.len() != 3 || faces_at.len() != 3 {
                return Err(construction(
                    WHAT,
                    format!(
                        "the corner at {} joins {} edges; a {what} ends only at corners of three \
                         edges and three faces for now",
                        point(solid.vertices[v]),
                        at_v.len()
                    ),
                ));
            }
            let alone = at_v.iter().all(|&j| j == k || !picked.contains(&j));
            if round.varies() && !alone {
                return Err(construction(
                    WHAT,
                    format!(
                        "the fillet of the edge {} varies in radius and meets another fillet at \
                         {}; a varying fillet ends only at corners where no other edge is \
                         filleted, for now",
                        at(),
                        point(solid.vertices[v])
                    ),
                ));
            }
        }
    }
    // The walls: rebuilt, their picked rims rounded, their circles given to the flat faces.
    let setback = |f: usize, a: usize, b: usize| -> f64 {
        solid
            .edge_between(a, b)
            .and_then(|k| {
                rounds.get(&k).map(|r| {
                    if solid.edges[k].left == f {
                        r.set_left
                    } else {
                        r.set_right
                    }
                })
            })
            .unwrap_or(0.0)
    };
    let (wall_faces, circles) =
        super::rims::build_walls(&solid, &walls, &rims, feature, &setback, tolerance)?;
    for (f, circle) in circles {
        solid.faces[f].kept.push(vec![circle]);
    }
    let mut b = Builder {
        solid: &solid,
        feature,
        rounds,
        tolerance,
        mixed: HashMap::new(),
        two: HashMap::new(),
    };
    b.classify_corners();
    // Each face's corners, then its loops.
    let mut corners: HashMap<(usize, usize), Corner> = HashMap::new();
    let mut out = Vec::new();
    for (f, facet) in solid.faces.iter().enumerate() {
        let mut boundary = Vec::new();
        for ring in &facet.loops {
            let n = ring.len();
            let ring_corners = (0..n)
                .map(|i| b.corner(f, ring[(i + n - 1) % n], ring[i], ring[(i + 1) % n]))
                .collect::<Result<Vec<_>, _>>()?;
            for i in 0..n {
                let (here, there) = (&ring_corners[i], &ring_corners[(i + 1) % n]);
                if let Corner::Cut { curve, .. } = here {
                    boundary.push(curve.clone());
                }
                let (p, q) = (here.last(), there.first());
                let along = solid.vertices[ring[(i + 1) % n]] - solid.vertices[ring[i]];
                if (q - p).dot(along) <= tolerance * along.length() {
                    let k = solid.edge_between(ring[i], ring[(i + 1) % n]).unwrap_or(0);
                    let e = solid.edges[k];
                    let varying = [e.a, e.b].into_iter().find(|&v| {
                        solid
                            .edges_at(v)
                            .iter()
                            .any(|j| b.rounds.get(j).is_some_and(Round::varies))
                    });
                    if let Some(v) = varying {
                        return Err(construction(
                            WHAT,
                            format!(
                                "the fillet of varying radius at {} is too large for face \
                                 {f}: its contact runs past the end of the edge from {} to {} \
                                 before it reaches the face it ends on (beyond its edge its \
                                 radius keeps changing at the same rate)",
                                point(solid.vertices[v]),
                                point(solid.vertices[e.a]),
                                point(solid.vertices[e.b])
                            ),
                        ));
                    }
                    return Err(construction(
                        WHAT,
                        format!(
                            "the {what} is too large for the edge from {} to {}: the {what}s at \
                             its ends overlap on face {f}",
                            point(solid.vertices[e.a]),
                            point(solid.vertices[e.b])
                        ),
                    ));
                }
                boundary.push(line(p, q)?);
            }
            for (i, c) in ring_corners.into_iter().enumerate() {
                corners.insert((f, ring[i]), c);
            }
        }
        boundary.extend(facet.kept.iter().flatten().cloned());
        let face = planar_face(&boundary).map_err(|e| {
            construction(
                WHAT,
                format!("the {what} leaves face {f} without a valid boundary ({e})"),
            )
        })?;
        let normal = facet.normal;
        out.push(facing(face, |_| normal)?);
    }
    out.extend(solid.kept.iter().cloned());
    // Unpicked edges whose ends moved: both faces must agree on the new end.
    let corner_at = |f: usize, v: usize| -> Result<&Corner, GeometryError> {
        corners
            .get(&(f, v))
            .ok_or_else(|| construction(WHAT, "a face lost a corner"))
    };
    for (k, e) in solid.edges.iter().enumerate() {
        if b.rounds.contains_key(&k) {
            continue;
        }
        for (v, from_left) in [(e.a, true), (e.b, false)] {
            // The left face runs a → b: its corner at a ends the edge with its last point,
            // at b starts it with its first; the right face the other way round.
            let (l, r) = (corner_at(e.left, v)?, corner_at(e.right, v)?);
            let (pl, pr) = if from_left {
                (l.last(), r.first())
            } else {
                (l.first(), r.last())
            };
            if pl.distance(pr) > 10.0 * tolerance {
                return Err(construction(
                    WHAT,
                    format!(
                        "the corner at {} needs a vertex blend, which is not built yet: the \
                         {what}s there leave a gap of {:.3e}",
                        point(solid.vertices[v]),
                        pl.distance(pr)
                    ),
                ));
            }
        }
    }
    // The picked edges' fillets or strips.
    for &k in &picked {
        let e = solid.edges[k];
        let r = b.rounds[&k];
        // The left face runs a → b, so its corner at a is where the edge starts (its last
        // point) and at b where it ends (its first); the right face the other way round.
        let (la, lb) = (
            corner_at(e.left, e.a)?.last(),
            corner_at(e.left, e.b)?.first(),
        );
        let (ra, rb) = (
            corner_at(e.right, e.a)?.first(),
            corner_at(e.right, e.b)?.last(),
        );
        match feature {
            EdgeFeature::Chamfer { .. } => {
                // A dominant strip at a corner of two chamfers runs on to the other's.
                let cut_at = |v: usize| {
                    b.two_chamfers(v)
                        .filter(|&(dominant, ..)| dominant == k)
                        .map(|(.., cut)| cut)
                };
                let mut ring = vec![la, lb];
                ring.extend(cut_at(e.b));
                ring.extend([rb, ra]);
                ring.extend(cut_at(e.a));
                let sides = (0..ring.len())
                    .map(|i| line(ring[i], ring[(i + 1) % ring.len()]))
                    .collect::<Result<Vec<_>, _>>()?;
                let strip = planar_face(&sides)?;
                let (nl, nr) = (solid.faces[e.left].normal, solid.faces[e.right].normal);
                out.push(facing(strip, |_| nl + nr)?);
            }
            EdgeFeature::Fillet { .. } => {
                let ends = [b.end_plane(k, e.a)?, b.end_plane(k, e.b)?];
                for (v, plane, (l, rr)) in [(e.a, ends[0], (la, ra)), (e.b, ends[1], (lb, rb))] {
                    let section = b.section(k, plane)?;
                    let (s0, s1) = section.ends()?;
                    if s0.distance(l) > 10.0 * tolerance || s1.distance(rr) > 10.0 * tolerance {
                        return Err(construction(
                            WHAT,
                            format!(
                                "the corner at {} needs a vertex blend, which is not built yet: \
                                 the fillets there miss each other by {:.3e}",
                                point(solid.vertices[v]),
                                s0.distance(l).max(s1.distance(rr))
                            ),
                        ));
                    }
                }
                let face = b.fillet_face(k, ends)?;
                let (_, centre) = b.arc(k)?;
                let side = r.side;
                // The ball centres' line: along the edge, or, where the radius varies,
                // through the cone's apex.
                let t = if r.varies() {
                    (centre - b.apex(k)).normalize()
                } else {
                    r.t
                };
                out.push(facing(face, |p| {
                    let on_axis = centre + t * (p - centre).dot(t);
                    (p - on_axis) * -side
                })?);
            }
        }
    }
    // Corners of three picked edges.
    for v in 0..solid.vertices.len() {
        let at_v = solid.edges_at(v);
        if at_v.len() != 3 || !at_v.iter().all(|k| b.rounds.contains_key(k)) {
            continue;
        }
        let faces_at: Vec<usize> = {
            let mut f: Vec<usize> = at_v
                .iter()
                .flat_map(|&j| [solid.edges[j].left, solid.edges[j].right])
                .collect();
            f.sort_unstable();
            f.dedup();
            f
        };
        let q: Vec<DVec3> = faces_at
            .iter()
            .map(|&f| corner_at(f, v).map(Corner::first))
            .collect::<Result<_, _>>()?;
        let normals: Vec<DVec3> = faces_at.iter().map(|&f| solid.faces[f].normal).collect();
        match feature {
            EdgeFeature::Chamfer { .. } if b.mixed_corner(v).is_some() => {
                let Some((pivot, shared)) = b.mixed_corner(v) else {
                    continue;
                };
                let Corner::Cut { from, to, .. } = corner_at(shared, v)? else {
                    return Err(construction(WHAT, "a mixed chamfer corner lost its cut"));
                };
                let (from, to) = (*from, *to);
                // Each end's edge (the one whose square end it is), and where the pivot's
                // strip meets that edge's other face.
                let through = |p: DVec3| -> Result<DVec3, GeometryError> {
                    let mut ends = Vec::new();
                    for &k in &at_v {
                        if k != pivot {
                            ends.push((b.square_end(k, shared, pivot, v)?.distance(p), k));
                        }
                    }
                    let (_, k) = ends
                        .into_iter()
                        .min_by(|x, y| x.0.total_cmp(&y.0))
                        .ok_or_else(|| construction(WHAT, "a corner lost its edges"))?;
                    Ok(corner_at(b.other_face(k, shared), v)?.first())
                };
                let (c_from, c_to) = (through(from)?, through(to)?);
                // Flat where the four corners lie in a plane; else, as OpenCASCADE fills
                // the four straight sides, the bilinear patch through them.
                let normal = (c_from - from).cross(to - from);
                let flat = (c_to - from).dot(normal.normalize_or_zero()).abs() <= tolerance;
                let patch = if flat {
                    planar_face(&[
                        line(from, c_from)?,
                        line(c_from, c_to)?,
                        line(c_to, to)?,
                        line(to, from)?,
                    ])
                    .map_err(|e| {
                        construction(
                            WHAT,
                            format!(
                                "the chamfers at {} do not close with a flat patch ({e})",
                                point(solid.vertices[v])
                            ),
                        )
                    })?
                } else {
                    TrimmedSurface::untrimmed(bilinear(from, c_from, to, c_to)?)
                };
                let n = normals[0] + normals[1] + normals[2];
                out.push(facing(patch, |_| n)?);
            }
            EdgeFeature::Chamfer { .. } => {
                let patch =
                    planar_face(&[line(q[0], q[1])?, line(q[1], q[2])?, line(q[2], q[0])?])?;
                let n = normals[0] + normals[1] + normals[2];
                out.push(facing(patch, |_| n)?);
            }
            EdgeFeature::Fillet { .. } if b.mixed_corner(v).is_some() => {
                let Some((odd, shared)) = b.mixed_corner(v) else {
                    continue;
                };
                let Corner::Cut { from, to, .. } = corner_at(shared, v)? else {
                    return Err(construction(WHAT, "a mixed fillet corner lost its cut"));
                };
                // The like fillet ending at `from`: its end section revolved about the odd
                // fillet's axis to the other's.
                let like = at_v
                    .iter()
                    .copied()
                    .filter(|&k| k != odd)
                    .min_by(|&i, &j| {
                        b.bound(i, shared)
                            .distance(*from)
                            .total_cmp(&b.bound(j, shared).distance(*from))
                    })
                    .ok_or_else(|| construction(WHAT, "a corner lost its edges"))?;
                let section = b.section(like, b.end_plane(like, v)?)?;
                let foot = b.odd_axis_foot(odd, shared)?;
                let (x, y) = (*from - foot, *to - foot);
                let torus = revolve(&section, foot, x.cross(y), x.angle_between(y))?;
                // The ball centres' circle: over the face's arc, r off the face.
                let side = b.rounds[&like].side;
                let axis = b.rounds[&odd].t;
                let lift = b.plane(shared).normal * (side * b.rounds[&like].radius);
                let ring = x.length();
                out.push(facing(TrimmedSurface::untrimmed(torus), |p| {
                    let radial = (p - foot).reject_from_normalized(axis).normalize_or_zero();
                    (p - (foot + lift + radial * ring)) * -side
                })?);
            }
            EdgeFeature::Fillet { .. } => {
                let (side, radius) = (b.rounds[&at_v[0]].side, b.rounds[&at_v[0]].radius);
                let centre = (0..3)
                    .map(|i| q[i] + normals[i] * (side * radius))
                    .sum::<DVec3>()
                    / 3.0;
                let dirs = [normals[0] * -side, normals[1] * -side, normals[2] * -side];
                let ball = corner_ball(centre, radius, dirs)?;
                out.push(facing(ball, |p| (p - centre) * -side)?);
            }
        }
    }
    out.extend(wall_faces);
    closed_result(out, tolerance * 10.0, picked.len() + rims.len(), what)
}

/// The angle that carries parameter t of `curve` to `target` (radians, by `angle_of`, which
/// grows with t), by bisection: the parameter of a point on a circular arc.
fn arc_parameter(curve: &SpaceCurve, angle_of: impl Fn(DVec3) -> f64, target: f64) -> f64 {
    let (mut lo, mut hi) = curve.domain();
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        match curve.point_at(mid) {
            Ok(p) if angle_of(p) < target => lo = mid,
            _ => hi = mid,
        }
    }
    0.5 * (lo + hi)
}

/// The spherical triangle of the ball of radius `radius` around `centre` between the unit
/// directions `dirs`: the ball revolved about one of them (the pole, the one most nearly at
/// right angles to the others) from the meridian through the second to the one through the
/// third, so two sides are meridians (lines of the domain) and the third, the great arc
/// between the second and the third, is a trim curve through 49 of its points in (u, v)
/// (each found on the revolution's and the meridian's arcs by bisection). Where the pole is
/// at right angles to both others, the great arc is the equator and the patch is the whole
/// surface (exact).
fn corner_ball(
    centre: DVec3,
    radius: f64,
    dirs: [DVec3; 3],
) -> Result<TrimmedSurface, GeometryError> {
    let off = |j: usize| {
        (0..3)
            .filter(|&k| k != j)
            .map(|k| dirs[j].dot(dirs[k]).abs())
            .fold(0.0, f64::max)
    };
    let pole = (0..3)
        .min_by(|&i, &j| off(i).total_cmp(&off(j)))
        .unwrap_or(0);
    let (p, a, b) = (dirs[pole], dirs[(pole + 1) % 3], dirs[(pole + 2) % 3]);
    let axis = if p.cross(a).dot(b) > 0.0 { p } else { -p };
    let flat = |d: DVec3| (d - p * d.dot(p)).normalize_or_zero();
    let (a_flat, b_flat) = (flat(a), flat(b));
    if a_flat == DVec3::ZERO || b_flat == DVec3::ZERO {
        return Err(construction(WHAT, "a corner's faces meet along a line"));
    }
    let sweep = a_flat.angle_between(b_flat);
    let polar = |d: DVec3| d.cross(p).length().atan2(d.dot(p));
    const SAMPLES: usize = 48;
    let great: Vec<DVec3> = (0..=SAMPLES)
        .map(|i| {
            let t = i as f64 / SAMPLES as f64;
            let angle = a.angle_between(b);
            let w = b - a * a.dot(b);
            let w = w.normalize_or_zero();
            a * (angle * t).cos() + w * (angle * t).sin()
        })
        .collect();
    let square = off(pole) < 1e-9;
    let reach = if square {
        FRAC_PI_2
    } else {
        great.iter().map(|&d| polar(d)).fold(0.0, f64::max) * (1.0 + 1e-9)
    };
    let profile = arc(centre, p, a_flat, radius, 0.0, reach)?;
    let surface = revolve(&profile, centre, axis, sweep)?;
    if square {
        return Ok(TrimmedSurface::untrimmed(surface));
    }
    // (u, v) of a direction: u on the revolution's unit arc by its longitude from a, v on the
    // meridian by its polar angle.
    let around = arc(DVec3::ZERO, DVec3::X, DVec3::Y, 1.0, 0.0, sweep)?;
    let longitude = |q: DVec3| q.y.atan2(q.x).rem_euclid(std::f64::consts::TAU);
    let y_axis = axis.cross(a_flat);
    let down = |q: DVec3| polar((q - centre) / radius);
    let uv = |d: DVec3| {
        let lon = (d.dot(y_axis))
            .atan2(d.dot(a_flat))
            .rem_euclid(std::f64::consts::TAU);
        let lon = if lon > sweep + 1e-9 { 0.0 } else { lon };
        DVec2::new(
            arc_parameter(&around, longitude, lon),
            arc_parameter(&profile, down, polar(d)),
        )
    };
    let points: Vec<DVec2> = great.iter().map(|&d| uv(d)).collect();
    let (first, last) = (points[0], points[SAMPLES]);
    let side = crate::splines::interpolate_through(
        &points,
        3,
        crate::splines::Parametrization::ChordLength,
        None,
    )?;
    let trim = vec![
        line(DVec2::new(0.0, 0.0), DVec2::new(0.0, first.y))?,
        side,
        line(DVec2::new(1.0, last.y), DVec2::new(1.0, 0.0))?,
        line(DVec2::new(1.0, 0.0), DVec2::new(0.0, 0.0))?,
    ];
    TrimmedSurface::new(surface, vec![trim])
}

impl Builder<'_> {
    /// The plane edge `k`'s fillet ends on at vertex `v` (see the module documentation).
    fn end_plane(&self, k: usize, v: usize) -> Result<Plane, GeometryError> {
        let solid = self.solid;
        let e = solid.edges[k];
        let r = self.rounds[&k];
        let others: Vec<usize> = solid.edges_at(v).into_iter().filter(|&j| j != k).collect();
        let (Some(&k_left), Some(&k_right)) = (
            others
                .iter()
                .find(|&&j| solid.edges[j].left == e.left || solid.edges[j].right == e.left),
            others
                .iter()
                .find(|&&j| solid.edges[j].left == e.right || solid.edges[j].right == e.right),
        ) else {
            return Err(construction(WHAT, "a corner's edges do not meet its faces"));
        };
        if let Some((odd, shared)) = self.mixed_corner(v) {
            // The odd fillet ends where the like fillets' ball centres run; the like ones
            // square to their edges through the odd one's axis.
            let radius = r.radius;
            if k == odd {
                let like = self.rounds[&k_left].side;
                let p = self.plane(shared);
                return Ok(Plane {
                    offset: p.offset + like * radius,
                    ..p
                });
            }
            let foot = self.odd_axis_foot(odd, shared)?;
            return Ok(Plane {
                normal: r.t,
                offset: r.t.dot(foot),
            });
        }
        let h = self.other_face(k_left, e.left);
        let picked: Vec<usize> = [k_left, k_right]
            .into_iter()
            .filter(|j| self.rounds.contains_key(j))
            .collect();
        if picked.is_empty() {
            return Ok(self.plane(h));
        }
        if picked.iter().any(|j| self.rounds[j].side != r.side) {
            return Err(construction(
                WHAT,
                format!(
                    "the corner at {} joins a convex and a concave filleted edge; that vertex \
                     blend is not built yet",
                    point(solid.vertices[v])
                ),
            ));
        }
        // The corner ball's centre: on this fillet's axis, r from face h on the ball's side.
        let (_, centre) = self.arc(k)?;
        let radius = r.radius;
        let hp = self.plane(h);
        let centre = pierce(
            Line {
                origin: centre,
                direction: r.t,
            },
            Plane {
                normal: hp.normal,
                offset: hp.offset + r.side * radius,
            },
        )
        .ok_or_else(|| construction(WHAT, "a fillet runs parallel to the face it ends on"))?;
        let toward = |j: usize| {
            let d = solid.direction(j);
            if solid.edges[j].b == v { d } else { -d }
        };
        let normal = if picked.len() == 2 {
            toward(k)
        } else {
            toward(k) - toward(picked[0])
        };
        let normal = normal.normalize();
        Ok(Plane {
            normal,
            offset: normal.dot(centre),
        })
    }

    /// The refusal of a fillet whose end sections cross on edge `k`.
    fn too_large(&self, k: usize) -> GeometryError {
        let e = self.solid.edges[k];
        construction(
            WHAT,
            format!(
                "the fillet is too large for the edge from {} to {}",
                point(self.solid.vertices[e.a]),
                point(self.solid.vertices[e.b])
            ),
        )
    }

    /// Edge `k`'s fillet: the cylinder of its arc along the edge, over the stretch between
    /// its end planes, trimmed by their conics where they are not square to the edge.
    fn fillet_face(&self, k: usize, ends: [Plane; 2]) -> Result<TrimmedSurface, GeometryError> {
        if self.rounds[&k].varies() {
            return self.varying_fillet_face(k, ends);
        }
        let t = self.rounds[&k].t;
        let (arc, at_a) = self.lambdas(k, ends[0])?;
        let (_, at_b) = self.lambdas(k, ends[1])?;
        let low = at_a.iter().copied().fold(f64::INFINITY, f64::min);
        let high = at_b.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let length = high - low;
        if !(length > self.tolerance) || at_a.iter().zip(&at_b).any(|(a, b)| a >= b) {
            return Err(self.too_large(k));
        }
        let start = arc.map_points(|p| p + t * low)?;
        let surface = extrude(&start, t * length)?;
        let flat = |l: &[f64]| {
            let (lo, hi) = l
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &x| {
                    (lo.min(x), hi.max(x))
                });
            hi - lo <= 1e-12 * length.max(1.0)
        };
        if flat(&at_a) && flat(&at_b) {
            return Ok(TrimmedSurface::untrimmed(surface));
        }
        let to_v = |l: &[f64]| l.iter().map(|x| (x - low) / length).collect::<Vec<f64>>();
        let (va, vb) = (to_v(&at_a), to_v(&at_b));
        let weights: Vec<f64> = (0..arc.count()).map(|i| arc.weight(i)).collect();
        end_trimmed(surface, arc.knots(), [(&weights, &va), (&weights, &vb)])
    }

    /// A fillet of varying radius (see [`Builder::cone_scales`]): the ruled surface between
    /// the arc at a scaled about the apex to the least and the greatest scale its end planes
    /// cut, v running along the edge, trimmed by the end sections. On that surface the point
    /// O + σ(v)(C(u) − O) with σ(v) = σ₀ + v(σ₁ − σ₀) lies on a plane where
    /// v(u) = Σ (wᵢ/μᵢ) Nᵢ(u) yᵢ / Σ (wᵢ/μᵢ) Nᵢ(u) with yᵢ = (μᵢ − σ₀)/(σ₁ − σ₀): the trim curve
    /// of [`graph_curve`] over the section's weights.
    fn varying_fillet_face(
        &self,
        k: usize,
        ends: [Plane; 2],
    ) -> Result<TrimmedSurface, GeometryError> {
        let (arc, apex, at_a) = self.cone_scales(k, ends[0])?;
        let (_, _, at_b) = self.cone_scales(k, ends[1])?;
        let growing = self.rounds[&k].grow > 1.0;
        let (low, high) = if growing {
            (
                at_a.iter().copied().fold(f64::INFINITY, f64::min),
                at_b.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            )
        } else {
            (
                at_a.iter().copied().fold(f64::NEG_INFINITY, f64::max),
                at_b.iter().copied().fold(f64::INFINITY, f64::min),
            )
        };
        let span = high - low;
        let to_v = |m: &[f64]| m.iter().map(|x| (x - low) / span).collect::<Vec<f64>>();
        let (va, vb) = (to_v(&at_a), to_v(&at_b));
        if !(span.abs() > 1e-12) || va.iter().zip(&vb).any(|(a, b)| a >= b) {
            return Err(self.too_large(k));
        }
        let scaled = |m: f64| arc.map_points(|p| apex + (p - apex) * m);
        let surface = ruled(&scaled(low)?, &scaled(high)?)?;
        let square = |v: &[f64], end: f64| v.iter().all(|x| (x - end).abs() <= 1e-12);
        if square(&va, 0.0) && square(&vb, 1.0) {
            return Ok(TrimmedSurface::untrimmed(surface));
        }
        let weights_at =
            |m: &[f64]| -> Vec<f64> { (0..arc.count()).map(|i| arc.weight(i) / m[i]).collect() };
        end_trimmed(
            surface,
            arc.knots(),
            [(&weights_at(&at_a), &va), (&weights_at(&at_b), &vb)],
        )
    }
}

/// A fillet surface (u across the arc over `knots`, v along the edge in [0, 1]) trimmed
/// between its end sections, each given by its weights and v values ([`graph_curve`]).
fn end_trimmed(
    surface: crate::surface::NurbsSurface,
    knots: &[f64],
    [(wa, va), (wb, vb)]: [(&[f64], &[f64]); 2],
) -> Result<TrimmedSurface, GeometryError> {
    let bottom = graph_curve(knots, wa, va)?;
    let top = graph_curve(knots, wb, vb)?;
    let last = va.len() - 1;
    let trim = vec![
        bottom,
        line(DVec2::new(1.0, va[last]), DVec2::new(1.0, vb[last]))?,
        top.reverse(),
        line(DVec2::new(0.0, vb[0]), DVec2::new(0.0, va[0]))?,
    ];
    TrimmedSurface::new(surface, vec![trim])
}
