#!/usr/bin/env bash
# equal_error.sh — the path tracer against Blender Cycles at equal error, side by side in one run
# (issue 19, part 1). Renders the Cornell box (../shared/testdata/cornell/cornell_box.gltf,
# 256x256) with Cycles (tests/cycles/cornell_cycles.py: Lambertian materials, 64 bounces, box
# filter, no denoising, no adaptive sampling) and with `sy render -b pathtracer --filter none
# --params specular=0` (the reference's materials are Lambertian), both at the same samples per
# pixel, alternately RUNS times, and measures each image's relMSE against the independent 4096-spp
# Cycles reference (cornell_box_cycles_256_4096.exr; tests/exr_error: mean of (x - y)^2 / (y^2 +
# 0.01)). Times are each renderer's own: Cycles' "Time:" line (scene sync, BVH and sampling; not
# Blender's start-up or the file save) and sy render's render time (scene translation and sampling).
#
# An unbiased estimator's relMSE falls as 1 / time, so time x relMSE is a renderer's cost of one
# unit of quality; their quotient (Cycles' over ours) is how many times faster the path tracer
# reaches the same error. Each run prints both and the quotient; the last line the median, min and
# max over the runs.
#
# With MODEL (a glTF sample under ../shared/testdata/gltf, e.g. DamagedHelmet or ToyCar: textured,
# glossy, not a box of Lambertian walls), the scene is that model at 256x192 under a uniform white
# environment the camera does not see (--env-color 1,1,1 --env-hidden), 8 bounces, its own camera;
# Cycles renders it through Blender's own glTF importer from the same view
# (tests/cycles/materials_cycles.py). The importer's materials are not exactly ours, so each
# renderer's error is measured against its own reference at REF_SPP (default 4096, rendered once
# into OUT_DIR and reused): time x relMSE is then each renderer's cost of its own converged image's
# quality, and the quotient the speed-up at equal error. The references' own noise adds about
# SPP / REF_SPP of the measured relMSE to both.
#
# A measurement, not a test: it needs Blender (Debian's `blender` package) and skips without it.
# Usage: tests/cycles/equal_error.sh [BUILD_DIR (build)] [OUT_DIR (equal-error)] [SPP (128)] [RUNS (3)] [MODEL]
#        (environment: REF_SPP, the references' samples in MODEL mode)
set -euo pipefail
. "$(dirname "$0")/../support/measure.sh" # root, build, skip_without_blender, skip_without
out=${2:-equal-error}
spp=${3:-128}
runs=${4:-3}
model=${5:-}
ref_spp=${REF_SPP:-4096}
data=$root/../shared/testdata/cornell
gltf=$data/cornell_box.gltf
ref=$data/cornell_box_cycles_256_4096.exr
if [ -n "$model" ]; then
    gltf=$(ls "$root/../shared/testdata/gltf/$model"/glTF/*.gltf 2>/dev/null | head -1 || true)
    [ -n "$gltf" ] || gltf=$root/../shared/testdata/gltf/$model/glTF/$model.gltf
    ref=$gltf # present when the model is; the references are made below
fi
skip_without_blender
skip_without "$gltf" "$ref"
need_sy_tools # sy, err
mkdir -p "$out"

if [ -n "$model" ]; then
    world=(--env-color 1,1,1 --env-hidden)
    sy_model() { # SPP SEED OUT.exr LOG: prints the render's seconds
        "$sy" render "$gltf" -b pathtracer -w 256 -h 192 --spp "$1" --seed "$2" --filter none "${world[@]}" -o "$3" \
            >"$4" 2>&1 || { echo "equal_error.sh: error: sy render failed, see $4" >&2; exit 1; }
        sed -n 's/.* samples per pixel, \([0-9.]*\) s .*/\1/p' "$4" | head -1
    }
    cycles_model() { # SPP SEED OUT.exr LOG: prints the render's seconds
        blender -b -noaudio --factory-startup -P "$root/tests/cycles/materials_cycles.py" -- --gltf "$gltf" \
            --like "$out/ref_sy.exr" --spp "$1" --bounces 8 --env 1,1,1 --seed "$2" --out "$3" --sy "$sy" >"$4" 2>&1 ||
            { echo "equal_error.sh: error: Blender failed, see $4" >&2; exit 1; }
        sed -n 's/^ *Time: \([0-9]*\):\([0-9.]*\).*/\1 \2/p' "$4" | tail -1 | awk '{ printf "%.3f", $1 * 60 + $2 }'
    }
    echo "$model 256x192, $spp spp, white environment, 8 bounces, $(nproc) threads; each against its own $ref_spp-spp reference"
    equal_error_own_refs "$spp" "$spp" "$ref_spp" "$runs" "$out" cycles_model sy_model
    exit 0
fi

cycles() { # cycles RUN: prints the render's seconds
    local log=$out/cycles_$1.log
    # seeds 1.. : the reference was rendered with seed 0, whose first samples it shares
    blender -b -noaudio --factory-startup -P "$root/tests/cycles/cornell_cycles.py" -- --gltf "$gltf" \
        --size 256 --spp "$spp" --bounces 64 --seed "$1" --out "$out/cycles_$1.exr" >"$log" 2>&1 ||
        { echo "equal_error.sh: error: Blender failed, see $log" >&2; exit 1; }
    # " Time: 00:06.12 (Saving: 00:00.01)": minutes and seconds
    sed -n 's/^ *Time: \([0-9]*\):\([0-9.]*\).*/\1 \2/p' "$log" | tail -1 | awk '{ printf "%.3f", $1 * 60 + $2 }'
}
ours() { # ours RUN: prints the render's seconds
    local log=$out/sy_$1.log
    "$sy" render "$gltf" -b pathtracer -w 256 -h 256 --spp "$spp" --seed "$1" --filter none --params specular=0 \
        -o "$out/sy_$1.exr" >"$log" 2>&1 || { echo "equal_error.sh: error: sy render failed, see $log" >&2; exit 1; }
    # "OUT.exr: 256x256, pathtracer, 128 samples per pixel, 4.647 s (27.55 samples/s)"
    sed -n 's/.* samples per pixel, \([0-9.]*\) s .*/\1/p' "$log" | head -1
}
relmse() { "$err" "$1" "$ref" | awk '{ print $2 }'; }

echo "Cornell box 256x256, $spp spp, $(nproc) threads, relMSE against $(basename "$ref")"
printf '%4s  %9s %10s %10s  %9s %10s %10s  %8s  %s\n' run "Cycles s" relMSE "s x relMSE" "sy s" relMSE \
    "s x relMSE" "speed-up" "sy time to Cycles' error"
ratios=()
for run in $(seq 1 "$runs"); do
    tc=$(cycles "$run")
    ts=$(ours "$run")
    ec=$(relmse "$out/cycles_$run.exr")
    es=$(relmse "$out/sy_$run.exr")
    line=$(awk -v r="$run" -v tc="$tc" -v ec="$ec" -v ts="$ts" -v es="$es" 'BEGIN {
        printf "%4d  %9.2f %10.3e %10.3e  %9.2f %10.3e %10.3e  %7.2fx  %.2f s\n", r, tc, ec, tc * ec, ts, es, ts * es,
               (tc * ec) / (ts * es), ts * es / ec }')
    echo "$line"
    ratios+=("$(echo "$line" | awk '{ sub("x", "", $8); print $8 }')")
done
printf '%s\n' "${ratios[@]}" | sort -g | awk '{ v[NR] = $1 } END {
    m = NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2
    printf "equal-error speed-up over Cycles: median %.2fx (min %.2fx, max %.2fx) over %d runs\n", m, v[1], v[NR], NR }'
