# sy-completion.bash — bash completion for `sy` (Switchyard's command line tool).
#
# Use: `source apps/sy/sy-completion.bash` (or copy it to bash-completion's directory,
# $(pkg-config --variable=completionsdir bash-completion)/sy). It completes the commands, the
# options of each command (the options every command takes included), the values of options that
# take a word from a list (--tonemap, --stereo, ...), back-end names after -b (asked of the `sy`
# being completed: `sy backends`), and file names: scenes (.gltf, .glb, .x3d; and the word "demo")
# where a SCENE is expected, any file after options that take a path. Needs bash 4; does not need
# the bash-completion package. Keep the lists in step with apps/sy/sy_cli.c (usage_text) and the
# cluster commands (apps/sy/sy_cluster_cli.h, sy_cmd_serve.c, sy_bench_cluster.c);
# tests/integration/completion_test.sh checks a few.

_sy_commands="info render demo compare convert coverage pick view web bench backends serve help version"
_sy_bench_kinds="sync rays pathtracer filters raster viewports load cluster memory instances governor limit cull web deform anim lights temporal stream"
_sy_common="--help -q --quiet -v --verbose --env --env-color --env-intensity --env-hidden --background
            --no-default-light --allow-path --strict --max-scene-mb --variant"
_sy_cluster="--cluster --cluster-mode --secret-file --tls-ca --timeout-ms --cluster-pixels"
# options that take a value (the next word)
_sy_with_value=" -b -o -w -h --camera --look-at --orbit --fov --bookmark --bookmarks --clip-cap --plane --hide --isolate --select --params --at --clip --max-memory --gl --filter --threshold --exposure --tonemap --stereo --eye-sep
  --shutter --shutter-samples --shutter-steps --zero-parallax --overlay --composite --frames --fps --repeat --spp --seed --time --cluster --cluster-mode --secret-file --tls-ca
  --timeout-ms --cluster-pixels --screenshot --keys --top --backends --repeats --nodes --tris --reference --env
  --env-color --env-intensity --background --allow-path --max-scene-mb --variant --listen --output --port-file --tls-cert --tls-key --name
  --max-sessions --max-lifetime --blob-cache-mb --max-objects --auth-backoff-ms --max-peer-memory-mb
  --max-frame-kb --max-message-mb --max-unauthenticated --handshake-timeout-ms --coop-frame --budget --quality --png "

# _sy_options COMMAND [BENCH_KIND]: the options of a command
_sy_options() {
    case "${1:-}" in
    render) echo "-b -o -w -h --camera --look-at --orbit --fov --bookmark --hide --isolate --select --params --at --clip --clip-cap --max-memory --gl --filter --threshold --half --exposure --tonemap --stereo
                  --eye-sep --zero-parallax --overlay --composite --frames --fps --resume --repeat --spp --seed --time --aov --temporal
                  --shutter --motion-blur --shutter-samples --shutter-steps --sub-frames
                  $_sy_cluster $_sy_common" ;;
    view) echo "-b -w -h --camera --look-at --orbit --fov --bookmark --bookmarks --clip --clip-cap --hide --isolate --select --overlay --composite --frames --screenshot --filter --threshold --keys --spp --budget --no-temporal
                $_sy_cluster $_sy_common" ;;
    web) echo "-b -w -h --camera --look-at --orbit --fov --bookmark --hide --isolate --select --listen --quality --filter --threshold --budget --min-scale --client-render --no-temporal --read-only --clip --bookmarks --delay-ms $_sy_common" ;;
    info) echo "--json $_sy_common" ;;
    compare) echo "-w -h -o --spp --camera --backends $_sy_common" ;;
    convert) echo "-o $_sy_common" ;;
    coverage) echo "-w -h --camera --top --json $_sy_common" ;;
    pick) echo "-b -w -h --camera --look-at --orbit --fov --bookmark --hide --isolate --select --params --clip --clip-cap --measure --plane --json $_sy_common" ;;
    demo) echo "-o -w -h --filter $_sy_common" ;;
    backends) echo "--json --params $_sy_common" ;;
    serve) echo "--listen --secret-file --output --port-file --tls-cert --tls-key --name --max-sessions
                 --max-lifetime --blob-cache-mb --max-objects --auth-backoff-ms --max-peer-memory-mb --max-frame-kb
                 --max-message-mb --max-unauthenticated --handshake-timeout-ms --help -q -v" ;;
    bench)
        case "${2:-}" in
        cluster) echo "-w -h --repeats --hostile-only --coop-only --scale --coop-frame --help -q -v" ;;
        filters) echo "-w -h --repeats --reference $_sy_common" ;;
        temporal) echo "-w -h --frames --spp --png $_sy_common" ;;
        memory) echo "-w -h -b --tris --glb $_sy_common" ;;
        web) echo "-w -h -b --repeats $_sy_common" ;;
        governor) echo "-w -h --budget --frames --tris --trace --help -q -v" ;;
        cull) echo "-w -h --tris --objects --budget --frames --seed --write --help" ;;
        *) echo "-w -h --repeats --nodes --tris --params $_sy_common" ;;
        esac ;;
    "") echo "--version --help -h -q --quiet -v --verbose" ;;
    esac
}

# _sy_files [scenes]: file names for $cur (directories always; "scenes": only scene files and "demo")
_sy_files() {
    local f
    compopt -o filenames 2>/dev/null
    while IFS= read -r f; do
        if [ -d "$f" ]; then COMPREPLY+=("$f")
        elif [ "${1:-}" != scenes ]; then COMPREPLY+=("$f")
        else case "${f,,}" in *.gltf | *.glb | *.x3d) COMPREPLY+=("$f") ;; esac
        fi
    done < <(compgen -f -- "$cur")
    if [ "${1:-}" = scenes ] && [[ demo == "$cur"* ]]; then COMPREPLY+=(demo); fi
}

_sy_complete() {
    COMPREPLY=()
    local cur=${COMP_WORDS[COMP_CWORD]} prev=${COMP_WORDS[COMP_CWORD - 1]}
    if [ "$cur" = "=" ]; then cur="" prev=${COMP_WORDS[COMP_CWORD - 1]}; # --opt=<TAB>
    elif [ "$prev" = "=" ]; then prev=${COMP_WORDS[COMP_CWORD - 2]}; fi
    # the command (and bench's kind): the first operands, skipping options and their values
    local cmd="" kind="" i w skip=0 operands=0
    for ((i = 1; i < COMP_CWORD; i++)); do
        w=${COMP_WORDS[i]}
        if [ $skip = 1 ]; then skip=0; continue; fi
        if [ "$w" = "=" ]; then skip=1; continue; fi
        case "$w" in
        -h) [ -n "$cmd" ] && skip=1 ;; # before the command: --help; after it: the height
        -*) [[ "$_sy_with_value" == *" $w "* ]] && skip=1 ;;
        *) if [ -z "$cmd" ]; then cmd=$w
           elif [ "$cmd" = bench ] && [ -z "$kind" ]; then kind=$w
           else operands=$((operands + 1)); fi ;;
        esac
    done
    # the value of an option
    if [[ "$prev" == -* ]] && [[ "$_sy_with_value" == *" $prev "* ]]; then
        local words=""
        case "$prev" in
        -b) words=$("${COMP_WORDS[0]}" backends 2>/dev/null | cut -d' ' -f1) ;;
        --tonemap) words="clamp reinhard aces" ;;
        --stereo) words="sbs tb anaglyph separate" ;;
        --composite) words="depth over replace" ;;
        --filter) words="none pixel atrous jbu adaptive radiance" ;;
        --gl) words="osmesa egl glfw" ;;
        --cluster-mode) words="sort-first balanced cooperative multi-display stereo frames" ;;
        --cluster-pixels) words="float half" ;;
        -o | --output | --screenshot | --env | --allow-path | --overlay | --secret-file | --tls-ca | --tls-cert | \
            --tls-key | --port-file | --reference | --cluster)
            [ "$prev" = -o ] && [ "$cmd" = demo ] && { compopt -o filenames 2>/dev/null; COMPREPLY=($(compgen -d -- "$cur")); return 0; }
            _sy_files; return 0 ;;
        *) return 0 ;; # a number, a name, parameters: nothing to offer
        esac
        COMPREPLY=($(compgen -W "$words" -- "$cur"))
        return 0
    fi
    if [[ "$cur" == -* ]]; then
        COMPREPLY=($(compgen -W "$(_sy_options "$cmd" "$kind")" -- "$cur"))
        return 0
    fi
    case "$cmd" in
    "") COMPREPLY=($(compgen -W "$_sy_commands" -- "$cur")) ;;
    help) [ $operands = 0 ] && COMPREPLY=($(compgen -W "$_sy_commands" -- "$cur")) ;;
    bench)
        if [ -z "$kind" ]; then COMPREPLY=($(compgen -W "$_sy_bench_kinds" -- "$cur"))
        else _sy_files; fi ;;
    info) _sy_files ;; # a scene or an EXR image
    render | view | web | compare | convert | coverage | pick) [ $operands = 0 ] && _sy_files scenes ;;
    esac
    return 0
}
complete -F _sy_complete sy
