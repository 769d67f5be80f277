//! Typed errors of the GPU layer, shown in the UI's status line.

use thiserror::Error;

#[derive(Debug, Clone, PartialEq, Error)]
pub enum GpuError {
    #[error(
        "no GPU adapter found: {0} (on Linux install lavapipe: apt-get install mesa-vulkan-drivers)"
    )]
    NoAdapter(String),
    #[error(
        "no usable GPU adapter: {found}. knotwork evaluates surfaces with compute shaders; {hint}"
    )]
    UnsuitableAdapter {
        /// Each adapter found and what it lacks ("GL · llvmpipe: no compute shaders").
        found: String,
        /// What to install or change.
        hint: &'static str,
    },
    #[error("the GPU device could not be created: {0}")]
    RequestDevice(String),
    #[error(
        "object {object}, patch {patch}: degree ({degree_u}, {degree_v}) is above the GPU evaluator's maximum {max} (reduce the degree or split the surface)"
    )]
    DegreeTooHigh {
        object: usize,
        patch: usize,
        degree_u: usize,
        degree_v: usize,
        max: u32,
    },
    #[error("{count} patches exceed the {max} one dispatch can evaluate")]
    TooManyPatches { count: usize, max: u32 },
    #[error("{count} objects exceed the {max} the GPU's vertices can name")]
    TooManyObjects { count: usize, max: usize },
    #[error("tessellation of {segments} segments per patch edge is outside 1..={max}")]
    SegmentsOutOfRange { segments: u32, max: u32 },
    #[error("the {what} buffer would need {bytes} bytes; this device allows {limit}")]
    BufferTooLarge {
        what: &'static str,
        bytes: u64,
        limit: u64,
    },
    #[error("the model has {found} control points but its GPU buffers hold {expected}")]
    ControlPointCountChanged { expected: usize, found: usize },
    #[error("there is no object {object} (the scene has {count})")]
    NoSuchObject { object: usize, count: usize },
    #[error("object {object} has no patch {patch} (it has {count})")]
    NoSuchPatch {
        object: usize,
        patch: usize,
        count: usize,
    },
    #[error("the surface could not be prepared for the GPU: {0}")]
    Geometry(String),
    #[error(
        "this GPU has no compute shaders (WebGL2: the CPU evaluates the surfaces), so it cannot run {0}"
    )]
    NeedsCompute(&'static str),
    #[error("reading back from the GPU failed: {0}")]
    Readback(String),
}
