//! Edge and face features of closed bodies: fillets (`fillet_edges`), chamfers
//! (`chamfer_edges`), shells (`shell`), faces moved (`offset_face`) and drafted
//! (`draft_face`), each a new polysurface, the body hidden
//! ([`crate::doc::surface_ops::solid_feature`] on [`crate::kernel::features`]). Each picks
//! edges (faces, for a shell) by points near them; with history the result follows the body,
//! and editing the value re-runs it in place ([`crate::doc::Command::EditRecipe`]).

use serde::{Deserialize, Serialize};

use crate::doc::EditError;
use crate::doc::surface_ops::{self, SolidFeature};
use crate::scene::Scene;
use crate::scene::operation::{
    ObjectRef, Operation, OperationEntry, OperationParams, Planned, entry,
};

/// The default tolerance: 1e-6 of the scene's size, as the boolean's.
pub const FEATURE_TOLERANCE: f64 = 1e-6;

fn default_tolerance() -> f64 {
    FEATURE_TOLERANCE
}

/// Points given as [x, y, z], checked finite.
fn points(
    operation: &'static str,
    field: &'static str,
    points: &[[f64; 3]],
) -> Result<Vec<glam::DVec3>, EditError> {
    points
        .iter()
        .map(|p| {
            let v = glam::DVec3::from_array(*p);
            if v.is_finite() {
                Ok(v)
            } else {
                Err(EditError::BadParameter {
                    operation,
                    field,
                    message: "a point is not finite".into(),
                })
            }
        })
        .collect()
}

/// The plan and report of one feature.
/// `picks`: the points that pick edges or faces, and a fillet's radii at points.
fn planned(
    scene: &Scene,
    object: ObjectRef,
    feature: SolidFeature,
    picks: (&[glam::DVec3], &[(glam::DVec3, f64)]),
    tolerance: f64,
) -> Result<(Planned, Option<serde_json::Value>), EditError> {
    let (plan, made) =
        surface_ops::solid_feature(scene, scene.resolve(object)?, feature, picks, tolerance)?;
    let report = serde_json::json!({
        "picked": made.picked,
        "faces": made.faces.len(),
        "volume": made.volume().ok(),
    });
    Ok((plan, Some(report)))
}

/// The selected closed body, if it is one.
fn closed_body(scene: &Scene, selection: &[usize]) -> Option<usize> {
    match selection {
        [k] if scene.objects.get(*k)?.body().is_some_and(|b| b.closed()) => Some(*k),
        _ => None,
    }
}

/// `{"op": "fillet_edges", "object": k, "radius": r, "near": [[x, y, z], ...],
/// "radius_at": [[x, y, z, r], ...], "tolerance": t}`: each point picks the edge nearest it;
/// none, every edge. Each `radius_at` sets the radius at the picked edges' end nearest its
/// point, the radius running linearly along each edge between its ends
/// ([`crate::kernel::features::round_edges_varying`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FilletEdges {
    pub object: ObjectRef,
    pub radius: f64,
    #[serde(default)]
    pub near: Vec<[f64; 3]>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub radius_at: Vec<[f64; 4]>,
    #[serde(default = "default_tolerance")]
    pub tolerance: f64,
}

impl OperationParams for FilletEdges {
    const NAME: &'static str = "fillet_edges";

    fn objects_mut(&mut self) -> Vec<&mut ObjectRef> {
        vec![&mut self.object]
    }

    /// The report: `{"picked", "faces", "volume"}`.
    fn plan_with_report(
        &self,
        scene: &Scene,
    ) -> Result<(Planned, Option<serde_json::Value>), EditError> {
        let radius = super::finite(Self::NAME, "radius", self.radius, true)?;
        let tolerance = super::finite(Self::NAME, "tolerance", self.tolerance, true)?;
        let near = points(Self::NAME, "near", &self.near)?;
        let at: Vec<[f64; 3]> = self.radius_at.iter().map(|a| [a[0], a[1], a[2]]).collect();
        let radii = points(Self::NAME, "radius_at", &at)?
            .into_iter()
            .zip(&self.radius_at)
            .map(|(p, a)| Ok((p, super::finite(Self::NAME, "radius_at", a[3], true)?)))
            .collect::<Result<Vec<_>, EditError>>()?;
        planned(
            scene,
            self.object,
            SolidFeature::Fillet { radius },
            (&near, &radii),
            tolerance,
        )
    }
}

/// `{"op": "chamfer_edges", "object": k, "distance": d, "other": d2, "near": [...],
/// "tolerance": t}`: `other` (the set-back on the edge's second face) is `distance` when left
/// out.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ChamferEdges {
    pub object: ObjectRef,
    pub distance: f64,
    #[serde(default)]
    pub other: Option<f64>,
    #[serde(default)]
    pub near: Vec<[f64; 3]>,
    #[serde(default = "default_tolerance")]
    pub tolerance: f64,
}

impl OperationParams for ChamferEdges {
    const NAME: &'static str = "chamfer_edges";

    fn objects_mut(&mut self) -> Vec<&mut ObjectRef> {
        vec![&mut self.object]
    }

    /// The report: `{"picked", "faces", "volume"}`.
    fn plan_with_report(
        &self,
        scene: &Scene,
    ) -> Result<(Planned, Option<serde_json::Value>), EditError> {
        let distance = super::finite(Self::NAME, "distance", self.distance, true)?;
        let other = super::finite(Self::NAME, "other", self.other.unwrap_or(distance), true)?;
        let tolerance = super::finite(Self::NAME, "tolerance", self.tolerance, true)?;
        let near = points(Self::NAME, "near", &self.near)?;
        planned(
            scene,
            self.object,
            SolidFeature::Chamfer { distance, other },
            (&near, &[]),
            tolerance,
        )
    }
}

/// `{"op": "shell", "object": k, "thickness": t, "open": [[x, y, z], ...], "tolerance": t}`:
/// below 0 the wall lies inside the body, above 0 outside; each point opens the face nearest
/// it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Shell {
    pub object: ObjectRef,
    pub thickness: f64,
    #[serde(default)]
    pub open: Vec<[f64; 3]>,
    #[serde(default = "default_tolerance")]
    pub tolerance: f64,
}

impl OperationParams for Shell {
    const NAME: &'static str = "shell";

    fn objects_mut(&mut self) -> Vec<&mut ObjectRef> {
        vec![&mut self.object]
    }

    /// The report: `{"picked", "faces", "volume"}`.
    fn plan_with_report(
        &self,
        scene: &Scene,
    ) -> Result<(Planned, Option<serde_json::Value>), EditError> {
        let thickness = super::finite(Self::NAME, "thickness", self.thickness, false)?;
        let tolerance = super::finite(Self::NAME, "tolerance", self.tolerance, true)?;
        let open = points(Self::NAME, "open", &self.open)?;
        planned(
            scene,
            self.object,
            SolidFeature::Shell { thickness },
            (&open, &[]),
            tolerance,
        )
    }
}

/// `{"op": "offset_face", "object": k, "faces": [[x, y, z], ...], "distance": d,
/// "tolerance": t}`: each point picks the face nearest it, moved `distance` along its outward
/// normal (in below 0), its neighbours extended or trimmed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OffsetFace {
    pub object: ObjectRef,
    pub faces: Vec<[f64; 3]>,
    pub distance: f64,
    #[serde(default = "default_tolerance")]
    pub tolerance: f64,
}

impl OperationParams for OffsetFace {
    const NAME: &'static str = "offset_face";

    fn objects_mut(&mut self) -> Vec<&mut ObjectRef> {
        vec![&mut self.object]
    }

    /// The report: `{"picked", "faces", "volume"}`.
    fn plan_with_report(
        &self,
        scene: &Scene,
    ) -> Result<(Planned, Option<serde_json::Value>), EditError> {
        let distance = super::finite(Self::NAME, "distance", self.distance, false)?;
        let tolerance = super::finite(Self::NAME, "tolerance", self.tolerance, true)?;
        let faces = points(Self::NAME, "faces", &self.faces)?;
        planned(
            scene,
            self.object,
            SolidFeature::OffsetFace { distance },
            (&faces, &[]),
            tolerance,
        )
    }
}

/// `{"op": "draft_face", "object": k, "faces": [[x, y, z], ...], "angle": degrees,
/// "neutral": [x, y, z], "pull": [x, y, z], "tolerance": t}`: each point picks the face
/// nearest it, tilted by `angle` about the line where it meets the neutral plane (through
/// `neutral`, across `pull`: the direction the part leaves its mould; [0, 0, 1] by default),
/// a positive angle narrowing the part along `pull`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DraftFace {
    pub object: ObjectRef,
    pub faces: Vec<[f64; 3]>,
    pub angle: f64,
    pub neutral: [f64; 3],
    #[serde(default = "up")]
    pub pull: [f64; 3],
    #[serde(default = "default_tolerance")]
    pub tolerance: f64,
}

fn up() -> [f64; 3] {
    [0.0, 0.0, 1.0]
}

impl OperationParams for DraftFace {
    const NAME: &'static str = "draft_face";

    fn objects_mut(&mut self) -> Vec<&mut ObjectRef> {
        vec![&mut self.object]
    }

    /// The report: `{"picked", "faces", "volume"}`.
    fn plan_with_report(
        &self,
        scene: &Scene,
    ) -> Result<(Planned, Option<serde_json::Value>), EditError> {
        let angle = super::finite(Self::NAME, "angle", self.angle, false)?;
        let tolerance = super::finite(Self::NAME, "tolerance", self.tolerance, true)?;
        let faces = points(Self::NAME, "faces", &self.faces)?;
        let frame = points(Self::NAME, "neutral", &[self.neutral, self.pull])?;
        planned(
            scene,
            self.object,
            SolidFeature::Draft {
                angle: angle.to_radians(),
                origin: frame[0],
                pull: frame[1],
            },
            (&faces, &[]),
            tolerance,
        )
    }
}

/// The default size of a feature on the selected body: a fiftieth of the scene's size.
fn default_size(scene: &Scene) -> f64 {
    0.02 * surface_ops::scene_size(scene)
}

pub const FILLET_ENTRY: OperationEntry = OperationEntry {
    own_panel: true,
    ..entry::<FilletEdges>(
        "rolling-ball fillets of a closed body's edges (each point picks the nearest edge)",
        |scene, selection| {
            Some(Operation::new(FilletEdges {
                object: closed_body(scene, selection)?.into(),
                radius: default_size(scene),
                near: Vec::new(),
                radius_at: Vec::new(),
                tolerance: FEATURE_TOLERANCE,
            }))
        },
    )
};

pub const CHAMFER_ENTRY: OperationEntry = OperationEntry {
    own_panel: true,
    ..entry::<ChamferEdges>(
        "chamfers of a closed body's edges (each point picks the nearest edge)",
        |scene, selection| {
            Some(Operation::new(ChamferEdges {
                object: closed_body(scene, selection)?.into(),
                distance: default_size(scene),
                other: None,
                near: Vec::new(),
                tolerance: FEATURE_TOLERANCE,
            }))
        },
    )
};

pub const SHELL_ENTRY: OperationEntry = OperationEntry {
    own_panel: true,
    ..entry::<Shell>(
        "a closed body hollowed to a wall thickness (each point opens the nearest face)",
        |scene, selection| {
            Some(Operation::new(Shell {
                object: closed_body(scene, selection)?.into(),
                thickness: -default_size(scene),
                open: Vec::new(),
                tolerance: FEATURE_TOLERANCE,
            }))
        },
    )
};

pub const OFFSET_FACE_ENTRY: OperationEntry = OperationEntry {
    own_panel: true,
    ..entry::<OffsetFace>(
        "faces of a closed body moved along their normals (each point picks the nearest face)",
        |_, _| None,
    )
};

pub const DRAFT_ENTRY: OperationEntry = OperationEntry {
    own_panel: true,
    ..entry::<DraftFace>(
        "faces of a closed body tilted about a neutral plane (each point picks the nearest face)",
        |_, _| None,
    )
};
