//! `knotwork bench` (and `cargo bench --bench gpu_eval`): throughput of the compute pass and
//! edit latency on whatever adapter wgpu finds (lavapipe where there is no GPU).
//!
//! - Throughput: vertices (position, normal, (u, v), curvature) per second of the evaluation
//!   pass, timed with timestamp queries where the device has them (else wall time around
//!   submit-and-wait), for the Utah teapot at 64 and 128 segments per patch and a 32 × 32 bicubic
//!   B-spline at 16 segments per span.
//! - Edit latency: wall time from a control-point change in the document to the updated vertex
//!   buffer being ready on the GPU: local re-decomposition on the CPU, upload of the changed
//!   Bézier points, the compute pass over the moved point's support, and the wait for it.
//!
//! Figures are medians over the iterations.

use std::io::Write;
use std::time::Instant;

use glam::DVec3;

use crate::gpu::timing::GpuTimer;
use crate::gpu::{GpuContext, GpuError, ObjectPatches, PatchEvaluator, PatchGeometry};
use crate::kernel::construct;
use crate::scene::{Decomposition, ObjectGeometry, Scene, SceneObject};

fn median(mut values: Vec<f64>) -> f64 {
    values.sort_by(f64::total_cmp);
    values.get(values.len() / 2).copied().unwrap_or(f64::NAN)
}

/// A 32 × 32 bicubic B-spline surface (29 × 29 Bézier patches) over uniform knots, a gentle
/// landscape 10 units across.
pub fn large_bspline() -> Result<SceneObject, crate::kernel::GeometryError> {
    let n = 32;
    let points = (0..n)
        .flat_map(|i| {
            (0..n).map(move |j| {
                let (x, y) = (i as f64 / 3.1, j as f64 / 3.1);
                DVec3::new(x, y, 0.6 * (x * 0.9).sin() * (y * 0.7).cos())
            })
        })
        .collect();
    let surface = construct::bspline_surface([3, 3], [n, n], points)?;
    Ok(SceneObject::new(
        "bicubic B-spline 32 × 32",
        ObjectGeometry::Nurbs(surface),
    ))
}

/// Submits one evaluation and waits for it; returns (GPU ms if timed, wall ms, patches).
fn evaluate_once(
    context: &GpuContext,
    evaluator: &PatchEvaluator,
    geometry: &mut PatchGeometry,
    timer: &mut Option<GpuTimer>,
) -> Result<(Option<f64>, f64, u32), GpuError> {
    let start = Instant::now();
    let mut encoder = context.device.create_command_encoder(&Default::default());
    let writes = timer.as_mut().and_then(GpuTimer::compute_pass_writes);
    let patches = geometry.encode(&context.queue, &mut encoder, evaluator, writes);
    if let Some(timer) = timer.as_mut() {
        timer.resolve(&mut encoder);
    }
    context.queue.submit([encoder.finish()]);
    if let Some(timer) = timer.as_mut() {
        timer.after_submit();
    }
    wait(context)?;
    let wall = start.elapsed().as_secs_f64() * 1e3;
    let mut gpu = None;
    if let Some(timer) = timer.as_mut() {
        while timer.pending() {
            wait(context)?;
        }
        timer.collect();
        gpu = timer.latest.eval_ms;
    }
    Ok((gpu, wall, patches))
}

fn wait(context: &GpuContext) -> Result<(), GpuError> {
    context
        .device
        .poll(wgpu::PollType::wait_indefinitely())
        .map(|_| ())
        .map_err(|e| GpuError::Readback(e.to_string()))
}

fn upload(
    context: &GpuContext,
    evaluator: &PatchEvaluator,
    objects: &[SceneObject],
    decompositions: &[Decomposition],
) -> Result<PatchGeometry, GpuError> {
    let inputs: Vec<ObjectPatches<'_>> = objects
        .iter()
        .zip(decompositions)
        .map(|(o, d)| ObjectPatches {
            set: &d.set,
            domains: &d.domains,
            segments: o.segments,
        })
        .collect();
    PatchGeometry::new(&context.device, evaluator, &inputs)
}

/// Benchmarks one object at its segments: full-evaluation throughput, then edit latency for
/// moving control point `edit_point` back and forth.
fn bench_object(
    context: &GpuContext,
    evaluator: &PatchEvaluator,
    mut object: SceneObject,
    edit_point: usize,
    iterations: usize,
    out: &mut impl Write,
) -> Result<(), Box<dyn std::error::Error>> {
    let start = Instant::now();
    let mut decomposition = object.decompose()?;
    let decompose_ms = start.elapsed().as_secs_f64() * 1e3;
    let mut geometry = upload(
        context,
        evaluator,
        std::slice::from_ref(&object),
        std::slice::from_ref(&decomposition),
    )?;
    let mut timer = GpuTimer::new(&context.device, &context.queue);
    let (mut gpu_ms, mut wall_ms) = (Vec::new(), Vec::new());
    for i in 0..iterations + 2 {
        geometry.invalidate();
        let (gpu, wall, _) = evaluate_once(context, evaluator, &mut geometry, &mut timer)?;
        if i >= 2 {
            gpu_ms.extend(gpu);
            wall_ms.push(wall);
        }
    }
    let vertices = f64::from(geometry.vertex_count());
    let (gpu, wall) = (
        (!gpu_ms.is_empty()).then(|| median(gpu_ms)),
        median(wall_ms),
    );
    let pass = gpu.unwrap_or(wall);
    writeln!(
        out,
        "{:<26} {:>3} seg | {:>7} patches {:>9} vertices | pass {:8.3} ms ({}) | {:7.2} M vertices/s | submit+wait {:8.3} ms",
        object.name,
        object.segments,
        geometry.patch_count(),
        geometry.vertex_count(),
        pass,
        if gpu.is_some() { "timestamps" } else { "wall" },
        vertices / (pass * 1e-3) / 1e6,
        wall,
    )?;

    // Edit latency: move one point up and down, as a drag does.
    let base = object.control_points()[edit_point];
    let mut latency = Vec::new();
    let mut patches = 0;
    for i in 0..iterations + 2 {
        let lift = if i % 2 == 0 { 0.05 } else { 0.0 };
        let start = Instant::now();
        let support = object.move_control_point(edit_point, base + DVec3::Z * lift)?;
        decomposition = object.decompose()?;
        geometry.update_object(&context.queue, 0, &decomposition.set, Some(&support))?;
        let mut no_timer = None;
        let (_, _, evaluated) = evaluate_once(context, evaluator, &mut geometry, &mut no_timer)?;
        if i >= 2 {
            latency.push(start.elapsed().as_secs_f64() * 1e3);
            patches = evaluated;
        }
    }
    writeln!(
        out,
        "{:<26} {:>3} seg | edit latency {:8.3} ms (point {edit_point}: {patches} patches re-evaluated; decomposition alone {decompose_ms:.3} ms)",
        object.name,
        object.segments,
        median(latency),
    )?;
    Ok(())
}

/// Runs every benchmark on `context`, printing one line per figure.
pub fn run(
    context: &GpuContext,
    iterations: usize,
    out: &mut impl Write,
) -> Result<(), Box<dyn std::error::Error>> {
    writeln!(out, "adapter: {}", context.describe())?;
    let evaluator = PatchEvaluator::new(&context.device);
    let scene = Scene::demo()?;
    let teapot = scene
        .objects
        .first()
        .cloned()
        .ok_or("the demo scene has no teapot")?;
    for segments in [64, 128] {
        let mut t = teapot.clone();
        t.segments = segments;
        // A point of the body, shared by two patches.
        bench_object(context, &evaluator, t, 40, iterations, out)?;
    }
    let mut big = large_bspline()?;
    big.segments = 16;
    bench_object(context, &evaluator, big, 16 * 32 + 16, iterations, out)?;

    // The whole demo scene in one pass at its default tessellation.
    let decompositions: Vec<Decomposition> = scene
        .objects
        .iter()
        .map(SceneObject::decompose)
        .collect::<Result<_, _>>()?;
    let mut geometry = upload(context, &evaluator, &scene.objects, &decompositions)?;
    let mut timer = GpuTimer::new(&context.device, &context.queue);
    let mut times = Vec::new();
    for i in 0..iterations + 2 {
        geometry.invalidate();
        let (gpu, wall, _) = evaluate_once(context, &evaluator, &mut geometry, &mut timer)?;
        if i >= 2 {
            times.push(gpu.unwrap_or(wall));
        }
    }
    writeln!(
        out,
        "demo scene (6 objects)        | {:>7} patches {:>9} vertices | pass {:8.3} ms, one compute pass",
        geometry.patch_count(),
        geometry.vertex_count(),
        median(times),
    )?;
    Ok(())
}
