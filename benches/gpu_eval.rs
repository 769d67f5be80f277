//! Throughput and edit latency of the GPU evaluator (the same figures as `knotwork bench`: the
//! benchmark groups of `src/cli/bench/groups.rs`, compiled in here too), and the f64 CPU
//! reference for comparison.
//!
//!   cargo bench --bench gpu_eval            (KNOTWORK_BENCH_ITERATIONS=N to change the count)

use std::time::{Duration, Instant};

// The group names are the command line's, which this bench does not parse.
#[allow(dead_code)]
#[path = "../src/cli/bench/groups.rs"]
mod groups;

use knotwork::gpu::GpuContext;
use knotwork::kernel::{BezierPatchSet, samples};

fn bench_cpu(teapot: &BezierPatchSet, segments: u32) {
    let n = segments as usize + 1;
    let start = Instant::now();
    let mut checksum = 0.0;
    let mut count = 0usize;
    while start.elapsed() < Duration::from_millis(500) || count == 0 {
        for k in 0..teapot.patches().len() {
            for i in 0..n {
                for j in 0..n {
                    let (u, v) = (i as f64 / segments as f64, j as f64 / segments as f64);
                    if let Ok(d) = teapot.evaluate(k, u, v) {
                        let normal = teapot.normal_from(&teapot.patches()[k], &d, u, v);
                        checksum += d.point.x + normal.z;
                    }
                    count += 1;
                }
            }
        }
    }
    let rate = count as f64 / start.elapsed().as_secs_f64();
    println!(
        "cpu  teapot {segments:>3} segments: f64 reference (point, derivatives, normal), one thread: {:6.2} M points/s (checksum {checksum:.1})",
        rate / 1e6
    );
}

fn main() {
    let iterations = std::env::var("KNOTWORK_BENCH_ITERATIONS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(20);
    let context = match GpuContext::headless_blocking() {
        Ok(c) => c,
        Err(e) => {
            eprintln!("gpu_eval: {e}");
            std::process::exit(1);
        }
    };
    if let Err(e) = groups::run(&context, iterations, "all", &mut std::io::stdout()) {
        eprintln!("gpu_eval: {e}");
        std::process::exit(1);
    }
    match samples::utah_teapot() {
        Ok(teapot) => {
            for segments in [16, 64] {
                bench_cpu(&teapot, segments);
            }
        }
        Err(e) => eprintln!("gpu_eval: {e}"),
    }
}
