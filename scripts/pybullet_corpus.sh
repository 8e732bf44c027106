#!/usr/bin/env bash
# pybullet_data's robots (the data of the PyPI wheel pybullet 3.2.7) checked by Pinocchio
# (scripts/pybullet_corpus.py): every URDF hanging from its fixed base and a sample of the
# 1,000 random objects, the legged robots standing on the ground with servos, and minitaur
# with its knee loops closed, by the direct solve (--load-steps 1); forward kinematics, gravity
# energy and g(q) against the stops', servos', contacts' and loops' forces. Files that restpose
# or urdfdom refuse are listed in the script with the reason.
#
# The tools and the data come from PyPI into the venv of scripts/peers_venv.sh (shared with
# peers_check.sh and pinocchio_corpus.sh). RESTPOSE: the binary (default: built here with
# cargo). Exits 0 when every pose agrees with Pinocchio, 1 on a disagreement, a crash or a
# refusal other than the listed ones, 2 when PyPI is unreachable and the venv does not exist
# yet (nothing could be checked). A warm run takes about 10 s.
set -uo pipefail
cd "$(dirname "$0")/.."

source scripts/peers_venv.sh
RESTPOSE="$RESTPOSE" ERD_ROBOTS="$ERD_ROBOTS" PYBULLET_DATA="$PYBULLET_DATA" \
    "$VENV/bin/python" scripts/pybullet_corpus.py
