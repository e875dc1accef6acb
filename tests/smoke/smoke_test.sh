#!/usr/bin/env bash
# smoke_test.sh — every sample, every picture back-end: renders each model in ../shared/testdata
# (glTF, GLB, X3D, the Cornell box) with each picture back-end that was built (whitted, pathtracer
# at 4 spp, raster) at 80x60, with a time limit per render as a hang guard, and checks that each
# render exits 0, writes an image with finite pixels, covers some of it and is not dark. Catches
# the day a sample hangs, crashes or renders black in any back-end.
#
#   smoke_test.sh SY SMOKE_STATS DATA_DIR PARTS [full|reduced]
# PARTS: the parts that were built ("embree raster ..."). full: each model's main file (its glTF/
# form, the Cornell box, every X3D file) in every back-end, and its other forms (embedded, binary,
# Draco, quantized: the same scene once loaded) in Whitted only, which keeps the test within about
# two minutes on two cores; reduced (sanitizer and minimal builds): every third main file, every back-end.
# Environment: SY_SMOKE_ALL=1 renders every file in every back-end; SY_SMOKE_LIMIT (seconds per
# render, default 90: a hang guard, not a speed test; the first frame of a sample costs 1 to 19
# seconds of CPU (TransmissionTest compiles six main-pass shaders), and ctest runs other tests beside
# this one on a 2-core machine); SY_SMOKE_JOBS
# (renders at once, default 2); SY_SMOKE_OUT (keep the images and logs there).
#
# Expected outcomes are listed below with their reasons (EXPECT_FAIL: the load must fail with an
# error naming the reason; DARK: the model legitimately renders dark in a back-end, only coverage
# is checked). An expected failure that renders, or an unexpected one, fails the test.
# Exit status: 0 all as expected, 1 otherwise, 77 when DATA_DIR is absent (reason printed).
set -uo pipefail
sy=$1
stats=$2
data=$3
parts=$4
mode=${5:-full}
limit=${SY_SMOKE_LIMIT:-90}
jobs=${SY_SMOKE_JOBS:-2}
W=80 H=60
MIN_COVERED=0.01 # a model fills at least 1 % of the frame
MIN_MEAN=0.02    # mean linear luminance over covered pixels (issue 15's "dark" is below 0.05 at 64 spp)

[ -d "$data/gltf" ] || { echo "SKIP: $data/gltf is absent (the Khronos and X3D samples live in ../shared/testdata)"; exit 77; }

# Files that must fail to load, glob -> the word the error names (and why).
EXPECT_FAIL=(
)
# Renders that are legitimately dark: "glob|backend|reason" (backend * for all).
DARK=(
)

backends=()
case " $parts " in *" embree "*) backends+=(whitted pathtracer) ;; esac
case " $parts " in *" raster "*) backends+=(raster) ;; esac
[ ${#backends[@]} -gt 0 ] || { echo "SKIP: no picture back-end was built (parts: $parts)"; exit 77; }

# the jobs: "FILE BACKEND" lines
main_files() {
  (cd "$data" && { find gltf -path '*/glTF/*.gltf'; find cornell -name '*.gltf'; find x3d -name '*.x3d'; } | sort)
}
other_files() {
  (cd "$data" && find gltf \( -name '*.gltf' -o -name '*.glb' \) ! -path '*/glTF/*' | sort)
}
joblist=()
nfiles=0
if [ "${SY_SMOKE_ALL:-0}" = 1 ]; then
  while IFS= read -r f; do nfiles=$((nfiles + 1)); for b in "${backends[@]}"; do joblist+=("$f" "$b"); done; done < <(main_files; other_files)
else
  i=0
  while IFS= read -r f; do
    i=$((i + 1))
    [ "$mode" = reduced ] && [ $((i % 3)) -ne 1 ] && continue
    nfiles=$((nfiles + 1))
    for b in "${backends[@]}"; do joblist+=("$f" "$b"); done
  done < <(main_files)
  if [ "$mode" != reduced ]; then
    other=whitted
    case " ${backends[*]} " in *" whitted "*) ;; *) other=${backends[0]} ;; esac
    while IFS= read -r f; do nfiles=$((nfiles + 1)); joblist+=("$f" "$other"); done < <(other_files)
  fi
fi

out=${SY_SMOKE_OUT:-}
own_out=0
if [ -z "$out" ]; then out=$(mktemp -d "${TMPDIR:-/tmp}/sy-smoke.XXXXXX") || exit 1; own_out=1; fi
mkdir -p "$out"
trap '[ $own_out = 1 ] && rm -rf "$out"' EXIT

# one render: prints "STATUS FILE BACKEND SECONDS DETAIL"
render_one() {
  local f=$1 b=$2
  local tag=${f//\//_}.$b
  local img=$out/$tag.exr log=$out/$tag.log
  local extra=()
  [ "$b" = pathtracer ] && extra=(--spp 4)
  local t0 t1 rc
  t0=$(date +%s.%N)
  timeout -k 5 "$limit" "$sy" render "$data/$f" -b "$b" -w $W -h $H "${extra[@]}" -o "$img" >"$log" 2>&1
  rc=$?
  t1=$(date +%s.%N)
  local secs
  secs=$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.1f", b - a }')
  if [ $rc -eq 124 ] || [ $rc -eq 137 ]; then echo "HANG $f $b $secs no result within ${limit}s"; return; fi
  if [ $rc -ne 0 ]; then
    echo "FAIL $f $b $secs exit $rc: $(grep -m1 'error' "$log" | tr '\n' ' ')"
    return
  fi
  local s
  if ! s=$("$stats" "$img" 2>&1); then echo "BAD $f $b $secs $s"; return; fi
  echo "OK $f $b $secs $s"
}
export -f render_one
export sy stats data out limit W H

results=$out/results.txt
printf '%s\n' "${joblist[@]}" |
  xargs -d '\n' -n 2 -P "$jobs" bash -c 'render_one "$1" "$2"' _ >"$results"

fail=0
matches() { # matches FILE GLOB
  # shellcheck disable=SC2053
  [[ $1 == $2 ]]
}
expected_failure() { # prints "word|reason" when FILE must fail
  local e
  for e in "${EXPECT_FAIL[@]}"; do
    if matches "$1" "${e%%|*}"; then echo "${e#*|}"; return 0; fi
  done
  return 1
}
dark_reason() { # dark_reason FILE BACKEND
  local e g rest bk
  for e in "${DARK[@]+"${DARK[@]}"}"; do
    g=${e%%|*}; rest=${e#*|}; bk=${rest%%|*}
    if matches "$1" "$g" && { [ "$bk" = '*' ] || [ "$bk" = "$2" ]; }; then echo "${rest#*|}"; return 0; fi
  done
  return 1
}

n_ok=0 n_expected=0
while read -r status f b secs detail; do
  if exp=$(expected_failure "$f"); then
    word=${exp%%|*}; why=${exp#*|}
    if [ "$status" = FAIL ] && grep -q -- "$word" "$out/${f//\//_}.$b.log"; then
      echo "expected failure: $f ($b): $why"
      n_expected=$((n_expected + 1))
    else
      echo "UNEXPECTED: $f ($b) should fail naming $word ($why), got: $status $detail"
      fail=1
    fi
    continue
  fi
  case $status in
    OK)
      read -r _ covered _ mean <<<"$detail"
      if awk -v c="$covered" -v m="$MIN_COVERED" 'BEGIN { exit !(c < m) }'; then
        echo "EMPTY: $f ($b): covered $covered of the frame (want >= $MIN_COVERED)"
        fail=1
      elif awk -v c="$mean" -v m="$MIN_MEAN" 'BEGIN { exit !(c < m) }'; then
        if why=$(dark_reason "$f" "$b"); then
          echo "dark as expected: $f ($b): mean $mean: $why"
          n_expected=$((n_expected + 1))
        else
          echo "DARK: $f ($b): mean luminance $mean over covered pixels (want >= $MIN_MEAN)"
          fail=1
        fi
      else
        if why=$(dark_reason "$f" "$b"); then
          echo "UNEXPECTED: $f ($b) is listed as dark ($why) but has mean $mean: update the list"
          fail=1
        fi
        n_ok=$((n_ok + 1))
      fi
      ;;
    *)
      echo "$status: $f ($b) after ${secs}s: $detail"
      fail=1
      ;;
  esac
done <"$results"

total=$(wc -l <"$results")
echo "slowest renders (seconds, wall clock):"
sort -k4 -rn "$results" | head -5 | awk '{ printf "  %6s  %s (%s)\n", $4, $2, $3 }'
echo "smoke ($mode): $total renders of $nfiles files (back-ends: ${backends[*]}): $n_ok fine, $n_expected as expected, $((total - n_ok - n_expected)) wrong"
[ "$total" -eq $((${#joblist[@]} / 2)) ] || { echo "missing results: $total of $((${#joblist[@]} / 2))"; fail=1; }
exit $fail
