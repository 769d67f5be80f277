//! Render pipelines: the shaded surface drawn from the compute pass's vertex buffer, and the
//! control net overlay. They draw into an offscreen [`ViewTarget`], which the editor shows as an
//! egui image and tests read back.

mod viewport;

pub use viewport::{
    COLOR_FORMAT, ControlNet, DEPTH_FORMAT, DrawOptions, POINT_COLOR, SAMPLE_COUNT, Shading,
    ViewTarget, ViewportRenderer, scene_uniform,
};
