#!/usr/bin/env bash
# The main job on the built-in simulator: installs what is needed, builds
# `bsls`, renders both sides of the simulated face (capture), decodes them
# into labelled junctions and lines (decode) and writes files a person can
# open into OUT_DIR (default out/demo):
#   face_{left,right}.png            the simulated camera frames
#   face_{left,right}_truth.json     their exact ground truth
#   face_{left,right}_junctions.json labelled junctions and lines (contracts 5)
#   face_{left,right}_overlay.png    the frames with each line coloured by p
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-out/demo}

bash scripts/install-deps.sh
cmake -S . -B build/release -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
cmake --build build/release -j "$(nproc)" --target bsls
bsls=build/release/clients/cli/bsls

mkdir -p "$out"
for side in left right; do
  "$bsls" simulate --surface face --side "$side" --noise 3 \
    -o "$out/face_${side}.png" --truth "$out/face_${side}_truth.json"
  "$bsls" process "$out/face_${side}.png" --side "$side" \
    --junctions "$out/face_${side}_junctions.json" --overlay "$out/face_${side}_overlay.png"
  "$bsls" evaluate "$out/face_${side}_junctions.json" "$out/face_${side}_truth.json"
done
echo "demo: results in $out"
