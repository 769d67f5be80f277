//! Every edge of a right prism filleted at once (a polygon, convex or not, with holes or not,
//! extruded square to its caps): the ball rolls along each cap's rim after the upright edges
//! are rounded, so where a concave upright edge meets a convex rim (an L-shaped block's inner
//! corner) the rim's fillet runs on round the concave fillet's top instead of needing a
//! vertex blend:
//!
//! - the profile's corners are rounded in the plane (convex and concave arcs of radius r);
//!   its walls are that profile extruded between r and h − r (planes and cylinders);
//! - each cap is the profile moved in by r (each line by r, each convex arc to its centre,
//!   each concave arc to radius 2r about its centre);
//! - each rim's fillet is the quarter circle swept along the rounded profile: a cylinder along
//!   a line, a ball's eighth about a convex corner, a torus about a concave one (the ball's
//!   centre on the circle of radius 2r), all exact and tangent where they meet.
//!
//! The volume is then A(h − 2r) + 2 (A′ r + P′ πr²/4 + 2πr³/3), A the rounded profile's
//! area and A′, P′ the moved-in cap's area and perimeter (Steiner's formula for the sections
//! of a rim, each the cap grown by √(r² − s²)); the tests check it.

use std::f64::consts::FRAC_PI_2;

use glam::{DVec2, DVec3};

use crate::construct::{arc, extrude, line, revolve};
use crate::curve::SpaceCurve;
use crate::error::{GeometryError, construction};
use crate::planar::planar_face;
use crate::trim::TrimmedSurface;

use super::polyhedron::Polyhedron;
use super::{WHAT, facing, point};

/// A right prism: the frame of its bottom cap (origin, axes in the plane, up), its height
/// and its profile's loops in the bottom plane (the material on each loop's left).
struct Prism {
    origin: DVec3,
    e1: DVec3,
    e2: DVec3,
    up: DVec3,
    height: f64,
    loops: Vec<Vec<DVec2>>,
}

impl Prism {
    fn at(&self, q: DVec2, z: f64) -> DVec3 {
        self.origin + self.e1 * q.x + self.e2 * q.y + self.up * z
    }

    fn vector(&self, q: DVec2) -> DVec3 {
        self.e1 * q.x + self.e2 * q.y
    }
}

/// `solid` as a right prism: two faces with opposite normals, every other face square to
/// them; None where it is not one.
fn prism_of(solid: &Polyhedron) -> Option<Prism> {
    let faces = &solid.faces;
    if !solid.kept.is_empty() || faces.iter().any(|f| !f.kept.is_empty()) {
        return None;
    }
    let bottom = (0..faces.len()).find(|&f| {
        let n = faces[f].normal;
        let parallel = faces
            .iter()
            .filter(|g| g.normal.dot(n).abs() > 1.0 - 1e-9)
            .count();
        let square = faces
            .iter()
            .filter(|g| g.normal.dot(n).abs() < 1e-9)
            .count();
        parallel == 2 && square == faces.len() - 2
    })?;
    let up = -faces[bottom].normal;
    let top = (0..faces.len()).find(|&f| faces[f].normal.dot(up) > 1.0 - 1e-9)?;
    let height = faces[top].offset + faces[bottom].offset;
    let origin = solid.vertices[faces[bottom].loops.first()?.first().copied()?];
    let e1 = up.any_orthonormal_vector();
    let e2 = up.cross(e1);
    // The bottom's loops run counter-clockwise about its outward normal (down): reversed,
    // they have the material on their left seen from above.
    let loops = faces[bottom]
        .loops
        .iter()
        .map(|ring| {
            ring.iter()
                .rev()
                .map(|&v| {
                    let d = solid.vertices[v] - origin;
                    DVec2::new(d.dot(e1), d.dot(e2))
                })
                .collect()
        })
        .collect();
    Some(Prism {
        origin,
        e1,
        e2,
        up,
        height,
        loops,
    })
}

/// One piece of a rounded profile: a line, or an arc of radius r about `centre` (convex:
/// turning left, the material inside).
#[derive(Debug, Clone, Copy)]
enum Piece {
    Line(DVec2, DVec2),
    Arc {
        from: DVec2,
        to: DVec2,
        centre: DVec2,
        convex: bool,
    },
}

fn left(d: DVec2) -> DVec2 {
    DVec2::new(-d.y, d.x)
}

/// The loop's corners rounded at radius r: its pieces in order; refused where two roundings
/// overlap on an edge.
fn rounded(ring: &[DVec2], r: f64, prism: &Prism) -> Result<Vec<Piece>, GeometryError> {
    let n = ring.len();
    let dir = |i: usize| (ring[(i + 1) % n] - ring[i]).normalize();
    let mut corners = Vec::with_capacity(n);
    for (i, &corner) in ring.iter().enumerate() {
        let (d0, d1) = (dir((i + n - 1) % n), dir(i));
        let turn = d0.perp_dot(d1);
        let psi = (-d0).dot(d1).clamp(-1.0, 1.0).acos();
        if turn.abs() < 1e-12 {
            return Err(construction(
                WHAT,
                "a cap's boundary runs straight on at a corner",
            ));
        }
        let c = r / (0.5 * psi).tan();
        let (p1, p2) = (corner - d0 * c, corner + d1 * c);
        let convex = turn > 0.0;
        let centre = if convex {
            p1 + left(d0) * r
        } else {
            p1 - left(d0) * r
        };
        corners.push((p1, p2, centre, convex));
    }
    let mut pieces = Vec::with_capacity(2 * n);
    for i in 0..n {
        let (p1, p2, centre, convex) = corners[i];
        pieces.push(Piece::Arc {
            from: p1,
            to: p2,
            centre,
            convex,
        });
        let next = corners[(i + 1) % n].0;
        if (next - p2).dot(dir(i)) <= 1e-9 * (ring[(i + 1) % n] - ring[i]).length() {
            return Err(construction(
                WHAT,
                format!(
                    "the fillet is too large for the edge from {} to {}: the roundings at its \
                     ends overlap",
                    point(prism.at(ring[i], 0.0)),
                    point(prism.at(ring[(i + 1) % n], 0.0))
                ),
            ));
        }
        pieces.push(Piece::Line(p2, next));
    }
    Ok(pieces)
}

/// The arc about `centre` (3D) from `from` to `to` (on a circle about it, in a plane across
/// `up`), turning about `up` (left) or against it.
fn arc_about(
    centre: DVec3,
    from: DVec3,
    to: DVec3,
    up: DVec3,
    counter: bool,
) -> Result<SpaceCurve, GeometryError> {
    let (a, b) = (from - centre, to - centre);
    let radius = a.length();
    let axis = if counter { up } else { -up };
    let x = a / radius;
    let y = axis.cross(x);
    let sweep = b.dot(y).atan2(b.dot(x)).rem_euclid(std::f64::consts::TAU);
    arc(centre, x, y, radius, 0.0, sweep)
}

/// Every edge of the right prism `solid` filleted at radius `r` (see the module
/// documentation); None where `solid` is not a right prism.
pub(crate) fn fillet_prism(
    solid: &Polyhedron,
    r: f64,
) -> Option<Result<Vec<TrimmedSurface>, GeometryError>> {
    let prism = prism_of(solid)?;
    Some(build(&prism, r))
}

fn build(prism: &Prism, r: f64) -> Result<Vec<TrimmedSurface>, GeometryError> {
    let h = prism.height;
    if !(2.0 * r < h) {
        return Err(construction(
            WHAT,
            format!("the radius {r} is too large for the body's height {h}"),
        ));
    }
    let up = prism.up;
    let mut out = Vec::new();
    let mut caps: [Vec<SpaceCurve>; 2] = [Vec::new(), Vec::new()];
    for ring in &prism.loops {
        for piece in rounded(ring, r, prism)? {
            match piece {
                Piece::Line(a, b) => {
                    let d = (b - a).normalize();
                    let m = left(d);
                    let inner = |q: DVec2| q + m * r;
                    let out_dir = -prism.vector(m);
                    // The wall.
                    let wall = planar_face(&[
                        line(prism.at(a, r), prism.at(b, r))?,
                        line(prism.at(b, r), prism.at(b, h - r))?,
                        line(prism.at(b, h - r), prism.at(a, h - r))?,
                        line(prism.at(a, h - r), prism.at(a, r))?,
                    ])?;
                    out.push(facing(wall, |_| out_dir)?);
                    // The caps' edges, and the rims: a quarter cylinder each.
                    for (level, z, sign) in [(0, 0.0, -1.0), (1, h, 1.0)] {
                        caps[level].push(line(prism.at(inner(a), z), prism.at(inner(b), z))?);
                        let centre = prism.at(inner(a), z - sign * r);
                        let quarter = arc(centre, out_dir, up * sign, r, 0.0, FRAC_PI_2)?;
                        let rim = extrude(&quarter, prism.vector(b - a))?;
                        let axis_point = centre;
                        let along = prism.vector(d);
                        out.push(facing(TrimmedSurface::untrimmed(rim), |p| {
                            let q = p - axis_point;
                            q - along * q.dot(along)
                        })?);
                    }
                }
                Piece::Arc {
                    from,
                    to,
                    centre,
                    convex,
                } => {
                    // The wall: the arc extruded.
                    let base = arc_about(
                        prism.at(centre, r),
                        prism.at(from, r),
                        prism.at(to, r),
                        up,
                        convex,
                    )?;
                    let wall = extrude(&base, up * (h - 2.0 * r))?;
                    let c3 = prism.at(centre, 0.0);
                    let radial = move |p: DVec3| {
                        let q = p - c3;
                        q - up * q.dot(up)
                    };
                    out.push(facing(TrimmedSurface::untrimmed(wall), |p| {
                        if convex { radial(p) } else { -radial(p) }
                    })?);
                    let u = (from - centre).normalize();
                    for (level, z, sign) in [(0, 0.0, -1.0), (1, h, 1.0)] {
                        let axis = if convex { up } else { -up };
                        let sweep = {
                            let (a, b) = (from - centre, to - centre);
                            a.normalize().dot(b.normalize()).clamp(-1.0, 1.0).acos()
                        };
                        if convex {
                            // A ball's part about the corner's centre.
                            let ball = prism.at(centre, z - sign * r);
                            let meridian =
                                arc(ball, prism.vector(u), up * sign, r, 0.0, FRAC_PI_2)?;
                            let patch = revolve(&meridian, ball, axis, sweep)?;
                            out.push(facing(TrimmedSurface::untrimmed(patch), |p| p - ball)?);
                        } else {
                            // A torus: the ball's centre on the circle of radius 2r.
                            let ring_point = prism.at(centre + u * (2.0 * r), z - sign * r);
                            let meridian =
                                arc(ring_point, -prism.vector(u), up * sign, r, 0.0, FRAC_PI_2)?;
                            let patch =
                                revolve(&meridian, prism.at(centre, z - sign * r), axis, sweep)?;
                            let hub = prism.at(centre, z - sign * r);
                            out.push(facing(TrimmedSurface::untrimmed(patch), |p| {
                                let q = p - hub;
                                let flat = (q - up * q.dot(up)).normalize_or_zero();
                                p - (hub + flat * (2.0 * r))
                            })?);
                            // The cap's edge: the arc of radius 2r.
                            let (a, b) = (
                                centre + u * (2.0 * r),
                                centre + (to - centre).normalize() * (2.0 * r),
                            );
                            caps[level].push(arc_about(
                                prism.at(centre, z),
                                prism.at(a, z),
                                prism.at(b, z),
                                up,
                                false,
                            )?);
                        }
                    }
                }
            }
        }
    }
    for (level, sign) in [(0, -1.0), (1, 1.0)] {
        let cap = planar_face(&caps[level])?;
        out.push(facing(cap, |_| up * sign)?);
    }
    Ok(out)
}
