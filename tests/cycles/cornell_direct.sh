#!/usr/bin/env bash
# cornell_direct.sh — the Cornell box's direct light in every back-end against Blender Cycles.
# Renders ../shared/testdata/cornell/cornell_box.gltf with Cycles (direct light only: 0 bounces;
# tests/cycles/cornell_cycles.py) and with sy's raster (indirect=0: without its indirect estimate),
# whitted and pathtracer (max_depth=1: direct light only), then prints each back-end's mean over
# every wall's and block's interior pixels as a ratio to Cycles. A second table compares the
# default renders (raster with its indirect estimate, whitted, the path tracer with all bounces)
# with the full global-illumination reference ../shared/testdata/cornell/cornell_box_cycles_256_4096.exr.
# A measurement, not a test: it needs Blender (Debian's `blender` package) and skips without it.
# Usage: tests/cycles/cornell_direct.sh [BUILD_DIR (build)] [OUT_DIR (cornell-direct)] [CYCLES_SPP (1024)]
set -euo pipefail
. "$(dirname "$0")/../support/measure.sh" # root, build, skip_without_blender, skip_without
out=${2:-cornell-direct}
spp=${3:-1024}
gltf=$root/../shared/testdata/cornell/cornell_box.gltf
skip_without_blender
skip_without "$gltf"
mkdir -p "$out"
sy=$build/apps/sy/sy
"$sy" render "$gltf" -b raster -w 256 -h 256 -o "$out/raster_direct.exr" --params indirect=0
"$sy" render "$gltf" -b whitted -w 256 -h 256 -o "$out/whitted_direct.exr" --params max_depth=1
"$sy" render "$gltf" -b pathtracer -w 256 -h 256 -o "$out/pathtracer_direct.exr" --spp 256 --filter none \
    --params max_depth=1,specular=0
"$sy" render "$gltf" -b raster -w 256 -h 256 -o "$out/raster.exr"
"$sy" render "$gltf" -b whitted -w 256 -h 256 -o "$out/whitted.exr"
"$sy" render "$gltf" -b pathtracer -w 256 -h 256 -o "$out/pathtracer.exr" --spp 256 --filter none --params specular=0
cycles="$out/cycles_direct_${spp}.exr"
run_blender() { blender -b -noaudio --factory-startup -P "$root/tests/cycles/cornell_cycles.py" -- "$@"; }
[ -f "$cycles" ] || run_blender --gltf "$gltf" --size 256 --spp "$spp" --bounces 0 --out "$cycles" |
    grep -E "^(Time|Saved)" || true
echo "== direct light: against Cycles with 0 bounces, $spp spp"
run_blender --gltf "$gltf" --size 256 --out "$cycles" \
    --compare "$out/raster_direct.exr" "$out/whitted_direct.exr" "$out/pathtracer_direct.exr" |
    sed -n '/^region statistics/,/^largest/p'
echo "== global illumination: against Cycles' 4096-spp reference (64 bounces)"
run_blender --gltf "$gltf" --size 256 --out "$root/../shared/testdata/cornell/cornell_box_cycles_256_4096.exr" \
    --compare "$out/raster.exr" "$out/whitted.exr" "$out/pathtracer.exr" | sed -n '/^region statistics/,/^largest/p'
