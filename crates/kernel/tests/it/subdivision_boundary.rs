//! The boundary patches of a Catmull-Clark surface (a regular quad with one side on the
//! boundary: the bicubic B-spline with the outer row extrapolated) against the exact limit
//! points of the refined levels.

use glam::DVec3;
use knotwork_kernel::PolygonMesh;
use knotwork_kernel::subdiv::patches::boundary_bspline_grid;
use knotwork_kernel::subdiv::{Options, SubdivisionSurface};

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
