//! `knotwork boolean union|difference|intersection A B -o OUT.step`: the solids of A combined
//! with those of B ([`knotwork::kernel::boolean`]), written as STEP solids.

use std::process::ExitCode;

use knotwork::kernel::boolean::{BooleanOp, boolean_joined as combine};
use knotwork::kernel::join::Topology;
use knotwork::kernel::trim::TrimmedSurface;
use knotwork::scene::polysurface::{Body, Polysurface};
use knotwork::scene::{ObjectGeometry, Scene, SceneObject};

use super::*;

/// The closed bodies of the file at `path` (its objects with faces), each one's faces; an
/// open body is refused by name.
pub(super) fn solids_of(path: &std::path::Path) -> Result<(Scene, Vec<Body>), String> {
    named_solids_of(path)
        .map(|(scene, bodies)| (scene, bodies.into_iter().map(|(_, b)| b).collect()))
}

/// [`solids_of`], each body with its object's name.
pub(super) fn named_solids_of(
    path: &std::path::Path,
) -> Result<(Scene, Vec<(String, Body)>), String> {
    let project = open_project(path)?;
    let mut bodies = Vec::new();
    for object in &project.scene.objects {
        let Some(body) = object.body() else {
            continue;
        };
        if !body.closed() {
            let open = body.validity.as_ref().map_or(0, |v| v.naked.len());
            return Err(format!(
                "{}: {} is not a closed solid ({open} open edge(s)); join its faces into a \
                 closed body first",
                path.display(),
                object.name
            ));
        }
        bodies.push((object.name.clone(), body));
    }
    if bodies.is_empty() {
        return Err(format!("{} holds no solid", path.display()));
    }
    Ok((project.scene, bodies))
}

pub(super) fn diagonal(bodies: &[Body]) -> f64 {
    let (lo, hi) = bodies
        .iter()
        .flat_map(|b| &b.faces)
        .map(|f| f.surface().bounds())
        .fold(
            (glam::DVec3::INFINITY, glam::DVec3::NEG_INFINITY),
            |(lo, hi), (a, b)| (lo.min(a), hi.max(b)),
        );
    lo.distance(hi)
}

/// Runs `knotwork boolean`: prints the result's solids, faces and volume as JSON.
pub fn boolean(
    op: BooleanOp,
    a: &std::path::Path,
    b: &std::path::Path,
    output: &std::path::Path,
    tolerance: Option<f64>,
) -> ExitCode {
    let run = || -> Result<serde_json::Value, String> {
        let started = std::time::Instant::now();
        let (scene_a, bodies_a) = solids_of(a)?;
        let (_, bodies_b) = solids_of(b)?;
        let read_ms = started.elapsed().as_secs_f64() * 1e3;
        let size = diagonal(&bodies_a).max(diagonal(&bodies_b));
        let tolerance = match tolerance {
            Some(t) if t > 0.0 && t.is_finite() => t,
            Some(t) => return Err(format!("the tolerance must be a number above 0, got {t}")),
            None => 1e-6 * size,
        };
        // All of a file's bodies as one operand, each body's shared edges numbered on.
        let joined = |bodies: Vec<Body>| -> (Vec<TrimmedSurface>, Option<Topology>) {
            let known = bodies.iter().all(|b| b.topology.is_some());
            let topology = known.then(|| {
                Topology::concatenated(
                    bodies
                        .iter()
                        .filter_map(|b| Some((b.topology.as_ref()?, b.faces.len()))),
                )
            });
            (bodies.into_iter().flat_map(|b| b.faces).collect(), topology)
        };
        let (faces_a, topology_a) = joined(bodies_a);
        let (faces_b, topology_b) = joined(bodies_b);
        let at = std::time::Instant::now();
        let result = combine(
            op,
            (&faces_a, topology_a.as_ref()),
            (&faces_b, topology_b.as_ref()),
            tolerance,
        )
        .map_err(|e| e.to_string())?;
        let boolean_ms = at.elapsed().as_secs_f64() * 1e3;
        if result.solids.is_empty() {
            return Err(format!(
                "the {} is empty: the bodies {}",
                op.name(),
                match op {
                    BooleanOp::Intersection => "do not overlap",
                    _ => "leave nothing",
                }
            ));
        }
        let mut volume = 0.0;
        let mut faces = 0;
        let mut solids = Vec::new();
        for (k, solid) in result.solids.iter().enumerate() {
            let all = solid.faces();
            faces += all.len();
            volume += solid.volume().map_err(|e| e.to_string())?;
            solids.push((
                format!("{} {}", op.name(), k + 1),
                all,
                solid.topology.clone(),
            ));
        }
        let at = std::time::Instant::now();
        let left_out = write_solids(scene_a.unit, solids, tolerance, output)?;
        let write_ms = at.elapsed().as_secs_f64() * 1e3;
        Ok(serde_json::json!({
            "operation": op.name(),
            "solids": result.solids.len(),
            "voids": result.solids.iter().map(|s| s.shells.len() - 1).sum::<usize>(),
            "faces": faces,
            "volume": volume,
            "tolerance": tolerance,
            "split_faces": result.split_faces,
            "read_ms": read_ms,
            "boolean_ms": boolean_ms,
            "write_ms": write_ms,
            "left_out": left_out,
        }))
    };
    finish("boolean", run())
}

/// Writes the named solids (each its faces and their shared edges, joined within ten times
/// `tolerance`) to the STEP file `output` in `unit`; returns what the writer left out.
pub(super) fn write_solids(
    unit: Option<knotwork::kernel::format::LengthUnit>,
    solids: Vec<(String, Vec<TrimmedSurface>, Topology)>,
    tolerance: f64,
    output: &std::path::Path,
) -> Result<serde_json::Value, String> {
    let mut scene = Scene {
        unit,
        ..Scene::default()
    };
    scene.objects.clear();
    for (name, faces, topology) in solids {
        let p = Polysurface::with_topology(faces, tolerance * 10.0, topology)
            .map_err(|e| e.to_string())?;
        scene
            .objects
            .push(SceneObject::new(name, ObjectGeometry::new(p)));
    }
    let name = output.to_string_lossy();
    let step_tolerance = knotwork::io::step::default_tolerance(&scene);
    let written = knotwork::io::step::export_scene(&scene, &name, step_tolerance)
        .map_err(|e| e.to_string())?;
    std::fs::write(output, written.text)
        .map_err(|e| format!("cannot write {}: {e}", output.display()))?;
    Ok(serde_json::json!(written.left_out))
}
