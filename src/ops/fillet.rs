//! Fillet: a ball of a radius rolled between two objects; the fillet surface is added as
//! "fillet" and both objects are trimmed back to where the ball touches them
//! ([`crate::doc::surface_ops::fillet_objects`]).

use crate::doc::EditError;
use crate::doc::surface_ops::{self, FilletRequest};
use crate::scene::Scene;
use crate::scene::operation::{ObjectRef, OperationEntry, OperationParams, Planned, entry};

impl OperationParams for FilletRequest {
    const NAME: &'static str = "fillet";

    fn objects_mut(&mut self) -> Vec<&mut ObjectRef> {
        vec![&mut self.a, &mut self.b]
    }

    /// The report: `{"sections", "closed", "branches", "notes"}`.
    fn plan_with_report(
        &self,
        scene: &Scene,
    ) -> Result<(Planned, Option<serde_json::Value>), EditError> {
        super::finite(Self::NAME, "radius", self.radius, true)?;
        if let Some(end) = self.radius_end {
            super::finite(Self::NAME, "radius_end", end, true)?;
        }
        super::finite(Self::NAME, "tolerance", self.tolerance, true)?;
        let (planned, made) = surface_ops::fillet(scene, self)?;
        let report = serde_json::json!({
            "sections": made.fillet.centres.len(),
            "closed": made.fillet.closed,
            "branches": made.fillet.branches,
            "notes": made.notes,
        });
        Ok((planned, Some(report)))
    }
}

pub const ENTRY: OperationEntry = OperationEntry {
    own_panel: true,
    ..entry::<FilletRequest>(
        "a rolling-ball fillet between two objects, trimming both",
        |_, _| None,
    )
};
