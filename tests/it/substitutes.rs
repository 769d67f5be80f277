//! The efficient substitutes of a subdivision surface (ACC, Gregory, PN triangles) against the
//! exact limit and their own defining properties: on a regular cage ACC and Gregory are the
//! bicubic B-spline (so the exact Catmull-Clark limit) with the exact normals; at the cage's
//! vertices the substitutes pass through the limit points (Gregory and PN also with the limit
//! normals); neighbouring patches meet with one position and one normal (ACC's tangent patches,
//! Gregory's G¹ construction, PN's shared edge normals); the error against the exact limit is
//! small on cages with extraordinary vertices; faces at boundaries keep the exact limit; and a
//! substitute of the wrong scheme is refused.

use std::collections::HashMap;

use crate::common;

use glam::{DAffine3, DVec3};
use knotwork::kernel::PolygonMesh;
use knotwork::kernel::subdiv::patches::Display;
use knotwork::kernel::subdiv::substitutes::{SubstituteKind, evaluate};
use knotwork::kernel::subdiv::{Options, Scheme, SubdivisionSurface, cages};
use knotwork::scene::SubdivObject;

fn surface(mesh: PolygonMesh, scheme: Scheme) -> SubdivisionSurface {
    let options = Options {
        scheme,
        ..Options::default()
    };
    SubdivisionSurface::new(mesh, Vec::new(), Vec::new(), options, 0).unwrap()
}

/// A cube with its corners pushed about: valence-3 vertices, no symmetry to hide behind.
fn skewed_cube() -> SubdivisionSurface {
    let cube = cages::cube(DVec3::ZERO, 2.0).unwrap();
    let points: Vec<DVec3> = cube
        .points()
        .iter()
        .enumerate()
        .map(|(k, &p)| p + DVec3::new(0.13, -0.07, 0.11) * ((k * 7 % 5) as f64 - 2.0) * 0.4)
        .collect();
    let faces: Vec<Vec<u32>> = cube.faces().map(<[u32]>::to_vec).collect();
    surface(
        PolygonMesh::new(points, &faces).unwrap(),
        Scheme::CatmullClark,
    )
}

/// A torus cage: every vertex regular.
fn torus() -> SubdivisionSurface {
    surface(
        cages::torus(DVec3::new(0.1, 0.2, -0.3), 2.0, 0.7, 8, 6).unwrap(),
        Scheme::CatmullClark,
    )
}

fn icosahedron(scheme: Scheme) -> SubdivisionSurface {
    surface(
        cages::icosahedron(DVec3::new(0.2, -0.1, 0.3), 1.5).unwrap(),
        scheme,
    )
}

/// The angle between two directions in degrees, accurate for tiny angles.
fn degrees(a: DVec3, b: DVec3) -> f64 {
    a.cross(b).length().atan2(a.dot(b)).to_degrees()
}

/// Every substitute patch's samples by the level vertex they show: (position, normal).
fn samples_by_vertex(
    s: &SubdivisionSurface,
    kind: SubstituteKind,
    levels: u32,
) -> HashMap<u32, Vec<(DVec3, DVec3)>> {
    let (feed, plan) = s.substitute_feed(levels, kind, false).unwrap();
    let base = plan.base_points(s.points());
    let mut out: HashMap<u32, Vec<(DVec3, DVec3)>> = HashMap::new();
    for (k, patch) in feed.substitutes.iter().enumerate() {
        let mut control = Vec::new();
        plan.patch_points(&base, k, &mut control);
        let n = patch.segments as usize;
        for i in 0..=n {
            for j in 0..=n {
                let v = feed.vertex[patch.first_slot as usize + i * (n + 1) + j];
                if v == u32::MAX {
                    continue;
                }
                let sample = evaluate(kind, &control, i as f64 / n as f64, j as f64 / n as f64);
                let normal = if kind == SubstituteKind::Gregory {
                    sample.derivatives.regular_normal().unwrap()
                } else {
                    sample.normal
                };
                out.entry(v)
                    .or_default()
                    .push((sample.derivatives.point, normal));
            }
        }
    }
    out
}

#[test]
fn acc_and_gregory_are_the_bspline_on_regular_cages() {
    let torus = torus();
    for kind in [SubstituteKind::Acc, SubstituteKind::Gregory] {
        let error = torus.substitute_error(kind, 3, false).unwrap();
        eprintln!("{kind:?} on the torus: {error:?}");
        assert_eq!(error.patches, 48, "{kind:?}: every face a patch");
        assert_eq!(error.samples, 48 * 81);
        assert!(error.max_distance < 1e-13, "{kind:?}: {error:?}");
        assert!(error.max_normal_degrees < 1e-5, "{kind:?}: {error:?}");
    }
}

#[test]
fn substitutes_pass_through_the_limit_points() {
    let cases = [
        (skewed_cube(), SubstituteKind::Acc, false),
        (skewed_cube(), SubstituteKind::Gregory, true),
        (icosahedron(Scheme::Loop), SubstituteKind::PnTriangle, true),
        // Not all quads: the patches live on level 1.
        (
            icosahedron(Scheme::CatmullClark),
            SubstituteKind::Gregory,
            true,
        ),
    ];
    for (s, kind, exact_normals) in cases {
        let levels = 2;
        let limit = s.limit(levels).unwrap();
        let by_vertex = samples_by_vertex(&s, kind, levels);
        // The base mesh's vertices keep their numbers on every level.
        let base_vertices = if s.mesh().faces().all(|f| f.len() == 4) || kind.is_triangle() {
            s.points().len()
        } else {
            s.hierarchy(1).unwrap().levels[1].vertex_count
        };
        for v in 0..base_vertices as u32 {
            let samples = &by_vertex[&v];
            for &(p, n) in samples {
                let exact = limit.positions[v as usize];
                assert!(
                    p.distance(exact) < 1e-12,
                    "{kind:?} vertex {v}: {p} vs {exact}"
                );
                if exact_normals {
                    let angle = degrees(n, limit.normals[v as usize]);
                    assert!(angle < 1e-6, "{kind:?} vertex {v}: normal off by {angle}°");
                }
            }
        }
    }
}

#[test]
fn neighbouring_patches_share_positions_and_normals() {
    let cases = [
        (skewed_cube(), SubstituteKind::Acc),
        (skewed_cube(), SubstituteKind::Gregory),
        (icosahedron(Scheme::Loop), SubstituteKind::PnTriangle),
        (icosahedron(Scheme::CatmullClark), SubstituteKind::Acc),
    ];
    for (s, kind) in cases {
        let by_vertex = samples_by_vertex(&s, kind, 3);
        let mut shared = 0;
        for (v, samples) in &by_vertex {
            let (p0, n0) = samples[0];
            for &(p, n) in &samples[1..] {
                shared += 1;
                assert!(p.distance(p0) < 1e-12, "{kind:?} vertex {v}: {p} vs {p0}");
                let angle = degrees(n, n0);
                assert!(angle < 1e-6, "{kind:?} vertex {v}: normals {angle}° apart");
            }
        }
        assert!(shared >= 50, "{kind:?}: only {shared} shared samples");
    }
}

#[test]
fn substitutes_stay_close_to_the_exact_limit() {
    let cases = [
        (skewed_cube(), SubstituteKind::Acc),
        (skewed_cube(), SubstituteKind::Gregory),
        (icosahedron(Scheme::CatmullClark), SubstituteKind::Acc),
        (icosahedron(Scheme::CatmullClark), SubstituteKind::Gregory),
        (icosahedron(Scheme::Loop), SubstituteKind::PnTriangle),
    ];
    for (s, kind) in cases {
        let error = s.substitute_error(kind, 4, true).unwrap();
        eprintln!("{kind:?}: {error:?}");
        assert!(error.samples > 0);
        // Not the exact limit, but close: a few percent of the size at most, normals within
        // a few degrees on average.
        assert!(error.max_distance > 1e-6, "{kind:?}: suspiciously exact");
        assert!(error.max_distance < 0.03, "{kind:?}: {error:?}");
        assert!(error.mean_normal_degrees < 5.0, "{kind:?}: {error:?}");
    }
}

#[test]
fn boundary_faces_keep_the_exact_limit() {
    let cylinder = surface(
        cages::cylinder(DVec3::ZERO, 1.0, 2.0, 5, 4).unwrap(),
        Scheme::CatmullClark,
    );
    let (feed, plan) = cylinder
        .substitute_feed(2, SubstituteKind::Gregory, true)
        .unwrap();
    // 5 × 4 quads: the two rows along the boundary stay exact, the middle rows' faces have
    // valence-4 corners (regular: B-spline), so nothing is left for a substitute.
    assert_eq!(plan.exact.len(), 10);
    assert_eq!(feed.patches.len(), 10);
    assert_eq!(feed.regular.len() + feed.substitutes.len(), 10);
}

#[test]
fn a_substitute_of_another_scheme_is_refused() {
    let loop_cage = icosahedron(Scheme::Loop);
    let refused = SubdivObject::checked(loop_cage.clone(), Display::Acc).unwrap_err();
    assert!(
        refused.to_string().contains("approximate Catmull-Clark"),
        "{refused}"
    );
    assert!(SubdivObject::checked(loop_cage, Display::PnTriangles).is_ok());
    let cube = skewed_cube();
    assert!(SubdivObject::checked(cube.clone(), Display::PnTriangles).is_err());
    // Moving the cage moves the substitute with it (affine invariance of the averages).
    let shift = DAffine3::from_translation(DVec3::new(1.0, -2.0, 0.5));
    let moved = cube.transformed(&shift).unwrap();
    let a = samples_by_vertex(&cube, SubstituteKind::Gregory, 2);
    let b = samples_by_vertex(&moved, SubstituteKind::Gregory, 2);
    for (v, samples) in &a {
        let p = samples[0].0 + DVec3::new(1.0, -2.0, 0.5);
        assert!(p.distance(b[v][0].0) < 1e-12);
    }
}

/// The `v` lines of an OBJ file.
fn obj_vertices(text: &str) -> Vec<DVec3> {
    text.lines()
        .filter_map(|l| l.strip_prefix("v "))
        .map(|l| {
            let c: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            DVec3::new(c[0], c[1], c[2])
        })
        .collect()
}

#[test]
fn the_subdivide_command_writes_substitutes_on_both_backends() {
    let dir = crate::common::scratch_dir("substitutes-subdivide");
    let cube = skewed_cube();
    let faces: Vec<&[u32]> = cube.mesh().faces().collect();
    let input = dir.join("cube.obj");
    std::fs::write(&input, knotwork::io::obj::write(cube.points(), &[], &faces)).unwrap();
    let run = |args: &[&str]| common::run_subdivide(&input, args);
    let expected = cube.substitute_mesh(2, SubstituteKind::Gregory).unwrap();
    for backend in ["cpu", "gpu"] {
        let out = dir.join(format!("{backend}.obj"));
        let done = run(&[
            "--levels",
            "2",
            "--substitute",
            "gregory",
            "--backend",
            backend,
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(
            done.status.success(),
            "{}",
            String::from_utf8_lossy(&done.stderr)
        );
        let text = std::fs::read_to_string(&out).unwrap();
        let written = obj_vertices(&text);
        assert_eq!(written.len(), expected.positions.len());
        assert_eq!(
            text.lines().filter(|l| l.starts_with("vn ")).count(),
            written.len()
        );
        // Relative to the cube's diagonal (edge 2): f64 text, or the compute shaders' f32.
        let tolerance = if backend == "cpu" { 1e-12 } else { 1e-5 } * 2.0 * 3f64.sqrt();
        for (w, e) in written.iter().zip(&expected.positions) {
            assert!(w.distance(*e) < tolerance, "{backend}: {w} vs {e}");
        }
    }
    let refused = run(&[
        "--levels",
        "2",
        "--substitute",
        "pn-triangles",
        "-o",
        "x.obj",
    ]);
    assert_eq!(refused.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&refused.stderr).contains("approximate Loop"));
    std::fs::remove_dir_all(&dir).ok();
}
