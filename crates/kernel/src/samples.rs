//! Sample models embedded in the crate.
//!
//! The Utah teapot: 32 bicubic Bézier patches over 290 distinct control points, Z up, as published
//! in three.js's `examples/jsm/geometries/TeapotGeometry.js` (npm `three` 0.187.0, MIT licence;
//! the data go back to Martin Newell, 1975). `data/teapot.json` is that table, parsed from the
//! source; its `source`, `provenance` and `patch_layout` fields say where it came from and how it
//! is laid out.

use glam::DVec3;
use serde::Deserialize;

use super::bezier::{BezierPatch, BezierPatchSet};
use super::error::GeometryError;

/// The teapot table as embedded in the crate.
pub const TEAPOT_JSON: &str = include_str!("data/teapot.json");

#[derive(Deserialize)]
struct TeapotFile {
    patch_indices: Vec<Vec<u32>>,
    vertices: Vec<[f64; 3]>,
}

/// The Utah teapot as a [`BezierPatchSet`] (32 bicubic patches, 290 shared control points).
///
/// In the source table u runs along the rows of each 4 × 4 net and Su × Sv points into the
/// teapot. Each net is transposed here (u along the source's columns), so that Su × Sv — the
/// kernel's normal — points outward on every patch. The collapsed edges (the lid's knob and the
/// bottom centre) then lie at v = 0.
pub fn utah_teapot() -> Result<BezierPatchSet, GeometryError> {
    let data_error = |message: String| GeometryError::SampleData {
        name: "teapot.json",
        message,
    };
    let file: TeapotFile =
        serde_json::from_str(TEAPOT_JSON).map_err(|e| data_error(e.to_string()))?;
    let points = file.vertices.iter().map(|&p| DVec3::from(p)).collect();
    let mut patches = Vec::with_capacity(file.patch_indices.len());
    for (k, source) in file.patch_indices.iter().enumerate() {
        if source.len() != 16 {
            return Err(data_error(format!(
                "patch {k} has {} indices, expected 16",
                source.len()
            )));
        }
        // Transposed: new (i, j) = source (row j, column i).
        let indices = (0..4)
            .flat_map(|i| (0..4).map(move |j| source[j * 4 + i]))
            .collect();
        patches.push(BezierPatch::new(3, 3, indices));
    }
    BezierPatchSet::new(points, None, patches)
}

/// Two bicubic B-spline surfaces that cross like a floor and a wall: a wavy floor over
/// [0, 4]² (normal +z) and a curved wall near y = 2 rising from z = −1 to 2 (normal −y).
/// The surface operations' tests and benchmarks fillet and intersect them.
pub fn floor_and_wall() -> Result<(crate::NurbsSurface, crate::NurbsSurface), GeometryError> {
    let mut floor = Vec::new();
    for i in 0..6 {
        for j in 0..6 {
            let (x, y) = (i as f64 * 0.8, j as f64 * 0.8);
            floor.push(DVec3::new(x, y, 0.15 * (x * 1.1).sin() * (0.7 * y).cos()));
        }
    }
    let mut wall = Vec::new();
    for i in 0..6 {
        for j in 0..5 {
            let (x, z) = (i as f64 * 0.8, -1.0 + j as f64 * 0.75);
            wall.push(DVec3::new(x, 2.0 + 0.3 * (0.8 * x).sin() + 0.1 * z * z, z));
        }
    }
    Ok((
        super::construct::bspline_surface([3, 3], [6, 6], floor)?,
        super::construct::bspline_surface([3, 3], [6, 5], wall)?,
    ))
}
