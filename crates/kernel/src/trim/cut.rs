//! Trimming a surface along a curve in its (u, v) domain: the part on one side of the curve
//! is kept. An open curve must run from the domain's boundary to its boundary (ends a little
//! inside are carried on along their end tangent to it); the kept region is then closed by the
//! boundary walked counter-clockwise (the curve's left) or clockwise (its right). A closed
//! curve keeps its inside or its outside. The curve is the cubic through the given points
//! (chord-length parameters; The NURBS Book §9.2.1), closed and C² for a loop.

use glam::DVec2;

use super::{TrimLoop, TrimmedSurface, domain_rect, domain_size, polygon_contains, shapes};
use crate::error::GeometryError;
use crate::error::construction;
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

const WHAT: &str = "trim";

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
/// on a trimmed one, an open cut keeps the loops on the kept side, or where it crosses one,
/// the part next to its middle of what both keep; a closed cut toggles the region it encloses
/// and may cross no loop.
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
    // Keep the existing loops on the kept side; where the cut crosses one, the part next to
    // the cut's middle of what both keep.
    let polygon = side_polygon(rect, &points, keep);
    let mut loops = vec![region];
    for l in surface.loops() {
        let flat = super::flatten_loop(l, CROSSING_FLATNESS * domain_size(rect));
        if flat.iter().all(|&p| polygon_contains(&polygon, p)) {
            loops.push(l.clone());
        } else if flat.iter().any(|&p| polygon_contains(&polygon, p)) {
            let beside = beside_middle(&points, keep, domain_size(rect));
            return kept_within_trims(surface, &loops[..1], beside);
        }
    }
    TrimmedSurface::new(surface.surface().clone(), loops)
}

/// One cutting curve in a surface's (u, v) domain: points along it, open (running from the
/// boundary to the boundary) or closed (the first point not repeated at the end).
#[derive(Debug, Clone, PartialEq)]
pub struct Cut {
    pub points: Vec<DVec2>,
    pub closed: bool,
}

/// Open cuts whose ends meet (within `gap`) joined into one, and a chain that comes back to
/// its start closed: an intersection curve is cut where it crosses the other surface's seam
/// or patch boundary, which means nothing on this surface.
pub fn chain_cuts(cuts: Vec<Cut>, gap: f64) -> Vec<Cut> {
    let (mut open, mut out): (Vec<Cut>, Vec<Cut>) = cuts.into_iter().partition(|c| !c.closed);
    while let Some(mut chain) = open.pop() {
        loop {
            let (first, last) = (chain.points[0], chain.points[chain.points.len() - 1]);
            let found = open.iter().enumerate().find_map(|(k, c)| {
                let (a, b) = (c.points[0], c.points[c.points.len() - 1]);
                if a.distance(last) <= gap {
                    Some((k, false, false))
                } else if b.distance(last) <= gap {
                    Some((k, true, false))
                } else if b.distance(first) <= gap {
                    Some((k, false, true))
                } else if a.distance(first) <= gap {
                    Some((k, true, true))
                } else {
                    None
                }
            });
            let Some((k, reverse, before)) = found else {
                break;
            };
            let mut next = open.swap_remove(k).points;
            if reverse {
                next.reverse();
            }
            if before {
                next.pop();
                next.extend(chain.points);
                chain.points = next;
            } else {
                chain.points.extend(next.into_iter().skip(1));
            }
        }
        let n = chain.points.len();
        if n > 3 && chain.points[0].distance(chain.points[n - 1]) <= gap {
            chain.points.pop();
            chain.closed = true;
        }
        out.push(chain);
    }
    out
}

/// The open cuts as chords from boundary to boundary, and the closed ones as polygons.
fn prepared(rect: [f64; 4], cuts: &[Cut]) -> Result<Prepared, GeometryError> {
    let mut chords = Vec::new();
    let mut rings = Vec::new();
    for cut in cuts {
        let points = thinned(&cut.points, cut.closed);
        if cut.closed {
            if points.len() >= 3 {
                rings.push(points);
            }
        } else {
            chords.push(open_cut(rect, &points)?);
        }
    }
    Ok(Prepared { chords, rings })
}

/// The cuts made ready: open ones as chords from boundary to boundary, closed ones as rings.
struct Prepared {
    chords: Vec<Vec<DVec2>>,
    rings: Vec<Vec<DVec2>>,
}

/// The region the cuts leave around a point: its outer loop (`None`: the whole domain), that
/// loop as a polygon, and its holes.
struct Region {
    outer: Option<TrimLoop>,
    outline: Vec<DVec2>,
    holes: Vec<TrimLoop>,
}

/// The points without those closer than a fifth of the median spacing to the one kept before
/// them (and, closed, to the first): a marching step cut short at a boundary or at the loop's
/// close would make the interpolating cubic swing.
fn thinned(points: &[DVec2], closed: bool) -> Vec<DVec2> {
    let mut steps: Vec<f64> = points.windows(2).map(|w| w[0].distance(w[1])).collect();
    if steps.is_empty() {
        return points.to_vec();
    }
    steps.sort_by(f64::total_cmp);
    let least = 0.2 * steps[steps.len() / 2];
    let mut out: Vec<DVec2> = Vec::with_capacity(points.len());
    let last = points.len() - 1;
    for (k, &p) in points.iter().enumerate() {
        let keep_end = !closed && k == last;
        match out.last() {
            Some(&q) if q.distance(p) < least && !keep_end => {}
            Some(&q) if q.distance(p) < least => {
                // An open curve keeps its end: the point before it goes instead.
                if out.len() > 1 {
                    out.pop();
                }
                out.push(p);
            }
            _ => out.push(p),
        }
    }
    if closed {
        while out.len() > 3 && out[out.len() - 1].distance(out[0]) < least {
            out.pop();
        }
    }
    out
}

/// The point half-way along a polyline (by its points).
fn middle(points: &[DVec2]) -> DVec2 {
    let n = points.len();
    if n % 2 == 1 {
        points[n / 2]
    } else {
        0.5 * (points[n / 2 - 1] + points[n / 2])
    }
}

/// The region of the domain that the cuts leave around `keep`, as its loops: the outer loop
/// (bounded by the chords nearest `keep` and the domain's boundary between them, or the
/// innermost closed cut around `keep`), and the closed cuts inside it as holes. `None` for
/// the outer loop where it is the whole domain.
fn region_loops(
    rect: [f64; 4],
    chords: &[Vec<DVec2>],
    rings: &[Vec<DVec2>],
    keep: DVec2,
) -> Result<Region, GeometryError> {
    let size = domain_size(rect);
    let [u0, u1, v0, v1] = rect;
    let whole = vec![
        DVec2::new(u0, v0),
        DVec2::new(u1, v0),
        DVec2::new(u1, v1),
        DVec2::new(u0, v1),
    ];
    // The innermost closed cut around `keep`, if any: the region is inside it.
    let around = rings
        .iter()
        .filter(|r| polygon_contains(r, keep))
        .min_by(|a, b| {
            super::signed_area(a)
                .abs()
                .total_cmp(&super::signed_area(b).abs())
        });
    let (outer, outline): (Option<TrimLoop>, Vec<DVec2>) = if let Some(ring) = around {
        (Some(vec![cut_curve(ring, true)?]), ring.clone())
    } else {
        // Each chord's side holding `keep`; a chord bounds the region when it lies on the
        // kept side of every other chord.
        let sides: Vec<(Keep, Vec<DVec2>)> = chords
            .iter()
            .map(|c| {
                let left = side_polygon(rect, c, Keep::Left);
                if polygon_contains(&left, keep) {
                    (Keep::Left, left)
                } else {
                    (Keep::Right, side_polygon(rect, c, Keep::Right))
                }
            })
            .collect();
        let bounding: Vec<usize> = (0..chords.len())
            .filter(|&c| {
                (0..chords.len())
                    .all(|d| d == c || polygon_contains(&sides[d].1, middle(&chords[c])))
            })
            .collect();
        if bounding.is_empty() {
            (None, whole.clone())
        } else {
            // Each bounding chord walked with the region on its left: (entry, exit, points).
            let walked: Vec<(f64, f64, Vec<DVec2>)> = bounding
                .iter()
                .map(|&c| {
                    let mut points = chords[c].clone();
                    if sides[c].0 == Keep::Right {
                        points.reverse();
                    }
                    let (a, b) = (points[0], points[points.len() - 1]);
                    (
                        perimeter_position(rect, a),
                        perimeter_position(rect, b),
                        points,
                    )
                })
                .collect();
            let mut region: TrimLoop = Vec::new();
            let mut outline = Vec::new();
            let mut at = 0usize;
            for _ in 0..walked.len() {
                let (_, exit, points) = &walked[at];
                region.push(cut_curve(points, false)?);
                outline.extend_from_slice(&points[..points.len() - 1]);
                // The next chord met walking the boundary counter-clockwise from the exit.
                let ahead = |s: f64| (s - exit).rem_euclid(4.0);
                let next = (0..walked.len())
                    .min_by(|&x, &y| ahead(walked[x].0).total_cmp(&ahead(walked[y].0)))
                    .unwrap_or(at);
                let mut from = points[points.len() - 1];
                for corner in boundary_walk(rect, *exit, walked[next].0, true) {
                    if corner.distance(from) > 1e-12 * size {
                        region.push(shapes::line(from, corner)?);
                        outline.push(from);
                    }
                    from = corner;
                }
                at = next;
                if at == 0 {
                    break;
                }
            }
            (Some(region), outline)
        }
    };
    // Closed cuts inside the region (and not around `keep`) are holes; a closed cut inside
    // such a hole is not (it bounds another part).
    let candidates: Vec<&Vec<DVec2>> = rings
        .iter()
        .filter(|ring| {
            !std::ptr::eq(*ring, around.map_or(std::ptr::null(), |r| r as *const _))
                && !polygon_contains(ring, keep)
                && ring.iter().all(|&p| polygon_contains(&outline, p))
        })
        .collect();
    let mut holes = Vec::new();
    for ring in &candidates {
        let nested = candidates
            .iter()
            .any(|other| !std::ptr::eq(*other, *ring) && polygon_contains(other, ring[0]));
        if !nested {
            holes.push(vec![cut_curve(ring, true)?]);
        }
    }
    Ok(Region {
        outer,
        outline,
        holes,
    })
}

/// The part of `surface` that `cuts` leave around `keep` (a point of its domain): the user's
/// pick of what to keep. The surface's own trims are kept where they lie inside that part;
/// where the cuts cross one, the part around `keep` of what both keep
/// ([`kept_within_trims`]).
pub fn keep_region(
    surface: &TrimmedSurface,
    cuts: &[Cut],
    keep: DVec2,
) -> Result<TrimmedSurface, GeometryError> {
    let rect = domain_rect(surface.surface());
    // A point on the domain's edge (a pole picked) is taken a hair inside it.
    let centre = DVec2::new(0.5 * (rect[0] + rect[1]), 0.5 * (rect[2] + rect[3]));
    let keep = keep + (centre - keep) * 1e-7;
    let Prepared { chords, rings } = prepared(rect, cuts)?;
    let Region {
        outer,
        outline,
        holes,
    } = region_loops(rect, &chords, &rings, keep)?;
    if outer.is_none() && holes.is_empty() {
        return Err(construction(
            WHAT,
            "the curves do not cut the surface into parts: nothing to trim",
        ));
    }
    // Holes in the whole domain: the domain's outline is the outer loop.
    let outer = match outer {
        Some(o) => Some(o),
        None => {
            let [u0, u1, v0, v1] = rect;
            Some(shapes::rectangle(DVec2::new(u0, v0), DVec2::new(u1, v1))?)
        }
    };
    // The kept part is the region ∩ what the surface kept: its trims inside the region stay,
    // and the region's own outline only where the surface keeps the ground just inside it.
    let mut kept_old = Vec::new();
    let flatness = CROSSING_FLATNESS * domain_size(rect);
    let hole_polygons: Vec<Vec<DVec2>> = holes
        .iter()
        .map(|h| super::flatten_loop(h, flatness))
        .collect();
    let in_region = |p: DVec2| {
        polygon_contains(&outline, p) && !hole_polygons.iter().any(|h| polygon_contains(h, p))
    };
    for l in surface.loops() {
        let flat = super::flatten_loop(l, flatness);
        let gap = END_GAP * domain_size(rect);
        if flat.iter().all(|&p| on_boundary(rect, p, gap)) {
            // The domain's own outline (an outer loop round the whole domain): the region's
            // outline replaces it.
            continue;
        }
        let inside = flat.iter().filter(|&&p| in_region(p)).count();
        if inside == flat.len() {
            kept_old.push(l.clone());
        } else if inside > 0 {
            // The cuts cross the surface's trims (a second trim): the part around `keep` of
            // what both keep.
            let region: Vec<TrimLoop> = outer.into_iter().chain(holes).collect();
            return kept_within_trims(surface, &region, keep);
        }
    }
    let outer = outer.filter(|_| {
        just_inside(&outline, domain_size(rect)).is_none_or(|p| surface.contains(p.x, p.y))
    });
    // A new hole where the surface keeps nothing already (inside one of its holes) would
    // make that ground kept again by the even-odd rule: it goes.
    let holes = holes
        .into_iter()
        .zip(&hole_polygons)
        .filter(|(_, polygon)| {
            just_inside(polygon, domain_size(rect)).is_none_or(|p| surface.contains(p.x, p.y))
        })
        .map(|(hole, _)| hole);
    let loops: Vec<TrimLoop> = outer.into_iter().chain(holes).chain(kept_old).collect();
    if loops.is_empty() {
        return Err(construction(WHAT, "nothing of the surface is left there"));
    }
    TrimmedSurface::new(surface.surface().clone(), loops)
}

/// The chord tolerance (a fraction of the domain's size) of the loops a trim across a
/// surface's own trims makes.
const CROSSING_FLATNESS: f64 = 1e-6;

/// The part around `keep` of what both `region` (loops in `surface`'s domain, kept by the
/// even-odd rule as trims are) and `surface`'s own trims keep: a trim that crosses the
/// surface's trims (a second cut into a trimmed surface, a fillet trimming a trimmed face).
/// Both are flattened to polygons within [`CROSSING_FLATNESS`] of the domain's size and
/// intersected (i_overlay's boolean operations, robust where the two share runs of the
/// domain's boundary); each loop of the part becomes one straight-sided trim curve.
fn kept_within_trims(
    surface: &TrimmedSurface,
    region: &[TrimLoop],
    keep: DVec2,
) -> Result<TrimmedSurface, GeometryError> {
    use i_overlay::core::{fill_rule::FillRule, overlay_rule::OverlayRule};
    use i_overlay::float::single::SingleFloatOverlay;
    let rect = domain_rect(surface.surface());
    let tolerance = CROSSING_FLATNESS * domain_size(rect);
    let contours = |loops: &[TrimLoop]| -> Vec<Vec<[f64; 2]>> {
        loops
            .iter()
            .map(|l| {
                super::flatten_loop(l, tolerance)
                    .iter()
                    .map(|p| [p.x, p.y])
                    .collect()
            })
            .collect()
    };
    let own = if surface.is_trimmed() {
        contours(surface.loops())
    } else {
        let [u0, u1, v0, v1] = rect;
        vec![vec![[u0, v0], [u1, v0], [u1, v1], [u0, v1]]]
    };
    let parts = contours(region).overlay(&own, OverlayRule::Intersect, FillRule::EvenOdd);
    let points = |contour: &Vec<[f64; 2]>| -> Vec<DVec2> {
        contour.iter().map(|&[u, v]| DVec2::new(u, v)).collect()
    };
    // Each part is its outer contour, then its holes.
    let around = parts.iter().find(|part| {
        part.split_first().is_some_and(|(outer, holes)| {
            polygon_contains(&points(outer), keep)
                && holes.iter().all(|h| !polygon_contains(&points(h), keep))
        })
    });
    let Some(part) = around else {
        return Err(construction(WHAT, "nothing of the surface is left there"));
    };
    let loops = part
        .iter()
        .map(|contour| polyline_loop(&points(contour)))
        .collect::<Result<Vec<_>, _>>()?;
    TrimmedSurface::new(surface.surface().clone(), loops)
}

/// The closed polygon through `points` as one degree-1 trim curve (chord-length knots), back
/// to its first point.
fn polyline_loop(points: &[DVec2]) -> Result<TrimLoop, GeometryError> {
    if points.len() < 3 {
        return Err(construction(
            WHAT,
            "a loop of the trimmed part is degenerate",
        ));
    }
    let mut closed = points.to_vec();
    closed.push(points[0]);
    let mut knots = vec![0.0, 0.0];
    let mut length = 0.0;
    for w in closed.windows(2).take(closed.len() - 2) {
        length += w[0].distance(w[1]);
        knots.push(length);
    }
    length += closed[closed.len() - 2].distance(closed[closed.len() - 1]);
    knots.extend([length, length]);
    Ok(vec![crate::TrimCurve::new(1, knots, closed, None)?])
}

/// A point a little to the `keep` side of the cut through `points` (1e-5 of the domain's
/// size from its middle point, more than a flattened loop strays).
fn beside_middle(points: &[DVec2], keep: Keep, size: f64) -> DVec2 {
    let k = (points.len() / 2).min(points.len().saturating_sub(2));
    let (a, b) = (points[k], points[k + 1]);
    let left = (b - a).perp().normalize_or_zero();
    let sign = if keep == Keep::Left { 1.0 } else { -1.0 };
    a + left * sign * 1e-5 * size
}

/// A point a little inside the polygon, next to its first edge.
fn just_inside(polygon: &[DVec2], size: f64) -> Option<DVec2> {
    let (a, b) = (*polygon.first()?, *polygon.get(1)?);
    let m = 0.5 * (a + b);
    let normal = (b - a).perp().normalize_or_zero();
    [1.0, -1.0]
        .into_iter()
        .map(|side| m + normal * side * 1e-7 * size)
        .find(|&p| polygon_contains(polygon, p))
}

/// The parts `cuts` divide `surface` into (each a trimmed surface), in the order the cuts
/// first border them.
pub fn split_by(
    surface: &TrimmedSurface,
    cuts: &[Cut],
) -> Result<Vec<TrimmedSurface>, GeometryError> {
    let rect = domain_rect(surface.surface());
    let Prepared { chords, rings } = prepared(rect, cuts)?;
    let size = domain_size(rect);
    // A point just either side of each cut's middle picks each part next to it.
    let mut probes = Vec::new();
    for points in chords.iter().chain(&rings) {
        let n = points.len();
        let k = n / 2;
        let (a, b) = (points[k.saturating_sub(1)], points[(k + 1).min(n - 1)]);
        let normal = (b - a).perp().normalize_or_zero();
        for side in [1.0, -1.0] {
            probes.push(points[k] + normal * side * 1e-6 * size);
        }
    }
    let signature = |p: DVec2| -> Vec<bool> {
        chords
            .iter()
            .map(|c| polygon_contains(&side_polygon(rect, c, Keep::Left), p))
            .chain(rings.iter().map(|r| polygon_contains(r, p)))
            .collect()
    };
    let mut seen: Vec<Vec<bool>> = Vec::new();
    let mut parts = Vec::new();
    for p in probes {
        let s = signature(p);
        if seen.contains(&s) {
            continue;
        }
        seen.push(s);
        parts.push(keep_region(surface, cuts, p)?);
    }
    if parts.len() < 2 {
        return Err(construction(
            WHAT,
            "the curves do not cut the surface into parts: nothing to split",
        ));
    }
    Ok(parts)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::construct;
    use glam::DVec3;

    fn square() -> TrimmedSurface {
        TrimmedSurface::untrimmed(construct::plane(DVec3::ZERO, DVec3::X, DVec3::Y).unwrap())
    }

    /// Points round the circle about `c` of radius `r`, counter-clockwise.
    fn circle_points(c: DVec2, r: f64, n: usize) -> Vec<DVec2> {
        (0..n)
            .map(|i| {
                let a = std::f64::consts::TAU * i as f64 / n as f64;
                c + r * DVec2::new(a.cos(), a.sin())
            })
            .collect()
    }

    /// A cut across the surface's own trims keeps what both keep around the point picked:
    /// a chord through a hole, a circle across an earlier chord, a second circle across the
    /// first; the areas are the closed forms (circular segments and lenses).
    #[test]
    fn a_second_cut_across_the_trims_keeps_what_both_keep() {
        use std::f64::consts::PI;
        let segment = |r: f64, d: f64| r * r * (d / r).acos() - d * (r * r - d * d).sqrt();
        let area = |t: &TrimmedSurface| t.parameter_area(1e-7);
        let line = |x: f64| Cut {
            points: vec![DVec2::new(x, 0.0), DVec2::new(x, 1.0)],
            closed: false,
        };
        let ring = |c: DVec2, r: f64| Cut {
            points: circle_points(c, r, 64),
            closed: true,
        };
        // A hole of radius 0.1 at (0.3, 0.5), then the chord x = 0.35 through it: the left.
        let holed = keep_region(
            &square(),
            &[ring(DVec2::new(0.3, 0.5), 0.1)],
            DVec2::new(0.9, 0.9),
        )
        .unwrap();
        let left = keep_region(&holed, &[line(0.35)], DVec2::new(0.1, 0.1)).unwrap();
        let exact = 0.35 - (PI * 0.01 - segment(0.1, 0.05));
        assert!(
            (area(&left) - exact).abs() < 1e-5,
            "{} {exact}",
            area(&left)
        );
        assert!(!left.contains(0.3, 0.5) && left.contains(0.1, 0.1) && !left.contains(0.5, 0.1));
        // The chord x = 0.6 kept left, then the circle about (0.6, 0.5) of radius 0.3 kept
        // inside: half the disc.
        let half = keep_region(&square(), &[line(0.6)], DVec2::new(0.1, 0.5)).unwrap();
        let disc = keep_region(
            &half,
            &[ring(DVec2::new(0.6, 0.5), 0.3)],
            DVec2::new(0.5, 0.5),
        )
        .unwrap();
        assert!(
            (area(&disc) - 0.5 * PI * 0.09).abs() < 1e-5,
            "{}",
            area(&disc)
        );
        // Two overlapping holes: the square less their union (two discs less their lens).
        let first = keep_region(
            &square(),
            &[ring(DVec2::new(0.4, 0.5), 0.2)],
            DVec2::new(0.05, 0.05),
        )
        .unwrap();
        let both = keep_region(
            &first,
            &[ring(DVec2::new(0.6, 0.5), 0.2)],
            DVec2::new(0.05, 0.05),
        )
        .unwrap();
        let lens = 2.0 * segment(0.2, 0.1);
        let exact = 1.0 - (2.0 * PI * 0.04 - lens);
        assert!(
            (area(&both) - exact).abs() < 1e-5,
            "{} {exact}",
            area(&both)
        );
        // Inside the first hole nothing is left.
        assert!(keep_region(&first, &[line(0.45)], DVec2::new(0.4, 0.5)).is_err());
        // A trim along a chord (a fillet's) across the hole: the side asked for, less the
        // hole's part there.
        let along = trim_along(
            &first,
            &[DVec2::new(0.5, 0.0), DVec2::new(0.5, 1.0)],
            false,
            Keep::Right,
        )
        .unwrap();
        let exact = 0.5 - segment(0.2, 0.1);
        assert!(
            (area(&along) - exact).abs() < 1e-5,
            "{} {exact}",
            area(&along)
        );
        assert!(along.contains(0.9, 0.5) && !along.contains(0.2, 0.5));
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

    #[test]
    fn two_chords_and_a_hole_keep_the_part_picked() {
        let s = square();
        let down = |x: f64| {
            vec![
                DVec2::new(x, 0.0),
                DVec2::new(x + 0.05, 0.5),
                DVec2::new(x, 1.0),
            ]
        };
        let ring: Vec<DVec2> = (0..10)
            .map(|i| {
                let a = i as f64 / 10.0 * std::f64::consts::TAU;
                DVec2::new(0.5 + 0.08 * a.cos(), 0.5 + 0.08 * a.sin())
            })
            .collect();
        let cuts = vec![
            Cut {
                points: down(0.3),
                closed: false,
            },
            Cut {
                points: down(0.7),
                closed: false,
            },
            Cut {
                points: ring,
                closed: true,
            },
        ];
        let middle = keep_region(&s, &cuts, DVec2::new(0.5, 0.2)).unwrap();
        assert!(middle.contains(0.5, 0.1) && middle.contains(0.6, 0.9));
        assert!(
            !middle.contains(0.1, 0.5) && !middle.contains(0.9, 0.5) && !middle.contains(0.5, 0.5)
        );
        let left = keep_region(&s, &cuts, DVec2::new(0.1, 0.1)).unwrap();
        assert!(left.contains(0.1, 0.9) && !left.contains(0.5, 0.2));
        let parts = split_by(&s, &cuts).unwrap();
        assert_eq!(parts.len(), 4);
        let area: f64 = parts.iter().map(|p| p.parameter_area(1e-7)).sum();
        assert!((area - 1.0).abs() < 1e-5, "{area}");
    }

    #[test]
    fn a_trimmed_surface_keeps_its_hole_when_cut_again() {
        let ring: Vec<DVec2> = (0..12)
            .map(|i| {
                let a = i as f64 / 12.0 * std::f64::consts::TAU;
                DVec2::new(0.2 + 0.05 * a.cos(), 0.5 + 0.05 * a.sin())
            })
            .collect();
        let holed = trim_along(&square(), &ring, true, Keep::Right).unwrap();
        assert!(!holed.contains(0.2, 0.5));
        let cut = Cut {
            points: vec![DVec2::new(0.6, 0.0), DVec2::new(0.6, 1.0)],
            closed: false,
        };
        let left = keep_region(&holed, std::slice::from_ref(&cut), DVec2::new(0.1, 0.1)).unwrap();
        assert!(left.contains(0.1, 0.1) && !left.contains(0.2, 0.5) && !left.contains(0.8, 0.5));
        let right = keep_region(&holed, &[cut], DVec2::new(0.9, 0.1)).unwrap();
        assert!(right.contains(0.8, 0.5) && !right.contains(0.1, 0.1));
    }
}
