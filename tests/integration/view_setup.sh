# view_setup.sh — sourced by the viewer tests (view_test.sh, view_cluster_test.sh) with their
# arguments SY PNG_COMPARE WORK_DIR: sets SY (the sy binary), CMP (the PNG comparison tool) and W (a
# fresh, empty work directory), then exits 77 with the reason when the machine cannot run `sy view`
# in a virtual X server (no xvfb-run, or sy built without GLFW/OpenGL).
SY=$1
CMP=$2
W=$3
rm -rf "$W"
mkdir -p "$W"
if ! command -v xvfb-run >/dev/null 2>&1; then
    echo "skipped: xvfb-run is not installed (Debian package xvfb)"
    exit 77
fi
if ! "$SY" 2>&1 | grep -q "sy view"; then
    echo "skipped: sy was built without GLFW/OpenGL (no 'sy view')"
    exit 77
fi
