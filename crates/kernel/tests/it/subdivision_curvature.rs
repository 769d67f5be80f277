//! Exact curvature of subdivision limits at a level's points: Loop's regular points against a
//! closed form, and every exact value the same when the level is refined once more.

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
/// a jittered lattice torus under Loop).
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
