//! Solids of revolution read as their meridian profile: every face a surface of revolution
//! about one axis (a plane across it, a cylinder, a cone, a sphere, a torus), every edge a
//! circle about it. A face is one segment of the profile (a line, or a circular arc) in the
//! half plane (r, h) of distance from the axis and height along it; an edge is a vertex of
//! the profile off the axis. Edge features are then plane geometry, exact once revolved:
//!
//! - a **fillet** of an edge is the arc tangent to its two segments (the rolling ball's
//!   section; a torus, or a sphere where its centre is on the axis, when revolved);
//! - a **chamfer** the chord between the points set back along them (a cone or a plane);
//! - a **shell** the profile offset segment by segment (each line moved along its normal,
//!   each corner where the moved lines meet, the axis kept), revolved and subtracted by the
//!   boolean, as for polyhedra.

use std::f64::consts::TAU;

use glam::{DVec2, DVec3};

use crate::boolean::outward_faces;
use crate::construct::{arc_through, circle, line, perpendicular_frame, revolve};
use crate::error::{GeometryError, construction};
use crate::join::face_loops;
use crate::planar::planar_face;
use crate::trim::TrimmedSurface;

use super::{EdgeFeature, WHAT, facing, point};

/// One segment of a profile: from `a` to `b` in (r, h), a straight line, or the circular arc
/// through `through`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Segment {
    pub a: DVec2,
    pub b: DVec2,
    pub through: Option<DVec2>,
    /// Whether it runs along the axis (closes the profile; no face).
    pub on_axis: bool,
}

impl Segment {
    fn straight(a: DVec2, b: DVec2) -> Self {
        Self {
            a,
            b,
            through: None,
            on_axis: false,
        }
    }

    fn reversed(self) -> Self {
        Self {
            a: self.b,
            b: self.a,
            ..self
        }
    }

    /// The unit direction of a straight segment.
    fn direction(&self) -> DVec2 {
        (self.b - self.a).normalize_or_zero()
    }

    /// The outward normal at `q` (on it), the material on its left.
    fn outward(&self, q: DVec2) -> DVec2 {
        match self.through {
            None => {
                let d = self.direction();
                DVec2::new(d.y, -d.x)
            }
            Some(m) => {
                let c = circumcentre(self.a, m, self.b).unwrap_or(m);
                let radial = (q - c).normalize_or_zero();
                if (self.a - c).perp_dot(m - c) > 0.0 {
                    radial
                } else {
                    -radial
                }
            }
        }
    }
}

/// A segment of a profile moved off itself: a line (a point and a unit direction) or a
/// circle (centre and radius).
#[derive(Debug, Clone, Copy)]
pub(crate) enum Piece {
    Line(DVec2, DVec2),
    Circle(DVec2, f64),
}

/// Where two pieces meet: the crossing nearest `guess` (None where they do not meet).
pub(crate) fn meet_pieces(a: Piece, b: Piece, guess: DVec2) -> Option<DVec2> {
    let nearest = |points: Vec<DVec2>| {
        points
            .into_iter()
            .min_by(|p, q| p.distance(guess).total_cmp(&q.distance(guess)))
    };
    match (a, b) {
        (Piece::Line(p, d), Piece::Line(q, e)) => {
            let cross = d.perp_dot(e);
            (cross.abs() > 1e-12).then(|| p + d * ((q - p).perp_dot(e) / cross))
        }
        (Piece::Line(p, d), Piece::Circle(c, r)) | (Piece::Circle(c, r), Piece::Line(p, d)) => {
            // |p + t d − c|² = r²: t² + 2 t d·(p − c) + |p − c|² − r² = 0.
            let w = p - c;
            let (half, constant) = (d.dot(w), w.length_squared() - r * r);
            let disc = half * half - constant;
            (disc >= 0.0).then(|| {
                let root = disc.sqrt();
                nearest(vec![p + d * (-half - root), p + d * (-half + root)])
            })?
        }
        (Piece::Circle(c0, r0), Piece::Circle(c1, r1)) => {
            let d = c0.distance(c1);
            if d < 1e-300 || d > r0 + r1 || d < (r0 - r1).abs() {
                return None;
            }
            let along = (d * d + r0 * r0 - r1 * r1) / (2.0 * d);
            let h = (r0 * r0 - along * along).max(0.0).sqrt();
            let u = (c1 - c0) / d;
            let m = c0 + u * along;
            let across = DVec2::new(-u.y, u.x) * h;
            nearest(vec![m + across, m - across])
        }
    }
}

/// The line or circle of `s` moved `distance` into the material (the side its outward
/// normal points away from); None where a circle shrinks to nothing.
fn carrier(s: &Segment, distance: f64) -> Option<Piece> {
    match s.through {
        None => {
            let d = s.direction();
            Some(Piece::Line(s.a + DVec2::new(-d.y, d.x) * distance, d))
        }
        Some(m) => {
            let c = circumcentre(s.a, m, s.b)?;
            let radius = s.a.distance(c);
            // Outward along the radius: the material inside the circle, which shrinks.
            let inside = s.outward(s.a).dot(s.a - c) > 0.0;
            let r = if inside {
                radius - distance
            } else {
                radius + distance
            };
            (r > 0.0).then_some(Piece::Circle(c, r))
        }
    }
}

/// The point of the line or circle of `s` nearest `p`.
fn foot(s: &Segment, p: DVec2) -> DVec2 {
    match s.through.and_then(|m| circumcentre(s.a, m, s.b)) {
        None => {
            let d = s.direction();
            s.a + d * (p - s.a).dot(d)
        }
        Some(c) => c + (p - c).normalize_or_zero() * s.a.distance(c),
    }
}

/// The centre of the circle through three points of a plane.
fn circumcentre(a: DVec2, m: DVec2, b: DVec2) -> Option<DVec2> {
    let (p, q) = (m - a, b - a);
    let d = 2.0 * p.perp_dot(q);
    if d.abs() < 1e-300 {
        return None;
    }
    let (pp, qq) = (p.length_squared(), q.length_squared());
    Some(a + DVec2::new(q.y * pp - p.y * qq, p.x * qq - q.x * pp) / d)
}

/// A solid of revolution: its axis and its closed profile, counter-clockwise in (r, h) (the
/// material on the left), each segment off the axis with the face it came from.
#[derive(Debug, Clone, PartialEq)]
pub struct Profile {
    pub origin: DVec3,
    pub axis: DVec3,
    x: DVec3,
    pub segments: Vec<Segment>,
}

/// The axis of a surface of revolution: a family of its isocurves are circles with their
/// centres on one line along their common normal. None where it is not one.
pub(crate) fn revolution_axis(
    surface: &crate::NurbsSurface,
    tolerance: f64,
) -> Option<(DVec3, DVec3)> {
    let [(u0, u1), (v0, v1)] = surface.domain();
    let at = |s: f64, t: f64, across: bool| {
        let (u, v) = if across { (t, s) } else { (s, t) };
        surface
            .point_at(u0 + (u1 - u0) * u, v0 + (v1 - v0) * v)
            .ok()
    };
    'family: for across in [false, true] {
        let mut circles = Vec::new();
        for t in [0.2, 0.5, 0.8] {
            let p: Vec<DVec3> = [0.05, 0.3, 0.55, 0.8, 0.95]
                .iter()
                .map(|&s| at(s, t, across))
                .collect::<Option<_>>()?;
            let (a, b) = (p[1] - p[0], p[3] - p[0]);
            let n = a.cross(b);
            if n.length() < 1e-12 * a.length_squared().max(b.length_squared()) {
                continue 'family;
            }
            let centre = p[0]
                + (n.cross(a) * b.length_squared() + b.cross(n) * a.length_squared())
                    / (2.0 * n.length_squared());
            let radius = p[0].distance(centre);
            let normal = n.normalize();
            if p.iter().any(|q| {
                (q.distance(centre) - radius).abs() > tolerance
                    || (*q - centre).dot(normal).abs() > tolerance
            }) {
                continue 'family;
            }
            circles.push((centre, normal));
        }
        let (c0, n0) = circles[0];
        if circles.iter().all(|&(c, n)| {
            n.cross(n0).length() < 1e-7 && (c - c0).reject_from(n0).length() <= tolerance
        }) {
            return Some((c0, n0));
        }
    }
    None
}

impl Profile {
    /// The point at (r, h) in the profile's half plane at angle 0.
    fn at(&self, q: DVec2) -> DVec3 {
        self.origin + self.x * q.x + self.axis * q.y
    }

    /// (r, h) of a point.
    fn rh(&self, p: DVec3) -> DVec2 {
        let d = p - self.origin;
        let h = d.dot(self.axis);
        DVec2::new((d - self.axis * h).length(), h)
    }

    /// The profile of the closed shell `faces` (turned outward first), or why it is not a
    /// solid of revolution.
    pub fn from_faces(faces: &[TrimmedSurface], tolerance: f64) -> Result<Self, GeometryError> {
        let (faces, _) = outward_faces(faces, tolerance, "the solid")?;
        let not = |k: usize| {
            construction(
                WHAT,
                format!(
                    "face {k} is neither flat nor a surface of revolution about the solid's \
                     axis; edge features are built on solids whose faces are all flat, or on \
                     solids of revolution"
                ),
            )
        };
        let (origin, axis) = faces
            .iter()
            .filter(|f| f.surface().plane(tolerance).is_none())
            .find_map(|f| revolution_axis(f.surface(), tolerance))
            .ok_or_else(|| not(0))?;
        let (x, _) = perpendicular_frame(axis);
        let mut profile = Self {
            origin,
            axis,
            x,
            segments: Vec::new(),
        };
        let mut pieces = Vec::new();
        for (k, face) in faces.iter().enumerate() {
            let surface = face.surface();
            // The circle edges' (r, h).
            let mut ends: Vec<DVec2> = Vec::new();
            // The (u, v) box the face's loops span: a surface may run on past them (a cone's
            // past its apex, onto the other nappe), where its meridian folds back.
            let [(du0, du1), (dv0, dv1)] = surface.domain();
            let (mut lo, mut hi) = (DVec2::new(du1, dv1), DVec2::new(du0, dv0));
            for trim_loop in face_loops(face)? {
                for curve in &trim_loop {
                    let (t0, t1) = curve.domain();
                    let uvs: Vec<DVec2> = (0..7)
                        .map(|i| curve.point_at(t0 + (t1 - t0) * i as f64 / 6.0))
                        .collect::<Result<_, GeometryError>>()?;
                    let q: Vec<DVec2> = uvs
                        .iter()
                        .map(|&uv| {
                            lo = lo.min(uv);
                            hi = hi.max(uv);
                            Ok(profile.rh(surface.point_at_clamped(uv)?))
                        })
                        .collect::<Result<_, GeometryError>>()?;
                    let round = q.iter().all(|p| p.distance(q[0]) <= tolerance);
                    if round
                        && q[0].x > tolerance
                        && !ends.iter().any(|e| e.distance(q[0]) <= tolerance)
                    {
                        ends.push(q[0]);
                    }
                }
            }
            let (u0, u1, v0, v1) = if lo.x < hi.x && lo.y < hi.y {
                (lo.x.max(du0), hi.x.min(du1), lo.y.max(dv0), hi.y.min(dv1))
            } else {
                (du0, du1, dv0, dv1)
            };
            let grid: Vec<DVec2> = (0..49)
                .map(|i| {
                    let (s, t) = ((i % 7) as f64 / 6.0, (i / 7) as f64 / 6.0);
                    surface
                        .point_at(u0 + (u1 - u0) * s, v0 + (v1 - v0) * t)
                        .map(|p| profile.rh(p))
                })
                .collect::<Result<_, _>>()?;
            if let Some((_, n)) = surface.plane(tolerance)
                && n.cross(axis).length() > 1e-9
            {
                return Err(not(k));
            }
            // The meridian: a line, or a circle, through the samples.
            let p0 = grid[0];
            let p1 = *grid
                .iter()
                .max_by(|a, b| a.distance(p0).total_cmp(&b.distance(p0)))
                .unwrap_or(&p0);
            let chord = (p1 - p0).normalize_or_zero();
            let off = |q: &DVec2| (*q - p0).perp_dot(chord).abs();
            let p2 = *grid
                .iter()
                .max_by(|a, b| off(a).total_cmp(&off(b)))
                .unwrap_or(&p0);
            let circle_of = if off(&p2) <= tolerance {
                None
            } else {
                let c = circumcentre(p0, p2, p1).ok_or_else(|| not(k))?;
                let radius = c.distance(p0);
                if grid
                    .iter()
                    .any(|q| (q.distance(c) - radius).abs() > tolerance)
                {
                    return Err(not(k));
                }
                Some((c, radius))
            };
            let piece = match (ends.len(), circle_of) {
                (2, None) => Segment::straight(ends[0], ends[1]),
                (1, None) => {
                    // To the axis: a disc, or a cone's apex.
                    let d = chord;
                    if d.x.abs() < 1e-12 {
                        return Err(not(k));
                    }
                    let apex = ends[0] - d * (ends[0].x / d.x);
                    Segment::straight(ends[0], DVec2::new(0.0, apex.y))
                }
                (n @ (1 | 2), Some((c, radius))) => {
                    let a = ends[0];
                    let b = if n == 2 {
                        ends[1]
                    } else {
                        // A cap of a ball centred on the axis: to the pole the samples reach.
                        if c.x.abs() > tolerance {
                            return Err(not(k));
                        }
                        let far = *grid
                            .iter()
                            .max_by(|p, q| p.distance(a).total_cmp(&q.distance(a)))
                            .unwrap_or(&a);
                        let poles = [DVec2::new(0.0, c.y + radius), DVec2::new(0.0, c.y - radius)];
                        if poles[0].distance(far) < poles[1].distance(far) {
                            poles[0]
                        } else {
                            poles[1]
                        }
                    };
                    // The middle of the arc the samples lie on.
                    let angle = |q: DVec2| (q - c).to_angle();
                    let (ta, tb) = (angle(a), angle(b));
                    let sweep = (tb - ta).rem_euclid(TAU);
                    let inside = |q: &DVec2| (angle(*q) - ta).rem_euclid(TAU) <= sweep + 1e-9;
                    let counter = grid.iter().filter(|q| inside(q)).count() * 2 >= grid.len();
                    let mid = if counter {
                        ta + 0.5 * sweep
                    } else {
                        ta - 0.5 * (TAU - sweep)
                    };
                    Segment {
                        a,
                        b,
                        through: Some(c + DVec2::from_angle(mid) * radius),
                        on_axis: false,
                    }
                }
                (0, Some((c, radius))) if c.x.abs() <= tolerance => {
                    // A whole ball on the axis: pole to pole.
                    Segment {
                        a: DVec2::new(0.0, c.y - radius),
                        b: DVec2::new(0.0, c.y + radius),
                        through: Some(DVec2::new(radius, c.y)),
                        on_axis: false,
                    }
                }
                _ => return Err(not(k)),
            };
            pieces.push(piece);
        }
        // Faces a file split along meridians (two half cylinders) are one segment.
        let mut unique: Vec<Segment> = Vec::with_capacity(pieces.len());
        for piece in pieces {
            let same = |s: &Segment| {
                let near = |p: DVec2, q: DVec2| p.distance(q) <= 10.0 * tolerance;
                (near(s.a, piece.a) && near(s.b, piece.b)
                    || near(s.a, piece.b) && near(s.b, piece.a))
                    && s.through.is_some() == piece.through.is_some()
            };
            if !unique.iter().any(same) {
                unique.push(piece);
            }
        }
        profile.segments = chain(unique, tolerance)?;
        Ok(profile)
    }

    /// The profile's vertices off the axis (the solid's edges): each the index of the segment
    /// that starts there.
    pub fn edges(&self) -> Vec<usize> {
        let n = self.segments.len();
        (0..n)
            .filter(|&i| {
                let (before, after) = (self.segments[(i + n - 1) % n], self.segments[i]);
                !before.on_axis && !after.on_axis && after.a.x > 0.0
            })
            .collect()
    }

    /// [`Self::from_faces`], refused unless the profile revolved encloses the volume the
    /// faces do (to 1e-7): a face read as a line or an arc within the tolerance that is
    /// another curve (a spline meridian) would otherwise change the body the feature is
    /// built on.
    pub fn exactly(faces: &[TrimmedSurface], tolerance: f64) -> Result<Self, GeometryError> {
        let profile = Self::from_faces(faces, tolerance)?;
        let (outward, _) = outward_faces(faces, tolerance, "the solid")?;
        let (read, made) = (
            crate::mass::signed_volume(&outward)?.abs(),
            crate::mass::signed_volume(&profile.faces()?)?.abs(),
        );
        if (read - made).abs() > 1e-7 * read {
            return Err(construction(
                WHAT,
                format!(
                    "the solid's faces are not exactly lines and arcs turned about its axis \
                     (read as such, its volume {read:.6} becomes {made:.6}); a face with another \
                     meridian is not built yet"
                ),
            ));
        }
        Ok(profile)
    }

    /// Whether the faces meet at an angle at the vertex where segment `i` starts (not
    /// tangentially, as a ball's cap on a cylinder of its radius).
    pub fn is_sharp(&self, i: usize) -> bool {
        let n = self.segments.len();
        let (before, after) = (self.segments[(i + n - 1) % n], self.segments[i]);
        let v = after.a;
        let (o1, o2) = (before.outward(v), after.outward(v));
        o1.perp_dot(o2).abs() >= 1e-9 || o1.dot(o2) < 0.0
    }

    /// The distance from `p` to the circle of the edge where segment `i` starts.
    pub fn edge_distance(&self, i: usize, p: DVec3) -> f64 {
        self.rh(p).distance(self.segments[i].a)
    }

    /// The distance from `p` to segment `i`'s face (to its chord, for an arc).
    pub fn face_distance(&self, i: usize, p: DVec3) -> f64 {
        let s = self.segments[i];
        let q = self.rh(p);
        let d = s.b - s.a;
        let t = ((q - s.a).dot(d) / d.length_squared().max(f64::MIN_POSITIVE)).clamp(0.0, 1.0);
        q.distance(s.a + d * t)
    }

    /// The profile with the corners at the vertices `picked` (indices of the segments that
    /// start there) rounded or cut by `feature`.
    pub fn rounded(&self, picked: &[usize], feature: EdgeFeature) -> Result<Self, GeometryError> {
        let n = self.segments.len();
        let mut segments = self.segments.clone();
        let mut inserted: Vec<(usize, Segment)> = Vec::new();
        for &i in picked {
            let (before, after) = (self.segments[(i + n - 1) % n], self.segments[i]);
            let v = after.a;
            let edge = || point(self.at(v));
            // The directions of travel at the vertex (the material on the left: the outward
            // normal turned a quarter left).
            let travel = |s: &Segment| {
                let o = s.outward(v);
                DVec2::new(-o.y, o.x)
            };
            let (d1, d2) = (travel(&before), travel(&after));
            let turn = d1.perp_dot(d2);
            if turn.abs() < 1e-9 && d1.dot(d2) > 0.0 {
                return Err(construction(
                    WHAT,
                    format!("the faces at the edge {} meet flat", edge()),
                ));
            }
            let (p1, p2, through) = match feature {
                EdgeFeature::Fillet { radius } => {
                    // The ball's centre: where both segments moved by r towards it meet
                    // (inside the material at a convex edge, outside at a concave one).
                    let side = if turn > 0.0 { radius } else { -radius };
                    let centre = carrier(&before, side)
                        .zip(carrier(&after, side))
                        .and_then(|(a, b)| meet_pieces(a, b, v))
                        .ok_or_else(|| {
                            construction(
                                WHAT,
                                format!(
                                    "the fillet of the edge {} does not fit between its faces",
                                    edge()
                                ),
                            )
                        })?;
                    let (p1, p2) = (foot(&before, centre), foot(&after, centre));
                    let middle = (0.5 * (p1 + p2) - centre).normalize_or_zero();
                    (p1, p2, Some(centre + middle * radius))
                }
                EdgeFeature::Chamfer { distance, other } => {
                    let back = |s: &Segment, d: f64, toward: DVec2| match s.through {
                        None => Some(v + toward * d),
                        Some(_) => carrier(s, 0.0)
                            .and_then(|c| meet_pieces(c, Piece::Circle(v, d), v + toward * d)),
                    };
                    let p1 = back(&before, distance, -d1);
                    let p2 = back(&after, other, d2);
                    let (Some(p1), Some(p2)) = (p1, p2) else {
                        return Err(construction(
                            WHAT,
                            format!("the chamfer of the edge {} does not fit", edge()),
                        ));
                    };
                    (p1, p2, None)
                }
            };
            segments[(i + n - 1) % n].b = p1;
            segments[i].a = p2;
            inserted.push((
                i,
                Segment {
                    a: p1,
                    b: p2,
                    through,
                    on_axis: false,
                },
            ));
        }
        // Arcs cut back keep their circle and their way round: a new middle point.
        for (new, old) in segments.iter_mut().zip(&self.segments) {
            if let Some(m) = old.through
                && (new.a != old.a || new.b != old.b)
                && let Some(c) = circumcentre(old.a, m, old.b)
            {
                let way = (m - old.a).perp_dot(old.b - m).signum();
                let (a, b) = (new.a - c, new.b - c);
                let mut angle = a.angle_to(b);
                if angle * way < 0.0 {
                    angle += way * std::f64::consts::TAU;
                }
                new.through = Some(c + DVec2::from_angle(0.5 * angle).rotate(a));
            }
        }
        // Every segment keeps its direction and some length.
        for (old, new) in self.segments.iter().zip(&segments) {
            let (d_old, d_new) = (old.b - old.a, new.b - new.a);
            if d_new.dot(d_old) <= 1e-9 * d_old.length_squared()
                || new.a.x < -1e-12
                || new.b.x < -1e-12
            {
                return Err(construction(
                    WHAT,
                    format!(
                        "the feature is too large: the face from the circle through {} to the \
                         one through {} is used up",
                        point(self.at(old.a)),
                        point(self.at(old.b))
                    ),
                ));
            }
        }
        inserted.sort_by_key(|&(i, _)| std::cmp::Reverse(i));
        for (i, s) in inserted {
            segments.insert(i, s);
        }
        Ok(Self {
            segments,
            ..self.clone()
        })
    }

    /// The profile with each segment `k` off the axis moved `distance(k)` along its outward
    /// normal (a line shifted, an arc's circle grown or shrunk about its centre) and each
    /// corner where the moved pieces meet (where two pieces are tangent, the corner moved
    /// along their common normal; the axis kept).
    pub fn offset(&self, distance: impl Fn(usize) -> f64) -> Result<Self, GeometryError> {
        let n = self.segments.len();
        let thick = |s: &Segment| {
            construction(
                WHAT,
                format!(
                    "the wall is thicker than the body allows: the face from {} to {} vanishes",
                    point(self.at(s.a)),
                    point(self.at(s.b))
                ),
            )
        };
        let shifts: Vec<f64> = (0..n)
            .map(|k| {
                if self.segments[k].on_axis {
                    0.0
                } else {
                    distance(k)
                }
            })
            .collect();
        let moved: Vec<Piece> = self
            .segments
            .iter()
            .zip(&shifts)
            .map(|(s, &shift)| match s.through {
                None => {
                    let d = s.direction();
                    Ok(Piece::Line(s.a + DVec2::new(d.y, -d.x) * shift, d))
                }
                Some(m) => {
                    let c = circumcentre(s.a, m, s.b).ok_or_else(|| thick(s))?;
                    let radius = c.distance(s.a);
                    // Outward away from the centre: the circle grows by the shift.
                    let grow = s.outward(m).dot(m - c).signum();
                    let moved = radius + grow * shift;
                    if moved <= 0.0 {
                        return Err(thick(s));
                    }
                    Ok(Piece::Circle(c, moved))
                }
            })
            .collect::<Result<_, _>>()?;
        let mut corners = Vec::with_capacity(n);
        for i in 0..n {
            let (before, after) = (&self.segments[(i + n - 1) % n], &self.segments[i]);
            let v = after.a;
            let (n0, n1) = (before.outward(v), after.outward(v));
            let guess = v + (n0 * shifts[(i + n - 1) % n] + n1 * shifts[i]) * 0.5;
            let corner = if n0.distance(n1) < 1e-9 {
                if (shifts[i] - shifts[(i + n - 1) % n]).abs() > 1e-12 {
                    return Err(construction(
                        WHAT,
                        format!(
                            "a face left open meets a tangent face at {}; that shell is not \
                             built yet",
                            point(self.at(v))
                        ),
                    ));
                }
                Some(v + n1 * shifts[i])
            } else {
                meet_pieces(moved[(i + n - 1) % n], moved[i], guess)
            };
            corners.push(corner.ok_or_else(|| thick(after))?);
        }
        let mut segments = Vec::with_capacity(n);
        for (k, s) in self.segments.iter().enumerate() {
            let (a, b) = (corners[k], corners[(k + 1) % n]);
            if a.x < -1e-9 || b.x < -1e-9 {
                return Err(thick(s));
            }
            let through = match (s.through, moved[k]) {
                (Some(m), Piece::Circle(c, radius)) => {
                    let t = c + (m - c).normalize() * radius;
                    // The arc keeps its turn: a, the middle and b in the same order about c.
                    let turn = |p: DVec2, q: DVec2| (p - c).perp_dot(q - c);
                    let (old, new) = (turn(s.a, m) * turn(m, s.b), turn(a, t) * turn(t, b));
                    if old.signum() != new.signum() || turn(s.a, m).signum() != turn(a, t).signum()
                    {
                        return Err(thick(s));
                    }
                    Some(t)
                }
                _ => {
                    if (b - a).dot(s.b - s.a) <= 1e-9 * (s.b - s.a).length_squared() {
                        return Err(thick(s));
                    }
                    None
                }
            };
            segments.push(Segment {
                a,
                b,
                through,
                on_axis: s.on_axis,
            });
        }
        Ok(Self {
            segments,
            ..self.clone()
        })
    }

    /// The closed shell of the profile revolved: a flat ring or disc for each segment across
    /// the axis, the revolved line or arc for each other one, outward.
    pub fn faces(&self) -> Result<Vec<TrimmedSurface>, GeometryError> {
        let mut out = Vec::new();
        for s in self.segments.iter().filter(|s| !s.on_axis) {
            let face =
                if s.through.is_none() && (s.a.y - s.b.y).abs() <= 1e-12 * (1.0 + s.a.y.abs()) {
                    let centre = self.origin + self.axis * s.a.y;
                    let (lo, hi) = (s.a.x.min(s.b.x), s.a.x.max(s.b.x));
                    let mut rings = vec![circle(centre, self.axis, self.x, hi)?];
                    if lo > 1e-9 * hi {
                        rings.push(circle(centre, self.axis, self.x, lo)?);
                    }
                    planar_face(&rings)?
                } else {
                    let curve = match s.through {
                        None => line(self.at(s.a), self.at(s.b))?,
                        Some(m) => arc_through(self.at(s.a), self.at(m), self.at(s.b))?,
                    };
                    TrimmedSurface::untrimmed(revolve(&curve, self.origin, self.axis, TAU)?)
                };
            let seg = *s;
            out.push(facing(face, |p| {
                let q = self.rh(p);
                let o = seg.outward(q);
                let d = p - self.origin;
                let radial = (d - self.axis * d.dot(self.axis)).normalize_or_zero();
                radial * o.x + self.axis * o.y
            })?);
        }
        Ok(out)
    }
}

/// The faces' segments chained into one closed loop, joined along the axis where a chain
/// reaches it, counter-clockwise.
fn chain(mut pieces: Vec<Segment>, tolerance: f64) -> Result<Vec<Segment>, GeometryError> {
    let near = |a: DVec2, b: DVec2| a.distance(b) <= 10.0 * tolerance;
    let Some(first) = pieces.pop() else {
        return Err(construction(WHAT, "the solid has no faces"));
    };
    let mut out = vec![first];
    loop {
        let end = out[out.len() - 1].b;
        if near(end, out[0].a) {
            break;
        }
        if let Some(k) = pieces.iter().position(|s| near(s.a, end) || near(s.b, end)) {
            let s = pieces.remove(k);
            out.push(if near(s.a, end) { s } else { s.reversed() });
            continue;
        }
        if end.x > 10.0 * tolerance {
            return Err(construction(WHAT, "the solid's profile does not close"));
        }
        // Along the axis to the nearest segment that starts or ends on it, or back to the
        // start.
        let on_axis = |p: DVec2| p.x <= 10.0 * tolerance;
        let next = pieces
            .iter()
            .enumerate()
            .flat_map(|(k, s)| [(k, s.a, false), (k, s.b, true)])
            .filter(|&(_, p, _)| on_axis(p))
            .min_by(|x, y| (x.1.y - end.y).abs().total_cmp(&(y.1.y - end.y).abs()));
        let axis_to = |b: DVec2| Segment {
            a: end,
            b,
            through: None,
            on_axis: true,
        };
        match next {
            Some((k, p, flip)) => {
                out.push(axis_to(p));
                let s = pieces.remove(k);
                out.push(if flip { s.reversed() } else { s });
            }
            None if on_axis(out[0].a) => {
                out.push(axis_to(out[0].a));
                break;
            }
            None => return Err(construction(WHAT, "the solid's profile does not close")),
        }
    }
    if !pieces.is_empty() {
        return Err(construction(
            WHAT,
            "the solid's profile has more than one loop (a void or a second body); that is not \
             built yet",
        ));
    }
    // Counter-clockwise: the area by the chords and the arcs' middle points.
    let area: f64 = out
        .iter()
        .map(|s| match s.through {
            None => s.a.perp_dot(s.b),
            Some(m) => s.a.perp_dot(m) + m.perp_dot(s.b),
        })
        .sum();
    if area < 0.0 {
        out = out.into_iter().rev().map(Segment::reversed).collect();
    }
    Ok(out)
}

/// [`super::round_edges`] on a solid of revolution.
pub(crate) fn round_revolved(
    faces: &[TrimmedSurface],
    pick: &super::EdgePick,
    feature: EdgeFeature,
    tolerance: f64,
    what: &str,
) -> Result<super::FeatureResult, GeometryError> {
    let profile = Profile::exactly(faces, tolerance)?;
    let edges = profile.edges();
    let mut picked: Vec<usize> = match pick {
        // Every edge where the faces meet at an angle.
        super::EdgePick::All => edges
            .iter()
            .copied()
            .filter(|&i| profile.is_sharp(i))
            .collect(),
        super::EdgePick::Near(points) => points
            .iter()
            .filter_map(|&p| {
                edges.iter().copied().min_by(|&i, &j| {
                    profile
                        .edge_distance(i, p)
                        .total_cmp(&profile.edge_distance(j, p))
                })
            })
            .collect(),
    };
    picked.sort_unstable();
    picked.dedup();
    if edges.is_empty() {
        return Err(construction(WHAT, "the solid has no edges to round"));
    }
    if picked.is_empty() {
        return Err(construction(WHAT, "no edge is picked"));
    }
    let faces = profile.rounded(&picked, feature)?.faces()?;
    super::closed_result(faces, tolerance * 10.0, picked.len(), what)
}

/// [`super::shell`] on a solid of revolution: the offset profiles revolved.
pub(crate) fn shell_revolved(
    faces: &[TrimmedSurface],
    thickness: f64,
    open: &[DVec3],
    tolerance: f64,
) -> Result<(Vec<TrimmedSurface>, Vec<TrimmedSurface>, usize), GeometryError> {
    let profile = Profile::exactly(faces, tolerance)?;
    let walls: Vec<usize> = (0..profile.segments.len())
        .filter(|&k| !profile.segments[k].on_axis)
        .collect();
    let mut opened: Vec<usize> = open
        .iter()
        .filter_map(|&p| {
            walls.iter().copied().min_by(|&i, &j| {
                profile
                    .face_distance(i, p)
                    .total_cmp(&profile.face_distance(j, p))
            })
        })
        .collect();
    opened.sort_unstable();
    opened.dedup();
    if opened.len() >= walls.len() {
        return Err(construction(WHAT, "a shell cannot leave every face open"));
    }
    let is_open = |k: usize| opened.contains(&k);
    let t = thickness.abs();
    let (outer, inner) = if thickness < 0.0 {
        (
            profile.clone(),
            profile.offset(|k| if is_open(k) { t } else { -t })?,
        )
    } else {
        (
            profile.offset(|k| if is_open(k) { 0.0 } else { t })?,
            profile.offset(|k| if is_open(k) { t } else { 0.0 })?,
        )
    };
    Ok((outer.faces()?, inner.faces()?, opened.len()))
}
