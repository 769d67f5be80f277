//! The per-pixel analysis modes (zebra, isophotes, draft angle, reflection) drawn on a real
//! device and checked against independent references: a sphere ray-cast here in f64, whose
//! exact normal gives the stripe, line and zone every pixel must show; and the same free-form
//! surface tessellated coarsely and finely, which must give the same zebra image, as only a
//! per-pixel evaluation of the surface can. Failures write the actual, expected and difference
//! images.

use crate::common;

use glam::{DMat4, DVec3, DVec4};
use knotwork::kernel::{NurbsSurface, construct};
use knotwork::render::{BACKGROUND, DRAFT_COLORS};
use knotwork::scene::{ObjectGeometry, SceneObject};
use knotwork::view::{
    AnalysisSettings, OrbitCamera, Overlays, ShadingMode, StripeFrame, ViewSettings, ZebraSource,
};

const WIDTH: u32 = 320;
const HEIGHT: u32 = 240;
const RADIUS: f64 = 2.0;

fn view_of(camera: OrbitCamera, shading: ShadingMode, analysis: AnalysisSettings) -> ViewSettings {
    ViewSettings {
        camera,
        shading,
        analysis,
        overlays: Overlays {
            net: false,
            points: false,
            ..Default::default()
        },
        ..Default::default()
    }
}

fn sphere_camera() -> OrbitCamera {
    let mut camera = OrbitCamera {
        yaw: -0.7,
        pitch: 0.35,
        ..Default::default()
    };
    let r = RADIUS as f32;
    camera.frame(
        glam::Vec3::splat(-r),
        glam::Vec3::splat(r),
        WIDTH as f32 / HEIGHT as f32,
    );
    camera
}

fn sphere() -> (SceneObject, f64) {
    let surface = construct::sphere(DVec3::ZERO, RADIUS).unwrap();
    // The kernel's orientation: +1 where its normals point outward.
    let [(u0, u1), (v0, v1)] = surface.domain();
    let (u, v) = (0.37 * (u0 + u1), 0.41 * (v0 + v1));
    let p = surface.point_at(u, v).unwrap();
    let orientation = surface.normal(u, v).unwrap().dot(p).signum();
    let mut object = SceneObject::new("sphere", ObjectGeometry::new(surface));
    // Fine enough that the drawn sphere lies within a tenth of a pixel of the ray-cast one (the
    // tessellation decides where a pixel lands on the surface; the analysis at that point is the
    // per-pixel evaluation's own, which the coarse-versus-fine test checks).
    object.segments = 32;
    (object, orientation)
}

/// What the f64 ray cast of the sphere gives at one pixel centre.
#[derive(Clone, Copy)]
struct Hit {
    /// The outward unit normal.
    normal: DVec3,
    /// Toward the eye.
    view: DVec3,
}

/// Casts the ray through every pixel centre against the sphere (in f64).
fn ray_cast(camera: &OrbitCamera) -> Vec<Option<Hit>> {
    let inverse: DMat4 = camera
        .view_projection(WIDTH as f32 / HEIGHT as f32)
        .as_dmat4()
        .inverse();
    let unproject = |x: f64, y: f64, z: f64| {
        let h: DVec4 = inverse * DVec4::new(x, y, z, 1.0);
        h.truncate() / h.w
    };
    let mut hits = Vec::with_capacity((WIDTH * HEIGHT) as usize);
    for py in 0..HEIGHT {
        for px in 0..WIDTH {
            let x = (f64::from(px) + 0.5) / f64::from(WIDTH) * 2.0 - 1.0;
            let y = 1.0 - (f64::from(py) + 0.5) / f64::from(HEIGHT) * 2.0;
            let origin = unproject(x, y, 0.0);
            let dir = (unproject(x, y, 1.0) - origin).normalize();
            // |o + t d|² = r²
            let b = origin.dot(dir);
            let c = origin.length_squared() - RADIUS * RADIUS;
            let disc = b * b - c;
            hits.push((disc > 0.0).then(|| {
                let t = -b - disc.sqrt();
                let p = origin + t * dir;
                Hit {
                    normal: p / RADIUS,
                    view: -dir,
                }
            }));
        }
    }
    hits
}

/// How one mode should look at a pixel: a class, and how far (in the class's coordinate) the
/// pixel is from a class boundary; pixels closer than two pixels' worth are not checked.
trait Reference {
    /// The coordinate whose level sets separate the classes at this hit.
    fn coordinate(&self, hit: &Hit) -> f64;
    /// The class the coordinate gives and its distance to the nearest class boundary.
    fn class(&self, coordinate: f64) -> (u8, f64);
    /// The class a rendered pixel shows (None: neither, a failure).
    fn seen(&self, rgb: [u8; 3]) -> Option<u8>;
}

/// Checks every ray-cast pixel away from the silhouette and from class boundaries; returns the
/// number checked.
fn check_against_ray_cast(
    name: &str,
    image: &[u8],
    hits: &[Option<Hit>],
    mode: &dyn Reference,
) -> usize {
    let at = |x: i64, y: i64| -> Option<f64> {
        if !(0..i64::from(WIDTH)).contains(&x) || !(0..i64::from(HEIGHT)).contains(&y) {
            return None;
        }
        hits[(y * i64::from(WIDTH) + x) as usize].map(|h| mode.coordinate(&h))
    };
    let mut expected = vec![0u8; image.len()];
    let mut diff = vec![0u8; image.len()];
    let (mut checked, mut wrong) = (0, 0);
    for y in 0..i64::from(HEIGHT) {
        for x in 0..i64::from(WIDTH) {
            let i = (y * i64::from(WIDTH) + x) as usize;
            let Some(c) = at(x, y) else { continue };
            // The coordinate's change per pixel, from the neighbours (all must be on the sphere).
            let neighbours: Option<Vec<f64>> = [
                (1, 0),
                (-1, 0),
                (0, 1),
                (0, -1),
                (2, 0),
                (0, 2),
                (-2, 0),
                (0, -2),
            ]
            .iter()
            .map(|(dx, dy)| at(x + dx, y + dy))
            .collect();
            let Some(neighbours) = neighbours else {
                continue;
            };
            let step = neighbours[..4]
                .iter()
                .map(|n| (n - c).abs())
                .fold(0.0, f64::max);
            let (class, distance) = mode.class(c);
            expected[i * 4..i * 4 + 4].copy_from_slice(&[class * 80, class * 80, class * 80, 255]);
            if distance < 2.0 * step + 1e-9 {
                continue;
            }
            checked += 1;
            let rgb = [image[i * 4], image[i * 4 + 1], image[i * 4 + 2]];
            if mode.seen(rgb) != Some(class) {
                wrong += 1;
                diff[i * 4..i * 4 + 4].copy_from_slice(&[255, 0, 0, 255]);
            }
        }
    }
    eprintln!("{name}: {wrong} of {checked} pixels differ from the ray cast");
    if checked < 1500 || wrong > checked / 1000 {
        for (what, pixels) in [
            ("actual", image),
            ("expected", &expected[..]),
            ("diff", &diff[..]),
        ] {
            let path = common::artifact_path(&format!("{what}-{name}.png"));
            common::write_png(&path, WIDTH, HEIGHT, pixels);
            eprintln!("{what}: {}", path.display());
        }
        panic!("{name}: {wrong} of {checked} checked pixels differ from the f64 ray cast");
    }
    checked
}

fn grey(rgb: [u8; 3]) -> f64 {
    rgb.iter().map(|&c| f64::from(c)).sum::<f64>() / 3.0
}

/// Zebra: white where the stripe coordinate's fraction lies within a quarter of a half.
struct Zebra {
    settings: AnalysisSettings,
    frame: (DVec3, DVec3, DVec3),
}

impl Zebra {
    fn new(settings: AnalysisSettings, camera: &OrbitCamera) -> Self {
        let frame = match settings.zebra_frame {
            StripeFrame::View => {
                let (r, u, b) = camera.axes();
                (r.as_dvec3(), u.as_dvec3(), b.as_dvec3())
            }
            StripeFrame::World => (DVec3::X, DVec3::Z, -DVec3::Y),
        };
        Self { settings, frame }
    }
}

impl Reference for Zebra {
    fn coordinate(&self, hit: &Hit) -> f64 {
        // The surface facing the viewer is the outward side.
        let n = hit.normal;
        let d = match self.settings.zebra_source {
            ZebraSource::Normal => n,
            // The view ray reflected: -v + 2 (v.n) n.
            ZebraSource::Reflection => -hit.view + 2.0 * hit.view.dot(n) * n,
        };
        let (e1, e2, e3) = self.frame;
        let angle = self.settings.zebra_angle.to_radians();
        let b = -angle.sin() * e1 + angle.cos() * e2;
        let phi = d.dot(b).atan2(d.dot(e3));
        phi * f64::from(self.settings.zebra_pairs) / std::f64::consts::PI
    }

    fn class(&self, x: f64) -> (u8, f64) {
        let f = (x.rem_euclid(1.0) - 0.5).abs();
        (u8::from(f < 0.25), (f - 0.25).abs())
    }

    fn seen(&self, rgb: [u8; 3]) -> Option<u8> {
        match grey(rgb) {
            g if g > 140.0 => Some(1),
            g if g < 90.0 => Some(0),
            _ => None,
        }
    }
}

/// Isophotes: a dark line where the angle between the normal and the light is a multiple of the
/// spacing, colour elsewhere. This checks the bands (class 0): no pixel two pixels or more away
/// from a line may be dark; the lines' centres are checked separately.
struct Isophotes {
    settings: AnalysisSettings,
    orientation: f64,
}

impl Reference for Isophotes {
    fn coordinate(&self, hit: &Hit) -> f64 {
        let light = AnalysisSettings::unit(self.settings.isophote_direction);
        let cosine = (self.orientation * hit.normal).dot(light).clamp(-1.0, 1.0);
        cosine.acos().to_degrees() / self.settings.isophote_spacing
    }

    fn class(&self, x: f64) -> (u8, f64) {
        (0, 0.5 - (x.rem_euclid(1.0) - 0.5).abs())
    }

    fn seen(&self, rgb: [u8; 3]) -> Option<u8> {
        Some(u8::from(rgb.iter().all(|&c| c < 30)))
    }
}

/// Draft angle: green at or above the threshold, yellow between 0 and it, red below 0.
struct Draft {
    settings: AnalysisSettings,
    orientation: f64,
}

impl Reference for Draft {
    fn coordinate(&self, hit: &Hit) -> f64 {
        let pull = AnalysisSettings::unit(self.settings.pull_direction);
        (self.orientation * hit.normal)
            .dot(pull)
            .clamp(-1.0, 1.0)
            .asin()
            .to_degrees()
    }

    fn class(&self, angle: f64) -> (u8, f64) {
        let threshold = self.settings.draft_threshold;
        let class = if angle >= threshold {
            0
        } else if angle >= 0.0 {
            1
        } else {
            2
        };
        (class, angle.abs().min((angle - threshold).abs()))
    }

    fn seen(&self, rgb: [u8; 3]) -> Option<u8> {
        // The hue of each zone's colour (lighting scales all channels alike).
        let [r, g, b] = rgb.map(f64::from);
        let hue = |c: [f32; 3]| {
            let [cr, cg, cb] = c.map(f64::from);
            let s = cr + cg + cb;
            [cr / s, cg / s, cb / s]
        };
        let s = r + g + b;
        if s < 30.0 {
            return None;
        }
        let seen = [r / s, g / s, b / s];
        // sRGB encoding bends the ratios; nearest of the three hues.
        let distance = |h: [f64; 3]| (0..3).map(|k| (h[k] - seen[k]).powi(2)).sum::<f64>();
        let encoded = |c: [f32; 3]| c.map(|x| x.powf(1.0 / 2.2));
        (0..3u8).min_by(|&a, &b| {
            distance(hue(encoded(DRAFT_COLORS[a as usize])))
                .total_cmp(&distance(hue(encoded(DRAFT_COLORS[b as usize]))))
        })
    }
}

fn render(objects: &[SceneObject], view: &ViewSettings) -> Vec<u8> {
    common::draw_offscreen(&common::gpu(), objects, None, view, (WIDTH, HEIGHT))
}

#[test]
fn zebra_stripes_on_a_sphere_match_the_f64_ray_cast() {
    let (object, _) = sphere();
    let camera = sphere_camera();
    let hits = ray_cast(&camera);
    for (name, settings) in [
        ("zebra-view-reflection", AnalysisSettings::default()),
        (
            "zebra-world-normal",
            AnalysisSettings {
                zebra_pairs: 6,
                zebra_angle: 60.0,
                zebra_frame: StripeFrame::World,
                zebra_source: ZebraSource::Normal,
                ..Default::default()
            },
        ),
        (
            "zebra-view-vertical",
            AnalysisSettings {
                zebra_pairs: 5,
                zebra_angle: 90.0,
                ..Default::default()
            },
        ),
    ] {
        let image = render(
            std::slice::from_ref(&object),
            &view_of(camera, ShadingMode::Zebra, settings),
        );
        check_against_ray_cast(name, &image, &hits, &Zebra::new(settings, &camera));
    }
}

#[test]
fn isophote_lines_and_draft_zones_on_a_sphere_match_the_f64_ray_cast() {
    let (object, orientation) = sphere();
    let camera = sphere_camera();
    let hits = ray_cast(&camera);
    let settings = AnalysisSettings {
        isophote_spacing: 15.0,
        isophote_direction: [0.3, -0.2, 1.0],
        ..Default::default()
    };
    let image = render(
        std::slice::from_ref(&object),
        &view_of(camera, ShadingMode::Isophotes, settings),
    );
    // Bands must be free of lines; the lines themselves are checked below on their centres.
    let isophotes = Isophotes {
        settings,
        orientation,
    };
    check_against_ray_cast("isophotes", &image, &hits, &isophotes);
    // Every pixel within a tenth of a pixel of a line's centre is dark.
    let (mut on_line, mut dark) = (0, 0);
    for (i, hit) in hits.iter().enumerate() {
        let Some(hit) = hit else { continue };
        let x = isophotes.coordinate(hit);
        let right = hits.get(i + 1).copied().flatten();
        let Some(right) = right else { continue };
        let step = (isophotes.coordinate(&right) - x).abs();
        let to_line = 0.5 - (x.rem_euclid(1.0) - 0.5).abs();
        if step > 0.0 && step < 0.1 && to_line < 0.1 * step {
            on_line += 1;
            dark += usize::from(image[i * 4..i * 4 + 3].iter().all(|&c| c < 60));
        }
    }
    eprintln!("{dark} of {on_line} line-centre pixels are dark");
    assert!(
        on_line > 20 && dark * 10 >= on_line * 9,
        "{dark} of {on_line}"
    );

    for (name, pull, threshold) in [
        ("draft-z", [0.0, 0.0, 1.0], 10.0),
        ("draft-tilted", [1.0, 0.5, 1.0], 25.0),
    ] {
        let settings = AnalysisSettings {
            pull_direction: pull,
            draft_threshold: threshold,
            ..Default::default()
        };
        let image = render(
            std::slice::from_ref(&object),
            &view_of(camera, ShadingMode::Draft, settings),
        );
        check_against_ray_cast(
            name,
            &image,
            &hits,
            &Draft {
                settings,
                orientation,
            },
        );
    }
}

/// A gently waved bicubic B-spline surface over [0, 4]² (free-form: no closed form).
fn waved_surface(lift: f64) -> NurbsSurface {
    let n = 7;
    let mut points = Vec::new();
    for i in 0..n {
        for j in 0..n {
            let (x, y) = (
                4.0 * i as f64 / (n - 1) as f64,
                4.0 * j as f64 / (n - 1) as f64,
            );
            let mut z = 0.6 * (1.3 * x).sin() * (0.9 * y).cos();
            if (i, j) == (3, 3) {
                z += lift;
            }
            points.push(DVec3::new(x, y, z));
        }
    }
    construct::bspline_surface([3, 3], [n, n], points).unwrap()
}

fn waved_object(lift: f64, segments: u32) -> SceneObject {
    let mut object = SceneObject::new("waved", ObjectGeometry::new(waved_surface(lift)));
    object.segments = segments;
    object
}

/// A camera looking down at the waved surface, framing it up to height `top`.
fn waved_camera(top: f32) -> OrbitCamera {
    let mut camera = OrbitCamera {
        yaw: -1.1,
        pitch: 0.6,
        ..Default::default()
    };
    camera.frame(
        glam::Vec3::new(0.0, 0.0, -0.6),
        glam::Vec3::new(4.0, 4.0, top),
        WIDTH as f32 / HEIGHT as f32,
    );
    camera
}

/// The share of pixels both images cover whose grey level differs by more than 100 (a flipped
/// stripe), and how many pixels both cover.
fn stripe_difference(a: &[u8], b: &[u8]) -> (f64, usize) {
    let background = BACKGROUND.map(|c| (c * 255.0).round() as u8);
    let covered = |p: &[u8]| {
        p.iter()
            .zip(background)
            .take(3)
            .any(|(&x, y)| x.abs_diff(y) > 6)
    };
    let (mut both, mut flipped) = (0usize, 0usize);
    for (pa, pb) in a.chunks_exact(4).zip(b.chunks_exact(4)) {
        if covered(pa) && covered(pb) {
            both += 1;
            let (ga, gb) = (grey([pa[0], pa[1], pa[2]]), grey([pb[0], pb[1], pb[2]]));
            flipped += usize::from((ga - gb).abs() > 100.0);
        }
    }
    (flipped as f64 / both.max(1) as f64, both)
}

#[test]
fn zebra_does_not_depend_on_the_tessellation() {
    let camera = waved_camera(0.6);
    let settings = AnalysisSettings {
        zebra_pairs: 10,
        ..Default::default()
    };
    let view = view_of(camera, ShadingMode::Zebra, settings);
    let coarse = render(&[waved_object(0.0, 4)], &view);
    let fine = render(&[waved_object(0.0, 64)], &view);
    let (same_surface, covered) = stripe_difference(&coarse, &fine);
    // The measure can fail: a bump of 4 % of the size moves the stripes visibly.
    let bumped = render(&[waved_object(0.15, 64)], &view);
    let (bump, _) = stripe_difference(&bumped, &fine);
    eprintln!(
        "stripes flipped: coarse vs fine {:.3} %, bumped vs fine {:.3} % of {covered} pixels",
        100.0 * same_surface,
        100.0 * bump
    );
    if same_surface > 0.006 || bump < 0.015 {
        for (name, image) in [("coarse", &coarse), ("fine", &fine), ("bumped", &bumped)] {
            let path = common::artifact_path(&format!("zebra-{name}.png"));
            common::write_png(&path, WIDTH, HEIGHT, image);
            eprintln!("{name}: {}", path.display());
        }
    }
    assert!(covered > 8_000, "{covered}");
    assert!(
        same_surface < 0.006,
        "coarse and fine zebra differ on {same_surface}"
    );
    assert!(bump > 0.015, "a bump changes only {bump} of the stripes");
}

#[test]
fn every_analysis_mode_matches_its_reference_image() {
    let camera = waved_camera(2.4);
    let ball = SceneObject::new(
        "ball",
        ObjectGeometry::new(construct::sphere(DVec3::new(2.0, 2.5, 1.4), 1.0).unwrap()),
    );
    let objects = [waved_object(0.0, 16), ball];
    let mut images = Vec::new();
    for mode in [
        ShadingMode::Zebra,
        ShadingMode::Isophotes,
        ShadingMode::Reflection,
        ShadingMode::Draft,
        ShadingMode::Mean,
    ] {
        let mut view = view_of(camera, mode, AnalysisSettings::default());
        if mode == ShadingMode::Isophotes {
            view.range = Some((0.0, 180.0));
        }
        if mode == ShadingMode::Mean {
            view.range = Some((-1.0, 1.0));
        }
        let image = render(&objects, &view);
        common::compare_with_reference_png(
            &format!("analysis-{}.png", mode.name()),
            &image,
            (WIDTH, HEIGHT),
        );
        images.push(image);
    }
    // Each mode looks different from every other.
    for a in 0..images.len() {
        for b in a + 1..images.len() {
            let differing = images[a]
                .chunks_exact(4)
                .zip(images[b].chunks_exact(4))
                .filter(|(p, q)| p.iter().zip(*q).any(|(x, y)| x.abs_diff(*y) > 24))
                .count();
            assert!(
                differing > 5000,
                "modes {a} and {b} differ on {differing} pixels only"
            );
        }
    }
}
