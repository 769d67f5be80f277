//! Single-thread throughput of the f64 NURBS kernel on a bicubic rational surface with 8 × 8
//! control points (the benchmark surface):
//!
//!   cargo bench --bench kernel_eval         (KNOTWORK_BENCH_GRID=N for an N × N grid)
//!
//! - grid, point + normal: `NurbsSurface::tessellate_grid` (basis once per row and column)
//! - grid, 2nd derivatives + curvature: `NurbsSurface::curvature_grid`
//! - random (u, v), point + normal / + curvature: span search and A2.3 at every point
//!
//! Each figure is the median of several runs, in million points per second.

use std::hint::black_box;
use std::time::Instant;

use glam::DVec3;
use knotwork::kernel::NurbsSurface;
use knotwork::kernel::basis::uniform_clamped_knots;

fn surface() -> NurbsSurface {
    let n = 8;
    let mut points = Vec::new();
    let mut weights = Vec::new();
    for i in 0..n {
        for j in 0..n {
            let (x, y) = (i as f64, j as f64);
            points.push(DVec3::new(x, y, (0.7 * x).sin() + (0.5 * y).cos()));
            weights.push(0.5 + ((i * 7 + j * 3) % 5) as f64 * 0.4);
        }
    }
    let knots = uniform_clamped_knots(3, n);
    NurbsSurface::new(
        [3, 3],
        [knots.clone(), knots],
        [n, n],
        points,
        Some(weights),
    )
    .unwrap_or_else(|e| panic!("benchmark surface: {e}"))
}

/// Runs `f` (which evaluates `points` points) several times; returns the median rate in M/s
/// and the median time per call in ms.
fn rate(points: usize, runs: usize, mut f: impl FnMut()) -> (f64, f64) {
    f(); // warm up
    let mut times: Vec<f64> = (0..runs)
        .map(|_| {
            let start = Instant::now();
            f();
            start.elapsed().as_secs_f64()
        })
        .collect();
    times.sort_by(f64::total_cmp);
    let t = times[times.len() / 2];
    (points as f64 / t / 1e6, t * 1e3)
}

/// A deterministic sequence in [0, 1) (the golden-ratio additive recurrence).
fn params(count: usize, offset: f64) -> Vec<f64> {
    let phi = 0.618_033_988_749_894_9;
    (0..count)
        .map(|k| (offset + k as f64 * phi).fract())
        .collect()
}

fn main() {
    let s = surface();
    let grid: usize = std::env::var("KNOTWORK_BENCH_GRID")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(1000)
        .max(2);
    let us: Vec<f64> = (0..grid).map(|k| k as f64 / (grid - 1) as f64).collect();
    let n = grid * grid;
    println!("kernel: bicubic rational NURBS, 8 x 8 control points, one thread");

    let mut buffer = Vec::new();
    let (mps, ms) = rate(n, 7, || {
        s.tessellate_grid_into(&us, &us, &mut buffer).ok();
        black_box(&buffer);
    });
    println!("grid {grid}x{grid}, point + normal:            {mps:7.2} M points/s  ({ms:.1} ms)");

    let mut buffer = Vec::new();
    let (mps, ms) = rate(n, 5, || {
        s.curvature_grid_into(&us, &us, &mut buffer).ok();
        black_box(&buffer);
    });
    println!("grid {grid}x{grid}, 2nd derivatives + K,H,k1,k2: {mps:7.2} M points/s  ({ms:.1} ms)");

    let random = 200_000;
    let ru = params(random, 0.1);
    let rv = params(random, 0.7).into_iter().rev().collect::<Vec<_>>();
    let (mps, ms) = rate(random, 5, || {
        for (&u, &v) in ru.iter().zip(&rv) {
            black_box(s.normal(u, v).ok());
        }
    });
    let per = ms * 1e6 / random as f64;
    println!(
        "random (u,v), point + normal (with 2nd ders): {mps:7.2} M points/s  ({per:.0} ns each)"
    );

    let (mps, ms) = rate(random, 5, || {
        for (&u, &v) in ru.iter().zip(&rv) {
            black_box(s.local_geometry(u, v).ok());
        }
    });
    let per = ms * 1e6 / random as f64;
    println!(
        "random (u,v), + curvature:                    {mps:7.2} M points/s  ({per:.0} ns each)"
    );
}
