//! Adaptive subdivision against what it promises: pieces are refined only where the limit is
//! not flat (a planar cage stays at depth 0, a tolerance below the geometry's detail refines
//! everything to the level, a smaller tolerance never refines less); the result is crack-free
//! (on a closed cage every edge of the shown triangles is shared by exactly two of them, in
//! opposite directions) whatever depths meet; every point of the exact limit at the full level
//! lies within the tolerance of the shown triangles; schemes without nested grids and bad
//! tolerances are refused; and the document works the depths out again when a drag ends,
//! undoably.

use std::collections::HashMap;

use crate::common;

use glam::DVec3;
use knotwork::doc::{Document, Touched};
use knotwork::gpu::subdiv_eval::evaluate_adaptive;
use knotwork::kernel::PolygonMesh;
use knotwork::kernel::subdiv::adaptive::AdaptiveLayout;
use knotwork::kernel::subdiv::display::DisplayMesh;
use knotwork::kernel::subdiv::patches::Display;
use knotwork::kernel::subdiv::{Boundary, Options, Scheme, SubdivisionSurface, cages};
use knotwork::scene::{ObjectGeometry, Scene, SceneObject, SubdivObject};

fn surface(mesh: PolygonMesh, scheme: Scheme, level: u32) -> SubdivisionSurface {
    let options = Options {
        scheme,
        ..Options::default()
    };
    SubdivisionSurface::new(mesh, Vec::new(), Vec::new(), options, level).unwrap()
}

/// A torus cage (closed, all regular) with one point pulled far out: a spike that needs depth
/// beside wide regions that need little.
fn spiked_torus(scheme: Scheme, level: u32) -> SubdivisionSurface {
    let torus = cages::torus(DVec3::new(0.1, 0.2, -0.3), 2.0, 0.7, 10, 6).unwrap();
    let mut points = torus.points().to_vec();
    points[7] += DVec3::new(0.4, -0.3, 1.6);
    let mut faces: Vec<Vec<u32>> = torus.faces().map(<[u32]>::to_vec).collect();
    if scheme != Scheme::CatmullClark {
        faces = faces
            .iter()
            .flat_map(|f| [vec![f[0], f[1], f[2]], vec![f[0], f[2], f[3]]])
            .collect();
    }
    surface(PolygonMesh::new(points, &faces).unwrap(), scheme, level)
}

/// The depths each piece shows, in order.
fn depths(layout: &AdaptiveLayout) -> Vec<u32> {
    layout.pieces.iter().map(|p| p.depth).collect()
}

/// Checks that every edge of `mesh`'s triangles is used exactly twice, once each way (a
/// closed, consistently oriented surface without cracks or T-junctions), and that no triangle
/// is degenerate.
fn assert_closed(name: &str, mesh: &DisplayMesh) {
    let mut uses: HashMap<(u32, u32), i32> = HashMap::new();
    for polygon in &mesh.polygons {
        assert_eq!(polygon.len(), 3, "{name}: triangles only");
        let [a, b, c] = [polygon[0], polygon[1], polygon[2]];
        assert!(a != b && b != c && a != c, "{name}: a degenerate triangle");
        for (x, y) in [(a, b), (b, c), (c, a)] {
            *uses.entry((x, y)).or_default() += 1;
        }
    }
    for (&(x, y), &n) in &uses {
        assert_eq!(n, 1, "{name}: edge {x}-{y} used {n} times the same way");
        assert_eq!(
            uses.get(&(y, x)).copied().unwrap_or(0),
            1,
            "{name}: edge {x}-{y} has no twin: a crack or a T-junction"
        );
    }
}

/// The distance from `p` to triangle (a, b, c) (Ericson, Real-Time Collision Detection, 5.1.5).
fn point_triangle_distance(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return p.distance(a);
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return p.distance(b);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return p.distance(a + ab * (d1 / (d1 - d3)));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return p.distance(c);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return p.distance(a + ac * (d2 / (d2 - d6)));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return p.distance(b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6))));
    }
    let denom = 1.0 / (va + vb + vc);
    p.distance(a + ab * (vb * denom) + ac * (vc * denom))
}

#[test]
fn a_flat_cage_stays_at_depth_zero_and_a_tiny_tolerance_refines_everything() {
    // A planar 4 × 4 grid with its corners kept sharp: its limit is the square itself, every
    // piece is flat at depth 0.
    let options = Options {
        boundary: Boundary::EdgeAndCorner,
        ..Options::default()
    };
    let mesh = cages::grid(DVec3::new(0.3, -0.2, 0.5), 2.0, 4).unwrap();
    let grid = SubdivisionSurface::new(mesh, Vec::new(), Vec::new(), options, 4).unwrap();
    let layout = grid.adaptive_layout(4, 1e-6).unwrap();
    assert!(!layout.pieces.is_empty());
    assert!(
        depths(&layout).iter().all(|&d| d == 0),
        "{:?}",
        depths(&layout)
    );
    // Catmull-Clark pieces are level-1 quads: depth 0 shows level 1.
    assert_eq!(
        layout.histogram(),
        vec![0, layout.pieces.len()],
        "every piece on level 1"
    );

    // A curved surface with a tolerance far below its detail: everything at the level.
    for scheme in [Scheme::CatmullClark, Scheme::Loop, Scheme::Butterfly] {
        let s = spiked_torus(scheme, 3);
        let layout = s.adaptive_layout(3, 1e-9).unwrap();
        assert!(
            layout.pieces.iter().all(|p| p.depth == p.piece.depth),
            "{scheme:?}"
        );
        assert_eq!(layout.histogram().len(), 4, "{scheme:?}: up to level 3");
    }
}

#[test]
fn a_smaller_tolerance_never_refines_less_and_the_depths_vary_on_a_spike() {
    for scheme in [Scheme::CatmullClark, Scheme::Loop, Scheme::Butterfly] {
        let s = spiked_torus(scheme, 4);
        let mut previous: Option<Vec<u32>> = None;
        for tolerance in [0.05, 0.01, 0.002, 0.0005] {
            let d = depths(&s.adaptive_layout(4, tolerance).unwrap());
            if let Some(p) = &previous {
                assert!(
                    d.iter().zip(p).all(|(now, before)| now >= before),
                    "{scheme:?}: tolerance {tolerance} refined a piece less"
                );
            }
            previous = Some(d);
        }
        let d = depths(&s.adaptive_layout(4, 0.002).unwrap());
        let (lo, hi) = (d.iter().min().unwrap(), d.iter().max().unwrap());
        assert!(lo < hi, "{scheme:?}: depths {lo}..{hi} should vary");
    }
}

#[test]
fn the_adaptive_mesh_is_closed_where_depths_meet() {
    for scheme in [Scheme::CatmullClark, Scheme::Loop, Scheme::Butterfly] {
        for tolerance in [0.02, 0.004, 0.001] {
            let s = spiked_torus(scheme, 4);
            let layout = s.adaptive_layout(4, tolerance).unwrap();
            let d = depths(&layout);
            let mesh = s.adaptive_mesh_from(4, &layout).unwrap();
            assert_closed(&format!("{scheme:?} at {tolerance}"), &mesh);
            // Fewer triangles than the uniform level (the point of it), more than the coarsest.
            let uniform = s.display_mesh(4, Display::Limit).unwrap();
            let uniform_triangles: usize = uniform.polygons.iter().map(|p| p.len() - 2).sum();
            assert!(
                mesh.polygons.len() < uniform_triangles,
                "{scheme:?} at {tolerance}: {} triangles, uniform {uniform_triangles} (depths {:?})",
                mesh.polygons.len(),
                &d[..8]
            );
        }
    }
    // A cube: extraordinary vertices, Catmull-Clark pieces of level 1.
    let cube = surface(
        cages::cube(DVec3::ZERO, 2.0).unwrap(),
        Scheme::CatmullClark,
        4,
    );
    let mesh = cube.adaptive_mesh(4, 0.003).unwrap();
    assert_closed("cube", &mesh);
}

#[test]
fn every_limit_point_lies_within_the_tolerance_of_the_shown_triangles() {
    for scheme in [Scheme::CatmullClark, Scheme::Loop] {
        let s = spiked_torus(scheme, 3);
        let (lo, hi) = s.mesh().bounds().unwrap();
        let diagonal = lo.distance(hi);
        let tolerance = 0.004;
        let mesh = s.adaptive_mesh(3, tolerance).unwrap();
        let exact = s.display_mesh(3, Display::Limit).unwrap();
        let mut worst: f64 = 0.0;
        for &p in &exact.positions {
            let nearest = mesh
                .polygons
                .iter()
                .map(|t| {
                    let [a, b, c] = [0, 1, 2].map(|k| mesh.positions[t[k] as usize]);
                    point_triangle_distance(p, a, b, c)
                })
                .fold(f64::INFINITY, f64::min);
            worst = worst.max(nearest);
        }
        assert!(
            worst <= tolerance * diagonal,
            "{scheme:?}: a limit point {worst} from the mesh, tolerance {}",
            tolerance * diagonal
        );
        assert!(
            worst > 0.0,
            "{scheme:?}: the mesh is coarser than the limit"
        );
    }
}

#[test]
fn schemes_without_nested_grids_and_bad_tolerances_are_refused() {
    let icosahedron = cages::icosahedron(DVec3::ZERO, 1.0).unwrap();
    for scheme in [Scheme::DooSabin, Scheme::Sqrt3] {
        let s = surface(icosahedron.clone(), scheme, 2);
        let error = s.adaptive_feed(2, 0.01).unwrap_err().to_string();
        assert!(error.contains("adaptive"), "{error}");
        assert!(SubdivObject::checked(s, Display::Adaptive).is_err());
    }
    let s = surface(icosahedron, Scheme::Loop, 2);
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let error = s.adaptive_feed(2, bad).unwrap_err().to_string();
        assert!(error.contains("tolerance"), "{bad}: {error}");
        let object = SubdivObject::checked(s.clone(), Display::Adaptive).unwrap();
        assert!(object.with_tolerance_checked(bad).is_err(), "{bad}");
    }
}

#[test]
fn a_drag_that_ends_works_the_depths_out_again_and_undo_brings_them_back() {
    let s = spiked_torus(Scheme::CatmullClark, 3);
    let object = SubdivObject::checked(s, Display::Adaptive)
        .unwrap()
        .with_tolerance_checked(0.003)
        .unwrap();
    let layout = |doc: &Document| {
        let o = doc.scene.objects[0]
            .geometry
            .downcast_ref::<knotwork::scene::SubdivObject>();
        o.expect("a subdivision surface")
            .adaptive_layout()
            .unwrap()
            .unwrap()
    };
    let mut scene = Scene::default();
    scene.objects.push(SceneObject::new(
        "spike",
        ObjectGeometry::boxed(Box::new(object)),
    ));
    let mut doc = Document::new(scene);
    let before = layout(&doc);
    // Flatten the spike: point 7 back near the torus.
    doc.begin_drag(0, &[7]).unwrap();
    for step in 1..=4 {
        doc.drag_by(DVec3::new(-0.1, 0.075, -0.4) * f64::from(step))
            .unwrap();
        assert_eq!(layout(&doc), before, "the depths hold while dragging");
    }
    let touched = doc.commit_drag().unwrap().touched();
    assert_eq!(
        touched,
        Touched::Object(0),
        "other depths: a rebuild of the object"
    );
    let after = layout(&doc);
    assert_ne!(after, before);
    // The depths the shape now has, chosen afresh.
    let Some(moved) = doc.scene.objects[0]
        .geometry
        .downcast_ref::<knotwork::scene::SubdivObject>()
    else {
        panic!("not a subdivision surface");
    };
    assert_eq!(*after, moved.surface.adaptive_layout(3, 0.003).unwrap());
    assert_eq!(doc.undo().unwrap().touched(), Touched::Object(0));
    assert_eq!(layout(&doc), before);
    doc.redo().unwrap();
    assert_eq!(layout(&doc), after);

    // The same move as a command (a file, a script, a test) ends where the drag ended: the
    // depths chosen afresh, the document equal.
    let dragged = doc.scene.clone();
    doc.undo().unwrap();
    let target = doc.scene.objects[0].control_points()[7] + DVec3::new(-0.4, 0.3, -1.6);
    doc.execute(&knotwork::doc::Command::MovePoints {
        object: 0,
        moves: vec![(7, target)],
    })
    .unwrap();
    assert_eq!(layout(&doc), after);
    assert_eq!(doc.scene, dragged);
}

#[test]
fn the_compute_shaders_match_the_f64_adaptive_limit() {
    let context = common::gpu();
    for scheme in [Scheme::CatmullClark, Scheme::Loop, Scheme::Butterfly] {
        let s = spiked_torus(scheme, 3);
        let tolerance = 0.003;
        let layout = s.adaptive_layout(3, tolerance).unwrap();
        let exact = s.display_mesh(3, Display::Limit).unwrap();
        let gpu = evaluate_adaptive(&context.device, &context.queue, &s, 3, tolerance).unwrap();
        let triangles = s.adaptive_triangles(3, &layout).unwrap();
        let (lo, hi) = s.mesh().bounds().unwrap();
        let size = lo.distance(hi);
        let mut worst: f64 = 0.0;
        for v in triangles.iter().flatten() {
            let Some((p, n, _)) = gpu[*v as usize] else {
                panic!("{scheme:?}: vertex {v} of a triangle not evaluated");
            };
            worst = worst.max(p.distance(exact.positions[*v as usize]) / size);
            let angle = n.angle_between(exact.normals[*v as usize]).to_degrees();
            assert!(
                angle < 0.05,
                "{scheme:?}: normal {angle}° off at vertex {v}"
            );
        }
        eprintln!("{scheme:?}: GPU vs f64 {worst:.1e} of the size");
        assert!(worst < 1e-5, "{scheme:?}: {worst:e}");
    }
}

#[test]
fn the_subdivide_command_writes_the_adaptive_limit_on_both_backends() {
    let dir = crate::common::scratch_dir("adaptive-subdivide");
    let s = spiked_torus(Scheme::CatmullClark, 0);
    let faces: Vec<&[u32]> = s.mesh().faces().collect();
    let input = dir.join("torus.obj");
    std::fs::write(&input, knotwork::io::obj::write(s.points(), &[], &faces)).unwrap();
    let run = |args: &[&str]| common::run_subdivide(&input, args);
    let expected = s.adaptive_mesh(3, 0.004).unwrap();
    for backend in ["cpu", "gpu"] {
        let out = dir.join(format!("{backend}.obj"));
        let done = run(&[
            "--levels",
            "3",
            "--adaptive",
            "0.004",
            "--backend",
            backend,
            "-o",
            out.to_str().unwrap(),
        ]);
        let said = String::from_utf8_lossy(&done.stdout);
        assert!(
            done.status.success(),
            "{}",
            String::from_utf8_lossy(&done.stderr)
        );
        assert!(said.contains("pieces per level"), "{said}");
        let text = std::fs::read_to_string(&out).unwrap();
        let positions: Vec<DVec3> = text
            .lines()
            .filter_map(|l| l.strip_prefix("v "))
            .map(|l| {
                let c: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
                DVec3::new(c[0], c[1], c[2])
            })
            .collect();
        let polygons: Vec<Vec<u32>> = text
            .lines()
            .filter_map(|l| l.strip_prefix("f "))
            .map(|l| {
                l.split_whitespace()
                    .map(|x| x.split('/').next().unwrap().parse::<u32>().unwrap() - 1)
                    .collect()
            })
            .collect();
        assert_eq!(polygons, expected.polygons, "{backend}");
        assert_eq!(positions.len(), expected.positions.len(), "{backend}");
        let (lo, hi) = s.mesh().bounds().unwrap();
        let tolerance = if backend == "cpu" { 1e-12 } else { 1e-5 } * lo.distance(hi);
        for (w, e) in positions.iter().zip(&expected.positions) {
            assert!(w.distance(*e) < tolerance, "{backend}: {w} vs {e}");
        }
        let written = DisplayMesh {
            positions,
            normals: Vec::new(),
            polygons,
        };
        assert_closed(backend, &written);
    }
    let refused = run(&["--levels", "2", "--adaptive", "0", "-o", "x.obj"]);
    assert_eq!(refused.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&refused.stderr).contains("tolerance"));
    std::fs::remove_dir_all(&dir).ok();
}
