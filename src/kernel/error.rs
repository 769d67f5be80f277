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
    #[error("{field}: degree {degree} is outside 1..={max}")]
    Degree {
        field: &'static str,
        degree: usize,
        max: usize,
    },
    #[error(
        "{field}: {count} control points are too few for degree {degree} (at least degree + 1 are needed)"
    )]
    TooFewControlPoints {
        field: &'static str,
        count: usize,
        degree: usize,
    },
    #[error(
        "{field}: {found} knots, but {count} control points of degree {degree} need count + degree + 1 = {expected}"
    )]
    KnotCount {
        field: &'static str,
        found: usize,
        expected: usize,
        count: usize,
        degree: usize,
    },
    #[error("{field}[{index}]: knot {value} is not finite")]
    NonFiniteKnot {
        field: &'static str,
        index: usize,
        value: f64,
    },
    #[error(
        "{field}[{index}]: knot {value} is smaller than the knot before it ({previous}); knots must not decrease"
    )]
    DecreasingKnot {
        field: &'static str,
        index: usize,
        value: f64,
        previous: f64,
    },
    #[error(
        "{field}[{index}]: knot {value} is repeated {multiplicity} times, more than {max} ({reason})"
    )]
    KnotMultiplicity {
        field: &'static str,
        index: usize,
        value: f64,
        multiplicity: usize,
        max: usize,
        reason: &'static str,
    },
    #[error("{field}: the parameter domain [{start}, {end}] is empty")]
    EmptyDomain {
        field: &'static str,
        start: f64,
        end: f64,
    },
    #[error("{at}: coordinate {coordinate} is not finite")]
    NonFinitePoint { at: String, coordinate: usize },
    #[error("{at}: weight {weight} must be finite and > 0")]
    BadWeight { at: String, weight: f64 },
    #[error("{field}: {found} control points, expected {expected}")]
    PointCount {
        field: &'static str,
        found: usize,
        expected: usize,
    },
    #[error("{parameter} = {value} is outside the domain [{start}, {end}]")]
    OutsideDomain {
        parameter: &'static str,
        value: f64,
        start: f64,
        end: f64,
    },
    #[error("{parameter} = {value} must lie strictly inside the domain ({start}, {end})")]
    NotInterior {
        parameter: &'static str,
        value: f64,
        start: f64,
        end: f64,
    },
    #[error(
        "cannot insert knot {value} {times} more times: its multiplicity would exceed the degree {degree}"
    )]
    InsertionTooMany {
        value: f64,
        times: usize,
        degree: usize,
    },
    #[error("{what}: {message}")]
    Construction { what: &'static str, message: String },
    #[error("sample data {name}: {message}")]
    SampleData { name: &'static str, message: String },
}
