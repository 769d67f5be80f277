//! What a [`Command`] would change, worked out without touching the scene: one function per
//! command (or per family of commands that share their checks), so that a refused command
//! leaves the document as it was.

use glam::DVec3;

use super::{
    Change, Command, EditError, TrimEdit, direction_name, drag, geometry_error, object_at,
};
use crate::kernel::{Direction, GeometryError, NurbsSurface, TrimmedSurface};
use crate::scene::{ObjectGeometry, Scene, SceneObject, valid_name};

/// Whether object `k` is a curve (which the knot, degree, direction and split commands then
/// edit as one).
fn is_curve(scene: &Scene, k: usize) -> bool {
    scene
        .objects
        .get(k)
        .is_some_and(|o| o.kind().space_curve().is_some())
}

/// The changes `command` would make and the label of its undo step.
pub(super) fn plan(scene: &Scene, command: &Command) -> Result<(Vec<Change>, String), EditError> {
    use super::curve_edits::{self, map_curve};
    let changes = match command {
        Command::InsertKnot { object, value, .. } if is_curve(scene, *object) => {
            map_curve(scene, *object, "knot insertion", |c| {
                c.insert_knot(*value, 1)
            })
        }
        Command::ElevateDegree { object, .. } if is_curve(scene, *object) => {
            map_curve(scene, *object, "degree elevation", |c| c.elevate_degree(1))
        }
        Command::Reverse { object, .. } if is_curve(scene, *object) => {
            map_curve(scene, *object, "reversal", |c| Ok(c.reverse()))
        }
        Command::Split { object, value, .. } if is_curve(scene, *object) => {
            curve_edits::split_curve(scene, *object, *value)
        }
        Command::RemoveKnot {
            object,
            value,
            tolerance,
            ..
        } if is_curve(scene, *object) => {
            let target = object_at(scene, *object)?;
            map_curve(scene, *object, "knot removal", |c| {
                let (removed, count) = c.remove_knot(*value, 1, *tolerance);
                if count == 0 {
                    return Err(GeometryError::Construction {
                        what: "knot removal",
                        message: format!(
                            "the knot {value} cannot be removed without moving {} more than {tolerance}",
                            target.name
                        ),
                    });
                }
                Ok(removed)
            })
        }
        Command::Apply {
            operation,
            keep_history,
        } => {
            return super::construction::plan_operation(scene, operation, *keep_history)
                .map(|(planned, _)| planned);
        }
        Command::EditRecipe { object, operation } => {
            let target = object_at(scene, *object)?;
            let Some(recipe) = &target.recipe else {
                return Err(geometry_error(target)(GeometryError::Construction {
                    what: "edit history",
                    message: "it has no construction history".into(),
                }));
            };
            if recipe.operation.name() != operation.name() {
                return Err(EditError::BadParameter {
                    operation: operation.name(),
                    field: "op",
                    message: format!(
                        "{} was made by {}, not {}",
                        target.name,
                        recipe.operation.name(),
                        operation.name()
                    ),
                });
            }
            let mut after = target.clone();
            after.recipe = Some(crate::scene::operation::Recipe {
                operation: operation.by_id(scene)?,
                output: recipe.output,
            });
            let remade = super::construction::rebuilt(&after, scene)
                .map_err(|message| {
                    geometry_error(target)(GeometryError::Construction {
                        what: "edit history",
                        message,
                    })
                })?
                .unwrap_or(after);
            return Ok((
                vec![Change::Replace {
                    index: *object,
                    before: target.clone(),
                    after: remade,
                }],
                command.label(),
            ));
        }
        Command::BreakHistory { object } => {
            let target = object_at(scene, *object)?;
            if !target.has_history() {
                return Err(geometry_error(target)(GeometryError::Construction {
                    what: "break history",
                    message: "it has no construction history".into(),
                }));
            }
            map_object(scene, *object, |o| o.recipe = None)
        }
        Command::EditCurve { object, edit } => curve_edits::edit_curve(scene, *object, edit),
        Command::ApplyLattice { object, tolerance } => {
            return apply_lattice(scene, *object, *tolerance, command.label());
        }
        Command::Add { object } => add(scene, object),
        Command::ReplaceScene { scene: new, .. } => Ok(replace_scene(scene, new)),
        Command::MovePoints { object, moves } => move_points(scene, *object, moves),
        Command::SetWeight {
            object,
            points,
            weight,
        } => set_weight(scene, *object, points, *weight),
        Command::InsertKnot {
            object,
            direction,
            value,
        } => map_surface(scene, *object, "knot insertion", |s| {
            s.insert_knot(*direction, *value, 1)
        }),
        Command::RemoveKnot {
            object,
            direction,
            value,
            tolerance,
        } => remove_knot(scene, *object, *direction, *value, *tolerance),
        Command::ElevateDegree { object, direction } => elevate_degree(scene, *object, *direction),
        Command::Split {
            object,
            direction,
            value,
        } => split(scene, *object, *direction, *value),
        Command::Reverse { object, direction } => {
            map_trimmed(scene, *object, "reversal", |t| t.reverse(*direction))
        }
        Command::SwapUv { object } => {
            map_trimmed(scene, *object, "swapping u and v", |t| t.swap_uv())
        }
        Command::SetKnots {
            object,
            direction,
            knots,
        } => map_surface(scene, *object, "knot editing", |s| {
            let mut all = [s.knots()[0].to_vec(), s.knots()[1].to_vec()];
            all[direction.index()] = knots.clone();
            NurbsSurface::from_homogeneous(
                s.degree(),
                all,
                s.count(),
                s.homogeneous_points().to_vec(),
            )
        }),
        Command::Trim { object, edit } => trim(scene, *object, edit),
        Command::Duplicate { object } => duplicate(scene, *object),
        Command::Delete { object } => Ok(vec![Change::Remove {
            index: *object,
            object: object_at(scene, *object)?.clone(),
        }]),
        Command::Rename { object, name } => {
            if !valid_name(name) {
                return Err(EditError::InvalidName);
            }
            map_object(scene, *object, |o| o.name = name.clone())
        }
        Command::SetVisible { object, visible } => {
            map_object(scene, *object, |o| o.visible = *visible)
        }
        Command::SetColor { object, color } => {
            if color.is_some_and(|c| !c.iter().all(|x| (0.0..=1.0).contains(x))) {
                return Err(EditError::InvalidColor);
            }
            map_object(scene, *object, |o| o.color = *color)
        }
        Command::SetUnit { unit } => Ok(vec![Change::Unit {
            before: scene.unit,
            after: *unit,
        }]),
        Command::SetSegments { object, segments } => {
            check_segments(*segments)?;
            map_object(scene, *object, |o| o.segments = *segments)
        }
        Command::SetAllSegments { segments } => set_all_segments(scene, *segments),
        Command::SetDisplacement {
            object,
            displacement,
        } => set_displacement(scene, *object, displacement.as_ref()),
        Command::SetSubdivision { object, settings } => {
            let changes = set_subdivision(scene, *object, settings)?;
            let label = subdivision_label(scene, *object, settings);
            return Ok((changes, label));
        }
        Command::SetLattice { objects, lattice } => set_lattice(scene, objects, lattice.as_ref()),
    }?;
    Ok((changes, command.label()))
}

/// Every object of `scene` removed (the last first) and every object of `new` inserted.
fn replace_scene(scene: &Scene, new: &Scene) -> Vec<Change> {
    let unit = (scene.unit != new.unit).then_some(Change::Unit {
        before: scene.unit,
        after: new.unit,
    });
    let removed = scene.objects.iter().enumerate().rev();
    let removals = removed.map(|(index, object)| Change::Remove {
        index,
        object: object.clone(),
    });
    let inserts = new
        .objects
        .iter()
        .enumerate()
        .map(|(index, object)| Change::Insert {
            index,
            object: object.clone(),
        });
    removals.chain(inserts).chain(unit).collect()
}

/// One object replaced by `after`.
fn replace(scene: &Scene, index: usize, after: SceneObject) -> Result<Vec<Change>, EditError> {
    Ok(vec![Change::Replace {
        index,
        before: object_at(scene, index)?.clone(),
        after,
    }])
}

/// One object replaced by a copy that `edit` changed (a setting, not the geometry).
fn map_object(
    scene: &Scene,
    index: usize,
    edit: impl FnOnce(&mut SceneObject),
) -> Result<Vec<Change>, EditError> {
    let mut after = object_at(scene, index)?.clone();
    edit(&mut after);
    replace(scene, index, after)
}

/// The object's NURBS surface with its trim loops, or the error naming `operation`.
fn nurbs(object: &SceneObject, operation: &'static str) -> Result<TrimmedSurface, EditError> {
    object
        .geometry
        .as_trimmed()
        .ok_or_else(|| EditError::NeedsNurbs {
            name: object.name.clone(),
            operation,
            kind: object.kind().kind_name(),
        })
}

/// The object with its (trimmed) NURBS surface replaced by `map`'s result.
fn with_trimmed(
    object: &SceneObject,
    operation: &'static str,
    map: impl FnOnce(&TrimmedSurface) -> Result<TrimmedSurface, GeometryError>,
) -> Result<SceneObject, EditError> {
    let trimmed = map(&nurbs(object, operation)?).map_err(geometry_error(object))?;
    Ok(SceneObject {
        geometry: ObjectGeometry::from_trimmed(trimmed),
        ..object.clone()
    })
}

/// Object `index` with its trimmed NURBS surface replaced by `map`'s result.
fn map_trimmed(
    scene: &Scene,
    index: usize,
    operation: &'static str,
    map: impl FnOnce(&TrimmedSurface) -> Result<TrimmedSurface, GeometryError>,
) -> Result<Vec<Change>, EditError> {
    let after = with_trimmed(object_at(scene, index)?, operation, map)?;
    replace(scene, index, after)
}

/// Object `index` with its NURBS surface replaced by `map`'s result; the trim loops stay (and
/// are revalidated where the domain changed).
fn map_surface(
    scene: &Scene,
    index: usize,
    operation: &'static str,
    map: impl FnOnce(&NurbsSurface) -> Result<NurbsSurface, GeometryError>,
) -> Result<Vec<Change>, EditError> {
    map_trimmed(scene, index, operation, |t| {
        t.with_surface(map(t.surface())?)
    })
}

fn add(scene: &Scene, object: &SceneObject) -> Result<Vec<Change>, EditError> {
    if !valid_name(&object.name) {
        return Err(EditError::InvalidName);
    }
    object.decompose().map_err(geometry_error(object))?;
    Ok(vec![Change::Insert {
        index: scene.objects.len(),
        object: object.clone(),
    }])
}

fn duplicate(scene: &Scene, index: usize) -> Result<Vec<Change>, EditError> {
    let object = object_at(scene, index)?;
    Ok(vec![Change::Insert {
        index: index + 1,
        object: SceneObject {
            name: super::parts::split_name(&object.name, "copy"),
            ..object.clone()
        },
    }])
}

/// Moves points of object `k`; a shared lattice's points move in every object that shares it,
/// and the moved object then works out again what depends on its shape, as a drag does when it
/// ends.
fn move_points(
    scene: &Scene,
    k: usize,
    moves: &[(usize, DVec3)],
) -> Result<Vec<Change>, EditError> {
    object_at(scene, k)?;
    if moves.is_empty() {
        return Err(EditError::NothingSelected { operation: "move" });
    }
    let targets = scene.linked_lattices(k);
    let mut changes = Vec::with_capacity(targets.len());
    for index in targets {
        let object = &scene.objects[index];
        let mut after = object.clone();
        drag::move_points_of(&mut after, moves)?;
        if index == k
            && let Some(geometry) = after.kind().resettled()
        {
            after.geometry = geometry;
        }
        changes.push(Change::Replace {
            index,
            before: object.clone(),
            after,
        });
    }
    Ok(changes)
}

fn set_weight(
    scene: &Scene,
    k: usize,
    points: &[usize],
    weight: f64,
) -> Result<Vec<Change>, EditError> {
    let object = object_at(scene, k)?;
    if !(weight.is_finite() && weight > 0.0) {
        return Err(EditError::InvalidWeight { weight });
    }
    if points.is_empty() {
        return Err(EditError::NothingSelected {
            operation: "set weight",
        });
    }
    let mut after = object.clone();
    for &index in points {
        after
            .set_weight(index, weight)
            .map_err(geometry_error(object))?;
    }
    replace(scene, k, after)
}

/// Removes knot `value` once if the surface stays within `tolerance` (The NURBS Book A5.8).
fn remove_knot(
    scene: &Scene,
    k: usize,
    direction: Direction,
    value: f64,
    tolerance: f64,
) -> Result<Vec<Change>, EditError> {
    let object = object_at(scene, k)?;
    let trimmed = nurbs(object, "knot removal")?;
    let (removed, count) = trimmed
        .surface()
        .remove_knot(direction, value, 1, tolerance);
    if count == 0 {
        return Err(EditError::KnotNotRemovable {
            name: object.name.clone(),
            direction: direction_name(direction),
            value,
            tolerance,
        });
    }
    map_trimmed(scene, k, "knot removal", |t| t.with_surface(removed))
}

/// Raises the degree by one (The NURBS Book A5.10); a triangular patch has one degree, so the
/// direction does not matter for it.
fn elevate_degree(scene: &Scene, k: usize, direction: Direction) -> Result<Vec<Change>, EditError> {
    let object = object_at(scene, k)?;
    if let Some(patch) = object.kind().triangle_patch() {
        let elevated = patch.elevated().map_err(geometry_error(object))?;
        let after = SceneObject {
            geometry: ObjectGeometry::boxed(Box::new(elevated)),
            ..object.clone()
        };
        return replace(scene, k, after);
    }
    map_surface(scene, k, "degree elevation", |s| {
        s.elevate_degree(direction, 1)
    })
}

/// Splits at the isoparametric curve into "name (a)" and "name (b)"; a side whose kept region
/// is empty is left out.
fn split(
    scene: &Scene,
    k: usize,
    direction: Direction,
    value: f64,
) -> Result<Vec<Change>, EditError> {
    let object = object_at(scene, k)?;
    let (a, b) = nurbs(object, "split")?
        .split(direction, value)
        .map_err(geometry_error(object))?;
    let parts: Vec<ObjectGeometry> = [a, b]
        .into_iter()
        .flatten()
        .map(ObjectGeometry::from_trimmed)
        .collect();
    match parts.len() {
        0 => Err(geometry_error(object)(GeometryError::Construction {
            what: "split",
            message: "nothing is kept on either side".into(),
        })),
        _ => Ok(super::parts::split_parts(object, k, parts)),
    }
}

fn trim(scene: &Scene, k: usize, edit: &TrimEdit) -> Result<Vec<Change>, EditError> {
    map_trimmed(scene, k, "trimming", |t| edit.apply(t))
}

fn set_all_segments(scene: &Scene, segments: u32) -> Result<Vec<Change>, EditError> {
    check_segments(segments)?;
    Ok(scene
        .objects
        .iter()
        .enumerate()
        .filter(|(_, o)| o.segments != segments)
        .map(|(index, o)| Change::Replace {
            index,
            before: o.clone(),
            after: SceneObject {
                segments,
                ..o.clone()
            },
        })
        .collect())
}

/// Sets or removes the displacement; refused for kinds without a (u, v) domain and for
/// numbers the kernel refuses (a command may come from a script with any numbers).
fn set_displacement(
    scene: &Scene,
    k: usize,
    displacement: Option<&crate::kernel::displace::Displacement>,
) -> Result<Vec<Change>, EditError> {
    let object = object_at(scene, k)?;
    if let Some(d) = displacement {
        d.checked().map_err(geometry_error(object))?;
        if object.geometry.displacement_domain().is_none() {
            return Err(geometry_error(object)(GeometryError::Construction {
                what: "displacement",
                message: format!(
                    "{} has no (u, v) domain to map heights on",
                    object.kind().kind_name()
                ),
            }));
        }
    }
    if object.displacement.as_ref() == displacement {
        return Err(EditError::NothingTo("change"));
    }
    map_object(scene, k, |o| o.displacement = displacement.cloned())
}

fn set_subdivision(
    scene: &Scene,
    k: usize,
    settings: &crate::scene::SubdivSettings,
) -> Result<Vec<Change>, EditError> {
    let object = object_at(scene, k)?;
    let Some(mesh) = object.kind().cage() else {
        return Err(geometry_error(object)(GeometryError::Construction {
            what: "subdivision",
            message: "only a polygon mesh or a subdivision surface has a cage".into(),
        }));
    };
    let mut surface = crate::scene::SubdivObject::with_settings(mesh, settings)
        .map_err(geometry_error(object))?;
    // A new crease or corner leaves most faces' neighbourhoods as they were.
    if let Some(earlier) = object.geometry.as_subdivision() {
        surface = surface.reusing_stencils_of(earlier);
    }
    map_object(scene, k, |o| {
        o.geometry = ObjectGeometry::boxed(Box::new(surface));
    })
}

/// What a change of subdivision settings did, for its undo step: "subdivide" a mesh, else the
/// first thing that differs (level, rules, display, creases, corners).
fn subdivision_label(scene: &Scene, k: usize, new: &crate::scene::SubdivSettings) -> String {
    let old = scene.objects.get(k).and_then(|o| {
        o.geometry
            .as_subdivision()
            .map(crate::scene::SubdivObject::settings)
    });
    let Some(old) = old else {
        return format!(
            "subdivide ({}, level {})",
            new.options.scheme.label(),
            new.level
        );
    };
    let crease_change = |before: &[crate::kernel::subdiv::Crease]| {
        let sharpness = |c: &[crate::kernel::subdiv::Crease], a, b| {
            c.iter()
                .find(|e| (e.a, e.b) == (a, b) || (e.b, e.a) == (a, b))
                .map_or(0.0, |e| e.sharpness)
        };
        let edges = before.iter().chain(&new.creases).map(|e| (e.a, e.b));
        let changed: Vec<(u32, u32)> = edges
            .filter(|&(a, b)| sharpness(before, a, b) != sharpness(&new.creases, a, b))
            .collect();
        match changed.as_slice() {
            [(a, b), ..] if sharpness(&new.creases, *a, *b) == 0.0 => {
                format!("remove crease {a}–{b}")
            }
            [(a, b), ..] => format!(
                "crease {a}–{b} sharpness {}",
                sharpness(&new.creases, *a, *b)
            ),
            [] => "creases".into(),
        }
    };
    if old.level != new.level {
        format!("subdivision level {}", new.level)
    } else if old.options != new.options {
        format!("{} subdivision", new.options.scheme.label())
    } else if old.display != new.display || old.tolerance != new.tolerance {
        format!("show as {:?}", new.display).to_lowercase()
    } else if old.creases != new.creases {
        crease_change(&old.creases)
    } else if old.corners != new.corners {
        "sharp corners".into()
    } else {
        format!("subdivision level {}", new.level)
    }
}

/// Puts `lattice` on the objects (or releases theirs); a lattice is checked again, as a
/// command may come from a script with any numbers.
fn set_lattice(
    scene: &Scene,
    objects: &[usize],
    lattice: Option<&crate::kernel::ffd::Lattice>,
) -> Result<Vec<Change>, EditError> {
    let mut changes = Vec::new();
    let mut seen = std::collections::BTreeSet::new();
    for &k in objects {
        let object = object_at(scene, k)?;
        if lattice.is_some() && object.kind().space_curve().is_some() {
            return Err(geometry_error(object)(GeometryError::Construction {
                what: "lattice",
                message: "a lattice deforms surfaces; a curve takes none".into(),
            }));
        }
        if let Some(l) = lattice {
            crate::kernel::ffd::Lattice::new(
                l.origin(),
                l.axes(),
                l.degrees(),
                l.points().to_vec(),
            )
            .map_err(geometry_error(object))?;
        }
        if object.lattice.as_ref() != lattice && seen.insert(k) {
            changes.push(Change::Replace {
                index: k,
                before: object.clone(),
                after: SceneObject {
                    lattice: lattice.cloned(),
                    ..object.clone()
                },
            });
        }
    }
    if changes.is_empty() {
        return Err(EditError::NothingTo("change"));
    }
    Ok(changes)
}

/// The changes an [`Command::ApplyLattice`] makes, and its label saying how the bake turned out
/// ("apply lattice: exact: …" or "apply lattice: refitted: …").
fn apply_lattice(
    scene: &Scene,
    k: usize,
    tolerance: f64,
    label: String,
) -> Result<(Vec<Change>, String), EditError> {
    object_at(scene, k)?;
    let targets = scene.linked_lattices(k);
    let named = targets.len() > 1;
    let mut changes = Vec::with_capacity(targets.len());
    let mut reports = Vec::with_capacity(targets.len());
    for index in targets {
        let object = &scene.objects[index];
        let (after, baked) = object
            .baked_lattice(tolerance)
            .map_err(geometry_error(object))?;
        after.decompose().map_err(geometry_error(object))?;
        reports.push(if named {
            format!("{}: {}", object.name, baked.describe())
        } else {
            baked.describe()
        });
        changes.push(Change::Replace {
            index,
            before: object.clone(),
            after,
        });
    }
    Ok((changes, format!("{label}: {}", reports.join("; "))))
}

/// Refuses segments per span outside 1..=[`crate::scene::MAX_SEGMENTS`].
fn check_segments(segments: u32) -> Result<(), EditError> {
    let max = crate::scene::MAX_SEGMENTS;
    if (1..=max).contains(&segments) {
        Ok(())
    } else {
        Err(EditError::Segments { segments, max })
    }
}
