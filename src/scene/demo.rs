//! The sample scene the editor opens on.

use std::f64::consts::TAU;

use glam::{DAffine3, DVec3};

use super::{ObjectGeometry, Scene, SceneObject};
use crate::kernel::{GeometryError, NurbsSurface, construct, samples};

impl Scene {
    /// The sample scene: the Utah teapot, an exact rational torus and sphere, a non-uniform
    /// B-spline surface of degree (2, 5), a loft and a surface of revolution, in two rows.
    pub fn demo() -> Result<Self, GeometryError> {
        let at = |x: f64, y: f64| DAffine3::from_translation(DVec3::new(x, y, 0.0));
        let teapot = samples::utah_teapot()?;
        let torus = construct::torus(DVec3::new(8.0, 0.0, 1.0), DVec3::Z, 2.0, 0.8)?;
        let sphere = construct::sphere(DVec3::new(15.0, 0.0, 2.0), 2.0)?;
        let sheet = wavy_bspline()?.transformed(&at(-2.5, 6.0))?;
        let loft = vase_loft()?.transformed(&at(8.0, 8.0))?;
        let goblet = goblet_revolution()?.transformed(&at(15.0, 8.0))?;
        let mut objects = vec![
            SceneObject::new("Utah teapot", ObjectGeometry::new(teapot)),
            SceneObject::new("Torus (rational)", ObjectGeometry::new(torus)),
            SceneObject::new("Sphere (rational)", ObjectGeometry::new(sphere)),
            SceneObject::new("B-spline (2, 5)", ObjectGeometry::new(sheet)),
            SceneObject::new("Loft", ObjectGeometry::new(loft)),
            SceneObject::new("Revolution", ObjectGeometry::new(goblet)),
        ];
        objects[0].segments = 12;
        Ok(Self {
            objects,
            unit: None,
        })
    }
}

/// A 7 × 9 non-rational B-spline sheet of degree (2, 5) over non-uniform knots. The double knot
/// u = 0.45 leaves the degree-2 direction only C0 there: a crease the curvature modes show.
fn wavy_bspline() -> Result<NurbsSurface, GeometryError> {
    let (nu, nv) = (7, 9);
    let mut points = Vec::with_capacity(nu * nv);
    for i in 0..nu {
        for j in 0..nv {
            let (x, y) = (i as f64 / (nu - 1) as f64, j as f64 / (nv - 1) as f64);
            let z = 0.9 * (x * 5.0).sin() * (y * 4.0).cos() + 0.6 * x * y;
            points.push(DVec3::new(5.0 * x, 4.0 * y, 1.0 + z));
        }
    }
    NurbsSurface::new(
        [2, 5],
        [
            vec![0.0, 0.0, 0.0, 0.2, 0.45, 0.45, 0.8, 1.0, 1.0, 1.0],
            vec![
                0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.3, 0.45, 0.7, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0,
            ],
        ],
        [nu, nv],
        points,
        None,
    )
}

/// A vase: four rational circles of varying radius and height, lofted with degree 3.
fn vase_loft() -> Result<NurbsSurface, GeometryError> {
    let sections = [(0.0, 1.2), (1.2, 2.0), (2.6, 0.9), (3.6, 1.4)]
        .iter()
        .map(|&(z, r)| construct::circle(DVec3::new(0.0, 0.0, z), DVec3::Z, DVec3::X, r))
        .collect::<Result<Vec<_>, _>>()?;
    construct::loft(&sections, 3)
}

/// A goblet: an interpolated cubic profile revolved a full turn about z.
fn goblet_revolution() -> Result<NurbsSurface, GeometryError> {
    let profile: Vec<DVec3> = [(1.3, 0.0), (0.3, 0.3), (0.25, 1.4), (1.2, 2.2), (1.7, 3.4)]
        .iter()
        .map(|&(r, z)| DVec3::new(r, 0.0, z))
        .collect();
    let curve = construct::interpolate(&profile, 3)?;
    construct::revolve(&curve, DVec3::ZERO, DVec3::Z, TAU)
}
