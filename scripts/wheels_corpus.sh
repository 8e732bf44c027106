#!/usr/bin/env bash
# Robot descriptions published as PyPI wheels beyond example-robot-data and pybullet_data
# (scripts/wheels_corpus.py), hanging from their fixed base by the direct solve
# (--load-steps 1): rtb-data 2.0.0 (the Robotics Toolbox for Python's KUKA, ABB, Interbotix,
# Franka, xArm, Puma, … as URDF and xacro, masses from geometry where a link has none: each
# xacro file expanded by restpose and by ROS's Python xacro must give the same rest),
# icub-models 3.2.0 (16 iCub variants) and gym-ignition-models 1.1.1; every rest is checked
# by Pinocchio, with masses computed independently from the same meshes where they come from
# geometry.
#
# The tools and the data come from PyPI into the venv of scripts/peers_venv.sh (shared with
# peers_check.sh and the other corpora). RESTPOSE: the binary (default: built here with cargo).
# Exits 0 when every check passes, 1 on a disagreement or a crash, 2 when PyPI is unreachable
# and the venv does not exist yet (nothing could be checked). A warm run takes about 25 s.
set -uo pipefail
cd "$(dirname "$0")/.."

source scripts/peers_venv.sh
RTB_DATA="$("$VENV/bin/python" -c 'import os, rtbdata; print(os.path.dirname(rtbdata.__file__))')"
GYM_IGNITION_MODELS="$("$VENV/bin/python" -c 'import os, gym_ignition_models as g; print(os.path.dirname(g.__file__))')"
RESTPOSE="$RESTPOSE" ERD_ROBOTS="$ERD_ROBOTS" RTB_DATA="$RTB_DATA" ICUB_MODELS="$VENV/share/iCub" \
    GYM_IGNITION_MODELS="$GYM_IGNITION_MODELS" PYTHONPATH=scripts "$VENV/bin/python" scripts/wheels_corpus.py
