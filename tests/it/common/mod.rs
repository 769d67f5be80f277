//! Helpers shared by the GPU tests.
#![allow(dead_code)]

use std::path::PathBuf;

use glam::DVec3;
use knotwork::gpu::GpuContext;
use knotwork::kernel::{NurbsSurface, PolygonMesh};

/// The headless GPU the tests run on (lavapipe here). Fails — never skips — without one.
pub fn gpu() -> GpuContext {
    match GpuContext::headless_blocking() {
        Ok(context) => {
            eprintln!("GPU adapter: {}", context.describe());
            context
        }
        Err(e) => panic!("GPU tests need an adapter and found none: {e}"),
    }
}

/// Where failing image tests write their actual, expected and difference images.
pub fn artifact_path(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("image-tests");
    std::fs::create_dir_all(&dir).expect("artifact directory");
    dir.join(name)
}

/// The directory `name` for test files, made where missing, under this run's scratch folder in
/// the target directory (`CARGO_TARGET_TMPDIR/scratch-<process id>`), never in the system's
/// temporary folder: empty when a run first asks for it, shared by the calls that give the same
/// name. The first call of a run removes the scratch folders of earlier runs that have ended
/// (where `/proc` says which processes live), so a run leaves at most its own files behind,
/// and a failing test's files stay there to be looked at until the next run.
pub fn scratch_dir(name: &str) -> PathBuf {
    static ROOT: std::sync::OnceLock<PathBuf> = std::sync::OnceLock::new();
    let root = ROOT.get_or_init(|| {
        let parent = PathBuf::from(env!("CARGO_TARGET_TMPDIR"));
        let own = format!("scratch-{}", std::process::id());
        if std::path::Path::new("/proc/self").exists()
            && let Ok(entries) = std::fs::read_dir(&parent)
        {
            for entry in entries.flatten() {
                let name = entry.file_name().to_string_lossy().into_owned();
                let ended = name.strip_prefix("scratch-").is_some_and(|pid| {
                    name != own && !std::path::Path::new("/proc").join(pid).exists()
                });
                if ended {
                    let _ = std::fs::remove_dir_all(entry.path());
                }
            }
        }
        parent.join(own)
    });
    let dir = root.join(name);
    std::fs::create_dir_all(&dir).expect("a scratch directory");
    dir
}

/// Writes tightly packed RGBA8 pixels as a PNG.
pub fn write_png(path: &PathBuf, width: u32, height: u32, rgba: &[u8]) {
    let file = std::fs::File::create(path).expect("create png");
    let mut encoder = png::Encoder::new(std::io::BufWriter::new(file), width, height);
    encoder.set_color(png::ColorType::Rgba);
    encoder.set_depth(png::BitDepth::Eight);
    let mut writer = encoder.write_header().expect("png header");
    writer.write_image_data(rgba).expect("png data");
}

/// Uploads decompositions to a bare [`knotwork::gpu::PatchGeometry`] at the given segments per
/// span, below the sync layer (the evaluator's own refusals are tested with it).
pub fn upload(
    context: &GpuContext,
    evaluator: &knotwork::gpu::PatchEvaluator,
    objects: &[(&knotwork::scene::Decomposition, u32)],
) -> Result<knotwork::gpu::PatchGeometry, knotwork::gpu::GpuError> {
    let inputs: Vec<knotwork::gpu::ObjectPatches<'_>> = objects
        .iter()
        .map(|(d, segments)| knotwork::gpu::ObjectPatches {
            stencils: None,
            cage_points: 0,
            trims: d.trims.as_ref(),
            displacement: None,
            lattice: None,
            set: &d.set,
            domains: &d.domains,
            segments: *segments,
        })
        .collect();
    knotwork::gpu::PatchGeometry::new(&context.device, evaluator, &inputs)
}

/// A deterministic generator (SplitMix64) so one u64 from proptest describes a whole surface.
pub struct Rng(pub u64);

impl Rng {
    pub fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    pub fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }
    pub fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
}

/// A clamped knot vector of degree p on a random domain with 0–3 distinct interior knots of
/// random multiplicity 1..=p. Returns (knots, control point count).
pub fn random_knots(rng: &mut Rng, p: usize) -> (Vec<f64>, usize) {
    let a = rng.range(-2.0, 1.0);
    let b = a + rng.range(0.5, 3.0);
    let mut interior: Vec<f64> = (0..rng.below(4)).map(|_| rng.range(0.05, 0.95)).collect();
    interior.sort_by(f64::total_cmp);
    interior.dedup_by(|x, y| (*x - *y).abs() < 0.05);
    let mut knots = vec![a; p + 1];
    for t in interior {
        let m = 1 + rng.below(p);
        knots.extend(std::iter::repeat_n(a + (b - a) * t, m));
    }
    knots.extend(std::iter::repeat_n(b, p + 1));
    let count = knots.len() - p - 1;
    (knots, count)
}

/// A random rational NURBS surface of degree (p, q): clamped non-uniform knots with repeated
/// interior knots ([`random_knots`]), points in [-1, 1]³, weights 0.2–5.
pub fn random_surface(p: usize, q: usize, seed: u64) -> NurbsSurface {
    let mut rng = Rng(seed);
    let (ku, cu) = random_knots(&mut rng, p);
    let (kv, cv) = random_knots(&mut rng, q);
    let points = (0..cu * cv)
        .map(|_| {
            DVec3::new(
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
            )
        })
        .collect();
    let weights = (0..cu * cv).map(|_| rng.range(0.2, 5.0)).collect();
    NurbsSurface::new([p, q], [ku, kv], [cu, cv], points, Some(weights)).unwrap()
}

/// A rational (2, 3) surface (`random_surface(2, 3, 77)`) kept inside an ellipse about its
/// domain's centre: patches outside it are culled, the ones it crosses are trimmed.
pub fn trimmed_ellipse_object(name: &str) -> knotwork::scene::SceneObject {
    let base = random_surface(2, 3, 77);
    let [(u0, u1), (v0, v1)] = base.domain();
    let ellipse = knotwork::kernel::trim::shapes::ellipse(
        glam::DVec2::new(0.5 * (u0 + u1), 0.5 * (v0 + v1)),
        glam::DVec2::new(0.3 * (u1 - u0), 0.35 * (v1 - v0)),
    )
    .unwrap();
    let trimmed = knotwork::kernel::TrimmedSurface::new(base, vec![ellipse]).unwrap();
    knotwork::scene::SceneObject::new(name, knotwork::scene::ObjectGeometry::from_trimmed(trimmed))
}

/// Evaluates `objects` through the editor's sync layer and renders them (and `net`) offscreen at
/// `width` × `height` with `view`; returns the RGBA pixels.
pub fn draw_offscreen(
    context: &GpuContext,
    objects: &[knotwork::scene::SceneObject],
    net: Option<&knotwork::render::ControlNet>,
    view: &knotwork::view::ViewSettings,
    (width, height): (u32, u32),
) -> Vec<u8> {
    draw_offscreen_with_samples(context, objects, net, view, (width, height), 4)
}

/// [`draw_offscreen`] into a target of `samples` per pixel (1 or 4).
pub fn draw_offscreen_with_samples(
    context: &GpuContext,
    objects: &[knotwork::scene::SceneObject],
    net: Option<&knotwork::render::ControlNet>,
    view: &knotwork::view::ViewSettings,
    size: (u32, u32),
    samples: u32,
) -> Vec<u8> {
    draw_offscreen_tessellated(context, objects, net, view, size, samples, Path::Fixed)
}

/// How [`draw_offscreen_tessellated`] evaluates and draws.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Path {
    /// Compute shaders, each object's fixed segments.
    Fixed,
    /// Compute shaders, tessellated for the view at the view's tolerance.
    Adaptive,
    /// The WebGL2 path: the CPU evaluator and the renderer that shades from the vertices alone.
    Cpu,
}

/// [`draw_offscreen_with_samples`] through `path`.
pub fn draw_offscreen_tessellated(
    context: &GpuContext,
    objects: &[knotwork::scene::SceneObject],
    net: Option<&knotwork::render::ControlNet>,
    view: &knotwork::view::ViewSettings,
    (width, height): (u32, u32),
    samples: u32,
    path: Path,
) -> Vec<u8> {
    use knotwork::gpu::SceneSync;
    use knotwork::render::{ViewTarget, ViewportRenderer, scene_uniform};
    let scene = knotwork::scene::Scene {
        objects: objects.to_vec(),
        unit: None,
    };
    let (mut sync, mut renderer) = if path == Path::Cpu {
        let mut sync = SceneSync::on_cpu(&context.device, &context.queue);
        sync.rebuild(&scene, 1.0).unwrap();
        (sync, ViewportRenderer::for_vertices_only(&context.device))
    } else {
        let sync = SceneSync::with_scene(&context.device, &context.queue, &scene, 1.0).unwrap();
        (sync, ViewportRenderer::new(&context.device))
    };
    let target = ViewTarget::with_samples(&context.device, width, height, samples);
    assert_eq!(target.samples(), samples);
    let colors: Vec<Option<[f32; 3]>> = objects.iter().map(|o| o.color).collect();
    renderer.set_object_colors(&context.device, &context.queue, &colors);
    if path == Path::Adaptive {
        sync.set_adaptive(&scene, true, 1.0).unwrap();
        sync.set_view(knotwork::render::adaptive_target(
            &view.camera,
            (width, height),
            f64::from(view.tolerance_px),
        ));
    }
    let range = view.range.unwrap_or((-1.0, 1.0));
    let uniform = scene_uniform(view, &target, 4.0, range, None);
    let mut encoder = context.device.create_command_encoder(&Default::default());
    sync.encode(&mut encoder, None);
    renderer.set_scene(&context.queue, &uniform);
    renderer.render(
        &mut encoder,
        &target,
        sync.surface_buffers().unwrap(),
        net,
        view.overlays,
        None,
    );
    context.queue.submit([encoder.finish()]);
    let pixels = target.read_rgba(&context.device, &context.queue).unwrap();
    assert_eq!(pixels.len(), (width * height * 4) as usize);
    pixels
}

/// Compares `image` with the PNG reference `tests/reference/NAME`, allowing a channel difference
/// of 8 on up to 0.5 % of the pixels (anti-aliasing differs between drivers). Writes the actual
/// and difference images on failure. `KNOTWORK_BLESS=1` rewrites the reference instead.
pub fn compare_with_reference_png(name: &str, image: &[u8], (width, height): (u32, u32)) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/reference")
        .join(name);
    if std::env::var("KNOTWORK_BLESS").is_ok_and(|v| v == "1") {
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        write_png(&path.to_path_buf(), width, height, image);
        return;
    }
    let file = std::fs::File::open(&path).unwrap_or_else(|e| {
        panic!(
            "{}: {e} (KNOTWORK_BLESS=1 cargo test writes it)",
            path.display()
        )
    });
    let mut decoder = png::Decoder::new(std::io::BufReader::new(file));
    decoder.set_transformations(png::Transformations::EXPAND);
    let mut reader = decoder.read_info().unwrap();
    let mut expected = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut expected).unwrap();
    assert_eq!((info.width, info.height), (width, height), "{name}: size");
    let mut diff = vec![0u8; image.len()];
    let mut differing = 0;
    for (i, (a, e)) in image
        .chunks_exact(4)
        .zip(expected.chunks_exact(4))
        .enumerate()
    {
        let d = a
            .iter()
            .zip(e)
            .take(3)
            .map(|(x, y)| x.abs_diff(*y))
            .max()
            .unwrap_or(0);
        if d > 8 {
            differing += 1;
        }
        diff[i * 4..i * 4 + 4].copy_from_slice(&[d.saturating_mul(8), 0, 0, 255]);
    }
    let allowed = (width * height) as usize / 200;
    if differing > allowed {
        let actual_path = artifact_path(&format!("actual-{name}"));
        let diff_path = artifact_path(&format!("diff-{name}"));
        write_png(&actual_path, width, height, image);
        write_png(&diff_path, width, height, &diff);
        panic!(
            "{name}: {differing} pixels differ from the reference (allowed {allowed}); actual {}, difference {}",
            actual_path.display(),
            diff_path.display()
        );
    }
}

/// A smooth, non-polynomial height over a grid.
pub fn height(i: usize, j: usize) -> f64 {
    0.3 * (i as f64).sin() * (1.3 * j as f64).cos() + 0.1 * (i * j) as f64 / 7.0
}

/// An m × m grid of points (i, j, height), quads counter-clockwise seen from +z.
pub fn grid_mesh(m: usize) -> PolygonMesh {
    let points = (0..m * m)
        .map(|k| {
            let (i, j) = (k / m, k % m);
            DVec3::new(i as f64, j as f64, height(i, j))
        })
        .collect();
    let id = |i: usize, j: usize| (i * m + j) as u32;
    let mut faces = Vec::new();
    for i in 0..m - 1 {
        for j in 0..m - 1 {
            faces.push(vec![id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    PolygonMesh::new(points, &faces).unwrap()
}

/// A planar regular triangle lattice (every interior vertex of valence 6), heights from `f`.
pub fn triangle_lattice(m: usize, f: impl Fn(f64, f64) -> f64) -> PolygonMesh {
    let points = (0..m * m)
        .map(|k| {
            let (i, j) = (k / m, k % m);
            let (x, y) = (i as f64 + 0.5 * j as f64, j as f64 * 0.75f64.sqrt());
            DVec3::new(x, y, f(x, y))
        })
        .collect();
    let id = |i: usize, j: usize| (i * m + j) as u32;
    let mut faces = Vec::new();
    for i in 0..m - 1 {
        for j in 0..m - 1 {
            faces.push(vec![id(i, j), id(i + 1, j), id(i, j + 1)]);
            faces.push(vec![id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    PolygonMesh::new(points, &faces).unwrap()
}

/// A 4 × 4 grid of points with one raised, faced by quads, two triangles and a hexagon: an
/// open cage with n-gons and boundaries.
pub fn open_mixed_grid() -> PolygonMesh {
    let mut points = grid_mesh(4).points().to_vec();
    points[5].z += 0.4;
    let id = |i: u32, j: u32| i * 4 + j;
    let faces = vec![
        vec![id(0, 0), id(1, 0), id(1, 1), id(0, 1)],
        vec![id(1, 0), id(2, 0), id(2, 1)],
        vec![id(1, 0), id(2, 1), id(1, 1)],
        vec![id(2, 0), id(3, 0), id(3, 1), id(2, 1)],
        vec![id(0, 1), id(1, 1), id(1, 2), id(0, 2)],
        vec![id(1, 1), id(2, 1), id(2, 2), id(1, 2)],
        vec![id(2, 1), id(3, 1), id(3, 2), id(2, 2)],
        vec![id(0, 2), id(1, 2), id(2, 2), id(2, 3), id(1, 3), id(0, 3)],
        vec![id(2, 2), id(3, 2), id(3, 3), id(2, 3)],
    ];
    PolygonMesh::new(points, &faces).unwrap()
}

/// Runs `knotwork subdivide INPUT ARGS…` (the real binary) and returns what it did.
pub fn run_subdivide(input: &std::path::Path, args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_knotwork"))
        .arg("subdivide")
        .arg(input)
        .args(args)
        .output()
        .expect("the knotwork binary runs")
}

/// The vertices of `scene` as the compute shaders (or, with `cpu`, the WebGL2 path's CPU
/// evaluator) write them, with the sync layer that wrote them.
pub fn evaluate_scene(
    scene: &knotwork::scene::Scene,
    cpu: bool,
) -> (knotwork::gpu::SceneSync, Vec<knotwork::gpu::SurfaceVertex>) {
    let context = gpu();
    let mut sync = if cpu {
        knotwork::gpu::SceneSync::on_cpu(&context.device, &context.queue)
    } else {
        knotwork::gpu::SceneSync::new(&context.device, &context.queue)
    };
    sync.rebuild(scene, 1.0).unwrap();
    sync.evaluate_blocking().unwrap();
    let v = sync.read_vertices().unwrap();
    (sync, v)
}

/// Runs the Khronos glTF-Validator on `files`; panics on any error or warning, or if the
/// validator cannot run.
pub fn validate_gltf(files: &[PathBuf]) {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let script = root.join("web/validate-gltf.mjs");
    assert!(
        root.join("web/node_modules/gltf-validator").is_dir(),
        "the glTF validator is missing: run `npm ci` in web/ (tests/run.sh does)"
    );
    let output = std::process::Command::new("node")
        .arg(&script)
        .args(files)
        .output()
        .unwrap_or_else(|e| panic!("the glTF validator needs Node.js: {e}"));
    let stdout = String::from_utf8_lossy(&output.stdout);
    eprintln!("{stdout}{}", String::from_utf8_lossy(&output.stderr));
    let reports: Vec<serde_json::Value> = stdout
        .lines()
        .map(|l| serde_json::from_str(l).expect("validator output"))
        .collect();
    assert_eq!(reports.len(), files.len(), "one report per file");
    for report in &reports {
        assert_eq!(report["errors"], 0, "{report}");
        assert_eq!(report["warnings"], 0, "{report}");
    }
    assert!(
        output.status.success(),
        "validator exit status {}",
        output.status
    );
}

/// Runs the `knotwork` binary with `args`; the test fails with its standard error when it
/// exits with an error.
pub fn knotwork_ok<S: AsRef<std::ffi::OsStr>>(args: &[S]) -> std::process::Output {
    let output = std::process::Command::new(env!("CARGO_BIN_EXE_knotwork"))
        .args(args)
        .output()
        .expect("the knotwork binary runs");
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    output
}

/// Runs the `knotwork` binary with `args` ([`knotwork_ok`]) and reads its standard output as
/// JSON.
pub fn knotwork_json<S: AsRef<std::ffi::OsStr>>(args: &[S]) -> serde_json::Value {
    serde_json::from_slice(&knotwork_ok(args).stdout).expect("JSON on standard output")
}

/// The box [0, 2] × [0, 1] × [0, 1.5] as six planes facing either way (so that only the shared
/// edges say how to orient them), moved by `motion` and joined: volume 3 and area 13 before
/// the motion's scale.
pub fn box_of_planes(motion: &glam::DAffine3) -> knotwork::scene::polysurface::Polysurface {
    use knotwork::kernel::trim::TrimmedSurface;
    let plane = |o: DVec3, u: DVec3, v: DVec3| {
        let s = knotwork::kernel::construct::plane(o, u, v)
            .and_then(|s| s.transformed(motion))
            .expect("a plane");
        TrimmedSurface::untrimmed(s)
    };
    let (x, y, z) = (DVec3::X * 2.0, DVec3::Y, DVec3::Z * 1.5);
    let faces = vec![
        plane(DVec3::ZERO, y, x),
        plane(z, y, x),
        plane(DVec3::ZERO, x, z),
        plane(y, x, z),
        plane(DVec3::ZERO, z, y),
        plane(x, y, z),
    ];
    knotwork::scene::polysurface::Polysurface::new(faces, 1e-9).expect("six faces")
}

/// A thread pool of `threads` threads, to run the kernel's parallel builders in (and compare
/// what pools of different sizes build).
pub fn thread_pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
}

/// A random rotation (a uniformly drawn unit quaternion), scale 0.1–10 and translation
/// ±100 per axis.
pub fn random_motion(rng: &mut Rng) -> glam::DAffine3 {
    let q = loop {
        let q = glam::DQuat::from_xyzw(
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
        );
        let n = q.length();
        if n > 0.1 && n <= 1.0 {
            break q / n;
        }
    };
    let scale = 10f64.powf(rng.range(-1.0, 1.0));
    let offset = glam::DVec3::new(
        rng.range(-100.0, 100.0),
        rng.range(-100.0, 100.0),
        rng.range(-100.0, 100.0),
    );
    glam::DAffine3::from_scale_rotation_translation(glam::DVec3::splat(scale), q, offset)
}
