//! CPU tessellation in f64 for export: parameter grids chosen by a chordal tolerance or a fixed
//! segment count, triangulated with every vertex shared within a surface.
//!
//! The grid of a NURBS surface is one tensor grid over its whole domain that contains every
//! span break, so neighbouring spans share their edge vertices (no cracks, no T-junctions).
//! Positions, normals and curvatures come from the same kernel functions the GPU evaluator is
//! tested against ([`NurbsSurface::tessellate_grid`], [`NurbsSurface::curvature_grid`]).
//!
//! **Tolerance.** A first grid is sized from second-derivative bounds: the linear interpolant of
//! S over a triangle of the grid cell hu × hv deviates by at most
//! (hu² Muu + 2 hu hv Muv + hv² Mvv) / 8 (Filip, Magedson & Markot, "Surface algorithms using
//! bounds on derivatives", CAGD 3, 1986), with M the largest |Suu|, |Suv|, |Svv| sampled on each
//! span. Sampling is not a proof for a rational surface, so the grid is then *checked*: at every
//! triangle's centroid and edge midpoints, |S(u, v) − L(u, v)| (an upper bound of the distance
//! from the triangle to the surface there) must be ≤ the tolerance, and the spans of any cell
//! that fails are refined until none does.

use glam::DVec3;

use super::diffgeo::CurvatureValues;
use super::surface::GridSample;
use super::{BezierPatchSet, Direction, GeometryError, NurbsSurface, PolygonMesh};

/// How finely to tessellate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Tessellation {
    /// The largest allowed distance (model units) between the triangles and the surface.
    Tolerance(f64),
    /// Segments per Bézier span edge (per patch edge, per mesh face edge), like the viewport.
    Segments(u32),
}

/// The most segments a grid may have per span edge.
pub const MAX_SPAN_SEGMENTS: usize = 4096;
/// The most triangles one tessellation (and one export) may produce: about 1 GiB of f64 vertex
/// data while building on a 64-bit machine. A 32-bit address space (the page's wasm32, where a
/// failed allocation aborts) holds a fifth of that: at most about 250 MiB while building.
pub const MAX_TRIANGLES: usize = if usize::BITS < 64 {
    4_000_000
} else {
    20_000_000
};

/// Samples per span and direction for the second-derivative estimate.
const DERIVATIVE_SAMPLES: usize = 5;
/// The fraction of the tolerance the one coarsening step aims the worst deviation at.
const COARSEN_TARGET: f64 = 0.8;
/// Refinement rounds of the tolerance check before giving up.
const CHECK_ROUNDS: usize = 12;

/// A tessellated surface: vertices (shared by the triangles that meet there) and triangles,
/// wound counter-clockwise seen from the side the normals point to.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TriangleMesh {
    pub positions: Vec<DVec3>,
    /// Unit normals.
    pub normals: Vec<DVec3>,
    /// (u, v) normalized to [0, 1] over the surface's domain; empty for a polygon mesh.
    pub uvs: Vec<[f64; 2]>,
    /// K, H, k1, k2 per vertex; empty unless asked for.
    pub curvatures: Vec<CurvatureValues>,
    pub triangles: Vec<[u32; 3]>,
}

impl TriangleMesh {
    /// The sum of the triangles' areas.
    pub fn area(&self) -> f64 {
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|k| self.positions[k as usize]);
                0.5 * (b - a).cross(c - a).length()
            })
            .sum()
    }

    /// The signed volume the triangles enclose, Σ a · (b × c) / 6 (the divergence theorem
    /// over a closed mesh; positive when they face outward).
    pub fn signed_volume(&self) -> f64 {
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|k| self.positions[k as usize]);
                a.dot(b.cross(c)) / 6.0
            })
            .sum()
    }
}

/// A tensor grid of parameters over a surface's domain.
#[derive(Debug, Clone, PartialEq)]
pub struct ParameterGrid {
    pub us: Vec<f64>,
    pub vs: Vec<f64>,
}

impl ParameterGrid {
    /// How many triangles the grid makes before zero-area ones are left out: two per cell
    /// ([`triangulate`]).
    pub fn triangle_count(&self) -> usize {
        2 * (self.us.len() - 1) * (self.vs.len() - 1)
    }
}

/// `segments` uniform steps in every span of `breaks`.
fn subdivide(breaks: &[f64], segments: &[usize]) -> Vec<f64> {
    let mut out = vec![breaks[0]];
    for (w, &n) in breaks.windows(2).zip(segments) {
        out.extend((1..n).map(|k| w[0] + (w[1] - w[0]) * k as f64 / n as f64));
        out.push(w[1]);
    }
    out
}

fn too_fine(what: &str) -> GeometryError {
    GeometryError::Construction {
        what: "tessellation",
        message: format!(
            "{what}: choose a larger tolerance or fewer segments (at most {MAX_SPAN_SEGMENTS} segments per span, {MAX_TRIANGLES} triangles)"
        ),
    }
}

/// The uniform grid with `segments` segments in every span (the viewport's tessellation).
pub fn uniform_grid(surface: &NurbsSurface, segments: u32) -> Result<ParameterGrid, GeometryError> {
    let n = segments as usize;
    if !(1..=MAX_SPAN_SEGMENTS).contains(&n) {
        return Err(too_fine(&format!("{segments} segments per span")));
    }
    let [bu, bv] = [Direction::U, Direction::V].map(|d| surface.span_breaks(d));
    Ok(ParameterGrid {
        us: subdivide(&bu, &vec![n; bu.len() - 1]),
        vs: subdivide(&bv, &vec![n; bv.len() - 1]),
    })
}

/// The grid whose triangles lie within `tolerance` of the surface at their centroids and edge
/// midpoints (see the module documentation), with span counts as low as the bound allows.
pub fn tolerance_grid(
    surface: &NurbsSurface,
    tolerance: f64,
) -> Result<ParameterGrid, GeometryError> {
    check_tolerance(tolerance)?;
    let [bu, bv] = [Direction::U, Direction::V].map(|d| surface.span_breaks(d));
    let (mut nu, mut nv) = estimated_segments(surface, &bu, &bv, tolerance)?;
    let mut coarsened = false;
    for _ in 0..CHECK_ROUNDS {
        let grid = ParameterGrid {
            us: subdivide(&bu, &nu),
            vs: subdivide(&bv, &nv),
        };
        if grid.triangle_count() > MAX_TRIANGLES {
            return Err(too_fine(&format!("tolerance {tolerance}")));
        }
        let deviations = cell_deviations(surface, &grid)?;
        let cols = grid.vs.len() - 1;
        let failing: Vec<(usize, usize, f64)> = deviations
            .iter()
            .enumerate()
            .filter(|(_, d)| !(**d <= tolerance))
            .map(|(k, &d)| (k / cols, k % cols, d))
            .collect();
        if failing.is_empty() && !coarsened {
            // The derivative bound is pessimistic (often 3× or more): once, widen each span's
            // steps by √(target / its worst deviation), since the deviation grows with h².
            // A cell's new deviation is then about ≤ target (its span column's and row's worst
            // bound it), and the check below catches the rest.
            coarsened = true;
            let target = COARSEN_TARGET * tolerance;
            let mut worst_u = vec![0.0f64; nu.len()];
            let mut worst_v = vec![0.0f64; nv.len()];
            for (k, &d) in deviations.iter().enumerate() {
                let (a, b) = (
                    span_of(&grid.us, &bu, k / cols),
                    span_of(&grid.vs, &bv, k % cols),
                );
                worst_u[a] = worst_u[a].max(d);
                worst_v[b] = worst_v[b].max(d);
            }
            let mut changed = false;
            for (n, worst) in nu.iter_mut().zip(worst_u).chain(nv.iter_mut().zip(worst_v)) {
                let coarser = ((*n as f64) * (worst / target).sqrt()).ceil().max(1.0) as usize;
                if coarser < *n {
                    *n = coarser;
                    changed = true;
                }
            }
            if changed {
                continue;
            }
        }
        if failing.is_empty() {
            return Ok(grid);
        }
        // Refine the spans that hold a failing cell, in proportion to √(deviation / tolerance)
        // (the error falls with h²).
        let mut factor_u = vec![1.0f64; nu.len()];
        let mut factor_v = vec![1.0f64; nv.len()];
        for (i, j, deviation) in failing {
            let f = (1.2 * (deviation / tolerance).sqrt()).clamp(1.25, 4.0);
            let (a, b) = (span_of(&grid.us, &bu, i), span_of(&grid.vs, &bv, j));
            factor_u[a] = factor_u[a].max(f);
            factor_v[b] = factor_v[b].max(f);
        }
        for (n, f) in nu
            .iter_mut()
            .zip(factor_u)
            .chain(nv.iter_mut().zip(factor_v))
        {
            if f > 1.0 {
                *n = ((*n as f64 * f).ceil() as usize).max(*n + 1);
                if *n > MAX_SPAN_SEGMENTS {
                    return Err(too_fine(&format!("tolerance {tolerance}")));
                }
            }
        }
    }
    Err(too_fine(&format!("tolerance {tolerance}")))
}

/// How closely [`estimated_triangles`] estimates a tolerance's triangles.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Estimate {
    /// The grid the derivative bounds size: 25 derivative samples per span pair, an estimate
    /// from above (the bound is pessimistic, often by 2 or 3 in triangles).
    Bound,
    /// The bound with [`tolerance_grid`]'s coarsening measured on a sample of the cells:
    /// within a few per cent (about 250 cell checks per surface).
    Close,
}

/// About how many triangles [`grid_for`] gives `surface` at `tessellation`, in time bounded by
/// its span count (never by the answer): exact for segments; for a tolerance, the grid the
/// derivative bounds size ([`estimated_segments`], 25 samples per span pair), with
/// [`Estimate::Close`] the one coarsening step of [`tolerance_grid`] estimated on a sample of
/// its cells, at most [`ESTIMATE_CELLS`] of them.
pub fn estimated_triangles(
    surface: &NurbsSurface,
    tessellation: Tessellation,
    how: Estimate,
) -> Result<usize, GeometryError> {
    let [bu, bv] = [Direction::U, Direction::V].map(|d| surface.span_breaks(d));
    let (nu, nv) = match tessellation {
        Tessellation::Segments(n) => {
            let n = (n as usize).clamp(1, MAX_SPAN_SEGMENTS);
            (vec![n; bu.len() - 1], vec![n; bv.len() - 1])
        }
        Tessellation::Tolerance(t) => {
            check_tolerance(t)?;
            let bound = estimated_segments(surface, &bu, &bv, t)?;
            match how {
                Estimate::Bound => bound,
                Estimate::Close => sampled_coarsening(surface, &bu, &bv, bound, t)?,
            }
        }
    };
    let (cu, cv): (usize, usize) = (nu.iter().sum(), nv.iter().sum());
    Ok(2usize.saturating_mul(cu).saturating_mul(cv))
}

/// The most grid cells [`estimated_triangles`] measures.
pub const ESTIMATE_CELLS: usize = 256;

/// [`tolerance_grid`]'s coarsening step on the grid `(nu, nv)`, each span's worst deviation
/// measured on an evenly spread sample of its cells (every cell of a small grid).
fn sampled_coarsening(
    surface: &NurbsSurface,
    bu: &[f64],
    bv: &[f64],
    (mut nu, mut nv): (Vec<usize>, Vec<usize>),
    tolerance: f64,
) -> Result<(Vec<usize>, Vec<usize>), GeometryError> {
    let (us, vs) = (subdivide(bu, &nu), subdivide(bv, &nv));
    let (rows, cols) = (us.len() - 1, vs.len() - 1);
    // A stride per direction so that about ESTIMATE_CELLS cells are measured, each span hit.
    let per_direction = (ESTIMATE_CELLS as f64).sqrt() as usize;
    let pick = |cells: usize, counts: &[usize]| -> Vec<usize> {
        let stride = cells.div_ceil(per_direction).max(1);
        let mut picked: Vec<usize> = (0..cells).step_by(stride).collect();
        let mut first = 0;
        for &n in counts {
            picked.push(first + n / 2);
            first += n;
        }
        picked.sort_unstable();
        picked.dedup();
        picked
    };
    let (pick_u, pick_v) = (pick(rows, &nu), pick(cols, &nv));
    let mut worst_u = vec![0.0f64; nu.len()];
    let mut worst_v = vec![0.0f64; nv.len()];
    for &i in &pick_u {
        for &j in &pick_v {
            let cell = ParameterGrid {
                us: vec![us[i], us[i + 1]],
                vs: vec![vs[j], vs[j + 1]],
            };
            let d = cell_deviations(surface, &cell)?[0];
            let (a, b) = (span_of(&us, bu, i), span_of(&vs, bv, j));
            worst_u[a] = worst_u[a].max(d);
            worst_v[b] = worst_v[b].max(d);
        }
    }
    let target = COARSEN_TARGET * tolerance;
    for (n, worst) in nu.iter_mut().zip(worst_u).chain(nv.iter_mut().zip(worst_v)) {
        if worst.is_finite() {
            *n = ((*n as f64) * (worst / target).sqrt())
                .ceil()
                .clamp(1.0, *n as f64) as usize;
        }
    }
    Ok((nu, nv))
}

/// A tolerance is finite and > 0.
fn check_tolerance(tolerance: f64) -> Result<(), GeometryError> {
    if tolerance.is_finite() && tolerance > 0.0 {
        return Ok(());
    }
    Err(GeometryError::Construction {
        what: "tessellation",
        message: format!("the tolerance must be finite and > 0, got {tolerance}"),
    })
}

/// The span of `breaks` that grid cell `cell` (between `params[cell]` and `params[cell + 1]`)
/// lies in.
fn span_of(params: &[f64], breaks: &[f64], cell: usize) -> usize {
    let mid = 0.5 * (params[cell] + params[cell + 1]);
    breaks.windows(2).position(|w| mid <= w[1]).unwrap_or(0)
}

/// Segments per u-span and per v-span from sampled second-derivative bounds: per span pair,
/// hu² Muu ≤ 2T, hv² Mvv ≤ 2T and hu hv Muv ≤ 2T, so the bound (…)/8 is ≤ T; each u-span takes
/// the most any of its v-spans needs, and the other way round.
fn estimated_segments(
    surface: &NurbsSurface,
    bu: &[f64],
    bv: &[f64],
    tolerance: f64,
) -> Result<(Vec<usize>, Vec<usize>), GeometryError> {
    let samples = |breaks: &[f64]| -> Vec<f64> {
        breaks
            .windows(2)
            .flat_map(|w| {
                (0..DERIVATIVE_SAMPLES)
                    .map(move |k| w[0] + (w[1] - w[0]) * k as f64 / (DERIVATIVE_SAMPLES - 1) as f64)
            })
            .collect()
    };
    let (su, sv) = (samples(bu), samples(bv));
    let (spans_u, spans_v) = (bu.len() - 1, bv.len() - 1);
    // Per span pair: the largest |Suu|, |Suv|, |Svv|.
    let mut bounds = vec![[0.0f64; 3]; spans_u * spans_v];
    surface.evaluate_grid(&su, &sv, true, |i, j, d| {
        let cell = (i / DERIVATIVE_SAMPLES) * spans_v + j / DERIVATIVE_SAMPLES;
        let m = &mut bounds[cell];
        for (slot, value) in m.iter_mut().zip([d.suu, d.suv, d.svv]) {
            let length = value.length();
            if length.is_finite() {
                *slot = slot.max(length);
            }
        }
    })?;
    let mut nu = vec![1usize; spans_u];
    let mut nv = vec![1usize; spans_v];
    let safety = 1.25;
    for a in 0..spans_u {
        for b in 0..spans_v {
            let [muu, muv, mvv] = bounds[a * spans_v + b].map(|m| m * safety);
            let (wu, wv) = (bu[a + 1] - bu[a], bv[b + 1] - bv[b]);
            let mut hu = if muu > 0.0 {
                (2.0 * tolerance / muu).sqrt()
            } else {
                wu
            };
            let mut hv = if mvv > 0.0 {
                (2.0 * tolerance / mvv).sqrt()
            } else {
                wv
            };
            hu = hu.min(wu);
            hv = hv.min(wv);
            if hu * hv * muv > 2.0 * tolerance {
                let s = (2.0 * tolerance / (hu * hv * muv)).sqrt();
                hu *= s;
                hv *= s;
            }
            let count = |w: f64, h: f64| ((w / h).ceil() as usize).clamp(1, MAX_SPAN_SEGMENTS);
            nu[a] = nu[a].max(count(wu, hu));
            nv[b] = nv[b].max(count(wv, hv));
        }
    }
    Ok((nu, nv))
}

/// The worst |S(t) − L(t)| per grid cell (row-major, cell (i, j) at i · (|vs| − 1) + j) over
/// the centroids and edge midpoints of its two triangles (00, 10, 11) and (00, 11, 01).
pub fn cell_deviations(
    surface: &NurbsSurface,
    grid: &ParameterGrid,
) -> Result<Vec<f64>, GeometryError> {
    let (us, vs) = (&grid.us, &grid.vs);
    let points = |u: &[f64], v: &[f64]| surface.point_grid(u, v);
    let between = |t: &[f64], a: f64| -> Vec<f64> {
        t.windows(2).map(|w| w[0] + (w[1] - w[0]) * a).collect()
    };
    let (nu, nv) = (us.len(), vs.len());
    let corners = points(us, vs)?;
    let mid_u = between(us, 0.5);
    let mid_v = between(vs, 0.5);
    let u_edges = points(&mid_u, vs)?; // (i + ½, j)
    let v_edges = points(us, &mid_v)?; // (i, j + ½)
    let centres = points(&mid_u, &mid_v)?; // the diagonals' midpoints
    let centroid_a = points(&between(us, 2.0 / 3.0), &between(vs, 1.0 / 3.0))?;
    let centroid_b = points(&between(us, 1.0 / 3.0), &between(vs, 2.0 / 3.0))?;
    let mut out = Vec::with_capacity((nu - 1) * (nv - 1));
    for i in 0..nu - 1 {
        for j in 0..nv - 1 {
            let [p00, p10, p11, p01] = cell_corners(nv, i, j).map(|k| corners[k]);
            let c = i * (nv - 1) + j;
            let checks = [
                (u_edges[i * nv + j], 0.5 * (p00 + p10)),
                (u_edges[i * nv + j + 1], 0.5 * (p01 + p11)),
                (v_edges[i * (nv - 1) + j], 0.5 * (p00 + p01)),
                (v_edges[(i + 1) * (nv - 1) + j], 0.5 * (p10 + p11)),
                (centres[c], 0.5 * (p00 + p11)),
                (centroid_a[c], (p00 + p10 + p11) / 3.0),
                (centroid_b[c], (p00 + p11 + p01) / 3.0),
            ];
            out.push(
                checks
                    .iter()
                    .map(|(s, l)| s.distance(*l))
                    .fold(0.0, f64::max),
            );
        }
    }
    Ok(out)
}

/// `a`, the sorted `values` strictly between `a` and `b`, and `b`: parameter lines (a grid's,
/// a surface's span breaks) cut to [a, b].
pub(crate) fn values_within(values: &[f64], a: f64, b: f64) -> Vec<f64> {
    let mut out = vec![a];
    out.extend(values.iter().copied().filter(|&x| x > a && x < b));
    out.push(b);
    out
}

/// The grid for `tessellation`.
pub fn grid_for(
    surface: &NurbsSurface,
    tessellation: Tessellation,
) -> Result<ParameterGrid, GeometryError> {
    match tessellation {
        Tessellation::Tolerance(t) => tolerance_grid(surface, t),
        Tessellation::Segments(n) => uniform_grid(surface, n),
    }
}

/// Points, unit normals and (when asked) K, H, k1, k2 of a surface on a tensor grid,
/// row-major (u outer, as [`NurbsSurface::tessellate_grid`] orders them).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct GridValues {
    pub samples: Vec<GridSample>,
    /// One per sample when curvature was asked for, else empty.
    pub curvatures: Vec<CurvatureValues>,
}

/// Who evaluates export grids. [`KernelGrids`] is the f64 kernel (the reference); the editor
/// also has one on the GPU's compute shaders, whose answers agree within f32 precision. The
/// grids themselves, the triangles and everything else of an export are chosen on the CPU, so
/// the two give the same topology.
pub trait GridSampler: Sync {
    /// Every `(surface, grid)` of `jobs` evaluated on its grid, in order; curvatures when
    /// `curvature`.
    fn sample_grids(
        &self,
        jobs: &[(&NurbsSurface, &ParameterGrid)],
        curvature: bool,
    ) -> Result<Vec<GridValues>, GeometryError>;

    /// How far rounding may move the positions it returns for `surface` (a distance): two
    /// corners of a triangle within twice this are one point, so the triangle has no area (a
    /// pole's triangles stay out whoever evaluates, and wherever the surface lies). By
    /// default f64 rounding ([`rounding_slack`]).
    fn position_slack(&self, surface: &NurbsSurface) -> f64 {
        rounding_slack(surface)
    }
}

/// 16 units in the last place of f64 at `surface`'s largest coordinate: how far rounding may
/// move a point the kernel evaluates on it.
pub fn rounding_slack(surface: &NurbsSurface) -> f64 {
    let (lo, hi) = surface.bounds();
    let largest = lo.abs().max(hi.abs()).max_element();
    if largest.is_finite() {
        16.0 * f64::EPSILON * largest
    } else {
        0.0
    }
}

/// The f64 kernel's grids ([`NurbsSurface::tessellate_grid`], [`NurbsSurface::curvature_grid`]),
/// the jobs spread over rayon's pool (each computed on its own, so any thread count gives the
/// same bits).
#[derive(Debug, Clone, Copy, Default)]
pub struct KernelGrids;

impl GridSampler for KernelGrids {
    fn sample_grids(
        &self,
        jobs: &[(&NurbsSurface, &ParameterGrid)],
        curvature: bool,
    ) -> Result<Vec<GridValues>, GeometryError> {
        crate::par::map(jobs.len(), |j| {
            let (surface, grid) = jobs[j];
            if curvature {
                let (samples, curvatures) = surface
                    .curvature_grid(&grid.us, &grid.vs)?
                    .into_iter()
                    .unzip();
                Ok(GridValues {
                    samples,
                    curvatures,
                })
            } else {
                Ok(GridValues {
                    samples: surface.tessellate_grid(&grid.us, &grid.vs)?,
                    curvatures: Vec::new(),
                })
            }
        })
        .into_iter()
        .collect()
    }
}

/// The surface on `grid` as a triangle mesh: positions and unit normals from
/// [`NurbsSurface::tessellate_grid`] (curvatures from [`NurbsSurface::curvature_grid`] when
/// `curvature`), (u, v) normalized over the domain, and two triangles per cell. Triangles of
/// zero area (at a pole or collapsed edge) are left out.
pub fn triangulate(
    surface: &NurbsSurface,
    grid: &ParameterGrid,
    curvature: bool,
) -> Result<TriangleMesh, GeometryError> {
    triangulate_with(surface, grid, curvature, &KernelGrids)
}

/// [`triangulate`] with the grid evaluated by `sampler`.
pub fn triangulate_with(
    surface: &NurbsSurface,
    grid: &ParameterGrid,
    curvature: bool,
    sampler: &dyn GridSampler,
) -> Result<TriangleMesh, GeometryError> {
    triangulate_all(&[(surface, grid)], curvature, sampler)?
        .pop()
        .ok_or_else(|| sampler_error(1, 0))
}

/// Every `(surface, grid)` of `jobs` triangulated as [`triangulate`] does, the grids evaluated
/// by `sampler` in one call.
pub fn triangulate_all(
    jobs: &[(&NurbsSurface, &ParameterGrid)],
    curvature: bool,
    sampler: &dyn GridSampler,
) -> Result<Vec<TriangleMesh>, GeometryError> {
    let values = sampler.sample_grids(jobs, curvature)?;
    if values.len() != jobs.len() {
        return Err(sampler_error(jobs.len(), values.len()));
    }
    meshes_on_grids(jobs.iter().copied(), values, curvature, &|surface| {
        sampler.position_slack(surface)
    })
}

/// How far the rounding of whoever evaluated a grid may move the positions on a surface
/// ([`GridSampler::position_slack`]).
pub type PositionSlack<'a> = &'a dyn Fn(&NurbsSurface) -> f64;

/// The triangle mesh of each `(surface, grid)` of `jobs` from its grid's `values`, with
/// triangles of no area within `slack` left out.
fn meshes_on_grids<'a>(
    jobs: impl Iterator<Item = (&'a NurbsSurface, &'a ParameterGrid)>,
    values: Vec<GridValues>,
    curvature: bool,
    slack: PositionSlack<'_>,
) -> Result<Vec<TriangleMesh>, GeometryError> {
    jobs.zip(values)
        .map(|((surface, grid), values)| {
            mesh_on_grid(surface, grid, values, curvature, slack(surface))
        })
        .collect()
}

/// The rest of a [`GridPlan`]: its meshes from its jobs, their values (or why there are
/// none) and the rounding of whoever evaluated them.
type FinishPlan = Box<
    dyn FnOnce(
            &[(NurbsSurface, ParameterGrid)],
            Result<Vec<GridValues>, GeometryError>,
            PositionSlack<'_>,
        ) -> Result<Vec<TriangleMesh>, GeometryError>
        + Send,
>;

/// A tessellation worked out up to its grid evaluation: the surfaces and parameter grids whose
/// points it needs, and the rest of the work, run once their values are known
/// ([`Self::finish`]). Everything but the evaluation is chosen on the CPU, so a plan finished
/// with any sampler's values has the same topology as [`Self::run`]'s. It lets the grids be
/// evaluated where the caller cannot wait for them: by the GPU in the web page, whose values
/// are read back a frame or more later.
pub struct GridPlan {
    jobs: Vec<(NurbsSurface, ParameterGrid)>,
    curvature: bool,
    finish: FinishPlan,
}

impl GridPlan {
    /// A plan with nothing to evaluate: `meshes` are its result.
    pub fn done(meshes: Vec<TriangleMesh>) -> Self {
        Self {
            jobs: Vec::new(),
            curvature: false,
            finish: Box::new(move |_, _, _| Ok(meshes)),
        }
    }

    /// A plan that evaluates `jobs` (curvatures too when `curvature`) and then calls `finish`
    /// with them, their values and the rounding of whoever evaluated them. A sampler that
    /// answers with a different number of grids than `jobs` reaches `finish` as an error.
    pub fn new(
        jobs: Vec<(NurbsSurface, ParameterGrid)>,
        curvature: bool,
        finish: impl FnOnce(
            &[(NurbsSurface, ParameterGrid)],
            Result<Vec<GridValues>, GeometryError>,
            PositionSlack<'_>,
        ) -> Result<Vec<TriangleMesh>, GeometryError>
        + Send
        + 'static,
    ) -> Self {
        Self {
            jobs,
            curvature,
            finish: Box::new(finish),
        }
    }

    /// The plan of [`triangulate_all`]: each surface's mesh on its grid.
    pub fn triangulate(jobs: Vec<(NurbsSurface, ParameterGrid)>, curvature: bool) -> Self {
        Self::new(jobs, curvature, move |jobs, values, slack| {
            meshes_on_grids(
                jobs.iter().map(|(surface, grid)| (surface, grid)),
                values?,
                curvature,
                slack,
            )
        })
    }

    /// This plan with `then` applied to its meshes once they are made.
    pub fn then(
        self,
        then: impl FnOnce(Vec<TriangleMesh>) -> Result<Vec<TriangleMesh>, GeometryError>
        + Send
        + 'static,
    ) -> Self {
        let Self {
            jobs,
            curvature,
            finish,
        } = self;
        Self {
            jobs,
            curvature,
            finish: Box::new(move |jobs, values, slack| then(finish(jobs, values, slack)?)),
        }
    }

    /// The surfaces and grids to evaluate (none when the plan is [`Self::done`]).
    pub fn jobs(&self) -> Vec<(&NurbsSurface, &ParameterGrid)> {
        self.jobs
            .iter()
            .map(|(surface, grid)| (surface, grid))
            .collect()
    }

    /// Whether the grids' curvatures are asked for too.
    pub fn curvature(&self) -> bool {
        self.curvature
    }

    /// The meshes, from the values of [`Self::jobs`] (or why there are none) and the rounding
    /// of whoever evaluated them (`slack`, [`GridSampler::position_slack`]).
    pub fn finish(
        self,
        values: Result<Vec<GridValues>, GeometryError>,
        slack: PositionSlack<'_>,
    ) -> Result<Vec<TriangleMesh>, GeometryError> {
        let values = values.and_then(|values| {
            if values.len() == self.jobs.len() {
                Ok(values)
            } else {
                Err(sampler_error(self.jobs.len(), values.len()))
            }
        });
        (self.finish)(&self.jobs, values, slack)
    }

    /// The meshes, with the grids evaluated by `sampler` now.
    pub fn run(self, sampler: &dyn GridSampler) -> Result<Vec<TriangleMesh>, GeometryError> {
        let values = if self.jobs.is_empty() {
            Ok(Vec::new())
        } else {
            sampler.sample_grids(&self.jobs(), self.curvature)
        };
        self.finish(values, &|surface| sampler.position_slack(surface))
    }
}

/// Grids evaluated without the caller waiting for them: asked for in one frame, collected in a
/// later one. The GPU's compute shaders in the web page, which cannot wait for a readback
/// inside a frame.
pub trait DeferredGridSampler {
    /// Starts evaluating every `(surface, grid)` of `jobs` (curvatures too when `curvature`).
    fn request(
        &self,
        jobs: &[(&NurbsSurface, &ParameterGrid)],
        curvature: bool,
    ) -> Result<Box<dyn PendingGridValues>, GeometryError>;

    /// How far rounding may move the positions it returns for `surface`
    /// ([`GridSampler::position_slack`]).
    fn position_slack(&self, surface: &NurbsSurface) -> f64;
}

/// Grids on their way ([`DeferredGridSampler::request`]).
pub trait PendingGridValues {
    /// Every grid's values, in the order asked, once all have arrived; `None` while some are
    /// still on their way, an error where the evaluation failed.
    fn poll(&mut self) -> Option<Result<Vec<GridValues>, GeometryError>>;
}

/// The error for a sampler that answered `got` of `asked` grids or samples.
fn sampler_error(asked: usize, got: usize) -> GeometryError {
    GeometryError::Construction {
        what: "grid evaluation",
        message: format!("asked for {asked} values, the evaluator returned {got}"),
    }
}

/// The triangle mesh of `surface` on `grid` from the grid's evaluated `values`: (u, v)
/// normalized over the domain, two triangles per cell, those of zero area (within `slack`, a
/// distance: [`is_degenerate`]) left out.
fn mesh_on_grid(
    surface: &NurbsSurface,
    grid: &ParameterGrid,
    values: GridValues,
    curvature: bool,
    slack: f64,
) -> Result<TriangleMesh, GeometryError> {
    let (us, vs) = (&grid.us, &grid.vs);
    let count = us.len() * vs.len();
    if values.samples.len() != count || (curvature && values.curvatures.len() != count) {
        return Err(sampler_error(count, values.samples.len()));
    }
    let mut mesh = TriangleMesh {
        positions: values.samples.iter().map(|s| s.point).collect(),
        normals: values.samples.iter().map(|s| s.normal).collect(),
        curvatures: values.curvatures,
        ..Default::default()
    };
    let [(u0, u1), (v0, v1)] = surface.domain();
    mesh.uvs = us
        .iter()
        .flat_map(|&u| {
            vs.iter()
                .map(move |&v| [(u - u0) / (u1 - u0), (v - v0) / (v1 - v0)])
        })
        .collect();
    let nv = vs.len();
    for i in 0..us.len() - 1 {
        for j in 0..nv - 1 {
            let [a, b, c, d] = cell_corners(nv, i, j).map(|k| k as u32);
            for t in [[a, b, c], [a, c, d]] {
                if !is_degenerate(&mesh.positions, t, slack) {
                    mesh.triangles.push(t);
                }
            }
        }
    }
    Ok(mesh)
}

/// The vertex indices (i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1) of grid cell (i, j) in a
/// row-major grid with `nv` vertices per row; its triangles are (0, 1, 2) and (0, 2, 3).
fn cell_corners(nv: usize, i: usize, j: usize) -> [usize; 4] {
    [
        i * nv + j,
        (i + 1) * nv + j,
        (i + 1) * nv + j + 1,
        i * nv + j + 1,
    ]
}

/// Whether triangle `t` has (numerically) no area: twice its area at most 1e-12 of its
/// longest edge squared, or an edge of at most 2 `slack` (how far rounding may move the
/// positions: two corners that are one point, as at a pole, placed a rounding error apart).
fn is_degenerate(positions: &[DVec3], t: [u32; 3], slack: f64) -> bool {
    let [a, b, c] = t.map(|i| positions[i as usize]);
    let (e1, e2, e3) = (b - a, c - a, c - b);
    let lengths = [e1, e2, e3].map(DVec3::length_squared);
    let scale = lengths[0].max(lengths[1]).max(lengths[2]);
    let shortest = lengths[0].min(lengths[1]).min(lengths[2]);
    e1.cross(e2).length() <= 1e-12 * scale || shortest <= 4.0 * slack * slack
}

/// One Bézier patch of a set as a NURBS surface on [0, 1]².
pub fn patch_surface(set: &BezierPatchSet, patch: usize) -> Result<NurbsSurface, GeometryError> {
    let p = set.patches().get(patch).ok_or(GeometryError::NoSuchPatch {
        patch,
        count: set.patches().len(),
    })?;
    let (du, dv) = (p.degree_u(), p.degree_v());
    let mut points = Vec::with_capacity((du + 1) * (dv + 1));
    let mut weights = Vec::with_capacity(points.capacity());
    for i in 0..=du {
        for j in 0..=dv {
            let k = p.index(i, j) as usize;
            points.push(set.points()[k]);
            weights.push(set.weights()[k]);
        }
    }
    NurbsSurface::bezier([du, dv], points, Some(weights))
}

/// Every patch of `set`, each on its own grid (one piece per patch, (u, v) the patch's own).
/// Patches that share an edge (the same control point indices along it, in either order) take
/// the same segment count along it, so they place the same vertices there (no cracks): the
/// counts live in classes of joined edge directions ([`edge_count_classes`]), each the largest
/// any of its patches needs.
pub fn tessellate_patches(
    set: &BezierPatchSet,
    tessellation: Tessellation,
    curvature: bool,
) -> Result<Vec<TriangleMesh>, GeometryError> {
    tessellate_patches_with(set, tessellation, curvature, &KernelGrids)
}

/// [`tessellate_patches`] with the grids evaluated by `sampler` (in one call).
pub fn tessellate_patches_with(
    set: &BezierPatchSet,
    tessellation: Tessellation,
    curvature: bool,
    sampler: &dyn GridSampler,
) -> Result<Vec<TriangleMesh>, GeometryError> {
    plan_patches(set, tessellation, curvature)?.run(sampler)
}

/// [`tessellate_patches`] up to the evaluation of its grids ([`GridPlan`]).
pub fn plan_patches(
    set: &BezierPatchSet,
    tessellation: Tessellation,
    curvature: bool,
) -> Result<GridPlan, GeometryError> {
    let surfaces = (0..set.patches().len())
        .map(|k| patch_surface(set, k))
        .collect::<Result<Vec<_>, _>>()?;
    let classes = edge_count_classes(set);
    let mut counts = vec![1usize; classes.len()];
    match tessellation {
        Tessellation::Segments(n) => counts.fill(n as usize),
        Tessellation::Tolerance(t) => {
            for (k, s) in surfaces.iter().enumerate() {
                let g = tolerance_grid(s, t)?;
                let (cu, cv) = (classes[2 * k], classes[2 * k + 1]);
                counts[cu] = counts[cu].max(g.us.len() - 1);
                counts[cv] = counts[cv].max(g.vs.len() - 1);
            }
        }
    }
    // A class's count can be coarser in one direction than a patch's own grid had; check again
    // and refine the classes of the patches that fail until every patch passes.
    let grids = loop {
        let grids: Vec<ParameterGrid> = (0..surfaces.len())
            .map(|k| ParameterGrid {
                us: subdivide(&[0.0, 1.0], &[counts[classes[2 * k]]]),
                vs: subdivide(&[0.0, 1.0], &[counts[classes[2 * k + 1]]]),
            })
            .collect();
        let triangles: usize = grids.iter().map(ParameterGrid::triangle_count).sum();
        if counts
            .iter()
            .any(|&n| !(1..=MAX_SPAN_SEGMENTS).contains(&n))
            || triangles > MAX_TRIANGLES
        {
            return Err(too_fine("this patch set"));
        }
        let Tessellation::Tolerance(t) = tessellation else {
            break grids;
        };
        let mut factors = vec![1.0f64; counts.len()];
        for (k, (s, g)) in surfaces.iter().zip(&grids).enumerate() {
            let worst = cell_deviations(s, g)?.into_iter().fold(0.0, f64::max);
            if !(worst <= t) {
                let f = (1.2 * (worst / t).sqrt()).clamp(1.25, 4.0);
                for class in [classes[2 * k], classes[2 * k + 1]] {
                    factors[class] = factors[class].max(f);
                }
            }
        }
        if factors.iter().all(|&f| f == 1.0) {
            break grids;
        }
        for (n, f) in counts.iter_mut().zip(factors) {
            if f > 1.0 {
                *n = ((*n as f64 * f).ceil() as usize).max(*n + 1);
            }
        }
    };
    Ok(GridPlan::triangulate(
        surfaces.into_iter().zip(grids).collect(),
        curvature,
    ))
}

/// About how many triangles [`tessellate_patches`] gives `set` at `tessellation`: each patch's
/// [`estimated_triangles`] grid, its counts shared along joined edges as there.
pub fn estimated_patch_triangles(
    set: &BezierPatchSet,
    tessellation: Tessellation,
    how: Estimate,
) -> Result<usize, GeometryError> {
    let classes = edge_count_classes(set);
    let mut counts = vec![1usize; classes.len()];
    for k in 0..set.patches().len() {
        let surface = patch_surface(set, k)?;
        let (nu, nv) = match tessellation {
            Tessellation::Segments(n) => {
                let n = (n as usize).clamp(1, MAX_SPAN_SEGMENTS);
                (n, n)
            }
            Tessellation::Tolerance(t) => {
                check_tolerance(t)?;
                let one = [0.0, 1.0];
                let first = estimated_segments(&surface, &one, &one, t)?;
                let (nu, nv) = match how {
                    Estimate::Bound => first,
                    Estimate::Close => sampled_coarsening(&surface, &one, &one, first, t)?,
                };
                (nu[0], nv[0])
            }
        };
        let (cu, cv) = (classes[2 * k], classes[2 * k + 1]);
        counts[cu] = counts[cu].max(nu);
        counts[cv] = counts[cv].max(nv);
    }
    Ok((0..set.patches().len())
        .map(|k| 2 * counts[classes[2 * k]] * counts[classes[2 * k + 1]])
        .sum())
}

/// For each patch k of `set`, the class of its u-direction count (entry 2k: the segments along
/// its v = 0 and v = 1 edges) and of its v-direction count (entry 2k + 1), numbered from 0.
/// Two directions are in one class when an edge of one is an edge of the other: the same
/// control point indices along it, in either order (union–find). Edges collapsed to one point
/// join nothing.
pub fn edge_count_classes(set: &BezierPatchSet) -> Vec<usize> {
    let slots = 2 * set.patches().len();
    let mut parent: Vec<usize> = (0..slots).collect();
    fn root(parent: &mut [usize], mut x: usize) -> usize {
        while parent[x] != x {
            parent[x] = parent[parent[x]];
            x = parent[x];
        }
        x
    }
    let mut seen: std::collections::HashMap<Vec<u32>, usize> = std::collections::HashMap::new();
    for (k, patch) in set.patches().iter().enumerate() {
        let (p, q) = (patch.degree_u(), patch.degree_v());
        let edges = [
            (
                2 * k,
                (0..=p).map(|i| patch.index(i, 0)).collect::<Vec<_>>(),
            ),
            (2 * k, (0..=p).map(|i| patch.index(i, q)).collect()),
            (2 * k + 1, (0..=q).map(|j| patch.index(0, j)).collect()),
            (2 * k + 1, (0..=q).map(|j| patch.index(p, j)).collect()),
        ];
        for (slot, mut key) in edges {
            if key.iter().all(|&i| i == key[0]) {
                continue;
            }
            if key.first() > key.last() {
                key.reverse();
            }
            let other = *seen.entry(key).or_insert(slot);
            let (a, b) = (root(&mut parent, slot), root(&mut parent, other));
            parent[a] = b;
        }
    }
    let mut numbers = std::collections::HashMap::new();
    (0..slots)
        .map(|slot| {
            let r = root(&mut parent, slot);
            let next = numbers.len();
            *numbers.entry(r).or_insert(next)
        })
        .collect()
}

/// A polygon mesh as one piece: every face (a bilinear patch, see
/// [`PolygonMesh::to_bezier_patch_set`]) on its own grid — one cell for a planar quad at any
/// tolerance — with vertices welded where position and normal agree exactly (so a smooth
/// region shares its vertices and a crease keeps one per side). No (u, v).
pub fn tessellate_mesh(
    mesh: &PolygonMesh,
    tessellation: Tessellation,
    curvature: bool,
) -> Result<TriangleMesh, GeometryError> {
    let set = mesh.to_bezier_patch_set()?;
    let mut out = TriangleMesh::default();
    let mut welded = std::collections::HashMap::new();
    for k in 0..set.patches().len() {
        let surface = patch_surface(&set, k)?;
        let grid = grid_for(&surface, tessellation)?;
        let piece = triangulate(&surface, &grid, curvature)?;
        let mut remap = Vec::with_capacity(piece.positions.len());
        for v in 0..piece.positions.len() {
            let (p, n) = (piece.positions[v], piece.normals[v]);
            let key = [p.x, p.y, p.z, n.x, n.y, n.z].map(f64::to_bits);
            let index = *welded.entry(key).or_insert_with(|| {
                out.positions.push(p);
                out.normals.push(n);
                if curvature {
                    out.curvatures.push(piece.curvatures[v]);
                }
                (out.positions.len() - 1) as u32
            });
            remap.push(index);
        }
        out.triangles
            .extend(piece.triangles.iter().map(|t| t.map(|i| remap[i as usize])));
        if out.triangles.len() > MAX_TRIANGLES {
            return Err(too_fine("this mesh"));
        }
    }
    Ok(out)
}

/// The most line segments [`curve_polyline`] gives one Bézier segment of a curve.
pub const MAX_CURVE_SEGMENTS: usize = 4096;

/// A curve as a polyline for export: per Bézier segment ([`SpaceCurve::span_breaks`]),
/// `Segments(n)` takes n equal parameter steps, and `Tolerance(t)` halves the steps until every
/// chord's midpoint lies within t of the curve's point at the middle parameter (at most
/// [`MAX_CURVE_SEGMENTS`] per segment). The first and last points are the curve's ends.
pub fn curve_polyline(
    curve: &crate::SpaceCurve,
    tessellation: Tessellation,
) -> Result<Vec<DVec3>, GeometryError> {
    let breaks = curve.span_breaks();
    let mut points = vec![curve.point_at(breaks[0])?];
    for span in breaks.windows(2) {
        let (a, b) = (span[0], span[1]);
        // Kept in [a, b]: a + (b − a) can round past b.
        let at = |k: usize, n: usize| (a + (b - a) * k as f64 / n as f64).clamp(a, b);
        let n = match tessellation {
            Tessellation::Segments(n) => (n as usize).clamp(1, MAX_CURVE_SEGMENTS),
            Tessellation::Tolerance(tolerance) => {
                let mut n = 2;
                while n < MAX_CURVE_SEGMENTS {
                    let mut worst = 0.0f64;
                    for k in 0..n {
                        let (p, q) = (curve.point_at(at(k, n))?, curve.point_at(at(k + 1, n))?);
                        let middle = curve.point_at(0.5 * (at(k, n) + at(k + 1, n)))?;
                        worst = worst.max(middle.distance(0.5 * (p + q)));
                    }
                    if worst <= tolerance {
                        break;
                    }
                    n *= 2;
                }
                n
            }
        };
        for k in 1..=n {
            points.push(curve.point_at(if k == n { b } else { at(k, n) })?);
        }
    }
    Ok(points)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::construct;

    #[test]
    fn the_estimate_is_within_five_percent_of_the_tessellation_and_never_builds_it() {
        let close = |estimate: usize, actual: usize, what: &str| {
            let ratio = estimate as f64 / actual as f64;
            assert!(
                (0.95..=1.05).contains(&ratio),
                "{what}: {estimate} for {actual}"
            );
        };
        let teapot = crate::samples::utah_teapot().unwrap();
        for t in [1e-2, 1e-3] {
            let estimate =
                estimated_patch_triangles(&teapot, Tessellation::Tolerance(t), Estimate::Close)
                    .unwrap();
            let actual = tessellate_patches(&teapot, Tessellation::Tolerance(t), false).unwrap();
            close(
                estimate,
                actual.iter().map(|p| p.triangles.len()).sum(),
                "teapot",
            );
        }
        let sphere = construct::sphere(DVec3::ZERO, 2.0).unwrap();
        let torus = construct::torus(DVec3::ZERO, DVec3::Z, 3.0, 1.0).unwrap();
        for (name, s) in [("sphere", &sphere), ("torus", &torus)] {
            for t in [1e-2, 1e-3, 1e-4] {
                let estimate =
                    estimated_triangles(s, Tessellation::Tolerance(t), Estimate::Close).unwrap();
                close(
                    estimate,
                    tolerance_grid(s, t).unwrap().triangle_count(),
                    name,
                );
            }
            let segments =
                estimated_triangles(s, Tessellation::Segments(7), Estimate::Bound).unwrap();
            assert_eq!(segments, uniform_grid(s, 7).unwrap().triangle_count());
        }
        // Far past what a tessellation may build: a number, not an error (nor the wait).
        let tiny =
            estimated_patch_triangles(&teapot, Tessellation::Tolerance(1e-9), Estimate::Bound)
                .unwrap();
        assert!(tiny > MAX_TRIANGLES, "{tiny}");
        assert!(
            estimated_triangles(&sphere, Tessellation::Tolerance(f64::NAN), Estimate::Close)
                .is_err()
        );
    }

    #[test]
    fn a_plane_needs_one_cell_per_span_and_a_cylinder_gets_finer_with_the_tolerance() {
        let plane = construct::plane(DVec3::ZERO, DVec3::X, DVec3::Y).unwrap();
        let grid = tolerance_grid(&plane, 1e-6).unwrap();
        assert_eq!((grid.us.len(), grid.vs.len()), (2, 2));
        let cylinder = construct::cylinder(DVec3::ZERO, DVec3::Z, 1.0).unwrap();
        let coarse = tolerance_grid(&cylinder, 1e-2).unwrap();
        let fine = tolerance_grid(&cylinder, 1e-4).unwrap();
        // Straight along the axis; around it a chord of angle θ deviates by 1 − cos(θ/2).
        assert_eq!(coarse.vs.len().min(coarse.us.len()), 2);
        let around = |g: &ParameterGrid| g.us.len().max(g.vs.len()) - 1;
        let needed = |t: f64| (std::f64::consts::TAU / (2.0 * (1.0 - t).acos())).ceil() as usize;
        assert!(around(&coarse) >= needed(1e-2), "{}", around(&coarse));
        assert!(around(&fine) >= needed(1e-4), "{}", around(&fine));
        // …and not wastefully more (the rational parametrization is not arc length).
        assert!(around(&fine) <= 3 * needed(1e-4), "{}", around(&fine));
        for g in [&coarse, &fine] {
            let worst = cell_deviations(&cylinder, g)
                .unwrap()
                .into_iter()
                .fold(0.0, f64::max);
            assert!(worst > 0.0);
        }
    }

    #[test]
    fn bad_tolerances_and_absurd_segment_counts_are_refused() {
        let sphere = construct::sphere(DVec3::ZERO, 1.0).unwrap();
        for t in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert!(tolerance_grid(&sphere, t).is_err(), "{t}");
        }
        assert!(tolerance_grid(&sphere, 1e-300).is_err());
        assert!(uniform_grid(&sphere, 0).is_err());
        assert!(uniform_grid(&sphere, 100_000).is_err());
    }

    #[test]
    fn teapot_patches_sharing_an_edge_share_its_count_and_the_count_follows_the_tolerance() {
        let teapot = crate::samples::utah_teapot().unwrap();
        let classes = edge_count_classes(&teapot);
        assert_eq!(classes.len(), 2 * teapot.patches().len());
        // Fewer classes than directions (edges are shared), more than one (not one global count).
        let distinct: std::collections::BTreeSet<_> = classes.iter().collect();
        assert!(
            distinct.len() > 1 && distinct.len() < classes.len(),
            "{distinct:?}"
        );
        let coarse = tessellate_patches(&teapot, Tessellation::Tolerance(1e-2), false).unwrap();
        let fine = tessellate_patches(&teapot, Tessellation::Tolerance(1e-3), false).unwrap();
        let count = |m: &[TriangleMesh]| m.iter().map(|p| p.triangles.len()).sum::<usize>();
        assert!(count(&fine) > 2 * count(&coarse));
        // Every patch's worst deviation is within the tolerance.
        for (k, piece) in fine.iter().enumerate() {
            let s = patch_surface(&teapot, k).unwrap();
            let axis = |c: usize| {
                let mut t: Vec<f64> = piece.uvs.iter().map(|uv| uv[c]).collect();
                t.sort_by(f64::total_cmp);
                t.dedup();
                t
            };
            let grid = ParameterGrid {
                us: axis(0),
                vs: axis(1),
            };
            let worst = cell_deviations(&s, &grid)
                .unwrap()
                .into_iter()
                .fold(0.0, f64::max);
            assert!(worst <= 1e-3, "patch {k}: {worst}");
        }
        // Patches that share an edge place the same vertices along it: no cracks.
        let mut edges: std::collections::HashMap<Vec<u32>, Vec<DVec3>> = Default::default();
        let mut shared = 0;
        for (k, piece) in fine.iter().enumerate() {
            let patch = &teapot.patches()[k];
            let (p, q) = (patch.degree_u(), patch.degree_v());
            let sides: [(Vec<u32>, usize, f64); 4] = [
                ((0..=p).map(|i| patch.index(i, 0)).collect(), 1, 0.0),
                ((0..=p).map(|i| patch.index(i, q)).collect(), 1, 1.0),
                ((0..=q).map(|j| patch.index(0, j)).collect(), 0, 0.0),
                ((0..=q).map(|j| patch.index(p, j)).collect(), 0, 1.0),
            ];
            for (mut key, fixed, at) in sides {
                if key.iter().all(|&i| i == key[0]) {
                    continue;
                }
                // The vertices on this edge, in order along it.
                let mut on_edge: Vec<(f64, DVec3)> = piece
                    .uvs
                    .iter()
                    .zip(&piece.positions)
                    .filter(|(uv, _)| uv[fixed] == at)
                    .map(|(uv, &x)| (uv[1 - fixed], x))
                    .collect();
                on_edge.sort_by(|a, b| a.0.total_cmp(&b.0));
                let mut points: Vec<DVec3> = on_edge.into_iter().map(|(_, x)| x).collect();
                if key.first() > key.last() {
                    key.reverse();
                    points.reverse();
                }
                if let Some(other) = edges.get(&key) {
                    assert_eq!(other.len(), points.len(), "patch {k}: {key:?}");
                    for (a, b) in other.iter().zip(&points) {
                        assert!(a.distance(*b) < 1e-9, "patch {k}: {a} vs {b}");
                    }
                    shared += 1;
                } else {
                    edges.insert(key, points);
                }
            }
        }
        assert!(shared > 20, "{shared} shared edges");
    }

    #[test]
    fn grid_triangles_face_the_normal_and_poles_lose_their_empty_triangles() {
        let sphere = construct::sphere(DVec3::ZERO, 1.0).unwrap();
        let grid = uniform_grid(&sphere, 4).unwrap();
        let mesh = triangulate(&sphere, &grid, false).unwrap();
        assert!(mesh.triangles.len() < grid.triangle_count());
        for t in &mesh.triangles {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
            let n = t.map(|i| mesh.normals[i as usize]);
            let face = (b - a).cross(c - a);
            assert!(face.dot(n[0] + n[1] + n[2]) > 0.0);
        }
    }

    /// Which triangles are empty does not depend on where the surface lies: a sphere's pole
    /// triangles stay out far from the origin too, where f64 rounding puts a pole's points a
    /// few units in the last place apart (it did not: 1e-12 of a small triangle's edge is
    /// below that rounding).
    #[test]
    fn pole_triangles_stay_out_far_from_the_origin() {
        let at_origin = construct::sphere(DVec3::ZERO, 1.0).unwrap();
        let grid = uniform_grid(&at_origin, 24).unwrap();
        let expected = triangulate(&at_origin, &grid, false)
            .unwrap()
            .triangles
            .len();
        // Each cell at a pole loses its empty triangle.
        assert!(expected < grid.triangle_count());
        for offset in [
            DVec3::new(1234.5, -678.9, 250.0),
            DVec3::new(-3.0e4, 7.5e4, 1.0e5),
        ] {
            for radius in [1.0, 0.01] {
                let far = construct::sphere(offset, radius).unwrap();
                let grid = uniform_grid(&far, 24).unwrap();
                let mesh = triangulate(&far, &grid, false).unwrap();
                assert_eq!(mesh.triangles.len(), expected, "{offset} r = {radius}");
            }
        }
    }
}
