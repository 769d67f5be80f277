//! What a kind registers ([`KindEntry`]) and the helpers every kind's project record uses:
//! below the kinds and the registry that lists them, so that neither imports the other.

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
