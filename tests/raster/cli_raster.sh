#!/bin/bash
# cli_raster.sh SY TESTDATA TMPDIR — `sy render -b raster --gl ...` from the command line: OSMesa
# renders the Cornell box; a provider without a display fails with a message naming it and the
# fallback; an unknown provider is named in the error.
set -u
sy=$1; data=$2; tmp=$3
scene=$data/cornell/cornell_box.gltf
if [ ! -r "$scene" ]; then echo "SKIP: $scene not found"; exit 77; fi
mkdir -p "$tmp"
fail=0
"$sy" render "$scene" -b raster --gl osmesa -w 64 -h 64 -o "$tmp/cornell.exr" --params msaa=2,shadow_map_size=256 \
  || { echo "FAIL: osmesa render"; fail=1; }
[ -s "$tmp/cornell.exr" ] || { echo "FAIL: no EXR written"; fail=1; }
err=$(env -u DISPLAY -u WAYLAND_DISPLAY "$sy" render "$scene" -b raster --gl glfw -w 32 -h 32 -o "$tmp/x.exr" 2>&1)
rc=$?
if [ $rc -ne 1 ] || ! grep -q "glfw" <<<"$err" || ! grep -q -- "--gl osmesa" <<<"$err"; then
  echo "FAIL: no-display error (rc $rc): $err"; fail=1
fi
err=$("$sy" render "$scene" -b raster --gl vulkan -w 32 -h 32 -o "$tmp/x.exr" 2>&1)
rc=$?
if [ $rc -eq 0 ] || ! grep -q "gl=vulkan" <<<"$err"; then echo "FAIL: unknown provider (rc $rc): $err"; fail=1; fi
[ $fail -eq 0 ] && echo "cli_raster: all checks passed"
exit $fail
