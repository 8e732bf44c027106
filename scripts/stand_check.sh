#!/usr/bin/env bash
# Will it stand? example-robot-data's quadrupeds (solo12, anymal b and c, hyq, go1, a1) in their
# SRDF `standing` state on a level floor and on slopes of 0.1, 0.2, 0.3 rad: restpose's
# `required_mu` and stability margin checked against Pinocchio's centre of mass and mass, a
# support polygon computed in the script, and tan(alpha) where the robot is rigid
# (scripts/stand_check.py says how). Arguments: robot names to run only those.
#
# The tools come from PyPI into the venv of scripts/peers_venv.sh (shared with peers_check.sh).
# Exits 0 when every check passes, 1 on a failure, 2 when PyPI is unreachable and the venv
# does not exist yet (nothing could be checked).
set -uo pipefail
cd "$(dirname "$0")/.."

source scripts/peers_venv.sh
RESTPOSE="$RESTPOSE" ERD_ROBOTS="$ERD_ROBOTS" "$VENV/bin/python" scripts/stand_check.py "$@"
