//! Continuity analysis over a scene's objects: the faces each object shows
//! ([`super::SceneObject::faces`]: every kind's faces through the one surface interface,
//! displaced and deformed as in the viewport) handed to [`crate::kernel::continuity`], and the
//! report as the CLI prints it.

use glam::DVec3;
use serde_json::{Value, json};

use super::Scene;
use crate::kernel::ParametricSurface;
use crate::kernel::continuity::{SharedEdge, Tolerances, shared_edges_scaled};

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

/// Analyses the shared edges between the faces of `objects` (every object when `None`) as the
/// viewport shows them ([`super::SceneObject::faces`]); hidden objects are left out.
pub fn analyse(
    scene: &Scene,
    objects: Option<&[usize]>,
    options: &ContinuityOptions,
) -> ContinuityReport {
    let chosen = |k: usize| objects.is_none_or(|list| list.contains(&k));
    let mut faces = Vec::new();
    let mut surfaces: Vec<Box<dyn ParametricSurface + '_>> = Vec::new();
    // Each face's object's size: boundaries match within a share of the smaller one's.
    let mut scales = Vec::new();
    let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    for (k, object) in scene.objects.iter().enumerate() {
        if !chosen(k) || !object.visible {
            continue;
        }
        let object_faces = object.faces();
        if object_faces.is_empty() {
            continue;
        }
        let bounds = object.bounds();
        for (patch, surface) in object_faces {
            faces.push(FaceRef { object: k, patch });
            surfaces.push(surface);
            scales.push(bounds.map_or(f64::INFINITY, |(a, b)| a.distance(b)));
        }
        if let Some((a, b)) = bounds {
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
    let refs: Vec<&dyn ParametricSurface> = surfaces.iter().map(|s| s.as_ref()).collect();
    let edges = shared_edges_scaled(&refs, &scales, &tolerances, size);
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
