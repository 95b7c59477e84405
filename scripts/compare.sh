#!/usr/bin/env bash
# ./dlslot compare: the four modes on one sequence, Table I and II. Private network namespace
# unless --lcm-url is given.
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BIN=${DLSLOT_BUILD_DIR:-$ROOT/build}/bin
args=("$@")
[[ " $* " == *" --config "* ]] || args+=(--config "$ROOT/config/dlslot.yaml")
if [[ " $* " == *" --lcm-url "* ]]; then
  exec "$BIN/dlslot-compare" "${args[@]}"
fi
exec "$ROOT/scripts/netns-run" -- "$BIN/dlslot-compare" "${args[@]}"
