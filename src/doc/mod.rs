//! Editing the document: every change the user makes is a [`Command`] applied to the
//! [`Scene`]; applying it yields an [`Edit`] that records the objects before and after, so the
//! [`History`] can undo and redo it exactly. A command that fails changes nothing.
//!
//! Kernel data only: no GPU, no UI. The editor turns picks and drags into commands and
//! re-uploads the objects an edit touched ([`Edit::touched`]).

pub mod construction;
pub mod create;
pub(crate) mod curve_edits;
pub mod document;
pub mod drag;
pub mod history;
mod parts;
mod plan;
pub mod surface_ops;

use glam::DVec3;

use crate::kernel::{Direction, GeometryError, TrimLoop, TrimmedSurface};
use crate::scene::{LengthUnit, Scene, SceneObject};

pub use crate::scene::change::{Change, EditError, MAX_COORDINATE, PointsMoved, Touched};
pub use document::Document;
pub use drag::PointDrag;
pub use history::History;

/// One change to the document, as the user asked for it.
#[derive(Debug, Clone, PartialEq)]
pub enum Command {
    /// Moves control points (indices of [`SceneObject::control_points`]) to new positions.
    MovePoints {
        object: usize,
        moves: Vec<(usize, DVec3)>,
    },
    /// Sets the weight of control points (a rational surface results).
    SetWeight {
        object: usize,
        points: Vec<usize>,
        weight: f64,
    },
    /// Inserts the knot `value` once (The NURBS Book A5.3): the shape does not change.
    InsertKnot {
        object: usize,
        direction: Direction,
        value: f64,
    },
    /// Removes the interior knot `value` once if the surface stays within `tolerance` (A5.8).
    RemoveKnot {
        object: usize,
        direction: Direction,
        value: f64,
        tolerance: f64,
    },
    /// Raises the degree by one (A5.10): the shape does not change.
    ElevateDegree {
        object: usize,
        direction: Direction,
    },
    /// Splits the surface at the isoparametric curve `direction` = `value` into two objects.
    Split {
        object: usize,
        direction: Direction,
        value: f64,
    },
    /// Reverses a parameter direction (the normal flips).
    Reverse {
        object: usize,
        direction: Direction,
    },
    /// Exchanges u and v (the normal flips).
    SwapUv {
        object: usize,
    },
    /// Replaces a knot vector (same length, validated by the kernel); the control points stay.
    SetKnots {
        object: usize,
        direction: Direction,
        knots: Vec<f64>,
    },
    /// Adds an object at the end of the scene.
    Add {
        object: SceneObject,
    },
    /// Replaces every object by `scene`'s (New, Open): one undo step, so the document before
    /// comes back with Undo. `label` names it ("open part.json"); `name` is what the new
    /// document is called ("part.json", "sample scene"), which its [`Edit`] keeps.
    ReplaceScene {
        scene: Scene,
        label: String,
        name: String,
    },
    /// Adds a copy of an object right after it.
    Duplicate {
        object: usize,
    },
    Delete {
        object: usize,
    },
    Rename {
        object: usize,
        name: String,
    },
    SetVisible {
        object: usize,
        visible: bool,
    },
    /// Gives the object its own colour (sRGB, each component 0 to 1), or the editor's grey.
    SetColor {
        object: usize,
        color: Option<[f32; 3]>,
    },
    /// Declares the unit the document's coordinates are in (the numbers stay as they are).
    SetUnit {
        unit: Option<LengthUnit>,
    },
    /// Segments per Bézier span edge of one object's tessellation.
    SetSegments {
        object: usize,
        segments: u32,
    },
    /// The same segments per span for every object (one undo step).
    SetAllSegments {
        segments: u32,
    },
    /// Turns a polygon mesh into a subdivision surface, or sets a subdivision surface's rules,
    /// level, display, creases and corners (a cage the rules refuse changes nothing).
    SetSubdivision {
        object: usize,
        settings: crate::scene::SubdivSettings,
    },
    /// Sets (or with `None` removes) an object's displacement along the normal; refused for
    /// kinds without a (u, v) domain (polygon meshes, subdivision surfaces).
    SetDisplacement {
        object: usize,
        displacement: Option<crate::kernel::displace::Displacement>,
    },
    /// Puts one free-form deformation lattice around objects (they share it: a move of its
    /// points moves every copy), replaces their lattice, or with `None` releases it (they are
    /// shown undeformed again).
    SetLattice {
        objects: Vec<usize>,
        lattice: Option<crate::kernel::ffd::Lattice>,
    },
    /// Bakes the lattice of an object, and of the objects sharing it, into their geometry
    /// ([`SceneObject::baked_lattice`]; `tolerance` a fraction of each object's box diagonal
    /// for a refit). The undo step's label says whether each result is exact or refitted.
    ApplyLattice {
        object: usize,
        tolerance: f64,
    },
    /// Changes the trim loops of a NURBS surface (an edit that would make a loop invalid is
    /// refused with the reason and changes nothing).
    Trim {
        object: usize,
        edit: TrimEdit,
    },
    /// Ends an object's construction history: it keeps its shape and no longer follows its
    /// curves.
    BreakHistory {
        object: usize,
    },
    /// An edit of a curve object that no construct request makes.
    EditCurve {
        object: usize,
        edit: CurveEdit,
    },
    /// Runs an operation ([`crate::scene::operation`]): the road every operation takes. With
    /// `keep_history`, each object it adds keeps the operation ([`crate::scene::operation::Recipe`])
    /// and is made again when an object it reads changes.
    Apply {
        operation: crate::scene::operation::Operation,
        keep_history: bool,
    },
    /// Changes the operation an object with history was made by (a fillet's radius, a
    /// shell's thickness: the same operation with other values) and makes the object again,
    /// with what follows it, as one undo step.
    EditRecipe {
        object: usize,
        operation: crate::scene::operation::Operation,
    },
}

/// An edit of a curve object ([`Command::EditCurve`]).
#[derive(Debug, Clone, PartialEq)]
pub enum CurveEdit {
    /// Moves the last control point onto the first, closing an open curve (Rhino's CloseCrv).
    Close,
    /// A periodic (closed, smooth) curve as a clamped one with its seam at the domain's start:
    /// the same shape, whose ends can then move apart.
    Open,
    /// Removes control point `point` (at least degree + 1 stay): the knots are spaced again
    /// evenly, clamped at the ends.
    RemovePoint { point: usize },
    /// Appends curve object `other` (the nearer of its ends to this curve's end first), which
    /// is removed; the ends must meet within 1e-6 of the curves' size.
    Join { other: usize },
}

/// One change to a surface's trim loops.
#[derive(Debug, Clone, PartialEq)]
pub enum TrimEdit {
    /// Adds a loop: a hole (on an untrimmed surface the domain's boundary becomes the outer
    /// loop), or with `keep_inside` on an untrimmed surface the only region kept.
    Add { curves: TrimLoop, keep_inside: bool },
    /// Removes loop `trim_loop`.
    Delete { trim_loop: usize },
    /// Keeps the other side.
    Invert,
    /// Replaces every loop (none: untrimmed).
    Replace { loops: Vec<TrimLoop> },
    /// Moves control point `point` of curve `curve` of loop `trim_loop` to (u, v).
    MovePoint {
        trim_loop: usize,
        curve: usize,
        point: usize,
        to: glam::DVec2,
    },
    /// Adds a control point to a curve without changing its shape (knot insertion).
    InsertPoint { trim_loop: usize, curve: usize },
    /// Removes an interior control point of a curve.
    DeletePoint {
        trim_loop: usize,
        curve: usize,
        point: usize,
    },
}

impl TrimEdit {
    fn label(&self) -> String {
        match self {
            TrimEdit::Add { keep_inside, .. } => (if *keep_inside {
                "trim to loop"
            } else {
                "add trim hole"
            })
            .into(),
            TrimEdit::Delete { trim_loop } => format!("delete trim loop {trim_loop}"),
            TrimEdit::Invert => "invert trim".into(),
            TrimEdit::Replace { .. } => "set trim loops".into(),
            TrimEdit::MovePoint { .. } => "move trim point".into(),
            TrimEdit::InsertPoint { .. } => "insert trim point".into(),
            TrimEdit::DeletePoint { .. } => "delete trim point".into(),
        }
    }

    /// The trimmed surface after this edit.
    pub fn apply(&self, t: &TrimmedSurface) -> Result<TrimmedSurface, GeometryError> {
        use crate::kernel::trim::shapes;
        let loop_of = |l: usize| {
            t.loops().get(l).ok_or_else(|| GeometryError::Construction {
                what: "trim",
                message: format!("there is no loop {l} (the surface has {})", t.loops().len()),
            })
        };
        let replace = |l: usize, new: TrimLoop| {
            let mut loops = t.loops().to_vec();
            loops[l] = new;
            t.with_loops(loops)
        };
        match self {
            TrimEdit::Add {
                curves,
                keep_inside,
            } => t.add_loop(curves.clone(), *keep_inside),
            TrimEdit::Delete { trim_loop } => t.remove_loop(*trim_loop),
            TrimEdit::Invert => t.inverted(),
            TrimEdit::Replace { loops } => t.with_loops(loops.clone()),
            TrimEdit::MovePoint {
                trim_loop,
                curve,
                point,
                to,
            } => replace(
                *trim_loop,
                shapes::move_loop_point(loop_of(*trim_loop)?, *trim_loop, *curve, *point, *to)?,
            ),
            TrimEdit::InsertPoint { trim_loop, curve } => replace(
                *trim_loop,
                shapes::insert_loop_point(loop_of(*trim_loop)?, *trim_loop, *curve)?,
            ),
            TrimEdit::DeletePoint {
                trim_loop,
                curve,
                point,
            } => replace(
                *trim_loop,
                shapes::delete_loop_point(loop_of(*trim_loop)?, *trim_loop, *curve, *point)?,
            ),
        }
    }
}

impl Command {
    /// [`Command::Apply`] of the operation `params`, without history.
    pub fn operation(params: impl crate::scene::operation::OperationParams) -> Self {
        Command::Apply {
            operation: crate::scene::operation::Operation::new(params),
            keep_history: false,
        }
    }

    /// A short name for the undo and redo buttons.
    pub fn label(&self) -> String {
        match self {
            Command::MovePoints { moves, .. } => format!("move {} point(s)", moves.len()),
            Command::SetWeight { points, weight, .. } => {
                format!("weight {weight} on {} point(s)", points.len())
            }
            Command::InsertKnot {
                direction, value, ..
            } => format!("insert knot {} = {value}", direction_name(*direction)),
            Command::RemoveKnot {
                direction, value, ..
            } => format!("remove knot {} = {value}", direction_name(*direction)),
            Command::ElevateDegree { direction, .. } => {
                format!("elevate degree in {}", direction_name(*direction))
            }
            Command::Split {
                direction, value, ..
            } => format!("split at {} = {value}", direction_name(*direction)),
            Command::Reverse { direction, .. } => {
                format!("reverse {}", direction_name(*direction))
            }
            Command::SwapUv { .. } => "swap u and v".into(),
            Command::SetKnots { direction, .. } => {
                format!("edit {} knots", direction_name(*direction))
            }
            Command::Add { object } => format!("add {}", object.name),
            Command::ReplaceScene { label, .. } => label.clone(),
            Command::Duplicate { .. } => "duplicate".into(),
            Command::Delete { .. } => "delete".into(),
            Command::Rename { name, .. } => format!("rename to {name}"),
            Command::SetVisible { visible, .. } => (if *visible { "show" } else { "hide" }).into(),
            Command::SetColor { color, .. } => (if color.is_some() {
                "colour"
            } else {
                "default colour"
            })
            .into(),
            Command::SetUnit { unit } => match unit {
                Some(unit) => format!("unit {}", unit.symbol()),
                None => "unitless".into(),
            },
            Command::SetSegments { segments, .. } => format!("{segments} segments"),
            Command::SetAllSegments { segments } => {
                format!("{segments} segments for every object")
            }
            Command::SetSubdivision { settings, .. } => {
                format!("subdivision level {}", settings.level)
            }
            Command::Trim { edit, .. } => edit.label(),
            Command::BreakHistory { .. } => "break history".into(),
            Command::Apply { operation, .. } => operation.label(),
            Command::EditRecipe { operation, .. } => format!("edit {}", operation.label()),
            Command::EditCurve { edit, .. } => match edit {
                CurveEdit::Close => "close curve".into(),
                CurveEdit::Open => "open curve".into(),
                CurveEdit::RemovePoint { point } => format!("remove point {point}"),
                CurveEdit::Join { .. } => "join curves".into(),
            },
            Command::SetDisplacement {
                displacement: Some(d),
                ..
            } => format!("{} displacement", d.pattern.label()),
            Command::SetDisplacement { .. } => "remove displacement".into(),
            Command::SetLattice {
                lattice: Some(l),
                objects,
            } => {
                let [a, b, c] = l.degrees();
                match objects.len() {
                    1 => format!("lattice of degree ({a}, {b}, {c})"),
                    n => format!("lattice of degree ({a}, {b}, {c}) around {n} objects"),
                }
            }
            Command::SetLattice { .. } => "release lattice".into(),
            Command::ApplyLattice { .. } => "apply lattice".into(),
        }
    }
}

/// "u" or "v".
pub fn direction_name(direction: Direction) -> &'static str {
    match direction {
        Direction::U => "u",
        Direction::V => "v",
    }
}

/// One undo step: the changes a command (or a whole drag) made.
#[derive(Debug, Clone, PartialEq)]
pub struct Edit {
    pub label: String,
    pub changes: Vec<Change>,
    /// The name of the document this step made (New, Open: [`Command::ReplaceScene`]'s
    /// `name`), so that the editor names the document after Undo and Redo too.
    pub document: Option<String>,
}

impl Edit {
    /// Whether this step ended an object's construction history.
    pub fn ends_history(&self) -> bool {
        construction::ended_histories(&self.changes)
            .next()
            .is_some()
    }

    /// Applies the changes forward (redo). Fails without changing anything if the scene does
    /// not match what the edit expects.
    pub fn redo(&self, scene: &mut Scene) -> Result<(), EditError> {
        let mut next = scene.clone();
        for change in &self.changes {
            forward(&mut next, change)?;
        }
        *scene = next;
        Ok(())
    }

    /// Applies the inverse changes in reverse order (undo).
    pub fn undo(&self, scene: &mut Scene) -> Result<(), EditError> {
        let mut next = scene.clone();
        for change in self.changes.iter().rev() {
            let inverse = match change {
                Change::Replace {
                    index,
                    before,
                    after,
                } => Change::Replace {
                    index: *index,
                    before: after.clone(),
                    after: before.clone(),
                },
                Change::Insert { index, object } => Change::Remove {
                    index: *index,
                    object: object.clone(),
                },
                Change::Remove { index, object } => Change::Insert {
                    index: *index,
                    object: object.clone(),
                },
                Change::Unit { before, after } => Change::Unit {
                    before: *after,
                    after: *before,
                },
            };
            forward(&mut next, &inverse)?;
        }
        *scene = next;
        Ok(())
    }

    /// What the editor must re-upload after this edit (either way): one object replaced in
    /// structure is [`Touched::Object`], one inserted or removed
    /// [`Touched::InsertedOrRemoved`], so that the others keep their GPU patches.
    pub fn touched(&self) -> Touched {
        match self.changes.as_slice() {
            [
                Change::Replace {
                    index,
                    before,
                    after,
                },
            ] => {
                if before.displacement != after.displacement
                    || before.lattice.as_ref().map(|l| l.degrees())
                        != after.lattice.as_ref().map(|l| l.degrees())
                {
                    Touched::Object(*index)
                } else if before.lattice != after.lattice && before.geometry == after.geometry {
                    // Only the lattice's points moved: the GPU uploads the lattice again.
                    Touched::Points(*index)
                } else if before.geometry == after.geometry && before.segments == after.segments {
                    if before.visible == after.visible {
                        Touched::Nothing
                    } else {
                        Touched::Object(*index)
                    }
                } else if before.segments == after.segments
                    && before.visible == after.visible
                    && before.kind().same_layout(&after.geometry)
                {
                    Touched::Points(*index)
                } else {
                    Touched::Object(*index)
                }
            }
            [Change::Insert { index, .. } | Change::Remove { index, .. }] => {
                Touched::InsertedOrRemoved(*index)
            }
            _ => Touched::Structure,
        }
    }
}

fn forward(scene: &mut Scene, change: &Change) -> Result<(), EditError> {
    let mismatch = |what: String| Err(EditError::HistoryMismatch(what));
    let objects = &mut scene.objects;
    match change {
        Change::Replace {
            index,
            before,
            after,
        } => match objects.get_mut(*index) {
            Some(slot) if slot == before => *slot = after.clone(),
            _ => return mismatch(format!("object {index} differs")),
        },
        Change::Insert { index, object } => {
            if *index > objects.len() {
                return mismatch(format!("cannot insert at {index}"));
            }
            objects.insert(*index, object.clone());
        }
        Change::Remove { index, object } => match objects.get(*index) {
            Some(slot) if slot == object => {
                objects.remove(*index);
            }
            _ => return mismatch(format!("object {index} differs")),
        },
        Change::Unit { before, after } => {
            if scene.unit != *before {
                return mismatch("the unit differs".into());
            }
            scene.unit = *after;
        }
    }
    Ok(())
}

pub(crate) fn object_at(scene: &Scene, object: usize) -> Result<&SceneObject, EditError> {
    scene.objects.get(object).ok_or(EditError::NoSuchObject {
        object,
        count: scene.objects.len(),
    })
}

pub(crate) fn geometry_error(object: &SceneObject) -> impl Fn(GeometryError) -> EditError + '_ {
    move |source| EditError::Geometry {
        name: object.name.clone(),
        source,
    }
}

/// Applies `command` to `scene` and returns the edit that undoes it. On error the scene is
/// unchanged.
pub fn apply(scene: &mut Scene, command: &Command) -> Result<Edit, EditError> {
    apply_reporting(scene, command).map(|(edit, _)| edit)
}

/// [`apply`], with the report of an operation that gives one
/// ([`crate::scene::operation::OperationParams::plan_with_report`]: a fit's deviation, where an
/// offset folds), for `knotwork apply` and the command line.
pub fn apply_reporting(
    scene: &mut Scene,
    command: &Command,
) -> Result<(Edit, Option<serde_json::Value>), EditError> {
    let ((mut changes, mut label), report) = match command {
        Command::Apply {
            operation,
            keep_history,
        } => construction::plan_operation(scene, operation, *keep_history)?,
        _ => (plan::plan(scene, command)?, None),
    };
    give_new_objects_ids(scene, &mut changes);
    construction::follow(scene, command, &mut changes, &mut label)?;
    let document = match command {
        Command::ReplaceScene { name, .. } => Some(name.clone()),
        _ => None,
    };
    let edit = Edit {
        label,
        changes,
        document,
    };
    edit.redo(scene)?;
    Ok((edit, report))
}

/// Gives every object `changes` insert that would share its [`crate::scene::operation::ObjectId`]
/// with another (a copy, a split part, a part of an exploded polysurface) an id of its own, so
/// that ids stay unique in the scene.
fn give_new_objects_ids(scene: &Scene, changes: &mut [Change]) {
    let removed: std::collections::HashSet<_> = changes
        .iter()
        .filter_map(|c| match c {
            Change::Remove { object, .. } => Some(object.id),
            _ => None,
        })
        .collect();
    let mut present: std::collections::HashSet<_> = scene
        .objects
        .iter()
        .map(|o| o.id)
        .filter(|id| !removed.contains(id))
        .collect();
    for change in changes.iter_mut() {
        if let Change::Insert { object, .. } = change
            && !present.insert(object.id)
        {
            object.id = crate::scene::operation::ObjectId::fresh();
            present.insert(object.id);
        }
    }
}
