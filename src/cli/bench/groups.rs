//! The benchmark groups of `knotwork bench` (and of `cargo bench --bench gpu_eval`, which
//! compiles this file in too; outside the library, so that its hot modules carry no benchmark
//! code): throughput of the compute pass and
//! edit latency on whatever adapter wgpu finds (lavapipe where there is no GPU).
//!
//! - Throughput: vertices (position, normal, (u, v), curvature) per second of the evaluation
//!   pass, timed with timestamp queries where the device has them (else wall time around
//!   submit-and-wait), for the Utah teapot at 64 and 128 segments per patch and a 32 × 32 bicubic
//!   B-spline at 16 segments per span.
//! - Edit latency: wall time from a control-point change in the document to the updated vertex
//!   buffer being ready on the GPU: re-deriving the Bézier patches of the moved point's support
//!   on the CPU (as a drag does), upload of the changed Bézier points, the compute pass over
//!   that support, and the wait for it. "Decomposition alone" is a whole-object decomposition.
//!
//! - Pick latency: projecting 10,000 control points (a 100 × 100 net, all on screen) and
//!   picking the one under a cursor, and a box selection, as a click in the editor does.
//! - Drag-to-new-frame latency: one drag step as the editor runs it (move the point, local
//!   re-decomposition, upload, compute pass over the support) plus the render pass of a
//!   1280 × 800 viewport with the control net, until the frame is finished on the GPU; for the
//!   teapot at 64 segments and a 64 × 64-control-point bicubic surface.
//!
//! Figures are medians over the iterations.

use std::io::Write;
use std::time::Instant;

use glam::DVec3;

use knotwork::doc::Document;
use knotwork::gpu::timing::GpuTimer;
use knotwork::gpu::{GpuContext, GpuError, SceneSync, SurfaceBuffers, SurfaceVertex};
use knotwork::kernel::{TrimmedSurface, construct};
use knotwork::render::{ControlNet, ViewTarget, ViewportRenderer, adaptive_target, scene_uniform};
use knotwork::scene::{ObjectGeometry, Scene, SceneObject};
use knotwork::view::pick::{self, PickView};
use knotwork::view::{OrbitCamera, ViewSettings};

/// Runs `f` `runs` times (at least once): the median wall time in milliseconds and the last
/// result.
fn median_ms<T, E>(runs: usize, mut f: impl FnMut() -> Result<T, E>) -> Result<(f64, T), E> {
    let mut times = Vec::new();
    loop {
        let started = Instant::now();
        let value = f()?;
        times.push(started.elapsed().as_secs_f64() * 1e3);
        if times.len() >= runs {
            return Ok((median(times), value));
        }
    }
}

/// The bytes of the repository's file `relative` (a reference fixture), the path named in the
/// error where it cannot be read.
fn reference_file(relative: &str) -> Result<Vec<u8>, String> {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(relative);
    std::fs::read(&path).map_err(|e| format!("{}: {e}", path.display()))
}

fn median(mut values: Vec<f64>) -> f64 {
    values.sort_by(f64::total_cmp);
    values.get(values.len() / 2).copied().unwrap_or(f64::NAN)
}

/// A 32 × 32 bicubic B-spline surface (29 × 29 Bézier patches) over uniform knots, a gentle
/// landscape 10 units across.
pub fn large_bspline() -> Result<SceneObject, knotwork::kernel::GeometryError> {
    landscape(32)
}

/// An n × n bicubic B-spline landscape over uniform knots.
pub fn landscape(n: usize) -> Result<SceneObject, knotwork::kernel::GeometryError> {
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
        format!("bicubic B-spline {n} × {n}"),
        ObjectGeometry::new(surface),
    ))
}

/// Submits one evaluation and waits for it; returns (GPU ms if timed, wall ms, patches).
fn evaluate_once(
    context: &GpuContext,
    sync: &mut SceneSync,
    timer: &mut Option<GpuTimer>,
) -> Result<(Option<f64>, f64, u32), GpuError> {
    let start = Instant::now();
    let mut encoder = context.device.create_command_encoder(&Default::default());
    let writes = timer.as_mut().and_then(GpuTimer::compute_pass_writes);
    let patches = sync.encode(&mut encoder, writes);
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

/// The median wall time over `runs` runs of `timed` (an update of the GPU copy), each run
/// set up by `before` (not timed) and started with the device idle (lavapipe runs the last
/// run's compute pass on these same cores, the work a GPU does beside the CPU). Each run's
/// uploads go out with a submission, as the editor's next frame sends them: without one they
/// pile up (a rebuild's buffers are held until then), and later runs slowed down up to five
/// times on a process of a gigabyte.
fn median_update_ms<T, R>(
    context: &GpuContext,
    runs: usize,
    mut before: impl FnMut() -> Result<T, Box<dyn std::error::Error>>,
    mut timed: impl FnMut(T) -> Result<R, Box<dyn std::error::Error>>,
) -> Result<f64, Box<dyn std::error::Error>> {
    let mut times = Vec::with_capacity(runs);
    for _ in 0..runs {
        let state = before()?;
        wait(context)?;
        let started = Instant::now();
        timed(state)?;
        context.queue.submit([]);
        times.push(started.elapsed().as_secs_f64() * 1e3);
    }
    Ok(median(times))
}

fn wait(context: &GpuContext) -> Result<(), GpuError> {
    context
        .device
        .poll(wgpu::PollType::wait_indefinitely())
        .map(|_| ())
        .map_err(|e| GpuError::Readback(e.to_string()))
}

/// A document of one object and its GPU copy, as the editor keeps them.
fn document_on_gpu(
    context: &GpuContext,
    object: SceneObject,
) -> Result<(Document, SceneSync), GpuError> {
    let doc = Document::new(Scene {
        objects: vec![object],
        unit: None,
    });
    let sync = SceneSync::with_scene(&context.device, &context.queue, &doc.scene, 1.0)?;
    Ok((doc, sync))
}

/// Benchmarks one object at its segments: full-evaluation throughput, then edit latency for
/// moving control point `edit_point` back and forth.
fn bench_object(
    context: &GpuContext,
    object: SceneObject,
    edit_point: usize,
    iterations: usize,
    out: &mut impl Write,
) -> Result<(), Box<dyn std::error::Error>> {
    let start = Instant::now();
    object.decompose()?;
    let decompose_ms = start.elapsed().as_secs_f64() * 1e3;
    let (mut doc, mut sync) = document_on_gpu(context, object)?;
    let mut timer = GpuTimer::new(&context.device, &context.queue);
    // The full pass with the vertices' curvature (the curvature modes) and without (the rest).
    for curvature in [true, false] {
        sync.set_vertex_curvature(curvature);
        let (mut gpu_ms, mut wall_ms) = (Vec::new(), Vec::new());
        for i in 0..iterations + 2 {
            sync.invalidate();
            let (gpu, wall, _) = evaluate_once(context, &mut sync, &mut timer)?;
            if i >= 2 {
                gpu_ms.extend(gpu);
                wall_ms.push(wall);
            }
        }
        let geometry = sync.geometry().ok_or("nothing on the GPU")?;
        let (patch_count, vertex_count) = (geometry.patch_count(), geometry.vertex_count());
        let vertices = f64::from(vertex_count);
        let best = |v: &[f64]| v.iter().copied().fold(f64::INFINITY, f64::min);
        let best_pass = if gpu_ms.is_empty() {
            best(&wall_ms)
        } else {
            best(&gpu_ms)
        };
        let (gpu, wall) = (
            (!gpu_ms.is_empty()).then(|| median(gpu_ms)),
            median(wall_ms),
        );
        let pass = gpu.unwrap_or(wall);
        writeln!(
            out,
            "{:<26} {:>3} seg | {:>7} patches {:>9} vertices | pass {:8.3} ms ({}, best {best_pass:.3} ms; {}) | {:7.2} M vertices/s, {:6.2} GB/s of vertices written | submit+wait {:8.3} ms",
            doc.scene.objects[0].name,
            doc.scene.objects[0].segments,
            patch_count,
            vertex_count,
            pass,
            if gpu.is_some() { "timestamps" } else { "wall" },
            if curvature {
                "with curvature"
            } else {
                "no curvature"
            },
            vertices / (pass * 1e-3) / 1e6,
            vertices * std::mem::size_of::<SurfaceVertex>() as f64 / (pass * 1e-3) / 1e9,
            wall,
        )?;
    }
    sync.set_vertex_curvature(true);

    // Edit latency: move one point up and down, as a drag does (the document's transient
    // edit, then the sync layer).
    doc.begin_drag(0, &[edit_point])?;
    let mut latency = Vec::new();
    let mut patches = 0;
    for i in 0..iterations + 2 {
        let lift = if i % 2 == 0 { 0.05 } else { 0.0 };
        let start = Instant::now();
        let moved = doc.drag_by(DVec3::Z * lift)?;
        sync.points_moved(&doc.scene, &moved)?;
        let mut no_timer = None;
        let (_, _, evaluated) = evaluate_once(context, &mut sync, &mut no_timer)?;
        if i >= 2 {
            latency.push(start.elapsed().as_secs_f64() * 1e3);
            patches = evaluated;
        }
    }
    doc.cancel_drag();
    writeln!(
        out,
        "{:<26} {:>3} seg | edit latency {:8.3} ms (point {edit_point}: {patches} patches re-evaluated; decomposition alone {decompose_ms:.3} ms)",
        doc.scene.objects[0].name,
        doc.scene.objects[0].segments,
        median(latency),
    )?;
    Ok(())
}

/// Pick latency with 10,000 control points on screen: projection of every point plus the pick
/// under a cursor, and a box selection over a quarter of the view.
fn bench_pick(iterations: usize, out: &mut impl Write) -> Result<(), Box<dyn std::error::Error>> {
    let object = landscape(100)?;
    let points = object.control_points();
    let (lo, hi) = object.bounds().ok_or("empty net")?;
    let mut camera = OrbitCamera::default();
    let (w, h) = (1280.0f32, 800.0f32);
    camera.frame(lo.as_vec3(), hi.as_vec3(), w / h);
    let view = PickView::new(camera.view_projection(w / h), w, h);
    let target = view
        .project(points[50 * 100 + 50])
        .ok_or("point off screen")?
        .screen;
    let on_screen = points.iter().filter_map(|&p| view.project(p)).count();
    let (mut pick_ms, mut box_ms) = (Vec::new(), Vec::new());
    let mut found = None;
    let mut boxed = 0;
    for _ in 0..iterations.max(5) * 5 {
        let start = Instant::now();
        let projected: Vec<_> = points.iter().map(|&p| view.project(p)).collect();
        found = pick::pick_point(&projected, target, knotwork::app::PICK_RADIUS);
        pick_ms.push(start.elapsed().as_secs_f64() * 1e3);
        let start = Instant::now();
        let projected: Vec<_> = points.iter().map(|&p| view.project(p)).collect();
        boxed = pick::points_in_box(
            &projected,
            glam::DVec2::new(320.0, 200.0),
            glam::DVec2::new(960.0, 600.0),
        )
        .len();
        box_ms.push(start.elapsed().as_secs_f64() * 1e3);
    }
    writeln!(
        out,
        "pick, {} control points ({on_screen} on screen) | click {:7.3} ms (picked {:?}) | box select {:7.3} ms ({boxed} points)",
        points.len(),
        median(pick_ms),
        found,
        median(box_ms),
    )?;
    Ok(())
}

/// Drag-to-new-frame latency: the editor's drag step for control point `point` of `object`
/// followed by the viewport's render pass, until the GPU has finished the frame.
fn bench_drag_frame(
    context: &GpuContext,
    object: SceneObject,
    point: usize,
    iterations: usize,
    out: &mut impl Write,
) -> Result<(), Box<dyn std::error::Error>> {
    let (name, segments, point_count) = (
        object.name.clone(),
        object.segments,
        object.control_point_count(),
    );
    let (lo, hi) = object.bounds().ok_or("empty object")?;
    let net = ControlNet::new(
        &context.device,
        &object.control_points(),
        &|k| k == point,
        &object.net_lines(),
    );
    let (mut doc, mut sync) = document_on_gpu(context, object)?;
    let renderer = ViewportRenderer::new(&context.device);
    let mut view = ViewSettings::default();
    view.camera.frame(lo.as_vec3(), hi.as_vec3(), 1.6);
    // As the editor draws a drag: at full quality on a GPU, at the lower quality in motion on a
    // software adapter; at the object's fixed segments, then tessellated for the view.
    let qualities = [
        (knotwork::render::Quality::hardware(), "GPU quality"),
        (
            knotwork::render::Quality::software(),
            "software-adapter quality",
        ),
    ];
    for (adaptive, (quality, label)) in [false, true]
        .into_iter()
        .flat_map(|a| qualities.into_iter().map(move |q| (a, q)))
    {
        let (samples, (w, h)) = quality.target((1280, 800), true);
        let mode = if adaptive {
            sync.set_adaptive(&doc.scene, true, 1.0)?;
            let target = knotwork::render::adaptive_target(
                &view.camera,
                (w, h),
                f64::from(view.tolerance_px),
            );
            sync.set_view(target);
            evaluate_once(context, &mut sync, &mut None)?;
            sync.read_adaptive_stats()?;
            if sync.grow_adaptive_room(&doc.scene, 1.0)? {
                sync.set_view(target);
                evaluate_once(context, &mut sync, &mut None)?;
            }
            let vertices = sync
                .read_adaptive_stats()?
                .map_or(0, |stats| stats.vertices);
            format!("adaptive 0.5 px, {vertices} vertices")
        } else {
            format!("{segments:>3} seg")
        };
        let target = ViewTarget::with_samples(&context.device, w, h, samples);
        let uniform = scene_uniform(&view, &target, 3.5, (-1.0, 1.0), None);
        renderer.set_scene(&context.queue, &uniform);
        let draw = |encoder: &mut wgpu::CommandEncoder, buffers: SurfaceBuffers<'_>| {
            renderer.render(encoder, &target, buffers, Some(&net), view.overlays, None);
        };
        let (latency, render_only, patches) =
            drag_frames(context, &mut doc, &mut sync, &net, point, iterations, &draw)?;
        writeln!(
            out,
            "{:<26} {mode} | drag-to-new-frame {:8.3} ms ({label}: {w} × {h}, {samples} sample{}; {} control points, {patches} patches re-evaluated; the render pass alone {:.3} ms)",
            name,
            latency,
            if samples == 1 { "" } else { "s" },
            point_count,
            render_only,
        )?;
    }
    Ok(())
}

/// Drags `point` of the document's only object back and forth `iterations` times, each step
/// followed by `draw`, until the frame is finished on the GPU: (median drag-to-new-frame ms,
/// median ms of `draw` alone, patches re-evaluated per step).
fn drag_frames(
    context: &GpuContext,
    doc: &mut Document,
    sync: &mut SceneSync,
    net: &ControlNet,
    point: usize,
    iterations: usize,
    draw: &dyn Fn(&mut wgpu::CommandEncoder, SurfaceBuffers<'_>),
) -> Result<(f64, f64, u32), Box<dyn std::error::Error>> {
    doc.begin_drag(0, &[point])?;
    // As the editor does while a drag lasts.
    sync.freeze_levels(true);
    let mut latency = Vec::new();
    let mut patches = 0;
    for i in 0..iterations + 2 {
        let lift = 0.01 * (i % 7) as f64;
        let start = Instant::now();
        let moved = doc.drag_by(DVec3::new(lift, 0.0, lift))?;
        sync.points_moved(&doc.scene, &moved)?;
        net.update_points(
            &context.queue,
            &doc.scene.objects[0].control_points(),
            &|k| k == point,
        );
        let mut encoder = context.device.create_command_encoder(&Default::default());
        let evaluated = sync.encode(&mut encoder, None);
        draw(
            &mut encoder,
            sync.surface_buffers().ok_or("nothing on the GPU")?,
        );
        context.queue.submit([encoder.finish()]);
        wait(context)?;
        if i >= 2 {
            latency.push(start.elapsed().as_secs_f64() * 1e3);
            patches = evaluated;
        }
    }
    // The same frame without the edit: what the render pass alone costs.
    doc.cancel_drag();
    sync.freeze_levels(false);
    let mut render_only = Vec::new();
    for _ in 0..iterations.max(3) {
        let start = Instant::now();
        let mut encoder = context.device.create_command_encoder(&Default::default());
        draw(
            &mut encoder,
            sync.surface_buffers().ok_or("nothing on the GPU")?,
        );
        context.queue.submit([encoder.finish()]);
        wait(context)?;
        render_only.push(start.elapsed().as_secs_f64() * 1e3);
    }
    Ok((median(latency), median(render_only), patches))
}

/// The groups of figures [`run`] can be limited to.
pub const GROUPS: [&str; 21] = [
    "edit",
    "cage",
    "webgl2",
    "frame",
    "scale",
    "export",
    "subdivision",
    "trim",
    "analysis",
    "construct",
    "substitutes",
    "adaptive",
    "triangle",
    "displacement",
    "lattice",
    "intersect",
    "step",
    "mass",
    "boolean",
    "features",
    "all",
];

/// Runs every benchmark on `context` (or only `group`, one of [`GROUPS`]), printing one line
/// per figure.
pub fn run(
    context: &GpuContext,
    iterations: usize,
    group: &str,
    out: &mut impl Write,
) -> Result<(), Box<dyn std::error::Error>> {
    let limits = context.device.limits();
    writeln!(
        out,
        "adapter: {} (storage buffers up to {} MiB)",
        context.describe(),
        limits
            .max_storage_buffer_binding_size
            .min(limits.max_buffer_size)
            >> 20
    )?;
    writeln!(
        out,
        "threads: {} (RAYON_NUM_THREADS sets them)",
        rayon::current_num_threads()
    )?;
    let wants = |g: &str| group == "all" || group == g;
    if wants("trim") {
        bench_trim(context, iterations, out)?;
    }
    if wants("subdivision") {
        bench_subdivision(context, iterations, out)?;
    }
    if wants("cage") {
        bench_cage_tools(context, iterations, out)?;
    }
    let scene = Scene::demo()?;
    if wants("frame") {
        bench_frame(context, &scene, iterations, out)?;
    }
    if wants("scale") {
        bench_scale(context, iterations, out)?;
    }
    if wants("analysis") {
        bench_analysis(context, &scene, iterations, out)?;
    }
    if wants("edit") {
        bench_edit(context, &scene, iterations, out)?;
    }
    if wants("export") {
        bench_export(context, &scene, iterations, out)?;
    }
    if wants("webgl2") {
        bench_webgl2(context, &scene, iterations, out)?;
    }
    if wants("construct") {
        bench_construct(iterations, out)?;
    }
    if wants("substitutes") {
        bench_substitutes(context, iterations, out)?;
    }
    if wants("adaptive") {
        bench_adaptive(context, iterations, out)?;
    }
    if wants("triangle") {
        bench_triangle(context, iterations, out)?;
    }
    if wants("displacement") {
        bench_displacement(context, iterations, out)?;
    }
    if wants("lattice") {
        bench_lattice(context, iterations, out)?;
    }
    if wants("intersect") {
        bench_intersect(&scene, iterations, out)?;
    }
    if wants("step") {
        bench_step(iterations, out)?;
        bench_step_large(context, iterations, out)?;
    }
    if wants("mass") {
        bench_mass(iterations, out)?;
    }
    if wants("boolean") {
        bench_boolean(iterations, out)?;
    }
    if wants("features") {
        bench_features(iterations, out)?;
    }
    Ok(())
}

/// A STEP model of over 10,000 faces: OpenCASCADE's plate of 806 faces placed 13 times side by
/// side and written by knotwork's writer, then opened as the editor opens it (the file parsed
/// a share a step, then a few faces a step between frames: the longest step is the longest the
/// editor's frame waits), evaluated on the GPU as the editor does when the model arrives, and
/// drawn at 1280 × 800 as the viewport draws it at rest and on a software adapter.
fn bench_step_large(
    context: &GpuContext,
    iterations: usize,
    out: &mut impl Write,
) -> Result<(), Box<dyn std::error::Error>> {
    const COPIES: usize = 13;
    let bytes = reference_file("tests/reference/occ/step/plate-20.step")?;
    let plate = knotwork::io::step::read_project(&bytes, &mut |_, _| true)?;
    let object = plate.scene.objects.first().ok_or("the plate has no body")?;

    let (lo, hi) = object.bounds().ok_or("the plate has no box")?;
    let step = 1.1 * (hi - lo);
    let mut scene = Scene {
        objects: Vec::new(),
        unit: plate.scene.unit,
    };
    for k in 0..COPIES {
        let at = DVec3::new((k % 4) as f64 * step.x, (k / 4) as f64 * step.y, 0.0);
        scene.objects.push(SceneObject {
            name: format!("plate {}", k + 1),
            geometry: object
                .kind()
                .transformed(&glam::DAffine3::from_translation(at))?,
            ..object.clone()
        });
    }
    let tolerance = knotwork::io::step::default_tolerance(&scene);
    let text = knotwork::io::step::export_scene(&scene, "plates.step", tolerance)?.text;
    let clock = Instant::now();
    let open = knotwork::io::step::timed_open(text.as_bytes().to_vec(), &|| {
        clock.elapsed().as_secs_f64() * 1e3
    })?;
    writeln!(
        out,
        "STEP {COPIES} plates ({} faces, {:.1} MB) | first step {:6.1} ms, then parsed, built and joined in {:8.1} ms over {} steps (longest {:.1} ms)",
        open.faces,
        text.len() as f64 / 1e6,
        open.first_step_ms,
        open.steps_ms,
        open.steps,
        open.longest_step_ms
    )?;
    let opened = knotwork::io::step::read_project(text.as_bytes(), &mut |_, _| true)?.scene;
    // The objects' GPU feeds first (their faces' trim grids are built on first use), then
    // the GPU copy from them as the editor makes it.
    let start = Instant::now();
    for object in &opened.objects {
        object.decompose()?;
    }
    let feed_ms = start.elapsed().as_secs_f64() * 1e3;
    let threads = rayon::current_num_threads();
    let start = Instant::now();
    let sync = evaluated(context, &opened)?;
    let evaluate_ms = feed_ms + start.elapsed().as_secs_f64() * 1e3;
    let quality = sync.quality_used();
    let geometry = sync.geometry().ok_or("nothing on the GPU")?;
    let view = framed_view(&opened)?;
    let renderer = ViewportRenderer::new(&context.device);
    let mut frames = Vec::new();
    for (samples, (w, h)) in [
        (4, (1280, 800)),
        knotwork::render::Quality::software().target((1280, 800), true),
    ] {
        let ms = median_frame_ms(
            context,
            &renderer,
            geometry,
            &view,
            (samples, (w, h)),
            iterations.clamp(1, 10),
        )?;
        frames.push(format!(
            "{w} × {h} {samples} sample{} {ms:.2} ms",
            if samples == 1 { "" } else { "s" },
        ));
    }
    writeln!(
        out,
        "STEP {COPIES} plates on the GPU            | evaluated {evaluate_ms:8.1} ms ({feed_ms:.1} ms of it the faces' feeds and trim grids, on {threads} thread{}), {} patches, {} vertices (quality {quality} to fit the device); frame {}",
        if threads == 1 { "" } else { "s" },
        geometry.patch_count(),
        geometry.vertex_count(),
        frames.join(", ")
    )?;
    Ok(())
}

/// STEP: OpenCASCADE's plates with a 20 × 20 grid of filleted holes (806 faces,
/// tests/reference/occ/step/plate-20.step) and of filleted blind holes (1,206 faces: planes,
/// cylinders, tori; blind-20.step), each read (parse, faces as trimmed NURBS, shared edges) and
/// tessellated watertight at 1e-4 of its diagonal, one core, median wall time; and, where
/// Python with cadquery-ocp is found (`KNOTWORK_OCC_PYTHON`, else `python3`), OpenCASCADE
/// reading and meshing the same file at the same deflection in the same run
/// (make_step.py mesh).
fn bench_step(iterations: usize, out: &mut impl Write) -> Result<(), Box<dyn std::error::Error>> {
    let runs = iterations.clamp(1, 5);
    for (file, what) in [
        ("plate-20.step", "20 × 20 holes"),
        ("blind-20.step", "20 × 20 blind holes"),
    ] {
        bench_step_plate(file, what, runs, out)?;
    }
    bench_step_subdivision(runs, out)
}

/// One plate of [`bench_step`].
fn bench_step_plate(
    file: &str,
    what: &str,
    runs: usize,
    out: &mut impl Write,
) -> Result<(), Box<dyn std::error::Error>> {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/reference/occ");
    let path = root.join("step").join(file);
    let bytes = std::fs::read(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let clock = Instant::now();
    let now = || clock.elapsed().as_secs_f64() * 1e3;
    let mut timings = Vec::new();
    for _ in 0..runs {
        timings.push(knotwork::io::step::timed_read_and_mesh(&bytes, &now)?);
    }
    let read_ms = median(timings.iter().map(|t| t.read_ms).collect());
    let mesh_ms = median(timings.iter().map(|t| t.mesh_ms).collect());
    let (tolerance, triangles, faces) = timings
        .first()
        .map_or((f64::NAN, 0, 0), |t| (t.tolerance, t.triangles, t.faces));
    let model = knotwork::io::step::read::read(&bytes, &mut |_, _| true)?;
    // Memory per face: the surfaces' homogeneous points and knots, and the trim curves'.
    let mut bytes_held = 0usize;
    for f in model.bodies.iter().flat_map(|b| &b.faces) {
        let s = f.surface();
        bytes_held +=
            s.homogeneous_points().len() * 32 + (s.knots()[0].len() + s.knots()[1].len()) * 8;
        for c in f.loops().iter().flatten() {
            bytes_held += c.count() * 24 + c.knots().len() * 8;
        }
    }
    let total = read_ms + mesh_ms;
    let (_, open) = median_ms(runs, || {
        let clock = std::time::Instant::now();
        knotwork::io::step::timed_open(bytes.clone(), &|| clock.elapsed().as_secs_f64() * 1e3)
    })?;
    writeln!(
        out,
        "STEP {what}, opened as the editor does | first step {:6.1} ms, then parsed, built and joined in {:8.1} ms over {} steps (longest {:.1} ms), {} faces",
        open.first_step_ms, open.steps_ms, open.steps, open.longest_step_ms, open.faces
    )?;
    writeln!(
        out,
        "STEP {what} ({faces} faces, {:.1} MB) | read {read_ms:8.1} ms, tessellate {mesh_ms:8.1} ms at {tolerance:.3e} ({triangles} triangles), total {total:8.1} ms; {:.1} KB of geometry per face",
        bytes.len() as f64 / 1e6,
        bytes_held as f64 / faces.max(1) as f64 / 1e3
    )?;
    let python = std::env::var("KNOTWORK_OCC_PYTHON").unwrap_or_else(|_| "python3".into());
    let occ = std::process::Command::new(&python)
        .arg(root.join("make_step.py"))
        .args(["mesh", &path.display().to_string(), &tolerance.to_string()])
        .output();
    match occ {
        Ok(o) if o.status.success() => {
            let text = String::from_utf8_lossy(&o.stdout);
            let line = text
                .lines()
                .rev()
                .find(|l| l.starts_with('{'))
                .unwrap_or("{}");
            let v: serde_json::Value = serde_json::from_str(line).unwrap_or_default();
            let occ_ms = v["total_s"].as_f64().unwrap_or(f64::NAN) * 1e3;
            writeln!(
                out,
                "STEP {what}, OpenCASCADE | read {:8.1} ms, mesh {:8.1} ms, total {occ_ms:8.1} ms: knotwork {:.2}× as fast",
                v["read_s"].as_f64().unwrap_or(f64::NAN) * 1e3,
                v["mesh_s"].as_f64().unwrap_or(f64::NAN) * 1e3,
                occ_ms / total
            )?;
        }
        _ => writeln!(
            out,
            "STEP {what}, OpenCASCADE | not measured ({python} with cadquery-ocp not found; set KNOTWORK_OCC_PYTHON)"
        )?,
    }
    Ok(())
}

/// STEP export of a subdivision surface under each scheme (a 20 mm cube cage for the quad
/// schemes, an icosahedron of radius 15 for the triangle ones), at the writer's default
/// tolerance: the limit as patches (refined until within 1e-4 of the cage's size) and the
/// file written, median wall time, with the patches and the deviation reached.
fn bench_step_subdivision(
    runs: usize,
    out: &mut impl Write,
) -> Result<(), Box<dyn std::error::Error>> {
    use knotwork::kernel::subdiv::patches::Display;
    use knotwork::kernel::subdiv::{Options, Scheme, SubdivisionSurface, cages};
    use knotwork::scene::SubdivObject;
    for (name, scheme) in [
        ("Catmull-Clark cube", Scheme::CatmullClark),
        ("Doo-Sabin cube", Scheme::DooSabin),
        ("Loop icosahedron", Scheme::Loop),
        ("butterfly icosahedron", Scheme::Butterfly),
        ("√3 icosahedron", Scheme::Sqrt3),
    ] {
        let cage = if scheme.needs_triangles() {
            cages::icosahedron(DVec3::ZERO, 15.0)?
        } else {
            cages::cube(DVec3::ZERO, 20.0)?
        };
        let options = Options {
            scheme,
            ..Default::default()
        };
        let surface = SubdivisionSurface::new(cage, vec![], vec![], options, 2)?;
        let scene = Scene {
            objects: vec![SceneObject::new(
                name,
                ObjectGeometry::new(SubdivObject::new(surface, Display::Limit)),
            )],
            unit: None,
        };
        let tolerance = knotwork::io::step::default_tolerance(&scene);
        let (ms, written) = median_ms(runs, || {
            knotwork::io::step::export_scene(&scene, "subdivision.step", tolerance)
        })?;
        let note = written.approximated.first().map_or("", String::as_str);
        writeln!(
            out,
            "STEP export {name:22} | {ms:8.1} ms, {:.2} MB: {note}",
            written.text.len() as f64 / 1e6
        )?;
    }
    Ok(())
}

/// Surface–surface intersection (f64, one core): the teapot (every one of its 32 patches) with
/// a plane through its body and with a sphere about its body, at tolerance 1e-6 of the scene's
/// size (chord 1e-3, smallest loop 1e-2), as the document intersects two objects (each face's
/// cells made once); all branches, median wall time.
fn bench_intersect(
    scene: &Scene,
    iterations: usize,
    out: &mut impl Write,
) -> Result<(), Box<dyn std::error::Error>> {
    use knotwork::kernel::intersect::{IntersectOptions, intersect_face_sets};
    let teapot = scene
        .objects
        .first()
        .ok_or("the demo scene has no teapot")?;
    let (lo, hi) = teapot.bounds().ok_or("the teapot has no box")?;
    let size = lo.distance(hi);
    let centre = 0.5 * (lo + hi);
    let plane = construct::plane(
        DVec3::new(lo.x - 1.0, lo.y - 1.0, centre.z),
        DVec3::new(hi.x - lo.x + 2.0, 0.0, 0.0),
        DVec3::new(0.0, hi.y - lo.y + 2.0, 0.0),
    )?;
    let sphere = construct::sphere(centre, 0.3 * size)?;
    let options = IntersectOptions::for_size(size);
    for (name, other) in [("a plane", &plane), ("a sphere", &sphere)] {
        let faces = teapot.faces();
        let faces = knotwork::doc::surface_ops::face_refs(&faces);
        let (ms, (branches, points)) = median_ms(iterations.clamp(3, 20), || {
            let mut branches = 0;
            let mut points = 0;
            for (_, found) in intersect_face_sets(&faces, &[other], &options)? {
                branches += found.curves.len();
                points += found.curves.iter().map(|c| c.points.len()).sum::<usize>();
            }
            Ok::<_, knotwork::kernel::GeometryError>((branches, points))
        })?;
        writeln!(
            out,
            "intersect teapot (32 patches) with {name} | {branches} branches, {points} points | {ms:8.3} ms (one core, median)"
        )?;
    }
    bench_surface_ops(iterations, out)
}

/// Offsets, a fillet, a blend, a match and a join (f64, one core): a bicubic floor offset at
/// 1e-4 of its size (fitted) and a sphere (exact); the rolling-ball fillet of two crossing
/// bicubics; a G2 blend and a G2 match between two bicubics' edges at 1e-6 of the size; six
/// planes joined into a closed box and tessellated watertight at 1e-3 of its size.
fn bench_surface_ops(
    iterations: usize,
    out: &mut impl Write,
) -> Result<(), Box<dyn std::error::Error>> {
    use knotwork::kernel::fillet::{FilletOptions, fillet_surfaces};
    use knotwork::kernel::join::{find_topology, tessellate_joined};
    use knotwork::kernel::offset::offset_nurbs;
    let runs = iterations.clamp(3, 20);
    let (floor, wall) = knotwork::kernel::samples::floor_and_wall()?;
    let size = floor.size();
    let sphere = construct::sphere(DVec3::ZERO, 1.0)?;
    for (name, surface, distance, tolerance) in [
        ("bicubic 6 x 6 (fitted)", &floor, 0.3, 1e-4 * size),
        ("sphere (exact)", &sphere, 0.2, 1e-4),
    ] {
        let (ms, points) = median_ms(runs, || {
            offset_nurbs(surface, distance, tolerance)
                .map(|o| o.surface.count()[0] * o.surface.count()[1])
        })?;
        writeln!(
            out,
            "offset {name} | {points} control points | {ms:8.3} ms (one core, median)"
        )?;
    }
    let options = FilletOptions {
        radius: 0.4,
        radius_end: None,
        side_a: 1.0,
        side_b: 1.0,
        tolerance: 1e-4 * size,
        size,
    };
    let (ms, sections) = median_ms(runs, || {
        fillet_surfaces(&floor, &wall, &options).map(|f| f.centres.len())
    })?;
    writeln!(
        out,
        "fillet two bicubics, radius 0.4 | {sections} sections | {ms:8.3} ms (one core, median)"
    )?;
    // The floor and a copy of it moved along and up: a G2 blend across the gap between their
    // nearest edges, and the copy's edge matched to the floor's at G2.
    {
        use knotwork::kernel::blend::{
            BlendOptions, EdgeContinuity, blend_edges, match_edge, nearest_sides,
        };
        let (lo, hi) = floor.bounds();
        let step = DVec3::new((hi.x - lo.x) * 1.3, 0.0, 0.2 * size);
        let copy = floor.transformed(&glam::DAffine3::from_translation(step))?;
        let (sa, sb, _) = nearest_sides(&floor, &copy, 1e-9 * size).ok_or("no edges")?;
        let options = BlendOptions {
            continuity: EdgeContinuity::G2,
            tension: [1.0, 1.0],
            tolerance: 1e-6 * size,
        };
        let (ms, samples) = median_ms(runs, || {
            blend_edges(&floor, sa, &copy, sb, &options).map(|b| b.samples)
        })?;
        writeln!(
            out,
            "G2 blend between two bicubics' edges | {samples} samples | {ms:8.3} ms (one core, median)"
        )?;
        let (ms, points) = median_ms(runs, || {
            match_edge(&copy, sb, &floor, sa, EdgeContinuity::G2, 1e-6 * size)
                .map(|m| m.surface.count()[0] * m.surface.count()[1])
        })?;
        writeln!(
            out,
            "G2 match of a bicubic's edge to another's | {points} control points | {ms:8.3} ms (one core, median)"
        )?;
    }
    let (x, y, z) = (DVec3::X * 2.0, DVec3::Y, DVec3::Z * 1.5);
    let faces: Vec<TrimmedSurface> = [
        (DVec3::ZERO, y, x),
        (z, x, y),
        (DVec3::ZERO, x, z),
        (y, z, x),
        (DVec3::ZERO, z, y),
        (x, y, z),
    ]
    .into_iter()
    .map(|(o, u, v)| construct::plane(o, u, v).map(TrimmedSurface::untrimmed))
    .collect::<Result<_, _>>()?;
    let (ms, (shared, triangles)) = median_ms(runs, || {
        let topology = find_topology(&faces, 1e-9)?;
        let mesh = tessellate_joined(&faces, &topology, 1e-3 * 2.9, false)?;
        Ok::<_, knotwork::kernel::GeometryError>((topology.shared.len(), mesh.triangles.len()))
    })?;
    writeln!(
        out,
        "join a box of 6 planes and tessellate it watertight | {shared} shared edges, {triangles} triangles | {ms:8.3} ms (one core, median)"
    )?;
    Ok(())
}

/// Free-form deformation: the 32 × 32 landscape and the teapot through lattices of degree
/// (1, 1, 1), (2, 2, 2) and (3, 3, 3) on the GPU (full pass, drag latency of a lattice point),
/// and baking each (exact or refitted at 1e-3 of the size; time and resulting size).
fn bench_lattice(
    context: &GpuContext,
    iterations: usize,
    out: &mut impl Write,
) -> Result<(), Box<dyn std::error::Error>> {
    use knotwork::kernel::ffd::Lattice;
    let mut teapot = SceneObject::new(
        "teapot",
        ObjectGeometry::new(knotwork::kernel::samples::utah_teapot()?),
    );
    teapot.segments = 16;
    for base in [large_bspline()?, teapot] {
        for degree in [1usize, 2, 3] {
            let mut object = base.clone();
            let (lo, hi) = object.kind().bounds().ok_or("an empty object")?;
            let mut lattice = Lattice::around(lo, hi, [degree; 3])?;
            let top = lattice.point_index(degree, degree, degree);
            let p = lattice.points()[top];
            lattice.set_point(top, p + (hi - lo) * 0.2)?;
            object.lattice = Some(lattice);
            object.name = format!("{} in a degree-{degree} lattice", base.name);
            let (ms, baked) = median_ms(iterations.clamp(1, 3), || object.baked_lattice(1e-3))?;
            writeln!(
                out,
                "{} apply | {} | {} control points | {ms:8.1} ms",
                object.name,
                baked.1.describe(),
                baked.0.control_point_count()
            )?;
            bench_object(context, object, top, iterations, out)?;
        }
    }
    Ok(())
}

/// Displacement along the normal: the 32 × 32 landscape plain and displaced by each pattern
/// (full pass, drag latency), and its export with the displacement.
fn bench_displacement(
    context: &GpuContext,
    iterations: usize,
    out: &mut impl Write,
) -> Result<(), Box<dyn std::error::Error>> {
    use knotwork::kernel::displace::{Displacement, Pattern};
    use knotwork::kernel::tess::Tessellation;
    let plain = large_bspline()?;
    let centre = 32 * 16 + 16;
    bench_object(context, plain.clone(), centre, iterations, out)?;
    for pattern in Pattern::ALL {
        let mut object = plain.clone();
        object.displacement = Some(Displacement::new(pattern, 0.05, 24.0)?);
        object.name = format!("landscape displaced by {}", pattern.label());
        let (ms, triangles) = median_ms(iterations.clamp(1, 5), || {
            object
                .tessellate(Tessellation::Tolerance(1e-3), false)
                .map(|m| m.iter().map(|m| m.triangles.len()).sum::<usize>())
        })?;
        writeln!(
            out,
            "{} export (8 segments per cycle) | {triangles:>8} triangles | {ms:8.1} ms",
            object.name
        )?;
        bench_object(context, object, centre, iterations, out)?;
    }
    Ok(())
}

/// Triangular Bézier patches (the Create dialog's dome) of degree 3, 6, 10 and 20 on the GPU
/// (the viewport's lattice: full pass, drag latency) and the f64 export tessellation at a
/// tolerance of 1e-4 of the size.
fn bench_triangle(
    context: &GpuContext,
    iterations: usize,
    out: &mut impl Write,
) -> Result<(), Box<dyn std::error::Error>> {
    use knotwork::doc::create::{Primitive, PrimitiveParams};
    use knotwork::kernel::tess::Tessellation;
    for degree in [3usize, 6, 10, 20] {
        let object = PrimitiveParams {
            kind: Primitive::TriangleBezier,
            degree: [degree, degree],
            ..Default::default()
        }
        .build()?;
        let size = object.bounds().map_or(1.0, |(lo, hi)| lo.distance(hi));
        let (ms, triangles) = median_ms(iterations.clamp(1, 5), || {
            object
                .tessellate(Tessellation::Tolerance(1e-4 * size), false)
                .map(|m| m.iter().map(|m| m.triangles.len()).sum::<usize>())
        })?;
        writeln!(
            out,
            "triangular Bézier degree {degree:>2} export tol 1e-4 × size | {triangles:>7} triangles | {ms:8.2} ms"
        )?;
        let mut named = object;
        named.name = format!("triangular Bézier degree {degree}");
        let middle = named.control_point_count() / 2;
        bench_object(context, named, middle, iterations, out)?;
    }
    Ok(())
}

/// Adaptive subdivision against the uniform limit at the same level, on cages with a spike
/// (one point pulled out) beside wide gentle regions: per tolerance the pieces per level, the
/// triangles against the uniform level's, the time to choose the depths and build the feed;
/// then both through the editor's path (full pass, drag latency).
fn bench_adaptive(
    context: &GpuContext,
    iterations: usize,
    out: &mut impl Write,
) -> Result<(), Box<dyn std::error::Error>> {
    use knotwork::kernel::subdiv::patches::Display;
    use knotwork::kernel::subdiv::{Options, Scheme, SubdivisionSurface, cages};
    use knotwork::scene::SubdivObject;
    let spiked = |mesh: knotwork::kernel::PolygonMesh| {
        let mut points = mesh.points().to_vec();
        points[7] += DVec3::new(0.4, -0.3, 1.6);
        let faces: Vec<Vec<u32>> = mesh.faces().map(<[u32]>::to_vec).collect();
        knotwork::kernel::PolygonMesh::new(points, &faces)
    };
    let torus = spiked(cages::torus(DVec3::ZERO, 2.0, 0.7, 24, 16)?)?;
    let triangles = triangulated(&torus)?;
    let cases = [
        ("spiked 24x16 torus", &torus, Scheme::CatmullClark, 4),
        ("spiked 24x16 tri torus", &triangles, Scheme::Loop, 4),
    ];
    for (name, mesh, scheme, level) in cases {
        let options = Options {
            scheme,
            ..Default::default()
        };
        let surface =
            SubdivisionSurface::new(mesh.clone(), Vec::new(), Vec::new(), options, level)?;
        let uniform = surface.display_mesh(level, Display::Limit)?;
        let uniform_triangles: usize = uniform.polygons.iter().map(|p| p.len() - 2).sum();
        for tolerance in [0.005, 0.001] {
            let (layout_ms, layout) = median_ms(iterations.clamp(1, 5), || {
                surface.adaptive_layout(level, tolerance)
            })?;
            let (feed_ms, _) = median_ms(iterations.clamp(1, 5), || {
                surface.adaptive_feed(level, tolerance)
            })?;
            let shown = surface.adaptive_triangles(level, &layout)?.len();
            writeln!(
                out,
                "{name} {} adaptive L{level} tol {tolerance:.0e} | pieces per {} | {shown} triangles, {:.1} % of uniform {uniform_triangles} | depths {layout_ms:.1} ms, feed {feed_ms:.1} ms",
                scheme.label(),
                layout.describe(),
                100.0 * shown as f64 / uniform_triangles as f64,
            )?;
        }
        for (display, tolerance) in [
            (Display::Limit, None),
            (Display::Adaptive, Some(0.005)),
            (Display::Adaptive, Some(0.001)),
        ] {
            let mut object = SubdivObject::checked(surface.clone(), display)?;
            let label = match tolerance {
                Some(t) => {
                    object = object.with_tolerance_checked(t)?;
                    format!("adaptive tol {t:.0e}")
                }
                None => "uniform".to_owned(),
            };
            let object = SceneObject::new(
                format!("{name} {} {label}", scheme.label()),
                ObjectGeometry::boxed(Box::new(object)),
            );
            bench_object(context, object, 7, iterations, out)?;
        }
    }
    Ok(())
}

/// The transfinite constructions on the CPU (f64): Gordon surfaces through networks of
/// isoparametric curves of the 32 × 32 bicubic landscape (n × n curves), and the Create
/// dialog's Gordon, bicubic Coons and Hermite examples.
fn bench_construct(
    iterations: usize,
    out: &mut impl Write,
) -> Result<(), Box<dyn std::error::Error>> {
    use knotwork::doc::create::{Primitive, PrimitiveParams};
    use knotwork::kernel::{Direction, transfinite};
    let Some(land) = large_bspline()?.geometry.nurbs_surface().cloned() else {
        return Err("the landscape is a NURBS surface".into());
    };
    for n in [4usize, 8, 16] {
        let at = |k: usize| k as f64 / (n - 1) as f64;
        let u_curves = (0..n)
            .map(|k| land.isocurve(Direction::V, at(k), 0))
            .collect::<Result<Vec<_>, _>>()?;
        let v_curves = (0..n)
            .map(|k| land.isocurve(Direction::U, at(k), 0))
            .collect::<Result<Vec<_>, _>>()?;
        let (ms, surface) = median_ms(iterations.clamp(1, 5), || {
            transfinite::gordon(&u_curves, &v_curves, 3)
        })?;
        let [cu, cv] = surface.count();
        writeln!(
            out,
            "construct Gordon, {n:>2} × {n:<2} curves of 32 points | {cu} × {cv} control points | {ms:8.2} ms"
        )?;
    }
    bench_modelling(&land, iterations, out)?;
    for kind in [
        Primitive::Gordon,
        Primitive::BicubicCoons,
        Primitive::Hermite,
    ] {
        let params = PrimitiveParams {
            kind,
            ..Default::default()
        };
        let (ms, object) = median_ms(iterations.clamp(1, 5), || params.build())?;
        let net = object
            .geometry
            .nurbs_surface()
            .map_or(String::from("-"), |s| {
                format!("{} × {}", s.count()[0], s.count()[1])
            });
        writeln!(
            out,
            "construct {:<45} | {net:>7} control points | {ms:8.3} ms",
            kind.label()
        )?;
    }
    Ok(())
}

/// Four closed 16-point section curves and their loft, one of whose points moves a little
/// further at every step (a drag with construction history, as the kernel sees it).
struct LoftDrag {
    sections: Vec<knotwork::kernel::SpaceCurve>,
    step: usize,
}

impl LoftDrag {
    fn new() -> Result<Self, knotwork::kernel::GeometryError> {
        use glam::DVec3;
        let section = |z: f64, wobble: f64| {
            let points: Vec<DVec3> = (0..16)
                .map(|i| {
                    let a = i as f64 / 16.0 * std::f64::consts::TAU;
                    DVec3::new(a.cos() * (2.0 + wobble * (3.0 * a).sin()), a.sin() * 2.0, z)
                })
                .collect();
            knotwork::kernel::splines::interpolate_closed(
                &points,
                3,
                knotwork::kernel::splines::Parametrization::ChordLength,
            )
        };
        Ok(Self {
            sections: vec![
                section(0.0, 0.2)?,
                section(1.0, 0.5)?,
                section(2.5, 0.1)?,
                section(3.0, 0.4)?,
            ],
            step: 0,
        })
    }

    /// Moves point 5 of the second section and lofts again.
    fn step(&mut self) -> Result<knotwork::kernel::NurbsSurface, knotwork::kernel::GeometryError> {
        use knotwork::kernel::loft::{LoftOptions, loft_sections};
        self.step += 1;
        let moved = &self.sections[1];
        let mut points: Vec<glam::DVec3> =
            (0..moved.count()).map(|i| moved.control_point(i)).collect();
        points[5] += glam::DVec3::new(0.0, 0.0, 0.01 * self.step as f64);
        self.sections[1] = knotwork::kernel::SpaceCurve::new(
            moved.degree(),
            moved.knots().to_vec(),
            points,
            None,
        )?;
        loft_sections(&self.sections, &LoftOptions::default())
    }
}

/// Dragging a point of a section of a loft with construction history, through the document
/// (the editor's own path): each drag step moves the curve, builds the loft again from its
/// sections, re-derives the loft's and the curve's GPU feeds, and the compute passes run and are
/// waited for (wall time).
fn bench_loft_drag(
    context: &GpuContext,
    iterations: usize,
    out: &mut impl Write,
) -> Result<(), Box<dyn std::error::Error>> {
    use knotwork::ops::construct::{Construct, LoftStyleName, Request};
    let drag = LoftDrag::new()?;
    let names: Vec<String> = (0..drag.sections.len())
        .map(|k| format!("section {k}"))
        .collect();
    let objects = drag
        .sections
        .iter()
        .zip(&names)
        .map(|(c, name)| SceneObject::new(name, knotwork::scene::ObjectGeometry::new(c.clone())))
        .collect();
    let mut doc = Document::new(Scene {
        objects,
        unit: None,
    });
    let loft = Construct::new(Request::Loft {
        curves: (0..names.len()).map(Into::into).collect(),
        degree: 3,
        closed: false,
        style: LoftStyleName::Normal,
    });
    doc.execute(&knotwork::doc::Command::Apply {
        operation: knotwork::scene::operation::Operation::new(loft),
        keep_history: true,
    })?;
    let mut sync = SceneSync::with_scene(&context.device, &context.queue, &doc.scene, 1.0)?;
    evaluate_once(context, &mut sync, &mut None)?;
    doc.begin_drag(1, &[5])?;
    let mut times = Vec::new();
    let mut relaid = 0;
    for i in 0..iterations.max(3) + 2 {
        let start = Instant::now();
        let moved = doc.drag_by(glam::DVec3::new(0.0, 0.0, 0.01 * i as f64))?;
        relaid += usize::from(moved.relaid);
        sync.points_moved(&doc.scene, &moved)?;
        evaluate_once(context, &mut sync, &mut None)?;
        if i >= 2 {
            times.push(start.elapsed().as_secs_f64() * 1e3);
        }
    }
    doc.commit_drag();
    let geometry = sync.geometry().ok_or("nothing on the GPU")?;
    writeln!(
        out,
        "loft drag with history (4 closed sections of 16 points) | {:>7} patches {:>9} vertices | drag step: curve, loft rebuilt, GPU re-evaluation {:8.3} ms (wall, median; {relaid} of {} steps relaid the buffers)",
        geometry.patch_count(),
        geometry.vertex_count(),
        median(times.clone()),
        times.len() + 2
    )?;
    Ok(())
}

/// `count` cubic curves of `spans` Bézier segments each (a helix-like wave), as scene objects.
pub fn curve_field(count: usize, spans: usize) -> Result<Scene, knotwork::kernel::GeometryError> {
    let mut objects = Vec::with_capacity(count);
    for k in 0..count {
        let n = spans + 3;
        let points: Vec<glam::DVec3> = (0..n)
            .map(|i| {
                let t = i as f64 / n as f64 * std::f64::consts::TAU * 4.0;
                glam::DVec3::new(
                    i as f64 * 0.1,
                    (k as f64 * 0.05) + 0.3 * t.sin(),
                    0.3 * t.cos(),
                )
            })
            .collect();
        let knots = knotwork::kernel::basis::uniform_clamped_knots(3, n);
        let curve = knotwork::kernel::SpaceCurve::new(3, knots, points, None)?;
        objects.push(SceneObject::new(
            format!("curve {k}"),
            knotwork::scene::ObjectGeometry::new(curve),
        ));
    }
    Ok(Scene {
        objects,
        unit: None,
    })
}

/// Curve evaluation: 1,000 curves of 64 Bézier segments in one curve pass (wall time, waited
/// for), and one curve's drag step (its segments' support re-evaluated).
fn bench_curves(
    context: &GpuContext,
    iterations: usize,
    out: &mut impl Write,
) -> Result<(), Box<dyn std::error::Error>> {
    let scene = curve_field(1000, 64)?;
    let mut sync = SceneSync::with_scene(&context.device, &context.queue, &scene, 1.0)?;
    let mut times = Vec::new();
    let mut segments = 0;
    for i in 0..iterations.max(3) + 2 {
        sync.invalidate();
        let (_, wall, evaluated) = evaluate_once(context, &mut sync, &mut None)?;
        segments = evaluated;
        if i >= 2 {
            times.push(wall);
        }
    }
    let vertices = sync.curves().map_or(0, |c| c.vertex_count());
    let pass = median(times);
    writeln!(
        out,
        "curves (1,000 of 64 segments) | {segments:>7} segments {vertices:>9} vertices | pass {pass:8.3} ms (wall), {:.1} M vertices/s",
        f64::from(vertices) / pass / 1e3
    )?;
    let mut doc = Document::new(scene);
    doc.begin_drag(500, &[30])?;
    let mut times = Vec::new();
    let mut support = 0;
    for i in 0..iterations.max(3) + 2 {
        let start = Instant::now();
        let moved = doc.drag_by(glam::DVec3::new(0.0, 0.0, 0.01 * i as f64))?;
        support = moved.patches.len();
        sync.points_moved(&doc.scene, &moved)?;
        evaluate_once(context, &mut sync, &mut None)?;
        if i >= 2 {
            times.push(start.elapsed().as_secs_f64() * 1e3);
        }
    }
    writeln!(
        out,
        "curve drag among 1,000 curves  | {support:>7} segments re-evaluated | drag step {:8.3} ms (wall, median)",
        median(times)
    )?;
    Ok(())
}

/// The constructions from a user's curves (f64): the loft of four 16-point section curves
/// rebuilt after one point moves (what a drag with construction history does per mouse
/// move), a network of 10 × 10 iso-curves of the landscape that all need refitting, and a
/// one-rail sweep.
fn bench_modelling(
    land: &knotwork::kernel::NurbsSurface,
    iterations: usize,
    out: &mut impl Write,
) -> Result<(), Box<dyn std::error::Error>> {
    use glam::DVec3;
    use knotwork::kernel::network::network_surface;
    use knotwork::kernel::{Direction, SpaceCurve};
    let runs = iterations.clamp(1, 5);
    let mut drag = LoftDrag::new()?;
    let (ms, surface) = median_ms(runs.max(3), || drag.step())?;
    let [cu, cv] = surface.count();
    writeln!(
        out,
        "construct loft of 4 closed sections of 16 points, rebuilt after a point moves | {cu} × {cv} control points | {ms:8.3} ms"
    )?;
    let n = 10;
    // Iso-curves at 0.05 … 0.95 that run the whole landscape: every curve overhangs the
    // outermost crossings, so none is crossed at the common parameters and every one is
    // reparametrized and fitted; every other one is reversed.
    let at = |k: usize| 0.05 + 0.9 * k as f64 / (n - 1) as f64;
    let turned = |c: SpaceCurve, k: usize| if k % 2 == 1 { c.reverse() } else { c };
    let u_curves = (0..n)
        .map(|k| Ok(turned(land.isocurve(Direction::V, at(k), 0)?, k)))
        .collect::<Result<Vec<_>, knotwork::kernel::GeometryError>>()?;
    let v_curves = (0..n)
        .map(|k| Ok(turned(land.isocurve(Direction::U, at(k), 0)?, k)))
        .collect::<Result<Vec<_>, knotwork::kernel::GeometryError>>()?;
    let (ms, network) = median_ms(runs, || network_surface(&u_curves, &v_curves, 3))?;
    let [cu, cv] = network.surface.count();
    writeln!(
        out,
        "construct network of 10 × 10 crossing curves, each refitted | {cu} × {cv} control points | {ms:8.2} ms ({})",
        network.deviation
    )?;
    let rail = knotwork::kernel::construct::arc(
        DVec3::ZERO,
        DVec3::X,
        DVec3::Z,
        5.0,
        0.0,
        std::f64::consts::FRAC_PI_2,
    )?;
    let profile =
        knotwork::kernel::construct::circle(DVec3::new(5.0, 0.0, 0.0), DVec3::Z, DVec3::X, 0.5)?;
    let (ms, swept) = median_ms(runs, || {
        knotwork::kernel::sweep::sweep_one_rail(
            &rail,
            std::slice::from_ref(&profile),
            knotwork::kernel::sweep::SweepFrame::RotationMinimizing,
        )
    })?;
    let [cu, cv] = swept.count();
    writeln!(
        out,
        "construct sweep of a circle along a quarter circle | {cu} × {cv} control points | {ms:8.3} ms"
    )?;
    Ok(())
}

/// Renders `geometry` into `target` once and waits for it: the wall time in milliseconds.
fn timed_render(
    context: &GpuContext,
    renderer: &ViewportRenderer,
    target: &ViewTarget,
    geometry: &knotwork::gpu::PatchGeometry,
    overlays: knotwork::view::Overlays,
) -> Result<f64, GpuError> {
    let start = Instant::now();
    let mut encoder = context.device.create_command_encoder(&Default::default());
    renderer.render(
        &mut encoder,
        target,
        geometry.surface_buffers(),
        None,
        overlays,
        None,
    );
    context.queue.submit([encoder.finish()]);
    wait(context)?;
    Ok(start.elapsed().as_secs_f64() * 1e3)
}

/// `scene` on the GPU, evaluated once.
fn evaluated(context: &GpuContext, scene: &Scene) -> Result<SceneSync, GpuError> {
    let mut sync = SceneSync::with_scene(&context.device, &context.queue, scene, 1.0)?;
    let mut encoder = context.device.create_command_encoder(&Default::default());
    sync.encode(&mut encoder, None);
    context.queue.submit([encoder.finish()]);
    wait(context)?;
    Ok(sync)
}

/// The median render pass of `geometry` seen by `view` on a `samples`-sample target of
/// `size`, over `iterations` frames after two to warm up.
fn median_frame_ms(
    context: &GpuContext,
    renderer: &ViewportRenderer,
    geometry: &knotwork::gpu::PatchGeometry,
    view: &ViewSettings,
    (samples, (w, h)): (u32, (u32, u32)),
    iterations: usize,
) -> Result<f64, GpuError> {
    let target = ViewTarget::with_samples(&context.device, w, h, samples);
    renderer.set_scene(
        &context.queue,
        &scene_uniform(view, &target, 3.5, (-0.5, 0.5), None),
    );
    let mut times = Vec::new();
    for round in 0..iterations + 2 {
        let ms = timed_render(context, renderer, &target, geometry, view.overlays)?;
        if round >= 2 {
            times.push(ms);
        }
    }
    Ok(median(times))
}

/// The default view settings with the camera framing `scene`.
fn framed_view(scene: &Scene) -> Result<ViewSettings, Box<dyn std::error::Error>> {
    let (lo, hi) = scene.bounds().ok_or("empty scene")?;
    let mut view = ViewSettings::default();
    view.camera.frame(lo.as_vec3(), hi.as_vec3(), 1.6);
    Ok(view)
}

/// The render pass of the demo scene and of the teapot at 64 segments at 1280 × 800, as the
/// viewport draws them at rest (4× multisampling) and as it draws them on a software adapter:
/// one sample at full resolution, and one sample at the resolution scale used while dragging.
fn bench_frame(
    context: &GpuContext,
    scene: &Scene,
    iterations: usize,
    out: &mut impl Write,
) -> Result<(), Box<dyn std::error::Error>> {
    let mut teapot = scene.objects[0].clone();
    teapot.segments = 64;
    let teapot = Scene {
        objects: vec![teapot],
        unit: None,
    };
    let renderer = ViewportRenderer::new(&context.device);
    for (name, scene) in [("demo scene", scene), ("teapot 64 seg", &teapot)] {
        let sync = evaluated(context, scene)?;
        let geometry = sync.geometry().ok_or("nothing on the GPU")?;
        let view = framed_view(scene)?;
        for (samples, (w, h)) in [
            (4, (1280, 800)),
            (1, (1280, 800)),
            knotwork::render::Quality::software().target((1280, 800), true),
        ] {
            let ms = median_frame_ms(
                context,
                &renderer,
                geometry,
                &view,
                (samples, (w, h)),
                iterations,
            )?;
            writeln!(
                out,
                "frame {name:<14} | {w:>4} × {h:<4} {samples} sample{} | {:8.2} ms",
                if samples == 1 { " " } else { "s" },
                ms
            )?;
        }
    }
    Ok(())
}

/// The scale series: generated bicubic B-spline surfaces of 1,024, 10,000 and 40,000 patches
/// framed at 1280 × 800, tessellated fixed at 4 segments and for the view at 0.5 px (then also
/// seen from close by, where most patches are culled): vertices, the compute pass, the frame
/// at 4 samples and 1 sample, and the GPU memory per patch.
fn bench_scale(
    context: &GpuContext,
    iterations: usize,
    out: &mut impl Write,
) -> Result<(), Box<dyn std::error::Error>> {
    let renderer = ViewportRenderer::new(&context.device);
    for n in [35, 103, 203] {
        let mut object = landscape(n)?;
        object.segments = 4;
        let scene = Scene {
            objects: vec![object],
            unit: None,
        };
        let started = Instant::now();
        let mut sync = SceneSync::with_scene(&context.device, &context.queue, &scene, 1.0)?;
        let upload_ms = started.elapsed().as_secs_f64() * 1e3;
        let framed = framed_view(&scene)?;
        let mut close = framed;
        close.camera.distance *= 0.15;
        for (mode, view) in [
            ("fixed 4 seg", framed),
            ("adaptive", framed),
            ("adaptive close", close),
        ] {
            if mode.starts_with("adaptive") {
                sync.set_adaptive(&scene, true, 1.0)?;
                let target =
                    adaptive_target(&view.camera, (1280, 800), f64::from(view.tolerance_px));
                sync.set_view(target);
                // As the editor does after a frame that needed more room than it had.
                evaluate_once(context, &mut sync, &mut None)?;
                sync.read_adaptive_stats()?;
                if sync.grow_adaptive_room(&scene, 1.0)? {
                    sync.set_view(target);
                }
            }
            let mut timer = None;
            let mut pass = Vec::new();
            for _ in 0..iterations.clamp(1, 5) {
                sync.invalidate();
                // Wall time: lavapipe's timestamps read near zero for dispatches this large
                // after the first.
                let (_, wall, _) = evaluate_once(context, &mut sync, &mut timer)?;
                pass.push(wall);
            }
            let stats = sync.read_adaptive_stats()?;
            let geometry = sync.geometry().ok_or("nothing on the GPU")?;
            let mut frames = Vec::new();
            for samples in [4, 1] {
                let target = ViewTarget::with_samples(&context.device, 1280, 800, samples);
                renderer.set_scene(
                    &context.queue,
                    &scene_uniform(&view, &target, 3.5, (-0.5, 0.5), None),
                );
                let mut times = Vec::new();
                for _ in 0..iterations.clamp(1, 3) {
                    times.push(timed_render(
                        context,
                        &renderer,
                        &target,
                        geometry,
                        view.overlays,
                    )?);
                }
                frames.push(median(times));
            }
            let patches = geometry.patch_count();
            let visible = stats.map_or(patches, |s| s.visible_patches);
            let pass = median(pass);
            writeln!(
                out,
                "scale {patches:>6} patches, {mode:<14} | {visible:>6} visible | {:>8} vertices | upload {upload_ms:8.1} ms | pass {:8.2} ms (submit+wait), {:6.2} GB/s of vertices written | frame 1280 × 800 {:8.1} ms (4 samples), {:8.1} ms (1 sample) | {:.0} bytes per patch",
                geometry.vertex_count(),
                pass,
                f64::from(geometry.vertex_count()) * std::mem::size_of::<SurfaceVertex>() as f64
                    / (pass * 1e-3)
                    / 1e9,
                frames[0],
                frames[1],
                geometry.buffer_bytes() as f64 / f64::from(patches.max(1)),
            )?;
        }
    }
    Ok(())
}

/// Frame time of every shading mode on `scene` at 1280 × 800 against plain shading (the
/// analysis modes evaluate the surface per pixel), and the continuity analysis of the teapot and
/// of a 10 × 10 grid of joined bicubic surfaces.
fn bench_analysis(
    context: &GpuContext,
    scene: &Scene,
    iterations: usize,
    out: &mut impl Write,
) -> Result<(), Box<dyn std::error::Error>> {
    use knotwork::view::ShadingMode;
    let sync = evaluated(context, scene)?;
    let geometry = sync.geometry().ok_or("nothing on the GPU")?;
    let renderer = ViewportRenderer::new(&context.device);
    let target = ViewTarget::new(&context.device, 1280, 800);
    let mut view = framed_view(scene)?;
    view.overlays.net = false;
    view.overlays.points = false;
    // Every mode in turn, round after round, so that drift affects them alike.
    let modes = ShadingMode::ALL;
    let mut times = vec![Vec::new(); modes.len()];
    for round in 0..iterations + 2 {
        for (k, &mode) in modes.iter().enumerate() {
            view.shading = mode;
            let range = if mode == ShadingMode::Isophotes {
                (0.0, 180.0)
            } else {
                (-0.5, 0.5)
            };
            renderer.set_scene(
                &context.queue,
                &scene_uniform(&view, &target, 3.5, range, None),
            );
            let ms = timed_render(context, &renderer, &target, geometry, view.overlays)?;
            if round >= 2 {
                times[k].push(ms);
            }
        }
    }
    let medians: Vec<f64> = times.into_iter().map(median).collect();
    let plain = medians[0];
    for (mode, ms) in modes.iter().zip(&medians) {
        writeln!(
            out,
            "frame 1280 × 800, demo scene, {:<11} | {ms:8.2} ms | {:5.2} × plain{}",
            mode.name(),
            ms / plain,
            if mode.per_pixel() {
                " (per-pixel evaluation)"
            } else {
                ""
            },
        )?;
    }
    let options = knotwork::scene::continuity::ContinuityOptions::default();
    let teapot = Scene {
        objects: vec![scene.objects[0].clone()],
        unit: None,
    };
    let grid = joined_grid(10)?;
    for (name, scene) in [
        ("teapot (32 patches)", &teapot),
        ("10 × 10 joined bicubic surfaces", &grid),
    ] {
        let mut times = Vec::new();
        let mut edges = 0;
        for _ in 0..iterations.clamp(1, 5) {
            let start = Instant::now();
            edges = knotwork::scene::continuity::analyse(scene, None, &options)
                .edges
                .len();
            times.push(start.elapsed().as_secs_f64() * 1e3);
        }
        writeln!(
            out,
            "continuity, {name} | {edges:>4} shared edges, {} samples each | {:8.2} ms",
            options.samples,
            median(times)
        )?;
    }
    Ok(())
}

/// `n` × `n` bicubic surfaces, each a 4 × 4 net over a unit square of a wavy height field,
/// meeting edge to edge (C0 along shared nets, the height field's continuity inside).
pub fn joined_grid(n: usize) -> Result<Scene, knotwork::kernel::GeometryError> {
    let height = |x: f64, y: f64| 0.3 * (0.9 * x).sin() * (1.1 * y).cos();
    let mut objects = Vec::new();
    for i in 0..n {
        for j in 0..n {
            let mut points = Vec::new();
            for a in 0..4 {
                for b in 0..4 {
                    let (x, y) = (i as f64 + a as f64 / 3.0, j as f64 + b as f64 / 3.0);
                    points.push(DVec3::new(x, y, height(x, y)));
                }
            }
            let surface = knotwork::kernel::construct::bspline_surface([3, 3], [4, 4], points)?;
            objects.push(SceneObject::new(
                format!("S{i}_{j}"),
                ObjectGeometry::new(surface),
            ));
        }
    }
    Ok(Scene {
        objects,
        unit: None,
    })
}

/// Edit throughput and latency, picking, drag-to-new-frame and the demo scene's full pass.
fn bench_edit(
    context: &GpuContext,
    scene: &Scene,
    iterations: usize,
    out: &mut impl Write,
) -> Result<(), Box<dyn std::error::Error>> {
    let teapot = scene
        .objects
        .first()
        .cloned()
        .ok_or("the demo scene has no teapot")?;
    for segments in [64, 128] {
        let mut t = teapot.clone();
        t.segments = segments;
        // A point of the body, shared by two patches.
        bench_object(context, t, 40, iterations, out)?;
    }
    let mut big = large_bspline()?;
    big.segments = 16;
    bench_object(context, big, 16 * 32 + 16, iterations, out)?;

    bench_loft_drag(context, iterations, out)?;
    bench_curves(context, iterations, out)?;
    bench_pick(iterations, out)?;
    let mut t = teapot.clone();
    t.segments = 64;
    bench_drag_frame(context, t, 40, iterations, out)?;
    let mut sheet = landscape(64)?;
    sheet.segments = 8;
    bench_drag_frame(context, sheet, 32 * 64 + 32, iterations, out)?;

    // The whole demo scene in one pass at its default tessellation.
    let mut sync = SceneSync::with_scene(&context.device, &context.queue, scene, 1.0)?;
    let mut timer = GpuTimer::new(&context.device, &context.queue);
    let mut times = Vec::new();
    for i in 0..iterations + 2 {
        sync.invalidate();
        let (gpu, wall, _) = evaluate_once(context, &mut sync, &mut timer)?;
        if i >= 2 {
            times.push(gpu.unwrap_or(wall));
        }
    }
    let geometry = sync.geometry().ok_or("nothing on the GPU")?;
    writeln!(
        out,
        "demo scene (6 objects)        | {:>7} patches {:>9} vertices | pass {:8.3} ms, one compute pass",
        geometry.patch_count(),
        geometry.vertex_count(),
        median(times),
    )?;
    Ok(())
}

/// The WebGL2 path on this device: the CPU evaluator (full evaluation of the demo scene and of
/// the teapot at 64 segments, wall time including the upload) and the demo scene's
/// drag-to-new-frame with the renderer that shades from the vertices, at the software-adapter
/// quality in motion.
fn bench_webgl2(
    context: &GpuContext,
    scene: &Scene,
    iterations: usize,
    out: &mut impl Write,
) -> Result<(), Box<dyn std::error::Error>> {
    let mut teapot = Scene {
        objects: scene.objects.first().cloned().into_iter().collect(),
        unit: None,
    };
    for object in &mut teapot.objects {
        object.segments = 64;
    }
    for (name, scene) in [
        ("demo scene (6 objects)", scene),
        ("teapot at 64 seg", &teapot),
    ] {
        let mut sync = SceneSync::on_cpu(&context.device, &context.queue);
        sync.rebuild(scene, 1.0)?;
        let mut times = Vec::new();
        for i in 0..iterations + 2 {
            sync.invalidate();
            let (_, wall, _) = evaluate_once(context, &mut sync, &mut None)?;
            if i >= 2 {
                times.push(wall);
            }
        }
        let counts = sync.counts().unwrap_or_default();
        let ms = median(times);
        writeln!(
            out,
            "WebGL2 path: {name:<24} | {:>7} patches {:>9} vertices | CPU evaluation and upload {ms:8.3} ms ({:.2} M vertices/s)",
            counts.patches,
            counts.vertices,
            f64::from(counts.vertices) / ms / 1e3,
        )?;
    }
    let mut doc = Document::new(scene.clone());
    let mut sync = SceneSync::on_cpu(&context.device, &context.queue);
    sync.rebuild(&doc.scene, 1.0)?;
    let teapot = doc
        .scene
        .objects
        .first()
        .ok_or("the demo scene has no teapot")?;
    let point = 40;
    let net = ControlNet::new(
        &context.device,
        &teapot.control_points(),
        &|k| k == point,
        &teapot.net_lines(),
    );
    let renderer = ViewportRenderer::for_vertices_only(&context.device);
    let mut view = ViewSettings::default();
    let (lo, hi) = doc.scene.bounds().ok_or("empty scene")?;
    view.camera.frame(lo.as_vec3(), hi.as_vec3(), 1.6);
    let (samples, (w, h)) = knotwork::render::Quality::software().target((1280, 800), true);
    let target = ViewTarget::with_samples(&context.device, w, h, samples);
    renderer.set_scene(
        &context.queue,
        &scene_uniform(&view, &target, 3.5, (-1.0, 1.0), None),
    );
    let draw = |encoder: &mut wgpu::CommandEncoder, buffers: SurfaceBuffers<'_>| {
        renderer.render(encoder, &target, buffers, Some(&net), view.overlays, None);
    };
    let (latency, render_only, patches) =
        drag_frames(context, &mut doc, &mut sync, &net, point, iterations, &draw)?;
    writeln!(
        out,
        "WebGL2 path: demo scene drag    | drag-to-new-frame {latency:8.3} ms ({w} × {h}, {samples} sample; {patches} patches re-evaluated on the CPU; the render pass alone {render_only:.3} ms)",
    )?;
    Ok(())
}

/// A Catmull-Clark cage as a scene object at `level`.
fn cage_object(
    name: &str,
    mesh: knotwork::kernel::PolygonMesh,
    level: u32,
) -> Result<SceneObject, knotwork::kernel::GeometryError> {
    cage_object_with(
        name,
        mesh,
        level,
        knotwork::kernel::subdiv::Scheme::CatmullClark,
    )
}

/// A cage with no creases under `scheme`, shown at `level`.
fn cage_surface(
    mesh: knotwork::kernel::PolygonMesh,
    level: u32,
    scheme: knotwork::kernel::subdiv::Scheme,
) -> Result<knotwork::kernel::subdiv::SubdivisionSurface, knotwork::kernel::GeometryError> {
    let options = knotwork::kernel::subdiv::Options {
        scheme,
        ..Default::default()
    };
    knotwork::kernel::subdiv::SubdivisionSurface::new(mesh, Vec::new(), Vec::new(), options, level)
}

/// A cage under `scheme` as a scene object at `level`.
fn cage_object_with(
    name: &str,
    mesh: knotwork::kernel::PolygonMesh,
    level: u32,
    scheme: knotwork::kernel::subdiv::Scheme,
) -> Result<SceneObject, knotwork::kernel::GeometryError> {
    let surface = cage_surface(mesh, level, scheme)?;
    Ok(SceneObject::new(
        format!("{name} L{level}"),
        knotwork::scene::ObjectGeometry::new(knotwork::scene::SubdivObject::from(surface)),
    ))
}

/// `mesh` with each quad split along its first diagonal (other faces kept).
fn triangulated(
    mesh: &knotwork::kernel::PolygonMesh,
) -> Result<knotwork::kernel::PolygonMesh, knotwork::kernel::GeometryError> {
    let mut faces = Vec::with_capacity(2 * mesh.face_count());
    for face in mesh.faces() {
        if let [a, b, c, d] = *face {
            faces.push(vec![a, b, c]);
            faces.push(vec![a, c, d]);
        } else {
            faces.push(face.to_vec());
        }
    }
    knotwork::kernel::PolygonMesh::new(mesh.points().to_vec(), &faces)
}

/// Subdivision: the 48 × 32 torus cage at levels 3 and 4 and a 100,000-face torus at level 2
/// (regular quads: bicubic patches), the cube at level 5 (every face irregular: limit stencils),
/// tori under Doo-Sabin, √3 and the butterfly (split into triangles for these two)
/// through the editor's path (table build = the object's feed; full pass; drag latency), and
/// the torus at level 4 with every face as stencils: table build, bytes per refined vertex and
/// one full stencil pass.
fn bench_subdivision(
    context: &GpuContext,
    iterations: usize,
    out: &mut impl Write,
) -> Result<(), Box<dyn std::error::Error>> {
    use knotwork::kernel::subdiv::cages;
    use knotwork::kernel::subdiv::patches::Display;
    let torus = cages::torus(DVec3::ZERO, 2.0, 0.6, 48, 32)?;
    for level in [3, 4] {
        bench_object(
            context,
            cage_object("torus cage", torus.clone(), level)?,
            700,
            iterations,
            out,
        )?;
    }
    // One dispatch evaluates at most 65,535 patches: 250 × 250 faces.
    let big = cages::torus(DVec3::ZERO, 2.0, 0.6, 250, 250)?;
    bench_object(
        context,
        cage_object("62,500-face torus", big, 2)?,
        30_000,
        iterations,
        out,
    )?;
    let cube = cages::cube(DVec3::ZERO, 2.0)?;
    bench_object(
        context,
        cage_object("cube cage", cube, 5)?,
        3,
        iterations,
        out,
    )?;

    // The other schemes, every face through limit stencils: Doo-Sabin and √3 (one stencil
    // patch per polygon, at most 65,535) on a 24 × 16 torus, quads and split into triangles;
    // the butterfly (a grid per cage triangle) on the 48 × 32 one split into triangles.
    use knotwork::kernel::subdiv::Scheme;
    let small = cages::torus(DVec3::ZERO, 2.0, 0.6, 24, 16)?;
    let small_triangles = triangulated(&small)?;
    let triangles = triangulated(&torus)?;
    for (name, mesh, scheme, level) in [
        ("24x16 torus Doo-Sabin", &small, Scheme::DooSabin, 2),
        ("24x16 torus Doo-Sabin", &small, Scheme::DooSabin, 3),
        ("24x16 tri torus √3", &small_triangles, Scheme::Sqrt3, 3),
        ("24x16 tri torus √3", &small_triangles, Scheme::Sqrt3, 4),
        (
            "48x32 tri torus butterfly",
            &triangles,
            Scheme::Butterfly,
            2,
        ),
        (
            "48x32 tri torus butterfly",
            &triangles,
            Scheme::Butterfly,
            3,
        ),
    ] {
        let start = Instant::now();
        let object = cage_object_with(name, mesh.clone(), level, scheme)?;
        object.decompose()?;
        let build_ms = start.elapsed().as_secs_f64() * 1e3;
        writeln!(
            out,
            "{name} L{level}: stencil tables built in {build_ms:.1} ms"
        )?;
        bench_object(context, object, 200, iterations, out)?;
    }

    // The 1,536-face cages with extraordinary points, through the editor's feed at level 4
    // (B-spline patches for the regular quads, stencils for the rest): the cube's cage refined
    // four times (eight points of three quads) and the 24 × 32 torus split into triangles
    // (every face irregular under Catmull-Clark), also under Loop.
    let one_thread = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
    let (points, level) =
        knotwork::kernel::subdiv::SubdivisionSurface::from_mesh(cages::cube(DVec3::ZERO, 2.0)?, 4)?
            .refined(4)?;
    let faces: Vec<Vec<u32>> = level.faces().map(<[u32]>::to_vec).collect();
    let refined_cube = knotwork::kernel::PolygonMesh::new(points, &faces)?;
    let torus_triangles = triangulated(&cages::torus(DVec3::ZERO, 2.0, 0.6, 24, 32)?)?;
    for (name, mesh, scheme) in [
        (
            "cube refined to 1,536 quads",
            refined_cube,
            Scheme::CatmullClark,
        ),
        (
            "24x32 torus in 1,536 triangles",
            torus_triangles.clone(),
            Scheme::CatmullClark,
        ),
        (
            "24x32 torus in 1,536 triangles, Loop",
            torus_triangles,
            Scheme::Loop,
        ),
    ] {
        let surface = cage_surface(mesh, 4, scheme)?;
        let mut builds = Vec::new();
        let mut ones = Vec::new();
        let mut feed = None;
        for _ in 0..iterations.clamp(1, 5) {
            let start = Instant::now();
            feed = Some(surface.limit_feed(4, Display::Limit)?);
            builds.push(start.elapsed().as_secs_f64() * 1e3);
            let start = Instant::now();
            one_thread.install(|| surface.limit_feed(4, Display::Limit))?;
            ones.push(start.elapsed().as_secs_f64() * 1e3);
        }
        let Some(feed) = feed else { continue };
        // As the editor shows a new cage: the object's feed, the GPU layout and its upload
        // (a new object each time, so nothing is cached; the compute pass not waited for).
        let scene_of = |surface: &knotwork::kernel::subdiv::SubdivisionSurface| Scene {
            objects: vec![SceneObject::new(
                name,
                knotwork::scene::ObjectGeometry::new(knotwork::scene::SubdivObject::from(
                    surface.clone(),
                )),
            )],
            unit: None,
        };
        let mut sync =
            SceneSync::with_scene(&context.device, &context.queue, &scene_of(&surface), 1.0)?;
        let mut to_gpu = Vec::new();
        for _ in 0..iterations.clamp(1, 5) {
            wait(context)?;
            let scene = scene_of(&surface);
            let start = Instant::now();
            sync.rebuild(&scene, 1.0)?;
            // The uploads, sent as the editor's next frame sends them.
            context.queue.submit([]);
            to_gpu.push(start.elapsed().as_secs_f64() * 1e3);
        }
        writeln!(
            out,
            "{name} L4, editor's feed | built {:8.1} ms on {} threads, {:8.1} ms on one, {:8.1} ms to the GPU | {} B-spline patches, {} stencil slots, {} entries",
            median(builds),
            rayon::current_num_threads(),
            median(ones),
            median(to_gpu),
            feed.regular.len(),
            feed.slots.len(),
            feed.entries.len(),
        )?;
    }

    let binding = context.device.limits().max_storage_buffer_binding_size;
    for level in [3, 4, 5] {
        let surface =
            knotwork::kernel::subdiv::SubdivisionSurface::from_mesh(torus.clone(), level)?;
        let start = Instant::now();
        one_thread.install(|| surface.limit_feed_with(level, Display::Limit, false))?;
        let one_ms = start.elapsed().as_secs_f64() * 1e3;
        let start = Instant::now();
        let feed = surface.limit_feed_with(level, Display::Limit, false)?;
        let build_ms = start.elapsed().as_secs_f64() * 1e3;
        let slots = feed.slots.len();
        let bytes = feed.entries.len() * 32 + slots * 8;
        let mut pass_ms = Vec::new();
        for _ in 0..iterations.clamp(1, 5) {
            let start = Instant::now();
            match knotwork::gpu::subdiv_eval::evaluate_feed(
                &context.device,
                &context.queue,
                surface.points(),
                &feed,
            ) {
                Ok(_) => pass_ms.push(start.elapsed().as_secs_f64() * 1e3),
                Err(GpuError::BufferTooLarge { .. }) => break,
                Err(e) => return Err(e.into()),
            }
        }
        let pass = if pass_ms.is_empty() {
            "too large for the device".to_string()
        } else {
            format!("upload+pass+readback {:8.1} ms", median(pass_ms))
        };
        writeln!(
            out,
            "torus cage L{level}, all stencils  | table build {build_ms:8.1} ms on {} threads, {one_ms:8.1} ms on one | {slots} slots, {} entries, {:.0} bytes per refined vertex, {:.0} MB in {} binding(s) of {} MiB | {pass}",
            rayon::current_num_threads(),
            feed.entries.len(),
            bytes as f64 / slots as f64,
            bytes as f64 / 1e6,
            (bytes as u64).div_ceil(binding),
            binding >> 20,
        )?;
    }
    Ok(())
}

/// The efficient substitutes against the exact limit, cage by cage: for each substitute its
/// error against the exact limit at the level's vertices ([`SubdivisionSurface::substitute_error`],
/// over the substitute patches) and the CPU time to recompute its control points after an edit;
/// then the exact display and each substitute through the editor's path (full pass, drag
/// latency), at the same level and so the same vertex count.
fn bench_substitutes(
    context: &GpuContext,
    iterations: usize,
    out: &mut impl Write,
) -> Result<(), Box<dyn std::error::Error>> {
    use knotwork::kernel::subdiv::patches::Display;
    use knotwork::kernel::subdiv::{Options, Scheme, SubdivisionSurface, cages};
    use knotwork::scene::SubdivObject;
    let cube = cages::cube(DVec3::ZERO, 2.0)?;
    let icosahedron = cages::icosahedron(DVec3::ZERO, 1.5)?;
    let torus = triangulated(&cages::torus(DVec3::ZERO, 2.0, 0.7, 24, 16)?)?;
    let quads = [Display::Limit, Display::Acc, Display::Gregory];
    let triangles = [Display::Limit, Display::PnTriangles];
    let cases: [(
        &str,
        &knotwork::kernel::PolygonMesh,
        Scheme,
        u32,
        &[Display],
    ); 5] = [
        ("cube", &cube, Scheme::CatmullClark, 4, &quads),
        ("icosahedron", &icosahedron, Scheme::CatmullClark, 4, &quads),
        ("24x16 tri torus", &torus, Scheme::CatmullClark, 3, &quads),
        ("icosahedron", &icosahedron, Scheme::Loop, 4, &triangles),
        ("24x16 tri torus", &torus, Scheme::Loop, 4, &triangles),
    ];
    for (name, mesh, scheme, level, displays) in cases {
        let options = Options {
            scheme,
            ..Default::default()
        };
        let surface =
            SubdivisionSurface::new((*mesh).clone(), Vec::new(), Vec::new(), options, level)?;
        for &display in displays {
            let label = match display.substitute() {
                Some(kind) => {
                    let e = surface.substitute_error(kind, level, true)?;
                    let (_, plan) = surface.substitute_feed(level, kind, true)?;
                    let (points_ms, _) = median_ms(iterations.clamp(1, 20), || {
                        Ok::<_, std::convert::Infallible>(plan.control_points(surface.points()))
                    })?;
                    writeln!(
                        out,
                        "{name} {} L{level} vs exact | {} patches, {} samples | distance max {:.2e} rms {:.2e} of the size | normal max {:.2}° mean {:.2}° | points per edit {points_ms:.3} ms",
                        kind.label(),
                        e.patches,
                        e.samples,
                        e.max_distance,
                        e.rms_distance,
                        e.max_normal_degrees,
                        e.mean_normal_degrees,
                    )?;
                    kind.label()
                }
                None => "exact limit",
            };
            let object = SceneObject::new(
                format!("{name} {} {label}", scheme.label()),
                ObjectGeometry::boxed(Box::new(SubdivObject::checked(surface.clone(), display)?)),
            );
            bench_object(context, object, 1, iterations, out)?;
        }
    }
    Ok(())
}

/// glTF export of the demo scene (CPU, f64 tessellation) at a tolerance of 1e-3 and 1e-4 of the
/// scene's size, with and without the curvature attributes: median time, triangles, file size.
fn bench_export(
    context: &GpuContext,
    scene: &Scene,
    iterations: usize,
    out: &mut impl Write,
) -> Result<(), Box<dyn std::error::Error>> {
    use knotwork::io::gltf::{self, CurvatureColors, ExportOptions};
    use knotwork::io::project::Project;
    use knotwork::kernel::tess::Tessellation;
    let project = Project {
        scene: scene.clone(),
        view: None,
    };
    let size = gltf::default_tolerance(scene) / 1e-3;
    for (fraction, curvature) in [(1e-3, false), (1e-3, true), (1e-4, false)] {
        let options = ExportOptions {
            tessellation: Tessellation::Tolerance(fraction * size),
            curvature,
            colors: curvature.then(|| {
                CurvatureColors::automatic(scene, 1, knotwork::gpu::records::curvature_ramp_rgb())
            }),
        };
        let (ms, (triangles, bytes)) = median_ms(iterations.clamp(1, 5), || {
            let export = gltf::export(&project, &options)?;
            Ok::<_, gltf::ExportError>((export.triangles, gltf::to_glb(&export).len()))
        })?;
        writeln!(
            out,
            "export demo .glb, tol {fraction:.0e} × size{} | {triangles:>9} triangles {:>8.2} MB | {ms:8.1} ms, {:.2} M triangles/s",
            if curvature {
                " + curvature"
            } else {
                "             "
            },
            bytes as f64 / 1e6,
            triangles as f64 / ms / 1e3,
        )?;
    }
    // The same files with the grids evaluated by the compute shaders (`export --backend gpu`;
    // the triangles are the kernel's): on a software adapter this is the emulated GPU, so the
    // figure that matters is a real GPU's.
    let grids = std::sync::Arc::new(knotwork::gpu::export_grids::GpuGrids::new(
        &context.device,
        &context.queue,
    ));
    for (fraction, curvature) in [(1e-3, true), (1e-4, false)] {
        let options = ExportOptions {
            tessellation: Tessellation::Tolerance(fraction * size),
            curvature,
            colors: None,
        };
        let (ms, triangles) = median_ms(iterations.clamp(1, 5), || {
            gltf::export_with(&project, &options, grids.clone()).map(|e| e.triangles)
        })?;
        writeln!(
            out,
            "export demo .glb, tol {fraction:.0e} × size{}, grids on the GPU | {triangles:>9} triangles | {ms:8.1} ms, {:.2} M triangles/s{}",
            if curvature { " + curvature" } else { "" },
            triangles as f64 / ms / 1e3,
            if grids.fallbacks() > 0 {
                " (some batches fell back to the CPU)"
            } else {
                ""
            },
        )?;
    }
    // What the web page's exportGlb runs (as WebAssembly there): the document as project-file
    // text, the default tolerance, curvature and mean-curvature colours over the automatic
    // range; the browser test prints the page's figure for the same call.
    let text = knotwork::io::project::write(&project);
    let options = r#"{"curvature": true, "colors": "mean"}"#;
    let (ms, bytes) = median_ms(iterations.clamp(1, 5), || {
        gltf::glb_from_json(&text, options, knotwork::gpu::records::curvature_ramp_rgb())
            .map(|glb| glb.len())
    })?;
    writeln!(
        out,
        "export demo .glb as the page's exportGlb does (project text in, curvature, mean colours) | {:>8.2} MB | {ms:8.1} ms",
        bytes as f64 / 1e6,
    )?;
    // The estimate the Export window shows and every export checks first: its time depends
    // on the spans, not on the triangles it predicts.
    for fraction in [1e-3, 1e-5, 1e-7] {
        let tessellation = Tessellation::Tolerance(fraction * size);
        let (ms, triangles) = median_ms(iterations.clamp(1, 5), || {
            gltf::estimate_triangles(
                scene,
                tessellation,
                usize::MAX,
                knotwork::kernel::tess::Estimate::Close,
            )
            .map(|counts| counts.iter().sum::<usize>())
        })?;
        writeln!(
            out,
            "export estimate, demo at tol {fraction:.0e} × size | {triangles:>12} triangles | {ms:8.2} ms",
        )?;
    }
    // Curvature for a subdivision surface's export: its stencils leave it undefined at
    // extraordinary vertices, so it is estimated on the mesh (Rusinkiewicz 2004).
    let cube = knotwork::kernel::subdiv::cages::cube(glam::DVec3::ZERO, 2.0)?;
    let surface = knotwork::kernel::subdiv::SubdivisionSurface::from_mesh(cube, 5)?;
    let cage = Project {
        scene: Scene {
            objects: vec![knotwork::scene::SceneObject::new(
                "cube cage",
                knotwork::scene::ObjectGeometry::new(knotwork::scene::SubdivObject::new(
                    surface,
                    Default::default(),
                )),
            )],
            unit: None,
        },
        view: None,
    };
    for curvature in [false, true] {
        let options = ExportOptions {
            tessellation: Tessellation::Segments(4),
            curvature,
            colors: None,
        };
        let (ms, triangles) = median_ms(iterations.clamp(1, 5), || {
            gltf::export(&cage, &options).map(|e| e.triangles)
        })?;
        writeln!(
            out,
            "export Catmull-Clark cube, level 5{} | {triangles:>9} triangles | {ms:8.1} ms",
            if curvature {
                " + estimated curvature"
            } else {
                "                      "
            },
        )?;
    }
    Ok(())
}

/// The trimming benchmark's scene: `objects` bicubic landscapes of 10 × 10 Bézier patches side
/// by side (1,000 patches for 10), each trimmed by its domain's boundary and one hole in every
/// patch, a ten-sided loop of cubic curves (about 10,000 curves for 10 objects); with `trimmed`
/// false the same surfaces untrimmed.
pub fn trimmed_scene(
    objects: usize,
    trimmed: bool,
) -> Result<Scene, knotwork::kernel::GeometryError> {
    use glam::DVec2;
    use knotwork::kernel::trim::shapes;
    use knotwork::kernel::{TrimCurve, TrimmedSurface};
    let mut scene = Scene::default();
    for k in 0..objects {
        let landscape = landscape(13)?;
        let Some(surface) = landscape.geometry.nurbs_surface().cloned() else {
            continue;
        };
        let offset = glam::DAffine3::from_translation(DVec3::new(4.2 * k as f64, 0.0, 0.0));
        let surface = surface.transformed(&offset)?;
        let geometry = if trimmed {
            let mut loops = vec![shapes::rectangle(DVec2::ZERO, DVec2::ONE)?];
            for i in 0..10 {
                for j in 0..10 {
                    let c = DVec2::new((i as f64 + 0.5) / 10.0, (j as f64 + 0.5) / 10.0);
                    let corner = |a: usize, r: f64| {
                        let t = a as f64 * std::f64::consts::TAU / 10.0;
                        c + DVec2::new(t.cos(), t.sin()) * r
                    };
                    let hole = (0..10)
                        .map(|a| {
                            let (p, q) = (corner(a, 0.03), corner(a + 1, 0.03));
                            let bulge =
                                corner(a, 0.036).lerp(corner(a + 1, 0.036), 0.5) - (p + q) / 2.0;
                            TrimCurve::new(
                                3,
                                vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0],
                                vec![
                                    p,
                                    p.lerp(q, 1.0 / 3.0) + bulge,
                                    p.lerp(q, 2.0 / 3.0) + bulge,
                                    q,
                                ],
                                None,
                            )
                        })
                        .collect::<Result<Vec<_>, _>>()?;
                    loops.push(hole);
                }
            }
            ObjectGeometry::from_trimmed(TrimmedSurface::new(surface, loops)?)
        } else {
            ObjectGeometry::new(surface)
        };
        let mut object = SceneObject::new(format!("trimmed {k}"), geometry);
        object.segments = 8;
        scene.objects.push(object);
    }
    Ok(scene)
}

/// Frame time of the trimming scene at 1280 × 800 with and without trims, and the export of
/// the trimmed surfaces by constrained Delaunay triangulation.
fn bench_trim(
    context: &GpuContext,
    iterations: usize,
    out: &mut impl Write,
) -> Result<(), Box<dyn std::error::Error>> {
    let build = Instant::now();
    let trimmed = trimmed_scene(10, true)?;
    let curves: usize = trimmed
        .objects
        .iter()
        .filter_map(|o| o.geometry.as_trimmed())
        .map(|t| t.loops().iter().map(Vec::len).sum::<usize>())
        .sum();
    let build_ms = build.elapsed().as_secs_f64() * 1e3;
    let plain = trimmed_scene(10, false)?;
    // Both scenes on the GPU, drawn in turn so that drift of the machine affects both alike.
    let syncs = [evaluated(context, &plain)?, evaluated(context, &trimmed)?];
    let renderer = ViewportRenderer::new(&context.device);
    let target = ViewTarget::new(&context.device, 1280, 800);
    // The whole scene (each hole a few pixels across), then one surface filling the view (holes
    // about 60 pixels across).
    let whole = trimmed.bounds().ok_or("empty scene")?;
    let one = trimmed.objects[0].bounds().ok_or("empty object")?;
    let mut results = Vec::new();
    for (lo, hi) in [whole, one] {
        let mut view = ViewSettings::default();
        view.camera.frame(lo.as_vec3(), hi.as_vec3(), 1.6);
        view.overlays.net = false;
        view.overlays.points = false;
        renderer.set_scene(
            &context.queue,
            &scene_uniform(&view, &target, 3.5, (-1.0, 1.0), None),
        );
        let mut times = [Vec::new(), Vec::new()];
        for i in 0..iterations + 2 {
            for (k, sync) in syncs.iter().enumerate() {
                let geometry = sync.geometry().ok_or("nothing on the GPU")?;
                let ms = timed_render(context, &renderer, &target, geometry, view.overlays)?;
                if i >= 2 {
                    times[k].push(ms);
                }
            }
        }
        results.push(times.map(median));
    }
    let patches = syncs[0].geometry().map_or(0, |g| g.patch_count());
    let [untrimmed_ms, trimmed_ms] = results[0];
    let [close_untrimmed, close_trimmed] = results[1];
    writeln!(
        out,
        "trimming: {patches} patches, {curves} trim curves, 1280 × 800 | frame {trimmed_ms:8.3} ms trimmed vs {untrimmed_ms:8.3} ms untrimmed ({:+.0} %); one surface filling the view {close_trimmed:.3} vs {close_untrimmed:.3} ms ({:+.0} %); scene built and validated in {build_ms:.0} ms",
        100.0 * (trimmed_ms / untrimmed_ms - 1.0),
        100.0 * (close_trimmed / close_untrimmed - 1.0),
    )?;
    let size = trimmed.bounds().map_or(1.0, |(lo, hi)| {
        (hi - lo).length() / trimmed.objects.len() as f64
    });
    let tessellation = knotwork::kernel::tess::Tessellation::Tolerance(1e-3 * size);
    let mut times = Vec::new();
    let mut triangles = 0;
    for _ in 0..iterations.clamp(1, 3) {
        let started = Instant::now();
        triangles = 0;
        for object in &trimmed.objects {
            for mesh in object.tessellate(tessellation, false)? {
                triangles += mesh.triangles.len();
            }
        }
        times.push(started.elapsed().as_secs_f64() * 1e3);
    }
    let ms = median(times);
    writeln!(
        out,
        "export trimmed, tol 1e-3 × size | {triangles:>9} triangles | {ms:8.1} ms, {:.2} M triangles/s (grid clipped by the loops)",
        triangles as f64 / ms / 1e3,
    )?;
    Ok(())
}

/// Exact mass properties ([`knotwork::kernel::mass`]): a NURBS sphere, and every closed body of
/// OpenCASCADE's plate of 806 faces (planes and cylinders trimmed by their holes) and of the
/// CAx-IF's B-spline head (rational bicubic faces), as `knotwork info` measures them.
fn bench_mass(iterations: usize, out: &mut impl Write) -> Result<(), Box<dyn std::error::Error>> {
    use knotwork::kernel::mass::mass_properties;
    use knotwork::kernel::trim::TrimmedSurface;
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let sphere = TrimmedSurface::untrimmed(construct::sphere(DVec3::new(1.0, 2.0, 3.0), 2.0)?);
    let (ms, m) = median_ms(iterations.max(3), || {
        mass_properties(std::slice::from_ref(&sphere), &[])
    })?;
    writeln!(
        out,
        "mass NURBS sphere (32 rational patches)        | {ms:8.3} ms (volume {:.12})",
        m.volume
    )?;
    for (file, name) in [
        ("tests/reference/occ/step/plate-20.step", "plate, 806 faces"),
        (
            "tests/reference/step-public/cax-if__s1-tu-203__headfront.stp",
            "B-spline head, 5 faces",
        ),
    ] {
        let bytes = std::fs::read(root.join(file))?;
        let model = knotwork::io::step::read::read(&bytes, &mut |_, _| true)?;
        let (ms, volume) = median_ms(iterations.max(3), || {
            model
                .bodies
                .iter()
                .map(|b| {
                    let flipped = knotwork::kernel::join::orientation(b.faces.len(), &b.topology);
                    mass_properties(&b.faces, &flipped).map(|m| m.volume)
                })
                .sum::<Result<f64, _>>()
        })?;
        writeln!(out, "mass {name:<40} | {ms:8.3} ms (volume {volume:.6})")?;
    }
    Ok(())
}

/// The faces of a prism over the regular `sides`-gon of radius `radius` around `centre` in the
/// xy plane, `height` tall: `sides` planes and two capping discs.
fn prism(
    centre: DVec3,
    radius: f64,
    sides: usize,
    height: f64,
) -> Result<Vec<TrimmedSurface>, knotwork::kernel::GeometryError> {
    let corner = |k: usize| {
        let angle = std::f64::consts::TAU * k as f64 / sides as f64;
        centre + DVec3::new(angle.cos(), angle.sin(), 0.0) * radius
    };
    let up = DVec3::Z * height;
    let mut faces = Vec::with_capacity(sides + 2);
    for k in 0..sides {
        let (a, b) = (corner(k), corner(k + 1));
        faces.push(TrimmedSurface::untrimmed(construct::plane(a, b - a, up)?));
    }
    for lift in [DVec3::ZERO, up] {
        // One line per side, so that each edge of a cap meets one side.
        let outline: Vec<_> = (0..sides)
            .map(|k| construct::line(corner(k) + lift, corner(k + 1) + lift))
            .collect::<Result<_, _>>()?;
        faces.push(knotwork::kernel::planar::planar_face(&outline)?);
    }
    Ok(faces)
}

/// Booleans: the plate of the issue (130 × 130 × 10 minus 144 pins, every third slanted) read
/// from STEP, cut and written as STEP in one go (OpenCASCADE's time for the same, recorded when
/// the fixtures were made, beside it); and one drag step of a live difference of two
/// 20-face prisms (the tool moved, the difference made again through its history).
fn bench_boolean(
    iterations: usize,
    out: &mut impl Write,
) -> Result<(), Box<dyn std::error::Error>> {
    use knotwork::doc::{Command, Document};
    use knotwork::kernel::boolean::{BooleanOp, boolean_joined};
    use knotwork::ops::boolean::{Boolean, Kind};
    use knotwork::ops::transform::Transform;
    use knotwork::scene::polysurface::Polysurface;
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/reference/boolean");
    // Each file's faces with their shared edges as the file gives them (as `knotwork
    // boolean` takes them, and OpenCASCADE reads its shells).
    type Read = (Vec<TrimmedSurface>, knotwork::kernel::join::Topology);
    let read_faces = |name: &str| -> Result<Read, Box<dyn std::error::Error>> {
        let bytes = std::fs::read(root.join(name))?;
        let model = knotwork::io::step::read::read(&bytes, &mut |_, _| true)?;
        let topology = knotwork::kernel::join::Topology::concatenated(
            model.bodies.iter().map(|b| (&b.topology, b.faces.len())),
        );
        Ok((
            model.bodies.into_iter().flat_map(|b| b.faces).collect(),
            topology,
        ))
    };
    let started = Instant::now();
    let (plate, pins) = (read_faces("plate-a.step")?, read_faces("plate-b.step")?);
    let read_ms = started.elapsed().as_secs_f64() * 1e3;
    let at = Instant::now();
    let made = boolean_joined(
        BooleanOp::Difference,
        (&plate.0, Some(&plate.1)),
        (&pins.0, Some(&pins.1)),
        1e-6 * 184.0,
    )?;
    let boolean_ms = at.elapsed().as_secs_f64() * 1e3;
    let at = Instant::now();
    let mut scene = Scene::default();
    scene.objects.clear();
    scene.objects.push(SceneObject::new(
        "plate",
        ObjectGeometry::new(Polysurface::with_topology(
            made.faces(),
            1e-5 * 184.0,
            made.topology(),
        )?),
    ));
    let tolerance = knotwork::io::step::default_tolerance(&scene);
    let written = knotwork::io::step::export_scene(&scene, "plate.step", tolerance)?;
    let write_ms = at.elapsed().as_secs_f64() * 1e3;
    let occt: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(root.join("occt-plate.json"))?)?;
    writeln!(
        out,
        "boolean plate minus 144 pins, read+cut+write   | {:8.1} ms (read {read_ms:.1}, boolean {boolean_ms:.1}, write {write_ms:.1}; {} faces, {} bytes, volume {:.4}; OpenCASCADE {:.1} ms)",
        read_ms + boolean_ms + write_ms,
        made.faces().len(),
        written.text.len(),
        made.solids
            .iter()
            .map(|s| s.volume())
            .sum::<Result<f64, _>>()?,
        occt["occt_read_cut_write_seconds"]
            .as_f64()
            .unwrap_or(f64::NAN)
            * 1e3,
    )?;
    // Two 20-face prisms, the second turned and shifted; the difference kept with history.
    let mut scene = Scene::default();
    scene.objects.clear();
    let a = prism(DVec3::ZERO, 1.0, 18, 1.0)?;
    let b = knotwork::kernel::solids::transformed(
        &prism(DVec3::ZERO, 0.6, 18, 1.4)?,
        &glam::DAffine3::from_rotation_translation(
            glam::DQuat::from_rotation_x(0.3),
            DVec3::new(0.7, 0.2, -0.2),
        ),
    )?;
    for (name, faces) in [("A", a), ("B", b)] {
        scene.objects.push(SceneObject::new(
            name,
            ObjectGeometry::new(Polysurface::new(faces, 1e-6)?),
        ));
    }
    let mut doc = Document::new(scene);
    doc.execute(&Command::Apply {
        operation: knotwork::scene::operation::Operation::new(Boolean {
            operation: Kind::Difference,
            a: vec![0.into()],
            b: vec![1.into()],
            tolerance: 1e-6,
        }),
        keep_history: true,
    })?;
    let mut step = 0;
    let (ms, _) = median_ms(iterations.max(3), || {
        step += 1;
        let shift = if step % 2 == 0 { 0.01 } else { -0.01 };
        doc.execute(&Command::operation(Transform::new(
            1,
            &glam::DAffine3::from_translation(DVec3::new(shift, 0.0, 0.0)),
        )))
        .map(|_| ())
    })?;
    writeln!(
        out,
        "boolean drag step, two 20-face prisms (live)   | {ms:8.3} ms"
    )?;
    Ok(())
}

/// Edge features on a 20-face part (the 18-sided prism: 54 edges, 36 corners), on one core:
/// every edge filleted (cylinders, and a ball's triangle at each corner) and chamfered, the
/// part shelled with its top open (offset and boolean), each with the result joined and
/// checked closed; and one step of a radius dragged on the editor's fillet with history (the
/// fillet made again in place, as one undo step).
fn bench_features(
    iterations: usize,
    out: &mut impl Write,
) -> Result<(), Box<dyn std::error::Error>> {
    use knotwork::doc::{Command, Document};
    use knotwork::kernel::features::{
        EdgeFeature, EdgePick, round_edges, round_edges_varying, shell,
    };
    use knotwork::ops::features::FilletEdges;
    use knotwork::scene::operation::Operation;
    use knotwork::scene::polysurface::Polysurface;
    let part = prism(DVec3::ZERO, 1.0, 18, 1.0)?;
    let tolerance = 1e-6 * 2.3;
    let (fillet_ms, filleted) = median_ms(iterations.max(3), || {
        round_edges(
            &part,
            &EdgePick::All,
            EdgeFeature::Fillet { radius: 0.05 },
            tolerance,
        )
    })?;
    let (chamfer_ms, chamfered) = median_ms(iterations.max(3), || {
        round_edges(
            &part,
            &EdgePick::All,
            EdgeFeature::Chamfer {
                distance: 0.05,
                other: 0.05,
            },
            tolerance,
        )
    })?;
    let top = [DVec3::new(0.0, 0.0, 1.0)];
    let (shell_ms, shelled) = median_ms(iterations.clamp(3, 5), || {
        shell(&part, -0.05, &top, tolerance)
    })?;
    writeln!(
        out,
        "fillet every edge, 20-face prism (54 edges)    | {fillet_ms:8.2} ms ({} faces, volume {:.6})",
        filleted.faces.len(),
        filleted.volume()?
    )?;
    writeln!(
        out,
        "chamfer every edge, 20-face prism              | {chamfer_ms:8.2} ms ({} faces, volume {:.6})",
        chamfered.faces.len(),
        chamfered.volume()?
    )?;
    writeln!(
        out,
        "shell, 20-face prism, top open                 | {shell_ms:8.2} ms ({} faces, volume {:.6})",
        shelled.faces.len(),
        shelled.volume()?
    )?;
    // Every other upright edge, its radius running from 0.03 at the base to 0.08 at the top.
    let (uprights, radii): (Vec<DVec3>, Vec<[(DVec3, f64); 2]>) = (0..18)
        .step_by(2)
        .map(|k| {
            let angle = std::f64::consts::TAU * k as f64 / 18.0;
            let foot = DVec3::new(angle.cos(), angle.sin(), 0.0);
            (
                foot + DVec3::Z * 0.5,
                [(foot, 0.03), (foot + DVec3::Z, 0.08)],
            )
        })
        .unzip();
    let radii: Vec<(DVec3, f64)> = radii.into_iter().flatten().collect();
    let (varying_ms, varied) = median_ms(iterations.max(3), || {
        round_edges_varying(
            &part,
            &EdgePick::Near(uprights.clone()),
            EdgeFeature::Fillet { radius: 0.05 },
            &radii,
            tolerance,
        )
    })?;
    writeln!(
        out,
        "fillet 9 upright edges, radius 0.03 to 0.08    | {varying_ms:8.2} ms ({} faces, volume {:.6})",
        varied.faces.len(),
        varied.volume()?
    )?;
    // A block with a round hole (its rims a torus each), then the same block with its upright
    // edges rounded (its caps' rims tangent chains), filleted, and shelled with the top open.
    {
        use knotwork::kernel::boolean::{BooleanOp, boolean};
        use knotwork::kernel::solids::{block, capped_cylinder};
        let size = DVec3::new(4.0, 3.0, 1.5);
        let hole = capped_cylinder(DVec3::new(2.0, 1.5, -0.5), DVec3::Z * 2.5, 0.5)?;
        let tolerance = 1e-6 * size.length();
        let plate = boolean(
            BooleanOp::Difference,
            &block(DVec3::ZERO, size)?,
            &hole,
            tolerance,
        )?
        .faces();
        let (rims_ms, rims) = median_ms(iterations.max(3), || {
            round_edges(
                &plate,
                &EdgePick::All,
                EdgeFeature::Fillet { radius: 0.2 },
                tolerance,
            )
        })?;
        let corners: Vec<DVec3> = [(0.0, 0.0), (4.0, 0.0), (4.0, 3.0), (0.0, 3.0)]
            .iter()
            .map(|&(x, y)| DVec3::new(x, y, 0.75))
            .collect();
        let slab = round_edges(
            &block(DVec3::ZERO, size)?,
            &EdgePick::Near(corners),
            EdgeFeature::Fillet { radius: 0.6 },
            tolerance,
        )?
        .faces;
        let slab = boolean(BooleanOp::Difference, &slab, &hole, tolerance)?.faces();
        let (chains_ms, chains) = median_ms(iterations.max(3), || {
            round_edges(
                &slab,
                &EdgePick::All,
                EdgeFeature::Fillet { radius: 0.2 },
                tolerance,
            )
        })?;
        let top = [DVec3::new(1.0, 1.0, 1.5)];
        let (slab_shell_ms, slab_shell) =
            median_ms(iterations.max(3), || shell(&slab, -0.2, &top, tolerance))?;
        writeln!(
            out,
            "fillet every edge, block with a hole (14)      | {rims_ms:8.2} ms ({} faces, volume {:.6})",
            rims.faces.len(),
            rims.volume()?
        )?;
        writeln!(
            out,
            "fillet 4 rim chains, rounded plate with a hole | {chains_ms:8.2} ms ({} faces, volume {:.6})",
            chains.faces.len(),
            chains.volume()?
        )?;
        writeln!(
            out,
            "shell, rounded plate with a hole, top open     | {slab_shell_ms:8.2} ms ({} faces, volume {:.6})",
            slab_shell.faces.len(),
            slab_shell.volume()?
        )?;
        // A block with a block fused on its top (tori where the foot's concave fillets
        // meet the upright convex ones, quadrilaterals closing the chamfers there), and a
        // block with a pin, shelled (planes and the round wall offset, then the boolean).
        let boss = boolean(
            BooleanOp::Union,
            &block(DVec3::ZERO, size)?,
            &block(DVec3::new(1.0, 1.0, 1.0), DVec3::new(1.5, 1.0, 1.5))?,
            tolerance,
        )?
        .faces();
        let (boss_fillet_ms, boss_fillet) = median_ms(iterations.max(3), || {
            round_edges(
                &boss,
                &EdgePick::All,
                EdgeFeature::Fillet { radius: 0.15 },
                tolerance,
            )
        })?;
        let (boss_chamfer_ms, boss_chamfer) = median_ms(iterations.max(3), || {
            round_edges(
                &boss,
                &EdgePick::All,
                EdgeFeature::Chamfer {
                    distance: 0.15,
                    other: 0.15,
                },
                tolerance,
            )
        })?;
        let pin = boolean(
            BooleanOp::Union,
            &block(DVec3::ZERO, size)?,
            &capped_cylinder(DVec3::new(2.0, 1.5, 1.0), DVec3::Z * 1.5, 0.5)?,
            tolerance,
        )?
        .faces();
        let (pin_shell_ms, pin_shell) =
            median_ms(iterations.clamp(3, 5), || shell(&pin, -0.2, &[], tolerance))?;
        writeln!(
            out,
            "fillet every edge, block with a boss (24)      | {boss_fillet_ms:8.2} ms ({} faces, volume {:.6})",
            boss_fillet.faces.len(),
            boss_fillet.volume()?
        )?;
        writeln!(
            out,
            "chamfer every edge, block with a boss          | {boss_chamfer_ms:8.2} ms ({} faces, volume {:.6})",
            boss_chamfer.faces.len(),
            boss_chamfer.volume()?
        )?;
        writeln!(
            out,
            "shell, block with a pin, closed                | {pin_shell_ms:8.2} ms ({} faces, volume {:.6})",
            pin_shell.faces.len(),
            pin_shell.volume()?
        )?;
    }
    // The radius dragged: each step edits the fillet's history in place.
    let mut scene = Scene::default();
    scene.objects.clear();
    scene.objects.push(SceneObject::new(
        "part",
        ObjectGeometry::new(Polysurface::new(part, 1e-6)?),
    ));
    let mut doc = Document::new(scene);
    let fillet = FilletEdges {
        object: 0.into(),
        radius: 0.05,
        near: Vec::new(),
        radius_at: Vec::new(),
        tolerance: 1e-6,
    };
    doc.execute(&Command::Apply {
        operation: Operation::new(fillet.clone()),
        keep_history: true,
    })?;
    let mut step = 0;
    let (drag_ms, _) = median_ms(iterations.max(3), || {
        step += 1;
        let recipe = doc.scene.objects[1]
            .recipe
            .clone()
            .ok_or("the fillet has no history")?;
        let mut edited = recipe
            .operation
            .params::<FilletEdges>()
            .ok_or("not a fillet")?
            .clone();
        edited.radius = 0.05 + 0.001 * (step % 10) as f64;
        doc.execute(&Command::EditRecipe {
            object: 1,
            operation: Operation::new(edited),
        })
        .map(|_| ())
        .map_err(|e| Box::<dyn std::error::Error>::from(e.to_string()))
    })?;
    writeln!(
        out,
        "fillet radius drag step, 20-face prism (live)  | {drag_ms:8.2} ms"
    )?;
    Ok(())
}

/// Cage tools on a 10,000-face torus cage (100 × 100 quads) at level 2, one core: the topology
/// edit alone (the kernel's tool), the editor's step (the tool, the new cage checked as a
/// subdivision surface, the undo step), and that step with the new surface on the GPU (its
/// feed built, B-spline patches and the region's stencils, and uploaded, as the editor
/// rebuilds after a change of topology; the compute pass not waited for).
fn bench_cage_tools(
    context: &GpuContext,
    iterations: usize,
    out: &mut impl Write,
) -> Result<(), Box<dyn std::error::Error>> {
    use knotwork::doc::{Command, Document};
    use knotwork::kernel::subdiv::cage_edit::{Cage, Tool};
    use knotwork::kernel::subdiv::{SubdivisionSurface, cages};
    use knotwork::scene::operation::Operation;
    let mesh = cages::torus(glam::DVec3::ZERO, 4.0, 1.0, 100, 100)?;
    let cage = Cage {
        points: mesh.points().to_vec(),
        faces: mesh.faces().map(<[u32]>::to_vec).collect(),
        creases: Vec::new(),
        corners: Vec::new(),
    };
    let f = mesh.face(5050).to_vec();
    let tools = [
        Tool::Extrude {
            faces: vec![5050, 5051, 5150, 5151],
            offset: 0.05,
            individual: false,
        },
        Tool::Inset {
            faces: vec![5050, 5051, 5150, 5151],
            thickness: 0.01,
            depth: 0.0,
            individual: false,
        },
        Tool::LoopCut {
            edge: [f[0], f[1]],
            cuts: 2,
            slide: 0.0,
        },
        Tool::Dissolve {
            edges: vec![[f[1], f[2]]],
        },
        // A whole edge loop round the tube (100 edges through vertices of four edges).
        Tool::Bevel {
            edges: cage
                .edge_loop(f[0], f[3])?
                .into_iter()
                .map(|(a, b)| [a, b])
                .collect(),
            width: 0.01,
            segments: 2,
        },
        Tool::Poke {
            faces: vec![5050, 5051, 5150, 5151],
        },
        Tool::Subdivide {
            faces: vec![5050, 5051, 5150, 5151],
            cuts: 2,
        },
        // Two edge loops round the torus, crossing at a point: its corner mesh of four beveled
        // edges (a pipe), three segments.
        Tool::Bevel {
            edges: cage
                .edge_loop(f[0], f[1])?
                .into_iter()
                .chain(cage.edge_loop(f[1], f[2])?)
                .map(|(a, b)| [a, b])
                .collect(),
            width: 0.01,
            segments: 3,
        },
        Tool::Mirror {
            axis: 0,
            merge_distance: 0.0,
        },
        Tool::Triangulate {
            faces: vec![5050, 5051, 5150, 5151],
        },
        Tool::DissolveVertices {
            vertices: vec![f[2]],
        },
        Tool::Connect {
            vertices: vec![f[0], f[2]],
        },
        // Four faces turned a quarter turn round the torus's axis in 12 steps.
        Tool::Spin {
            faces: vec![5050, 5051, 5150, 5151],
            edges: Vec::new(),
            centre: [0.0; 3],
            axis: [0.0, 0.0, 1.0],
            degrees: 90.0,
            steps: 12,
            advance: 0.0,
        },
        // The knife through the torus's axis: the plane y = 0.01 across the tube on both
        // sides of the hole (a ring of 100 faces each), every face tried.
        Tool::Knife {
            faces: Vec::new(),
            point: [0.0, 0.01, 0.0],
            normal: [0.0, 1.0, 0.0],
            threshold: None,
        },
        Tool::BevelVertices {
            vertices: vec![f[0], f[2]],
            width: 0.01,
            segments: 1,
        },
        // Two points rounded in three segments (a corner mesh of four sides each).
        Tool::BevelVertices {
            vertices: vec![f[0], f[2]],
            width: 0.01,
            segments: 3,
        },
        Tool::Extrude {
            faces: vec![5050, 5051, 5150, 5151],
            offset: 0.05,
            individual: true,
        },
        Tool::Inset {
            faces: vec![5050, 5051, 5150, 5151],
            thickness: 0.01,
            depth: 0.02,
            individual: false,
        },
    ];
    let runs = iterations.clamp(3, 20);
    // Merge by distance over 20,000 points: the torus and its mirror image (the same torus,
    // every point doubled), welded back into the 10,000-face torus.
    let doubled = cage.mirror(0, 0.0)?;
    let (weld_ms, welded) = median_ms(runs, || doubled.merge_by_distance(&[], 1e-9))?;
    writeln!(
        out,
        "cage merge by distance, 20,000 points in pairs: {weld_ms:.2} ms ({} points after)",
        welded.points.len()
    )?;
    // Grid fill of a hole of 4 × 4 faces cut in the torus: its rim of 16 edges.
    let hole: Vec<usize> = (0..4)
        .flat_map(|i| (0..4).map(move |j| 5050 + 100 * i + j))
        .collect();
    let holed = cage.delete_faces(&hole)?;
    // The rims of a cage's holes: its closed loops of open edges.
    let rims_of = |cage: &Cage| {
        let mut directed = std::collections::HashSet::new();
        for face in &cage.faces {
            for c in 0..face.len() {
                directed.insert((face[c], face[(c + 1) % face.len()]));
            }
        }
        let open: Vec<(u32, u32)> = directed
            .iter()
            .filter(|&&(a, b)| !directed.contains(&(b, a)))
            .copied()
            .collect();
        cage.closed_loops(&open)
    };
    let rim = rims_of(&holed)?.pop().unwrap_or_default();
    let (fill_ms, filled) = median_ms(runs, || holed.grid_fill_rim(&rim, None, None))?;
    writeln!(
        out,
        "cage grid fill of a 16-edge hole in 10,000 faces: {fill_ms:.2} ms ({} faces after)",
        filled.faces.len()
    )?;
    // Bridge of that hole's rim (16 points) to a hole of one face (4 points) ten faces
    // along: a strip of 20 triangles, turned as Blender's bridge turns them.
    let two_holes = holed.delete_faces(&[5060])?;
    let rims = rims_of(&two_holes)?;
    if let [first, second] = &rims[..] {
        let (bridge_ms, bridged) = median_ms(runs, || two_holes.bridge_loops(first, second))?;
        writeln!(
            out,
            "cage bridge of a {}-point rim to a {}-point rim in 10,000 faces: {bridge_ms:.2} ms \
             ({} faces after)",
            first.len(),
            second.len(),
            bridged.faces.len()
        )?;
    }
    // Selection on the same cage: the loop through an edge, and Select More of it.
    let (loop_ms, edges) = median_ms(runs, || cage.edge_loop(f[0], f[1]))?;
    let selected: std::collections::BTreeSet<u32> =
        edges.iter().flat_map(|&(a, b)| [a, b]).collect();
    let (grow_ms, grown) = median_ms(runs, || {
        Ok::<_, std::convert::Infallible>(cage.grown(&selected))
    })?;
    writeln!(
        out,
        "cage select on 10,000 faces: edge loop {loop_ms:.2} ms ({} edges), more {grow_ms:.2} ms \
         ({} points)",
        edges.len(),
        grown.len()
    )?;
    let surface = SubdivisionSurface::from_mesh(mesh.clone(), 2)?;
    let scene = knotwork::scene::Scene {
        objects: vec![knotwork::scene::SceneObject::new(
            "torus",
            knotwork::scene::ObjectGeometry::new(knotwork::scene::SubdivObject::from(surface)),
        )],
        unit: None,
    };
    for tool in tools {
        let (tool_ms, edited) = median_ms(runs, || cage.apply(&tool))?;
        // The editor's step: a document of the torus, the tool applied as one undo step.
        let step = || -> Result<Document, Box<dyn std::error::Error>> {
            let mut doc = Document::new(scene.clone());
            doc.execute(&Command::Apply {
                operation: Operation::new(knotwork::ops::cage::CageEdit {
                    object: 0.into(),
                    tool: tool.clone(),
                }),
                keep_history: false,
            })
            .map_err(|e| e.to_string())?;
            Ok(doc)
        };
        let (step_ms, _) = median_ms(runs, step)?;
        let mut sync = SceneSync::with_scene(&context.device, &context.queue, &scene, 1.0)?;
        let gpu_ms = median_update_ms(
            context,
            runs,
            || Ok(()),
            |()| {
                let doc = step()?;
                sync.rebuild(&doc.scene, 1.0)
                    .map_err(|e| Box::<dyn std::error::Error>::from(e.to_string()))
            },
        )?;
        writeln!(
            out,
            "cage tool {:<9} on 10,000 faces: {tool_ms:.2} ms topology, {step_ms:.2} ms editor step, \
             {gpu_ms:.2} ms to the GPU ({} faces after)",
            tool.label(),
            edited.faces.len()
        )?;
    }
    bench_cage_tool_beside_a_plate(context, &scene, runs, out)?;
    bench_cage_tools_on_a_modelled_cage(context, runs, out)
}

/// Cage tools on Blender's Suzanne refined once (tests/reference/cage/197-monkey-inset.in.obj
/// through one Catmull-Clark step: 1,968 faces, 444 of them beside its poles and open eyes
/// and shown as limit stencils) at level 2, to the GPU as the editor takes them (the tool's
/// step, the object's feed, its upload): with the stencils of the faces the tool left alone
/// taken from the object before, and with the new object built fresh, every stencil face
/// refined.
fn bench_cage_tools_on_a_modelled_cage(
    context: &GpuContext,
    runs: usize,
    out: &mut impl Write,
) -> Result<(), Box<dyn std::error::Error>> {
    use knotwork::doc::{Command, Document};
    use knotwork::kernel::subdiv::SubdivisionSurface;
    use knotwork::kernel::subdiv::cage_edit::Tool;
    use knotwork::scene::operation::Operation;
    use knotwork::scene::{ObjectGeometry, SceneObject, SubdivObject};
    let bytes = reference_file("tests/reference/cage/197-monkey-inset.in.obj")?;
    let parsed = knotwork::io::obj::parse(&String::from_utf8_lossy(&bytes))?;
    let faces = parsed.all_faces();
    let mesh = knotwork::kernel::PolygonMesh::new(parsed.vertices, &faces)?;
    let (points, level) = SubdivisionSurface::from_mesh(mesh, 1)?.refined(1)?;
    let faces: Vec<Vec<u32>> = level.faces().map(<[u32]>::to_vec).collect();
    let mesh = knotwork::kernel::PolygonMesh::new(points, &faces)?;
    let surface = SubdivisionSurface::from_mesh(mesh, 2)?;
    let scene = Scene {
        objects: vec![SceneObject::new(
            "Suzanne",
            ObjectGeometry::new(SubdivObject::from(surface)),
        )],
        unit: None,
    };
    let tools = [
        Tool::Extrude {
            faces: vec![100, 101, 102, 103],
            offset: 0.05,
            individual: false,
        },
        Tool::Inset {
            faces: vec![500],
            thickness: 0.01,
            depth: 0.0,
            individual: false,
        },
        Tool::Poke { faces: vec![900] },
    ];
    // The scene's object is prepared here, as the editor has shown it before a tool.
    let mut sync = SceneSync::with_scene(&context.device, &context.queue, &scene, 1.0)?;
    for tool in tools {
        let label = tool.label();
        let command = Command::Apply {
            operation: Operation::new(knotwork::ops::cage::CageEdit {
                object: 0.into(),
                tool,
            }),
            keep_history: false,
        };
        let mut figures = Vec::new();
        let mut faces = (0, 0);
        for fresh in [false, true] {
            let update = |()| -> Result<_, Box<dyn std::error::Error>> {
                let mut doc = Document::new(scene.clone());
                doc.execute(&command).map_err(|e| e.to_string())?;
                let object = &mut doc.scene.objects[0];
                if let Some(edited) = object.geometry.as_subdivision() {
                    if fresh {
                        let whole =
                            SubdivObject::with_settings(edited.surface.mesh(), &edited.settings())?;
                        object.geometry = ObjectGeometry::new(whole);
                    } else {
                        faces = edited.stencil_faces()?.unwrap_or_default();
                    }
                }
                sync.rebuild(&doc.scene, 1.0)
                    .map_err(|e| Box::<dyn std::error::Error>::from(e.to_string()))
            };
            figures.push(median_update_ms(context, runs, || Ok(()), update)?);
        }
        writeln!(
            out,
            "cage tool {label:<9} on Suzanne refined once (1,968 faces) to the GPU: {:.2} ms \
             refining {} stencil faces and taking {}, {:.2} ms refining all",
            figures[0], faces.0, faces.1, figures[1]
        )?;
    }
    Ok(())
}

/// The cage tool Inset on the 10,000-face torus of [`bench_cage_tools`] (`torus`, one object)
/// in a scene that also holds OpenCASCADE's 806-face STEP plate (tests/reference/occ/step/
/// plate-20.step): the GPU copy brought up to date with every object's patches derived again
/// (a whole rebuild), and with the plate's kept (only the torus changed:
/// [`knotwork::doc::Touched::Object`], what the editor does). Median wall time of the update
/// alone, after the tool's editor step.
fn bench_cage_tool_beside_a_plate(
    context: &GpuContext,
    torus: &Scene,
    runs: usize,
    out: &mut impl Write,
) -> Result<(), Box<dyn std::error::Error>> {
    use knotwork::doc::{Command, Touched};
    use knotwork::kernel::subdiv::cage_edit::Tool;
    use knotwork::scene::operation::Operation;
    let bytes = reference_file("tests/reference/occ/step/plate-20.step")?;
    let model = knotwork::io::step::read::read(&bytes, &mut |_, _| true)?;
    let mut scene = knotwork::io::step::to_scene(&model)?;
    let object = scene.objects.len();
    scene.objects.extend(torus.objects.iter().cloned());
    let command = Command::Apply {
        operation: Operation::new(knotwork::ops::cage::CageEdit {
            object: object.into(),
            tool: Tool::Inset {
                faces: vec![5050, 5051, 5150, 5151],
                thickness: 0.01,
                depth: 0.0,
                individual: false,
            },
        }),
        keep_history: false,
    };
    let mut figures = Vec::new();
    for touched in [Touched::Structure, Touched::Object(object)] {
        let mut sync = SceneSync::with_scene(&context.device, &context.queue, &scene, 1.0)?;
        let edited = || -> Result<Document, Box<dyn std::error::Error>> {
            let mut doc = Document::new(scene.clone());
            doc.execute(&command).map_err(|e| e.to_string())?;
            Ok(doc)
        };
        let update = |doc: Document| {
            sync.apply(&doc.scene, touched, 1.0)
                .map_err(|e| Box::<dyn std::error::Error>::from(e.to_string()))
        };
        figures.push(median_update_ms(context, runs, edited, update)?);
    }
    writeln!(
        out,
        "cage tool Inset beside an 806-face STEP plate ({} objects): GPU copy updated in \
         {:.2} ms with every object derived again, {:.2} ms with the plate's patches kept",
        scene.objects.len(),
        figures[0],
        figures[1]
    )?;
    Ok(())
}
