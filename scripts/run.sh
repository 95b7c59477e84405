#!/usr/bin/env bash
# ./dlslot run: the whole pipeline on one sequence. Inside a private network namespace unless
# --lcm-url is given (then on that network: a live or multi-machine set-up).
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BIN=${DLSLOT_BUILD_DIR:-$ROOT/build}/bin
args=("$@")
[[ " $* " == *" --config "* ]] || args+=(--config "$ROOT/config/dlslot.yaml")
if [[ " $* " == *" --lcm-url "* ]]; then
  exec "$BIN/dlslot-run" "${args[@]}"
fi
exec "$ROOT/scripts/netns-run" -- "$BIN/dlslot-run" "${args[@]}"
