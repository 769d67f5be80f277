//! Blend: a surface across the gap between an edge of one object and an edge of another, G0,
//! G1 or G2 to both, added as "blend" ([`crate::doc::surface_ops::blend_objects`]).

use crate::doc::EditError;
use crate::doc::surface_ops::{self, BlendRequest};
use crate::scene::Scene;
use crate::scene::operation::{ObjectRef, OperationEntry, OperationParams, Planned, entry};

impl OperationParams for BlendRequest {
    const NAME: &'static str = "blend";

    fn objects_mut(&mut self) -> Vec<&mut ObjectRef> {
        vec![&mut self.a, &mut self.b]
    }

    fn plan(&self, scene: &Scene) -> Result<Planned, EditError> {
        for t in self.tension {
            super::finite(Self::NAME, "tension", t, true)?;
        }
        super::finite(Self::NAME, "tolerance", self.tolerance, true)?;
        surface_ops::blend(scene, self)
    }
}

pub const ENTRY: OperationEntry = OperationEntry {
    own_panel: true,
    ..entry::<BlendRequest>(
        "a surface across the gap between two objects' edges",
        |_, _| None,
    )
};
