//! Render pipelines: the shaded surface drawn from the compute pass's vertex buffer, and the
//! control net overlay. They draw into an offscreen [`ViewTarget`], which the editor shows as an
//! egui image and tests read back.

pub mod guides;
mod quality;
mod viewport;

pub use quality::{Quality, is_software};

pub use viewport::{
    BACKGROUND, CHECKER_CELLS, COLOR_FORMAT, ControlNet, DEPTH_FORMAT, DRAFT_COLORS, GuideLines,
    LEVEL_COLORS, LineVertex, POINT_COLOR, SAMPLE_COUNT, ViewTarget, ViewportRenderer,
    adaptive_target, scene_uniform,
};
