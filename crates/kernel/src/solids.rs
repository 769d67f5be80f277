//! Primitive solids as closed shells of trimmed faces (outward normals): a block, a capped
//! cylinder and cone, a sphere and a torus, each exact (planes, and rational quadrics and the
//! torus from [`crate::construct`]). A solid's faces share their edges, so they join into one
//! closed shell ([`crate::join`]) and take part in booleans ([`crate::boolean`]).

use glam::{DAffine3, DVec3};

use crate::construct::{self, perpendicular_frame};
use crate::error::{GeometryError, construction};
use crate::planar::planar_face;
use crate::trim::TrimmedSurface;

/// The faces `faces` moved by `motion` (a rigid motion or a scale).
pub fn transformed(
    faces: &[TrimmedSurface],
    motion: &DAffine3,
) -> Result<Vec<TrimmedSurface>, GeometryError> {
    faces
        .iter()
        .map(|f| f.with_surface(f.surface().transformed(motion)?))
        .collect()
}

/// The block with corner `corner` and edges along x, y and z of lengths `size` (all > 0):
/// six planes, each over its whole domain.
pub fn block(corner: DVec3, size: DVec3) -> Result<Vec<TrimmedSurface>, GeometryError> {
    if !(size.min_element() > 0.0 && size.is_finite() && corner.is_finite()) {
        return Err(construction(
            "block",
            format!("the sides must be finite numbers above 0, got {size}"),
        ));
    }
    let (x, y, z) = (DVec3::X * size.x, DVec3::Y * size.y, DVec3::Z * size.z);
    let o = corner;
    // Each plane's u × v points out of the block.
    [
        (o, y, x),
        (o + z, x, y),
        (o, x, z),
        (o + y, z, x),
        (o, z, y),
        (o + x, y, z),
    ]
    .into_iter()
    .map(|(origin, u, v)| construct::plane(origin, u, v).map(TrimmedSurface::untrimmed))
    .collect()
}

/// The cone (or cylinder) side around the axis from `base` to `base + axis`, radius
/// `base_radius` at the base and `top_radius` at the top (0: an apex), capped by discs.
pub fn capped_cone(
    base: DVec3,
    axis: DVec3,
    base_radius: f64,
    top_radius: f64,
) -> Result<Vec<TrimmedSurface>, GeometryError> {
    let side = construct::cone(base, axis, base_radius, top_radius)?;
    let (x, _) = perpendicular_frame(axis);
    let n = axis.normalize();
    let mut faces = vec![TrimmedSurface::untrimmed(side)];
    let bottom = construct::circle(base, -n, x, base_radius)?;
    faces.push(planar_face(&[bottom])?);
    if top_radius > 0.0 {
        let top = construct::circle(base + axis, n, x, top_radius)?;
        faces.push(planar_face(&[top])?);
    }
    Ok(faces)
}

/// The cylinder of radius `radius` around the axis from `base` to `base + axis`, capped.
pub fn capped_cylinder(
    base: DVec3,
    axis: DVec3,
    radius: f64,
) -> Result<Vec<TrimmedSurface>, GeometryError> {
    capped_cone(base, axis, radius, radius)
}

/// The ball of radius `radius` around `center`: one closed face.
pub fn ball(center: DVec3, radius: f64) -> Result<Vec<TrimmedSurface>, GeometryError> {
    Ok(vec![TrimmedSurface::untrimmed(construct::sphere(
        center, radius,
    )?)])
}

/// The solid torus: one closed face.
pub fn solid_torus(
    center: DVec3,
    axis: DVec3,
    major: f64,
    minor: f64,
) -> Result<Vec<TrimmedSurface>, GeometryError> {
    Ok(vec![TrimmedSurface::untrimmed(construct::torus(
        center, axis, major, minor,
    )?)])
}
