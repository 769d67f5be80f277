//! The JSON file format and the `knotwork eval` CLI: round trips, analytic answers through the
//! binary, and every kind of bad input rejected with a message naming the JSON path.

use std::io::Write;
use std::process::{Command, Stdio};

use glam::DVec3;
use knotwork::kernel::construct;
use knotwork::scene::json::{self, FormatError, Geometry, NamedGeometry};
use serde_json::{Value, json};

const BILINEAR: &str = r#"{"type": "nurbs_surface", "degree": [1, 1],
  "knots": [[0, 0, 1, 1], [0, 0, 1, 1]],
  "points": [[[0, 0, 0, 1], [0, 1, 0, 1]], [[1, 0, 0, 1], [1, 1, 1, 1]]]}"#;

fn read_error(text: &str) -> FormatError {
    json::read(text).expect_err("must be rejected")
}

/// Replaces one field of the bilinear example.
fn with(field: &str, value: Value) -> String {
    let mut v: Value = serde_json::from_str(BILINEAR).unwrap();
    v[field] = value;
    v.to_string()
}

#[test]
fn reads_the_documented_surface_format() {
    let objects = json::read(BILINEAR).unwrap();
    let Geometry::Surface(s) = &objects[0].geometry else {
        panic!("expected a surface")
    };
    assert_eq!(s.count(), [2, 2]);
    // points[i][j]: i along u, j along v. S(1, 1) is the last point, S(0.5, 0.5) the average.
    assert_eq!(s.point_at(1.0, 0.0).unwrap(), DVec3::X);
    assert_eq!(s.point_at(0.0, 1.0).unwrap(), DVec3::Y);
    assert_eq!(s.point_at(0.5, 0.5).unwrap(), DVec3::new(0.5, 0.5, 0.25));
    // w may be omitted; weights are not multiplied into x, y, z.
    let text = r#"{"type": "nurbs_curve", "degree": 1, "knots": [0, 0, 1, 1], "points": [[0, 0, 0], [2, 0, 0, 4]]}"#;
    let Geometry::Curve(c) = &json::read(text).unwrap()[0].geometry else {
        panic!("expected a curve")
    };
    assert_eq!(c.control_point(1), DVec3::new(2.0, 0.0, 0.0));
    assert_eq!(c.weight(1), 4.0);
    // The rational midpoint: (0·1 + 2·4) / (1 + 4) · ½/½ = 1.6.
    assert!((c.point_at(0.5).unwrap().x - 1.6).abs() < 1e-15);
}

#[test]
fn whole_files_round_trip_with_names_and_trim_curves() {
    let trim = knotwork::kernel::TrimCurve::new(
        1,
        vec![0.0, 0.0, 0.5, 1.0, 1.0],
        vec![glam::DVec2::ZERO, glam::DVec2::X, glam::DVec2::ONE],
        Some(vec![1.0, 2.0, 1.0]),
    )
    .unwrap();
    let objects = vec![
        NamedGeometry {
            name: Some("torus".into()),
            geometry: Geometry::Surface(construct::torus(DVec3::ZERO, DVec3::Z, 2.0, 0.5).unwrap()),
        },
        NamedGeometry {
            name: Some("trim".into()),
            geometry: Geometry::Trim(trim),
        },
    ];
    let text = json::write(&objects);
    assert!(text.contains("\"format\": \"knotwork\"") && text.contains("\"version\": 1"));
    assert_eq!(json::read(&text).unwrap(), objects);
}

/// Malformed documents with the JSON path and message each must be rejected with.
fn malformed_cases() -> Vec<(String, &'static str, &'static str)> {
    vec![
        ("{\"type\": \"nurbs_surface\", ".into(), "", "not valid JSON"),
        ("[1, 2]".into(), "", "expected an object with a \"type\" field, found an array"),
        (with("degree", json!("three")), "degree", "invalid type"),
        (with("degree", json!([1])), "degree", "invalid length"),
        (with("type", json!("subdivision_cage")), "type", "unknown object type"),
        (with("knots", json!([[0, 0, 1, 1], [0, 0, 1]])), "knots[1]", "3 knots"),
        (with("knots", json!([[0, 0, 1, 1], [0, 1, 0.5, 1]])), "knots[1][2]", "smaller than"),
        (with("knots", json!([[0, 0, 1, 1], [0, 0, "a", 1]])), "knots[1][2]", "invalid type"),
        (BILINEAR.replace("[[0, 0, 1, 1], [0, 0, 1, 1]]", "[[0, 0, 1e400, 1], [0, 0, 1, 1]]"), "", "number out of range"),
        (with("points", json!([[[0, 0, 0, 1], [0, 1, 0, 1]], [[1, 0, 0, 0], [1, 1, 1, 1]]])), "points[1][0]", "weight 0"),
        (with("points", json!([[[0, 0, 0, 1], [0, 1, 0, -2]], [[1, 0, 0, 1], [1, 1, 1, 1]]])), "points[0][1]", "weight -2"),
        (with("points", json!([[[0, 0, 0, 1], [0, 1, 0, 1]], [[1, 0, 0, 1]]])), "points[1]", "rectangular"),
        (with("points", json!([[[0, 0, 0, 1], [0, 1, 0, 1, 7]], [[1, 0, 0, 1], [1, 1, 1, 1]]])), "points[0][1]", "found 5"),
        (with("points", json!([[[0, 0, 0, 1], [0, 1, 0, 1]]])), "knots[0]", "too few"),
        (with("extra", json!(1)), "extra", "unknown field"),
        (r#"{"format": "knotwork", "version": 7, "objects": []}"#.into(), "version", "version 7 is not supported"),
        (r#"{"format": "other", "version": 1, "objects": []}"#.into(), "format", "expected \"knotwork\""),
        (format!(r#"{{"format": "knotwork", "version": 1, "objects": [{BILINEAR}, {}]}}"#, with("degree", json!([0, 1]))), "objects[1].knots[0]", "degree 0"),
        (r#"{"type": "nurbs_curve", "degree": 2, "knots": [0, 0, 0, 1, 1, 1], "points": [[0, 0, 0], [1, 1, 1], [2, 0]]}"#.into(), "points[2]", "found 2"),
        (
            serde_json::from_str::<Value>(&with("knots", json!([[0, 0, 0, 1, 1], [0, 0, 1, 1]])))
                .map(|mut v| {
                    v["points"] = json!([[[0, 0, 0], [0, 1, 0]], [[1, 0, 0], [1, 1, 0]], [[2, 0, 0], [2, 1, 0]]]);
                    v.to_string()
                })
                .unwrap(),
            "knots[0][0]",
            "repeated 3 times",
        ),
        (with("points", json!([[[0, 0, 0, 1], [0, 1, 0, 1]], [[1, 0, 0, 1], [1, 1, 1, 1]], [[2, 0, 0, 1], [2, 1, 0, 1]]])), "knots[0]", "3 control points of degree 1 need"),
    ]
}

#[test]
fn malformed_files_name_the_problem_and_path() {
    for (text, path, message) in malformed_cases() {
        let e = read_error(&text);
        assert_eq!(e.path, path, "path of {e} for {text}");
        assert!(
            e.to_string().contains(message),
            "message {e:?} lacks {message:?} for {text}"
        );
    }
}

fn knotwork() -> Command {
    Command::new(env!("CARGO_BIN_EXE_knotwork"))
}

fn sphere_request(params: Value) -> String {
    let sphere = construct::sphere(DVec3::ZERO, 2.0).unwrap();
    let object = NamedGeometry {
        name: None,
        geometry: Geometry::Surface(sphere),
    };
    json!({"surface": json::object_to_value(&object), "params": params}).to_string()
}

fn vec3(v: &Value) -> DVec3 {
    DVec3::new(
        v[0].as_f64().unwrap(),
        v[1].as_f64().unwrap(),
        v[2].as_f64().unwrap(),
    )
}

#[test]
fn eval_cli_reports_analytic_sphere_values() {
    let dir = crate::common::scratch_dir("eval-cli");
    let path = dir.join("request.json");
    std::fs::write(
        &path,
        sphere_request(json!([
            [0.1, 0.3],
            [0.9, 0.5],
            [0.5, 0.0],
            [1.5, 0.5],
            [0.5]
        ])),
    )
    .unwrap();
    let out = knotwork().arg("eval").arg(&path).output().unwrap();
    assert!(
        out.status.success(),
        "stderr: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let response: Value = serde_json::from_slice(&out.stdout).unwrap();
    let results = response["results"].as_array().unwrap();
    assert_eq!(results.len(), 5);
    for r in &results[..3] {
        let p = vec3(&r["point"]);
        assert!((p.length() - 2.0).abs() < 1e-12);
        assert!(vec3(&r["normal"]).distance(p / 2.0) < 1e-9);
        for key in ["su", "sv", "suu", "suv", "svv"] {
            assert!(vec3(&r[key]).is_finite(), "{key}");
        }
        assert!((r["gaussian"].as_f64().unwrap() - 0.25).abs() < 1e-6);
        assert!((r["mean"].as_f64().unwrap() + 0.5).abs() < 1e-6);
        assert!((r["k1"].as_f64().unwrap() + 0.5).abs() < 1e-6);
        assert!((r["k2"].as_f64().unwrap() + 0.5).abs() < 1e-6);
    }
    assert_eq!(
        results[2]["regular"],
        json!(false),
        "v = 0 is the south pole"
    );
    assert!(
        results[3]["error"]
            .as_str()
            .unwrap()
            .contains("outside the domain")
    );
    assert!(
        results[4]["error"]
            .as_str()
            .unwrap()
            .contains("parameter pair")
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// Runs `knotwork eval -` with `input` on standard input.
fn run_stdin(input: &str) -> std::process::Output {
    run_stdin_with(input, &[])
}

/// Runs `knotwork eval - EXTRA...` with `input` on standard input.
fn run_stdin_with(input: &str, extra: &[&str]) -> std::process::Output {
    run_stdin_with_env(input, extra, &[])
}

/// [`run_stdin_with`] with environment variables set.
fn run_stdin_with_env(input: &str, extra: &[&str], env: &[(&str, &str)]) -> std::process::Output {
    let mut child = knotwork()
        .args(["eval", "-"])
        .args(extra)
        .envs(env.iter().copied())
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    child
        .stdin
        .take()
        .unwrap()
        .write_all(input.as_bytes())
        .unwrap();
    child.wait_with_output().unwrap()
}

#[test]
fn eval_cli_reads_stdin_and_fails_cleanly_on_bad_input() {
    let ok = run_stdin(&sphere_request(json!([[0.25, 0.5]])));
    assert!(ok.status.success());
    let bad_surface = json!({"surface": serde_json::from_str::<Value>(&with("knots", json!([[0, 0, 1, 1], [0, 1, 0.5, 1]]))).unwrap(), "params": [[0.5, 0.5]]});
    for (input, message) in [
        (bad_surface.to_string(), "surface.knots[1][2]"),
        ("{\"surface\": 1".to_string(), "not valid JSON"),
        (json!({"params": []}).to_string(), "missing field `surface`"),
        (json!({"surface": {"type": "nurbs_curve", "degree": 1, "knots": [0, 0, 1, 1], "points": [[0, 0, 0], [1, 0, 0]]}, "params": []}).to_string(), "expected \"nurbs_surface\""),
    ] {
        let out = run_stdin(&input);
        assert!(!out.status.success(), "{input} must fail");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(stderr.contains(message), "stderr {stderr:?} lacks {message:?}");
        assert!(out.stdout.is_empty());
    }
    let missing = knotwork()
        .args(["eval", "/nonexistent/request.json"])
        .output()
        .unwrap();
    assert!(!missing.status.success());
    assert!(
        String::from_utf8_lossy(&missing.stderr).contains("cannot read /nonexistent/request.json")
    );
}

/// Every surface validation error also reaches the CLI user: exit code ≠ 0, the message and the
/// path (under `surface.`) on stderr, nothing on stdout.
#[test]
fn eval_cli_reports_every_surface_validation_error() {
    let mut checked = 0;
    for (text, path, message) in malformed_cases() {
        let Ok(value) = serde_json::from_str::<Value>(&text) else {
            continue;
        };
        if value.get("type") != Some(&json!("nurbs_surface")) || path.is_empty() {
            continue;
        }
        let request = json!({"surface": value, "params": [[0.0, 0.0]]}).to_string();
        let out = run_stdin(&request);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{text} must fail");
        assert!(out.stdout.is_empty());
        assert!(
            stderr.contains(&format!("surface.{path}")),
            "{stderr:?} lacks path {path}"
        );
        assert!(stderr.contains(message), "{stderr:?} lacks {message:?}");
        checked += 1;
    }
    assert!(checked >= 10, "only {checked} cases reached the CLI");
}

#[test]
fn eval_cli_on_the_gpu_agrees_with_the_cpu() {
    // A torus (rational, exact) and a non-uniform rational B-spline of degree (3, 2), at points
    // inside spans, on knots, on the domain's edges and one outside.
    let torus = construct::torus(DVec3::new(0.5, 0.0, 0.0), DVec3::Z, 2.0, 0.7).unwrap();
    let points = (0..5)
        .flat_map(|i| {
            (0..4).map(move |j| DVec3::new(i as f64, j as f64, ((i + 2 * j) % 3) as f64 * 0.4))
        })
        .collect();
    let bspline = knotwork::kernel::NurbsSurface::new(
        [3, 2],
        [
            vec![0.0, 0.0, 0.0, 0.0, 0.4, 2.0, 2.0, 2.0, 2.0],
            vec![1.0, 1.0, 1.0, 1.5, 3.0, 3.0, 3.0],
        ],
        [5, 4],
        points,
        Some((0..20).map(|k| 0.5 + (k % 3) as f64).collect()),
    )
    .unwrap();
    for (surface, params) in [
        (
            torus,
            json!([
                [0.1, 0.2],
                [0.25, 0.5],
                [0.0, 0.0],
                [1.0, 1.0],
                [0.77, 0.31],
                [1.2, 0.5]
            ]),
        ),
        (
            bspline,
            json!([
                [0.2, 1.2],
                [0.4, 1.5],
                [0.0, 1.0],
                [2.0, 3.0],
                [1.3, 2.7],
                [0.5, 3.5]
            ]),
        ),
    ] {
        let size = {
            let (lo, hi) = surface.bounds();
            (hi - lo).length()
        };
        let object = NamedGeometry {
            name: None,
            geometry: Geometry::Surface(surface),
        };
        let request =
            json!({"surface": json::object_to_value(&object), "params": params}).to_string();
        let run = |extra: &[&str]| -> Vec<Value> {
            let out = run_stdin_with(&request, extra);
            assert!(
                out.status.success(),
                "{}",
                String::from_utf8_lossy(&out.stderr)
            );
            let response: Value = serde_json::from_slice(&out.stdout).unwrap();
            response["results"].as_array().unwrap().clone()
        };
        let cpu = run(&[]);
        let gpu = run(&["--backend", "gpu"]);
        assert_eq!(cpu.len(), gpu.len());
        for (c, g) in cpu.iter().zip(&gpu) {
            if c.get("error").is_some() {
                assert_eq!(c["error"], g["error"], "the same error on both backends");
                continue;
            }
            assert!(
                vec3(&c["point"]).distance(vec3(&g["point"])) <= 1e-5 * size,
                "{c}\n{g}"
            );
            let angle = vec3(&c["normal"]).angle_between(vec3(&g["normal"]));
            assert!(angle <= 1e-3, "normal {angle} rad: {c}\n{g}");
            for key in ["su", "sv", "suu", "suv", "svv"] {
                let (a, b) = (vec3(&c[key]), vec3(&g[key]));
                let scale = vec3(&c["su"])
                    .length()
                    .max(vec3(&c["sv"]).length())
                    .max(a.length());
                assert!(a.distance(b) <= 1e-4 * scale, "{key}: {a} vs {b}");
            }
            for (key, power) in [("gaussian", 2), ("mean", 1), ("k1", 1), ("k2", 1)] {
                let (a, b) = (c[key].as_f64().unwrap(), g[key].as_f64().unwrap());
                let scale = size.powi(power);
                let error = (a - b).abs() * scale / (a.abs() * scale).max(1.0);
                assert!(error <= 1e-3, "{key}: {a} vs {b}");
            }
            assert_eq!(c["regular"], g["regular"]);
        }
    }
}

/// Runs `knotwork eval --backend gpu` on a sphere request with `env` set.
fn eval_gpu_with_env(env: &[(&str, &str)]) -> std::process::Output {
    run_stdin_with_env(
        &sphere_request(json!([[0.25, 0.5]])),
        &["--backend", "gpu"],
        env,
    )
}

#[test]
fn eval_on_the_gpu_without_a_compute_adapter_exits_1_with_the_reason() {
    // Mesa's GL capped at version 3.0 (GLES 3.0): an adapter without compute shaders, as a
    // machine without a Vulkan driver has. Where wgpu finds no GL adapter at all, the refusal
    // is "no adapter". Either way: the reason, exit code 1, and never a panic inside wgpu.
    let no_compute = eval_gpu_with_env(&[
        ("WGPU_BACKEND", "gl"),
        ("MESA_GL_VERSION_OVERRIDE", "3.0"),
        ("MESA_GLES_VERSION_OVERRIDE", "3.0"),
    ]);
    // A backend this platform does not have: no adapter at all.
    let none = eval_gpu_with_env(&[("WGPU_BACKEND", "metal")]);
    for (what, out) in [("GL 3.0", no_compute), ("no backend", none)] {
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{what}: {stderr}");
        assert!(!stderr.contains("panicked"), "{what}: {stderr}");
        assert!(
            stderr.contains("no compute shaders") || stderr.contains("no GPU adapter found"),
            "{what}: {stderr}"
        );
        assert!(stderr.contains("mesa-vulkan-drivers"), "{what}: {stderr}");
        assert!(
            out.stdout.is_empty(),
            "{what}: nothing is printed as a result"
        );
    }
}

#[test]
fn every_command_is_described_in_the_help() {
    // Each subcommand's line in `knotwork --help` says what it does (a misplaced doc comment
    // once left `export` blank and gave `info` export's text).
    let out = knotwork().arg("--help").output().unwrap();
    let help = String::from_utf8_lossy(&out.stdout);
    let commands: Vec<&str> = help
        .lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| !l.trim().is_empty())
        .collect();
    assert!(commands.len() > 10, "{help}");
    for line in commands {
        let mut words = line.split_whitespace();
        let name = words.next().unwrap_or_default();
        let rest: Vec<&str> = words.collect();
        assert!(!rest.is_empty(), "`{name}` has no description in --help");
        if name == "info" {
            assert!(rest.join(" ").starts_with("Describe a STEP file"), "{line}");
        }
        if name == "export" {
            assert!(rest.join(" ").starts_with("Export a project"), "{line}");
        }
    }
}
