//! Construction history in the document: a surface built from curve objects
//! ([`crate::scene::construction::Construction`]) is built again whenever one of its input
//! curves changes — on every drag step ([`super::drag`]) and with every command that changes,
//! renames or removes a curve ([`follow`]) — in the same undo step as the change. A direct
//! edit of the surface itself ends its history.

use super::{Change, Command, EditError};
use crate::io::construct;
use crate::scene::construction::Construction;
use crate::scene::json::Geometry;
use crate::scene::{ObjectGeometry, Scene, SceneObject};

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
    let Some(construction) = &object.construction else {
        return Ok(None);
    };
    let rebuilt = build(construction, scene)?;
    Ok(Some(SceneObject {
        geometry: rebuilt.geometry,
        ..object.clone()
    }))
}

/// The objects whose construction history `changes` end (each was built from curves before
/// and is not after).
pub(super) fn ended_histories(changes: &[Change]) -> impl Iterator<Item = &str> {
    changes.iter().filter_map(|change| match change {
        Change::Replace { before, after, .. }
            if before.construction.is_some() && after.construction.is_none() =>
        {
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
                if after.construction.is_some() && before.geometry != after.geometry =>
            {
                after.construction = None;
            }
            Change::Insert { object, .. } if copies => object.construction = None,
            _ => {}
        }
    }
    // An object whose history the command ended (a direct edit, a trim, a fillet's trim):
    // the label says so, since dragging its curves no longer moves it.
    if !matches!(command, Command::BreakHistory { .. }) {
        say_ended_histories(changes, label);
    }
    let histories = |objects: &[SceneObject]| objects.iter().any(|o| o.construction.is_some());
    if !histories(&scene.objects) {
        return Ok(());
    }
    let mut next = scene.clone();
    for change in changes.iter() {
        super::forward(&mut next, change)?;
    }
    let mut moved_curves = Vec::new();
    let mut renames = Vec::new();
    let mut removed = Vec::new();
    for change in changes.iter() {
        match change {
            Change::Replace { before, after, .. } => {
                if before.name != after.name {
                    renames.push((before.name.clone(), after.name.clone()));
                }
                if before.kind().space_curve().is_some() && before.geometry != after.geometry {
                    moved_curves.push(after.name.clone());
                }
            }
            Change::Remove { object, .. } => removed.push(object.name.clone()),
            Change::Insert { .. } | Change::Unit { .. } => {}
        }
    }
    // A name removed and inserted again (an object replaced wholesale) is still there.
    removed.retain(|name| !next.objects.iter().any(|o| &o.name == name));
    let mut extra = Vec::new();
    let mut failures = Vec::new();
    for index in 0..next.objects.len() {
        let object = &next.objects[index];
        let Some(construction) = &object.construction else {
            continue;
        };
        let mut after = object.clone();
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
        if &after != object {
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
