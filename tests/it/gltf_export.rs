//! glTF export: the official Khronos validator on every exported test scene, a round trip
//! through an independent reader (the `gltf` crate) against the f64 kernel, the embedded
//! editable model, and the chordal tolerance measured on the written triangles.

use crate::common;

use std::path::PathBuf;
use std::process::Command;

use glam::DVec3;
use knotwork::io::gltf::{self as export, CurvatureColors, ExportOptions, from_gltf_axes};
use knotwork::io::project::Project;
use knotwork::kernel::tess::Tessellation;
use knotwork::kernel::triangle::TriangleBezier;
use knotwork::kernel::trim::polygon_contains;
use knotwork::kernel::trim::tess::flatten_on_surface;
use knotwork::kernel::{BezierPatchSet, NurbsSurface, PolygonMesh, construct};
use knotwork::scene::{ObjectGeometry, Scene, SceneObject};
use knotwork::view::ViewSettings;
use knotwork::view::{OrbitCamera, Overlays, ShadingMode};

fn out_dir() -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("gltf-tests");
    std::fs::create_dir_all(&dir).expect("test output directory");
    dir
}

fn no_files(name: &str) -> Result<Vec<u8>, String> {
    Err(format!("no file {name} in this test"))
}

fn demo_project() -> Project {
    Project {
        scene: Scene::demo().unwrap(),
        view: Some(ViewSettings {
            camera: OrbitCamera {
                target: glam::Vec3::new(7.0, 3.0, 1.5),
                distance: 30.0,
                yaw: 0.7,
                pitch: 0.4,
                ..Default::default()
            },
            shading: ShadingMode::Mean,
            range: Some((-0.25, 0.5)),
            overlays: Overlays {
                points: false,
                ..Default::default()
            },
            ..Default::default()
        }),
    }
}

fn single(name: &str, geometry: ObjectGeometry) -> Project {
    Project {
        scene: Scene {
            objects: vec![SceneObject::new(name, geometry)],
            unit: None,
        },
        view: None,
    }
}

fn options(tessellation: Tessellation) -> ExportOptions {
    ExportOptions {
        tessellation,
        curvature: false,
        colors: None,
    }
}

/// A cube with one quad split into two triangles and one n-gon on top of a tower: a polygon
/// mesh with triangles, quads and a hexagon.
fn polygon_mesh() -> PolygonMesh {
    let mut points: Vec<DVec3> = (0..8)
        .map(|k| DVec3::new((k & 1) as f64, ((k >> 1) & 1) as f64, (k >> 2) as f64))
        .collect();
    points.extend((0..6).map(|k| {
        let a = k as f64 * std::f64::consts::TAU / 6.0;
        DVec3::new(0.5 + 0.4 * a.cos(), 0.5 + 0.4 * a.sin(), 1.6)
    }));
    let faces = vec![
        vec![0, 2, 3, 1],
        vec![4, 5, 7],
        vec![4, 7, 6],
        vec![0, 1, 5, 4],
        vec![1, 3, 7, 5],
        vec![3, 2, 6, 7],
        vec![2, 0, 4, 6],
        vec![8, 9, 10, 11, 12, 13],
    ];
    PolygonMesh::new(points, &faces).unwrap()
}

use common::validate_gltf as validate;

fn write(name: &str, export: &export::Export) -> Vec<PathBuf> {
    let path = out_dir().join(name);
    export::files(export, &path.display().to_string())
        .into_iter()
        .map(|(file, bytes)| {
            std::fs::write(&file, bytes).unwrap();
            PathBuf::from(file)
        })
        .collect()
}

#[test]
fn every_exported_test_scene_passes_the_khronos_validator() {
    let demo = demo_project();
    let tolerance = export::default_tolerance(&demo.scene);
    let mut with_hidden = demo.clone();
    with_hidden.scene.objects[1].visible = false;
    let colors = ExportOptions {
        tessellation: Tessellation::Tolerance(tolerance),
        curvature: true,
        colors: Some(CurvatureColors::automatic(
            &demo.scene,
            1,
            knotwork::gpu::records::curvature_ramp_rgb(),
        )),
    };
    let mesh = single("cage", ObjectGeometry::new(polygon_mesh()));
    let obj = knotwork::io::obj::read(
        "o pyramid\nv 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\nv 0.5 1 0.5\nf 1 2 3 4\nf 1 2 5\nf 2 3 5\nf 3 4 5\nf 4 1 5\n",
    )
    .unwrap();
    let cases = [
        (
            "demo.glb",
            &demo,
            options(Tessellation::Tolerance(tolerance)),
        ),
        ("demo.gltf", &demo, options(Tessellation::Segments(6))),
        ("demo-curvature.glb", &demo, colors),
        (
            "hidden.glb",
            &with_hidden,
            options(Tessellation::Segments(3)),
        ),
        ("mesh.glb", &mesh, options(Tessellation::Tolerance(1e-3))),
        ("obj.glb", &obj, options(Tessellation::Segments(2))),
    ];
    let mut files = Vec::new();
    for (name, project, options) in cases {
        let e = export::export(project, &options).unwrap();
        assert!(e.triangles > 0);
        files.extend(write(name, &e));
    }
    files.retain(|f| f.extension().is_some_and(|e| e != "bin"));
    validate(&files);
}

/// Positions (knotwork axes), normals, (u, v) and triangles of one primitive.
struct Primitive {
    positions: Vec<DVec3>,
    normals: Vec<DVec3>,
    uvs: Vec<[f64; 2]>,
    triangles: Vec<[usize; 3]>,
}

/// Every node of a `.glb` (name → its primitives), read by the `gltf` crate, with the node's
/// translation added back and glTF's Y-up turned into knotwork's Z-up.
fn read_glb(bytes: &[u8]) -> Vec<(String, Vec<Primitive>)> {
    let file = gltf::Gltf::from_slice(bytes).expect("the gltf crate reads the export");
    let blob = file.blob.as_deref().expect("a BIN chunk");
    let mut out = Vec::new();
    for node in file.nodes() {
        let (translation, rotation, scale) = node.transform().decomposed();
        assert_eq!((rotation, scale), ([0.0, 0.0, 0.0, 1.0], [1.0; 3]));
        let origin = DVec3::from(translation.map(f64::from));
        let mesh = node.mesh().expect("every node has a mesh");
        let mut primitives = Vec::new();
        for primitive in mesh.primitives() {
            assert_eq!(primitive.mode(), gltf::mesh::Mode::Triangles);
            let reader = primitive.reader(|b| (b.index() == 0).then_some(blob));
            let positions: Vec<DVec3> = reader
                .read_positions()
                .unwrap()
                .map(|p| from_gltf_axes(DVec3::from(p.map(f64::from)) + origin))
                .collect();
            // The accessor's min and max are the data's.
            let bounds = primitive.bounding_box();
            let raw: Vec<[f32; 3]> = reader.read_positions().unwrap().collect();
            for c in 0..3 {
                let lo = raw.iter().map(|p| p[c]).fold(f32::INFINITY, f32::min);
                let hi = raw.iter().map(|p| p[c]).fold(f32::NEG_INFINITY, f32::max);
                assert_eq!((bounds.min[c], bounds.max[c]), (lo, hi));
            }
            let normals = reader
                .read_normals()
                .unwrap()
                .map(|n| from_gltf_axes(DVec3::from(n.map(f64::from))))
                .collect();
            let uvs = reader
                .read_tex_coords(0)
                .map(|t| t.into_f32().map(|t| t.map(f64::from)).collect())
                .unwrap_or_default();
            let indices: Vec<usize> = reader
                .read_indices()
                .unwrap()
                .into_u32()
                .map(|i| i as usize)
                .collect();
            primitives.push(Primitive {
                positions,
                normals,
                uvs,
                triangles: indices.chunks(3).map(|t| [t[0], t[1], t[2]]).collect(),
            });
        }
        out.push((node.name().unwrap_or_default().to_owned(), primitives));
    }
    out
}

#[test]
fn the_glb_read_back_matches_the_kernel_at_the_stored_uv_and_faces_its_normals() {
    let project = demo_project();
    let tolerance = export::default_tolerance(&project.scene);
    let e = export::export(&project, &options(Tessellation::Tolerance(tolerance))).unwrap();
    let glb = export::to_glb(&e);
    let nodes = read_glb(&glb);
    assert_eq!(nodes.len(), project.scene.objects.len());
    let mut checked = 0;
    for (name, primitives) in &nodes {
        let object = project
            .scene
            .objects
            .iter()
            .find(|o| &o.name == name)
            .unwrap_or_else(|| panic!("node {name} names an object"));
        let (lo, hi) = object.bounds().unwrap();
        let size = (hi - lo).length();
        for (k, primitive) in primitives.iter().enumerate() {
            for (v, (&p, uv)) in primitive.positions.iter().zip(&primitive.uvs).enumerate() {
                // The demo holds NURBS surfaces, patch sets and a triangular patch.
                let geometry = &object.geometry;
                let expected = if let Some(s) = geometry.nurbs_surface() {
                    let [(u0, u1), (v0, v1)] = s.domain();
                    s.point_at(u0 + (u1 - u0) * uv[0], v0 + (v1 - v0) * uv[1])
                        .unwrap()
                } else if let Some(set) = geometry.downcast_ref::<BezierPatchSet>() {
                    set.evaluate(k, uv[0], uv[1]).unwrap().point
                } else if let Some(patch) = geometry.downcast_ref::<TriangleBezier>() {
                    patch.evaluate(uv[0], uv[1]).point
                } else {
                    unreachable!("the demo has no meshes or cages")
                };
                assert!(
                    p.distance(expected) <= 1e-6 * size,
                    "{name} primitive {k} vertex {v}: {p} vs {expected} at {uv:?}"
                );
                checked += 1;
            }
            for n in &primitive.normals {
                assert!(
                    (n.length() - 1.0).abs() < 1e-6,
                    "{name}: |n| = {}",
                    n.length()
                );
            }
            for t in &primitive.triangles {
                let [a, b, c] = t.map(|i| primitive.positions[i]);
                let face = (b - a).cross(c - a);
                if face.length() < 1e-9 * size * size {
                    continue;
                }
                let normal: DVec3 = t.iter().map(|&i| primitive.normals[i]).sum();
                assert!(
                    face.dot(normal) > 0.0,
                    "{name} primitive {k}: triangle {t:?} is wound against its normals"
                );
            }
        }
    }
    assert!(checked > 5_000, "{checked} vertices checked");
    eprintln!(
        "demo at tolerance {tolerance:.4}: {} triangles, {} vertices, {} bytes; {checked} vertices checked",
        e.triangles,
        e.vertices,
        glb.len()
    );
}

#[test]
fn the_embedded_model_reopens_equal_to_the_original_from_glb_and_gltf() {
    let mut project = demo_project();
    project.scene.objects[2].visible = false;
    project.scene.objects.push(SceneObject::new(
        "cage",
        ObjectGeometry::new(polygon_mesh()),
    ));
    let e = export::export(&project, &options(Tessellation::Segments(4))).unwrap();
    let reopened = knotwork::io::open("scene.glb", &export::to_glb(&e), &no_files).unwrap();
    assert_eq!(reopened, project);
    // The .gltf text needs no .bin for the model; and with the .bin beside it, it opens too.
    let files = write("reopen.gltf", &e);
    let text = std::fs::read(&files[0]).unwrap();
    assert_eq!(
        knotwork::io::open("reopen.gltf", &text, &no_files).unwrap(),
        project
    );
    let opened = knotwork::app::open_path(&files[0]).unwrap();
    assert_eq!(opened, project);
}

#[test]
fn another_tools_gltf_opens_as_polygon_meshes_at_the_exported_positions() {
    // knotwork's own export with the model taken out is a plain glTF file.
    let project = single("cage", ObjectGeometry::new(polygon_mesh()));
    let mut e = export::export(&project, &options(Tessellation::Segments(1))).unwrap();
    e.root.scenes[0].extras = None;
    let glb = export::to_glb(&e);
    let opened = knotwork::io::open("foreign.glb", &glb, &no_files).unwrap();
    assert_eq!(opened.scene.objects.len(), 1);
    assert_eq!(opened.scene.objects[0].name, "cage");
    let Some(mesh) = opened.scene.objects[0]
        .geometry
        .downcast_ref::<knotwork::kernel::PolygonMesh>()
    else {
        panic!("a polygon mesh")
    };
    // Flat faces at one segment: the triangles' corners are the cage's own points (welded back
    // by position), to f32 precision.
    let original = polygon_mesh();
    for p in mesh.points() {
        let nearest = original
            .points()
            .iter()
            .map(|q| q.distance(*p))
            .fold(f64::INFINITY, f64::min);
        assert!(nearest < 1e-6, "{p} is not a cage point");
    }
    assert_eq!(mesh.points().len(), original.points().len());
    // 5 quads, 2 triangles and a hexagon (4 triangles) become 2 × 5 + 2 + 4 triangles.
    assert_eq!(mesh.face_count(), 16);
}

/// The largest distance from the exported triangles' centroids and edge midpoints to the
/// surface, by `distance`.
fn worst_distance(glb: &[u8], distance: impl Fn(DVec3) -> f64) -> (f64, usize) {
    let mut worst = 0.0f64;
    let mut triangles = 0;
    for (_, primitives) in read_glb(glb) {
        for primitive in primitives {
            for t in &primitive.triangles {
                let [a, b, c] = t.map(|i| primitive.positions[i]);
                for p in [
                    (a + b + c) / 3.0,
                    0.5 * (a + b),
                    0.5 * (b + c),
                    0.5 * (c + a),
                ] {
                    worst = worst.max(distance(p));
                }
                triangles += 1;
            }
        }
    }
    (worst, triangles)
}

#[test]
fn triangles_stay_within_the_tolerance_of_a_sphere_a_torus_and_a_rational_bspline() {
    let (center, radius) = (DVec3::new(1.0, -2.0, 0.5), 2.0);
    let sphere = construct::sphere(center, radius).unwrap();
    let (major, minor) = (3.0, 1.0);
    let torus = construct::torus(DVec3::ZERO, DVec3::Z, major, minor).unwrap();
    let rational = rational_sheet();
    let sphere_distance = |p: DVec3| ((p - center).length() - radius).abs();
    let torus_distance = |p: DVec3| {
        let ring = (p.x.hypot(p.y) - major).hypot(p.z);
        (ring - minor).abs()
    };
    let sheet_distance = |p: DVec3| rational.closest_point(p).unwrap().distance;
    type Distance<'a> = &'a dyn Fn(DVec3) -> f64;
    let cases: [(&str, &NurbsSurface, Distance, &[f64]); 3] = [
        ("sphere", &sphere, &sphere_distance, &[1e-2, 1e-3, 5e-4]),
        ("torus", &torus, &torus_distance, &[1e-2, 1e-3]),
        (
            "rational B-spline",
            &rational,
            &sheet_distance,
            &[1e-2, 2e-3],
        ),
    ];
    for (name, surface, distance, tolerances) in cases {
        let project = single(name, ObjectGeometry::new(surface.clone()));
        let mut previous = 0;
        for &t in tolerances {
            let e = export::export(&project, &options(Tessellation::Tolerance(t))).unwrap();
            let (worst, triangles) = worst_distance(&export::to_glb(&e), distance);
            eprintln!("{name}: tolerance {t}: {triangles} triangles, worst distance {worst:.3e}");
            // f32 storage adds at most a few 1e-7 of the model's size.
            assert!(worst <= t + 2e-6, "{name}: {worst} > {t}");
            // Not wastefully fine: the worst triangle uses a good part of the allowance.
            assert!(worst > 0.2 * t, "{name}: {worst} ≪ {t}");
            assert!(triangles > previous);
            previous = triangles;
        }
    }
}

/// A rational bicubic × biquadratic sheet with uneven weights and interior knots.
fn rational_sheet() -> NurbsSurface {
    let (nu, nv) = (6, 5);
    let mut points = Vec::new();
    let mut weights = Vec::new();
    for i in 0..nu {
        for j in 0..nv {
            let (x, y) = (i as f64, j as f64);
            points.push(DVec3::new(x, y, 0.6 * (0.9 * x).sin() * (0.7 * y).cos()));
            weights.push(1.0 + 0.8 * ((i * 7 + j * 3) % 5) as f64 / 4.0);
        }
    }
    NurbsSurface::new(
        [3, 2],
        [
            vec![0.0, 0.0, 0.0, 0.0, 0.3, 0.6, 1.0, 1.0, 1.0, 1.0],
            vec![0.0, 0.0, 0.0, 0.4, 0.7, 1.0, 1.0, 1.0],
        ],
        [nu, nv],
        points,
        Some(weights),
    )
    .unwrap()
}

#[test]
fn the_export_cli_writes_a_valid_glb_that_opens_as_the_same_project() {
    let dir = out_dir();
    let input = dir.join("cli-input.json");
    let project = demo_project();
    std::fs::write(&input, knotwork::io::project::write(&project)).unwrap();
    let output = dir.join("cli-output.glb");
    let run = Command::new(env!("CARGO_BIN_EXE_knotwork"))
        .args(["export"])
        .arg(&input)
        .arg("-o")
        .arg(&output)
        .args(["--curvature", "--colors", "gaussian"])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(
        run.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert!(stdout.contains("triangles"), "{stdout}");
    validate(std::slice::from_ref(&output));
    let bytes = std::fs::read(&output).unwrap();
    assert_eq!(
        knotwork::io::open("cli.glb", &bytes, &no_files).unwrap(),
        project
    );
    // A bad argument and a bad input fail with a message, and write nothing.
    let bad = dir.join("cli-bad.glb");
    for args in [
        vec!["--tolerance", "-1"],
        vec!["--segments", "0"],
        vec!["--tolerance", "1e-3", "--segments", "4"],
    ] {
        let run = Command::new(env!("CARGO_BIN_EXE_knotwork"))
            .arg("export")
            .arg(&input)
            .arg("-o")
            .arg(&bad)
            .args(&args)
            .output()
            .unwrap();
        assert!(!run.status.success(), "{args:?}");
        assert!(!run.stderr.is_empty());
        assert!(!bad.exists(), "{args:?} wrote a file");
    }
    std::fs::write(dir.join("cli-broken.json"), "{\"format\": \"knotwork\"").unwrap();
    let run = Command::new(env!("CARGO_BIN_EXE_knotwork"))
        .arg("export")
        .arg(dir.join("cli-broken.json"))
        .arg("-o")
        .arg(&bad)
        .output()
        .unwrap();
    assert!(!run.status.success());
    assert!(String::from_utf8_lossy(&run.stderr).contains("cannot open"));
}

/// A rational sphere with a circular hole and a plane kept inside a cubic loop.
fn trimmed_project() -> Project {
    use glam::DVec2;
    use knotwork::kernel::TrimmedSurface;
    use knotwork::kernel::trim::shapes::{ellipse, interpolating_loop};
    let sphere = construct::sphere(DVec3::ZERO, 1.5).unwrap();
    let holed = TrimmedSurface::untrimmed(sphere)
        .add_loop(
            ellipse(DVec2::new(0.5, 0.5), DVec2::new(0.1, 0.15)).unwrap(),
            false,
        )
        .unwrap();
    let plane =
        construct::plane(DVec3::new(3.0, 0.0, 0.0), DVec3::X * 2.0, DVec3::Y * 2.0).unwrap();
    let kept = TrimmedSurface::new(
        plane,
        vec![
            interpolating_loop(&[
                DVec2::new(0.2, 0.2),
                DVec2::new(0.8, 0.3),
                DVec2::new(0.7, 0.8),
                DVec2::new(0.3, 0.7),
            ])
            .unwrap(),
        ],
    )
    .unwrap();
    Project {
        scene: Scene {
            objects: vec![
                SceneObject::new("holed sphere", ObjectGeometry::from_trimmed(holed)),
                SceneObject::new("kept plane", ObjectGeometry::from_trimmed(kept)),
            ],
            unit: None,
        },
        view: None,
    }
}

#[test]
fn trimmed_surfaces_export_valid_gltf_and_their_trims_reopen_exactly() {
    let project = trimmed_project();
    let tolerance = 1e-4 * 3.0;
    let e = export::export(&project, &options(Tessellation::Tolerance(tolerance))).unwrap();
    let files = write("trimmed.glb", &e);
    validate(&files);
    // The embedded model keeps the trims bit for bit.
    let glb = export::to_glb(&e);
    let reopened = knotwork::io::open("trimmed.glb", &glb, &no_files).unwrap();
    assert_eq!(reopened, project);
    // Every exported vertex lies on its surface at the stored (u, v) and in the kept region.
    for (name, primitives) in read_glb(&glb) {
        let object = project
            .scene
            .objects
            .iter()
            .find(|o| o.name == name)
            .unwrap();
        let Some(t) = object
            .geometry
            .downcast_ref::<knotwork::kernel::TrimmedSurface>()
        else {
            panic!("{name} is trimmed")
        };
        let [(u0, u1), (v0, v1)] = t.surface().domain();
        // The export's boundary: the loops flattened on the surface within a quarter of the
        // tolerance (vertices where its chords cross the tessellation grid lie on the chords).
        let boundary = flatten_on_surface(t, 0.25 * tolerance).unwrap();
        let kept = |u: f64, v: f64| {
            let p = glam::DVec2::new(u, v);
            t.contains(u, v) || boundary.iter().filter(|q| polygon_contains(q, p)).count() % 2 == 1
        };
        for primitive in primitives {
            for (p, uv) in primitive.positions.iter().zip(&primitive.uvs) {
                let (u, v) = (u0 + (u1 - u0) * uv[0], v0 + (v1 - v0) * uv[1]);
                let on = t.surface().point_at(u, v).unwrap();
                assert!(p.distance(on) < 1e-5, "{name}: {p} vs {on}");
                // f32 (u, v) in the file: a vertex on the trim edge may sit a rounding outside.
                let inside = kept(u, v)
                    || [(1e-6, 0.0), (-1e-6, 0.0), (0.0, 1e-6), (0.0, -1e-6)]
                        .iter()
                        .any(|(du, dv)| kept(u + du, v + dv));
                assert!(inside, "{name}: a vertex at ({u}, {v}) is trimmed away");
            }
        }
    }
    // The hole's area is missing from the sphere: 4πr² minus the patch the loop cuts out.
    let sphere_area: f64 = read_glb(&glb)
        .into_iter()
        .filter(|(n, _)| n == "holed sphere")
        .flat_map(|(_, p)| p)
        .map(|p| {
            p.triangles
                .iter()
                .map(|t| {
                    let [a, b, c] = t.map(|k| p.positions[k]);
                    0.5 * (b - a).cross(c - a).length()
                })
                .sum::<f64>()
        })
        .sum();
    let full = 4.0 * std::f64::consts::PI * 1.5 * 1.5;
    assert!(
        sphere_area < 0.99 * full && sphere_area > 0.5 * full,
        "{sphere_area}"
    );
}

/// An export whose objects together exceed the triangle limit is refused with the limit in the
/// message, however small each object is; at a limit it fits under, the same export is written
/// with the same count. (The page's limit is the 32-bit `MAX_TRIANGLES`, a fifth of the
/// desktop's.) The estimate (at segments, an upper bound: collapsed triangles are left out)
/// refuses before anything is tessellated, and names what would fit.
#[test]
fn an_export_over_the_triangle_limit_is_refused_with_the_limit() {
    let project = demo_project();
    let opts = options(Tessellation::Segments(4));
    let written = export::export(&project, &opts).unwrap();
    let close = knotwork::kernel::tess::Estimate::Close;
    let estimate: usize =
        export::estimate_triangles(&project.scene, opts.tessellation, usize::MAX, close)
            .unwrap()
            .iter()
            .sum();
    assert!(
        (written.triangles..=written.triangles * 11 / 10).contains(&estimate),
        "{estimate} for {}",
        written.triangles
    );
    let below = written.triangles - 1;
    match export::export_within(&project, &opts, below) {
        Err(
            e @ export::ExportError::TooManyTriangles {
                limit, estimated, ..
            },
        ) => {
            assert_eq!(limit, below);
            assert!(estimated, "refused from the estimate");
            assert!(e.to_string().contains(&below.to_string()), "{e}");
            assert!(e.to_string().contains("choose 3 segments or fewer"), "{e}");
        }
        other => panic!("expected a refusal, got {:?}", other.map(|e| e.triangles)),
    }
    let exact = export::export_within(&project, &opts, estimate).unwrap();
    assert_eq!(exact.triangles, written.triangles);
    // A tolerance that would take hundreds of millions of triangles: refused from the
    // estimate, with a tolerance that fits.
    let tiny = options(Tessellation::Tolerance(1e-8));
    let error = export::export(&project, &tiny).unwrap_err().to_string();
    assert!(
        error.contains("about ") && error.contains("choose a tolerance of"),
        "{error}"
    );
}

/// The stepped export (one object a step) gives the one-call export's file, reports its
/// progress in steps and, finished early, says it was cancelled.
#[test]
fn an_export_in_steps_is_the_same_file_and_can_be_cancelled() {
    let project = demo_project();
    let opts = options(Tessellation::Segments(3));
    let whole = export::to_glb(&export::export(&project, &opts).unwrap());
    let limit = knotwork::kernel::tess::MAX_TRIANGLES;
    let mut job = export::ExportJob::new(project.clone(), opts.clone(), limit).unwrap();
    let mut progress = vec![job.progress()];
    while !job.step().unwrap() {
        progress.push(job.progress());
    }
    progress.push(job.progress());
    assert_eq!(
        progress.len(),
        project.scene.objects.len() + 1,
        "{progress:?}"
    );
    assert!(progress.windows(2).all(|w| w[0] < w[1]), "{progress:?}");
    assert_eq!((progress[0], progress[progress.len() - 1]), (0.0, 1.0));
    assert_eq!(export::to_glb(&job.finish().unwrap()), whole);
    let mut cancelled = export::ExportJob::new(project, opts, limit).unwrap();
    cancelled.step().unwrap();
    assert!(matches!(
        cancelled.finish(),
        Err(export::ExportError::Cancelled)
    ));
}

/// Every kind as the registry's examples show it, each also displaced and deformed by a
/// lattice where it can be; the subdivision example at levels 1 to 4 and in every display; an
/// octahedron in each of the five schemes (and PN triangles for Loop).
fn every_kind() -> Project {
    use knotwork::kernel::displace::{Displacement, Pattern};
    use knotwork::kernel::ffd::Lattice;
    use knotwork::kernel::subdiv::patches::Display;
    use knotwork::kernel::subdiv::{Options, Scheme, SubdivisionSurface};
    use knotwork::scene::{ObjectKind, SubdivObject, registry};
    let mut objects = Vec::new();
    for entry in registry::kinds() {
        for object in (entry.examples)() {
            if object.kind().displacement_domain().is_some() {
                let mut displaced = object.clone();
                displaced.name += " displaced";
                displaced.displacement =
                    Some(Displacement::new(Pattern::Waves, 0.05, 2.0).unwrap());
                objects.push(displaced);
            }
            let (lo, hi) = object.kind().bounds().unwrap();
            let mut lattice = Lattice::around(lo - 0.1, hi + 0.1, [1, 1, 1]).unwrap();
            let corner = lattice.points()[7];
            lattice.set_point(7, corner + 0.2 * (hi - lo)).unwrap();
            let mut deformed = object.clone();
            deformed.name += " in a lattice";
            deformed.lattice = Some(lattice);
            objects.extend([object, deformed]);
        }
    }
    let cage = registry::kinds()
        .into_iter()
        .flat_map(|entry| (entry.examples)())
        .find_map(|o| o.geometry.downcast_ref::<SubdivObject>().cloned())
        .expect("a subdivision example");
    for level in 1..=4 {
        for display in [
            Display::Limit,
            Display::Refined,
            Display::Acc,
            Display::Gregory,
            Display::Adaptive,
        ] {
            let mut settings = cage.settings();
            (settings.level, settings.display) = (level, display);
            let shown = SubdivObject::with_settings(cage.cage().unwrap(), &settings).unwrap();
            let name = format!("cage level {level} {display:?}");
            objects.push(SceneObject::new(name, ObjectGeometry::new(shown)));
        }
    }
    let octahedron = PolygonMesh::new(
        vec![
            DVec3::X,
            DVec3::Y,
            -DVec3::X,
            -DVec3::Y,
            DVec3::Z,
            -DVec3::Z,
        ],
        &[
            vec![0, 1, 4],
            vec![1, 2, 4],
            vec![2, 3, 4],
            vec![3, 0, 4],
            vec![1, 0, 5],
            vec![2, 1, 5],
            vec![3, 2, 5],
            vec![0, 3, 5],
        ],
    )
    .unwrap();
    let schemes = [
        (Scheme::CatmullClark, Display::Limit),
        (Scheme::Loop, Display::Limit),
        (Scheme::Loop, Display::PnTriangles),
        (Scheme::DooSabin, Display::Limit),
        (Scheme::Sqrt3, Display::Limit),
        (Scheme::Butterfly, Display::Refined),
    ];
    for (scheme, display) in schemes {
        let options = Options {
            scheme,
            ..Default::default()
        };
        let surface =
            SubdivisionSurface::new(octahedron.clone(), Vec::new(), Vec::new(), options, 3)
                .unwrap();
        let shown = SubdivObject::checked(surface, display).unwrap();
        let name = format!("octahedron {scheme:?} {display:?}");
        objects.push(SceneObject::new(name, ObjectGeometry::new(shown)));
    }
    Project {
        scene: Scene {
            objects,
            unit: None,
        },
        view: None,
    }
}

#[test]
fn every_kind_with_every_export_option_passes_the_khronos_validator() {
    let project = every_kind();
    let tolerance = export::default_tolerance(&project.scene);
    let ramp = knotwork::gpu::records::curvature_ramp_rgb();
    let mut files = Vec::new();
    for (t, tessellation) in [
        Tessellation::Tolerance(tolerance),
        Tessellation::Segments(3),
    ]
    .into_iter()
    .enumerate()
    {
        for (c, (curvature, component)) in [
            (false, None),
            (true, None),
            (false, Some(0)),
            (true, Some(3)),
        ]
        .into_iter()
        .enumerate()
        {
            let options = ExportOptions {
                tessellation,
                curvature,
                colors: component
                    .map(|k| CurvatureColors::automatic(&project.scene, k, ramp.clone())),
            };
            let e = export::export(&project, &options).unwrap();
            let written = write(&format!("every-kind-{t}-{c}.glb"), &e);
            // Every vertex of every surface has its curvature and colour.
            let bytes = std::fs::read(&written[0]).unwrap();
            let document = gltf::Gltf::from_slice(&bytes).unwrap_or_else(|err| {
                panic!("options {t}/{c}: the export does not read back: {err}")
            });
            for mesh in document.meshes() {
                for primitive in mesh.primitives() {
                    let vertices = primitive.get(&gltf::Semantic::Positions).unwrap().count();
                    // A curve is a line strip of positions alone.
                    if primitive.mode() == gltf::mesh::Mode::LineStrip {
                        assert_eq!(primitive.attributes().count(), 1, "{:?}", mesh.name());
                        assert!(vertices >= 2);
                        continue;
                    }
                    let extras = [
                        (curvature, gltf::Semantic::Extras("CURVATURE".into())),
                        (component.is_some(), gltf::Semantic::Colors(0)),
                    ];
                    for (wanted, semantic) in extras {
                        let count = primitive.get(&semantic).map(|a| a.count());
                        let expected = wanted.then_some(vertices);
                        assert_eq!(count, expected, "{:?} {semantic:?}", mesh.name());
                    }
                }
            }
            files.extend(written);
        }
    }
    validate(&files);
}
