#!/usr/bin/env bash
# first_frame_sweep.sh — a measuring helper, not a test (issue 32 item 8: the first frame of every
# sample under 2 s, shader variants compiled well under a second on llvmpipe). Renders each sample
# in ../shared/testdata once with the rasterizer at 200x150 and prints, per sample, the wall and
# CPU (user + system, all threads) seconds of `sy render`, the seconds sy reports for the frame,
# and the shader compiles of its first frame as SY_GL_PROFILE=1 reports them (draws that took the
# GL thread more than 20 ms of CPU: llvmpipe compiles a fragment shader per program and pipeline
# state on its first draw): how many, their sum, the slowest and its variant.
#
#   first_frame_sweep.sh SY DATA_DIR [cold|warm] [REGEX]
#
# cold (default): Mesa's on-disk shader cache off (MESA_SHADER_CACHE_DISABLE=true), every compile
# paid; warm: a cache of the sweep's own, filled by a first render of each sample, then measured.
# REGEX picks samples by path. SWEEP_ALL=1 adds every other form of the glTF samples (embedded,
# binary, Draco, quantized); by default the main files: each glTF/ form, the Cornell box, every X3D
# file (as tests/smoke). SWEEP_LOG=DIR keeps each render's stderr there.
# Output: one tab-separated line per sample, then the sum, the slowest sample and the count over 2 s
# (wall and CPU). On a machine shared with other work the wall seconds follow the load; the CPU
# seconds less so.
set -uo pipefail
sy=${1:?usage: first_frame_sweep.sh SY DATA_DIR [cold|warm] [REGEX]}
data=${2:?usage: first_frame_sweep.sh SY DATA_DIR [cold|warm] [REGEX]}
mode=${3:-cold}
re=${4:-.}
[ -d "$data/gltf" ] || { echo "first_frame_sweep: $data/gltf is absent" >&2; exit 2; }
tmp=$(mktemp -d "${TMPDIR:-/tmp}/sy-sweep.XXXXXX") || exit 1
trap 'rm -rf "$tmp"' EXIT
log=${SWEEP_LOG:-}
[ -n "$log" ] && mkdir -p "$log"

files() {
  (cd "$data" && { find gltf -path '*/glTF/*.gltf'; find cornell -name '*.gltf'; find x3d -name '*.x3d'
    [ "${SWEEP_ALL:-0}" = 1 ] && find gltf \( -name '*.gltf' -o -name '*.glb' \) ! -path '*/glTF/*'; } | sort)
}

render() { # FILE ERRFILE: prints "wall cpu"
  /usr/bin/time -f '%e %U %S' -o "$tmp/time" "$sy" render "$data/$1" -b raster -w 200 -h 150 -o "$tmp/x.png" \
    >"$2" 2>&1
  local rc=$?
  awk -v rc=$rc '{ printf "%.2f %.2f %d", $1, $2 + $3, rc }' "$tmp/time"
}

case $mode in
  cold) export MESA_SHADER_CACHE_DISABLE=true ;;
  warm) export MESA_SHADER_CACHE_DIR=$tmp/cache MESA_SHADER_CACHE_DISABLE=false ;;
  *) echo "first_frame_sweep: mode is cold or warm, not $mode" >&2; exit 2 ;;
esac
export SY_GL_PROFILE=1
printf 'sample\twall_s\tcpu_s\tsy_s\tcompiles\tcompile_cpu_s\tslowest_s\tslowest_variant\n'
n=0 sum_w=0 sum_c=0 over_w=0 over_c=0 worst_w=0 worst=""
while IFS= read -r f; do
  [[ $f =~ $re ]] || continue
  [ "$mode" = warm ] && render "$f" /dev/null >/dev/null
  err=$tmp/err
  read -r wall cpu rc < <(render "$f" "$err")
  [ -n "$log" ] && cp "$err" "$log/$(echo "$f" | tr / _).log"
  sys=$(sed -n 's/.*, raster, \([0-9.]*\) s$/\1/p' "$err" | tail -1)
  stats=$(awk '/draw took/ { t = $0; sub(/.*draw took /, "", t); t += 0; v = $0; sub(/.*shader compile\): /, "", v); sub(/;.*/, "", v)
      if (v == "another program") { v = $0; sub(/.*raster profile: /, "", v); sub(/ draw took.*/, "", v) }
      n++; s += t; if (t > m) { m = t; w = v } }
    END { printf "%d\t%.2f\t%.2f\t%s", n, s, m, (n ? w : "-") }' "$err")
  [ "$rc" = 0 ] || stats="$stats (exit $rc: $(tail -1 "$err"))"
  printf '%s\t%s\t%s\t%s\t%s\n' "$f" "$wall" "$cpu" "${sys:--}" "$stats"
  n=$((n + 1))
  sum_w=$(awk -v a="$sum_w" -v b="$wall" 'BEGIN { print a + b }')
  sum_c=$(awk -v a="$sum_c" -v b="$cpu" 'BEGIN { print a + b }')
  awk -v b="$wall" 'BEGIN { exit !(b > 2) }' && over_w=$((over_w + 1))
  awk -v b="$cpu" 'BEGIN { exit !(b > 2) }' && over_c=$((over_c + 1))
  if awk -v a="$worst_w" -v b="$wall" 'BEGIN { exit !(b > a) }'; then worst_w=$wall worst=$f; fi
done < <(files)
printf '# %d samples (%s cache): wall sum %.1f s, CPU sum %.1f s; slowest %s %s s; over 2 s: %d (wall), %d (CPU); load %s\n' \
  "$n" "$mode" "$sum_w" "$sum_c" "$worst" "$worst_w" "$over_w" "$over_c" "$(cut -d' ' -f1-3 /proc/loadavg)"
