//! What an edit changed in a scene, in the terms the GPU sync layer re-uploads by: the
//! document ([`crate::doc`]) says it, the GPU ([`crate::gpu::SceneSync`]) acts on it, and
//! neither needs the other. It also holds what every edit is made of ([`Change`]) and why one is
//! refused ([`EditError`]), so that an operation ([`super::operation`]) plans changes without
//! depending on the document.

use thiserror::Error;

use super::{LengthUnit, MAX_NAME_LENGTH, SceneObject};
use crate::kernel::GeometryError;

/// How an edit affected an object, for the editor to re-upload as little as possible.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Touched {
    /// Only control point positions or weights of object `index` changed: same patch layout.
    Points(usize),
    /// Objects were added, removed or changed in structure: rebuild the GPU geometry.
    Structure,
    /// Object `index` alone changed in structure (another patch layout, shown or hidden, its
    /// displacement or lattice reshaped); every other object is as it was, at the same index.
    /// The GPU geometry is rebuilt with the other objects' patches kept, not derived again.
    Object(usize),
    /// One object was inserted at `index`, or the object at `index` was removed (an edit and
    /// its undo name the same index); every other object is as it was, in the same order. The
    /// GPU geometry is rebuilt with the other objects' patches kept.
    InsertedOrRemoved(usize),
    /// Only names or similar: nothing to re-upload.
    Nothing,
}

impl Touched {
    /// Whether the GPU geometry is rebuilt ([`Self::Structure`], [`Self::Object`] or
    /// [`Self::InsertedOrRemoved`]): the layout of patches, vertices and selections may have
    /// changed.
    pub fn is_structure(self) -> bool {
        matches!(
            self,
            Self::Structure | Self::Object(_) | Self::InsertedOrRemoved(_)
        )
    }
}

/// What a drag step or a move changed: the object and the Bézier patches of its decomposition
/// that must be re-derived and re-evaluated (the union of the moved points' supports).
/// `relaid`: the move ended with the object's layout changed (an adaptive refinement chose
/// other depths), so its GPU geometry must be rebuilt rather than updated. `linked`: other
/// objects whose shared lattice moved too (their lattices are uploaded again). `rebuilt`:
/// objects built from the moved curve (construction history), built again with it; `relaid`
/// also says when one of those came out in another layout.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PointsMoved {
    pub object: usize,
    pub patches: Vec<usize>,
    pub relaid: bool,
    pub linked: Vec<usize>,
    pub rebuilt: Vec<usize>,
}

/// Why a command was refused. The document is unchanged.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum EditError {
    #[error("there is no object {object} (the scene has {count})")]
    NoSuchObject { object: usize, count: usize },
    #[error("an object it reads (id {id}) is no longer in the scene")]
    ObjectGone { id: u64 },
    #[error("{operation}: {field} {message}")]
    BadParameter {
        operation: &'static str,
        field: &'static str,
        message: String,
    },
    #[error("{name}: {operation} needs a NURBS surface; this object is {kind}")]
    NeedsNurbs {
        name: String,
        operation: &'static str,
        kind: &'static str,
    },
    #[error("{name}: {source}")]
    Geometry {
        name: String,
        #[source]
        source: GeometryError,
    },
    #[error(
        "{name}: the knot {direction} = {value} cannot be removed without moving the surface more than {tolerance}"
    )]
    KnotNotRemovable {
        name: String,
        direction: &'static str,
        value: f64,
        tolerance: f64,
    },
    #[error("a weight must be finite and > 0, got {weight}")]
    InvalidWeight { weight: f64 },
    #[error(
        "point {point}: the coordinate {value:e} is outside ±{MAX_COORDINATE:e}, the model space the GPU draws and the analyses measure"
    )]
    CoordinateOutOfRange { point: usize, value: f64 },
    #[error("nothing selected: {operation} needs at least one control point")]
    NothingSelected { operation: &'static str },
    #[error("a name must be 1 to {MAX_NAME_LENGTH} characters, without control characters")]
    InvalidName,
    #[error("a colour's red, green and blue must each be from 0 to 1")]
    InvalidColor,
    #[error("segments per span must be in 1..={max}, got {segments}")]
    Segments { segments: u32, max: u32 },
    #[error("no drag is in progress")]
    NoDrag,
    #[error("point {point} is not part of the drag")]
    NotDragged { point: usize },
    #[error("the history has nothing to {0}")]
    NothingTo(&'static str),
    #[error("the document no longer matches the history ({0}); the history was cleared")]
    HistoryMismatch(String),
}

/// The largest coordinate a moved point may have: beyond it the GPU's f32 loses the shape and
/// the squared distances of the analyses overflow.
pub const MAX_COORDINATE: f64 = 1e9;

/// What one applied command did to the scene, in the order it happened.
#[derive(Debug, Clone, PartialEq)]
// An edit holds a handful of changes, each a whole object before and after: boxing them would
// cost an allocation per change for no saving.
#[allow(clippy::large_enum_variant)]
pub enum Change {
    Replace {
        index: usize,
        before: SceneObject,
        after: SceneObject,
    },
    Insert {
        index: usize,
        object: SceneObject,
    },
    Remove {
        index: usize,
        object: SceneObject,
    },
    /// The document's length unit changed (opening a STEP file, or the unit menu).
    Unit {
        before: Option<LengthUnit>,
        after: Option<LengthUnit>,
    },
}
