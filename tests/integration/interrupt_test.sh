#!/usr/bin/env bash
# interrupt_test.sh SY TMPDIR — SIGINT / SIGTERM never leave half an image or a temporary file
# (issue 14, finding 6):
#  1. a progressive render interrupted once finishes its pass and writes the image accumulated so
#     far (exit 130, sy:samples and sy:interrupted in the EXR header);
#  2. two interrupts while the image is being written: no image, no "*.tmp-*", killed by SIGTERM;
#  3. one interrupt while a single-pass back-end writes: the same;
#  4. an interrupt during a single-pass render: no file at all.
# No step sleeps or depends on how fast sy runs (issue 32): sy announces the phase it is in
# (SY_TEST_PHASES, apps/sy/sy_testpoint.h) and the test polls for it; where the interrupt must land in
# a phase, sy stops there until the signal comes (SY_TEST_PAUSE).
set -u
set -m # job control: background jobs keep SIGINT (a script's background jobs otherwise ignore it)
SY=$1
W=$2
rm -rf "$W"
mkdir -p "$W"
fails=0
fail() { echo "FAIL: $*"; for f in "$W"/*.err; do [ -e "$f" ] && { echo "--- $f"; cat "$f"; }; done; fails=$((fails + 1)); }
# phases NAME: a FIFO for sy's announced phases, open on descriptor 3 (read-write, so sy's open and
# writes never block); pass SY_TEST_PHASES="$W/NAME.fifo" to sy
phases() { rm -f "$W/$1.fifo"; mkfifo "$W/$1.fifo" && exec 3<>"$W/$1.fifo"; }
# wait_phase PHASE: blocks until sy announces PHASE; the 120 s bound is only a hang guard (sy ended
# or stuck without reaching it), and it fails loudly
wait_phase() {
    local line
    while read -r -t 120 -u 3 line; do [ "$line" = "$1" ] && return 0; done
    echo "FAIL: sy did not announce the phase '$1' within 120 s"
    return 1
}
leftovers() { compgen -G "$W/*.tmp-*" >/dev/null; }
# render_bg NAME PAUSE ARGS...: `sy render demo ARGS` in the background (its pid in pid, output in
# $W/NAME.out / .err), announcing its phases on NAME's FIFO and, unless PAUSE is empty, held at the
# phase PAUSE until a signal comes
render_bg() {
    local name=$1 pause=$2
    shift 2
    phases "$name"
    SY_TEST_PHASES="$W/$name.fifo" SY_TEST_PAUSE=$pause "$SY" render demo "$@" >"$W/$name.out" 2>"$W/$name.err" &
    pid=$!
}
# ended: waits for that sy; its exit status in rc
ended() {
    wait $pid
    rc=$?
}

# 1. graceful: the first SIGINT ends the progressive render after its current pass
render_bg pt "" -b pathtracer --spp 1000000 -w 64 -h 48 -o "$W/pt.exr"
wait_phase pass && kill -INT $pid # after a finished pass: the interrupt is graceful
ended
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

# 2. two interrupts while the (multi-channel) image is being written: abort, nothing left
render_bg aov commit -b pathtracer --spp 1 --aov -w 120 -h 120 -o "$W/aov.exr"
if wait_phase commit; then # written, held before the rename
    compgen -G "$W/aov.exr.tmp-*" >/dev/null || fail "second interrupt while writing: no temporary file while writing"
    kill -TERM $pid
    # the first interrupt is graceful: the second, once sy has taken the first, aborts
    wait_phase interrupted && kill -TERM $pid
fi
ended
if [ $rc -ne 143 ]; then fail "second interrupt while writing: status $rc (want 143, killed by SIGTERM)"
elif [ -e "$W/aov.exr" ]; then fail "second interrupt while writing: an image was written"
else echo "ok: second interrupt while writing -> status $rc, no image"
fi
leftovers && fail "interrupt while writing left a temporary file: $(ls "$W")"

# 3. a single-pass back-end: the first interrupt while writing aborts
render_bg w commit -b whitted -w 100 -h 100 -o "$W/w.png"
wait_phase commit && kill -INT $pid
ended
if [ $rc -ne 130 ] || [ -e "$W/w.png" ]; then fail "interrupt while writing a PNG: status $rc (want 130), image: $(ls "$W")"
else echo "ok: interrupt while writing a PNG -> status $rc, no image"
fi
leftovers && fail "interrupt while writing a PNG left a temporary file: $(ls "$W")"

# 4. an interrupt during a single-pass render: nothing written
render_bg r tiles -b whitted -w 100 -h 100 -o "$W/r.exr"
wait_phase tiles && kill -TERM $pid # a tile is done, the render held in progress
ended
if [ $rc -ne 143 ] || compgen -G "$W/r.exr*" >/dev/null; then fail "interrupt while rendering: status $rc, files: $(ls "$W")"
else echo "ok: interrupt while rendering -> status $rc, nothing written"
fi
[ $fails -eq 0 ] || { echo "interrupt_test: $fails failure(s)"; exit 1; }
