//! Bézier patch sets (the Utah teapot) as a scene object kind.

use glam::{DAffine3, DVec3};

use serde::{Deserialize, Serialize};

use super::json::{self, FormatError};
use super::kind::KindFace;
use super::record::{self, KindEntry};
use super::{Decomposition, ObjectGeometry, ObjectKind, SceneObject};
use crate::kernel::parametric::PatchFace;
use crate::kernel::tess::{self, Tessellation, TriangleMesh};
use crate::kernel::{BezierPatch, BezierPatchSet, GeometryError, MAX_BEZIER_DEGREE};

impl ObjectKind for BezierPatchSet {
    fn kind_name(&self) -> &'static str {
        "a set of Bézier patches"
    }

    fn describe(&self) -> String {
        format!(
            "{} Bézier patches, {} points",
            self.patches().len(),
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
        BezierPatchSet::weights(self).to_vec()
    }

    fn net_lines(&self) -> Vec<u32> {
        crate::kernel::bezier::net_line_indices(self)
    }

    fn bounds(&self) -> Option<(DVec3, DVec3)> {
        BezierPatchSet::bounds(self)
    }

    /// The changed patches are those that use the point.
    fn move_control_point(
        &mut self,
        index: usize,
        position: DVec3,
    ) -> Result<Vec<usize>, GeometryError> {
        self.set_point(index, position)?;
        Ok(self
            .patches()
            .iter()
            .enumerate()
            .filter(|(_, p)| p.indices().contains(&(index as u32)))
            .map(|(k, _)| k)
            .collect())
    }

    fn set_weight(&mut self, index: usize, weight: f64) -> Result<(), GeometryError> {
        BezierPatchSet::set_weight(self, index, weight)
    }

    /// The set itself, every patch on (0, 1)².
    fn gpu_feed(&self) -> Result<Decomposition, GeometryError> {
        Ok(Decomposition {
            set: self.clone(),
            domains: vec![[0.0, 1.0, 0.0, 1.0]; self.patches().len()],
            ..Default::default()
        })
    }

    fn surface_point(&self, patch: usize, s: f64, t: f64) -> Result<DVec3, GeometryError> {
        Ok(self.evaluate(patch, s, t)?.point)
    }

    fn update_gpu_feed(
        &self,
        feed: &mut Decomposition,
        _patches: &[usize],
    ) -> Result<(), GeometryError> {
        feed.set = self.clone();
        Ok(())
    }

    fn tessellate(
        &self,
        tessellation: Tessellation,
        curvature: bool,
    ) -> Result<Vec<TriangleMesh>, GeometryError> {
        tess::tessellate_patches(self, tessellation, curvature)
    }

    fn plan_tessellation(
        &self,
        tessellation: Tessellation,
        curvature: bool,
    ) -> Result<tess::GridPlan, GeometryError> {
        tess::plan_patches(self, tessellation, curvature)
    }

    fn estimated_triangles(
        &self,
        tessellation: Tessellation,
        how: tess::Estimate,
    ) -> Result<usize, GeometryError> {
        tess::estimated_patch_triangles(self, tessellation, how)
    }

    /// Every patch, over [0, 1]².
    fn faces(&self) -> Vec<KindFace<'_>> {
        (0..self.patches().len())
            .map(|patch| KindFace {
                patch: Some(patch),
                surface: Box::new(PatchFace { set: self, patch }),
                triangle: false,
            })
            .collect()
    }

    fn transformed(&self, transform: &DAffine3) -> Result<ObjectGeometry, GeometryError> {
        BezierPatchSet::transformed(self, transform).map(ObjectGeometry::new)
    }

    fn bake_lattice(
        &self,
        lattice: &crate::kernel::ffd::Lattice,
        tolerance: f64,
    ) -> Result<(ObjectGeometry, crate::kernel::ffd::Baked), GeometryError> {
        let (set, baked) = super::ffd::bake_patch_set(self, lattice, tolerance)?;
        Ok((ObjectGeometry::new(set), baked))
    }

    fn same_layout(&self, other: &ObjectGeometry) -> bool {
        other.downcast_ref::<BezierPatchSet>().is_some_and(|b| {
            self.patches() == b.patches() && self.points().len() == b.points().len()
        })
    }

    /// Every patch's own (0, 1)²: each patch carries the whole height map.
    fn displacement_domain(&self) -> Option<[f64; 4]> {
        Some([0.0, 1.0, 0.0, 1.0])
    }

    fn nurbs_surface(&self) -> Option<&crate::kernel::NurbsSurface> {
        None
    }

    fn cage(&self) -> Option<&crate::kernel::PolygonMesh> {
        None
    }

    /// Patch by patch, each exact as a rational Bézier NURBS.
    fn exchange_faces(
        &self,
        _tolerance: f64,
    ) -> Option<Result<super::ExchangeFaces, GeometryError>> {
        let face = |patch: &crate::kernel::BezierPatch| {
            let (p, q) = (patch.degree_u(), patch.degree_v());
            let mut points = Vec::with_capacity((p + 1) * (q + 1));
            let mut weights = Vec::with_capacity(points.capacity());
            for i in 0..=p {
                for j in 0..=q {
                    let k = patch.index(i, j) as usize;
                    points.push(self.points()[k]);
                    weights.push(self.weights().get(k).copied().unwrap_or(1.0));
                }
            }
            crate::kernel::NurbsSurface::bezier([p, q], points, Some(weights))
                .map(crate::kernel::TrimmedSurface::untrimmed)
        };
        Some(
            self.patches()
                .iter()
                .map(face)
                .collect::<Result<Vec<_>, _>>()
                .map(|faces| super::ExchangeFaces {
                    faces,
                    topology: None,
                    note: None,
                }),
        )
    }

    fn record(&self) -> serde_json::Value {
        record::to_record(&PatchesRecord {
            kind: ENTRY.record_type.into(),
            points: self
                .points()
                .iter()
                .zip(self.weights())
                .map(|(p, &w)| vec![p.x, p.y, p.z, w])
                .collect(),
            patches: self
                .patches()
                .iter()
                .map(|p| PatchRecord {
                    degree: [p.degree_u(), p.degree_v()],
                    indices: p.indices().to_vec(),
                })
                .collect(),
        })
    }
}

/// One patch of a set: its degrees and the indices of its (du + 1)(dv + 1) points.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct PatchRecord {
    degree: [usize; 2],
    indices: Vec<u32>,
}

/// A set of Bézier patches: the shared points `[x, y, z, w]` (Cartesian, w optional) and the
/// patches.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct PatchesRecord {
    #[serde(rename = "type")]
    kind: String,
    points: Vec<Vec<f64>>,
    patches: Vec<PatchRecord>,
}

pub(super) const ENTRY: KindEntry = KindEntry {
    record_type: "bezier_patches",
    read: read_record,
    examples,
};

fn read_record(path: &str, record: serde_json::Value) -> Result<ObjectGeometry, FormatError> {
    let raw: PatchesRecord = record::deserialize(path, record)?;
    let (cartesian, weights) = json::curve_points(path, &raw.points, 3)?;
    let points = cartesian
        .iter()
        .map(|c| DVec3::new(c[0], c[1], c[2]))
        .collect();
    let mut patches = Vec::with_capacity(raw.patches.len());
    for (k, patch) in raw.patches.into_iter().enumerate() {
        let [du, dv] = patch.degree;
        if !(1..=MAX_BEZIER_DEGREE).contains(&du) || !(1..=MAX_BEZIER_DEGREE).contains(&dv) {
            return Err(FormatError::new(
                format!("{path}.patches[{k}].degree"),
                format!("degree ({du}, {dv}) is outside 1..={MAX_BEZIER_DEGREE}"),
            ));
        }
        patches.push(BezierPatch::new(du, dv, patch.indices));
    }
    BezierPatchSet::new(points, Some(weights), patches)
        .map(ObjectGeometry::new)
        .map_err(|e| FormatError::geometry(path, e))
}

/// The Utah teapot (32 bicubic patches over shared points).
fn examples() -> Vec<SceneObject> {
    crate::kernel::samples::utah_teapot()
        .map(|set| {
            let mut teapot = SceneObject::new("teapot", ObjectGeometry::new(set));
            teapot.segments = 6;
            teapot
        })
        .into_iter()
        .collect()
}
