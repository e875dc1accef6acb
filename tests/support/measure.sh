# measure.sh — the start of the measurement scripts outside ctest (tests/cycles, tests/look;
# sourced, bash): `root`, the checkout; `skip_without_blender [PACKAGES]` and
# `skip_without PATH...` end the script with status 0 and the reason ("NAME: skipped: ...", NAME the
# script's file name) when Blender (Debian's PACKAGES, default blender) or one of the paths (the
# shared test data) is absent: a measurement that cannot run says why and is not a failure.
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
skip_without_blender() {
    command -v blender >/dev/null 2>&1 && return 0
    echo "$(basename "$0"): skipped: Blender is not installed (apt-get install ${*:-blender})"
    exit 0
}
skip_without() {
    local p
    for p in "$@"; do
        [ -e "$p" ] || { echo "$(basename "$0"): skipped: $p is absent"; exit 0; }
    done
}
