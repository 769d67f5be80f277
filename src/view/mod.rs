//! Camera, screen-space picking, drag constraints and the view settings.

pub mod camera;
pub mod follow;
pub mod osnap;
pub mod pick;
pub mod settings;

pub use camera::OrbitCamera;
pub use pick::{Constraint, PickView, Projected, SurfaceHit};
pub use settings::{
    AnalysisSettings, CombCurves, ContinuityTarget, DEFAULT_TOLERANCE_PX, Overlays, QUALITY_RANGE,
    ShadingMode, StripeFrame, TOLERANCE_RANGE, ViewSettings, ZebraSource,
};
