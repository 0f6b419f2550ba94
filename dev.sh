#!/usr/bin/env bash
# Development entry point.
#   ./dev.sh demo   set up .venv, render the demo still to out/demo.png
#   ./dev.sh test   set up .venv, run the whole test suite (extra arguments go to pytest)
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")"

VENV=.venv
PYTHON=${PYTHON:-python3.11}
STAMP=$VENV/.requirements.sha256

setup() {
    if [ ! -x "$VENV/bin/python" ]; then
        echo "creating $VENV with $PYTHON"
        "$PYTHON" -m venv "$VENV"
    fi
    local want
    want=$(sha256sum requirements.txt | cut -d' ' -f1)
    if [ -f "$STAMP" ] && [ "$(cat "$STAMP")" = "$want" ]; then
        echo "$VENV is up to date with requirements.txt"
    else
        echo "installing requirements.txt into $VENV (the bpy wheel is about 400 MB)"
        "$VENV/bin/python" -m pip install --disable-pip-version-check -r requirements.txt
        echo "$want" > "$STAMP"
    fi
}

run_tests() {
    local status=0
    "$VENV/bin/python" -m pytest -n 2 tests "$@" || status=$?
    if [ "$status" -eq 5 ]; then
        echo "error: pytest collected no tests" >&2
        return 1
    fi
    return "$status"
}

case "${1:-}" in
    demo)
        setup
        "$VENV/bin/python" examples/demo_still.py --out out/demo.png
        ;;
    test)
        shift
        setup
        run_tests "$@"
        ;;
    *)
        echo "usage: $0 demo | test [pytest arguments]" >&2
        exit 2
        ;;
esac
