//! Continuity analysis over a scene's objects: the faces each kind offers (a NURBS surface, a
//! trimmed surface with its kept region, every patch of a patch set) handed to
//! [`crate::kernel::continuity`], and the report as the CLI prints it.

use glam::DVec3;
use serde_json::{Value, json};

use super::{ObjectGeometry, Scene};
use crate::kernel::continuity::{FaceSurface, PatchFace, SharedEdge, Tolerances, shared_edges};

/// The tolerances a user sets: the gap as a fraction of the scene's size, the angle in
/// degrees, the relative curvature difference, and samples per edge.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContinuityOptions {
    pub gap: f64,
    pub angle_degrees: f64,
    pub curvature: f64,
    pub samples: usize,
}

impl Default for ContinuityOptions {
    fn default() -> Self {
        Self {
            gap: 1e-3,
            angle_degrees: 1.0,
            curvature: 0.05,
            samples: 33,
        }
    }
}

/// One face of the analysis: object `object`, and for a patch set its patch.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FaceRef {
    pub object: usize,
    pub patch: Option<usize>,
}

/// Every shared edge of the analysed objects, with the faces and the tolerances used.
#[derive(Debug, Clone, PartialEq)]
pub struct ContinuityReport {
    pub faces: Vec<FaceRef>,
    pub edges: Vec<SharedEdge>,
    pub tolerances: Tolerances,
    /// The analysed objects' bounding box diagonal.
    pub size: f64,
}

/// The surfaces an object offers to the analyses (continuity, combs, principal directions): a
/// NURBS surface, a trimmed surface with its kept region, every patch of a patch set (with its
/// index); none for polygon meshes and subdivision surfaces.
pub fn faces_of(geometry: &ObjectGeometry) -> Vec<(Option<usize>, Box<dyn FaceSurface + '_>)> {
    match geometry {
        ObjectGeometry::Nurbs(s) => vec![(None, Box::new(s) as Box<dyn FaceSurface>)],
        ObjectGeometry::Trimmed(t) => vec![(None, Box::new(t.as_ref()) as Box<dyn FaceSurface>)],
        ObjectGeometry::Patches(set) => (0..set.patches().len())
            .map(|patch| {
                (
                    Some(patch),
                    Box::new(PatchFace { set, patch }) as Box<dyn FaceSurface>,
                )
            })
            .collect(),
        _ => Vec::new(),
    }
}

/// Analyses the shared edges between `objects` (every object when `None`); hidden objects,
/// polygon meshes and subdivision surfaces are left out.
pub fn analyse(
    scene: &Scene,
    objects: Option<&[usize]>,
    options: &ContinuityOptions,
) -> ContinuityReport {
    let chosen = |k: usize| objects.is_none_or(|list| list.contains(&k));
    let mut faces = Vec::new();
    let mut surfaces: Vec<Box<dyn FaceSurface + '_>> = Vec::new();
    let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    for (k, object) in scene.objects.iter().enumerate() {
        if !chosen(k) || !object.visible {
            continue;
        }
        let object_faces = faces_of(&object.geometry);
        if object_faces.is_empty() {
            continue;
        }
        for (patch, surface) in object_faces {
            faces.push(FaceRef { object: k, patch });
            surfaces.push(surface);
        }
        if let Some((a, b)) = object.bounds() {
            lo = lo.min(a);
            hi = hi.max(b);
        }
    }
    let size = if lo.x.is_finite() {
        lo.distance(hi)
    } else {
        0.0
    };
    let tolerances = Tolerances {
        matching: (1e-2 * size).max(10.0 * options.gap * size),
        distance: options.gap * size,
        angle_degrees: options.angle_degrees,
        curvature: options.curvature,
        samples: options.samples.max(2),
    };
    let refs: Vec<&dyn FaceSurface> = surfaces.iter().map(|s| s.as_ref()).collect();
    let edges = shared_edges(&refs, &tolerances, size);
    ContinuityReport {
        faces,
        edges,
        tolerances,
        size,
    }
}

impl ContinuityReport {
    /// How face `face` is named: the object's name, with "patch N" for a patch set.
    pub fn face_name(&self, scene: &Scene, face: usize) -> String {
        let f = self.faces[face];
        let name = &scene.objects[f.object].name;
        match f.patch {
            Some(p) => format!("{name} patch {p}"),
            None => name.clone(),
        }
    }

    /// One JSON entry per shared edge: objects, edge (each face's object, patch and side),
    /// samples, max gap, max angle in degrees, max curvature difference (absolute and
    /// relative), where each maximum lies, and the verdict.
    pub fn to_json(&self, scene: &Scene) -> Value {
        let face = |(k, side): (usize, crate::kernel::continuity::Side)| {
            let f = self.faces[k];
            let mut v = json!({ "object": scene.objects[f.object].name, "side": side.name() });
            if let Some(p) = f.patch {
                v["patch"] = json!(p);
            }
            v
        };
        let at = |p: DVec3| json!([p.x, p.y, p.z]);
        Value::Array(
            self.edges
                .iter()
                .map(|e| {
                    json!({
                        "objects": [
                            scene.objects[self.faces[e.a.0].object].name,
                            scene.objects[self.faces[e.b.0].object].name,
                        ],
                        "edge": { "a": face(e.a), "b": face(e.b), "reversed": e.reversed },
                        "samples": e.samples.len(),
                        "max_gap": e.max_gap.value,
                        "max_gap_at": at(e.max_gap.at),
                        "max_angle_degrees": e.max_angle_degrees.value,
                        "max_angle_at": at(e.max_angle_degrees.at),
                        "max_curvature_difference": e.max_curvature_difference.value,
                        "max_relative_curvature_difference": e.max_relative_curvature_difference.value,
                        "max_curvature_at": at(e.max_relative_curvature_difference.at),
                        "verdict": e.verdict.name(),
                    })
                })
                .collect(),
        )
    }
}
