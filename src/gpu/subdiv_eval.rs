//! A subdivision surface's level evaluated by the compute shaders alone (`knotwork subdivide
//! --backend gpu` and the tests): every face as stencil patches, each slot read back to the
//! level vertex it shows.

use glam::DVec3;

use super::error::GpuError;
use super::patch_eval::{ObjectPatches, PatchGeometry};
use super::pipelines::PatchEvaluator;
use crate::kernel::BezierPatchSet;
use crate::kernel::subdiv::SubdivisionSurface;
use crate::kernel::subdiv::patches::{Display, LimitFeed};

/// What the GPU computed for each vertex of a level: position, unit normal and (K, H, k1, k2),
/// `None` for vertices on no face.
pub type LevelVertices = Vec<Option<(DVec3, DVec3, [f64; 4])>>;

/// Evaluates `surface` at level `levels` (≥ 1) on the GPU as `display` shows it: the limit
/// (or refined, or substitute) position, the normal and the curvatures of every vertex of the
/// level. A substitute's patches are evaluated from their control points, the faces it leaves
/// exact from the limit stencils.
pub fn evaluate_level(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    surface: &SubdivisionSurface,
    levels: u32,
    display: Display,
) -> Result<LevelVertices, GpuError> {
    let geometry = |e: crate::kernel::GeometryError| GpuError::Geometry(e.to_string());
    if let Some(kind) = display.substitute() {
        let (feed, plan) = surface
            .substitute_feed(levels, kind, false)
            .map_err(geometry)?;
        let mut points = surface.points().to_vec();
        points.extend(plan.control_points(surface.points()));
        return evaluate_feed(device, queue, &points, &feed);
    }
    let feed = surface
        .limit_feed_with(levels, display, false)
        .map_err(geometry)?;
    evaluate_feed(device, queue, surface.points(), &feed)
}

/// Evaluates the adaptive limit of `surface` up to level `levels` (≥ 1) with flatness
/// tolerance `tolerance` ([`SubdivisionSurface::adaptive_feed`]) on the GPU: the result of
/// every level vertex a piece shows.
pub fn evaluate_adaptive(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    surface: &SubdivisionSurface,
    levels: u32,
    tolerance: f64,
) -> Result<LevelVertices, GpuError> {
    let (feed, _) = surface
        .adaptive_feed(levels, tolerance)
        .map_err(|e| GpuError::Geometry(e.to_string()))?;
    evaluate_feed(device, queue, surface.points(), &feed)
}

/// Evaluates every stencil and substitute patch of `feed` over `cage` (the cage's points,
/// then any substitute's control points) on the GPU and returns each level vertex's result.
pub fn evaluate_feed(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    cage: &[DVec3],
    feed: &LimitFeed,
) -> Result<LevelVertices, GpuError> {
    let set = BezierPatchSet::new(cage.to_vec(), None, Vec::new())
        .map_err(|e| GpuError::Geometry(e.to_string()))?;
    let evaluator = PatchEvaluator::new(device);
    let mut geometry = PatchGeometry::new(
        device,
        &evaluator,
        &[ObjectPatches {
            set: &set,
            domains: &[],
            segments: 1,
            stencils: Some(feed),
            cage_points: cage.len(),
            trims: None,
            displacement: None,
            lattice: None,
        }],
    )?;
    let mut encoder = device.create_command_encoder(&Default::default());
    geometry.encode(queue, &mut encoder, &evaluator, None);
    queue.submit([encoder.finish()]);
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| GpuError::Readback(e.to_string()))?;
    let vertices = geometry.read_vertices(device, queue)?;
    let count = feed
        .vertex
        .iter()
        .filter(|&&v| v != u32::MAX)
        .max()
        .map_or(0, |&v| v as usize + 1);
    let mut out: LevelVertices = vec![None; count];
    let grids = feed.patches.iter().map(|p| (p.segments, p.first_slot));
    let grids = grids.chain(feed.substitutes.iter().map(|p| (p.segments, p.first_slot)));
    for (record, (segments, first_slot)) in geometry.records().iter().zip(grids) {
        let slots = (segments as usize + 1).pow(2);
        for k in 0..slots {
            let vertex = feed.vertex[first_slot as usize + k];
            if vertex == u32::MAX {
                continue;
            }
            let v = vertices[record.vertex_offset as usize + k];
            let f = |a: [f32; 3]| DVec3::from(a.map(f64::from));
            out[vertex as usize] = Some((f(v.position), f(v.normal), v.curvature().map(f64::from)));
        }
    }
    Ok(out)
}
