//! Split: an object split into the parts surfaces or curves on it cut it into
//! ([`crate::doc::surface_ops::cuts_on`]).

use serde::{Deserialize, Serialize};

use crate::doc::EditError;
use crate::doc::surface_ops;
use crate::scene::Scene;
use crate::scene::operation::{
    ObjectRef, Operation, OperationEntry, OperationParams, Planned, entry,
};

use super::resolve_all;

/// `{"op": "split", "object": k, "cutters": [i, ...]}`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Split {
    pub object: ObjectRef,
    pub cutters: Vec<ObjectRef>,
}

impl OperationParams for Split {
    const NAME: &'static str = "split";

    fn objects_mut(&mut self) -> Vec<&mut ObjectRef> {
        std::iter::once(&mut self.object)
            .chain(self.cutters.iter_mut())
            .collect()
    }

    fn plan(&self, scene: &Scene) -> Result<Planned, EditError> {
        let cutters = resolve_all(scene, &self.cutters)?;
        surface_ops::split_by(scene, scene.resolve(self.object)?, &cutters)
    }
}

pub const ENTRY: OperationEntry = OperationEntry {
    own_panel: true,
    ..entry::<Split>(
        "an object split into the parts surfaces or curves on it cut it into",
        |scene, selection| match selection {
            [k, cutters @ ..]
                if !cutters.is_empty() && selection.iter().all(|j| *j < scene.objects.len()) =>
            {
                Some(Operation::new(Split {
                    object: (*k).into(),
                    cutters: cutters.iter().map(|&j| j.into()).collect(),
                }))
            }
            _ => None,
        },
    )
};
