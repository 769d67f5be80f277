//! GPU timing with timestamp queries: how long the evaluation (compute) pass and the render pass
//! took on the GPU, read back asynchronously so that no frame waits for it (works on the web too).

use super::async_readback::AsyncReadback;

/// Queries: 0/1 bracket the compute pass, 2/3 the render pass.
const QUERY_COUNT: u32 = 4;
/// `resolve_query_set` destinations must be 256-byte aligned: compute at 0, render at 256.
const RENDER_RESOLVE_OFFSET: u64 = wgpu::QUERY_RESOLVE_BUFFER_ALIGNMENT;
const BUFFER_SIZE: u64 = 2 * wgpu::QUERY_RESOLVE_BUFFER_ALIGNMENT;

/// The latest GPU pass durations, in milliseconds.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct GpuTimings {
    pub eval_ms: Option<f64>,
    pub render_ms: Option<f64>,
}

pub struct GpuTimer {
    query_set: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    readback: AsyncReadback,
    period_ns: f64,
    /// Which pairs the current frame wrote: (compute, render).
    written: (bool, bool),
    /// Which pairs the buffer being mapped holds.
    in_flight: (bool, bool),
    pub latest: GpuTimings,
}

impl GpuTimer {
    /// `None` when the device lacks `TIMESTAMP_QUERY`.
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue) -> Option<Self> {
        if !device.features().contains(wgpu::Features::TIMESTAMP_QUERY) {
            return None;
        }
        let query_set = device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some("knotwork timestamps"),
            ty: wgpu::QueryType::Timestamp,
            count: QUERY_COUNT,
        });
        Some(Self {
            query_set,
            resolve: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("timestamp resolve"),
                size: BUFFER_SIZE,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            }),
            readback: AsyncReadback::new(device, "timestamp readback", BUFFER_SIZE),
            period_ns: f64::from(queue.get_timestamp_period()),
            written: (false, false),
            in_flight: (false, false),
            latest: GpuTimings::default(),
        })
    }

    fn idle(&self) -> bool {
        self.readback.idle()
    }

    /// Timestamp writes for this frame's compute pass, while no earlier readback is in flight.
    pub fn compute_pass_writes(&mut self) -> Option<wgpu::ComputePassTimestampWrites<'_>> {
        if !self.idle() {
            return None;
        }
        self.written.0 = true;
        Some(wgpu::ComputePassTimestampWrites {
            query_set: &self.query_set,
            beginning_of_pass_write_index: Some(0),
            end_of_pass_write_index: Some(1),
        })
    }

    /// Timestamp writes for this frame's render pass, while no earlier readback is in flight.
    pub fn render_pass_writes(&mut self) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
        if !self.idle() {
            return None;
        }
        self.written.1 = true;
        Some(wgpu::RenderPassTimestampWrites {
            query_set: &self.query_set,
            beginning_of_pass_write_index: Some(2),
            end_of_pass_write_index: Some(3),
        })
    }

    /// Records the resolve and the copy into the readback buffer for what this frame timed.
    pub fn resolve(&mut self, encoder: &mut wgpu::CommandEncoder) {
        let (compute, render) = std::mem::take(&mut self.written);
        if !(compute || render) || !self.idle() {
            return;
        }
        if compute {
            encoder.resolve_query_set(&self.query_set, 0..2, &self.resolve, 0);
        }
        if render {
            encoder.resolve_query_set(&self.query_set, 2..4, &self.resolve, RENDER_RESOLVE_OFFSET);
        }
        self.readback.record(encoder, &self.resolve, 0, BUFFER_SIZE);
        self.in_flight = (compute, render);
    }

    /// Call after submitting the encoder given to [`Self::resolve`]: starts mapping the results.
    pub fn after_submit(&mut self) {
        self.readback.after_submit();
    }

    /// Whether a readback is still on its way (the caller should keep frames coming).
    pub fn pending(&self) -> bool {
        self.readback.pending()
    }

    /// Takes finished results into [`Self::latest`]. Returns true when new figures arrived.
    pub fn collect(&mut self) -> bool {
        let ticks = self.readback.take().map(|bytes| {
            let words: Vec<u64> = bytemuck::pod_collect_to_vec(&bytes);
            let stride = (RENDER_RESOLVE_OFFSET / 8) as usize;
            (
                words[1].saturating_sub(words[0]),
                words[stride + 1].saturating_sub(words[stride]),
            )
        });
        let Some((eval, render)) = ticks else {
            return false;
        };
        let to_ms = |t: u64| t as f64 * self.period_ns / 1e6;
        if self.in_flight.0 {
            self.latest.eval_ms = Some(to_ms(eval));
        }
        if self.in_flight.1 {
            self.latest.render_ms = Some(to_ms(render));
        }
        true
    }
}
