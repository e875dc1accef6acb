#!/usr/bin/env bash
# parts_test.sh SY CMAKE_CACHE "PARTS" LIBRARY... — package_parts: a build has what its options
# asked for and nothing else (issue 17, modular build).
#   - sy and every library of the build link no library of a part that is off: no GL, EGL, GLFW,
#     OSMesa without raster; no nng, libsodium, zstd without cluster; no MPI without mpi (ldd for
#     shared objects and sy, nm -u for archives);
#   - the configuration did not even look for them (CMakeCache.txt has no entry of their finders);
#   - sy backends lists exactly the back-ends of the parts that are on.
set -u
SY=$1 CACHE=$2 PARTS=" $3 "
shift 3
fails=0
fail() { echo "FAIL: $*" >&2; fails=$((fails + 1)); }
on() { [[ "$PARTS" == *" $1 "* ]]; }
libs_re=() syms_re=() cache_re=()
if ! on raster; then
    libs_re+=('lib(GL|EGL|OpenGL|GLX|OSMesa|glfw)[.-]'); syms_re+=('glfw|eglGetDisplay|OSMesa'); cache_re+=('^(OSMESA|EGL|GLFW3)_FOUND')
fi
if ! on cluster; then
    libs_re+=('lib(nng|sodium|zstd)[.-]'); syms_re+=('nng_|sodium_|ZSTD_'); cache_re+=('^nng_DIR:.*[^-]$|^(SODIUM|ZSTD)_FOUND')
fi
if ! on mpi; then libs_re+=('lib(mpi|open-pal|open-rte)[.-]'); syms_re+=('MPI_'); cache_re+=('^MPI_C_FOUND:BOOL=TRUE'); fi
[ ${#libs_re[@]} -gt 0 ] || { echo "every part is on: nothing to check"; }
for f in "$SY" "$@"; do
    for re in "${libs_re[@]}"; do
        case $f in
        *.a) hits=$(nm -u "$f" 2>/dev/null | grep -E " U (${syms_re[*]// /|})" | head -3) ;;
        *) hits=$(ldd "$f" | grep -E "$re") ;;
        esac
        [ -z "$hits" ] || fail "$(basename "$f") uses a part that is off: $hits"
    done
done
for re in "${cache_re[@]}"; do
    hits=$(grep -E "$re" "$CACHE" | head -3)
    [ -z "$hits" ] || fail "the configuration looked for a part that is off: $hits"
done
# the back-ends sy offers
"$SY" backends >"${TMPDIR:-/tmp}/sy_parts_$$.out" 2>&1 || fail "sy backends failed"
listed=$(awk '{print $1}' "${TMPDIR:-/tmp}/sy_parts_$$.out" | grep -E '^(whitted|pathtracer|coverage|raster)$' | sort | tr '\n' ' ')
rm -f "${TMPDIR:-/tmp}/sy_parts_$$.out"
expect=""
on embree && expect="coverage pathtracer "
on raster && expect="${expect}raster "
on embree && expect="${expect}whitted "
[ "$listed" = "$expect" ] || fail "sy backends lists '$listed', this build's parts give '$expect'"
[ $fails -eq 0 ] && echo "package_parts: ok (parts:$PARTS; back-ends: $listed)"
exit $((fails > 0))
