#!/usr/bin/env bash
# lights_equal_error.sh — the path tracer's light tree against Blender Cycles 3.4 at equal error on
# the many-lights scene (issue 39, "many lights": the target is >= 10x; Cycles 3.4 has no light
# tree, it picks among the emissive triangles and lamps by a distribution over their power).
# The scene is `sy bench lights`' (10^4 small emissive quads, 10^3 point lights of 0.2 .. 20 cd,
# 30 boxes over a floor; OUT_DIR/many_lights.gltf, written once). Both render it at 320x240 with
# 8 bounces: `sy render -b pathtracer --filter none --params max_depth=8` (light_tree=auto: the
# tree) at SPP, Cycles through Blender's glTF importer from sy's view
# (tests/cycles/materials_cycles.py: black world, punctual lights without size, single-sided
# emitters emitting from their front only, punctual lights as bright as sy's: --lighting COMPAT) at
# CYCLES_SPP (default SPP), alternately RUNS times. Each image's relMSE is
# against its own renderer's REF_SPP-sample reference (default 256, made once in OUT_DIR: the
# importer's materials are close to ours, not the same), so time x relMSE is each renderer's cost
# of one unit of its own converged image's quality and the quotient (Cycles' over ours) the speed-up
# at equal error; the references' own noise adds about SPP / REF_SPP of the measured relMSE to both.
# The references' mean ratio is printed (the same scene: within a few %).
#
# A measurement, not a test: it needs Blender (Debian's `blender` package) and skips without it;
# use a Release build.
# Usage: tests/cycles/lights_equal_error.sh [BUILD_DIR (build)] [OUT_DIR (lights-equal-error)] [SPP (16)] [RUNS (3)]
#        (environment: REF_SPP, CYCLES_SPP)
set -euo pipefail
. "$(dirname "$0")/../support/measure.sh" # root, build, skip_without_blender, skip_without
out=${2:-lights-equal-error}
spp=${3:-16}
runs=${4:-3}
ref_spp=${REF_SPP:-256}
cspp=${CYCLES_SPP:-$spp}
skip_without_blender
need_sy_tools # sy, err
mkdir -p "$out"
gltf=$out/many_lights.gltf
[ -s "$gltf" ] || "$sy" bench lights "$out" --repeats 1 >"$out/bench.log" 2>&1 ||
    { echo "lights_equal_error.sh: error: sy bench lights failed, see $out/bench.log" >&2; exit 1; }

sy_run() { # SPP SEED OUT.exr LOG: prints the render's seconds
    "$sy" render "$gltf" -b pathtracer -w 320 -h 240 --spp "$1" --seed "$2" --filter none --params max_depth=8 \
        -o "$3" >"$4" 2>&1 || { echo "lights_equal_error.sh: error: sy render failed, see $4" >&2; exit 1; }
    sed -n 's/.* samples per pixel, \([0-9.]*\) s .*/\1/p' "$4" | head -1
}
cycles_run() { # SPP SEED OUT.exr LOG: prints the render's seconds
    blender -b -noaudio --factory-startup -P "$root/tests/cycles/materials_cycles.py" -- --gltf "$gltf" \
        --like "$out/ref_sy.exr" --spp "$1" --bounces 8 --env 0,0,0 --lighting COMPAT --seed "$2" --out "$3" \
        --sy "$sy" >"$4" 2>&1 || { echo "lights_equal_error.sh: error: Blender failed, see $4" >&2; exit 1; }
    sed -n 's/^ *Time: \([0-9]*\):\([0-9.]*\).*/\1 \2/p' "$4" | tail -1 | awk '{ printf "%.3f", $1 * 60 + $2 }'
}
echo "many lights ($gltf) 320x240, 8 bounces, sy $spp spp, Cycles $cspp spp, $(nproc) threads; each against its own $ref_spp-spp reference (target >= 10x)"
equal_error_own_refs "$spp" "$cspp" "$ref_spp" "$runs" "$out" cycles_run sy_run
