//! Global interpolation and compatible curves, the pieces the constructions share: knots by
//! averaging, the collocation system of A9.1 (banded where it can be), curves brought to one
//! degree and knot vector, and skinning compatible sections. Below `construct`, `loft`,
//! `splines`, `sweep` and `transfinite`, which all build on it.

use glam::DVec4;

use super::basis::{basis_functions, find_span, interior_knots, merge_knots, missing_knots};
use super::curve::SpaceCurve;
use super::error::{GeometryError, construction};
use super::ops::{self, Polygon};
use super::surface::NurbsSurface;
use super::vector::Vector;

/// Knots by averaging the parameters (The NURBS Book, eq. 9.8), clamped on [0, 1].
pub fn averaged_knots(params: &[f64], degree: usize) -> Vec<f64> {
    let n = params.len() - 1;
    let mut knots = vec![0.0; degree + 1];
    for j in 1..=n - degree {
        knots.push(params[j..j + degree].iter().sum::<f64>() / degree as f64);
    }
    knots.extend(std::iter::repeat_n(1.0, degree + 1));
    knots
}

/// Control points of the degree-`degree` B-spline over `knots` that passes through `points`
/// at `params` (The NURBS Book, A9.1 "GlobalCurveInterp"): the collocation system
/// Σ N_{j,p}(t_k) P_j = Q_k, solved by Gaussian elimination with partial pivoting.
pub fn interpolate_points<V: Vector>(
    points: &[V],
    params: &[f64],
    degree: usize,
    knots: &[f64],
    what: &'static str,
) -> Result<Vec<V>, GeometryError> {
    let n = points.len();
    let mut basis = vec![0.0; degree + 1];
    // Each row's p + 1 non-zero entries and the column of the first.
    let rows: Vec<(usize, Vec<f64>)> = params
        .iter()
        .map(|&t| {
            let span = find_span(knots, degree, n, t);
            basis_functions(knots, degree, span, t, &mut basis);
            (span - degree, basis.clone())
        })
        .collect();
    if let Some(control) = solve_banded(&rows, points) {
        return Ok(control);
    }
    let mut matrix = vec![vec![0.0; n]; n];
    for (row, (first, values)) in matrix.iter_mut().zip(&rows) {
        row[*first..first + values.len()].copy_from_slice(values);
    }
    super::vector::solve_linear(matrix, points.to_vec())
        .ok_or_else(|| construction(what, "the interpolation system is singular"))
}

/// The collocation system whose row k is `rows[k]` (its non-zero entries from column
/// `rows[k].0`) solved by Gaussian elimination without pivoting, in O(n p²): for parameters
/// in increasing order that satisfy Schoenberg–Whitney the matrix is totally positive and
/// banded, elimination needs no pivoting and fills nothing outside each row's entries (de Boor,
/// A Practical Guide to Splines, ch. XIII). `None` where the rows are not in that form or a
/// pivot vanishes (the caller then solves the full system with pivoting).
fn solve_banded<V: Vector>(rows: &[(usize, Vec<f64>)], rhs: &[V]) -> Option<Vec<V>> {
    let n = rows.len();
    let width = rows.first()?.1.len();
    let last = |k: usize| rows[k].0 + width - 1;
    if rows.windows(2).any(|w| w[1].0 < w[0].0)
        || (0..n).any(|k| rows[k].0 > k || last(k) < k || last(k) >= n)
    {
        return None;
    }
    let mut a: Vec<Vec<f64>> = rows.iter().map(|(_, v)| v.clone()).collect();
    let mut b = rhs.to_vec();
    let at = |k: usize, j: usize| j - rows[k].0;
    for k in 0..n {
        let pivot = a[k][at(k, k)];
        if !(pivot.abs() >= 1e-14) {
            return None;
        }
        let mut i = k + 1;
        while i < n && rows[i].0 <= k {
            let f = a[i][at(i, k)] / pivot;
            if f != 0.0 {
                for j in k..=last(k) {
                    let v = a[k][at(k, j)];
                    a[i][at(i, j)] -= f * v;
                }
                b[i] = b[i] - b[k] * f;
            }
            i += 1;
        }
    }
    let mut x = vec![V::ZERO; n];
    for k in (0..n).rev() {
        let mut acc = b[k];
        for j in k + 1..=last(k) {
            acc = acc - x[j] * a[k][at(k, j)];
        }
        x[k] = acc / a[k][at(k, k)];
    }
    Some(x)
}

/// Brings curves to one degree, one domain [0, 1] and one knot vector (degree elevation, then
/// refinement with the union of all knots; The NURBS Book, §10.3), without changing their
/// shapes. Returns the homogeneous control polygons.
pub fn make_compatible(curves: &[SpaceCurve]) -> Result<Vec<Polygon<DVec4>>, GeometryError> {
    let degree = curves.iter().map(|c| c.degree()).max().unwrap_or(1);
    let mut polys = Vec::with_capacity(curves.len());
    for c in curves {
        let c = c.reparametrized(0.0, 1.0)?.clamped();
        let elevated = ops::elevate_degree(c.polygon(), degree - c.degree());
        polys.push(elevated);
    }
    // The union of the interior knots, with the highest multiplicity any curve has.
    let interior = |p: &Polygon<DVec4>| interior_knots(&p.knots, p.degree, p.points.len());
    let mut union: Vec<(f64, usize)> = Vec::new();
    for poly in &polys {
        merge_knots(&mut union, &interior(poly), 1e-14);
    }
    for poly in &mut polys {
        let x = missing_knots(&interior(poly), &union, 1e-14);
        *poly = ops::refine_knots(poly, &x);
    }
    // Snap nearly equal knots so all vectors are bit-identical.
    let reference = polys[0].knots.clone();
    for poly in &mut polys {
        if poly.knots.len() != reference.len() {
            return Err(construction(
                "compatible curves",
                "knot vectors differ after refinement",
            ));
        }
        poly.knots.clone_from(&reference);
    }
    Ok(polys)
}

/// The surface that interpolates compatible sections (homogeneous control polygons with one
/// degree and knot vector, along u) at `params` in v with degree `degree_v` over averaged knots
/// (The NURBS Book §10.3, A9.1 per column of control points): section k is reproduced exactly
/// at v = params[k].
pub fn skin(
    polys: &[Polygon<DVec4>],
    params: &[f64],
    degree_v: usize,
    what: &'static str,
) -> Result<NurbsSurface, GeometryError> {
    let n = polys[0].points.len();
    let k = polys.len();
    let knots_v = averaged_knots(params, degree_v);
    let mut points = vec![DVec4::ZERO; n * k];
    for i in 0..n {
        let column: Vec<DVec4> = polys.iter().map(|p| p.points[i]).collect();
        let control = interpolate_points(&column, params, degree_v, &knots_v, what)?;
        for (j, h) in control.into_iter().enumerate() {
            if !(h.w > 0.0) {
                return Err(construction(
                    what,
                    "the interpolated weights are not all positive; use sections with equal weights",
                ));
            }
            points[i * k + j] = h;
        }
    }
    NurbsSurface::from_homogeneous(
        [polys[0].degree, degree_v],
        [polys[0].knots.clone(), knots_v],
        [n, k],
        points,
    )
}

#[cfg(test)]
mod tests {
    use glam::DVec3;

    use super::*;

    #[test]
    fn the_banded_interpolation_solve_is_the_full_solve() {
        // 300 points on a wavy space curve, cubic, chord-length parameters, averaged knots.
        let points: Vec<DVec3> = (0..300)
            .map(|k| {
                let t = k as f64 * 0.05;
                DVec3::new(t.cos() * (1.0 + 0.3 * (3.0 * t).sin()), t.sin(), 0.2 * t)
            })
            .collect();
        let params = super::super::splines::parameters(
            &points,
            super::super::splines::Parametrization::ChordLength,
            "t",
        )
        .unwrap();
        let knots = averaged_knots(&params, 3);
        let banded = interpolate_points(&points, &params, 3, &knots, "t").unwrap();
        // The full system with pivoting.
        let n = points.len();
        let mut matrix = vec![vec![0.0; n]; n];
        let mut basis = vec![0.0; 4];
        for (row, &t) in matrix.iter_mut().zip(&params) {
            let span = find_span(&knots, 3, n, t);
            basis_functions(&knots, 3, span, t, &mut basis);
            row[span - 3..=span].copy_from_slice(&basis);
        }
        let full = super::super::vector::solve_linear(matrix, points.clone()).unwrap();
        for (a, b) in banded.iter().zip(&full) {
            assert!(a.distance(*b) < 1e-10, "{a} vs {b}");
        }
        // And the curve passes through the points.
        let curve = SpaceCurve::new(3, knots, banded, None).unwrap();
        for (p, &t) in points.iter().zip(&params) {
            assert!(curve.point_at(t).unwrap().distance(*p) < 1e-10);
        }
    }
}
