//! Cage tools: a subdivision surface's cage edited by one of Blender's edit-mode tools
//! ([`crate::kernel::subdiv::cage_edit`]), its rules, level, display, creases and corners kept.

use serde::{Deserialize, Serialize};

use crate::doc::{EditError, geometry_error};
use crate::kernel::PolygonMesh;
use crate::kernel::subdiv::cage_edit::{Cage, Tool};
use crate::scene::SubdivObject;
use crate::scene::operation::{ObjectRef, OperationEntry, OperationParams, Planned, entry};
use crate::scene::{ObjectGeometry, Scene, SceneObject};

/// `{"op": "cage", "object": k, "tool": {"extrude": {"faces": [0, 1], "offset": 0.5}}}`; the
/// tools are `extrude`, `inset` (`individual`), `loop-cut` (`edge`: [a, b], `cuts`, `slide`
/// −1 to 1), `bevel` (`edges`: [[a, b], …], `width`, `segments`), `bridge` (`loop1`, `loop2`), `merge`
/// (`vertices`, `at_first`), `dissolve` (`edges`), `delete` and `poke` (`faces`), and `mirror` (`axis`
/// 0 to 2, `merge_distance`), with faces and vertices by their index in the cage.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CageEdit {
    pub object: ObjectRef,
    pub tool: Tool,
}

impl OperationParams for CageEdit {
    const NAME: &'static str = "cage";

    fn objects_mut(&mut self) -> Vec<&mut ObjectRef> {
        vec![&mut self.object]
    }

    fn label(&self) -> String {
        self.tool.label().to_string()
    }

    fn plan(&self, scene: &Scene) -> Result<Planned, EditError> {
        let k = scene.resolve(self.object)?;
        let object = &scene.objects[k];
        let Some(subdiv) = object.geometry.as_subdivision() else {
            return Err(EditError::BadParameter {
                operation: Self::NAME,
                field: "object",
                message: format!("{:?} is not a subdivision surface", object.name),
            });
        };
        let edited = Cage::of_surface(&subdiv.surface)
            .apply(&self.tool)
            .map_err(|e| EditError::BadParameter {
                operation: Self::NAME,
                field: "tool",
                message: e.to_string(),
            })?;
        let mesh =
            PolygonMesh::new(edited.points, &edited.faces).map_err(geometry_error(object))?;
        let mut settings = subdiv.settings();
        settings.creases = edited.creases;
        settings.corners = edited.corners;
        // The faces the tool left alone keep their limit stencils.
        let geometry = SubdivObject::with_settings(&mesh, &settings)
            .map_err(geometry_error(object))?
            .reusing_stencils_of(subdiv);
        let after = SceneObject {
            geometry: ObjectGeometry::new(geometry),
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
    ..entry::<CageEdit>(
        "a subdivision cage edited: extrude, inset, loop cut, bevel, bridge, merge, dissolve, delete, poke or mirror",
        |_, _| None,
    )
};
