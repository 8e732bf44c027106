#!/usr/bin/env bash
# rtb-data's robots (the data of the PyPI wheel rtb-data 2.0.0, the Robotics Toolbox for
# Python's robot descriptions: KUKA, ABB, Interbotix, Franka, xArm, Puma, … as URDF and xacro)
# hanging from their fixed base by the direct solve (--load-steps 1), masses from geometry where
# a link has none (scripts/rtb_corpus.py): each xacro file expanded by restpose and by ROS's
# Python xacro must give the same rest, and every rest is checked by Pinocchio with masses
# computed independently from the same meshes.
#
# The tools and the data come from PyPI into the venv of scripts/peers_venv.sh (shared with
# peers_check.sh and the other corpora). RESTPOSE: the binary (default: built here with cargo).
# Exits 0 when every check passes, 1 on a disagreement or a crash, 2 when PyPI is unreachable
# and the venv does not exist yet (nothing could be checked). A warm run takes about 30 s.
set -uo pipefail
cd "$(dirname "$0")/.."

source scripts/peers_venv.sh
RTB_DATA="$("$VENV/bin/python" -c 'import os, rtbdata; print(os.path.dirname(rtbdata.__file__))')"
GYM_IGNITION_MODELS="$("$VENV/bin/python" -c 'import os, gym_ignition_models as g; print(os.path.dirname(g.__file__))')"
RESTPOSE="$RESTPOSE" ERD_ROBOTS="$ERD_ROBOTS" RTB_DATA="$RTB_DATA" ICUB_MODELS="$VENV/share/iCub" \
    GYM_IGNITION_MODELS="$GYM_IGNITION_MODELS" PYTHONPATH=scripts "$VENV/bin/python" scripts/rtb_corpus.py
