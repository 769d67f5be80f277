#!/usr/bin/env bash
# Builds the web bundle and serves the editor on http://127.0.0.1:8080/ (Ctrl+C stops).
#
#   web/serve.sh [--opt] [--port N]
#
# --opt also runs wasm-opt (minutes; a smaller download). Needs Rust (rustup) and Node.js.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
port=8080
build_args=()
while [ $# -gt 0 ]; do
  case "$1" in
    --opt) build_args+=(--opt) ;;
    --port) port=$2; shift ;;
    *) echo "usage: web/serve.sh [--opt] [--port N]" >&2; exit 2 ;;
  esac
  shift
done
"$root/web/build.sh" "${build_args[@]}"
echo "knotwork: open http://127.0.0.1:$port/ in a browser with WebGPU" >&2
exec node "$root/web/server.mjs" --port "$port"
