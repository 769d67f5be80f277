//! Exact curvature of subdivision limits at a level's points: Loop's regular points against a
//! closed form, Loop's boundaries and creases against a fit to the finer limit, and every exact
//! value the same when the level is refined once more.

use glam::DVec3;
use knotwork_kernel::PolygonMesh;
use knotwork_kernel::diffgeo::SurfaceDerivatives;
use knotwork_kernel::subdiv::patches::Display;
use knotwork_kernel::subdiv::{Crease, Options, Scheme, SubdivisionSurface, cages};

use crate::sheets::{Draw, QuadricLattice, Sheet, random_motion};

/// Loop's limit over a triangle lattice whose points sample a quadratic height is that quadric
/// moved up ([`QuadricLattice`]), so at every regular point away from the boundary the limit
/// display's curvature is the graph's (do Carmo §3-3, with W = 1 + |∇q|²: K = det ∇²q / W²
/// and H = ((1 + q_y²) q_xx − 2 q_x q_y q_xy + (1 + q_x²) q_yy) / (2 W^{3/2})), taken at the
/// limit point. Random lattices, quadratics and motions, levels 1 to 3; the limit mesh
/// (export's) agrees.
#[test]
fn loops_regular_points_have_the_quadrics_curvature() {
    let mut draw = Draw(0x51_7CC1_B727_220A);
    let mut checked = 0;
    for case in 0..6 {
        let quadric = QuadricLattice::random(&mut draw, 8 + case % 3, 9 + case % 2);
        let size = quadric.size();
        let options = Options {
            scheme: Scheme::Loop,
            ..Options::default()
        };
        for level in 1..=3u32 {
            let surface = SubdivisionSurface::new(
                quadric.mesh.clone(),
                Vec::new(),
                Vec::new(),
                options,
                level,
            )
            .unwrap();
            let feed = surface
                .limit_feed_with(level, Display::Limit, false)
                .unwrap();
            let exact = surface.limit(level).unwrap().curvatures(Scheme::Loop);
            let cage = surface.points();
            for (p, patch) in feed.patches.iter().enumerate() {
                let end = feed
                    .patches
                    .get(p + 1)
                    .map_or(feed.slots.len(), |next| next.first_slot as usize);
                for slot in patch.first_slot as usize..end {
                    // Slots past a triangle's diagonal repeat its first slot.
                    let vertex = feed.vertex[slot];
                    if feed.no_curvature[slot] || vertex == u32::MAX {
                        continue;
                    }
                    let derivatives = SurfaceDerivatives::from_weights(
                        cage,
                        feed.slot_entries(patch, slot).unwrap(),
                    )
                    .unwrap();
                    let Some((gaussian, mean)) = quadric.curvature_at(derivatives.point) else {
                        continue;
                    };
                    let found = derivatives.curvature_values().unwrap();
                    let e = exact[vertex as usize].unwrap();
                    for (k, h) in [(found.gaussian, found.mean), (e.gaussian, e.mean)] {
                        assert!(
                            (k - gaussian).abs() * size * size < 1e-8
                                && (h - mean).abs() * size < 1e-8,
                            "case {case} level {level} slot {slot}: K {k} H {h} against K {gaussian} H {mean}"
                        );
                    }
                    checked += 1;
                }
            }
        }
    }
    assert!(checked > 2000, "{checked} slots checked");
}

/// Each exact value is the limit's own, not the level's: refined once more, the point is still
/// a point of the level (with the same limit position) and its curvature is the same, on
/// uneven cages where no polynomial fits (a jittered torus under Catmull-Clark, creased sheets,
/// a jittered lattice torus and a creased sheet under Loop).
#[test]
fn exact_curvature_is_the_same_one_level_finer() {
    let mut draw = Draw(0x9A3C_0F1E_22D4_7B51);
    let jitter = |mesh: PolygonMesh, draw: &mut Draw| {
        let motion = random_motion(draw);
        let faces: Vec<Vec<u32>> = mesh.faces().map(<[u32]>::to_vec).collect();
        let points = mesh
            .points()
            .iter()
            .map(|&p| {
                let shake = DVec3::new(draw.unit(), draw.unit(), draw.unit()) * 0.2 - 0.1;
                motion.transform_point3(p + shake)
            })
            .collect();
        PolygonMesh::new(points, &faces).unwrap()
    };
    let torus = cages::torus(DVec3::ZERO, 2.0, 0.7, 8, 6).unwrap();
    // The same torus's quads split along one diagonal: six triangles at every point.
    let triangles: Vec<Vec<u32>> = torus
        .faces()
        .flat_map(|f| [vec![f[0], f[1], f[2]], vec![f[0], f[2], f[3]]])
        .collect();
    let lattice = PolygonMesh::new(torus.points().to_vec(), &triangles).unwrap();
    let sheet = Sheet::random(&mut draw, 4, 4, Some(2));
    let mut cases: Vec<(SubdivisionSurface, usize)> = vec![
        (
            SubdivisionSurface::from_mesh(jitter(torus, &mut draw), 0).unwrap(),
            0,
        ),
        (
            SubdivisionSurface::new(
                jitter(lattice, &mut draw),
                Vec::new(),
                Vec::new(),
                Options {
                    scheme: Scheme::Loop,
                    ..Options::default()
                },
                0,
            )
            .unwrap(),
            0,
        ),
        (sheet.surface(0), 0),
    ];
    // A sheet with its boundary rule "edge only" and a crease, as most cages come.
    let open = Sheet::random(&mut draw, 5, 4, None);
    cases.push((
        SubdivisionSurface::new(
            open.mesh.clone(),
            vec![Crease {
                a: 7,
                b: 8,
                sharpness: 10.0,
            }],
            Vec::new(),
            Options::default(),
            0,
        )
        .unwrap(),
        0,
    ));
    // The same under Loop, its quads split along one diagonal: three triangles on each side
    // of the crease and along the boundary.
    cases.push((Sheet::random(&mut draw, 5, 5, Some(2)).loop_surface(0), 0));
    for (c, (surface, _)) in cases.iter_mut().enumerate() {
        let scheme = surface.options.scheme;
        let (lo, hi) = surface.mesh().bounds().unwrap();
        let size = (hi - lo).length();
        for level in 1..=2u32 {
            let coarse = surface.limit(level).unwrap();
            let fine = surface.limit(level + 1).unwrap();
            let (coarse_values, fine_values) = (coarse.curvatures(scheme), fine.curvatures(scheme));
            let mut compared = 0;
            for (v, value) in coarse_values.iter().enumerate() {
                let Some(value) = value else {
                    continue;
                };
                let p = coarse.positions[v];
                let w = fine
                    .positions
                    .iter()
                    .position(|q| q.distance(p) < 1e-12 * size)
                    .unwrap_or_else(|| panic!("case {c}: point {v} is not a finer point"));
                let finer = fine_values[w].unwrap_or_else(|| {
                    panic!("case {c}: point {v} has no curvature a level finer")
                });
                let k = value.k1.abs().max(value.k2.abs()).max(1.0 / size);
                assert!(
                    (finer.mean - value.mean).abs() < 1e-9 * k
                        && (finer.gaussian - value.gaussian).abs() < 1e-9 * k * k,
                    "case {c} level {level} point {v}: {value:?} then {finer:?}"
                );
                compared += 1;
            }
            assert!(
                compared > 40,
                "case {c} level {level}: {compared} points compared"
            );
        }
    }
}

/// Loop's exact curvature along the boundary and on each side of a crease (the box spline of
/// the side's net extended by phantom points) against an estimate that shares none of its
/// assumptions: a quadric height z = a x² + b xy + c y² + d x + e y fitted by least squares to
/// the limit positions, six levels finer, of the points within a small radius on the side's
/// half (Monge patch, do Carmo §3-3: W = 1 + d² + e², K = (4ac − b²)/W²,
/// H = ((1 + e²) 2a − 2de b + (1 + d²) 2c)/(2 W^{3/2})). The fit's error is of the order of
/// its radius, so two radii, r and r/2, are extrapolated to zero (2 f(r/2) − f(r)), and the
/// check is to 5 % (the worst seen: 2.6 %, next to a corner). Phantom points taken as
/// reflections through the point (2v − e) instead missed by more than 100 %. At the corners
/// of one triangle (boundary rule "edge and corner") the exact curvature is zero
/// ([`loop_corner_weights`]); there the fit takes the cubic terms too, and its |H| · size and
/// |K| · size² must be under 0.03 (the worst seen: 9.3e-3; on the sides |H| · size is 0.03 to
/// 15, median 4.4). Random jittered sheets in random positions, at the cage's own points.
#[test]
fn loops_boundary_and_crease_curvature_matches_a_fit_to_the_finer_limit() {
    use knotwork_kernel::subdiv::limit::{loop_corner_weights, loop_sided_weights};
    let mut draw = Draw(0x3D_19A7_C0E2_5B44);
    let (mut boundary, mut crease, mut corners) = (0, 0, 0);
    let (mut worst, mut worst_corner): (f64, f64) = (0.0, 0.0);
    for case in 0..4 {
        let sheet = Sheet::random(&mut draw, 5, 5, Some(2));
        let surface = sheet.loop_surface(0);
        let coarse = surface.limit(0).unwrap();
        let fine = surface.limit(6).unwrap();
        let level = &coarse.level;
        // Eight steps of the finer level (a cage step is about size / (5√2)).
        let radius = 8.0 * sheet.size / (5.0 * std::f64::consts::SQRT_2 * 64.0);
        for v in 0..coarse.positions.len() as u32 {
            let p = coarse.positions[v as usize];
            let ring = level.ring(v);
            for &f in &ring.faces {
                // u along a sharp edge of the side (the crease's tangent).
                let Some(weights) = ring
                    .neighbours
                    .iter()
                    .filter(|&&n| {
                        let e = level.edge_between(v, n).unwrap();
                        level.is_boundary_edge(e as u32) || level.edge_sharpness[e] > 0.0
                    })
                    .find_map(|&n| {
                        loop_sided_weights(level, v, n, 0, f, 1.0)
                            .or_else(|| loop_corner_weights(level, v, n, 0, 1.0))
                    })
                else {
                    continue;
                };
                let d = SurfaceDerivatives::from_weights(&coarse.refined, weights).unwrap();
                let exact = d.curvature_values().unwrap();
                let normal = d.su.cross(d.sv).normalize();
                let x_axis = d.su.normalize();
                // y into the side: towards the face's centroid.
                let centroid = level
                    .face(f)
                    .iter()
                    .map(|&c| coarse.positions[c as usize])
                    .sum::<DVec3>()
                    / 3.0;
                let mut y_axis = normal.cross(x_axis);
                if (centroid - p).dot(y_axis) < 0.0 {
                    y_axis = -y_axis;
                }
                // (Turning y over leaves K and H about +z as they are.)
                let axes = [x_axis, y_axis, normal];
                if ring.neighbours.len() == 2 {
                    // The limit at a corner of one triangle is the point, a linear map and
                    // terms of third degree: fitted with the cubic terms too, the height's
                    // quadratic part is the limit's up to terms of fourth degree.
                    let (gaussian, mean) =
                        monge_fit::<9, 10>(&fine.positions, p, axes, radius, |x, y| {
                            [
                                x * x,
                                x * y,
                                y * y,
                                x,
                                y,
                                x * x * x,
                                x * x * y,
                                x * y * y,
                                y * y * y,
                            ]
                        });
                    let error = (mean * sheet.size)
                        .abs()
                        .max(gaussian.abs() * sheet.size.powi(2));
                    worst_corner = worst_corner.max(error);
                    assert!(
                        exact.gaussian == 0.0 && exact.mean == 0.0 && error < 0.03,
                        "case {case} corner {v}: exact K {} H {}, fitted K {gaussian} H {mean}",
                        exact.gaussian,
                        exact.mean
                    );
                    corners += 1;
                    continue;
                }
                let fit = |radius: f64| {
                    monge_fit::<5, 6>(&fine.positions, p, axes, radius, |x, y| {
                        [x * x, x * y, y * y, x, y]
                    })
                };
                let ((k1, h1), (k2, h2)) = (fit(radius), fit(radius / 2.0));
                let (gaussian, mean) = (2.0 * k2 - k1, 2.0 * h2 - h1);
                let k = exact.k1.abs().max(exact.k2.abs()).max(1.0 / sheet.size);
                let error = ((exact.mean - mean).abs() / k)
                    .max((exact.gaussian - gaussian).abs() / (k * k));
                worst = worst.max(error);
                assert!(
                    error < 0.05,
                    "case {case} point {v} face {f}: exact K {} H {}, fitted K {gaussian} H {mean}",
                    exact.gaussian,
                    exact.mean
                );
                if ring.boundary {
                    boundary += 1;
                } else {
                    crease += 1;
                }
            }
        }
    }
    eprintln!(
        "{boundary} boundary sides, {crease} crease sides, worst {worst:.2e}; \
         {corners} corners, worst {worst_corner:.2e}"
    );
    assert!(
        boundary > 100 && crease > 60 && corners == 8,
        "{boundary} boundary and {crease} crease sides, {corners} corners"
    );
}

/// The Gaussian and mean curvature at `p` of the height over the plane of `axes` (x, y and
/// the normal) fitted by least squares to the `points` within `radius` of `p` on the side
/// y ≥ 0, as a sum of the `N` `terms` whose first five are x², xy, y², x and y (Monge patch,
/// do Carmo §3-3: z = a x² + b xy + c y² + d x + e y + …, W = 1 + d² + e²,
/// K = (4ac − b²)/W², H = ((1 + e²) 2a − 2de b + (1 + d²) 2c)/(2 W^{3/2})). `M` is N + 1.
fn monge_fit<const N: usize, const M: usize>(
    points: &[DVec3],
    p: DVec3,
    [x_axis, y_axis, normal]: [DVec3; 3],
    radius: f64,
    terms: impl Fn(f64, f64) -> [f64; N],
) -> (f64, f64) {
    let mut m = [[0.0f64; M]; N];
    let mut used = 0;
    for q in points {
        let r = *q - p;
        let (x, y, z) = (r.dot(x_axis), r.dot(y_axis), r.dot(normal));
        if r.length() > radius || y < -1e-9 * radius {
            continue;
        }
        let row = terms(x, y);
        for i in 0..N {
            for j in 0..N {
                m[i][j] += row[i] * row[j];
            }
            m[i][N] += row[i] * z;
        }
        used += 1;
    }
    assert!(used >= 2 * N + 2, "{used} points in the fit of {N} terms");
    let x = solve(m);
    let [a, b, c, dx, dy] = [x[0], x[1], x[2], x[3], x[4]];
    let w = 1.0 + dx * dx + dy * dy;
    let gaussian = (4.0 * a * c - b * b) / (w * w);
    let mean = ((1.0 + dy * dy) * 2.0 * a - 2.0 * dx * dy * b + (1.0 + dx * dx) * 2.0 * c)
        / (2.0 * w.powf(1.5));
    (gaussian, mean)
}

/// The solution of the N × N system whose augmented rows are `m` (Gaussian elimination with
/// partial pivoting).
fn solve<const N: usize, const M: usize>(mut m: [[f64; M]; N]) -> [f64; N] {
    for col in 0..N {
        let pivot = (col..N)
            .max_by(|&i, &j| m[i][col].abs().total_cmp(&m[j][col].abs()))
            .unwrap();
        m.swap(col, pivot);
        let pivot_row = m[col];
        for below in m.iter_mut().skip(col + 1) {
            let f = below[col] / pivot_row[col];
            for (x, p) in below[col..].iter_mut().zip(&pivot_row[col..]) {
                *x -= f * p;
            }
        }
    }
    let mut x = [0.0; N];
    for row in (0..N).rev() {
        let sum: f64 = (row + 1..N).map(|k| m[row][k] * x[k]).sum();
        x[row] = (m[row][N] - sum) / m[row][row];
    }
    x
}
