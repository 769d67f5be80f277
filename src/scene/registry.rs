//! The kinds of object knotwork knows, each registered once: the `"type"` of its records in a
//! project file, the function that reads such a record back, and small examples of it that
//! the conformance tests run through every check. The built-in kinds are listed here; a kind
//! defined elsewhere (a plug-in, a test module) joins with [`register`] and is then read from
//! projects, shown, edited, analysed and exported like the built-in ones.

use std::sync::{PoisonError, RwLock};

use super::json::FormatError;
use super::{ObjectGeometry, SceneObject};

/// Reads a kind's record (its `"type"` and own fields; the object's name, visibility and the
/// like already taken out) found at JSON path `path`.
pub type ReadRecord =
    fn(path: &str, record: serde_json::Value) -> Result<ObjectGeometry, FormatError>;

/// One kind of object, as registered.
#[derive(Debug, Clone, Copy)]
pub struct KindEntry {
    /// The `"type"` of the kind's records ([`super::ObjectKind::record`]).
    pub record_type: &'static str,
    /// Reads a record of this type back.
    pub read: ReadRecord,
    /// Small objects of the kind for the conformance tests: every variant of the kind that
    /// takes another road (a trimmed surface beside an untrimmed one, a crease, a triangle in a
    /// cage), each with the segments it is best checked at.
    pub examples: fn() -> Vec<SceneObject>,
}

/// Why [`register`] refused a kind.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("a kind with records of type \"{0}\" is registered already")]
pub struct AlreadyRegistered(pub &'static str);

/// The built-in kinds.
const BUILT_IN: [KindEntry; 7] = [
    super::nurbs::ENTRY,
    super::patch_set::ENTRY,
    super::mesh::ENTRY,
    super::subdiv::ENTRY,
    super::triangle::ENTRY,
    super::curve::ENTRY,
    super::polysurface::ENTRY,
];

/// Kinds registered while the program runs.
static REGISTERED: RwLock<Vec<KindEntry>> = RwLock::new(Vec::new());

/// Adds a kind; refused when a kind with the same record type is there already (built in or
/// registered before), so that a record always reads as one kind.
pub fn register(entry: KindEntry) -> Result<(), AlreadyRegistered> {
    let mut registered = REGISTERED.write().unwrap_or_else(PoisonError::into_inner);
    if BUILT_IN
        .iter()
        .chain(registered.iter())
        .any(|k| k.record_type == entry.record_type)
    {
        return Err(AlreadyRegistered(entry.record_type));
    }
    registered.push(entry);
    Ok(())
}

/// Every kind: the built-in ones, then the registered ones in the order they came.
pub fn kinds() -> Vec<KindEntry> {
    let registered = REGISTERED.read().unwrap_or_else(PoisonError::into_inner);
    BUILT_IN.iter().chain(registered.iter()).copied().collect()
}

/// The kind whose records have type `record_type`.
pub fn kind_of_record(record_type: &str) -> Option<KindEntry> {
    kinds().into_iter().find(|k| k.record_type == record_type)
}

/// Reads a JSON value at `path` into the record struct `T` (serde), with the JSON path of
/// whatever is wrong: the helper every kind's reader uses.
pub fn deserialize<T: serde::de::DeserializeOwned>(
    path: &str,
    value: serde_json::Value,
) -> Result<T, FormatError> {
    serde_path_to_error::deserialize(value).map_err(|e| super::json::serde_error(path, e))
}

/// A serialisable record as a JSON value (`Null` if serde refuses it, which the plain data of
/// a record never makes it do).
pub fn to_record<T: serde::Serialize>(record: &T) -> serde_json::Value {
    serde_json::to_value(record).unwrap_or(serde_json::Value::Null)
}

/// Points as a record writes them, `[x, y, z]` each.
pub fn point_records(points: &[glam::DVec3]) -> Vec<[f64; 3]> {
    points.iter().map(|p| p.to_array()).collect()
}

/// The points of a record's `[x, y, z]` list ([`point_records`] read back).
pub fn points_of(records: &[[f64; 3]]) -> Vec<glam::DVec3> {
    records
        .iter()
        .map(|&p| glam::DVec3::from_array(p))
        .collect()
}
