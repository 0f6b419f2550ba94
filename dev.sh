#!/usr/bin/env bash
# Development entry point. Supported Blender lines: 4.5 LTS (bpy 4.5, CPython 3.11) and
# 5.2 LTS (bpy 5.2, CPython 3.13); each has its pins in requirements/blender-X.Y.txt and its own
# virtual environment .venv-X.Y.
#   ./dev.sh demo   set up .venv-5.2, render the README's demo image (three panels) to out/demo.png
#   ./dev.sh test   run ruff, then set up each venv and run the whole suite on every supported version, one
#                   after the other (extra arguments go to pytest), then the real-application stage
#                   (tests/gui/: Debian's Blender in a window under Xvfb); non-zero if any of them fails
# BLENDER=4.5 or BLENDER=5.2 picks one version (e.g. BLENDER=5.2 ./dev.sh test -k register);
# BLENDER=gui runs only the real-application stage; RELATIVITY_SKIP_GUI=1 skips it (said in the summary).
# PYTHON311 / PYTHON313 name the interpreters to use; without PYTHON313 a python3.13 is looked
# for on PATH and in pyenv, else built once from Debian's python3.13 source package
# (tools/build_python313.sh; RELATIVITY_BUILD_PYTHON313=1 forces that route).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")"

SUPPORTED="4.5 5.2"
PYTHON313_BUILD=${RELATIVITY_PYTHON313_PREFIX:-${XDG_CACHE_HOME:-$HOME/.cache}/relativity-addon/python3.13}

works() {  # works PYTHON X.Y: an interpreter of that version with venv, ensurepip and ssl
    "$1" -c "import sys, ssl, venv, ensurepip; sys.exit(sys.version_info[:2] != tuple(map(int, '$2'.split('.'))))" \
        >/dev/null 2>&1
}

find_python313() {
    if [ -n "${PYTHON313:-}" ]; then
        echo "$PYTHON313"
        return
    fi
    if [ -z "${RELATIVITY_BUILD_PYTHON313:-}" ]; then
        local root candidate
        root=$(pyenv root 2>/dev/null || echo "$HOME/.pyenv")
        for candidate in python3.13 /usr/bin/python3.13 /usr/local/bin/python3.13 "$root"/versions/3.13*/bin/python3.13; do
            if works "$candidate" 3.13; then
                echo "$candidate"
                return
            fi
        done
    fi
    if ! works "$PYTHON313_BUILD/bin/python3.13" 3.13; then
        echo "no usable python3.13 found: building CPython 3.13 from Debian's source package into $PYTHON313_BUILD" >&2
        tools/build_python313.sh "$PYTHON313_BUILD" >&2 || return 1
    fi
    echo "$PYTHON313_BUILD/bin/python3.13"
}

python_version() {
    case "$1" in
        4.5) echo 3.11 ;;
        5.2) echo 3.13 ;;
    esac
}

python_for() {
    case "$1" in
        4.5) echo "${PYTHON311:-python3.11}" ;;
        5.2) find_python313 ;;
    esac
}

setup() {  # setup X.Y: create .venv-X.Y and install requirements/blender-X.Y.txt unless current
    local version=$1 venv=.venv-$1 requirements=requirements/blender-$1.txt want python
    if [ ! -x "$venv/bin/python" ]; then
        python=$(python_for "$version") || return 1
        if ! works "$python" "$(python_version "$version")"; then
            echo "error: Blender $version's bpy wheel needs CPython $(python_version "$version") with venv and ssl; none found (install python$(python_version "$version") or set PYTHON$(python_version "$version" | tr -d .))" >&2
            return 1
        fi
        echo "creating $venv with $python"
        "$python" -m venv "$venv" || return 1
    fi
    want=$(sha256sum "$requirements" | cut -d' ' -f1)
    if [ -f "$venv/.requirements.sha256" ] && [ "$(cat "$venv/.requirements.sha256")" = "$want" ]; then
        echo "$venv is up to date with $requirements"
    else
        echo "installing $requirements into $venv (the bpy wheel is about 400 MB)"
        "$venv/bin/python" -m pip install --disable-pip-version-check -r "$requirements" || return 1
        echo "$want" > "$venv/.requirements.sha256"
    fi
}

run_tests() {  # run_tests X.Y [pytest arguments]
    local version=$1 status=0
    shift
    ".venv-$version/bin/python" -m pytest -n 2 --dist worksteal tests --ignore=tests/gui "$@" || status=$?
    if [ "$status" -eq 5 ]; then
        echo "error: pytest collected no tests (Blender $version)" >&2
        return 1
    fi
    return "$status"
}

lint() {  # ruff (check and format), mypy and codespell over the repository, in their own venv (requirements/lint.txt)
    local venv=.venv-lint want
    [ -x "$venv/bin/python" ] || "${PYTHON311:-python3.11}" -m venv "$venv" || return 1
    want=$(sha256sum requirements/lint.txt | cut -d' ' -f1)
    if [ ! -f "$venv/.requirements.sha256" ] || [ "$(cat "$venv/.requirements.sha256")" != "$want" ]; then
        "$venv/bin/python" -m pip install --disable-pip-version-check -q -r requirements/lint.txt || return 1
        echo "$want" > "$venv/.requirements.sha256"
    fi
    local status=0
    "$venv/bin/ruff" check . || status=1
    "$venv/bin/ruff" format --check . || status=1
    "$venv/bin/mypy" || status=1  # files and levels: [tool.mypy] in pyproject.toml
    "$venv/bin/codespell" || status=1
    return "$status"
}

run_gui() {  # run_gui [pytest arguments]: Debian's Blender under Xvfb against the 5.2 wheel (tests/gui/)
    local status=0 root
    root=$(tools/blender_root.sh) || return 1
    gui_setup_seconds=$((SECONDS - gui_start))
    RELATIVITY_BLENDER_ROOT=$root .venv-5.2/bin/python -m pytest -p no:cacheprovider tests/gui "$@" || status=$?
    if [ "$status" -eq 5 ] && [ "$#" -gt 0 ]; then
        echo "no real-application test selected by: $*"
        return 0
    fi
    return "$status"
}

versions() {
    local chosen=${BLENDER:-$SUPPORTED}
    [ "$chosen" != gui ] || return 0
    for version in $chosen; do
        case " $SUPPORTED " in
            *" $version "*) ;;
            *) echo "error: BLENDER=$version is not supported (choose from: $SUPPORTED)" >&2; exit 2 ;;
        esac
    done
    echo "$chosen"
}

case "${1:-}" in
    demo)
        version=${BLENDER:-5.2}
        BLENDER=$version versions >/dev/null || exit 2
        setup "$version"
        ".venv-$version/bin/python" examples/demo_still.py --panels --out out/demo.png
        ;;
    test)
        shift
        chosen=$(versions) || exit 2
        failed=0
        summary=()
        echo "=== lint (ruff check and format, mypy, codespell) ==="
        if lint; then summary+=("lint (ruff check and format, mypy, codespell): clean"); else summary+=("lint (ruff check and format, mypy, codespell): FAILED"); failed=1; fi
        for version in $chosen; do
            echo "=== Blender $version ==="
            start=$SECONDS
            status=0
            setup "$version" || status=$?
            tests_start=$SECONDS
            [ "$status" -ne 0 ] || run_tests "$version" "$@" || status=$?
            result=passed
            [ "$status" -eq 0 ] || { result="FAILED (exit $status)"; failed=1; }
            summary+=("Blender $version: $result; setup $((tests_start - start)) s, tests $((SECONDS - tests_start)) s")
        done
        if [ -z "${BLENDER:-}" ] || [ "${BLENDER:-}" = gui ]; then
            echo "=== the real Blender application (Debian sid's Blender, no OSL, under Xvfb) ==="
            if [ -n "${RELATIVITY_SKIP_GUI:-}" ] && [ "${RELATIVITY_SKIP_GUI}" != 0 ]; then
                summary+=("real Blender application: SKIPPED (RELATIVITY_SKIP_GUI is set)")
            else
                gui_start=$SECONDS
                gui_setup_seconds=0
                status=0
                setup 5.2 && run_gui "$@" || status=$?
                result=passed
                [ "$status" -eq 0 ] || { result="FAILED (exit $status)"; failed=1; }
                summary+=("real Blender application: $result; root and venv $gui_setup_seconds s, tests $((SECONDS - gui_start - gui_setup_seconds)) s")
            fi
        fi
        printf '%s\n' "${summary[@]}"
        exit "$failed"
        ;;
    *)
        echo "usage: $0 demo | test [pytest arguments]   (BLENDER=4.5 or 5.2 picks one version, BLENDER=gui the real-application stage)" >&2
        exit 2
        ;;
esac
