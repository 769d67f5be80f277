//! Trim: an object trimmed by surfaces or curves on it, keeping the part around the surface
//! point nearest `keep` ([`crate::doc::surface_ops::cuts_on`]).

use serde::{Deserialize, Serialize};

use crate::doc::EditError;
use crate::doc::surface_ops;
use crate::scene::Scene;
use crate::scene::operation::{ObjectRef, OperationEntry, OperationParams, Planned, entry};

use super::resolve_all;

/// `{"op": "trim", "object": k, "cutters": [i, ...], "keep": [x, y, z]}`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Trim {
    pub object: ObjectRef,
    pub cutters: Vec<ObjectRef>,
    pub keep: [f64; 3],
}

impl OperationParams for Trim {
    const NAME: &'static str = "trim";

    fn objects_mut(&mut self) -> Vec<&mut ObjectRef> {
        std::iter::once(&mut self.object)
            .chain(self.cutters.iter_mut())
            .collect()
    }

    fn plan(&self, scene: &Scene) -> Result<Planned, EditError> {
        let keep = glam::DVec3::from_array(self.keep);
        if !keep.is_finite() {
            return Err(EditError::BadParameter {
                operation: Self::NAME,
                field: "keep",
                message: format!("must be three finite numbers (got {keep})"),
            });
        }
        let cutters = resolve_all(scene, &self.cutters)?;
        surface_ops::trim_by(scene, scene.resolve(self.object)?, &cutters, keep)
    }
}

pub const ENTRY: OperationEntry = OperationEntry {
    own_panel: true,
    ..entry::<Trim>("an object trimmed by surfaces or curves on it", |_, _| None)
};
