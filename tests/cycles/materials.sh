#!/usr/bin/env bash
# materials.sh — the glTF material-extension models in every back-end against Blender Cycles
# (issue 34). For each model: sy's path tracer at SPP samples (no filter), Whitted and the
# rasterizer, all under a uniform white environment the camera does not see (--env-color 1,1,1
# --env-hidden: transparent where nothing is hit); then Cycles through Blender's own glTF importer,
# same view (tests/cycles/materials_cycles.py reads the camera from the path tracer's image), same
# environment, same samples and bounce limit, punctual lights as bright as sy's (--lighting COMPAT;
# see materials_cycles.py). Prints one row per model: the path tracer's mean RGB
# over Cycles' and its relMSE against Cycles (exr_error), Whitted's and the rasterizer's mean over
# the path tracer's, and the extensions the file uses that Blender's importer ignores (those rows
# compare a different material; look at the contact sheets instead).
# A measurement, not a test: it needs Blender (Debian's `blender` and `python3-numpy`) and skips
# without it.
# Usage: tests/cycles/materials.sh [BUILD_DIR (build)] [OUT_DIR (materials-cycles)] [SPP (1024)] [WxH (160x120)] [MODEL...]
set -euo pipefail
. "$(dirname "$0")/../support/measure.sh" # root, build, skip_without_blender, skip_without
out=${2:-materials-cycles}
spp=${3:-1024}
size=${4:-160x120}
shift $(($# < 4 ? $# : 4))
models=("$@")
[ ${#models[@]} -gt 0 ] || models=(ClearCoatTest TransmissionTest TransmissionRoughnessTest SpecularTest AttenuationTest
    SheenCloth TextureTransformMultiTest AnisotropyRotationTest AnisotropyStrengthTest IridescenceSuzanne ToyCar
    EmissiveStrengthTest)
data=$root/../shared/testdata/gltf
skip_without_blender blender python3-numpy
skip_without "$data"
mkdir -p "$out"
need_sy_tools # sy, err
w=${size%x*} h=${size#*x}
world=(--env-color 1,1,1 --env-hidden)
printf '%-26s %9s %9s %9s %9s  %s\n' model "pt/cyc" "relMSE" "wh/pt" "ras/pt" "Blender ignores"
for m in "${models[@]}"; do
    f=$(ls "$data/$m"/glTF/*.gltf 2>/dev/null | head -1)
    [ -n "$f" ] || { echo "$m: no glTF file under $data/$m/glTF"; continue; }
    o=$out/$m
    "$sy" -q render "$f" -b pathtracer --spp "$spp" --filter none -w "$w" -h "$h" "${world[@]}" -o "$o.pathtracer.exr" >/dev/null
    "$sy" -q render "$f" -b whitted -w "$w" -h "$h" "${world[@]}" -o "$o.whitted.exr" >/dev/null
    "$sy" -q render "$f" -b raster -w "$w" -h "$h" "${world[@]}" -o "$o.raster.exr" >/dev/null
    log=$(blender -b -noaudio --factory-startup -P "$root/tests/cycles/materials_cycles.py" -- --gltf "$f" \
        --like "$o.pathtracer.exr" --spp "$spp" --bounces 8 --env 1,1,1 --lighting COMPAT --out "$o.cycles.exr" \
        --sy "$sy" 2>&1) ||
        { echo "$m: Blender failed:"; echo "$log" | tail -5; continue; }
    ignored=$(echo "$log" | sed -n 's/^ignored-extensions: //p')
    read -r _ rel _ _ _ _ _ ratio <<<"$("$err" "$o.pathtracer.exr" "$o.cycles.exr")"
    wr=$("$err" "$o.whitted.exr" "$o.pathtracer.exr" | awk '{print $8}')
    rr=$("$err" "$o.raster.exr" "$o.pathtracer.exr" | awk '{print $8}')
    printf '%-26s %9.4f %9.5f %9.4f %9.4f  %s\n' "$m" "$ratio" "$rel" "$wr" "$rr" "$ignored"
done
echo "images: $out/MODEL.{pathtracer,whitted,raster,cycles}.exr"
