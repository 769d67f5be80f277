//! Construction history in the document: a surface built from curve objects
//! ([`crate::scene::construction::Construction`]) is built again whenever one of its input
//! curves changes — on every drag step ([`super::drag`]) and with every command that changes,
//! renames or removes a curve ([`follow`]) — in the same undo step as the change. A direct
//! edit of the surface itself ends its history.

use super::{Change, Command, EditError};
use crate::io::construct;
use crate::scene::construction::Construction;
use crate::scene::json::Geometry;
use crate::scene::operation::{ObjectId, Operation, Planned, Recipe};
use crate::scene::{ObjectGeometry, Scene, SceneObject};

/// [`Command::Apply`]: the operation's plan; with `keep_history` each object it adds keeps a
/// [`Recipe`] (the operation with its inputs by id, and the object's place among those added).
pub(super) fn plan_operation(
    scene: &Scene,
    operation: &Operation,
    keep_history: bool,
) -> Result<(Planned, Option<serde_json::Value>), EditError> {
    let ((mut changes, label), report) = operation.plan_with_report(scene)?;
    if keep_history {
        let kept = operation.by_id(scene)?;
        let mut output = 0;
        for change in &mut changes {
            if let Change::Insert { object, .. } = change {
                object.construction = None;
                object.recipe = Some(Recipe {
                    operation: kept.clone(),
                    output,
                });
                output += 1;
            }
        }
    }
    Ok(((changes, label), report))
}

/// The geometry `recipe` makes from `scene` as it is now: its operation planned again, and the
/// object it adds at the recipe's place.
fn remade(recipe: &Recipe, scene: &Scene) -> Result<ObjectGeometry, String> {
    let (changes, _) = recipe.operation.plan(scene).map_err(|e| e.to_string())?;
    changes
        .into_iter()
        .filter_map(|c| match c {
            Change::Insert { object, .. } => Some(object.geometry),
            _ => None,
        })
        .nth(recipe.output)
        .ok_or_else(|| {
            format!(
                "{} no longer makes an object {}",
                recipe.operation.name(),
                recipe.output + 1
            )
        })
}

/// Whether `object`'s history reads the object `name`/`id`.
fn reads(object: &SceneObject, name: &str, id: ObjectId) -> bool {
    object.construction.as_ref().is_some_and(|c| c.uses(name))
        || object
            .recipe
            .as_ref()
            .is_some_and(|r| r.operation.reads(id))
}

/// The objects whose history reads object `k`, directly or through another such object (built
/// from it, or made by an operation on it), by increasing index: what a drag of `k` makes again.
pub fn dependents_of(scene: &Scene, k: usize) -> Vec<usize> {
    let mut inputs = vec![k];
    let mut found = Vec::new();
    while let Some(input) = inputs.pop() {
        let Some(input) = scene.objects.get(input) else {
            continue;
        };
        for (j, o) in scene.objects.iter().enumerate() {
            if j != k && !found.contains(&j) && reads(o, &input.name, input.id) {
                found.push(j);
                inputs.push(j);
            }
        }
    }
    found.sort_unstable();
    found
}

/// What a construction built: the geometry, its default name ("loft", "network surface") and
/// how well it fits its curves where the construction measures that.
pub struct Rebuilt {
    pub geometry: ObjectGeometry,
    pub name: &'static str,
    pub report: Option<String>,
}

/// Builds `construction` from the curves of `scene` as they are now ([`construct::build_value`]).
pub fn build(construction: &Construction, scene: &Scene) -> Result<Rebuilt, String> {
    let request = construction
        .request_with(scene)
        .map_err(|e| e.to_string())?;
    let built = construct::build_value(request).map_err(|e| e.to_string())?;
    let geometry = match built.geometry {
        Geometry::Surface(s) => ObjectGeometry::new(s),
        Geometry::TrimmedSurface(t) => ObjectGeometry::from_trimmed(t),
        Geometry::Curve(c) => ObjectGeometry::new(c),
        Geometry::Trim(_) => return Err("a trim curve is not a scene object".into()),
    };
    Ok(Rebuilt {
        geometry,
        name: built.name,
        report: built.report,
    })
}

/// The object built again from its construction in `scene`, with the same name, settings and
/// history; `Ok(None)` for an object without history.
pub fn rebuilt(object: &SceneObject, scene: &Scene) -> Result<Option<SceneObject>, String> {
    let geometry = match (&object.construction, &object.recipe) {
        (Some(construction), _) => build(construction, scene)?.geometry,
        (None, Some(recipe)) => remade(recipe, scene)?,
        (None, None) => return Ok(None),
    };
    Ok(Some(SceneObject {
        geometry,
        ..object.clone()
    }))
}

/// The objects whose construction history `changes` end (each was built from curves before
/// and is not after).
pub(super) fn ended_histories(changes: &[Change]) -> impl Iterator<Item = &str> {
    changes.iter().filter_map(|change| match change {
        Change::Replace { before, after, .. } if before.has_history() && !after.has_history() => {
            Some(before.name.as_str())
        }
        _ => None,
    })
}

/// Adds to `label` whose construction history `changes` end, if any: dragging their curves
/// no longer moves them, which the user should hear.
pub(super) fn say_ended_histories(changes: &[Change], label: &mut String) {
    let ended: Vec<String> = ended_histories(changes)
        .map(|name| format!("{name}'s construction history ends: it no longer follows its curves"))
        .collect();
    if !ended.is_empty() {
        label.push_str(" (");
        label.push_str(&ended.join("; "));
        label.push(')');
    }
}

/// Completes a command's changes with what construction history asks for:
/// - an object whose geometry the command changed itself loses its history (a copy or a split
///   part never takes it);
/// - objects built from a curve the command changed are built again (one that cannot be is
///   kept as it was, and the label says why);
/// - a renamed input is renamed in the histories that use it; a removed one ends them.
pub(super) fn follow(
    scene: &Scene,
    command: &Command,
    changes: &mut Vec<Change>,
    label: &mut String,
) -> Result<(), EditError> {
    if matches!(command, Command::ReplaceScene { .. }) {
        return Ok(());
    }
    let copies = matches!(command, Command::Duplicate { .. } | Command::Split { .. });
    for change in changes.iter_mut() {
        match change {
            Change::Replace { before, after, .. }
                if after.has_history() && before.geometry != after.geometry =>
            {
                after.construction = None;
                after.recipe = None;
            }
            Change::Insert { object, .. } if copies => {
                object.construction = None;
                object.recipe = None;
            }
            _ => {}
        }
    }
    // An object whose history the command ended (a direct edit, a trim, a fillet's trim):
    // the label says so, since dragging its curves no longer moves it.
    if !matches!(command, Command::BreakHistory { .. }) {
        say_ended_histories(changes, label);
    }
    let histories = |objects: &[SceneObject]| objects.iter().any(SceneObject::has_history);
    if !histories(&scene.objects) {
        return Ok(());
    }
    let mut next = scene.clone();
    for change in changes.iter() {
        super::forward(&mut next, change)?;
    }
    let mut moved_curves = Vec::new();
    let mut moved = Vec::new();
    let mut renames = Vec::new();
    let mut removed = Vec::new();
    let mut removed_ids = Vec::new();
    for change in changes.iter() {
        match change {
            Change::Replace { before, after, .. } => {
                if before.name != after.name {
                    renames.push((before.name.clone(), after.name.clone()));
                }
                if before.kind().space_curve().is_some() && before.geometry != after.geometry {
                    moved_curves.push(after.name.clone());
                }
                if before.geometry != after.geometry
                    || before.displacement != after.displacement
                    || before.lattice != after.lattice
                {
                    moved.push(after.id);
                }
            }
            Change::Remove { object, .. } => {
                removed.push(object.name.clone());
                removed_ids.push(object.id);
            }
            Change::Insert { .. } | Change::Unit { .. } => {}
        }
    }
    // A name removed and inserted again (an object replaced wholesale) is still there.
    removed.retain(|name| !next.objects.iter().any(|o| &o.name == name));
    removed_ids.retain(|id| !next.objects.iter().any(|o| o.id == *id));
    let mut extra = Vec::new();
    let mut failures = Vec::new();
    for index in 0..next.objects.len() {
        let object = &next.objects[index];
        let mut after = object.clone();
        if let Some(recipe) = &object.recipe {
            let reads = recipe.operation.objects();
            let reads_id =
                |id: &ObjectId| reads.contains(&crate::scene::operation::ObjectRef::Id(*id));
            if removed_ids.iter().any(reads_id) {
                after.recipe = None;
                failures.push(format!(
                    "{}'s history ends: an object it was made from was removed",
                    object.name
                ));
            } else if moved.iter().any(reads_id) {
                match remade(recipe, &next) {
                    Ok(geometry) => {
                        after.geometry = geometry;
                        // What is made from this object follows too.
                        moved.push(after.id);
                    }
                    Err(e) => failures.push(format!("{} not made again: {e}", object.name)),
                }
            }
        } else if let Some(construction) = &object.construction {
            let mut renamed = construction.clone();
            for (from, to) in &renames {
                renamed = renamed.renamed(from, to);
            }
            after.construction = Some(renamed.clone());
            if let Some(gone) = removed.iter().find(|name| renamed.uses(name)) {
                after.construction = None;
                failures.push(format!(
                    "{}'s construction history ends: {gone} was removed",
                    object.name
                ));
            } else if moved_curves.iter().any(|name| renamed.uses(name)) {
                match build(&renamed, &next) {
                    Ok(rebuilt) => after.geometry = rebuilt.geometry,
                    Err(e) => failures.push(format!("{} not rebuilt: {e}", object.name)),
                }
            }
        }
        if after != *object {
            extra.push(Change::Replace {
                index,
                before: object.clone(),
                after: after.clone(),
            });
            next.objects[index] = after;
        }
    }
    changes.extend(extra);
    if !failures.is_empty() {
        label.push_str(" (");
        label.push_str(&failures.join("; "));
        label.push(')');
    }
    Ok(())
}
