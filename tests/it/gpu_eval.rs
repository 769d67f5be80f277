//! The compute evaluator on a real wgpu device (lavapipe in CI) against the f64 kernel:
//! positions, normals and curvature of every object kind, watertight seams, incremental updates
//! and refused requests.

use crate::common;

use std::collections::{BTreeSet, HashMap};

use glam::DVec3;
use knotwork::doc::Document;
use knotwork::gpu::records::{VERTEX_IRREGULAR, VERTEX_NO_CURVATURE};
use knotwork::gpu::{
    GpuContext, GpuError, MAX_SEGMENTS, PatchGeometry, PatchRecord, SceneSync, SurfaceVertex,
};
use knotwork::kernel::diffgeo::{CurvatureValues, FundamentalForms};
use knotwork::kernel::{BezierPatch, BezierPatchSet, Direction, NurbsSurface, construct};
use knotwork::scene::{Decomposition, ObjectGeometry, Scene, SceneObject};

/// Largest deviations of one object's GPU vertices from the f64 reference.
#[derive(Debug, Default)]
struct Deviation {
    /// |p_gpu − p| / size.
    position: f64,
    /// Angle between the normals, radians.
    normal_angle: f64,
    /// max over K, H, k1, k2 of |k_gpu − k| · size / max(1, |k| · size), at regular points.
    curvature: f64,
    /// |(u, v)_gpu − (u, v)| / domain size.
    parameter: f64,
    /// Vertices compared, and of them those whose curvature was compared.
    vertices: usize,
    curvature_checked: usize,
    /// Where the worst normal and curvature deviations are: (patch, i, j).
    worst_normal_at: (usize, usize, usize),
    worst_curvature_at: (usize, usize, usize),
}

/// The f64 reference at local (s, t) of patch k of `object`: point, normal, curvature, the
/// parameter in the object's domain, and sin² of the angle between Su and Sv (0 where one of
/// them vanishes).
struct Reference {
    point: DVec3,
    normal: DVec3,
    curvature: Option<CurvatureValues>,
    uv: [f64; 2],
    sin2: f64,
}

/// Away from degenerate points, where normals and curvature are compared: sin² of the angle
/// between Su and Sv above these. In f32 the normal's direction error grows as ε/sin and the
/// curvature's as ε/sin², so the limits leave 1e-3 rad and 1e-3 relative ample room.
const NORMAL_SIN2: f64 = 1e-6;
const CURVATURE_SIN2: f64 = 1e-4;

/// The f64 reference of one object, independent of the Bézier decomposition the GPU is fed: a
/// NURBS object is evaluated on its own knots and points (The NURBS Book A3.6/A4.4), a patch set
/// patch by patch, a polygon mesh as the bilinear patches it is drawn as.
enum ReferenceSurface<'a> {
    Patches(std::borrow::Cow<'a, BezierPatchSet>),
    /// The surface and its span rectangles, in the order of the GPU's patches.
    Nurbs(&'a NurbsSurface, Vec<[f64; 4]>),
}

/// How far inside its span a NURBS reference point is taken, in span fractions: a span's edge
/// at a C0 or C1 knot is then evaluated from that span's side, as the GPU's patch does.
const INSIDE_SPAN: f64 = 1e-10;

impl<'a> ReferenceSurface<'a> {
    fn new(object: &'a SceneObject) -> Self {
        let geometry = &object.geometry;
        if let Some(set) = geometry.downcast_ref::<knotwork::kernel::BezierPatchSet>() {
            Self::Patches(std::borrow::Cow::Borrowed(set))
        } else if let Some(mesh) = geometry.downcast_ref::<knotwork::kernel::PolygonMesh>() {
            Self::Patches(std::borrow::Cow::Owned(mesh.to_bezier_patch_set().unwrap()))
        } else {
            match geometry.nurbs_surface() {
                // Their feeds' Bézier patches (a triangular patch has none: only stencils).
                None => Self::Patches(std::borrow::Cow::Owned(object.decompose().unwrap().set)),
                Some(surface) => {
                    let bu = surface.span_breaks(Direction::U);
                    let bv = surface.span_breaks(Direction::V);
                    let spans = bu
                        .windows(2)
                        .flat_map(|a| bv.windows(2).map(move |b| [a[0], a[1], b[0], b[1]]))
                        .collect();
                    Self::Nurbs(surface, spans)
                }
            }
        }
    }
}

fn reference(surface: &ReferenceSurface<'_>, k: usize, s: f64, t: f64) -> Reference {
    let (d, normal, curvature, [u, v]) = match surface {
        ReferenceSurface::Patches(set) => {
            let d = set.evaluate(k, s, t).unwrap();
            let normal = set.normal_from(&set.patches()[k], &d, s, t);
            let c = CurvatureValues::from_forms(&FundamentalForms::new(&d, normal));
            (d, normal, c, [s, t])
        }
        ReferenceSurface::Nurbs(surface, spans) => {
            let [u0, u1, v0, v1] = spans[k];
            let inside = |x: f64| x.clamp(INSIDE_SPAN, 1.0 - INSIDE_SPAN);
            let (u, v) = (u0 + (u1 - u0) * inside(s), v0 + (v1 - v0) * inside(t));
            let g = surface.local_geometry(u, v).unwrap();
            let exact = [u0 + (u1 - u0) * s, v0 + (v1 - v0) * t];
            (g.derivatives, g.normal, Some(g.curvature.values()), exact)
        }
    };
    let sin2 = if d.regular_normal().is_some() {
        d.su.cross(d.sv).length_squared() / (d.su.length_squared() * d.sv.length_squared())
    } else {
        0.0
    };
    Reference {
        point: d.point,
        normal,
        curvature,
        uv: [u, v],
        sin2,
    }
}

/// Compares object `index`'s vertices (at `segments` per span, starting at record
/// `first_record`) with the f64 reference. Panics on a non-finite value anywhere.
fn compare_object(
    object: &SceneObject,
    decomposition: &Decomposition,
    records: &[PatchRecord],
    first_record: usize,
    vertices: &[SurfaceVertex],
) -> Deviation {
    let (lo, hi) = object.bounds().unwrap();
    let size = (hi - lo).length();
    let domain_size = decomposition.domains.iter().fold(0.0f64, |m, d| {
        m.max((d[1] - d[0]).abs()).max((d[3] - d[2]).abs())
    });
    let mut worst = Deviation::default();
    let surface = ReferenceSurface::new(object);
    for k in 0..decomposition.set.patches().len() {
        let record = records[first_record + k];
        let n = record.segments_u as usize;
        for i in 0..=n {
            for j in 0..=n {
                let vertex = &vertices[record.vertex_offset as usize + i * (n + 1) + j];
                let all = vertex
                    .position
                    .iter()
                    .chain(&vertex.normal)
                    .chain(&vertex.gaussian_mean)
                    .chain([&vertex.u, &vertex.v]);
                assert!(
                    all.clone().all(|x| x.is_finite()),
                    "{} patch {k} ({i},{j}): {vertex:?}",
                    object.name
                );
                let (s, t) = (i as f64 / n as f64, j as f64 / n as f64);
                let Reference {
                    point,
                    normal,
                    curvature,
                    uv: [u, v],
                    sin2,
                } = reference(&surface, k, s, t);
                let position = DVec3::from(vertex.position.map(f64::from));
                let gpu_normal = DVec3::from(vertex.normal.map(f64::from)).normalize();
                worst.position = worst.position.max((position - point).length() / size);
                let angle = gpu_normal.dot(normal).clamp(-1.0, 1.0).acos();
                if (sin2 > NORMAL_SIN2 || sin2 == 0.0) && angle > worst.normal_angle {
                    worst.normal_angle = angle;
                    worst.worst_normal_at = (k, i, j);
                }
                worst.parameter = worst.parameter.max(
                    (f64::from(vertex.u) - u)
                        .abs()
                        .max((f64::from(vertex.v) - v).abs())
                        / domain_size,
                );
                worst.vertices += 1;
                if let Some(c) = curvature
                    && sin2 > CURVATURE_SIN2
                    && vertex.flags() & (VERTEX_IRREGULAR | VERTEX_NO_CURVATURE) == 0
                {
                    // Dimensionless: K scaled by size², H, k1 and k2 by size.
                    let exact = [c.gaussian, c.mean, c.k1, c.k2];
                    let scales = [size * size, size, size, size];
                    for ((gpu, exact), scale) in vertex.curvature().iter().zip(exact).zip(scales) {
                        let gpu = f64::from(*gpu);
                        let error = (gpu - exact).abs() * scale / (exact.abs() * scale).max(1.0);
                        if error > worst.curvature {
                            worst.curvature = error;
                            worst.worst_curvature_at = (k, i, j);
                        }
                    }
                    worst.curvature_checked += 1;
                }
            }
        }
    }
    worst
}

/// `objects` on the GPU through the editor's sync layer, evaluated by the compute shaders or
/// (`cpu`) by the CPU evaluator of the WebGL2 path; returns it and the vertices.
fn evaluate_scene(
    context: &GpuContext,
    objects: &[SceneObject],
    cpu: bool,
) -> (SceneSync, Vec<SurfaceVertex>) {
    let scene = Scene {
        objects: objects.to_vec(),
        unit: None,
    };
    let mut sync = if cpu {
        SceneSync::on_cpu(&context.device, &context.queue)
    } else {
        SceneSync::new(&context.device, &context.queue)
    };
    sync.rebuild(&scene, 1.0).unwrap();
    sync.evaluate_blocking().unwrap();
    let vertices = sync.read_vertices().unwrap();
    (sync, vertices)
}

/// Largest deviations allowed from the f64 reference: (position, normal angle, curvature,
/// parameter).
type Limits = (f64, f64, f64, f64);
/// The compute shaders, in f32.
const GPU_LIMITS: Limits = (1e-5, 1e-3, 1e-3, 1e-6);
/// The CPU evaluator: f64 rounded to f32 at the end.
const CPU_LIMITS: Limits = (1e-6, 1e-5, 1e-5, 1e-6);

fn assert_matches(objects: &[SceneObject]) {
    assert_matches_on(objects, false, GPU_LIMITS);
}

fn assert_matches_on(objects: &[SceneObject], cpu: bool, limits: Limits) {
    let context = common::gpu();
    let (sync, vertices) = evaluate_scene(&context, objects, cpu);
    let records = sync.records().unwrap();
    let (position, normal, curvature, parameter) = limits;
    for (index, (object, d)) in objects.iter().zip(sync.feeds()).enumerate() {
        let first = sync.first_patch(index).unwrap();
        let worst = compare_object(object, d, records, first, &vertices);
        eprintln!("{}: {worst:?}", object.name);
        assert!(worst.position <= position, "{}: {worst:?}", object.name);
        assert!(worst.normal_angle <= normal, "{}: {worst:?}", object.name);
        assert!(worst.curvature <= curvature, "{}: {worst:?}", object.name);
        assert!(worst.parameter <= parameter, "{}: {worst:?}", object.name);
        assert!(
            worst.curvature_checked * 10 >= worst.vertices * 8,
            "{}: curvature compared at only {} of {} vertices",
            object.name,
            worst.curvature_checked,
            worst.vertices
        );
        // Every vertex carries its object's index.
        let record = records[first];
        assert_eq!(
            vertices[record.vertex_offset as usize].object(),
            index as u32
        );
    }
}

#[test]
fn the_demo_scene_matches_the_f64_reference() {
    let mut scene = Scene::demo().unwrap();
    for (object, segments) in scene.objects.iter_mut().zip([9, 8, 8, 7, 6, 6]) {
        object.segments = segments;
    }
    assert_matches(&scene.objects);
}

/// Grids taller than one invocation's run of rows: the teapot (the bicubic pipeline, with its
/// collapsed edges) and the sphere (a general-degree pipeline, with its poles) at 40 segments,
/// 41 rows in runs of EVAL_GRID_ROWS, against the f64 reference and without cracks.
#[test]
fn grids_of_several_runs_of_rows_match_the_f64_reference() {
    let scene = Scene::demo().unwrap();
    let mut objects = [scene.objects[0].clone(), scene.objects[2].clone()];
    for object in &mut objects {
        object.segments = 40;
    }
    const { assert!(41 > knotwork::gpu::records::EVAL_GRID_ROWS) };
    assert_matches(&objects);
    assert!(assert_watertight(&objects) > 0);
}

/// The WebGL2 path's CPU evaluator writes the same vertices (to f32 rounding of the f64
/// kernel) and the same triangles as the compute shaders, in the same layout.
#[test]
fn the_cpu_evaluator_matches_the_f64_reference_and_the_compute_layout() {
    let mut scene = Scene::demo().unwrap();
    for (object, segments) in scene.objects.iter_mut().zip([9, 8, 8, 7, 6, 6]) {
        object.segments = segments;
    }
    assert_matches_on(&scene.objects, true, CPU_LIMITS);
    let context = common::gpu();
    let (gpu, gpu_vertices) = evaluate_scene(&context, &scene.objects, false);
    let (cpu, cpu_vertices) = evaluate_scene(&context, &scene.objects, true);
    assert_eq!(gpu.records(), cpu.records());
    assert_eq!(gpu_vertices.len(), cpu_vertices.len());
    let flags_apart = gpu_vertices
        .iter()
        .zip(&cpu_vertices)
        .filter(|(g, c)| g.flags() != c.flags())
        .count();
    assert!(
        flags_apart * 1000 <= gpu_vertices.len(),
        "{flags_apart} of {} vertices flagged differently",
        gpu_vertices.len()
    );
    for (g, c) in gpu_vertices.iter().zip(&cpu_vertices) {
        assert_eq!((g.object(), g.record), (c.object(), c.record));
        // The GPU interpolates (u, v) in f32: a few ulps apart.
        let close = |a: f32, b: f32| (a - b).abs() <= 1e-6 * (1.0 + b.abs());
        assert!(close(g.u, c.u) && close(g.v, c.v), "{g:?} {c:?}");
    }
    // Both through the one evaluator contract: the same counts and the same triangles.
    let (g, c) = (gpu.evaluator().unwrap(), cpu.evaluator().unwrap());
    assert_eq!(
        (g.patch_count(), g.vertex_count(), g.index_count()),
        (c.patch_count(), c.vertex_count(), c.index_count())
    );
    assert_eq!(
        (0..6).map(|k| g.first_patch(k)).collect::<Vec<_>>(),
        (0..6).map(|k| c.first_patch(k)).collect::<Vec<_>>()
    );
    let triangles = |e: &dyn knotwork::gpu::VertexEvaluator| {
        e.read_triangle_indices(&context.device, &context.queue)
    };
    assert_eq!(triangles(g).unwrap(), triangles(c).unwrap());
}

#[test]
fn a_polygon_mesh_of_triangles_quads_and_an_ngon_matches_the_f64_reference() {
    // A non-planar quad, a triangle (a collapsed bilinear patch) and a fanned hexagon.
    let points = (0..9)
        .map(|k| {
            let t = k as f64 * 0.7;
            DVec3::new(t.cos() * (1.0 + 0.1 * t), t.sin(), 0.3 * (2.0 * t).sin())
        })
        .collect();
    let faces = [vec![0, 1, 2, 3], vec![3, 4, 5], vec![0, 3, 5, 6, 7, 8]];
    let mesh = knotwork::kernel::PolygonMesh::new(points, &faces).unwrap();
    let mut object = SceneObject::new("mesh", ObjectGeometry::new(mesh));
    object.segments = 6;
    assert_matches(&[object]);
}

#[test]
fn random_rational_nurbs_of_degree_1_to_7_match_the_f64_reference() {
    let mut objects = Vec::new();
    for (k, (p, q)) in [
        (1, 1),
        (1, 3),
        (2, 2),
        (3, 3),
        (2, 5),
        (4, 4),
        (5, 3),
        (6, 6),
        (7, 7),
        (7, 2),
    ]
    .into_iter()
    .enumerate()
    {
        let surface = common::random_surface(p, q, 1000 + k as u64);
        let mut object =
            SceneObject::new(format!("random ({p}, {q})"), ObjectGeometry::new(surface));
        object.segments = 5;
        objects.push(object);
    }
    assert_matches(&objects);
}

#[test]
fn degree_nine_is_evaluated_and_degree_ten_is_refused() {
    let context = common::gpu();
    let evaluator = knotwork::gpu::PatchEvaluator::new(&context.device);
    let nine = common::random_surface(9, 9, 77);
    let object = SceneObject::new("degree 9", ObjectGeometry::new(nine));
    let mut object = object;
    object.segments = 4;
    assert_matches(std::slice::from_ref(&object));
    let ten = construct::bspline_surface(
        [10, 2],
        [11, 3],
        (0..33)
            .map(|k| DVec3::new(k as f64, (k % 3) as f64, 0.0))
            .collect(),
    )
    .unwrap();
    let d = SceneObject::new("degree 10", ObjectGeometry::new(ten))
        .decompose()
        .unwrap();
    match common::upload(&context, &evaluator, &[(&d, 4)]) {
        Err(e @ GpuError::DegreeTooHigh { degree_u: 10, .. }) => {
            assert!(e.to_string().contains("maximum 9"), "{e}")
        }
        Err(e) => panic!("unexpected error {e}"),
        Ok(_) => panic!("degree 10 must be refused"),
    }
}

/// The bits of f32 homogeneous control points.
type ControlBits = Vec<[u32; 4]>;

/// The f32 values of the control points the GPU holds for `set`.
fn uploaded_points(set: &BezierPatchSet) -> Vec<[u32; 4]> {
    set.points()
        .iter()
        .zip(set.weights())
        .map(|(p, &w)| {
            let h = *p * w;
            [h.x as f32, h.y as f32, h.z as f32, w as f32].map(f32::to_bits)
        })
        .collect()
}

/// Every patch edge of every object, keyed by its control points' values in the canonical
/// direction (the smaller of the sequence and its reverse), with the bits of the vertex
/// positions along it in that direction. Palindromic edges are stored both ways.
fn edges_by_control_points(
    decompositions: &[Decomposition],
    geometry: &PatchGeometry,
    vertices: &[SurfaceVertex],
) -> HashMap<Vec<[u32; 4]>, Vec<Vec<[u32; 3]>>> {
    let mut edges: HashMap<Vec<[u32; 4]>, Vec<Vec<[u32; 3]>>> = HashMap::new();
    for (object, d) in decompositions.iter().enumerate() {
        let values = uploaded_points(&d.set);
        let first = geometry.first_patch(object).unwrap();
        for (k, patch) in d.set.patches().iter().enumerate() {
            let record = geometry.records()[first + k];
            let (p, q) = (patch.degree_u(), patch.degree_v());
            let n = record.segments_u as usize;
            let vertex = |i: usize, j: usize| {
                vertices[record.vertex_offset as usize + i * (n + 1) + j]
                    .position
                    .map(f32::to_bits)
            };
            let sides: [(ControlBits, Vec<[u32; 3]>); 4] = [
                (
                    (0..=q)
                        .map(|j| values[patch.index(0, j) as usize])
                        .collect(),
                    (0..=n).map(|j| vertex(0, j)).collect(),
                ),
                (
                    (0..=q)
                        .map(|j| values[patch.index(p, j) as usize])
                        .collect(),
                    (0..=n).map(|j| vertex(n, j)).collect(),
                ),
                (
                    (0..=p)
                        .map(|i| values[patch.index(i, 0) as usize])
                        .collect(),
                    (0..=n).map(|i| vertex(i, 0)).collect(),
                ),
                (
                    (0..=p)
                        .map(|i| values[patch.index(i, q) as usize])
                        .collect(),
                    (0..=n).map(|i| vertex(i, n)).collect(),
                ),
            ];
            for (controls, positions) in sides {
                let reversed: Vec<[u32; 4]> = controls.iter().rev().copied().collect();
                let backwards: Vec<[u32; 3]> = positions.iter().rev().copied().collect();
                let as_floats = |c: &[[u32; 4]]| -> Vec<[f32; 4]> {
                    c.iter().map(|p| p.map(f32::from_bits)).collect()
                };
                let order = as_floats(&controls)
                    .partial_cmp(&as_floats(&reversed))
                    .unwrap_or(std::cmp::Ordering::Equal);
                match order {
                    std::cmp::Ordering::Less => edges.entry(controls).or_default().push(positions),
                    std::cmp::Ordering::Greater => {
                        edges.entry(reversed).or_default().push(backwards)
                    }
                    std::cmp::Ordering::Equal => {
                        let entry = edges.entry(controls).or_default();
                        entry.push(positions);
                        entry.push(backwards);
                    }
                }
            }
        }
    }
    edges
}

/// Asserts that every edge shared by two or more patches has bit-identical vertices on all of
/// them; returns the number of shared edges.
fn assert_watertight(objects: &[SceneObject]) -> usize {
    let context = common::gpu();
    let (sync, vertices) = evaluate_scene(&context, objects, false);
    let edges = edges_by_control_points(sync.feeds(), sync.geometry().unwrap(), &vertices);
    let mut shared = 0;
    for (controls, lists) in &edges {
        if lists.len() < 2 {
            continue;
        }
        shared += 1;
        let palindrome = controls.iter().eq(controls.iter().rev());
        for list in &lists[1..] {
            let same = list == &lists[0];
            let same_reversed = list.iter().rev().eq(lists[0].iter());
            assert!(
                same || (palindrome && same_reversed),
                "an edge with control points {controls:?} has different vertices in two patches:\n{:?}\n{:?}",
                lists[0],
                list
            );
        }
    }
    shared
}

#[test]
fn shared_edges_are_bit_identical() {
    // The teapot (4 of its seams run in opposite directions in their two patches), the Bézier
    // patches of B-spline and NURBS surfaces, at tessellations that are not powers of two.
    let mut scene = Scene::demo().unwrap();
    for (object, segments) in scene.objects.iter_mut().zip([13, 7, 9, 11, 6, 10]) {
        object.segments = segments;
    }
    let shared = assert_watertight(&scene.objects);
    eprintln!("{shared} shared edges, all bit-identical");
    assert!(shared >= 64 + 16, "only {shared} shared edges found");
}

#[test]
fn objects_with_equal_boundary_control_points_meet_without_cracks() {
    // One bicubic B-spline split in u into two objects with their own point pools; the second
    // also reversed in u and v, so the shared boundary runs the other way in it.
    let points = (0..6)
        .flat_map(|i| {
            (0..5).map(move |j| {
                let (x, y) = (i as f64 * 0.7, j as f64 * 0.9);
                DVec3::new(x, y, (x * 1.3).sin() * (y * 0.8).cos())
            })
        })
        .collect();
    let surface = NurbsSurface::new(
        [3, 3],
        [
            vec![0.0, 0.0, 0.0, 0.0, 0.3, 0.7, 1.0, 1.0, 1.0, 1.0],
            vec![0.0, 0.0, 0.0, 0.0, 0.4, 1.0, 1.0, 1.0, 1.0],
        ],
        [6, 5],
        points,
        Some((0..30).map(|k| 0.5 + (k % 4) as f64 * 0.5).collect()),
    )
    .unwrap();
    let (left, right) = surface.split(Direction::U, 0.55).unwrap();
    let right = right.reverse(Direction::U).reverse(Direction::V);
    let objects: Vec<SceneObject> = [("left", left), ("right", right)]
        .into_iter()
        .map(|(name, s)| {
            let mut o = SceneObject::new(name, ObjectGeometry::new(s));
            o.segments = 11;
            o
        })
        .collect();
    let d: Vec<Decomposition> = objects.iter().map(|o| o.decompose().unwrap()).collect();
    let left_values: BTreeSet<[u32; 4]> = uploaded_points(&d[0].set).into_iter().collect();
    let common_values = uploaded_points(&d[1].set)
        .into_iter()
        .filter(|p| left_values.contains(p))
        .count();
    assert!(common_values >= 5, "the halves share their boundary points");
    let shared = assert_watertight(&objects);
    // Seams inside each half, plus the 2 spans of the boundary between the halves.
    assert!(shared >= 2 + 2, "{shared} shared edges");
}

#[test]
fn an_edit_re_evaluates_exactly_the_support_of_the_moved_point() {
    let context = common::gpu();
    let mut scene = Scene::demo().unwrap();
    for object in &mut scene.objects {
        object.segments = 6;
    }
    // A 10 × 12 bicubic B-spline with non-uniform knots joins the demo objects.
    let net = (0..10)
        .flat_map(|i| {
            (0..12).map(move |j| DVec3::new(i as f64, j as f64, ((i * j) % 5) as f64 * 0.2))
        })
        .collect();
    let big = construct::bspline_surface([3, 3], [10, 12], net).unwrap();
    scene
        .objects
        .push(SceneObject::new("bicubic", ObjectGeometry::new(big)));
    scene.objects.last_mut().unwrap().segments = 6;
    let mut doc = Document::new(scene);
    let (mut sync, _) = evaluate_scene(&context, &doc.scene.objects, false);

    // (object, control point): B-spline (2, 5) interior and corner points, the bicubic's
    // middle, a torus point on the seam, a teapot point shared by patches.
    for (object, index) in [(3, 4 * 9 + 4), (3, 0), (6, 5 * 12 + 6), (1, 0), (0, 0)] {
        let before = doc.scene.objects[object].decompose().unwrap();
        let position =
            doc.scene.objects[object].control_points()[index] + DVec3::new(0.1, -0.2, 0.3);
        // The editor's road: the document moves the point, the sync layer shows it.
        let moved = doc.move_points(object, &[(index, position)]).unwrap();
        let after = doc.scene.objects[object].decompose().unwrap();
        // Independently: the patches whose Bézier control points changed.
        let old = uploaded_points(&before.set);
        let new = uploaded_points(&after.set);
        let changed: BTreeSet<usize> = after
            .set
            .patches()
            .iter()
            .enumerate()
            .filter(|(_, p)| {
                p.indices()
                    .iter()
                    .any(|&i| old[i as usize] != new[i as usize])
            })
            .map(|(k, _)| k)
            .collect();
        let support: BTreeSet<usize> = moved.patches.iter().copied().collect();
        assert_eq!(support, changed, "object {object}, point {index}");
        if object == 3 || object == 6 {
            assert!(support.len() < after.set.patches().len(), "local support");
        }

        let uploaded = sync.points_moved(&doc.scene, &moved).unwrap();
        assert!(uploaded > 0);
        let evaluated = sync.evaluate_blocking().unwrap();
        assert_eq!(
            evaluated as usize,
            support.len(),
            "object {object}, point {index}"
        );
        let incremental = sync.read_vertices().unwrap();
        let (_, full) = evaluate_scene(&context, &doc.scene.objects, false);
        assert!(
            incremental == full,
            "object {object}, point {index}: the incremental result differs from a full evaluation"
        );
        eprintln!(
            "object {object} point {index}: {} of {} patches re-evaluated, {uploaded} points uploaded",
            support.len(),
            after.set.patches().len()
        );
    }
    // Each move is one undo step; undoing them all brings back every vertex.
    assert_eq!(doc.history.undo_depth(), 5);
    while doc.undo().is_ok() {}
    let original = {
        let mut scene = Scene::demo().unwrap();
        for object in &mut scene.objects {
            object.segments = 6;
        }
        scene
    };
    assert_eq!(doc.scene.objects[..6], original.objects[..]);
}

#[test]
fn bad_requests_are_refused_and_leave_the_device_usable() {
    let context = common::gpu();
    let evaluator = knotwork::gpu::PatchEvaluator::new(&context.device);
    let scene = Scene::demo().unwrap();
    let teapot = scene.objects[0].decompose().unwrap();
    let new = |segments| common::upload(&context, &evaluator, &[(&teapot, segments)]);
    assert!(matches!(
        new(0),
        Err(GpuError::SegmentsOutOfRange { segments: 0, .. })
    ));
    assert!(matches!(
        new(MAX_SEGMENTS + 1),
        Err(GpuError::SegmentsOutOfRange { .. })
    ));
    assert!(matches!(
        new(u32::MAX),
        Err(GpuError::SegmentsOutOfRange { .. })
    ));
    // 1024 segments: 1025² vertices × 32 patches × 48 bytes is far past the binding limit.
    match new(MAX_SEGMENTS) {
        Err(GpuError::BufferTooLarge {
            what: "vertex",
            bytes,
            limit,
        }) => assert!(bytes > limit),
        Ok(_) => panic!("1024 segments should not fit this device's default limits"),
        Err(e) => panic!("unexpected error {e}"),
    }
    // A model with a different point count cannot be written into existing buffers, and an
    // object or patch that does not exist is refused.
    let other = BezierPatchSet::new(
        vec![DVec3::ZERO; 4],
        None,
        vec![BezierPatch::new(1, 1, vec![0, 1, 2, 3])],
    )
    .unwrap();
    let mut geometry = new(4).unwrap();
    assert!(matches!(
        geometry.update_object(&context.queue, 0, &other, None),
        Err(GpuError::ControlPointCountChanged {
            expected: 290,
            found: 4
        })
    ));
    assert!(matches!(
        geometry.update_object(&context.queue, 1, &teapot.set, None),
        Err(GpuError::NoSuchObject { object: 1, .. })
    ));
    assert!(matches!(
        geometry.update_object(&context.queue, 0, &teapot.set, Some(&[32])),
        Err(GpuError::NoSuchPatch { patch: 32, .. })
    ));
    // A NaN control point is refused by the document, which stays as it was.
    let mut object = scene.objects[3].clone();
    assert!(
        object
            .move_control_point(3, DVec3::new(f64::NAN, 0.0, 0.0))
            .is_err()
    );
    assert_eq!(object, scene.objects[3]);
    // The device still works.
    let mut encoder = context.device.create_command_encoder(&Default::default());
    geometry.encode(&context.queue, &mut encoder, &evaluator, None);
    context.queue.submit([encoder.finish()]);
    let vertices = geometry
        .read_vertices(&context.device, &context.queue)
        .unwrap();
    let worst = compare_object(&scene.objects[0], &teapot, geometry.records(), 0, &vertices);
    assert!(worst.position <= 1e-5, "{worst:?}");
}

#[test]
fn degenerate_points_are_finite_and_flagged() {
    // The sphere's poles and the teapot's collapsed edges: finite normals and curvature
    // everywhere, flagged irregular, and the sphere's curvature there is still its 1/r².
    let context = common::gpu();
    let scene = Scene::demo().unwrap();
    let objects = [scene.objects[0].clone(), scene.objects[2].clone()];
    let (sync, vertices) = evaluate_scene(&context, &objects, false);
    let geometry = sync.geometry().unwrap();
    let irregular: Vec<&SurfaceVertex> = vertices
        .iter()
        .filter(|v| v.flags() & VERTEX_IRREGULAR != 0)
        .collect();
    assert!(vertices.iter().all(|v| {
        v.position
            .iter()
            .chain(&v.normal)
            .chain(&v.gaussian_mean)
            .all(|x| x.is_finite())
    }));
    let teapot_irregular = irregular.iter().filter(|v| v.object() == 0).count();
    let sphere_irregular: Vec<_> = irregular.iter().filter(|v| v.object() == 1).collect();
    let n = |object: usize| {
        geometry.records()[geometry.first_patch(object).unwrap()].segments_u as usize + 1
    };
    // Teapot: 8 collapsed edges of n vertices each.
    assert_eq!(teapot_irregular, 8 * n(0), "teapot");
    // Sphere: the poles are the v-ends of its 8 patches' edges.
    assert_eq!(sphere_irregular.len(), 8 * n(1), "sphere");
    for v in sphere_irregular {
        assert!(v.flags() & VERTEX_NO_CURVATURE == 0);
        let k = f64::from(v.curvature()[0]);
        // Sampled GPU_CURVATURE_NUDGE inside in f32: within 0.2 %.
        assert!(
            (k - 0.25).abs() < 5e-4,
            "K at a pole = {k}, expected 1/r² = 0.25"
        );
        assert!(
            (f64::from(v.normal[2]).abs() - 1.0).abs() < 1e-4,
            "{:?}",
            v.normal
        );
    }
}

/// Without vertex curvature (every shading mode but the curvature ones) the compute pass writes
/// the same positions, normals and parameters bit for bit, and the curvature as undefined; the
/// stencil patches of a subdivision surface keep theirs.
#[test]
fn vertices_without_curvature_are_otherwise_the_same() {
    let context = common::gpu();
    let scene = Scene::demo().unwrap();
    let mut sync = SceneSync::with_scene(&context.device, &context.queue, &scene, 1.0).unwrap();
    sync.evaluate_blocking().unwrap();
    let with = sync.read_vertices().unwrap();
    sync.set_vertex_curvature(false);
    assert!(sync.needs_evaluation(), "a change re-evaluates everything");
    assert_eq!(sync.evaluate_blocking().unwrap(), 84);
    let without = sync.read_vertices().unwrap();
    assert_eq!(with.len(), without.len());
    let mut curved = 0;
    for (a, b) in with.iter().zip(&without) {
        assert_eq!(
            (a.position, a.normal, a.u, a.v, a.object(), a.record),
            (b.position, b.normal, b.u, b.v, b.object(), b.record)
        );
        assert_eq!(a.flags() & VERTEX_IRREGULAR, b.flags() & VERTEX_IRREGULAR);
        assert_eq!(b.gaussian_mean, [0.0; 2]);
        assert_ne!(b.flags() & VERTEX_NO_CURVATURE, 0);
        curved += usize::from(a.gaussian_mean != [0.0; 2]);
    }
    assert!(
        curved * 2 > with.len(),
        "the curvature was there before: {curved}"
    );
    // Back on, the curvature returns exactly.
    sync.set_vertex_curvature(true);
    sync.evaluate_blocking().unwrap();
    assert_eq!(sync.read_vertices().unwrap(), with);
}

/// A hardware GPU's device asks for the adapter's own buffer limits (up to
/// [`knotwork::gpu::context::HARDWARE_BINDING_CAP`]). lavapipe is a software adapter and gets
/// WebGPU's defaults; asked as a hardware GPU offering what lavapipe offers (a 128 MiB binding,
/// 2 GiB buffers) would be, it grants the larger buffers. And the room a device binds decides
/// the quality a model is evaluated at: the teapot at 249 segments a span (2 M vertices, 96 MB)
/// is lowered to fit a 64 MiB binding and kept whole in a 128 MiB one.
#[test]
fn a_device_is_granted_a_hardware_gpus_limits_and_its_buffer_room_decides_the_quality() {
    use knotwork::gpu::context::{HARDWARE_BINDING_CAP, limits_for, required_limits};
    let context = common::gpu();
    let info = context.adapter.get_info();
    let offered = context.adapter.limits();
    assert!(knotwork::render::is_software(&info), "{info:?}");
    assert_eq!(
        context.device.limits(),
        required_limits(),
        "a software adapter's device"
    );
    let hardware = wgpu::AdapterInfo {
        device_type: wgpu::DeviceType::DiscreteGpu,
        name: "a hardware GPU".into(),
        ..info
    };
    let asked = limits_for(&hardware, &offered);
    eprintln!(
        "offered: binding {} buffer {}; asked: binding {} buffer {}",
        offered.max_storage_buffer_binding_size,
        offered.max_buffer_size,
        asked.max_storage_buffer_binding_size,
        asked.max_buffer_size
    );
    let within = |offer: u64, default: u64| offer.min(HARDWARE_BINDING_CAP).max(default);
    assert_eq!(
        asked.max_buffer_size,
        within(offered.max_buffer_size, required_limits().max_buffer_size)
    );
    assert_eq!(
        asked.max_storage_buffer_binding_size,
        within(
            offered.max_storage_buffer_binding_size,
            required_limits().max_storage_buffer_binding_size
        )
        .min(asked.max_buffer_size)
    );
    let device = |limits: wgpu::Limits| {
        pollster::block_on(context.adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("asked limits"),
            required_limits: limits,
            ..Default::default()
        }))
        .expect("the adapter grants limits within what it offers")
    };
    let (granted, _) = device(asked.clone());
    assert_eq!(granted.limits(), asked);

    let mut scene = Scene::demo().unwrap();
    scene.objects.truncate(1);
    scene.objects[0].segments = 249;
    let vertex_bytes = 250 * 250 * 32 * std::mem::size_of::<SurfaceVertex>() as u64;
    let small = wgpu::Limits {
        max_storage_buffer_binding_size: 64 << 20,
        ..required_limits()
    };
    assert!(vertex_bytes > small.max_storage_buffer_binding_size);
    assert!(vertex_bytes <= required_limits().max_storage_buffer_binding_size);
    let (small_device, small_queue) = device(small);
    let lowered = SceneSync::with_scene(&small_device, &small_queue, &scene, 1.0).unwrap();
    assert!(lowered.quality_used() < 1.0, "{}", lowered.quality_used());
    let whole = SceneSync::with_scene(&context.device, &context.queue, &scene, 1.0).unwrap();
    assert_eq!(whole.quality_used(), 1.0);
    assert_eq!(whole.read_vertices().unwrap().len(), 250 * 250 * 32);
}
