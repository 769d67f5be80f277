//! The built-in modelling operations, one module each ([`crate::scene::operation`] says what an
//! operation is): every one owns its parameters (the fields of its JSON value beside `"op"`),
//! checks them (a refusal names the bad field), plans its changes against the scene and names
//! its undo step. The editor's panels, the page's `apply`, `knotwork apply` and construction
//! history run them all through [`crate::doc::Command::Apply`].
//!
//! To add an operation: a module here with its [`crate::scene::operation::OperationParams`] type and its `ENTRY`, and
//! one line in [`BUILT_IN`]. An operation defined elsewhere (a plug-in, a test) joins with
//! [`register`] instead and is then read, offered and applied like these.

pub mod blend;
pub mod boolean;
pub mod cage;
pub mod construct;
pub mod contour;
pub mod explode;
pub mod features;
pub mod fillet;
pub mod intersect;
pub mod join;
pub mod matching;
pub mod offset;
pub mod project;
pub mod split;
pub mod transform;
pub mod trim;

use crate::doc::Change;
use crate::scene::SceneObject;
use crate::scene::json::FormatError;
use crate::scene::operation::{self, Operation, OperationEntry, OperationTaken};

/// The built-in operations.
pub const BUILT_IN: [OperationEntry; 20] = [
    construct::ENTRY,
    transform::ENTRY,
    offset::ENTRY,
    fillet::ENTRY,
    blend::ENTRY,
    matching::ENTRY,
    intersect::ENTRY,
    contour::ENTRY,
    join::ENTRY,
    explode::ENTRY,
    trim::ENTRY,
    split::ENTRY,
    project::ENTRY,
    boolean::ENTRY,
    features::FILLET_ENTRY,
    features::CHAMFER_ENTRY,
    features::SHELL_ENTRY,
    features::OFFSET_FACE_ENTRY,
    features::DRAFT_ENTRY,
    cage::ENTRY,
];

/// The plan that puts `after` in place of object `index` (now `before`), as one undo step named
/// `label`.
pub(crate) fn replace_object(
    index: usize,
    before: &SceneObject,
    after: SceneObject,
    label: String,
) -> operation::Planned {
    (
        vec![Change::Replace {
            index,
            before: before.clone(),
            after,
        }],
        label,
    )
}

/// Adds an operation defined outside this module; refused when one of the same name exists.
pub fn register(entry: OperationEntry) -> Result<(), OperationTaken> {
    operation::register(entry, &BUILT_IN)
}

/// Every operation: the built-in ones, then the registered ones in the order they came.
pub fn operations() -> Vec<OperationEntry> {
    let mut all = BUILT_IN.to_vec();
    all.extend(operation::registered());
    all
}

/// The operation named `name`.
pub fn named(name: &str) -> Option<OperationEntry> {
    operations().into_iter().find(|e| e.name == name)
}

/// Reads an operation's JSON value `{"op": NAME, ...}` found at JSON path `path`.
pub fn from_value(path: &str, value: serde_json::Value) -> Result<Operation, FormatError> {
    let name = match value.get("op") {
        Some(serde_json::Value::String(name)) => name.clone(),
        Some(other) => {
            return Err(FormatError::new(
                format!("{path}.op"),
                format!("expected an operation's name, found {other}"),
            ));
        }
        None => {
            return Err(FormatError::new(
                path,
                "expected an operation: {\"op\": NAME, ...}",
            ));
        }
    };
    let entry = named(&name).ok_or_else(|| {
        let known: Vec<&str> = operations().iter().map(|e| e.name).collect();
        FormatError::new(
            format!("{path}.op"),
            format!(
                "no operation is named \"{name}\" (there are \"{}\")",
                known.join("\", \"")
            ),
        )
    })?;
    (entry.read)(path, value)
}

/// Reads an operation from JSON text (the page's `apply`, `knotwork apply`'s file).
pub fn parse(text: &str) -> Result<Operation, FormatError> {
    let value: serde_json::Value = serde_json::from_str(text)
        .map_err(|e| FormatError::new("", format!("not valid JSON: {e}")))?;
    from_value("", value)
}

/// Checks that `value` is a finite number (and above 0 where `positive`), or refuses it naming
/// `field` of operation `operation`.
pub fn finite(
    operation: &'static str,
    field: &'static str,
    value: f64,
    positive: bool,
) -> Result<f64, crate::doc::EditError> {
    if value.is_finite() && (!positive || value > 0.0) {
        return Ok(value);
    }
    Err(crate::doc::EditError::BadParameter {
        operation,
        field,
        message: format!(
            "must be a finite number{} (got {value})",
            if positive { " above 0" } else { "" }
        ),
    })
}

/// The indices of the objects `objects` name now.
pub fn resolve_all(
    scene: &crate::scene::Scene,
    objects: &[crate::scene::operation::ObjectRef],
) -> Result<Vec<usize>, crate::doc::EditError> {
    objects.iter().map(|&o| scene.resolve(o)).collect()
}
