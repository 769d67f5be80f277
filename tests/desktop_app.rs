//! The desktop editor end to end: the real binary opens its window (under Xvfb where there is no
//! display), evaluates and draws the teapot on the GPU, closes itself and reports its status.

use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

#[test]
fn desktop_app_opens_draws_the_teapot_and_reports_its_status() {
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
    let stdout = String::from_utf8_lossy(&output.stdout);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        output.status.success(),
        "exit {:?}\nstdout:\n{stdout}\nstderr:\n{stderr}",
        output.status
    );
    let last = stdout.lines().last().unwrap_or_default();
    let status: serde_json::Value =
        serde_json::from_str(last).unwrap_or_else(|e| panic!("status line {last:?}: {e}"));
    eprintln!("desktop status: {status}");
    assert_eq!(status["error"], serde_json::Value::Null);
    assert!(
        ["vulkan", "metal", "dx12", "webgl2/gl"]
            .contains(&status["backend"].as_str().unwrap_or("")),
        "{status}"
    );
    assert!(!status["adapter"].as_str().unwrap_or("").is_empty());
    // The demo scene: teapot (32 patches at 12 segments) and five NURBS objects (52 Bézier
    // patches at 16), all evaluated by the first compute pass.
    assert_eq!(status["objects"], 6);
    assert_eq!(status["patches"], 84);
    assert_eq!(
        status["segments"],
        serde_json::json!([12, 16, 16, 16, 16, 16])
    );
    assert_eq!(status["vertices"], 32 * 13 * 13 + 52 * 17 * 17);
    assert_eq!(status["patches_reevaluated"], 84);
    assert!(status["frames"].as_u64().unwrap_or(0) >= 3, "{status}");
    // The start-up log carries the same status for users.
    assert!(stderr.contains("knotwork status: {"), "{stderr}");
}
