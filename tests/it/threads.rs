//! The threaded page's rule for parallel loops: no thread waits for another inside one.

use std::path::{Path, PathBuf};

/// Every `.rs` file under `dir`.
fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            sources(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// No code a parallel loop reaches shares a cell or lock that makes a thread wait: the
/// threaded page's main thread works in every loop, and a wait traps there (the page then
/// stops drawing). Lazily computed values are `par::RaceCell`s. The code searched is the
/// kernel, the STEP reader and the editor's documents, scene, operations and file formats
/// (the renderer, the GPU and the UI run on the main thread alone). Allowed: the kernel's
/// `par.rs`, whose helpers are set once before any loop, and the scene's registries, whose
/// `RwLock`s are written at start-up and only read after (reads wait only for a writer).
#[test]
fn no_loop_shares_a_cell_or_lock_that_waits() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut paths = Vec::new();
    for dir in [
        "crates/kernel/src",
        "crates/step/src",
        "src/doc",
        "src/scene",
        "src/ops",
        "src/io",
    ] {
        sources(&root.join(dir), &mut paths);
    }
    assert!(paths.len() > 150, "the sources searched: {}", paths.len());
    let allowed = [
        "crates/kernel/src/par.rs",
        "src/scene/registry.rs",
        "src/scene/operation.rs",
    ];
    let waiting = [
        "OnceLock", "LazyLock", "Mutex", "RwLock", "Condvar", "Barrier",
    ];
    let mut found = Vec::new();
    for path in &paths {
        let name = path.strip_prefix(root).unwrap_or(path);
        if allowed.iter().any(|a| name == Path::new(a)) {
            continue;
        }
        let text = std::fs::read_to_string(path).unwrap();
        for (n, line) in text.lines().enumerate() {
            let code = line.split("//").next().unwrap_or("");
            if let Some(kind) = waiting.iter().find(|w| code.contains(*w)) {
                found.push(format!("{}:{}: {kind}", name.display(), n + 1));
            }
        }
    }
    assert!(found.is_empty(), "cells or locks that wait: {found:#?}");
}
