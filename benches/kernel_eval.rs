//! Single-thread throughput of the f64 NURBS kernel on a bicubic rational surface with 8 × 8
//! control points (the benchmark surface):
//!
//!   cargo bench --bench kernel_eval         (KNOTWORK_BENCH_GRID=N for an N × N grid)
//!
//! - grid, point + normal: `NurbsSurface::tessellate_grid` (basis once per row and column,
//!   four rows per SIMD lane group)
//! - the same in tiles of 100 × 100, the size of one face's export grid (the output stays in
//!   cache, so this is the arithmetic without the memory traffic of a 48 MB result)
//! - grid, 2nd derivatives + curvature: `NurbsSurface::curvature_grid`
//! - random (u, v), point + normal / + curvature: span search and A2.3 at every point
//!
//! Each figure is the median of several runs, in million points per second.
//!
//! The peers run in the same invocation where `npm install --prefix benches/peers` has been
//! done (and node is on the path): openNURBS (rhino3dm, WebAssembly) and verb-nurbs on the same
//! surface, whose evaluations are first checked to agree with each other; the bench prints
//! their rates and the ratios.

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

    let normals = mps;

    // The same million points as 100 tiles of 100 × 100, each over its own part of the domain.
    let tile: Vec<Vec<f64>> = (0..10)
        .map(|t| {
            (0..100)
                .map(|k| (t as f64 + k as f64 / 99.0) / 10.0)
                .collect()
        })
        .collect();
    let mut buffer = Vec::new();
    let (mps, ms) = rate(100 * 100 * 100, 7, || {
        for tu in &tile {
            for tv in &tile {
                s.tessellate_grid_into(tu, tv, &mut buffer).ok();
                black_box(&buffer);
            }
        }
    });
    println!("100 tiles of 100x100, point + normal:       {mps:7.2} M points/s  ({ms:.1} ms)");
    let tiles = mps;

    let mut buffer = Vec::new();
    let (mps, ms) = rate(n, 5, || {
        s.curvature_grid_into(&us, &us, &mut buffer).ok();
        black_box(&buffer);
    });
    println!("grid {grid}x{grid}, 2nd derivatives + K,H,k1,k2: {mps:7.2} M points/s  ({ms:.1} ms)");
    let curvature = mps;
    let probe = s
        .point_at(0.3, 0.7)
        .unwrap_or_else(|e| panic!("probe: {e}"));

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

    peers(probe, normals, tiles, curvature);
}

/// Runs `benches/peers/kernel_peers.mjs` (openNURBS and verb-nurbs in node) and prints their
/// rates beside knotwork's; says how to install them where they are missing.
fn peers(probe: DVec3, normals: f64, tiles: f64, curvature: f64) {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("benches/peers");
    if !dir.join("node_modules/rhino3dm").exists() || !dir.join("node_modules/verb-nurbs").exists()
    {
        println!("peers: not installed (npm install --prefix benches/peers, then run again)");
        return;
    }
    let output = match std::process::Command::new("node")
        .arg(dir.join("kernel_peers.mjs"))
        .output()
    {
        Ok(output) if output.status.success() => output,
        Ok(output) => {
            println!(
                "peers: node failed: {}",
                String::from_utf8_lossy(&output.stderr)
            );
            return;
        }
        Err(e) => {
            println!("peers: cannot run node: {e}");
            return;
        }
    };
    let text = String::from_utf8_lossy(&output.stdout);
    let value = |name: &str| -> Option<Vec<f64>> {
        text.lines()
            .find_map(|line| line.strip_prefix(name)?.strip_prefix(' '))
            .map(|rest| rest.split(' ').filter_map(|v| v.parse().ok()).collect())
    };
    let (Some(theirs), Some(points), Some(peer_normals), Some(verb)) = (
        value("probe"),
        value("opennurbs_points"),
        value("opennurbs_normals"),
        value("verb_second_derivatives"),
    ) else {
        println!("peers: unexpected output:\n{text}");
        return;
    };
    let off = (DVec3::new(theirs[0], theirs[1], theirs[2]) - probe).length();
    let between = value("agree")
        .and_then(|v| v.first().copied())
        .unwrap_or(f64::NAN);
    println!(
        "peers, one thread, same surface (S(0.3, 0.7): verb to knotwork {off:.1e}, openNURBS to verb {between:.1e}):"
    );
    let (points, peer_normals, verb) = (points[0], peer_normals[0], verb[0]);
    println!(
        "  openNURBS (rhino3dm 8.35, WASM): {points:5.2} M points/s, {peer_normals:5.2} M normals/s"
    );
    println!("  verb-nurbs 3.0.3: {verb:5.2} M points/s with second derivatives");
    println!(
        "  grid with normals: {:.0}x openNURBS (tiles: {:.0}x); grid with curvature: {:.0}x verb",
        normals / peer_normals,
        tiles / peer_normals,
        curvature / verb
    );
}
