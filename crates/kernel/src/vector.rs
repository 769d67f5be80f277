//! The small vector vocabulary the generic algorithms need, implemented for glam's f64 vectors.
//!
//! Knot insertion, refinement, degree elevation and interpolation act on homogeneous control
//! points (w·x, w·y, [w·z,] w) — `DVec3` for 2D curves, `DVec4` for 3D curves and surfaces — so
//! one implementation serves trim curves, space curves and every row of a surface.

use std::fmt::Debug;
use std::ops::{Add, Div, Mul, Sub};

use glam::{DVec2, DVec3, DVec4};

/// A vector space element with a dot product.
pub trait Vector:
    Copy
    + Debug
    + PartialEq
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<f64, Output = Self>
    + Div<f64, Output = Self>
    + Send
    + Sync
    + 'static
{
    const ZERO: Self;
    /// The number of coordinates.
    const DIMENSION: usize;
    fn dot(self, other: Self) -> f64;
    fn coordinates(self) -> Vec<f64>;
    /// The vector with these coordinates; `None` if the slice has the wrong length.
    fn from_coordinates(c: &[f64]) -> Option<Self>;
    fn norm(self) -> f64 {
        self.dot(self).sqrt()
    }
}

macro_rules! impl_vector {
    ($t:ty, $n:expr) => {
        impl Vector for $t {
            const ZERO: Self = <$t>::ZERO;
            const DIMENSION: usize = $n;
            fn dot(self, other: Self) -> f64 {
                <$t>::dot(self, other)
            }
            fn coordinates(self) -> Vec<f64> {
                self.to_array().to_vec()
            }
            fn from_coordinates(c: &[f64]) -> Option<Self> {
                <[f64; $n]>::try_from(c).ok().map(<$t>::from_array)
            }
        }
    };
}

impl_vector!(DVec2, 2);
impl_vector!(DVec3, 3);
impl_vector!(DVec4, 4);

/// A Cartesian control point type of a NURBS curve (`DVec2` for trim curves, `DVec3` for space
/// curves) and its homogeneous counterpart.
pub trait CurvePoint: Vector {
    /// (w·P, w) in one more dimension.
    type Homogeneous: Vector;
    fn to_homogeneous(self, weight: f64) -> Self::Homogeneous;
    /// The weight w of a homogeneous point.
    fn weight_of(h: Self::Homogeneous) -> f64;
    /// The weighted part w·P of a homogeneous point.
    fn weighted_part(h: Self::Homogeneous) -> Self;
    /// The Cartesian point P = (w·P) / w.
    fn project(h: Self::Homogeneous) -> Self {
        Self::weighted_part(h) / Self::weight_of(h)
    }
}

impl CurvePoint for DVec2 {
    type Homogeneous = DVec3;
    fn to_homogeneous(self, weight: f64) -> DVec3 {
        (self * weight).extend(weight)
    }
    fn weight_of(h: DVec3) -> f64 {
        h.z
    }
    fn weighted_part(h: DVec3) -> DVec2 {
        h.truncate()
    }
}

impl CurvePoint for DVec3 {
    type Homogeneous = DVec4;
    fn to_homogeneous(self, weight: f64) -> DVec4 {
        (self * weight).extend(weight)
    }
    fn weight_of(h: DVec4) -> f64 {
        h.w
    }
    fn weighted_part(h: DVec4) -> DVec3 {
        h.truncate()
    }
}

/// The solution x of the n × n system `matrix` x = `rhs` (values of any vector type), by
/// Gaussian elimination with partial pivoting; `None` when a pivot is below 1e-14 (singular).
pub fn solve_linear<V: Vector>(mut matrix: Vec<Vec<f64>>, mut rhs: Vec<V>) -> Option<Vec<V>> {
    let n = rhs.len();
    if matrix.len() != n || matrix.iter().any(|row| row.len() != n) {
        return None;
    }
    for col in 0..n {
        let pivot = (col..n)
            .max_by(|&a, &b| matrix[a][col].abs().total_cmp(&matrix[b][col].abs()))
            .unwrap_or(col);
        if !(matrix[pivot][col].abs() >= 1e-14) {
            return None;
        }
        matrix.swap(col, pivot);
        rhs.swap(col, pivot);
        for r in col + 1..n {
            let factor = matrix[r][col] / matrix[col][col];
            if factor != 0.0 {
                let (upper, lower) = matrix.split_at_mut(r);
                for (x, &y) in lower[0][col..].iter_mut().zip(&upper[col][col..]) {
                    *x -= factor * y;
                }
                rhs[r] = rhs[r] - rhs[col] * factor;
            }
        }
    }
    let mut solution = vec![V::ZERO; n];
    for r in (0..n).rev() {
        let mut acc = rhs[r];
        for c in r + 1..n {
            acc = acc - solution[c] * matrix[r][c];
        }
        solution[r] = acc / matrix[r][r];
    }
    Some(solution)
}

/// The binomial coefficient C(n, k) in f64 (exact for the degrees the kernel accepts).
pub fn binomial(n: usize, k: usize) -> f64 {
    if k > n {
        return 0.0;
    }
    let k = k.min(n - k);
    (0..k).fold(1.0, |acc, i| acc * (n - i) as f64 / (i + 1) as f64)
}

/// The distance from p to the segment ab (the nearest point of the segment by projection,
/// clamped to its ends), in any dimension.
pub fn distance_to_segment<V: Vector>(p: V, a: V, b: V) -> f64 {
    let d = b - a;
    let len2 = d.dot(d);
    let t = if len2 > 0.0 {
        ((p - a).dot(d) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p - (a + d * t)).norm()
}

/// The distance from p to the triangle abc: to its plane where p projects inside it
/// (barycentric coordinates from the normal n = (b − a) × (c − a): the projection is inside
/// where ((b − a) × (p − a))·n, ((c − b) × (p − b))·n and ((a − c) × (p − c))·n are ≥ 0),
/// otherwise to the nearest of its edges ([`distance_to_segment`]); a degenerate triangle is
/// its edges.
pub fn distance_to_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let n = (b - a).cross(c - a);
    let area2 = n.length_squared();
    if area2 > 0.0 {
        let inside = [(a, b), (b, c), (c, a)]
            .iter()
            .all(|&(x, y)| (y - x).cross(p - x).dot(n) >= 0.0);
        if inside {
            return ((p - a).dot(n)).abs() / area2.sqrt();
        }
    }
    distance_to_segment(p, a, b)
        .min(distance_to_segment(p, b, c))
        .min(distance_to_segment(p, c, a))
}

#[cfg(test)]
mod triangle_tests {
    use super::*;

    #[test]
    fn distance_to_a_triangle_in_each_region() {
        let (a, b, c) = (DVec3::ZERO, DVec3::X * 2.0, DVec3::Y * 2.0);
        // Above the inside: the height.
        assert_eq!(
            distance_to_triangle(DVec3::new(0.5, 0.5, 3.0), a, b, c),
            3.0
        );
        // Beside edge bc (the hypotenuse x + y = 2), in the plane: √2 / 2 from (1.5, 1.5).
        let d = distance_to_triangle(DVec3::new(1.5, 1.5, 0.0), a, b, c);
        assert!((d - 0.5f64.sqrt()).abs() < 1e-15, "{d}");
        // Past vertex b: the distance to b.
        assert_eq!(
            distance_to_triangle(DVec3::new(5.0, -4.0, 0.0), a, b, c),
            5.0
        );
        // A degenerate triangle is its segment.
        assert_eq!(
            distance_to_triangle(DVec3::new(1.0, 1.0, 0.0), a, b, b),
            1.0
        );
    }
}
