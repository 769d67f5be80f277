//! New objects from the kernel's constructors, with the few parameters the Create dialog asks
//! for. Curve-based surfaces (revolve, extrude, loft, Coons, Gordon, sweep) use built-in
//! profiles scaled by the parameters.

use crate::kernel::subdiv::{SubdivisionSurface, cages};
use std::f64::consts::TAU;

use glam::DVec3;

use crate::kernel::transfinite::{self, HermiteData};
use crate::kernel::{Direction, GeometryError, NurbsSurface, construct};
use crate::scene::{ObjectGeometry, SceneObject};

/// What the Create dialog can make.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Primitive {
    Plane,
    Cylinder,
    Cone,
    Sphere,
    Torus,
    Revolve,
    Extrude,
    Loft,
    Coons,
    BicubicCoons,
    Gordon,
    Hermite,
    Sweep,
    BezierPatch,
    TriangleBezier,
    CageCube,
    CageCylinder,
    CageTorus,
    CageGrid,
    CageIcosahedron,
}

impl Primitive {
    pub const ALL: [Primitive; 20] = [
        Primitive::Plane,
        Primitive::Cylinder,
        Primitive::Cone,
        Primitive::Sphere,
        Primitive::Torus,
        Primitive::Revolve,
        Primitive::Extrude,
        Primitive::Loft,
        Primitive::Coons,
        Primitive::BicubicCoons,
        Primitive::Gordon,
        Primitive::Hermite,
        Primitive::Sweep,
        Primitive::BezierPatch,
        Primitive::TriangleBezier,
        Primitive::CageCube,
        Primitive::CageCylinder,
        Primitive::CageTorus,
        Primitive::CageGrid,
        Primitive::CageIcosahedron,
    ];

    pub fn label(self) -> &'static str {
        match self {
            Primitive::Plane => "Plane",
            Primitive::Cylinder => "Cylinder",
            Primitive::Cone => "Cone",
            Primitive::Sphere => "Sphere",
            Primitive::Torus => "Torus",
            Primitive::Revolve => "Revolve (vase profile)",
            Primitive::Extrude => "Extrude (wave curve)",
            Primitive::Loft => "Loft (three circles)",
            Primitive::Coons => "Coons patch",
            Primitive::BicubicCoons => "Coons patch with tangents (bicubic)",
            Primitive::Gordon => "Gordon surface (4 × 3 curve network)",
            Primitive::Hermite => "Hermite patch (corner tangents and twists)",
            Primitive::Sweep => "Sweep (circle along an arc)",
            Primitive::BezierPatch => "Bézier patch",
            Primitive::TriangleBezier => "Triangular Bézier patch",
            Primitive::CageCube => "Subdivision cube",
            Primitive::CageCylinder => "Subdivision cylinder",
            Primitive::CageTorus => "Subdivision torus (48 × 32)",
            Primitive::CageGrid => "Subdivision grid (8 × 8)",
            Primitive::CageIcosahedron => "Subdivision icosahedron (triangles, √3)",
        }
    }
}

/// A degree-(4, 4) Bézier hill of width `size` around `center`, `ratio` setting its height:
/// the surface whose curves the Gordon and bicubic Coons examples take.
fn wavy_hill(center: DVec3, size: f64, ratio: f64) -> Result<NurbsSurface, GeometryError> {
    let mut points = Vec::with_capacity(25);
    for i in 0..=4 {
        for j in 0..=4 {
            let (x, y) = (i as f64 / 4.0, j as f64 / 4.0);
            let z = (std::f64::consts::PI * x).sin() * (TAU * y).cos() + 0.5 * (x - y);
            points.push(center + DVec3::new((x - 0.5) * size, (y - 0.5) * size, z * ratio * size));
        }
    }
    NurbsSurface::bezier([4, 4], points, None)
}

/// A degree-n triangular Bézier dome over an equilateral triangle of side `size` around
/// `center`: b_ijk over the triangle's point (i A + j B + k C)/n, raised by
/// 3 ratio size (ij + jk + ki)/n² (flat edges' ends, curved inside).
fn triangle_dome(
    center: DVec3,
    size: f64,
    ratio: f64,
    degree: usize,
) -> Result<crate::kernel::triangle::TriangleBezier, GeometryError> {
    let n = degree.max(1);
    let corner = |k: f64| {
        let a = TAU * k / 3.0 + TAU / 4.0;
        center + DVec3::new(a.cos(), a.sin(), 0.0) * size / 3f64.sqrt()
    };
    let (a, b, c) = (corner(0.0), corner(1.0), corner(2.0));
    let nf = n as f64;
    let mut points = Vec::with_capacity((n + 1) * (n + 2) / 2);
    for j in 0..=n {
        for i in 0..=n - j {
            let k = n - i - j;
            let (x, y, z) = (i as f64, j as f64, k as f64);
            let lift = 3.0 * ratio * size * (x * y + y * z + z * x) / (nf * nf);
            points.push((a * x + b * y + c * z) / nf + DVec3::Z * lift);
        }
    }
    crate::kernel::triangle::TriangleBezier::new(n, points)
}

/// The Create dialog's parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PrimitiveParams {
    pub kind: Primitive,
    pub center: DVec3,
    /// Overall size: width, radius or major radius.
    pub size: f64,
    /// Height (cylinder, cone, extrude, loft), or the second radius (cone top, torus minor),
    /// as a fraction of `size` where it is a ratio.
    pub height: f64,
    pub ratio: f64,
    /// Degrees of a Bézier patch.
    pub degree: [usize; 2],
}

impl Default for PrimitiveParams {
    fn default() -> Self {
        Self {
            kind: Primitive::Sphere,
            center: DVec3::ZERO,
            size: 2.0,
            height: 3.0,
            ratio: 0.35,
            degree: [3, 3],
        }
    }
}

/// The level a new cage is shown at.
pub const DEFAULT_CAGE_LEVEL: u32 = 3;

impl PrimitiveParams {
    /// Builds the object, named after the primitive. Bad parameters give the kernel's error.
    pub fn build(&self) -> Result<SceneObject, GeometryError> {
        let c = self.center;
        let (s, h, r) = (self.size, self.height, self.ratio);
        let cage = match self.kind {
            Primitive::CageCube => Some(cages::cube(c, s)?),
            Primitive::CageCylinder => Some(cages::cylinder(c, s, h, 8, 3)?),
            Primitive::CageTorus => Some(cages::torus(c, s, s * r, 48, 32)?),
            Primitive::CageGrid => Some(cages::grid(c, s, 8)?),
            Primitive::CageIcosahedron => Some(cages::icosahedron(c, s)?),
            _ => None,
        };
        if self.kind == Primitive::TriangleBezier {
            return Ok(SceneObject::new(
                "Triangular Bézier patch",
                ObjectGeometry::boxed(Box::new(triangle_dome(c, s, r, self.degree[0])?)),
            ));
        }
        if let Some(mesh) = cage {
            let surface = if self.kind == Primitive::CageIcosahedron {
                let options = crate::kernel::subdiv::Options {
                    scheme: crate::kernel::subdiv::Scheme::Sqrt3,
                    ..Default::default()
                };
                SubdivisionSurface::new(mesh, Vec::new(), Vec::new(), options, DEFAULT_CAGE_LEVEL)?
            } else {
                SubdivisionSurface::from_mesh(mesh, DEFAULT_CAGE_LEVEL)?
            };
            let name = self.kind.label().split(" (").next().unwrap_or("Cage");
            return Ok(SceneObject::new(
                name,
                ObjectGeometry::new(crate::scene::SubdivObject::from(surface)),
            ));
        }
        let circle = |z: f64, radius: f64| {
            construct::circle(c + DVec3::new(0.0, 0.0, z), DVec3::Z, DVec3::X, radius)
        };
        let surface: NurbsSurface = match self.kind {
            Primitive::Plane => {
                construct::plane(c - DVec3::new(s, s, 0.0) * 0.5, DVec3::X * s, DVec3::Y * s)?
            }
            Primitive::Cylinder => construct::cylinder(c, DVec3::Z * h, s)?,
            Primitive::Cone => construct::cone(c, DVec3::Z * h, s, s * r)?,
            Primitive::Sphere => construct::sphere(c, s)?,
            Primitive::Torus => construct::torus(c, DVec3::Z, s, s * r)?,
            Primitive::Revolve => {
                let profile: Vec<DVec3> = [(1.0, 0.0), (0.6, 0.35), (0.9, 0.7), (0.5, 1.0)]
                    .iter()
                    .map(|&(x, z)| DVec3::new(x * s, 0.0, z * h))
                    .collect();
                let curve = construct::interpolate(&profile, 3)?;
                construct::revolve(&curve, c, DVec3::Z, TAU)?
            }
            Primitive::Extrude => {
                let wave: Vec<DVec3> = (0..6)
                    .map(|k| {
                        let x = k as f64 / 5.0;
                        c + DVec3::new(x * s, 0.25 * s * (x * TAU).sin(), 0.0)
                    })
                    .collect();
                construct::extrude(&construct::interpolate(&wave, 3)?, DVec3::Z * h)?
            }
            Primitive::Loft => {
                let sections = [
                    circle(0.0, s)?,
                    circle(0.5 * h, s * r.max(0.05))?,
                    circle(h, s)?,
                ];
                construct::loft(&sections, 2)?
            }
            Primitive::Coons => {
                let edge = |a: DVec3, m: DVec3, b: DVec3| {
                    construct::interpolate(&[c + a * s, c + m * s, c + b * s], 2)
                };
                construct::coons(
                    &edge(
                        DVec3::ZERO,
                        DVec3::new(0.5, 0.0, r),
                        DVec3::new(1.0, 0.0, 0.0),
                    )?,
                    &edge(
                        DVec3::new(0.0, 1.0, 0.0),
                        DVec3::new(0.5, 1.0, -r),
                        DVec3::new(1.0, 1.0, 0.0),
                    )?,
                    &edge(
                        DVec3::ZERO,
                        DVec3::new(0.0, 0.5, r),
                        DVec3::new(0.0, 1.0, 0.0),
                    )?,
                    &edge(
                        DVec3::new(1.0, 0.0, 0.0),
                        DVec3::new(1.0, 0.5, -r),
                        DVec3::new(1.0, 1.0, 0.0),
                    )?,
                )?
            }
            Primitive::BicubicCoons => {
                let hill = wavy_hill(c, s, r)?;
                let side = |direction, value, order| hill.isocurve(direction, value, order);
                let (u, v) = (Direction::U, Direction::V);
                transfinite::bicubic_coons(
                    [
                        &side(v, 0.0, 0)?,
                        &side(v, 1.0, 0)?,
                        &side(u, 0.0, 0)?,
                        &side(u, 1.0, 0)?,
                    ],
                    [
                        &side(v, 0.0, 1)?,
                        &side(v, 1.0, 1)?,
                        &side(u, 0.0, 1)?,
                        &side(u, 1.0, 1)?,
                    ],
                )?
            }
            Primitive::Gordon => {
                let hill = wavy_hill(c, s, r)?;
                let u_curves = [0.0, 0.3, 0.7, 1.0]
                    .map(|v| hill.isocurve(Direction::V, v, 0))
                    .into_iter()
                    .collect::<Result<Vec<_>, _>>()?;
                let v_curves = [0.0, 0.5, 1.0]
                    .map(|u| hill.isocurve(Direction::U, u, 0))
                    .into_iter()
                    .collect::<Result<Vec<_>, _>>()?;
                transfinite::gordon(&u_curves, &v_curves, 3)?
            }
            Primitive::Hermite => {
                let corner = |x: f64, y: f64| c + DVec3::new((x - 0.5) * s, (y - 0.5) * s, 0.0);
                let lift = DVec3::Z * (s * r * 3.0);
                transfinite::hermite_patch(&HermiteData {
                    points: [
                        corner(0.0, 0.0),
                        corner(1.0, 0.0),
                        corner(0.0, 1.0),
                        corner(1.0, 1.0),
                    ],
                    su: [
                        DVec3::X * s + lift,
                        DVec3::X * s - lift,
                        DVec3::X * s - lift,
                        DVec3::X * s + lift,
                    ],
                    sv: [
                        DVec3::Y * s + lift,
                        DVec3::Y * s + lift,
                        DVec3::Y * s - lift,
                        DVec3::Y * s - lift,
                    ],
                    twist: [DVec3::ZERO; 4],
                })?
            }
            Primitive::Sweep => {
                let profile = construct::circle(c, DVec3::X, DVec3::Y, s * r)?;
                let rail_points: Vec<DVec3> = (0..5)
                    .map(|k| {
                        let t = k as f64 / 4.0 * std::f64::consts::PI;
                        c + DVec3::new(0.0, s * (1.0 - t.cos()), h * t.sin() * 0.5)
                    })
                    .collect();
                construct::sweep(&profile, &construct::interpolate(&rail_points, 3)?, 12)?
            }
            Primitive::BezierPatch => {
                let flat = construct::flat_bezier_patch(self.degree, s, s)?;
                flat.transformed(&glam::DAffine3::from_translation(
                    c - DVec3::new(s, s, 0.0) * 0.5,
                ))?
            }
            Primitive::TriangleBezier
            | Primitive::CageCube
            | Primitive::CageCylinder
            | Primitive::CageTorus
            | Primitive::CageGrid
            | Primitive::CageIcosahedron => {
                return Err(GeometryError::Construction {
                    what: "cage",
                    message: "built above".into(),
                });
            }
        };
        let name = match self.kind {
            Primitive::BezierPatch => {
                format!("Bézier patch ({}, {})", self.degree[0], self.degree[1])
            }
            Primitive::BicubicCoons => "Bicubic Coons".to_string(),
            kind => kind
                .label()
                .split(' ')
                .next()
                .unwrap_or("Object")
                .to_string(),
        };
        Ok(SceneObject::new(name, ObjectGeometry::new(surface)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_primitive_builds_with_the_defaults_and_decomposes() {
        for kind in Primitive::ALL {
            let params = PrimitiveParams {
                kind,
                ..Default::default()
            };
            let object = params.build().unwrap_or_else(|e| panic!("{kind:?}: {e}"));
            object.decompose().unwrap();
        }
        // The sphere is a sphere: every control-net-independent sample lies at the radius.
        let sphere = PrimitiveParams::default().build().unwrap();
        let Some(s) = sphere
            .geometry
            .downcast_ref::<crate::kernel::NurbsSurface>()
        else {
            unreachable!()
        };
        let p = s.point_at(0.3, 0.6).unwrap();
        assert!((p.length() - 2.0).abs() < 1e-12);
        let bad = PrimitiveParams {
            size: -1.0,
            ..Default::default()
        };
        assert!(bad.build().is_err());
    }
}
