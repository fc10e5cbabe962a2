# tools/browser/install.sh: sourced by tools/browser-check.sh, tools/gltf-validate.sh and
# tools/threejs-grade.sh. browser_tools_install installs what they need: chromium, nodejs and npm
# with apt-get when missing (as root; pass "no-chromium" to skip the browser), and the npm packages
# pinned by tools/browser/package-lock.json with `npm ci` into $node_dir when that folder does not
# hold them yet. Needs $root, $build and $node_dir set and a say() function; exits 2 on failure.
# Tests run in parallel: one installer at a time, and no tool runs while the packages are half there.
browser_tools_install() {
    mkdir -p "$build"
    exec 9>"$build/.browser-check.lock"
    flock 9

    local missing=()
    [ "${1:-}" = no-chromium ] || command -v chromium >/dev/null || missing+=(chromium)
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
    local lock="$root/tools/browser/package-lock.json" pkg
    local stale=0
    cmp -s "$lock" "$node_dir/package-lock.json" || stale=1
    for pkg in playwright-core gltf-validator three; do
        [ -d "$node_dir/node_modules/$pkg" ] || stale=1
    done
    if ((stale)); then
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
}
