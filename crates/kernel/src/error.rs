//! Typed errors of the geometry kernel.

use std::fmt;

use glam::DVec2;
use thiserror::Error;

/// Where inside an object a rejected value lies, written as the JSON path below the object in
/// knotwork's file format (`points[3]`, `points[2][5]`, `patches[1].degree[0]`, `knots[0][4]`),
/// so that a file reader puts the object's own path in front and an editor names the point.
/// Built from fields and indices, never parsed back from text.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Location(String);

impl Location {
    /// A field of the object: `name`.
    pub fn field(name: &str) -> Self {
        Self(name.to_owned())
    }

    /// Control point `index` of a list: `points[index]`.
    pub fn point(index: usize) -> Self {
        Self::field("points").index(index)
    }

    /// Control point (i, j) of a grid: `points[i][j]`.
    pub fn grid_point(i: usize, j: usize) -> Self {
        Self::point(i).index(j)
    }

    /// Patch `index` of a set: `patches[index]`.
    pub fn patch(index: usize) -> Self {
        Self::field("patches").index(index)
    }

    /// Face `index` of a cage: `faces[index]`.
    pub fn face(index: usize) -> Self {
        Self::field("faces").index(index)
    }

    /// The edge between vertices `a` and `b` of a cage: `edges[a-b]`, smaller index first.
    pub fn edge(a: u32, b: u32) -> Self {
        Self(format!("edges[{}-{}]", a.min(b), a.max(b)))
    }

    /// This location's element `index`: `...[index]`.
    pub fn index(mut self, index: usize) -> Self {
        self.0 = format!("{}[{index}]", self.0);
        self
    }

    /// This location's field `name`: `....name`.
    pub fn then(mut self, name: &str) -> Self {
        self.0 = format!("{}.{name}", self.0);
        self
    }

    /// The path as text.
    pub fn as_str(&self) -> &str {
        &self.0
    }
}

impl PartialEq<str> for Location {
    fn eq(&self, other: &str) -> bool {
        self.0 == other
    }
}

impl PartialEq<&str> for Location {
    fn eq(&self, other: &&str) -> bool {
        self.0 == *other
    }
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str(&self.0)
    }
}

/// Why a piece of geometry was rejected. Each variant that concerns one value names it with a
/// [`Location`] ([`GeometryError::location`]); its message starts with that location.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum GeometryError {
    #[error("{at}: {found} control points, expected {expected}")]
    PointCount {
        at: Location,
        found: usize,
        expected: usize,
    },
    #[error("{at}: control point index {index} is out of range (the set has {count} points)")]
    IndexOutOfRange {
        at: Location,
        index: u32,
        count: usize,
    },
    #[error("{at}: coordinate {coordinate} is not finite")]
    NonFinitePoint { at: Location, coordinate: usize },
    #[error("{at}: weight {weight} must be finite and > 0")]
    BadWeight { at: Location, weight: f64 },
    #[error("{points} control points but {weights} weights")]
    WeightCount { points: usize, weights: usize },
    #[error("control point {index} does not exist (the set has {count} points)")]
    NoSuchPoint { index: usize, count: usize },
    #[error("patch index {patch} is out of range (the set has {count} patches)")]
    NoSuchPatch { patch: usize, count: usize },
    #[error("{at}: degree {degree} is outside 1..={max}")]
    Degree {
        at: Location,
        degree: usize,
        max: usize,
    },
    #[error(
        "{at}: {count} control points are too few for degree {degree} (at least degree + 1 are needed)"
    )]
    TooFewControlPoints {
        at: Location,
        count: usize,
        degree: usize,
    },
    #[error(
        "{at}: {found} knots, but {count} control points of degree {degree} need count + degree + 1 = {expected}"
    )]
    KnotCount {
        at: Location,
        found: usize,
        expected: usize,
        count: usize,
        degree: usize,
    },
    #[error("{at}: knot {value} is not finite")]
    NonFiniteKnot { at: Location, value: f64 },
    #[error(
        "{at}: knot {value} is smaller than the knot before it ({previous}); knots must not decrease"
    )]
    DecreasingKnot {
        at: Location,
        value: f64,
        previous: f64,
    },
    #[error("{at}: knot {value} is repeated {multiplicity} times, more than {max} ({reason})")]
    KnotMultiplicity {
        at: Location,
        value: f64,
        multiplicity: usize,
        max: usize,
        reason: &'static str,
    },
    #[error("{at}: the parameter domain [{start}, {end}] is empty")]
    EmptyDomain { at: Location, start: f64, end: f64 },
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
    #[error("{at}: {problem}")]
    Cage { at: Location, problem: CageProblem },
    #[error("{at}: {problem}")]
    Trim { at: Location, problem: TrimProblem },
    #[error("sample data {name}: {message}")]
    SampleData { name: &'static str, message: String },
}

/// Why a subdivision cage was refused; the [`Location`] names the face, edge or vertex
/// (`faces[3]`, `edges[2-7]`, `points[5]`, `creases[1]`).
#[derive(Debug, Clone, PartialEq, Error)]
pub enum CageProblem {
    #[error("the edge is shared by {faces} faces (at most 2 for a manifold cage)")]
    NonManifoldEdge { faces: usize },
    #[error(
        "the edge is used twice in the same direction (neighbouring faces disagree on orientation)"
    )]
    Orientation,
    #[error("the faces around this vertex do not form one fan")]
    NonManifoldVertex,
    #[error("the face repeats vertex {vertex}")]
    RepeatedVertex { vertex: u32 },
    #[error("the face has {corners} corners; {scheme} subdivision takes triangles only")]
    NotTriangle {
        corners: usize,
        scheme: &'static str,
    },
    #[error("the face is degenerate (its corners coincide)")]
    Degenerate,
    #[error("sharpness {sharpness} must be finite and ≥ 0")]
    Sharpness { sharpness: f64 },
    #[error("there is no edge between vertices {a} and {b}")]
    NoSuchEdge { a: u32, b: u32 },
    #[error("vertex {vertex} does not exist (the cage has {count} points)")]
    NoSuchVertex { vertex: u32, count: usize },
    #[error("level {level} is outside 0..={max}")]
    Level { level: u32, max: u32 },
    #[error("level {level} would make {faces} faces, more than {max}")]
    TooManyFaces { level: u32, faces: u64, max: u64 },
}

impl GeometryError {
    /// [`Self::NonFinitePoint`] for point `p` at `at`, naming its first coordinate that is not
    /// finite.
    pub fn non_finite_point(at: Location, p: glam::DVec3) -> Self {
        Self::NonFinitePoint {
            at,
            coordinate: p
                .to_array()
                .iter()
                .position(|x| !x.is_finite())
                .unwrap_or(0),
        }
    }

    /// The value this error is about, where it names one.
    pub fn location(&self) -> Option<&Location> {
        match self {
            Self::PointCount { at, .. }
            | Self::IndexOutOfRange { at, .. }
            | Self::NonFinitePoint { at, .. }
            | Self::BadWeight { at, .. }
            | Self::Degree { at, .. }
            | Self::TooFewControlPoints { at, .. }
            | Self::KnotCount { at, .. }
            | Self::NonFiniteKnot { at, .. }
            | Self::DecreasingKnot { at, .. }
            | Self::KnotMultiplicity { at, .. }
            | Self::EmptyDomain { at, .. }
            | Self::Cage { at, .. }
            | Self::Trim { at, .. } => Some(at),
            _ => None,
        }
    }

    /// The message without its location (the whole message where it has none).
    pub fn detail(&self) -> String {
        let text = self.to_string();
        match self.location() {
            Some(at) => text
                .strip_prefix(at.as_str())
                .and_then(|rest| rest.strip_prefix(": "))
                .map_or_else(|| text.clone(), str::to_owned),
            None => text,
        }
    }
}

/// Why a trim loop was refused; the [`Location`] names the loop and curve (`trims[1][2]`).
#[derive(Debug, Clone, PartialEq, Error)]
pub enum TrimProblem {
    #[error("the loop has no curves")]
    EmptyLoop,
    #[error(
        "the loop is open: curve {curve} ends at {end} but curve {next} starts at {start} (each curve must start where the one before it ends)"
    )]
    Open {
        curve: usize,
        next: usize,
        end: Uv,
        start: Uv,
    },
    #[error("the curve leaves the surface's domain [{u0}, {u1}] × [{v0}, {v1}] near {near}")]
    OutsideDomain {
        near: Uv,
        u0: f64,
        u1: f64,
        v0: f64,
        v1: f64,
    },
    #[error("the loop crosses itself: this curve meets curve {other} of the same loop near {near}")]
    SelfIntersection { other: usize, near: Uv },
    #[error("the loop crosses loop {other_loop} (its curve {other_curve}) near {near}")]
    Crossing {
        other_loop: usize,
        other_curve: usize,
        near: Uv,
    },
    #[error("the loop encloses no area")]
    ZeroArea,
    #[error("{0}")]
    Curve(String),
}

/// A (u, v) point in a message.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Uv(pub DVec2);

impl fmt::Display for Uv {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(f, "({:.6}, {:.6})", self.0.x, self.0.y)
    }
}

/// The error of a construction (`what`) refused with `message`.
pub fn construction(what: &'static str, message: impl Into<String>) -> GeometryError {
    GeometryError::Construction {
        what,
        message: message.into(),
    }
}
