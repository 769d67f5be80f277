#!/usr/bin/env bash
# Builds the web bundles: the crate for wasm32 (profile web-release), then wasm-bindgen, twice:
#   web/pkg/          single-threaded, for any page;
#   web/pkg-threads/  with WebAssembly atomics and shared memory, for pages served
#                     cross-origin isolated (index.html picks it there): the kernel's parallel
#                     work runs on Web Workers. The standard library is rebuilt with atomics
#                     (-Z build-std, which RUSTC_BOOTSTRAP allows on the stable compiler; it
#                     needs the rust-src component).
# With --opt also wasm-opt -Oz (npm binaryen; takes minutes, shrinks the bundles); with
# --single only the single-threaded bundle.
#
#   web/build.sh [--opt] [--single]
#
# Installs what is missing and can be installed without root: the wasm32 target and rust-src
# (rustup) and wasm-bindgen-cli at exactly the wasm-bindgen version in Cargo.lock (cargo
# install).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
optimize=false
threads=true
for arg in "$@"; do
  case "$arg" in
    --opt) optimize=true ;;
    --single) threads=false ;;
    *) echo "usage: web/build.sh [--opt] [--single]" >&2; exit 2 ;;
  esac
done

target_dir=${CARGO_TARGET_DIR:-$root/target}
if command -v rustup >/dev/null && ! rustup target list --installed | grep -qx wasm32-unknown-unknown; then
  echo "knotwork: adding the wasm32-unknown-unknown target" >&2
  rustup target add wasm32-unknown-unknown
fi
if $threads && command -v rustup >/dev/null && ! rustup component list --installed | grep -q '^rust-src'; then
  echo "knotwork: adding the rust-src component (the threaded bundle rebuilds std)" >&2
  rustup component add rust-src
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
rm -rf web/pkg web/pkg-threads
wasm-bindgen --target web --no-typescript --out-dir web/pkg "$wasm"
bundles=(web/pkg)

if $threads; then
  # A target directory of its own: other flags, and a standard library of its own. The link
  # makes the memory shared and imported (the workers instantiate the module on the page's),
  # up to 4 GiB, and exports the thread-local storage symbols wasm-bindgen's thread start
  # needs; rustc no longer adds these for +atomics by itself.
  link_args=(--shared-memory --import-memory --max-memory=4294967296 --export=__wasm_init_tls
    --export=__tls_size --export=__tls_align --export=__tls_base)
  CARGO_TARGET_DIR="$target_dir/wasm-threads" RUSTC_BOOTSTRAP=1 \
    RUSTFLAGS="-C target-feature=+atomics,+bulk-memory,+mutable-globals" \
    cargo rustc --lib --crate-type cdylib --profile web-release --target wasm32-unknown-unknown \
    -Z build-std=panic_abort,std -- "${link_args[@]/#/-Clink-arg=}"
  wasm-bindgen --target web --no-typescript --out-dir web/pkg-threads \
    "$target_dir/wasm-threads/wasm32-unknown-unknown/web-release/knotwork.wasm"
  bundles+=(web/pkg-threads)
fi

if $optimize; then
  # npm's binaryen, not Debian's (wasm-opt 108 writes bundles that fail to load).
  (cd web && npm ci --no-audit --no-fund --loglevel=error)
  for pkg in "${bundles[@]}"; do
    before=$(stat -c %s "$pkg/knotwork_bg.wasm")
    web/node_modules/.bin/wasm-opt -Oz --enable-bulk-memory --enable-nontrapping-float-to-int \
      --enable-sign-ext --enable-mutable-globals --enable-reference-types --enable-multivalue \
      --enable-threads -o "$pkg/knotwork_bg.opt.wasm" "$pkg/knotwork_bg.wasm"
    mv "$pkg/knotwork_bg.opt.wasm" "$pkg/knotwork_bg.wasm"
    echo "knotwork: wasm-opt -Oz ($pkg): $before -> $(stat -c %s "$pkg/knotwork_bg.wasm") bytes" >&2
  done
fi
for pkg in "${bundles[@]}"; do
  echo "knotwork: web bundle in $pkg ($(stat -c %s "$pkg/knotwork_bg.wasm") bytes of wasm)" >&2
done
