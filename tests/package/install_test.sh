#!/usr/bin/env bash
# install_test.sh BUILD_DIR SOURCE_DIR TMP EXR_EQUAL [C_FLAGS] — install_consumer: the library as a
# program outside the tree sees it (issue 17).
#   1. cmake --install BUILD_DIR into TMP/prefix: headers in include/switchyard, the CMake package,
#      pkg-config files, sy (which runs from there: sy --version).
#   2. apps/examples configured as a project of its own with find_package(Switchyard COMPONENTS
#      ...) against that prefix, built, and run on a two-triangle glTF written here; render_gltf's
#      image equals the in-tree render_gltf's pixel for pixel (exr_equal).
#   3. render_gltf built with only `cc ... $(pkg-config --cflags --libs switchyard-rt
#      switchyard-formats)`, and again with --static (both lines of docs/EMBEDDING.md, on a static
#      and on a shared installation), run, the same pixels again.
#   4. Both render_gltf binaries (Whitted only) link no GL library (ldd: no libGL, libEGL,
#      libOpenGL, libGLX, libOSMesa, libglfw).
#   5. find_package of a component this installation lacks fails with a message naming it.
# Works for static and shared builds (BUILD_SHARED_LIBS) alike.
set -u
BUILD=$1 SRC=$2 TMP=$3 EXR_EQUAL=$4 CFLAGS_EXTRA=${5:-}
# Sanitizer builds: the consumer programs built here lack the tree's tests/support/sy_keep_loaded.c,
# whose ASan default options keep LeakSanitizer's tracer from crashing at exit on Mesa's dynamic TLS
# (docs/TESTING.md); they get the same option from the environment.
case $CFLAGS_EXTRA in *sanitize=address*) export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}intercept_tls_get_addr=0" ;; esac
fails=0
fail() { echo "FAIL: $*" >&2; fails=$((fails + 1)); }
rm -rf "$TMP"
mkdir -p "$TMP"
P=$TMP/prefix
cmake --install "$BUILD" --prefix "$P" >"$TMP/install.log" 2>&1 || { cat "$TMP/install.log"; echo "FAIL: cmake --install"; exit 1; }
for f in include/switchyard/sy_scene.h include/switchyard/sy_viewport.h include/switchyard/sy_gltf.h \
         lib/cmake/Switchyard/SwitchyardConfig.cmake lib/pkgconfig/switchyard.pc lib/pkgconfig/switchyard-core.pc \
         lib/pkgconfig/switchyard-rt.pc bin/sy; do
    [ -e "$P/$f" ] || fail "not installed: $f"
done
[ -e "$P/include/switchyard/sy_gltf_shim.h" ] && fail "an internal header (sy_gltf_shim.h) was installed"
for h in "$P"/include/switchyard/*_internal.h; do
    [ -e "$h" ] && fail "a loader's internal header ($(basename "$h")) was installed"
done
"$P/bin/sy" --version >"$TMP/version.out" 2>&1 || fail "installed sy --version: $(cat "$TMP/version.out")"
grep -q '^sy ' "$TMP/version.out" || fail "installed sy --version printed: $(cat "$TMP/version.out")"

# two triangles, one in front of the other (no test data needed)
cat >"$TMP/tri.gltf" <<'GLTF'
{"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],
 "meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],
 "accessors":[{"bufferView":0,"componentType":5126,"count":6,"type":"VEC3","min":[-1,-1,-1],"max":[1,1,0]}],
 "bufferViews":[{"buffer":0,"byteLength":72}],
 "buffers":[{"byteLength":72,"uri":"data:application/octet-stream;base64,AACAvwAAgL8AAAAAAACAPwAAgL8AAAAAAAAAAAAAgD8AAAAAAACAvwAAgL8AAIC/AACAPwAAgL8AAIC/AACAPwAAgD8AAIC/"}]}
GLTF
"$BUILD/apps/examples/render_gltf" "$TMP/tri.gltf" "$TMP/in_tree.exr" >"$TMP/in_tree.log" 2>&1 ||
    fail "in-tree render_gltf: $(cat "$TMP/in_tree.log")"

# 2. find_package
gen=()
command -v ninja >/dev/null 2>&1 && gen=(-G Ninja)
if cmake -S "$SRC/apps/examples" -B "$TMP/cmake" "${gen[@]}" -DCMAKE_PREFIX_PATH="$P" \
        -DCMAKE_C_FLAGS="$CFLAGS_EXTRA" -DCMAKE_EXE_LINKER_FLAGS="$CFLAGS_EXTRA" >"$TMP/cmake.log" 2>&1 &&
    cmake --build "$TMP/cmake" >>"$TMP/cmake.log" 2>&1; then
    "$TMP/cmake/render_gltf" "$TMP/tri.gltf" "$TMP/cmake.exr" >"$TMP/run1.log" 2>&1 ||
        fail "find_package render_gltf: $(cat "$TMP/run1.log")"
    "$EXR_EQUAL" "$TMP/in_tree.exr" "$TMP/cmake.exr" || fail "find_package render_gltf: pixels differ from the in-tree build"
    "$TMP/cmake/switch_backends" "$TMP/tri.gltf" "$TMP/sw" >"$TMP/run2.log" 2>&1 ||
        fail "find_package switch_backends: $(cat "$TMP/run2.log")"
    grep -q "^whitted .*after one transform change" "$TMP/run2.log" || fail "switch_backends printed: $(cat "$TMP/run2.log")"
    "$TMP/cmake/layered_stereo" "$TMP/tri.gltf" "$TMP/tri.gltf" "$TMP/st.exr" >"$TMP/run3.log" 2>&1 ||
        fail "find_package layered_stereo: $(cat "$TMP/run3.log")"
    echo "ok: find_package(Switchyard): the three examples built and ran ($(grep -c . "$TMP/run2.log") back-ends switched)"
else
    tail -30 "$TMP/cmake.log"
    fail "the examples do not configure or build against the installed package"
fi

# 3. pkg-config: both lines docs/EMBEDDING.md gives, with and without --static, whichever kind of
# libraries this installation has (the plain line failed on the default static install with 1,213
# undefined references: OpenMP, the C++ runtime, xxHash)
export PKG_CONFIG_PATH=$P/lib/pkgconfig
for mode in plain --static; do
    opt=()
    [ "$mode" = --static ] && opt=(--static)
    if flags=$(pkg-config "${opt[@]}" --cflags --libs switchyard-rt switchyard-formats 2>"$TMP/pc.err"); then
        # shellcheck disable=SC2086
        if cc -std=c11 $CFLAGS_EXTRA "$SRC/apps/examples/render_gltf.c" -o "$TMP/pc_render_$mode" $flags \
            -Wl,-rpath,"$P/lib" >"$TMP/cc.log" 2>&1; then
            "$TMP/pc_render_$mode" "$TMP/tri.gltf" "$TMP/pc.exr" >"$TMP/run4.log" 2>&1 ||
                fail "pkg-config ($mode) render_gltf: $(cat "$TMP/run4.log")"
            "$EXR_EQUAL" "$TMP/in_tree.exr" "$TMP/pc.exr" || fail "pkg-config ($mode) render_gltf: pixels differ from the in-tree build"
            echo "ok: pkg-config ${opt[*]} switchyard-rt switchyard-formats: $flags"
        else
            grep -c "undefined reference" "$TMP/cc.log" | sed 's/^/undefined references: /'
            head -30 "$TMP/cc.log"
            fail "render_gltf does not build with pkg-config's flags ($mode)"
        fi
    else
        fail "pkg-config ($mode) switchyard-rt switchyard-formats: $(cat "$TMP/pc.err")"
    fi
done
pkg-config --exists switchyard || fail "pkg-config switchyard (every component) is not usable"
# the headers as a C programmer includes them (<switchyard/...>, as <embree3/rtcore.h>), and the
# flat form of earlier releases
printf '#include <switchyard/sy_scene.h>\n#include <switchyard/sy_gltf.h>\n#include <sy_viewport.h>\nint main(void) { return 0; }\n' \
    >"$TMP/include_forms.c"
# shellcheck disable=SC2046
cc -std=c11 -fsyntax-only $(pkg-config --cflags switchyard-rt switchyard-formats) "$TMP/include_forms.c" 2>"$TMP/inc.err" ||
    fail "#include <switchyard/sy_scene.h> with pkg-config's flags: $(cat "$TMP/inc.err")"
# the umbrella header: every public header of the installation at once, warning-free in C11, and
# in C++ (extern "C" declarations, nothing C-only in the headers)
printf '#include <switchyard/switchyard.h>\nint main(void) { sy_scene *s = NULL; (void)s; return 0; }\n' >"$TMP/umbrella.c"
cp "$TMP/umbrella.c" "$TMP/umbrella.cpp"
# shellcheck disable=SC2046
cc -std=c11 -Wall -Wextra -Werror -fsyntax-only $(pkg-config --cflags switchyard) "$TMP/umbrella.c" 2>"$TMP/umb.err" ||
    fail "#include <switchyard/switchyard.h> (C11): $(head -5 "$TMP/umb.err")"
# shellcheck disable=SC2046
c++ -std=c++17 -Wall -Wextra -Werror -fsyntax-only $(pkg-config --cflags switchyard) "$TMP/umbrella.cpp" 2>"$TMP/umbxx.err" ||
    fail "#include <switchyard/switchyard.h> (C++17): $(head -5 "$TMP/umbxx.err")"
for h in "$P"/include/switchyard/sy_*.h; do # C++ programs link the C functions: extern "C" in every header
    grep -qE '^[A-Za-z_][A-Za-z0-9_ *]*\(' "$h" || continue # only includes or macros (sy_mediator.h, sy_scene.h)
    grep -q '__cplusplus' "$h" || fail "$(basename "$h") declares its functions without extern \"C\" for C++"
done
grep -q '#include "sy_fields.h"' "$P/include/switchyard/switchyard.h" && fail "the umbrella names core's internal sy_fields.h"
[ -e "$P/include/switchyard/sy_fields.h" ] && fail "an internal header (sy_fields.h) was installed"
grep -q '_internal\.h"' "$P/include/switchyard/switchyard.h" && fail "the umbrella names a loader's internal header"

# 4. no GL in a Whitted-only program
for exe in "$TMP/cmake/render_gltf" "$TMP/pc_render_plain" "$TMP/pc_render_--static"; do
    [ -x "$exe" ] || continue
    gl=$(ldd "$exe" | grep -Ei 'lib(GL|EGL|OpenGL|GLX|OSMesa|glfw)[.-]')
    if [ -n "$gl" ]; then fail "$(basename "$(dirname "$exe")")/$(basename "$exe") links GL: $gl"; else
        echo "ok: $exe links no GL library ($(ldd "$exe" | wc -l) libraries)"; fi
done

# 5. a missing component is named
mkdir -p "$TMP/missing"
printf 'cmake_minimum_required(VERSION 3.20)\nproject(m C)\nfind_package(Switchyard REQUIRED COMPONENTS warp_drive)\n' \
    >"$TMP/missing/CMakeLists.txt"
if cmake -S "$TMP/missing" -B "$TMP/missing/b" -DCMAKE_PREFIX_PATH="$P" >"$TMP/missing.log" 2>&1; then
    fail "find_package accepted a component that does not exist"
else
    grep -q "warp_drive" "$TMP/missing.log" || fail "find_package's error does not name the missing component: $(tail -5 "$TMP/missing.log")"
fi
[ $fails -eq 0 ] && echo "install_consumer: ok"
exit $((fails > 0))
