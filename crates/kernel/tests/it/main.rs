//! The kernel's integration tests in one test binary (a module per file, as the app's
//! `tests/it/`): `cargo test -p knotwork-kernel --test it nurbs::` runs one file's tests.

mod bezier;
mod nurbs;
mod parametric;
mod sheets;
mod subdivision_boundary;
mod subdivision_curvature;
mod trimmed_export;
