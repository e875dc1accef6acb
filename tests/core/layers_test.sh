#!/bin/bash
# core_layers: the layer rules of docs/ARCHITECTURE.md hold in the source and in the built core.
#   1. core/ includes only core headers (and system headers); backends/ includes no core/,
#      mediators/ or formats/ header; formats/ no mediators/ or backends/ header.
#   2. The built core library references no transport or codec symbol (nng, libsodium, zstd, MPI).
#   4. Within each library, modules do not call each other in a loop (the calls between the object
#      files of each archive, from nm, sort topologically with tsort), so each layer reads bottom-up.
#   3. apps/ never decides behaviour by a back-end's name: no string comparison against a
#      registered back-end name (capabilities are asked instead, sy_mediator.h).
#   5. apps/ shows its plan: one folder per thing, nothing loose at its root but CMakeLists.txt and
#      README.md, and the README names every folder.
#   6. No library under apps/ (a folder whose CMakeLists.txt has add_library: web, cull, scenes)
#      reaches into one mediator: no header of a mediators/NAME/ folder (sy_mediator_rt.h, ...),
#      no sy_mediator_NAME_* call, no sy_context_state (a mediator's own state); they ask the
#      typed capabilities of core/sy_mediator.h (sy_context_coverage, ...). Programs (apps/sy)
#      may use a mediator's diagnostics.
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
    local allowed all_proj out
    allowed=$( { headers_of "$dir"; for a in "$@"; do headers_of "$a"; done; } | sort -u)
    all_proj=$(for d in core mediators backends formats apps; do headers_of $d; done | sort -u)
    # one awk over every include line (a process per line took most of the test's time)
    out=$(grep -rn '#include "' "$SRC/$dir" --include=*.c --include=*.h --include=*.cpp |
        awk -v allowed="$allowed" -v proj="$all_proj" -v dir="$dir" '
            BEGIN { n = split(allowed, a, "\n"); for (i = 1; i <= n; ++i) ok[a[i]] = 1
                    n = split(proj, p, "\n"); for (i = 1; i <= n; ++i) pj[p[i]] = 1 }
            { file = $0; sub(/:[0-9]+:.*/, "", file)
              h = $0; sub(/.*#include "/, "", h); sub(/".*/, "", h); sub(/.*\//, "", h)
              if ((h in pj) && !(h in ok)) print file " includes \"" h "\", which " dir "/ may not use" }')
    if [ -n "$out" ]; then
        while IFS= read -r l; do bad "$l"; done <<<"$out"
    fi
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
# 5. apps/: one folder per thing
loose=$(find "$SRC/apps" -mindepth 1 -maxdepth 1 ! -type d ! -name CMakeLists.txt ! -name README.md -printf '%f\n' | sort)
[ -z "$loose" ] || bad "apps/ has files loose at its root (one folder per thing, apps/README.md): $(echo $loose)"
folders=$(find "$SRC/apps" -mindepth 1 -maxdepth 1 -type d -printf '%f\n' | sort)
[ -n "$folders" ] || bad "apps/ has no folder (the check would see nothing)"
for d in $folders; do
    grep -qF "\`$d/\`" "$SRC/apps/README.md" 2>/dev/null || bad "apps/README.md does not name the folder $d/"
done
[ -z "$loose" ] && [ -f "$SRC/apps/README.md" ] && echo "ok: apps/ holds only folders ($(echo $folders)), CMakeLists.txt and README.md"
# 6. no library under apps/ reaches into one mediator
med_dirs=$(find "$SRC/mediators" -mindepth 1 -maxdepth 1 -type d -printf '%f\n' | sort)
med_headers=$(for m in $med_dirs; do ls "$SRC/mediators/$m"/*.h 2>/dev/null; done | xargs -n1 basename 2>/dev/null | sort -u)
app_libs=$(grep -l 'add_library' "$SRC"/apps/*/CMakeLists.txt 2>/dev/null | xargs -n1 dirname 2>/dev/null)
[ -n "$med_headers" ] && [ -n "$app_libs" ] || bad "found no mediator header or no library under apps/ (the check would see nothing)"
reach=0
for lib in $app_libs; do
    while IFS=: read -r file line inc; do
        h=$(sed -E 's/.*#include "([^"]+)".*/\1/' <<<"$inc")
        if grep -qxF "$(basename "$h")" <<<"$med_headers"; then
            bad "${file#$SRC/}:$line includes \"$h\", one mediator's header (ask a capability, core/sy_mediator.h)"
            reach=1
        fi
    done < <(grep -rn '#include "' "$lib" --include=*.c --include=*.h)
    hits=$(grep -rnE "\bsy_mediator_($(echo $med_dirs | tr ' ' '|'))_[a-z0-9_]*[ ]*\(|\bsy_context_state[ ]*\(" "$lib" --include=*.c --include=*.h)
    [ -z "$hits" ] || { bad "a library under apps/ reaches into one mediator's state:"; echo "${hits//$SRC\//}"; reach=1; }
done
[ $reach = 0 ] && echo "ok: the libraries under apps/ ($(echo $(for l in $app_libs; do basename "$l"; done))) use no mediator's own header, call or state"
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
