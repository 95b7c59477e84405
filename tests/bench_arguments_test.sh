#!/usr/bin/env bash
# ./dlslot bench refuses arguments it cannot honour before it installs or builds anything: exit 2
# and a message naming the argument. (Its pipeline runs take minutes and are not run here.)
#   tests/bench_arguments_test.sh
set -uo pipefail
dlslot=$(cd "$(dirname "$0")/.." && pwd)/dlslot
failed=0
expect() {  # expect 'WHAT THE MESSAGE NAMES' ARGS...
  local want=$1 out rc
  shift
  out=$("$dlslot" bench "$@" 2>&1)
  rc=$?
  if [[ $rc -ne 2 || $out != *"$want"* ]]; then
    echo "bench $*: expected exit 2 and a message with '$want', got exit $rc: $out" >&2
    failed=$((failed + 1))
  fi
}
expect "--runs 0: expected a whole number >= 1" --pipeline --runs 0
expect "--runs 2x: expected a whole number >= 1" --pipeline --runs 2x
expect "--against and --record exclude each other" --pipeline --against HEAD --record why
expect "--against no-such-revision: not a revision of this repository" --pipeline --against no-such-revision
echo "bench arguments test: $((4 - failed)) passed, $failed failed"
[[ $failed -eq 0 ]]
