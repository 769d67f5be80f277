//! New objects from the kernel's constructors, with the few parameters the Create dialog asks
//! for. Curve-based surfaces (revolve, extrude, loft, Coons, Gordon, sweep) use built-in
//! profiles scaled by the parameters.

use crate::kernel::subdiv::{Scheme, SubdivisionSurface, cages};
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
    SolidBox,
    SolidCylinder,
    SolidCone,
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
    pub const ALL: [Primitive; 23] = [
        Primitive::Plane,
        Primitive::Cylinder,
        Primitive::Cone,
        Primitive::Sphere,
        Primitive::Torus,
        Primitive::SolidBox,
        Primitive::SolidCylinder,
        Primitive::SolidCone,
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

    /// What the height and the ratio mean for this primitive, where it uses them (the Create
    /// window shows only the fields that apply).
    pub fn fields(self) -> (Option<&'static str>, Option<&'static str>) {
        use Primitive::*;
        match self {
            Cylinder | Revolve | Extrude | CageCylinder | SolidBox | SolidCylinder => {
                (Some("height"), None)
            }
            Cone | SolidCone => (Some("height"), Some("top radius (× radius)")),
            Loft => (Some("height"), Some("waist (× radius)")),
            Sweep => (Some("height"), Some("profile radius (× size)")),
            Torus | CageTorus => (None, Some("minor radius (× major)")),
            Coons => (None, Some("edge bulge (× size)")),
            BicubicCoons | Gordon => (None, Some("wave height (× size)")),
            Hermite => (None, Some("corner lift (× size)")),
            TriangleBezier => (None, Some("dome height (× size)")),
            Plane | Sphere | BezierPatch | CageCube | CageGrid | CageIcosahedron => (None, None),
        }
    }

    pub fn label(self) -> &'static str {
        match self {
            Primitive::Plane => "Plane",
            Primitive::Cylinder => "Cylinder",
            Primitive::Cone => "Cone",
            Primitive::Sphere => "Sphere",
            Primitive::Torus => "Torus",
            Primitive::SolidBox => "Box (solid; size is its width)",
            Primitive::SolidCylinder => "Cylinder (solid, capped)",
            Primitive::SolidCone => "Cone (solid, capped)",
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

/// `faces` as one closed polysurface, joined within 1e-6 of `size`.
fn solid(
    faces: Vec<crate::kernel::TrimmedSurface>,
    size: f64,
) -> Result<ObjectGeometry, GeometryError> {
    Ok(ObjectGeometry::new(
        crate::scene::polysurface::Polysurface::new(faces, 1e-6 * size)?,
    ))
}

/// The level a new cage is shown at.
pub const DEFAULT_CAGE_LEVEL: u32 = 3;

impl PrimitiveParams {
    /// Builds the object, named after the primitive. Bad parameters give the kernel's error.
    pub fn build(&self) -> Result<SceneObject, GeometryError> {
        let (c, s, h, r) = (self.center, self.size, self.height, self.ratio);
        let nurbs = |surface: NurbsSurface| ObjectGeometry::new(surface);
        let geometry = match self.kind {
            Primitive::TriangleBezier => {
                ObjectGeometry::boxed(Box::new(triangle_dome(c, s, r, self.degree[0])?))
            }
            Primitive::CageCube => subdivided(cages::cube(c, s)?, Scheme::CatmullClark)?,
            Primitive::CageCylinder => {
                subdivided(cages::cylinder(c, s, h, 8, 3)?, Scheme::CatmullClark)?
            }
            Primitive::CageTorus => {
                subdivided(cages::torus(c, s, s * r, 48, 32)?, Scheme::CatmullClark)?
            }
            Primitive::CageGrid => subdivided(cages::grid(c, s, 8)?, Scheme::CatmullClark)?,
            Primitive::CageIcosahedron => subdivided(cages::icosahedron(c, s)?, Scheme::Sqrt3)?,
            Primitive::Plane => nurbs(construct::plane(
                c - DVec3::new(s, s, 0.0) * 0.5,
                DVec3::X * s,
                DVec3::Y * s,
            )?),
            Primitive::Cylinder => nurbs(construct::cylinder(c, DVec3::Z * h, s)?),
            Primitive::Cone => nurbs(construct::cone(c, DVec3::Z * h, s, s * r)?),
            Primitive::Sphere => nurbs(construct::sphere(c, s)?),
            Primitive::Torus => nurbs(construct::torus(c, DVec3::Z, s, s * r)?),
            // Closed polysurfaces, solids that booleans take, joined within 1e-6 of their size.
            Primitive::SolidBox => solid(
                crate::kernel::solids::block(c - DVec3::new(s, s, 0.0) * 0.5, DVec3::new(s, s, h))?,
                s.max(h),
            )?,
            Primitive::SolidCylinder => solid(
                crate::kernel::solids::capped_cylinder(c, DVec3::Z * h, s)?,
                s.max(h),
            )?,
            Primitive::SolidCone => solid(
                crate::kernel::solids::capped_cone(c, DVec3::Z * h, s, s * r)?,
                s.max(h),
            )?,
            Primitive::Revolve => nurbs(self.revolved()?),
            Primitive::Extrude => nurbs(self.extruded()?),
            Primitive::Loft => nurbs(self.lofted()?),
            Primitive::Coons => nurbs(self.coons()?),
            Primitive::BicubicCoons => nurbs(self.bicubic_coons()?),
            Primitive::Gordon => nurbs(self.gordon()?),
            Primitive::Hermite => nurbs(self.hermite()?),
            Primitive::Sweep => nurbs(self.swept()?),
            Primitive::BezierPatch => nurbs(
                construct::flat_bezier_patch(self.degree, s, s)?.transformed(
                    &glam::DAffine3::from_translation(c - DVec3::new(s, s, 0.0) * 0.5),
                )?,
            ),
        };
        Ok(SceneObject::new(self.name(), geometry))
    }

    /// The new object's name: the primitive's, with a Bézier patch's degrees.
    fn name(&self) -> String {
        let label = self.kind.label();
        match self.kind {
            Primitive::TriangleBezier => "Triangular Bézier patch".to_owned(),
            Primitive::BezierPatch => {
                format!("Bézier patch ({}, {})", self.degree[0], self.degree[1])
            }
            Primitive::BicubicCoons => "Bicubic Coons".to_owned(),
            Primitive::CageCube
            | Primitive::CageCylinder
            | Primitive::CageTorus
            | Primitive::CageGrid
            | Primitive::CageIcosahedron => label.split(" (").next().unwrap_or("Cage").to_owned(),
            _ => label.split(' ').next().unwrap_or("Object").to_owned(),
        }
    }

    /// A vase: an interpolated profile revolved a full turn about z (The NURBS Book A8.1).
    fn revolved(&self) -> Result<NurbsSurface, GeometryError> {
        let (s, h) = (self.size, self.height);
        let profile: Vec<DVec3> = [(1.0, 0.0), (0.6, 0.35), (0.9, 0.7), (0.5, 1.0)]
            .iter()
            .map(|&(x, z)| DVec3::new(x * s, 0.0, z * h))
            .collect();
        let curve = construct::interpolate(&profile, 3)?;
        construct::revolve(&curve, self.center, DVec3::Z, TAU)
    }

    /// A wave extruded along z.
    fn extruded(&self) -> Result<NurbsSurface, GeometryError> {
        let (c, s) = (self.center, self.size);
        let wave: Vec<DVec3> = (0..6)
            .map(|k| {
                let x = k as f64 / 5.0;
                c + DVec3::new(x * s, 0.25 * s * (x * TAU).sin(), 0.0)
            })
            .collect();
        construct::extrude(&construct::interpolate(&wave, 3)?, DVec3::Z * self.height)
    }

    /// Three circles lofted, the middle one narrowed by the ratio.
    fn lofted(&self) -> Result<NurbsSurface, GeometryError> {
        let (c, s, h) = (self.center, self.size, self.height);
        let circle = |z: f64, radius: f64| {
            construct::circle(c + DVec3::new(0.0, 0.0, z), DVec3::Z, DVec3::X, radius)
        };
        let sections = [
            circle(0.0, s)?,
            circle(0.5 * h, s * self.ratio.max(0.05))?,
            circle(h, s)?,
        ];
        construct::loft(&sections, 2)
    }

    /// A bilinearly blended Coons patch between four arched quadratic edges.
    fn coons(&self) -> Result<NurbsSurface, GeometryError> {
        let (c, s, r) = (self.center, self.size, self.ratio);
        let edge = |a: DVec3, m: DVec3, b: DVec3| {
            construct::interpolate(&[c + a * s, c + m * s, c + b * s], 2)
        };
        let (x, y) = (DVec3::X, DVec3::Y);
        construct::coons(
            &edge(DVec3::ZERO, DVec3::new(0.5, 0.0, r), x)?,
            &edge(y, DVec3::new(0.5, 1.0, -r), x + y)?,
            &edge(DVec3::ZERO, DVec3::new(0.0, 0.5, r), y)?,
            &edge(x, DVec3::new(1.0, 0.5, -r), x + y)?,
        )
    }

    /// The bicubically blended Coons patch of a wavy hill's boundary curves and cross-boundary
    /// derivatives.
    fn bicubic_coons(&self) -> Result<NurbsSurface, GeometryError> {
        let hill = wavy_hill(self.center, self.size, self.ratio)?;
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
        )
    }

    /// The Gordon surface of a wavy hill's 4 × 3 isocurve network.
    fn gordon(&self) -> Result<NurbsSurface, GeometryError> {
        let hill = wavy_hill(self.center, self.size, self.ratio)?;
        let u_curves = [0.0, 0.3, 0.7, 1.0]
            .map(|v| hill.isocurve(Direction::V, v, 0))
            .into_iter()
            .collect::<Result<Vec<_>, _>>()?;
        let v_curves = [0.0, 0.5, 1.0]
            .map(|u| hill.isocurve(Direction::U, u, 0))
            .into_iter()
            .collect::<Result<Vec<_>, _>>()?;
        transfinite::gordon(&u_curves, &v_curves, 3)
    }

    /// A bicubic Hermite patch over a square, its corner tangents tilted up and down by the
    /// ratio.
    fn hermite(&self) -> Result<NurbsSurface, GeometryError> {
        let (c, s) = (self.center, self.size);
        let corner = |x: f64, y: f64| c + DVec3::new((x - 0.5) * s, (y - 0.5) * s, 0.0);
        let lift = DVec3::Z * (s * self.ratio * 3.0);
        let (su, sv) = (DVec3::X * s, DVec3::Y * s);
        transfinite::hermite_patch(&HermiteData {
            points: [
                corner(0.0, 0.0),
                corner(1.0, 0.0),
                corner(0.0, 1.0),
                corner(1.0, 1.0),
            ],
            su: [su + lift, su - lift, su - lift, su + lift],
            sv: [sv + lift, sv + lift, sv - lift, sv - lift],
            twist: [DVec3::ZERO; 4],
        })
    }

    /// A circle swept along an arched rail.
    fn swept(&self) -> Result<NurbsSurface, GeometryError> {
        let (c, s, h) = (self.center, self.size, self.height);
        let profile = construct::circle(c, DVec3::X, DVec3::Y, s * self.ratio)?;
        let rail_points: Vec<DVec3> = (0..5)
            .map(|k| {
                let t = k as f64 / 4.0 * std::f64::consts::PI;
                c + DVec3::new(0.0, s * (1.0 - t.cos()), h * t.sin() * 0.5)
            })
            .collect();
        construct::sweep(&profile, &construct::interpolate(&rail_points, 3)?, 12)
    }
}

/// A cage shown as a subdivision surface of `scheme` at [`DEFAULT_CAGE_LEVEL`].
fn subdivided(
    mesh: crate::kernel::PolygonMesh,
    scheme: Scheme,
) -> Result<ObjectGeometry, GeometryError> {
    let options = crate::kernel::subdiv::Options {
        scheme,
        ..Default::default()
    };
    let surface =
        SubdivisionSurface::new(mesh, Vec::new(), Vec::new(), options, DEFAULT_CAGE_LEVEL)?;
    Ok(ObjectGeometry::new(crate::scene::SubdivObject::from(
        surface,
    )))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_create_window_shows_exactly_the_fields_that_change_the_primitive() {
        for kind in Primitive::ALL {
            let base = PrimitiveParams {
                kind,
                ..Default::default()
            };
            let built = base.build().unwrap();
            let (height, ratio) = kind.fields();
            let taller = PrimitiveParams {
                height: base.height * 1.5,
                ..base
            };
            let other = PrimitiveParams {
                ratio: base.ratio * 0.6,
                ..base
            };
            let label = kind.label();
            assert_eq!(
                taller.build().unwrap() != built,
                height.is_some(),
                "{label}: height"
            );
            assert_eq!(
                other.build().unwrap() != built,
                ratio.is_some(),
                "{label}: ratio"
            );
        }
    }

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
        let Some(s) = sphere.kind().nurbs_surface() else {
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
