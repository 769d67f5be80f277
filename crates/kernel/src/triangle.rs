//! Triangular Bézier patches of any degree (Farin, Curves and Surfaces for CAGD, chapter 17;
//! the lecture notes' seed 001): points b_ijk, i + j + k = n, over barycentric coordinates
//! (u, v, w), w = 1 − u − v,
//!
//!   b(u, v) = Σ B^n_ijk(u, v, w) b_ijk,   B^n_ijk = n! / (i! j! k!) u^i v^j w^k.
//!
//! The corner u = 1 is b_n00, v = 1 is b_0n0 and w = 1 (u = v = 0) is b_00n. Points are stored
//! row by row: row j = 0..=n holds i = 0..=n − j ([`lattice_index`]).
//!
//! Evaluation is the de Casteljau algorithm on barycentric coordinates; its last two steps give
//! the first and second derivatives (Farin 17.4). [`bernstein_weights`] gives the same values
//! from the explicit polynomials, for the GPU's stencils.

use glam::DVec3;

use super::diffgeo::SurfaceDerivatives;
use super::vector::binomial;
use super::{GeometryError, Location};

/// The highest degree a triangular patch may have (231 points).
pub const MAX_TRIANGLE_DEGREE: usize = 20;

/// How many points a degree-n patch has: (n + 1)(n + 2) / 2.
pub fn point_count(degree: usize) -> usize {
    (degree + 1) * (degree + 2) / 2
}

/// The index of b_ijk (k = n − i − j) in a degree-n patch's points: row j holds i = 0..=n − j.
pub fn lattice_index(degree: usize, i: usize, j: usize) -> usize {
    // Rows 0..j hold (n + 1) + n + … + (n + 2 − j) points.
    j * (2 * degree + 3 - j) / 2 + i
}

/// A triangular Bézier patch of degree n ≥ 1 with Cartesian points (polynomial).
#[derive(Debug, Clone, PartialEq)]
pub struct TriangleBezier {
    degree: usize,
    points: Vec<DVec3>,
}

impl TriangleBezier {
    /// Checks the degree (1..=[`MAX_TRIANGLE_DEGREE`]), the point count and that every
    /// coordinate is finite.
    pub fn new(degree: usize, points: Vec<DVec3>) -> Result<Self, GeometryError> {
        if !(1..=MAX_TRIANGLE_DEGREE).contains(&degree) {
            return Err(GeometryError::Degree {
                at: Location::field("degree"),
                degree,
                max: MAX_TRIANGLE_DEGREE,
            });
        }
        let expected = point_count(degree);
        if points.len() != expected {
            return Err(GeometryError::PointCount {
                at: Location::field("points"),
                expected,
                found: points.len(),
            });
        }
        if let Some((k, p)) = points.iter().enumerate().find(|(_, p)| !p.is_finite()) {
            return Err(GeometryError::NonFinitePoint {
                at: Location::point(k),
                coordinate: p
                    .to_array()
                    .iter()
                    .position(|x| !x.is_finite())
                    .unwrap_or(0),
            });
        }
        Ok(Self { degree, points })
    }

    pub fn degree(&self) -> usize {
        self.degree
    }

    pub fn points(&self) -> &[DVec3] {
        &self.points
    }

    /// Moves point `index` to `position` (refused for a bad index or a non-finite position).
    pub fn set_point(&mut self, index: usize, position: DVec3) -> Result<(), GeometryError> {
        let count = self.points.len();
        let slot = self
            .points
            .get_mut(index)
            .ok_or(GeometryError::NoSuchPoint { index, count })?;
        if !position.is_finite() {
            return Err(GeometryError::non_finite_point(
                Location::point(index),
                position,
            ));
        }
        *slot = position;
        Ok(())
    }

    /// b_ijk (k = n − i − j).
    pub fn point(&self, i: usize, j: usize) -> DVec3 {
        self.points[lattice_index(self.degree, i, j)]
    }

    /// The patch as one tensor-product Bézier patch of bidegree (n, n) over the unit square,
    /// exactly: the square mapped onto the triangle by u = s, v = (1 − s) t, w = (1 − s)(1 − t)
    /// (the side s = 1 collapses to the corner b_n00; the normal keeps its direction, since
    /// S_s × S_t = (1 − s) b_u × b_v). Because
    /// B^n_ijk(s, (1 − s) t, (1 − s)(1 − t)) = B^n_i(s) · B^{n−i}_j(t),
    /// row i of the tensor patch is the Bézier curve of degree m = n − i with points
    /// b_{i,j,m−j}, raised to degree n (Farin, Curves and Surfaces for CAGD, degree elevation
    /// repeated: Q_l = Σ_j C(m, j) C(n − m, l − j) / C(n, l) P_j). Points row by row: index
    /// i (n + 1) + l, i along s.
    pub fn tensor_points(&self) -> Vec<DVec3> {
        let n = self.degree;
        let mut out = Vec::with_capacity((n + 1) * (n + 1));
        for i in 0..=n {
            let m = n - i;
            for l in 0..=n {
                let mut q = DVec3::ZERO;
                for j in l.saturating_sub(n - m)..=l.min(m) {
                    let c = binomial(m, j) * binomial(n - m, l - j) / binomial(n, l);
                    q += self.point(i, j) * c;
                }
                out.push(q);
            }
        }
        out
    }

    /// The point and the derivatives in (u, v) (w = 1 − u − v) at (u, v), by the de Casteljau
    /// algorithm (Farin 17.3): each step replaces the points of degree r by
    /// b^{r+1}_ijk = u b^r_{i+1,j,k} + v b^r_{i,j+1,k} + w b^r_{i,j,k+1}. With the three points
    /// left after n − 1 steps, b_u = n (b_100 − b_001), b_v = n (b_010 − b_001); with the six
    /// left after n − 2 steps, b_uu = n(n − 1)(b_200 − 2 b_101 + b_002), b_uv = n(n − 1)(b_110 −
    /// b_101 − b_011 + b_002), b_vv = n(n − 1)(b_020 − 2 b_011 + b_002) (Farin 17.4). Works
    /// outside the triangle too (the polynomial's extension).
    pub fn evaluate(&self, u: f64, v: f64) -> SurfaceDerivatives {
        let n = self.degree;
        let w = 1.0 - u - v;
        let mut level = self.points.clone();
        let mut d = n;
        // After a step from degree d the points have degree d − 1, stored the same way.
        let step = |points: &[DVec3], d: usize| -> Vec<DVec3> {
            let mut out = Vec::with_capacity(point_count(d - 1));
            for j in 0..d {
                for i in 0..d - j {
                    out.push(
                        points[lattice_index(d, i + 1, j)] * u
                            + points[lattice_index(d, i, j + 1)] * v
                            + points[lattice_index(d, i, j)] * w,
                    );
                }
            }
            out
        };
        let mut second = [DVec3::ZERO; 3];
        while d > 1 {
            if d == 2 {
                // b_200, b_110, b_020, b_101, b_011, b_002 of the quadratic left.
                let at = |i: usize, j: usize| level[lattice_index(2, i, j)];
                let (b200, b020, b002) = (at(2, 0), at(0, 2), at(0, 0));
                let (b110, b101, b011) = (at(1, 1), at(1, 0), at(0, 1));
                let f = (n * (n - 1)) as f64;
                second = [
                    (b200 - b101 * 2.0 + b002) * f,
                    (b110 - b101 - b011 + b002) * f,
                    (b020 - b011 * 2.0 + b002) * f,
                ];
            }
            level = step(&level, d);
            d -= 1;
        }
        let at = |i: usize, j: usize| level[lattice_index(1, i, j)];
        let (b100, b010, b001) = (at(1, 0), at(0, 1), at(0, 0));
        let f = n as f64;
        SurfaceDerivatives {
            point: b100 * u + b010 * v + b001 * w,
            su: (b100 - b001) * f,
            sv: (b010 - b001) * f,
            suu: second[0],
            suv: second[1],
            svv: second[2],
        }
    }

    /// The same surface at degree n + 1 (Farin 17.5): b'_ijk = (i b_{i−1,j,k} + j b_{i,j−1,k} +
    /// k b_{i,j,k−1}) / (n + 1). Refused past [`MAX_TRIANGLE_DEGREE`].
    pub fn elevated(&self) -> Result<Self, GeometryError> {
        let n = self.degree;
        let m = n + 1;
        let mut points = Vec::with_capacity(point_count(m));
        for j in 0..=m {
            for i in 0..=m - j {
                let k = m - i - j;
                let mut p = DVec3::ZERO;
                if i > 0 {
                    p += self.point(i - 1, j) * i as f64;
                }
                if j > 0 {
                    p += self.point(i, j - 1) * j as f64;
                }
                if k > 0 {
                    p += self.point(i, j) * k as f64;
                }
                points.push(p / m as f64);
            }
        }
        Self::new(m, points)
    }

    /// Index pairs of the control net's lines: each lattice triangle's three edges once.
    pub fn net_lines(&self) -> Vec<u32> {
        let n = self.degree;
        let mut lines = Vec::new();
        for j in 0..=n {
            for i in 0..=n - j {
                let here = lattice_index(n, i, j) as u32;
                if i + j < n {
                    lines.extend([here, lattice_index(n, i + 1, j) as u32]);
                    lines.extend([here, lattice_index(n, i, j + 1) as u32]);
                    lines.extend([
                        lattice_index(n, i + 1, j) as u32,
                        lattice_index(n, i, j + 1) as u32,
                    ]);
                }
            }
        }
        lines
    }

    /// A bound on the second derivatives' size: n(n − 1) times the largest second difference
    /// of the points along the three lattice directions (the flatness bound of Filip, Magedson
    /// & Markot 1986 for polynomial patches).
    pub fn second_difference_bound(&self) -> f64 {
        let n = self.degree;
        if n < 2 {
            return 0.0;
        }
        let mut worst: f64 = 0.0;
        for j in 0..=n - 2 {
            for i in 0..=n - 2 - j {
                let (b002, b101, b011) =
                    (self.point(i, j), self.point(i + 1, j), self.point(i, j + 1));
                let (b200, b110, b020) = (
                    self.point(i + 2, j),
                    self.point(i + 1, j + 1),
                    self.point(i, j + 2),
                );
                for d in [
                    b200 - b101 * 2.0 + b002,
                    b020 - b011 * 2.0 + b002,
                    b200 - b110 * 2.0 + b020,
                ] {
                    worst = worst.max(d.length());
                }
            }
        }
        (n * (n - 1)) as f64 * worst
    }

    /// Segments per edge so that the lattice triangulation stays within `tolerance` of the
    /// patch: a triangle of edge h deviates by at most M h² / 8 where M bounds the second
    /// derivatives ([`Self::second_difference_bound`]); at least 1, at most `max`.
    pub fn segments_for(&self, tolerance: f64, max: u32) -> u32 {
        let m = self.second_difference_bound();
        if !(tolerance > 0.0) || m == 0.0 {
            return 1;
        }
        let s = (m / (8.0 * tolerance)).sqrt().ceil();
        if s.is_finite() {
            (s as u32).clamp(1, max.max(1))
        } else {
            max.max(1)
        }
    }

    /// The patch moved by `f` point by point (an affine map, so the patch maps exactly).
    pub fn mapped(&self, f: impl Fn(DVec3) -> DVec3) -> Result<Self, GeometryError> {
        Self::new(self.degree, self.points.iter().map(|&p| f(p)).collect())
    }
}

/// The Bernstein polynomials of degree n and their derivatives at (u, v) (w = 1 − u − v), from
/// the explicit formula B^n_ijk = n!/(i! j! k!) u^i v^j w^k and its partial derivatives with
/// ∂w/∂u = ∂w/∂v = −1: per point (in [`lattice_index`] order) the weights of the position, b_u,
/// b_v, b_uu, b_uv and b_vv.
pub fn bernstein_weights(degree: usize, u: f64, v: f64) -> Vec<[f64; 6]> {
    let n = degree;
    let w = 1.0 - u - v;
    // x^e and its first two derivatives' factors: e x^(e−1), e (e − 1) x^(e−2).
    let power = |x: f64, e: usize| -> [f64; 3] {
        let p = |k: usize| if e >= k { x.powi((e - k) as i32) } else { 0.0 };
        let e = e as f64;
        [p(0), e * p(1), e * (e - 1.0) * p(2)]
    };
    let factorial = |k: usize| (1..=k).fold(1.0, |a, x| a * x as f64);
    let mut out = Vec::with_capacity(point_count(n));
    for j in 0..=n {
        for i in 0..=n - j {
            let k = n - i - j;
            let c = factorial(n) / (factorial(i) * factorial(j) * factorial(k));
            let (a, b, g) = (power(u, i), power(v, j), power(w, k));
            // d/du (U V W) = U' V W − U V W', d/dv = U V' W − U V W'.
            let value = a[0] * b[0] * g[0];
            let du = a[1] * b[0] * g[0] - a[0] * b[0] * g[1];
            let dv = a[0] * b[1] * g[0] - a[0] * b[0] * g[1];
            let duu = a[2] * b[0] * g[0] - 2.0 * a[1] * b[0] * g[1] + a[0] * b[0] * g[2];
            let duv =
                a[1] * b[1] * g[0] - a[1] * b[0] * g[1] - a[0] * b[1] * g[1] + a[0] * b[0] * g[2];
            let dvv = a[0] * b[2] * g[0] - 2.0 * a[0] * b[1] * g[1] + a[0] * b[0] * g[2];
            out.push([value, du, dv, duu, duv, dvv].map(|x| x * c));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_tensor_patch_is_the_triangle_on_the_collapsed_square() {
        for n in [1, 2, 3, 5] {
            let points: Vec<DVec3> = (0..point_count(n))
                .map(|k| {
                    let x = k as f64;
                    DVec3::new(
                        (x * 1.3).sin() * 2.0 + x,
                        (x * 0.7).cos() - 0.5 * x,
                        (x * 2.1).sin(),
                    )
                })
                .collect();
            let patch = TriangleBezier::new(n, points).unwrap();
            let tensor = crate::NurbsSurface::bezier([n, n], patch.tensor_points(), None).unwrap();
            for a in 0..=8 {
                for b in 0..=8 {
                    let (s, t) = (a as f64 / 8.0, b as f64 / 8.0);
                    let want = patch.evaluate(s, (1.0 - s) * t).point;
                    let got = tensor.point_at(s, t).unwrap();
                    assert!(
                        got.distance(want) < 1e-12,
                        "degree {n} at ({s}, {t}): {got} vs {want}"
                    );
                }
            }
            // The side s = 1 is the corner b_n00.
            let corner = patch.point(n, 0);
            assert!(tensor.point_at(1.0, 0.37).unwrap().distance(corner) < 1e-12);
        }
    }

    fn sample(n: usize) -> TriangleBezier {
        let points = (0..point_count(n))
            .map(|k| {
                let x = k as f64;
                DVec3::new(
                    (x * 0.7).sin() + x,
                    (x * 1.3).cos() * 2.0,
                    (x * 0.4).sin() * x,
                )
            })
            .collect();
        TriangleBezier::new(n, points).unwrap()
    }

    #[test]
    fn lattice_index_runs_row_by_row() {
        let n = 4;
        let mut k = 0;
        for j in 0..=n {
            for i in 0..=n - j {
                assert_eq!(lattice_index(n, i, j), k);
                k += 1;
            }
        }
        assert_eq!(k, point_count(n));
    }

    #[test]
    fn de_casteljau_matches_the_explicit_bernstein_sums() {
        for n in 1..=7 {
            let patch = sample(n);
            for (u, v) in [(0.2, 0.3), (0.0, 0.0), (1.0, 0.0), (0.1, 0.85), (0.7, 0.6)] {
                let d = patch.evaluate(u, v);
                let weights = bernstein_weights(n, u, v);
                let sum = |c: usize| {
                    weights
                        .iter()
                        .zip(patch.points())
                        .fold(DVec3::ZERO, |acc, (w, &p)| acc + p * w[c])
                };
                let got = [d.point, d.su, d.sv, d.suu, d.suv, d.svv];
                for (c, g) in got.iter().enumerate() {
                    let e = sum(c);
                    assert!(
                        g.distance(e) <= 1e-11 * (1.0 + e.length()),
                        "n {n} c {c}: {g} vs {e}"
                    );
                }
                // Partition of unity.
                let total: f64 = weights.iter().map(|w| w[0]).sum();
                assert!((total - 1.0).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn corners_and_elevation() {
        let patch = sample(3);
        assert_eq!(patch.evaluate(1.0, 0.0).point, patch.point(3, 0));
        assert_eq!(patch.evaluate(0.0, 1.0).point, patch.point(0, 3));
        assert_eq!(patch.evaluate(0.0, 0.0).point, patch.point(0, 0));
        let up = patch.elevated().unwrap();
        assert_eq!(up.degree(), 4);
        for (u, v) in [(0.2, 0.3), (0.5, 0.1), (0.05, 0.9)] {
            let (a, b) = (patch.evaluate(u, v), up.evaluate(u, v));
            assert!(a.point.distance(b.point) < 1e-12);
            assert!(a.su.distance(b.su) < 1e-11 && a.svv.distance(b.svv) < 1e-10);
        }
    }

    #[test]
    fn bad_patches_are_refused() {
        assert!(TriangleBezier::new(0, vec![DVec3::ZERO]).is_err());
        assert!(TriangleBezier::new(2, vec![DVec3::ZERO; 5]).is_err());
        let mut points = vec![DVec3::ZERO; 6];
        points[4].y = f64::NAN;
        assert!(TriangleBezier::new(2, points).is_err());
        assert!(
            TriangleBezier::new(MAX_TRIANGLE_DEGREE + 1, vec![DVec3::ZERO; point_count(21)])
                .is_err()
        );
    }
}
