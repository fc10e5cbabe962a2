#!/usr/bin/env bash
# tools/setup.sh: makes this checkout ready to run on Debian 12: installs the missing packages
# of tools/debian-packages.txt (apt-get, as root or through sudo), configures a Release build in
# build/ and builds TARGET (default: everything). Quiet when there is nothing to do.
# Usage: tools/setup.sh [TARGET...] | tools/setup.sh --packages-only
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${SHADOWLAB_BUILD_DIR:-$root/build}"
say() { echo "shadowlab setup: $*" >&2; }

mapfile -t wanted < <(grep -v -E '^\s*(#|$)' "$root/tools/debian-packages.txt")
missing=()
for pkg in "${wanted[@]}"; do
    dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed" || missing+=("$pkg")
done
if ((${#missing[@]})); then
    say "installing ${#missing[@]} Debian package(s): ${missing[*]}"
    if [ "$(id -u)" -eq 0 ]; then
        sudo=()
    elif command -v sudo >/dev/null; then
        sudo=(sudo)
    else
        say "error: not root and no sudo; install these packages first: ${missing[*]}"
        exit 2
    fi
    export DEBIAN_FRONTEND=noninteractive
    "${sudo[@]}" apt-get update -q >&2
    "${sudo[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}" >&2
fi

[ "${1:-}" = "--packages-only" ] && exit 0

if [ ! -f "$build/build.ninja" ]; then
    say "configuring a Release build in $build"
    # ccache, where installed, makes rebuilds in fresh build folders (worktrees, CI caches) cheap.
    launcher=()
    command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
    cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release "${launcher[@]}" >&2
fi
# Ninja rebuilds only what changed; a no-op takes a fraction of a second.
targets=()
for t in "$@"; do targets+=(--target "$t"); done
if ! out=$(cmake --build "$build" -j "$(nproc)" "${targets[@]}" 2>&1); then
    echo "$out" >&2
    say "error: the build failed (output above)"
    exit 1
fi
if ! grep -q "ninja: no work to do" <<<"$out"; then
    say "built $( [ ${#targets[@]} -gt 0 ] && echo "$*" || echo everything ) in $build"
fi
