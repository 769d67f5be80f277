//! Offset: the offset of an object's faces at a signed distance along the normal, added as
//! "NAME offset" (exact for planes, spheres, cylinders, cones, tori and other revolutions of
//! lines and arcs, fitted within the tolerance elsewhere;
//! [`crate::doc::surface_ops::offset_geometry`]). With history it follows its surface.

use serde::{Deserialize, Serialize};

use crate::doc::EditError;
use crate::doc::surface_ops::{self, EDITOR_TOLERANCE};
use crate::scene::Scene;
use crate::scene::operation::{Operation, OperationEntry, OperationParams, Planned, entry};

/// `{"op": "offset", "object": k, "distance": d, "tolerance": t}` (`tolerance` a fraction of
/// the scene's size, 1e-4 by default).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Offset {
    pub object: crate::scene::operation::ObjectRef,
    pub distance: f64,
    #[serde(default = "default_tolerance")]
    pub tolerance: f64,
}

fn default_tolerance() -> f64 {
    EDITOR_TOLERANCE
}

impl OperationParams for Offset {
    const NAME: &'static str = "offset";

    fn objects_mut(&mut self) -> Vec<&mut crate::scene::operation::ObjectRef> {
        vec![&mut self.object]
    }

    fn plan(&self, scene: &Scene) -> Result<Planned, EditError> {
        let distance = super::finite(Self::NAME, "distance", self.distance, false)?;
        let tolerance = super::finite(Self::NAME, "tolerance", self.tolerance, true)?;
        surface_ops::offset(scene, scene.resolve(self.object)?, distance, tolerance)
    }
}

pub const ENTRY: OperationEntry = OperationEntry {
    own_panel: true,
    ..entry::<Offset>(
        "the offset of the object's faces along the normal",
        |scene, selection| match selection {
            [k] if !scene.objects.get(*k)?.kind().faces().is_empty() => {
                Some(Operation::new(Offset {
                    object: (*k).into(),
                    distance: 0.1 * surface_ops::scene_size(scene),
                    tolerance: EDITOR_TOLERANCE,
                }))
            }
            _ => None,
        },
    )
};
