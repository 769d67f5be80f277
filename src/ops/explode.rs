//! Explode: a polysurface's faces as objects of their own, the first in its place.

use serde::{Deserialize, Serialize};

use crate::doc::EditError;
use crate::doc::surface_ops;
use crate::scene::Scene;
use crate::scene::operation::{
    ObjectRef, Operation, OperationEntry, OperationParams, Planned, entry,
};

/// `{"op": "explode", "object": k}`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Explode {
    pub object: ObjectRef,
}

impl OperationParams for Explode {
    const NAME: &'static str = "explode";

    fn objects_mut(&mut self) -> Vec<&mut ObjectRef> {
        vec![&mut self.object]
    }

    fn plan(&self, scene: &Scene) -> Result<Planned, EditError> {
        surface_ops::explode(scene, scene.resolve(self.object)?)
    }
}

pub const ENTRY: OperationEntry = OperationEntry {
    own_panel: true,
    ..entry::<Explode>(
        "a polysurface's faces as objects of their own",
        |scene, selection| match selection {
            [k] if *k < scene.objects.len() => Some(Operation::new(Explode {
                object: (*k).into(),
            })),
            _ => None,
        },
    )
};
