//! The geometry kernel of knotwork: pure f64 mathematics, no GPU, no UI and no file formats.
//!
//! Curves and surfaces (NURBS, Bézier patch sets, triangular Bézier patches, polygon meshes,
//! subdivision cages in five schemes), trimmed surfaces, constructions (extrude, revolve, loft,
//! sweep, Coons, Gordon, Hermite), differential geometry and continuity, free-form deformation
//! and displacement, and export tessellation. Everything the editor's GPU evaluator draws is
//! defined here first, and the GPU is tested against these functions.
//!
//! ```
//! use glam::DVec3;
//! use knotwork_kernel::construct;
//!
//! // An exact rational sphere: every point lies at the radius, and the Gaussian curvature is 1/r².
//! let sphere = construct::sphere(DVec3::ZERO, 2.0)?;
//! let [(u0, u1), (v0, v1)] = sphere.domain();
//! let (u, v) = (0.3 * u0 + 0.7 * u1, 0.6 * v0 + 0.4 * v1);
//! assert!((sphere.point_at(u, v)?.length() - 2.0).abs() < 1e-12);
//! let local = sphere.local_geometry(u, v)?;
//! assert!((local.curvature.values().gaussian - 0.25).abs() < 1e-9);
//! # Ok::<(), knotwork_kernel::GeometryError>(())
//! ```

// `!(x > 0.0)` is the deliberate NaN-rejecting form of every validity check in the kernel.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod basis;
pub mod bernstein;
pub mod bezier;
pub mod blend;
pub mod boolean;
pub mod construct;
pub mod continuity;
pub mod curve;
pub mod curve_edit;
pub mod diffgeo;
pub mod displace;
pub mod edge;
pub mod error;
pub mod features;
pub mod ffd;
pub mod fillet;
pub mod fit;
pub mod format;
pub mod interpolation;
pub mod intersect;
pub mod intersect_curve;
pub mod join;
mod lanes;
pub mod loft;
pub mod mass;
pub mod mesh;
pub mod mesh_curvature;
pub mod network;
pub mod offset;
pub mod ops;
pub mod par;
pub mod parametric;
pub mod planar;
pub mod samples;
pub mod solids;
pub mod splines;
pub mod subdiv;
pub mod surface;
pub mod sweep;
pub mod tess;
pub mod transfinite;
pub mod triangle;
pub mod trim;
pub mod vector;

pub use bezier::{BezierPatch, BezierPatchSet};
pub use curve::{NurbsCurve, SpaceCurve, TrimCurve};
pub use diffgeo::{Curvature, CurvatureValues, FundamentalForms, SurfaceDerivatives};
pub use error::{CageProblem, GeometryError, Location};
pub use format::{FormatError, LengthUnit};
pub use mesh::PolygonMesh;
pub use parametric::ParametricSurface;
pub use surface::{Direction, NurbsSurface};
pub use trim::{TrimLoop, TrimProblem, TrimmedSurface};

/// The highest polynomial degree (per parameter direction) the kernel's Bézier evaluator accepts.
pub const MAX_BEZIER_DEGREE: usize = 15;

/// Helpers the kernel's unit tests share.
#[cfg(test)]
pub(crate) mod test_support {
    use super::{NurbsSurface, SpaceCurve};

    /// A deterministic generator for tests (SplitMix64: Steele, Lea & Flood, "Fast splittable
    /// pseudorandom number generators", 2014), uniform in [0, 1).
    pub(crate) fn uniform(state: &mut u64) -> f64 {
        *state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = *state;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }

    /// The largest distance from `samples` + 1 evenly spaced points of the curve to the surface
    /// (point inversion).
    pub(crate) fn curve_to_surface(
        surface: &NurbsSurface,
        curve: &SpaceCurve,
        samples: usize,
    ) -> f64 {
        (0..=samples)
            .map(|i| {
                curve
                    .point_at(curve.parameter_at(i as f64 / samples as f64))
                    .unwrap()
            })
            .map(|p| surface.closest_point(p).unwrap().distance)
            .fold(0.0, f64::max)
    }

    use glam::{DAffine3, DQuat, DVec3};

    /// Marsaglia's xorshift64 from `seed` (any value; 0 is moved off).
    pub(crate) struct Xorshift(u64);

    impl Xorshift {
        pub fn new(seed: u64) -> Self {
            Self(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
        }

        /// The generator in state `state` (not 0) as it is, unmixed.
        pub fn from_state(state: u64) -> Self {
            Self(state.max(1))
        }

        /// The next 64 random bits.
        pub fn bits(&mut self) -> u64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            self.0
        }

        /// A number in [0, 1).
        pub fn unit(&mut self) -> f64 {
            (self.bits() >> 11) as f64 / (1u64 << 53) as f64
        }

        /// An integer in [0, n).
        pub fn below(&mut self, n: u64) -> u64 {
            self.bits() % n
        }
    }

    /// A random B-spline surface over [0, 1]² in general position: degrees 1 to 5 each way,
    /// up to four spans of random widths (a knot sometimes repeated up to the degree, leaving
    /// a kink), a net of random heights, placed by [`placement`]; sometimes degree-elevated
    /// once along u. Where `weighted`, with weights in [0.2, 5), else polynomial.
    pub(crate) fn random_bspline_surface(state: &mut u64, weighted: bool) -> NurbsSurface {
        let degree = [0, 1].map(|_| 1 + (uniform(state) * 5.0) as usize);
        let knots = degree.map(|p| {
            let mut inner: Vec<f64> = (0..(uniform(state) * 4.0) as usize)
                .map(|_| 0.05 + 0.9 * uniform(state))
                .collect();
            if !inner.is_empty() && uniform(state) < 0.3 {
                let times = 1 + (uniform(state) * p as f64) as usize;
                inner.extend(std::iter::repeat_n(inner[0], times.min(p) - 1));
            }
            inner.sort_by(f64::total_cmp);
            let mut knots = vec![0.0; p + 1];
            knots.extend(inner);
            knots.extend(vec![1.0; p + 1]);
            knots
        });
        let count = [0, 1].map(|d| knots[d].len() - degree[d] - 1);
        let points = (0..count[0] * count[1])
            .map(|k| {
                let (i, j) = (k / count[1], k % count[1]);
                DVec3::new(i as f64, j as f64, 2.0 * uniform(state) - 1.0)
            })
            .collect();
        let weights = weighted.then(|| {
            (0..count[0] * count[1])
                .map(|_| 0.2 * 25f64.powf(uniform(state)))
                .collect()
        });
        let (motion, _) = placement((uniform(state) * 1e9) as u64);
        let surface = NurbsSurface::new(degree, knots, count, points, weights)
            .and_then(|s| s.transformed(&motion))
            .unwrap();
        if uniform(state) < 0.3 {
            surface.elevate_degree(crate::Direction::U, 1).unwrap()
        } else {
            surface
        }
    }

    /// A rotation about a random axis, a uniform scale in [0.5, 3.5) and a shift in
    /// [-100, 100)³, from `seed`: the motion and its scale.
    pub(crate) fn placement(seed: u64) -> (DAffine3, f64) {
        let mut random = Xorshift::new(seed);
        let mut next = || random.unit();
        let axis = DVec3::new(next() - 0.5, next() - 0.5, next() - 0.5).normalize();
        let rotation = DQuat::from_axis_angle(axis, 6.0 * next());
        let scale = 0.5 + 3.0 * next();
        let shift = DVec3::new(next(), next(), next()) * 200.0 - 100.0;
        (
            DAffine3::from_scale_rotation_translation(DVec3::splat(scale), rotation, shift),
            scale,
        )
    }
}
