//! Bernstein polynomials and Bézier sums with derivatives.
//!
//! B_{i,n}(t) = C(n, i) tⁱ (1 − t)ⁿ⁻ⁱ, computed by the triangular recurrence
//! B_{i,n} = (1 − t) B_{i,n−1} + t B_{i−1,n−1} (The NURBS Book, A1.3 "AllBernstein"), which is
//! numerically stable and gives exact 0 and 1 at t = 0 and t = 1, so patch boundaries interpolate
//! their boundary control points exactly.
//!
//! Derivatives of a Bézier sum C(t) = Σ B_{i,n}(t) Pᵢ use the hodograph (difference) form
//! (The NURBS Book, eq. 1.9 and its repetition):
//! C′(t) = n Σ_{i<n} B_{i,n−1}(t) (P_{i+1} − P_i),
//! C″(t) = n (n − 1) Σ_{i<n−1} B_{i,n−2}(t) (P_{i+2} − 2 P_{i+1} + P_i).
//! Unlike summing basis derivatives, the difference form is exactly zero when the control points
//! are equal — which is what makes collapsed patch edges detectable in f32 on the GPU too.

use std::ops::{Add, Mul, Sub};

/// Writes all Bernstein polynomials of degree `out.len() − 1` at `t` into `out`
/// (The NURBS Book, A1.3). An empty `out` is left untouched.
pub fn bernstein_all(t: f64, out: &mut [f64]) {
    let Some(degree) = out.len().checked_sub(1) else {
        return;
    };
    let s = 1.0 - t;
    out[0] = 1.0;
    for j in 1..=degree {
        let mut saved = 0.0;
        for b in &mut out[..j] {
            let temp = *b;
            *b = saved + s * temp;
            saved = t * temp;
        }
        out[j] = saved;
    }
}

/// The Bernstein polynomials of degrees n, n − 1 and n − 2 at one parameter: everything needed to
/// evaluate a degree-n Bézier sum and its first two derivatives in difference form.
/// Arrays hold N entries; entries past each degree are zero.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BernsteinBasis<const N: usize> {
    degree: usize,
    /// B_{i,n}(t)
    full: [f64; N],
    /// B_{i,n−1}(t) (all zero when n = 0)
    lower1: [f64; N],
    /// B_{i,n−2}(t) (all zero when n < 2)
    lower2: [f64; N],
}

impl<const N: usize> BernsteinBasis<N> {
    /// The basis of degree `degree` at `t`; `None` when `degree + 1 > N`.
    pub fn new(degree: usize, t: f64) -> Option<Self> {
        if degree >= N {
            return None;
        }
        let mut basis = Self {
            degree,
            full: [0.0; N],
            lower1: [0.0; N],
            lower2: [0.0; N],
        };
        bernstein_all(t, &mut basis.full[..=degree]);
        if degree >= 1 {
            bernstein_all(t, &mut basis.lower1[..degree]);
        }
        if degree >= 2 {
            bernstein_all(t, &mut basis.lower2[..degree - 1]);
        }
        Some(basis)
    }

    pub fn degree(&self) -> usize {
        self.degree
    }

    /// B_{i,n}(t) for i = 0..=n.
    pub fn values(&self) -> &[f64] {
        &self.full[..=self.degree]
    }

    /// The Bézier sum of `points` (n + 1 of them) and its first and second derivatives:
    /// [C(t), C′(t), C″(t)], the derivatives in difference form (module docs).
    pub fn sum_with_derivatives<T>(&self, points: &[T]) -> [T; 3]
    where
        T: Copy + Default + Add<Output = T> + Sub<Output = T> + Mul<f64, Output = T>,
    {
        let n = self.degree;
        let mut value = T::default();
        let mut d1 = T::default();
        let mut d2 = T::default();
        for (&p, &b) in points[..=n].iter().zip(&self.full) {
            value = value + p * b;
        }
        if n >= 1 {
            for i in 0..n {
                d1 = d1 + (points[i + 1] - points[i]) * self.lower1[i];
            }
            d1 = d1 * n as f64;
        }
        if n >= 2 {
            for i in 0..n - 1 {
                let second = (points[i + 2] - points[i + 1]) - (points[i + 1] - points[i]);
                d2 = d2 + second * self.lower2[i];
            }
            d2 = d2 * (n * (n - 1)) as f64;
        }
        [value, d1, d2]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn binomial(n: usize, k: usize) -> f64 {
        (0..k).fold(1.0, |acc, i| acc * (n - i) as f64 / (i + 1) as f64)
    }

    #[test]
    fn matches_closed_form() {
        for n in 0..8 {
            for step in 0..=10 {
                let t = step as f64 / 10.0;
                let mut b = vec![0.0; n + 1];
                bernstein_all(t, &mut b);
                for (i, bi) in b.iter().enumerate() {
                    let exact = binomial(n, i) * t.powi(i as i32) * (1.0 - t).powi((n - i) as i32);
                    assert!((bi - exact).abs() < 1e-14, "n={n} i={i} t={t}");
                }
            }
        }
    }

    #[test]
    fn sum_derivatives_match_finite_differences() {
        let h = 1e-5;
        let points = [0.3, -1.2, 2.5, 0.7, -0.4, 1.9, 3.3, -2.0];
        for n in 1..8 {
            let t = 0.37;
            let eval = |t: f64| {
                BernsteinBasis::<8>::new(n, t)
                    .map(|b| b.sum_with_derivatives(&points[..=n]))
                    .unwrap_or_default()
            };
            let [c, d1, d2] = eval(t);
            let [cp, ..] = eval(t + h);
            let [cm, ..] = eval(t - h);
            assert!((d1 - (cp - cm) / (2.0 * h)).abs() < 1e-7, "n={n}");
            assert!((d2 - (cp - 2.0 * c + cm) / (h * h)).abs() < 1e-3, "n={n}");
        }
    }

    #[test]
    fn derivatives_of_equal_points_are_exactly_zero() {
        let points = [1.7; 4];
        for step in 0..=64 {
            let t = step as f64 / 64.0;
            let b = BernsteinBasis::<4>::new(3, t).unwrap_or_else(|| unreachable!());
            let [c, d1, d2] = b.sum_with_derivatives(&points);
            assert_eq!((d1, d2), (0.0, 0.0));
            assert!((c - 1.7).abs() < 1e-15);
        }
    }

    #[test]
    fn rejects_degree_past_capacity() {
        assert!(BernsteinBasis::<4>::new(4, 0.5).is_none());
        assert!(BernsteinBasis::<4>::new(3, 0.5).is_some());
    }
}
