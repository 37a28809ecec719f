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
# Then the same through the services, as a clinic runs it: the
# capture daemon bslsd on its simulated framestore and one processing service
# bsls-processd on this machine, driven by the Python automation example
# (clients/python/examples/scripted_session.py), which grabs both sides,
# waits for the reconstruction and writes into OUT_DIR/session/:
#   surface.ply, left.ply, right.ply the joined and per-side surfaces
#   report.json, record.json         the session report; the sealed record (frames,
#                                    calibrations, every file by SHA-256, versions)
#   measurements.json/.txt           heights and a distance measured by the service
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-out/demo}

bash scripts/install-deps.sh
cmake -S . -B build/release -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
cmake --build build/release -j "$(nproc)" --target bsls bslsd bsls-processd bsls_python_stubs
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

# The services: one processing replica and the daemon, on sockets in $run.
run=$(mktemp -d)
calibrations=$(cd "$out" && pwd)
session="$out/session"
rm -rf "$session"
cleanup() {
  kill "${daemon_pid:-}" "${processd_pid:-}" 2>/dev/null || true
  wait 2>/dev/null || true
  rm -rf "$run"
}
trap cleanup EXIT
build/release/processing/processd/bsls-processd --socket "$run/processd.sock" \
  --set "scratch_dir=$run" --replica demo 2>"$run/processd.log" &
processd_pid=$!
cat >"$run/bslsd.yaml" <<EOF
store:
  root: $run/store
listen:
  unix_socket: $run/bslsd.sock
roles:
  admin: [$(id -un)]
slides:
  backend: simulated
processing:
  server: unix:$run/processd.sock
  calibration_left: $calibrations/calibration_left.yaml
  calibration_right: $calibrations/calibration_right.yaml
log_level: warn
# The demo's own account: started as root, bslsd would switch to user bsls.
user: "$(id -u):$(id -g)"
EOF
build/release/daemon/bslsd/bslsd --config "$run/bslsd.yaml" 2>"$run/bslsd.log" &
daemon_pid=$!
for _ in $(seq 300); do
  [ -S "$run/bslsd.sock" ] && [ -S "$run/processd.sock" ] && break
  kill -0 "$daemon_pid" "$processd_pid" 2>/dev/null || break
  sleep 0.1
done
PYTHONPATH=build/release/clients/python/stubs:clients/python \
  /usr/bin/python3 clients/python/examples/scripted_session.py --socket "$run/bslsd.sock" \
  --session demo --patient DEMO-0001 --out "$session" --processd "unix:$run/processd.sock" ||
  { cat "$run/bslsd.log" "$run/processd.log" >&2; exit 1; }
echo "demo: results in $out (the services' run in $session)"
