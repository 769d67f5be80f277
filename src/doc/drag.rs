//! Moving control points as a transient edit of the document: a drag begins, changes the
//! document on every step (the history does not see the steps), and ends as one undo step or is
//! cancelled. Every way of moving points — a mouse drag, the panel's numeric entry, the page's
//! `moveControlPoint` — goes through here, so each reports the same Bézier patches to
//! re-evaluate (the moved points' local support) and each lands in the history the same way.

use std::collections::BTreeSet;

use glam::DVec3;

use super::{Change, Document, Edit, EditError, PointsMoved, geometry_error, object_at};
use crate::kernel::{GeometryError, Location};
use crate::scene::SceneObject;

/// A drag in progress.
#[derive(Debug, Clone, PartialEq)]
pub struct PointDrag {
    /// The object whose points move.
    pub object: usize,
    /// The object as it was when the drag began (what undo and cancel restore).
    before: SceneObject,
    /// Each dragged point and where it started, by increasing index.
    starts: Vec<(usize, DVec3)>,
    /// The other objects sharing the object's lattice (whose lattice points move too), as
    /// they were when the drag began.
    linked: Vec<(usize, SceneObject)>,
    /// The objects built from the dragged curve (construction history), as they were when the
    /// drag began: each step builds them again.
    dependents: Vec<(usize, SceneObject)>,
}

impl PointDrag {
    /// The dragged points (indices of [`SceneObject::control_points`]) and their starts.
    pub fn starts(&self) -> &[(usize, DVec3)] {
        &self.starts
    }

    /// The other objects whose shared lattice moves with the dragged one.
    pub fn linked(&self) -> Vec<usize> {
        self.linked.iter().map(|(k, _)| *k).collect()
    }

    /// The objects built from the dragged curve, which each step builds again.
    pub fn dependents(&self) -> Vec<usize> {
        self.dependents.iter().map(|(k, _)| *k).collect()
    }
}

impl Document {
    /// The drag in progress, if any.
    pub fn drag(&self) -> Option<&PointDrag> {
        self.drag.as_ref()
    }

    /// Begins dragging `points` of `object`. A drag already in progress is committed first.
    /// Refused (nothing begins) for a missing object, no points, or a point it does not have.
    pub fn begin_drag(&mut self, object: usize, points: &[usize]) -> Result<(), EditError> {
        self.commit_drag();
        let target = object_at(&self.scene, object)?;
        if points.is_empty() {
            return Err(EditError::NothingSelected { operation: "move" });
        }
        let count = target.control_point_count();
        if let Some(&bad) = points.iter().find(|&&k| k >= count) {
            return Err(geometry_error(target)(GeometryError::NoSuchPoint {
                index: bad,
                count,
            }));
        }
        let positions = target.control_points();
        let unique: BTreeSet<usize> = points.iter().copied().collect();
        let linked = self
            .scene
            .linked_lattices(object)
            .into_iter()
            .filter(|&k| k != object)
            .map(|k| (k, self.scene.objects[k].clone()))
            .collect();
        let dependents = super::construction::dependents_of(&self.scene, object)
            .into_iter()
            .map(|k| (k, self.scene.objects[k].clone()))
            .collect();
        self.drag = Some(PointDrag {
            object,
            before: target.clone(),
            starts: unique.into_iter().map(|k| (k, positions[k])).collect(),
            linked,
            dependents,
        });
        Ok(())
    }

    /// Moves every dragged point to its start plus `delta`. The document changes; the history
    /// does not until [`Self::commit_drag`]. A non-finite `delta` is refused and moves nothing.
    pub fn drag_by(&mut self, delta: DVec3) -> Result<PointsMoved, EditError> {
        let moves: Vec<(usize, DVec3)> = match &self.drag {
            Some(drag) => drag.starts.iter().map(|&(k, p)| (k, p + delta)).collect(),
            None => return Err(EditError::NoDrag),
        };
        self.drag_to(&moves)
    }

    /// Moves dragged points to the given positions (the others stay where they are). Every
    /// position is checked before any point moves: a non-finite one, or a point the drag does
    /// not hold, is refused and nothing moves.
    pub fn drag_to(&mut self, moves: &[(usize, DVec3)]) -> Result<PointsMoved, EditError> {
        let Some(drag) = &self.drag else {
            return Err(EditError::NoDrag);
        };
        let object = drag.object;
        let target = object_at(&self.scene, object)?;
        for &(k, p) in moves {
            if drag.starts.binary_search_by_key(&k, |&(d, _)| d).is_err() {
                return Err(EditError::NotDragged { point: k });
            }
            if !p.is_finite() {
                return Err(geometry_error(target)(GeometryError::non_finite_point(
                    Location::point(k),
                    p,
                )));
            }
        }
        let linked = drag.linked();
        let dependents: Vec<usize> = drag.dependents.iter().map(|(k, _)| *k).collect();
        let mut patches = BTreeSet::new();
        for index in std::iter::once(object).chain(linked.iter().copied()) {
            let support = move_points_of(&mut self.scene.objects[index], moves)?;
            if index == object {
                patches.extend(support);
            }
        }
        // The surfaces built from the curve follow it. One that cannot be built for this
        // position keeps its last shape.
        let mut rebuilt = Vec::new();
        let mut relaid = false;
        for index in dependents {
            let Ok(Some(after)) =
                super::construction::rebuilt(&self.scene.objects[index], &self.scene)
            else {
                continue;
            };
            let before = &self.scene.objects[index];
            relaid |= !before.kind().same_layout(&after.geometry);
            self.scene.objects[index] = after;
            rebuilt.push(index);
        }
        Ok(PointsMoved {
            object,
            patches: patches.into_iter().collect(),
            relaid,
            linked,
            rebuilt,
        })
    }

    /// Ends the drag as one undo step ("move N point(s)") and returns it; `None` when no drag
    /// was in progress or nothing moved. What depends on the object's shape is worked out again
    /// first ([`crate::scene::ObjectKind::resettled`]); the edit's
    /// [`Edit::touched`] says whether that changed its layout.
    pub fn commit_drag(&mut self) -> Option<&Edit> {
        let drag = self.drag.take()?;
        let slot = self.scene.objects.get_mut(drag.object)?;
        if let Some(geometry) = slot.kind().resettled() {
            slot.geometry = geometry;
        }
        // A direct edit of an object made with history ends its history.
        if slot.geometry != drag.before.geometry {
            slot.recipe = None;
        }
        let after = slot.clone();
        if after == drag.before {
            return None;
        }
        let mut changes = vec![Change::Replace {
            index: drag.object,
            before: drag.before,
            after,
        }];
        for (index, before) in drag.linked.into_iter().chain(drag.dependents) {
            let after = self.scene.objects.get(index)?.clone();
            if after != before {
                changes.push(Change::Replace {
                    index,
                    before,
                    after,
                });
            }
        }
        let mut label = format!("move {} point(s)", drag.starts.len());
        super::construction::say_ended_histories(&changes, &mut label);
        Some(self.history.record(Edit {
            label,
            changes,
            document: None,
        }))
    }

    /// Ends the drag and puts the object back as it was; returns the object's index, or `None`
    /// when no drag was in progress.
    pub fn cancel_drag(&mut self) -> Option<usize> {
        let drag = self.drag.take()?;
        for (index, before) in drag.linked.into_iter().chain(drag.dependents) {
            if let Some(slot) = self.scene.objects.get_mut(index) {
                *slot = before;
            }
        }
        let slot = self.scene.objects.get_mut(drag.object)?;
        *slot = drag.before;
        Some(drag.object)
    }

    /// Moves control points of `object` as one undo step, along the same incremental path as a
    /// drag (begin, one step, commit). Refused with nothing changed for a bad object, point or
    /// position.
    pub fn move_points(
        &mut self,
        object: usize,
        moves: &[(usize, DVec3)],
    ) -> Result<PointsMoved, EditError> {
        let points: Vec<usize> = moves.iter().map(|&(k, _)| k).collect();
        self.begin_drag(object, &points)?;
        match self.drag_to(moves) {
            Ok(mut moved) => {
                moved.relaid = self
                    .commit_drag()
                    .is_some_and(|edit| edit.touched().is_structure());
                Ok(moved)
            }
            Err(e) => {
                self.cancel_drag();
                Err(e)
            }
        }
    }
}

/// Moves control points of one object (or its lattice's points) in place and returns the
/// feed patches they support: the one way points move, for a drag step and for
/// [`super::Command::MovePoints`] alike.
pub(super) fn move_points_of(
    target: &mut SceneObject,
    moves: &[(usize, DVec3)],
) -> Result<BTreeSet<usize>, EditError> {
    let mut patches = BTreeSet::new();
    for &(k, p) in moves {
        if let Some(&value) = p
            .to_array()
            .iter()
            .find(|c| c.is_finite() && c.abs() > super::MAX_COORDINATE)
        {
            return Err(EditError::CoordinateOutOfRange { point: k, value });
        }
        let support = target
            .move_control_point(k, p)
            .map_err(|source| EditError::Geometry {
                name: target.name.clone(),
                source,
            })?;
        patches.extend(support);
    }
    Ok(patches)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Scene;

    #[test]
    fn a_drag_is_one_undo_step_and_a_cancel_restores_the_object() {
        let mut doc = Document::new(Scene::demo().unwrap());
        let original = doc.scene.clone();
        // The (2, 5) sheet: point (4, 4) supports patches 8..16 (see scene's tests).
        doc.begin_drag(3, &[4 * 9 + 4]).unwrap();
        for step in 1..=5 {
            let moved = doc.drag_by(DVec3::Z * 0.1 * f64::from(step)).unwrap();
            assert_eq!(moved.patches, (8..16).collect::<Vec<_>>());
        }
        assert_eq!(
            doc.history.undo_depth(),
            0,
            "steps do not enter the history"
        );
        assert!(doc.commit_drag().is_some());
        assert_eq!(doc.history.undo_depth(), 1);
        doc.undo().unwrap();
        assert_eq!(doc.scene, original);

        doc.begin_drag(3, &[0]).unwrap();
        doc.drag_by(DVec3::X).unwrap();
        assert_eq!(doc.cancel_drag(), Some(3));
        assert_eq!(doc.scene, original);
        assert_eq!(doc.history.undo_depth(), 0);
        assert_eq!(
            doc.history.redo_depth(),
            1,
            "a cancel leaves the redo stack alone"
        );
    }

    #[test]
    fn bad_moves_change_nothing_and_a_command_ends_the_drag() {
        let mut doc = Document::new(Scene::demo().unwrap());
        let original = doc.clone();
        assert!(
            doc.move_points(3, &[(0, DVec3::ONE), (1, DVec3::NAN)])
                .is_err()
        );
        assert!(doc.move_points(3, &[(10_000, DVec3::ONE)]).is_err());
        assert!(doc.move_points(99, &[(0, DVec3::ONE)]).is_err());
        assert!(doc.move_points(3, &[]).is_err());
        assert_eq!(doc, original);

        let moved = doc.move_points(3, &[(4 * 9 + 4, DVec3::ONE)]).unwrap();
        assert_eq!(moved.patches, (8..16).collect::<Vec<_>>());
        assert_eq!(doc.history.undo_label(), Some("move 1 point(s)"));

        // A command during a drag commits the drag first, then applies.
        doc.begin_drag(1, &[0]).unwrap();
        doc.drag_by(DVec3::Y).unwrap();
        doc.execute(&super::super::Command::Rename {
            object: 0,
            name: "pot".into(),
        })
        .unwrap();
        assert!(doc.drag().is_none());
        assert_eq!(doc.history.undo_depth(), 3);
    }
}
