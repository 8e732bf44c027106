# Sourced by peers_check.sh and stand_check.sh (from the repository root): the venv with the
# real tools from PyPI, created once and reused (RESTPOSE_PEERS_VENV, default
# ~/.cache/restpose-peers/venv; versions pinned below), the binary to check (RESTPOSE, default:
# built here with cargo) and example-robot-data's robots directory in the venv (ERD_ROBOTS).
# Exits 1 on a failure, 2 when PyPI is unreachable and the venv does not exist yet.
VENV="${RESTPOSE_PEERS_VENV:-$HOME/.cache/restpose-peers/venv}"
PACKAGES=(mujoco==4.0.0 pin==4.1.0 example-robot-data==6.0.0)

if [[ -z "${RESTPOSE:-}" ]]; then
    cargo build --release --quiet --bin restpose || exit 1
    RESTPOSE="${CARGO_TARGET_DIR:-target}/release/restpose"
fi
RESTPOSE="$(cd "$(dirname "$RESTPOSE")" && pwd)/$(basename "$RESTPOSE")"

if [[ ! -f "$VENV/.complete" ]]; then
    echo "$(basename "$0" .sh): creating $VENV (${PACKAGES[*]})"
    rm -rf "$VENV"
    python3 -m venv "$VENV" || exit 1
    if ! "$VENV/bin/pip" install --quiet --disable-pip-version-check "${PACKAGES[@]}"; then
        rm -rf "$VENV"
        # A skip only when the index cannot be reached; any other install failure fails.
        if python3 -c 'import os, urllib.request
index = os.environ.get("PIP_INDEX_URL", "https://pypi.org/simple").rstrip("/")
urllib.request.urlopen(index + "/pip/", timeout=20)' 2>/dev/null; then
            echo "$(basename "$0" .sh): installing ${PACKAGES[*]} failed although the package index is reachable" >&2
            exit 1
        fi
        echo "$(basename "$0" .sh): cannot install ${PACKAGES[*]}: the package index is unreachable" >&2
        exit 2
    fi
    touch "$VENV/.complete"
fi

ERD_ROBOTS="$("$VENV/bin/python" -c '
import glob, sys
hits = glob.glob(sys.prefix + "/lib/python*/site-packages/cmeel.prefix/share/example-robot-data/robots")
print(hits[0] if hits else "")')"
if [[ -z "$ERD_ROBOTS" ]]; then
    echo "$(basename "$0" .sh): example-robot-data's robots not found in $VENV" >&2
    exit 1
fi
