#!/usr/bin/env bash
# tools/gltf-validate.sh: validates glTF 2.0 files with the Khronos glTF validator (the npm package
# gltf-validator pinned by tools/browser/package-lock.json; tools/browser/gltf-validate.mjs prints
# every message). Errors fail; warnings, infos and hints are listed and allowed. Installs nodejs and
# npm with apt-get when missing (as root) and the npm packages into $SHADOWLAB_NODE_DIR (default
# BUILD/node), as tools/browser-check.sh does (tools/browser/install.sh).
# Usage: tools/gltf-validate.sh FILE.glb|FILE.gltf...
# Exit: 0 no error, 1 an error in some file, 2 bad usage or set-up.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${SHADOWLAB_BUILD_DIR:-$root/build}"
node_dir="${SHADOWLAB_NODE_DIR:-$build/node}"
say() { echo "gltf-validate: $*" >&2; }

[ $# -gt 0 ] || { say "usage: tools/gltf-validate.sh FILE.glb|FILE.gltf..."; exit 2; }

. "$root/tools/browser/install.sh"
browser_tools_install no-chromium

export SHADOWLAB_NODE_DIR="$node_dir"
exec node "$root/tools/browser/gltf-validate.mjs" "$@"
