//! Contour: the sections of an object by parallel planes through `origin + k · spacing ·
//! normal`, added as curve objects "NAME contour" ([`crate::doc::surface_ops::contour_curves`]).
//! With history they follow the object.

use glam::DVec3;
use serde::{Deserialize, Serialize};

use crate::doc::EditError;
use crate::doc::surface_ops;
use crate::scene::Scene;
use crate::scene::operation::{
    ObjectRef, Operation, OperationEntry, OperationParams, Planned, entry,
};

/// `{"op": "contour", "object": k, "origin": [x, y, z], "normal": [x, y, z], "spacing": s}`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Contour {
    pub object: ObjectRef,
    pub origin: [f64; 3],
    pub normal: [f64; 3],
    pub spacing: f64,
}

impl OperationParams for Contour {
    const NAME: &'static str = "contour";

    fn objects_mut(&mut self) -> Vec<&mut ObjectRef> {
        vec![&mut self.object]
    }

    fn plan(&self, scene: &Scene) -> Result<Planned, EditError> {
        let spacing = super::finite(Self::NAME, "spacing", self.spacing, true)?;
        surface_ops::contour(
            scene,
            scene.resolve(self.object)?,
            DVec3::from_array(self.origin),
            DVec3::from_array(self.normal),
            spacing,
        )
    }
}

pub const ENTRY: OperationEntry = OperationEntry {
    own_panel: true,
    ..entry::<Contour>(
        "sections of the object by parallel planes (along z, a tenth of the scene's size apart)",
        |scene, selection| match selection {
            [k] if !scene.objects.get(*k)?.kind().faces().is_empty() => {
                Some(Operation::new(Contour {
                    object: (*k).into(),
                    origin: [0.0; 3],
                    normal: [0.0, 0.0, 1.0],
                    spacing: 0.1 * surface_ops::scene_size(scene),
                }))
            }
            _ => None,
        },
    )
};
