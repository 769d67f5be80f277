//! Helpers shared by the GPU tests.
#![allow(dead_code)]

use std::path::PathBuf;

use knotwork::gpu::GpuContext;

/// The headless GPU the tests run on (lavapipe here). Fails — never skips — without one.
pub fn gpu() -> GpuContext {
    match GpuContext::headless_blocking() {
        Ok(context) => {
            eprintln!("GPU adapter: {}", context.describe());
            context
        }
        Err(e) => panic!("GPU tests need an adapter and found none: {e}"),
    }
}

/// Where failing image tests write their actual, expected and difference images.
pub fn artifact_path(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("image-tests");
    std::fs::create_dir_all(&dir).expect("artifact directory");
    dir.join(name)
}

/// Writes tightly packed RGBA8 pixels as a PNG.
pub fn write_png(path: &PathBuf, width: u32, height: u32, rgba: &[u8]) {
    let file = std::fs::File::create(path).expect("create png");
    let mut encoder = png::Encoder::new(std::io::BufWriter::new(file), width, height);
    encoder.set_color(png::ColorType::Rgba);
    encoder.set_depth(png::BitDepth::Eight);
    let mut writer = encoder.write_header().expect("png header");
    writer.write_image_data(rgba).expect("png data");
}

/// Submits one compute pass evaluating `geometry`.
pub fn evaluate(
    context: &GpuContext,
    evaluator: &knotwork::gpu::PatchEvaluator,
    geometry: &mut knotwork::gpu::PatchGeometry,
) {
    let mut encoder = context.device.create_command_encoder(&Default::default());
    geometry.encode(&mut encoder, evaluator, None);
    context.queue.submit([encoder.finish()]);
}
