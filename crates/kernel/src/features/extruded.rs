//! Right prisms (an outline of lines and circular arcs, convex or not, with holes or not,
//! extruded square to its caps) filleted along their caps' rims. An outline whose pieces meet
//! tangentially (a rounded rectangle, a slot, a disc with flats, a round hole) has no upright
//! edges: each cap's loop is one tangent chain, picked whole by any of its edges, and its
//! fillet is the quarter circle swept along it (a cylinder along a line, a torus about an arc:
//! the ball's centre on the arc moved in by r), or its chamfer the chord swept (a plane, a
//! cone). An outline with sharp corners (a polygon, or lines and arcs meeting at an angle)
//! has every edge filleted at once: the ball rolls along each cap's rim after the upright
//! edges are rounded (at a corner the circle of radius r tangent to both pieces, its centre
//! where their offsets meet), so where a concave upright edge meets a convex rim (an L-shaped block's inner
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

use std::f64::consts::{FRAC_PI_2, TAU};

use glam::{DVec2, DVec3};

use crate::boolean::outward_faces;
use crate::construct::{arc, extrude, line, revolve};
use crate::curve::SpaceCurve;
use crate::error::{GeometryError, construction};
use crate::join::face_loops;
use crate::mass::signed_volume;
use crate::planar::planar_face;
use crate::trim::TrimmedSurface;

use super::polyhedron::{Polyhedron, in_space};
use super::revolved::revolution_axis;
use super::{EdgeFeature, EdgePick, FeatureResult, WHAT, closed_result, facing, point};

/// One piece of a prism's outline in its bottom plane: a line, or the arc of `radius` about
/// `centre` turning by `sweep` (counter-clockwise seen from above where positive).
#[derive(Debug, Clone, Copy, PartialEq)]
enum Piece {
    Line(DVec2, DVec2),
    Arc {
        from: DVec2,
        centre: DVec2,
        radius: f64,
        sweep: f64,
    },
}

impl Piece {
    fn start(&self) -> DVec2 {
        match *self {
            Piece::Line(a, _) => a,
            Piece::Arc { from, .. } => from,
        }
    }

    fn end(&self) -> DVec2 {
        match *self {
            Piece::Line(_, b) => b,
            Piece::Arc {
                from,
                centre,
                sweep,
                ..
            } => centre + DVec2::from_angle(sweep).rotate(from - centre),
        }
    }

    /// The unit direction of travel at the start (`at_end` false) or the end.
    fn tangent(&self, at_end: bool) -> DVec2 {
        match *self {
            Piece::Line(a, b) => (b - a).normalize(),
            Piece::Arc { centre, sweep, .. } => {
                let p = if at_end { self.end() } else { self.start() };
                left(p - centre).normalize() * sweep.signum()
            }
        }
    }

    fn reversed(self) -> Self {
        match self {
            Piece::Line(a, b) => Piece::Line(b, a),
            Piece::Arc {
                centre,
                radius,
                sweep,
                ..
            } => Piece::Arc {
                from: self.end(),
                centre,
                radius,
                sweep: -sweep,
            },
        }
    }

    /// The signed area the piece sweeps about the origin, ½∮(x dy − y dx) (exact for an arc:
    /// ½[R²θ + R cₓ (sin φ₁ − sin φ₀) − R c_y (cos φ₁ − cos φ₀)]).
    fn area(&self) -> f64 {
        match *self {
            Piece::Line(a, b) => 0.5 * a.perp_dot(b),
            Piece::Arc {
                from,
                centre,
                radius,
                sweep,
            } => {
                let f0 = (from - centre).to_angle();
                let f1 = f0 + sweep;
                0.5 * (radius * radius * sweep + radius * centre.x * (f1.sin() - f0.sin())
                    - radius * centre.y * (f1.cos() - f0.cos()))
            }
        }
    }

    /// The distance from `q` to the piece.
    fn distance(&self, q: DVec2) -> f64 {
        match *self {
            Piece::Line(a, b) => {
                let d = b - a;
                let t =
                    ((q - a).dot(d) / d.length_squared().max(f64::MIN_POSITIVE)).clamp(0.0, 1.0);
                q.distance(a + d * t)
            }
            Piece::Arc {
                from,
                centre,
                radius,
                sweep,
            } => {
                let angle = DVec2::from_angle(-(from - centre).to_angle())
                    .rotate(q - centre)
                    .to_angle();
                let within = if sweep >= 0.0 {
                    angle.rem_euclid(TAU) <= sweep
                } else {
                    (-angle).rem_euclid(TAU) <= -sweep
                };
                if within {
                    (q.distance(centre) - radius).abs()
                } else {
                    q.distance(self.start()).min(q.distance(self.end()))
                }
            }
        }
    }
}

/// A right prism: the frame of its bottom cap (origin, axes in the plane, up), its height
/// and its outline's loops in the bottom plane (the material on each loop's left).
struct Prism {
    origin: DVec3,
    e1: DVec3,
    e2: DVec3,
    up: DVec3,
    height: f64,
    loops: Vec<Vec<Piece>>,
}

impl Prism {
    fn at(&self, q: DVec2, z: f64) -> DVec3 {
        self.origin + self.e1 * q.x + self.e2 * q.y + self.up * z
    }

    fn vector(&self, q: DVec2) -> DVec3 {
        self.e1 * q.x + self.e2 * q.y
    }

    fn flat(&self, p: DVec3) -> (DVec2, f64) {
        let d = p - self.origin;
        (DVec2::new(d.dot(self.e1), d.dot(self.e2)), d.dot(self.up))
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
            let ring: Vec<DVec2> = ring
                .iter()
                .rev()
                .map(|&v| {
                    let d = solid.vertices[v] - origin;
                    DVec2::new(d.dot(e1), d.dot(e2))
                })
                .collect();
            (0..ring.len())
                .map(|i| Piece::Line(ring[i], ring[(i + 1) % ring.len()]))
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

/// The closed shell `faces` as a right prism whose upright faces are planes and cylinders
/// (an outline of lines and arcs), or None where it is not one: two flat caps with opposite
/// normals, every other face a plane or a cylinder square to them, and the volume the
/// outline's area times the height.
fn curved_prism_of(faces: &[TrimmedSurface], tolerance: f64) -> Option<Prism> {
    let (faces, _) = outward_faces(faces, tolerance, "the solid").ok()?;
    let planes: Vec<Option<DVec3>> = faces
        .iter()
        .map(|f| {
            let s = f.surface();
            s.plane(tolerance)?;
            let [(u0, u1), (v0, v1)] = s.domain();
            s.normal(0.5 * (u0 + u1), 0.5 * (v0 + v1)).ok()
        })
        .collect();
    let upright = |k: usize, up: DVec3| match planes[k] {
        Some(n) => n.dot(up).abs() < 1e-9,
        None => revolution_axis(faces[k].surface(), tolerance)
            .is_some_and(|(_, axis)| axis.cross(up).length() < 1e-7),
    };
    let bottom = (0..faces.len()).find(|&f| {
        planes[f].is_some_and(|n| {
            (0..faces.len()).all(|g| {
                g == f || upright(g, n) || planes[g].is_some_and(|m| m.dot(n) < -1.0 + 1e-9)
            }) && (0..faces.len())
                .filter(|&g| planes[g].is_some_and(|m| m.dot(n) < -1.0 + 1e-9))
                .count()
                == 1
        })
    })?;
    let up = -planes[bottom]?;
    let top = (0..faces.len()).find(|&g| planes[g].is_some_and(|m| m.dot(up) > 1.0 - 1e-9))?;
    let surface = faces[bottom].surface();
    let origin = surface
        .point_at(surface.domain()[0].0, surface.domain()[1].0)
        .ok()?;
    let e1 = up.any_orthonormal_vector();
    let e2 = up.cross(e1);
    let top_surface = faces[top].surface();
    let height = (top_surface
        .point_at(top_surface.domain()[0].0, top_surface.domain()[1].0)
        .ok()?
        - origin)
        .dot(up);
    let mut prism = Prism {
        origin,
        e1,
        e2,
        up,
        height,
        loops: Vec::new(),
    };
    for trim_loop in face_loops(&faces[bottom]).ok()? {
        let curves = in_space(surface, &trim_loop, tolerance)?.ok()?;
        let mut pieces: Vec<Piece> = Vec::new();
        for curve in &curves {
            let piece = piece_of(&prism, curve, tolerance)?;
            // Pieces of one line or one circle, split by the file, are one.
            match pieces
                .last()
                .and_then(|&last| merged(last, piece, tolerance))
            {
                Some(m) => *pieces.last_mut()? = m,
                None => pieces.push(piece),
            }
        }
        // The last piece may continue the first.
        if pieces.len() > 1
            && let Some(j) = merged(pieces[pieces.len() - 1], pieces[0], tolerance)
        {
            pieces.pop();
            pieces[0] = j;
        }
        prism.loops.push(pieces);
    }
    // The outer loop counter-clockwise seen from above, the holes clockwise.
    let areas: Vec<f64> = prism
        .loops
        .iter()
        .map(|l| l.iter().map(Piece::area).sum())
        .collect();
    let outer = (0..areas.len()).max_by(|&i, &j| areas[i].abs().total_cmp(&areas[j].abs()))?;
    for (k, l) in prism.loops.iter_mut().enumerate() {
        if (areas[k] > 0.0) != (k == outer) {
            *l = l.iter().rev().map(|p| p.reversed()).collect();
        }
    }
    let area: f64 = prism.loops.iter().flatten().map(Piece::area).sum();
    let volume = signed_volume(&faces).ok()?;
    ((volume - area * height).abs() <= 1e-6 * volume.abs()).then_some(prism)
}

/// `first` and `second` (which follows it) as one piece where they are parts of one line or
/// one circle turning the same way.
fn merged(first: Piece, second: Piece, tolerance: f64) -> Option<Piece> {
    match (first, second) {
        (Piece::Line(a, b), Piece::Line(_, c))
            if (c - a).perp_dot((b - a).normalize()).abs() <= tolerance =>
        {
            Some(Piece::Line(a, c))
        }
        (
            Piece::Arc {
                from,
                centre,
                radius,
                sweep,
            },
            Piece::Arc {
                centre: c2,
                radius: r2,
                sweep: s2,
                ..
            },
        ) if centre.distance(c2) <= tolerance
            && (radius - r2).abs() <= tolerance
            && sweep * s2 > 0.0 =>
        {
            Some(Piece::Arc {
                from,
                centre,
                radius,
                sweep: sweep + s2,
            })
        }
        _ => None,
    }
}

/// A curve in a prism's bottom plane as a piece of its outline: a line or a circular arc;
/// None where it is neither.
fn piece_of(prism: &Prism, curve: &SpaceCurve, tolerance: f64) -> Option<Piece> {
    let (t0, t1) = curve.domain();
    let points: Vec<DVec2> = (0..=16)
        .map(|i| {
            curve
                .point_at(t0 + (t1 - t0) * i as f64 / 16.0)
                .ok()
                .map(|p| prism.flat(p).0)
        })
        .collect::<Option<_>>()?;
    let (a, b) = (points[0], points[16]);
    let chord = b - a;
    if chord.length() > tolerance
        && points
            .iter()
            .all(|&p| (p - a).perp_dot(chord.normalize()).abs() <= tolerance)
    {
        return Some(Piece::Line(a, b));
    }
    // The circle through the first point, two inner ones (the ends may coincide).
    let (p, q) = (points[5], points[11]);
    let centre = {
        let (d1, d2) = (p - a, q - a);
        let det = 2.0 * d1.perp_dot(d2);
        if det.abs() < 1e-300 {
            return None;
        }
        a + DVec2::new(
            d2.y * d1.length_squared() - d1.y * d2.length_squared(),
            d1.x * d2.length_squared() - d2.x * d1.length_squared(),
        ) / det
    };
    let radius = a.distance(centre);
    if points
        .iter()
        .any(|&p| (p.distance(centre) - radius).abs() > tolerance)
    {
        return None;
    }
    let mut sweep = 0.0;
    for pair in points.windows(2) {
        sweep += (pair[0] - centre).angle_to(pair[1] - centre);
    }
    Some(Piece::Arc {
        from: a,
        centre,
        radius,
        sweep,
    })
}

fn left(d: DVec2) -> DVec2 {
    DVec2::new(-d.y, d.x)
}

/// The piece moved into the material by `distance` (below 0: out of it): a line along its
/// normal, an arc's radius shrunk (convex) or grown (concave) about its centre; None where an
/// arc shrinks to nothing.
fn offset_piece(piece: Piece, distance: f64) -> Option<Piece> {
    match piece {
        Piece::Line(a, b) => {
            let m = left((b - a).normalize()) * distance;
            Some(Piece::Line(a + m, b + m))
        }
        Piece::Arc {
            from,
            centre,
            radius,
            sweep,
        } => {
            let r = radius - sweep.signum() * distance;
            (r > 1e-9 * radius).then(|| Piece::Arc {
                from: centre + (from - centre) * (r / radius),
                centre,
                radius: r,
                sweep,
            })
        }
    }
}

/// Where the line or circle of `a` meets that of `b`, the meeting nearest `near`.
fn meet(a: Piece, b: Piece, near: DVec2) -> Option<DVec2> {
    let carrier = |piece: Piece| match piece {
        Piece::Line(p, q) => super::revolved::Piece::Line(p, (q - p).normalize()),
        Piece::Arc { centre, radius, .. } => super::revolved::Piece::Circle(centre, radius),
    };
    super::revolved::meet_pieces(carrier(a), carrier(b), near)
}

/// The point of the piece's line or circle nearest `p`.
fn foot(piece: Piece, p: DVec2) -> DVec2 {
    match piece {
        Piece::Line(a, b) => {
            let d = (b - a).normalize();
            a + d * (p - a).dot(d)
        }
        Piece::Arc { centre, radius, .. } => centre + (p - centre).normalize() * radius,
    }
}

/// The signed angle from `a` to `b` turning the way of `sweep` (in (0, 2π) or (−2π, 0)).
fn turning(a: DVec2, b: DVec2, sweep: f64) -> f64 {
    let s = a.angle_to(b);
    if sweep > 0.0 && s < 0.0 {
        s + TAU
    } else if sweep < 0.0 && s > 0.0 {
        s - TAU
    } else {
        s
    }
}

/// The piece running from `start` to `end` instead (both on its line or circle); the piece
/// itself where they are its own ends (a whole circle stays whole).
fn between(piece: Piece, start: DVec2, end: DVec2) -> Piece {
    if start == piece.start() && end == piece.end() {
        return piece;
    }
    match piece {
        Piece::Line(..) => Piece::Line(start, end),
        Piece::Arc {
            centre,
            radius,
            sweep,
            ..
        } => Piece::Arc {
            from: start,
            centre,
            radius,
            sweep: turning(start - centre, end - centre, sweep),
        },
    }
}

/// The loop's sharp corners rounded at radius r in the plane: at each, the circle of radius r
/// tangent to both pieces (its centre where their offsets by r meet, inside at a convex
/// corner and outside at a concave one), the pieces cut back to where it touches them;
/// tangent junctions kept. Refused where two roundings overlap on a piece or a rounding
/// does not fit.
fn rounded(ring: &[Piece], r: f64, prism: &Prism) -> Result<Vec<Piece>, GeometryError> {
    let n = ring.len();
    let mut ends: Vec<(DVec2, DVec2)> = ring.iter().map(|p| (p.start(), p.end())).collect();
    let mut arcs: Vec<Option<Piece>> = vec![None; n];
    for i in 0..n {
        let (before, after) = (ring[(i + n - 1) % n], ring[i]);
        let (d0, d1) = (before.tangent(true), after.tangent(false));
        let turn = d0.perp_dot(d1);
        if turn.abs() < 1e-9 && d0.dot(d1) > 0.0 {
            continue;
        }
        let corner = after.start();
        let side = if turn > 0.0 { r } else { -r };
        let centre = offset_piece(before, side)
            .zip(offset_piece(after, side))
            .and_then(|(a, b)| meet(a, b, corner))
            .ok_or_else(|| {
                construction(
                    WHAT,
                    format!(
                        "the fillet of the upright edge at {} does not fit between its faces",
                        point(prism.at(corner, 0.0))
                    ),
                )
            })?;
        let (p1, p2) = (foot(before, centre), foot(after, centre));
        arcs[i] = Some(Piece::Arc {
            from: p1,
            centre,
            radius: r,
            sweep: (p1 - centre).angle_to(p2 - centre),
        });
        ends[(i + n - 1) % n].1 = p1;
        ends[i].0 = p2;
    }
    let mut pieces = Vec::with_capacity(2 * n);
    for i in 0..n {
        if let Some(arc) = arcs[i] {
            pieces.push(arc);
        }
        let piece = between(ring[i], ends[i].0, ends[i].1);
        if !runs_on(piece, ring[i]) {
            return Err(construction(
                WHAT,
                format!(
                    "the fillet is too large for the edge from {} to {}: the roundings at its \
                     ends overlap",
                    point(prism.at(ring[i].start(), 0.0)),
                    point(prism.at(ring[i].end(), 0.0))
                ),
            ));
        }
        pieces.push(piece);
    }
    Ok(pieces)
}

/// The arc of `radius` about `centre` from the direction of `from`, turning by `sweep`, at
/// height z.
fn arc_curve(
    prism: &Prism,
    centre: DVec2,
    from: DVec2,
    radius: f64,
    sweep: f64,
    z: f64,
) -> Result<SpaceCurve, GeometryError> {
    let x = prism.vector((from - centre).normalize());
    let axis = if sweep > 0.0 { prism.up } else { -prism.up };
    arc(
        prism.at(centre, z),
        x,
        axis.cross(x),
        radius,
        0.0,
        sweep.abs(),
    )
}

/// Every edge of the right prism `solid` filleted at radius `r` (see the module
/// documentation); None where `solid` is not a right prism.
pub(crate) fn fillet_prism(
    solid: &Polyhedron,
    r: f64,
) -> Option<Result<Vec<TrimmedSurface>, GeometryError>> {
    let prism = prism_of(solid)?;
    let caps = vec![[true, true]; prism.loops.len()];
    Some(build(
        &prism,
        EdgeFeature::Fillet { radius: r },
        &caps,
        true,
    ))
}

/// `feature` on the edges of `faces` that `pick` names, where `faces` is a right prism with
/// an outline of lines and arcs (see the module documentation): None where it is not one,
/// with the number of edges (chains) picked.
pub(crate) fn round_curved_prism(
    faces: &[TrimmedSurface],
    pick: &EdgePick,
    feature: EdgeFeature,
    tolerance: f64,
) -> Option<Result<(Vec<TrimmedSurface>, usize), GeometryError>> {
    let prism = curved_prism_of(faces, tolerance)?;
    Some(round_picked(&prism, pick, feature))
}

fn round_picked(
    prism: &Prism,
    pick: &EdgePick,
    feature: EdgeFeature,
) -> Result<(Vec<TrimmedSurface>, usize), GeometryError> {
    // Each loop's sharp corners (its upright edges).
    let sharp: Vec<Vec<usize>> = prism
        .loops
        .iter()
        .map(|l| {
            let n = l.len();
            (0..n)
                .filter(|&i| {
                    let (d0, d1) = (l[(i + n - 1) % n].tangent(true), l[i].tangent(false));
                    !(d0.perp_dot(d1).abs() < 1e-9 && d0.dot(d1) > 0.0)
                })
                .collect()
        })
        .collect();
    let mut caps = vec![[false, false]; prism.loops.len()];
    let mut uprights = 0;
    match pick {
        EdgePick::All => {
            caps.iter_mut().for_each(|c| *c = [true, true]);
            uprights = sharp.iter().map(Vec::len).sum();
        }
        EdgePick::Near(points) => {
            for &p in points {
                if !p.is_finite() {
                    return Err(construction(WHAT, "a picking point is not a finite number"));
                }
                let (q, z) = prism.flat(p);
                let mut best = (f64::INFINITY, None);
                for (l, pieces) in prism.loops.iter().enumerate() {
                    for piece in pieces {
                        let d = piece.distance(q);
                        for (cap, h) in [(0, 0.0), (1, prism.height)] {
                            let gap = d.hypot(z - h);
                            if gap < best.0 {
                                best = (gap, Some((l, Some(cap))));
                            }
                        }
                    }
                    for &i in &sharp[l] {
                        let corner = pieces[i].start();
                        let dz = if z < 0.0 {
                            -z
                        } else if z > prism.height {
                            z - prism.height
                        } else {
                            0.0
                        };
                        let gap = q.distance(corner).hypot(dz);
                        if gap < best.0 {
                            best = (gap, Some((l, None)));
                        }
                    }
                }
                match best.1 {
                    Some((l, Some(cap))) => caps[l][cap] = true,
                    Some((_, None)) => uprights += 1,
                    None => return Err(construction(WHAT, "the solid has no edges")),
                }
            }
        }
    }
    let picked = caps.iter().flatten().filter(|&&c| c).count() + uprights;
    let every = caps.iter().all(|c| c[0] && c[1]);
    let corners: usize = sharp.iter().map(Vec::len).sum();
    if corners > 0 && !(every && matches!(pick, EdgePick::All)) {
        return Err(construction(
            WHAT,
            "the outline has sharp corners: a fillet along its rims is built with every edge \
             picked, where its chains end on the upright edges' fillets",
        ));
    }
    if corners > 0 && !matches!(feature, EdgeFeature::Fillet { .. }) {
        return Err(construction(
            WHAT,
            "a chamfer of every edge of an outline with sharp corners and arcs is not built yet",
        ));
    }
    Ok((build(prism, feature, &caps, true)?, picked))
}

/// The prism's faces with `feature` along the rims `caps` names (each loop's bottom and top),
/// its outline's sharp corners first rounded at the radius where `round_corners`.
fn build(
    prism: &Prism,
    feature: EdgeFeature,
    caps: &[[bool; 2]],
    round_corners: bool,
) -> Result<Vec<TrimmedSurface>, GeometryError> {
    let h = prism.height;
    // How far a rim's feature reaches into the cap and down the wall.
    let (in_cap, in_wall) = match feature {
        EdgeFeature::Fillet { radius } => (radius, radius),
        EdgeFeature::Chamfer { distance, other } => (distance, other),
    };
    let twice = caps.iter().any(|c| c[0] && c[1]);
    if !(in_wall < h) || (twice && !(2.0 * in_wall < h)) {
        return Err(construction(
            WHAT,
            format!("the radius {in_wall} is too large for the body's height {h}"),
        ));
    }
    let up = prism.up;
    let mut out = Vec::new();
    let mut cap_curves: [Vec<SpaceCurve>; 2] = [Vec::new(), Vec::new()];
    for (ring, picked) in prism.loops.iter().zip(caps) {
        let z0 = if picked[0] { in_wall } else { 0.0 };
        let z1 = if picked[1] { h - in_wall } else { h };
        let ring = if round_corners {
            rounded(ring, in_wall, prism)?
        } else {
            ring.clone()
        };
        for piece in ring {
            let m = left(piece.tangent(false));
            // The wall's outward direction at a point, and the rims' sections at the start.
            let wall_out: Box<dyn Fn(DVec3) -> DVec3> = match piece {
                Piece::Line(..) => {
                    let o = -prism.vector(m);
                    Box::new(move |_| o)
                }
                Piece::Arc { centre, sweep, .. } => {
                    let c3 = prism.at(centre, 0.0);
                    let s = sweep.signum();
                    Box::new(move |p: DVec3| {
                        let q = p - c3;
                        (q - up * q.dot(up)) * s
                    })
                }
            };
            let start = piece.start();
            match piece {
                Piece::Line(a, b) => {
                    let wall = planar_face(&[
                        line(prism.at(a, z0), prism.at(b, z0))?,
                        line(prism.at(b, z0), prism.at(b, z1))?,
                        line(prism.at(b, z1), prism.at(a, z1))?,
                        line(prism.at(a, z1), prism.at(a, z0))?,
                    ])?;
                    out.push(facing(wall, &wall_out)?);
                }
                Piece::Arc {
                    from,
                    centre,
                    radius,
                    sweep,
                } => {
                    let base = arc_curve(prism, centre, from, radius, sweep, z0)?;
                    let wall = extrude(&base, up * (z1 - z0))?;
                    out.push(facing(TrimmedSurface::untrimmed(wall), &wall_out)?);
                }
            }
            for (level, z, sign) in [(0, 0.0, -1.0), (1, h, 1.0)] {
                if !picked[level] {
                    cap_curves[level].push(match piece {
                        Piece::Line(a, b) => line(prism.at(a, z), prism.at(b, z))?,
                        Piece::Arc {
                            from,
                            centre,
                            radius,
                            sweep,
                        } => arc_curve(prism, centre, from, radius, sweep, z)?,
                    });
                    continue;
                }
                // The rim's section at the piece's start: the quarter circle of the ball
                // (or the chord) from the wall to the cap.
                let section = match feature {
                    EdgeFeature::Fillet { radius } => arc(
                        prism.at(start + m * radius, z - sign * radius),
                        -prism.vector(m),
                        up * sign,
                        radius,
                        0.0,
                        FRAC_PI_2,
                    )?,
                    EdgeFeature::Chamfer { .. } => line(
                        prism.at(start, z - sign * in_wall),
                        prism.at(start + m * in_cap, z),
                    )?,
                };
                let rim = match piece {
                    Piece::Line(a, b) => {
                        cap_curves[level].push(line(
                            prism.at(a + m * in_cap, z),
                            prism.at(b + m * in_cap, z),
                        )?);
                        extrude(&section, prism.vector(b - a))?
                    }
                    Piece::Arc {
                        from,
                        centre,
                        radius,
                        sweep,
                    } => {
                        // Moved in: towards the centre about a convex arc, away about a
                        // concave one.
                        let inner = radius - sweep.signum() * in_cap;
                        if inner < -1e-9 * radius {
                            return Err(construction(
                                WHAT,
                                format!(
                                    "the {} is too large for the rounded edge about {}: its \
                                     radius is {radius:.6}",
                                    if matches!(feature, EdgeFeature::Fillet { .. }) {
                                        "fillet"
                                    } else {
                                        "chamfer"
                                    },
                                    point(prism.at(centre, z))
                                ),
                            ));
                        }
                        if inner > 1e-9 * radius {
                            let from_in = centre + (from - centre) * (inner / radius);
                            cap_curves[level]
                                .push(arc_curve(prism, centre, from_in, inner, sweep, z)?);
                        }
                        let axis = if sweep > 0.0 { up } else { -up };
                        revolve(&section, prism.at(centre, z), axis, sweep.abs())?
                    }
                };
                out.push(facing(TrimmedSurface::untrimmed(rim), |p| {
                    wall_out(p) + up * sign
                })?);
            }
        }
    }
    for (level, sign) in [(0, -1.0), (1, 1.0)] {
        if cap_curves[level].is_empty() {
            return Err(construction(
                WHAT,
                "a cap vanishes: the feature is as wide as it",
            ));
        }
        let cap = planar_face(&cap_curves[level])?;
        out.push(facing(cap, |_| up * sign)?);
    }
    Ok(out)
}

/// The loop's pieces moved into the material by `distance` (below 0: out of it): each line
/// along its normal, each arc's radius shrunk or grown about its centre; pieces meeting
/// tangentially still do, sharp corners between lines go to where the moved lines meet.
/// Refused where an arc or a line vanishes, or a sharp corner touches an arc.
fn offset_loop(ring: &[Piece], distance: f64, prism: &Prism) -> Result<Vec<Piece>, GeometryError> {
    let n = ring.len();
    let moved: Vec<Piece> = ring
        .iter()
        .map(|&piece| {
            offset_piece(piece, distance).ok_or_else(|| {
                construction(
                    WHAT,
                    format!(
                        "the wall is thicker than the body allows: the arc from {} vanishes",
                        point(prism.at(piece.start(), 0.0))
                    ),
                )
            })
        })
        .collect::<Result<_, _>>()?;
    let mut ends: Vec<(DVec2, DVec2)> = moved.iter().map(|p| (p.start(), p.end())).collect();
    for i in 0..n {
        let (before, after) = (ring[(i + n - 1) % n], ring[i]);
        let (d0, d1) = (before.tangent(true), after.tangent(false));
        if d0.perp_dot(d1).abs() < 1e-9 && d0.dot(d1) > 0.0 {
            continue;
        }
        // A sharp corner goes to where the moved pieces meet.
        let corner = meet(moved[(i + n - 1) % n], moved[i], after.start()).ok_or_else(|| {
            construction(
                WHAT,
                format!(
                    "the wall is thicker than the body allows: the faces at {} no longer meet",
                    point(prism.at(after.start(), 0.0))
                ),
            )
        })?;
        ends[(i + n - 1) % n].1 = corner;
        ends[i].0 = corner;
    }
    (0..n)
        .map(|i| {
            let piece = between(moved[i], ends[i].0, ends[i].1);
            if runs_on(piece, ring[i]) {
                Ok(piece)
            } else {
                Err(construction(
                    WHAT,
                    format!(
                        "the wall is thicker than the body allows: the edge from {} to {} \
                         vanishes",
                        point(prism.at(ring[i].start(), 0.0)),
                        point(prism.at(ring[i].end(), 0.0))
                    ),
                ))
            }
        })
        .collect()
}

/// Whether `piece`, cut back or moved from `old`, still runs its way: a line the same
/// direction, an arc turning the same way by a nearby angle (not wrapped round).
fn runs_on(piece: Piece, old: Piece) -> bool {
    match (piece, old) {
        (Piece::Line(a, b), Piece::Line(a0, b0)) => {
            (b - a).dot(b0 - a0) > 1e-9 * (b0 - a0).length_squared()
        }
        (Piece::Arc { sweep, .. }, Piece::Arc { sweep: s0, .. }) => {
            sweep * s0 > 0.0 && sweep.abs() > 1e-9 && (sweep - s0).abs() < FRAC_PI_2
        }
        _ => false,
    }
}

/// The shell of `faces` to `thickness` (below 0 inside) with the caps nearest `open` left
/// open, where `faces` is a right prism with an outline of lines and arcs (see
/// [`super::shell`]); None where it is not one. Built face by face, no boolean: the outer
/// body's walls and closed cap, the inner body's reversed, and at an open cap a ring between
/// each loop and its offset. Only caps may be left open: a wall's neighbours would no longer
/// meet it tangentially.
pub(crate) fn shell_prism(
    faces: &[TrimmedSurface],
    thickness: f64,
    open: &[DVec3],
    tolerance: f64,
) -> Option<Result<FeatureResult, GeometryError>> {
    let prism = curved_prism_of(faces, tolerance)?;
    Some(
        shell_of(&prism, thickness, open)
            .and_then(|(faces, picked)| closed_result(faces, tolerance * 10.0, picked, "shell")),
    )
}

/// A loop's pieces as curves at height z.
fn loop_curves(prism: &Prism, ring: &[Piece], z: f64) -> Result<Vec<SpaceCurve>, GeometryError> {
    ring.iter()
        .map(|&piece| match piece {
            Piece::Line(a, b) => line(prism.at(a, z), prism.at(b, z)),
            Piece::Arc {
                from,
                centre,
                radius,
                sweep,
            } => arc_curve(prism, centre, from, radius, sweep, z),
        })
        .collect()
}

fn shell_of(
    prism: &Prism,
    thickness: f64,
    open: &[DVec3],
) -> Result<(Vec<TrimmedSurface>, usize), GeometryError> {
    let h = prism.height;
    let mut opened = [false, false];
    for &p in open {
        if !p.is_finite() {
            return Err(construction(WHAT, "a picking point is not a finite number"));
        }
        let (q, z) = prism.flat(p);
        let wall = prism
            .loops
            .iter()
            .flatten()
            .map(|piece| {
                let dz = if z < 0.0 {
                    -z
                } else if z > h {
                    z - h
                } else {
                    0.0
                };
                piece.distance(q).hypot(dz)
            })
            .fold(f64::INFINITY, f64::min);
        let (bottom, top) = (z.abs(), (z - h).abs());
        if wall < bottom.min(top) {
            return Err(construction(
                WHAT,
                format!(
                    "the face nearest {} is a wall of the outline; a shell of this body opens \
                     only its caps for now",
                    point(p)
                ),
            ));
        }
        opened[usize::from(top < bottom)] = true;
    }
    if opened[0] && opened[1] {
        return Err(construction(
            WHAT,
            "a shell of this body opening both caps is a tube; build it as the outline's \
             offset extruded",
        ));
    }
    let t = thickness.abs();
    // The outline moved in by `d` (walls), between heights z0 and z1.
    let moved = |d: f64, z0: f64, z1: f64| -> Result<Prism, GeometryError> {
        if z1 - z0 <= 1e-9 * h {
            return Err(construction(
                WHAT,
                "the wall is thicker than the body allows: its caps meet",
            ));
        }
        Ok(Prism {
            origin: prism.origin + prism.up * z0,
            height: z1 - z0,
            loops: prism
                .loops
                .iter()
                .map(|l| offset_loop(l, d, prism))
                .collect::<Result<Vec<_>, _>>()?,
            ..*prism
        })
    };
    // The outer and inner bodies: the solid and its inward offset, or the outward offset and
    // the solid; an open cap stays where the solid's is.
    let (d_out, d_in) = if thickness < 0.0 { (0.0, t) } else { (-t, 0.0) };
    let (o0, o1) = (
        if thickness > 0.0 && !opened[0] {
            -t
        } else {
            0.0
        },
        if thickness > 0.0 && !opened[1] {
            h + t
        } else {
            h
        },
    );
    let (i0, i1) = (
        if thickness < 0.0 && !opened[0] {
            t
        } else {
            0.0
        },
        if thickness < 0.0 && !opened[1] {
            h - t
        } else {
            h
        },
    );
    let (outer, inner) = (moved(d_out, o0, o1)?, moved(d_in, i0, i1)?);
    let plain = |p: &Prism| {
        build(
            p,
            EdgeFeature::Fillet { radius: 0.0 },
            &vec![[false, false]; p.loops.len()],
            false,
        )
    };
    let mut faces = plain(&outer)?;
    let mut hollow = plain(&inner)?;
    let picked = opened.iter().filter(|&&o| o).count();
    if let Some(level) = opened.iter().position(|&o| o) {
        // Both bodies' caps there give way to a ring between each loop and its offset.
        let (z, sign) = if level == 0 { (0.0, -1.0) } else { (h, 1.0) };
        let at = faces.len() - 2 + level;
        faces.remove(at);
        hollow.remove(at);
        let up = prism.up;
        for (a, b) in outer.loops.iter().zip(&inner.loops) {
            let mut ring = loop_curves(prism, a, z)?;
            ring.extend(loop_curves(prism, b, z)?);
            faces.push(facing(planar_face(&ring)?, |_| up * sign)?);
        }
    }
    for face in &hollow {
        faces.push(face.reverse(crate::surface::Direction::U)?);
    }
    Ok((faces, picked))
}
