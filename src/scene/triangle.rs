//! Triangular Bézier patches as a scene object kind. The GPU feed is one stencil patch on the
//! triangle lattice: each vertex's position and derivatives are the Bernstein polynomials and
//! their derivatives at its (u, v) ([`crate::kernel::triangle::bernstein_weights`]) times the
//! control points, evaluated by the compute shaders' stencil pass (with curvature); the table
//! depends only on the degree and the tessellation, so a drag only uploads the moved point.
//! The f64 oracle is the de Casteljau algorithm ([`TriangleBezier::evaluate`]).

use std::sync::Arc;

use glam::{DAffine3, DVec3};

use serde::{Deserialize, Serialize};

use super::json::FormatError;
use super::kind::KindFace;
use super::record::{self, KindEntry};
use super::{Decomposition, ObjectGeometry, ObjectKind, SceneObject};
use crate::kernel::diffgeo::{CurvatureValues, FundamentalForms};
use crate::kernel::subdiv::patches::{LimitFeed, StencilPatch};
use crate::kernel::tess::{MAX_SPAN_SEGMENTS, Tessellation, TriangleMesh};
use crate::kernel::triangle::{TriangleBezier, bernstein_weights};
use crate::kernel::{BezierPatchSet, GeometryError};

/// Segments per edge the viewport gives a triangular patch of degree n: 8 n, from 8 to 64.
pub fn viewport_segments(degree: usize) -> u32 {
    (8 * degree as u32).clamp(8, 64)
}

/// The stencil table of a degree-`degree` patch on a lattice of `segments` per edge: one
/// triangle stencil patch, slot (i, j) the Bernstein weights at (u, v) = (i, j) / s; the slots
/// past the diagonal (i + j > s, in no triangle) repeat the first slot's (the corner u = v = 0,
/// whose few non-zero weights cost little) without curvature, as a subdivision surface's
/// triangle patches do.
fn bernstein_feed(degree: usize, segments: u32) -> LimitFeed {
    let mut feed = LimitFeed::default();
    feed.patches.push(StencilPatch {
        cage_face: 0,
        triangle: true,
        segments,
        first_slot: 0,
        level: u32::MAX,
        piece: [u32::MAX; 2],
        points: u32::MAX,
    });
    let s = f64::from(segments);
    for i in 0..=segments {
        for j in 0..=segments {
            if i + j > segments {
                let first = feed.slots[0];
                feed.slots.push(first);
                feed.no_curvature.push(true);
                feed.vertex.push(u32::MAX);
                continue;
            }
            let (u, v) = (f64::from(i) / s, f64::from(j) / s);
            let start = feed.entries.len() as u32;
            for (k, w) in bernstein_weights(degree, u, v).into_iter().enumerate() {
                if w.iter().any(|&x| x != 0.0) {
                    feed.entries.push((k as u32, w));
                }
            }
            feed.slots.push([start, feed.entries.len() as u32 - start]);
            feed.no_curvature.push(false);
            feed.vertex.push(u32::MAX);
        }
    }
    feed
}

/// Segments per edge for an export at `tessellation`: enough for the tolerance
/// ([`TriangleBezier::segments_for`]) or the segments asked for.
fn export_segments(patch: &TriangleBezier, tessellation: Tessellation) -> u32 {
    let max = MAX_SPAN_SEGMENTS as u32;
    match tessellation {
        Tessellation::Tolerance(t) => patch.segments_for(t, max),
        Tessellation::Segments(n) => n.clamp(1, max),
    }
}

impl ObjectKind for TriangleBezier {
    fn kind_name(&self) -> &'static str {
        "a triangular Bézier patch"
    }

    fn describe(&self) -> String {
        format!(
            "triangular Bézier patch, degree {}, {} points",
            self.degree(),
            self.points().len()
        )
    }

    fn control_point_count(&self) -> usize {
        self.points().len()
    }

    fn control_points(&self) -> Vec<DVec3> {
        self.points().to_vec()
    }

    fn weights(&self) -> Vec<f64> {
        vec![1.0; self.points().len()]
    }

    fn net_lines(&self) -> Vec<u32> {
        TriangleBezier::net_lines(self)
    }

    fn bounds(&self) -> Option<(DVec3, DVec3)> {
        super::kind::points_box(self.points().iter().copied())
    }

    /// Every point moves the whole patch (feed patch 0).
    fn move_control_point(
        &mut self,
        index: usize,
        position: DVec3,
    ) -> Result<Vec<usize>, GeometryError> {
        self.set_point(index, position)?;
        Ok(vec![0])
    }

    fn weighted(&self) -> bool {
        false
    }

    fn set_weight(&mut self, _index: usize, _weight: f64) -> Result<(), GeometryError> {
        Err(GeometryError::Construction {
            what: "triangular Bézier patch",
            message: "its points have no weights (it is polynomial)".into(),
        })
    }

    /// No Bézier patches: the control points, and one triangle stencil patch over them.
    fn gpu_feed(&self) -> Result<Decomposition, GeometryError> {
        let segments = viewport_segments(self.degree());
        Ok(Decomposition {
            set: BezierPatchSet::new(self.points().to_vec(), None, Vec::new())?,
            domains: Vec::new(),
            stencils: Some(Arc::new(bernstein_feed(self.degree(), segments))),
            cage_points: self.points().len(),
            fixed_segments: Some(segments),
            trims: None,
            curve: None,
        })
    }

    /// The de Casteljau point at (u, v) = (s, t); past the diagonal (s + t > 1, the lattice
    /// slots in no triangle) the corner u = v = 0 they repeat.
    fn surface_point(&self, patch: usize, s: f64, t: f64) -> Result<DVec3, GeometryError> {
        if patch != 0 {
            return Err(GeometryError::NoSuchPatch { patch, count: 1 });
        }
        if s + t > 1.0 + 1e-9 {
            return Ok(self.evaluate(0.0, 0.0).point);
        }
        Ok(self.evaluate(s, t).point)
    }

    fn update_gpu_feed(
        &self,
        feed: &mut Decomposition,
        _patches: &[usize],
    ) -> Result<(), GeometryError> {
        feed.sync_points(self.points())
    }

    /// s² triangles for s segments per edge.
    fn estimated_triangles(
        &self,
        tessellation: Tessellation,
        _how: crate::kernel::tess::Estimate,
    ) -> Result<usize, GeometryError> {
        let s = export_segments(self, tessellation) as usize;
        Ok(s * s)
    }

    /// The lattice of enough segments per edge for the tolerance (the second-difference bound,
    /// [`TriangleBezier::segments_for`]) or the segments asked for, each vertex evaluated by de
    /// Casteljau with its normal, (u, v) and, if asked, curvature.
    fn tessellate(
        &self,
        tessellation: Tessellation,
        curvature: bool,
    ) -> Result<Vec<TriangleMesh>, GeometryError> {
        let s = export_segments(self, tessellation);
        let mut mesh = TriangleMesh {
            positions: Vec::new(),
            normals: Vec::new(),
            uvs: Vec::new(),
            curvatures: Vec::new(),
            triangles: Vec::new(),
        };
        // Row j holds i = 0..=s − j, as the lattice's points.
        let index = |i: u32, j: u32| {
            crate::kernel::triangle::lattice_index(s as usize, i as usize, j as usize) as u32
        };
        for j in 0..=s {
            for i in 0..=s - j {
                let (u, v) = (f64::from(i) / f64::from(s), f64::from(j) / f64::from(s));
                let d = self.evaluate(u, v);
                let normal = d.regular_normal().unwrap_or_else(|| {
                    // A degenerate corner: the normal a little way inside.
                    let (cu, cv) = (u + (1.0 / 3.0 - u) * 1e-6, v + (1.0 / 3.0 - v) * 1e-6);
                    self.evaluate(cu, cv).regular_normal().unwrap_or(DVec3::Z)
                });
                mesh.positions.push(d.point);
                mesh.normals.push(normal);
                mesh.uvs.push([u, v]);
                if curvature {
                    let forms = FundamentalForms::new(&d, normal);
                    mesh.curvatures
                        .push(
                            CurvatureValues::from_forms(&forms).unwrap_or(CurvatureValues {
                                gaussian: 0.0,
                                mean: 0.0,
                                k1: 0.0,
                                k2: 0.0,
                            }),
                        );
                }
                if i + j < s {
                    mesh.triangles
                        .push([index(i, j), index(i + 1, j), index(i, j + 1)]);
                    if i + j + 1 < s {
                        mesh.triangles.push([
                            index(i + 1, j),
                            index(i + 1, j + 1),
                            index(i, j + 1),
                        ]);
                    }
                }
            }
        }
        Ok(vec![mesh])
    }

    /// The patch over its triangle (the analyses see it over the square, its corner (0, 1) a
    /// collapsed side).
    fn faces(&self) -> Vec<KindFace<'_>> {
        vec![KindFace {
            patch: None,
            surface: Box::new(self),
            triangle: true,
        }]
    }

    fn transformed(&self, transform: &DAffine3) -> Result<ObjectGeometry, GeometryError> {
        let moved = self.mapped(|p| transform.transform_point3(p))?;
        Ok(ObjectGeometry::new(moved))
    }

    fn bake_lattice(
        &self,
        lattice: &crate::kernel::ffd::Lattice,
        tolerance: f64,
    ) -> Result<(ObjectGeometry, crate::kernel::ffd::Baked), GeometryError> {
        let (patch, baked) = super::ffd::bake_triangle(self, lattice, tolerance)?;
        Ok((ObjectGeometry::new(patch), baked))
    }

    fn same_layout(&self, other: &ObjectGeometry) -> bool {
        other
            .downcast_ref::<TriangleBezier>()
            .is_some_and(|b| b.degree() == self.degree())
    }

    /// (0, 1)², of which the patch covers the triangle u + v ≤ 1.
    fn displacement_domain(&self) -> Option<[f64; 4]> {
        Some([0.0, 1.0, 0.0, 1.0])
    }

    fn nurbs_surface(&self) -> Option<&crate::kernel::NurbsSurface> {
        None
    }

    fn cage(&self) -> Option<&crate::kernel::PolygonMesh> {
        None
    }

    fn triangle_patch(&self) -> Option<&TriangleBezier> {
        Some(self)
    }

    /// Exactly, as the tensor patch over the square collapsed onto the triangle.
    fn exchange_faces(
        &self,
        _tolerance: f64,
    ) -> Option<Result<super::ExchangeFaces, GeometryError>> {
        let n = self.degree();
        Some(
            crate::kernel::NurbsSurface::bezier([n, n], self.tensor_points(), None).map(|s| {
                super::ExchangeFaces {
                    faces: vec![crate::kernel::TrimmedSurface::untrimmed(s)],
                    topology: None,
                    note: None,
                }
            }),
        )
    }

    fn record(&self) -> serde_json::Value {
        record::to_record(&TriangleRecord {
            kind: ENTRY.record_type.into(),
            degree: self.degree(),
            points: record::point_records(self.points()),
        })
    }
}

/// A triangular Bézier patch: its degree and (n + 1)(n + 2)/2 points, row by row (row j holds
/// b_ij for i = 0..=n − j, k = n − i − j).
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct TriangleRecord {
    #[serde(rename = "type")]
    kind: String,
    degree: usize,
    points: Vec<[f64; 3]>,
}

pub(super) const ENTRY: KindEntry = KindEntry {
    record_type: "triangular_bezier",
    read: read_record,
    examples,
};

fn read_record(path: &str, record: serde_json::Value) -> Result<ObjectGeometry, FormatError> {
    let raw: TriangleRecord = record::deserialize(path, record)?;
    let points = record::points_of(&raw.points);
    TriangleBezier::new(raw.degree, points)
        .map(ObjectGeometry::new)
        .map_err(|e| FormatError::geometry(path, e))
}

/// A quartic dome over the triangle (0, 0), (2, 0), (0, 2): height 12 u v w plus a tilt.
fn examples() -> Vec<SceneObject> {
    let n = 4;
    let mut points = Vec::new();
    for j in 0..=n {
        for i in 0..=n - j {
            let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
            let w = 1.0 - u - v;
            points.push(DVec3::new(2.0 * u, 2.0 * v, 12.0 * u * v * w + 0.2 * u));
        }
    }
    TriangleBezier::new(n, points)
        .map(|patch| SceneObject::new("triangular dome", ObjectGeometry::new(patch)))
        .into_iter()
        .collect()
}
