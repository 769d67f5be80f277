//! The kinds of object knotwork knows, each registered once: the `"type"` of its records in a
//! project file, the function that reads such a record back, and small examples of it that
//! the conformance tests run through every check. The built-in kinds are listed here; a kind
//! defined elsewhere (a plug-in, a test module) joins with [`register`] and is then read from
//! projects, shown, edited, analysed and exported like the built-in ones.

use std::sync::{PoisonError, RwLock};

pub use super::record::{KindEntry, ReadRecord, deserialize, point_records, points_of, to_record};

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
