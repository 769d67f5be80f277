//! wgpu device setup, shared by the editor (through eframe) and headless use (tests, benches, CLI).
//!
//! Adapter choice is explicit: [`adapter_shortfall`] says, from an adapter's description alone,
//! what it lacks for knotwork's compute shaders, and [`choose_adapter`] takes the best adapter
//! that lacks nothing. An adapter without compute (a GL driver, say) is never handed to the
//! evaluator, whose pipelines would otherwise fail inside wgpu.

use super::error::GpuError;

/// What to do when no adapter can run the compute shaders.
#[cfg(not(target_arch = "wasm32"))]
pub const ADAPTER_HINT: &str = "on Linux without a GPU install lavapipe, a software Vulkan driver \
(Debian/Ubuntu: apt-get install mesa-vulkan-drivers); elsewhere update the graphics driver, \
or unset WGPU_BACKEND if it names gl";
/// What to do when no adapter can run the compute shaders, in a browser.
#[cfg(target_arch = "wasm32")]
pub const ADAPTER_HINT: &str = "a browser with WebGPU runs the compute shaders (Chrome or Edge \
113 and later, Safari 26, Firefox 141 on Windows; on Linux start Chrome with \
--enable-unsafe-webgpu)";

/// The limits knotwork needs of a device: WebGPU's defaults (so what runs natively also runs
/// in the browser) with 8192² textures. A hardware GPU is asked for larger buffers where it
/// has them ([`limits_for`]).
pub fn required_limits() -> wgpu::Limits {
    wgpu::Limits {
        max_texture_dimension_2d: 8192,
        ..wgpu::Limits::default()
    }
}

/// The most one storage binding, and one buffer, may hold on a hardware adapter (1 GiB): eight
/// times WebGPU's default binding, room for 16 Mi vertices of 64 bytes, well inside the video
/// memory of any GPU that offers it.
pub const HARDWARE_BINDING_CAP: u64 = 1 << 30;

/// Whether `info` describes a software rasterizer (lavapipe, SwiftShader, WARP, a browser's
/// fallback adapter): by device type, or by name where a driver reports another type.
pub fn is_software_adapter(info: &wgpu::AdapterInfo) -> bool {
    let name = info.name.to_ascii_lowercase();
    info.device_type == wgpu::DeviceType::Cpu
        || [
            "llvmpipe",
            "lavapipe",
            "swiftshader",
            "softpipe",
            "warp",
            "microsoft basic render",
        ]
        .iter()
        .any(|s| name.contains(s))
}

/// The limits knotwork asks of an adapter described by `info` with limits `adapter`, which
/// meets [`required_limits`]: those, with the storage binding and buffer sizes raised to the
/// adapter's own (at most [`HARDWARE_BINDING_CAP`]) where the adapter is a hardware GPU, so
/// that a large model is evaluated at full quality where its buffers fit the GPU rather than
/// WebGPU's 128 MiB default. A software adapter keeps the defaults: its buffers are the
/// machine's memory, and its speed, not its limits, is what bounds a model there. Asking for
/// no more than the adapter reports is what WebGPU and wgpu promise to grant.
pub fn limits_for(info: &wgpu::AdapterInfo, adapter: &wgpu::Limits) -> wgpu::Limits {
    let mut limits = required_limits();
    if !is_software_adapter(info) {
        let raised = |asked: u64, offered: u64| asked.max(offered.min(HARDWARE_BINDING_CAP));
        limits.max_buffer_size = raised(limits.max_buffer_size, adapter.max_buffer_size);
        limits.max_storage_buffer_binding_size = raised(
            limits.max_storage_buffer_binding_size,
            adapter.max_storage_buffer_binding_size,
        )
        .min(limits.max_buffer_size);
    }
    limits
}

/// Limits below [`required_limits`] named in a refusal; the rest are counted.
const LIMITS_NAMED: usize = 3;

/// What an adapter lacks for the evaluator and the viewport, from its description alone:
/// compute shaders (a downlevel flag) and the limits below [`required_limits`] (storage and
/// compute limits first; [`LIMITS_NAMED`] of them by name, the rest counted). Empty when it has everything.
pub fn adapter_shortfall(
    downlevel: &wgpu::DownlevelCapabilities,
    limits: &wgpu::Limits,
) -> Vec<String> {
    let mut missing = Vec::new();
    if !downlevel
        .flags
        .contains(wgpu::DownlevelFlags::COMPUTE_SHADERS)
    {
        missing.push("no compute shaders".to_owned());
    }
    let mut short = Vec::new();
    required_limits().check_limits_with_fail_fn(limits, false, |name, needed, has| {
        short.push(format!("{name} {has} (needs {needed})"));
    });
    // The limits the compute shaders need most are named first.
    short.sort_by_key(|text| !(text.contains("storage") || text.contains("compute")));
    let more = short.len().saturating_sub(LIMITS_NAMED);
    missing.extend(short.into_iter().take(LIMITS_NAMED));
    if more > 0 {
        missing.push(format!("{more} more limits below WebGPU's defaults"));
    }
    missing
}

/// "GL · llvmpipe (LLVM 15.0.6, 256 bits)".
fn adapter_label(info: &wgpu::AdapterInfo) -> String {
    let name = if info.name.is_empty() {
        "(unnamed adapter)"
    } else {
        info.name.as_str()
    };
    format!("{} · {name}", backend_name(info.backend))
}

/// [`adapter_shortfall`] as a refusal: `Ok` for an adapter that has everything, otherwise
/// [`GpuError::UnsuitableAdapter`] naming it, what it lacks and what to install.
pub fn check_adapter(
    info: &wgpu::AdapterInfo,
    downlevel: &wgpu::DownlevelCapabilities,
    limits: &wgpu::Limits,
) -> Result<(), GpuError> {
    let missing = adapter_shortfall(downlevel, limits);
    if missing.is_empty() {
        return Ok(());
    }
    Err(GpuError::UnsuitableAdapter {
        found: format!("{}: {}", adapter_label(info), missing.join(", ")),
        hint: ADAPTER_HINT,
    })
}

/// [`check_adapter`] for a live adapter.
pub fn check(adapter: &wgpu::Adapter) -> Result<(), GpuError> {
    check_adapter(
        &adapter.get_info(),
        &adapter.get_downlevel_capabilities(),
        &adapter.limits(),
    )
}

/// Preference among suitable adapters: a discrete GPU, then integrated, virtual, a CPU
/// (lavapipe, SwiftShader), anything else.
fn preference(device_type: wgpu::DeviceType) -> u8 {
    match device_type {
        wgpu::DeviceType::DiscreteGpu => 0,
        wgpu::DeviceType::IntegratedGpu => 1,
        wgpu::DeviceType::VirtualGpu => 2,
        wgpu::DeviceType::Cpu => 3,
        wgpu::DeviceType::Other => 4,
    }
}

/// The best adapter of `adapters` that can run the compute shaders (see [`preference`]); when
/// none can, the refusal names every adapter and what it lacks.
pub fn choose_adapter(adapters: &[wgpu::Adapter]) -> Result<&wgpu::Adapter, GpuError> {
    let mut refusals = Vec::new();
    let mut best: Option<&wgpu::Adapter> = None;
    for adapter in adapters {
        match check(adapter) {
            Ok(()) => {
                let rank = |a: &wgpu::Adapter| preference(a.get_info().device_type);
                if best.is_none_or(|b| rank(adapter) < rank(b)) {
                    best = Some(adapter);
                }
            }
            Err(GpuError::UnsuitableAdapter { found, .. }) => refusals.push(found),
            Err(e) => refusals.push(e.to_string()),
        }
    }
    match best {
        Some(adapter) => Ok(adapter),
        None if refusals.is_empty() => Err(GpuError::NoAdapter("wgpu found no adapter".into())),
        None => Err(GpuError::UnsuitableAdapter {
            found: refusals.join("; "),
            hint: ADAPTER_HINT,
        }),
    }
}

/// The device the editor, tests and benchmarks ask for: [`limits_for`] the adapter (WebGPU's
/// defaults, larger buffers on a hardware GPU), plus `TIMESTAMP_QUERY` where the adapter has
/// it (GPU timings in the status panel and the benchmarks). An adapter that cannot meet
/// [`required_limits`] (the editor then shows why, and draws nothing) gets a device at its own
/// limits so that the window can still open.
pub fn device_descriptor(adapter: &wgpu::Adapter) -> wgpu::DeviceDescriptor<'static> {
    let required_limits = if check(adapter).is_ok() {
        limits_for(&adapter.get_info(), &adapter.limits())
    } else {
        wgpu::Limits::downlevel_webgl2_defaults().using_resolution(adapter.limits())
    };
    wgpu::DeviceDescriptor {
        label: Some("knotwork device"),
        required_features: adapter.features() & wgpu::Features::TIMESTAMP_QUERY,
        required_limits,
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
    /// Opens the best adapter that can run the compute shaders ([`choose_adapter`] over the
    /// adapters of the backends `WGPU_BACKEND` allows). Fails, never falls back silently, when
    /// there is none, naming what each adapter found lacks.
    pub async fn headless() -> Result<Self, GpuError> {
        let descriptor = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
        let backends = descriptor.backends;
        let instance = wgpu::Instance::new(descriptor);
        #[cfg(not(target_arch = "wasm32"))]
        let adapter = {
            let adapters = instance.enumerate_adapters(backends).await;
            choose_adapter(&adapters)?.clone()
        };
        #[cfg(target_arch = "wasm32")]
        let adapter = {
            let _ = backends;
            let adapter = instance
                .request_adapter(&wgpu::RequestAdapterOptions::default())
                .await
                .map_err(|e| GpuError::NoAdapter(e.to_string()))?;
            check(&adapter)?;
            adapter
        };
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

#[cfg(test)]
mod tests {
    use super::*;

    fn info(backend: wgpu::Backend, name: &str) -> wgpu::AdapterInfo {
        wgpu::AdapterInfo {
            name: name.into(),
            vendor: 0,
            device: 0,
            device_type: wgpu::DeviceType::Cpu,
            device_pci_bus_id: String::new(),
            driver: String::new(),
            driver_info: String::new(),
            backend,
            subgroup_min_size: 0,
            subgroup_max_size: 0,
            transient_saves_memory: None,
            limit_bucket: None,
        }
    }

    #[test]
    fn an_adapter_without_compute_is_refused_with_what_it_lacks_and_what_to_install() {
        // A GL adapter as wgpu reports one without compute: no COMPUTE_SHADERS flag and
        // WebGL2's limits (no storage buffers, a workgroup size of zero).
        let gl = wgpu::DownlevelCapabilities {
            flags: wgpu::DownlevelFlags::empty(),
            ..Default::default()
        };
        let limits = wgpu::Limits::downlevel_webgl2_defaults();
        let refusal =
            check_adapter(&info(wgpu::Backend::Gl, "llvmpipe"), &gl, &limits).expect_err("refused");
        let message = refusal.to_string();
        for expected in [
            "webgl2/gl · llvmpipe",
            "no compute shaders",
            "max_storage_buffers_per_shader_stage 0 (needs 8)",
            "more limits below WebGPU's defaults",
            "mesa-vulkan-drivers",
        ] {
            assert!(message.contains(expected), "{expected:?} in {message}");
        }
    }

    #[test]
    fn an_adapter_with_webgpu_defaults_and_compute_is_accepted() {
        let full = wgpu::DownlevelCapabilities::default();
        let mut limits = required_limits();
        assert!(check_adapter(&info(wgpu::Backend::Vulkan, "llvmpipe"), &full, &limits).is_ok());
        // One limit short is enough to refuse, and it is named.
        limits.max_storage_buffers_per_shader_stage = 4;
        let message = check_adapter(&info(wgpu::Backend::Vulkan, "x"), &full, &limits)
            .expect_err("refused")
            .to_string();
        assert!(
            message.contains("max_storage_buffers_per_shader_stage 4 (needs 8)")
                && !message.contains("no compute shaders"),
            "{message}"
        );
    }

    /// An adapter's description of `device_type` named `name` (WebGPU's backend).
    fn typed(device_type: wgpu::DeviceType, name: &str) -> wgpu::AdapterInfo {
        wgpu::AdapterInfo {
            device_type,
            ..info(wgpu::Backend::BrowserWebGpu, name)
        }
    }

    #[test]
    fn a_hardware_gpu_gets_its_own_buffer_limits_up_to_the_cap_and_software_the_defaults() {
        let defaults = required_limits();
        let mut big = required_limits();
        big.max_storage_buffer_binding_size = u64::from(u32::MAX);
        big.max_buffer_size = u64::MAX;
        // A software rasterizer keeps WebGPU's defaults whatever it offers, by type or by name.
        for software in [
            typed(wgpu::DeviceType::Cpu, ""),
            typed(wgpu::DeviceType::Other, "SwiftShader Device (Subzero)"),
            typed(
                wgpu::DeviceType::DiscreteGpu,
                "llvmpipe (LLVM 15.0.6, 256 bits)",
            ),
        ] {
            assert!(is_software_adapter(&software));
            assert_eq!(limits_for(&software, &big), defaults, "{}", software.name);
        }
        // A GPU offering more than the cap (NVIDIA's Vulkan driver offers 4 GiB − 1 a binding)
        // gets the cap; one offering WebGPU's defaults gets them; a browser's GPU adapter
        // (type Other) is a hardware one.
        for gpu in [
            typed(wgpu::DeviceType::DiscreteGpu, "NVIDIA H200"),
            typed(wgpu::DeviceType::Other, ""),
        ] {
            assert!(!is_software_adapter(&gpu));
            let raised = limits_for(&gpu, &big);
            assert_eq!(raised.max_storage_buffer_binding_size, HARDWARE_BINDING_CAP);
            assert_eq!(raised.max_buffer_size, HARDWARE_BINDING_CAP);
            assert_eq!(
                wgpu::Limits {
                    max_storage_buffer_binding_size: defaults.max_storage_buffer_binding_size,
                    max_buffer_size: defaults.max_buffer_size,
                    ..raised
                },
                defaults,
                "only the two buffer limits change"
            );
            assert_eq!(limits_for(&gpu, &defaults), defaults);
        }
        // A binding larger than the adapter's largest buffer is cut to the buffer.
        let mut lopsided = required_limits();
        lopsided.max_storage_buffer_binding_size = 512 << 20;
        lopsided.max_buffer_size = 384 << 20;
        let gpu = typed(
            wgpu::DeviceType::IntegratedGpu,
            "Intel(R) Iris(R) Xe Graphics",
        );
        let raised = limits_for(&gpu, &lopsided);
        assert_eq!(raised.max_storage_buffer_binding_size, 384 << 20);
        assert_eq!(raised.max_buffer_size, 384 << 20);
    }

    #[test]
    fn the_limits_asked_lie_between_the_defaults_and_what_the_adapter_offers() {
        // Adapters that meet the defaults, with buffer limits drawn from 128 MiB to 16 GiB:
        // the request must be one the adapter grants (no limit above its own) and one the
        // evaluator can work with (no limit below the defaults).
        let defaults = required_limits();
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        let mut draw = |lo: u64, hi: u64| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            lo + state % (hi - lo + 1)
        };
        for _ in 0..2000 {
            let mut adapter = required_limits();
            adapter.max_buffer_size = draw(defaults.max_buffer_size, 16 << 30);
            adapter.max_storage_buffer_binding_size =
                draw(defaults.max_storage_buffer_binding_size, 16 << 30);
            let kind = [
                wgpu::DeviceType::DiscreteGpu,
                wgpu::DeviceType::IntegratedGpu,
                wgpu::DeviceType::VirtualGpu,
                wgpu::DeviceType::Other,
                wgpu::DeviceType::Cpu,
            ][draw(0, 4) as usize];
            let asked = limits_for(&typed(kind, ""), &adapter);
            assert!(asked.check_limits(&adapter), "{kind:?} {adapter:?}");
            assert!(defaults.check_limits(&asked), "{kind:?} {asked:?}");
            assert!(
                asked.max_storage_buffer_binding_size
                    <= asked
                        .max_buffer_size
                        .max(defaults.max_storage_buffer_binding_size)
            );
            assert!(asked.max_buffer_size <= HARDWARE_BINDING_CAP.max(defaults.max_buffer_size));
        }
    }
}
