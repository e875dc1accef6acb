#!/usr/bin/env bash
# run_fuzzer.sh FUZZER SECONDS MAX_LEN REGRESSION_DIR [SEED_DIR PATTERN MAX_SEED_BYTES [DICT]]
# Runs a libFuzzer binary for a bounded time: the regression corpus and the matching seed files
# (read in place from the shared test data) are copied into a temporary, writable corpus directory
# (libFuzzer adds what it finds there); the directory is removed afterwards. A crash makes
# libFuzzer exit non-zero and write crash-* into the temporary artifact directory, whose files are
# listed so they can be added to tests/fuzz/corpus_regressions.
set -euo pipefail
fuzzer=$1 seconds=$2 max_len=$3 regress=$4
seed_dir=${5:-} pattern=${6:-} max_seed=${7:-65536} dict=${8:-}
dict_opt=()
[ -n "$dict" ] && dict_opt=(-dict="$dict")
work=$(mktemp -d "${TMPDIR:-/tmp}/sy_fuzzrun_XXXXXX")
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/corpus" "$work/artifacts"
cp "$regress"/* "$work/corpus/" 2>/dev/null || true
if [ -n "$seed_dir" ]; then
  if [ -d "$seed_dir" ]; then
    n=0
    while IFS= read -r -d '' f; do
      cp "$f" "$work/corpus/seed_${n}_$(basename "$f")"; n=$((n + 1))
    done < <(find "$seed_dir" -type f -name "$pattern" -size -"$max_seed"c -print0)
    echo "seeds: $n files matching $pattern under $seed_dir"
  else
    echo "note: seed directory $seed_dir not found; fuzzing from the regression corpus only"
  fi
fi
set +e
"$fuzzer" "${dict_opt[@]}" -max_total_time="$seconds" -max_len="$max_len" -timeout=10 -rss_limit_mb=2048 \
  -print_final_stats=1 -artifact_prefix="$work/artifacts/" "$work/corpus" 2>&1 | tail -n 40
rc=${PIPESTATUS[0]}
set -e
if [ "$rc" -ne 0 ]; then
  echo "FUZZER FAILED (exit $rc); reproducers:"
  for f in "$work"/artifacts/*; do [ -e "$f" ] && { echo "  $f"; base64 -w0 "$f" | head -c 2000; echo; }; done
  exit 1
fi
echo "fuzzer finished cleanly after ${seconds}s"
