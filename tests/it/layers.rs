//! The shape of the code, checked: no file of the kernel, STEP or app crate imports, through
//! `crate::`, `super::` or `self::` paths, a file that imports it back (directly or round a
//! longer cycle), test modules aside; and no kind is looked at by downcast outside
//! `src/scene/` (everything else asks through `ObjectKind` and the kinds' own accessors).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Every `.rs` file below `dir`, relative to it.
fn sources(dir: &Path) -> Vec<PathBuf> {
    let mut found = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "rs") {
                found.push(path.strip_prefix(dir).unwrap().to_path_buf());
            }
        }
    }
    found.sort();
    found
}

/// The module path of a file: `doc/mod.rs` and `doc.rs` are `doc`, `lib.rs` the root.
fn module_of(file: &Path) -> Vec<String> {
    let mut parts: Vec<String> = file
        .with_extension("")
        .iter()
        .map(|p| p.to_string_lossy().into_owned())
        .collect();
    if matches!(
        parts.last().map(String::as_str),
        Some("mod" | "lib" | "main")
    ) {
        parts.pop();
    }
    parts
}

/// The code of a file without comments, string contents and its test module.
fn code_of(text: &str) -> String {
    let text = text.split("#[cfg(test)]").next().unwrap_or("");
    let mut out = String::with_capacity(text.len());
    let mut chars = text.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '/' if chars.peek() == Some(&'/') => {
                for d in chars.by_ref() {
                    if d == '\n' {
                        out.push('\n');
                        break;
                    }
                }
            }
            '"' => {
                let mut escaped = false;
                for d in chars.by_ref() {
                    if escaped {
                        escaped = false;
                    } else if d == '\\' {
                        escaped = true;
                    } else if d == '"' {
                        break;
                    }
                }
                out.push_str("\"\"");
            }
            _ => out.push(c),
        }
    }
    out
}

/// The paths starting `crate::`, `super::` or `self::` in `code`, a `use` list's braces
/// expanded one level (`crate::a::{b, c::d}` gives `crate::a::b` and `crate::a::c`).
fn paths_in(code: &str) -> Vec<Vec<String>> {
    let is_ident = |c: char| c.is_alphanumeric() || c == '_';
    let mut paths = Vec::new();
    let bytes: Vec<char> = code.chars().collect();
    let mut i = 0;
    while i < bytes.len() {
        let starts_word = i == 0 || !is_ident(bytes[i - 1]) && bytes[i - 1] != ':';
        let rest: String = bytes[i..bytes.len().min(i + 7)].iter().collect();
        if !(starts_word
            && (rest.starts_with("crate::")
                || rest.starts_with("super::")
                || rest.starts_with("self::")))
        {
            i += 1;
            continue;
        }
        let mut segments = Vec::new();
        let mut word = String::new();
        while i < bytes.len() {
            let c = bytes[i];
            if is_ident(c) {
                word.push(c);
                i += 1;
            } else if c == ':' && bytes.get(i + 1) == Some(&':') {
                segments.push(std::mem::take(&mut word));
                i += 2;
                if bytes.get(i) == Some(&'{') {
                    let close = (i..bytes.len()).find(|&k| bytes[k] == '}').unwrap_or(i);
                    let inner: String = bytes[i + 1..close].iter().collect();
                    for item in inner.split(',') {
                        let first = item.trim().split("::").next().unwrap_or("").trim();
                        let first = first.split_whitespace().next().unwrap_or("");
                        if !first.is_empty() && first != "self" {
                            let mut p = segments.clone();
                            p.push(first.to_string());
                            paths.push(p);
                        }
                    }
                    i = close + 1;
                    segments.clear();
                    break;
                }
            } else {
                break;
            }
        }
        if !word.is_empty() {
            segments.push(word);
        }
        if segments.len() > 1 {
            paths.push(segments);
        }
    }
    paths
}

/// The cycles (strongly connected groups of more than one file) of the import graph of the
/// crate whose sources are in `dir`.
fn import_cycles(dir: &Path) -> Vec<Vec<String>> {
    let files = sources(dir);
    let by_module: BTreeMap<Vec<String>, String> = files
        .iter()
        .map(|f| (module_of(f), f.to_string_lossy().into_owned()))
        .collect();
    let resolve = |path: &[String]| {
        (0..=path.len())
            .rev()
            .find_map(|n| by_module.get(&path[..n]).cloned())
    };
    let mut edges: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for file in &files {
        let name = file.to_string_lossy().into_owned();
        let here = module_of(file);
        let code = code_of(&std::fs::read_to_string(dir.join(file)).unwrap());
        let targets = edges.entry(name.clone()).or_default();
        for path in paths_in(&code) {
            let mut absolute = Vec::new();
            let mut rest = path.as_slice();
            if rest[0] == "crate" {
                rest = &rest[1..];
            } else {
                absolute = here.clone();
                while let Some(first) = rest.first() {
                    match first.as_str() {
                        "super" => {
                            absolute.pop();
                        }
                        "self" => {}
                        _ => break,
                    }
                    rest = &rest[1..];
                }
            }
            absolute.extend(rest.iter().cloned());
            if let Some(target) = resolve(&absolute)
                && target != name
            {
                targets.insert(target);
            }
        }
    }
    // Tarjan's strongly connected components.
    struct State<'a> {
        edges: &'a BTreeMap<String, BTreeSet<String>>,
        index: BTreeMap<&'a str, usize>,
        low: BTreeMap<&'a str, usize>,
        stack: Vec<&'a str>,
        on_stack: BTreeSet<&'a str>,
        groups: Vec<Vec<String>>,
    }
    fn visit<'a>(s: &mut State<'a>, v: &'a str) {
        let n = s.index.len();
        s.index.insert(v, n);
        s.low.insert(v, n);
        s.stack.push(v);
        s.on_stack.insert(v);
        for w in s.edges.get(v).into_iter().flatten() {
            let w = w.as_str();
            if !s.index.contains_key(w) {
                visit(s, w);
                let low = s.low[v].min(s.low[w]);
                s.low.insert(v, low);
            } else if s.on_stack.contains(w) {
                let low = s.low[v].min(s.index[w]);
                s.low.insert(v, low);
            }
        }
        if s.low[v] == s.index[v] {
            let mut group = Vec::new();
            while let Some(w) = s.stack.pop() {
                s.on_stack.remove(w);
                group.push(w.to_string());
                if w == v {
                    break;
                }
            }
            if group.len() > 1 {
                group.sort();
                s.groups.push(group);
            }
        }
    }
    let mut state = State {
        edges: &edges,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on_stack: BTreeSet::new(),
        groups: Vec::new(),
    };
    for v in edges.keys() {
        if !state.index.contains_key(v.as_str()) {
            visit(&mut state, v);
        }
    }
    state.groups
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn no_file_imports_a_file_that_imports_it_back() {
    for dir in ["src", "crates/kernel/src", "crates/step/src"] {
        let cycles = import_cycles(&root().join(dir));
        assert!(cycles.is_empty(), "{dir}: import cycles {cycles:?}");
    }
}

#[test]
fn the_cycle_check_finds_a_cycle() {
    // Two files importing each other, and a third on its own, in a scratch crate.
    let dir = crate::common::artifact_path("layers-cycle");
    std::fs::create_dir_all(dir.join("doc")).unwrap();
    std::fs::write(dir.join("lib.rs"), "pub mod doc;\npub mod ops;\n").unwrap();
    std::fs::write(
        dir.join("doc/mod.rs"),
        "use crate::ops::Offset;\n// crate::nothing::here\n",
    )
    .unwrap();
    std::fs::write(dir.join("ops.rs"), "use crate::doc::{self, Command};\n").unwrap();
    std::fs::write(dir.join("alone.rs"), "use super::doc;\n").unwrap();
    assert_eq!(
        import_cycles(&dir),
        vec![vec!["doc/mod.rs".to_string(), "ops.rs".to_string()]]
    );
    std::fs::write(
        dir.join("ops.rs"),
        "#[cfg(test)]\nuse crate::doc::Command;\n",
    )
    .unwrap();
    assert!(import_cycles(&dir).is_empty());
}

#[test]
fn kinds_are_downcast_only_inside_the_scene() {
    let src = root().join("src");
    let mut found = Vec::new();
    for file in sources(&src) {
        if file.starts_with("scene") {
            continue;
        }
        let code = code_of(&std::fs::read_to_string(src.join(&file)).unwrap());
        if code.contains("downcast_ref") || code.contains("downcast_mut") {
            found.push(file);
        }
    }
    assert!(found.is_empty(), "downcasts outside src/scene/: {found:?}");
}
