#!/usr/bin/env bash
# A Debian unstable ("sid") root with Debian's own Blender package, for the real-application stage
# (tests/gui/, run by ./dev.sh test). Debian's Blender is a distribution build without OSL, the
# build many Linux users run.
#   tools/blender_root.sh           print the root's path, building it first if it is missing or stale
#   tools/blender_root.sh --path    print the path it would have (builds nothing)
# The root lives in ${XDG_CACHE_HOME:-~/.cache}/relativity-addon/blender-sid-KEY, KEY a hash of this
# script (so any change to the package list or the steps builds a new root; older roots are deleted).
# Needs root (or sudo) and Debian's package registry; debootstrap is installed on the host if missing.
# Inside the root: Blender, Xvfb, xdotool, x11-apps (xwd) and the Python modules that Debian's
# Blender imports but does not pull in (numpy, cattrs, requests); node, to compile the Flamenco job
# types the way Flamenco's Manager does (tests/gui/test_flamenco_baked.py).
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
cache=${XDG_CACHE_HOME:-$HOME/.cache}/relativity-addon
key=$(sha256sum "$here/blender_root.sh" | cut -c1-12)
root=$cache/blender-sid-$key
if [ "${1:-}" = "--path" ]; then
    echo "$root"
    exit 0
fi
if [ -f "$root/.complete" ]; then
    echo "$root"
    exit 0
fi

sudo=""
[ "$(id -u)" -eq 0 ] || sudo=sudo
PACKAGES="blender xvfb xauth xdotool x11-apps x11-utils python3-numpy python3-cattr python3-requests nodejs"
mirror=${RELATIVITY_DEBIAN_MIRROR:-$(grep -hoE '^URIs: *[^ ]+/debian/?$' /etc/apt/sources.list.d/*.sources 2>/dev/null | head -n1 | sed 's/^URIs: *//')}
mirror=${mirror:-http://deb.debian.org/debian}

mkdir -p "$cache"
exec 9>"$cache/blender-sid.lock"  # one build at a time; a second run waits, then finds the root built
flock 9
if [ -f "$root/.complete" ]; then
    echo "$root"
    exit 0
fi
for old in "$cache"/blender-sid-*; do  # stale roots (another key) and half-built ones
    [ -e "$old" ] || continue
    case "$old" in "$root" | "$root".*) ;; *) echo "removing the stale Blender root $old" >&2 ;; esac
    for mount in dev/pts dev proc sys; do ! mountpoint -q "$old/$mount" || $sudo umount -l "$old/$mount"; done
    [ "$old" = "$root" ] && [ -f "$old/.complete" ] || $sudo rm -rf --one-file-system "$old"
done

if ! command -v debootstrap >/dev/null; then
    echo "installing debootstrap on the host" >&2
    $sudo apt-get update -qq
    $sudo env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq debootstrap >/dev/null
fi

work=$root.building
log=$cache/blender-sid-$key.log
unmount() {
    for mount in dev/pts dev proc sys; do ! mountpoint -q "$work/$mount" || $sudo umount -l "$work/$mount"; done
}
trap unmount EXIT
echo "building the Debian sid root with Blender in $root (log: $log)" >&2
{
    $sudo debootstrap --variant=minbase sid "$work" "$mirror"
    # sid's Release file may be older than its Valid-Until (a mirror snapshot): accept it.
    echo 'Acquire::Check-Valid-Until "false";' | $sudo tee "$work/etc/apt/apt.conf.d/99relativity-no-valid-until" >/dev/null
    # No manual pages or documentation in the root (and no man-db database to rebuild at each install).
    printf 'path-exclude=/usr/share/man/*\npath-exclude=/usr/share/doc/*\npath-include=/usr/share/doc/*/copyright\n' |
        $sudo tee "$work/etc/dpkg/dpkg.cfg.d/01relativity-nodoc" >/dev/null
    $sudo cp /etc/resolv.conf "$work/etc/resolv.conf"
    $sudo mount -t proc proc "$work/proc"
    $sudo mount --rbind /dev "$work/dev"
    $sudo mount --rbind /sys "$work/sys"
    $sudo chroot "$work" apt-get update
    # shellcheck disable=SC2086
    $sudo chroot "$work" env DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends $PACKAGES
    $sudo chroot "$work" apt-get clean
    $sudo chroot "$work" blender --version
} >"$log" 2>&1 || {
    tail -n 30 "$log" >&2
    echo "error: building the Debian sid root with Blender failed (last lines above; log: $log)" >&2
    exit 1
}
unmount
trap - EXIT
$sudo touch "$work/.complete"
$sudo mv "$work" "$root"
echo "$root"
