//! The geometry kernel: pure f64 mathematics, no GPU and no UI.
//!
//! Everything the GPU draws is defined here first; the GPU evaluator (`crate::gpu`) is tested
//! against these functions.

pub mod bernstein;
pub mod bezier;
pub mod error;
pub mod samples;

pub use bezier::{BezierPatch, BezierPatchSet, SurfaceDerivatives};
pub use error::GeometryError;

/// The highest polynomial degree (per parameter direction) the kernel's Bézier evaluator accepts.
pub const MAX_BEZIER_DEGREE: usize = 15;
