#!/usr/bin/env bash
# Remakes tests/fuzz/corpus from the simulator: a short simulated run (dlslot-run on the
# intersection scenario, inside a private network namespace) gives the message seeds
# (make_seeds) and the file seeds (the head of each simulated file, a 4-point scan, the shipped
# config). Needs a normal build (build/) and make_seeds from the fuzz build (build-fuzz/).
#   tests/fuzz/make_corpus.sh
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
C=$ROOT/tests/fuzz/corpus
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$ROOT/scripts/launch" dlslot-run --scenario intersection --frames 6 --out "$work/run" --no-render --quiet >/dev/null
rm -rf "$C"
for t in point_cloud_t detections_t ground_truth_t odometry_t associations_t slot_state_t process_status_t run_event_t map_state_t; do
  mkdir -p "$C/fuzz_msg_$t"
done
for r in labels csv_detections poses oxts calib times velodyne config tum run_log; do mkdir -p "$C/fuzz_file_$r"; done
"${MAKE_SEEDS:-$ROOT/build-fuzz/bin/make_seeds}" "$work/run/run.lcmlog" "$C"
d=$work/run/data
head -n 4 "$d/training/label_02/0000.txt" > "$C/fuzz_file_labels/sim-labels.txt"
head -n 4 "$d/detections/sim/0000.txt" > "$C/fuzz_file_labels/sim-detections.txt"
printf '0,2,560.1,170.2,600.4,200.9,0.93,1.52,1.63,3.88,2.10,1.65,13.4,-1.57,-1.72\n' > "$C/fuzz_file_csv_detections/row.csv"
head -n 3 "$d/training/poses/0000.txt" > "$C/fuzz_file_poses/sim-poses.txt"
head -n 2 "$d/training/oxts/0000.txt" > "$C/fuzz_file_oxts/sim-oxts.txt"
cp "$d/training/calib/0000.txt" "$C/fuzz_file_calib/sim-calib.txt"
head -c 64 "$d/training/velodyne/0000/000000.bin" > "$C/fuzz_file_velodyne/sim-4-points.bin"
printf '0.000000\n0.103760\n0.207520\n' > "$C/fuzz_file_times/times.txt"
# The shipped config without its comments (6 KB of the 20 KB; the same YAML): yaml-cpp scans every
# comment byte, so the full file made each execution 2x slower for no coverage.
sed -e 's/[[:space:]]*#.*$//' -e '/^[[:space:]]*$/d' "$ROOT/config/dlslot.yaml" > "$C/fuzz_file_config/dlslot.yaml"
head -n 3 "$work/run/trajectory_slot_tum.txt" > "$C/fuzz_file_tum/sim-slot.txt"
du -sh "$C"
# A few lines of the shared real data, where present: real KITTI labels (with DontCare rows),
# PointRCNN detections (CSV) and calibration.
R=$ROOT/../shared/data/kitti-tracking-0000-head
if [[ -d $R ]]; then
  head -n 4 "$R/training/label_02/0000.txt" > "$C/fuzz_file_labels/kitti-labels.txt"
  head -n 2 "$R/detections/pointrcnn_Car/0000.txt" > "$C/fuzz_file_csv_detections/kitti-pointrcnn.csv"
  cp "$R/training/calib/0000.txt" "$C/fuzz_file_calib/kitti-calib.txt"
fi
