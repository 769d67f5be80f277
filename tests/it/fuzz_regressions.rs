//! Inputs the fuzzers found (fuzz/regressions/TARGET/), and every reader's seed-like edge cases,
//! run through the same check as the fuzz targets (`knotwork::io::fuzz::check`): no reader may
//! panic, and whatever opens must survive a save and reopen.

use std::path::Path;

use knotwork::io::fuzz::{Target, check};

#[test]
fn every_kept_fuzz_input_is_handled() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/regressions");
    let mut count = 0;
    for target in Target::ALL {
        let dir = root.join(target.name());
        let mut files: Vec<_> = std::fs::read_dir(&dir)
            .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
            .filter_map(|entry| Some(entry.ok()?.path()))
            .filter(|path| path.file_name().is_some_and(|n| n != ".keep"))
            .collect();
        files.sort();
        for file in files {
            let data = std::fs::read(&file).unwrap();
            eprintln!("{}", file.display());
            check(target, &data);
            count += 1;
        }
    }
    eprintln!("{count} kept fuzz inputs");
}

#[test]
fn edge_cases_of_every_reader_are_handled() {
    let cases: [&[u8]; 12] = [
        b"",
        b"\xff\xfe\x00",
        b"{}",
        b"[]",
        b"null",
        b"glTF",
        b"glTF\x02\x00\x00\x00\xff\xff\xff\xff",
        b"v 1e400 0 0\nf 1 1 1\n",
        b"f -1 -2 -3\n",
        b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3 4\n",
        b"{\"asset\":{\"version\":\"2.0\"},\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"children\":[0]}]}",
        b"{\"version\": 2, \"objects\": [{\"type\": \"polygon_mesh\"}]}",
    ];
    for target in Target::ALL {
        for case in cases {
            check(target, case);
        }
    }
}
