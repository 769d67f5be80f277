//! Binary STL for printing: every visible object's export mesh (the tessellation glTF uses,
//! within the same tolerance), one facet list. A joined polysurface's mesh shares its vertices
//! along shared edges, so a closed body comes out watertight; each object's triangles are
//! turned so that a closed one's normals point outward (its signed volume positive). STL has no
//! unit: coordinates are the document's (millimetres when it says so, as printers assume).
//! [`printable_bodies`] is the meshing both print formats (this and 3MF) share.
//!
//! Layout (little-endian): an 80-byte header, the facet count (u32), then per facet the normal
//! and three vertices as f32 triples and a zero u16 attribute count: 50 bytes a facet.

use crate::kernel::tess::{GridSampler, Tessellation, TriangleMesh};
use crate::scene::{Scene, SceneObject};

/// Why a file for printing (STL, 3MF) could not be written.
#[derive(Debug, thiserror::Error)]
pub enum PrintError {
    #[error("nothing to export: no visible object has faces")]
    Empty,
    #[error("{name}: {source}")]
    Object {
        name: String,
        source: crate::kernel::GeometryError,
    },
    #[error("{0} facets are more than the file format holds")]
    TooMany(usize),
}

/// One visible object's export mesh for printing: its parts (one per face), turned together
/// so that a closed body's normals point outward.
pub struct PrintBody<'a> {
    pub object: &'a SceneObject,
    pub parts: Vec<TriangleMesh>,
}

impl PrintBody<'_> {
    /// The body's triangle count.
    pub fn facets(&self) -> usize {
        self.parts.iter().map(|m| m.triangles.len()).sum()
    }
}

/// The export meshes of `scene`'s visible objects with triangles at `tessellation`, each
/// object's parts turned together so that its signed volume (the divergence theorem over the
/// triangles) is not negative: outward for a closed body. The objects are tessellated on every
/// core and taken in scene order (the first object that fails is the one named).
pub fn printable_bodies<'a>(
    scene: &'a Scene,
    tessellation: Tessellation,
    sampler: &dyn GridSampler,
) -> Result<Vec<PrintBody<'a>>, PrintError> {
    let visible: Vec<&SceneObject> = scene.objects.iter().filter(|o| o.visible).collect();
    let tessellated: Vec<_> = knotwork_kernel::par::map(visible.len(), |k| {
        visible[k].tessellate_with(tessellation, false, sampler)
    });
    let mut bodies = Vec::new();
    for (object, parts) in visible.into_iter().zip(tessellated) {
        let mut parts = parts.map_err(|source| PrintError::Object {
            name: object.name.clone(),
            source,
        })?;
        let volume: f64 = parts.iter().map(TriangleMesh::signed_volume).sum();
        if volume < 0.0 {
            for part in &mut parts {
                for t in &mut part.triangles {
                    t.swap(1, 2);
                }
            }
        }
        let body = PrintBody { object, parts };
        if body.facets() > 0 {
            bodies.push(body);
        }
    }
    if bodies.is_empty() {
        return Err(PrintError::Empty);
    }
    Ok(bodies)
}

/// The binary STL of `scene`'s visible objects at `tessellation` (grids evaluated by
/// `sampler`), and its facet count.
pub fn write(
    scene: &Scene,
    tessellation: Tessellation,
    sampler: &dyn GridSampler,
) -> Result<(Vec<u8>, usize), PrintError> {
    let bodies = printable_bodies(scene, tessellation, sampler)?;
    let facets: usize = bodies.iter().map(PrintBody::facets).sum();
    let count = u32::try_from(facets).map_err(|_| PrintError::TooMany(facets))?;
    let mut bytes = Vec::with_capacity(84 + 50 * facets);
    let mut header = [b' '; 80];
    let unit = scene.unit.map_or("unitless", |u| u.symbol());
    let title = format!("knotwork binary STL, {unit}");
    header[..title.len().min(80)].copy_from_slice(&title.as_bytes()[..title.len().min(80)]);
    bytes.extend_from_slice(&header);
    bytes.extend_from_slice(&count.to_le_bytes());
    for mesh in bodies.iter().flat_map(|b| &b.parts) {
        for t in &mesh.triangles {
            let [a, b, c] = t.map(|k| mesh.positions[k as usize]);
            for v in [(b - a).cross(c - a).normalize_or_zero(), a, b, c] {
                for x in v.to_array() {
                    bytes.extend_from_slice(&(x as f32).to_le_bytes());
                }
            }
            bytes.extend_from_slice(&[0, 0]);
        }
    }
    Ok((bytes, facets))
}
