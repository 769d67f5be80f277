//! Trimming a surface along a curve in its (u, v) domain: the part on one side of the curve
//! is kept. An open curve must run from the domain's boundary to its boundary (ends a little
//! inside are carried on along their end tangent to it); the kept region is then closed by the
//! boundary walked counter-clockwise (the curve's left) or clockwise (its right). A closed
//! curve keeps its inside or its outside. The curve is the cubic through the given points
//! (chord-length parameters; The NURBS Book §9.2.1), closed and C² for a loop.

use glam::DVec2;

use super::{TrimLoop, TrimmedSurface, domain_rect, domain_size, polygon_contains, shapes};
use crate::construct::construction;
use crate::error::GeometryError;
use crate::splines::{Parametrization, interpolate_closed, interpolate_through};

/// Which side of a cut curve, looking along it, is kept.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Keep {
    Left,
    Right,
}

impl Keep {
    /// The other side.
    pub fn opposite(self) -> Self {
        match self {
            Keep::Left => Keep::Right,
            Keep::Right => Keep::Left,
        }
    }
}

const WHAT: &str = "trim by a curve";

/// How far (a fraction of the domain's size) an open cut's end may lie from the boundary and
/// still count as on it.
const END_GAP: f64 = 1e-7;

/// The position along the rectangle's boundary, counter-clockwise from (u0, v0): 0–1 the
/// bottom edge, 1–2 the right, 2–3 the top, 3–4 the left.
fn perimeter_position(rect: [f64; 4], p: DVec2) -> f64 {
    let [u0, u1, v0, v1] = rect;
    let (w, h) = (u1 - u0, v1 - v0);
    let distances = [
        (p.y - v0).abs() / h,
        (p.x - u1).abs() / w,
        (p.y - v1).abs() / h,
        (p.x - u0).abs() / w,
    ];
    let side = (0..4)
        .min_by(|&a, &b| distances[a].total_cmp(&distances[b]))
        .unwrap_or(0);
    let t = match side {
        0 => (p.x - u0) / w,
        1 => (p.y - v0) / h,
        2 => (u1 - p.x) / w,
        _ => (v1 - p.y) / h,
    };
    side as f64 + t.clamp(0.0, 1.0)
}

fn perimeter_point(rect: [f64; 4], s: f64) -> DVec2 {
    let [u0, u1, v0, v1] = rect;
    let s = s.rem_euclid(4.0);
    let (side, t) = (s.floor().min(3.0), s - s.floor().min(3.0));
    match side as usize {
        0 => DVec2::new(u0 + t * (u1 - u0), v0),
        1 => DVec2::new(u1, v0 + t * (v1 - v0)),
        2 => DVec2::new(u1 - t * (u1 - u0), v1),
        _ => DVec2::new(u0, v1 - t * (v1 - v0)),
    }
}

/// The boundary's corners met walking from perimeter position `from` to `to`, counter-clockwise
/// (`ccw`) or clockwise, then `to`'s point.
fn boundary_walk(rect: [f64; 4], from: f64, to: f64, ccw: bool) -> Vec<DVec2> {
    let mut out = Vec::new();
    if ccw {
        let end = if to > from { to } else { to + 4.0 };
        let mut corner = from.floor() + 1.0;
        while corner < end {
            out.push(perimeter_point(rect, corner));
            corner += 1.0;
        }
        out.push(perimeter_point(rect, end));
    } else {
        let end = if to < from { to } else { to - 4.0 };
        let mut corner = from.ceil() - 1.0;
        while corner > end {
            out.push(perimeter_point(rect, corner));
            corner -= 1.0;
        }
        out.push(perimeter_point(rect, end));
    }
    out
}

/// Where the ray from `p` along `d` leaves the rectangle (`p` inside).
fn ray_exit(rect: [f64; 4], p: DVec2, d: DVec2) -> Option<DVec2> {
    let [u0, u1, v0, v1] = rect;
    let mut t = f64::INFINITY;
    if d.x > 0.0 {
        t = t.min((u1 - p.x) / d.x);
    } else if d.x < 0.0 {
        t = t.min((u0 - p.x) / d.x);
    }
    if d.y > 0.0 {
        t = t.min((v1 - p.y) / d.y);
    } else if d.y < 0.0 {
        t = t.min((v0 - p.y) / d.y);
    }
    t.is_finite().then(|| {
        let q = p + d * t.max(0.0);
        DVec2::new(q.x.clamp(u0, u1), q.y.clamp(v0, v1))
    })
}

fn on_boundary(rect: [f64; 4], p: DVec2, gap: f64) -> bool {
    let [u0, u1, v0, v1] = rect;
    (p.x - u0).abs() <= gap
        || (p.x - u1).abs() <= gap
        || (p.y - v0).abs() <= gap
        || (p.y - v1).abs() <= gap
}

/// An open cut's points made ready: inside the domain, consecutive duplicates dropped, and
/// each end on the boundary (snapped, or carried on along the end's direction).
fn open_cut(rect: [f64; 4], cut: &[DVec2]) -> Result<Vec<DVec2>, GeometryError> {
    let [u0, u1, v0, v1] = rect;
    let size = domain_size(rect);
    let clamp = |p: DVec2| DVec2::new(p.x.clamp(u0, u1), p.y.clamp(v0, v1));
    let mut points: Vec<DVec2> = Vec::with_capacity(cut.len() + 2);
    for &p in cut {
        if !p.is_finite() {
            return Err(construction(WHAT, "a point of the curve is not finite"));
        }
        let p = clamp(p);
        if points
            .last()
            .is_none_or(|q: &DVec2| q.distance(p) > 1e-12 * size)
        {
            points.push(p);
        }
    }
    if points.len() < 2 {
        return Err(construction(
            WHAT,
            "the curve has fewer than 2 distinct points",
        ));
    }
    let gap = END_GAP * size;
    for end in [0, 1] {
        let n = points.len();
        let (p, q) = if end == 0 {
            (points[0], points[1])
        } else {
            (points[n - 1], points[n - 2])
        };
        if on_boundary(rect, p, gap) {
            continue;
        }
        let exit = ray_exit(rect, p, (p - q).normalize_or_zero())
            .ok_or_else(|| construction(WHAT, "the curve's end has no direction"))?;
        if end == 0 {
            points.insert(0, exit);
        } else {
            points.push(exit);
        }
    }
    Ok(points)
}

/// The (u, v) cubic through `points` (closed: back to the first, which is not repeated).
fn cut_curve(points: &[DVec2], closed: bool) -> Result<crate::TrimCurve, GeometryError> {
    if closed {
        interpolate_closed(points, 3, Parametrization::ChordLength)
    } else {
        interpolate_through(points, 3, Parametrization::ChordLength, None)
    }
}

/// The region left (or right) of an open cut as a polygon: the cut, then the boundary back.
fn side_polygon(rect: [f64; 4], points: &[DVec2], keep: Keep) -> Vec<DVec2> {
    let (first, last) = (points[0], points[points.len() - 1]);
    let (from, to) = (
        perimeter_position(rect, last),
        perimeter_position(rect, first),
    );
    let mut polygon = points.to_vec();
    let mut walk = boundary_walk(rect, from, to, keep == Keep::Left);
    walk.pop();
    polygon.extend(walk);
    polygon
}

/// Which side of the cut `p` lies on.
pub fn side_of(
    surface: &TrimmedSurface,
    cut: &[DVec2],
    closed: bool,
    p: DVec2,
) -> Result<Keep, GeometryError> {
    let rect = domain_rect(surface.surface());
    if closed {
        let inside = polygon_contains(cut, p);
        let ccw = super::signed_area(cut) > 0.0;
        return Ok(if inside == ccw {
            Keep::Left
        } else {
            Keep::Right
        });
    }
    let points = open_cut(rect, cut)?;
    Ok(
        if polygon_contains(&side_polygon(rect, &points, Keep::Left), p) {
            Keep::Left
        } else {
            Keep::Right
        },
    )
}

/// `surface` trimmed along the cut through `cut` ((u, v) points; `closed`: a loop, the first
/// point not repeated at the end), keeping the side `keep`. An untrimmed surface takes any cut;
/// a trimmed one a cut that crosses none of its loops (a closed cut toggles the region it
/// encloses; an open cut keeps the loops on the kept side).
pub fn trim_along(
    surface: &TrimmedSurface,
    cut: &[DVec2],
    closed: bool,
    keep: Keep,
) -> Result<TrimmedSurface, GeometryError> {
    let rect = domain_rect(surface.surface());
    if closed {
        if cut.len() < 3 {
            return Err(construction(WHAT, "a closed curve needs at least 3 points"));
        }
        let curve = cut_curve(cut, true)?;
        let ccw = super::signed_area(cut) > 0.0;
        let keep_inside = (keep == Keep::Left) == ccw;
        return surface.add_loop(vec![curve], keep_inside && !surface.is_trimmed());
    }
    let points = open_cut(rect, cut)?;
    let curve = cut_curve(&points, false)?;
    let (first, last) = (points[0], points[points.len() - 1]);
    let walk = boundary_walk(
        rect,
        perimeter_position(rect, last),
        perimeter_position(rect, first),
        keep == Keep::Left,
    );
    let mut region: TrimLoop = vec![curve];
    let mut at = last;
    for corner in walk {
        if corner.distance(at) > 1e-12 * domain_size(rect) {
            region.push(shapes::line(at, corner)?);
        }
        at = corner;
    }
    if let Some(c) = region.last_mut() {
        // Close exactly onto the cut's start.
        let n = c.count();
        if n >= 2 && c.control_point(n - 1).distance(first) > 0.0 {
            *c = shapes::line(c.control_point(0), first)?;
        }
    }
    if !surface.is_trimmed() {
        return TrimmedSurface::new(surface.surface().clone(), vec![region]);
    }
    // Keep the existing loops on the kept side; a loop the cut crosses is refused by the
    // validation (loops may not cross).
    let polygon = side_polygon(rect, &points, keep);
    let mut loops = vec![region];
    for l in surface.loops() {
        let flat = super::flatten_loop(l, 1e-6 * domain_size(rect));
        if flat.iter().all(|&p| polygon_contains(&polygon, p)) {
            loops.push(l.clone());
        } else if flat.iter().any(|&p| polygon_contains(&polygon, p)) {
            return Err(construction(
                WHAT,
                "the curve crosses the surface's trims; trim the untrimmed surface instead",
            ));
        }
    }
    TrimmedSurface::new(surface.surface().clone(), loops)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::construct;
    use glam::DVec3;

    fn square() -> TrimmedSurface {
        TrimmedSurface::untrimmed(construct::plane(DVec3::ZERO, DVec3::X, DVec3::Y).unwrap())
    }

    #[test]
    fn an_open_cut_keeps_the_side_asked_for() {
        let s = square();
        // A wavy cut from the bottom edge to the top edge, up the middle.
        let cut: Vec<DVec2> = (0..=20)
            .map(|i| {
                let t = i as f64 / 20.0;
                DVec2::new(0.5 + 0.1 * (t * 6.0).sin(), t)
            })
            .collect();
        let left = trim_along(&s, &cut, false, Keep::Left).unwrap();
        assert!(left.contains(0.1, 0.5) && !left.contains(0.9, 0.5));
        let right = trim_along(&s, &cut, false, Keep::Right).unwrap();
        assert!(right.contains(0.9, 0.5) && !right.contains(0.1, 0.5));
        let area = left.parameter_area(1e-6) + right.parameter_area(1e-6);
        assert!((area - 1.0).abs() < 1e-6, "{area}");
        assert_eq!(
            side_of(&s, &cut, false, DVec2::new(0.2, 0.3)).unwrap(),
            Keep::Left
        );
    }

    #[test]
    fn an_open_cut_ending_inside_is_carried_to_the_edge() {
        let s = square();
        let cut = vec![
            DVec2::new(0.3, 0.2),
            DVec2::new(0.5, 0.5),
            DVec2::new(0.7, 0.8),
        ];
        let kept = trim_along(&s, &cut, false, Keep::Right).unwrap();
        assert!(kept.contains(0.9, 0.1) && !kept.contains(0.1, 0.9));
    }

    #[test]
    fn a_cut_across_a_corner_walks_round_the_boundary() {
        let s = square();
        let cut = vec![
            DVec2::new(0.6, 0.0),
            DVec2::new(0.8, 0.2),
            DVec2::new(1.0, 0.4),
        ];
        let corner = trim_along(&s, &cut, false, Keep::Right).unwrap();
        let rest = trim_along(&s, &cut, false, Keep::Left).unwrap();
        assert!(corner.contains(0.95, 0.05) && !corner.contains(0.5, 0.5));
        assert!(rest.contains(0.5, 0.5) && !rest.contains(0.95, 0.05));
    }

    #[test]
    fn a_closed_cut_keeps_its_inside_or_makes_a_hole() {
        let s = square();
        let cut: Vec<DVec2> = (0..12)
            .map(|i| {
                let a = i as f64 / 12.0 * std::f64::consts::TAU;
                DVec2::new(0.5 + 0.2 * a.cos(), 0.5 + 0.2 * a.sin())
            })
            .collect();
        let inside = trim_along(&s, &cut, true, Keep::Left).unwrap();
        assert!(inside.contains(0.5, 0.5) && !inside.contains(0.05, 0.05));
        let hole = trim_along(&s, &cut, true, Keep::Right).unwrap();
        assert!(!hole.contains(0.5, 0.5) && hole.contains(0.05, 0.05));
    }
}
