//! Throughput and latency of teapot evaluation: the WGSL compute pass on whatever adapter wgpu
//! finds (lavapipe here), and the f64 CPU reference for comparison.
//!
//!   cargo bench --bench gpu_eval            (KNOTWORK_BENCH_ITERATIONS=N to change the count)
//!
//! GPU time comes from timestamp queries around the compute pass where the device has them;
//! "latency" is wall time from writing new control points to the vertices being ready (submit,
//! evaluate, wait), which is what a drag costs before drawing.

use std::time::{Duration, Instant};

use knotwork::gpu::timing::GpuTimer;
use knotwork::gpu::{GpuContext, PatchEvaluator, PatchGeometry};
use knotwork::kernel::{BezierPatchSet, samples};

fn median(mut values: Vec<f64>) -> f64 {
    values.sort_by(f64::total_cmp);
    values[values.len() / 2]
}

fn bench_gpu(context: &GpuContext, teapot: &BezierPatchSet, segments: u32, iterations: usize) {
    let evaluator = PatchEvaluator::new(&context.device);
    let mut geometry = match PatchGeometry::new(&context.device, &evaluator, teapot, segments) {
        Ok(g) => g,
        Err(e) => {
            println!("gpu  teapot {segments:>3} segments: {e}");
            return;
        }
    };
    let mut timer = GpuTimer::new(&context.device, &context.queue);
    let mut gpu_ms = Vec::new();
    let mut wall_ms = Vec::new();
    for i in 0..iterations + 3 {
        let start = Instant::now();
        geometry
            .update_control_points(&context.queue, teapot)
            .expect("same model");
        let mut encoder = context.device.create_command_encoder(&Default::default());
        let writes = timer.as_mut().and_then(GpuTimer::compute_pass_writes);
        geometry.encode(&mut encoder, &evaluator, writes);
        if let Some(timer) = &mut timer {
            timer.resolve(&mut encoder);
        }
        context.queue.submit([encoder.finish()]);
        if let Some(timer) = &mut timer {
            timer.after_submit();
        }
        context
            .device
            .poll(wgpu::PollType::wait_indefinitely())
            .expect("device alive");
        let elapsed = start.elapsed();
        if let Some(timer) = &mut timer {
            while timer.pending() {
                let _ = context.device.poll(wgpu::PollType::wait_indefinitely());
            }
            timer.collect();
        }
        if i >= 3 {
            wall_ms.push(elapsed.as_secs_f64() * 1e3);
            if let Some(ms) = timer.as_ref().and_then(|t| t.latest.eval_ms) {
                gpu_ms.push(ms);
            }
        }
    }
    let vertices = f64::from(geometry.vertex_count());
    let wall = median(wall_ms);
    let gpu = (!gpu_ms.is_empty()).then(|| median(gpu_ms));
    println!(
        "gpu  teapot {segments:>3} segments: {:>8} vertices | GPU pass {} | latency (write points → vertices ready) {wall:8.3} ms | {:7.2} M vertices/s",
        geometry.vertex_count(),
        gpu.map_or("     n/a".to_owned(), |ms| format!("{ms:8.3} ms")),
        vertices / (gpu.unwrap_or(wall) * 1e-3) / 1e6,
    );
}

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
    // `cargo bench` passes --bench; `cargo test --benches` passes nothing we need to honour.
    let iterations = std::env::var("KNOTWORK_BENCH_ITERATIONS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(20);
    let teapot = match samples::utah_teapot() {
        Ok(t) => t,
        Err(e) => {
            eprintln!("gpu_eval: {e}");
            std::process::exit(1);
        }
    };
    let context = match GpuContext::headless_blocking() {
        Ok(c) => c,
        Err(e) => {
            eprintln!("gpu_eval: {e}");
            std::process::exit(1);
        }
    };
    println!("adapter: {}", context.describe());
    for segments in [16, 32, 64, 128] {
        bench_gpu(&context, &teapot, segments, iterations);
    }
    for segments in [16, 64] {
        bench_cpu(&teapot, segments);
    }
}
