//! NURBS surfaces (every degree, knots and weights) as a scene object kind. They reach the GPU
//! as their Bézier patches (The NURBS Book A5.7); an edit re-derives only the patches in the
//! moved point's local support.

use glam::{DAffine3, DVec3};

use super::json::{self, FormatError, Geometry, NamedGeometry};
use super::kind::KindFace;
use super::record::KindEntry;
use super::{Decomposition, ObjectGeometry, ObjectKind, SceneObject};
use crate::kernel::tess::{self, Tessellation, TriangleMesh};
use crate::kernel::{Direction, GeometryError, NurbsSurface, TrimmedSurface};

impl ObjectKind for NurbsSurface {
    fn kind_name(&self) -> &'static str {
        "a NURBS surface"
    }

    fn describe(&self) -> String {
        let [p, q] = self.degree();
        let [nu, nv] = self.count();
        let kind = if self.is_polynomial() {
            "B-spline"
        } else {
            "NURBS"
        };
        format!("{kind} degree ({p}, {q}), {nu} × {nv} points")
    }

    fn control_point_count(&self) -> usize {
        self.homogeneous_points().len()
    }

    /// The net row by row (i along u, j along v), index i · nv + j.
    fn control_points(&self) -> Vec<DVec3> {
        let [nu, nv] = self.count();
        (0..nu)
            .flat_map(|i| (0..nv).map(move |j| self.control_point(i, j)))
            .collect()
    }

    fn weights(&self) -> Vec<f64> {
        self.homogeneous_points().iter().map(|h| h.w).collect()
    }

    fn net_lines(&self) -> Vec<u32> {
        let [nu, nv] = self.count();
        let index = |i: usize, j: usize| (i * nv + j) as u32;
        let mut lines = Vec::new();
        for i in 0..nu {
            for j in 0..nv {
                if i + 1 < nu {
                    lines.extend([index(i, j), index(i + 1, j)]);
                }
                if j + 1 < nv {
                    lines.extend([index(i, j), index(i, j + 1)]);
                }
            }
        }
        lines
    }

    fn net_grid(&self) -> Option<[usize; 2]> {
        Some(self.count())
    }

    fn bounds(&self) -> Option<(DVec3, DVec3)> {
        Some(NurbsSurface::bounds(self))
    }

    /// The changed patches are the point's local support
    /// ([`NurbsSurface::patches_supported_by`]).
    fn move_control_point(
        &mut self,
        index: usize,
        position: DVec3,
    ) -> Result<Vec<usize>, GeometryError> {
        let nv = self.count()[1];
        let (i, j) = (index / nv, index % nv);
        self.set_point(i, j, position)?;
        Ok(self.patches_supported_by(i, j))
    }

    fn set_weight(&mut self, index: usize, weight: f64) -> Result<(), GeometryError> {
        let nv = self.count()[1];
        NurbsSurface::set_weight(self, index / nv, index % nv, weight)
    }

    /// The Bézier patches ([`NurbsSurface::to_bezier_patch_set`]) and their spans.
    fn gpu_feed(&self) -> Result<Decomposition, GeometryError> {
        let set = self.to_bezier_patch_set()?;
        let bu = self.span_breaks(Direction::U);
        let bv = self.span_breaks(Direction::V);
        let domains = bu
            .windows(2)
            .flat_map(|wu| bv.windows(2).map(move |wv| [wu[0], wu[1], wv[0], wv[1]]))
            .collect();
        Ok(Decomposition {
            set,
            domains,
            ..Default::default()
        })
    }

    /// The surface itself (The NURBS Book A4.1) at the point of span `patch` (spans in u-major
    /// order, as the feed's patches).
    fn surface_point(&self, patch: usize, s: f64, t: f64) -> Result<DVec3, GeometryError> {
        let bu = self.span_breaks(Direction::U);
        let bv = self.span_breaks(Direction::V);
        let columns = bv.len().saturating_sub(1).max(1);
        let (i, j) = (patch / columns, patch % columns);
        let (Some(u), Some(v)) = (bu.get(i..i + 2), bv.get(j..j + 2)) else {
            return Err(GeometryError::NoSuchPatch {
                patch,
                count: (bu.len().saturating_sub(1)) * (bv.len().saturating_sub(1)),
            });
        };
        self.point_at(u[0] + (u[1] - u[0]) * s, v[0] + (v[1] - v[0]) * t)
    }

    /// Each named patch is re-derived from its span's own points and knots
    /// ([`NurbsSurface::bezier_patch_points`]).
    fn update_gpu_feed(
        &self,
        feed: &mut Decomposition,
        patches: &[usize],
    ) -> Result<(), GeometryError> {
        for &k in patches {
            let points = self.bezier_patch_points(k)?;
            let indices = feed
                .set
                .patches()
                .get(k)
                .ok_or(GeometryError::NoSuchPatch {
                    patch: k,
                    count: feed.set.patches().len(),
                })?
                .indices()
                .to_vec();
            for (&index, h) in indices.iter().zip(points) {
                feed.set.set_point(index as usize, h.truncate() / h.w)?;
                feed.set.set_weight(index as usize, h.w)?;
            }
        }
        Ok(())
    }

    /// One tensor grid over the whole domain ([`tess::grid_for`]).
    fn tessellate(
        &self,
        tessellation: Tessellation,
        curvature: bool,
    ) -> Result<Vec<TriangleMesh>, GeometryError> {
        self.tessellate_with(tessellation, curvature, &tess::KernelGrids)
    }

    fn plan_tessellation(
        &self,
        tessellation: Tessellation,
        curvature: bool,
    ) -> Result<tess::GridPlan, GeometryError> {
        let grid = tess::grid_for(self, tessellation)?;
        Ok(tess::GridPlan::triangulate(
            vec![(self.clone(), grid)],
            curvature,
        ))
    }

    fn estimated_triangles(
        &self,
        tessellation: Tessellation,
        how: tess::Estimate,
    ) -> Result<usize, GeometryError> {
        tess::estimated_triangles(self, tessellation, how)
    }

    fn faces(&self) -> Vec<KindFace<'_>> {
        vec![KindFace::whole(self)]
    }

    fn transformed(&self, transform: &DAffine3) -> Result<ObjectGeometry, GeometryError> {
        NurbsSurface::transformed(self, transform).map(ObjectGeometry::new)
    }

    fn bake_lattice(
        &self,
        lattice: &crate::kernel::ffd::Lattice,
        tolerance: f64,
    ) -> Result<(ObjectGeometry, crate::kernel::ffd::Baked), GeometryError> {
        let (surface, baked) = super::ffd::bake_nurbs(self, lattice, tolerance)?;
        Ok((ObjectGeometry::new(surface), baked))
    }

    fn same_layout(&self, other: &ObjectGeometry) -> bool {
        other
            .downcast_ref::<NurbsSurface>()
            .is_some_and(|b| same_net(self, b))
    }

    fn displacement_domain(&self) -> Option<[f64; 4]> {
        let [(u0, u1), (v0, v1)] = self.domain();
        Some([u0, u1, v0, v1])
    }

    fn nurbs_surface(&self) -> Option<&NurbsSurface> {
        Some(self)
    }

    fn cage(&self) -> Option<&crate::kernel::PolygonMesh> {
        None
    }

    fn record(&self) -> serde_json::Value {
        surface_record(Geometry::Surface(self.clone()))
    }
}

/// A NURBS surface's record, with its trim loops where it has them (knotwork's JSON for
/// surfaces, [`super::json`], with homogeneous points so that a rational surface reads back
/// bit for bit).
pub(super) fn surface_record(geometry: Geometry) -> serde_json::Value {
    json::object_value(
        &NamedGeometry {
            name: None,
            geometry,
        },
        true,
    )
}

/// NURBS surfaces, trimmed ones included (a record with `"trims"` reads as a trimmed surface).
pub(super) const ENTRY: KindEntry = KindEntry {
    record_type: "nurbs_surface",
    read: read_record,
    examples,
};

fn read_record(path: &str, record: serde_json::Value) -> Result<ObjectGeometry, FormatError> {
    match json::object_from_value(path, record)?.geometry {
        Geometry::Surface(s) => Ok(ObjectGeometry::new(s)),
        Geometry::TrimmedSurface(t) => Ok(ObjectGeometry::from_trimmed(t)),
        Geometry::Curve(_) | Geometry::Trim(_) => Err(FormatError::new(
            format!("{path}.type"),
            "a curve is not a scene object: knotwork projects hold surfaces",
        )),
    }
}

/// A rational surface of degree (3, 2) on uneven knots (6 × 5 points, weights 0.4 to 1.6).
fn example_surface() -> Result<NurbsSurface, GeometryError> {
    let (nu, nv) = (6, 5);
    let knots_u = vec![0.0, 0.0, 0.0, 0.0, 0.3, 0.55, 1.0, 1.0, 1.0, 1.0];
    let knots_v = vec![0.0, 0.0, 0.0, 0.4, 0.7, 1.0, 1.0, 1.0];
    let mut points = Vec::with_capacity(nu * nv);
    let mut weights = Vec::with_capacity(nu * nv);
    for i in 0..nu {
        for j in 0..nv {
            let (x, y) = (i as f64, j as f64);
            points.push(DVec3::new(x, y, 0.6 * (1.3 * x).sin() * (0.9 * y).cos()));
            weights.push(1.0 + 0.6 * (2.1 * x + 1.7 * y).sin());
        }
    }
    NurbsSurface::new([3, 2], [knots_u, knots_v], [nu, nv], points, Some(weights))
}

/// The rational surface alone, and kept inside an ellipse about its domain's centre (patches
/// outside culled, the ones it crosses trimmed per fragment).
fn examples() -> Vec<SceneObject> {
    let Ok(surface) = example_surface() else {
        return Vec::new();
    };
    let mut plain = SceneObject::new("rational (3, 2)", ObjectGeometry::new(surface.clone()));
    plain.segments = 7;
    let ellipse = crate::kernel::trim::shapes::ellipse(
        glam::DVec2::new(0.5, 0.5),
        glam::DVec2::new(0.3, 0.35),
    );
    let trimmed = ellipse.and_then(|e| TrimmedSurface::new(surface, vec![e]));
    let mut objects = vec![plain];
    if let Ok(trimmed) = trimmed {
        let mut object = SceneObject::new("trimmed (3, 2)", ObjectGeometry::from_trimmed(trimmed));
        object.segments = 6;
        objects.push(object);
    }
    objects
}

/// Whether two surfaces have the same degrees, knots and net size (so the same Bézier patch
/// layout on the GPU).
pub(super) fn same_net(a: &NurbsSurface, b: &NurbsSurface) -> bool {
    a.degree() == b.degree() && a.knots() == b.knots() && a.count() == b.count()
}
