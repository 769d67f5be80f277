//! The view-adaptive tessellation on the GPU (lavapipe where there is none), checked against
//! independent computations:
//! - each visible patch's levels against the f64 rule of `gpu::adaptive::ScreenError`;
//! - the culling against the control hulls' projections, computed here;
//! - every triangle against the layout's Rust reference (`PatchLevels::triangle`);
//! - every vertex against the f64 kernel's evaluation of its patch at its (s, t);
//! - watertightness: wherever two patches share an edge, both write it with one count and
//!   bit-identical vertices, even after the scan had to coarsen everything to fit;
//! - the vertex count follows the screen, not the model.

use crate::common;

use std::collections::HashMap;

use glam::{DVec3, DVec4, Vec3};
use knotwork::gpu::adaptive::PatchLevels;
use knotwork::gpu::adaptive_pass::{AdaptiveStats, AdaptiveTarget};
use knotwork::gpu::patch_eval::Tessellation;
use knotwork::gpu::records::{AdaptiveSlot, SurfaceVertex};
use knotwork::gpu::{GpuContext, ObjectPatches, PatchEvaluator, PatchGeometry};
use knotwork::render::adaptive_target;
use knotwork::scene::{Decomposition, Scene};
use knotwork::view::OrbitCamera;

const SIZE: (u32, u32) = (1280, 800);

/// The evaluator's input for `feeds` (Bézier patches only).
fn patch_inputs(feeds: &[Decomposition]) -> Vec<ObjectPatches<'_>> {
    feeds
        .iter()
        .map(|d| ObjectPatches {
            set: &d.set,
            domains: &d.domains,
            segments: 8,
            stencils: None,
            cage_points: 0,
            trims: None,
            displacement: None,
            lattice: None,
        })
        .collect()
}

struct Evaluated {
    stats: AdaptiveStats,
    slots: Vec<AdaptiveSlot>,
    vertices: Vec<SurfaceVertex>,
    indices: Vec<u32>,
}

fn evaluate(
    context: &GpuContext,
    evaluator: &PatchEvaluator,
    feeds: &[Decomposition],
    room: u32,
    target: AdaptiveTarget,
) -> Evaluated {
    let inputs = patch_inputs(feeds);
    let mut geometry = PatchGeometry::with_tessellation(
        &context.device,
        evaluator,
        &inputs,
        Tessellation::Adaptive { vertices: room },
    )
    .unwrap();
    geometry.set_view(target);
    assert!(geometry.needs_evaluation());
    let mut encoder = context.device.create_command_encoder(&Default::default());
    geometry.encode(&context.queue, &mut encoder, evaluator, None);
    context.queue.submit([encoder.finish()]);
    assert!(!geometry.needs_evaluation(), "the same view needs no pass");
    let pass = geometry.adaptive_pass().unwrap();
    let stats = pass.read_stats(&context.device, &context.queue).unwrap();
    let slots = pass.read_slots(&context.device, &context.queue).unwrap();
    Evaluated {
        stats,
        slots,
        vertices: geometry
            .read_vertices(&context.device, &context.queue)
            .unwrap(),
        indices: geometry
            .read_triangle_indices(&context.device, &context.queue)
            .unwrap(),
    }
}

/// Every Bézier patch of the scene in record order: (object, patch index, degrees, homogeneous
/// control points, pool indices).
struct PatchInfo {
    object: usize,
    patch: usize,
    degree: [usize; 2],
    points: Vec<DVec4>,
    indices: Vec<u32>,
}

fn patches(feeds: &[Decomposition]) -> Vec<PatchInfo> {
    let mut out = Vec::new();
    for (object, d) in feeds.iter().enumerate() {
        for (k, patch) in d.set.patches().iter().enumerate() {
            let points = patch
                .indices()
                .iter()
                .map(|&i| {
                    let w = d.set.weights()[i as usize];
                    (d.set.points()[i as usize] * w).extend(w)
                })
                .collect();
            out.push(PatchInfo {
                object,
                patch: k,
                degree: [patch.degree_u(), patch.degree_v()],
                points,
                indices: patch.indices().to_vec(),
            });
        }
    }
    out
}

fn demo_feeds() -> Vec<Decomposition> {
    let scene = Scene::demo().unwrap();
    scene
        .objects
        .iter()
        .map(|o| o.decompose().unwrap())
        .filter(|d| d.stencils.is_none() && d.trims.is_none())
        .collect()
}

fn camera_at(distance: f32) -> OrbitCamera {
    OrbitCamera {
        distance,
        ..OrbitCamera::default()
    }
}

/// The teapot alone, and a camera looking at its middle from `distance`.
fn teapot_feed() -> Vec<Decomposition> {
    vec![Scene::demo().unwrap().objects[0].decompose().unwrap()]
}

fn teapot_camera(feeds: &[Decomposition], distance: f32) -> OrbitCamera {
    let (lo, hi) = feeds[0].set.bounds().unwrap();
    OrbitCamera {
        target: ((lo + hi) * 0.5).as_vec3(),
        distance,
        ..OrbitCamera::default()
    }
}

/// Whether all control points lie outside one clip plane (computed in f64 here).
fn hull_outside(target: &AdaptiveTarget, points: &[DVec4]) -> bool {
    let m = target.view_proj.as_dmat4();
    let mut outside = 63u32;
    for p in points {
        let c = m * *p;
        let mut code = 0;
        code |= u32::from(c.x < -c.w);
        code |= u32::from(c.x > c.w) << 1;
        code |= u32::from(c.y < -c.w) << 2;
        code |= u32::from(c.y > c.w) << 3;
        code |= u32::from(c.z < 0.0) << 4;
        code |= u32::from(c.z > c.w) << 5;
        outside &= code;
    }
    outside != 0
}

fn levels_of(slot: &AdaptiveSlot) -> PatchLevels {
    PatchLevels::new(slot.edges, slot.inner)
}

/// The control point pool indices of edge `edge` of a (p, q) patch, in the layout's direction.
fn edge_indices(info: &PatchInfo, edge: usize) -> Vec<u32> {
    let [p, q] = info.degree;
    let at = |i: usize, j: usize| info.indices[i * (q + 1) + j];
    match edge {
        0 => (0..=p).map(|i| at(i, 0)).collect(),
        1 => (0..=q).map(|j| at(p, j)).collect(),
        2 => (0..=p).map(|i| at(i, q)).collect(),
        _ => (0..=q).map(|j| at(0, j)).collect(),
    }
}

/// An edge: its object and its control point indices in canonical order.
type EdgeKey = (usize, Vec<u32>);
/// One side of an edge: slot, edge of the layout, and whether it runs reversed.
type EdgeSide = (usize, usize, bool);

/// Asserts that every edge two visible patches share has one count and bit-identical vertices
/// on both sides. Returns how many shared edges were compared.
fn assert_watertight(run: &Evaluated, infos: &[PatchInfo]) -> usize {
    // Edge vertices of each slot: (edge, m) -> position bits.
    let mut by_edge: HashMap<EdgeKey, Vec<EdgeSide>> = HashMap::new();
    for (s, slot) in run.slots.iter().enumerate() {
        if slot.culled != 0 || slot.vertex_count == 0 {
            continue;
        }
        let info = &infos[slot.record as usize];
        for edge in 0..4 {
            let seq = edge_indices(info, edge);
            let mut canonical = seq.clone();
            canonical.reverse();
            let reversed = canonical < seq;
            let key = if reversed { canonical } else { seq };
            by_edge
                .entry((info.object, key))
                .or_default()
                .push((s, edge, reversed));
        }
    }
    let edge_vertices = |s: usize, edge: usize| -> Vec<[u32; 3]> {
        let slot = &run.slots[s];
        let levels = levels_of(slot);
        let mut out = vec![[0; 3]; slot.edges[edge] as usize + 1];
        for k in 0..levels.vertex_count() {
            if let (_, Some((e, m, _))) = levels.vertex(k)
                && e == edge
            {
                let v = run.vertices[(slot.vertex_offset + k) as usize];
                out[m as usize] = v.position.map(f32::to_bits);
            }
        }
        out
    };
    let mut shared = 0;
    for sides in by_edge.values() {
        for pair in sides.windows(2) {
            let [(a, ea, ra), (b, eb, rb)] = [pair[0], pair[1]];
            assert_eq!(
                run.slots[a].edges[ea], run.slots[b].edges[eb],
                "patches {a} and {b} give their shared edge different counts"
            );
            let mut va = edge_vertices(a, ea);
            let mut vb = edge_vertices(b, eb);
            if ra {
                va.reverse();
            }
            if rb {
                vb.reverse();
            }
            assert_eq!(
                va, vb,
                "patches {a} and {b} write their shared edge differently"
            );
            shared += 1;
        }
    }
    shared
}

#[test]
fn the_adaptive_tessellation_matches_its_references_and_is_watertight() {
    let context = common::gpu();
    let evaluator = PatchEvaluator::new(&context.device);
    let feeds = demo_feeds();
    let infos = patches(&feeds);
    let camera = camera_at(9.0);
    let target = adaptive_target(&camera, SIZE, 0.5);
    let run = evaluate(&context, &evaluator, &feeds, 1 << 21, target);
    assert_eq!(run.slots.len(), infos.len());
    assert_eq!(run.stats.shift, 0, "{:?}", run.stats);
    assert_eq!(run.stats.dropped, 0);

    let mut visible = 0;
    let mut level_differences = 0;
    let mut checked_vertices = 0;
    let mut worst = 0.0f64;
    for (s, slot) in run.slots.iter().enumerate() {
        let info = &infos[slot.record as usize];
        assert_eq!(
            slot.culled != 0,
            hull_outside(&target, &info.points),
            "slot {s}: culling"
        );
        if slot.culled != 0 {
            assert_eq!((slot.vertex_count, slot.triangle_count), (0, 0));
            continue;
        }
        visible += 1;
        // Levels: the f64 rule; f32 may round a count across an integer, never more.
        let expected = target.error.patch_levels(info.degree, &info.points);
        for (got, want) in slot
            .edges
            .iter()
            .chain(&slot.inner)
            .zip(expected.edges.iter().chain(&expected.inner))
        {
            assert!(
                got.abs_diff(*want) <= 1,
                "slot {s}: {slot:?} vs {expected:?}"
            );
            level_differences += u32::from(got != want);
        }
        let levels = levels_of(slot);
        assert_eq!(slot.vertex_count, levels.vertex_count());
        assert_eq!(slot.triangle_count, levels.triangle_count());
        // Triangles: the Rust layout, offset into the slot's vertices.
        for k in 0..levels.triangle_count() {
            let want = levels.triangle(k).unwrap().map(|v| v + slot.vertex_offset);
            let at = (slot.index_offset + 3 * k) as usize;
            assert_eq!(run.indices[at..at + 3], want, "slot {s} triangle {k}");
        }
        // Vertices: the kernel's f64 point at (s, t), the (u, v), the object and record.
        let set = &feeds[info.object].set;
        let scale = set
            .bounds()
            .map_or(1.0, |(lo, hi)| (hi - lo).length().max(1e-9));
        for k in 0..levels.vertex_count() {
            let (st, _) = levels.vertex(k);
            let v = run.vertices[(slot.vertex_offset + k) as usize];
            let exact = set.evaluate(info.patch, st.x, st.y).unwrap().point;
            let error = (DVec3::from(Vec3::from(v.position)) - exact).length() / scale;
            worst = worst.max(error);
            assert!(
                error < 2e-5,
                "slot {s} vertex {k}: off by {error} of the size"
            );
            assert_eq!(v.object() as usize, info.object);
            assert_eq!(v.record as usize, slot.record as usize);
            checked_vertices += 1;
        }
    }
    let shared = assert_watertight(&run, &infos);
    eprintln!(
        "{visible} of {} patches visible, {checked_vertices} vertices, worst distance {worst:.2e} \
         of the size, {level_differences} levels one off the f64 rule, {shared} shared edges \
         bit-identical; stats {:?}",
        infos.len(),
        run.stats
    );
    assert!(
        visible > 0 && shared > 50,
        "{visible} visible, {shared} shared"
    );
    assert_eq!(run.stats.visible_patches, visible);
    assert_eq!(
        run.stats.vertices,
        run.slots.iter().map(|s| s.vertex_count).sum::<u32>()
    );
    assert_eq!(
        run.stats.indices,
        3 * run.slots.iter().map(|s| s.triangle_count).sum::<u32>()
    );
}

#[test]
fn the_vertex_count_follows_the_screen_and_the_room() {
    let context = common::gpu();
    let evaluator = PatchEvaluator::new(&context.device);
    let feeds = teapot_feed();
    let infos = patches(&feeds);
    let seen_from = |distance: f32, tolerance_px: f64| {
        evaluate(
            &context,
            &evaluator,
            &feeds,
            1 << 21,
            adaptive_target(&teapot_camera(&feeds, distance), SIZE, tolerance_px),
        )
    };
    let near = seen_from(9.0, 0.5);
    let far = seen_from(36.0, 0.5);
    let loose = seen_from(9.0, 4.0);
    // Close up: part of the scene leaves the view and is culled.
    let close = seen_from(2.0, 0.5);
    eprintln!(
        "vertices: at 9 {}, at 36 {}, at 9 with 4 px {}, at 2 {} ({} of {} patches visible)",
        near.stats.vertices,
        far.stats.vertices,
        loose.stats.vertices,
        close.stats.vertices,
        close.stats.visible_patches,
        infos.len()
    );
    assert!(far.stats.vertices * 3 < near.stats.vertices);
    assert!(loose.stats.vertices * 4 < near.stats.vertices * 3);
    assert!(close.stats.visible_patches < near.stats.visible_patches);

    // Too little room: every level is halved alike until the patches fit, and shared edges
    // still agree.
    let room = near.stats.vertices / 5;
    let tight = evaluate(
        &context,
        &evaluator,
        &feeds,
        room,
        adaptive_target(&teapot_camera(&feeds, 9.0), SIZE, 0.5),
    );
    eprintln!("room {room}: {:?}", tight.stats);
    assert!(tight.stats.shift > 0);
    assert!(tight.stats.vertices <= room && tight.stats.dropped == 0);
    assert_eq!(tight.stats.needed_vertices, near.stats.vertices);
    assert!(assert_watertight(&tight, &infos) > 50);
    // Room for almost nothing: patches are dropped, nothing is written past the room.
    let starved = evaluate(
        &context,
        &evaluator,
        &feeds,
        40,
        adaptive_target(&teapot_camera(&feeds, 9.0), SIZE, 0.5),
    );
    assert!(starved.stats.dropped > 0 && starved.stats.vertices <= 40);
    assert!(starved.indices.iter().all(|&i| i < starved.stats.vertices));
}

/// While a drag lasts the levels stay as measured and an edit re-evaluates only its patches,
/// which then match the kernel at the moved points and stay watertight; after the drag every
/// patch is measured again.
#[test]
fn a_drag_re_evaluates_its_patches_at_frozen_levels() {
    let context = common::gpu();
    let evaluator = PatchEvaluator::new(&context.device);
    let mut feeds = teapot_feed();
    let target = adaptive_target(&teapot_camera(&feeds, 9.0), SIZE, 0.5);
    // The uploaded copy; `feeds` is edited below.
    let uploaded = feeds.clone();
    let objects = patch_inputs(&uploaded);
    let mut geometry = PatchGeometry::with_tessellation(
        &context.device,
        &evaluator,
        &objects,
        Tessellation::Adaptive { vertices: 1 << 20 },
    )
    .unwrap();
    let run = |geometry: &mut PatchGeometry| {
        let mut encoder = context.device.create_command_encoder(&Default::default());
        let evaluated = geometry.encode(&context.queue, &mut encoder, &evaluator, None);
        context.queue.submit([encoder.finish()]);
        evaluated
    };
    geometry.set_view(target);
    assert_eq!(run(&mut geometry), 32);
    let before = geometry
        .adaptive_pass()
        .unwrap()
        .read_slots(&context.device, &context.queue)
        .unwrap();

    // Move a body point shared by patches 0 and 1 (their common edge's second point).
    let shared = feeds[0].set.patches()[0].indices()[3 * 4 + 1];
    let moved = feeds[0].set.points()[shared as usize] + DVec3::new(0.0, 0.0, 0.8);
    feeds[0].set.set_point(shared as usize, moved).unwrap();
    let support: Vec<usize> = feeds[0]
        .set
        .patches()
        .iter()
        .enumerate()
        .filter(|(_, p)| p.indices().contains(&shared))
        .map(|(k, _)| k)
        .collect();
    geometry.freeze_levels(true);
    geometry
        .update_object(&context.queue, 0, &feeds[0].set, Some(&support))
        .unwrap();
    assert!(geometry.needs_evaluation());
    assert_eq!(
        run(&mut geometry) as usize,
        support.len(),
        "only the support"
    );
    let pass = geometry.adaptive_pass().unwrap();
    let slots = pass.read_slots(&context.device, &context.queue).unwrap();
    assert_eq!(slots, before, "the levels and places stay while frozen");
    let stats = pass.read_stats(&context.device, &context.queue).unwrap();
    let evaluated = Evaluated {
        stats,
        slots,
        vertices: geometry
            .read_vertices(&context.device, &context.queue)
            .unwrap(),
        indices: Vec::new(),
    };
    let infos = patches(&feeds);
    for &k in &support {
        let slot = evaluated
            .slots
            .iter()
            .find(|s| s.record as usize == k)
            .unwrap();
        let levels = levels_of(slot);
        for v in 0..levels.vertex_count() {
            let (st, _) = levels.vertex(v);
            let got = evaluated.vertices[(slot.vertex_offset + v) as usize].position;
            let exact = feeds[0].set.evaluate(k, st.x, st.y).unwrap().point;
            assert!(
                (DVec3::from(Vec3::from(got)) - exact).length() < 1e-4,
                "patch {k} vertex {v} at the moved points"
            );
        }
    }
    assert!(assert_watertight(&evaluated, &infos) > 10);
    // The drag ends: everything is measured again.
    geometry.freeze_levels(false);
    assert!(geometry.needs_evaluation());
    assert_eq!(run(&mut geometry), 32);
    assert!(!geometry.needs_evaluation());
}
