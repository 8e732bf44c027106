# Sourced by peers_check.sh, stand_check.sh, pinocchio_corpus.sh, pybullet_corpus.sh and
# wheels_corpus.sh (from
# the repository root): the venv with the real tools from PyPI, created once and reused
# (RESTPOSE_PEERS_VENV, default ~/.cache/restpose-peers/venv; versions pinned below), the binary
# to check (RESTPOSE, default: built here with cargo), example-robot-data's robots directory in
# the venv (ERD_ROBOTS) and pybullet's data directory (PYBULLET_DATA).
# Exits 1 on a failure, 2 when PyPI is unreachable and the venv does not exist yet.
VENV="${RESTPOSE_PEERS_VENV:-$HOME/.cache/restpose-peers/venv}"
# pybullet only for its data (pybullet_data/: scripts/pybullet_corpus.sh); a wheel, never a
# build from source. rtb-data (the Robotics Toolbox's robot descriptions), ROS's xacro,
# pycollada, icub-models and gym-ignition-models for scripts/wheels_corpus.sh.
PACKAGES=(mujoco==4.0.0 pin==4.1.0 example-robot-data==6.0.0 pybullet==3.2.7 rtb-data==2.0.0
          xacro==2.1.1 pycollada==0.9.3 icub-models==3.2.0 gym-ignition-models==1.1.1)

if [[ -z "${RESTPOSE:-}" ]]; then
    cargo build --release --quiet --bin restpose || exit 1
    RESTPOSE="${CARGO_TARGET_DIR:-target}/release/restpose"
fi
RESTPOSE="$(cd "$(dirname "$RESTPOSE")" && pwd)/$(basename "$RESTPOSE")"

# `.complete` names the package set the venv holds: a venv made for another set (an older
# checkout's, whose marker is empty) is brought to this one in place by pip.
if [[ "$(cat "$VENV/.complete" 2>/dev/null)" != "${PACKAGES[*]}" ]]; then
    fresh=0
    if [[ ! -x "$VENV/bin/pip" ]]; then
        fresh=1
        echo "$(basename "$0" .sh): creating $VENV (${PACKAGES[*]})"
        rm -rf "$VENV"
        python3 -m venv "$VENV" || exit 1
    else
        echo "$(basename "$0" .sh): updating $VENV to ${PACKAGES[*]}"
    fi
    if ! "$VENV/bin/pip" install --quiet --disable-pip-version-check --only-binary=pybullet \
        "${PACKAGES[@]}"; then
        [[ $fresh -eq 1 ]] && rm -rf "$VENV"
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
    echo "${PACKAGES[*]}" > "$VENV/.complete"
fi

ERD_ROBOTS="$("$VENV/bin/python" -c '
import glob, sys
hits = glob.glob(sys.prefix + "/lib/python*/site-packages/cmeel.prefix/share/example-robot-data/robots")
print(hits[0] if hits else "")')"
if [[ -z "$ERD_ROBOTS" ]]; then
    echo "$(basename "$0" .sh): example-robot-data's robots not found in $VENV" >&2
    exit 1
fi
PYBULLET_DATA="$("$VENV/bin/python" -c 'import pybullet_data; print(pybullet_data.getDataPath())' 2>/dev/null)"
if [[ ! -d "$PYBULLET_DATA" ]]; then
    echo "$(basename "$0" .sh): pybullet_data not found in $VENV" >&2
    exit 1
fi
