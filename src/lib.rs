//! knotwork: a freeform-surface editor whose surfaces are evaluated by WGSL compute shaders,
//! in the browser (WebGPU) and on the desktop (Vulkan, Metal, DX12).
//!
//! Layers, each depending only on the ones listed before it (the kernel is a crate of its
//! own, so the compiler keeps its boundary):
//! - [`kernel`]: pure f64 geometry (no GPU, no UI);
//! - [`scene`]: the document's objects, every kind behind one interface, the registry of kinds
//!   and their project records, and what an edit changed;
//! - [`view`]: the camera, picking, and the view settings a project saves;
//! - [`io`]: file formats (the project file, glTF, OBJ, PNG height maps, eval requests);
//! - [`doc`]: commands on the scene with undo and redo, drags, open and save;
//! - [`shaders`], [`gpu`]: WGSL sources and the compute evaluator on wgpu;
//! - [`render`]: the viewport pipelines;
//! - [`app`], [`status`]: the eframe editor, identical on web and desktop.

// `!(x > 0.0)` is the deliberate NaN-rejecting form of every validity check in the kernel.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod app;
pub mod doc;
pub mod gpu;
pub mod io;
pub mod ops;
/// The f64 geometry kernel (the `knotwork-kernel` crate), under its old path.
pub use knotwork_kernel as kernel;
pub mod render;
pub mod scene;
pub mod shaders;
pub mod status;
pub mod view;

#[cfg(target_arch = "wasm32")]
mod web;
#[cfg(any(test, all(target_arch = "wasm32", target_feature = "atomics")))]
mod web_alloc;
#[cfg(all(target_arch = "wasm32", target_feature = "atomics"))]
mod web_threads;

/// The desktop's allocator: mimalloc, which keeps freed pages for reuse, where the system
/// allocator hands the large buffers of every cage-tool rebuild back to the kernel and faults
/// them in again on the next step.
#[cfg(not(target_arch = "wasm32"))]
#[global_allocator]
static NATIVE_ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// The threaded page's allocator: small blocks cached per thread ([`web_alloc`]).
#[cfg(all(target_arch = "wasm32", target_feature = "atomics"))]
#[global_allocator]
static ALLOCATOR: web_alloc::ThreadCaching = web_alloc::ThreadCaching;
