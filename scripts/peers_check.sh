#!/usr/bin/env bash
# restpose's pose files checked by the real tools (scripts/peers_check.py): MuJoCo loads the
# URDF + keyframe and Pinocchio builds the URDF, and both put every link where restpose put it
# (1e-9); Pinocchio reads the SRDF named state back to `q_pinocchio`.
#
# The tools come from PyPI into a venv that is created once and reused:
# RESTPOSE_PEERS_VENV (default ~/.cache/restpose-peers/venv). Versions are pinned below.
# RESTPOSE: the binary (default: built here with cargo).
# Exits 0 when every check passes, 1 on a failure, 2 when PyPI is unreachable and the venv
# does not exist yet (nothing could be checked).
set -uo pipefail
cd "$(dirname "$0")/.."

source scripts/peers_venv.sh
RESTPOSE="$RESTPOSE" ERD_ROBOTS="$ERD_ROBOTS" "$VENV/bin/python" scripts/peers_check.py
