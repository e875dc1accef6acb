#!/usr/bin/env bash
# interrupt_test.sh SY TMPDIR — SIGINT / SIGTERM never leave half an image or a temporary file
# (issue 14, finding 6):
#  1. a progressive render interrupted once finishes its pass and writes the image accumulated so
#     far (exit 130, sy:samples and sy:interrupted in the EXR header);
#  2. two interrupts while the image is being written: no image, no "*.tmp-*", killed by SIGTERM;
#  3. one interrupt while a single-pass back-end writes: the same;
#  4. an interrupt during a single-pass render: no file at all.
set -u
set -m # job control: background jobs keep SIGINT (a script's background jobs otherwise ignore it)
SY=$1
W=$2
rm -rf "$W"
mkdir -p "$W"
fails=0
fail() { echo "FAIL: $*"; for f in "$W"/*.err; do [ -e "$f" ] && { echo "--- $f"; cat "$f"; }; done; fails=$((fails + 1)); }
# wait_for GLOB: until a file matching GLOB exists (at most 60 s)
wait_for() { for _ in $(seq 1 6000); do compgen -G "$1" >/dev/null && return 0; sleep 0.01; done; return 1; }
leftovers() { compgen -G "$W/*.tmp-*" >/dev/null; }

# 1. graceful: the first SIGINT ends the progressive render after its current pass
"$SY" render demo -b pathtracer --spp 1000000 -w 64 -h 48 -o "$W/pt.exr" >"$W/pt.out" 2>"$W/pt.err" &
pid=$!
sleep 2
kill -INT $pid
wait $pid
rc=$?
if [ $rc -ne 130 ] || [ ! -s "$W/pt.exr" ]; then
    fail "graceful interrupt: status $rc (want 130), image present: $([ -s "$W/pt.exr" ] && echo yes || echo no)"
elif ! grep -qa "sy:interrupted" "$W/pt.exr" || ! grep -qa "sy:samples" "$W/pt.exr"; then
    fail "graceful interrupt: the EXR header lacks sy:samples / sy:interrupted"
elif ! grep -q "interrupted: wrote the image of [1-9][0-9]* samples per pixel" "$W/pt.err"; then
    fail "graceful interrupt: no report of the samples kept"
else
    echo "ok: graceful interrupt -> $(tail -n 1 "$W/pt.out")"
fi
leftovers && fail "graceful interrupt left a temporary file: $(ls "$W")"

# 2. two interrupts while the (large, multi-channel) image is being written: abort, nothing left
"$SY" render demo -b pathtracer --spp 1 --aov -w 1200 -h 1200 -o "$W/aov.exr" >"$W/aov.out" 2>"$W/aov.err" &
pid=$!
if wait_for "$W/aov.exr.tmp-*"; then
    kill -TERM $pid
    sleep 0.05
    kill -TERM $pid 2>/dev/null
fi
wait $pid
rc=$?
if [ $rc -ne 143 ]; then fail "second interrupt while writing: status $rc (want 143, killed by SIGTERM)"
elif [ -e "$W/aov.exr" ]; then fail "second interrupt while writing: an image was written"
else echo "ok: second interrupt while writing -> status $rc, no image"
fi
leftovers && fail "interrupt while writing left a temporary file: $(ls "$W")"

# 3. a single-pass back-end: the first interrupt while writing aborts
"$SY" render demo -b whitted -w 1000 -h 1000 -o "$W/w.png" >"$W/w.out" 2>"$W/w.err" &
pid=$!
wait_for "$W/w.png.tmp-*" && kill -INT $pid
wait $pid
rc=$?
if [ $rc -ne 130 ] || [ -e "$W/w.png" ]; then fail "interrupt while writing a PNG: status $rc (want 130), image: $(ls "$W")"
else echo "ok: interrupt while writing a PNG -> status $rc, no image"
fi
leftovers && fail "interrupt while writing a PNG left a temporary file: $(ls "$W")"

# 4. an interrupt during a single-pass render: nothing written
"$SY" render demo -b whitted -w 1000 -h 1000 --params light_samples=64 -o "$W/r.exr" >"$W/r.out" 2>"$W/r.err" &
pid=$!
sleep 0.5
kill -TERM $pid
wait $pid
rc=$?
if [ $rc -ne 143 ] || compgen -G "$W/r.exr*" >/dev/null; then fail "interrupt while rendering: status $rc, files: $(ls "$W")"
else echo "ok: interrupt while rendering -> status $rc, nothing written"
fi
[ $fails -eq 0 ] || { echo "interrupt_test: $fails failure(s)"; exit 1; }
