#!/usr/bin/env bash
# tools/browser-check.sh: opens shadowlab's HTML pages in headless Chromium (Debian's `chromium`,
# driven by the pinned npm package playwright-core of tools/browser/package-lock.json) and fails
# on console errors, images or local links that do not load, SVG plots that do not render and text
# that overflows its box (tools/browser/check-pages.mjs says exactly what each check means). A
# full-page screenshot of each page goes to $SHADOWLAB_BROWSER_SCREENSHOTS (default
# BUILD/browser-check/screenshots). Installs chromium, nodejs and npm with apt-get when missing
# (as root), and the npm packages with `npm ci` into $SHADOWLAB_NODE_DIR (default BUILD/node) when
# that folder does not hold the pinned versions yet.
# Usage: tools/browser-check.sh HTML|DIR...   (a DIR is searched for *.html)
#        tools/browser-check.sh --install-only
# Exit: 0 no problem, 1 a problem on some page (one line each on stdout), 2 bad usage or set-up.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${SHADOWLAB_BUILD_DIR:-$root/build}"
node_dir="${SHADOWLAB_NODE_DIR:-$build/node}"
shots="${SHADOWLAB_BROWSER_SCREENSHOTS:-$build/browser-check/screenshots}"
say() { echo "browser check: $*" >&2; }

[ $# -gt 0 ] || { say "usage: tools/browser-check.sh HTML|DIR... | --install-only"; exit 2; }

# Tests run in parallel: one installer at a time, and no check while the packages are half there.
mkdir -p "$build"
exec 9>"$build/.browser-check.lock"
flock 9

missing=()
command -v chromium >/dev/null || missing+=(chromium)
command -v node >/dev/null || missing+=(nodejs)
command -v npm >/dev/null || missing+=(npm)
if ((${#missing[@]})); then
    [ "$(id -u)" -eq 0 ] || { say "error: not root; install these Debian packages first: ${missing[*]}"; exit 2; }
    say "installing ${missing[*]}"
    export DEBIAN_FRONTEND=noninteractive
    { apt-get update -q && apt-get install -y -q --no-install-recommends "${missing[@]}"; } >&2 ||
        { say "error: apt-get failed"; exit 2; }
fi

# The lock file copied beside node_modules records what that folder holds; a changed pin reinstalls.
lock="$root/tools/browser/package-lock.json"
if ! cmp -s "$lock" "$node_dir/package-lock.json" || [ ! -d "$node_dir/node_modules/playwright-core" ]; then
    say "installing the pinned npm packages into $node_dir"
    mkdir -p "$node_dir"
    rm -f "$node_dir/package-lock.json"
    cp "$root/tools/browser/package.json" "$node_dir/package.json"
    cp "$lock" "$node_dir/package-lock.tmp"
    mv "$node_dir/package-lock.tmp" "$node_dir/package-lock.json"
    # No install scripts: playwright-core would otherwise have nothing to run, and the system
    # Chromium is the browser (no browser download).
    if ! (cd "$node_dir" && npm ci --ignore-scripts --no-audit --no-fund --loglevel=error >&2); then
        rm -f "$node_dir/package-lock.json"
        say "error: npm ci failed in $node_dir (is the npm registry reachable?)"
        exit 2
    fi
fi
flock -u 9
[ "$1" = "--install-only" ] && exit 0

export SHADOWLAB_NODE_DIR="$node_dir"
exec node "$root/tools/browser/check-pages.mjs" --screenshots "$shots" "$@"
