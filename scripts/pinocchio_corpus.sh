#!/usr/bin/env bash
# The corpus's rest poses checked by Pinocchio (scripts/pinocchio_corpus.py): every URDF of
# example-robot-data hanging from its fixed base, and the legged robots standing on the ground
# with servos about their SRDF standing state, solved by the direct solve (--load-steps 1);
# Pinocchio's forward kinematics, gravity energy and generalized gravity g(q) must agree with
# restpose's link frames, energy and holding torques (stops, servos, contact forces).
#
# Pinocchio and the corpus come from PyPI into the venv that scripts/peers_check.sh uses
# (created once and reused: RESTPOSE_PEERS_VENV, default ~/.cache/restpose-peers/venv; the
# same pinned versions). RESTPOSE: the binary (default: built here with cargo).
# Exits 0 when every pose agrees with Pinocchio, 1 on a disagreement, 2 when PyPI is
# unreachable and the venv does not exist yet (nothing could be checked). A warm run takes
# about 30 s.
set -uo pipefail
cd "$(dirname "$0")/.."

VENV="${RESTPOSE_PEERS_VENV:-$HOME/.cache/restpose-peers/venv}"
PACKAGES=(mujoco==4.0.0 pin==4.1.0 example-robot-data==6.0.0)

if [[ -z "${RESTPOSE:-}" ]]; then
    cargo build --release --quiet --bin restpose || exit 1
    RESTPOSE="${CARGO_TARGET_DIR:-target}/release/restpose"
fi
RESTPOSE="$(cd "$(dirname "$RESTPOSE")" && pwd)/$(basename "$RESTPOSE")"

if [[ ! -f "$VENV/.complete" ]]; then
    echo "pinocchio corpus: creating $VENV (${PACKAGES[*]})"
    rm -rf "$VENV"
    python3 -m venv "$VENV" || exit 1
    if ! "$VENV/bin/pip" install --quiet --disable-pip-version-check "${PACKAGES[@]}"; then
        rm -rf "$VENV"
        # A skip only when the index cannot be reached; any other install failure fails.
        if python3 -c 'import os, urllib.request
index = os.environ.get("PIP_INDEX_URL", "https://pypi.org/simple").rstrip("/")
urllib.request.urlopen(index + "/pip/", timeout=20)' 2>/dev/null; then
            echo "pinocchio corpus: installing ${PACKAGES[*]} failed although the package index is reachable" >&2
            exit 1
        fi
        echo "pinocchio corpus: cannot install ${PACKAGES[*]}: the package index is unreachable" >&2
        exit 2
    fi
    touch "$VENV/.complete"
fi

ERD_ROBOTS="$("$VENV/bin/python" -c '
import glob, sys
hits = glob.glob(sys.prefix + "/lib/python*/site-packages/cmeel.prefix/share/example-robot-data/robots")
print(hits[0] if hits else "")')"
if [[ -z "$ERD_ROBOTS" ]]; then
    echo "pinocchio corpus: example-robot-data's robots not found in $VENV" >&2
    exit 1
fi
RESTPOSE="$RESTPOSE" ERD_ROBOTS="$ERD_ROBOTS" "$VENV/bin/python" scripts/pinocchio_corpus.py
