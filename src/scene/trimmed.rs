//! Trimmed NURBS surfaces as a scene object kind: the surface's own feed and editing, plus the
//! trim loops' classification grid for the fragment shader and each Bézier patch's coverage
//! (wholly kept, wholly trimmed away, or cut by a loop), so the GPU skips what is trimmed away
//! and tests only what a loop crosses.

use std::sync::Arc;

use glam::{DAffine3, DVec3};

use super::kind::KindFace;
use super::{Decomposition, ObjectGeometry, ObjectKind};
use crate::kernel::tess::{Tessellation, TriangleMesh};
use crate::kernel::trim::index::{Coverage, TrimIndex};
use crate::kernel::trim::tess::tessellate_trimmed;
use crate::kernel::{GeometryError, NurbsSurface, TrimmedSurface};

/// What a trimmed object (or an object of several trimmed faces) adds to its GPU feed.
#[derive(Debug, Clone, PartialEq)]
pub struct TrimFeed {
    /// The classification grids, one per trimmed face.
    pub indices: Vec<Arc<TrimIndex>>,
    /// Each Bézier patch's coverage, in the feed's patch order.
    pub coverage: Vec<Coverage>,
    /// Which of [`Self::indices`] each patch's trims are, in the feed's patch order (read only
    /// where the coverage is partial or outside).
    pub patch_index: Vec<u32>,
}

impl TrimFeed {
    /// The feed of one trimmed face whose patches have parameter rectangles `domains`.
    pub fn single(index: Arc<TrimIndex>, domains: &[[f64; 4]]) -> Self {
        Self {
            coverage: domains.iter().map(|&d| index.coverage(d)).collect(),
            patch_index: vec![0; domains.len()],
            indices: vec![index],
        }
    }

    /// The grid patch `patch`'s trims are classified by.
    pub fn index_for(&self, patch: usize) -> Option<&TrimIndex> {
        let k = *self.patch_index.get(patch)? as usize;
        self.indices.get(k).map(Arc::as_ref)
    }

    /// Whether patch `patch`'s point (u, v) is kept.
    pub fn keeps(&self, patch: usize, u: f64, v: f64) -> bool {
        match self.coverage.get(patch) {
            Some(Coverage::Inside) | None => true,
            Some(Coverage::Outside) => false,
            Some(Coverage::Partial) => self.index_for(patch).is_none_or(|i| i.contains(u, v)),
        }
    }
}

impl ObjectKind for TrimmedSurface {
    fn kind_name(&self) -> &'static str {
        "a trimmed NURBS surface"
    }

    fn describe(&self) -> String {
        let n = self.loops().len();
        format!(
            "{}, {n} trim loop{}",
            self.surface().describe(),
            if n == 1 { "" } else { "s" }
        )
    }

    fn control_point_count(&self) -> usize {
        self.surface().control_point_count()
    }

    fn control_points(&self) -> Vec<DVec3> {
        self.surface().control_points()
    }

    fn weights(&self) -> Vec<f64> {
        ObjectKind::weights(self.surface())
    }

    fn net_lines(&self) -> Vec<u32> {
        self.surface().net_lines()
    }

    fn net_grid(&self) -> Option<[usize; 2]> {
        self.surface().net_grid()
    }

    fn bounds(&self) -> Option<(DVec3, DVec3)> {
        ObjectKind::bounds(self.surface())
    }

    fn move_control_point(
        &mut self,
        index: usize,
        position: DVec3,
    ) -> Result<Vec<usize>, GeometryError> {
        self.surface_mut().move_control_point(index, position)
    }

    fn set_weight(&mut self, index: usize, weight: f64) -> Result<(), GeometryError> {
        ObjectKind::set_weight(self.surface_mut(), index, weight)
    }

    /// The surface's Bézier patches with the trim grid and each patch's coverage.
    fn gpu_feed(&self) -> Result<Decomposition, GeometryError> {
        let mut feed = self.surface().gpu_feed()?;
        if let Some(index) = self.index() {
            feed.trims = Some(TrimFeed::single(index, &feed.domains));
        }
        Ok(feed)
    }

    fn surface_point(&self, patch: usize, s: f64, t: f64) -> Result<DVec3, GeometryError> {
        self.surface().surface_point(patch, s, t)
    }

    fn update_gpu_feed(
        &self,
        feed: &mut Decomposition,
        patches: &[usize],
    ) -> Result<(), GeometryError> {
        self.surface().update_gpu_feed(feed, patches)
    }

    /// A constrained Delaunay triangulation of the kept region
    /// ([`crate::kernel::trim::tess`]).
    fn tessellate(
        &self,
        tessellation: Tessellation,
        curvature: bool,
    ) -> Result<Vec<TriangleMesh>, GeometryError> {
        Ok(vec![tessellate_trimmed(self, tessellation, curvature)?])
    }

    fn plan_tessellation(
        &self,
        tessellation: Tessellation,
        curvature: bool,
    ) -> Result<crate::kernel::tess::GridPlan, GeometryError> {
        crate::kernel::trim::tess::plan_trimmed(self, tessellation, curvature)
    }

    /// The whole surface's estimate: the trims only take triangles away.
    fn estimated_triangles(
        &self,
        tessellation: Tessellation,
        how: crate::kernel::tess::Estimate,
    ) -> Result<usize, GeometryError> {
        crate::kernel::tess::estimated_triangles(self.surface(), tessellation, how)
    }

    /// The surface with its kept region.
    fn faces(&self) -> Vec<KindFace<'_>> {
        vec![KindFace::whole(self)]
    }

    fn transformed(&self, transform: &DAffine3) -> Result<ObjectGeometry, GeometryError> {
        let surface = NurbsSurface::transformed(self.surface(), transform)?;
        Ok(ObjectGeometry::from_trimmed(self.with_surface(surface)?))
    }

    /// The surface is baked; the loops stay in its (unchanged) parameter domain.
    fn bake_lattice(
        &self,
        lattice: &crate::kernel::ffd::Lattice,
        tolerance: f64,
    ) -> Result<(ObjectGeometry, crate::kernel::ffd::Baked), GeometryError> {
        let (surface, baked) = super::ffd::bake_nurbs(self.surface(), lattice, tolerance)?;
        Ok((
            ObjectGeometry::from_trimmed(self.with_surface(surface)?),
            baked,
        ))
    }

    fn same_layout(&self, other: &ObjectGeometry) -> bool {
        other.downcast_ref::<TrimmedSurface>().is_some_and(|b| {
            super::nurbs::same_net(self.surface(), b.surface()) && self.loops() == b.loops()
        })
    }

    /// The surface's domain: the height map spans it, trimmed or not.
    fn displacement_domain(&self) -> Option<[f64; 4]> {
        self.surface().displacement_domain()
    }

    fn nurbs_surface(&self) -> Option<&NurbsSurface> {
        Some(self.surface())
    }

    fn as_trimmed(&self) -> Option<TrimmedSurface> {
        Some(self.clone())
    }

    fn cage(&self) -> Option<&crate::kernel::PolygonMesh> {
        None
    }

    /// A `nurbs_surface` record with `"trims"` (read back by the NURBS surface's entry).
    fn record(&self) -> serde_json::Value {
        super::nurbs::surface_record(super::json::Geometry::TrimmedSurface(self.clone()))
    }
}
