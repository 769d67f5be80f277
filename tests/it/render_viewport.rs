//! The whole GPU path — compute evaluation, vertex and index buffers, render pipelines — drawn
//! offscreen on a real device and compared with what the f64 reference says should be seen.
//! Failing comparisons write the actual, expected and difference images (see the panic message).

use crate::common;

use glam::{DMat4, DVec3};
use knotwork::gpu::GpuContext;
use knotwork::gpu::records::{CURVATURE_RAMP, RAMP_STOPS};
use knotwork::kernel::bezier::net_line_indices;
use knotwork::kernel::construct;
use knotwork::kernel::{BezierPatchSet, samples};
use knotwork::render::{BACKGROUND, ControlNet, POINT_COLOR};
use knotwork::scene::{ObjectGeometry, SceneObject};
use knotwork::view::{OrbitCamera, Overlays, ShadingMode, ViewSettings};

const WIDTH: u32 = 320;
const HEIGHT: u32 = 240;
const SEGMENTS: u32 = 16;

fn framed_camera(set: &BezierPatchSet) -> OrbitCamera {
    let (lo, hi) = set.bounds().unwrap();
    let mut camera = OrbitCamera::default();
    camera.frame(lo.as_vec3(), hi.as_vec3(), WIDTH as f32 / HEIGHT as f32);
    camera
}

fn render(context: &GpuContext, set: &BezierPatchSet, view: &ViewSettings) -> Vec<u8> {
    let mut teapot = SceneObject::new("patches", ObjectGeometry::new(set.clone()));
    teapot.segments = SEGMENTS;
    let net = ControlNet::new(
        &context.device,
        set.points(),
        &|_| false,
        &net_line_indices(set),
    );
    draw(context, &[teapot], Some(&net), view)
}

/// [`common::draw_offscreen`] at this file's size.
fn draw(
    context: &GpuContext,
    objects: &[SceneObject],
    net: Option<&ControlNet>,
    view: &ViewSettings,
) -> Vec<u8> {
    common::draw_offscreen(context, objects, net, view, (WIDTH, HEIGHT))
}

/// Pixel coordinates (x right, y down) of a world point, or None behind the camera.
fn project(view_proj: &DMat4, p: DVec3) -> Option<(f64, f64)> {
    let clip = *view_proj * p.extend(1.0);
    (clip.w > 0.0).then(|| {
        let (x, y) = (clip.x / clip.w, clip.y / clip.w);
        (
            (x + 1.0) * 0.5 * f64::from(WIDTH),
            (1.0 - y) * 0.5 * f64::from(HEIGHT),
        )
    })
}

fn background_bytes() -> [u8; 3] {
    let [r, g, b, _] = BACKGROUND;
    [r, g, b].map(|c| (c * 255.0).round() as u8)
}

/// Pixels of an RGBA image more than 24 apart from the background in some channel.
fn covered_pixels(image: &[u8], background: [u8; 3]) -> usize {
    image
        .chunks(4)
        .filter(|p| differs_from(p, background, 24))
        .count()
}

fn differs_from(pixel: &[u8], reference: [u8; 3], tolerance: u8) -> bool {
    pixel
        .iter()
        .zip(reference)
        .any(|(&a, b)| a.abs_diff(b) > tolerance)
}

/// The pixels within `r` of (x, y) (a (2r + 1)² square), clipped to the image.
fn neighbourhood(x: i64, y: i64, r: i64) -> impl Iterator<Item = (i64, i64)> {
    (-r..=r)
        .flat_map(move |dy| (-r..=r).map(move |dx| (x + dx, y + dy)))
        .filter(|&(x, y)| (0..i64::from(WIDTH)).contains(&x) && (0..i64::from(HEIGHT)).contains(&y))
}

fn pixel_index(x: i64, y: i64) -> usize {
    (y * i64::from(WIDTH) + x) as usize
}

/// The teapot, framed, rendered with `options`, and what the tests need to check it.
struct TeapotView {
    teapot: BezierPatchSet,
    image: Vec<u8>,
    view_proj: DMat4,
    background: [u8; 3],
}

fn render_teapot(show_surface: bool, show_net: bool, show_points: bool) -> TeapotView {
    let context = common::gpu();
    let teapot = samples::utah_teapot().unwrap();
    let view = ViewSettings {
        camera: framed_camera(&teapot),
        overlays: Overlays {
            surface: show_surface,
            net: show_net,
            points: show_points,
            ..Default::default()
        },
        ..Default::default()
    };
    let image = render(&context, &teapot, &view);
    let view_proj = view
        .camera
        .view_projection(WIDTH as f32 / HEIGHT as f32)
        .as_dmat4();
    TeapotView {
        teapot,
        image,
        view_proj,
        background: background_bytes(),
    }
}

/// Coverage of the f64 reference tessellation, rasterized on the CPU at pixel centres.
fn reference_coverage(set: &BezierPatchSet, view_proj: &DMat4) -> Vec<bool> {
    let mut mask = vec![false; (WIDTH * HEIGHT) as usize];
    let n = SEGMENTS as usize;
    for k in 0..set.patches().len() {
        let grid: Vec<Option<(f64, f64)>> = (0..=n)
            .flat_map(|i| (0..=n).map(move |j| (i, j)))
            .map(|(i, j)| {
                let p = set
                    .evaluate(k, i as f64 / n as f64, j as f64 / n as f64)
                    .unwrap()
                    .point;
                project(view_proj, p)
            })
            .collect();
        let at = |i: usize, j: usize| grid[i * (n + 1) + j];
        for i in 0..n {
            for j in 0..n {
                for tri in [
                    [at(i, j), at(i + 1, j), at(i + 1, j + 1)],
                    [at(i, j), at(i + 1, j + 1), at(i, j + 1)],
                ] {
                    if let [Some(a), Some(b), Some(c)] = tri {
                        fill_triangle(&mut mask, a, b, c);
                    }
                }
            }
        }
    }
    mask
}

fn fill_triangle(mask: &mut [bool], a: (f64, f64), b: (f64, f64), c: (f64, f64)) {
    let edge = |p: (f64, f64), q: (f64, f64), r: (f64, f64)| {
        (q.0 - p.0) * (r.1 - p.1) - (q.1 - p.1) * (r.0 - p.0)
    };
    let area = edge(a, b, c);
    if area.abs() < 1e-12 {
        return;
    }
    let x0 = a.0.min(b.0).min(c.0).floor().max(0.0) as u32;
    let x1 = (a.0.max(b.0).max(c.0).ceil() as u32).min(WIDTH - 1);
    let y0 = a.1.min(b.1).min(c.1).floor().max(0.0) as u32;
    let y1 = (a.1.max(b.1).max(c.1).ceil() as u32).min(HEIGHT - 1);
    for y in y0..=y1 {
        for x in x0..=x1 {
            let p = (f64::from(x) + 0.5, f64::from(y) + 0.5);
            let (w0, w1, w2) = (edge(b, c, p), edge(c, a, p), edge(a, b, p));
            let inside = if area > 0.0 {
                w0 >= 0.0 && w1 >= 0.0 && w2 >= 0.0
            } else {
                w0 <= 0.0 && w1 <= 0.0 && w2 <= 0.0
            };
            if inside {
                mask[(y * WIDTH + x) as usize] = true;
            }
        }
    }
}

fn mask_image(mask: &[bool]) -> Vec<u8> {
    mask.iter()
        .flat_map(|&m| {
            if m {
                [255, 255, 255, 255]
            } else {
                [0, 0, 0, 255]
            }
        })
        .collect()
}

#[test]
fn surface_silhouette_matches_a_cpu_rasterization_of_the_reference() {
    let TeapotView {
        teapot,
        image,
        view_proj,
        background,
    } = render_teapot(true, false, false);
    let actual: Vec<bool> = image
        .chunks_exact(4)
        .map(|p| differs_from(p, background, 6))
        .collect();
    let expected = reference_coverage(&teapot, &view_proj);

    // Anti-aliased edges may go either way; a mismatch anywhere else is an error.
    let on_boundary = |x: i64, y: i64| {
        let value = expected[pixel_index(x, y)];
        neighbourhood(x, y, 1).any(|(nx, ny)| expected[pixel_index(nx, ny)] != value)
    };
    let mut diff = image.clone();
    let mut interior_mismatches = 0;
    for y in 0..i64::from(HEIGHT) {
        for x in 0..i64::from(WIDTH) {
            let i = pixel_index(x, y);
            let mismatch = actual[i] != expected[i] && !on_boundary(x, y);
            interior_mismatches += usize::from(mismatch);
            diff[i * 4..i * 4 + 4].copy_from_slice(&if mismatch {
                [255, 0, 0, 255]
            } else {
                [0, 0, 0, 255]
            });
        }
    }
    let covered = expected.iter().filter(|&&m| m).count();
    let covered_gpu = actual.iter().filter(|&&m| m).count();
    eprintln!(
        "teapot covers {covered} px (reference) / {covered_gpu} px (GPU); {interior_mismatches} interior mismatches"
    );
    // The floor only guards against a trivially empty comparison.
    if interior_mismatches > 0 || covered < 5_000 {
        let paths = [
            "silhouette-actual.png",
            "silhouette-expected.png",
            "silhouette-diff.png",
        ]
        .map(common::artifact_path);
        common::write_png(&paths[0], WIDTH, HEIGHT, &image);
        common::write_png(&paths[1], WIDTH, HEIGHT, &mask_image(&expected));
        common::write_png(&paths[2], WIDTH, HEIGHT, &diff);
        panic!(
            "{interior_mismatches} pixels away from the silhouette disagree ({covered} covered); images: {}",
            paths.map(|p| p.display().to_string()).join(", ")
        );
    }

    // Lit, not flat: the visible surface spans a range of brightness.
    let luminance: Vec<f64> = image
        .chunks_exact(4)
        .zip(&expected)
        .filter(|&(_, &inside)| inside)
        .map(|(p, _)| {
            0.2126 * f64::from(p[0]) + 0.7152 * f64::from(p[1]) + 0.0722 * f64::from(p[2])
        })
        .collect();
    let (min, max) = luminance
        .iter()
        .fold((f64::MAX, f64::MIN), |(lo, hi), &l| (lo.min(l), hi.max(l)));
    assert!(max - min > 80.0, "shading range {min}..{max}");
}

/// sRGB encoding of a linear value (IEC 61966-2-1).
fn srgb_byte(linear: f32) -> u8 {
    let c = linear.clamp(0.0, 1.0);
    let encoded = if c <= 0.0031308 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    };
    (encoded * 255.0).round() as u8
}

#[test]
fn control_points_are_drawn_where_they_project() {
    let TeapotView {
        teapot,
        image,
        view_proj,
        background,
    } = render_teapot(false, false, true);
    let dot = [POINT_COLOR[0], POINT_COLOR[1], POINT_COLOR[2]].map(srgb_byte);
    let (mut visible, mut hit) = (0, 0);
    for p in teapot.points() {
        let Some((x, y)) = project(&view_proj, *p) else {
            continue;
        };
        if !(3.0..f64::from(WIDTH) - 3.0).contains(&x)
            || !(3.0..f64::from(HEIGHT) - 3.0).contains(&y)
        {
            continue;
        }
        visible += 1;
        // Dot colour within the dot's radius around the projection.
        let shows_dot = neighbourhood(x as i64, y as i64, 2).any(|(x, y)| {
            let i = pixel_index(x, y) * 4;
            !differs_from(&image[i..i + 3], dot, 24)
        });
        hit += usize::from(shows_dot);
    }
    eprintln!("{hit} of {visible} control points show a dot at their projection");
    assert!(visible > 250, "{visible}");
    // Where points coincide on screen a later dot's dark rim may hide an earlier one's colour;
    // nearly all must show.
    assert!(hit as f64 >= 0.97 * visible as f64, "{hit} of {visible}");
    // Nothing else is drawn: far from every point the image is background.
    assert!(!differs_from(&image[0..3], background, 0));
}

#[test]
fn control_net_lines_join_neighbouring_points() {
    let TeapotView {
        teapot,
        image,
        view_proj,
        background,
    } = render_teapot(false, true, false);
    let lit = |x: i64, y: i64| {
        neighbourhood(x, y, 1).any(|(x, y)| {
            let i = pixel_index(x, y) * 4;
            differs_from(&image[i..i + 3], background, 20)
        })
    };
    let (mut checked, mut drawn) = (0, 0);
    for patch in teapot.patches() {
        for i in 0..=3 {
            for j in 0..=3 {
                for (ni, nj) in [(i + 1, j), (i, j + 1)] {
                    if ni > 3 || nj > 3 {
                        continue;
                    }
                    let a = teapot.points()[patch.index(i, j) as usize];
                    let b = teapot.points()[patch.index(ni, nj) as usize];
                    if (a - b).length() < 0.05 {
                        continue; // collapsed
                    }
                    let Some((x, y)) = project(&view_proj, 0.5 * (a + b)) else {
                        continue;
                    };
                    if (2.0..f64::from(WIDTH) - 2.0).contains(&x)
                        && (2.0..f64::from(HEIGHT) - 2.0).contains(&y)
                    {
                        checked += 1;
                        drawn += usize::from(lit(x as i64, y as i64));
                    }
                }
            }
        }
    }
    eprintln!("{drawn} of {checked} net edge midpoints are drawn");
    assert!(checked > 300 && drawn == checked, "{drawn} of {checked}");
}

/// Renders the objects of `scene` (each at 16 segments per span), framed, in `shading`.
fn render_shaded(
    context: &GpuContext,
    objects: &[SceneObject],
    shading: ShadingMode,
    range: (f64, f64),
) -> Vec<u8> {
    let objects: Vec<SceneObject> = objects
        .iter()
        .map(|o| SceneObject {
            segments: SEGMENTS,
            ..o.clone()
        })
        .collect();
    let (lo, hi) = objects
        .iter()
        .filter_map(SceneObject::bounds)
        .reduce(|(a, b), (c, d)| (a.min(c), b.max(d)))
        .unwrap();
    let mut camera = OrbitCamera::default();
    camera.frame(lo.as_vec3(), hi.as_vec3(), WIDTH as f32 / HEIGHT as f32);
    let view = ViewSettings {
        camera,
        shading,
        range: Some(range),
        overlays: Overlays {
            net: false,
            points: false,
            ..Default::default()
        },
        ..Default::default()
    };
    draw(context, &objects, None, &view)
}

/// The sRGB bytes of the ramp's colour at `x` in [0, 1], computed here from the ramp's stops
/// (linear interpolation, then the sRGB transfer function).
fn expected_ramp_bytes(x: f32) -> [u8; 3] {
    let f = x * (RAMP_STOPS - 1) as f32;
    let k = (f.floor() as usize).min(RAMP_STOPS - 2);
    let t = f - k as f32;
    let (a, b) = (CURVATURE_RAMP[k], CURVATURE_RAMP[k + 1]);
    [0, 1, 2].map(|c| srgb_byte(a[c] + (b[c] - a[c]) * t))
}

/// Asserts that every covered pixel away from the silhouette has colour `expected` (within 3 per
/// channel); returns how many were checked.
fn assert_flat_colour(name: &str, image: &[u8], background: [u8; 3], expected: [u8; 3]) -> usize {
    let covered: Vec<bool> = image
        .chunks_exact(4)
        .map(|p| differs_from(p, background, 6))
        .collect();
    let mut checked = 0;
    let mut wrong = Vec::new();
    for y in 0..i64::from(HEIGHT) {
        for x in 0..i64::from(WIDTH) {
            let interior = neighbourhood(x, y, 1).all(|(nx, ny)| covered[pixel_index(nx, ny)]);
            if !interior {
                continue;
            }
            let i = pixel_index(x, y) * 4;
            checked += 1;
            if differs_from(&image[i..i + 3], expected, 3) {
                wrong.push((x, y, [image[i], image[i + 1], image[i + 2]]));
            }
        }
    }
    if !wrong.is_empty() {
        let path = common::artifact_path(&format!("actual-{name}"));
        common::write_png(&path, WIDTH, HEIGHT, image);
        panic!(
            "{name}: {} of {checked} pixels are not {expected:?}, e.g. {:?} (image: {})",
            wrong.len(),
            &wrong[..wrong.len().min(5)],
            path.display()
        );
    }
    checked
}

#[test]
fn gaussian_curvature_shading_reads_constant_on_the_sphere_and_zero_on_the_cylinder() {
    let context = common::gpu();
    // The ramp spans K in [-0.5, 0.5]: the sphere's K = 1/r² = 0.25 sits at 3/4 (the yellow
    // stop), the cylinder's K = 0 at 1/2 (the green stop).
    let background = background_bytes();
    let sphere = construct::sphere(DVec3::ZERO, 2.0).unwrap();
    let cylinder =
        construct::cylinder(DVec3::new(0.0, 0.0, -2.0), DVec3::new(0.0, 0.0, 4.0), 1.5).unwrap();
    for (name, surface, x) in [
        ("gaussian-sphere.png", sphere, 0.75),
        ("gaussian-cylinder.png", cylinder, 0.5),
    ] {
        let objects = [SceneObject::new(name, ObjectGeometry::new(surface))];
        let image = render_shaded(&context, &objects, ShadingMode::Gaussian, (-0.5, 0.5));
        let checked = assert_flat_colour(name, &image, background, expected_ramp_bytes(x));
        eprintln!(
            "{name}: {checked} interior pixels all {:?}",
            expected_ramp_bytes(x)
        );
        assert!(checked > 5_000, "{name}: only {checked} pixels covered");
        common::compare_with_reference_png(name, &image, (WIDTH, HEIGHT));
    }
}

/// The frames a software adapter draws in motion (one sample) show the same image as the
/// multisampled ones, up to anti-aliasing along edges: the same pixels covered, and colours
/// apart only on a thin share of the pixels.
#[test]
fn one_sample_frames_match_multisampled_frames_but_for_edge_antialiasing() {
    let context = common::gpu();
    let scene = knotwork::scene::Scene::demo().unwrap();
    let (lo, hi) = scene.bounds().unwrap();
    let mut view = ViewSettings::default();
    view.camera.frame(lo.as_vec3(), hi.as_vec3(), 1.6);
    view.overlays.grid = false;
    let size = (320, 200);
    let four = common::draw_offscreen_with_samples(&context, &scene.objects, None, &view, size, 4);
    let one = common::draw_offscreen_with_samples(&context, &scene.objects, None, &view, size, 1);
    let background = background_bytes();
    let covered = |image: &[u8]| covered_pixels(image, background);
    let (c4, c1) = (covered(&four), covered(&one));
    assert!(c4 > 5_000, "the demo scene covers the view: {c4} px");
    assert!(
        (c4 as f64 - c1 as f64).abs() < 0.03 * c4 as f64,
        "covered pixels: {c4} with 4 samples, {c1} with 1"
    );
    let apart = four
        .chunks(4)
        .zip(one.chunks(4))
        .filter(|(a, b)| a.iter().zip(b.iter()).any(|(x, y)| x.abs_diff(*y) > 24))
        .count();
    let share = apart as f64 / (size.0 * size.1) as f64;
    if share >= 0.04 {
        common::write_png(
            &std::path::PathBuf::from("target/one-sample-actual.png"),
            size.0,
            size.1,
            &one,
        );
    }
    assert!(share < 0.04, "{:.2} % of the pixels differ", share * 100.0);
}

/// The share of `covered` pixels whose colours in `a` and `b` differ by more than `tolerance`
/// in a channel.
fn share_apart(a: &[u8], b: &[u8], tolerance: u8, covered: usize) -> f64 {
    a.chunks(4)
        .zip(b.chunks(4))
        .filter(|(a, b)| {
            a.iter()
                .zip(b.iter())
                .any(|(x, y)| x.abs_diff(*y) > tolerance)
        })
        .count() as f64
        / covered.max(1) as f64
}

/// The view-adaptive tessellation at its default 0.5 px shows what a dense fixed tessellation
/// (64 segments per patch edge) shows: the same pixels covered and colours apart on a thin
/// share of them, with a fraction of the vertices.
#[test]
fn the_adaptive_tessellation_looks_like_a_dense_fixed_one() {
    let context = common::gpu();
    let mut scene = knotwork::scene::Scene::demo().unwrap();
    for object in &mut scene.objects {
        object.segments = 64;
    }
    let (lo, hi) = scene.bounds().unwrap();
    let mut view = ViewSettings::default();
    view.camera.frame(lo.as_vec3(), hi.as_vec3(), 1.6);
    view.overlays.grid = false;
    view.shading = knotwork::view::ShadingMode::Normals;
    let size = (640, 400);
    let fixed = common::draw_offscreen_tessellated(
        &context,
        &scene.objects,
        None,
        &view,
        size,
        4,
        common::Path::Fixed,
    );
    let adaptive = common::draw_offscreen_tessellated(
        &context,
        &scene.objects,
        None,
        &view,
        size,
        4,
        common::Path::Adaptive,
    );
    let background = background_bytes();
    let covered = |image: &[u8]| covered_pixels(image, background);
    let (cf, ca) = (covered(&fixed), covered(&adaptive));
    assert!(cf > 20_000, "the demo scene covers the view: {cf} px");
    let apart_by = |tolerance: u8| share_apart(&fixed, &adaptive, tolerance, cf);
    // Shading may shift slightly (normals interpolated over other triangles); a crack, a hole or
    // a missing patch would put whole pixels far apart.
    let (slight, far) = (apart_by(16), apart_by(64));
    eprintln!(
        "covered {cf} px fixed, {ca} adaptive; covered pixels apart by > 16: {:.2} %, by > 64: \
         {:.2} %",
        slight * 100.0,
        far * 100.0
    );
    let share = far;
    if slight >= 0.06 || far >= 0.01 || (cf as f64 - ca as f64).abs() >= 0.01 * cf as f64 {
        let path = common::artifact_path("adaptive-actual.png");
        common::write_png(&path, size.0, size.1, &adaptive);
        common::write_png(
            &common::artifact_path("adaptive-fixed.png"),
            size.0,
            size.1,
            &fixed,
        );
        eprintln!("wrote {}", path.display());
    }
    assert!(
        (cf as f64 - ca as f64).abs() < 0.01 * cf as f64,
        "covered pixels: {cf} fixed, {ca} adaptive"
    );
    assert!(
        slight < 0.06,
        "{:.2} % of the covered pixels differ",
        slight * 100.0
    );
    assert!(
        share < 0.01,
        "{:.2} % of the covered pixels differ far",
        share * 100.0
    );
}

/// The WebGL2 path (the CPU evaluator and the renderer without storage buffers, here forced on
/// lavapipe) draws the demo scene as the compute path does: the same pixels covered, the lit
/// and normal modes alike but for rounding, the curvature mode close (the vertices' curvature
/// interpolated rather than evaluated per pixel), and a trimmed surface's holes where the
/// per-fragment trim puts them, up to the triangles along the trim edge.
#[test]
fn the_webgl2_path_draws_what_the_compute_path_draws() {
    use knotwork::view::ShadingMode;
    let context = common::gpu();
    let mut scene = knotwork::scene::Scene::demo().unwrap();
    for object in &mut scene.objects {
        object.segments = 24;
    }
    let (lo, hi) = scene.bounds().unwrap();
    let mut view = ViewSettings::default();
    view.camera.frame(lo.as_vec3(), hi.as_vec3(), 1.6);
    view.overlays.grid = false;
    view.range = Some((-2.0, 2.0));
    let size = (640, 400);
    let background = background_bytes();
    // (mode, share of covered pixels allowed apart by more than 16, by more than 64)
    for (mode, slight_limit, far_limit) in [
        (ShadingMode::Plain, 0.02, 0.01),
        (ShadingMode::Normals, 0.02, 0.01),
        (ShadingMode::Mean, 0.08, 0.02),
    ] {
        view.shading = mode;
        let draw = |path| {
            common::draw_offscreen_tessellated(&context, &scene.objects, None, &view, size, 4, path)
        };
        let (compute, cpu) = (draw(common::Path::Fixed), draw(common::Path::Cpu));
        let (cc, cg) = (
            covered_pixels(&compute, background),
            covered_pixels(&cpu, background),
        );
        let (slight, far) = (
            share_apart(&compute, &cpu, 16, cc),
            share_apart(&compute, &cpu, 64, cc),
        );
        eprintln!(
            "{mode:?}: covered {cc} px compute, {cg} CPU; apart by > 16: {:.2} %, by > 64: {:.2} %",
            slight * 100.0,
            far * 100.0
        );
        let covered_alike = (cc as f64 - cg as f64).abs() < 0.01 * cc as f64;
        if !covered_alike || slight >= slight_limit || far >= far_limit {
            for (name, image) in [
                ("webgl2-actual.png", &cpu),
                ("webgl2-compute.png", &compute),
            ] {
                let path = common::artifact_path(name);
                common::write_png(&path, size.0, size.1, image);
                eprintln!("wrote {}", path.display());
            }
        }
        assert!(cc > 20_000, "the demo scene covers the view: {cc} px");
        assert!(covered_alike, "{mode:?}: covered {cc} px compute, {cg} CPU");
        assert!(
            slight < slight_limit,
            "{mode:?}: {:.2} % apart",
            slight * 100.0
        );
        assert!(far < far_limit, "{mode:?}: {:.2} % far apart", far * 100.0);
    }

    // A surface kept inside an ellipse: the CPU path drops the triangles whose centre is trimmed
    // away, the compute path trims per fragment; they differ along the trim edge only.
    let mut object = common::trimmed_ellipse_object("trimmed");
    object.segments = 32;
    let (lo, hi) = object.bounds().unwrap();
    view.camera.frame(lo.as_vec3(), hi.as_vec3(), 1.6);
    view.shading = ShadingMode::Normals;
    let objects = [object];
    let draw =
        |path| common::draw_offscreen_tessellated(&context, &objects, None, &view, size, 4, path);
    let (compute, cpu) = (draw(common::Path::Fixed), draw(common::Path::Cpu));
    let (cc, cg) = (
        covered_pixels(&compute, background),
        covered_pixels(&cpu, background),
    );
    let far = share_apart(&compute, &cpu, 64, cc);
    eprintln!(
        "trimmed: covered {cc} px compute, {cg} CPU; apart by > 64: {:.2} %",
        far * 100.0
    );
    if (cc as f64 - cg as f64).abs() >= 0.03 * cc as f64 || far >= 0.05 {
        for (name, image) in [
            ("webgl2-trim-actual.png", &cpu),
            ("webgl2-trim-compute.png", &compute),
        ] {
            let path = common::artifact_path(name);
            common::write_png(&path, size.0, size.1, image);
            eprintln!("wrote {}", path.display());
        }
    }
    assert!(cc > 2_000, "the trimmed surface is in view: {cc} px");
    assert!(
        (cc as f64 - cg as f64).abs() < 0.03 * cc as f64,
        "trimmed: covered {cc} px compute, {cg} CPU"
    );
    assert!(far < 0.05, "trimmed: {:.2} % far apart", far * 100.0);
}

/// An object's own colour (a STEP file's, say) shades it in the lit modes on both paths, in
/// place of the editor's grey; an object without one keeps the grey.
#[test]
fn an_objects_own_colour_shades_it_on_the_compute_and_webgl2_paths() {
    let context = common::gpu();
    let scene = knotwork::scene::Scene::demo().unwrap();
    let mut sphere = scene.objects[2].clone();
    sphere.segments = 16;
    let mut view = ViewSettings::default();
    let (lo, hi) = sphere.bounds().unwrap();
    view.camera.frame(lo.as_vec3(), hi.as_vec3(), 1.6);
    view.overlays.grid = false;
    let size = (320, 240);
    let background = background_bytes();
    // The share of covered pixels whose red passes green and blue by more than 40.
    let red_share = |image: &[u8]| {
        let covered = covered_pixels(image, background);
        let red = image
            .chunks(4)
            .filter(|p| differs_from(p, background, 8))
            .filter(|p| {
                i32::from(p[0]) > i32::from(p[1]) + 40 && i32::from(p[0]) > i32::from(p[2]) + 40
            })
            .count();
        (red as f64 / covered.max(1) as f64, covered)
    };
    for path in [common::Path::Fixed, common::Path::Cpu] {
        let draw = |object: &knotwork::scene::SceneObject| {
            common::draw_offscreen_tessellated(
                &context,
                std::slice::from_ref(object),
                None,
                &view,
                size,
                4,
                path,
            )
        };
        let grey = draw(&sphere);
        sphere.color = Some([0.9, 0.1, 0.1]);
        let red = draw(&sphere);
        sphere.color = None;
        let (grey_share, grey_covered) = red_share(&grey);
        let (red_share, red_covered) = red_share(&red);
        eprintln!(
            "{path:?}: red on {:.1} % of the coloured sphere, {:.1} % of the grey one",
            red_share * 100.0,
            grey_share * 100.0
        );
        if red_share < 0.9 || grey_share > 0.01 {
            for (name, image) in [("colour-actual.png", &red), ("colour-grey.png", &grey)] {
                let file = common::artifact_path(name);
                common::write_png(&file, size.0, size.1, image);
                eprintln!("wrote {}", file.display());
            }
        }
        assert!(
            grey_covered > 5_000 && grey_covered.abs_diff(red_covered) < grey_covered / 100,
            "{grey_covered} vs {red_covered} px"
        );
        assert!(red_share > 0.9, "{path:?}: {:.1} % red", red_share * 100.0);
        assert!(
            grey_share < 0.01,
            "{path:?}: {:.1} % red",
            grey_share * 100.0
        );
    }
}
