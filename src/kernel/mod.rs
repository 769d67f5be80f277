//! The geometry kernel: pure f64 mathematics, no GPU and no UI.
//!
//! Everything the GPU draws is defined here first; the GPU evaluator (`crate::gpu`) is tested
//! against these functions.

pub mod basis;
pub mod bernstein;
pub mod bezier;
pub mod construct;
pub mod continuity;
pub mod curve;
pub mod diffgeo;
pub mod displace;
pub mod error;
pub mod ffd;
pub mod mesh;
pub mod ops;
pub mod samples;
pub mod subdiv;
pub mod surface;
pub mod tess;
pub mod transfinite;
pub mod triangle;
pub mod trim;
pub mod vector;

pub use bezier::{BezierPatch, BezierPatchSet};
pub use curve::{NurbsCurve, SpaceCurve, TrimCurve};
pub use diffgeo::{Curvature, CurvatureValues, FundamentalForms, SurfaceDerivatives};
pub use error::{CageProblem, GeometryError, Location};
pub use mesh::PolygonMesh;
pub use surface::{Direction, NurbsSurface};
pub use trim::{TrimLoop, TrimProblem, TrimmedSurface};

/// The highest polynomial degree (per parameter direction) the kernel's Bézier evaluator accepts.
pub const MAX_BEZIER_DEGREE: usize = 15;
