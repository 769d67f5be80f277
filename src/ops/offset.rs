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

    /// The report: `{"exact", "deviation", "fold_samples", "folds": [{"point", "uv",
    /// "radius"}], "summary"}` (how each face was offset and where it folds).
    fn plan_with_report(
        &self,
        scene: &Scene,
    ) -> Result<(Planned, Option<serde_json::Value>), EditError> {
        let distance = super::finite(Self::NAME, "distance", self.distance, false)?;
        let tolerance = super::finite(Self::NAME, "tolerance", self.tolerance, true)?;
        let (planned, offsets) =
            surface_ops::offset(scene, scene.resolve(self.object)?, distance, tolerance)?;
        let folds: Vec<_> = offsets
            .iter()
            .flat_map(|o| &o.folds)
            .map(|f| {
                serde_json::json!({
                    "point": f.point.to_array(),
                    "uv": f.uv.to_array(),
                    "radius": f.radius,
                })
            })
            .collect();
        let report = serde_json::json!({
            "exact": offsets.iter().all(|o| o.is_exact()),
            "deviation": offsets.iter().map(|o| o.deviation).fold(0.0, f64::max),
            "fold_samples": offsets.iter().map(|o| o.fold_samples).sum::<usize>(),
            "folds": folds,
            "summary": surface_ops::offset_summary(&offsets, distance),
        });
        Ok((planned, Some(report)))
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
