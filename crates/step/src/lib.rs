//! STEP (ISO 10303-21 files of AP203, AP214 and AP242 geometry) on knotwork's f64 kernel:
//! reading B-rep shells as trimmed NURBS faces with their shared edges ([`read`]) and writing
//! faces as B-spline faces ([`write`]). No GPU, UI or browser crate: the editor turns what is
//! read into its objects, and the crate builds for wasm32 by itself.
//!
//! - [`part21`]: the Part 21 tokenizer and instance table.
//! - [`entities`]: points, placements, curves and surfaces, every argument checked.
//! - [`faces`]: a face's surface as an exact NURBS over the face, its loops in (u, v).
//! - [`read`]: units, the assembly, names, colours, and each shell's faces and shared edges.
//! - [`write`]: AP214 output.

// `!(x > 0.0)` is the deliberate NaN-rejecting form of the entity checks, as in the kernel.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod entities;
pub mod faces;
pub mod part21;
pub mod read;
pub mod write;

use knotwork_kernel as kernel;

pub use knotwork_kernel::{FormatError, LengthUnit};
