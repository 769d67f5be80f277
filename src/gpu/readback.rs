//! Blocking copies from GPU buffers to the CPU (native only: tests, benchmarks, the CLI).

use super::error::GpuError;

/// Copies `size` bytes from the start of `source` (which needs `COPY_SRC`) into a `Vec`, waiting
/// for the GPU.
pub fn read_buffer(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    source: &wgpu::Buffer,
    size: u64,
) -> Result<Vec<u8>, GpuError> {
    if size == 0 {
        return Ok(Vec::new());
    }
    let staging = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("knotwork readback"),
        size,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut encoder = device.create_command_encoder(&Default::default());
    encoder.copy_buffer_to_buffer(source, 0, &staging, 0, size);
    queue.submit([encoder.finish()]);
    map_and_copy(device, &staging)
}

/// The first `count` elements of type `T` of `source` (blocking; see [`read_buffer`]).
pub fn read_elements<T: bytemuck::Pod>(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    source: &wgpu::Buffer,
    count: u32,
) -> Result<Vec<T>, GpuError> {
    let size = u64::from(count) * std::mem::size_of::<T>() as u64;
    let bytes = read_buffer(device, queue, source, size)?;
    Ok(bytemuck::pod_collect_to_vec(&bytes))
}

/// Maps a `MAP_READ` buffer, waits, and copies its contents out.
pub fn map_and_copy(device: &wgpu::Device, staging: &wgpu::Buffer) -> Result<Vec<u8>, GpuError> {
    let (sender, receiver) = std::sync::mpsc::channel();
    staging.map_async(wgpu::MapMode::Read, .., move |result| {
        // The receiver outlives the poll below; a failed send only means nobody is listening.
        let _ = sender.send(result);
    });
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| GpuError::Readback(e.to_string()))?;
    receiver
        .recv()
        .map_err(|e| GpuError::Readback(e.to_string()))?
        .map_err(|e| GpuError::Readback(e.to_string()))?;
    let bytes = staging
        .get_mapped_range(..)
        .map_err(|e| GpuError::Readback(e.to_string()))?
        .to_vec();
    staging.unmap();
    Ok(bytes)
}
