#!/usr/bin/env bash
# section_cli_test.sh SY TESTDATA TMPDIR EXR_EQUAL — section caps, measurement and saved views on the
# command line (integration_section_cli, issue 37 items 2, 3, 5):
#   - usage errors (status 2, naming the option and the reason): --clip-cap that is not RRGGBB,
#     --clip-cap without --clip, sy pick --measure with one point, --plane with a zero normal or
#     NaN, --bookmark without :N, with N outside 1..9, a file that is not a bookmarks file (naming
#     FILE:LINE), an empty slot, --bookmark with --look-at
#   - Box.gltf (a closed cube) cut through its middle facing the camera: with --clip-cap ff00ff the
#     centre pixel is the cap colour (linear 1, 0, 1) in whitted, pathtracer and raster; without it
#     it is not
#   - sy pick --measure: the distance equals the length of the printed delta and of the positions'
#     difference; --plane 0,1,0,0: each hit's plane_distance is its y
#   - sy pick --clip-cap: a pick through the cut lands on the cap ("cap": 1, on the plane); not without it
#   - sy render --bookmark FILE:N renders the pixels of --look-at with the file's eye, target and up
#     (exr_equal), and with its field of view those of --look-at --fov (a line without one: the
#     camera's; --fov given wins); a field of view outside (0, 180) is a usage error
# Needs ../shared/testdata (Box): exits 77 (skipped) naming what is missing.
set -u
SY=$1
DATA=$2
EXR_EQUAL=$4
. "$(dirname "${BASH_SOURCE[0]}")/../support/check.sh" # fail (and $fails)
fresh_tmp "$3"

usage() { usage_error "$1" "$2" "$SY" "${@:3}"; } # WHAT EXPECT CMD ARGS... (status 2 and EXPECT on stderr)
usage "cap not a colour" "--clip-cap: 'red' is not a colour RRGGBB" render demo -w 16 -h 16 -o "$TMP/u.png" --clip 1,0,0,0 --clip-cap red
usage "cap of 5 digits" "--clip-cap: '12345' is not a colour" render demo -w 16 -h 16 -o "$TMP/u.png" --clip 1,0,0,0 --clip-cap 12345
usage "cap without planes" "--clip-cap: caps fill the cut faces of section planes" render demo -w 16 -h 16 -o "$TMP/u.png" --clip-cap ff0000
usage "measure one point" "--measure takes two points" pick demo 5 5 -w 16 -h 16 --measure
usage "plane zero normal" "the normal (a, b, c) is zero" pick demo 5 5 -w 16 -h 16 --plane 0,0,0,1
usage "plane NaN" "--plane: '1,nan,0,0' is not a plane" pick demo 5 5 -w 16 -h 16 --plane 1,nan,0,0
printf '1 0 0 5 0 0 0 0 1 0\n' >"$TMP/one.bookmarks"
printf '# views\n2 0 0 5 0 0 0 0 1\n' >"$TMP/bad.bookmarks"
printf '1 0 0 5 0 0 5 0 1 0\n' >"$TMP/same.bookmarks"
usage "bookmark without slot" "--bookmark $TMP/one.bookmarks: expected FILE:N" render demo -w 16 -h 16 -o "$TMP/u.png" --bookmark "$TMP/one.bookmarks"
usage "bookmark slot 0" "expected FILE:N" render demo -w 16 -h 16 -o "$TMP/u.png" --bookmark "$TMP/one.bookmarks:0"
usage "bookmark bad line" "bad.bookmarks:2: expected \"N EX EY EZ" render demo -w 16 -h 16 -o "$TMP/u.png" --bookmark "$TMP/bad.bookmarks:2"
usage "bookmark eye = target" "same.bookmarks:1: slot 1: eye and target are the same point" render demo -w 16 -h 16 -o "$TMP/u.png" --bookmark "$TMP/same.bookmarks:1"
usage "bookmark empty slot" "holds no view in that slot" render demo -w 16 -h 16 -o "$TMP/u.png" --bookmark "$TMP/one.bookmarks:4"
usage "bookmark missing file" "No such file" render demo -w 16 -h 16 -o "$TMP/u.png" --bookmark "$TMP/none.bookmarks:1"
usage "bookmark with look-at" "both place the camera" render demo -w 16 -h 16 -o "$TMP/u.png" --bookmark "$TMP/one.bookmarks:1" --look-at 0,0,5:0,0,0

BOX="$DATA/gltf/Box/glTF/Box.gltf"
if [ ! -f "$BOX" ]; then
    echo "skipped: $BOX is absent (../shared/testdata)"
    [ $fails -eq 0 ] || exit 1
    exit 77
fi

# caps: the Box (a closed cube, half size 0.5) seen straight down -z from z = 3, cut at z = 0
# (keeping z <= 0): the centre pixel sees the cut face, the cap colour with --clip-cap ff00ff (8-bit
# sRGB 255, 0, 255 through --tonemap clamp), the cube's inside without
centre_px() { # PNG -> "R G B" of its centre pixel (8-bit RGB or RGBA, non-interlaced)
    python3 - "$1" <<'EOF'
import struct, sys, zlib
data = open(sys.argv[1], "rb").read()
pos, idat, w = 8, b"", 0
while pos < len(data):
    n, kind = struct.unpack(">I4s", data[pos:pos + 8])
    body = data[pos + 8:pos + 8 + n]
    if kind == b"IHDR":
        w, h, depth, ctype = struct.unpack(">IIBB", body[:10])
        bpp = {2: 3, 6: 4}[ctype]
        assert depth == 8
    elif kind == b"IDAT":
        idat += body
    pos += 12 + n
raw, stride, rows, prev = zlib.decompress(idat), w * bpp, [], bytearray(w * bpp)
for y in range(h):
    f, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
    for i in range(stride):
        a = line[i - bpp] if i >= bpp else 0
        b, c = prev[i], prev[i - bpp] if i >= bpp else 0
        pa, pb, pc = abs(b - c), abs(a - c), abs(a + b - 2 * c)
        pr = a if pa <= pb and pa <= pc else b if pb <= pc else c
        line[i] = (line[i] + [0, a, b, (a + b) // 2, pr][f]) & 255
    rows.append(line)
    prev = line
px = rows[h // 2][(w // 2) * bpp:(w // 2) * bpp + 3]
print(px[0], px[1], px[2])
EOF
}
for be in whitted pathtracer raster; do
    "$SY" backends 2>/dev/null | grep -qw "$be" || continue
    for cap in with without; do
        extra=()
        [ $cap = with ] && extra=(--clip-cap ff00ff)
        run "cap_${be}_$cap" "$SY" render "$BOX" -b "$be" -w 64 -h 64 --tonemap clamp --look-at 0,0,3:0,0,0 \
            --clip 0,0,-1,0 "${extra[@]}" -o "$TMP/cap_${be}_$cap.png"
        [ "$rc" -eq 0 ] || { fail "render $be $cap caps: status $rc: $(cat "$TMP/cap_${be}_$cap.err")"; continue; }
        got=$(centre_px "$TMP/cap_${be}_$cap.png")
        echo "cap, $be, $cap caps: centre pixel $got"
        if [ $cap = with ] && [ "$got" != "255 0 255" ]; then fail "$be: the cut face is $got, not the cap colour 255 0 255"; fi
        if [ $cap = without ] && [ "$got" = "255 0 255" ]; then fail "$be: capped without --clip-cap"; fi
    done
done

# measurement: two points on the Box's front face
run_ok "pick --measure" measure "$SY" pick "$BOX" 200 200 300 300 --measure --plane 0,1,0,0
python3 - "$TMP/measure.out" <<'EOF' || fail "pick --measure: $(cat "$TMP/measure.out")"
import json, math, sys
d = json.load(open(sys.argv[1]))
a, b = (p["position"] for p in d["picks"])
diff = [y - x for x, y in zip(a, b)]
assert d["unit"] == "m", d["unit"]
assert abs(d["distance"] - math.dist(a, b)) < 1e-6, (d["distance"], a, b)
assert all(abs(x - y) < 1e-6 for x, y in zip(d["delta"], diff)), (d["delta"], diff)
assert d["distance"] > 0.1, d["distance"]
for p in d["picks"]:
    assert abs(p["plane_distance"] - p["position"][1]) < 1e-6, p
print("measure: %.6f m between %s and %s" % (d["distance"], a, b))
EOF

# a pick through the cut cube with --clip-cap lands on the cap: z = 0 (the plane), normal +z, "cap": 1
run_ok "pick on a cap" pickcap "$SY" pick "$BOX" 32 32 -b whitted -w 64 -h 64 --look-at 0,0,3:0,0,0 --clip 0,0,-1,0 --clip-cap ff00ff
python3 - "$TMP/pickcap.out" <<'EOF' || fail "pick on a cap: $(cat "$TMP/pickcap.out")"
import json, sys
d = json.load(open(sys.argv[1]))
assert d["hit"] and d.get("cap") == 1, d
assert abs(d["position"][2]) < 1e-5 and d["normal"][2] > 0.999, d
print("pick on the cap: %s normal %s" % (d["position"], d["normal"]))
EOF
run_ok "pick inside" pickin "$SY" pick "$BOX" 32 32 -b whitted -w 64 -h 64 --look-at 0,0,3:0,0,0 --clip 0,0,-1,0
grep -q '"cap"' "$TMP/pickin.out" && fail "a pick without --clip-cap names a cap: $(cat "$TMP/pickin.out")"

# a saved view renders as --look-at from its eye, target and up
printf '# saved\n3 1.5 1 2.5 0 0.1 0 0 1 0\n' >"$TMP/box.bookmarks"
run_ok "render --bookmark" bm "$SY" render "$BOX" -b whitted -w 64 -h 48 --bookmark "$TMP/box.bookmarks:3" -o "$TMP/bm.exr"
run_ok "render --look-at" la "$SY" render "$BOX" -b whitted -w 64 -h 48 --look-at 1.5,1,2.5:0,0.1,0:0,1,0 -o "$TMP/la.exr"
"$EXR_EQUAL" "$TMP/bm.exr" "$TMP/la.exr" >/dev/null || fail "--bookmark FILE:3 is not --look-at of its view"
# a saved view with its field of view (the tenth number, degrees) renders as --look-at with --fov;
# --fov given as well wins; the line without one above stays the camera's (a file of before)
printf '3 1.5 1 2.5 0 0.1 0 0 1 0 30
' >"$TMP/fov.bookmarks"
run_ok "render --bookmark with fov" bmf "$SY" render "$BOX" -b whitted -w 64 -h 48 --bookmark "$TMP/fov.bookmarks:3" -o "$TMP/bmf.exr"
run_ok "render --look-at --fov 30" laf "$SY" render "$BOX" -b whitted -w 64 -h 48 --look-at 1.5,1,2.5:0,0.1,0:0,1,0 --fov 30 -o "$TMP/laf.exr"
"$EXR_EQUAL" "$TMP/bmf.exr" "$TMP/laf.exr" >/dev/null || fail "--bookmark FILE:3 with 30 degrees is not --look-at --fov 30"
"$EXR_EQUAL" "$TMP/bmf.exr" "$TMP/la.exr" >/dev/null 2>&1 && fail "the bookmark's field of view changed nothing"
run_ok "render --bookmark --fov" bmf2 "$SY" render "$BOX" -b whitted -w 64 -h 48 --fov 30 --bookmark "$TMP/box.bookmarks:3" -o "$TMP/bmf2.exr"
"$EXR_EQUAL" "$TMP/bmf2.exr" "$TMP/laf.exr" >/dev/null || fail "--fov 30 with a bookmark without one is not --look-at --fov 30"
printf '3 1.5 1 2.5 0 0.1 0 0 1 0 200
' >"$TMP/badfov.bookmarks"
usage "bookmark fov 200" "field of view 200" render "$BOX" -w 16 -h 16 -o "$TMP/u.png" --bookmark "$TMP/badfov.bookmarks:3"

[ $fails -eq 0 ] && echo "integration_section_cli: ok"
[ $fails -eq 0 ]
