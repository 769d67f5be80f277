//! The rims of round holes and bosses on flat-faced solids: a cylindrical wall whose two ends
//! are full circles on flat faces square to its axis (a drilled hole, a pocket, a pin standing
//! on a plate). Each rim is an edge between a plane and the cylinder meeting at a right angle,
//! so a ball of radius r rolling along it touches the plane at r from the edge and the
//! cylinder at r from it (r / tan(ψ/2) with ψ = 90°), and its centre runs on a circle about
//! the axis: the fillet is a torus (the quarter circle of the ball's section revolved), a
//! chamfer a cone (the chord between the set-back points revolved), both exact. The plane's
//! circle grows or shrinks by the set-back, and the wall is rebuilt between its new ends.
//!
//! With m_P the direction in the plane away from the edge into the face and m_C the one along
//! the wall into it, the ball's centre is at edge + r (m_P + m_C) whether the edge is convex
//! (a hole's mouth, a boss's top) or concave (a boss's foot, a pocket's floor).

use std::f64::consts::TAU;

use glam::DVec3;

use crate::construct::{arc_through, circle, line, revolve};
use crate::curve::SpaceCurve;
use crate::error::{GeometryError, construction};
use crate::join::face_loops;
use crate::mass::area;
use crate::trim::TrimmedSurface;

use super::polyhedron::Polyhedron;
use super::revolved::revolution_axis;
use super::{EdgeFeature, EdgePick, WHAT, facing, point};

/// One end of a wall: the flat face it opens on and its height along the axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RimEnd {
    pub facet: usize,
    pub height: f64,
}

/// A cylindrical wall between two flat faces square to its axis.
#[derive(Debug, Clone, PartialEq)]
pub struct Wall {
    /// A point on the axis and the axis' unit direction.
    pub origin: DVec3,
    pub axis: DVec3,
    /// A unit direction square to the axis: where every rebuilt circle starts.
    x: DVec3,
    pub radius: f64,
    /// +1 where the wall's outward normal points away from the axis (a boss: the material
    /// inside), −1 where towards it (a hole).
    pub outward: f64,
    pub ends: [RimEnd; 2],
}

impl Wall {
    /// The rim's circle at end `end`.
    fn centre(&self, end: usize) -> DVec3 {
        self.origin + self.axis * self.ends[end].height
    }

    /// The distance of `p` from the rim at end `end`.
    pub fn rim_distance(&self, end: usize, p: DVec3) -> f64 {
        let d = p - self.centre(end);
        let h = d.dot(self.axis);
        let rho = (d - self.axis * h).length();
        (rho - self.radius).hypot(h)
    }

    /// A point on the rim at end `end` (for messages).
    fn rim_point(&self, end: usize) -> DVec3 {
        self.centre(end) + self.x * self.radius
    }

    /// ±1: the face at end `end` runs away from the rim outward from the axis (+1, a hole's
    /// mouth or a boss's foot) or inward (−1, a boss's top or a pocket's floor).
    fn plane_side(&self, end: usize, normal: DVec3) -> f64 {
        let along = self.wall_side(end);
        // The face's material is inside the circle where the wall's material and the face's
        // run the same way: n_f · m_C < 0 on the material side of a boss (+1), > 0 of a hole.
        if self.outward * -normal.dot(self.axis * along) > 0.0 {
            -1.0
        } else {
            1.0
        }
    }

    /// ±1: the wall runs from the rim at end `end` up the axis (+1) or down it (−1).
    fn wall_side(&self, end: usize) -> f64 {
        (self.ends[1 - end].height - self.ends[end].height).signum()
    }
}

/// Points along a space curve's domain, ends included.
fn samples(curve: &SpaceCurve, n: usize) -> Result<Vec<DVec3>, GeometryError> {
    let (t0, t1) = curve.domain();
    (0..=n)
        .map(|i| curve.point_at(t0 + (t1 - t0) * i as f64 / n as f64))
        .collect()
}

/// The walls of `solid`'s kept faces, taken out of it: their cylinder faces out of
/// `solid.kept`, their rims out of the flat faces' kept loops. Kept faces that do not make up
/// such a wall stay as they are.
pub fn take_walls(solid: &mut Polyhedron, tolerance: f64) -> Result<Vec<Wall>, GeometryError> {
    // Each kept face that is a piece of a cylinder: its axis, radius and outward side.
    let mut pieces: Vec<(usize, DVec3, DVec3, f64, f64)> = Vec::new();
    for (k, face) in solid.kept.iter().enumerate() {
        let s = face.surface();
        let Some((c, n)) = revolution_axis(s, tolerance) else {
            continue;
        };
        let [(u0, u1), (v0, v1)] = s.domain();
        let radius_at = |p: DVec3| (p - c).reject_from(n).length();
        let mut radii = Vec::new();
        for i in 0..=4 {
            for j in 0..=4 {
                let (u, v) = (
                    u0 + (u1 - u0) * i as f64 / 4.0,
                    v0 + (v1 - v0) * j as f64 / 4.0,
                );
                radii.push(radius_at(s.point_at(u, v)?));
            }
        }
        let r = radii[0];
        if r <= tolerance || radii.iter().any(|q| (q - r).abs() > tolerance) {
            continue;
        }
        let (u, v) = (0.5 * (u0 + u1), 0.5 * (v0 + v1));
        let p = s.point_at(u, v)?;
        let radial = (p - c).reject_from(n).normalize_or_zero();
        let side = s.normal(u, v)?.dot(radial).signum();
        pieces.push((k, c, n, r, side));
    }
    let mut walls = Vec::new();
    let mut taken_faces = Vec::new();
    let mut taken_loops: Vec<(usize, usize)> = Vec::new();
    let mut used = vec![false; pieces.len()];
    for i in 0..pieces.len() {
        if used[i] {
            continue;
        }
        let (_, c, n, r, side) = pieces[i];
        let same = |&(_, c2, n2, r2, side2): &(usize, DVec3, DVec3, f64, f64)| {
            n2.cross(n).length() < 1e-7
                && (c2 - c).reject_from(n).length() <= tolerance
                && (r2 - r).abs() <= tolerance
                && side2 == side
        };
        let group: Vec<usize> = (i..pieces.len())
            .filter(|&j| !used[j] && same(&pieces[j]))
            .collect();
        // The rims: kept loops of flat faces square to the axis that are the circle.
        let mut ends = Vec::new();
        for (f, facet) in solid.faces.iter().enumerate() {
            if facet.normal.cross(n).length() > 1e-7 {
                continue;
            }
            for (l, ring) in facet.kept.iter().enumerate() {
                let mut points = Vec::new();
                for curve in ring {
                    points.extend(samples(curve, 8)?);
                }
                let h0 = (points[0] - c).dot(n);
                if points.iter().all(|&p| {
                    ((p - c).reject_from(n).length() - r).abs() <= tolerance
                        && ((p - c).dot(n) - h0).abs() <= tolerance
                }) {
                    ends.push((f, l, h0));
                }
            }
        }
        if ends.len() != 2 || (ends[0].2 - ends[1].2).abs() <= 10.0 * tolerance {
            continue;
        }
        let (lo, hi) = (ends[0].2.min(ends[1].2), ends[0].2.max(ends[1].2));
        // The pieces must make the whole band between the rims: nothing beyond them, and the
        // area of the full band.
        let faces: Vec<TrimmedSurface> = group
            .iter()
            .map(|&j| solid.kept[pieces[j].0].clone())
            .collect();
        let mut inside = true;
        for face in &faces {
            for ring in face_loops(face)? {
                for curve in &ring {
                    let (t0, t1) = curve.domain();
                    for s in 0..=4 {
                        let uv = curve.point_at(t0 + (t1 - t0) * s as f64 / 4.0)?;
                        let h = (face.surface().point_at_clamped(uv)? - c).dot(n);
                        inside &= h >= lo - tolerance && h <= hi + tolerance;
                    }
                }
            }
        }
        let band = TAU * r * (hi - lo);
        if !inside || (area(&faces)? - band).abs() > 1e-6 * band + tolerance * r {
            continue;
        }
        for &j in &group {
            used[j] = true;
            taken_faces.push(pieces[j].0);
        }
        taken_loops.extend(ends.iter().map(|&(f, l, _)| (f, l)));
        let x = {
            let a = if n.x.abs() < 0.9 { DVec3::X } else { DVec3::Y };
            a.reject_from(n).normalize()
        };
        walls.push(Wall {
            origin: c,
            axis: n,
            x,
            radius: r,
            outward: side,
            ends: [
                RimEnd {
                    facet: ends[0].0,
                    height: ends[0].2,
                },
                RimEnd {
                    facet: ends[1].0,
                    height: ends[1].2,
                },
            ],
        });
    }
    taken_faces.sort_unstable();
    for k in taken_faces.into_iter().rev() {
        solid.kept.remove(k);
    }
    taken_loops.sort_unstable();
    for (f, l) in taken_loops.into_iter().rev() {
        solid.faces[f].kept.remove(l);
    }
    Ok(walls)
}

/// A rim a feature takes: wall `wall`, end `end`.
pub type Rim = (usize, usize);

/// The walls of a feature: each wall rebuilt (its rims set back where `picked` takes them),
/// the fillet or chamfer of each picked rim, and each end's new circle with the flat face it
/// bounds (to be pushed onto that face's kept loops). `setback` is the polygonal edges' set-back on each face (the edges of
/// face f from vertex a to b, set back by d), to check that a rim's new circle keeps clear of
/// them.
pub fn build_walls(
    solid: &Polyhedron,
    walls: &[Wall],
    picked: &[Rim],
    feature: EdgeFeature,
    setback: &dyn Fn(usize, usize, usize) -> f64,
    tolerance: f64,
) -> Result<WallFaces, GeometryError> {
    let what = match feature {
        EdgeFeature::Fillet { .. } => "fillet",
        EdgeFeature::Chamfer { .. } => "chamfer",
    };
    let mut out = Vec::new();
    let mut circles: Vec<(usize, DVec3, f64)> = Vec::new();
    for (w, wall) in walls.iter().enumerate() {
        let radial = |p: DVec3| (p - wall.origin).reject_from(wall.axis).normalize_or_zero();
        let mut heights = [wall.ends[0].height, wall.ends[1].height];
        for (end, height) in heights.iter_mut().enumerate() {
            let facet = &solid.faces[wall.ends[end].facet];
            let normal = facet.normal;
            let sp = wall.plane_side(end, normal);
            let sc = wall.wall_side(end);
            let rim = wall.rim_point(end);
            let at = || point(rim);
            let (on_plane, on_wall) = if picked.contains(&(w, end)) {
                match feature {
                    EdgeFeature::Fillet { radius } => (radius, radius),
                    EdgeFeature::Chamfer { distance, other } => (distance, other),
                }
            } else {
                (0.0, 0.0)
            };
            let new_radius = wall.radius + sp * on_plane;
            if new_radius <= 10.0 * tolerance {
                return Err(construction(
                    WHAT,
                    format!(
                        "the {what} is too large for the rim through {}: it is wider than the \
                         circle's radius {:.6}",
                        at(),
                        wall.radius
                    ),
                ));
            }
            *height += sc * on_wall;
            let centre = wall.centre(end);
            // The new circle keeps clear of the face's edges (set back where they take a
            // feature) and its other loops.
            let clear = |p: DVec3, margin: f64| {
                let rho = (p - centre).reject_from(wall.axis).length();
                if rho > new_radius + margin + tolerance {
                    Some(1.0)
                } else if rho < new_radius - margin - tolerance {
                    Some(-1.0)
                } else {
                    None
                }
            };
            let mut sides = Vec::new();
            for ring in &facet.loops {
                for i in 0..ring.len() {
                    let (a, b) = (ring[i], ring[(i + 1) % ring.len()]);
                    let margin = setback(wall.ends[end].facet, a, b);
                    let (pa, pb) = (solid.vertices[a], solid.vertices[b]);
                    // The nearest point of the segment to the axis, and its ends.
                    let d = pb - pa;
                    let t = ((centre - pa).dot(d) / d.length_squared().max(f64::MIN_POSITIVE))
                        .clamp(0.0, 1.0);
                    for p in [pa, pb, pa + d * t] {
                        sides.push(clear(p, margin));
                    }
                }
            }
            for ring in &facet.kept {
                for curve in ring {
                    for p in samples(curve, 16)? {
                        sides.push(clear(p, 0.0));
                    }
                }
            }
            for &(f, c, r) in &circles {
                if f == wall.ends[end].facet {
                    let gap = c.distance(centre);
                    if !(gap > r + new_radius + tolerance
                        || gap + r < new_radius - tolerance
                        || gap + new_radius < r - tolerance)
                    {
                        sides.push(None);
                    }
                }
            }
            if sides.iter().any(|s| s.is_none() || *s != sides[0]) {
                return Err(construction(
                    WHAT,
                    format!(
                        "the {what} of the rim through {} runs into another edge of its face",
                        at()
                    ),
                ));
            }
            circles.push((wall.ends[end].facet, centre, new_radius));
            if on_plane > 0.0 {
                let edge = rim;
                let (mp, mc) = (radial(edge) * sp, wall.axis * sc);
                let section = match feature {
                    EdgeFeature::Fillet { radius } => {
                        let ball = edge + (mp + mc) * radius;
                        let middle = ball - (mp + mc) * (radius / 2f64.sqrt());
                        arc_through(edge + mp * radius, middle, edge + mc * radius)?
                    }
                    EdgeFeature::Chamfer { distance, other } => {
                        line(edge + mp * distance, edge + mc * other)?
                    }
                };
                let face =
                    TrimmedSurface::untrimmed(revolve(&section, wall.origin, wall.axis, TAU)?);
                let outward = wall.outward;
                out.push(facing(face, |p| normal + radial(p) * outward)?);
            }
        }
        if (heights[1] - heights[0]) * (wall.ends[1].height - wall.ends[0].height)
            <= 10.0 * tolerance * (wall.ends[1].height - wall.ends[0].height).abs()
        {
            return Err(construction(
                WHAT,
                format!(
                    "the {what} is too large for the wall between the rims through {} and {}: \
                     the {what}s at its ends overlap",
                    point(wall.rim_point(0)),
                    point(wall.rim_point(1))
                ),
            ));
        }
        let band = line(
            wall.origin + wall.axis * heights[0] + wall.x * wall.radius,
            wall.origin + wall.axis * heights[1] + wall.x * wall.radius,
        )?;
        let face = TrimmedSurface::untrimmed(revolve(&band, wall.origin, wall.axis, TAU)?);
        let outward = wall.outward;
        out.push(facing(face, |p| radial(p) * outward)?);
    }
    let mut rims = Vec::new();
    for (wall, chunk) in walls.iter().zip(circles.chunks(2)) {
        for &(f, c, r) in chunk {
            rims.push((f, circle(c, wall.axis, wall.x, r)?));
        }
    }
    Ok((out, rims))
}

/// The walls offset for a shell: each flat face `f` moved `face_offset(f)` along its outward
/// normal and each wall `w` by `wall_offset(w)` (its radius grown by that where its material
/// is inside, shrunk where outside), each wall rebuilt between its end faces' new planes
/// (the height along the axis where a plane moved by δ meets it changes by δ / (n · axis)),
/// and each end's new circle with the flat face it bounds; refused where a circle closes up
/// or a wall's ends pass each other (the offset is more than the body allows there).
pub fn offset_walls(
    solid: &Polyhedron,
    walls: &[Wall],
    face_offset: &dyn Fn(usize) -> f64,
    wall_offset: &dyn Fn(usize) -> f64,
    tolerance: f64,
) -> Result<WallFaces, GeometryError> {
    let mut out = Vec::new();
    let mut rims = Vec::new();
    for (w, wall) in walls.iter().enumerate() {
        let radius = wall.radius + wall.outward * wall_offset(w);
        if radius <= 10.0 * tolerance {
            return Err(construction(
                WHAT,
                format!(
                    "the wall is thicker than the body allows: the round wall through {} closes up",
                    point(wall.rim_point(0))
                ),
            ));
        }
        let mut heights = [0.0; 2];
        for (end, height) in heights.iter_mut().enumerate() {
            let f = wall.ends[end].facet;
            let along = solid.faces[f].normal.dot(wall.axis);
            *height = wall.ends[end].height + face_offset(f) / along;
            let centre = wall.origin + wall.axis * *height;
            rims.push((f, circle(centre, wall.axis, wall.x, radius)?));
        }
        if (heights[1] - heights[0]) * (wall.ends[1].height - wall.ends[0].height) <= 0.0 {
            return Err(construction(
                WHAT,
                format!(
                    "the wall is thicker than the body allows: the round wall through {}                      vanishes",
                    point(wall.rim_point(0))
                ),
            ));
        }
        let band = line(
            wall.origin + wall.axis * heights[0] + wall.x * radius,
            wall.origin + wall.axis * heights[1] + wall.x * radius,
        )?;
        let face = TrimmedSurface::untrimmed(revolve(&band, wall.origin, wall.axis, TAU)?);
        let (origin, axis, outward) = (wall.origin, wall.axis, wall.outward);
        out.push(facing(face, |p| {
            (p - origin).reject_from(axis).normalize_or_zero() * outward
        })?);
    }
    Ok((out, rims))
}

/// The distance from `p` to wall `wall`'s band (its radial distance where `p` lies between
/// the rims, else the nearer rim's).
pub fn wall_distance(wall: &Wall, p: DVec3) -> f64 {
    let h = (p - wall.origin).dot(wall.axis);
    let (lo, hi) = (
        wall.ends[0].height.min(wall.ends[1].height),
        wall.ends[0].height.max(wall.ends[1].height),
    );
    if h >= lo && h <= hi {
        ((p - wall.origin).reject_from(wall.axis).length() - wall.radius).abs()
    } else {
        wall.rim_distance(0, p).min(wall.rim_distance(1, p))
    }
}

/// The faces [`build_walls`] makes, and the circles it gives the flat faces.
pub type WallFaces = (Vec<TrimmedSurface>, Vec<(usize, SpaceCurve)>);

/// The polyhedral edges and the rims that `pick` names: every one, or for each point the
/// edge or rim nearest it.
pub fn picked_with_rims(
    solid: &Polyhedron,
    walls: &[Wall],
    pick: &EdgePick,
) -> Result<(Vec<usize>, Vec<Rim>), GeometryError> {
    let all_rims = || (0..walls.len()).flat_map(|w| [(w, 0), (w, 1)]);
    let (mut edges, mut rims): (Vec<usize>, Vec<Rim>) = match pick {
        EdgePick::All => ((0..solid.edges.len()).collect(), all_rims().collect()),
        EdgePick::Near(points) => {
            let (mut edges, mut rims) = (Vec::new(), Vec::new());
            for &p in points {
                if !p.is_finite() {
                    return Err(construction(WHAT, "a picking point is not a finite number"));
                }
                let edge = solid
                    .nearest_edge(p)
                    .map(|k| (solid.edge_distance(k, p), k));
                let rim = all_rims()
                    .map(|(w, end)| (walls[w].rim_distance(end, p), (w, end)))
                    .min_by(|a, b| a.0.total_cmp(&b.0));
                match (edge, rim) {
                    (Some((d, _)), Some((e, r))) if e < d => rims.push(r),
                    (None, Some((_, r))) => rims.push(r),
                    (Some((_, k)), _) => edges.push(k),
                    (None, None) => return Err(construction(WHAT, "the solid has no edges")),
                }
            }
            (edges, rims)
        }
    };
    edges.sort_unstable();
    edges.dedup();
    rims.sort_unstable();
    rims.dedup();
    if edges.is_empty() && rims.is_empty() {
        return Err(construction(WHAT, "no edge is picked"));
    }
    Ok((edges, rims))
}
