#!/usr/bin/env bash
# compare_all.sh — `sy compare` over the Cornell box, every glTF sample model and X3D example in
# ../shared/testdata and the demo: one contact sheet per scene (OUT_DIR/NAME.png) and one table of
# every back-end's mean luminance over covered pixels, its ratio to the path tracer and its
# coverage IoU against it.
# A measurement, not a test (issue 15's targets: no back-end dark, mean >= 0.05; Whitted and raster
# within 0.67-1.5x of the path tracer); rows outside the targets are marked with '!'.
# Usage: tests/look/compare_all.sh [BUILD_DIR (build)] [OUT_DIR (compare-all)] [W H SPP (200 150 64)]
set -uo pipefail
. "$(dirname "$0")/../support/measure.sh" # root, build, skip_without_blender, skip_without
out=${2:-compare-all}
w=${3:-200}
h=${4:-150}
spp=${5:-64}
data=$root/../shared/testdata
skip_without "$data"
mkdir -p "$out"
scenes=(demo)
while IFS= read -r f; do scenes+=("$f"); done < <(cd "$data" && { find cornell gltf -path '*/glTF/*.gltf' -o -name 'cornell_box.gltf'; find x3d -name '*.x3d'; } | sort)
printf '%-58s %-10s %8s %8s %6s %7s\n' scene backend covered mean ratio iou
for s in "${scenes[@]}"; do
    path=$s
    [ "$s" = demo ] || path=$data/$s
    name=$(basename "${s%.*}")
    table=$("$build/apps/sy/sy" compare "$path" -w "$w" -h "$h" --spp "$spp" -o "$out/$name.png" 2>/dev/null)
    if [ $? -ne 0 ]; then
        printf '%-58s %s\n' "$s" "FAILED (sy compare exit status non-zero)"
        continue
    fi
    echo "$table" | awk -v s="$s" '
        $1 == "whitted" || $1 == "raster" || $1 == "pathtracer" {
            cov = $3; mean = $4; ratio = $5; iou = $6
            flag = (mean < 0.05 || ($1 != "pathtracer" && (ratio < 0.67 || ratio > 1.5))) ? "!" : ""
            printf "%-58s %-10s %8s %8.3f %6.2f %7.3f %s\n", s, $1, cov, mean, ratio, iou, flag
        }'
done
