//! Network surfaces: a Gordon surface through curves in two directions that cross each other,
//! given in any order and direction, of any degree, knots and parametrisation, rational or not.
//!
//! The Gordon surface ([`super::transfinite::gordon`]) needs every u-curve k to cross every
//! v-curve l at one common pair of parameters (u_l, v_k). A network drawn by a person has none
//! of that, so [`network_surface`]:
//!
//! 1. finds every crossing by closest points, refusing pairs farther apart than
//!    [`NETWORK_TOLERANCE`] of the network's size;
//! 2. sorts each family by where its curves cross the first curve of the other family, and
//!    reverses the curves that run the other way;
//! 3. chooses common parameters (the mean over the family of each crossing's normalised
//!    parameter) and reparametrises every curve onto them with a monotone C¹ cubic map
//!    (Fritsch–Carlson; Fritsch and Butland's harmonic-mean slopes), keeping the part between
//!    its first and last crossing;
//! 4. makes each family compatible by interpolating all its curves, at the same parameters (the
//!    crossings and evenly spaced points between them), with one cubic B-spline each: a
//!    non-rational C² approximation whose samples are doubled until it is within
//!    [`FIT_TOLERANCE`] of the network's size (a rational curve has no exact place in a Boolean
//!    sum, so every curve goes through this);
//! 5. builds the Gordon surface and measures how far each input curve is from it.
//!
//! A network that already fits (non-rational curves crossed at common parameters at their
//! ends) skips 3 and 4 and gives the exact Gordon surface.

use glam::DVec3;

use super::curve::{SpaceCurve, control_box_size};
use super::error::GeometryError;
use super::error::construction;
use super::interpolation::{averaged_knots, interpolate_points};
use super::surface::{Direction, NurbsSurface};
use super::transfinite::{crossing, gordon_at, normalized, samples};

/// Curves that come closer than this fraction of the network's size cross.
pub const NETWORK_TOLERANCE: f64 = 1e-4;
/// The reparametrised curves are within this fraction of the network's size of the input.
pub const FIT_TOLERANCE: f64 = 1e-6;
/// The most curves in one family.
pub const MAX_NETWORK_CURVES: usize = 64;
/// The most fitting samples per crossing interval, and in all.
const MAX_SAMPLES_PER_INTERVAL: usize = 256;
const MAX_SAMPLES: usize = 1024;

/// One of the two families of a network.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Family {
    U,
    V,
}

impl Family {
    fn name(self) -> &'static str {
        match self {
            Family::U => "u-curve",
            Family::V => "v-curve",
        }
    }
}

/// The largest distance of the input curves from a network surface, and where it occurs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NetworkDeviation {
    pub distance: f64,
    /// The curve's family and its index as given.
    pub family: Family,
    pub curve: usize,
    /// The point of the input curve farthest from the surface.
    pub point: DVec3,
}

impl std::fmt::Display for NetworkDeviation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let p = self.point;
        write!(
            f,
            "largest deviation {:.3e} from {} {} near ({:.6}, {:.6}, {:.6})",
            self.distance,
            self.family.name(),
            self.curve,
            p.x,
            p.y,
            p.z
        )
    }
}

/// A network surface and how closely it follows its curves.
#[derive(Debug, Clone)]
pub struct Network {
    pub surface: NurbsSurface,
    pub deviation: NetworkDeviation,
}

/// One curve of the network after sorting and orienting: the input curve on [0, 1] (reversed
/// where needed), its index as given, and the parameters on it where it crosses the other
/// family's curves, in their sorted order.
struct Strand {
    curve: SpaceCurve,
    index: usize,
    crossings: Vec<f64>,
}

/// The Gordon surface through a network of curves (see the module documentation): `u_curves`
/// run along u and `v_curves` along v, each family in any order and direction; every u-curve
/// must cross every v-curve within [`NETWORK_TOLERANCE`] of the network's size. `degree` is
/// the interpolation degree across the curves (lowered to the number of curves − 1). The u
/// direction follows the first u-curve as given, the v direction the first v-curve.
pub fn network_surface(
    u_curves: &[SpaceCurve],
    v_curves: &[SpaceCurve],
    degree: usize,
) -> Result<Network, GeometryError> {
    const WHAT: &str = "network";
    for (family, curves) in [(Family::U, u_curves), (Family::V, v_curves)] {
        if !(2..=MAX_NETWORK_CURVES).contains(&curves.len()) {
            return Err(construction(
                WHAT,
                format!(
                    "needs 2 to {MAX_NETWORK_CURVES} {}s, found {}",
                    family.name(),
                    curves.len()
                ),
            ));
        }
    }
    if degree == 0 {
        return Err(construction(WHAT, "the degree must be ≥ 1"));
    }
    let us: Vec<SpaceCurve> = u_curves.iter().map(normalized).collect::<Result<_, _>>()?;
    let vs: Vec<SpaceCurve> = v_curves.iter().map(normalized).collect::<Result<_, _>>()?;
    let size = control_box_size(us.iter().chain(&vs)).max(1e-300);
    // Every crossing: at_u[k][l] on u-curve k, at_v[l][k] on v-curve l.
    let u_samples: Vec<Vec<DVec3>> = us.iter().map(samples).collect::<Result<_, _>>()?;
    let v_samples: Vec<Vec<DVec3>> = vs.iter().map(samples).collect::<Result<_, _>>()?;
    let mut at_u = vec![vec![0.0; vs.len()]; us.len()];
    let mut at_v = vec![vec![0.0; us.len()]; vs.len()];
    for (k, (c, cs)) in us.iter().zip(&u_samples).enumerate() {
        for (l, (d, ds)) in vs.iter().zip(&v_samples).enumerate() {
            let (s, t, distance) = crossing((c, cs), (d, ds))?;
            if distance > NETWORK_TOLERANCE * size {
                return Err(construction(
                    WHAT,
                    format!(
                        "u-curve {k} and v-curve {l} do not cross: they come within \
                         {distance:.3e}, more than {NETWORK_TOLERANCE} × the network's size \
                         {size:.4}"
                    ),
                ));
            }
            at_u[k][l] = s;
            at_v[l][k] = t;
        }
    }
    let u_order = sorted_by(&at_v[0], Family::V, Family::U)?;
    let v_order = sorted_by(&at_u[0], Family::U, Family::V)?;
    let u_strands = in_order(oriented(&us, &at_u, &v_order, Family::U)?, &u_order);
    let v_strands = in_order(oriented(&vs, &at_v, &u_order, Family::V)?, &v_order);
    let u_params = common_parameters(&u_strands);
    let v_params = common_parameters(&v_strands);
    let fits = |strands: &[Strand], params: &[f64]| -> Result<Vec<SpaceCurve>, GeometryError> {
        if already_fits(strands, params) {
            Ok(strands.iter().map(|s| s.curve.clone()).collect())
        } else {
            fitted_family(strands, params, FIT_TOLERANCE * size)
        }
    };
    let fitted_u = fits(&u_strands, &u_params)?;
    let fitted_v = fits(&v_strands, &v_params)?;
    let surface = gordon_at(&fitted_u, &fitted_v, &u_params, &v_params, degree)?;
    let deviation = deviation(&surface, &u_strands, &v_strands, &u_params, &v_params)?;
    Ok(Network { surface, deviation })
}

/// The two families of a network given as one list of curves: curves cross (come within
/// [`NETWORK_TOLERANCE`] of the network's size) only curves of the other family, so the
/// crossing graph is bipartite and its two colours are the families (the one holding curve 0
/// first). Refused for a curve that crosses nothing, curves in more than one connected piece,
/// or a curve that crosses one of its own family.
pub fn families(curves: &[SpaceCurve]) -> Result<(Vec<usize>, Vec<usize>), GeometryError> {
    const WHAT: &str = "network";
    let normal: Vec<SpaceCurve> = curves.iter().map(normalized).collect::<Result<_, _>>()?;
    let size = control_box_size(&normal).max(1e-300);
    let sampled: Vec<Vec<DVec3>> = normal.iter().map(samples).collect::<Result<_, _>>()?;
    let n = curves.len();
    let mut crosses = vec![Vec::new(); n];
    for a in 0..n {
        for b in a + 1..n {
            let (_, _, distance) = crossing((&normal[a], &sampled[a]), (&normal[b], &sampled[b]))?;
            if distance <= NETWORK_TOLERANCE * size {
                crosses[a].push(b);
                crosses[b].push(a);
            }
        }
    }
    let mut colour: Vec<Option<bool>> = vec![None; n];
    if n > 0 {
        colour[0] = Some(false);
    }
    let mut queue = std::collections::VecDeque::from([0usize]);
    while let Some(a) = queue.pop_front() {
        let Some(ca) = colour.get(a).copied().flatten() else {
            continue;
        };
        for &b in &crosses[a] {
            match colour[b] {
                None => {
                    colour[b] = Some(!ca);
                    queue.push_back(b);
                }
                Some(cb) if cb == ca => {
                    return Err(construction(
                        WHAT,
                        format!("curves {a} and {b} cross but belong to one direction"),
                    ));
                }
                Some(_) => {}
            }
        }
    }
    if let Some(lone) = colour.iter().position(Option::is_none) {
        return Err(construction(
            WHAT,
            format!("curve {lone} crosses none of the curves crossing curve 0"),
        ));
    }
    let (u, v): (Vec<usize>, Vec<usize>) = (0..n).partition(|&k| colour[k] == Some(false));
    Ok((u, v))
}

/// The order of one family's curves along the first curve of the other: `params[k]` is where
/// curve k crosses it. Two curves crossing it at one place are refused.
fn sorted_by(params: &[f64], along: Family, family: Family) -> Result<Vec<usize>, GeometryError> {
    let mut order: Vec<usize> = (0..params.len()).collect();
    order.sort_by(|&a, &b| params[a].total_cmp(&params[b]));
    for w in order.windows(2) {
        if !(params[w[1]] - params[w[0]] > 1e-9) {
            return Err(construction(
                "network",
                format!(
                    "{} {} and {} {} cross {} 0 at the same place",
                    family.name(),
                    w[0],
                    family.name(),
                    w[1],
                    along.name()
                ),
            ));
        }
    }
    Ok(order)
}

/// The strands in the order `order` lists their indices.
fn in_order(strands: Vec<Strand>, order: &[usize]) -> Vec<Strand> {
    let mut slots: Vec<Option<Strand>> = strands.into_iter().map(Some).collect();
    order.iter().filter_map(|&k| slots[k].take()).collect()
}

/// Each curve of a family with its crossings in the sorted order of the other family
/// (`other_order`), reversed where they decrease; curves that cross the others out of order are
/// refused.
fn oriented(
    curves: &[SpaceCurve],
    crossings: &[Vec<f64>],
    other_order: &[usize],
    family: Family,
) -> Result<Vec<Strand>, GeometryError> {
    curves
        .iter()
        .zip(crossings)
        .enumerate()
        .map(|(k, (curve, at))| {
            let along: Vec<f64> = other_order.iter().map(|&l| at[l]).collect();
            let increasing = along.windows(2).all(|w| w[1] > w[0]);
            let decreasing = along.windows(2).all(|w| w[1] < w[0]);
            if increasing {
                Ok(Strand {
                    curve: curve.clone(),
                    index: k,
                    crossings: along,
                })
            } else if decreasing {
                Ok(Strand {
                    curve: curve.reverse(),
                    index: k,
                    crossings: along.iter().map(|t| 1.0 - t).collect(),
                })
            } else {
                let other = match family {
                    Family::U => Family::V,
                    Family::V => Family::U,
                };
                Err(construction(
                    "network",
                    format!(
                        "{} {k} crosses the {}s in a different order than the first {} does",
                        family.name(),
                        other.name(),
                        family.name()
                    ),
                ))
            }
        })
        .collect()
}

/// The common crossing parameters of a family: the mean of each crossing's parameter,
/// normalised per curve to run from 0 at its first crossing to 1 at its last.
fn common_parameters(strands: &[Strand]) -> Vec<f64> {
    let count = strands[0].crossings.len();
    let mut params = vec![0.0; count];
    for s in strands {
        let (a, b) = (s.crossings[0], s.crossings[count - 1]);
        for (acc, t) in params.iter_mut().zip(&s.crossings) {
            *acc += (t - a) / (b - a) / strands.len() as f64;
        }
    }
    params[0] = 0.0;
    params[count - 1] = 1.0;
    params
}

/// Whether a family can go into the Gordon surface as it is: non-rational, crossed at the
/// common parameters (within 1e-9), from end to end.
fn already_fits(strands: &[Strand], params: &[f64]) -> bool {
    strands.iter().all(|s| {
        s.curve.is_polynomial()
            && s.crossings
                .iter()
                .zip(params)
                .all(|(a, b)| (a - b).abs() <= 1e-9)
    })
}

/// The monotone C¹ cubic map from the common parameters `params` onto a curve's own crossing
/// parameters `own` (both increasing): Hermite cubics with Fritsch–Butland slopes (the harmonic
/// mean of the neighbouring secants inside, the secant at the ends), which keep it monotone.
struct MonotoneMap<'a> {
    params: &'a [f64],
    own: &'a [f64],
    slopes: Vec<f64>,
}

impl<'a> MonotoneMap<'a> {
    fn new(params: &'a [f64], own: &'a [f64]) -> Self {
        let n = params.len();
        let secant = |i: usize| (own[i + 1] - own[i]) / (params[i + 1] - params[i]);
        let slopes = (0..n)
            .map(|i| {
                if i == 0 {
                    secant(0)
                } else if i == n - 1 {
                    secant(n - 2)
                } else {
                    let (a, b) = (secant(i - 1), secant(i));
                    2.0 / (1.0 / a + 1.0 / b)
                }
            })
            .collect();
        Self {
            params,
            own,
            slopes,
        }
    }

    /// The curve's own parameter at common parameter `u`.
    fn at(&self, u: f64) -> f64 {
        let n = self.params.len();
        let i = self.params[1..n - 1]
            .iter()
            .take_while(|&&p| p <= u)
            .count();
        let (u0, u1) = (self.params[i], self.params[i + 1]);
        let h = u1 - u0;
        let t = ((u - u0) / h).clamp(0.0, 1.0);
        let (t2, t3) = (t * t, t * t * t);
        let h00 = 2.0 * t3 - 3.0 * t2 + 1.0;
        let h10 = t3 - 2.0 * t2 + t;
        let h01 = -2.0 * t3 + 3.0 * t2;
        let h11 = t3 - t2;
        (h00 * self.own[i]
            + h10 * h * self.slopes[i]
            + h01 * self.own[i + 1]
            + h11 * h * self.slopes[i + 1])
            .clamp(0.0, 1.0)
    }
}

/// The family's curves reparametrised onto the common `params` and made compatible: each is
/// interpolated by a cubic B-spline at the same parameters (the crossings and `m` evenly spaced
/// points in each interval between them, over averaged knots), with `m` doubled from 2 until
/// every curve is within `tolerance` of its input at the midpoints between samples.
fn fitted_family(
    strands: &[Strand],
    params: &[f64],
    tolerance: f64,
) -> Result<Vec<SpaceCurve>, GeometryError> {
    let mut per_interval = 2;
    loop {
        let mut sample_params = vec![params[0]];
        for w in params.windows(2) {
            for j in 1..=per_interval {
                sample_params.push(w[0] + (w[1] - w[0]) * j as f64 / per_interval as f64);
            }
        }
        let degree = 3.min(sample_params.len() - 1);
        let knots = averaged_knots(&sample_params, degree);
        let mut worst = 0.0_f64;
        let mut fitted = Vec::with_capacity(strands.len());
        for s in strands {
            let map = MonotoneMap::new(params, &s.crossings);
            let points: Vec<DVec3> = sample_params
                .iter()
                .map(|&u| s.curve.point_at(map.at(u)))
                .collect::<Result<_, _>>()?;
            let control = interpolate_points(&points, &sample_params, degree, &knots, "network")?;
            let curve = SpaceCurve::new(degree, knots.clone(), control, None)?;
            for w in sample_params.windows(2) {
                let mid = 0.5 * (w[0] + w[1]);
                let d = curve
                    .point_at(mid)?
                    .distance(s.curve.point_at(map.at(mid))?);
                worst = worst.max(d);
            }
            fitted.push(curve);
        }
        if worst <= tolerance
            || per_interval >= MAX_SAMPLES_PER_INTERVAL
            || 2 * sample_params.len() > MAX_SAMPLES
        {
            return Ok(fitted);
        }
        per_interval *= 2;
    }
}

/// The largest distance from the input curves to the surface: each curve is sampled between
/// its first and last crossing at 17 points per interval (a count that is not a power of two,
/// so the samples fall between the fitted curves' interpolation points, where their error is),
/// and each point is projected onto the surface's iso-curve through the curve (v = v_k for
/// u-curve k) by Newton's iteration from the common parameter ([`foot_on`]).
fn deviation(
    surface: &NurbsSurface,
    u_strands: &[Strand],
    v_strands: &[Strand],
    u_params: &[f64],
    v_params: &[f64],
) -> Result<NetworkDeviation, GeometryError> {
    const PER_INTERVAL: usize = 17;
    let mut worst = NetworkDeviation {
        distance: 0.0,
        family: Family::U,
        curve: u_strands[0].index,
        point: DVec3::ZERO,
    };
    for (family, strands, params, across, fixed_direction) in [
        (Family::U, u_strands, u_params, v_params, Direction::V),
        (Family::V, v_strands, v_params, u_params, Direction::U),
    ] {
        for (s, &fixed) in strands.iter().zip(across) {
            let iso = surface.isocurve(fixed_direction, fixed, 0)?;
            let map = MonotoneMap::new(params, &s.crossings);
            for w in params.windows(2) {
                for j in 0..=PER_INTERVAL {
                    let u = w[0] + (w[1] - w[0]) * j as f64 / PER_INTERVAL as f64;
                    let on_curve = s.curve.point_at(map.at(u))?;
                    let d = foot_on(&iso, on_curve, u)?.distance(on_curve);
                    if d > worst.distance {
                        worst = NetworkDeviation {
                            distance: d,
                            family,
                            curve: s.index,
                            point: on_curve,
                        };
                    }
                }
            }
        }
    }
    Ok(worst)
}

/// The point of `curve` nearest `target` near parameter `start`: Newton's iteration on
/// C′·(C − P) = 0 (The NURBS Book §6.1) from `start`, clamped to the domain, keeping the nearest
/// point seen.
fn foot_on(curve: &SpaceCurve, target: DVec3, start: f64) -> Result<DVec3, GeometryError> {
    let (a, b) = curve.domain();
    let mut t = start.clamp(a, b);
    let mut best = curve.point_at(t)?;
    for _ in 0..8 {
        let d = curve.derivatives(t, 2)?;
        if d[0].distance(target) < best.distance(target) {
            best = d[0];
        }
        let r = d[0] - target;
        let df = d[2].dot(r) + d[1].dot(d[1]);
        if !(df.abs() > 1e-300) {
            break;
        }
        t = (t - d[1].dot(r) / df).clamp(a, b);
    }
    let last = curve.point_at(t)?;
    Ok(if last.distance(target) < best.distance(target) {
        last
    } else {
        best
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::construct::arc;

    /// The parabola t ↦ (x(t), y(t), (x² + y²)/8) on the paraboloid, for the straight line
    /// from `a` to `b` in the xy-plane (x, y linear in t): a quadratic Bézier curve, its middle
    /// point from the tangent at a.
    fn on_paraboloid(a: (f64, f64), b: (f64, f64)) -> SpaceCurve {
        let z = |x: f64, y: f64| (x * x + y * y) / 8.0;
        let (dx, dy) = (b.0 - a.0, b.1 - a.1);
        let start = DVec3::new(a.0, a.1, z(a.0, a.1));
        let end = DVec3::new(b.0, b.1, z(b.0, b.1));
        let slope = (a.0 * dx + a.1 * dy) / 4.0; // dz/dt at a
        let middle = DVec3::new(a.0 + dx / 2.0, a.1 + dy / 2.0, start.z + slope / 2.0);
        SpaceCurve::new(
            2,
            vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
            vec![start, middle, end],
            None,
        )
        .unwrap()
    }

    #[test]
    fn a_shuffled_reversed_network_gives_a_surface_through_every_curve() {
        // u-curves at y = −2, 0.5, 2 and v-curves at x = −2, −0.3, 2, over different spans (so
        // that the crossings are not at common parameters), shuffled and some reversed. They
        // cross exactly: both lie on the paraboloid.
        let line_x = |y: f64, from: f64| on_paraboloid((from, y), (2.0, y));
        let line_y = |x: f64, to: f64| on_paraboloid((x, -2.0), (x, to));
        let us = vec![
            line_x(0.5, -2.7),
            line_x(-2.0, -2.0).reverse(),
            line_x(2.0, -2.2),
        ];
        let vs = vec![
            line_y(2.0, 2.0),
            line_y(-2.0, 3.0),
            line_y(-0.3, 2.5).reverse(),
        ];
        let network = network_surface(&us, &vs, 3).unwrap();
        assert!(network.deviation.distance < 1e-5, "{}", network.deviation);
        // Every input curve between its outermost crossings lies on the surface.
        for c in us.iter().chain(&vs) {
            for i in 0..=20 {
                let p = c.point_at(i as f64 / 20.0).unwrap();
                let inside = p.x >= -2.0 - 1e-12 && p.x <= 2.0 + 1e-12;
                let inside = inside && p.y >= -2.0 - 1e-12 && p.y <= 2.0 + 1e-12;
                if inside {
                    let d = network.surface.closest_point(p).unwrap().distance;
                    assert!(d < 1e-6, "{p} is {d} from the surface");
                }
            }
        }
        // The surface spans the network: its corners are the outer crossings.
        let corner = network.surface.point_at(0.0, 0.0).unwrap();
        assert!(
            corner.distance(DVec3::new(-2.0, -2.0, 1.0)) < 1e-9,
            "{corner}"
        );
    }

    #[test]
    fn rational_curves_are_followed_within_the_fit_tolerance() {
        // Two quarter circles (rational) and two lines, the boundary of a cylinder piece.
        let a0 = arc(
            DVec3::ZERO,
            DVec3::X,
            DVec3::Z,
            1.0,
            0.0,
            std::f64::consts::FRAC_PI_2,
        )
        .unwrap();
        let a1 = a0.map_points(|p| p + DVec3::Y * 2.0).unwrap();
        let l0 = crate::construct::line(DVec3::X, DVec3::X + DVec3::Y * 2.0).unwrap();
        let l1 = crate::construct::line(DVec3::Z, DVec3::Z + DVec3::Y * 2.0).unwrap();
        let network = network_surface(&[a0, a1], &[l1, l0], 3).unwrap();
        assert!(network.deviation.distance < 1e-5, "{}", network.deviation);
        // The middle of the patch is on the cylinder x² + z² = 1.
        let p = network.surface.point_at(0.5, 0.5).unwrap();
        assert!((p.x.hypot(p.z) - 1.0).abs() < 1e-5, "{p}");
    }

    #[test]
    fn curves_that_do_not_cross_are_named() {
        let u0 = crate::construct::line(DVec3::ZERO, DVec3::X).unwrap();
        let u1 = crate::construct::line(DVec3::Y, DVec3::new(1.0, 1.0, 0.0)).unwrap();
        let v0 = crate::construct::line(DVec3::ZERO, DVec3::Y).unwrap();
        let v1 =
            crate::construct::line(DVec3::new(1.0, 0.0, 0.5), DVec3::new(1.0, 1.0, 0.5)).unwrap();
        let e = network_surface(&[u0, u1], &[v0, v1], 3)
            .unwrap_err()
            .to_string();
        assert!(e.contains("u-curve 0 and v-curve 1 do not cross"), "{e}");
    }
}
