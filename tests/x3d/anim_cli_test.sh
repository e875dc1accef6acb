#!/usr/bin/env bash
# anim_cli_test.sh — `sy render --at` of an X3D file whose Viewpoint, light and Material are routed
# (issue 35): for each back-end given, two times give two different images, and the camera the
# image's metadata names (the sy:camera PNG text chunk, written from the camera node's world matrix
# at render time) is the Viewpoint's PositionInterpolator value at that time, computed here; a
# --frames sequence shows the same cameras at the same times.
# Usage: anim_cli_test.sh SY TMP BACKEND...
SY=$1
TMP=$2
shift 2
# fail (and $fails); x3d_shape, x3d_clock, x3d_drive (the scene's lines)
. "$(dirname "${BASH_SOURCE[0]}")/../support/check.sh"
. "$(dirname "${BASH_SOURCE[0]}")/../support/x3d_scene.sh"
rm -rf "$TMP"
mkdir -p "$TMP"
{
    echo "<X3D><Scene>"
    echo "<Viewpoint DEF='Cam' position='0 1 8' fieldOfView='0.8'/>"
    echo "<PointLight DEF='Lamp' location='-3 3 3' attenuation='0 0 0.05'/>"
    echo "<Transform translation='0 -1 0'>$(x3d_shape "<Box size='10 0.2 10'/>" "0.8 0.8 0.8")</Transform>"
    echo "<Transform DEF='Spin'><Shape><Appearance><Material DEF='Paint' diffuseColor='1 0 0'/></Appearance><Box/></Shape></Transform>"
    x3d_clock 2
    echo "<ColorInterpolator DEF='Hue' key='0 1' keyValue='1 0 0 0 0 1'/>"
    echo "<PositionInterpolator DEF='Dolly' key='0 1' keyValue='0 1 8 2 2 6'/>"
    echo "<PositionInterpolator DEF='Move' key='0 1' keyValue='-3 3 3 3 3 3'/>"
    x3d_drive Hue Paint diffuseColor
    x3d_drive Dolly Cam position
    x3d_drive Move Lamp location
    echo "</Scene></X3D>"
} >"$TMP/anim.x3d"
# t = 0.5 s: fraction 0.25; t = 1.5 s: 0.75 (Dolly: (0 1 8) + f (2 1 -2))
want_05="at (0.5, 1.25, 7.5)"
want_15="at (1.5, 1.75, 6.5)"
for b in "$@"; do
    extra=()
    [ "$b" = pathtracer ] && extra=(--spp 4)
    for t in 0.5 1.5; do
        if ! "$SY" render "$TMP/anim.x3d" -b "$b" -w 48 -h 32 --at "$t" "${extra[@]}" -o "$TMP/${b}_$t.png" \
            >"$TMP/out" 2>"$TMP/err"; then
            fail "$b --at $t: $(cat "$TMP/err")"
            continue
        fi
        want=$want_05
        [ "$t" = 1.5 ] && want=$want_15
        grep -aqF "the scene's first camera $want" "$TMP/${b}_$t.png" ||
            fail "$b --at $t: the image's camera is not the Viewpoint at $t s ($want): $(grep -ao "first camera at ([^)]*)" "$TMP/${b}_$t.png")"
    done
    cmp -s "$TMP/${b}_0.5.png" "$TMP/${b}_1.5.png" && fail "$b: --at 0.5 and --at 1.5 give the same image"
done
# a sequence (--frames 1:3 at 2 fps: 0.5, 1.0 and 1.5 s) through the first back-end: frames 1 and 3
# show the camera of --at 0.5 and --at 1.5
b=$1
if "$SY" render "$TMP/anim.x3d" -b "$b" -w 48 -h 32 --frames 1:3 --fps 2 -o "$TMP/seq_#.png" >"$TMP/out" 2>"$TMP/err"; then
    grep -aqF "the scene's first camera $want_05" "$TMP/seq_1.png" || fail "$b sequence: frame 1 is not at 0.5 s"
    grep -aqF "the scene's first camera $want_15" "$TMP/seq_3.png" || fail "$b sequence: frame 3 is not at 1.5 s"
else
    fail "$b --frames 1:3: $(cat "$TMP/err")"
fi
[ "$fails" -eq 0 ] || exit 1
rm -rf "$TMP"
echo "ok: $*"
