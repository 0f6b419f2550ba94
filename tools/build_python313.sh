#!/usr/bin/env bash
# Build CPython 3.13 (what Blender 5.2's bpy wheel needs) from Debian 13 "trixie"'s python3.13
# source package, for a Debian machine that has no python3.13 (./dev.sh runs this only then).
#   tools/build_python313.sh PREFIX    installs PREFIX/bin/python3.13 (with pip, venv and ssl)
# It adds a deb-src line for trixie (sources only: no binary package comes from trixie), installs
# the build dependencies from the machine's own release, downloads the source package with
# apt-get source and builds the upstream tree it contains (about 5 minutes on 2 cores).
set -euo pipefail
prefix=${1:?usage: tools/build_python313.sh PREFIX}
sudo=""
[ "$(id -u)" -eq 0 ] || sudo=sudo

list=/etc/apt/sources.list.d/relativity-trixie-src.sources
if [ ! -f "$list" ]; then
    uri=$(grep -hoE '^URIs: *[^ ]+/debian/?$' /etc/apt/sources.list.d/*.sources 2>/dev/null | head -n1 | sed 's/^URIs: *//')
    printf 'Types: deb-src\nURIs: %s\nSuites: trixie\nComponents: main\nSigned-By: /usr/share/keyrings/debian-archive-keyring.gpg\n' \
        "${uri:-http://deb.debian.org/debian}" | $sudo tee "$list" >/dev/null
fi
$sudo apt-get update -qq
$sudo env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
    dpkg-dev build-essential pkg-config xz-utils libssl-dev zlib1g-dev libffi-dev libbz2-dev \
    liblzma-dev libsqlite3-dev libreadline-dev libncurses-dev uuid-dev libgdbm-dev >/dev/null

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
apt-get source --download-only -qq python3.13
tar xf python3.13_*.orig.tar.xz
cd Python-3.13*/
log=$work/build.log
{ ./configure --prefix="$prefix" --with-ensurepip=install && make -j"$(nproc)" && make altinstall; } >"$log" 2>&1 || {
    tail -n 40 "$log" >&2
    echo "error: building CPython 3.13 failed (last lines above)" >&2
    exit 1
}
"$prefix/bin/python3.13" -c "import ssl, venv, ensurepip, ctypes, lzma, bz2, zlib; import sys; print('built', sys.version)"
