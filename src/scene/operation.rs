//! Modelling operations as values: each operation (an offset, a fillet, a boolean, a tool a
//! plug-in or a test module defines) is one type that owns its parameters (serde, with the
//! `"op"` tag of its JSON), the objects it reads ([`ObjectRef`]), its label and its plan
//! against the scene (the [`Change`]s it would make, so undo stays exact). The editor's panels,
//! the page's `apply` call, the command line's `knotwork apply` and construction history all
//! build an [`Operation`] and hand it to one place, the document's
//! [`crate::doc::Command::Apply`].
//!
//! An operation joins with [`register`] (the built-in ones are listed in [`crate::ops`]); its
//! JSON value is `{"op": NAME, ...its fields}`, objects given by their index in the scene.
//!
//! A result built with history keeps a [`Recipe`]: the operation with its inputs held by
//! [`ObjectId`], which survives renames, reordering and duplicate names, and the document runs
//! it again whenever an input changes ([`crate::doc::construction`]).

use std::any::Any;
use std::fmt::Debug;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{PoisonError, RwLock};

use serde::Serialize;
use serde::de::DeserializeOwned;

use super::Scene;
use super::change::{Change, EditError};
use super::json::FormatError;

/// An object's identity while the program runs: given once, when the object is made, kept by
/// every edit of it, and never given to another object. It is not written to files (a
/// project names objects by position); objects read from a file get new ones.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct ObjectId(u64);

impl ObjectId {
    /// An id no object has had before in this program.
    pub fn fresh() -> Self {
        static NEXT: AtomicU64 = AtomicU64::new(1);
        Self(NEXT.fetch_add(1, Ordering::Relaxed))
    }

    /// The id's number (for messages).
    pub fn get(self) -> u64 {
        self.0
    }
}

/// How an operation names an object: by its index in the scene (what a user, the page and the
/// command line give: `"object": 2`), or by [`ObjectId`] (what construction history keeps,
/// written `{"id": n}`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ObjectRef {
    Index(usize),
    Id(ObjectId),
}

impl Serialize for ObjectRef {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        match self {
            ObjectRef::Index(k) => serializer.serialize_u64(*k as u64),
            ObjectRef::Id(id) => {
                let mut map = serializer.serialize_map(Some(1))?;
                map.serialize_entry("id", &id.0)?;
                map.end()
            }
        }
    }
}

impl<'de> serde::Deserialize<'de> for ObjectRef {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        #[derive(serde::Deserialize)]
        #[serde(untagged)]
        enum Raw {
            Index(usize),
            Id { id: u64 },
        }
        match Raw::deserialize(deserializer) {
            Ok(Raw::Index(k)) => Ok(ObjectRef::Index(k)),
            Ok(Raw::Id { id }) => Ok(ObjectRef::Id(ObjectId(id))),
            Err(_) => Err(serde::de::Error::custom(
                "expected an object's index (a whole number ≥ 0)",
            )),
        }
    }
}

impl From<usize> for ObjectRef {
    fn from(index: usize) -> Self {
        ObjectRef::Index(index)
    }
}

impl Scene {
    /// The index of the object `object` names now.
    pub fn resolve(&self, object: ObjectRef) -> Result<usize, EditError> {
        match object {
            ObjectRef::Index(k) if k < self.objects.len() => Ok(k),
            ObjectRef::Index(k) => Err(EditError::NoSuchObject {
                object: k,
                count: self.objects.len(),
            }),
            ObjectRef::Id(id) => self
                .objects
                .iter()
                .position(|o| o.id == id)
                .ok_or(EditError::ObjectGone { id: id.get() }),
        }
    }
}

/// What an operation would do: the changes, in order, and the label of its undo step.
pub type Planned = (Vec<Change>, String);

/// The parameters of one operation: a serde type (its fields are the JSON value's, beside
/// `"op"`) that says which objects it reads and what it would change. Implementing this and
/// registering its [`OperationEntry`] ([`entry`]) is all an operation takes.
pub trait OperationParams:
    Serialize + DeserializeOwned + Clone + PartialEq + Debug + Send + Sync + 'static
{
    /// The `"op"` of its JSON value ("offset"); one per operation.
    const NAME: &'static str;

    /// The label of its undo step when the plan does not give a fuller one.
    fn label(&self) -> String {
        Self::NAME.replace('_', " ")
    }

    /// What it makes, in a word or two, for sentences such as "X is the loft of a, b, c"
    /// (its label unless it says otherwise).
    fn title(&self) -> String {
        self.label()
    }

    /// The objects it reads, to be renamed, followed and resolved.
    fn objects_mut(&mut self) -> Vec<&mut ObjectRef>;

    /// The changes it would make to `scene` and the label of the undo step; refused with the
    /// reason (naming the bad field) and no change when it cannot be done.
    fn plan(&self, scene: &Scene) -> Result<Planned, EditError> {
        self.plan_with_report(scene).map(|(planned, _)| planned)
    }

    /// [`Self::plan`] and what the operation found besides its changes (a fit's deviation,
    /// where an offset folds, how many sections a fillet has), as JSON for `knotwork apply`
    /// and the command line; `None` where the label says it all. An operation implements
    /// this one or [`Self::plan`].
    fn plan_with_report(
        &self,
        scene: &Scene,
    ) -> Result<(Planned, Option<serde_json::Value>), EditError> {
        Ok((self.plan(scene)?, None))
    }
}

/// An operation behind one interface (implemented for every [`OperationParams`]).
pub trait OperationKind: Debug + Send + Sync + 'static {
    fn name(&self) -> &'static str;
    fn label(&self) -> String;
    /// What it makes, in a word or two ([`OperationParams::title`]).
    fn title(&self) -> String;
    /// The objects it reads.
    fn objects(&self) -> Vec<ObjectRef>;
    fn objects_mut(&mut self) -> Vec<&mut ObjectRef>;
    fn plan(&self, scene: &Scene) -> Result<Planned, EditError>;
    /// The plan and the operation's report ([`OperationParams::plan_with_report`]).
    fn plan_with_report(
        &self,
        scene: &Scene,
    ) -> Result<(Planned, Option<serde_json::Value>), EditError>;
    /// Its JSON value, `{"op": NAME, ...fields}`.
    fn to_json(&self) -> serde_json::Value;
    fn clone_kind(&self) -> Box<dyn OperationKind>;
    fn equals(&self, other: &dyn OperationKind) -> bool;
    fn as_any(&self) -> &dyn Any;
}

impl<T: OperationParams> OperationKind for T {
    fn name(&self) -> &'static str {
        T::NAME
    }

    fn label(&self) -> String {
        OperationParams::label(self)
    }

    fn title(&self) -> String {
        OperationParams::title(self)
    }

    fn objects(&self) -> Vec<ObjectRef> {
        let mut copy = self.clone();
        OperationParams::objects_mut(&mut copy)
            .into_iter()
            .map(|r| *r)
            .collect()
    }

    fn objects_mut(&mut self) -> Vec<&mut ObjectRef> {
        OperationParams::objects_mut(self)
    }

    fn plan(&self, scene: &Scene) -> Result<Planned, EditError> {
        OperationParams::plan(self, scene)
    }

    fn plan_with_report(
        &self,
        scene: &Scene,
    ) -> Result<(Planned, Option<serde_json::Value>), EditError> {
        OperationParams::plan_with_report(self, scene)
    }

    fn to_json(&self) -> serde_json::Value {
        let mut value = serde_json::to_value(self).unwrap_or(serde_json::Value::Null);
        match &mut value {
            serde_json::Value::Object(map) => {
                map.insert("op".into(), T::NAME.into());
                value
            }
            _ => serde_json::json!({ "op": T::NAME }),
        }
    }

    fn clone_kind(&self) -> Box<dyn OperationKind> {
        Box::new(self.clone())
    }

    fn equals(&self, other: &dyn OperationKind) -> bool {
        other.as_any().downcast_ref::<T>() == Some(self)
    }

    fn as_any(&self) -> &dyn Any {
        self
    }
}

/// One operation, of any registered type.
pub struct Operation(Box<dyn OperationKind>);

impl Operation {
    pub fn new(params: impl OperationParams) -> Self {
        Self(Box::new(params))
    }

    /// The operation as its own type, if it is one.
    pub fn params<T: OperationParams>(&self) -> Option<&T> {
        self.0.as_any().downcast_ref()
    }

    /// The operation with every object it reads named by id (as `scene` has them now), for
    /// keeping in history; refused when one of them is not in `scene`.
    pub fn by_id(&self, scene: &Scene) -> Result<Self, EditError> {
        let mut copy = self.clone();
        for object in copy.0.objects_mut() {
            *object = ObjectRef::Id(scene.objects[scene.resolve(*object)?].id);
        }
        Ok(copy)
    }

    /// The operation with every object it reads named by its index in `scene` (as a file
    /// keeps it); refused when one of them is not in `scene`.
    pub fn by_index(&self, scene: &Scene) -> Result<Self, EditError> {
        let mut copy = self.clone();
        for object in copy.0.objects_mut() {
            *object = ObjectRef::Index(scene.resolve(*object)?);
        }
        Ok(copy)
    }

    /// Whether it reads object `id`.
    pub fn reads(&self, id: ObjectId) -> bool {
        self.0.objects().contains(&ObjectRef::Id(id))
    }
}

impl std::ops::Deref for Operation {
    type Target = dyn OperationKind;
    fn deref(&self) -> &Self::Target {
        self.0.as_ref()
    }
}

impl Clone for Operation {
    fn clone(&self) -> Self {
        Self(self.0.clone_kind())
    }
}

impl PartialEq for Operation {
    fn eq(&self, other: &Self) -> bool {
        self.0.equals(other.0.as_ref())
    }
}

impl Debug for Operation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.0.fmt(f)
    }
}

/// How an object was made by an operation and is made again when the operation's inputs
/// change: the operation (its inputs by [`ObjectId`]) and which of the objects it adds this is.
#[derive(Debug, Clone, PartialEq)]
pub struct Recipe {
    pub operation: Operation,
    /// This object's place among the objects the operation adds (0: the first).
    pub output: usize,
}

impl Recipe {
    /// "loft of s0, s1, s2": what the operation makes and the names the objects it reads have
    /// in `scene` now.
    pub fn describe(&self, scene: &Scene) -> String {
        let names: Vec<&str> = self
            .operation
            .objects()
            .into_iter()
            .filter_map(|object| scene.resolve(object).ok())
            .map(|k| scene.objects[k].name.as_str())
            .collect();
        format!("{} of {}", self.operation.title(), names.join(", "))
    }
}

/// One operation, as registered.
#[derive(Debug, Clone, Copy)]
pub struct OperationEntry {
    /// Its `"op"`.
    pub name: &'static str,
    /// What it does, in a line (the editor's tooltip, `knotwork apply --help`'s list).
    pub summary: &'static str,
    /// Reads its JSON value (found at JSON path `path`).
    pub read: fn(path: &str, value: serde_json::Value) -> Result<Operation, FormatError>,
    /// The operation with its default parameters on the selected objects, where it applies to
    /// them: what the editor's Operations panel offers as a button.
    pub on_selection: fn(scene: &Scene, selection: &[usize]) -> Option<Operation>,
    /// Whether the editor has a panel of its own for it (the surface tools' Offset), so that
    /// the generic Operations panel leaves it out.
    pub own_panel: bool,
}

/// The entry of operation type `T`.
pub const fn entry<T: OperationParams>(
    summary: &'static str,
    on_selection: fn(&Scene, &[usize]) -> Option<Operation>,
) -> OperationEntry {
    OperationEntry {
        name: T::NAME,
        summary,
        read: read_params::<T>,
        on_selection,
        own_panel: false,
    }
}

/// Reads operation `T`'s value (its `"op"` already checked or absent).
fn read_params<T: OperationParams>(
    path: &str,
    mut value: serde_json::Value,
) -> Result<Operation, FormatError> {
    if let serde_json::Value::Object(map) = &mut value {
        map.remove("op");
    }
    let params: T = super::record::deserialize(path, value)?;
    Ok(Operation::new(params))
}

/// Why [`register`] refused an operation.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("an operation named \"{0}\" is registered already")]
pub struct OperationTaken(pub &'static str);

/// Operations registered while the program runs.
static REGISTERED: RwLock<Vec<OperationEntry>> = RwLock::new(Vec::new());

/// Adds an operation; refused when one of the same name is among `taken` (the built-in ones)
/// or registered already.
pub fn register(entry: OperationEntry, taken: &[OperationEntry]) -> Result<(), OperationTaken> {
    let mut registered = REGISTERED.write().unwrap_or_else(PoisonError::into_inner);
    if taken
        .iter()
        .chain(registered.iter())
        .any(|e| e.name == entry.name)
    {
        return Err(OperationTaken(entry.name));
    }
    registered.push(entry);
    Ok(())
}

/// The operations registered while the program runs, in the order they came.
pub fn registered() -> Vec<OperationEntry> {
    REGISTERED
        .read()
        .unwrap_or_else(PoisonError::into_inner)
        .clone()
}
