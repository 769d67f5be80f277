//! Subdivision surfaces against textbook cases and invariants: the cube's counts and closed-form
//! points, a regular grid against the bicubic B-spline the NURBS kernel evaluates, an infinitely
//! sharp crease against the cubic B-spline of its polygon, Loop's weights and linear precision,
//! semi-sharp blending, affine invariance, symmetry, refused cages, and the GPU's stencil pass
//! against the f64 tables.

use crate::common;

use common::{grid_mesh, height, open_mixed_grid, triangle_lattice};
use glam::{DAffine3, DMat3, DVec3};
use knotwork::kernel::par;
use knotwork::kernel::subdiv::level::Level;
use knotwork::kernel::subdiv::limit;
use knotwork::kernel::subdiv::refine::loop_beta;
use knotwork::kernel::subdiv::stencil::Row;
use knotwork::kernel::subdiv::{
    Boundary, Corner, Crease, Creasing, Options, Scheme, SubdivisionSurface, cages,
};
use knotwork::kernel::{GeometryError, NurbsSurface, PolygonMesh};

fn cube() -> SubdivisionSurface {
    // Corners numbered by bits (x, y, z), outward-facing quads.
    let mesh = cages::cube(DVec3::ZERO, 2.0).unwrap();
    SubdivisionSurface::from_mesh(mesh, 0).unwrap()
}

/// The m × m grid as a Catmull-Clark cage and the bicubic B-spline over the same points
/// (unclamped uniform knots 0, 1, ..., m + 3: cage vertex a sits at parameter a + 2).
fn grid_and_bspline(m: usize) -> (SubdivisionSurface, NurbsSurface) {
    let mesh = grid_mesh(m);
    let knots: Vec<f64> = (0..m + 4).map(|k| k as f64).collect();
    let bspline = NurbsSurface::new(
        [3, 3],
        [knots.clone(), knots],
        [m, m],
        mesh.points().to_vec(),
        None,
    )
    .unwrap();
    (SubdivisionSurface::from_mesh(mesh, 0).unwrap(), bspline)
}

fn with(
    mesh: PolygonMesh,
    creases: Vec<Crease>,
    corners: Vec<Corner>,
    options: Options,
) -> SubdivisionSurface {
    SubdivisionSurface::new(mesh, creases, corners, options, 0).unwrap()
}

#[test]
fn the_cube_has_the_textbook_counts_and_points() {
    let cube = cube();
    // V' = V + F + E, F' = Σ corners: 26 / 24, then 98 / 96, then 386 / 384.
    for (levels, vertices, faces) in [(1, 26, 24), (2, 98, 96), (3, 386, 384)] {
        let (points, level) = cube.refined(levels).unwrap();
        assert_eq!((points.len(), level.face_count()), (vertices, faces));
        assert!(level.faces().all(|f| f.len() == 4));
    }
    // One step moves a corner (±1) to ±5/9: (n − 2)/n v + 1/n² Σ e + 1/n² Σ f with n = 3; for
    // x at (1, 1, 1): 1/3 · 1 + 1/9 · (−1 + 1 + 1) + 1/9 · (1 + 0 + 0) = 5/9.
    let (points, _) = cube.refined(1).unwrap();
    for (k, p) in points[..8].iter().enumerate() {
        let sign = DVec3::new(
            if k & 1 == 0 { -1.0 } else { 1.0 },
            if k & 2 == 0 { -1.0 } else { 1.0 },
            if k & 4 == 0 { -1.0 } else { 1.0 },
        );
        assert!((*p - sign * 5.0 / 9.0).length() < 1e-14, "{k}: {p}");
    }
    // The limit of a corner of valence 3: (9 v + 4 Σ e + Σ d) / 24 = ±1/2, the same from every
    // level (the limit does not move under refinement), with the normal along the diagonal.
    for levels in [0, 1, 3] {
        let limit = cube.limit(levels).unwrap();
        for k in 0..8 {
            let p = limit.positions[k];
            assert!(
                (p.abs() - DVec3::splat(0.5)).length() < 1e-12,
                "{levels}: {p}"
            );
            let n = limit.normals[k];
            assert!((n - p.normalize()).length() < 1e-12, "{levels}: {n}");
        }
    }
    // The refined corners converge to their limit.
    let (deep, _) = cube.refined(6).unwrap();
    assert!((deep[7] - DVec3::splat(0.5)).length() < 1e-3, "{}", deep[7]);
}

#[test]
fn level_zero_is_the_cage_and_refinement_is_affine_invariant_and_symmetric() {
    let cube = cube();
    let (points, level) = cube.refined(0).unwrap();
    assert_eq!(points, cube.points());
    assert_eq!(level.face_count(), 6);

    let map = DAffine3::from_mat3_translation(
        DMat3::from_cols_array(&[1.2, 0.3, -0.1, 0.2, 0.9, 0.4, -0.3, 0.1, 1.1]),
        DVec3::new(0.5, -2.0, 3.0),
    );
    let moved = cube.transformed(&map).unwrap();
    let a = cube.limit(3).unwrap();
    let b = moved.limit(3).unwrap();
    for (p, q) in a.positions.iter().zip(&b.positions) {
        assert!((map.transform_point3(*p) - *q).length() < 1e-12);
    }
    // The cube is symmetric under x -> -x: so is its limit point set.
    for p in &a.positions {
        let mirror = DVec3::new(-p.x, p.y, p.z);
        assert!(
            a.positions.iter().any(|q| (*q - mirror).length() < 1e-12),
            "{p} has no mirror image"
        );
    }
}

#[test]
fn a_regular_grid_is_the_bicubic_b_spline_the_kernel_evaluates() {
    let m = 8;
    let (surface, bspline) = grid_and_bspline(m);
    let limit = surface.limit(3).unwrap();
    let (refined, _) = surface.refined(3).unwrap();
    let mut checked = 0;
    for (v, p) in limit.positions.iter().enumerate() {
        // Over faces with regular corners (cage vertices 1..=m−2 in both directions) the limit
        // is the B-spline; the refined (x, y) is the parameter minus 2 there.
        let r = refined[v];
        let inside = |x: f64| (1.0..=(m - 2) as f64).contains(&x);
        if !(inside(r.x) && inside(r.y)) {
            continue;
        }
        let local = bspline.local_geometry(r.x + 2.0, r.y + 2.0).unwrap();
        let exact = local.derivatives.point;
        assert!((*p - exact).length() < 1e-12, "vertex {v}: {p} vs {exact}");
        let angle = limit.normals[v].angle_between(local.normal);
        assert!(angle < 1e-7, "vertex {v}: normal off by {angle}");
        checked += 1;
    }
    assert!(checked > 300, "{checked}");
}

/// The cubic B-spline of values `h` at parameter t (knots at the integers, value k at t = k).
fn cubic_bspline(h: &[f64], t: f64) -> f64 {
    let k = t.floor() as i64;
    let s = t - k as f64;
    let basis = [
        (1.0 - s).powi(3) / 6.0,
        (3.0 * s.powi(3) - 6.0 * s * s + 4.0) / 6.0,
        (-3.0 * s.powi(3) + 3.0 * s * s + 3.0 * s + 1.0) / 6.0,
        s.powi(3) / 6.0,
    ];
    (0..4)
        .map(|a| {
            let i = (k - 1 + a as i64).clamp(0, h.len() as i64 - 1) as usize;
            basis[a] * h[i]
        })
        .sum()
}

#[test]
fn an_infinitely_sharp_crease_converges_to_the_cubic_b_spline_of_its_polygon() {
    let m = 8;
    let c = 3;
    let id = |i: usize, j: usize| (i * m + j) as u32;
    let creases = (0..m - 1)
        .map(|i| Crease {
            a: id(i, c),
            b: id(i + 1, c),
            sharpness: 10.0,
        })
        .collect();
    let surface = with(grid_mesh(m), creases, Vec::new(), Options::default());
    let polygon: Vec<f64> = (0..m).map(|i| height(i, c)).collect();
    let limit = surface.limit(4).unwrap();
    let mut on_crease = 0;
    for p in &limit.positions {
        if (p.y - c as f64).abs() > 1e-12 || !(1.0..=(m - 2) as f64).contains(&p.x) {
            continue;
        }
        let z = cubic_bspline(&polygon, p.x);
        assert!((p.z - z).abs() < 1e-12, "at x = {}: {} vs {z}", p.x, p.z);
        on_crease += 1;
    }
    assert_eq!(on_crease, 16 * (m - 3) + 1);
}

#[test]
fn a_semi_sharp_edge_blends_the_midpoint_and_the_smooth_rule_by_its_sharpness() {
    let m = 4;
    let mesh = grid_mesh(m);
    let p = mesh.points().to_vec();
    let id = |i: usize, j: usize| i * m + j;
    // The interior edge (1, 1)–(2, 1) between faces (1, 0) and (1, 1).
    let (a, b) = (id(1, 1), id(2, 1));
    let centroid = |i: usize, j: usize| {
        (p[id(i, j)] + p[id(i + 1, j)] + p[id(i + 1, j + 1)] + p[id(i, j + 1)]) / 4.0
    };
    let midpoint = (p[a] + p[b]) / 2.0;
    let smooth = (p[a] + p[b] + centroid(1, 0) + centroid(1, 1)) / 4.0;
    for (s, expected) in [
        (0.0, smooth),
        (0.3, 0.3 * midpoint + 0.7 * smooth),
        (1.0, midpoint),
        (2.5, midpoint),
    ] {
        let surface = with(
            mesh.clone(),
            vec![Crease {
                a: a as u32,
                b: b as u32,
                sharpness: s,
            }],
            Vec::new(),
            Options::default(),
        );
        let (points, level) = surface.refined(1).unwrap();
        // The edge's child: the level-1 vertex at the middle of the two endpoints' children.
        let child = (0..level.vertex_count)
            .find(|&v| {
                level.vertex_edges(v as u32).iter().any(|&e| {
                    let [x, y] = level.edges[e as usize];
                    x as usize == a || y as usize == a
                }) && level.vertex_edges(v as u32).iter().any(|&e| {
                    let [x, y] = level.edges[e as usize];
                    x as usize == b || y as usize == b
                })
            })
            .unwrap();
        assert!(
            (points[child] - expected).length() < 1e-14,
            "s = {s}: {} vs {expected}",
            points[child]
        );
    }
}

#[test]
fn a_corner_vertex_stays_and_edge_and_corner_keeps_valence_two_corners() {
    let mesh = grid_mesh(5);
    let corner = with(
        mesh.clone(),
        Vec::new(),
        vec![Corner {
            vertex: 12,
            sharpness: 10.0,
        }],
        Options::default(),
    );
    let limit = corner.limit(3).unwrap();
    assert!((limit.positions[12] - mesh.points()[12]).length() < 1e-14);

    let pinned = with(
        mesh.clone(),
        Vec::new(),
        Vec::new(),
        Options {
            boundary: Boundary::EdgeAndCorner,
            ..Options::default()
        },
    );
    let free = with(mesh.clone(), Vec::new(), Vec::new(), Options::default());
    let (pinned_points, _) = pinned.refined(2).unwrap();
    let (free_points, _) = free.refined(2).unwrap();
    // Vertex 0 has one face: pinned under edge-and-corner, smoothed (3/4, 1/8, 1/8) under
    // edge-only.
    assert_eq!(pinned_points[0], mesh.points()[0]);
    let p = mesh.points();
    let once = 0.75 * p[0] + 0.125 * (p[1] + p[5]);
    let (one, _) = free.refined(1).unwrap();
    assert!((one[0] - once).length() < 1e-14);
    assert!((free_points[0] - p[0]).length() > 1e-3);
}

#[test]
fn loop_uses_its_original_weights_and_reproduces_planes_and_the_box_spline_mask() {
    assert!((loop_beta(6) - 1.0 / 16.0).abs() < 1e-15);
    assert!((loop_beta(3) - 3.0 / 16.0).abs() < 1e-15);
    // Not Warren's 3/(8n): for n = 5, (5/8 − (3/8 + cos(72°)/4)²)/5.
    let c = 0.375 + 0.25 * (72f64.to_radians()).cos();
    assert!((loop_beta(5) - (0.625 - c * c) / 5.0).abs() < 1e-15);
    assert!((loop_beta(5) - 3.0 / 40.0).abs() > 1e-3);

    let loop_options = Options {
        scheme: Scheme::Loop,
        ..Options::default()
    };
    let plane = |x: f64, y: f64| 0.3 * x - 0.2 * y + 1.0;
    let flat = with(
        triangle_lattice(7, plane),
        Vec::new(),
        Vec::new(),
        loop_options,
    );
    let limit = flat.limit(2).unwrap();
    for p in &limit.positions {
        assert!((p.z - plane(p.x, p.y)).abs() < 1e-12, "{p}");
    }
    // The box spline's values at a lattice point: 1/2 at the vertex, 1/12 at each neighbour;
    // reached here through three refinements and the limit mask of level 3.
    let bumpy = triangle_lattice(7, |x, y| (1.1 * x).sin() * (0.7 * y).cos());
    let points = bumpy.points().to_vec();
    let surface = with(bumpy, Vec::new(), Vec::new(), loop_options);
    let limit = surface.limit(3).unwrap();
    let v = 3 * 7 + 3;
    let neighbours = [v + 1, v - 1, v + 7, v - 7, v - 7 + 1, v + 7 - 1];
    let expected = 0.5 * points[v] + neighbours.iter().map(|&n| points[n]).sum::<DVec3>() / 12.0;
    assert!((limit.positions[v] - expected).length() < 1e-12);
}

#[test]
fn bad_cages_are_refused_naming_the_face_edge_or_vertex() {
    let p = |n: usize| {
        (0..n)
            .map(|k| DVec3::new(k as f64, (k * k) as f64 * 0.1, 0.0))
            .collect::<Vec<_>>()
    };
    let refuse = |points: Vec<DVec3>,
                  faces: Vec<Vec<u32>>,
                  options: Options,
                  creases: Vec<Crease>|
     -> GeometryError {
        let mesh = PolygonMesh::new(points, &faces).unwrap();
        SubdivisionSurface::new(mesh, creases, Vec::new(), options, 0).unwrap_err()
    };
    let three_on_an_edge = refuse(
        p(5),
        vec![vec![0, 1, 2], vec![1, 0, 3], vec![0, 1, 4]],
        Options::default(),
        Vec::new(),
    );
    assert!(
        three_on_an_edge.to_string().starts_with("edges[0-1]"),
        "{three_on_an_edge}"
    );
    let bowtie = refuse(
        p(5),
        vec![vec![0, 1, 2], vec![0, 3, 4]],
        Options::default(),
        Vec::new(),
    );
    assert!(bowtie.to_string().starts_with("points[0]"), "{bowtie}");
    let repeated = refuse(p(4), vec![vec![0, 1, 2, 1]], Options::default(), Vec::new());
    assert!(repeated.to_string().starts_with("faces[0]"), "{repeated}");
    let quad_under_loop = refuse(
        p(5),
        vec![vec![0, 1, 2], vec![1, 3, 4, 2]],
        Options {
            scheme: Scheme::Loop,
            ..Options::default()
        },
        Vec::new(),
    );
    assert!(
        quad_under_loop.to_string().starts_with("faces[1]"),
        "{quad_under_loop}"
    );
    let no_edge = refuse(
        p(4),
        vec![vec![0, 1, 2, 3]],
        Options::default(),
        vec![Crease {
            a: 0,
            b: 2,
            sharpness: 1.0,
        }],
    );
    assert!(no_edge.to_string().starts_with("creases[0]"), "{no_edge}");
    let negative = refuse(
        p(4),
        vec![vec![0, 1, 2, 3]],
        Options::default(),
        vec![Crease {
            a: 0,
            b: 1,
            sharpness: -1.0,
        }],
    );
    assert!(negative.to_string().contains("sharpness"), "{negative}");
    let flipped = refuse(
        p(4),
        vec![vec![0, 1, 2], vec![0, 1, 3]],
        Options::default(),
        Vec::new(),
    );
    assert!(flipped.to_string().starts_with("edges[0-1]"), "{flipped}");
}

/// A closed hexagonal prism (two hexagons, six quads) with creases and a corner, and an open
/// grid with triangles: n-gons, boundaries, integer, fractional and infinite creases.
fn mixed_cages() -> Vec<SubdivisionSurface> {
    let mut points = Vec::new();
    for z in [-1.0, 1.0] {
        for k in 0..6 {
            let a = std::f64::consts::TAU * k as f64 / 6.0;
            points.push(DVec3::new(
                a.cos() * (1.0 + 0.1 * k as f64),
                a.sin(),
                z + 0.05 * k as f64,
            ));
        }
    }
    let mut faces = vec![vec![5, 4, 3, 2, 1, 0], vec![6, 7, 8, 9, 10, 11]];
    for k in 0..6u32 {
        let n = (k + 1) % 6;
        faces.push(vec![k, n, n + 6, k + 6]);
    }
    let prism = PolygonMesh::new(points, &faces).unwrap();
    let creases = vec![
        Crease {
            a: 0,
            b: 1,
            sharpness: 10.0,
        },
        Crease {
            a: 1,
            b: 2,
            sharpness: 1.0,
        },
        Crease {
            a: 6,
            b: 7,
            sharpness: 0.6,
        },
        Crease {
            a: 7,
            b: 8,
            sharpness: 2.3,
        },
    ];
    let corners = vec![Corner {
        vertex: 9,
        sharpness: 1.5,
    }];
    let grid = open_mixed_grid();
    let id = |i: u32, j: u32| i * 4 + j;
    vec![
        with(
            prism.clone(),
            creases.clone(),
            corners.clone(),
            Options::default(),
        ),
        with(
            prism,
            creases,
            corners,
            Options {
                creasing: Creasing::Chaikin,
                ..Options::default()
            },
        ),
        with(
            grid.clone(),
            vec![Crease {
                a: id(1, 1),
                b: id(2, 1),
                sharpness: 0.5,
            }],
            Vec::new(),
            Options::default(),
        ),
        with(
            grid,
            Vec::new(),
            Vec::new(),
            Options {
                boundary: Boundary::EdgeAndCorner,
                ..Options::default()
            },
        ),
    ]
}

/// The f64 limit normals inside each quad at point `v` of `level` (over `points`) where `v`
/// is sharp on Catmull-Clark's limit (each quad's own, `limit::sharp_corner_tangents`); none
/// elsewhere.
fn sharp_point_normals(level: &Level, points: &[DVec3], v: u32) -> Vec<DVec3> {
    let apply = |row: &Row| {
        row.0
            .iter()
            .map(|&(i, w)| w * points[i as usize])
            .sum::<DVec3>()
    };
    level
        .vertex_faces(v)
        .iter()
        .filter_map(|&f| limit::sharp_corner_tangents(level, Scheme::CatmullClark, v, f))
        .map(|[a, b]| apply(&a).cross(apply(&b)).normalize())
        .collect()
}

#[test]
fn the_gpu_stencil_pass_matches_the_f64_tables() {
    let context = common::gpu();
    for (c, surface) in mixed_cages().iter().enumerate() {
        let (lo, hi) = surface.mesh().bounds().unwrap();
        let size = (hi - lo).length();
        for levels in 1..=3 {
            let limit = surface.limit(levels).unwrap();
            let gpu = knotwork::gpu::subdiv_eval::evaluate_level(
                &context.device,
                &context.queue,
                surface,
                levels,
                knotwork::kernel::subdiv::patches::Display::Limit,
            )
            .unwrap();
            let (points, level) = surface.refined(levels).unwrap();
            let mut worst = (0.0f64, 0.0f64);
            for (v, result) in gpu.iter().enumerate() {
                let (p, n, _) = result.expect("every vertex lies on a face");
                worst.0 = worst.0.max((p - limit.positions[v]).length() / size);
                // A sharp point (crease, corner, boundary) shows the normal of the quad whose
                // slot it was drawn from: the f64 normal of one of its quads.
                let candidates = sharp_point_normals(&level, &points, v as u32);
                let angle = candidates
                    .iter()
                    .map(|c| n.angle_between(*c))
                    .fold(n.angle_between(limit.normals[v]), f64::min);
                worst.1 = worst.1.max(angle);
            }
            eprintln!(
                "cage {c} level {levels}: position {:.1e}, normal {:.1e} rad",
                worst.0, worst.1
            );
            assert!(
                worst.0 < 1e-5 && worst.1 < 1e-3,
                "cage {c} level {levels}: {worst:?}"
            );
            let (refined, _) = surface.refined(levels).unwrap();
            let gpu = knotwork::gpu::subdiv_eval::evaluate_level(
                &context.device,
                &context.queue,
                surface,
                levels,
                knotwork::kernel::subdiv::patches::Display::Refined,
            )
            .unwrap();
            for (v, result) in gpu.iter().enumerate() {
                let (p, _, _) = result.unwrap();
                assert!(
                    (p - refined[v]).length() / size < 1e-5,
                    "cage {c} refined {v}"
                );
            }
        }
    }
}

/// A stencil table larger than one storage binding is dealt into pages, each behind its own
/// copy of the cage: on a device that binds only 256 KiB, a creased prism's table (about 1 MB at
/// level 4, every face as stencils, the cage in general position) evaluates to the same vertices
/// bit for bit as on the full device, and those match the f64 limit.
#[test]
fn stencil_tables_larger_than_one_binding_evaluate_in_pages() {
    let context = common::gpu();
    let small: u64 = 1 << 18;
    let limits = wgpu::Limits {
        max_storage_buffer_binding_size: small,
        ..knotwork::gpu::context::required_limits()
    };
    let (device, queue) =
        pollster::block_on(context.adapter.request_device(&wgpu::DeviceDescriptor {
            required_limits: limits,
            ..Default::default()
        }))
        .expect("a device with a smaller binding limit");
    let mut rng = common::Rng(0x5eed_9a9e);
    let motion = DAffine3::from_scale_rotation_translation(
        DVec3::splat(rng.range(0.3, 3.0)),
        glam::DQuat::from_axis_angle(
            DVec3::new(rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), 1.0).normalize(),
            rng.range(0.0, 6.0),
        ),
        DVec3::new(
            rng.range(-5.0, 5.0),
            rng.range(-5.0, 5.0),
            rng.range(-5.0, 5.0),
        ),
    );
    let surface = mixed_cages()[0].transformed(&motion).unwrap();
    let levels = 4;
    let display = knotwork::kernel::subdiv::patches::Display::Limit;
    let feed = surface.limit_feed_with(levels, display, false).unwrap();
    let table = feed.entries.len() as u64 * 32;
    assert!(
        table > 2 * small,
        "the table ({table} bytes) must need pages"
    );
    let paged = knotwork::gpu::subdiv_eval::evaluate_feed(&device, &queue, surface.points(), &feed)
        .expect("the paged table evaluates");
    let whole = knotwork::gpu::subdiv_eval::evaluate_feed(
        &context.device,
        &context.queue,
        surface.points(),
        &feed,
    )
    .unwrap();
    assert_eq!(paged.len(), whole.len());
    for (v, (a, b)) in paged.iter().zip(&whole).enumerate() {
        assert!(a == b, "vertex {v}: {a:?} paged, {b:?} in one binding");
    }
    let limit = surface.limit(levels).unwrap();
    let (lo, hi) = surface.mesh().bounds().unwrap();
    let size = (hi - lo).length();
    for (v, result) in paged.iter().enumerate() {
        let (p, _, _) = result.expect("every vertex lies on a face");
        let error = (p - limit.positions[v]).length() / size;
        assert!(error < 1e-5, "vertex {v}: {error:.1e} of the size");
    }

    // An edit (a cage point moved) reaches every page's copy of the cage: the updated
    // geometry shows what a geometry built at the moved cage shows.
    use knotwork::gpu::{ObjectPatches, PatchEvaluator, PatchGeometry};
    let evaluator = PatchEvaluator::new(&device);
    let mut points = surface.points().to_vec();
    let set = |points: &[DVec3]| {
        knotwork::kernel::BezierPatchSet::new(points.to_vec(), None, Vec::new()).unwrap()
    };
    let build = |set: &knotwork::kernel::BezierPatchSet| {
        let input = ObjectPatches {
            set,
            domains: &[],
            segments: 1,
            stencils: Some(&feed),
            cage_points: set.points().len(),
            trims: None,
            displacement: None,
            lattice: None,
        };
        PatchGeometry::new(&device, &evaluator, &[input]).unwrap()
    };
    let evaluate = |geometry: &mut PatchGeometry| {
        let mut encoder = device.create_command_encoder(&Default::default());
        geometry.encode(&queue, &mut encoder, &evaluator, None);
        queue.submit([encoder.finish()]);
        geometry.read_vertices(&device, &queue).unwrap()
    };
    let mut edited = build(&set(&points));
    evaluate(&mut edited);
    for k in [0, points.len() - 1] {
        points[k] += DVec3::new(0.3, -0.2, 0.1) * size;
    }
    edited
        .update_object(&queue, 0, &set(&points), None)
        .unwrap();
    let after_edit = evaluate(&mut edited);
    let rebuilt = evaluate(&mut build(&set(&points)));
    let as_bits =
        |v: &[knotwork::gpu::SurfaceVertex]| -> Vec<u8> { bytemuck::cast_slice(v).to_vec() };
    assert!(
        as_bits(&after_edit) == as_bits(&rebuilt),
        "the edit reached every page"
    );
    assert!(as_bits(&after_edit) != as_bits(&evaluate(&mut build(&set(surface.points())))));
}

#[test]
fn the_gpu_curvature_of_a_regular_grid_is_the_b_spline_s() {
    let context = common::gpu();
    let m = 8;
    let (surface, bspline) = grid_and_bspline(m);
    let (refined, _) = surface.refined(3).unwrap();
    let gpu = knotwork::gpu::subdiv_eval::evaluate_level(
        &context.device,
        &context.queue,
        &surface,
        3,
        knotwork::kernel::subdiv::patches::Display::Limit,
    )
    .unwrap();
    let mut checked = 0;
    for (v, result) in gpu.iter().enumerate() {
        let (_, _, k) = result.unwrap();
        let r = refined[v];
        let inside = |x: f64| (1.0..=(m - 2) as f64).contains(&x);
        if !(inside(r.x) && inside(r.y)) {
            continue;
        }
        let exact = bspline
            .local_geometry(r.x + 2.0, r.y + 2.0)
            .unwrap()
            .curvature;
        let scale = exact.k1.abs().max(exact.k2.abs()).max(1e-3);
        for (got, want) in [(k[0], exact.gaussian), (k[1], exact.mean)] {
            let tolerance = 1e-2
                * if want == exact.gaussian {
                    scale * scale
                } else {
                    scale
                };
            assert!(
                (got - want).abs() <= tolerance,
                "vertex {v}: {got} vs {want}"
            );
        }
        assert!((k[2] - exact.k1).abs() <= 1e-2 * scale && (k[3] - exact.k2).abs() <= 1e-2 * scale);
        checked += 1;
    }
    assert!(checked > 300, "{checked}");
}

/// The sheets whose limit is known in closed form, shared with the kernel's tests.
#[path = "../../crates/kernel/tests/it/sheets.rs"]
#[allow(dead_code)]
mod sheets;

/// Along the boundary, at sharp corners and on both sides of an infinitely sharp crease, the
/// editor's limit display (the compute pass and the CPU path) has curvature at every vertex,
/// and it is the closed form's: random sheets, one creased across, at levels 2 and 3; each
/// vertex's position, normal and (K, H, k1, k2) against the side's extended B-spline
/// ([`sheets::extended_bspline`]) at its nearest grid point, within f32's reach.
#[test]
fn the_gpu_shows_curvature_along_boundaries_and_creases() {
    use knotwork::gpu::records::VERTEX_NO_CURVATURE;
    let mut draw = sheets::Draw(0x0DDB_A11C_AFE5_EED5);
    for (m, n, crease_row, level) in [(4, 5, Some(2), 3), (5, 3, None, 2)] {
        let sheet = sheets::Sheet::random(&mut draw, m, n, crease_row);
        let size = sheet.size;
        // Every side's grid of closed-form values at the level's parameters.
        let references = sheet.references(level);
        let scene = one_surface_scene("sheet", sheet.surface(level));
        for cpu in [false, true] {
            let (_, vertices) = common::evaluate_scene(&scene, cpu);
            let mut worst = [0.0f64; 3];
            for vertex in &vertices {
                assert_eq!(
                    vertex.flags() & VERTEX_NO_CURVATURE,
                    0,
                    "cpu {cpu}: {vertex:?}"
                );
                let p = DVec3::from(vertex.position.map(f64::from));
                let normal = DVec3::from(vertex.normal.map(f64::from)).normalize();
                // On the crease both sides share the point: the side whose normal it has.
                let exact = references
                    .iter()
                    .filter(|g| g.derivatives.point.distance(p) < 1e-5 * size)
                    .max_by(|a, b| normal.dot(a.normal).total_cmp(&normal.dot(b.normal)))
                    .unwrap_or_else(|| panic!("cpu {cpu}: no closed-form point near {p}"));
                worst[0] = worst[0].max(exact.derivatives.point.distance(p) / size);
                worst[1] = worst[1].max(normal.angle_between(exact.normal));
                let c = exact.curvature;
                let scale = (c.k1.abs().max(c.k2.abs()) * size).max(1.0);
                let [k, h, k1, k2] = vertex.curvature().map(f64::from);
                for (got, want) in [
                    (k * size * size / scale, c.gaussian * size * size / scale),
                    (h * size, c.mean * size),
                    (k1 * size, c.k1 * size),
                    (k2 * size, c.k2 * size),
                ] {
                    worst[2] = worst[2].max((got - want).abs() / scale);
                }
            }
            eprintln!(
                "{m} x {n}, crease {crease_row:?}, level {level}, cpu {cpu}: {} vertices, \
                 position {:.1e}, normal {:.1e} rad, curvature {:.1e}",
                vertices.len(),
                worst[0],
                worst[1],
                worst[2]
            );
            assert!(
                worst[0] < 1e-5 && worst[1] < 1e-4 && worst[2] < 1e-3,
                "cpu {cpu}: {worst:?}"
            );
        }
    }
}

/// How far a drawn vertex's (K, H) is from (`gaussian`, `mean`), relative to the larger of
/// the curvature and 1 / `size`.
fn curvature_error(
    vertex: &knotwork::gpu::SurfaceVertex,
    gaussian: f64,
    mean: f64,
    size: f64,
) -> f64 {
    let [k, h] = vertex.gaussian_mean.map(f64::from);
    let scale = (gaussian.abs().sqrt().max(mean.abs()) * size).max(1.0);
    ((k - gaussian).abs() * size * size / (scale * scale)).max((h - mean).abs() * size / scale)
}

/// A scene of one subdivision surface, as the editor holds it.
fn one_surface_scene(name: &str, surface: SubdivisionSurface) -> knotwork::scene::Scene {
    use knotwork::scene::{ObjectGeometry, Scene, SceneObject, SubdivObject};
    Scene {
        objects: vec![SceneObject::new(
            name,
            ObjectGeometry::new(SubdivObject::from(surface)),
        )],
        unit: None,
    }
}

/// Loop's limit display on the compute pass and the CPU path has curvature at every regular
/// point, and away from the boundary it is the quadric's that the lattice samples
/// ([`sheets::QuadricLattice`]) within f32's reach.
#[test]
fn the_gpu_shows_loops_curvature_at_regular_points() {
    use knotwork::gpu::records::VERTEX_NO_CURVATURE;
    use knotwork::kernel::subdiv::Scheme;
    let mut draw = sheets::Draw(0x3C6E_F372_FE94_F82B);
    let quadric = sheets::QuadricLattice::random(&mut draw, 9, 8);
    let size = quadric.size();
    let options = Options {
        scheme: Scheme::Loop,
        ..Options::default()
    };
    let surface =
        SubdivisionSurface::new(quadric.mesh.clone(), Vec::new(), Vec::new(), options, 3).unwrap();
    let scene = one_surface_scene("lattice", surface);
    for cpu in [false, true] {
        let (_, vertices) = common::evaluate_scene(&scene, cpu);
        let (mut checked, mut worst) = (0, 0.0f64);
        for vertex in &vertices {
            // Slots past a triangle's diagonal (u + v > 1) repeat its first and are not drawn.
            if vertex.u + vertex.v > 1.0 + 1e-6 {
                continue;
            }
            let p = DVec3::from(vertex.position.map(f64::from));
            let Some((gaussian, mean)) = quadric.curvature_at(p) else {
                continue;
            };
            assert_eq!(
                vertex.flags() & VERTEX_NO_CURVATURE,
                0,
                "cpu {cpu}: {vertex:?}"
            );
            worst = worst.max(curvature_error(vertex, gaussian, mean, size));
            checked += 1;
        }
        eprintln!("Loop, cpu {cpu}: {checked} vertices checked, curvature {worst:.1e}");
        assert!(
            checked > 500 && worst < 1e-3,
            "cpu {cpu}: {checked}, {worst}"
        );
    }
}

/// Loop's limit display on the compute pass and the CPU path has curvature along the boundary
/// and on both sides of an infinitely sharp crease, and it is the kernel's exact value there
/// ([`limit::loop_sided_weights`], checked against the finer limit in the kernel's tests)
/// within f32's reach: each drawn vertex at such a point takes the value of the side its patch
/// lies on (the side of the level's face nearest the patch's centre). A corner of one triangle
/// shows its exact zero ([`limit::loop_corner_weights`]). Only the corners of two triangles
/// and the crease's ends, where the limit has no one quartic, stay grey.
#[test]
fn the_gpu_shows_loops_curvature_along_boundaries_and_creases() {
    use knotwork::gpu::records::VERTEX_NO_CURVATURE;
    use knotwork::kernel::diffgeo::SurfaceDerivatives;
    let mut draw = sheets::Draw(0x2545_F491_4F6C_DD1D);
    let sheet = sheets::Sheet::random(&mut draw, 4, 5, Some(2));
    let (size, level) = (sheet.size, 3u32);
    let surface = sheet.loop_surface(level);
    // Per point of the level on the boundary or the crease: per face at it, the face's side's
    // exact (K, H) and the face's centre.
    let limit_mesh = surface.limit(level).unwrap();
    let lattice = &limit_mesh.level;
    let centre = |f: u32| {
        lattice
            .face(f)
            .iter()
            .map(|&c| limit_mesh.positions[c as usize])
            .sum::<DVec3>()
            / 3.0
    };
    let sides: Vec<Vec<(f64, f64, DVec3)>> = (0..limit_mesh.positions.len() as u32)
        .map(|v| {
            lattice
                .vertex_faces(v)
                .iter()
                .filter_map(|&f| {
                    let face = lattice.face(f);
                    let at = face.iter().position(|&x| x == v)?;
                    let towards = face[(at + 1) % 3];
                    let weights = limit::loop_sided_weights(lattice, v, towards, 0, f, 1.0)
                        .or_else(|| limit::loop_corner_weights(lattice, v, towards, 0, 1.0))?;
                    let c = SurfaceDerivatives::from_weights(&limit_mesh.refined, weights)?
                        .curvature_values()?;
                    Some((c.gaussian, c.mean, centre(f)))
                })
                .collect()
        })
        .collect();
    let scene = one_surface_scene("sheet", surface);
    for cpu in [false, true] {
        let (_, vertices) = common::evaluate_scene(&scene, cpu);
        // Each patch's centre: the mean of its drawn vertices.
        let mut sums: std::collections::HashMap<u32, (DVec3, f64)> = Default::default();
        for vertex in vertices.iter().filter(|x| x.u + x.v <= 1.0 + 1e-6) {
            let sum = sums.entry(vertex.record).or_default();
            sum.0 += DVec3::from(vertex.position.map(f64::from));
            sum.1 += 1.0;
        }
        let (mut checked, mut grey, mut worst, mut flat) = (0, 0, 0.0f64, 0);
        for vertex in &vertices {
            // Slots past a triangle's diagonal (u + v > 1) repeat its first and are not drawn.
            if vertex.u + vertex.v > 1.0 + 1e-6 {
                continue;
            }
            let p = DVec3::from(vertex.position.map(f64::from));
            let Some(v) = limit_mesh
                .positions
                .iter()
                .position(|q| q.distance(p) < 1e-5 * size)
            else {
                continue;
            };
            let sharp = lattice
                .vertex_edges(v as u32)
                .iter()
                .any(|&e| lattice.is_boundary_edge(e) || lattice.edge_sharpness[e as usize] > 0.0);
            if !sharp {
                continue;
            }
            if sides[v].is_empty() {
                grey += 1;
                continue;
            }
            assert_eq!(
                vertex.flags() & VERTEX_NO_CURVATURE,
                0,
                "cpu {cpu}: point {v} {vertex:?}"
            );
            let (sum, count) = sums[&vertex.record];
            let patch_centre = sum / count;
            let &(gaussian, mean, _) = sides[v]
                .iter()
                .min_by(|a, b| {
                    a.2.distance(patch_centre)
                        .total_cmp(&b.2.distance(patch_centre))
                })
                .unwrap();
            worst = worst.max(curvature_error(vertex, gaussian, mean, size));
            checked += 1;
            if lattice.vertex_faces(v as u32).len() == 1 {
                flat += 1;
            }
        }
        eprintln!(
            "Loop boundary and crease, cpu {cpu}: {checked} vertices checked ({flat} at corners \
             of one triangle), curvature {worst:.1e}; {grey} at other corners and crease ends"
        );
        assert!(
            checked > 150 && worst < 1e-3 && grey < checked / 10 && flat >= 2,
            "cpu {cpu}: {checked}, {worst}, {grey}, {flat}"
        );
    }
}

/// Export's curvature of a Catmull-Clark surface (the `_CURVATURE` glTF writes): exact at
/// every vertex off the crease, interior, boundary and sharp corners alike (the closed form's
/// to 1e-7 of the size), and the mesh's estimate, finite, on the crease.
#[test]
fn export_takes_the_exact_curvature_wherever_the_limit_has_one() {
    use knotwork::scene::{ObjectGeometry, SceneObject, SubdivObject};
    let mut draw = sheets::Draw(0x9E37_79B9_7F4A_7C15);
    let sheet = sheets::Sheet::random(&mut draw, 4, 5, Some(2));
    let (size, level) = (sheet.size, 3u32);
    let steps = 1usize << level;
    let object = SceneObject::new(
        "sheet",
        ObjectGeometry::new(SubdivObject::from(sheet.surface(level))),
    );
    let meshes = object
        .tessellate(
            knotwork::kernel::tess::Tessellation::Tolerance(1e-3 * size),
            true,
        )
        .unwrap();
    let [mesh] = &meshes[..] else {
        panic!("one mesh: {}", meshes.len());
    };
    assert_eq!(mesh.curvatures.len(), mesh.positions.len());
    let (mut exact, mut on_crease) = (0, 0);
    for (v, c) in mesh.curvatures.iter().enumerate() {
        let p = mesh.positions[v];
        let near: Vec<_> = sheet
            .halves
            .iter()
            .filter_map(|(_, closed)| {
                let [(_, u_end), (_, v_end)] = closed.domain();
                (0..=u_end as usize * steps)
                    .flat_map(|a| (0..=v_end as usize * steps).map(move |b| (a, b)))
                    .map(|(a, b)| {
                        closed
                            .local_geometry(a as f64 / steps as f64, b as f64 / steps as f64)
                            .unwrap()
                    })
                    .find(|g| g.derivatives.point.distance(p) < 1e-9 * size)
            })
            .collect();
        assert!(
            c.gaussian.is_finite() && c.mean.is_finite(),
            "vertex {v}: {c:?}"
        );
        match &near[..] {
            [one] => {
                let e = one.curvature;
                let scale = 1.0 + e.k1.abs().max(e.k2.abs()) * size;
                assert!(
                    (c.mean - e.mean).abs() * size < 1e-7 * scale
                        && (c.gaussian - e.gaussian).abs() * size * size < 1e-7 * scale * scale,
                    "vertex {v}: {c:?} against {e:?}"
                );
                exact += 1;
            }
            [_, _] => on_crease += 1,
            _ => panic!("vertex {v} at {p} is on no side of the sheet"),
        }
    }
    assert_eq!(on_crease, 5 * steps + 1);
    assert_eq!(exact + on_crease, mesh.positions.len());
}

const TAGGED_CUBE: &str = "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n\
    f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n\
    t crease 2/1/0 4 5 10\nt corner 1/1/0 2 3.5\n";

#[test]
fn obj_crease_tags_open_as_a_cage_and_knotwork_subdivide_writes_the_level() {
    let project = knotwork::io::obj::read(TAGGED_CUBE).unwrap();
    let Some(cage) = project.scene.objects[0]
        .geometry
        .downcast_ref::<knotwork::scene::SubdivObject>()
    else {
        panic!("a tagged OBJ opens as a cage");
    };
    assert_eq!(cage.surface.creases().len(), 1);
    assert_eq!(cage.surface.corners().len(), 1);

    let dir = crate::common::scratch_dir("subdivide-tagged");
    let input = dir.join("cube.obj");
    std::fs::write(&input, TAGGED_CUBE).unwrap();
    let parsed = knotwork::io::obj::parse(TAGGED_CUBE).unwrap();
    let faces = parsed.all_faces();
    let mesh = PolygonMesh::new(parsed.vertices, &faces).unwrap();
    let surface =
        SubdivisionSurface::new(mesh, parsed.creases, parsed.corners, Options::default(), 0)
            .unwrap();
    let expected = surface.limit(2).unwrap();
    for backend in ["cpu", "gpu"] {
        let output = dir.join(format!("out-{backend}.obj"));
        let run = std::process::Command::new(env!("CARGO_BIN_EXE_knotwork"))
            .args([
                "subdivide",
                input.to_str().unwrap(),
                "--levels",
                "2",
                "--limit",
            ])
            .args(["--backend", backend, "-o", output.to_str().unwrap()])
            .output()
            .unwrap();
        assert!(
            run.status.success(),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
        let text = std::fs::read_to_string(&output).unwrap();
        let vertices: Vec<DVec3> = text
            .lines()
            .filter_map(|l| l.strip_prefix("v "))
            .map(|l| {
                let c: Vec<f64> = l.split(' ').map(|x| x.parse().unwrap()).collect();
                DVec3::new(c[0], c[1], c[2])
            })
            .collect();
        assert_eq!(vertices.len(), 98);
        assert_eq!(text.lines().filter(|l| l.starts_with("vn ")).count(), 98);
        assert_eq!(text.lines().filter(|l| l.starts_with("f ")).count(), 96);
        for (p, q) in vertices.iter().zip(&expected.positions) {
            assert!((*p - *q).length() < 1e-5, "{backend}: {p} vs {q}");
        }
    }
    // A bad cage exits 1 with the message.
    std::fs::write(
        &input,
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3 4\nf 1 2 3\n",
    )
    .unwrap();
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_knotwork"))
        .args(["subdivide", input.to_str().unwrap(), "-o"])
        .arg(dir.join("bad.obj"))
        .output()
        .unwrap();
    assert_eq!(run.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&run.stderr).contains("edges["));
}

#[test]
fn a_boundary_is_the_b_spline_with_mirrored_phantom_points() {
    // Catmull-Clark's boundary rules equal the bicubic B-spline whose control grid is extended
    // by one row of phantom points 2 P0 − P1 past each boundary: positions and normals at the
    // boundary points (away from the grid's corners) must agree.
    let m = 8;
    let mesh = grid_mesh(m);
    let p = |i: i64, j: i64| -> DVec3 {
        let clamp = |x: i64| x.clamp(0, m as i64 - 1);
        let (ci, cj) = (clamp(i), clamp(j));
        let inner = |a: i64, b: i64| mesh.points()[(a * m as i64 + b) as usize];
        let row = |b: i64| {
            if i == ci {
                inner(ci, b)
            } else {
                let toward = if i < 0 { 1 } else { -1 };
                2.0 * inner(ci, b) - inner(ci + toward, b)
            }
        };
        if j == cj {
            row(cj)
        } else {
            let toward = if j < 0 { 1 } else { -1 };
            2.0 * row(cj) - row(cj + toward)
        }
    };
    let n = m + 2;
    let points = (0..n * n)
        .map(|k| p((k / n) as i64 - 1, (k % n) as i64 - 1))
        .collect();
    let knots: Vec<f64> = (0..n + 4).map(|k| k as f64).collect();
    let extended = NurbsSurface::new([3, 3], [knots.clone(), knots], [n, n], points, None).unwrap();
    let surface = SubdivisionSurface::from_mesh(mesh, 0).unwrap();
    let limit = surface.limit(2).unwrap();
    for j in 2..m - 2 {
        for (i, v) in [(0, j), (m - 1, j), (j, 0), (j, m - 1)] {
            let index = i * m + v;
            let exact = extended
                .local_geometry(i as f64 + 3.0, v as f64 + 3.0)
                .unwrap();
            let p = limit.positions[index];
            assert!(
                (p - exact.derivatives.point).length() < 1e-12,
                "({i}, {v}): {p}"
            );
            let angle = limit.normals[index].angle_between(exact.normal);
            assert!(angle < 1e-7, "({i}, {v}): normal off by {angle}");
        }
    }
}

/// The stencil tables (the refinement's, their composition over the cage and every limit
/// slot's) are built on every core: a pool of one thread, one of four and the threaded web
/// page's scheme (the calling thread and three helpers claiming chunks) give the same feed
/// bit for bit, on cages in general position (jittered points) with extraordinary vertices,
/// semi-sharp creases and a sharp corner, under Catmull-Clark, Loop and Doo-Sabin.
#[test]
fn stencil_tables_are_the_same_bit_for_bit_on_one_thread_and_on_four() {
    use knotwork::kernel::subdiv::patches::Display;
    let mut rng = common::Rng(59);
    let mut jittered = |mesh: PolygonMesh| {
        let points: Vec<DVec3> = mesh
            .points()
            .iter()
            .map(|p| {
                *p + DVec3::new(
                    rng.range(-0.2, 0.2),
                    rng.range(-0.2, 0.2),
                    rng.range(-0.2, 0.2),
                )
            })
            .collect();
        let faces: Vec<Vec<u32>> = mesh.faces().map(|f| f.to_vec()).collect();
        PolygonMesh::new(points, &faces).unwrap()
    };
    let sharp = |mesh: PolygonMesh, scheme: Scheme| {
        let [a, b] = [
            mesh.faces().next().unwrap()[0],
            mesh.faces().next().unwrap()[1],
        ];
        with(
            mesh,
            vec![Crease {
                a,
                b,
                sharpness: 1.5,
            }],
            vec![Corner {
                vertex: 5,
                sharpness: 2.0,
            }],
            Options {
                scheme,
                ..Options::default()
            },
        )
    };
    let cases = [
        (
            sharp(
                jittered(cages::cube(DVec3::ZERO, 2.0).unwrap()),
                Scheme::CatmullClark,
            ),
            4,
        ),
        (
            sharp(
                jittered(cages::icosahedron(DVec3::ZERO, 1.5).unwrap()),
                Scheme::CatmullClark,
            ),
            3,
        ),
        (
            sharp(
                jittered(cages::icosahedron(DVec3::ZERO, 1.5).unwrap()),
                Scheme::Loop,
            ),
            4,
        ),
        (
            sharp(
                jittered(cages::cube(DVec3::ZERO, 2.0).unwrap()),
                Scheme::DooSabin,
            ),
            3,
        ),
    ];
    let pool = common::thread_pool;
    for (surface, level) in &cases {
        let build = || {
            surface
                .limit_feed_with(*level, Display::Limit, false)
                .unwrap()
        };
        let one = pool(1).install(build);
        let four = pool(4).install(build);
        let helped = par::with_helpers(par::SCOPED_HELPERS, build);
        assert!(!one.slots.is_empty() && !one.entries.is_empty());
        assert!(
            one == four && one == helped,
            "{:?} level {level}: the feeds differ",
            surface.options.scheme
        );
        let refine = || {
            surface
                .hierarchy(*level)
                .unwrap()
                .refine_points(surface.points())
        };
        let points_one = pool(1).install(refine);
        let points_four = pool(4).install(refine);
        assert!(
            points_one
                .iter()
                .zip(&points_four)
                .all(|(a, b)| a.to_array() == b.to_array())
        );
    }
}

/// A tool on a 1,536-face cage leaves a few extraordinary points (a poked face, an extruded
/// pair, a crease): the editor's GPU feed takes those faces' stencils from a refinement of
/// their neighbourhood only, and the rest as B-spline patches. Every vertex the GPU evaluates,
/// on the compute path and on the CPU (WebGL2) path, is the whole cage's f64 limit at a vertex
/// of the level: position and normal. The cage is in general position.
#[test]
fn after_a_tool_the_gpu_shows_the_whole_cages_limit_from_the_region_refined() {
    use knotwork::kernel::subdiv::cage_edit::{Cage, Tool};
    let torus = cages::torus(DVec3::ZERO, 3.0, 1.0, 48, 32).unwrap();
    let cage = Cage {
        points: torus.points().to_vec(),
        faces: torus.faces().map(<[u32]>::to_vec).collect(),
        creases: Vec::new(),
        corners: Vec::new(),
    };
    let cage = cage.apply(&Tool::Poke { faces: vec![100] }).unwrap();
    let mut cage = cage
        .apply(&Tool::Extrude {
            faces: vec![700, 701],
            offset: 0.3,
            individual: false,
        })
        .unwrap();
    let edge = (cage.faces[1200][0], cage.faces[1200][1]);
    cage.creases.push(Crease {
        a: edge.0,
        b: edge.1,
        sharpness: 1.7,
    });
    let motion = DAffine3::from_scale_rotation_translation(
        DVec3::splat(2.3),
        glam::DQuat::from_axis_angle(DVec3::new(0.3, -0.8, 0.5).normalize(), 2.1),
        DVec3::new(41.0, -17.0, 63.0),
    );
    let points: Vec<DVec3> = cage
        .points
        .iter()
        .map(|&p| motion.transform_point3(p))
        .collect();
    let mesh = PolygonMesh::new(points, &cage.faces).unwrap();
    let surface =
        SubdivisionSurface::new(mesh, cage.creases, Vec::new(), Options::default(), 2).unwrap();
    let (object, stencils) = as_scene_object(&surface);
    assert!(
        !stencils.patches.is_empty() && stencils.vertex.iter().all(|&v| v == u32::MAX),
        "the stencils come from the region's refinement"
    );
    assert!(stencils.regular.len() > 1200);
    the_scene_shows_the_limit(&surface, 2, object);
}

/// A torus split into triangles, every second ring of quads along the other diagonal, in
/// general position: no face is a regular quad, so under Catmull-Clark and under Loop the
/// editor's feed refines one neighbourhood per kind of face and every face reads those
/// stencils through its own list of points (on the GPU, through its record's point list).
/// Every vertex the GPU evaluates, on the compute and the CPU path, is the whole cage's f64
/// limit.
#[test]
fn faces_alike_share_their_stencils_on_the_gpu_and_show_the_whole_cages_limit() {
    let (columns, rows) = (24, 16);
    let torus = cages::torus(DVec3::ZERO, 3.0, 1.0, columns, rows).unwrap();
    let mut faces = Vec::new();
    for (k, face) in torus.faces().enumerate() {
        let [a, b, c, d] = [face[0], face[1], face[2], face[3]];
        if (k / rows) % 2 == 0 {
            faces.extend([vec![a, b, c], vec![a, c, d]]);
        } else {
            faces.extend([vec![b, c, d], vec![b, d, a]]);
        }
    }
    let motion = common::random_motion(&mut common::Rng(0x7e3b_9a11));
    let points: Vec<DVec3> = torus
        .points()
        .iter()
        .map(|&p| motion.transform_point3(p))
        .collect();
    for scheme in [Scheme::CatmullClark, Scheme::Loop] {
        let mesh = PolygonMesh::new(points.clone(), &faces).unwrap();
        let options = Options {
            scheme,
            ..Options::default()
        };
        let surface = SubdivisionSurface::new(mesh, Vec::new(), Vec::new(), options, 2).unwrap();
        let (object, stencils) = as_scene_object(&surface);
        assert!(
            stencils.regular.is_empty()
                && stencils.patches.len() >= faces.len()
                && stencils.patches.iter().all(|p| p.points != u32::MAX),
            "{scheme:?}: every face reads shared stencils through its point list"
        );
        let whole = surface
            .limit_feed_with(2, knotwork::kernel::subdiv::patches::Display::Limit, false)
            .unwrap();
        eprintln!(
            "{scheme:?}: {} entries shared, {} in the whole cage's table",
            stencils.entries.len(),
            whole.entries.len()
        );
        assert!(10 * stencils.entries.len() < whole.entries.len());
        the_scene_shows_the_limit(&surface, 2, object);
    }
}

/// `surface` as the editor's scene object, and the stencils its GPU feed carries.
fn as_scene_object(
    surface: &SubdivisionSurface,
) -> (
    knotwork::scene::SceneObject,
    knotwork::kernel::subdiv::patches::LimitFeed,
) {
    use knotwork::scene::{ObjectGeometry, SceneObject, SubdivObject};
    let object = SceneObject::new(
        "cage",
        ObjectGeometry::new(SubdivObject::from(surface.clone())),
    );
    let feed = object.decompose().unwrap();
    let stencils = feed.stencils.as_deref().unwrap().clone();
    (object, stencils)
}

/// Every vertex of `object` (showing `surface` at `levels`) that the GPU evaluates, on the
/// compute path and on the CPU (WebGL2) path, is the whole cage's f64 limit at a vertex of the
/// level: position within 1e-5 and normal within 1e-3 rad.
fn the_scene_shows_the_limit(
    surface: &SubdivisionSurface,
    levels: u32,
    object: knotwork::scene::SceneObject,
) {
    use knotwork::scene::Scene;
    // The level's limit points, bucketed in cells of a 400th of the cage's size.
    let limit = surface.limit(levels).unwrap();
    let (lo, hi) = surface.mesh().bounds().unwrap();
    let size = (hi - lo).length();
    let cell = size / 400.0;
    let key = |p: DVec3| ((p - lo) / cell).floor().as_ivec3().to_array();
    let mut buckets: std::collections::HashMap<[i32; 3], Vec<usize>> = Default::default();
    for (v, &p) in limit.positions.iter().enumerate() {
        buckets.entry(key(p)).or_default().push(v);
    }
    let nearest = |p: DVec3| -> Option<(f64, usize)> {
        let [x, y, z] = key(p);
        let mut best: Option<(f64, usize)> = None;
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    for &v in buckets.get(&[x + dx, y + dy, z + dz]).into_iter().flatten() {
                        let d = (limit.positions[v] - p).length();
                        if best.is_none_or(|(b, _)| d < b) {
                            best = Some((d, v));
                        }
                    }
                }
            }
        }
        best
    };
    let scene = Scene {
        objects: vec![object],
        unit: None,
    };
    for cpu in [false, true] {
        let (_, vertices) = common::evaluate_scene(&scene, cpu);
        assert!(vertices.len() >= limit.positions.len());
        let mut worst = (0.0f64, 0.0f64);
        for vertex in &vertices {
            let p = DVec3::from(vertex.position.map(f64::from));
            let n = DVec3::from(vertex.normal.map(f64::from));
            let Some((d, v)) = nearest(p) else {
                panic!("no limit point near {p} (cpu: {cpu})");
            };
            worst.0 = worst.0.max(d / size);
            worst.1 = worst.1.max(n.angle_between(limit.normals[v]));
        }
        eprintln!(
            "cpu {cpu}: {} vertices, position {:.1e}, normal {:.1e} rad",
            vertices.len(),
            worst.0,
            worst.1
        );
        assert!(worst.0 < 1e-5 && worst.1 < 1e-3, "cpu {cpu}: {worst:?}");
    }
}
