# measure.sh — the start of the measurement scripts outside ctest (tests/cycles, tests/look;
# sourced, bash; their first argument is BUILD_DIR): `root`, the checkout; `build`, the build folder
# (absolute; BUILD_DIR, default root/build; the script ends with status 1 when it is not a folder);
# `skip_without_blender [PACKAGES]` and
# `skip_without PATH...` end the script with status 0 and the reason ("NAME: skipped: ...", NAME the
# script's file name) when Blender (Debian's PACKAGES, default blender) or one of the paths (the
# shared test data) is absent: a measurement that cannot run says why and is not a failure.
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
build=$(cd "${1:-$root/build}" 2>/dev/null && pwd) || { echo "$(basename "$0"): no build folder ${1:-$root/build}" >&2; exit 1; }
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
