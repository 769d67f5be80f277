//! Trimmed NURBS surfaces: a surface and trim loops in its (u, v) domain. A loop is a list of
//! trim curves joined end to end; the kept region is the set of points inside an odd number of
//! loops (an outer loop with holes, islands inside holes), so the user never has to orient
//! anything. Loops are validated (closed, inside the domain, not crossing themselves or each
//! other, enclosing area) and normalised on construction: a loop at even nesting depth runs
//! counter-clockwise and one at odd depth clockwise, so the kept region always lies on the left
//! of every curve (what the split and the constrained triangulation rely on).
//!
//! Trims live in (u, v): they follow the surface when its control points move; knot insertion,
//! degree elevation and weights keep them; reversing a direction and swapping u and v map them;
//! splitting cuts them on the split line ([`split`]).

pub mod cut;
pub mod index;
pub mod piece;
pub mod shapes;
pub mod split;
pub mod tess;

use std::fmt;
use std::sync::Arc;

use crate::par::RaceCell;

use glam::DVec2;

use self::index::TrimIndex;
use self::piece::{MonotonePiece, distance_to_segment, monotone_pieces};
use super::error::{GeometryError, Location};
pub use super::error::{TrimProblem, Uv};
use super::surface::DerivativeBounds;
use super::vector::Vector;
use super::{Direction, NurbsSurface, TrimCurve};

/// One closed loop: curves joined end to end.
pub type TrimLoop = Vec<TrimCurve>;

/// Closure tolerance, as a fraction of the domain's size.
pub const CLOSURE_TOLERANCE: f64 = 1e-9;
/// Chord tolerance of the loops as the editor draws them, as a fraction of the domain's size.
pub const OUTLINE_TOLERANCE: f64 = 2e-3;
/// Chord tolerance of the flattened loops used for validation, as a fraction of the domain's
/// size.
pub const FLATTEN_TOLERANCE: f64 = 1e-6;
/// Loops are first checked on polygons this close to them (a fraction of the domain's size),
/// and on [`FLATTEN_TOLERANCE`]'s only where parts of them come within a few times this.
const SCREEN_TOLERANCE: f64 = 1e-4;

/// The location of curve `curve` of loop `trim_loop`: `trims[loop][curve]`.
pub fn trim_location(trim_loop: usize, curve: usize) -> Location {
    Location::field("trims").index(trim_loop).index(curve)
}

fn refuse(trim_loop: usize, curve: usize, problem: TrimProblem) -> GeometryError {
    GeometryError::Trim {
        at: trim_location(trim_loop, curve),
        problem,
    }
}

/// A NURBS surface with trim loops (none: the whole domain is kept).
#[derive(Clone)]
pub struct TrimmedSurface {
    surface: NurbsSurface,
    loops: Vec<TrimLoop>,
    /// The classification grid, built on first use and shared by clones (loops never change
    /// after construction).
    index: Arc<RaceCell<Arc<TrimIndex>>>,
    /// Every loop's monotone pieces ([`Self::monotone_pieces`]), cut on first use and shared
    /// by the index and the export tessellation.
    pieces: Arc<RaceCell<Arc<[MonotonePiece]>>>,
    /// The loops flattened for drawing ([`Self::outline`]), built on first use and shared.
    outline: Arc<RaceCell<Arc<Vec<Vec<DVec2>>>>>,
}

impl PartialEq for TrimmedSurface {
    fn eq(&self, other: &Self) -> bool {
        self.surface == other.surface && self.loops == other.loops
    }
}

impl fmt::Debug for TrimmedSurface {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.debug_struct("TrimmedSurface")
            .field("surface", &self.surface)
            .field("loops", &self.loops.len())
            .finish()
    }
}

/// The domain as (u0, u1, v0, v1).
pub fn domain_rect(surface: &NurbsSurface) -> [f64; 4] {
    let [(u0, u1), (v0, v1)] = surface.domain();
    [u0, u1, v0, v1]
}

/// The larger side of the domain (the scale of every (u, v) tolerance).
pub fn domain_size(rect: [f64; 4]) -> f64 {
    (rect[1] - rect[0]).max(rect[3] - rect[2])
}

fn curve_start(curve: &TrimCurve) -> DVec2 {
    curve.control_point(0)
}

fn curve_end(curve: &TrimCurve) -> DVec2 {
    curve.control_point(curve.count() - 1)
}

impl TrimmedSurface {
    /// `surface` trimmed by `loops`, validated and normalised (see the module documentation).
    /// Curves are clamped first, so each starts and ends at its end control points.
    pub fn new(surface: NurbsSurface, loops: Vec<TrimLoop>) -> Result<Self, GeometryError> {
        let loops: Vec<TrimLoop> = loops
            .into_iter()
            .map(|l| l.iter().map(TrimCurve::clamped).collect())
            .collect();
        let rect = domain_rect(&surface);
        let flat = validate(rect, &loops)?;
        let loops = normalise(loops, &flat);
        Ok(Self {
            surface,
            loops,
            index: Arc::default(),
            pieces: Arc::default(),
            outline: Arc::default(),
        })
    }

    /// The untrimmed surface.
    pub fn untrimmed(surface: NurbsSurface) -> Self {
        Self {
            surface,
            loops: Vec::new(),
            index: Arc::default(),
            pieces: Arc::default(),
            outline: Arc::default(),
        }
    }

    pub fn surface(&self) -> &NurbsSurface {
        &self.surface
    }

    /// The surface, mutable (its control points and weights; the loops stay valid because the
    /// domain cannot change through it).
    pub fn surface_mut(&mut self) -> &mut NurbsSurface {
        &mut self.surface
    }

    pub fn loops(&self) -> &[TrimLoop] {
        &self.loops
    }

    pub fn is_trimmed(&self) -> bool {
        !self.loops.is_empty()
    }

    /// The same loops on another surface (after knot insertion, degree elevation, a knot
    /// vector edit): revalidated, since the domain may have changed.
    pub fn with_surface(&self, surface: NurbsSurface) -> Result<Self, GeometryError> {
        if surface.domain() == self.surface.domain() {
            return Ok(Self {
                surface,
                loops: self.loops.clone(),
                index: self.index.clone(),
                pieces: self.pieces.clone(),
                outline: self.outline.clone(),
            });
        }
        Self::new(surface, self.loops.clone())
    }

    /// The same surface with other loops.
    pub fn with_loops(&self, loops: Vec<TrimLoop>) -> Result<Self, GeometryError> {
        Self::new(self.surface.clone(), loops)
    }

    /// Every loop's curves cut into monotone pieces, loop by loop and curve by curve (each
    /// piece's `source` is its (loop, curve)); cut on first use and shared by clones.
    pub fn monotone_pieces(&self) -> Arc<[MonotonePiece]> {
        self.pieces
            .get_or_init(|| {
                let mut pieces = Vec::new();
                for (l, lp) in self.loops.iter().enumerate() {
                    for (c, curve) in lp.iter().enumerate() {
                        pieces.extend(monotone_pieces(curve, (l, c)));
                    }
                }
                pieces.into()
            })
            .clone()
    }

    /// The classification grid ([`TrimIndex`]), `None` when untrimmed.
    pub fn index(&self) -> Option<Arc<TrimIndex>> {
        if self.loops.is_empty() {
            return None;
        }
        Some(
            self.index
                .get_or_init(|| {
                    Arc::new(TrimIndex::build(
                        domain_rect(&self.surface),
                        self.monotone_pieces(),
                    ))
                })
                .clone(),
        )
    }

    /// The rectangle [u₀, u₁] × [v₀, v₁] of the domain the face keeps, when it keeps one:
    /// untrimmed (its domain), or one loop whose every curve has its control points on one
    /// side of their common box (within 1e-12 of the domain's size), so that each curve runs
    /// along that side and the loop, which cannot cross itself, goes once round the box.
    pub fn kept_rectangle(&self) -> Option<[f64; 4]> {
        let rect = domain_rect(&self.surface);
        let [trim_loop] = self.loops.as_slice() else {
            return self.loops.is_empty().then_some(rect);
        };
        let (mut lo, mut hi) = (DVec2::INFINITY, DVec2::NEG_INFINITY);
        for curve in trim_loop {
            for i in 0..curve.count() {
                let p = curve.control_point(i);
                lo = lo.min(p);
                hi = hi.max(p);
            }
        }
        let slack = 1e-12 * domain_size(rect);
        let sides = [(0, lo.x), (0, hi.x), (1, lo.y), (1, hi.y)];
        let on_a_side = trim_loop.iter().all(|curve| {
            sides.iter().any(|&(axis, at)| {
                (0..curve.count()).all(|i| (curve.control_point(i)[axis] - at).abs() <= slack)
            })
        });
        (on_a_side && hi.x - lo.x > slack && hi.y - lo.y > slack)
            .then_some([lo.x, hi.x, lo.y, hi.y])
    }

    /// Whether (u, v) is kept.
    pub fn contains(&self, u: f64, v: f64) -> bool {
        self.index().is_none_or(|index| index.contains(u, v))
    }

    /// Every loop flattened for drawing (chords within [`OUTLINE_TOLERANCE`] of the domain's
    /// size), computed once and shared by clones: the editor draws it every frame.
    pub fn outline(&self) -> Arc<Vec<Vec<DVec2>>> {
        self.outline
            .get_or_init(|| {
                let tolerance = OUTLINE_TOLERANCE * domain_size(domain_rect(&self.surface));
                Arc::new(self.flattened_loops(tolerance))
            })
            .clone()
    }

    /// Every loop flattened to a closed polygon (last point not repeated) with chords within
    /// `tolerance` in (u, v).
    pub fn flattened_loops(&self, tolerance: f64) -> Vec<Vec<DVec2>> {
        self.loops
            .iter()
            .map(|l| flatten_loop(l, tolerance))
            .collect()
    }

    /// The area of the kept region in (u, v) (shoelace on loops flattened to `tolerance`; the
    /// loops are oriented so that the signed areas add up).
    pub fn parameter_area(&self, tolerance: f64) -> f64 {
        if self.loops.is_empty() {
            let [u0, u1, v0, v1] = domain_rect(&self.surface);
            return (u1 - u0) * (v1 - v0);
        }
        self.flattened_loops(tolerance)
            .iter()
            .map(|p| signed_area(p))
            .sum()
    }

    /// The same trimmed surface with `direction` reversed: u ↦ u0 + u1 − u in the loops.
    pub fn reverse(&self, direction: Direction) -> Result<Self, GeometryError> {
        let [u0, u1, v0, v1] = domain_rect(&self.surface);
        let k = direction.index();
        self.mapped(self.surface.reverse(direction), |p| {
            if k == 0 {
                DVec2::new(u0 + u1 - p.x, p.y)
            } else {
                DVec2::new(p.x, v0 + v1 - p.y)
            }
        })
    }

    /// The same trimmed surface with u and v exchanged.
    pub fn swap_uv(&self) -> Result<Self, GeometryError> {
        self.mapped(self.surface.swap_uv(), |p| DVec2::new(p.y, p.x))
    }

    /// The loops carried by `f`, a reflection of the domain onto `surface`'s (u ↦ u0 + u1 − u,
    /// or u and v exchanged). A reflection keeps the loops closed, inside the domain, apart
    /// and nested as they were, and turns each one's direction: each is run backwards to keep
    /// the kept region on its left, without validating them again.
    fn mapped(
        &self,
        surface: NurbsSurface,
        f: impl Fn(DVec2) -> DVec2 + Copy,
    ) -> Result<Self, GeometryError> {
        let loops = self
            .loops
            .iter()
            .map(|l| {
                l.iter()
                    .rev()
                    .map(|c| c.map_points(f).map(|c| c.reverse()))
                    .collect()
            })
            .collect::<Result<Vec<TrimLoop>, _>>()?;
        Ok(Self {
            surface,
            loops,
            index: Arc::default(),
            pieces: Arc::default(),
            outline: Arc::default(),
        })
    }

    /// The other side kept: the domain's boundary loop added, or removed where one is there
    /// (odd-even inside-ness makes that the complement within the domain).
    pub fn inverted(&self) -> Result<Self, GeometryError> {
        let rect = domain_rect(&self.surface);
        let boundary =
            shapes::rectangle(DVec2::new(rect[0], rect[2]), DVec2::new(rect[1], rect[3]))?;
        let is_boundary = |l: &TrimLoop| {
            let b = domain_size(rect) * CLOSURE_TOLERANCE * 10.0;
            let poly = flatten_loop(l, 1.0);
            poly.iter().all(|p| {
                (p.x - rect[0]).abs() < b
                    || (p.x - rect[1]).abs() < b
                    || (p.y - rect[2]).abs() < b
                    || (p.y - rect[3]).abs() < b
            }) && (signed_area(&poly).abs() - (rect[1] - rect[0]) * (rect[3] - rect[2])).abs()
                < 1e-9 * (rect[1] - rect[0]) * (rect[3] - rect[2])
        };
        let mut loops = self.loops.clone();
        if let Some(k) = loops.iter().position(is_boundary) {
            loops.remove(k);
        } else {
            loops.insert(0, boundary);
        }
        if loops.is_empty() {
            return Ok(Self::untrimmed(self.surface.clone()));
        }
        Self::new(self.surface.clone(), loops)
    }

    /// Adds `new_loop` as a hole (on an untrimmed surface the domain's boundary becomes the
    /// outer loop) or, where `keep_inside`, as the only region kept of an untrimmed surface; on
    /// a trimmed surface the loop toggles the region it encloses (a hole in the kept region, an
    /// island in a hole).
    pub fn add_loop(&self, new_loop: TrimLoop, keep_inside: bool) -> Result<Self, GeometryError> {
        let mut loops = self.loops.clone();
        if loops.is_empty() && !keep_inside {
            let rect = domain_rect(&self.surface);
            loops.push(shapes::rectangle(
                DVec2::new(rect[0], rect[2]),
                DVec2::new(rect[1], rect[3]),
            )?);
        }
        loops.push(new_loop);
        Self::new(self.surface.clone(), loops)
    }

    /// Loop `k` removed (the last one removed leaves the surface untrimmed).
    pub fn remove_loop(&self, k: usize) -> Result<Self, GeometryError> {
        if k >= self.loops.len() {
            return Err(GeometryError::Construction {
                what: "trim",
                message: format!(
                    "there is no loop {k} (the surface has {})",
                    self.loops.len()
                ),
            });
        }
        let mut loops = self.loops.clone();
        loops.remove(k);
        Self::new(self.surface.clone(), loops)
    }

    /// The two trimmed surfaces on either side of `direction` = `value`; a side whose kept
    /// region is empty is `None`.
    pub fn split(
        &self,
        direction: Direction,
        value: f64,
    ) -> Result<(Option<Self>, Option<Self>), GeometryError> {
        let (a, b) = self.surface.split(direction, value)?;
        if self.loops.is_empty() {
            return Ok((Some(Self::untrimmed(a)), Some(Self::untrimmed(b))));
        }
        let (left, right) = split::split_loops(&self.loops, direction, value)?;
        let side = |surface: NurbsSurface, loops: Vec<TrimLoop>| {
            if loops.is_empty() {
                Ok(None)
            } else {
                Self::new(surface, loops).map(Some)
            }
        };
        Ok((side(a, left)?, side(b, right)?))
    }
}

/// The polygon of one loop: each curve's points without its last (the next curve's first).
pub fn flatten_loop(l: &TrimLoop, tolerance: f64) -> Vec<DVec2> {
    let identity = |p: DVec2| Ok::<DVec2, std::convert::Infallible>(p);
    let Ok((polygon, _)) = flatten_loop_mapped(l, tolerance, piece::UV_DEPTHS, identity);
    polygon
}

/// [`flatten_loop`] with every chord within `tolerance` of the loop mapped by `map` (onto a
/// surface, say; [`piece::MonotonePiece::flatten_mapped`] with `depths` halvings), and for
/// each point the curve whose chord starts there.
pub fn flatten_loop_mapped<V: Vector, E>(
    l: &TrimLoop,
    tolerance: f64,
    depths: (usize, usize),
    map: impl Fn(DVec2) -> Result<V, E> + Copy,
) -> Result<(Vec<DVec2>, Vec<usize>), E> {
    let pieces: Vec<Vec<MonotonePiece>> = l
        .iter()
        .enumerate()
        .map(|(c, curve)| monotone_pieces(curve, (0, c)))
        .collect();
    flatten_pieces_mapped(
        pieces.iter().map(Vec::as_slice),
        tolerance,
        depths,
        map,
        |_, _| None,
    )
}

/// [`flatten_loop_mapped`] of a loop already cut into monotone pieces, one slice per curve
/// in the loop's order (as [`TrimmedSurface::monotone_pieces`] holds them), with the map's
/// derivative bounds over a box of (u, v) from `bounds` where it has them
/// ([`piece::MonotonePiece::flatten_mapped`]).
pub fn flatten_pieces_mapped<'a, V: Vector, E>(
    curves: impl IntoIterator<Item = &'a [MonotonePiece]>,
    tolerance: f64,
    depths: (usize, usize),
    map: impl Fn(DVec2) -> Result<V, E> + Copy,
    bounds: impl Fn(DVec2, DVec2) -> Option<DerivativeBounds> + Copy,
) -> Result<(Vec<DVec2>, Vec<usize>), E> {
    let mut out = Vec::new();
    let mut owners = Vec::new();
    for (c, pieces) in curves.into_iter().enumerate() {
        let start = out.len();
        for piece in pieces {
            piece.flatten_mapped(tolerance, depths, map, bounds, &mut out)?;
        }
        if out.len() > start {
            out.pop();
        }
        owners.resize(out.len(), c);
    }
    Ok((out, owners))
}

/// Twice-halved shoelace: the signed area of a closed polygon (positive counter-clockwise).
pub fn signed_area(polygon: &[DVec2]) -> f64 {
    let n = polygon.len();
    (0..n)
        .map(|i| polygon[i].perp_dot(polygon[(i + 1) % n]))
        .sum::<f64>()
        / 2.0
}

/// Whether `p` is inside the closed polygon (crossing parity of the ray toward +u).
pub fn polygon_contains(polygon: &[DVec2], p: DVec2) -> bool {
    let n = polygon.len();
    let mut inside = false;
    for i in 0..n {
        let (a, b) = (polygon[i], polygon[(i + 1) % n]);
        if (a.y <= p.y) != (b.y <= p.y) {
            let x = a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x);
            if x > p.x {
                inside = !inside;
            }
        }
    }
    inside
}

/// One chord of a flattened loop, for the crossing checks.
#[derive(Debug, Clone, Copy)]
struct Chord {
    a: DVec2,
    b: DVec2,
    trim_loop: usize,
    curve: usize,
    /// Position in its loop's polygon (chord k joins vertex k and k + 1).
    position: usize,
}

/// Checks the loops and returns each loop's polygon.
fn validate(rect: [f64; 4], loops: &[TrimLoop]) -> Result<Vec<Vec<DVec2>>, GeometryError> {
    let size = domain_size(rect);
    let gap = CLOSURE_TOLERANCE * size;
    let [u0, u1, v0, v1] = rect;
    let outside = |p: DVec2| {
        p.x < u0 - gap || p.x > u1 + gap || p.y < v0 - gap || p.y > v1 + gap || !p.is_finite()
    };
    for (l, lp) in loops.iter().enumerate() {
        if lp.is_empty() {
            return Err(refuse(l, 0, TrimProblem::EmptyLoop));
        }
        for (c, curve) in lp.iter().enumerate() {
            let next = (c + 1) % lp.len();
            let (end, start) = (curve_end(curve), curve_start(&lp[next]));
            if (end - start).length() > gap {
                return Err(refuse(
                    l,
                    c,
                    TrimProblem::Open {
                        curve: c,
                        next,
                        end: Uv(end),
                        start: Uv(start),
                    },
                ));
            }
            // Convex hull first (positive weights); the flattened curve where the hull leaves.
            let hull_out = (0..curve.count()).any(|i| outside(curve.control_point(i)));
            if hull_out {
                let mut points = Vec::new();
                for piece in monotone_pieces(curve, (l, c)) {
                    piece.flatten(FLATTEN_TOLERANCE * size * 0.01, &mut points);
                }
                if let Some(&p) = points.iter().find(|&&p| outside(p)) {
                    return Err(refuse(
                        l,
                        c,
                        TrimProblem::OutsideDomain {
                            near: Uv(p),
                            u0,
                            u1,
                            v0,
                            v1,
                        },
                    ));
                }
            }
        }
    }
    // Loops far apart (most faces' are) are seen to be so on coarse polygons; only where some
    // part of them comes close are the crossings looked for on the fine ones.
    let coarse = SCREEN_TOLERANCE * size;
    let (polygons, chords) = loop_polygons(loops, coarse);
    if clear_of_each_other(rect, &chords, &polygons, 4.0 * coarse) {
        return Ok(polygons);
    }
    let (polygons, chords) = loop_polygons(loops, FLATTEN_TOLERANCE * size);
    check_crossings(rect, &chords, &polygons)?;
    for (l, polygon) in polygons.iter().enumerate() {
        let area = signed_area(polygon);
        if polygon.len() < 3 || area.abs() <= 1e-12 * (u1 - u0) * (v1 - v0) {
            return Err(refuse(l, 0, TrimProblem::ZeroArea));
        }
    }
    Ok(polygons)
}

/// Each loop's polygon with chords within `tolerance` of it, and its chords, each knowing the
/// curve it belongs to.
fn loop_polygons(loops: &[TrimLoop], tolerance: f64) -> (Vec<Vec<DVec2>>, Vec<Chord>) {
    let mut polygons = Vec::with_capacity(loops.len());
    let mut chords = Vec::new();
    let identity = |p: DVec2| Ok::<DVec2, std::convert::Infallible>(p);
    for (l, lp) in loops.iter().enumerate() {
        let Ok((polygon, owner)) = flatten_loop_mapped(lp, tolerance, piece::UV_DEPTHS, identity);
        let n = polygon.len();
        for k in 0..n {
            chords.push(Chord {
                a: polygon[k],
                b: polygon[(k + 1) % n],
                trim_loop: l,
                curve: owner[k],
                position: k,
            });
        }
        polygons.push(polygon);
    }
    (polygons, chords)
}

/// Whether polygons whose chords lie within a quarter of `margin` of their loops say
/// everything [`validate`] asks of the loops: no two chords other than neighbours come within
/// `margin` of each other (then no two parts of the loops meet, nor do the polygons at any
/// finer tolerance), neighbours meet at more than 20° (a sharper corner could hide a fold),
/// and each polygon's area is more than `margin` times its perimeter (its sign and its
/// nesting are the loop's). Where not, the loops are checked on fine polygons.
fn clear_of_each_other(
    rect: [f64; 4],
    chords: &[Chord],
    polygons: &[Vec<DVec2>],
    margin: f64,
) -> bool {
    let thick = polygons.iter().all(|polygon| {
        let n = polygon.len();
        let perimeter: f64 = (0..n)
            .map(|k| polygon[k].distance(polygon[(k + 1) % n]))
            .sum();
        n >= 3 && signed_area(polygon).abs() > margin * perimeter
    });
    if !thick {
        return false;
    }
    let cos_sharp = 20f64.to_radians().cos();
    let mut clear = true;
    each_close_pair(rect, chords, margin, |p, q| {
        clear = match corner(p, q, polygons) {
            Some((shared, x, y)) => {
                let (e1, e2) = (x - shared, y - shared);
                e1.dot(e2) < cos_sharp * e1.length() * e2.length()
            }
            None => chord_distance(p, q) > margin,
        };
        clear
    });
    clear
}

/// Where chords `p` and `q` follow each other along one loop: the vertex they share and the
/// far end of `p` and of `q`; `None` for chords that are not neighbours.
fn corner(p: &Chord, q: &Chord, polygons: &[Vec<DVec2>]) -> Option<(DVec2, DVec2, DVec2)> {
    if p.trim_loop != q.trim_loop {
        return None;
    }
    let n = polygons[p.trim_loop].len();
    let follows = |a: &Chord, b: &Chord| b.position == (a.position + 1) % n;
    if follows(p, q) {
        Some((p.b, p.a, q.b))
    } else if follows(q, p) {
        Some((p.a, p.b, q.a))
    } else {
        None
    }
}

/// The distance between two chords: 0 where they meet, else the least of their ends'
/// distances to the other chord.
fn chord_distance(p: &Chord, q: &Chord) -> f64 {
    if chords_meet(p.a, p.b, q.a, q.b) {
        return 0.0;
    }
    distance_to_segment(p.a, q.a, q.b)
        .min(distance_to_segment(p.b, q.a, q.b))
        .min(distance_to_segment(q.a, p.a, p.b))
        .min(distance_to_segment(q.b, p.a, p.b))
}

/// Calls `visit` with every pair of chords whose boxes, grown by `margin`, share a cell of a
/// grid over the domain (some pairs more than once), until it returns false. The grid keeps
/// the number of pairs near linear in the number of chords.
fn each_close_pair(
    rect: [f64; 4],
    chords: &[Chord],
    margin: f64,
    mut visit: impl FnMut(&Chord, &Chord) -> bool,
) {
    let side = ((chords.len() as f64).sqrt().ceil() as usize).clamp(1, 512);
    let [u0, u1, v0, v1] = rect;
    let pad = 1e-6 * domain_size(rect) + margin;
    let (du, dv) = (
        (u1 - u0 + 2.0 * pad) / side as f64,
        (v1 - v0 + 2.0 * pad) / side as f64,
    );
    let cell = |p: DVec2| {
        (
            (((p.x - u0 + pad) / du).floor().max(0.0) as usize).min(side - 1),
            (((p.y - v0 + pad) / dv).floor().max(0.0) as usize).min(side - 1),
        )
    };
    let mut buckets: Vec<Vec<u32>> = vec![Vec::new(); side * side];
    let grow = DVec2::splat(margin);
    for (k, ch) in chords.iter().enumerate() {
        let (i0, j0) = cell(ch.a.min(ch.b) - grow);
        let (i1, j1) = cell(ch.a.max(ch.b) + grow);
        for j in j0..=j1 {
            for i in i0..=i1 {
                buckets[j * side + i].push(k as u32);
            }
        }
    }
    for bucket in &buckets {
        for (x, &s) in bucket.iter().enumerate() {
            for &t in &bucket[x + 1..] {
                if !visit(&chords[s as usize], &chords[t as usize]) {
                    return;
                }
            }
        }
    }
}

/// Orientation of (a, b, c): positive counter-clockwise.
fn orient(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    (b - a).perp_dot(c - a)
}

/// Whether chords ab and cd meet (touching counts).
fn chords_meet(a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> bool {
    let (d1, d2) = (orient(c, d, a), orient(c, d, b));
    let (d3, d4) = (orient(a, b, c), orient(a, b, d));
    if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0))
        && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))
    {
        return true;
    }
    let on = |p: DVec2, q: DVec2, r: DVec2, o: f64| {
        o == 0.0
            && r.x >= p.x.min(q.x)
            && r.x <= p.x.max(q.x)
            && r.y >= p.y.min(q.y)
            && r.y <= p.y.max(q.y)
    };
    on(c, d, a, d1) || on(c, d, b, d2) || on(a, b, c, d3) || on(a, b, d, d4)
}

/// Refuses the first pair of chords that meet, other than neighbours in one loop (which share
/// a vertex; they are refused only when they fold back onto each other). Chords are bucketed in
/// a grid so that the check stays near linear.
fn check_crossings(
    rect: [f64; 4],
    chords: &[Chord],
    polygons: &[Vec<DVec2>],
) -> Result<(), GeometryError> {
    let mut error = None;
    each_close_pair(rect, chords, 0.0, |p, q| {
        error = crossing_error(p, q, polygons);
        error.is_none()
    });
    error.map_or(Ok(()), Err)
}

fn crossing_error(p: &Chord, q: &Chord, polygons: &[Vec<DVec2>]) -> Option<GeometryError> {
    let (p, q) = if (p.trim_loop, p.position) > (q.trim_loop, q.position) {
        (q, p)
    } else {
        (p, q)
    };
    if let Some((shared, x, y)) = corner(p, q, polygons) {
        // They share a vertex; refuse only a fold back along the same line.
        let (e1, e2) = (x - shared, y - shared);
        let folded = e1.perp_dot(e2).abs() <= 1e-12 * e1.length() * e2.length() && e1.dot(e2) > 0.0;
        return folded.then(|| {
            refuse(
                q.trim_loop,
                q.curve,
                TrimProblem::SelfIntersection {
                    other: p.curve,
                    near: Uv(shared),
                },
            )
        });
    }
    if !chords_meet(p.a, p.b, q.a, q.b) {
        return None;
    }
    let near = Uv(0.5 * (p.a + q.a));
    Some(if p.trim_loop == q.trim_loop {
        refuse(
            q.trim_loop,
            q.curve,
            TrimProblem::SelfIntersection {
                other: p.curve,
                near,
            },
        )
    } else {
        refuse(
            q.trim_loop,
            q.curve,
            TrimProblem::Crossing {
                other_loop: p.trim_loop,
                other_curve: p.curve,
                near,
            },
        )
    })
}

/// Orients each loop by its nesting depth: even depth counter-clockwise, odd clockwise.
fn normalise(loops: Vec<TrimLoop>, polygons: &[Vec<DVec2>]) -> Vec<TrimLoop> {
    // Each polygon's box: a point outside it is outside the polygon (many holes in one face
    // are then compared box against point, not point against every chord).
    let boxes: Vec<(DVec2, DVec2)> = polygons
        .iter()
        .map(|poly| {
            poly.iter()
                .fold((DVec2::INFINITY, DVec2::NEG_INFINITY), |(lo, hi), &p| {
                    (lo.min(p), hi.max(p))
                })
        })
        .collect();
    loops
        .into_iter()
        .enumerate()
        .map(|(l, lp)| {
            let probe = polygons[l][0];
            let depth = polygons
                .iter()
                .zip(&boxes)
                .enumerate()
                .filter(|&(m, (poly, &(lo, hi)))| {
                    m != l
                        && probe.cmpge(lo).all()
                        && probe.cmple(hi).all()
                        && polygon_contains(poly, probe)
                })
                .count();
            let ccw = signed_area(&polygons[l]) > 0.0;
            if ccw == (depth % 2 == 0) {
                lp
            } else {
                lp.iter().rev().map(TrimCurve::reverse).collect()
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn polygon_area_and_containment() {
        let square = [
            DVec2::new(0.0, 0.0),
            DVec2::new(1.0, 0.0),
            DVec2::new(1.0, 1.0),
            DVec2::new(0.0, 1.0),
        ];
        assert_eq!(signed_area(&square), 1.0);
        assert!(polygon_contains(&square, DVec2::new(0.5, 0.5)));
        assert!(!polygon_contains(&square, DVec2::new(1.5, 0.5)));
    }

    /// The loops' validity as the fine polygons alone say it (what [`validate`] did before it
    /// screened the loops on coarse ones).
    fn fine_validity(rect: [f64; 4], loops: &[TrimLoop]) -> bool {
        let size = domain_size(rect);
        let (polygons, chords) = loop_polygons(loops, FLATTEN_TOLERANCE * size);
        let [u0, u1, v0, v1] = rect;
        check_crossings(rect, &chords, &polygons).is_ok()
            && polygons.iter().all(|polygon| {
                polygon.len() >= 3 && signed_area(polygon).abs() > 1e-12 * (u1 - u0) * (v1 - v0)
            })
    }

    /// Random circles, ellipses and triangles in a random domain, many of them a small gap
    /// apart or overlapping by a little (from 1e-7 to 1e-2 of the domain, across the coarse
    /// screen's margin): the screened check accepts and refuses exactly what the fine check
    /// alone does.
    #[test]
    fn screened_loop_checks_agree_with_fine_ones_on_near_misses() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut random = move || crate::test_support::uniform(&mut state);
        let (mut accepted, mut refused) = (0, 0);
        for case in 0..400 {
            let scale = 10f64.powf(-2.0 + 6.0 * random());
            let (u0, v0) = ((random() - 0.5) * 1e3, (random() - 0.5) * 1e3);
            let aspect = 0.2 + 4.0 * random();
            let rect = [u0, u0 + scale, v0, v0 + scale * aspect];
            let at = |x: f64, y: f64| DVec2::new(u0 + x * scale, v0 + y * scale * aspect);
            let size = domain_size(rect);
            let mut loops = vec![shapes::rectangle(at(0.0, 0.0), at(1.0, 1.0)).unwrap()];
            // Two shapes side by side, `gap` apart along u (negative: overlapping).
            let gap = (if random() < 0.5 { -1.0 } else { 1.0 })
                * 10f64.powf(-7.0 + 5.0 * random())
                * size;
            let r = (0.05 + 0.15 * random()) * scale;
            let c = at(0.3, 0.5);
            let first = match case % 3 {
                0 => shapes::ellipse(c, DVec2::new(r, r * (0.5 + random()))).unwrap(),
                1 => shapes::ellipse(c, DVec2::splat(r)).unwrap(),
                _ => shapes::polygon(&[
                    c + DVec2::new(r, 0.0),
                    c + DVec2::new(-r, 0.7 * r),
                    c + DVec2::new(-r, -0.9 * r),
                ])
                .unwrap(),
            };
            let r2 = (0.05 + 0.15 * random()) * scale;
            // Toward a random direction, so that the nearest points are not the ends of the
            // monotone pieces (which every polygon of a loop passes through).
            let angle = (random() - 0.5) * 2.4;
            let toward = DVec2::new(angle.cos(), angle.sin());
            let second = if case % 3 == 1 {
                // Circles: exactly `gap` apart.
                shapes::ellipse(c + toward * (r + gap + r2), DVec2::splat(r2)).unwrap()
            } else {
                // Else the other shape's extent toward it, found on its fine polygon.
                let fine = flatten_loop(&first, 1e-9 * size);
                let reach = fine
                    .iter()
                    .map(|p| (*p - c).dot(toward))
                    .fold(0.0, f64::max);
                shapes::ellipse(c + toward * (reach + gap + r2), DVec2::splat(r2)).unwrap()
            };
            loops.push(first);
            loops.push(second);
            let screened = validate(rect, &loops).is_ok();
            assert_eq!(
                screened,
                fine_validity(rect, &loops),
                "case {case}: gap {:.3e} of the size, domain {rect:?}",
                gap / size
            );
            if screened {
                accepted += 1;
            } else {
                refused += 1;
            }
        }
        // Both answers occur.
        assert!(
            accepted > 50 && refused > 50,
            "{accepted} accepted, {refused} refused"
        );
    }

    /// A plate's face in general position: a random domain (offset up to 500, size 1e-2 to
    /// 1e4, aspect 0.2 to 4) holding up to 400 circular and elliptical holes of random sizes,
    /// well apart. The grid lists every piece in every cell it passes through (checked at 65
    /// points along each piece), and classifies random points as the holes' closed forms do.
    #[test]
    fn the_grid_lists_each_piece_where_it_passes_and_classifies_holes_exactly() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut random = move || crate::test_support::uniform(&mut state);
        for case in 0..12 {
            let scale = 10f64.powf(-2.0 + 6.0 * random());
            let (u0, v0) = ((random() - 0.5) * 1e3, (random() - 0.5) * 1e3);
            let aspect = 0.2 + 3.8 * random();
            let (width, height) = (scale, scale * aspect);
            let rect = [u0, u0 + width, v0, v0 + height];
            let surface = NurbsSurface::new(
                [1, 1],
                [
                    vec![u0, u0, u0 + width, u0 + width],
                    vec![v0, v0, v0 + height, v0 + height],
                ],
                [2, 2],
                vec![
                    glam::DVec3::new(0.0, 0.0, 0.0),
                    glam::DVec3::new(0.0, 1.0, 0.0),
                    glam::DVec3::new(1.0, 0.0, 0.0),
                    glam::DVec3::new(1.0, 1.0, 0.0),
                ],
                None,
            );
            let Ok(surface) = surface else {
                panic!("case {case}: no plane over {rect:?}");
            };
            // Holes on a jittered n × n lattice, each inside its own lattice cell.
            let n = 1 + (case * 2).min(19);
            let mut holes: Vec<(DVec2, DVec2)> = Vec::new();
            for i in 0..n {
                for j in 0..n {
                    let cell = DVec2::new(width, height) / n as f64;
                    let radii = cell * DVec2::new(0.1 + 0.25 * random(), 0.1 + 0.25 * random());
                    let radii = if random() < 0.5 {
                        DVec2::splat(radii.min_element())
                    } else {
                        radii
                    };
                    let room = cell * 0.5 - radii;
                    let centre = DVec2::new(u0, v0)
                        + cell * DVec2::new(i as f64 + 0.5, j as f64 + 0.5)
                        + room * 0.8 * DVec2::new(2.0 * random() - 1.0, 2.0 * random() - 1.0);
                    holes.push((centre, radii));
                }
            }
            let mut loops = vec![
                shapes::rectangle(DVec2::new(u0, v0), DVec2::new(u0 + width, v0 + height))
                    .unwrap_or_default(),
            ];
            loops.extend(
                holes
                    .iter()
                    .map(|&(c, r)| shapes::ellipse(c, r).unwrap_or_default()),
            );
            let face = TrimmedSurface::new(surface, loops);
            let Ok(face) = face else {
                panic!("case {case}: {:?}", face.err());
            };
            let Some(index) = face.index() else {
                panic!("case {case}: no index");
            };
            for (k, piece) in index.pieces.iter().enumerate() {
                for s in 0..=64 {
                    let p = piece::bezier_point(&piece.points, s as f64 / 64.0);
                    let c = index.cell_at(p);
                    let first = index.cells[c].first as usize;
                    let listed = &index.lists[first..first + index.cells[c].count as usize];
                    assert!(
                        listed.contains(&(k as u32)),
                        "case {case}: piece {k} passes through cell {c} at {p} unlisted"
                    );
                }
            }
            let mut tested = 0;
            for _ in 0..4000 {
                let p = DVec2::new(u0 + width * random(), v0 + height * random());
                // Where a hole's implicit form is within 1e-9 of its level, the side is left
                // to rounding.
                let levels = holes
                    .iter()
                    .map(|&(c, r)| ((p - c) / r).length_squared() - 1.0);
                if levels.clone().any(|f| f.abs() < 1e-9) {
                    continue;
                }
                let kept = levels.clone().all(|f| f > 0.0);
                assert_eq!(face.contains(p.x, p.y), kept, "case {case}: {p}");
                tested += 1;
            }
            assert!(tested > 3900, "case {case}: {tested} points tested");
        }
    }

    /// Seed case 2 of the test above, before the fix: a circle of radius 0.013 at
    /// (−345.09, 207.56). Its quarter arcs end with one coordinate's derivative at zero, where
    /// rounding gave it the wrong sign (−2.8e-14 against 0.018), so a "turn" 1.1e-12 from the
    /// segment's end cut a piece too short to flatten, and the loop was refused as crossing
    /// itself.
    #[test]
    fn a_small_circle_far_from_the_origin_is_a_valid_hole() {
        let (u0, v0) = (-345.4599397910163, 207.47837119356538);
        let rect = [u0, -345.0438682516671, v0, 208.36221957514377];
        let outer = shapes::rectangle(DVec2::new(u0, v0), DVec2::new(rect[1], rect[3]));
        let hole = shapes::ellipse(
            DVec2::new(-345.0858555340312, 207.55815681651166),
            DVec2::splat(0.013027902389499458),
        );
        let (Ok(outer), Ok(hole)) = (outer, hole) else {
            panic!("the loops");
        };
        assert_eq!(validate(rect, &[outer, hole.clone()]).err(), None);
        let pieces = monotone_pieces(&hole[0], (1, 0));
        assert_eq!(pieces.len(), 4, "one piece per quarter arc");
    }
}
