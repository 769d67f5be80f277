//! Baking a free-form deformation into an object ([`crate::kernel::ffd`]): what each kind of
//! object becomes when its lattice is applied. Tensor-product patches compose exactly where the
//! degree (lattice's total degree × patch degree) stays within [`EXACT_MAX_DEGREE`], else they
//! are refitted by bicubic Hermite cells within the tolerance; a triangular patch composes
//! exactly up to [`MAX_TRIANGLE_DEGREE`], else is interpolated at that degree; a polygon mesh's
//! vertices move; a cage is solved for so that its limit surface passes through the deformed
//! limit points of its vertices.

use std::collections::HashMap;

use glam::{DVec3, DVec4};

use crate::kernel::ffd::{Baked, EXACT_MAX_DEGREE, Lattice, refit_spans};
use crate::kernel::subdiv::SubdivisionSurface;
use crate::kernel::triangle::{MAX_TRIANGLE_DEGREE, TriangleBezier};
use crate::kernel::{BezierPatch, BezierPatchSet, Direction, GeometryError, NurbsSurface};

/// A pool of points that shares bit-identical ones (neighbouring cells' common corners).
#[derive(Default)]
struct Pool {
    points: Vec<DVec3>,
    weights: Vec<f64>,
    seen: HashMap<[u64; 4], u32>,
}

impl Pool {
    fn add(&mut self, p: DVec3, w: f64) -> u32 {
        let key = [p.x.to_bits(), p.y.to_bits(), p.z.to_bits(), w.to_bits()];
        *self.seen.entry(key).or_insert_with(|| {
            self.points.push(p);
            self.weights.push(w);
            (self.points.len() - 1) as u32
        })
    }
}

/// The knot vector of degree `degree` with the distinct values `breaks`, every interior one
/// `degree` times (C0 joints; the ends `degree + 1` times).
fn full_multiplicity(breaks: &[f64], degree: usize) -> Vec<f64> {
    let mut knots = vec![breaks[0]; degree + 1];
    for &b in &breaks[1..breaks.len() - 1] {
        knots.extend(std::iter::repeat_n(b, degree));
    }
    knots.extend(std::iter::repeat_n(breaks[breaks.len() - 1], degree + 1));
    knots
}

/// The NURBS surface of degree `degree` over `breaks` whose Bézier cells (cell (a, b) at
/// `a · (cells along v) + b`, its homogeneous points row-major) are `cells`; then every interior
/// knot is removed as often as the shape stays within `tolerance` ((The NURBS Book A5.8): the
/// continuity the cells have across their joints comes back into the knot vector.
fn assemble(
    degree: [usize; 2],
    breaks: [&[f64]; 2],
    cells: &[Vec<DVec4>],
    tolerance: f64,
) -> Result<NurbsSurface, GeometryError> {
    let [p, q] = degree;
    let (nu, nv) = (breaks[0].len() - 1, breaks[1].len() - 1);
    let count = [nu * p + 1, nv * q + 1];
    let mut grid = vec![DVec4::ZERO; count[0] * count[1]];
    for a in 0..nu {
        for b in 0..nv {
            let cell = &cells[a * nv + b];
            for i in 0..=p {
                for j in 0..=q {
                    grid[(a * p + i) * count[1] + b * q + j] = cell[i * (q + 1) + j];
                }
            }
        }
    }
    let knots = [
        full_multiplicity(breaks[0], p),
        full_multiplicity(breaks[1], q),
    ];
    let mut surface = NurbsSurface::from_homogeneous(degree, knots, count, grid)?;
    for (direction, list) in [(Direction::U, breaks[0]), (Direction::V, breaks[1])] {
        let d = direction.index();
        for &value in &list[1..list.len() - 1] {
            let (removed, _) = surface.remove_knot(direction, value, degree[d], tolerance);
            surface = removed;
        }
    }
    Ok(surface)
}

/// The report of a bicubic refit with `cells` per span that reached `error`.
fn refitted(cells: usize, error: f64, tolerance: f64) -> Baked {
    Baked::Refit {
        cells,
        error,
        within: error <= tolerance,
    }
}

/// A NURBS surface with the lattice applied: exact (composed Bézier patches, knots removed
/// back to the continuity they have) where the degree allows, else refitted bicubic.
pub fn bake_nurbs(
    surface: &NurbsSurface,
    lattice: &Lattice,
    tolerance: f64,
) -> Result<(NurbsSurface, Baked), GeometryError> {
    let [p, q] = surface.degree();
    let big = lattice.total_degree();
    let breaks = [
        surface.span_breaks(Direction::U),
        surface.span_breaks(Direction::V),
    ];
    // Joints that were only rounding apart stay one knot.
    let joint_tolerance = 1e-9 * surface.size().max(1e-12);
    if big * p.max(q) <= EXACT_MAX_DEGREE {
        let cells = surface
            .bezier_patches()
            .iter()
            .map(|(patch, _)| {
                lattice
                    .compose_patch([p, q], patch.homogeneous_points())
                    .map(|(_, points)| points)
            })
            .collect::<Result<Vec<_>, _>>()?;
        let degree = [big * p, big * q];
        let baked = assemble(degree, [&breaks[0], &breaks[1]], &cells, joint_tolerance)?;
        return Ok((baked, Baked::Exact { degree }));
    }
    // Each span's derivatives from its own Bézier patch: one-sided at the span's edges, as a
    // cell there needs them where the surface is only C0 or C1 across a joint.
    let patches = surface.bezier_patches();
    let spans: Vec<[f64; 4]> = patches
        .iter()
        .map(|(_, [u, v])| [u[0], u[1], v[0], v[1]])
        .collect();
    let (all, cells, error) = refit_spans(lattice, &spans, tolerance, &|k, u, v| {
        patches[k].0.evaluate(u, v)
    })?;
    // The cells of every span laid out as one grid of cells.
    let split = |list: &[f64]| -> Vec<f64> {
        let mut out = vec![list[0]];
        for w in list.windows(2) {
            for c in 1..=cells {
                out.push(if c == cells {
                    w[1]
                } else {
                    w[0] + (w[1] - w[0]) * c as f64 / cells as f64
                });
            }
        }
        out
    };
    let fine = [split(&breaks[0]), split(&breaks[1])];
    let (su, sv) = (breaks[0].len() - 1, breaks[1].len() - 1);
    let columns = sv * cells;
    let mut grid = vec![Vec::new(); su * cells * columns];
    for (span, span_cells) in all.iter().enumerate() {
        let (a, b) = (span / sv, span % sv);
        for (k, cell) in span_cells.iter().enumerate() {
            let (ca, cb) = (a * cells + k / cells, b * cells + k % cells);
            grid[ca * columns + cb] = cell.iter().map(|p| p.extend(1.0)).collect();
        }
    }
    let baked = assemble([3, 3], [&fine[0], &fine[1]], &grid, joint_tolerance)?;
    Ok((baked, refitted(cells, error, tolerance)))
}

/// A set of Bézier patches with the lattice applied: each patch composed exactly where the
/// degree allows, else every patch refitted by bicubic cells.
pub fn bake_patch_set(
    set: &BezierPatchSet,
    lattice: &Lattice,
    tolerance: f64,
) -> Result<(BezierPatchSet, Baked), GeometryError> {
    let big = lattice.total_degree();
    let highest = set
        .patches()
        .iter()
        .map(|p| p.degree_u().max(p.degree_v()))
        .max()
        .unwrap_or(1);
    let mut pool = Pool::default();
    let mut patches = Vec::new();
    if big * highest <= EXACT_MAX_DEGREE {
        let mut degree = [0, 0];
        for patch in set.patches() {
            let homogeneous: Vec<DVec4> = patch
                .indices()
                .iter()
                .map(|&i| {
                    let w = set.weights()[i as usize];
                    (set.points()[i as usize] * w).extend(w)
                })
                .collect();
            let ([du, dv], points) =
                lattice.compose_patch([patch.degree_u(), patch.degree_v()], &homogeneous)?;
            degree = [degree[0].max(du), degree[1].max(dv)];
            let indices = points
                .iter()
                .map(|h| pool.add(h.truncate() / h.w, h.w))
                .collect();
            patches.push(BezierPatch::new(du, dv, indices));
        }
        let baked = BezierPatchSet::new(pool.points, Some(pool.weights), patches)?;
        return Ok((baked, Baked::Exact { degree }));
    }
    let spans = vec![[0.0, 1.0, 0.0, 1.0]; set.patches().len()];
    let (all, cells, error) =
        refit_spans(lattice, &spans, tolerance, &|k, u, v| set.evaluate(k, u, v))?;
    for cell in all.iter().flatten() {
        let indices = cell.iter().map(|&p| pool.add(p, 1.0)).collect();
        patches.push(BezierPatch::new(3, 3, indices));
    }
    let baked = BezierPatchSet::new(pool.points, None, patches)?;
    Ok((baked, refitted(cells, error, tolerance)))
}

/// A triangular patch with the lattice applied: composed exactly where the degree stays within
/// [`MAX_TRIANGLE_DEGREE`], else interpolated at that degree (the deviation measured on a
/// lattice of twice as many points).
pub fn bake_triangle(
    patch: &TriangleBezier,
    lattice: &Lattice,
    tolerance: f64,
) -> Result<(TriangleBezier, Baked), GeometryError> {
    let degree = lattice.total_degree() * patch.degree();
    if degree <= MAX_TRIANGLE_DEGREE {
        let baked = lattice.compose_triangle(patch)?;
        return Ok((
            baked,
            Baked::Exact {
                degree: [degree; 2],
            },
        ));
    }
    let baked = lattice.interpolate_triangle(patch, MAX_TRIANGLE_DEGREE)?;
    let n = 2 * MAX_TRIANGLE_DEGREE;
    let mut error: f64 = 0.0;
    for j in 0..=n {
        for i in 0..=n - j {
            let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
            let exact = lattice.deform_point(patch.evaluate(u, v).point);
            error = error.max(baked.evaluate(u, v).point.distance(exact));
        }
    }
    Ok((
        baked,
        Baked::Interpolated {
            degree: MAX_TRIANGLE_DEGREE,
            error,
            within: error <= tolerance,
        },
    ))
}

/// The most iterations of the cage solve for a large cage.
const CAGE_ITERATIONS: usize = 200;

/// Cages up to this many points are solved directly (the limit-position matrix probed column
/// by column, then Gaussian elimination).
const DIRECT_CAGE_POINTS: usize = 400;

/// A subdivision cage with the lattice applied: the cage whose limit positions at its vertices
/// are the deformed limit positions of the original's, T. The limit-position map L is linear
/// in the cage (rules depend only on topology), so L c = T is solved: directly for a small
/// cage (L's columns are the limit positions of unit cages), else by the iteration
/// c ← c + (T − L(c)). The deviation is measured at the limit points of level 2. Where the
/// scheme has no limit position per cage vertex (a dual scheme), the cage's points move through
/// the lattice.
pub fn bake_cage(
    surface: &SubdivisionSurface,
    lattice: &Lattice,
    tolerance: f64,
) -> Result<(SubdivisionSurface, Baked), GeometryError> {
    let count = surface.points().len();
    let mut cage = surface.clone();
    let limit0 = surface.limit(0)?;
    if limit0.positions.len() == count {
        let target: Vec<DVec3> = limit0
            .positions
            .iter()
            .map(|&p| lattice.deform_point(p))
            .collect();
        let mut solved = false;
        if count <= DIRECT_CAGE_POINTS {
            let mut unit = surface.clone();
            for k in 0..count {
                unit.set_point(k, DVec3::ZERO)?;
            }
            let mut matrix = vec![vec![0.0; count]; count];
            for k in 0..count {
                unit.set_point(k, DVec3::X)?;
                for (row, p) in matrix.iter_mut().zip(unit.limit(0)?.positions) {
                    row[k] = p.x;
                }
                unit.set_point(k, DVec3::ZERO)?;
            }
            if let Some(points) = crate::kernel::vector::solve_linear(matrix, target.clone()) {
                for (k, p) in points.into_iter().enumerate() {
                    cage.set_point(k, p)?;
                }
                solved = true;
            }
        }
        if !solved {
            for _ in 0..CAGE_ITERATIONS {
                let now = cage.limit(0)?.positions;
                let mut residual: f64 = 0.0;
                for (k, (&t, &l)) in target.iter().zip(&now).enumerate() {
                    residual = residual.max(t.distance(l));
                    let p = cage.points()[k];
                    cage.set_point(k, p + (t - l))?;
                }
                if residual <= 1e-3 * tolerance {
                    break;
                }
            }
        }
    } else {
        for (k, &p) in surface.points().iter().enumerate() {
            cage.set_point(k, lattice.deform_point(p))?;
        }
    }
    let before = surface.limit(2)?.positions;
    let after = cage.limit(2)?.positions;
    let error = before
        .iter()
        .zip(&after)
        .map(|(&b, &a)| lattice.deform_point(b).distance(a))
        .fold(0.0, f64::max);
    Ok((
        cage,
        Baked::Points {
            error,
            within: error <= tolerance,
        },
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernel::subdiv::{Options, Scheme, cages};

    #[test]
    fn a_cage_bakes_under_every_scheme() {
        for (scheme, mesh) in [
            (Scheme::CatmullClark, cages::cube(DVec3::ZERO, 2.0)),
            (Scheme::Loop, cages::icosahedron(DVec3::ZERO, 1.0)),
            (Scheme::DooSabin, cages::grid(DVec3::ZERO, 2.0, 4)),
            (Scheme::Sqrt3, cages::icosahedron(DVec3::ZERO, 1.0)),
            (Scheme::Butterfly, cages::icosahedron(DVec3::ZERO, 1.0)),
        ] {
            let options = Options {
                scheme,
                ..Options::default()
            };
            let surface =
                SubdivisionSurface::new(mesh.unwrap(), Vec::new(), Vec::new(), options, 2).unwrap();
            let (lo, hi) = crate::kernel::PolygonMesh::bounds(surface.mesh()).unwrap();
            let mut lattice = Lattice::around(lo, hi, [1, 1, 1]).unwrap();
            let p = lattice.points()[7];
            lattice.set_point(7, p + DVec3::splat(0.3)).unwrap();
            let (baked, how) =
                bake_cage(&surface, &lattice, 1e-2).unwrap_or_else(|e| panic!("{scheme:?}: {e}"));
            assert_eq!(baked.points().len(), surface.points().len());
            let Baked::Points { error, .. } = how else {
                panic!("{scheme:?}: {how:?}");
            };
            assert!(error.is_finite(), "{scheme:?}: {error}");
        }
    }
}
