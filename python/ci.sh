#!/usr/bin/env bash
# The Python package's CI (called by .ci/run; runnable alone from anywhere):
#   1. clippy on the binding crate (cargo fmt --all in .ci/run covers its formatting);
#   2. a venv with the pinned tools and peers from PyPI (maturin, numpy, pytest, pin,
#      example-robot-data), kept in $RESTPOSE_PY_VENV (default ~/.cache/restpose-python-venv)
#      and reused while its pins are unchanged;
#   3. the abi3 wheel built by maturin, installed into that venv (the `restpose` command too);
#   4. pytest on python/tests (API, errors, the command line, Pinocchio cross-checks).
# Exits 0 with "python SKIPPED" when PyPI is unreachable and no venv is cached; fails if pytest
# runs no test (its exit code 5).
set -euo pipefail
cd "$(dirname "$0")/.."
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$HOME/.cache/restpose-target}"
VENV="${RESTPOSE_PY_VENV:-$HOME/.cache/restpose-python-venv}"
PINS=(maturin==1.16.0 numpy==2.4.6 pytest==9.2.0 pin==4.1.0 example-robot-data==6.0.0)

echo "== clippy (python bindings)"
cargo clippy --release -p restpose-python --all-targets -- -D warnings

echo "== python venv ($VENV)"
if [[ ! -x "$VENV/bin/python" || "$(cat "$VENV/.pins" 2>/dev/null)" != "${PINS[*]}" ]]; then
    rm -rf "$VENV"
    python3 -m venv "$VENV"
    if ! "$VENV/bin/python" -m pip install --quiet --disable-pip-version-check "${PINS[@]}"; then
        rm -rf "$VENV"
        echo "python SKIPPED: PyPI is unreachable, the test tools could not be installed"
        exit 0
    fi
    echo "${PINS[*]}" > "$VENV/.pins"
fi
# shellcheck disable=SC1091
source "$VENV/bin/activate"

echo "== wheel (maturin, abi3)"
wheels="$CARGO_TARGET_DIR/wheels"
rm -rf "$wheels"
maturin build --release --quiet -m python/Cargo.toml -o "$wheels"
wheel=("$wheels"/restpose_urdf-*.whl)
echo "built ${wheel[0]##*/} ($(du -k "${wheel[0]}" | cut -f1) KiB)"
python -m pip install --quiet --disable-pip-version-check --force-reinstall --no-deps "${wheel[0]}"

echo "== pytest (python/tests)"
cd python/tests # not python/: the installed package is tested, not the source folder
rc=0
python -m pytest -q -p no:cacheprovider . || rc=$?
if [[ $rc -eq 5 ]]; then
    echo "python tests FAILED: pytest collected no test" >&2
    exit 1
fi
exit "$rc"
