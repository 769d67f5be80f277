//! Camera, screen-space picking and drag constraints.

pub mod camera;
pub mod pick;

pub use camera::OrbitCamera;
pub use pick::{Constraint, PickView, Projected, SurfaceHit};
