//! knotwork's integration tests, gathered into one test binary: each file of this folder is a
//! module, so that the app is linked once for all of them rather than once per file (the test
//! suite's cold build on two cores was dominated by linking). Run one file's tests with its
//! module name as the filter: `cargo test --test it step_files::`.

mod common;

mod adaptive_gpu;
mod adaptive_layout;
mod adaptive_subdivision;
mod analysis_overlays;
mod analysis_render;
mod boolean;
mod cage_tools;
mod construction_history;
mod continuity;
mod desktop_app;
mod displacement;
mod doc_commands;
mod editor_ui;
mod features;
mod file_format;
mod fuzz_regressions;
mod gltf_export;
mod gpu_eval;
mod gpu_export;
mod import_files;
mod intersect;
mod kernel_props;
mod lattice;
mod layers;
mod mass;
mod object_kinds;
mod occ_reference;
mod operations;
mod project_files;
mod readme;
mod render_viewport;
mod shaders;
mod step_files;
mod stl_export;
mod subdivision;
mod subdivision_schemes;
mod substitutes;
mod surface_ops;
mod threads;
mod transfinite;
mod triangle_bezier;
mod trim;
mod trim_render;
