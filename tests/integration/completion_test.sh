#!/usr/bin/env bash
# completion_test.sh SY COMPLETION_SCRIPT TMPDIR — integration_completion: sources
# apps/sy/sy-completion.bash in bash and asks it for completions as bash would (COMP_WORDS /
# COMP_CWORD, then _sy_complete): commands, bench kinds, a command's options (also after an option
# of sy's own), option values from a list, back-end names from `SY backends`, scene file names
# (only .gltf / .glb / .x3d, directories and "demo"), and any file after -o.
set -u
SY=$1
SCRIPT=$2
TMP=$3
fails=0
rm -rf "$TMP"
mkdir -p "$TMP/scenes/sub"
: >"$TMP/scenes/box.gltf"
: >"$TMP/scenes/notes.txt"
: >"$TMP/scenes/hall.x3d"

# shellcheck source=/dev/null
source "$SCRIPT" || { echo "FAIL: cannot source $SCRIPT"; exit 1; }

# complete_words "WORDS": completions of the last word (empty when WORDS is empty or ends in a
# space), with sy's path as the command word
complete_words() {
    local -a w
    read -ra w <<<"$1"
    if [ -z "$1" ] || [ "${1: -1}" = " " ]; then w+=(""); fi
    COMP_WORDS=("$SY" "${w[@]}")
    COMP_CWORD=${#w[@]}
    COMP_LINE="${COMP_WORDS[*]}"
    COMP_POINT=${#COMP_LINE}
    COMPREPLY=()
    _sy_complete
    printf '%s\n' "${COMPREPLY[@]}" | sort
}

# offers MODE "WORDS" ITEMS...: MODE expect: every ITEM is offered; refuse: none of them is
offers() {
    local mode=$1 words=$2
    shift 2
    local got
    got=$(complete_words "$words")
    for item in "$@"; do
        if grep -qxF -- "$item" <<<"$got"; then
            [ "$mode" = refuse ] || continue
            echo "FAIL: 'sy $words<TAB>' offers '$item': $(echo $got)"
        else
            [ "$mode" = expect ] || continue
            echo "FAIL: 'sy $words<TAB>' does not offer '$item': $(echo $got)"
        fi
        fails=$((fails + 1))
    done
}
expect() { offers expect "$@"; }
refuse() { offers refuse "$@"; }

expect "re" render
refuse "re" info
expect "-q re" render
expect "" info render bench backends serve help
expect "con" convert
expect "convert -" -o
expect "bench " sync rays filters cluster
expect "render demo --tone" --tonemap
expect "render demo --tonemap " clamp reinhard aces
expect "render demo --stereo s" sbs separate
expect "render demo --q" --quiet
expect "serve --max-l" --max-lifetime
expect "bench cluster --ho" --hostile-only
expect "bench gov" governor
expect "bench an" anim
expect "bench anim --no" --nodes
expect "bench governor --bu" --budget
expect "bench governor --budget 20 --tr" --trace
expect "view demo --bu" --budget
expect "help ren" render
# back-end names come from `sy backends`
first=$("$SY" backends | head -n 1 | cut -d' ' -f1)
[ -n "$first" ] || { echo "FAIL: sy backends lists nothing"; fails=$((fails + 1)); }
expect "render demo -b " "$first"
# scenes: scene files, directories and demo; not other files
expect "render $TMP/scenes/" "$TMP/scenes/box.gltf" "$TMP/scenes/hall.x3d" "$TMP/scenes/sub"
refuse "render $TMP/scenes/" "$TMP/scenes/notes.txt"
expect "render de" demo
# after -o any file; after a value-taking option the command's options are still found
expect "render demo -o $TMP/scenes/no" "$TMP/scenes/notes.txt"
expect "render -w 64 demo --ao" --aov
# the scene clock: --at and --clip take a value, after which the options are still found
expect "render demo --a" --at --aov
expect "render demo --cl" --clip --cluster
expect "render demo --at 1.5 --cl" --clip
# motion blur: --shutter, --shutter-samples and --shutter-steps take a value, --motion-blur does not
expect "render demo --sh" --shutter --shutter-samples --shutter-steps
expect "render demo --shutter-steps 4 --cl" --clip
expect "render demo --mo" --motion-blur
expect "render demo --shutter 0.02 --cl" --clip
# the camera placement: --look-at, --orbit and --fov in render, pick, view and web; they take a value
expect "render demo --lo" --look-at
expect "render demo --or" --orbit
expect "pick demo --f" --fov
expect "view demo --look-at 0,1,5:0,0,0 --or" --orbit
expect "web demo --orbit 30,20 --fo" --fov
refuse "info demo --lo" --look-at

if [ "$fails" -ne 0 ]; then
    echo "$fails completion checks failed"
    exit 1
fi
echo "ok: completion of commands, options, values, back-ends and files"
