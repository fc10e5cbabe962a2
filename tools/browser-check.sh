#!/usr/bin/env bash
# tools/browser-check.sh: opens shadowlab's HTML pages in headless Chromium (Debian's `chromium`,
# driven by the pinned npm package playwright-core of tools/browser/package-lock.json) and fails
# on console errors, images or local links that do not load, SVG plots that do not render and text
# that overflows its box (tools/browser/check-pages.mjs says exactly what each check means). A
# full-page screenshot of each page goes to $SHADOWLAB_BROWSER_SCREENSHOTS (default
# BUILD/browser-check/screenshots). Installs chromium, nodejs and npm with apt-get when missing
# (as root), and the npm packages with `npm ci` into $SHADOWLAB_NODE_DIR (default BUILD/node) when
# that folder does not hold the pinned versions yet (tools/browser/install.sh).
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

. "$root/tools/browser/install.sh"
browser_tools_install
[ "$1" = "--install-only" ] && exit 0

export SHADOWLAB_NODE_DIR="$node_dir"
exec node "$root/tools/browser/check-pages.mjs" --screenshots "$shots" "$@"
