//! The boundary patches of a Catmull-Clark surface (a regular quad with one side on the
//! boundary: the bicubic B-spline with the outer row extrapolated) against the exact limit
//! points of the refined levels.

use glam::DVec3;
use knotwork_kernel::PolygonMesh;
use knotwork_kernel::subdiv::patches::boundary_bspline_grid;
use knotwork_kernel::subdiv::{Options, SubdivisionSurface};

use crate::sheets::{Draw, Sheet};

/// A (n + 1) × (n + 1) grid of points over a bumpy, unevenly spaced sheet, as quads.
fn sheet(n: u32) -> SubdivisionSurface {
    let mut points = Vec::new();
    for i in 0..=n {
        for j in 0..=n {
            let (x, y) = (f64::from(i), f64::from(j));
            points.push(DVec3::new(
                x + 0.15 * (1.3 * y).sin(),
                y + 0.1 * (0.7 * x).cos(),
                0.4 * (0.9 * x).sin() * (0.6 * y + 0.3).cos() + 0.05 * x * y,
            ));
        }
    }
    let at = |i: u32, j: u32| i * (n + 1) + j;
    let faces: Vec<Vec<u32>> = (0..n)
        .flat_map(|i| {
            (0..n).map(move |j| vec![at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)])
        })
        .collect();
    let mesh = PolygonMesh::new(points, &faces).unwrap();
    SubdivisionSurface::new(mesh, Vec::new(), Vec::new(), Options::default(), 2).unwrap()
}

/// The uniform cubic B-spline's four weights at t ∈ [0, 1].
fn bspline(t: f64) -> [f64; 4] {
    let s = 1.0 - t;
    [
        s * s * s / 6.0,
        (3.0 * t * t * t - 6.0 * t * t + 4.0) / 6.0,
        (-3.0 * t * t * t + 3.0 * t * t + 3.0 * t + 1.0) / 6.0,
        t * t * t / 6.0,
    ]
}

#[test]
fn boundary_patches_pass_through_the_exact_limit_points() {
    let n = 5;
    let surface = sheet(n);
    let level = surface.base_level().unwrap();
    let scheme = surface.options.scheme;
    let limit = surface.limit(2).unwrap();
    let mut boundary_faces = 0;
    for f in 0..level.face_count() as u32 {
        let Some(grid) = boundary_bspline_grid(&level, scheme, f) else {
            continue;
        };
        boundary_faces += 1;
        let points: Vec<DVec3> = grid.iter().map(|row| row.apply(surface.points())).collect();
        // The level-2 vertices over the face lie at (i / 4, j / 4): each patch point there is
        // one of the exact limit points.
        for i in 0..=4 {
            for j in 0..=4 {
                let (bu, bv) = (bspline(f64::from(i) / 4.0), bspline(f64::from(j) / 4.0));
                let mut p = DVec3::ZERO;
                for a in 0..4 {
                    for b in 0..4 {
                        p += points[a * 4 + b] * (bu[a] * bv[b]);
                    }
                }
                let nearest = limit
                    .positions
                    .iter()
                    .map(|q| q.distance(p))
                    .fold(f64::INFINITY, f64::min);
                assert!(
                    nearest < 1e-12,
                    "face {f} at ({i}, {j}): {nearest:.3e} from the limit"
                );
            }
        }
    }
    // Every side of the 5 × 5 sheet has three faces away from the corners.
    assert_eq!(boundary_faces, 4 * (n as usize - 2));
}

/// Catmull-Clark's limit beside the boundary, at the sheet's corners and on both sides of an
/// infinitely sharp crease is the bicubic B-spline of the net extended across them
/// ([`sheets::extended_bspline`], each side of the crease a sheet of its own). Every slot of
/// the limit display on random sheets (uneven, in general position, with and without a crease
/// across, levels 1 to 3) has defined curvature, and its position, normal, Gaussian and mean
/// curvature and principal curvatures are the closed form's at the same point.
#[test]
fn curvature_along_boundaries_and_creases_is_the_extended_bspline() {
    use knotwork_kernel::diffgeo::{CurvatureValues, FundamentalForms, SurfaceDerivatives};
    use knotwork_kernel::subdiv::patches::Display;
    let mut draw = Draw(0x5DEE_CE66_D1CE_B00C);
    let mut checked = [0usize; 2];
    for case in 0..8 {
        let (m, n) = (3 + case % 3, 3 + (case / 2) % 3);
        // Half the cases creased along a row of points, boundary to boundary.
        let crease_row = (case % 2 == 1).then_some(1 + case % (m - 1));
        let sheet = Sheet::random(&mut draw, m, n, crease_row);
        let size = sheet.size;
        for level in 1..=3u32 {
            let surface = sheet.surface(level);
            let feed = surface
                .limit_feed_with(level, Display::Limit, false)
                .unwrap();
            let points = surface.points();
            let steps = 1usize << level;
            for (p, patch) in feed.patches.iter().enumerate() {
                let first = patch.first_slot as usize;
                let end = feed
                    .patches
                    .get(p + 1)
                    .map_or(feed.slots.len(), |next| next.first_slot as usize);
                let closed = sheet.half_of_face(patch.cage_face as usize);
                for slot in first..end {
                    assert!(
                        !feed.no_curvature[slot],
                        "case {case} level {level}: slot {slot} of face {} has no curvature",
                        patch.cage_face
                    );
                    let found = SurfaceDerivatives::from_weights(
                        points,
                        feed.slot_entries(patch, slot).unwrap(),
                    )
                    .unwrap();
                    // The closed form's grid point nearest the slot's limit point.
                    let [(_, u_end), (_, v_end)] = closed.domain();
                    let (mut best, mut reference) = (f64::INFINITY, None);
                    for a in 0..=u_end as usize * steps {
                        for b in 0..=v_end as usize * steps {
                            let (u, v) = (a as f64 / steps as f64, b as f64 / steps as f64);
                            let e = closed.evaluate(u, v).unwrap();
                            let distance = e.point.distance(found.point);
                            if distance < best {
                                best = distance;
                                reference = Some(e);
                            }
                        }
                    }
                    let reference = reference.unwrap();
                    assert!(
                        best < 1e-9 * size,
                        "case {case} level {level}: slot {slot} is {best:.3e} from the closed form's grid"
                    );
                    let normal = found.regular_normal().unwrap();
                    let normal_ref = reference.regular_normal().unwrap();
                    assert!(
                        normal.dot(normal_ref) > 1.0 - 1e-9,
                        "case {case} level {level}: slot {slot} normal {normal} against {normal_ref}"
                    );
                    let curvature = |d: &SurfaceDerivatives, normal| {
                        CurvatureValues::from_forms(&FundamentalForms::new(d, normal)).unwrap()
                    };
                    let (k, k_ref) = (curvature(&found, normal), curvature(&reference, normal_ref));
                    let scale = 1.0 + k_ref.k1.abs().max(k_ref.k2.abs()) * size;
                    for (name, x, y) in [
                        ("K", k.gaussian * size * size, k_ref.gaussian * size * size),
                        ("H", k.mean * size, k_ref.mean * size),
                        ("k1", k.k1 * size, k_ref.k1 * size),
                        ("k2", k.k2 * size, k_ref.k2 * size),
                    ] {
                        assert!(
                            (x - y).abs() < 1e-7 * scale * scale,
                            "case {case} level {level}: slot {slot} {name} {x} against {y} (relative to the size)"
                        );
                    }
                    checked[usize::from(crease_row.is_some())] += 1;
                }
            }
        }
    }
    assert!(
        checked[0] > 1000 && checked[1] > 1000,
        "{checked:?} slots checked"
    );
}

/// The limit mesh's exact curvatures (what export writes for a Catmull-Clark surface) on the
/// same random sheets: every vertex has one except those on the crease, whose two sides
/// differ, and each is the closed form's at its point.
#[test]
fn the_limit_mesh_has_the_closed_forms_curvature_off_the_crease() {
    let mut draw = Draw(0x2545_F491_4F6C_DD1D);
    for case in 0..6 {
        let (m, n) = (3 + case % 2, 3 + case % 3);
        let crease_row = (case % 2 == 0).then_some(1 + case % (m - 1));
        let sheet = Sheet::random(&mut draw, m, n, crease_row);
        let size = sheet.size;
        for level in 1..=3u32 {
            let steps = 1usize << level;
            let limit = sheet.surface(level).limit(level).unwrap();
            let curvatures = limit.curvatures(Options::default().scheme);
            let references = sheet.references(level);
            let mut missing = 0;
            for (v, c) in curvatures.iter().enumerate() {
                let Some(c) = c else {
                    missing += 1;
                    continue;
                };
                let (p, normal) = (limit.positions[v], limit.normals[v]);
                let exact = references
                    .iter()
                    .filter(|g| g.derivatives.point.distance(p) < 1e-9 * size)
                    .max_by(|a, b| normal.dot(a.normal).total_cmp(&normal.dot(b.normal)))
                    .unwrap();
                assert!(normal.dot(exact.normal) > 1.0 - 1e-9);
                let e = exact.curvature;
                let scale = 1.0 + e.k1.abs().max(e.k2.abs()) * size;
                assert!(
                    (c.mean - e.mean).abs() * size < 1e-7 * scale
                        && (c.gaussian - e.gaussian).abs() * size * size < 1e-7 * scale * scale,
                    "case {case} level {level} vertex {v}: {c:?} against {e:?}"
                );
            }
            // The crease's points at this level, ends included.
            let on_crease = crease_row.map_or(0, |_| n * steps + 1);
            assert_eq!(missing, on_crease, "case {case} level {level}");
        }
    }
}
