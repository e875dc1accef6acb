# servers.sh — the start of the cluster's shell tests that run `sy serve` processes (sourced; bash),
# called as `TEST.sh SY WORKDIR [TESTDATA] EXR_EQUAL`: sets SY, W (a fresh, empty work folder), DATA
# (empty without the test data) and EXR_EQUAL; the processes a test starts in the background go
# into the array pids and are killed on exit; `fail MESSAGE` prints it and every log of the run
# ($W/*.log, $W/*.err), then exits 1; wait_until / wait_gone come from ../support/wait.sh (states,
# never sleeps; a hang guard only).
set -u
SY=$1; W=$2; DATA=${3:-}; EXR_EQUAL=${4:?exr_equal}
rm -rf "$W"; mkdir -p "$W"
pids=()
cleanup() { for p in "${pids[@]}"; do kill "$p" 2>/dev/null; done; wait 2>/dev/null; }
trap cleanup EXIT
fail() {
  echo "FAIL: $*" >&2
  for f in "$W"/*.log "$W"/*.err; do [ -f "$f" ] && { echo "--- $f"; cat "$f"; }; done >&2
  exit 1
}
. "$(dirname "${BASH_SOURCE[0]}")/../support/wait.sh"
