#!/usr/bin/env bash
# Builds the web bundle into web/pkg/: the crate for wasm32 (profile web-release), then
# wasm-bindgen; with --opt also wasm-opt -Oz (npm binaryen; takes minutes, shrinks the bundle).
#
#   web/build.sh [--opt]
#
# Installs what is missing and can be installed without root: the wasm32 target (rustup) and
# wasm-bindgen-cli at exactly the wasm-bindgen version in Cargo.lock (cargo install).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
optimize=false
for arg in "$@"; do
  case "$arg" in
    --opt) optimize=true ;;
    *) echo "usage: web/build.sh [--opt]" >&2; exit 2 ;;
  esac
done

target_dir=${CARGO_TARGET_DIR:-$root/target}
if command -v rustup >/dev/null && ! rustup target list --installed | grep -qx wasm32-unknown-unknown; then
  echo "knotwork: adding the wasm32-unknown-unknown target" >&2
  rustup target add wasm32-unknown-unknown
fi

version=$(awk '/^name = "wasm-bindgen"$/ { getline; gsub(/version = |"/, ""); print; exit }' Cargo.lock)
if [ -z "$version" ]; then
  echo "knotwork: Cargo.lock names no wasm-bindgen version" >&2
  exit 1
fi
if [ "$(wasm-bindgen --version 2>/dev/null)" != "wasm-bindgen $version" ]; then
  # Not --locked: the CLI's own lockfile pins a crate version the registry no longer has.
  echo "knotwork: installing wasm-bindgen-cli $version" >&2
  cargo install wasm-bindgen-cli --version "$version"
fi

cargo rustc --lib --crate-type cdylib --profile web-release --target wasm32-unknown-unknown
wasm="$target_dir/wasm32-unknown-unknown/web-release/knotwork.wasm"
rm -rf web/pkg
wasm-bindgen --target web --no-typescript --out-dir web/pkg "$wasm"

if $optimize; then
  # npm's binaryen, not Debian's (wasm-opt 108 writes bundles that fail to load).
  (cd web && npm ci --no-audit --no-fund --loglevel=error)
  before=$(stat -c %s web/pkg/knotwork_bg.wasm)
  web/node_modules/.bin/wasm-opt -Oz --enable-bulk-memory --enable-nontrapping-float-to-int \
    --enable-sign-ext --enable-mutable-globals --enable-reference-types --enable-multivalue \
    -o web/pkg/knotwork_bg.opt.wasm web/pkg/knotwork_bg.wasm
  mv web/pkg/knotwork_bg.opt.wasm web/pkg/knotwork_bg.wasm
  echo "knotwork: wasm-opt -Oz: $before -> $(stat -c %s web/pkg/knotwork_bg.wasm) bytes" >&2
fi
echo "knotwork: web bundle in web/pkg ($(stat -c %s web/pkg/knotwork_bg.wasm) bytes of wasm)" >&2
