//! A small GPU-to-CPU copy that no frame waits for (works in the browser too): record a copy
//! into the staging buffer, start mapping it after the submission, and take the bytes once the
//! map has completed. GPU timing and the adaptive tessellation's statistics use it.

use std::sync::Arc;
use std::sync::atomic::{AtomicU8, Ordering};

const IDLE: u8 = 0;
const MAPPING: u8 = 1;
const MAPPED: u8 = 2;
const FAILED: u8 = 3;

pub struct AsyncReadback {
    staging: Arc<wgpu::Buffer>,
    state: Arc<AtomicU8>,
    copy_recorded: bool,
}

impl AsyncReadback {
    /// A staging buffer of `size` bytes.
    pub fn new(device: &wgpu::Device, label: &str, size: u64) -> Self {
        Self {
            staging: Arc::new(device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })),
            state: Arc::new(AtomicU8::new(IDLE)),
            copy_recorded: false,
        }
    }

    /// Whether a new copy may be recorded: no earlier one is recorded, mapping or unread.
    pub fn idle(&self) -> bool {
        !self.copy_recorded && self.state.load(Ordering::Acquire) == IDLE
    }

    /// Records a copy of `size` bytes of `source` from `offset` into the staging buffer, when
    /// [`Self::idle`]; returns whether it did.
    pub fn record(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        source: &wgpu::Buffer,
        offset: u64,
        size: u64,
    ) -> bool {
        if !self.idle() {
            return false;
        }
        encoder.copy_buffer_to_buffer(source, offset, &self.staging, 0, size);
        self.copy_recorded = true;
        true
    }

    /// Call after submitting the encoder given to [`Self::record`]: starts mapping.
    pub fn after_submit(&mut self) {
        if !std::mem::take(&mut self.copy_recorded) {
            return;
        }
        self.state.store(MAPPING, Ordering::Release);
        let state = Arc::clone(&self.state);
        self.staging
            .map_async(wgpu::MapMode::Read, .., move |result| {
                state.store(
                    if result.is_ok() { MAPPED } else { FAILED },
                    Ordering::Release,
                );
            });
    }

    /// Whether a copy is still on its way.
    pub fn pending(&self) -> bool {
        self.state.load(Ordering::Acquire) == MAPPING
    }

    /// The copied bytes once mapped (then the buffer is free again); `None` before that or
    /// when the map failed.
    pub fn take(&mut self) -> Option<Vec<u8>> {
        match self.state.load(Ordering::Acquire) {
            MAPPED => {}
            FAILED => {
                self.state.store(IDLE, Ordering::Release);
                return None;
            }
            _ => return None,
        }
        let bytes = self
            .staging
            .get_mapped_range(..)
            .ok()
            .map(|view| view.to_vec());
        self.staging.unmap();
        self.state.store(IDLE, Ordering::Release);
        bytes
    }
}
