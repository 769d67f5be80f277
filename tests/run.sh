#!/usr/bin/env bash
# Runs every test of knotwork:
#   1. cargo fmt --check, clippy -D warnings for the desktop and for wasm32, the kernel and STEP
#      crates' layers (no GPU, UI or browser crate; each builds for wasm32 alone), and the book
#      (docs/, mdBook) with its links;
#   2. cargo test over the workspace: the kernel crate (crates/kernel), GPU evaluation vs the
#      f64 reference (a real wgpu adapter: lavapipe where there is no GPU), shader validation
#      and layouts, offscreen image tests, glTF export checked by the Khronos glTF-Validator
#      (npm), and the desktop app itself in a window (under Xvfb where there is no display);
#   3. a one-minute smoke of the file readers' fuzz harness (examples/fuzz_smoke.rs: project,
#      OBJ, glTF, STEP and PNG height maps);
#   4. the web bundle (web/build.sh) in headless Chromium with WebGPU (web/browser-test.mjs).
#
#   tests/run.sh
#
# On Debian/Ubuntu as root it installs what is missing (mesa-vulkan-drivers for lavapipe,
# chromium, xvfb and xauth where there is no display, Node.js, npm packages, the wasm32 target,
# wasm-bindgen-cli); elsewhere it prints what to install and fails. A missing GPU adapter,
# display or browser is a failure, never a skip.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"

step() { printf '\n==> %s\n' "$*"; }
started=$(date +%s)

# --- What the machine needs ------------------------------------------------------------------
packages=()
if [ "$(uname -s)" = Linux ]; then
  icds=$(ls /usr/share/vulkan/icd.d/*.json /etc/vulkan/icd.d/*.json 2>/dev/null || true)
  [ -n "$icds" ] || packages+=(mesa-vulkan-drivers)
  # A virtual display for the desktop app's test where there is no display.
  if [ -z "${DISPLAY:-}${WAYLAND_DISPLAY:-}" ]; then
    command -v xvfb-run >/dev/null || packages+=(xvfb)
    command -v xauth >/dev/null || packages+=(xauth)
  fi
fi
chromium=${CHROMIUM:-/usr/bin/chromium}
[ -x "$chromium" ] || packages+=(chromium)
command -v node >/dev/null && command -v npm >/dev/null || packages+=(nodejs npm)
if [ ${#packages[@]} -gt 0 ]; then
  if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null; then
    step "installing ${packages[*]}"
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq
    apt-get install -y -qq --no-install-recommends "${packages[@]}" >/dev/null
  else
    echo "tests/run.sh: missing: ${packages[*]}" >&2
    echo "  Debian/Ubuntu: sudo apt-get install ${packages[*]}" >&2
    echo "  (mesa-vulkan-drivers gives a software Vulkan GPU, xvfb a virtual display;" >&2
    echo "   set CHROMIUM=/path/to/chromium to use another browser)" >&2
    exit 1
  fi
fi
if ! command -v cargo >/dev/null; then
  echo "tests/run.sh: Rust is missing: install it with rustup (https://rustup.rs)" >&2
  exit 1
fi
if [ "$(uname -s)" = Linux ]; then
  # Vulkan directly (skips a slow EGL probe); lavapipe where there is no GPU.
  export WGPU_BACKEND=${WGPU_BACKEND:-vulkan}
fi
if [ -z "${XDG_RUNTIME_DIR:-}" ] || [ ! -d "$XDG_RUNTIME_DIR" ]; then
  XDG_RUNTIME_DIR=$(mktemp -d)
  export XDG_RUNTIME_DIR
fi
if command -v rustup >/dev/null && ! rustup target list --installed | grep -qx wasm32-unknown-unknown; then
  step "adding the wasm32-unknown-unknown target"
  rustup target add wasm32-unknown-unknown
fi

# --- Static checks -----------------------------------------------------------------------------
step "cargo fmt --check"
cargo fmt --all -- --check
step "cargo clippy (desktop)"
cargo clippy --workspace --all-targets --locked -- -D warnings
step "cargo clippy (wasm32)"
cargo clippy --workspace --lib --bins --locked --target wasm32-unknown-unknown -- -D warnings
# The threaded web bundle's code (src/web_threads.rs) exists only with WebAssembly atomics: the
# same flags and target directory as web/build.sh's threaded build (std rebuilt; rust-src).
# With atomics wgpu's handles are neither Send nor Sync, so the Arcs that share them natively
# are allowed there.
if command -v rustup >/dev/null && ! rustup component list --installed | grep -q '^rust-src'; then
  step "adding the rust-src component"
  rustup component add rust-src
fi
step "cargo clippy (wasm32 with atomics: the threaded bundle)"
CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$root/target}/wasm-threads" RUSTC_BOOTSTRAP=1 \
  RUSTFLAGS="-C target-feature=+atomics,+bulk-memory,+mutable-globals" \
  cargo clippy --lib --locked --target wasm32-unknown-unknown -Z build-std=panic_abort,std -- \
  -D warnings -A clippy::arc_with_non_send_sync
# The kernel is a layer of its own: no GPU, UI, file format or browser crate in its graph, and
# it builds for wasm32 by itself; STEP is a crate on the kernel alone in the same way.
layer() {
  local crate=$1 forbidden
  step "$crate layer (dependencies, wasm32 build)"
  forbidden=$(cargo tree --locked -p "$crate" -e normal --prefix none | tail -n +2 |
    awk '{ print $1 }' |
    grep -Ex 'knotwork|knotwork-step|wgpu.*|naga|egui.*|eframe|winit|gltf.*|wasm-bindgen.*|web-sys|js-sys' |
    sort -u || true)
  if [ -n "$forbidden" ]; then
    echo "tests/run.sh: $crate depends on $(echo $forbidden)" >&2
    exit 1
  fi
  cargo build --locked -p "$crate" --target wasm32-unknown-unknown
}
layer knotwork-kernel
layer knotwork-step

# --- The book -----------------------------------------------------------------------------------
# The manual (docs/, mdBook) builds, and no link of the book, README.md or ARCHITECTURE.md is
# broken.
mdbook_version=0.5.4
if ! mdbook --version 2>/dev/null | grep -q "v$mdbook_version"; then
  step "installing mdbook $mdbook_version"
  cargo install mdbook --version "$mdbook_version" --locked --no-default-features --features search
fi
step "the book (mdbook build docs) and its links"
mdbook build docs
node docs/check-links.mjs

# --- Rust tests --------------------------------------------------------------------------------
# The npm packages first: the glTF tests run the Khronos validator from web/node_modules.
step "npm packages (glTF validator, browser driver)"
(cd web && npm ci --no-audit --no-fund --loglevel=error)
step "cargo test"
log=$(mktemp)
browser_log=$(mktemp)
trap 'rm -f "$log" "$browser_log"' EXIT
cargo test --workspace --locked 2>&1 | tee "$log"
rust_passed=$(awk '/^test result:/ { for (i = 1; i <= NF; i++) if ($(i + 1) ~ /^passed/) n += $i } END { print n + 0 }' "$log")

# --- Fuzz smoke ---------------------------------------------------------------------------------
# The file readers (project, OBJ, glTF, PNG height maps) under the stable mutation harness for
# about a minute in all; fuzz/run.sh runs the coverage-guided cargo-fuzz targets for as long as
# asked.
step "fuzz smoke (project, OBJ, glTF, STEP and PNG readers; construct requests)"
cargo run --quiet --locked --example fuzz_smoke -- --seconds 60

# --- The web page in a browser -----------------------------------------------------------------
step "web bundle"
web/build.sh
step "browser test (headless Chromium, WebGPU)"
set +e
CHROMIUM="$chromium" node web/browser-test.mjs 2>&1 | tee "$browser_log"
browser_status=${PIPESTATUS[0]}
set -e
browser_passed=$(sed -n 's/^browser: \([0-9]*\) passed.*/\1/p' "$browser_log")
browser_failed=$(sed -n 's/^browser: [0-9]* passed, \([0-9]*\) failed.*/\1/p' "$browser_log")
if [ "$browser_status" != 0 ]; then
  echo "tests/run.sh: the browser test failed" >&2
  exit 1
fi

printf '\nAll checks passed in %s s: cargo test %s, browser %s.\n' \
  "$(($(date +%s) - started))" "$rust_passed" "${browser_passed:-0}"
echo "tests: $((rust_passed + ${browser_passed:-0})) passed, ${browser_failed:-0} failed"
