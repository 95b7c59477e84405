#!/usr/bin/env bash
# `cmake --install` into a temporary prefix, then a short simulated pipeline run by the installed
# dlslot-run from a directory outside the source and build trees: the installed programs must find
# each other, the installed config and the installed scenarios (not the source tree's).
#   tests/install_test.sh BUILD_DIR [--slow]     (run inside scripts/netns-run: the run talks LCM)
# --slow (sanitizer builds): the installed config's lockstep wait is made ten times longer.
set -euo pipefail
build=${1:?usage: install_test.sh BUILD_DIR [--slow]}
slow=${2:-}
prefix=$(mktemp -d /tmp/dlslot-install.XXXXXX)
trap 'rm -rf "$prefix"' EXIT
fail() { echo "install test: $*" >&2; [[ -f $prefix/run.log ]] && tail -30 "$prefix/run.log" >&2; exit 1; }

cmake --install "$build" --prefix "$prefix" >/dev/null
for p in dlslot-run dlslot-player dlslot-detector dlslot-odometry dlslot-tracker dlslot-backend dlslot-renderer \
         dlslot-sim dlslot-eval dlslot-track-eval dlslot-compare; do
  [[ -x $prefix/bin/$p ]] || fail "bin/$p was not installed"
done
[[ -f $prefix/share/dlslot/config/dlslot.yaml ]] || fail "share/dlslot/config/dlslot.yaml was not installed"
[[ -f $prefix/share/dlslot/config/scenarios/intersection.yaml ]] || fail "the scenarios were not installed"
[[ -e $prefix/bin/intersection_test ]] && fail "a test binary was installed"
if [[ $slow == --slow ]]; then
  sed -i 's/lockstep_timeout_s: 5.0/lockstep_timeout_s: 50.0/' "$prefix/share/dlslot/config/dlslot.yaml"
  grep -q "lockstep_timeout_s: 50.0" "$prefix/share/dlslot/config/dlslot.yaml" || fail "no lockstep_timeout_s: 5.0 to lengthen"
fi

cd "$prefix"
"$prefix/bin/dlslot-run" --scenario intersection --frames 20 --out "$prefix/run" --no-render > "$prefix/run.log" 2>&1 \
  || fail "the installed dlslot-run failed"
grep -q "config: $prefix/share/dlslot/config/dlslot.yaml" "$prefix/run.log" || fail "it did not use the installed config"
[[ $(wc -l < "$prefix/run/trajectory_slot_kitti.txt") -eq 20 ]] || fail "trajectory_slot_kitti.txt has not 20 poses"
grep -q '"frames.played": 20' "$prefix/run/metrics.json" || fail "metrics.json does not say 20 frames played"
echo "install test: installed to $prefix, ran 20 frames from there: 1 passed, 0 failed"
