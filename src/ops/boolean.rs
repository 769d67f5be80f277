//! Boolean: union, difference or intersection of closed bodies, as one new polysurface, the
//! inputs hidden ([`crate::doc::surface_ops::boolean`] on [`crate::kernel::boolean`]); or a
//! split of closed bodies by surfaces into closed pieces, the body hidden
//! ([`crate::doc::surface_ops::split_solid`]). With history the result follows its inputs:
//! moving a body or dragging a control point of one re-runs it.

use serde::{Deserialize, Serialize};

use crate::doc::EditError;
use crate::doc::surface_ops;
use crate::kernel::boolean::BooleanOp;
use crate::scene::Scene;
use crate::scene::operation::{
    ObjectRef, Operation, OperationEntry, OperationParams, Planned, entry,
};

use super::resolve_all;

/// Which boolean (`"union"`, `"difference"`: a minus b, `"intersection"`, `"split"`: a cut
/// by the surfaces of b into closed pieces).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Kind {
    Union,
    Difference,
    Intersection,
    Split,
}

impl Kind {
    /// The kernel's boolean, for all but a split.
    pub fn boolean_op(self) -> Option<BooleanOp> {
        match self {
            Kind::Union => Some(BooleanOp::Union),
            Kind::Difference => Some(BooleanOp::Difference),
            Kind::Intersection => Some(BooleanOp::Intersection),
            Kind::Split => None,
        }
    }
}

/// `{"op": "boolean", "operation": "difference", "a": [i], "b": [j, ...], "tolerance": t}`:
/// the bodies of `a` combined with those of `b` (tools that do not overlap one another), or
/// for `"split"` cut by the faces of `b` (surfaces reaching through them);
/// `tolerance` a fraction of the scene's size, 1e-6 by default.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Boolean {
    pub operation: Kind,
    pub a: Vec<ObjectRef>,
    pub b: Vec<ObjectRef>,
    #[serde(default = "default_tolerance")]
    pub tolerance: f64,
}

/// The default tolerance: 1e-6 of the scene's size.
pub const BOOLEAN_TOLERANCE: f64 = 1e-6;

fn default_tolerance() -> f64 {
    BOOLEAN_TOLERANCE
}

impl OperationParams for Boolean {
    const NAME: &'static str = "boolean";

    fn objects_mut(&mut self) -> Vec<&mut ObjectRef> {
        self.a.iter_mut().chain(self.b.iter_mut()).collect()
    }

    fn plan(&self, scene: &Scene) -> Result<Planned, EditError> {
        let tolerance = super::finite(Self::NAME, "tolerance", self.tolerance, true)?;
        let a = resolve_all(scene, &self.a)?;
        let b = resolve_all(scene, &self.b)?;
        match self.operation.boolean_op() {
            Some(op) => surface_ops::boolean(scene, op, &a, &b, tolerance),
            None => surface_ops::split_solid(scene, &a, &b, tolerance),
        }
    }
}

impl Boolean {
    /// The union, difference or intersection ready to run a step at a time (the editor's long
    /// booleans; [`surface_ops::PreparedBoolean`]); `None` for a split, which runs at once.
    pub fn prepare(
        &self,
        scene: &Scene,
    ) -> Result<Option<surface_ops::PreparedBoolean>, EditError> {
        let Some(op) = self.operation.boolean_op() else {
            return Ok(None);
        };
        let tolerance = super::finite(Self::NAME, "tolerance", self.tolerance, true)?;
        let a = resolve_all(scene, &self.a)?;
        let b = resolve_all(scene, &self.b)?;
        surface_ops::prepare_boolean(scene, op, &a, &b, tolerance).map(Some)
    }
}

/// The operation for a selection: the first object against the rest (each with faces); the
/// editor's Union, Difference, Intersection and Split buttons.
pub fn offered(scene: &Scene, selection: &[usize], kind: Kind) -> Option<Operation> {
    params(scene, selection, kind).map(Operation::new)
}

/// [`offered`]'s parameters.
pub fn params(scene: &Scene, selection: &[usize], kind: Kind) -> Option<Boolean> {
    match selection {
        [first, rest @ ..]
            if !rest.is_empty()
                && selection
                    .iter()
                    .all(|&k| scene.objects.get(k).is_some_and(|o| !o.faces().is_empty())) =>
        {
            Some(Boolean {
                operation: kind,
                a: vec![(*first).into()],
                b: rest.iter().map(|&k| k.into()).collect(),
                tolerance: BOOLEAN_TOLERANCE,
            })
        }
        _ => None,
    }
}

pub const ENTRY: OperationEntry = OperationEntry {
    own_panel: true,
    ..entry::<Boolean>(
        "union, difference or intersection of closed bodies: the first selected against the rest",
        |scene, selection| offered(scene, selection, Kind::Difference),
    )
};
