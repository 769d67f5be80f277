//! Doo-Sabin, Kobbelt's √3 and the modified butterfly against textbook cases and invariants:
//! Doo-Sabin on a regular grid against the biquadratic B-spline the NURBS kernel evaluates,
//! √3's two-step masks derived by hand, the butterfly's interpolation and cubic precision,
//! face and vertex counts per level, limit masks that refinement leaves in place, refused
//! cages, the CLI and the project file, and the GPU's stencil pass against the f64 display.

use crate::common;

use common::{grid_mesh, open_mixed_grid, triangle_lattice};
use glam::DVec3;
use knotwork::kernel::subdiv::patches::Display;
use knotwork::kernel::subdiv::schemes::{butterfly_ring_weights, doo_sabin_weight, sqrt3_alpha};
use knotwork::kernel::subdiv::{Options, Scheme, SubdivisionSurface, cages};
use knotwork::kernel::{NurbsSurface, PolygonMesh};
use knotwork::scene::SubdivObject;

fn surface(mesh: PolygonMesh, scheme: Scheme) -> SubdivisionSurface {
    let options = Options {
        scheme,
        ..Options::default()
    };
    SubdivisionSurface::new(mesh, Vec::new(), Vec::new(), options, 0).unwrap()
}

fn icosahedron() -> PolygonMesh {
    cages::icosahedron(DVec3::new(0.2, -0.1, 0.3), 1.5).unwrap()
}

/// The open grid with a hexagon, triangles and quads (any-polygon schemes), and a lattice
/// with a bump (triangle schemes).
fn open_cages() -> (PolygonMesh, PolygonMesh) {
    let polygons = open_mixed_grid();
    let lattice = triangle_lattice(5, |x, y| 0.3 * (x * 0.9).sin() * (y * 1.1).cos());
    (polygons, lattice)
}

#[test]
fn the_weights_are_the_published_ones() {
    // Doo-Sabin on quads: (9, 3, 1, 3)/16; every n-gon's weights sum to 1.
    for (i, w) in [9.0, 3.0, 1.0, 3.0].iter().enumerate() {
        assert!((doo_sabin_weight(4, i) - w / 16.0).abs() < 1e-15);
    }
    for n in 3..12 {
        let sum: f64 = (0..n).map(|i| doo_sabin_weight(n, i)).sum();
        assert!((sum - 1.0).abs() < 1e-14, "n = {n}: {sum}");
    }
    // √3: α(6) = 1/3 (regular), α(3) = 5/9.
    assert!((sqrt3_alpha(6) - 1.0 / 3.0).abs() < 1e-15);
    assert!((sqrt3_alpha(3) - 5.0 / 9.0).abs() < 1e-15);
    // Butterfly rings sum to 1/4 (with 3/4 at the vertex: affine).
    for k in 3..16 {
        let sum: f64 = butterfly_ring_weights(k).iter().sum();
        assert!((sum - 0.25).abs() < 1e-14, "k = {k}: {sum}");
    }
    assert_eq!(
        butterfly_ring_weights(3),
        vec![5.0 / 12.0, -1.0 / 12.0, -1.0 / 12.0]
    );
}

#[test]
fn doo_sabin_on_a_regular_grid_is_the_biquadratic_b_spline() {
    let m = 8;
    let mesh = grid_mesh(m);
    let p = mesh.points().to_vec();
    // Uniform knots 0..m+2: control point a's Greville abscissa is a + 1.5, and the grid's
    // (x, y) are its indices, so by linear precision a limit point's (x, y) + 1.5 is its
    // parameter.
    let knots: Vec<f64> = (0..m + 3).map(|k| k as f64).collect();
    let bspline =
        NurbsSurface::new([2, 2], [knots.clone(), knots], [m, m], p.clone(), None).unwrap();
    let ds = surface(mesh, Scheme::DooSabin);
    // One step: corner 0 of face 0 (points (0,0), (1,0), (1,1), (0,1)) is (9, 3, 1, 3)/16.
    let (refined, level) = ds.refined(1).unwrap();
    let id = |i: usize, j: usize| p[i * m + j];
    let expected = (9.0 * id(0, 0) + 3.0 * id(1, 0) + id(1, 1) + 3.0 * id(0, 1)) / 16.0;
    assert!((refined[0] - expected).length() < 1e-15);
    // Counts: 14 × 14 face points and 2 Chaikin points per boundary edge; 15 × 15 faces (the
    // corners' are triangles).
    assert_eq!(refined.len(), 196 + 56);
    assert_eq!(level.face_count(), 225);
    assert_eq!(level.faces().filter(|f| f.len() == 3).count(), 4);
    let mut checked = 0;
    for levels in 1..=3 {
        let shown = ds.display_mesh(levels, Display::Limit).unwrap();
        for (q, n) in shown.positions.iter().zip(&shown.normals) {
            let inside = |x: f64| (1.0..=(m - 2) as f64).contains(&x);
            if !(inside(q.x) && inside(q.y)) {
                continue;
            }
            let local = bspline.local_geometry(q.x + 1.5, q.y + 1.5).unwrap();
            let exact = local.derivatives.point;
            assert!(
                (*q - exact).length() < 1e-12,
                "level {levels}: {q} vs {exact}"
            );
            let angle = n.angle_between(local.normal);
            assert!(angle < 1e-7, "level {levels}: normal off by {angle}");
            checked += 1;
        }
    }
    assert!(checked > 1000, "{checked}");
}

#[test]
fn doo_sabin_counts_and_the_dual_limit_of_the_cube() {
    let cube = surface(cages::cube(DVec3::ZERO, 2.0).unwrap(), Scheme::DooSabin);
    // Level 1: 24 face points; 6 + 12 + 8 faces. Level 2: 6·4 + 12·4 + 8·3 points.
    let (points, level) = cube.refined(1).unwrap();
    assert_eq!(
        (points.len(), level.face_count(), level.edges.len()),
        (24, 26, 48)
    );
    let (points, level) = cube.refined(2).unwrap();
    assert_eq!((points.len(), level.face_count()), (96, 98));
    // The limit display is the dual: one point per face, one quad per vertex. The cube's
    // faces stay planar and keep their centroids, so the face centres (±1 on an axis) are
    // limit points with the axis as normal.
    let shown = cube.display_mesh(2, Display::Limit).unwrap();
    assert_eq!((shown.positions.len(), shown.polygons.len()), (98, 96));
    let (limit0, _) = (cube.display_mesh(0, Display::Limit).unwrap(), ());
    for (q, n) in limit0.positions.iter().zip(&limit0.normals) {
        assert!((q.length() - 1.0).abs() < 1e-12, "{q}");
        assert!((*n - *q).length() < 1e-12, "{n} at {q}");
    }
    // Symmetry: every limit point lies within the cube and the surface is closed (each
    // polygon edge is shared by two polygons).
    let mut edges = std::collections::HashMap::new();
    for polygon in &shown.polygons {
        for k in 0..polygon.len() {
            let (a, b) = (polygon[k], polygon[(k + 1) % polygon.len()]);
            *edges.entry((a.min(b), a.max(b))).or_insert(0) += 1;
        }
    }
    assert!(edges.values().all(|&c| c == 2));
    assert!(shown.positions.iter().all(|q| q.abs().max_element() <= 1.0));
}

#[test]
fn sqrt3_two_steps_on_a_regular_lattice_give_the_hand_derived_masks() {
    // Interior, valence 6: one step p' = 2/3 p + 1/18 Σ pᵢ and the new ring is the six face
    // centroids q = (p + pᵢ + pᵢ₊₁)/3, so two steps give p'' = 2/3 p' + 1/18 Σ q
    // = 5/9 p + 2/27 Σ pᵢ. Boundary: kept in the first step, (4, 19, 4)/27 in the second.
    let m = 9;
    let mesh = triangle_lattice(m, |x, y| (0.7 * x).sin() + 0.3 * (1.3 * y).cos());
    let p = mesh.points().to_vec();
    let s = surface(mesh, Scheme::Sqrt3);
    let (two, _) = s.refined(2).unwrap();
    let id = |i: usize, j: usize| i * m + j;
    for i in 1..m - 1 {
        for j in 1..m - 1 {
            let ring = [
                id(i + 1, j),
                id(i - 1, j),
                id(i, j + 1),
                id(i, j - 1),
                id(i + 1, j - 1),
                id(i - 1, j + 1),
            ];
            let sum: DVec3 = ring.iter().map(|&k| p[k]).sum();
            let expected = 5.0 / 9.0 * p[id(i, j)] + 2.0 / 27.0 * sum;
            let got = two[id(i, j)];
            assert!(
                (got - expected).length() < 1e-12,
                "({i}, {j}): {got} vs {expected}"
            );
        }
    }
    for i in 1..m - 1 {
        let expected = (4.0 * p[id(i - 1, 0)] + 19.0 * p[id(i, 0)] + 4.0 * p[id(i + 1, 0)]) / 27.0;
        assert!((two[id(i, 0)] - expected).length() < 1e-12, "boundary {i}");
    }
    let (one, _) = s.refined(1).unwrap();
    assert_eq!(one[id(3, 0)], p[id(3, 0)]);
    // Counts: 1-to-3 in the first step; the second also splits each boundary edge in three.
    let faces0 = 2 * (m - 1) * (m - 1);
    let boundary_edges = 4 * (m - 1);
    let (_, l1) = s.refined(1).unwrap();
    let (_, l2) = s.refined(2).unwrap();
    assert_eq!(l1.face_count(), 3 * faces0);
    assert_eq!(l2.face_count(), 9 * faces0 + 2 * boundary_edges);
    assert_eq!(two.len(), m * m + faces0 + 3 * faces0 + 2 * boundary_edges);
    let closed = surface(icosahedron(), Scheme::Sqrt3);
    for (k, (v, f)) in [(12, 20), (32, 60), (92, 180), (272, 540)]
        .into_iter()
        .enumerate()
    {
        let (points, level) = closed.refined(k as u32).unwrap();
        assert_eq!((points.len(), level.face_count()), (v, f), "level {k}");
    }
}

#[test]
fn sqrt3_limit_points_and_normals_stay_put_under_refinement() {
    // A vertex keeps its number through refinement, so its limit position and normal must be
    // the same whether taken at level 1 or at level 3 (β∞ = 3α/(1 + 3α) and the cos/sin
    // tangent masks; the boundary's cubic B-spline (1, 4, 1)/6).
    let (_, lattice) = open_cages();
    for mesh in [icosahedron(), lattice] {
        let s = surface(mesh, Scheme::Sqrt3);
        let coarse = s.display_mesh(1, Display::Limit).unwrap();
        let fine = s.display_mesh(3, Display::Limit).unwrap();
        for v in 0..coarse.positions.len() {
            let d = (coarse.positions[v] - fine.positions[v]).length();
            assert!(d < 1e-12, "vertex {v}: moved by {d}");
        }
        // Interior normals are exact (the 1-ring is closed under the step).
        let level = s.refined(1).unwrap().1;
        for v in 0..coarse.positions.len() as u32 {
            let interior = level
                .vertex_edges(v)
                .iter()
                .all(|&e| !level.is_boundary_edge(e));
            if interior {
                let angle = coarse.normals[v as usize].angle_between(fine.normals[v as usize]);
                // (acos resolves angles near 0 to about 1.5e-8.)
                assert!(angle < 1e-7, "vertex {v}: normal turned by {angle}");
            }
        }
    }
    // The icosahedron: the positive masks keep the limit inside the cage's circumsphere;
    // by symmetry its 12 points have one limit radius, with radial normals.
    let s = surface(icosahedron(), Scheme::Sqrt3);
    let centre = DVec3::new(0.2, -0.1, 0.3);
    let shown = s.display_mesh(3, Display::Limit).unwrap();
    let r0 = (shown.positions[0] - centre).length();
    for (v, (q, n)) in shown.positions.iter().zip(&shown.normals).enumerate() {
        let r = (*q - centre).length();
        assert!(r < 1.5 && r > 1.0, "radius {r}");
        assert!(n.dot((*q - centre) / r) > 0.95);
        if v < 12 {
            assert!((r - r0).abs() < 1e-12, "{r} vs {r0}");
            assert!(n.dot((*q - centre) / r) > 1.0 - 1e-12);
        }
    }
}

/// A cubic in x and y.
fn cubic(x: f64, y: f64) -> f64 {
    0.1 * x * x * x - 0.2 * x * x * y + 0.05 * x * y * y + 0.03 * y * y * y - x + 0.5 * y + 0.2
}

#[test]
fn the_butterfly_interpolates_and_reproduces_cubics_on_regular_lattices() {
    let m = 9;
    let mesh = triangle_lattice(m, cubic);
    let cage = mesh.points().to_vec();
    let s = surface(mesh, Scheme::Butterfly);
    let hierarchy = s.hierarchy(1).unwrap();
    let base = &hierarchy.levels[0];
    let (one, level1) = s.refined(1).unwrap();
    // Loop's counts and numbering: old vertices, then one per edge.
    assert_eq!(one.len(), cage.len() + base.edges.len());
    assert_eq!(level1.face_count(), 4 * base.face_count());
    let boundary = |v: u32| {
        base.vertex_edges(v)
            .iter()
            .any(|&e| base.is_boundary_edge(e))
    };
    let mut interior_checked = 0;
    let mut boundary_checked = 0;
    for (e, &[a, b]) in base.edges.iter().enumerate() {
        let q = one[cage.len() + e];
        let mid = 0.5 * (cage[a as usize] + cage[b as usize]);
        // Polynomial precision: the point lies over the midpoint (linear) on the cubic.
        let on_cubic = (q.truncate() - mid.truncate()).length() < 1e-12
            && (q.z - cubic(q.x, q.y)).abs() < 1e-12;
        let regular = |v: u32| !boundary(v) && base.vertex_edges(v).len() == 6;
        if regular(a) && regular(b) {
            assert!(on_cubic, "edge {e}: {q}");
            interior_checked += 1;
        } else if base.is_boundary_edge(e as u32) {
            // The four-point rule reproduces cubics along a straight boundary.
            let straight = |v: u32| base.vertex_edges(v).len() >= 4;
            if straight(a) && straight(b) {
                assert!(on_cubic, "boundary edge {e}: {q}");
                boundary_checked += 1;
            }
        }
    }
    assert!(interior_checked > 100 && boundary_checked > 10);
    // Interpolation: every cage point stays, bit for bit, at every level.
    for mesh in [icosahedron(), triangle_lattice(5, cubic)] {
        let points = mesh.points().to_vec();
        let s = surface(mesh, Scheme::Butterfly);
        for levels in 1..=3 {
            let shown = s.display_mesh(levels, Display::Limit).unwrap();
            assert_eq!(&shown.positions[..points.len()], &points[..]);
        }
    }
    // Planar cages stay planar (affine invariance) through extraordinary rules too.
    let flat = cages::icosahedron(DVec3::ZERO, 1.0).unwrap();
    let squashed: Vec<DVec3> = flat
        .points()
        .iter()
        .map(|p| DVec3::new(p.x, p.y, 0.25 * p.x - 0.5 * p.y + 1.0))
        .collect();
    let faces: Vec<Vec<u32>> = flat.faces().map(<[u32]>::to_vec).collect();
    let s = surface(
        PolygonMesh::new(squashed, &faces).unwrap(),
        Scheme::Butterfly,
    );
    for q in s.refined(3).unwrap().0 {
        assert!((q.z - (0.25 * q.x - 0.5 * q.y + 1.0)).abs() < 1e-12);
    }
}

#[test]
fn triangle_schemes_refuse_quads_and_keep_nothing_broken() {
    let cube = cages::cube(DVec3::ZERO, 2.0).unwrap();
    for scheme in [Scheme::Sqrt3, Scheme::Butterfly] {
        let options = Options {
            scheme,
            ..Options::default()
        };
        let err = SubdivisionSurface::new(cube.clone(), Vec::new(), Vec::new(), options, 1)
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("triangles only") && err.contains(scheme.label()),
            "{err}"
        );
    }
    // Absurd levels are refused by the face estimate, not by running out of memory.
    let options = Options {
        scheme: Scheme::DooSabin,
        ..Options::default()
    };
    let big = cages::torus(DVec3::ZERO, 2.0, 0.5, 200, 100).unwrap();
    let err = SubdivisionSurface::new(big, Vec::new(), Vec::new(), options, 6)
        .unwrap_err()
        .to_string();
    assert!(err.contains("faces"), "{err}");
}

#[test]
fn the_gpu_stencil_pass_matches_the_f64_display_for_every_new_scheme() {
    let context = common::gpu();
    let (polygons, lattice) = open_cages();
    let cube = cages::cube(DVec3::new(0.1, 0.2, -0.3), 2.0).unwrap();
    let cases = [
        (Scheme::DooSabin, polygons),
        (Scheme::DooSabin, cube),
        (Scheme::Sqrt3, lattice.clone()),
        (Scheme::Sqrt3, icosahedron()),
        (Scheme::Butterfly, lattice),
        (Scheme::Butterfly, icosahedron()),
    ];
    for (scheme, mesh) in cases {
        let (lo, hi) = mesh.bounds().unwrap();
        let size = (hi - lo).length();
        let s = surface(mesh, scheme);
        for levels in 1..=3 {
            for display in [Display::Limit, Display::Refined] {
                let cpu = s.display_mesh(levels, display).unwrap();
                let gpu = knotwork::gpu::subdiv_eval::evaluate_level(
                    &context.device,
                    &context.queue,
                    &s,
                    levels,
                    display,
                )
                .unwrap();
                let used: std::collections::BTreeSet<u32> =
                    cpu.polygons.iter().flatten().copied().collect();
                let mut worst = (0.0f64, 0.0f64);
                for &v in &used {
                    let (p, n, _) = gpu[v as usize].expect("every display point has a slot");
                    worst.0 = worst.0.max((p - cpu.positions[v as usize]).length() / size);
                    if cpu.normals[v as usize] != DVec3::ZERO {
                        worst.1 = worst.1.max(n.angle_between(cpu.normals[v as usize]));
                    }
                }
                eprintln!(
                    "{scheme:?} level {levels} {display:?}: {} points, position {:.1e}, normal {:.1e} rad",
                    used.len(),
                    worst.0,
                    worst.1
                );
                assert!(
                    worst.0 < 1e-5 && worst.1 < 1e-3,
                    "{scheme:?} level {levels} {display:?}: {worst:?}"
                );
            }
        }
    }
}

const OCTAHEDRON: &str = "v 1 0 0\nv -1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\n\
f 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n";

const CUBE: &str = "v -1 -1 -1\nv 1 -1 -1\nv -1 1 -1\nv 1 1 -1\nv -1 -1 1\nv 1 -1 1\nv -1 1 1\nv 1 1 1\n\
f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n";

fn counts(text: &str) -> [usize; 3] {
    ["v ", "vn ", "f "].map(|p| text.lines().filter(|l| l.starts_with(p)).count())
}

#[test]
fn knotwork_subdivide_takes_the_new_schemes_on_both_backends() {
    let dir = crate::common::scratch_dir("schemes-subdivide");
    let octahedron = dir.join("octahedron.obj");
    std::fs::write(&octahedron, OCTAHEDRON).unwrap();
    let cube = dir.join("cube.obj");
    std::fs::write(&cube, CUBE).unwrap();
    // (input, scheme, levels, limit) → (vertices, normals, faces).
    let cases = [
        (&cube, "doo-sabin", "2", false, [96, 0, 98]),
        (&cube, "doo-sabin", "2", true, [98, 98, 96]),
        (&octahedron, "sqrt3", "2", true, [6 + 8 + 24, 38, 72]),
        (&octahedron, "butterfly", "2", false, [66, 0, 128]),
    ];
    for (input, scheme, levels, limit, expected) in cases {
        let mut outputs = Vec::new();
        for backend in ["cpu", "gpu"] {
            let output = dir.join(format!("{scheme}-{limit}-{backend}.obj"));
            let mut command = std::process::Command::new(env!("CARGO_BIN_EXE_knotwork"));
            command.args(["subdivide", input.to_str().unwrap(), "--scheme", scheme]);
            command.args(["--levels", levels, "--backend", backend, "-o"]);
            command.arg(&output);
            if limit {
                command.arg("--limit");
            }
            let run = command.output().unwrap();
            assert!(
                run.status.success(),
                "{scheme} {backend}: {}",
                String::from_utf8_lossy(&run.stderr)
            );
            let text = std::fs::read_to_string(&output).unwrap();
            assert_eq!(counts(&text), expected, "{scheme} {backend}");
            outputs.push(text);
        }
        // The two backends agree to f32 precision.
        let numbers = |t: &str| -> Vec<f64> {
            t.lines()
                .filter(|l| l.starts_with("v "))
                .flat_map(|l| l[2..].split(' ').map(|x| x.parse::<f64>().unwrap()))
                .collect::<Vec<_>>()
        };
        for (a, b) in numbers(&outputs[0]).iter().zip(numbers(&outputs[1])) {
            assert!((a - b).abs() < 1e-5, "{scheme}: {a} vs {b}");
        }
    }
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_knotwork"))
        .args([
            "subdivide",
            cube.to_str().unwrap(),
            "--scheme",
            "sqrt3",
            "-o",
        ])
        .arg(dir.join("bad.obj"))
        .output()
        .unwrap();
    assert_eq!(run.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(stderr.contains("triangles only"), "{stderr}");
}

#[test]
fn the_scheme_is_saved_in_the_project_file() {
    use knotwork::scene::{ObjectGeometry, SceneObject};
    for scheme in [Scheme::DooSabin, Scheme::Sqrt3, Scheme::Butterfly] {
        let options = Options {
            scheme,
            ..Options::default()
        };
        let s = SubdivisionSurface::new(icosahedron(), Vec::new(), Vec::new(), options, 2).unwrap();
        let mut scene = knotwork::scene::Scene::default();
        scene.objects.push(SceneObject::new(
            "cage",
            ObjectGeometry::new(knotwork::scene::SubdivObject::from(s)),
        ));
        let project = knotwork::io::project::Project { scene, view: None };
        let text = knotwork::io::project::write(&project);
        let name = serde_json::to_string(&scheme).unwrap();
        assert!(text.contains(&name), "{name} missing");
        let back = knotwork::io::project::read(&text).unwrap();
        match back.scene.objects[0]
            .geometry
            .downcast_ref::<SubdivObject>()
        {
            Some(b) => {
                assert_eq!(b.surface.options.scheme, scheme);
                assert_eq!(b.surface.level(), 2);
            }
            None => panic!("{:?}", back.scene.objects[0].geometry),
        }
    }
}

#[test]
fn switching_schemes_is_one_undo_step_and_a_refused_switch_changes_nothing() {
    use knotwork::doc::{Command, Document};
    use knotwork::scene::{ObjectGeometry, Scene, SceneObject};
    let cube = SubdivisionSurface::from_mesh(cages::cube(DVec3::ZERO, 2.0).unwrap(), 2).unwrap();
    let mut scene = Scene::default();
    scene.objects.push(SceneObject::new(
        "cage",
        ObjectGeometry::new(knotwork::scene::SubdivObject::from(cube)),
    ));
    let mut doc = Document::new(scene);
    let settings = |doc: &Document| {
        let geometry = &doc.scene.objects[0].geometry;
        geometry
            .downcast_ref::<SubdivObject>()
            .expect("a subdivision surface")
            .settings()
    };
    let before = settings(&doc);
    let mut doo_sabin = before.clone();
    doo_sabin.options.scheme = Scheme::DooSabin;
    doc.execute(&Command::SetSubdivision {
        object: 0,
        settings: doo_sabin.clone(),
    })
    .unwrap();
    assert_eq!(settings(&doc), doo_sabin);
    // The cube's quads are refused by √3, naming the face; the document stays as it was.
    let saved = doc.save(None);
    let mut sqrt3 = before.clone();
    sqrt3.options.scheme = Scheme::Sqrt3;
    let err = doc
        .execute(&Command::SetSubdivision {
            object: 0,
            settings: sqrt3,
        })
        .unwrap_err()
        .to_string();
    assert!(err.contains("triangles only"), "{err}");
    assert_eq!(doc.save(None), saved);
    doc.undo().unwrap();
    assert_eq!(settings(&doc), before);
    doc.redo().unwrap();
    assert_eq!(settings(&doc), doo_sabin);
}
