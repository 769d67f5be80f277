#!/usr/bin/env bash
# Fuzzes the readers that take files from users (targets: project, obj, gltf, png, construct,
# step) and the boolean on two primitive solids the bytes place (target: boolean).
#
#   fuzz/run.sh TARGET SECONDS [LIBFUZZER-ARGS...]   coverage-guided: cargo-fuzz (libFuzzer) on
#                                                    the nightly toolchain; `cargo install
#                                                    cargo-fuzz` once
#   fuzz/run.sh --stable SECONDS [TARGET...]         the stable-Rust mutation harness
#                                                    (examples/fuzz_smoke.rs; what CI runs)
#
# The corpus starts from valid and broken files (fuzz/corpus/TARGET, made on first use) and grows
# there; failing inputs land in fuzz/artifacts/TARGET. Copy a fixed one into
# fuzz/regressions/TARGET/ so that `cargo test --test it fuzz_regressions::` keeps it fixed.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
export CARGO_TARGET_DIR=${CARGO_TARGET_DIR:-$HOME/.cache/knotwork-target}

if [ "${1:-}" = --stable ]; then
  shift
  seconds=${1:?usage: fuzz/run.sh --stable SECONDS [TARGET...]}
  shift
  exec cargo run --quiet --locked --release --example fuzz_smoke -- --seconds "$seconds" "$@"
fi

target=${1:?usage: fuzz/run.sh TARGET SECONDS [LIBFUZZER-ARGS...]}
seconds=${2:?usage: fuzz/run.sh TARGET SECONDS [LIBFUZZER-ARGS...]}
shift 2
case "$target" in project|obj|gltf|png|construct|step|boolean) ;; *) echo "fuzz/run.sh: unknown target $target" >&2; exit 2 ;; esac
command -v cargo-fuzz >/dev/null || { echo "fuzz/run.sh: cargo install cargo-fuzz" >&2; exit 1; }
if [ ! -d "fuzz/corpus/$target" ]; then
  cargo run --quiet --locked --example fuzz_smoke -- --write-seeds fuzz/corpus "$target"
fi
mkdir -p "fuzz/artifacts/$target"
# The instrumented build keeps its own target directory (other flags, other toolchain). Safe Rust
# needs no address sanitizer: panics, overflows and failed checks are what is looked for.
CARGO_TARGET_DIR=$HOME/.cache/knotwork-fuzz-target \
  cargo +nightly fuzz run --sanitizer none --fuzz-dir fuzz "$target" "fuzz/corpus/$target" -- \
  -max_total_time="$seconds" -artifact_prefix="fuzz/artifacts/$target/" -print_final_stats=1 "$@"
