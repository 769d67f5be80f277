//! Polygon meshes (imported OBJ and glTF meshes) as a scene object kind, drawn as bilinear
//! Bézier patches: a quad is one patch, a triangle a patch with a collapsed edge, an n-gon a fan.

use glam::{DAffine3, DVec3};

use serde::{Deserialize, Serialize};

use super::json::FormatError;
use super::kind::KindFace;
use super::record::{self, KindEntry};
use super::{Decomposition, ObjectGeometry, ObjectKind, SceneObject};
use crate::kernel::tess::{self, Tessellation, TriangleMesh};
use crate::kernel::{GeometryError, PolygonMesh};

impl ObjectKind for PolygonMesh {
    fn kind_name(&self) -> &'static str {
        "a polygon mesh"
    }

    fn describe(&self) -> String {
        format!(
            "polygon mesh, {} faces, {} points",
            self.face_count(),
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
        self.edge_indices()
    }

    fn bounds(&self) -> Option<(DVec3, DVec3)> {
        PolygonMesh::bounds(self)
    }

    /// The changed patches are those of the faces around the point.
    fn move_control_point(
        &mut self,
        index: usize,
        position: DVec3,
    ) -> Result<Vec<usize>, GeometryError> {
        self.set_point(index, position)?;
        Ok(self.patches_using(index as u32))
    }

    fn weighted(&self) -> bool {
        false
    }

    fn set_weight(&mut self, _index: usize, _weight: f64) -> Result<(), GeometryError> {
        Err(GeometryError::Construction {
            what: "polygon mesh",
            message: "its points have no weights".into(),
        })
    }

    fn gpu_feed(&self) -> Result<Decomposition, GeometryError> {
        let set = self.to_bezier_patch_set()?;
        let domains = vec![[0.0, 1.0, 0.0, 1.0]; set.patches().len()];
        Ok(Decomposition {
            set,
            domains,
            ..Default::default()
        })
    }

    /// Bilinear interpolation of the face's corners: a quad (a, b, c, d) is
    /// (1 − s)(1 − t) a + s(1 − t) b + s t c + (1 − s) t d, a triangle the same with d = c, an
    /// n-gon's k-th fan triangle (f0, f_k+1, f_k+2) likewise.
    fn surface_point(&self, patch: usize, s: f64, t: f64) -> Result<DVec3, GeometryError> {
        let mut first = 0;
        for face in self.faces() {
            let count = PolygonMesh::patches_of_face(face);
            if patch < first + count {
                let k = patch - first;
                let [a, b, c, d] = match *face {
                    [a, b, c] => [a, b, c, c],
                    [a, b, c, d] => [a, b, c, d],
                    _ => [face[0], face[k + 1], face[k + 2], face[k + 2]],
                };
                let p = |i: u32| self.points()[i as usize];
                return Ok((1.0 - s) * (1.0 - t) * p(a)
                    + s * (1.0 - t) * p(b)
                    + s * t * p(c)
                    + (1.0 - s) * t * p(d));
            }
            first += count;
        }
        Err(GeometryError::NoSuchPatch {
            patch,
            count: first,
        })
    }

    /// The mesh's points are the feed's pool: they are copied.
    fn update_gpu_feed(
        &self,
        feed: &mut Decomposition,
        _patches: &[usize],
    ) -> Result<(), GeometryError> {
        for (index, &p) in self.points().iter().enumerate() {
            feed.set.set_point(index, p)?;
        }
        Ok(())
    }

    fn tessellate(
        &self,
        tessellation: Tessellation,
        curvature: bool,
    ) -> Result<Vec<TriangleMesh>, GeometryError> {
        Ok(vec![tess::tessellate_mesh(self, tessellation, curvature)?])
    }

    /// None: a polygon mesh is flat facets, with zero curvature inside each and a crease at
    /// every edge, so the analyses have nothing to measure on it. Subdivide it for a smooth
    /// surface.
    fn faces(&self) -> Vec<KindFace<'_>> {
        Vec::new()
    }

    fn transformed(&self, transform: &DAffine3) -> Result<ObjectGeometry, GeometryError> {
        PolygonMesh::transformed(self, transform).map(ObjectGeometry::new)
    }

    /// The vertices move through the lattice (they are the mesh's shape).
    fn bake_lattice(
        &self,
        lattice: &crate::kernel::ffd::Lattice,
        _tolerance: f64,
    ) -> Result<(ObjectGeometry, crate::kernel::ffd::Baked), GeometryError> {
        let mut mesh = self.clone();
        for (k, &p) in self.points().iter().enumerate() {
            mesh.set_point(k, lattice.deform_point(p))?;
        }
        Ok((
            ObjectGeometry::new(mesh),
            crate::kernel::ffd::Baked::Points {
                error: 0.0,
                within: true,
            },
        ))
    }

    fn same_layout(&self, other: &ObjectGeometry) -> bool {
        other
            .downcast_ref::<PolygonMesh>()
            .is_some_and(|b| self.points().len() == b.points().len() && self.faces().eq(b.faces()))
    }

    /// No one (u, v) domain: a mesh's patches are pieces of polygons.
    fn displacement_domain(&self) -> Option<[f64; 4]> {
        None
    }

    fn nurbs_surface(&self) -> Option<&crate::kernel::NurbsSurface> {
        None
    }

    /// The mesh itself: it can be subdivided.
    fn cage(&self) -> Option<&PolygonMesh> {
        Some(self)
    }

    fn record(&self) -> serde_json::Value {
        record::to_record(&MeshRecord {
            kind: ENTRY.record_type.into(),
            points: record::point_records(self.points()),
            faces: self.faces().map(<[u32]>::to_vec).collect(),
        })
    }
}

/// A polygon mesh: its points and its faces (point indices, counter-clockwise).
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct MeshRecord {
    #[serde(rename = "type")]
    kind: String,
    points: Vec<[f64; 3]>,
    faces: Vec<Vec<u32>>,
}

pub(super) const ENTRY: KindEntry = KindEntry {
    record_type: "polygon_mesh",
    read: read_record,
    examples,
};

fn read_record(path: &str, record: serde_json::Value) -> Result<ObjectGeometry, FormatError> {
    let raw: MeshRecord = record::deserialize(path, record)?;
    let points = record::points_of(&raw.points);
    PolygonMesh::new(points, &raw.faces)
        .map(ObjectGeometry::new)
        .map_err(|e| FormatError::new(path, e.to_string()))
}

/// A non-planar quad, a triangle and a hexagon (a fan of four patches).
fn examples() -> Vec<SceneObject> {
    let points = vec![
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(1.0, 0.0, 0.3),
        DVec3::new(1.0, 1.0, 0.0),
        DVec3::new(0.0, 1.0, 0.4),
        DVec3::new(2.0, 0.5, 0.2),
        DVec3::new(3.0, 0.0, 0.0),
        DVec3::new(4.0, 0.5, 0.1),
        DVec3::new(4.0, 1.5, -0.2),
        DVec3::new(3.0, 2.0, 0.0),
        DVec3::new(2.0, 1.5, 0.3),
    ];
    let faces = [vec![0, 1, 2, 3], vec![1, 4, 2], vec![4, 5, 6, 7, 8, 9]];
    PolygonMesh::new(points, &faces)
        .map(|mesh| {
            let mut object = SceneObject::new("polygon mesh", ObjectGeometry::new(mesh));
            object.segments = 5;
            object
        })
        .into_iter()
        .collect()
}
