//! Match: an edge of a NURBS or trimmed object moved onto another object's edge at G0, G1 or
//! G2 by resetting the control rows next to it ([`crate::doc::surface_ops::match_object`]).
//! (The module is `matching` because `match` is a keyword; the operation is "match".)

use crate::doc::EditError;
use crate::doc::surface_ops::{self, MatchRequest};
use crate::scene::Scene;
use crate::scene::operation::{ObjectRef, OperationEntry, OperationParams, Planned, entry};

impl OperationParams for MatchRequest {
    const NAME: &'static str = "match";

    fn objects_mut(&mut self) -> Vec<&mut ObjectRef> {
        vec![&mut self.object, &mut self.target]
    }

    fn plan(&self, scene: &Scene) -> Result<Planned, EditError> {
        super::finite(Self::NAME, "tolerance", self.tolerance, true)?;
        surface_ops::match_edge(scene, self)
    }
}

pub const ENTRY: OperationEntry = OperationEntry {
    own_panel: true,
    ..entry::<MatchRequest>(
        "an object's edge moved onto another's at G0, G1 or G2",
        |_, _| None,
    )
};
