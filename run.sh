#!/usr/bin/env bash
# run.sh — the main job: installs what is missing (Debian), builds with CMake, then renders the
# bundled demo scene with every back-end and prints where each image went and how long it took.
# Usage: ./run.sh [sy demo options, e.g. -o out -w 800 -h 450]
set -euo pipefail
cd "$(dirname "$0")"
. .ci/deps.sh
sy_install_deps
sy_configure_build build-release sy -- -DCMAKE_BUILD_TYPE=Release
./build-release/apps/sy/sy demo "$@"
