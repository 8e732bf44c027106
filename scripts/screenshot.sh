#!/usr/bin/env bash
# Renders a restpose recording to a PNG with the rerun viewer, headless (no display needed).
#
#   scripts/screenshot.sh robots/slider_crank.urdf docs/slider_crank.png
#   scripts/screenshot.sh robots/solo12/solo12_ground.urdf docs/solo12_ground.png --floating-base --friction stick
#
# Options after the two paths are passed to `restpose analyze`.
#
# Sets up what it needs: the viewer matching the SDK (`pip install rerun-sdk==0.36.3`) and a
# software Vulkan driver (`apt-get install mesa-vulkan-drivers`), then builds restpose with the
# `viewer` feature, solves the mechanism into a recording and renders it.
set -euo pipefail
cd "$(dirname "$0")/.."
urdf=${1:?usage: scripts/screenshot.sh ROBOT.urdf OUT.png [ANALYZE OPTIONS...]}
png=${2:?usage: scripts/screenshot.sh ROBOT.urdf OUT.png [ANALYZE OPTIONS...]}
shift 2
if ! python3 -c 'import rerun, sys; sys.exit(rerun.__version__ != "0.36.3")' 2>/dev/null; then
  pip install -q rerun-sdk==0.36.3
fi
if ! dpkg -s mesa-vulkan-drivers >/dev/null 2>&1; then
  apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq mesa-vulkan-drivers
fi
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$HOME/.cache/restpose-target}"
cargo build --release --features viewer -q
rrd="$(mktemp -d)/$(basename "${urdf%.urdf}").rrd"
"$CARGO_TARGET_DIR/release/restpose" analyze "$urdf" --rrd "$rrd" -q "$@"
mkdir -p "$(dirname "$png")"
# The headless viewer wants a runtime dir, and a window size (its default can exceed the GPU's
# largest buffer with the software renderer).
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-$(mktemp -d)}"
rerun --headless --window-size 1280x720 --screenshot-to "$png" --renderer vulkan "$rrd"
echo "wrote $png"
