#!/usr/bin/env bash
# tools/fresh-debian-check.sh: proves the README's two commands work on a bare Debian 12, the
# way a new user meets them. It debootstraps a minimal bookworm (no compiler, no CMake, no git)
# into DIR (kept and reused between checks), copies the committed tree into it with ../shared
# beside it, mounts proc, and runs `./shadowlab run seed -o out/seed` and `./run-tests` in chroot.
# Needs root and debootstrap. Usage: tools/fresh-debian-check.sh [DIR]   (see docs/fresh-machine.md)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
dir="${1:-/var/tmp/shadowlab-fresh}"
mirror="${DEBIAN_MIRROR:-http://deb.debian.org/debian}"

if [ ! -x "$dir/usr/bin/apt-get" ]; then
    echo "fresh check: debootstrap --variant=minbase bookworm $dir"
    debootstrap --variant=minbase bookworm "$dir" "$mirror"
fi
# Start from the bare system every time: drop whatever an earlier check installed.
if [ -f "$dir/.bare-packages" ]; then
    extra=$(comm -13 "$dir/.bare-packages" <(chroot "$dir" dpkg-query -W -f='${Package}\n' | sort))
    if [ -n "$extra" ]; then
        chroot "$dir" env DEBIAN_FRONTEND=noninteractive apt-get purge -y -q $extra >/dev/null
        chroot "$dir" env DEBIAN_FRONTEND=noninteractive apt-get autoremove --purge -y -q >/dev/null
    fi
else
    chroot "$dir" dpkg-query -W -f='${Package}\n' | sort >"$dir/.bare-packages"
fi
for tool in gcc g++ cmake git; do
    if chroot "$dir" sh -c "command -v $tool" >/dev/null; then
        echo "fresh check: error: $tool is present in the bare system" >&2
        exit 1
    fi
done

rm -rf "$dir/work"
mkdir -p "$dir/work/main"
git -C "$root" archive HEAD | tar -x -C "$dir/work/main"
[ -d "$root/../shared" ] && cp -r "$root/../shared" "$dir/work/shared"
cp /etc/resolv.conf "$dir/etc/resolv.conf"

mount -t proc proc "$dir/proc"
trap 'umount "$dir/proc"' EXIT
chroot "$dir" /usr/bin/env -i PATH=/usr/sbin:/usr/bin:/sbin:/bin HOME=/root TERM=dumb /bin/bash -c '
    set -e
    cd /work/main
    ./shadowlab run seed -o out/seed
    ls -l out/seed
    ./run-tests
'
echo "fresh check: both README commands passed on a bare Debian 12"
