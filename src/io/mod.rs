//! File formats: knotwork's JSON format for curves and surfaces, and the `eval` request format.

pub mod eval;
pub mod json;
