#!/bin/bash
# core_layers: the layer rules of docs/ARCHITECTURE.md hold in the source and in the built core.
#   1. core/ includes only core headers (and system headers); backends/ includes no core/,
#      mediators/ or formats/ header; formats/ no mediators/ or backends/ header.
#   2. The built core library references no transport or codec symbol (nng, libsodium, zstd, MPI).
#   4. Within each library, modules do not call each other in a loop (the calls between the object
#      files of each archive, from nm, sort topologically with tsort), so each layer reads bottom-up.
#   3. apps/ never decides behaviour by a back-end's name: no string comparison against a
#      registered back-end name (capabilities are asked instead, sy_mediator.h).
# Usage: layers_test.sh SOURCE_DIR LIBSY_CORE [MORE_LIBRARIES ...]   (archives, or shared objects:
# then 4 is left to the static build)
set -u
SRC=$1 CORE_LIB=$2
shift 2
MORE_LIBS=("$@")
fail=0
bad() { echo "FAIL: $*"; fail=1; }

headers_of() { ls "$SRC/$1"/*.h "$SRC/$1"/*/*.h 2>/dev/null | xargs -n1 basename | sort -u; }
check_includes() { # DIR ALLOWED_DIRS...: every quoted include of DIR names a header of DIR or of ALLOWED_DIRS
    local dir=$1; shift
    local allowed
    allowed=$( { headers_of "$dir"; for a in "$@"; do headers_of "$a"; done; } | sort -u)
    local all_proj
    all_proj=$(for d in core mediators backends formats apps; do headers_of $d; done | sort -u)
    while IFS=: read -r file inc; do
        h=$(sed -E 's/.*#include "([^"]+)".*/\1/' <<<"$inc")
        h=$(basename "$h")
        if grep -qxF "$h" <<<"$all_proj" && ! grep -qxF "$h" <<<"$allowed"; then
            bad "$file includes \"$h\", which $dir/ may not use"
        fi
    done < <(grep -rn '#include "' "$SRC/$dir" --include=*.c --include=*.h --include=*.cpp | sed -E 's/^([^:]+):[0-9]+:/\1:/')
}
check_includes core
check_includes backends
check_includes formats core
[ $fail = 0 ] && echo "ok: core, backends and formats include only what their layer may"

if [ ! -f "$CORE_LIB" ]; then bad "core library $CORE_LIB not found"; else
    syms=$(nm -u "$CORE_LIB" 2>/dev/null | grep -E ' U (nng_|sodium_|crypto_|randombytes|ZSTD_|MPI_|lws_|tj)' | sort -u)
    if [ -n "$syms" ]; then bad "the core library references transport symbols:"; echo "$syms" | head; else
        echo "ok: $(basename "$CORE_LIB") references no nng, libsodium, zstd or MPI symbol"; fi
    n=$(nm -u "$CORE_LIB" | wc -l)
    [ "$n" -gt 10 ] || bad "nm found only $n undefined symbols in $CORE_LIB: the check would not see anything"
fi

names=$(grep -rhoE 'SY_MEDIATOR_NAME\("[a-z_]+"\)|\.name = "[a-z_]+"' "$SRC/mediators" | grep -oE '"[a-z_]+"' | sort -u)
[ -n "$names" ] || bad "found no registered back-end name in mediators/ (the check would see nothing)"
for n in $names; do
    hits=$(grep -rnE "str(n)?(case)?cmp\([^;]*$n|$n[^;]*str(n)?(case)?cmp\(" "$SRC/apps" --include=*.c | grep -vE 'cmp\((cmd|argv\[[^]]*\]), ' )
    [ -z "$hits" ] || { bad "apps/ compares against the back-end name $n:"; echo "$hits"; }
done
[ $fail = 0 ] && echo "ok: apps/ compares no back-end name ($(echo $names | tr '\n' ' '))"
# 4. module call graph per archive: member -> member that defines a symbol it uses
for lib in "$CORE_LIB" "${MORE_LIBS[@]}"; do
    [ -f "$lib" ] || { bad "library $lib not found"; continue; }
    case $lib in
    *.a) ;;
    *) echo "skip: $(basename "$lib") is a shared object (BUILD_SHARED_LIBS): its modules are sorted in the static build"; continue ;;
    esac
    members=$(ar t "$lib" | grep -c '\.o$')
    [ "$members" -gt 1 ] || { echo "ok: $(basename "$lib"): one module"; continue; }
    edges=$(awk 'NR == FNR { if ($2 ~ /^[TDBR]$/) def[$3] = $1; next }
                 $2 == "U" && ($3 in def) && def[$3] != $1 { print $1, def[$3] }' \
            <(nm -A --defined-only "$lib" 2>/dev/null | sed -E 's/^[^:]*:([^:]*): *[0-9a-f]* /\1 /') \
            <(nm -A -u "$lib" 2>/dev/null | sed -E 's/^[^:]*:([^:]*): *U /\1 U /') | sort -u)
    n=$(echo "$edges" | grep -c .)
    if ! loop=$(echo "$edges" | tsort 2>&1 >/dev/null) || [ -n "$loop" ]; then
        bad "$(basename "$lib"): modules call each other in a loop: $(echo "$loop" | tr '\n' ' ')"
    elif [ "$n" -lt 1 ]; then
        bad "$(basename "$lib"): no calls between modules found (the check would see nothing)"
    else
        echo "ok: $(basename "$lib"): $n calls between modules, no loop"
    fi
done
exit $fail
