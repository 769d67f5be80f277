//! Typed errors of the geometry kernel.

use thiserror::Error;

/// Why a piece of geometry was rejected. Each variant names the offending field and index.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum GeometryError {
    #[error("patch {patch}: degree ({degree_u}, {degree_v}) is outside 1..={max}")]
    DegreeOutOfRange {
        patch: usize,
        degree_u: usize,
        degree_v: usize,
        max: usize,
    },
    #[error(
        "patch {patch}: has {found} control point indices, degree ({degree_u}, {degree_v}) needs {expected}"
    )]
    ControlPointCount {
        patch: usize,
        degree_u: usize,
        degree_v: usize,
        expected: usize,
        found: usize,
    },
    #[error(
        "patch {patch}: control point index {index} (entry {entry}) is out of range (the set has {count} points)"
    )]
    IndexOutOfRange {
        patch: usize,
        entry: usize,
        index: u32,
        count: usize,
    },
    #[error("control point {index}: coordinate {coordinate} is not finite")]
    NonFiniteCoordinate { index: usize, coordinate: usize },
    #[error("control point {index}: weight {weight} must be finite and > 0")]
    InvalidWeight { index: usize, weight: f64 },
    #[error("{points} control points but {weights} weights")]
    WeightCount { points: usize, weights: usize },
    #[error("control point {index} does not exist (the set has {count} points)")]
    NoSuchPoint { index: usize, count: usize },
    #[error("patch index {patch} is out of range (the set has {count} patches)")]
    NoSuchPatch { patch: usize, count: usize },
    #[error("parameter ({u}, {v}) is outside the patch domain [0, 1] × [0, 1]")]
    ParameterOutOfDomain { u: f64, v: f64 },
    #[error("sample data {name}: {message}")]
    SampleData { name: &'static str, message: String },
}
