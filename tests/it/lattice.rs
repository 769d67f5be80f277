//! Free-form deformation (Sederberg & Parry) against analytic values and the f64 kernel: a
//! lattice that scales space by 2 doubles a sphere's radius and halves its curvature on the
//! compute shaders and the CPU evaluator; a bent lattice moves every kind's vertices to the
//! kernel's deformed points; dragging a lattice point uploads only the lattice and gives the
//! vertices of a full evaluation; baking is exact (composed patches equal the live
//! deformation) where the degree allows and refitted within the tolerance elsewhere; the
//! document undoes it all, the project keeps the lattice and refuses bad ones, the export
//! writes the deformed surface.

use crate::common;

use glam::DVec3;
use knotwork::doc::create::{Primitive, PrimitiveParams};
use knotwork::doc::{Command, Document, Touched};
use knotwork::gpu::{SceneSync, SurfaceVertex};
use knotwork::io::project::{self, Project};
use knotwork::kernel::diffgeo::{CurvatureValues, FundamentalForms};
use knotwork::kernel::ffd::{Baked, Lattice};
use knotwork::kernel::tess::Tessellation;
use knotwork::kernel::{NurbsSurface, samples};
use knotwork::scene::{ObjectGeometry, Scene, SceneObject, SubdivObject};

/// The vertices of `scene` as the compute shaders (or the CPU evaluator) write them.
fn vertices(scene: &Scene, cpu: bool) -> (SceneSync, Vec<SurfaceVertex>) {
    common::evaluate_scene(scene, cpu)
}

/// A lattice of `degrees` around `object` with three of its points pushed (not an affine map).
fn bent_lattice(object: &SceneObject, degrees: [usize; 3]) -> Lattice {
    let (lo, hi) = object.kind().bounds().unwrap();
    let mut lattice = Lattice::around(lo, hi, degrees).unwrap();
    let size = (hi - lo).length();
    let [l, m, n] = degrees;
    for (index, push) in [
        (
            lattice.point_index(l, m, n),
            DVec3::new(0.15, -0.1, 0.2) * size,
        ),
        (
            lattice.point_index(0, m, 0),
            DVec3::new(-0.1, 0.1, 0.05) * size,
        ),
        (
            lattice.point_index(l / 2 + 1, 0, n / 2),
            DVec3::new(0.05, 0.0, -0.12) * size,
        ),
    ] {
        let p = lattice.points()[index];
        lattice.set_point(index, p + push).unwrap();
    }
    lattice
}

fn size(object: &SceneObject) -> f64 {
    let (lo, hi) = object.kind().bounds().unwrap();
    (hi - lo).length()
}

#[test]
fn a_lattice_that_scales_space_doubles_a_sphere_and_halves_its_curvature() {
    let mut sphere = PrimitiveParams {
        kind: Primitive::Sphere,
        ..Default::default()
    }
    .build()
    .unwrap();
    sphere.segments = 12;
    let (lo, hi) = sphere.kind().bounds().unwrap();
    let centre = 0.5 * (lo + hi);
    let radius = 0.5 * (hi.x - lo.x);
    let base = Lattice::around(lo, hi, [2, 3, 1]).unwrap();
    let scaled: Vec<DVec3> = base
        .points()
        .iter()
        .map(|&p| centre + 2.0 * (p - centre))
        .collect();
    sphere.lattice =
        Some(Lattice::new(base.origin(), base.axes(), base.degrees(), scaled).unwrap());
    let scene = Scene {
        objects: vec![sphere],
        unit: None,
    };
    let r = 2.0 * radius;
    for cpu in [false, true] {
        let (_, vs) = vertices(&scene, cpu);
        let (mut worst_p, mut worst_n, mut worst_k) = (0.0f64, 0.0f64, 0.0f64);
        let mut with_curvature = 0;
        for v in &vs {
            let p = DVec3::from(v.position.map(f64::from)) - centre;
            worst_p = worst_p.max((p.length() - r).abs() / r);
            let n = DVec3::from(v.normal.map(f64::from));
            worst_n = worst_n.max(n.angle_between(p.normalize()).min(n.angle_between(-p)));
            if v.flags() & 2 == 0 {
                with_curvature += 1;
                // K = 1 / r², |H| = 1 / r on the sphere of radius r.
                worst_k = worst_k
                    .max((f64::from(v.curvature()[0]) * r * r - 1.0).abs())
                    .max((f64::from(v.curvature()[1]).abs() * r - 1.0).abs());
            }
        }
        eprintln!(
            "scaled sphere (cpu {cpu}): radius {worst_p:.1e}, normal {:.1e}°, curvature {worst_k:.1e} over {with_curvature} vertices",
            worst_n.to_degrees()
        );
        assert!(worst_p < 2e-6, "cpu {cpu}: {worst_p:e}");
        assert!(worst_n.to_degrees() < 0.01, "cpu {cpu}: {worst_n}");
        assert!(with_curvature > vs.len() / 2, "cpu {cpu}");
        assert!(worst_k < 2e-3, "cpu {cpu}: {worst_k:e}");
    }
}

/// One object of every kind.
fn every_kind() -> Vec<SceneObject> {
    let mut teapot = SceneObject::new(
        "teapot",
        ObjectGeometry::new(samples::utah_teapot().unwrap()),
    );
    teapot.segments = 4;
    let mut nurbs = SceneObject::new(
        "rational (3, 2)",
        ObjectGeometry::new(common::random_surface(3, 2, 2026)),
    );
    nurbs.segments = 7;
    let mut mesh = SceneObject::new("mesh", ObjectGeometry::new(common::grid_mesh(4)));
    mesh.segments = 3;
    let build = |kind, degree| {
        PrimitiveParams {
            kind,
            degree,
            ..Default::default()
        }
        .build()
        .unwrap()
    };
    let cage = build(Primitive::CageCube, [3, 3]);
    let triangle = build(Primitive::TriangleBezier, [3, 3]);
    let mut trimmed = common::trimmed_ellipse_object("trimmed");
    trimmed.segments = 6;
    vec![teapot, nurbs, mesh, cage, triangle, trimmed]
}

#[test]
fn every_kind_follows_a_bent_lattice_on_both_evaluators() {
    for mut object in every_kind() {
        let lattice = bent_lattice(&object, [2, 2, 3]);
        object.lattice = Some(lattice.clone());
        let scale = size(&object);
        let name = object.name.clone();
        let scene = Scene {
            objects: vec![object.clone()],
            unit: None,
        };
        for cpu in [false, true] {
            let (sync, vs) = vertices(&scene, cpu);
            let mut worst = 0.0f64;
            let mut checked = 0;
            for (k, record) in sync.records().unwrap().iter().enumerate() {
                if record.trim_count == knotwork::gpu::trim_buffer::TRIM_CULLED {
                    continue;
                }
                let n = record.segments_u as usize;
                for i in 0..=n {
                    for j in 0..=n {
                        let (s, t) = (i as f64 / n as f64, j as f64 / n as f64);
                        let exact =
                            lattice.deform_point(object.kind().surface_point(k, s, t).unwrap());
                        let v = vs[record.vertex_offset as usize + i * (n + 1) + j];
                        worst = worst.max(DVec3::from(v.position.map(f64::from)).distance(exact));
                        checked += 1;
                    }
                }
            }
            eprintln!(
                "{name} (cpu {cpu}): {checked} vertices, GPU vs f64 {:.1e} of its size",
                worst / scale
            );
            assert!(checked > 50, "{name}");
            assert!(worst <= 1e-5 * scale, "{name} cpu {cpu}: {worst:e}");
        }
    }
}

#[test]
fn the_deformed_normal_and_curvature_match_the_kernel() {
    let mut object = SceneObject::new(
        "sheet",
        ObjectGeometry::new(common::random_surface(3, 3, 11)),
    );
    object.segments = 8;
    let lattice = bent_lattice(&object, [3, 1, 2]);
    object.lattice = Some(lattice.clone());
    let scene = Scene {
        objects: vec![object.clone()],
        unit: None,
    };
    let (sync, vs) = vertices(&scene, false);
    let feed = &sync.feeds()[0];
    let (mut worst_n, mut worst_h, mut checked) = (0.0f64, 0.0f64, 0);
    for (k, record) in sync.records().unwrap().iter().enumerate() {
        let n = record.segments_u as usize;
        for i in 1..n {
            for j in 1..n {
                let (s, t) = (i as f64 / n as f64, j as f64 / n as f64);
                let d = feed.set.evaluate(k, s, t).unwrap();
                let Some(normal) = d.regular_normal() else {
                    continue;
                };
                let normal = lattice.deform_normal(d.point, normal);
                let deformed = lattice.deform(&d);
                let v = vs[record.vertex_offset as usize + i * (n + 1) + j];
                let gpu_n = DVec3::from(v.normal.map(f64::from));
                worst_n = worst_n.max(gpu_n.angle_between(normal).to_degrees());
                let Some(c) =
                    CurvatureValues::from_forms(&FundamentalForms::new(&deformed, normal))
                else {
                    continue;
                };
                if v.flags() & 2 == 0 {
                    let scale = c.mean.abs().max(c.k1.abs()).max(c.k2.abs()).max(1e-3);
                    worst_h = worst_h.max((f64::from(v.curvature()[1]) - c.mean).abs() / scale);
                    checked += 1;
                }
            }
        }
    }
    eprintln!(
        "bent sheet: normal {worst_n:.1e}°, mean curvature {worst_h:.1e} relative, {checked} vertices"
    );
    assert!(checked > 100);
    assert!(worst_n < 0.02, "{worst_n}°");
    assert!(worst_h < 1e-2, "{worst_h:e}");
}

#[test]
fn dragging_a_lattice_point_uploads_only_the_lattice() {
    let mut teapot = SceneObject::new(
        "teapot",
        ObjectGeometry::new(samples::utah_teapot().unwrap()),
    );
    teapot.segments = 4;
    teapot.lattice = Some(bent_lattice(&teapot, [1, 1, 1]));
    let mut doc = Document::new(Scene {
        objects: vec![teapot],
        unit: None,
    });
    for cpu in [false, true] {
        let (mut sync, before) = vertices(&doc.scene, cpu);
        let corner = 7;
        doc.begin_drag(0, &[corner]).unwrap();
        for step in 1..=3 {
            let moved = doc
                .drag_by(DVec3::new(0.1, 0.2, -0.1) * f64::from(step))
                .unwrap();
            assert!(moved.patches.is_empty(), "no patch of the feed changes");
            let uploaded = sync.points_moved(&doc.scene, &moved).unwrap();
            assert_eq!(uploaded, 0, "no control point is uploaded");
            let evaluated = sync.evaluate_blocking().unwrap();
            assert_eq!(evaluated, 32, "every patch follows the lattice");
        }
        let dragged = sync.read_vertices().unwrap();
        let (_, full) = vertices(&doc.scene, cpu);
        assert!(
            dragged == full,
            "cpu {cpu}: incremental and full evaluation differ"
        );
        assert!(dragged != before);
        doc.commit_drag().unwrap();
        let touched = doc.undo().unwrap().touched();
        assert_eq!(touched, Touched::Points(0));
        sync.apply(&doc.scene, touched, 1.0).unwrap();
        sync.evaluate_blocking().unwrap();
        assert!(sync.read_vertices().unwrap() == before, "cpu {cpu}: undo");
    }
}

/// The largest distance between the baked object's surface and the live deformation, at a
/// grid of each feed patch's parameters (the bake keeps the parametrization).
fn bake_deviation(object: &SceneObject, baked: &SceneObject) -> f64 {
    let lattice = object.lattice.as_ref().unwrap();
    let feed = object.decompose().unwrap();
    let after = baked.decompose().unwrap();
    let mut worst = 0.0f64;
    let nurbs = |g: &ObjectGeometry| g.downcast_ref::<knotwork::kernel::NurbsSurface>().cloned();
    match (nurbs(&object.geometry), nurbs(&baked.geometry)) {
        (Some(a), Some(b)) => {
            let [(u0, u1), (v0, v1)] = a.domain();
            for i in 0..=13 {
                for j in 0..=13 {
                    let u = u0 + (u1 - u0) * i as f64 / 13.0;
                    let v = v0 + (v1 - v0) * j as f64 / 13.0;
                    let exact = lattice.deform_point(a.point_at(u, v).unwrap());
                    worst = worst.max(b.point_at(u, v).unwrap().distance(exact));
                }
            }
        }
        _ => {
            // Patch sets composed exactly keep one patch per patch.
            assert_eq!(feed.set.patches().len(), after.set.patches().len());
            for k in 0..feed.set.patches().len() {
                for (s, t) in [(0.1, 0.2), (0.5, 0.5), (0.9, 0.3), (1.0, 0.0)] {
                    let exact = lattice.deform_point(feed.set.evaluate(k, s, t).unwrap().point);
                    let got = after.set.evaluate(k, s, t).unwrap().point;
                    worst = worst.max(got.distance(exact));
                }
            }
        }
    }
    worst
}

#[test]
fn baking_is_exact_where_the_degree_allows_and_refitted_elsewhere() {
    // A bicubic B-spline sheet (4 × 3 spans) through a trilinear lattice: degree 9, exact.
    let mut sheet = SceneObject::new(
        "sheet",
        ObjectGeometry::new(common::random_surface(3, 3, 5)),
    );
    sheet.lattice = Some(bent_lattice(&sheet, [1, 1, 1]));
    let (baked, how) = sheet.baked_lattice(1e-4).unwrap();
    assert!(matches!(how, Baked::Exact { degree: [9, 9] }), "{how:?}");
    assert!(baked.lattice.is_none());
    let worst = bake_deviation(&sheet, &baked);
    eprintln!("exact bake: {worst:.1e} ({})", how.describe());
    assert!(worst < 1e-9 * size(&sheet), "{worst:e}");
    // The joints keep the continuity they had: the knots come back down from multiplicity 9.
    let Some(surface) = baked
        .geometry
        .downcast_ref::<knotwork::kernel::NurbsSurface>()
    else {
        panic!("a NURBS surface bakes to a NURBS surface");
    };
    let Some(original) = sheet
        .geometry
        .downcast_ref::<knotwork::kernel::NurbsSurface>()
    else {
        unreachable!()
    };
    let joints = |s: &NurbsSurface| s.knots()[0].len() - 2 * (s.degree()[0] + 1);
    assert!(
        joints(surface) < 9 * joints(original),
        "{} interior knots",
        joints(surface)
    );

    // A smooth bicubic sheet through a (2, 1, 1) lattice: degree 12 would be too high:
    // refitted.
    let m = 6;
    let points = (0..m * m)
        .map(|k| {
            let (i, j) = ((k / m) as f64, (k % m) as f64);
            DVec3::new(i, j, 0.4 * (0.8 * i).sin() * (0.6 * j).cos())
        })
        .collect();
    let knots = vec![0.0, 0.0, 0.0, 0.0, 1.0, 2.0, 3.0, 3.0, 3.0, 3.0];
    let mut sheet = SceneObject::new(
        "smooth sheet",
        ObjectGeometry::new(
            NurbsSurface::new([3, 3], [knots.clone(), knots], [m, m], points, None).unwrap(),
        ),
    );
    sheet.lattice = Some(bent_lattice(&sheet, [2, 1, 1]));
    let tolerance = 1e-4;
    let (baked, how) = sheet.baked_lattice(tolerance).unwrap();
    let Baked::Refit { error, within, .. } = how else {
        panic!("{how:?}");
    };
    let worst = bake_deviation(&sheet, &baked);
    eprintln!("refit bake: {worst:.1e} ({})", how.describe());
    assert!(within && error <= tolerance * size(&sheet));
    assert!(worst <= 2.0 * tolerance * size(&sheet), "{worst:e}");

    // The teapot's bicubic patches through a trilinear lattice: exact, patch by patch.
    let mut teapot = SceneObject::new(
        "teapot",
        ObjectGeometry::new(samples::utah_teapot().unwrap()),
    );
    teapot.lattice = Some(bent_lattice(&teapot, [1, 1, 1]));
    let (baked, how) = teapot.baked_lattice(1e-4).unwrap();
    assert!(matches!(how, Baked::Exact { degree: [9, 9] }), "{how:?}");
    let worst = bake_deviation(&teapot, &baked);
    assert!(worst < 1e-9 * size(&teapot), "{worst:e}");
    // Through a (2, 2, 1) lattice: refitted by bicubic cells within the tolerance.
    teapot.lattice = Some(bent_lattice(&teapot, [2, 2, 1]));
    let (baked, how) = teapot.baked_lattice(1e-3).unwrap();
    assert!(matches!(how, Baked::Refit { within: true, .. }), "{how:?}");
    let Some(set) = baked
        .geometry
        .downcast_ref::<knotwork::kernel::BezierPatchSet>()
    else {
        panic!()
    };
    assert!(
        set.patches()
            .iter()
            .all(|p| p.degree_u() == 3 && p.degree_v() == 3)
    );

    // A triangular patch of degree 3 through a trilinear lattice: degree 9, exact.
    let mut triangle = PrimitiveParams {
        kind: Primitive::TriangleBezier,
        degree: [3, 3],
        ..Default::default()
    }
    .build()
    .unwrap();
    let lattice = bent_lattice(&triangle, [1, 1, 1]);
    triangle.lattice = Some(lattice.clone());
    let (baked, how) = triangle.baked_lattice(1e-4).unwrap();
    assert!(matches!(how, Baked::Exact { degree: [9, 9] }), "{how:?}");
    for (k, (s, t)) in [(0.2, 0.3), (0.5, 0.1), (0.0, 1.0)].into_iter().enumerate() {
        let exact = lattice.deform_point(triangle.kind().surface_point(0, s, t).unwrap());
        let got = baked.kind().surface_point(0, s, t).unwrap();
        assert!(got.distance(exact) < 1e-8 * size(&triangle), "sample {k}");
    }

    // A grid cage: its limit surface passes through the deformed limit points of its
    // vertices (solved directly: the limit-position map of a regular grid is invertible).
    let surface =
        knotwork::kernel::subdiv::SubdivisionSurface::from_mesh(common::grid_mesh(5), 2).unwrap();
    let mut cage = SceneObject::new(
        "grid cage",
        ObjectGeometry::new(SubdivObject::from(surface)),
    );
    let lattice = bent_lattice(&cage, [1, 1, 1]);
    cage.lattice = Some(lattice.clone());
    let (baked, how) = cage.baked_lattice(1e-2).unwrap();
    eprintln!("cage bake: {}", how.describe());
    let subdivision = |g: &ObjectGeometry| g.downcast_ref::<SubdivObject>().cloned();
    let (Some(before), Some(after)) = (subdivision(&cage.geometry), subdivision(&baked.geometry))
    else {
        panic!()
    };
    let target = before.surface.limit(0).unwrap().positions;
    let got = after.surface.limit(0).unwrap().positions;
    for (t, g) in target.iter().zip(&got) {
        assert!(lattice.deform_point(*t).distance(*g) < 1e-9 * size(&cage));
    }
    assert!(matches!(how, Baked::Points { error, .. } if error > 0.0));
    // A cube's limit-position map is singular (its alternating mode vanishes): the best the
    // iteration reaches is reported, not hidden.
    let mut cube = PrimitiveParams {
        kind: Primitive::CageCube,
        ..Default::default()
    }
    .build()
    .unwrap();
    cube.lattice = Some(bent_lattice(&cube, [1, 1, 1]));
    let (_, how) = cube.baked_lattice(1e-2).unwrap();
    eprintln!("cube bake: {}", how.describe());
    assert!(matches!(how, Baked::Points { error, .. } if error > 0.0 && error.is_finite()));
}

#[test]
fn the_document_undoes_lattices_and_the_project_keeps_them() {
    let mut sheet = SceneObject::new(
        "sheet",
        ObjectGeometry::new(common::random_surface(2, 2, 9)),
    );
    sheet.segments = 6;
    let mut doc = Document::new(Scene {
        objects: vec![sheet.clone()],
        unit: None,
    });
    let (lo, hi) = sheet.kind().bounds().unwrap();
    let lattice = Lattice::around(lo, hi, [2, 1, 1]).unwrap();
    let edit = doc
        .execute(&Command::SetLattice {
            objects: vec![0],
            lattice: Some(lattice.clone()),
        })
        .unwrap();
    assert_eq!(edit.touched(), Touched::Object(0));
    // Its handles are the lattice's points now.
    assert_eq!(doc.scene.objects[0].control_point_count(), 12);
    assert!(doc.scene.objects[0].set_weight(0, 2.0).is_err());
    let moved = lattice.points()[5] + DVec3::new(0.0, 0.0, 0.5);
    doc.execute(&Command::MovePoints {
        object: 0,
        moves: vec![(5, moved)],
    })
    .unwrap();
    assert_eq!(doc.scene.objects[0].control_points()[5], moved);

    // Save and reopen keeps it; a broken lattice in a file is refused with the field named.
    let text = project::write(&Project {
        scene: doc.scene.clone(),
        view: None,
    });
    assert_eq!(project::read(&text).unwrap().scene, doc.scene);
    let broken = text.replacen("\"degrees\":[2,1,1]", "\"degrees\":[2,1,9]", 1);
    assert_ne!(broken, text, "the project names the degrees");
    let error = project::read(&broken).unwrap_err().to_string();
    assert!(error.contains("lattice"), "{error}");

    // The export writes the deformed surface.
    let object = &doc.scene.objects[0];
    let meshes = object
        .tessellate(Tessellation::Tolerance(1e-3), false)
        .unwrap();
    let plain = SceneObject {
        lattice: None,
        ..object.clone()
    }
    .tessellate(Tessellation::Segments(object.segments), false)
    .unwrap();
    let deformed = object.lattice.as_ref().unwrap();
    for (a, b) in meshes.iter().zip(&plain) {
        for (p, q) in a.positions.iter().zip(&b.positions) {
            assert!(p.distance(deformed.deform_point(*q)) < 1e-12);
        }
    }

    // Apply: one undo step whose label says how it went; undo brings the lattice back.
    let label = doc
        .execute(&Command::ApplyLattice {
            object: 0,
            tolerance: 1e-4,
        })
        .unwrap()
        .label
        .clone();
    assert!(label.starts_with("apply lattice: exact"), "{label}");
    assert!(doc.scene.objects[0].lattice.is_none());
    doc.undo().unwrap();
    assert!(doc.scene.objects[0].lattice.is_some());
    // Release: the undeformed sheet again; undo and redo walk back and forth.
    doc.execute(&Command::SetLattice {
        objects: vec![0],
        lattice: None,
    })
    .unwrap();
    assert_eq!(doc.scene.objects[0], sheet);
    doc.undo().unwrap();
    doc.undo().unwrap();
    doc.undo().unwrap();
    assert_eq!(doc.scene.objects[0], sheet);
    // Nothing to apply without a lattice, and a displaced object is refused: nothing changes.
    let before = doc.scene.clone();
    assert!(
        doc.execute(&Command::ApplyLattice {
            object: 0,
            tolerance: 1e-4
        })
        .is_err()
    );
    assert_eq!(doc.scene, before);
}

#[test]
fn objects_sharing_a_lattice_move_together() {
    // Two sheets side by side in one lattice.
    let sheet = |name: &str, x: f64| {
        let points = vec![
            DVec3::new(x, 0.0, 0.0),
            DVec3::new(x, 1.0, 0.1),
            DVec3::new(x + 1.0, 0.0, 0.2),
            DVec3::new(x + 1.0, 1.0, 0.0),
        ];
        let mut object = SceneObject::new(
            name,
            ObjectGeometry::new(NurbsSurface::bezier([1, 1], points, None).unwrap()),
        );
        object.segments = 8;
        object
    };
    let mut doc = Document::new(Scene {
        objects: vec![sheet("left", 0.0), sheet("right", 1.5)],
        unit: None,
    });
    let original = doc.scene.clone();
    let (lo, hi) = doc.scene.bounds().unwrap();
    let group = doc.scene.new_lattice_group();
    let lattice = Lattice::around(lo, hi, [2, 1, 1])
        .unwrap()
        .with_group(group);
    doc.execute(&Command::SetLattice {
        objects: vec![0, 1],
        lattice: Some(lattice.clone()),
    })
    .unwrap();
    assert_eq!(doc.scene.linked_lattices(0), [0, 1]);
    assert_eq!(doc.scene.linked_lattices(1), [0, 1]);
    // A lattice of another group is not shared even on the same box.
    assert_ne!(doc.scene.new_lattice_group(), group);

    // A drag of a point of the left sheet's lattice moves the right sheet's copy too; the GPU
    // uploads both lattices and evaluates both as a full evaluation would.
    for cpu in [false, true] {
        let (mut sync, before) = vertices(&doc.scene, cpu);
        doc.begin_drag(0, &[4]).unwrap();
        let moved = doc.drag_by(DVec3::new(0.0, 0.3, 0.8)).unwrap();
        assert_eq!(moved.linked, [1]);
        assert_eq!(doc.scene.objects[0].lattice, doc.scene.objects[1].lattice);
        assert_eq!(sync.points_moved(&doc.scene, &moved).unwrap(), 0);
        sync.evaluate_blocking().unwrap();
        let dragged = sync.read_vertices().unwrap();
        let (_, full) = vertices(&doc.scene, cpu);
        assert!(dragged == full, "cpu {cpu}: both objects follow");
        assert!(dragged != before);
        // Cancelled: both come back.
        doc.cancel_drag();
        assert_eq!(doc.scene.objects[0].lattice, Some(lattice.clone()));
        assert_eq!(doc.scene.objects[1].lattice, Some(lattice.clone()));
    }
    doc.begin_drag(1, &[4]).unwrap();
    doc.drag_by(DVec3::new(0.0, 0.0, 0.5)).unwrap();
    let edit = doc.commit_drag().unwrap();
    assert_eq!(edit.changes.len(), 2, "one undo step for both objects");
    assert_eq!(doc.scene.linked_lattices(0), [0, 1]);
    // A scripted move of the right sheet's lattice moves the left one's.
    let target = doc.scene.objects[1].control_points()[0] + DVec3::new(-0.2, 0.0, 0.0);
    doc.execute(&Command::MovePoints {
        object: 1,
        moves: vec![(0, target)],
    })
    .unwrap();
    assert_eq!(doc.scene.objects[0].control_points()[0], target);
    // The project keeps the sharing.
    let text = project::write(&Project {
        scene: doc.scene.clone(),
        view: None,
    });
    let reopened = project::read(&text).unwrap().scene;
    assert_eq!(reopened, doc.scene);
    assert_eq!(reopened.linked_lattices(1), [0, 1]);
    // Apply bakes both, saying how for each.
    let label = doc
        .execute(&Command::ApplyLattice {
            object: 0,
            tolerance: 1e-4,
        })
        .unwrap()
        .label
        .clone();
    assert!(
        label.contains("left: exact") && label.contains("right: exact"),
        "{label}"
    );
    assert!(doc.scene.objects.iter().all(|o| o.lattice.is_none()));
    doc.undo().unwrap();
    // Release takes the lattice off both; undoing everything gives the original scene.
    doc.execute(&Command::SetLattice {
        objects: doc.scene.linked_lattices(0),
        lattice: None,
    })
    .unwrap();
    assert!(doc.scene.objects.iter().all(|o| o.lattice.is_none()));
    while doc.undo().is_ok() {}
    assert_eq!(doc.scene, original);
}
