//! Join: objects whose faces share edges (within the tolerance, a fraction of the scene's
//! size) joined into polysurfaces ([`crate::doc::surface_ops::join_objects`]).

use serde::{Deserialize, Serialize};

use crate::doc::EditError;
use crate::doc::surface_ops;
use crate::scene::Scene;
use crate::scene::operation::{
    ObjectRef, Operation, OperationEntry, OperationParams, Planned, entry,
};

use super::resolve_all;

/// `{"op": "join", "objects": [i, j, ...], "tolerance": t}`: every surface when `objects` is
/// empty; `tolerance` defaults to [`surface_ops::JOIN_TOLERANCE`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Join {
    #[serde(default)]
    pub objects: Vec<ObjectRef>,
    #[serde(default = "default_tolerance")]
    pub tolerance: f64,
}

fn default_tolerance() -> f64 {
    surface_ops::JOIN_TOLERANCE
}

impl OperationParams for Join {
    const NAME: &'static str = "join";

    fn objects_mut(&mut self) -> Vec<&mut ObjectRef> {
        self.objects.iter_mut().collect()
    }

    fn plan(&self, scene: &Scene) -> Result<Planned, EditError> {
        let tolerance = super::finite(Self::NAME, "tolerance", self.tolerance, true)?;
        let objects = resolve_all(scene, &self.objects)?;
        surface_ops::join(scene, &objects, tolerance)
    }
}

pub const ENTRY: OperationEntry = OperationEntry {
    own_panel: true,
    ..entry::<Join>(
        "objects whose faces share edges joined into polysurfaces",
        |scene, selection| {
            (selection.len() >= 2 && selection.iter().all(|k| *k < scene.objects.len())).then(
                || {
                    Operation::new(Join {
                        objects: selection.iter().map(|&k| k.into()).collect(),
                        tolerance: surface_ops::JOIN_TOLERANCE,
                    })
                },
            )
        },
    )
};
