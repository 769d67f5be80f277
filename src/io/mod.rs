//! File formats: knotwork's JSON format for curves and surfaces, the project file that extends
//! it to a scene, and the `eval` request format.

pub mod eval;
pub mod json;
pub mod project;
