//! Edge features (fillets, chamfers, shells) against OpenCASCADE on random solids in general
//! position (`tests/reference/features/make_fixtures.py`), and through the command line.

use std::path::PathBuf;

use glam::DVec3;
use knotwork::kernel::features::{EdgeFeature, EdgePick, FeatureResult, round_edges, shell};
use knotwork::kernel::mass::mass_properties;

fn fixtures() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/reference/features")
}

fn points(row: &serde_json::Value, key: &str) -> Vec<DVec3> {
    row[key]
        .as_array()
        .expect("a list of points")
        .iter()
        .map(|p| {
            let c: Vec<f64> = p
                .as_array()
                .expect("a point")
                .iter()
                .map(|x| x.as_f64().expect("a coordinate"))
                .collect();
            DVec3::new(c[0], c[1], c[2])
        })
        .collect()
}

/// What the command line does with one solid and one fixture row.
fn run(
    faces: &[knotwork::kernel::trim::TrimmedSurface],
    row: &serde_json::Value,
    tolerance: f64,
) -> Result<FeatureResult, String> {
    let value = row["value"].as_f64().expect("a value");
    let near = points(row, "near");
    let pick = if near.is_empty() {
        EdgePick::All
    } else {
        EdgePick::Near(near)
    };
    match row["feature"].as_str().expect("a feature") {
        "fillet" => round_edges(
            faces,
            &pick,
            EdgeFeature::Fillet { radius: value },
            tolerance,
        ),
        "chamfer" => round_edges(
            faces,
            &pick,
            EdgeFeature::Chamfer {
                distance: value,
                other: value,
            },
            tolerance,
        ),
        _ => shell(faces, value, &points(row, "open"), tolerance),
    }
    .map_err(|e| e.to_string())
}

#[test]
fn random_solids_take_opencascades_fillets_chamfers_and_shells() {
    let dir = fixtures();
    let bytes = std::fs::read(dir.join("inputs.step")).expect("the fixture");
    let bodies = knotwork::io::step::read::read(&bytes, &mut |_, _| true)
        .expect("a STEP model")
        .bodies;
    let rows: Vec<serde_json::Value> = std::fs::read_to_string(dir.join("occt-features.jsonl"))
        .expect("references")
        .lines()
        .map(|l| serde_json::from_str(l).expect("a JSON row"))
        .collect();
    assert_eq!(bodies.len(), rows.len());
    let mut failures = Vec::new();
    let mut checked = 0;
    for (body, row) in bodies.iter().zip(&rows) {
        let what = format!(
            "case {} ({} {} {:.4}, {} picked)",
            row["case"],
            row["kind"],
            row["feature"],
            row["value"].as_f64().unwrap_or(0.0),
            points(row, "near").len() + points(row, "open").len()
        );
        let (lo, hi) = body.faces.iter().map(|f| f.surface().bounds()).fold(
            (DVec3::INFINITY, DVec3::NEG_INFINITY),
            |(lo, hi), (p, q)| (lo.min(p), hi.max(q)),
        );
        let tolerance = 1e-6 * lo.distance(hi);
        let result = match run(&body.faces, row, tolerance) {
            Ok(r) => r,
            Err(e) => {
                failures.push(format!("{what}: refused: {e}"));
                continue;
            }
        };
        let mass = mass_properties(&result.faces, &[]).expect("mass properties");
        let (volume, area) = (
            row["volume"].as_f64().unwrap(),
            row["area"].as_f64().unwrap(),
        );
        let dv = (mass.volume - volume).abs() / volume;
        let da = (mass.area - area).abs() / area;
        if dv > 1e-4 || da > 1e-4 {
            failures.push(format!(
                "{what}: volume {} against {volume} ({dv:.2e}), area {} against {area} ({da:.2e})",
                mass.volume, mass.area
            ));
        }
        checked += 1;
    }
    eprintln!("{checked} of {} cases made and compared", rows.len());
    assert!(
        failures.is_empty(),
        "{} failures:\n{}",
        failures.len(),
        failures.join("\n")
    );
}
