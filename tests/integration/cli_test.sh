#!/usr/bin/env bash
# cli_test.sh SY TESTDATA TMPDIR — tests of the `sy` command line tool (integration_cli).
#   - sy info Box.gltf: JSON in the one layout of every format (format, file_counts, loaded, extensions,
#     variants, bounds, warning_count, warnings): meshes/primitives/triangles/materials = 1/1/12/1,
#     bounds +-0.5; a file's warnings only in the JSON; extensionsUsed split into supported and
#     unsupported, the variant names, BoxAnimated's 1 animation and its clip (duration, channels)
#   - the scene clock: sy render BoxAnimated --at 0 equals the static load pixel for pixel (EXR,
#     exr_equal), --at 0.5 and --at 2 differ; --at -1 / nan, an unknown --clip and --clip on a scene
#     without animations are usage errors (status 2) naming the option
#   - conventions: --version, --help / help / CMD --help / help bench on stdout; a bad option, a
#     missing or bad value named with status 2; a failure status 1; backends --json; -q / -v;
#     an abbreviated long option (--frame for --frames) is a usage error naming the options it
#     begins, in every command
#   - sy render (cornell, whitted) to PNG and EXR: exit 0, files with the right signature and size
#   - bad inputs (missing file, truncated GLB, garbage .gltf, unknown back-end, output in a missing
#     or unwritable directory, unknown output extension): non-zero exit, the offending name in
#     stderr, and no output file nor temporary file left behind; a missing or unwritable output
#     directory is found before anything is rendered; --params with a key twice is a usage error
#   - typed parameters: sy backends --params (text and --json) lists each back-end's table; an unknown
#     --params key, a value out of range or not in the enum: status 2 naming it (and the valid keys)
#   - sy bench sync / sy bench anim / sy bench rays / sy bench governor / sy bench limit / sy bench instances on
#     small sizes: exit 0 and their result lines (no thresholds; bench limit: no replayed answer differs
#     from the frame's; bench instances: its files read back with what was written), a bad --spp named
#   - sy demo -o DIR -w 64 -h 36: demo_whitted.png / .exr written
#   - -b pathtracer: --spp with --aov (EXR with feature channels), --time; --seed (the same twice the same
#     image, another other noise); a non-EXR --env fails
#   - -b pathtracer --filter pixel --threshold T and --filter radiance write an image; --filter
#     bogus, a bad radiance option and a negative threshold fail naming the problem
#     naming the file
#   - world flags: a NaN --env-color, a negative --env-intensity, a short --background and a non-2:1
#     --env EXR fail naming the problem; a 2:1 map renders; sy compare prints a row per picture
#     back-end (not coverage) and writes a PNG sheet; the Box is lit by the default studio
#     (mean luminance >= 0.05) and black with --no-default-light
#   - --stereo sbs / tb / anaglyph / separate: output sizes and per-eye files; bad stereo parameters
#     and overlays (negative separation, zero parallax 0, unknown mode, missing file, unknown
#     back-end) fail naming the problem and write nothing
# SY_TEST_PARTS (tests/CMakeLists.txt) names the parts this build has ("embree raster cluster
# ..."); the checks of a part that was not built are skipped, saying so.
# The parts that need ../shared/testdata run only when it is present; when it is absent the rest
# still runs and the test then exits 77 (skipped) naming what was missing.
set -u
SY=$1
DATA=$2
TMP=$3
EXR_EQUAL=${4:-} # tests/support/exr_equal (optional: the --at pixel checks are skipped without it)
missing=""
# fail, run NAME CMD..., run_ok LABEL NAME CMD... (and $fails, $rc)
. "$(dirname "${BASH_SOURCE[0]}")/../support/check.sh"

rm -rf "$TMP"
mkdir -p "$TMP"

# has PART: this build has the part (SY_TEST_PARTS; unset = the full build)
has() { [ -z "${SY_TEST_PARTS+x}" ] || [[ " $SY_TEST_PARTS " == *" $1 "* ]]; }
# picture back-ends of this build
PICTURE=(whitted pathtracer)
has raster && PICTURE+=(raster)
for p in raster cluster; do has $p || echo "skip: the checks of '$p' (not in this build: SY_TEST_PARTS='$SY_TEST_PARTS')"; done

# magic FILE HEX: the file starts with these bytes
magic() {
    [ "$(head -c $((${#2} / 2)) "$1" | od -An -tx1 | tr -d ' \n')" = "$2" ]
}

# u32be FILE OFFSET: big-endian 32-bit integer
u32be() {
    local b
    b=($(od -An -tu1 -j "$2" -N 4 "$1"))
    echo $(((b[0] << 24) | (b[1] << 16) | (b[2] << 8) | b[3]))
}

# expect_error NAME NEEDLE OUTDIR CMD...: CMD must fail, mention NEEDLE on stderr, and leave OUTDIR
# (a fresh directory holding only the command's outputs) empty.
expect_error() {
    local name=$1 needle=$2 outdir=$3
    shift 3
    run "$name" "$@"
    if [ "$rc" -eq 0 ]; then fail "$name: exit status 0 for a bad input"; fi
    if [ "$rc" -ge 128 ]; then fail "$name: killed by a signal (status $rc)"; fi
    if ! grep -qF -- "$needle" "$TMP/$name.err"; then
        fail "$name: stderr does not name '$needle': $(cat "$TMP/$name.err")"
    fi
    if [ -n "$(ls -A "$outdir")" ]; then fail "$name: left files behind: $(ls -A "$outdir")"; fi
    echo "ok: $name -> status $rc: $(head -n 3 "$TMP/$name.err" | tr '\n' ' ')"
}

BOX="$DATA/gltf/Box/glTF/Box.gltf"
GLB="$DATA/gltf/Box/glTF-Binary/Box.glb"
CORNELL="$DATA/cornell/cornell_box.gltf"

# ---------------------------------------------------------------- without test data
run backends "$SY" backends
[ "$rc" -eq 0 ] && grep -q '^whitted' "$TMP/backends.out" || fail "sy backends does not list whitted"

# typed back-end parameters (core/sy_params.h): sy backends --params prints every class's table; an
# unknown --params key or a bad value is a usage error (2) naming it and listing the valid keys, and
# nothing is written
run backends_params "$SY" backends --params
[ "$rc" -eq 0 ] && grep -Eq '^  max_depth +int +1\.\.64 +8 +longest' "$TMP/backends_params.out" &&
    grep -Eq '^  filter +enum +none\|pixel\|atrous\|jbu\|adaptive\|radiance +none ' "$TMP/backends_params.out" ||
    fail "sy backends --params: status $rc, $(head -c 600 "$TMP/backends_params.out" "$TMP/backends_params.err")"
run backends_params_json "$SY" backends --params --json
[ "$rc" -eq 0 ] && grep -Eq '"name":[[:space:]]*"max_depth"' "$TMP/backends_params_json.out" ||
    fail "sy backends --params --json: status $rc"
mkdir -p "$TMP/o_params"
run params_unknown "$SY" render demo -b whitted --params max_detph=8 -o "$TMP/o_params/x.exr"
[ "$rc" -eq 2 ] && grep -q "unknown parameter 'max_detph' for back-end 'whitted'" "$TMP/params_unknown.err" &&
    grep -q "valid: spp, env_samples, max_depth, light_samples, threads, specular" "$TMP/params_unknown.err" ||
    fail "an unknown --params key: status $rc (want 2), $(cat "$TMP/params_unknown.err")"
run params_range "$SY" render demo -b whitted --params max_depth=99 -o "$TMP/o_params/x.exr"
[ "$rc" -eq 2 ] && grep -q "max_depth=99 for back-end 'whitted': expected an integer in \[1, 64\]" "$TMP/params_range.err" ||
    fail "--params max_depth=99: status $rc (want 2), $(cat "$TMP/params_range.err")"
run params_enum "$SY" render demo -b pathtracer --params filter_kernel=fast -o "$TMP/o_params/x.exr"
[ "$rc" -eq 2 ] && grep -q "filter_kernel=fast for back-end 'pathtracer': expected one of separable, brute" "$TMP/params_enum.err" ||
    fail "--params filter_kernel=fast: status $rc (want 2), $(cat "$TMP/params_enum.err")"
run params_twice "$SY" render demo -b whitted -w 16 -h 16 --params spp=1,spp=2 -o "$TMP/o_params/x.png"
[ "$rc" -eq 2 ] && grep -q "'spp' is given twice" "$TMP/params_twice.err" ||
    fail "--params spp=1,spp=2: status $rc (want 2), $(cat "$TMP/params_twice.err")"
[ -z "$(ls -A "$TMP/o_params")" ] || fail "refused --params left files behind: $(ls -A "$TMP/o_params")"

# conventions: --version and --help on stdout with status 0; a usage error names the option or value
# on stderr with status 2; a failure has status 1
run version "$SY" --version
[ "$rc" -eq 0 ] && grep -Eq '^sy \(Switchyard\) [0-9]+\.[0-9]+\.[0-9]+$' "$TMP/version.out" && [ ! -s "$TMP/version.err" ] ||
    fail "sy --version: status $rc, '$(cat "$TMP/version.out" "$TMP/version.err")'"
for h in "--help" "help" "render --help"; do
    run help "$SY" $h
    [ "$rc" -eq 0 ] && grep -q '^usage:' "$TMP/help.out" && grep -q 'sy render SCENE' "$TMP/help.out" && [ ! -s "$TMP/help.err" ] ||
        fail "sy $h: status $rc, the summary is not on stdout"
done
if has cluster; then
    run serve_help "$SY" serve --help
    [ "$rc" -eq 0 ] && grep -q 'usage: sy serve' "$TMP/serve_help.out" || fail "sy serve --help: status $rc"
fi
run badopt "$SY" render demo -b whitted -o "$TMP/x.png" --frobnicate
[ "$rc" -eq 2 ] && grep -q -- "'--frobnicate'" "$TMP/badopt.err" || fail "a bad option: status $rc (want 2), $(cat "$TMP/badopt.err")"
run badval "$SY" render demo -b whitted -o "$TMP/x.png" -w 0
[ "$rc" -eq 2 ] && grep -q -- "-w: '0'" "$TMP/badval.err" || fail "a bad value: status $rc (want 2), $(cat "$TMP/badval.err")"
run badmissing "$SY" render demo -b whitted -o "$TMP/x.png" -w
[ "$rc" -eq 2 ] && grep -q -- "option '-w' needs a value" "$TMP/badmissing.err" || fail "a missing value: status $rc, $(cat "$TMP/badmissing.err")"
run badword "$SY" render demo -b whitted -o "$TMP/x.png" --tonemap=bogus
[ "$rc" -eq 2 ] && grep -q -- "--tonemap: 'bogus'" "$TMP/badword.err" || fail "a bad --tonemap: status $rc, $(cat "$TMP/badword.err")"
# long options are matched exactly (issue 32): an abbreviation is a usage error naming the options it
# begins, in every command (sy_getopt, apps/sy/sy_options.c); getopt_long took "--frame 10" for --frames
mkdir -p "$TMP/o_abbrev"
run abbrev "$SY" render demo -b whitted -w 16 -h 16 -o "$TMP/o_abbrev/x.png" --frame 10
[ "$rc" -eq 2 ] && grep -q -- "unknown option '--frame': long options are not abbreviated; the option that begins so is: --frames" \
    "$TMP/abbrev.err" || fail "sy render --frame 10: status $rc (want 2), $(cat "$TMP/abbrev.err")"
run abbrev_eq "$SY" render demo -b whitted -w 16 -h 16 -o "$TMP/o_abbrev/x.png" --param=spp=1
[ "$rc" -eq 2 ] && grep -q -- "'--param'.*: --params" "$TMP/abbrev_eq.err" ||
    fail "sy render --param=spp=1: status $rc (want 2), $(cat "$TMP/abbrev_eq.err")"
run abbrev_many "$SY" render demo -b whitted -w 16 -h 16 -o "$TMP/o_abbrev/x.png" --env-i 2
[ "$rc" -eq 2 ] && grep -q -- "'--env-i'.*: --env-intensity" "$TMP/abbrev_many.err" ||
    fail "sy render --env-i 2: status $rc (want 2), $(cat "$TMP/abbrev_many.err")"
run abbrev_amb "$SY" render demo -b whitted -w 16 -h 16 -o "$TMP/o_abbrev/x.png" --env 2
[ "$rc" -ne 2 ] || ! grep -q "not abbreviated" "$TMP/abbrev_amb.err" ||
    fail "sy render --env (an option that begins others) was taken for an abbreviation: $(cat "$TMP/abbrev_amb.err")"
run abbrev_ambiguous "$SY" render demo -b whitted -w 16 -h 16 -o "$TMP/o_abbrev/x.png" --e 2
[ "$rc" -eq 2 ] && grep -q -- "'--e'.*the options that begin so are: .*--env, .*--env-color" "$TMP/abbrev_ambiguous.err" ||
    fail "sy render --e 2 (ambiguous): status $rc (want 2), $(cat "$TMP/abbrev_ambiguous.err")"
for cmd in "info demo --js" "backends --par" "bench limit --rep 1" "bench governor --fram 2" "compare demo --spp 1 --backend whitted"; do
    run abbrev_cmd "$SY" $cmd
    [ "$rc" -eq 2 ] && grep -q "not abbreviated" "$TMP/abbrev_cmd.err" ||
        fail "sy $cmd: status $rc (want 2), $(head -c 400 "$TMP/abbrev_cmd.err")"
done
if has cluster; then
    run abbrev_serve "$SY" serve --list tcp://127.0.0.1:0
    [ "$rc" -eq 2 ] && grep -q -- "'--list'.*: --listen" "$TMP/abbrev_serve.err" ||
        fail "sy serve --list: status $rc (want 2), $(cat "$TMP/abbrev_serve.err")"
fi
[ -z "$(ls -A "$TMP/o_abbrev")" ] || fail "an abbreviated option left files behind: $(ls -A "$TMP/o_abbrev")"
run help_bench "$SY" help bench
[ "$rc" -eq 0 ] && grep -q '^  sy bench sync' "$TMP/help_bench.out" && ! grep -q '^  sy render' "$TMP/help_bench.out" ||
    fail "sy help bench: status $rc, not the bench entries alone"
run backends_json "$SY" backends --json
[ "$rc" -eq 0 ] && head -n 1 "$TMP/backends_json.out" | grep -qx '\[' && grep -q '{"name": "whitted", "caps": \["depth"' "$TMP/backends_json.out" ||
    fail "sy backends --json: status $rc, $(cat "$TMP/backends_json.out" "$TMP/backends_json.err")"
# sy info says a file's warnings once, in its JSON (warning_count, warnings), not also on stderr
printf '{"asset":{"version":"2.0"},"meshes":[{"primitives":[{"attributes":{}}]}],"nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}]}' \
    > "$TMP/info_warn.gltf"
run info_warn "$SY" info "$TMP/info_warn.gltf"
[ "$rc" -eq 0 ] && grep -qxF '  "warning_count": 1,' "$TMP/info_warn.out" && grep -q 'no POSITION attribute; skipped' "$TMP/info_warn.out" &&
    [ ! -s "$TMP/info_warn.err" ] || fail "sy info with a warning: status $rc, $(cat "$TMP/info_warn.out" "$TMP/info_warn.err")"
# sy info lists the file's extensionsUsed, split by what the loader reads, and its material variants
printf '{"asset":{"version":"2.0"},"extensionsUsed":["KHR_materials_variants","EXT_sy_no_such_extension"],"extensions":{"KHR_materials_variants":{"variants":[{"name":"Red"},{"name":"Blue"}]}},"nodes":[{}],"scenes":[{"nodes":[0]}]}' \
    > "$TMP/info_ext.gltf"
run info_ext "$SY" info "$TMP/info_ext.gltf"
[ "$rc" -eq 0 ] &&
    grep -qF '"extensions": {"used": ["KHR_materials_variants", "EXT_sy_no_such_extension"], "supported": ["KHR_materials_variants"], "unsupported": ["EXT_sy_no_such_extension"]},' "$TMP/info_ext.out" &&
    grep -qF '"variants": ["Red", "Blue"],' "$TMP/info_ext.out" && grep -qxF '    "animations": 0' "$TMP/info_ext.out" ||
    fail "sy info extensions / variants: status $rc, $(cat "$TMP/info_ext.out" "$TMP/info_ext.err")"
# the front door (issue 33): sy backends marks the default; sy render SCENE without -b and -o
# renders with it into STEM.png in the current folder; -o X.jpg writes a JPEG; sy render DIR takes
# the one scene file of the folder and lists the candidates when there are several
default_b=$("$SY" backends | grep '  (default)$' | cut -d' ' -f1)
want_default=whitted
has raster && want_default=raster
[ "$default_b" = "$want_default" ] || fail "sy backends: default '$default_b' (want $want_default)"
grep -q "\"name\": \"$want_default\".*\"default\": true" <("$SY" backends --json | tr -d '\n') ||
    fail "sy backends --json: $want_default is not marked the default"
mkdir -p "$TMP/front/one" "$TMP/front/two" "$TMP/front/here"
printf '{"asset":{"version":"2.0"},"scenes":[{"nodes":[0]}],"nodes":[{}]}' > "$TMP/front/one/empty.gltf"
cp "$TMP/front/one/empty.gltf" "$TMP/front/two/a.gltf"
cp "$TMP/front/one/empty.gltf" "$TMP/front/two/b.glb.x3d"
(cd "$TMP/front/here" && "$SY" render demo -w 32 -h 24 >../plain.out 2>../plain.err)
rc=$?
[ "$rc" -eq 0 ] && magic "$TMP/front/here/demo.png" 89504e47 && grep -q "demo.png: 32x24, $want_default, " "$TMP/front/plain.out" ||
    fail "sy render demo (no -b, no -o): status $rc, $(cat "$TMP/front/plain.out" "$TMP/front/plain.err"; ls "$TMP/front/here")"
run jpeg "$SY" render demo -b whitted -w 32 -h 24 -o "$TMP/front/demo.jpg"
[ "$rc" -eq 0 ] && magic "$TMP/front/demo.jpg" ffd8ff || fail "sy render -o X.jpg: status $rc, $(cat "$TMP/jpeg.err")"
(cd "$TMP/front/here" && "$SY" render ../one -b whitted -w 32 -h 24 >../dir.out 2>../dir.err)
rc=$?
[ "$rc" -eq 0 ] && [ -f "$TMP/front/here/empty.png" ] || fail "sy render DIR (one scene file): status $rc, $(cat "$TMP/front/dir.err")"
run dir_two "$SY" render "$TMP/front/two" -b whitted -w 32 -h 24
[ "$rc" -eq 1 ] && grep -q "2 scene files; name one" "$TMP/dir_two.err" && grep -q "/two/a.gltf" "$TMP/dir_two.err" &&
    grep -q "/two/b.glb.x3d" "$TMP/dir_two.err" || fail "sy render DIR (two scene files): status $rc, $(cat "$TMP/dir_two.err")"
[ ! -e "$TMP/front/two.png" ] && [ ! -e two.png ] || fail "sy render DIR (two scene files) wrote an image"
run badcmd "$SY" renderr demo
[ "$rc" -eq 2 ] && grep -q "unknown command 'renderr'" "$TMP/badcmd.err" || fail "an unknown command: status $rc (want 2)"
run failure "$SY" render "$TMP/does_not_exist.gltf" -b whitted -o "$TMP/x.png"
[ "$rc" -eq 1 ] && grep -q "does_not_exist.gltf" "$TMP/failure.err" || fail "a failure: status $rc (want 1), $(cat "$TMP/failure.err")"
[ ! -e "$TMP/x.png" ] || fail "an image was written by a failed or refused command"

# files are recognised by content: an OBJ (under its own name or a glTF one) is read through Assimp
# and rendered; a VRML file (under a glTF name) is named as such, with status 1 and no image
mkdir -p "$TMP/in"
printf '# a triangle\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' > "$TMP/in/tri.obj"
cp "$TMP/in/tri.obj" "$TMP/in/tri_obj.gltf"
for f in tri.obj tri_obj.gltf; do
    rm -f "$TMP/x.png"
    run obj "$SY" render "$TMP/in/$f" -b whitted -w 32 -h 24 -o "$TMP/x.png"
    [ "$rc" -eq 0 ] && [ -s "$TMP/x.png" ] || fail "an OBJ file ($f): status $rc, $(cat "$TMP/obj.err")"
done
rm -f "$TMP/x.png"
printf '#VRML V2.0 utf8\nShape {}\n' > "$TMP/in/shape_wrl.gltf"
run wrl "$SY" render "$TMP/in/shape_wrl.gltf" -b whitted -o "$TMP/x.png"
[ "$rc" -eq 1 ] && grep -q "shape_wrl.gltf: VRML / X3D classic encoding content, which sy does not read as a scene" "$TMP/wrl.err" &&
    [ ! -e "$TMP/x.png" ] || fail "a VRML file: status $rc, $(cat "$TMP/wrl.err")"

# metadata: every image records the renderer, back-end, camera, size, samples, time and source
# (EXR string attributes, PNG text chunks); sy info IMAGE.exr prints them
mkdir -p "$TMP/meta"
run meta_exr "$SY" render demo -b whitted -w 40 -h 30 -o "$TMP/meta/m.exr" --params spp=2
run meta_info "$SY" info "$TMP/meta/m.exr"
for kv in '"sy:renderer": "Switchyard ' '"sy:backend": "whitted"' '"sy:params": "spp=2"' '"sy:size": "40x30"' \
          '"sy:samples": "2"' '"sy:source": "demo"' '"sy:camera": "the scene' '"sy:seconds": "' '"width": 40,' '"height": 30,'; do
    grep -qF -- "$kv" "$TMP/meta_info.out" || fail "sy info m.exr lacks $kv: $(cat "$TMP/meta_info.out" "$TMP/meta_info.err")"
done
# the exact view, for another renderer to see the same (tests/cycles/materials_cycles.py): 16
# numbers whose translation is the camera position of sy:camera, and the projection
c2w=$(sed -n 's/.*"sy:camera_to_world": "\([^"]*\)".*/\1/p' "$TMP/meta_info.out")
pos=$(sed -n 's/.*"sy:camera": "[^"]* at (\([^)]*\)).*/\1/p' "$TMP/meta_info.out" | tr -d ',')
set -- $c2w
[ $# -eq 16 ] && awk -v a="${13} ${14} ${15}" -v b="$pos" 'BEGIN { split(a, x, " "); split(b, y, " ");
    for (i = 1; i <= 3; ++i) if ((x[i] - y[i]) ^ 2 > 1e-6 * (1 + y[i] ^ 2)) exit 1 }' &&
    grep -qE '"sy:projection": "perspective yfov [0-9.]+"' "$TMP/meta_info.out" ||
    fail "sy info m.exr: camera_to_world '$c2w' (camera at '$pos') or projection: $(grep projection "$TMP/meta_info.out")"
run meta_png "$SY" render demo -b pathtracer --spp 3 -w 40 -h 30 -o "$TMP/meta/m.png"
for kv in 'sy:renderer' 'sy:backend.pathtracer' 'sy:samples.3' 'sy:source.demo'; do
    tr '\0' '.' < "$TMP/meta/m.png" | grep -qa -- "$kv" || fail "the PNG's text chunks lack $kv"
done
# sy info reads them back from the PNG (it refused the PNG sy render wrote, though README promised it)
run meta_info_png "$SY" info "$TMP/meta/m.png"
for kv in '"sy:renderer": "Switchyard ' '"sy:backend": "pathtracer"' '"sy:samples": "3"' '"sy:source": "demo"' \
          '"sy:size": "40x30"' '"width": 40,' '"height": 30,'; do
    [ "$rc" -eq 0 ] && grep -qF -- "$kv" "$TMP/meta_info_png.out" ||
        fail "sy info m.png: status $rc, lacks $kv: $(cat "$TMP/meta_info_png.out" "$TMP/meta_info_png.err")"
done
cp "$TMP/meta/m.png" "$TMP/meta/png_named.exr" # by content, whatever the name
run meta_info_png2 "$SY" info "$TMP/meta/png_named.exr"
grep -qF '"sy:backend": "pathtracer"' "$TMP/meta_info_png2.out" || fail "sy info of a PNG named .exr: $(cat "$TMP/meta_info_png2.err")"
head -c 60 "$TMP/meta/m.png" > "$TMP/meta/cut.png" # a truncated PNG: an error naming it, never a crash
run meta_info_cut "$SY" info "$TMP/meta/cut.png"
[ "$rc" -eq 1 ] && grep -q "cut.png: not a readable PNG" "$TMP/meta_info_cut.err" ||
    fail "sy info of a truncated PNG: status $rc, $(cat "$TMP/meta_info_cut.err")"

# garbage bytes named bad.gltf
mkdir -p "$TMP/in" "$TMP/o_garbage"
printf 'this is not glTF \000\377\376 {{{' >"$TMP/in/bad.gltf"
expect_error garbage bad.gltf "$TMP/o_garbage" "$SY" render "$TMP/in/bad.gltf" -b whitted -o "$TMP/o_garbage/x.png"
mkdir -p "$TMP/o_garbage_info"
expect_error garbage_info bad.gltf "$TMP/o_garbage_info" "$SY" info "$TMP/in/bad.gltf"

# a missing input file
mkdir -p "$TMP/o_missing"
expect_error missing no_such_scene.gltf "$TMP/o_missing" "$SY" render "$TMP/in/no_such_scene.gltf" -b whitted \
    -o "$TMP/o_missing/x.png"

# --variant (glTF KHR_materials_variants): refused for a scene that is not glTF, and for a variant
# the file does not have (the message lists what it has: Box has none)
mkdir -p "$TMP/o_variant"
expect_error variant_demo "material variants are a glTF extension" "$TMP/o_variant" "$SY" render demo --variant red \
    -b whitted -w 16 -h 16 -o "$TMP/o_variant/x.png"
if [ -f "$BOX" ]; then
    expect_error variant_none "the file has no KHR_materials_variants" "$TMP/o_variant" "$SY" render "$BOX" \
        --variant red -b whitted -w 16 -h 16 -o "$TMP/o_variant/x.png"
fi

# unknown back-end, output in a missing directory, unknown extension (on the built-in scene)
mkdir -p "$TMP/o_backend"
expect_error backend no-such-backend "$TMP/o_backend" "$SY" render demo -b no-such-backend -w 16 -h 16 \
    -o "$TMP/o_backend/x.png"
grep -q whitted "$TMP/backend.err" || fail "unknown back-end: the message does not list the available ones"
mkdir -p "$TMP/o_nodir"
expect_error nodir "$TMP/o_nodir/missing_dir/x.png" "$TMP/o_nodir" env SY_TEST_PHASES="$TMP/o_nodir.phases" "$SY" render \
    demo -b whitted -w 64 -h 64 -o "$TMP/o_nodir/missing_dir/x.png"
grep -q "missing_dir/x.png" "$TMP/nodir.err" && ! grep -qx tiles "$TMP/o_nodir.phases" 2>/dev/null ||
    fail "output in a missing directory: found only after rendering (phases: $(cat "$TMP/o_nodir.phases" 2>/dev/null))"
# an output folder sy may not write to is refused before anything is rendered (it was found only
# after the render); the phases sy announces (SY_TEST_PHASES, apps/sy/sy_testpoint.h) show no tile
# rendered. As root every folder is writable, so sy runs as nobody there (setpriv).
mkdir -p "$TMP/o_ro" "$TMP/ro_phases"
chmod 555 "$TMP/o_ro"
chmod 777 "$TMP/ro_phases" # the phases file, written by sy as whichever user runs it
as_user=()
[ "$(id -u)" -eq 0 ] && command -v setpriv >/dev/null && as_user=(setpriv --reuid=65534 --regid=65534 --clear-groups)
if [ "$(id -u)" -ne 0 ] || [ ${#as_user[@]} -gt 0 ]; then
    rm -f "$TMP/ro_phases/p"
    expect_error readonly "$TMP/o_ro/x.png" "$TMP/o_ro" env SY_TEST_PHASES="$TMP/ro_phases/p" "${as_user[@]}" "$SY" render \
        demo -b whitted -w 64 -h 64 -o "$TMP/o_ro/x.png"
    grep -q "Permission denied" "$TMP/readonly.err" || fail "an unwritable folder: the reason is not given: $(cat "$TMP/readonly.err")"
    ! grep -qx tiles "$TMP/ro_phases/p" 2>/dev/null || fail "an unwritable output folder was found only after rendering"
else
    echo "note: the unwritable-folder check needs a non-root user or setpriv (skipped)"
fi
chmod 755 "$TMP/o_ro"
mkdir -p "$TMP/o_ext"
expect_error extension x.bmp "$TMP/o_ext" "$SY" render demo -b whitted -w 16 -h 16 -o "$TMP/o_ext/x.bmp"

# benchmarks on small sizes: exit status and result lines only (speed is not tested here)
run_ok "bench sync" bench_sync "$SY" bench sync --nodes 200 --tris 48 --repeats 5
grep -Eq 'ratio full / incremental +[0-9.]+ x' "$TMP/bench_sync.out" || fail "bench sync: no ratio line"
# every part (each back-end, on the generated scene and through a .glb) re-placed exactly 1 node
n_parts=$(grep -c 'translate from scratch' "$TMP/bench_sync.out")
[ "$n_parts" -ge 2 ] && [ "$(grep -Ec 'placements recomputed +1$' "$TMP/bench_sync.out")" -eq "$n_parts" ] &&
    [ "$(grep -c ', through a .glb$' "$TMP/bench_sync.out")" -eq $((n_parts / 2)) ] ||
    fail "bench sync: a leaf move did not re-place exactly 1 in every part, or no part through a .glb"
grep -Eq '^sy bench sync: 200 nodes' "$TMP/bench_sync.out" || fail "bench sync: wrong node count"
cat "$TMP/bench_sync.out"
run_ok "bench anim" bench_anim "$SY" bench anim --tris 2000 --nodes 30 --repeats 3
grep -Eq 'skinned_tube.glb loaded by sy_gltf_load .* 16 channels; 3 frames' "$TMP/bench_anim.out" ||
    fail "bench anim: the skinned .glb did not load with its 16 channels"
grep -Eq 'animated_nodes.glb loaded by sy_gltf_load .* 60 channels; 3 frames' "$TMP/bench_anim.out" ||
    fail "bench anim: the nodes' .glb did not load with its 60 channels"
# the skinned scene's mirror deformed something each frame (a time above 0): the skin came through the file
grep -m1 'of which deformation (sy_deform_primitive)' "$TMP/bench_anim.out" | grep -Eq ' 0\.0*[1-9][0-9]* ms| [1-9][0-9]*\.[0-9]+ ms' ||
    fail "bench anim: the skinned mesh was not deformed"
[ "$(grep -Ec 'from scratch \(new context \+ first sync\) +[0-9.]+ ms +frame / scratch [0-9.]+' "$TMP/bench_anim.out")" -ge 2 ] ||
    fail "bench anim: no frame / scratch ratio per scene"
cat "$TMP/bench_anim.out"
run_ok "bench rays" bench_rays "$SY" bench rays demo -w 64 -h 64 --repeats 2
grep -Eq 'raw Embree rtcIntersect1 +[0-9.]+ Mrays/s' "$TMP/bench_rays.out" || fail "bench rays: no raw line"
grep -Eq 'whitted back-end \(primary\) +[0-9.]+ Mrays/s' "$TMP/bench_rays.out" || fail "bench rays: no ours line"
grep -Eq 'overhead +-?[0-9.]+ %' "$TMP/bench_rays.out" || fail "bench rays: no overhead (ratio) line"
cat "$TMP/bench_rays.out"
run_ok "bench limit" bench_limit "$SY" bench limit demo -w 24 -h 16 --repeats 1
[ "$(grep -Ec '^  rtcIntersect(1|4|8|16|1M) / rtcOccluded(1|4|8|16|1M) +[0-9.]+ Mrays/s .* path tracer = +[0-9.]+ %' \
    "$TMP/bench_limit.out")" -eq 5 ] || fail "bench limit: not one share line per raw Embree form"
grep -q 'answers differ' "$TMP/bench_limit.out" && fail "bench limit: the replay does not reproduce the frame's answers"
cat "$TMP/bench_limit.out"
mkdir -p "$TMP/o_limit"
expect_error bench_limit_spp "--spp: '0' is not in 1..1024" "$TMP/o_limit" "$SY" bench limit demo --spp 0
run_ok "bench memory" bench_memory "$SY" bench memory --tris 2000 -w 16 -h 16
[ "$(grep -Ec '^  peak RSS +[0-9.]+ MB +[0-9.]+ bytes/triangle' "$TMP/bench_memory.out")" -eq 4 ] ||
    fail "bench memory: not one peak line per ray tracer, generated and from the .glb"
for b in whitted pathtracer; do
    grep -Eq "^$b, generated: 2048 triangles" "$TMP/bench_memory.out" &&
        grep -Eq "^$b, from the .glb: 2048 triangles" "$TMP/bench_memory.out" &&
        grep -Eq "^$b: peak RSS from the .glb / generated [0-9.]+x" "$TMP/bench_memory.out" ||
        fail "bench memory: $b not measured generated and from the .glb, with their ratio"
done
grep -Eq '^  Embree peak .* [0-9.]+ bytes/triangle' "$TMP/bench_memory.out" || fail "bench memory: no Embree line"
run_ok "bench memory --glb" bench_memory_glb "$SY" bench memory --tris 2000 -b whitted --glb -w 16 -h 16
grep -Eq '^whitted, from the .glb: 2048 triangles' "$TMP/bench_memory_glb.out" &&
    ! grep -q 'generated:' "$TMP/bench_memory_glb.out" || fail "bench memory --glb: not the file alone, 2048 triangles"
run bench_memory_bad "$SY" bench memory -b raster --tris 2000
[ "$rc" -eq 1 ] && grep -q 'expected one of the ray tracers' "$TMP/bench_memory_bad.err" ||
    fail "bench memory -b raster: status $rc, $(cat "$TMP/bench_memory_bad.err")"
cat "$TMP/bench_memory.out"
# bench instances: the generated scene, then the same written to a .glb with normals and to one of
# positions and indices alone, each loaded back as sy render loads it (4 placements of one shared
# mesh of 200 triangles); one row per picture back-end and scene, one per back-end in the summary;
# the temporary files removed
run_ok "bench instances" bench_instances "$SY" bench instances --nodes 4 --tris 200 -w 32 -h 24 --repeats 2
for n in yes no; do
    grep -Eq "^  file with(out)? normals: .*\.glb, [0-9.]+ MB, written and loaded by sy_cli_load in [0-9.]+ s: 4 placements of 1 mesh, 800 triangles, normals $n\$" \
        "$TMP/bench_instances.out" || fail "bench instances: no file read back with normals $n"
done
nb=$("$SY" backends | grep -Evc ' (analysis|remote)( |$)')
for sc in generated "file with normals" "file without normals"; do
    [ "$(grep -Ec "^  [a-z]+ +$sc +[0-9.]+ s +[0-9.]+ ms +[0-9.]+ ms " "$TMP/bench_instances.out")" -eq "$nb" ] ||
        fail "bench instances: not one row per back-end ($nb) for the scene '$sc'"
done
[ "$(grep -Ec '^  [a-z]+ +[0-9.]+x +[0-9.]+x +[0-9.]+x +[0-9.]+x$' "$TMP/bench_instances.out")" -eq "$nb" ] ||
    fail "bench instances: not one summary row per back-end"
for f in $(grep -Eo '/[^ ,]*\.glb' "$TMP/bench_instances.out"); do
    [ ! -e "$f" ] || fail "bench instances: $f left behind"
done
cat "$TMP/bench_instances.out"
# bench governor: one row per picture back-end of the registry (no analysis or remote class), each
# with its numbers; a bad budget is a usage error
run_ok "bench governor" bench_governor "$SY" bench governor demo --frames 4 -w 32 -h 24
for b in $("$SY" backends | grep -Ev ' (analysis|remote)( |$)' | cut -d' ' -f1); do
    grep -Eq "^  $b +[0-9.]+ +[0-9.]+ +[0-9.]+ +[0-9.]+ +[0-9.]+ +[0-9.]+[ !] +[0-9]+% +[0-9.]+ +[0-9]+% " \
        "$TMP/bench_governor.out" || fail "bench governor: no row for back-end $b"
done
! grep -Eq '^  coverage ' "$TMP/bench_governor.out" || fail "bench governor: an analysis back-end was timed"
cat "$TMP/bench_governor.out"
# without SCENE: the generated height field, then the same through a .glb (as many rows each)
run_ok "bench governor (generated)" bench_governor_gen "$SY" bench governor --frames 2 -w 16 -h 12 --tris 200
awk '/^generated height field \(200 triangles\)/ {s = 1} /^the same through a .glb \(200 triangles\)/ {s = 2}
     /^  [a-z]+ +[0-9.]+ +[0-9.]+ / && s {n[s]++} END {exit !(n[1] > 0 && n[1] == n[2])}' \
    "$TMP/bench_governor_gen.out" || fail "bench governor: not as many rows for the height field through a .glb"
run bench_governor_bad "$SY" bench governor demo --budget 0
[ "$rc" -eq 2 ] && grep -q -- "--budget: '0' is not in 1..10000" "$TMP/bench_governor_bad.err" ||
    fail "bench governor --budget 0: status $rc, $(cat "$TMP/bench_governor_bad.err")"
# --max-memory: a scene over the ray tracer's memory limit is refused with the sizes, not killed
run max_memory "$SY" render demo -b whitted --max-memory 1 -w 16 -h 16 -o "$TMP/max_memory.png"
[ "$rc" -eq 1 ] && grep -Eq 'memory limit of 1\.0 MB' "$TMP/max_memory.err" && [ ! -e "$TMP/max_memory.png" ] ||
    fail "--max-memory 1: status $rc, $(cat "$TMP/max_memory.err")"
run max_memory_ok "$SY" render demo -b whitted --max-memory 256 -w 16 -h 16 -o "$TMP/max_memory.png"
[ "$rc" -eq 0 ] || fail "--max-memory 256: status $rc, $(cat "$TMP/max_memory_ok.err")"
if has raster; then
    run max_memory_raster "$SY" render demo -b raster --max-memory 256 -w 16 -h 16 -o "$TMP/max_memory.png"
    [ "$rc" -eq 1 ] && grep -q 'has no memory limit' "$TMP/max_memory_raster.err" ||
        fail "--max-memory with -b raster: status $rc, $(cat "$TMP/max_memory_raster.err")"
fi

# demo
run_ok "demo" demo "$SY" demo -o "$TMP/demo" -w 64 -h 36
if [ -f "$TMP/demo/demo_whitted.png" ] && magic "$TMP/demo/demo_whitted.png" 89504e470d0a1a0a; then
    [ "$(u32be "$TMP/demo/demo_whitted.png" 16)x$(u32be "$TMP/demo/demo_whitted.png" 20)" = 64x36 ] ||
        fail "demo: PNG is not 64x36"
else
    fail "demo: demo_whitted.png missing or not a PNG"
fi
[ -f "$TMP/demo/demo_whitted.exr" ] && magic "$TMP/demo/demo_whitted.exr" 762f3101 ||
    fail "demo: demo_whitted.exr missing or not an OpenEXR file"

# stereo layouts and overlays on the demo scene (sizes per layout, files per eye, bad parameters)
mkdir -p "$TMP/stereo"
run st_sbs "$SY" render demo -b whitted -w 40 -h 30 --stereo sbs -o "$TMP/stereo/sbs.png"
[ "$rc" -eq 0 ] && [ "$(u32be "$TMP/stereo/sbs.png" 16)x$(u32be "$TMP/stereo/sbs.png" 20)" = 80x30 ] ||
    fail "stereo sbs: expected an 80x30 PNG (status $rc: $(cat "$TMP/st_sbs.err"))"
run st_tb "$SY" render demo -b whitted -w 40 -h 30 --stereo tb -o "$TMP/stereo/tb.png"
[ "$rc" -eq 0 ] && [ "$(u32be "$TMP/stereo/tb.png" 16)x$(u32be "$TMP/stereo/tb.png" 20)" = 40x60 ] ||
    fail "stereo tb: expected a 40x60 PNG"
run st_ana "$SY" render demo -b whitted -w 40 -h 30 --stereo anaglyph -o "$TMP/stereo/ana.png"
[ "$rc" -eq 0 ] && [ "$(u32be "$TMP/stereo/ana.png" 16)x$(u32be "$TMP/stereo/ana.png" 20)" = 40x30 ] ||
    fail "stereo anaglyph: expected a 40x30 PNG"
run st_sep "$SY" render demo -b whitted -w 40 -h 30 --stereo separate -o "$TMP/stereo/eye.exr"
[ "$rc" -eq 0 ] && [ -f "$TMP/stereo/eye_left.exr" ] && [ -f "$TMP/stereo/eye_right.exr" ] &&
    [ ! -e "$TMP/stereo/eye.exr" ] || fail "stereo separate: expected eye_left.exr and eye_right.exr only"
if [ -f "$TMP/stereo/eye_left.exr" ] && cmp -s "$TMP/stereo/eye_left.exr" "$TMP/stereo/eye_right.exr"; then
    fail "stereo separate: both eyes are identical"
fi
mkdir -p "$TMP/o_stereo"
expect_error stereo_sep eye-sep "$TMP/o_stereo" "$SY" render demo -b whitted -w 8 -h 8 --stereo sbs --eye-sep -0.1 \
    -o "$TMP/o_stereo/x.png"
expect_error stereo_zp zero-parallax "$TMP/o_stereo" "$SY" render demo -b whitted -w 8 -h 8 --stereo sbs \
    --zero-parallax 0 -o "$TMP/o_stereo/x.png"
expect_error stereo_mode wobble "$TMP/o_stereo" "$SY" render demo -b whitted -w 8 -h 8 --stereo wobble \
    -o "$TMP/o_stereo/x.png"
expect_error overlay_missing no_such_overlay.gltf "$TMP/o_stereo" "$SY" render demo -b whitted -w 8 -h 8 \
    --overlay "$TMP/in/no_such_overlay.gltf" -o "$TMP/o_stereo/x.png"
expect_error overlay_backend nosuchbackend "$TMP/o_stereo" "$SY" render demo -b whitted -w 8 -h 8 \
    --overlay "$TMP/in/bad.gltf:nosuchbackend" -o "$TMP/o_stereo/x.png"

# ---------------------------------------------------------------- with test data
if [ -f "$BOX" ] && [ -f "$GLB" ]; then
    run_ok "info Box.gltf" info "$SY" info "$BOX"
    # one layout for every format: format, file_counts (the file's own, indented by four spaces),
    # loaded (on one line), bounds, warning_count, warnings
    grep -qxF '  "format": "gltf",' "$TMP/info.out" || fail "info Box.gltf: no format line"
    for kv in '"meshes": 1,' '"primitives": 1,' '"triangles": 12,' '"materials": 1,'; do
        grep -qxF "    $kv" "$TMP/info.out" || fail "info Box.gltf: no file_counts line '$kv'"
    done
    grep -qF '"loaded": {"nodes": 2, "meshes": 1, "primitives": 1, "triangles": 12, "materials": 1,' "$TMP/info.out" ||
        fail "info Box.gltf: loaded counts: $(grep loaded "$TMP/info.out")"
    grep -qF '"bounds": {"min": [-0.5, -0.5, -0.5], "max": [0.5, 0.5, 0.5]}' "$TMP/info.out" ||
        fail "info Box.gltf: bounds are not +-0.5: $(grep bounds "$TMP/info.out")"
    head -c 1 "$TMP/info.out" | grep -q '{' && tail -n 1 "$TMP/info.out" | grep -qx '}' ||
        fail "info Box.gltf: output is not one JSON object"
    grep -qF '"extensions": {"used": [], "supported": [], "unsupported": []},' "$TMP/info.out" &&
        grep -qF '"variants": [],' "$TMP/info.out" || fail "info Box.gltf: extensions / variants not empty"
    BOXANIM="$DATA/gltf/BoxAnimated/glTF-Binary/BoxAnimated.glb"
    if [ -f "$BOXANIM" ]; then
        run_ok "info BoxAnimated.glb" info_anim "$SY" info "$BOXANIM"
        grep -qxF '    "animations": 1' "$TMP/info_anim.out" || fail "info BoxAnimated.glb: not 1 animation"
        grep -qF '{"index": 0, "name": null, "start": 0, "duration": 3.70832992, "loop": false, "channels": 2, "samplers": 2}' \
            "$TMP/info_anim.out" || fail "info BoxAnimated.glb: clips: $(grep -A2 clips "$TMP/info_anim.out")"
        # the scene clock: --at 0 is the static load; two times differ; bad values are usage errors
        mkdir -p "$TMP/anim"
        run_ok "render BoxAnimated" anim_static "$SY" render "$BOXANIM" -w 64 -h 48 -o "$TMP/anim/static.exr"
        run_ok "render BoxAnimated --at 0" anim_0 "$SY" render "$BOXANIM" -w 64 -h 48 --at 0 -o "$TMP/anim/t0.exr"
        run_ok "render BoxAnimated --at 0.5" anim_05 "$SY" render "$BOXANIM" -w 64 -h 48 --at 0.5 -o "$TMP/anim/t05.exr"
        run_ok "render BoxAnimated --at 2 --clip 0" anim_2 "$SY" render "$BOXANIM" -w 64 -h 48 --at 2 --clip 0 \
            -o "$TMP/anim/t2.exr"
        if [ -n "$EXR_EQUAL" ]; then
            exr_same "render BoxAnimated: --at 0 differs from the static load" "$TMP/anim/static.exr" "$TMP/anim/t0.exr"
            exr_differ "render BoxAnimated: --at 0.5 and --at 2 give the same image" "$TMP/anim/t05.exr" "$TMP/anim/t2.exr"
        else
            echo "skip: --at pixel checks (no exr_equal given)"
        fi
        # a glTF file's clips are alternatives: without --clip the first one plays (the Fox's Survey,
        # Walk and Run drive the same joints; before, all three played and the last one won)
        FOX="$DATA/gltf/Fox/glTF/Fox.gltf"
        if [ -f "$FOX" ] && [ -n "$EXR_EQUAL" ]; then
            run_ok "render Fox --at 1.5" fox_def "$SY" render "$FOX" -w 48 -h 36 --at 1.5 -o "$TMP/anim/fox.exr"
            grep -qF "playing clip 0 (Survey) of 3; --clip NAME|INDEX plays another" "$TMP/fox_def.err" ||
                fail "render Fox: no note naming the clip played: $(cat "$TMP/fox_def.err")"
            run_ok "render Fox --at 1.5 --clip 0" fox_0 "$SY" render "$FOX" -w 48 -h 36 --at 1.5 --clip 0 \
                -o "$TMP/anim/fox0.exr"
            run_ok "render Fox --at 1.5 --clip Run" fox_run "$SY" render "$FOX" -w 48 -h 36 --at 1.5 --clip Run \
                -o "$TMP/anim/foxrun.exr"
            exr_same "render Fox: without --clip the image is not clip 0's" "$TMP/anim/fox.exr" "$TMP/anim/fox0.exr"
            exr_differ "render Fox: clip 0 and clip Run give the same image" "$TMP/anim/fox.exr" "$TMP/anim/foxrun.exr"
        else
            echo "skip: the default clip (no Fox sample or no exr_equal)"
        fi
        for bad in -1 nan inf 1e99x; do
            run anim_bad "$SY" render "$BOXANIM" -w 16 -h 16 --at "$bad" -o "$TMP/anim/bad.png"
            [ "$rc" -eq 2 ] && grep -qF -- "--at: '$bad'" "$TMP/anim_bad.err" ||
                fail "--at $bad: status $rc (want 2), $(cat "$TMP/anim_bad.err")"
        done
        run anim_clip "$SY" render "$BOXANIM" -w 16 -h 16 --clip walk -o "$TMP/anim/bad.png"
        [ "$rc" -eq 2 ] && grep -qF -- "--clip walk: no animation named 'walk' (available: 0:(unnamed))" "$TMP/anim_clip.err" ||
            fail "--clip walk: status $rc (want 2), $(cat "$TMP/anim_clip.err")"
        run anim_clip1 "$SY" render "$BOXANIM" -w 16 -h 16 --clip 1 -o "$TMP/anim/bad.png"
        [ "$rc" -eq 2 ] && grep -qF -- "--clip 1: no animation at index '1'" "$TMP/anim_clip1.err" ||
            fail "--clip 1: status $rc (want 2), $(cat "$TMP/anim_clip1.err")"
        [ ! -e "$TMP/anim/bad.png" ] || fail "a refused --at / --clip left an image"
        run anim_noclip "$SY" render "$BOX" -w 16 -h 16 --clip 0 -o "$TMP/anim/bad.png"
        [ "$rc" -eq 2 ] && grep -qF -- "--clip 0: the scene has no animations" "$TMP/anim_noclip.err" ||
            fail "--clip on Box: status $rc (want 2), $(cat "$TMP/anim_noclip.err")"
    else
        echo "skip: info BoxAnimated.glb ($BOXANIM absent)"
    fi

    mkdir -p "$TMP/o_trunc"
    head -c 100 "$GLB" >"$TMP/in/truncated.glb"
    expect_error truncated truncated.glb "$TMP/o_trunc" "$SY" render "$TMP/in/truncated.glb" -b whitted \
        -o "$TMP/o_trunc/x.png"
    mkdir -p "$TMP/o_trunc_exr"
    expect_error truncated_exr truncated.glb "$TMP/o_trunc_exr" "$SY" render "$TMP/in/truncated.glb" -b whitted \
        -o "$TMP/o_trunc_exr/x.exr"
    mkdir -p "$TMP/o_box_backend"
    expect_error box_backend nosuch "$TMP/o_box_backend" "$SY" render "$BOX" -b nosuch -o "$TMP/o_box_backend/x.png"
else
    missing="$missing $BOX $GLB"
fi

if [ -f "$CORNELL" ]; then
    # layered hybrid rendering: path-traced Cornell box under a rasterised overlay, depth-composited
    if [ -f "$BOX" ] && has raster; then
        mkdir -p "$TMP/hybrid"
        run hybrid "$SY" render "$CORNELL" -b pathtracer --spp 2 -w 32 -h 32 --overlay "$BOX:raster" \
            --composite depth -o "$TMP/hybrid/h.exr"
        [ "$rc" -eq 0 ] && magic "$TMP/hybrid/h.exr" 762f3101 ||
            fail "hybrid pathtracer + raster overlay: status $rc: $(cat "$TMP/hybrid.err")"
    fi
    # coverage (culling service): the 8 Cornell objects, most pixels first, pixel counts adding up
    run_ok "coverage" coverage "$SY" coverage "$CORNELL" -w 128 -h 128
    [ "$(grep -c '"node":' "$TMP/coverage.out")" = 8 ] || fail "coverage: expected the 8 Cornell objects"
    grep -q '"name": "light"' "$TMP/coverage.out" || fail "coverage: the light is not listed"
    px=($(grep -o '"pixels": [0-9]*' "$TMP/coverage.out" | grep -o '[0-9]*$'))
    total=$(grep -o '"covered_pixels": [0-9]*' "$TMP/coverage.out" | grep -o '[0-9]*$')
    sum=0
    prev=999999999
    for p in "${px[@]}"; do
        sum=$((sum + p))
        [ "$p" -le "$prev" ] || fail "coverage: objects not sorted by pixels"
        prev=$p
    done
    [ "$sum" = "$total" ] && [ "$total" -gt 0 ] && [ "$total" -le 16384 ] || fail "coverage: pixel counts do not add up"

    mkdir -p "$TMP/render"
    run_ok "render cornell png" render_png "$SY" render "$CORNELL" -b whitted -w 96 -h 96 -o "$TMP/render/cornell.png"
    if [ -f "$TMP/render/cornell.png" ] && magic "$TMP/render/cornell.png" 89504e470d0a1a0a; then
        [ "$(u32be "$TMP/render/cornell.png" 16)x$(u32be "$TMP/render/cornell.png" 20)" = 96x96 ] ||
            fail "render cornell: PNG is not 96x96"
    else
        fail "render cornell: no PNG written"
    fi
    run_ok "render cornell exr" render_exr "$SY" render "$CORNELL" -b whitted -w 64 -o "$TMP/render/cornell.exr"
    [ -f "$TMP/render/cornell.exr" ] && magic "$TMP/render/cornell.exr" 762f3101 || fail "render cornell: no EXR written"
    # exactly the two outputs, no temporary files
    [ "$(ls -A "$TMP/render" | sort | tr '\n' ' ')" = "cornell.exr cornell.png " ] ||
        fail "render cornell: unexpected files: $(ls -A "$TMP/render")"
    # an existing output stays untouched when a later render fails
    cp "$TMP/render/cornell.png" "$TMP/in/before.png"
    run render_fail "$SY" render "$TMP/in/bad.gltf" -b whitted -o "$TMP/render/cornell.png"
    [ "$rc" -ne 0 ] && cmp -s "$TMP/in/before.png" "$TMP/render/cornell.png" ||
        fail "a failed render changed an existing output file"
    echo "ok: render cornell -> $(cat "$TMP/render_png.out")"
else
    missing="$missing $CORNELL"
fi

# ---------------------------------------------------------------- path tracer (issue 3), demo scene
grep -q '^pathtracer depth progressive tiles' "$TMP/backends.out" || fail "sy backends does not list pathtracer"
mkdir -p "$TMP/pt" "$TMP/o_ptenv"
run pt_spp "$SY" render demo -b pathtracer --spp 2 -w 32 -h 24 --aov -o "$TMP/pt/pt.exr"
[ "$rc" -eq 0 ] && magic "$TMP/pt/pt.exr" 762f3101 && grep -q '2 samples per pixel' "$TMP/pt_spp.out" &&
    grep -aq 'albedo.R' "$TMP/pt/pt.exr" && grep -aq 'indirect.B' "$TMP/pt/pt.exr" ||
    fail "pathtracer --spp 2 --aov: status $rc, $(cat "$TMP/pt_spp.err")"
# --seed: the same seed twice the same image, another seed other noise (the default is 0)
if [ -n "$EXR_EQUAL" ]; then
    run_ok "pathtracer --seed 0" pt_seed0 "$SY" render demo -b pathtracer --spp 1 -w 24 -h 16 -o "$TMP/pt/s0.exr"
    run_ok "pathtracer --seed 0 given" pt_seed0b "$SY" render demo -b pathtracer --spp 1 -w 24 -h 16 --seed 0 -o "$TMP/pt/s0b.exr"
    run_ok "pathtracer --seed 7" pt_seed7 "$SY" render demo -b pathtracer --spp 1 -w 24 -h 16 --seed 7 -o "$TMP/pt/s7.exr"
    exr_same "render --seed 0 differs from the default seed" "$TMP/pt/s0.exr" "$TMP/pt/s0b.exr"
    exr_differ "render --seed 7 gives the default seed's noise" "$TMP/pt/s0.exr" "$TMP/pt/s7.exr"
fi
run pt_time "$SY" render demo -b pathtracer --time 0.3 -w 16 -h 16 --background 0.5,0.5,0.5 -o "$TMP/pt/pt.png"
[ "$rc" -eq 0 ] && magic "$TMP/pt/pt.png" 89504e47 || fail "pathtracer --time: status $rc, $(cat "$TMP/pt_time.err")"
expect_error pt_env bad.gltf "$TMP/o_ptenv" "$SY" render demo -b pathtracer --spp 1 -w 8 -h 8 \
    --env "$TMP/in/bad.gltf" -o "$TMP/o_ptenv/x.exr"

# ---------------------------------------------------------------- path tracer display filters (issue 7)
mkdir -p "$TMP/o_ptfilter"
run pt_filter "$SY" render demo -b pathtracer --spp 4 -w 32 -h 24 --filter pixel --threshold 0.02 -o "$TMP/pt/filtered.png"
[ "$rc" -eq 0 ] && magic "$TMP/pt/filtered.png" 89504e47 &&
    grep -q '^filter pixel: threshold 0.02, .*last pass at 4 spp.*NaN/Inf: 0 pixels' "$TMP/pt_filter.out" ||
    fail "pathtracer --filter pixel: status $rc, $(cat "$TMP/pt_filter.out" "$TMP/pt_filter.err")"
# a filter that runs every frame has no pass schedule: its report says nothing of one (it said
# "last pass at 0 spp, mean blend 0.000" before)
run pt_atrous "$SY" render demo -b pathtracer --spp 4 -w 32 -h 24 --filter atrous -o "$TMP/pt/atrous.png"
[ "$rc" -eq 0 ] && grep -q '^filter atrous: threshold .*ms, NaN/Inf: 0 pixels' "$TMP/pt_atrous.out" ||
    fail "pathtracer --filter atrous: status $rc, $(cat "$TMP/pt_atrous.out" "$TMP/pt_atrous.err")"
expect_error pt_filter_bad bogus "$TMP/o_ptfilter" "$SY" render demo -b pathtracer --spp 1 -w 8 -h 8 \
    --filter bogus -o "$TMP/o_ptfilter/x.png"
run pt_radiance "$SY" render demo -b pathtracer --spp 4 -w 32 -h 24 --filter radiance --params rf_unbiased=1 \
    -o "$TMP/pt/radiance.png"
[ "$rc" -eq 0 ] && magic "$TMP/pt/radiance.png" 89504e47 &&
    grep -q '^filter radiance: threshold 0.01, .*last pass at 4 spp.*NaN/Inf: 0 pixels' "$TMP/pt_radiance.out" ||
    fail "pathtracer --filter radiance: status $rc, $(cat "$TMP/pt_radiance.out" "$TMP/pt_radiance.err")"
expect_error pt_filter_radiance rf_kernel "$TMP/o_ptfilter" "$SY" render demo -b pathtracer --spp 1 -w 8 -h 8 \
    --filter radiance --params rf_kernel=box -o "$TMP/o_ptfilter/x.png"
expect_error pt_filter_threshold threshold "$TMP/o_ptfilter" "$SY" render demo -b pathtracer --spp 1 -w 8 -h 8 \
    --filter pixel --threshold -1 -o "$TMP/o_ptfilter/x.png"
expect_error pt_filter_sigma "sigma_s = 0: must be a finite value > 0" "$TMP/o_ptfilter" "$SY" render demo \
    -b pathtracer --spp 1 -w 8 -h 8 --filter pixel --params sigma_s=0 -o "$TMP/o_ptfilter/x.png"

# ---------------------------------------------------------------- loaders: confinement, warnings (issue 14)
# a buffer URI leaving the model's folder is refused naming the file, the URI and --allow-path;
# --allow-path admits the folder
mkdir -p "$TMP/esc/model" "$TMP/o_esc"
printf '\000\000\000\000\000\000\000\000\000\000\000\000\000\000\200\077\000\000\000\000\000\000\000\000\000\000\000\000\000\000\200\077\000\000\000\000' \
    >"$TMP/esc/outside.bin"
cat >"$TMP/esc/model/esc.gltf" <<'GLTF'
{"asset":{"version":"2.0"},"buffers":[{"uri":"../outside.bin","byteLength":36}],
 "bufferViews":[{"buffer":0,"byteLength":36}],
 "accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}],
 "meshes":[{"primitives":[{"attributes":{"POSITION":0}},{"attributes":{"POSITION":0},"mode":1}]}],
 "nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}],"scene":0}
GLTF
expect_error escape "'../outside.bin' resolves to" "$TMP/o_esc" "$SY" render "$TMP/esc/model/esc.gltf" -b whitted \
    -w 8 -h 8 -o "$TMP/o_esc/x.png"
grep -q -- "--allow-path" "$TMP/escape.err" || fail "escape: the error does not name --allow-path"
# allowed: renders, and the LINES primitive's odd vertex it drops is reported (file and item), exit 0
run allowed "$SY" render "$TMP/esc/model/esc.gltf" --allow-path "$TMP/esc" -b whitted -w 8 -h 8 -o "$TMP/esc/ok.png"
[ "$rc" -eq 0 ] && [ -s "$TMP/esc/ok.png" ] || fail "--allow-path: status $rc: $(cat "$TMP/allowed.err")"
grep -q "warning: $TMP/esc/model/esc.gltf: meshes\[0\].primitives\[1\]: LINES with 3 vertices (odd)" "$TMP/allowed.err" ||
    fail "the odd LINES vertex is not reported: $(cat "$TMP/allowed.err")"
# the log level (sy_log): -q keeps errors only, -v adds debug lines; before or after the command
run allowed_q "$SY" -q render "$TMP/esc/model/esc.gltf" --allow-path "$TMP/esc" -b whitted -w 8 -h 8 -o "$TMP/esc/ok.png"
[ "$rc" -eq 0 ] && [ ! -s "$TMP/allowed_q.err" ] || fail "sy -q: status $rc, stderr: $(cat "$TMP/allowed_q.err")"
run allowed_v "$SY" render "$TMP/esc/model/esc.gltf" --allow-path "$TMP/esc" -b whitted -w 8 -h 8 -o "$TMP/esc/ok.png" -v
[ "$rc" -eq 0 ] && grep -q "^sy: debug: $TMP/esc/model/esc.gltf: loaded in" "$TMP/allowed_v.err" &&
    grep -q "LINES with 3 vertices (odd)" "$TMP/allowed_v.err" || fail "sy ... -v: status $rc, stderr: $(cat "$TMP/allowed_v.err")"
grep -q "^sy: debug: " "$TMP/allowed.err" && fail "debug lines without -v: $(cat "$TMP/allowed.err")"
run quiet_error "$SY" --quiet render "$TMP/in/no_such_scene.gltf" -b whitted -o "$TMP/x.png"
[ "$rc" -eq 1 ] && grep -q "no_such_scene.gltf" "$TMP/quiet_error.err" || fail "sy --quiet hides an error: $(cat "$TMP/quiet_error.err")"
# --strict: the same warning is an error, nothing written
expect_error strict "--strict" "$TMP/o_esc" "$SY" render "$TMP/esc/model/esc.gltf" --allow-path "$TMP/esc" --strict \
    -b whitted -w 8 -h 8 -o "$TMP/o_esc/x.png"
expect_error allow_path_missing "--allow-path" "$TMP/o_esc" "$SY" render "$TMP/esc/model/esc.gltf" --allow-path \
    "$TMP/esc/no_such_dir" -b whitted -w 8 -h 8 -o "$TMP/o_esc/x.png"

# --- the world (issue 15): flags only fill sy_world_options; the library decides what they mean
mkdir -p "$TMP/world" "$TMP/o_world"
expect_error env_color_nan "--env-color" "$TMP/o_world" "$SY" render demo -b whitted -w 8 -h 8 --env-color 1,nan,0 \
    -o "$TMP/o_world/x.png"
expect_error env_intensity_neg "environment intensity" "$TMP/o_world" "$SY" render demo -b whitted -w 8 -h 8 \
    --env-intensity -1 -o "$TMP/o_world/x.png"
expect_error background_short "--background" "$TMP/o_world" "$SY" render demo -b whitted -w 8 -h 8 --background 1,2 \
    -o "$TMP/o_world/x.png"
# an EXR that is not a 2:1 lat-long map is refused, naming the file and the reason
run world_exr "$SY" render demo -b whitted -w 30 -h 20 -o "$TMP/world/notlatlong.exr"
[ "$rc" -eq 0 ] || fail "world: cannot write the test EXR: $(cat "$TMP/world_exr.err")"
expect_error env_not_latlong "not a lat-long map" "$TMP/o_world" "$SY" render demo -b whitted -w 8 -h 8 \
    --env "$TMP/world/notlatlong.exr" -o "$TMP/o_world/x.png"
grep -q "notlatlong.exr" "$TMP/env_not_latlong.err" || fail "env_not_latlong: the file is not named"
# a light out of range (negative intensity, cone beyond pi/2) is refused the same way for every
# back-end (core validates it once), naming the light and the value
bad_light() { # bad_light FILE LIGHT_JSON
    printf '{"asset":{"version":"2.0"},"extensionsUsed":["KHR_lights_punctual"],"extensions":{"KHR_lights_punctual":{"lights":[%s]}},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"extensions":{"KHR_lights_punctual":{"light":0}}}]}\n' "$2" >"$1"
}
bad_light "$TMP/world/neg_light.gltf" '{"type":"point","intensity":-2}'
bad_light "$TMP/world/wide_spot.gltf" '{"type":"spot","intensity":5,"spot":{"innerConeAngle":0.1,"outerConeAngle":2.0}}'
for b in "${PICTURE[@]}"; do
    expect_error "neg_light_$b" "KHR_lights_punctual.lights[0]" "$TMP/o_world" "$SY" render "$TMP/world/neg_light.gltf" \
        -b "$b" -w 8 -h 8 -o "$TMP/o_world/x.png"
    grep -q "intensity -2 must be" "$TMP/neg_light_$b.err" || fail "neg_light_$b: the value is not named: $(cat "$TMP/neg_light_$b.err")"
    expect_error "wide_spot_$b" "beyond pi/2" "$TMP/o_world" "$SY" render "$TMP/world/wide_spot.gltf" \
        -b "$b" -w 8 -h 8 -o "$TMP/o_world/x.png"
done
# a 2:1 map is taken (and lights every back-end; sy compare prints the table)
run world_exr2 "$SY" render demo -b whitted -w 32 -h 16 -o "$TMP/world/latlong.exr"
run env_ok "$SY" render demo -b "${PICTURE[-1]}" -w 16 -h 16 --env "$TMP/world/latlong.exr" --env-intensity 2 -o "$TMP/world/e.png"
[ "$rc" -eq 0 ] && [ -s "$TMP/world/e.png" ] || fail "--env with a 2:1 map: status $rc: $(cat "$TMP/env_ok.err")"
# sy compare: a table row per picture back-end, a PNG contact sheet; a bad sheet name is refused
run compare "$SY" compare demo -w 48 -h 32 --spp 4 -o "$TMP/world/sheet.png"
[ "$rc" -eq 0 ] || fail "sy compare: status $rc: $(cat "$TMP/compare.err")"
for b in "${PICTURE[@]}"; do
    grep -q "^$b " "$TMP/compare.out" || fail "sy compare: no row for $b: $(cat "$TMP/compare.out")"
done
grep -q "^coverage " "$TMP/compare.out" && fail "sy compare: the analysis back-end 'coverage' is compared"
magic "$TMP/world/sheet.png" 89504e47 || fail "sy compare: no PNG contact sheet"
expect_error compare_jpg "must end in .png" "$TMP/o_world" "$SY" compare demo -w 8 -h 8 -o "$TMP/o_world/x.jpg"
# default lighting: the Box (no lights of its own) is lit by the studio unless --no-default-light
if [ -f "$BOX" ]; then
    lum() { awk -v b="$1" '$1 == b {print $4}' "$2"; }
    run box_lit "$SY" compare "$BOX" -w 32 -h 24 --spp 4 --backends whitted -o "$TMP/world/box.png"
    run box_dark "$SY" compare "$BOX" -w 32 -h 24 --spp 4 --backends whitted --no-default-light -o "$TMP/world/box2.png"
    lit=$(lum whitted "$TMP/box_lit.out"); dark=$(lum whitted "$TMP/box_dark.out")
    awk -v a="$lit" -v b="$dark" 'BEGIN { exit !(a >= 0.05 && b == 0) }' ||
        fail "default lighting: Box mean luminance lit $lit (want >= 0.05), --no-default-light $dark (want 0)"
fi

if [ "$fails" -ne 0 ]; then
    echo "integration_cli: $fails failure(s)" >&2
    exit 1
fi
if [ -n "$missing" ]; then
    echo "SKIP: test data not found:$missing (the parts without test data passed)"
    exit 77
fi
echo "integration_cli: all checks passed"
rm -rf "$TMP"
exit 0
