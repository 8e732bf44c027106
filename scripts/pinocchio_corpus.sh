#!/usr/bin/env bash
# The corpus's rest poses checked by Pinocchio (scripts/pinocchio_corpus.py): every URDF of
# example-robot-data hanging from its fixed base, and the legged robots standing on the ground
# with servos about their SRDF standing state, solved by the direct solve (--load-steps 1);
# Pinocchio's forward kinematics, gravity energy and generalized gravity g(q) must agree with
# restpose's link frames, energy and holding torques (stops, servos, contact forces).
#
# Pinocchio and the corpus come from PyPI into the venv of scripts/peers_venv.sh (shared with
# peers_check.sh: created once and reused, RESTPOSE_PEERS_VENV, default
# ~/.cache/restpose-peers/venv; pinned versions). RESTPOSE: the binary (default: built here
# with cargo). pybullet_data's robots: scripts/pybullet_corpus.sh.
# Exits 0 when every pose agrees with Pinocchio, 1 on a disagreement, 2 when PyPI is
# unreachable and the venv does not exist yet (nothing could be checked). A warm run takes
# about 30 s.
set -uo pipefail
cd "$(dirname "$0")/.."

source scripts/peers_venv.sh
RESTPOSE="$RESTPOSE" ERD_ROBOTS="$ERD_ROBOTS" "$VENV/bin/python" scripts/pinocchio_corpus.py
