//! Camera and, later, picking and drag constraints.

pub mod camera;

pub use camera::OrbitCamera;
