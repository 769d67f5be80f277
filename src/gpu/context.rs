//! wgpu device setup, shared by the editor (through eframe) and headless use (tests, benches, CLI).

use super::error::GpuError;

/// The device the editor, tests and benchmarks ask for: WebGPU's default limits (so what runs
/// natively also runs in the browser) with 8192² textures, plus `TIMESTAMP_QUERY` where the adapter
/// has it (GPU timings in the status panel and the benchmarks).
pub fn device_descriptor(adapter: &wgpu::Adapter) -> wgpu::DeviceDescriptor<'static> {
    let base = if adapter.get_info().backend == wgpu::Backend::Gl {
        wgpu::Limits::downlevel_webgl2_defaults()
    } else {
        wgpu::Limits::default()
    };
    wgpu::DeviceDescriptor {
        label: Some("knotwork device"),
        required_features: adapter.features() & wgpu::Features::TIMESTAMP_QUERY,
        required_limits: wgpu::Limits {
            max_texture_dimension_2d: 8192,
            ..base
        },
        ..Default::default()
    }
}

/// A short lowercase name of a wgpu backend, as `window.knotwork.status().backend` reports it.
pub fn backend_name(backend: wgpu::Backend) -> &'static str {
    match backend {
        wgpu::Backend::Vulkan => "vulkan",
        wgpu::Backend::Metal => "metal",
        wgpu::Backend::Dx12 => "dx12",
        wgpu::Backend::Gl => "webgl2/gl",
        wgpu::Backend::BrowserWebGpu => "webgpu",
        wgpu::Backend::Noop => "noop",
    }
}

/// A device without a window: for tests, benchmarks and the command line.
pub struct GpuContext {
    pub adapter: wgpu::Adapter,
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
}

impl GpuContext {
    /// Opens the first adapter wgpu offers (honouring `WGPU_BACKEND` and friends). Fails, never
    /// falls back silently, when there is none.
    pub async fn headless() -> Result<Self, GpuError> {
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        let adapter = instance
            .request_adapter(&wgpu::RequestAdapterOptions {
                power_preference: wgpu::PowerPreference::from_env()
                    .unwrap_or(wgpu::PowerPreference::HighPerformance),
                force_fallback_adapter: false,
                compatible_surface: None,
                apply_limit_buckets: false,
            })
            .await
            .map_err(|e| GpuError::NoAdapter(e.to_string()))?;
        let (device, queue) = adapter
            .request_device(&device_descriptor(&adapter))
            .await
            .map_err(|e| GpuError::RequestDevice(e.to_string()))?;
        Ok(Self {
            adapter,
            device,
            queue,
        })
    }

    /// Blocking [`Self::headless`] for native callers.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn headless_blocking() -> Result<Self, GpuError> {
        pollster::block_on(Self::headless())
    }

    /// "Vulkan · llvmpipe (LLVM 15.0.6, 256 bits)" and the like.
    pub fn describe(&self) -> String {
        let info = self.adapter.get_info();
        format!("{:?} · {}", info.backend, info.name)
    }
}
