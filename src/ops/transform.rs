//! Transform: an object (and its lattice, which carries the deformation along) mapped by an
//! affine transformation, baked into its control points.

use glam::{DAffine3, DMat3, DVec3};
use serde::{Deserialize, Serialize};

use crate::doc::{EditError, geometry_error};
use crate::scene::operation::{ObjectRef, OperationEntry, OperationParams, Planned, entry};
use crate::scene::{Scene, SceneObject};

/// `{"op": "transform", "object": k, "matrix": [[a, b, c], [d, e, f], [g, h, i]],
/// "translation": [x, y, z]}`: p ↦ M p + t, M given by its rows.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Transform {
    pub object: ObjectRef,
    pub matrix: [[f64; 3]; 3],
    #[serde(default)]
    pub translation: [f64; 3],
}

impl Transform {
    /// Object `object` mapped by `transform`.
    pub fn new(object: impl Into<ObjectRef>, transform: &DAffine3) -> Self {
        let m = transform.matrix3.transpose();
        Self {
            object: object.into(),
            matrix: [
                m.x_axis.to_array(),
                m.y_axis.to_array(),
                m.z_axis.to_array(),
            ],
            translation: transform.translation.to_array(),
        }
    }

    /// The affine map it applies.
    pub fn affine(&self) -> DAffine3 {
        let rows = self.matrix.map(DVec3::from_array);
        DAffine3 {
            matrix3: DMat3::from_cols(rows[0], rows[1], rows[2]).transpose(),
            translation: DVec3::from_array(self.translation),
        }
    }
}

impl OperationParams for Transform {
    const NAME: &'static str = "transform";

    fn objects_mut(&mut self) -> Vec<&mut ObjectRef> {
        vec![&mut self.object]
    }

    fn plan(&self, scene: &Scene) -> Result<Planned, EditError> {
        let bad = |field: &'static str| EditError::BadParameter {
            operation: Self::NAME,
            field,
            message: "must hold finite numbers only".into(),
        };
        if !self.matrix.iter().flatten().all(|x| x.is_finite()) {
            return Err(bad("matrix"));
        }
        if !self.translation.iter().all(|x| x.is_finite()) {
            return Err(bad("translation"));
        }
        let transform = self.affine();
        let k = scene.resolve(self.object)?;
        let object = &scene.objects[k];
        let geometry = object
            .kind()
            .transformed(&transform)
            .map_err(geometry_error(object))?;
        let lattice = object
            .lattice
            .as_ref()
            .map(|l| l.transformed(&transform))
            .transpose()
            .map_err(geometry_error(object))?;
        let after = SceneObject {
            geometry,
            lattice,
            ..object.clone()
        };
        Ok(super::replace_object(
            k,
            object,
            after,
            OperationParams::label(self),
        ))
    }
}

pub const ENTRY: OperationEntry = OperationEntry {
    own_panel: true,
    ..entry::<Transform>("the object moved, turned or scaled", |_, _| None)
};
