//! Project: curves projected onto a surface along a direction, or pulled to its nearest points,
//! added as curve objects ([`crate::doc::surface_ops::projected_curves`]). With history they
//! follow the curves and the surface.

use serde::{Deserialize, Serialize};

use crate::doc::EditError;
use crate::doc::surface_ops;
use crate::scene::Scene;
use crate::scene::operation::{ObjectRef, OperationEntry, OperationParams, Planned, entry};

use super::resolve_all;

/// `{"op": "project", "curves": [i, ...], "onto": k, "direction": [x, y, z]}`; without
/// `direction` (or with `null`) the curves are pulled.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProjectCurves {
    pub curves: Vec<ObjectRef>,
    pub onto: ObjectRef,
    #[serde(default)]
    pub direction: Option<[f64; 3]>,
}

impl OperationParams for ProjectCurves {
    const NAME: &'static str = "project";

    fn objects_mut(&mut self) -> Vec<&mut ObjectRef> {
        self.curves
            .iter_mut()
            .chain(std::iter::once(&mut self.onto))
            .collect()
    }

    fn plan(&self, scene: &Scene) -> Result<Planned, EditError> {
        let curves = resolve_all(scene, &self.curves)?;
        surface_ops::project(
            scene,
            &curves,
            scene.resolve(self.onto)?,
            self.direction.map(glam::DVec3::from_array),
        )
    }
}

pub const ENTRY: OperationEntry = OperationEntry {
    own_panel: true,
    ..entry::<ProjectCurves>(
        "curves projected onto a surface along a direction, or pulled onto it",
        |_, _| None,
    )
};
