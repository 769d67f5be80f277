//! The compute evaluator on a real wgpu device (lavapipe in CI) against the f64 CPU reference.

mod common;

use glam::DVec3;
use knotwork::gpu::{GpuError, MAX_SEGMENTS, PatchEvaluator, PatchGeometry, SurfaceVertex};
use knotwork::kernel::{BezierPatch, BezierPatchSet, samples};

/// Largest deviations of one GPU evaluation from the CPU reference.
#[derive(Debug, Default)]
struct Deviation {
    position: f64,
    normal_angle: f64,
    parameter: f64,
}

/// Compares every GPU vertex of `set` at `segments` with the f64 reference, returning the worst
/// position error relative to the model's size, normal angle (radians) and (u, v) error. Panics
/// on NaN.
fn compare_with_reference(
    set: &BezierPatchSet,
    segments: u32,
    vertices: &[SurfaceVertex],
) -> Deviation {
    let (lo, hi) = set.bounds().expect("non-empty set");
    let size = (hi - lo).length();
    let n = segments as usize + 1;
    assert_eq!(vertices.len(), set.patches().len() * n * n);
    let mut worst = Deviation::default();
    for k in 0..set.patches().len() {
        for i in 0..n {
            for j in 0..n {
                let vertex = &vertices[k * n * n + i * n + j];
                let values = vertex
                    .position
                    .iter()
                    .chain(&vertex.normal)
                    .chain([&vertex.u, &vertex.v]);
                assert!(
                    values.clone().all(|x| x.is_finite()),
                    "patch {k} ({i},{j}): {vertex:?}"
                );
                let (u, v) = (i as f64 / segments as f64, j as f64 / segments as f64);
                let reference = set.evaluate(k, u, v).unwrap();
                let normal = set.normal(k, u, v).unwrap();
                let position = DVec3::from(vertex.position.map(f64::from));
                let gpu_normal = DVec3::from(vertex.normal.map(f64::from)).normalize();
                let error = (position - reference.point).length() / size;
                let angle = gpu_normal.dot(normal).clamp(-1.0, 1.0).acos();
                let param = (f64::from(vertex.u) - u)
                    .abs()
                    .max((f64::from(vertex.v) - v).abs());
                worst.position = worst.position.max(error);
                worst.normal_angle = worst.normal_angle.max(angle);
                worst.parameter = worst.parameter.max(param);
            }
        }
    }
    worst
}

#[test]
fn teapot_on_the_gpu_matches_the_cpu_reference() {
    let context = common::gpu();
    let teapot = samples::utah_teapot().unwrap();
    let evaluator = PatchEvaluator::new(&context.device);
    for segments in [1, 7, 32, 64] {
        let mut geometry =
            PatchGeometry::new(&context.device, &evaluator, &teapot, segments).unwrap();
        common::evaluate(&context, &evaluator, &mut geometry);
        let vertices = geometry
            .read_vertices(&context.device, &context.queue)
            .unwrap();
        let worst = compare_with_reference(&teapot, segments, &vertices);
        eprintln!("teapot at {segments} segments: {worst:?}");
        assert!(worst.position <= 1e-5, "{segments}: {worst:?}");
        assert!(worst.normal_angle <= 1e-3, "{segments}: {worst:?}");
        assert!(worst.parameter <= 1e-6, "{segments}: {worst:?}");
    }
}

#[test]
fn triangles_cover_every_grid_and_face_along_the_normal() {
    let context = common::gpu();
    let teapot = samples::utah_teapot().unwrap();
    let evaluator = PatchEvaluator::new(&context.device);
    let segments = 9;
    let mut geometry = PatchGeometry::new(&context.device, &evaluator, &teapot, segments).unwrap();
    common::evaluate(&context, &evaluator, &mut geometry);
    let vertices = geometry
        .read_vertices(&context.device, &context.queue)
        .unwrap();
    let indices = geometry
        .read_triangle_indices(&context.device, &context.queue)
        .unwrap();
    let per_patch = (segments as usize).pow(2) * 2;
    assert_eq!(indices.len(), 32 * per_patch * 3);
    let mut used = vec![false; vertices.len()];
    let (mut facing, mut degenerate) = (0, 0);
    for (t, triangle) in indices.chunks_exact(3).enumerate() {
        let patch = t / per_patch;
        let [a, b, c] = [triangle[0], triangle[1], triangle[2]].map(|i| i as usize);
        let first = patch * (segments as usize + 1).pow(2);
        for i in [a, b, c] {
            assert!(
                (first..first + (segments as usize + 1).pow(2)).contains(&i),
                "triangle {t} leaves its patch"
            );
            used[i] = true;
        }
        let p = |i: usize| DVec3::from(vertices[i].position.map(f64::from));
        let n = |i: usize| DVec3::from(vertices[i].normal.map(f64::from));
        let area_normal = (p(b) - p(a)).cross(p(c) - p(a));
        let shortest_edge = [(a, b), (b, c), (c, a)]
            .map(|(x, y)| (p(x) - p(y)).length())
            .into_iter()
            .fold(f64::INFINITY, f64::min);
        // The teapot is about 7 units across; an edge of 1e-5 of that has collapsed (the f32
        // evaluation leaves the pole's copies a few ulps apart).
        if shortest_edge < 7e-5 {
            degenerate += 1; // a sliver at a collapsed edge
        } else if area_normal.dot(n(a) + n(b) + n(c)) > 0.0 {
            facing += 1;
        }
    }
    assert!(
        used.iter().all(|&u| u),
        "every vertex belongs to a triangle"
    );
    // Counter-clockwise about the outward normal: all but the collapsed-edge slivers.
    assert_eq!(
        facing + degenerate,
        indices.len() / 3,
        "{degenerate} degenerate"
    );
    assert_eq!(
        degenerate,
        8 * segments as usize,
        "one sliver per quad on the 8 collapsed edges"
    );
}

fn lcg(state: &mut u64) -> f64 {
    *state = state
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (*state >> 11) as f64 / (1u64 << 53) as f64
}

#[test]
fn rational_patches_of_every_supported_degree_match() {
    let context = common::gpu();
    let evaluator = PatchEvaluator::new(&context.device);
    let mut state = 42u64;
    let mut points = Vec::new();
    let mut weights = Vec::new();
    let mut patches = Vec::new();
    for (p, q) in [
        (1, 1),
        (1, 7),
        (2, 2),
        (3, 3),
        (3, 5),
        (4, 4),
        (7, 3),
        (7, 7),
    ] {
        let first = points.len() as u32;
        for _ in 0..(p + 1) * (q + 1) {
            points.push(DVec3::new(lcg(&mut state), lcg(&mut state), lcg(&mut state)) * 4.0 - 2.0);
            weights.push(0.2 + 4.8 * lcg(&mut state));
        }
        patches.push(BezierPatch::new(
            p,
            q,
            (first..points.len() as u32).collect(),
        ));
    }
    let set = BezierPatchSet::new(points, Some(weights), patches).unwrap();
    let mut geometry = PatchGeometry::new(&context.device, &evaluator, &set, 16).unwrap();
    common::evaluate(&context, &evaluator, &mut geometry);
    let vertices = geometry
        .read_vertices(&context.device, &context.queue)
        .unwrap();
    let worst = compare_with_reference(&set, 16, &vertices);
    eprintln!("random rational patches: {worst:?}");
    assert!(worst.position <= 1e-5, "{worst:?}");
    assert!(worst.normal_angle <= 1e-3, "{worst:?}");
}

#[test]
fn moved_control_points_are_re_evaluated() {
    let context = common::gpu();
    let mut teapot = samples::utah_teapot().unwrap();
    let evaluator = PatchEvaluator::new(&context.device);
    let mut geometry = PatchGeometry::new(&context.device, &evaluator, &teapot, 12).unwrap();
    common::evaluate(&context, &evaluator, &mut geometry);
    let before = geometry
        .read_vertices(&context.device, &context.queue)
        .unwrap();
    // Lift the knob's pole (shared by four patches) and push a body point outward.
    let pole = teapot
        .points()
        .iter()
        .position(|p| *p == DVec3::new(0.0, 0.0, 3.15))
        .unwrap();
    teapot.set_point(pole, DVec3::new(0.0, 0.0, 3.6)).unwrap();
    let body = teapot.patches()[5].index(1, 2) as usize;
    teapot.set_point(body, teapot.points()[body] * 1.3).unwrap();
    geometry
        .update_control_points(&context.queue, &teapot)
        .unwrap();
    common::evaluate(&context, &evaluator, &mut geometry);
    let after = geometry
        .read_vertices(&context.device, &context.queue)
        .unwrap();
    assert_ne!(before, after);
    let worst = compare_with_reference(&teapot, 12, &after);
    assert!(
        worst.position <= 1e-5 && worst.normal_angle <= 1e-3,
        "{worst:?}"
    );
}

#[test]
fn bad_requests_are_refused_and_leave_the_device_usable() {
    let context = common::gpu();
    let teapot = samples::utah_teapot().unwrap();
    let evaluator = PatchEvaluator::new(&context.device);
    let new = |segments| PatchGeometry::new(&context.device, &evaluator, &teapot, segments);
    assert!(matches!(
        new(0),
        Err(GpuError::SegmentsOutOfRange { segments: 0, .. })
    ));
    assert!(matches!(
        new(MAX_SEGMENTS + 1),
        Err(GpuError::SegmentsOutOfRange { .. })
    ));
    assert!(matches!(
        new(u32::MAX),
        Err(GpuError::SegmentsOutOfRange { .. })
    ));
    // 1024 segments: 1025² vertices × 32 patches × 32 bytes is far past the binding limit.
    match new(MAX_SEGMENTS) {
        Err(GpuError::BufferTooLarge {
            what: "vertex",
            bytes,
            limit,
        }) => assert!(bytes > limit),
        Ok(_) => panic!("1024 segments should not fit this device's default limits"),
        Err(e) => panic!("unexpected error {e}"),
    }
    // A degree the GPU evaluator does not take.
    let points = vec![DVec3::ZERO; 18];
    let set = BezierPatchSet::new(
        points.clone(),
        None,
        vec![BezierPatch::new(8, 1, (0..18).collect())],
    )
    .unwrap();
    assert!(matches!(
        PatchGeometry::new(&context.device, &evaluator, &set, 4),
        Err(GpuError::DegreeTooHigh {
            patch: 0,
            degree_u: 8,
            ..
        })
    ));
    // A model with a different point count cannot be written into existing buffers.
    let geometry = new(4).unwrap();
    assert!(matches!(
        geometry.update_control_points(&context.queue, &set),
        Err(GpuError::ControlPointCountChanged {
            expected: 290,
            found: 18
        })
    ));
    // The device still works.
    let mut geometry = new(4).unwrap();
    common::evaluate(&context, &evaluator, &mut geometry);
    let vertices = geometry
        .read_vertices(&context.device, &context.queue)
        .unwrap();
    assert!(compare_with_reference(&teapot, 4, &vertices).position <= 1e-5);
}
