#!/usr/bin/env bash
# tests/soak/serve_soak.sh — the `sy serve` soak of issue 32 (item 6), outside ctest: one render
# server and one client on loopback, the client moving the camera every frame (a change list and a
# RENDER each) for SECONDS (default 600); every 10 s the server's RSS, open descriptors and threads
# are printed. Exit 0 when every frame sent came back and each of the three grew by less than 5 %
# from the end of the warm-up (60 s, or a tenth of a shorter soak) to the end; 1 otherwise.
#   tests/soak/serve_soak.sh [BUILD_DIR (build)] [SECONDS (600)] [BACKEND (raster, else whitted)] [OUT_LOG]
# Runs `sy bench cluster --soak` (apps/sy/sy_bench_cluster_soak.c); docs/TESTING.md.
set -euo pipefail
build=${1:-build}
seconds=${2:-600}
backend=${3:-}
log=${4:-}
sy="$build/apps/sy/sy"
[ -x "$sy" ] || { echo "serve_soak: $sy not found (build first: cmake --build $build)" >&2; exit 2; }
args=(bench cluster --soak "$seconds")
[ -n "$backend" ] && args+=(-b "$backend")
echo "serve_soak: $sy ${args[*]} (load: $(cut -d' ' -f1-3 /proc/loadavg), $(nproc) cores)"
if [ -n "$log" ]; then
  "$sy" "${args[@]}" 2>&1 | tee "$log"
  exit "${PIPESTATUS[0]}"
fi
exec "$sy" "${args[@]}"
