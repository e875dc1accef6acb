#!/usr/bin/env bash
# exr_error_test.sh EXR_ERROR TESTDATA_DIR — checks tests/support/exr_error, the error measure of
# tests/cycles/equal_error.sh, on two 256x256 Cycles renders from ../shared/testdata: an image
# against itself has no error and a mean ratio of 1; the mean ratios of A against B and B against
# A multiply to 1; with --blocks 2 the four equal blocks' relMSE average to the whole image's; a
# missing file, a bad option and a size mismatch exit 2 with a message naming the problem.
# Exit 77 (skipped) when the test data is absent.
set -u
ERR=$1
DATA=$2
A=$DATA/cornell/cornell_box_cycles_256_4096.exr
B=$DATA/gltf/DamagedHelmet/blender_cycles/cycles_orbit_r3_256px_32spp.exr
for f in "$A" "$B"; do [ -f "$f" ] || { echo "skipped: $f is absent"; exit 77; }; done
fail=0
bad() { echo "FAIL: $*"; fail=1; }
field() { echo "$1" | awk -v k="$2" '{ for (i = 1; i < NF; ++i) if ($i == k) print $(i + 1) }'; }

same=$("$ERR" "$A" "$A") || bad "A against A failed"
echo "A against A: $same"
[ "$(field "$same" relmse)" = 0 ] || bad "an image against itself has relMSE $(field "$same" relmse)"
[ "$(field "$same" mean_ratio)" = 1.00000 ] || bad "an image against itself has mean ratio $(field "$same" mean_ratio)"

ab=$("$ERR" "$A" "$B") || bad "A against B failed"
ba=$("$ERR" "$B" "$A") || bad "B against A failed"
echo "A against B: $ab"
echo "B against A: $ba"
awk -v r="$(field "$ab" relmse)" 'BEGIN { exit !(r > 0.01) }' || bad "two different renders have relMSE $(field "$ab" relmse)"
awk -v x="$(field "$ab" mean_ratio)" -v y="$(field "$ba" mean_ratio)" 'BEGIN { p = x * y; exit !(p > 0.9998 && p < 1.0002) }' ||
    bad "mean ratios $(field "$ab" mean_ratio) and $(field "$ba" mean_ratio) do not multiply to 1"

blocks=$("$ERR" "$A" "$B" --blocks 2) || bad "--blocks 2 failed"
echo "$blocks"
echo "$blocks" | awk -v whole="$(field "$ab" relmse)" 'NR > 1 { for (i = 1; i <= NF; ++i) { s += $i; n++ } }
    END { m = s / n; exit !(n == 4 && m > whole * 0.999 && m < whole * 1.001) }' ||
    bad "the blocks' mean relMSE is not the whole image's"

out=$("$ERR" "$A" /nonexistent.exr 2>&1)
[ $? = 2 ] && echo "$out" | grep -q nonexistent.exr || bad "a missing file: '$out'"
out=$("$ERR" "$A" "$B" --blocks 0 2>&1)
[ $? = 2 ] && echo "$out" | grep -q usage || bad "--blocks 0: '$out'"
[ $fail = 0 ] && echo "ok: exr_error"
exit $fail
