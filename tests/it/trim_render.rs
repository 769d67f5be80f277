//! Trimming on the GPU: the fragment shader's classification of trimmed surfaces against a CPU
//! rasterisation of the exact kept region (the f64 loops, flattened to 1e-7 in (u, v)), at a framed view
//! and at a close zoom onto a curved trim edge, where a texture-based trim would staircase.
//! The silhouette must agree within one pixel. Failing comparisons write the actual, expected
//! and difference images.

use crate::common;

use glam::{DMat4, DVec2, DVec3, DVec4, Vec3};
use knotwork::kernel::trim::polygon_contains;
use knotwork::kernel::trim::shapes::{ellipse, interpolating_loop, rectangle};
use knotwork::kernel::{NurbsSurface, TrimmedSurface, construct};
use knotwork::render::BACKGROUND;
use knotwork::scene::{ObjectGeometry, SceneObject};
use knotwork::view::{OrbitCamera, Overlays, ViewSettings};

const WIDTH: u32 = 256;
const HEIGHT: u32 = 192;

/// The plane origin + u·a + v·b (u, v ∈ [0, 1]), whose (u, v) an affine map gives back.
struct Plane {
    origin: DVec3,
    a: DVec3,
    b: DVec3,
}

impl Plane {
    fn surface(&self) -> NurbsSurface {
        // Degree-elevated and refined so the GPU sees several Bézier patches.
        construct::plane(self.origin, self.a, self.b)
            .unwrap()
            .elevate_degree(knotwork::kernel::Direction::U, 2)
            .unwrap()
            .insert_knot(knotwork::kernel::Direction::U, 0.45, 1)
            .unwrap()
            .insert_knot(knotwork::kernel::Direction::V, 0.6, 1)
            .unwrap()
    }

    /// (u, v) of the world point p on the plane.
    fn uv(&self, p: DVec3) -> DVec2 {
        let d = p - self.origin;
        let (aa, ab, bb) = (self.a.dot(self.a), self.a.dot(self.b), self.b.dot(self.b));
        let (da, db) = (d.dot(self.a), d.dot(self.b));
        let det = aa * bb - ab * ab;
        DVec2::new((bb * da - ab * db) / det, (aa * db - ab * da) / det)
    }
}

fn draw(objects: &[SceneObject], camera: &OrbitCamera) -> (Vec<u8>, DMat4) {
    let view = ViewSettings {
        camera: *camera,
        overlays: Overlays {
            surface: true,
            net: false,
            points: false,
            ..Default::default()
        },
        ..Default::default()
    };
    let pixels = common::draw_offscreen(&common::gpu(), objects, None, &view, (WIDTH, HEIGHT));
    let vp = camera
        .view_projection(WIDTH as f32 / HEIGHT as f32)
        .as_dmat4();
    (pixels, vp)
}

/// Where the ray through pixel (x + 0.5, y + 0.5) meets the plane z = 0.
fn ground_point(inverse: &DMat4, x: u32, y: u32) -> Option<DVec3> {
    let ndc_x = (f64::from(x) + 0.5) / f64::from(WIDTH) * 2.0 - 1.0;
    let ndc_y = 1.0 - (f64::from(y) + 0.5) / f64::from(HEIGHT) * 2.0;
    let unproject = |z: f64| {
        let p = *inverse * DVec4::new(ndc_x, ndc_y, z, 1.0);
        p.truncate() / p.w
    };
    let (near, far) = (unproject(0.0), unproject(1.0));
    let t = near.z / (near.z - far.z);
    (t.is_finite() && t > 0.0).then(|| near + (far - near) * t)
}

/// Compares the drawn surface's silhouette with the exact kept region: every pixel whose class
/// differs must have a pixel of the other class within one pixel in the exact image.
fn check_silhouette(name: &str, plane: &Plane, trimmed: &TrimmedSurface, camera: &OrbitCamera) {
    let object = SceneObject::new(name, ObjectGeometry::from_trimmed(trimmed.clone()));
    let (pixels, vp) = draw(&[object], camera);
    let inverse = vp.inverse();
    let loops = trimmed.flattened_loops(1e-7);
    let kept = |uv: DVec2| {
        (0.0..=1.0).contains(&uv.x)
            && (0.0..=1.0).contains(&uv.y)
            && loops.iter().filter(|l| polygon_contains(l, uv)).count() % 2 == 1
    };
    let [r, g, b, _] = BACKGROUND;
    let background = [r, g, b].map(|c| (c * 255.0).round() as u8);
    let (w, h) = (WIDTH as i64, HEIGHT as i64);
    let mut expected = vec![false; (w * h) as usize];
    for y in 0..HEIGHT {
        for x in 0..WIDTH {
            expected[(i64::from(y) * w + i64::from(x)) as usize] =
                ground_point(&inverse, x, y).is_some_and(|p| kept(plane.uv(p)));
        }
    }
    let drawn: Vec<bool> = pixels
        .chunks(4)
        .map(|p| {
            p[..3]
                .iter()
                .zip(background)
                .any(|(&a, b)| a.abs_diff(b) > 40)
        })
        .collect();
    let mut bad = 0;
    let mut diff = vec![0u8; pixels.len()];
    for y in 0..h {
        for x in 0..w {
            let k = (y * w + x) as usize;
            if drawn[k] == expected[k] {
                continue;
            }
            let near_edge = (-1..=1).any(|dy| {
                (-1..=1).any(|dx| {
                    let (a, b) = (x + dx, y + dy);
                    (0..w).contains(&a)
                        && (0..h).contains(&b)
                        && expected[(b * w + a) as usize] != expected[k]
                })
            });
            if !near_edge {
                bad += 1;
                diff[4 * k] = 255;
                diff[4 * k + 3] = 255;
            }
        }
    }
    let inside = expected.iter().filter(|&&e| e).count();
    assert!(
        inside > 1000,
        "{name}: the view shows too little of the surface ({inside} px)"
    );
    if bad > 0 {
        let actual = common::artifact_path(&format!("trim_{name}_actual.png"));
        common::write_png(&actual, WIDTH, HEIGHT, &pixels);
        let mask: Vec<u8> = expected
            .iter()
            .flat_map(|&e| {
                if e {
                    [255, 255, 255, 255]
                } else {
                    [0, 0, 0, 255]
                }
            })
            .collect();
        let exp = common::artifact_path(&format!("trim_{name}_expected.png"));
        common::write_png(&exp, WIDTH, HEIGHT, &mask);
        let d = common::artifact_path(&format!("trim_{name}_difference.png"));
        common::write_png(&d, WIDTH, HEIGHT, &diff);
        panic!(
            "{name}: {bad} pixels differ from the exact trimmed region by more than one pixel; see {actual:?}, {exp:?}, {d:?}"
        );
    }
}

fn plane() -> Plane {
    Plane {
        origin: DVec3::new(-1.0, -0.8, 0.0),
        a: DVec3::new(2.2, 0.3, 0.0),
        b: DVec3::new(-0.2, 1.7, 0.0),
    }
}

fn top_camera(lo: Vec3, hi: Vec3) -> OrbitCamera {
    let mut camera = OrbitCamera {
        pitch: 1.2,
        yaw: 0.3,
        ..OrbitCamera::default()
    };
    camera.frame(lo, hi, WIDTH as f32 / HEIGHT as f32);
    camera
}

fn trimmed(plane: &Plane) -> TrimmedSurface {
    let boundary = rectangle(DVec2::ZERO, DVec2::ONE).unwrap();
    let hole = ellipse(DVec2::new(0.35, 0.5), DVec2::new(0.2, 0.28)).unwrap();
    let blob = interpolating_loop(&[
        DVec2::new(0.65, 0.2),
        DVec2::new(0.9, 0.3),
        DVec2::new(0.85, 0.75),
        DVec2::new(0.7, 0.6),
    ])
    .unwrap();
    let island = ellipse(DVec2::new(0.35, 0.5), DVec2::new(0.06, 0.08)).unwrap();
    TrimmedSurface::new(plane.surface(), vec![boundary, hole, blob, island]).unwrap()
}

#[test]
fn the_gpu_trims_as_the_exact_region_does() {
    let plane = plane();
    let t = trimmed(&plane);
    let camera = top_camera(Vec3::new(-1.3, -0.9, -0.1), Vec3::new(1.3, 1.0, 0.1));
    check_silhouette("framed", &plane, &t, &camera);
}

#[test]
fn a_close_zoom_on_a_curved_trim_edge_stays_exact() {
    let plane = plane();
    let t = trimmed(&plane);
    // The hole's edge at its widest point, seen 1/200 of the surface across.
    let s = t.surface();
    let edge = s.point_at(0.35 + 0.2, 0.5).unwrap().as_vec3();
    let half = Vec3::splat(0.01);
    let camera = top_camera(edge - half, edge + half);
    check_silhouette("zoomed", &plane, &t, &camera);
}
