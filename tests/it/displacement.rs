//! Displacement along the normal against analytic values and the f64 kernel: a displaced plane
//! on the compute shaders and on the WebGL2 path's CPU evaluator is the height field
//! z = a h(u, v) with its analytic normal; a displaced sphere's vertices are the kernel's
//! displaced points and normals; the document refuses kinds without a (u, v) domain and undoes
//! a displacement; the project file keeps it and refuses bad ones with the field named; the
//! export moves its points.

use crate::common;

use glam::DVec3;
use knotwork::doc::create::{Primitive, PrimitiveParams};
use knotwork::doc::{Command, Document, Touched};
use knotwork::gpu::patch_eval::ObjectDisplacement;
use knotwork::gpu::{SceneSync, SurfaceVertex};
use knotwork::io::project::{self, Project};
use knotwork::kernel::NurbsSurface;
use knotwork::kernel::displace::{Displacement, Pattern};
use knotwork::kernel::tess::Tessellation;
use knotwork::scene::{ObjectGeometry, Scene, SceneObject};

/// The plane z = 0 over [0, 2]², u along x and v along y on [0, 1]².
fn plane(displacement: Displacement) -> SceneObject {
    let points = vec![
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(0.0, 2.0, 0.0),
        DVec3::new(2.0, 0.0, 0.0),
        DVec3::new(2.0, 2.0, 0.0),
    ];
    let mut object = SceneObject::new(
        "plane",
        ObjectGeometry::new(NurbsSurface::bezier([1, 1], points, None).unwrap()),
    );
    object.segments = 48;
    object.displacement = Some(displacement);
    object
}

/// The vertices of `scene` as the compute shaders (or the CPU evaluator) write them.
fn vertices(scene: &Scene, cpu: bool) -> (SceneSync, Vec<SurfaceVertex>) {
    common::evaluate_scene(scene, cpu)
}

/// A grey PNG of 24 × 16 smooth bumps.
fn bumps_png() -> Vec<u8> {
    let (w, h) = (24u32, 16u32);
    let grey: Vec<u8> = (0..w * h)
        .map(|k| {
            let (i, j) = (f64::from(k % w), f64::from(k / w));
            (127.5 + 120.0 * (0.5 * i).sin() * (0.7 * j + 0.3).cos()).round() as u8
        })
        .collect();
    knotwork::io::height_image::encode_grey_png(w, h, &grey).unwrap()
}

/// A displacement by the bumps image tiled 2 × 2 times.
fn image_map(amplitude: f64) -> Displacement {
    let image = knotwork::io::height_image::decode_png(&bumps_png()).unwrap();
    Displacement::with_image(std::sync::Arc::new(image), amplitude, 2.0).unwrap()
}

#[test]
fn a_displaced_plane_is_the_height_field_on_both_evaluators() {
    let maps = Pattern::ALL
        .map(|pattern| Displacement::new(pattern, 0.15, 3.0).unwrap())
        .into_iter()
        .chain([image_map(0.15)]);
    for map in maps {
        let pattern = map.pattern;
        let scene = Scene {
            objects: vec![plane(map.clone())],
            unit: None,
        };
        for cpu in [false, true] {
            let (_, vs) = vertices(&scene, cpu);
            assert!(vs.len() > 1000);
            let (mut worst_p, mut worst_n) = (0.0f64, 0.0f64);
            for v in &vs {
                let (u, w) = (f64::from(v.u), f64::from(v.v));
                let [h, hx, hy] = map.height(u, w);
                let exact = DVec3::new(2.0 * u, 2.0 * w, 0.15 * h);
                let p = DVec3::from(v.position.map(f64::from));
                worst_p = worst_p.max(p.distance(exact));
                // z = a h(X/2, Y/2): normal (−a h_x / 2, −a h_y / 2, 1).
                let normal = DVec3::new(-0.15 * hx / 2.0, -0.15 * hy / 2.0, 1.0).normalize();
                let n = DVec3::from(v.normal.map(f64::from));
                worst_n = worst_n.max(n.angle_between(normal).to_degrees());
                assert_ne!(v.flags() & 2, 0, "a displaced vertex has no curvature");
            }
            eprintln!("{pattern:?} (cpu {cpu}): position {worst_p:.1e}, normal {worst_n:.1e}°");
            assert!(worst_p < 2e-6, "{pattern:?} cpu {cpu}: {worst_p:e}");
            assert!(worst_n < 0.01, "{pattern:?} cpu {cpu}: {worst_n}°");
        }
    }
}

#[test]
fn a_displaced_sphere_on_the_gpu_is_the_kernels_displaced_sphere() {
    let mut sphere = PrimitiveParams {
        kind: Primitive::Sphere,
        ..Default::default()
    }
    .build()
    .unwrap();
    sphere.segments = 12;
    let map = Displacement::new(Pattern::Ripples, 0.05, 5.0).unwrap();
    sphere.displacement = Some(map.clone());
    let domain = sphere.geometry.displacement_domain().unwrap();
    let scene = Scene {
        objects: vec![sphere.clone()],
        unit: None,
    };
    let (sync, vs) = vertices(&scene, false);
    let feed = &sync.feeds()[0];
    let records = sync.records().unwrap();
    let mut worst = 0.0f64;
    let mut checked = 0;
    for (k, record) in records.iter().enumerate() {
        let n = record.segments_u;
        for i in 1..n {
            for j in 1..n {
                let (s, t) = (f64::from(i) / f64::from(n), f64::from(j) / f64::from(n));
                let d = feed.set.evaluate(k, s, t).unwrap();
                let Some(normal) = d.regular_normal() else {
                    continue;
                };
                let (p, _) = ObjectDisplacement {
                    map: map.clone(),
                    domain,
                }
                .apply(record, &d, d.point, normal, (s, t));
                let v = vs[(record.vertex_offset + i * (n + 1) + j) as usize];
                worst = worst.max(DVec3::from(v.position.map(f64::from)).distance(p));
                checked += 1;
            }
        }
    }
    eprintln!("displaced sphere: {checked} vertices, GPU vs f64 {worst:.1e}");
    assert!(checked > 500);
    assert!(worst < 1e-5, "{worst:e}");
}

#[test]
fn the_document_refuses_cages_and_undoes_a_displacement() {
    let cage = PrimitiveParams {
        kind: Primitive::CageCube,
        ..Default::default()
    }
    .build()
    .unwrap();
    let map = Displacement::new(Pattern::Waves, 0.1, 2.0).unwrap();
    let mut doc = Document::new(Scene {
        objects: vec![cage, plane(map.clone())],
        unit: None,
    });
    doc.scene.objects[1].displacement = None;
    let original = doc.scene.clone();
    let refused = doc.execute(&Command::SetDisplacement {
        object: 0,
        displacement: Some(map.clone()),
    });
    assert!(
        refused
            .unwrap_err()
            .to_string()
            .contains("no (u, v) domain"),
        "a cage has no (u, v)"
    );
    assert_eq!(doc.scene, original);
    let bad = Displacement {
        frequency: -1.0,
        ..map.clone()
    };
    assert!(
        doc.execute(&Command::SetDisplacement {
            object: 1,
            displacement: Some(bad)
        })
        .is_err()
    );
    let touched = doc
        .execute(&Command::SetDisplacement {
            object: 1,
            displacement: Some(map.clone()),
        })
        .unwrap()
        .touched();
    assert_eq!(touched, Touched::Object(1));
    assert_eq!(doc.scene.objects[1].displacement, Some(map));
    doc.undo().unwrap();
    assert_eq!(doc.scene, original);
}

#[test]
fn the_project_file_keeps_it_and_refuses_bad_ones() {
    let map = Displacement::new(Pattern::Noise, -0.04, 6.0).unwrap();
    let text = project::write(&Project {
        scene: Scene {
            objects: vec![plane(map.clone())],
            unit: None,
        },
        view: None,
    });
    assert!(text.contains("\"noise\""), "{text}");
    let back = project::read(&text).unwrap();
    assert_eq!(back.scene.objects[0].displacement, Some(map));
    let with = |displacement: &str| {
        let mut value: serde_json::Value = serde_json::from_str(&text).unwrap();
        value["objects"][0]["displacement"] = serde_json::from_str(displacement).unwrap();
        value.to_string()
    };
    let e = project::read(&with(
        r#"{"pattern": "noise", "amplitude": 0.1, "frequency": 0}"#,
    ))
    .unwrap_err()
    .to_string();
    assert!(e.contains("displacement") && e.contains("frequency"), "{e}");
    let e = project::read(&with(
        r#"{"pattern": "plaid", "amplitude": 0.1, "frequency": 2}"#,
    ))
    .unwrap_err()
    .to_string();
    assert!(e.contains("displacement"), "{e}");

    // An image displacement keeps its PNG; a broken one is refused with the field named.
    let map = image_map(0.07);
    let text = project::write(&Project {
        scene: Scene {
            objects: vec![plane(map.clone())],
            unit: None,
        },
        view: None,
    });
    let back = project::read(&text).unwrap();
    assert_eq!(back.scene.objects[0].displacement, Some(map));
    let mut value: serde_json::Value = serde_json::from_str(&text).unwrap();
    value["objects"][0]["displacement"]["image"] = "bm90IGEgcG5n".into();
    let e = project::read(&value.to_string()).unwrap_err().to_string();
    assert!(e.contains("displacement.image") && e.contains("PNG"), "{e}");
    value["objects"][0]["displacement"]
        .as_object_mut()
        .unwrap()
        .remove("image");
    let e = project::read(&value.to_string()).unwrap_err().to_string();
    assert!(
        e.contains("image"),
        "an image pattern without an image: {e}"
    );
}

#[test]
fn the_export_moves_the_points() {
    let map = Displacement::new(Pattern::Waves, 0.2, 2.0).unwrap();
    let object = plane(map.clone());
    let meshes = object
        .tessellate(Tessellation::Tolerance(1e-3), false)
        .unwrap();
    let mesh = &meshes[0];
    // 8 segments per cycle at least: 16 here.
    assert!(mesh.positions.len() >= 17 * 17);
    let mut highest: f64 = 0.0;
    for (p, uv) in mesh.positions.iter().zip(&mesh.uvs) {
        let z = 0.2 * map.height(uv[0], uv[1])[0];
        assert!((p.z - z).abs() < 1e-12, "{p} vs {z}");
        highest = highest.max(p.z);
    }
    assert!(highest > 0.19, "the crests are exported: {highest}");

    // An image: one segment per pixel of its longer side per tile (24 × 2 here).
    let map = image_map(0.1);
    let meshes = plane(map.clone())
        .tessellate(Tessellation::Tolerance(1e-3), false)
        .unwrap();
    assert!(meshes[0].positions.len() >= 49 * 49);
    for (p, uv) in meshes[0].positions.iter().zip(&meshes[0].uvs) {
        let z = 0.1 * map.height(uv[0], uv[1])[0];
        assert!((p.z - z).abs() < 1e-12, "{p} vs {z}");
    }
}
