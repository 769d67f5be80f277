//! Bézier patch sets (the Utah teapot) as a scene object kind.

use glam::{DAffine3, DVec3};

use super::kind::KindFace;
use super::{Decomposition, ObjectGeometry, ObjectKind};
use crate::kernel::parametric::PatchFace;
use crate::kernel::tess::{self, Tessellation, TriangleMesh};
use crate::kernel::{BezierPatchSet, GeometryError};

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
        BezierPatchSet::transformed(self, transform).map(ObjectGeometry::Patches)
    }

    fn bake_lattice(
        &self,
        lattice: &crate::kernel::ffd::Lattice,
        tolerance: f64,
    ) -> Result<(ObjectGeometry, crate::kernel::ffd::Baked), GeometryError> {
        let (set, baked) = super::ffd::bake_patch_set(self, lattice, tolerance)?;
        Ok((ObjectGeometry::Patches(set), baked))
    }

    fn same_layout(&self, other: &ObjectGeometry) -> bool {
        matches!(other, ObjectGeometry::Patches(b)
            if self.patches() == b.patches() && self.points().len() == b.points().len())
    }
}
