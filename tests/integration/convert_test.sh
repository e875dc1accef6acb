#!/usr/bin/env bash
# convert_test.sh SY EXR_EQUAL TESTDATA TMPDIR — sy convert (integration_convert):
#   - round trips of glTF (DamagedHelmet: 5 textures; ClearCoatTest: KHR_materials_clearcoat and
#     texture transforms; Cameras), the Cornell box, two X3D files (ConformanceNist PointLight, an
#     ImageTexture scene) and an Assimp OBJ + MTL (spider.obj): sy convert to .glb and to .gltf,
#     then the converted file has the same loaded nodes, meshes, primitives, triangles, lights and
#     cameras, and renders (whitted 96x72, EXR) bit-identically to the original. X3D files carry a
#     Background / environment glTF cannot hold (convert warns naming it), so both renders of them
#     are given the same world (--env-color 0.5,0.5,0.5 --background 0,0,0) and are then identical.
#   - bad input (unreadable scene, unknown output extension, missing output folder): non-zero exit,
#     a message naming the offending path, no file left behind.
# Models that are absent are skipped, saying so; with none present the test exits 77 (skipped).
set -u
SY=$1 EXR_EQUAL=$2 DATA=$3 TMP=$4
rm -rf "$TMP" && mkdir -p "$TMP/out" "$TMP/bad"
failures=0 ran=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

# loaded COUNTS-FILE: "nodes meshes primitives triangles lights cameras" of sy info's loaded line
loaded() {
    local l
    l=$(grep '"loaded":' "$1") || return 1
    for k in nodes meshes primitives triangles lights cameras; do
        echo "$l" | sed -n "s/.*\"$k\": \([0-9]*\).*/$k=\1/p"
    done | tr '\n' ' '
}

# roundtrip NAME FILE EXT [RENDER-OPTIONS...]
roundtrip() {
    local name=$1 file=$2 ext=$3
    shift 3
    if [ ! -f "$file" ]; then echo "skip: $name ($file absent)"; return; fi
    ran=$((ran + 1))
    local out="$TMP/out/$name.$ext"
    if ! "$SY" convert "$file" -o "$out" 2>"$TMP/$name.convert.err"; then
        fail "$name: sy convert: $(cat "$TMP/$name.convert.err")"; return
    fi
    "$SY" info "$file" >"$TMP/$name.a.json" 2>/dev/null && "$SY" info "$out" >"$TMP/$name.b.json" 2>"$TMP/$name.info.err" ||
        { fail "$name: sy info of the converted file: $(cat "$TMP/$name.info.err")"; return; }
    local a b
    a=$(loaded "$TMP/$name.a.json") b=$(loaded "$TMP/$name.b.json")
    [ -n "$a" ] && [ "$a" = "$b" ] || fail "$name: loaded counts differ: original $a, converted $b"
    "$SY" -q render "$file" -b whitted -w 96 -h 72 "$@" -o "$TMP/$name.a.exr" &&
        "$SY" -q render "$out" -b whitted -w 96 -h 72 "$@" -o "$TMP/$name.b.exr" ||
        { fail "$name: render failed"; return; }
    "$EXR_EQUAL" "$TMP/$name.a.exr" "$TMP/$name.b.exr" || fail "$name: the converted file renders differently"
    echo "ok: $name ($ext): $a; renders bit-identical"
}

G="$DATA/gltf" X="$DATA/x3d/web3d"
WORLD=(--env-color 0.5,0.5,0.5 --background 0,0,0)
roundtrip helmet "$G/DamagedHelmet/glTF/DamagedHelmet.gltf" glb
roundtrip helmet_text "$G/DamagedHelmet/glTF/DamagedHelmet.gltf" gltf
roundtrip clearcoat "$G/ClearCoatTest/glTF/ClearCoatTest.gltf" glb
roundtrip cameras "$G/Cameras/glTF/Cameras.gltf" gltf
roundtrip cornell "$DATA/cornell/cornell_box.gltf" glb
roundtrip x3d_light "$X/ConformanceNist/Lights/PointLight/test_locationsim.x3d" gltf "${WORLD[@]}"
roundtrip x3d_texture "$X/X3dForWebAuthors/Chapter05AppearanceMaterialTextures/GeometryPrimitiveNodesImageTexture.x3d" glb "${WORLD[@]}"
roundtrip obj_spider /usr/share/assimp/models/OBJ/spider.obj glb

# what the converted files say: ClearCoatTest keeps its extension, DamagedHelmet its 5 textures
if [ -f "$TMP/out/clearcoat.glb" ]; then
    grep -qF '"used": ["KHR_materials_clearcoat"' "$TMP/clearcoat.b.json" ||
        fail "clearcoat: the converted file does not use KHR_materials_clearcoat: $(grep extensions "$TMP/clearcoat.b.json")"
fi
if [ -f "$TMP/out/helmet.glb" ]; then
    grep -qF '"textures": 5, "lights"' "$TMP/helmet.b.json" || fail "helmet: not 5 textures: $(grep loaded "$TMP/helmet.b.json")"
fi
# X3D: the world is named as what glTF cannot hold
if [ -f "$TMP/x3d_light.convert.err" ]; then
    grep -q "background .*glTF cannot hold it" "$TMP/x3d_light.convert.err" || fail "x3d_light: no warning about the background"
fi

# bad input: a non-zero status, the path named, nothing left in the output folder
expect_error() {
    local name=$1 needle=$2
    shift 2
    "$@" >"$TMP/$name.out" 2>"$TMP/$name.err"
    local rc=$?
    [ "$rc" -ne 0 ] && [ "$rc" -lt 128 ] || fail "$name: status $rc"
    grep -qF -- "$needle" "$TMP/$name.err" || fail "$name: stderr does not name '$needle': $(cat "$TMP/$name.err")"
    [ -z "$(ls -A "$TMP/bad")" ] || fail "$name: left files behind: $(ls -A "$TMP/bad")"
    echo "ok: $name -> status $rc: $(head -n 1 "$TMP/$name.err")"
}
printf 'this is not a scene' >"$TMP/garbage.gltf"
expect_error unreadable garbage.gltf "$SY" convert "$TMP/garbage.gltf" -o "$TMP/bad/x.glb"
expect_error missing no_such.gltf "$SY" convert "$TMP/no_such.gltf" -o "$TMP/bad/x.glb"
expect_error extension x.obj "$SY" convert demo -o "$TMP/bad/x.obj"
expect_error nodir "$TMP/bad/missing_dir/x.glb" "$SY" convert demo -o "$TMP/bad/missing_dir/x.glb"
"$SY" convert demo >/dev/null 2>"$TMP/noout.err"
[ $? -eq 2 ] && grep -q -- "-o" "$TMP/noout.err" || fail "convert without -o: not a usage error: $(cat "$TMP/noout.err")"

if [ "$failures" -ne 0 ]; then echo "$failures failure(s)"; exit 1; fi
if [ "$ran" -eq 0 ]; then echo "skip: no test model present under $DATA"; exit 77; fi
echo "all passed ($ran round trips)"
