#!/bin/sh
# docs_test.sh SOURCE_DIR OUTPUT_DIR [DOXYGEN] — the ctest docs_doxygen: runs doxygen on
# docs/Doxyfile (public headers + docs/*.md) into OUTPUT_DIR and fails on any warning or error.
# Exit 77 (skipped) when doxygen is not installed.
src=$1
out=$2
doxygen=${3:-}
if [ -z "$doxygen" ] || ! command -v "$doxygen" >/dev/null 2>&1; then
    echo "SKIP: doxygen not found (apt-get install doxygen)"
    exit 77
fi
rm -rf "$out" && mkdir -p "$out" || exit 1
cd "$src" || exit 1
SY_DOXYGEN_OUTPUT="$out" "$doxygen" docs/Doxyfile >"$out/doxygen.log" 2>&1
rc=$?
if [ $rc -ne 0 ] || grep -q -e ': warning:' -e ': error:' "$out/doxygen.log"; then
    cat "$out/doxygen.log"
    echo "docs_doxygen: doxygen failed (status $rc) or warned; document every public declaration"
    exit 1
fi
if [ ! -f "$out/html/index.html" ]; then
    echo "docs_doxygen: no html/index.html in $out"
    exit 1
fi
echo "docs_doxygen: $("$doxygen" --version), $(ls "$out/html" | wc -l) files in $out/html, no warnings"
