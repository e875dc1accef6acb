# .ci/deps.sh — sourced by run.sh and test.sh: installs the Debian packages the build needs (only
# when one is missing) and configures + builds with CMake (Ninja when present).
SY_PACKAGES="cmake ninja-build libavcodec-dev libavformat-dev libswscale-dev gcc g++ pkg-config libembree-dev libtinygltf-dev nlohmann-json3-dev libstb-dev
 libopenexr-dev libpng-dev libxxhash-dev libxml2-dev clang libclang-rt-14-dev
 libglfw3-dev libgl-dev xvfb xauth libosmesa6-dev libegl-dev
 libnng-dev libsodium-dev libzstd-dev zlib1g-dev iproute2 libfreetype-dev fonts-dejavu-core
 libopenmpi-dev openmpi-bin libimath-dev libcjson-dev doxygen libmeshoptimizer-dev
 libwebsockets-dev libturbojpeg0-dev libvpx-dev libassimp-dev assimp-utils assimp-testmodels libdraco-dev libwebp-dev
 chromium nodejs
 python3-dev python3-numpy python3-pytest python3-setuptools python3-wheel python3-pip"
# python3-*: the Python package (apps/python: development files, NumPy; pytest for its tests; pip,
# setuptools and wheel for `pip install --no-build-isolation ./apps/python`)
# npm (three.js for sy web's client page, playwright-core for the browser tests) comes with Node.js
# from nodesource; Debian's own nodejs needs the npm package beside it.
command -v npm >/dev/null 2>&1 || SY_PACKAGES="$SY_PACKAGES npm"

sy_install_deps() {
  local missing=()
  for p in $SY_PACKAGES; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  if [ ${#missing[@]} -gt 0 ]; then
    echo "installing missing packages: ${missing[*]}"
    local sudo=""
    [ "$(id -u)" -eq 0 ] || sudo="sudo"
    $sudo apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
  fi
}

# sy_configure_build DIR [TARGET] -- CMAKE_ARGS...: configure DIR and build TARGET (default: all).
sy_configure_build() {
  local dir=$1; shift
  local target=()
  if [ $# -gt 0 ] && [ "$1" != "--" ]; then target=(--target "$1"); shift; fi
  [ "${1:-}" = "--" ] && shift
  local gen=()
  command -v ninja >/dev/null 2>&1 && gen=(-G Ninja)
  cmake -S . -B "$dir" "${gen[@]}" "$@" >/dev/null
  cmake --build "$dir" "${target[@]}" -j "$(nproc 2>/dev/null || echo 2)"
}
