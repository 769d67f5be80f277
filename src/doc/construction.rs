//! Construction history in the document: an object made by an operation with its history kept
//! (a loft of curve objects, an offset of a surface, …; [`Recipe`]) is made again whenever an
//! object it reads changes — on every drag step ([`super::drag`]) and with every command that
//! changes one ([`follow`]) — in the same undo step as the change; removing an input ends the
//! history. Inputs are held by id, so renames and duplicate names change nothing. A direct edit
//! of the object itself ends its history.

use super::{Change, Command, EditError};
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

/// Whether `object`'s history reads the object `id`.
fn reads(object: &SceneObject, id: ObjectId) -> bool {
    object
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
            if j != k && !found.contains(&j) && reads(o, input.id) {
                found.push(j);
                inputs.push(j);
            }
        }
    }
    found.sort_unstable();
    found
}

/// The object made again from its history in `scene`, with the same name, settings and
/// history; `Ok(None)` for an object without history.
pub fn rebuilt(object: &SceneObject, scene: &Scene) -> Result<Option<SceneObject>, String> {
    let Some(recipe) = &object.recipe else {
        return Ok(None);
    };
    let geometry = remade(recipe, scene)?;
    Ok(Some(SceneObject {
        geometry,
        ..object.clone()
    }))
}

/// The objects whose construction history `changes` end (each was built from curves before
/// and is not after).
pub(super) fn ended_histories(changes: &[Change]) -> impl Iterator<Item = &SceneObject> {
    changes.iter().filter_map(|change| match change {
        Change::Replace { before, after, .. } if before.has_history() && !after.has_history() => {
            Some(before)
        }
        _ => None,
    })
}

/// Adds to `label` whose construction history `changes` end, if any: dragging their curves
/// no longer moves them, which the user should hear.
pub(super) fn say_ended_histories(changes: &[Change], label: &mut String) {
    let ended: Vec<String> = ended_histories(changes)
        .map(|object| {
            let inputs = match &object.recipe {
                Some(r) if r.operation.name() == crate::ops::construct::ENTRY.name => "its curves",
                _ => "what it was made from",
            };
            format!(
                "{}'s construction history ends: it no longer follows {inputs}",
                object.name
            )
        })
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
/// - objects made from an object the command changed are made again (one that cannot be is
///   kept as it was, and the label says why), and so are those made from them;
/// - a removed input ends the histories that read it.
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
                if after.has_history()
                    && before.geometry != after.geometry
                    && !matches!(command, Command::EditRecipe { .. }) =>
            {
                after.recipe = None;
            }
            Change::Insert { object, .. } if copies => {
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
    let mut moved = Vec::new();
    let mut removed = Vec::new();
    for change in changes.iter() {
        match change {
            Change::Replace { before, after, .. } => {
                if before.geometry != after.geometry
                    || before.displacement != after.displacement
                    || before.lattice != after.lattice
                {
                    moved.push(after.id);
                }
            }
            Change::Remove { object, .. } => removed.push((object.id, object.name.clone())),
            Change::Insert { .. } | Change::Unit { .. } => {}
        }
    }
    // An object removed and inserted again (a scene replaced wholesale) is still there.
    removed.retain(|(id, _)| !next.objects.iter().any(|o| o.id == *id));
    let mut extra = Vec::new();
    let mut failures = Vec::new();
    for index in 0..next.objects.len() {
        let object = &next.objects[index];
        let mut after = object.clone();
        if let Some(recipe) = &object.recipe {
            if let Some((_, gone)) = removed.iter().find(|(id, _)| recipe.operation.reads(*id)) {
                after.recipe = None;
                failures.push(format!(
                    "{}'s construction history ends: {gone} was removed",
                    object.name
                ));
            } else if moved.iter().any(|id| recipe.operation.reads(*id)) {
                match remade(recipe, &next) {
                    Ok(geometry) => {
                        after.geometry = geometry;
                        // What is made from this object follows too.
                        moved.push(after.id);
                    }
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
