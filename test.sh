#!/usr/bin/env bash
# test.sh — the whole test suite: installs what is missing (Debian), builds two configurations
# (optimised, and AddressSanitizer + UndefinedBehaviorSanitizer) and runs ctest in both.
set -euo pipefail
cd "$(dirname "$0")"
. .ci/deps.sh
sy_install_deps
jobs=$(nproc 2>/dev/null || echo 2)
sy_configure_build build -- -DCMAKE_BUILD_TYPE=RelWithDebInfo
ctest --test-dir build --output-on-failure -j "$jobs"
sy_configure_build build-asan -- -DCMAKE_BUILD_TYPE=Debug -DSY_SANITIZE=ON
# tests/lsan.supp names third-party driver libraries (Mesa, GLX, GLFW) only, never our code.
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  LSAN_OPTIONS="suppressions=$(pwd)/tests/lsan.supp:print_suppressions=0" \
  ctest --test-dir build-asan --output-on-failure -j "$jobs"
# Fuzzing (tests/fuzz): clang + libFuzzer, only the fuzz targets; each fuzz_run_* test fuzzes
# SY_FUZZ_SECONDS on seeds from ../shared/testdata (about 2 minutes in all with the build).
CC=clang CXX=clang++ sy_configure_build build-fuzz sy_fuzzers -- -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSY_FUZZ=ON \
  -DSY_FUZZ_SECONDS=15
ctest --test-dir build-fuzz --output-on-failure -L fuzz
