//! The desktop editor end to end: the real binary opens its window (under Xvfb where there is no
//! display), evaluates and draws the teapot on the GPU, closes itself and reports its status;
//! `--open` loads a project, and a broken one is refused while the sample scene stays.

use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// Runs the editor with `extra` arguments for 3 frames, with its data directory (where the
/// autosave lives) in `data`; returns its output and the status line.
fn run_editor(data: &std::path::Path, extra: &[&str]) -> (Output, serde_json::Value) {
    run_editor_with_env(data, extra, &[])
}

/// [`run_editor`] with environment variables set.
fn run_editor_with_env(
    data: &std::path::Path,
    extra: &[&str],
    env: &[(&str, &str)],
) -> (Output, serde_json::Value) {
    let binary = env!("CARGO_BIN_EXE_knotwork");
    let headless =
        std::env::var_os("DISPLAY").is_none() && std::env::var_os("WAYLAND_DISPLAY").is_none();
    let mut command = if headless {
        let mut xvfb = Command::new("xvfb-run");
        xvfb.args(["-a", "-s", "-screen 0 1280x800x24", binary]);
        xvfb
    } else {
        Command::new(binary)
    };
    command
        .args(["--exit-after-frames", "3"])
        .args(extra)
        .env("XDG_DATA_HOME", data)
        .envs(env.iter().copied())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    let mut child = command.spawn().unwrap_or_else(|e| {
        panic!("could not start the desktop app (without a display, install xvfb and xauth): {e}")
    });
    let started = Instant::now();
    while child.try_wait().expect("child status").is_none() {
        if started.elapsed() > Duration::from_secs(180) {
            let _ = child.kill();
            panic!("the desktop app did not close itself within 180 s");
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    let output = child.wait_with_output().expect("child output");
    let stdout = String::from_utf8_lossy(&output.stdout).into_owned();
    let last = stdout.lines().last().unwrap_or_default();
    let status: serde_json::Value = serde_json::from_str(last).unwrap_or_else(|e| {
        panic!(
            "status line {last:?}: {e}\nstderr:\n{}",
            String::from_utf8_lossy(&output.stderr)
        )
    });
    eprintln!("desktop status: {status}");
    (output, status)
}

/// A fresh data directory for one test.
fn data_dir(name: &str) -> std::path::PathBuf {
    crate::common::scratch_dir(&format!("desktop-{name}"))
}

#[test]
fn desktop_app_opens_draws_the_teapot_and_reports_its_status() {
    let data = data_dir("smoke");
    let (output, status) = run_editor(&data, &[]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        output.status.success(),
        "exit {:?}\nstderr:\n{stderr}",
        output.status
    );
    assert_eq!(status["error"], serde_json::Value::Null);
    assert!(
        ["vulkan", "metal", "dx12", "webgl2/gl"]
            .contains(&status["backend"].as_str().unwrap_or("")),
        "{status}"
    );
    assert!(!status["adapter"].as_str().unwrap_or("").is_empty());
    // The demo scene: teapot (32 patches; 12 segments when fixed) and five NURBS objects (52
    // Bézier patches; 16), all measured by the first compute pass and tessellated for the
    // view: each visible patch has at least its 9-vertex minimum, and the statistics came
    // back from the GPU.
    assert_eq!(status["objects"], 6);
    assert_eq!(status["patches"], 84);
    assert_eq!(
        status["segments"],
        serde_json::json!([12, 16, 16, 16, 16, 16])
    );
    assert_eq!(status["tessellation"], "adaptive");
    assert_eq!(status["patches_reevaluated"], 84);
    let visible = status["visible_patches"].as_u64().unwrap_or(0);
    assert!((1..=84).contains(&visible), "{status}");
    assert!(
        status["vertices"].as_u64().unwrap_or(0) >= 9 * visible,
        "{status}"
    );
    assert_eq!(status["adaptive_coarsening"], 0);
    assert!(status["frames"].as_u64().unwrap_or(0) >= 3, "{status}");
    // The start-up log carries the same status for users.
    assert!(stderr.contains("knotwork status: {"), "{stderr}");
}

#[test]
fn desktop_app_opens_a_project_restores_it_and_refuses_a_broken_one() {
    let dir = data_dir("open");
    let good = dir.join("plane.json");
    std::fs::write(
        &good,
        r#"{"format": "knotwork", "version": 2, "objects": [{"type": "nurbs_surface",
            "name": "Plane", "segments": 4, "degree": [1, 1], "knots": [[0, 0, 1, 1], [0, 0, 1, 1]],
            "points": [[[0, 0, 0], [0, 1, 0]], [[1, 0, 0], [1, 1, 0]]]}],
            "view": {"target": [0.5, 0.5, 0], "distance": 4, "yaw": 0, "pitch": 0.5,
            "shading": "plain", "quality": 1, "tessellation": "fixed", "tolerance_px": 0.5}}"#,
    )
    .unwrap();
    let (output, status) = run_editor(&dir, &["--open", good.to_str().unwrap()]);
    assert!(output.status.success(), "{status}");
    assert_eq!(status["objects"], 1);
    assert_eq!(status["patches"], 1);
    // The file asks for the fixed tessellation: 4 segments.
    assert_eq!(status["tessellation"], "fixed");
    assert_eq!(status["vertices"], 5 * 5);
    assert_eq!(status["autosaved_revision"], status["revision"]);

    // The next start restores the last session; --fresh does not.
    let (_, status) = run_editor(&dir, &[]);
    assert_eq!(status["objects"], 1, "{status}");
    assert!(
        status["notice"]
            .as_str()
            .unwrap_or_default()
            .contains("restored"),
        "{status}"
    );
    let (_, status) = run_editor(&dir, &["--fresh"]);
    assert_eq!(status["objects"], 6, "{status}");

    let broken = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/bad-projects/zero-weight.json"
    );
    let (output, status) = run_editor(&dir, &["--fresh", "--open", broken]);
    assert!(
        !output.status.success(),
        "an error in the status fails the smoke run"
    );
    let error = status["error"].as_str().unwrap_or_default();
    assert!(
        error
            .contains("zero-weight.json: objects[0].points[0][1]: weight 0 must be finite and > 0"),
        "{error}"
    );
    assert_eq!(status["objects"], 6, "the sample scene stays open");

    let missing = dir.join("missing.json");
    let out = Command::new(env!("CARGO_BIN_EXE_knotwork"))
        .args(["--open", missing.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("could not open"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn without_compute_shaders_the_editor_runs_on_the_cpu_evaluator() {
    // Mesa's GL capped at 3.0: the only adapter has no compute shaders and no storage buffers,
    // as WebGL2 in a browser. The window opens on the WebGL2 path (the CPU evaluates the
    // surfaces, the renderer shades from the vertices), draws its frames and exits cleanly.
    let data = data_dir("no-compute");
    let (output, status) = run_editor_with_env(
        &data,
        &["--fresh"],
        &[
            ("WGPU_BACKEND", "gl"),
            ("MESA_GL_VERSION_OVERRIDE", "3.0"),
            ("MESA_GLES_VERSION_OVERRIDE", "3.0"),
        ],
    );
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(0), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_eq!(status["error"], serde_json::Value::Null, "{status}");
    assert_eq!(status["backend"], "webgl2/gl", "{status}");
    assert!(
        status["evaluator"]
            .as_str()
            .unwrap_or_default()
            .contains("CPU"),
        "{status}"
    );
    assert_eq!(status["tessellation"], "fixed", "{status}");
    // The demo scene at its fixed segments: 32 teapot patches at 12, 52 others at 16.
    assert_eq!(status["vertices"], 32 * 13 * 13 + 52 * 17 * 17, "{status}");
    assert!(status["frames"].as_u64().unwrap_or(0) >= 3, "{status}");
    let _ = std::fs::remove_dir_all(&data);
}
