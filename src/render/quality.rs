//! How the viewport trades image quality for speed. On a GPU every frame gets 4× multisampling
//! at full resolution. On a software adapter (lavapipe, SwiftShader, WARP: most of a frame is the
//! fragment work of the multisampled pass) frames drawn while the view or the model moves use
//! one sample at a lower resolution, and the frame after the motion stops is drawn at full
//! quality again.

use super::viewport::SAMPLE_COUNT;

/// Samples per pixel and resolution scale of the viewport, at rest and in motion.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Quality {
    /// Samples per pixel while the view rests (1 or [`SAMPLE_COUNT`]).
    pub samples: u32,
    /// Samples per pixel while dragging or orbiting.
    pub drag_samples: u32,
    /// Resolution scale while dragging or orbiting, in (0, 1]: the target is this fraction of
    /// the viewport's physical pixels in each direction, shown stretched.
    pub drag_scale: f32,
}

/// Whether [`Quality::for_adapter`] treats the adapter as a software rasterizer
/// ([`crate::gpu::context::is_software_adapter`]).
pub use crate::gpu::context::is_software_adapter as is_software;

impl Quality {
    /// Full quality in every frame.
    pub fn hardware() -> Self {
        Self {
            samples: SAMPLE_COUNT,
            drag_samples: SAMPLE_COUNT,
            drag_scale: 1.0,
        }
    }

    /// Full quality at rest; one sample at half the resolution in motion (a quarter of the
    /// pixels and a sixteenth of the samples).
    pub fn software() -> Self {
        Self {
            samples: SAMPLE_COUNT,
            drag_samples: 1,
            drag_scale: 0.5,
        }
    }

    /// [`Self::software`] on a software adapter, else [`Self::hardware`].
    pub fn for_adapter(info: &wgpu::AdapterInfo) -> Self {
        if is_software(info) {
            Self::software()
        } else {
            Self::hardware()
        }
    }

    /// Samples and target size for a viewport of `size` physical pixels, in motion or at rest.
    pub fn target(&self, size: (u32, u32), moving: bool) -> (u32, (u32, u32)) {
        if !moving {
            return (self.samples, size);
        }
        let scale = |v: u32| ((v as f32 * self.drag_scale).round() as u32).clamp(1, v.max(1));
        (self.drag_samples, (scale(size.0), scale(size.1)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn software_adapters_drop_samples_and_resolution_only_in_motion() {
        let q = Quality::software();
        assert_eq!(q.target((1280, 800), false), (4, (1280, 800)));
        assert_eq!(q.target((1280, 800), true), (1, (640, 400)));
        assert_eq!(q.target((1, 1), true), (1, (1, 1)));
        let h = Quality::hardware();
        assert_eq!(h.target((1280, 800), true), (4, (1280, 800)));
    }
}
