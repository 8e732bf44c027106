#!/usr/bin/env bash
# Every written pose round-trips: example-robot-data's 15 standing robots (those of
# scripts/pinocchio_corpus.sh) written with --write-urdf, --write-joint-states and --json,
# re-analysed in 0 iterations and passed by verify (scripts/round_trip.py says how).
#
# The tools come from PyPI into the venv of scripts/peers_venv.sh (shared with peers_check.sh).
# Exits 0 when every check passes, 1 on a failure, 2 when PyPI is unreachable and the venv
# does not exist yet (nothing could be checked).
set -uo pipefail
cd "$(dirname "$0")/.."

source scripts/peers_venv.sh
RESTPOSE="$RESTPOSE" ERD_ROBOTS="$ERD_ROBOTS" "$VENV/bin/python" scripts/round_trip.py "$@"
