# measure.sh — the start of the measurement scripts outside ctest (tests/cycles, tests/look;
# sourced, bash; their first argument is BUILD_DIR): `root`, the checkout; `build`, the build folder
# (absolute; BUILD_DIR, default root/build; the script ends with status 1 when it is not a folder);
# `need_sy_tools` (sy, err) and `equal_error_own_refs` (below: the comparison with Cycles against each
# renderer's own reference);
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

# need_sy_tools: sets `sy` (BUILD_DIR/apps/sy/sy) and `err` (BUILD_DIR/tests/exr_error); ends the
# script with status 1 when either is missing (not built).
need_sy_tools() {
    sy=$build/apps/sy/sy
    err=$build/tests/exr_error
    local tool
    for tool in "$sy" "$err"; do
        [ -x "$tool" ] || { echo "$(basename "$0"): error: $tool is missing (build first: cmake --build $build)" >&2; exit 1; }
    done
}

# equal_error_own_refs SPP CYCLES_SPP REF_SPP RUNS OUT CYCLES_FN SY_FN: sy against Blender Cycles at
# equal error where each renderer is measured against its own REF_SPP-sample reference
# (OUT/ref_sy.exr first: Cycles takes its view from it; then OUT/ref_cycles.exr; both with seed 0,
# made only when absent), the runs with seeds 1..RUNS so that none shares its reference's samples
# (with one seed for both, sy's error came out about 12 % low at 16 / 256 spp). CYCLES_FN and SY_FN
# are called as FN SPP SEED OUT.exr LOG and print the render's seconds. Prints a row per run (time,
# relMSE, their product; the quotient of the products is the speed-up), the references' mean
# ratio and the median speed-up. Needs `err`, the exr_error tool.
equal_error_own_refs() {
    local spp=$1 cspp=$2 ref_spp=$3 runs=$4 out=$5 cyc=$6 ours=$7 run tc ts ec es line
    [ -s "$out/ref_sy.exr" ] || "$ours" "$ref_spp" 0 "$out/ref_sy.exr" "$out/ref_sy.log" >/dev/null
    [ -s "$out/ref_cycles.exr" ] || "$cyc" "$ref_spp" 0 "$out/ref_cycles.exr" "$out/ref_cycles.log" >/dev/null
    printf '%4s  %9s %10s %10s  %9s %10s %10s  %8s\n' run "Cycles s" relMSE "s x relMSE" "sy s" relMSE "s x relMSE" "speed-up"
    local ratios=()
    for run in $(seq 1 "$runs"); do
        tc=$("$cyc" "$cspp" "$run" "$out/cycles_$run.exr" "$out/cycles_$run.log")
        ts=$("$ours" "$spp" "$run" "$out/sy_$run.exr" "$out/sy_$run.log")
        ec=$("$err" "$out/cycles_$run.exr" "$out/ref_cycles.exr" | awk 'NR == 1 { print $2 }')
        es=$("$err" "$out/sy_$run.exr" "$out/ref_sy.exr" | awk 'NR == 1 { print $2 }')
        line=$(awk -v r="$run" -v tc="$tc" -v ec="$ec" -v ts="$ts" -v es="$es" 'BEGIN {
            printf "%4d  %9.2f %10.3e %10.3e  %9.2f %10.3e %10.3e  %7.2fx\n", r, tc, ec, tc * ec, ts, es, ts * es,
                   (tc * ec) / (ts * es) }')
        echo "$line"
        ratios+=("$(echo "$line" | awk '{ sub("x", "", $8); print $8 }')")
    done
    echo "references: the mean of sy's over Cycles' $("$err" "$out/ref_sy.exr" "$out/ref_cycles.exr" | awk 'NR == 1 { print $8 }')"
    printf '%s\n' "${ratios[@]}" | sort -g | awk '{ v[NR] = $1 } END {
        m = NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2
        printf "equal-error speed-up over Cycles: median %.2fx (min %.2fx, max %.2fx) over %d runs\n", m, v[1], v[NR], NR }'
}
