//! Face features of polyhedra: faces offset along their normals, and faces drafted (tilted
//! about the line where they meet a neutral plane), the neighbours extended or trimmed so the
//! body stays closed: every face keeps its loops, each corner moves to where its faces' new
//! planes meet ([`super::shell::replaned`]).

use glam::{DQuat, DVec3};

use crate::error::{GeometryError, construction};
use crate::trim::TrimmedSurface;

use super::polyhedron::Polyhedron;
use super::shell::replaned;
use super::{FeatureResult, WHAT, closed_result};

/// The faces of `solid` nearest `points`, without repeats; refused for none.
fn picked_faces(solid: &Polyhedron, points: &[DVec3]) -> Result<Vec<usize>, GeometryError> {
    let faces = solid.nearest_faces(points)?;
    if faces.is_empty() {
        return Err(construction(WHAT, "no face is picked"));
    }
    Ok(faces)
}

fn checked(tolerance: f64) -> Result<(), GeometryError> {
    if tolerance.is_finite() && tolerance > 0.0 {
        Ok(())
    } else {
        Err(construction(
            WHAT,
            format!("the tolerance must be a number above 0, got {tolerance}"),
        ))
    }
}

/// The polyhedral solid `faces` with the faces nearest `points` moved `distance` along their
/// outward normals (out above 0, in below), the neighbouring faces extended or trimmed to
/// them, at `tolerance`.
pub fn offset_faces(
    faces: &[TrimmedSurface],
    points: &[DVec3],
    distance: f64,
    tolerance: f64,
) -> Result<FeatureResult, GeometryError> {
    checked(tolerance)?;
    if !distance.is_finite() {
        return Err(construction(
            WHAT,
            format!("the distance must be a finite number, got {distance}"),
        ));
    }
    let solid = Polyhedron::from_faces(faces, tolerance)?;
    let picked = picked_faces(&solid, points)?;
    let moved = replaned(
        &solid,
        |f| {
            let facet = &solid.faces[f];
            let shift = if picked.contains(&f) { distance } else { 0.0 };
            (facet.normal, facet.offset + shift)
        },
        tolerance,
        "the face moves further than the body allows",
    )?;
    closed_result(moved, tolerance * 10.0, picked.len(), "offset face")
}

/// The polyhedral solid `faces` with the faces nearest `points` drafted by `angle` (radians,
/// |angle| < 90°) about the lines where they meet the neutral plane through `origin` with
/// normal `pull` (the direction the part is pulled from its mould): a positive angle leans
/// each face in as it rises along `pull` (its normal turned toward `pull`), so the part
/// narrows away from the neutral plane. The neighbouring faces are extended or trimmed.
pub fn draft_faces(
    faces: &[TrimmedSurface],
    points: &[DVec3],
    angle: f64,
    (origin, pull): (DVec3, DVec3),
    tolerance: f64,
) -> Result<FeatureResult, GeometryError> {
    checked(tolerance)?;
    if !(angle.is_finite() && angle.abs() < 0.5 * std::f64::consts::PI - 1e-9) {
        return Err(construction(
            WHAT,
            format!("the draft angle must be a number between −90° and 90°, got {angle} rad"),
        ));
    }
    let pull = pull.normalize_or_zero();
    if pull == DVec3::ZERO || !origin.is_finite() || !pull.is_finite() {
        return Err(construction(
            WHAT,
            "the neutral plane needs a finite point and a direction",
        ));
    }
    let solid = Polyhedron::from_faces(faces, tolerance)?;
    let picked = picked_faces(&solid, points)?;
    let mut planes = Vec::with_capacity(solid.faces.len());
    for (f, facet) in solid.faces.iter().enumerate() {
        if !picked.contains(&f) {
            planes.push((facet.normal, facet.offset));
            continue;
        }
        // The hinge: where the face's plane meets the neutral plane.
        let n = facet.normal;
        let axis = n.cross(pull);
        if axis.length() < 1e-9 {
            return Err(construction(
                WHAT,
                format!("face {f} is parallel to the neutral plane; it has no draft"),
            ));
        }
        let axis = axis.normalize();
        // A point of both planes: on the line through origin's projection, in the face's
        // plane, along the direction in the neutral plane across the hinge.
        let across = pull.cross(axis);
        let t = (facet.offset - n.dot(origin)) / n.dot(across);
        let hinge = origin + across * t;
        let turned = DQuat::from_axis_angle(axis, angle) * n;
        planes.push((turned, turned.dot(hinge)));
    }
    let drafted = replaned(
        &solid,
        |f| planes[f],
        tolerance,
        "the draft tilts the face further than the body allows",
    )?;
    closed_result(drafted, tolerance * 10.0, picked.len(), "draft")
}
