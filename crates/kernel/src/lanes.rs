//! Four f64 lanes evaluated together: the kernel's SIMD vocabulary.
//!
//! [`F4`] is a plain `[f64; 4]` whose operators work lane by lane, with no fused multiply-add, so
//! every lane rounds exactly as the scalar expression would. Code written with it is compiled
//! twice where the CPU allows: once for the baseline target and once inside a function with
//! `#[target_feature(enable = "avx2")]`, where LLVM turns each operator into one 256-bit
//! instruction (the caller picks one at run time). Both builds give the
//! same bits, and the same as scalar code with the same operation order.

use std::ops::{Add, Div, Mul, Sub};

/// Four f64 values, one per lane.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[repr(C, align(32))]
pub(crate) struct F4(pub(crate) [f64; 4]);

impl F4 {
    #[inline(always)]
    pub(crate) fn splat(x: f64) -> Self {
        Self([x; 4])
    }

    #[inline(always)]
    pub(crate) fn sqrt(self) -> Self {
        let a = self.0;
        Self([a[0].sqrt(), a[1].sqrt(), a[2].sqrt(), a[3].sqrt()])
    }

    #[inline(always)]
    pub(crate) fn max(self, other: Self) -> Self {
        let (a, b) = (self.0, other.0);
        Self([
            a[0].max(b[0]),
            a[1].max(b[1]),
            a[2].max(b[2]),
            a[3].max(b[3]),
        ])
    }

    #[inline(always)]
    pub(crate) fn min(self, other: Self) -> Self {
        let (a, b) = (self.0, other.0);
        Self([
            a[0].min(b[0]),
            a[1].min(b[1]),
            a[2].min(b[2]),
            a[3].min(b[3]),
        ])
    }

    /// Lane by lane `self > other` (false where either is NaN).
    #[inline(always)]
    pub(crate) fn gt(self, other: Self) -> [bool; 4] {
        let (a, b) = (self.0, other.0);
        [a[0] > b[0], a[1] > b[1], a[2] > b[2], a[3] > b[3]]
    }

    #[inline(always)]
    pub(crate) fn is_finite(self) -> [bool; 4] {
        self.0.map(f64::is_finite)
    }
}

macro_rules! lane_op {
    ($trait:ident, $method:ident, $op:tt) => {
        impl $trait for F4 {
            type Output = F4;
            #[inline(always)]
            fn $method(self, rhs: F4) -> F4 {
                let (a, b) = (self.0, rhs.0);
                F4([a[0] $op b[0], a[1] $op b[1], a[2] $op b[2], a[3] $op b[3]])
            }
        }
        impl $trait<f64> for F4 {
            type Output = F4;
            #[inline(always)]
            fn $method(self, rhs: f64) -> F4 {
                self $op F4::splat(rhs)
            }
        }
    };
}

lane_op!(Add, add, +);
lane_op!(Sub, sub, -);
lane_op!(Mul, mul, *);
lane_op!(Div, div, /);

/// `a && b` lane by lane.
#[inline(always)]
pub(crate) fn and(a: [bool; 4], b: [bool; 4]) -> [bool; 4] {
    [a[0] && b[0], a[1] && b[1], a[2] && b[2], a[3] && b[3]]
}

/// Four 3-vectors, one per lane, stored by component.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct V3 {
    pub(crate) x: F4,
    pub(crate) y: F4,
    pub(crate) z: F4,
}

impl V3 {
    #[inline(always)]
    pub(crate) fn dot(self, o: Self) -> F4 {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    #[inline(always)]
    pub(crate) fn length_squared(self) -> F4 {
        self.dot(self)
    }

    /// The cross product, component by component as glam's `DVec3::cross` forms it.
    #[inline(always)]
    pub(crate) fn cross(self, o: Self) -> Self {
        Self {
            x: self.y * o.z - o.y * self.z,
            y: self.z * o.x - o.z * self.x,
            z: self.x * o.y - o.x * self.y,
        }
    }

    #[inline(always)]
    pub(crate) fn scale(self, s: F4) -> Self {
        Self {
            x: self.x * s,
            y: self.y * s,
            z: self.z * s,
        }
    }

    #[inline(always)]
    pub(crate) fn div(self, s: F4) -> Self {
        Self {
            x: self.x / s,
            y: self.y / s,
            z: self.z / s,
        }
    }

    /// Lane `l` as a glam vector.
    #[inline(always)]
    pub(crate) fn lane(self, l: usize) -> glam::DVec3 {
        glam::DVec3::new(self.x.0[l], self.y.0[l], self.z.0[l])
    }
}

impl Add for V3 {
    type Output = V3;
    #[inline(always)]
    fn add(self, o: V3) -> V3 {
        V3 {
            x: self.x + o.x,
            y: self.y + o.y,
            z: self.z + o.z,
        }
    }
}

impl Sub for V3 {
    type Output = V3;
    #[inline(always)]
    fn sub(self, o: V3) -> V3 {
        V3 {
            x: self.x - o.x,
            y: self.y - o.y,
            z: self.z - o.z,
        }
    }
}

/// Four homogeneous points (w·P, w), one per lane.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct H4 {
    pub(crate) xyz: V3,
    pub(crate) w: F4,
}

impl H4 {
    /// `self · s` with the same scalar in every lane.
    #[inline(always)]
    pub(crate) fn times(self, s: f64) -> Self {
        let s = F4::splat(s);
        Self {
            xyz: self.xyz.scale(s),
            w: self.w * s,
        }
    }

    #[inline(always)]
    pub(crate) fn plus(self, o: Self) -> Self {
        Self {
            xyz: self.xyz + o.xyz,
            w: self.w + o.w,
        }
    }

    /// Writes a glam 4-vector into lane `l`.
    #[inline(always)]
    pub(crate) fn set_lane(&mut self, l: usize, h: glam::DVec4) {
        self.xyz.x.0[l] = h.x;
        self.xyz.y.0[l] = h.y;
        self.xyz.z.0[l] = h.z;
        self.w.0[l] = h.w;
    }
}

/// Σ_s points[s] · weights[s], summed in order from the first product: the lane form of a
/// (q + 1)-term basis sum.
#[inline(always)]
pub(crate) fn weighted_sum<const N: usize>(points: &[H4; N], weights: &[f64; N]) -> H4 {
    let mut acc = points[0].times(weights[0]);
    for s in 1..N {
        acc = acc.plus(points[s].times(weights[s]));
    }
    acc
}
