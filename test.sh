#!/usr/bin/env bash
# test.sh — the whole test suite: installs what is missing (Debian), builds four configurations
# (optimised; AddressSanitizer + UndefinedBehaviorSanitizer; minimal: Embree only, shared
# libraries; clang with libFuzzer) and runs ctest in each. Every step runs even when an earlier one
# failed; the exit status is non-zero when any failed.
set -uo pipefail
cd "$(dirname "$0")"
. .ci/deps.sh
sy_install_deps || exit 1
jobs=$(nproc 2>/dev/null || echo 2)
failed=()
step() { # step NAME COMMAND...: runs the command, remembers NAME when it fails
    local name=$1
    shift
    "$@" || failed+=("$name")
}
step "build (RelWithDebInfo)" sy_configure_build build -- -DCMAKE_BUILD_TYPE=RelWithDebInfo &&
  step "ctest (RelWithDebInfo)" ctest --test-dir build --output-on-failure -j "$jobs"
# SY_REQUIRE_BROWSER=1 (.ci/run): the browser tests must run; a skipped one fails by itself
# (browser_test.sh), and a main configuration without them (no sy web) fails here.
browser_tests_present() {
  local n
  n=$(ctest --test-dir build -N -L browser | sed -n 's/^Total Tests: //p')
  [ "${n:-0}" -gt 0 ] || { echo "test.sh: SY_REQUIRE_BROWSER=1 but the build has no browser tests (sy web not built?)"; return 1; }
}
[ "${SY_REQUIRE_BROWSER:-0}" = 1 ] && step "browser tests present" browser_tests_present
# Sanitizer build: every executable keeps dlopen()ed GL drivers loaded until exit
# (tests/support/sy_keep_loaded.c), so LeakSanitizer needs one suppression only (tests/lsan.supp).
# Every test but the browser ones (-LE browser: a minute and a half of chromium driving sy web,
# whose server code the web_* tests already run here).
step "build (ASan+UBSan)" sy_configure_build build-asan -- -DCMAKE_BUILD_TYPE=Debug -DSY_SANITIZE=ON &&
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  LSAN_OPTIONS="suppressions=$(pwd)/tests/lsan.supp:print_suppressions=0" \
  step "ctest (ASan+UBSan)" ctest --test-dir build-asan --output-on-failure -j "$jobs" -LE browser
# Minimal configuration (the modular build): only the Embree back-ends, as shared libraries (no sy web); GL,
# GLFW, nng, libsodium, zstd and MPI are not even looked for (package_parts checks that; video is
# off too: Debian's libavformat links libsodium). Its code
# is the main configuration's: it runs the tests of what its shape changes (label linkage: the
# installed package, the parts linked, the CLI, every sample, a back-end added from outside).
step "build (minimal: Embree only, shared)" sy_configure_build build-min -- -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DSY_WITH_RASTER=OFF -DSY_WITH_CLUSTER=OFF -DSY_WITH_WEB=OFF -DSY_WITH_VIDEO=OFF -DBUILD_SHARED_LIBS=ON &&
  step "ctest (minimal)" ctest --test-dir build-min --output-on-failure -j "$jobs" -L linkage
# Fuzzing (tests/fuzz): clang + libFuzzer, only the fuzz targets; each fuzz_run_* test fuzzes
# SY_FUZZ_SECONDS on seeds from ../shared/testdata, one target per core (tests/fuzz/fuzz.sh runs
# long campaigns).
CC=clang CXX=clang++ step "build (libFuzzer)" sy_configure_build build-fuzz sy_fuzzers -- \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSY_FUZZ=ON -DSY_FUZZ_SECONDS=5 &&
  step "ctest (fuzz)" ctest --test-dir build-fuzz --output-on-failure -L fuzz -j "$jobs"
if [ ${#failed[@]} -gt 0 ]; then
  printf 'test.sh: failed: %s\n' "${failed[@]}"
  exit 1
fi
