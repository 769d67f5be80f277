//! Intersect: the curves where two objects' surfaces meet, added as curve objects "A × B",
//! "A × B 2", … ([`crate::kernel::intersect`]). With history they follow both objects.

use serde::{Deserialize, Serialize};

use crate::doc::EditError;
use crate::scene::Scene;
use crate::scene::operation::{
    ObjectRef, Operation, OperationEntry, OperationParams, Planned, entry,
};

/// `{"op": "intersect", "a": i, "b": j}`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Intersect {
    pub a: ObjectRef,
    pub b: ObjectRef,
}

impl OperationParams for Intersect {
    const NAME: &'static str = "intersect";

    fn objects_mut(&mut self) -> Vec<&mut ObjectRef> {
        vec![&mut self.a, &mut self.b]
    }

    fn plan(&self, scene: &Scene) -> Result<Planned, EditError> {
        crate::doc::curve_edits::intersection_curves(
            scene,
            scene.resolve(self.a)?,
            scene.resolve(self.b)?,
        )
    }
}

pub const ENTRY: OperationEntry = OperationEntry {
    own_panel: true,
    ..entry::<Intersect>(
        "the curves where two objects' surfaces meet",
        |scene, selection| match selection {
            [a, b] if a != b && *a < scene.objects.len() && *b < scene.objects.len() => {
                Some(Operation::new(Intersect {
                    a: (*a).into(),
                    b: (*b).into(),
                }))
            }
            _ => None,
        },
    )
};
