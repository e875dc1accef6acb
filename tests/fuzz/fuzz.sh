#!/usr/bin/env bash
# fuzz.sh TARGET SECONDS [options] — fuzzes one libFuzzer target for a bounded time and prints the
# totals (executions, exec/s, corpus size) at the end. Targets: gltf glb x3d exr changes web_request
# web_message web_frame cull_query.
#
#   tests/fuzz/fuzz.sh x3d 600                 # 10 minutes, one process
#   tests/fuzz/fuzz.sh gltf 3600 -j 2          # two libFuzzer jobs in parallel
#   tests/fuzz/fuzz.sh exr 600 --corpus /tmp/exr-corpus   # keep (and later resume) the corpus
#
# Options:
#   -j N, --jobs N     N parallel jobs (libFuzzer -jobs=N -workers=N), each for SECONDS
#   --corpus DIR       writable corpus directory, kept afterwards (default: a temporary one);
#                      crash reproducers then go to DIR.artifacts
#   --fuzzer PATH      the fuzz binary (default: $SY_FUZZ_BUILD/tests/fuzz/fuzz_TARGET; when missing,
#                      $SY_FUZZ_BUILD, default <repo>/build-fuzz, is configured with clang and
#                      -DSY_FUZZ=ON and the target built)
#   --seeds-tool PATH  fuzz_seeds (default: next to the fuzz binary)
#   --testdata DIR     shared test data (default: $SY_TESTDATA_DIR, else <repo>/../shared/testdata)
#   --max-len N        override the target's maximum input length
#   --seed N           libFuzzer's random seed (default 0: a new one each run; the ctests pass
#                      SY_FUZZ_SEED, default 1, so the suite mutates the same way on every machine)
#   -- ARGS            further libFuzzer arguments
#
# Seeds are read in place at fuzz time: the regression corpus tests/fuzz/corpus_regressions/TARGET
# and, through a directory of symbolic links, the matching test-data files no larger than the
# target's maximum input length (bigger ones are skipped); fuzz_seeds adds generated EXR images and
# wire-format encodings of test-data scenes. Companion files of the seeds (glTF .bin buffers and
# images, X3D textures) are copied into a temporary resource directory that the targets resolve
# external URIs in ($SY_FUZZ_RESOURCES; copies, since the loaders confine URIs after links).
# Assimp targets: Assimp's own leaks are suppressed (assimp_lsan.supp), and a crash, abort or hang
# inside Assimp that the import process contains (formats/sy_assimp_isolate.c) is reported as
# "contained" (reproducer kept in CORPUS.contained with --corpus) and fuzzing goes on; a fault
# anywhere else fails the run.
# Exit status: 0 clean, 1 crash / sanitizer report / failure.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
repo=$(cd "$here/../.." && pwd)
usage() { awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0"; exit 2; }
[ $# -ge 2 ] || usage
target=$1 seconds=$2
shift 2
jobs=1 corpus="" fuzzer="" seeds_tool="" max_len="" seed=0 extra=()
testdata=${SY_TESTDATA_DIR:-$repo/../shared/testdata}
while [ $# -gt 0 ]; do
  case $1 in
    -j|--jobs) jobs=$2; shift 2 ;;
    --corpus) corpus=$2; shift 2 ;;
    --fuzzer) fuzzer=$2; shift 2 ;;
    --seeds-tool) seeds_tool=$2; shift 2 ;;
    --testdata) testdata=$2; shift 2 ;;
    --max-len) max_len=$2; shift 2 ;;
    --seed) seed=$2; shift 2 ;;
    --) shift; extra=("$@"); break ;;
    *) usage ;;
  esac
done

# per target: maximum input length, seed directories + name patterns, resource patterns, dictionaries
case $target in
  gltf) len=32768; seed_dirs=(gltf cornell); seed_pat=('*.gltf'); res_pat=('*.bin' '*.png' '*.jpg' '*.jpeg')
        dicts=(gltf.dict) ;;
  glb) len=131072; seed_dirs=(gltf); seed_pat=('*.glb'); res_pat=('*.bin' '*.png' '*.jpg' '*.jpeg')
        dicts=(glb.dict gltf.dict) ;;
  x3d) len=16384; seed_dirs=(x3d); seed_pat=('*.x3d'); res_pat=('*.png' '*.jpg' '*.jpeg' '*.x3d'); dicts=(x3d.dict) ;;
  exr) len=65536; seed_dirs=(.); seed_pat=('*.exr'); res_pat=(); dicts=(exr.dict) ;;
  changes) len=65536; seed_dirs=(); seed_pat=(); res_pat=(); dicts=(wire.dict) ;;
  web_request) len=12288; seed_dirs=(); seed_pat=(); res_pat=(); dicts=(web.dict) ;;
  web_message) len=4096; seed_dirs=(); seed_pat=(); res_pat=(); dicts=(web.dict) ;;
  web_frame) len=65536; seed_dirs=(); seed_pat=(); res_pat=(); dicts=() ;;
  cull_query) len=65536; seed_dirs=(); seed_pat=(); res_pat=(); dicts=(web.dict) ;;
  assimp_obj|assimp_ply|assimp_stl|assimp_fbx|assimp_dae) # Assimp's test models (assimp-testmodels), in place
        ext=${target#assimp_}; len=65536; testdata=/usr/share/assimp/models; res_pat=('*.mtl' '*.png' '*.jpg')
        case $ext in obj) seed_dirs=(OBJ) ;; ply) seed_dirs=(PLY) ;; stl) seed_dirs=(STL) ;; fbx) seed_dirs=(FBX) ;; dae) seed_dirs=(Collada) ;; esac
        seed_pat=("*.$ext" "*.${ext^^}"); dicts=(assimp.dict) ;;
  *) echo "fuzz.sh: unknown target '$target' (gltf glb x3d exr changes web_request web_message web_frame cull_query)" >&2; exit 2 ;;
esac
[ -n "$max_len" ] && len=$max_len

if [ -z "$fuzzer" ]; then
  build=${SY_FUZZ_BUILD:-$repo/build-fuzz}
  fuzzer=$build/tests/fuzz/fuzz_$target
  if [ ! -x "$fuzzer" ]; then
    echo "fuzz.sh: building $fuzzer"
    [ -f "$build/CMakeCache.txt" ] || CC=clang CXX=clang++ cmake -S "$repo" -B "$build" -G Ninja \
      -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSY_FUZZ=ON >/dev/null
    cmake --build "$build" --target "fuzz_$target" fuzz_seeds
  fi
fi
[ -x "$fuzzer" ] || { echo "fuzz.sh: no fuzz binary at $fuzzer" >&2; exit 1; }
[ -n "$seeds_tool" ] || seeds_tool=$(dirname "$fuzzer")/fuzz_seeds
fuzzer=$(cd "$(dirname "$fuzzer")" && pwd)/$(basename "$fuzzer")

work=$(mktemp -d "${TMPDIR:-/tmp}/sy_fuzz_${target}_XXXXXX")
trap 'rm -rf "$work"' EXIT
if [ -n "$corpus" ]; then
  mkdir -p "$corpus" "$corpus.artifacts"
  corpus=$(cd "$corpus" && pwd)
  artifacts=$corpus.artifacts
else
  corpus=$work/corpus artifacts=$work/artifacts
  mkdir -p "$corpus" "$artifacts"
fi
mkdir -p "$work/seeds" "$work/resources" "$work/generated"

# seeds: links to test-data files (read in place), the too-big ones skipped
nseed=0 nbig=0
if [ ${#seed_dirs[@]} -gt 0 ] && [ ! -d "$testdata" ]; then
  echo "fuzz.sh: note: test data $testdata not found; fuzzing from the regression corpus only"
elif [ ${#seed_dirs[@]} -gt 0 ]; then
  for d in "${seed_dirs[@]}"; do
    [ -d "$testdata/$d" ] || continue
    for p in "${seed_pat[@]}"; do
      while IFS= read -r -d '' f; do
        if [ "$(stat -c %s "$f")" -gt "$len" ]; then nbig=$((nbig + 1)); continue; fi
        ln -s "$(cd "$(dirname "$f")" && pwd)/$(basename "$f")" "$work/seeds/s${nseed}_$(basename "$f")"
        nseed=$((nseed + 1))
      done < <(find "$testdata/$d" -type f -name "$p" -print0 | sort -z)
    done
    for p in "${res_pat[@]}"; do # companion files, flat by name (first wins), up to 1 MiB; copies,
      while IFS= read -r -d '' f; do # not links: the loaders confine URIs to the folder after links
        [ -e "$work/resources/$(basename "$f")" ] && continue
        cp "$f" "$work/resources/$(basename "$f")"
      done < <(find "$testdata/$d" -type f -name "$p" -size -1048577c -print0 | sort -z)
    done
  done
fi
# generated seeds
if [ "$target" = exr ] || [ "$target" = changes ]; then
  if [ -x "$seeds_tool" ]; then
    inputs=()
    if [ "$target" = changes ] && [ -d "$testdata" ]; then
      while IFS= read -r -d '' f; do inputs+=("$f"); done < <(
        { find "$testdata/gltf" "$testdata/cornell" -type f -name '*.gltf' -size -65537c -print0 2>/dev/null
          find "$testdata/x3d" -type f -name '*.x3d' -size -16385c -print0 2>/dev/null; } | sort -z)
    fi
    ASAN_OPTIONS=detect_leaks=0 "$seeds_tool" "$target" "$work/generated" "${inputs[@]}" | tail -n 1
    find "$work/generated" -type f -size +"$len"c -delete
  else
    echo "fuzz.sh: note: no seed generator at $seeds_tool"
  fi
fi
dict=$work/dict
: >"$dict"
for d in "${dicts[@]}"; do cat "$here/$d" >>"$dict"; done
echo "fuzz.sh: $target for ${seconds}s x $jobs job(s), max_len $len: $nseed test-data seeds ($nbig skipped as larger" \
     "than max_len), $(ls "$work/generated" | wc -l) generated, $(ls "$here/corpus_regressions/$target" | wc -l) regression inputs"

regress=$here/corpus_regressions/$target
args=(-max_len="$len" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix="$artifacts/")
[ -s "$dict" ] && args+=(-dict="$dict") # libFuzzer refuses an empty dictionary (web_frame has none)
[ "$jobs" -gt 1 ] && args+=(-jobs="$jobs" -workers="$jobs")
# a smaller ASan quarantine and shorter allocation stacks: ~10% more executions (tinygltf and
# libxml2 allocate a lot); an ASAN_OPTIONS of the caller wins
export ASAN_OPTIONS=${ASAN_OPTIONS:-quarantine_size_mb=64:malloc_context_size=10}
assimp=false
case $target in assimp_*) assimp=true ;; esac
# Assimp's own leaks on malformed files (assimp_lsan.supp says why they are not the loader's)
$assimp && export LSAN_OPTIONS="suppressions=$here/assimp_lsan.supp${LSAN_OPTIONS:+:$LSAN_OPTIONS}"

# assimp_fault FILE LOG: prints the faulting frame and succeeds when the fault FILE reproduces (or,
# when it does not come again alone, the one in the run's LOG) lies inside Assimp (the first stack
# frame outside the C / C++ runtimes, the sanitizers and libFuzzer is in libassimp; or only
# libFuzzer's own frames: its heap overwritten by Assimp on an earlier input) AND the same input
# loaded as applications load it (the import process, SY_FUZZ_ISOLATED=1) only fails the load. Such faults are Assimp 5.2's, contained, and do not fail
# the run; any other fault does. The re-run has no RSS thread (-rss_limit_mb=0): a sanitizer build
# loads in process when other threads exist (formats/sy_assimp_isolate.c).
assimp_fault() {
  local out frame
  out=$(cd "$work" && SY_FUZZ_RESOURCES="$work/resources" timeout 120 "$fuzzer" -timeout=10 -rss_limit_mb=2048 -runs=1 "$1" 2>&1)
  # a fault found inside libFuzzer's own code (its mutator's buffers) does not come again from the
  # input alone: then the run's log ($2) has the stack
  grep -q "ERROR: AddressSanitizer" <<<"$out" || out=$(cat "$2" 2>/dev/null)
  frame=$(printf '%s\n' "$out" | awk '/^ *#[0-9]+ 0x/ {
      if ($0 ~ /(libc\.so|libstdc\+\+|libgcc_s|libclang_rt|libasan|libubsan|ld-linux)/) next
      if ($0 ~ / in (__sanitizer|__asan|__lsan|__ubsan|__interceptor|fuzzer::|malloc|calloc|realloc|free|operator new|operator delete|abort|raise|gsignal|__GI_|__pthread_kill)/) next
      print; exit }')
  case $frame in
    *libassimp.so*) ;;
    # inside libFuzzer with none of our frames on any stack of the report: its own buffers (heap an
    # uninstrumented library overwrote on an earlier input, or libFuzzer's own fault), not ours
    # (our code is instrumented: ASan stops at our own bad access, with our frames on the stack)
    *" in main "*)
      grep -Eq '^ *#[0-9]+ 0x.* in fuzzer::' <<<"$out" && ! grep -Eq '^ *#[0-9]+ 0x.* in (sy_|LLVMFuzzerTestOneInput)' <<<"$out" ||
        return 1
      frame="libFuzzer's heap, overwritten earlier (uninstrumented Assimp): $frame" ;;
    *) return 1 ;;
  esac
  (cd "$work" && SY_FUZZ_ISOLATED=1 SY_FUZZ_RESOURCES="$work/resources" timeout 300 "$fuzzer" -rss_limit_mb=0 -runs=1 "$1" >/dev/null 2>&1) || return 1
  printf '%s\n' "$frame" | sed 's/^ *//'
}

start=$(date +%s)
set +e
logs=() contained=() round=0 rc=0
while :; do
  left=$((seconds - ($(date +%s) - start)))
  [ "$round" -gt 0 ] && [ "$left" -lt 2 ] && break
  [ "$left" -ge 1 ] || left=1
  timer=()
  [ -x /usr/bin/time ] && timer=(/usr/bin/time -a -f '%U %S' -o "$work/cpu")
  (cd "$work" && SY_FUZZ_RESOURCES="$work/resources" "${timer[@]}" "$fuzzer" -max_total_time="$left" "${args[@]}" \
     -seed=$((seed ? seed + round : 0)) \
     "${extra[@]}" "$corpus" "$regress" "$work/seeds" "$work/generated" >"$work/fuzz-main-$round.log" 2>&1)
  rc=$?
  logs+=("$work/fuzz-main-$round.log")
  round=$((round + 1))
  # an Assimp target that stopped on a fault inside Assimp that the import process contains: note
  # it, set the reproducer aside and fuzz on for the time left (at most 20 restarts)
  [ "$rc" -ne 0 ] && $assimp && [ "$jobs" -eq 1 ] && [ "$round" -le 20 ] || break
  new=() ok=true
  for f in "$artifacts"/*; do [ -e "$f" ] && new+=("$f"); done
  [ ${#new[@]} -gt 0 ] || break
  kept=$work/contained
  [ "$artifacts" = "$work/artifacts" ] || kept=$corpus.contained
  mkdir -p "$kept"
  for f in "${new[@]}"; do
    if frame=$(assimp_fault "$f" "${logs[-1]}"); then
      contained+=("$kept/$(basename "$f") at ${frame:0:160}")
      mv "$f" "$kept/"
    else ok=false; fi
  done
  $ok || break
  rc=0
done
set -e
end=$(date +%s)
[ "$jobs" -gt 1 ] && logs=("$work"/fuzz-[0-9]*.log)
grep -hE '^#[0-9]+[[:space:]]+(INITED|DONE)|^(==[0-9]+==|SUMMARY|INFO: Seed)|ERROR|Test unit written' "${logs[@]}" | tail -n 30 || true
for c in "${contained[@]}"; do echo "fuzz.sh: contained: a fault inside Assimp that the import process turns into a failed load: $c"; done
execs=$(cat "${logs[@]}" | awk '/stat::number_of_executed_units/ {s += $NF} END {print s + 0}')
corp=$(cat "${logs[@]}" | grep -oE 'corp: [0-9]+/[0-9]+[a-zA-Z]*' | tail -n 1 | cut -d' ' -f2 || true)
files=$(find "$corpus" -type f | wc -l)
bytes=$(du -sb "$corpus" | cut -f1)
crashes=$(find "$artifacts" -type f | wc -l)
elapsed=$((end - start)); [ "$elapsed" -gt 0 ] || elapsed=1
cpu=$(awk '{c += $1 + $2} END {if (NR) printf "%d", c + 0.5}' "$work/cpu" 2>/dev/null || true) # user + system, all jobs and rounds
per_cpu=""
[ -n "$cpu" ] && [ "$cpu" -gt 0 ] && per_cpu=" cpu_seconds=$cpu exec_per_cpu_s=$((execs / cpu))"
echo "fuzz.sh: RESULT target=$target seconds=$elapsed jobs=$jobs executions=$execs exec_per_s=$((execs / elapsed))$per_cpu" \
     "corpus=${corp:-?} (libFuzzer: inputs/bytes) new_files=$files new_bytes=$bytes crashes=$crashes contained=${#contained[@]} exit=$rc"
if [ "$rc" -ne 0 ] || [ "$crashes" -ne 0 ]; then
  echo "FUZZER FAILED (exit $rc); reproducers (add them to tests/fuzz/corpus_regressions/$target with the fix):"
  for f in "$artifacts"/*; do [ -e "$f" ] && { echo "  $f"; base64 -w0 "$f" | head -c 2000; echo; }; done
  exit 1
fi
