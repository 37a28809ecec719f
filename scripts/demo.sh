#!/usr/bin/env bash
# The main job on the built-in simulator: installs what is needed, builds
# `bsls`, calibrates both sides from simulated calibration sessions, renders
# both sides of the simulated face (capture), decodes them into labelled
# junctions and lines (decode), reconstructs and joins them into one surface
# in millimetres (reconstruct) and measures it, writing files a person can
# open into OUT_DIR (default out/demo):
#   calibration_{left,right}/        the simulated calibration sessions (PNGs, session.yaml)
#   calibration_{left,right}.yaml    the calibrations (bsls calibrate)
#   face_{left,right}.png            the simulated camera frames
#   face_{left,right}_truth.json     their exact ground truth
#   face_{left,right}_junctions.json labelled junctions and lines (contracts 5)
#   face_{left,right}_overlay.png    the frames with each line coloured by p
#   face_{left,right}.ply            each side's surface (world mm, binary PLY)
#   face.ply, face.stl               both sides joined (open in MeshLab, ParaView, a slicer...)
#   face_report.json                 per-side figures and the seam error of the join
#   face_measurements.json           heights and a distance on the face, with uncertainties
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-out/demo}

bash scripts/install-deps.sh
cmake -S . -B build/release -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
cmake --build build/release -j "$(nproc)" --target bsls
bsls=build/release/clients/cli/bsls

mkdir -p "$out"
for side in left right; do
  rm -rf "$out/calibration_${side}"
  "$bsls" simulate-calibration --side "$side" --noise 2 -o "$out/calibration_${side}"
  "$bsls" calibrate "$out/calibration_${side}/session.yaml" -o "$out/calibration_${side}.yaml"
  "$bsls" simulate --surface face --side "$side" --noise 3 \
    -o "$out/face_${side}.png" --truth "$out/face_${side}_truth.json"
  "$bsls" process "$out/face_${side}.png" --side "$side" \
    --calibration "$out/calibration_${side}.yaml" --surface "$out/face_${side}.ply" \
    --junctions "$out/face_${side}_junctions.json" --overlay "$out/face_${side}_overlay.png"
  "$bsls" evaluate "$out/face_${side}_junctions.json" "$out/face_${side}_truth.json"
done
"$bsls" reconstruct --left "$out/face_left.png" --right "$out/face_right.png" \
  --calibration-left "$out/calibration_left.yaml" \
  --calibration-right "$out/calibration_right.yaml" \
  -o "$out/face.ply" --report "$out/face_report.json"
"$bsls" reconstruct --left "$out/face_left.png" --right "$out/face_right.png" \
  --calibration-left "$out/calibration_left.yaml" \
  --calibration-right "$out/calibration_right.yaml" -o "$out/face.stl" >/dev/null
# World frame: the calibration target's square (0, 0); the simulated target
# sits centred under the rig, so the face's midline is near x = 22.75 mm.
"$bsls" measure "$out/face.ply" --height "22.75,-22.75" --height "0,0" \
  --distance "0,-20 45,-20" --json "$out/face_measurements.json"
echo "demo: results in $out"
