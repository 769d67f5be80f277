//! `knotwork boolean` against OpenCASCADE: STEP bodies made and combined by OpenCASCADE
//! (`tests/reference/boolean/make_fixtures.py`, in general position), each union, difference
//! and intersection's volume within 1e-6 of OpenCASCADE's, the invariants vol(A ∪ B) +
//! vol(A ∩ B) = vol(A) + vol(B) and vol(A − B) + vol(A ∩ B) = vol(A), and every written
//! result read back by knotwork as closed solids.

use std::path::PathBuf;

use super::common::knotwork_json;

fn fixtures() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/reference/boolean")
}

/// An empty directory of its own for one test's files.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("knotwork-boolean-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("a scratch directory");
    dir
}

fn relative(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(1e-300)
}

#[test]
fn booleans_of_step_bodies_match_opencascade_and_the_volume_invariants() {
    let dir = fixtures();
    let rows = std::fs::read_to_string(dir.join("occt-booleans.jsonl")).expect("references");
    let out = scratch("match");
    for line in rows.lines() {
        let row: serde_json::Value = serde_json::from_str(line).expect("a JSON row");
        let case = row["case"].as_str().expect("a case name");
        let a = dir.join(format!("{case}-a.step"));
        let b = dir.join(format!("{case}-b.step"));
        let mut ours = std::collections::BTreeMap::new();
        for op in ["union", "difference", "intersection"] {
            let written = out.join(format!("{case}-{op}.step"));
            let result = knotwork_json(&[
                "boolean".as_ref(),
                op.as_ref(),
                a.as_os_str(),
                b.as_os_str(),
                "-o".as_ref(),
                written.as_os_str(),
            ]);
            let volume = result["volume"].as_f64().expect("a volume");
            let reference = row[op].as_f64().expect("OpenCASCADE's volume");
            assert!(
                relative(volume, reference) < 1e-6,
                "{case} {op}: {volume} against OpenCASCADE's {reference}"
            );
            // The written file opens as closed solids.
            let info = knotwork_json(&["info".as_ref(), written.as_os_str()]);
            let bodies = info["bodies"].as_array().expect("bodies");
            assert_eq!(
                bodies.len() as u64,
                result["solids"].as_u64().expect("solids")
            );
            for body in bodies {
                assert_eq!(body["closed"], true, "{case} {op}: {body}");
            }
            ours.insert(op, volume);
        }
        let (va, vb) = (row["a"].as_f64().unwrap(), row["b"].as_f64().unwrap());
        let scale = va + vb;
        assert!(
            (ours["union"] + ours["intersection"] - va - vb).abs() < 1e-6 * scale,
            "{case}: {ours:?}"
        );
        assert!(
            (ours["difference"] + ours["intersection"] - va).abs() < 1e-6 * scale,
            "{case}: {ours:?}"
        );
    }
}

#[test]
fn an_open_body_or_a_missing_file_exits_1_with_the_reason() {
    let dir = fixtures();
    let out = scratch("refuse");
    let run = |a: &std::path::Path, b: &std::path::Path| {
        std::process::Command::new(env!("CARGO_BIN_EXE_knotwork"))
            .args(["boolean", "union"])
            .arg(a)
            .arg(b)
            .arg("-o")
            .arg(out.join("x.step"))
            .output()
            .expect("the binary runs")
    };
    let missing = run(&dir.join("no-such-file.step"), &dir.join("blocks-b.step"));
    assert_eq!(missing.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&missing.stderr).contains("no-such-file"));
    // Far apart, the intersection is empty: refused, nothing written.
    let output = std::process::Command::new(env!("CARGO_BIN_EXE_knotwork"))
        .args(["boolean", "intersection"])
        .arg(dir.join("blocks-a.step"))
        .arg(dir.join("ball-block-b.step"))
        .arg("-o")
        .arg(out.join("empty.step"))
        .output()
        .expect("the binary runs");
    assert_eq!(output.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&output.stderr).contains("empty"));
    assert!(!out.join("empty.step").exists());
}
