#!/usr/bin/env bash
# cluster_frames_test.sh SY WORKDIR TESTDATA EXR_EQUAL — `sy render --frames A:B --cluster-mode frames`
# (issue 35): whole frames of a sequence on two loopback `sy serve` processes from a work queue,
# each server setting its replica's scene clock (RENDER's time) and restarting the path tracer's
# accumulation per frame:
#   - 10 frames of BoxAnimated with the path tracer (fixed spp): every frame written and equal, pixel
#     for pixel (exr_equal), to the same frame of a local sequence; both servers took frames;
#   - a sort-first sequence (the cluster mediator) equals the local frames too, a still one included;
#   - --resume: only the frames whose output is missing are rendered (an existing one is left alone);
#   - a server killed with SIGKILL mid-sequence (12 costlier frames; killed once the first is written):
#     every frame is still written, equal to the local one, and the summary counts the re-queued frame;
#   - usage: frames mode without --frames, and with a video, is refused (status 2).
# Servers stop by themselves (--max-lifetime) and are killed on exit; every wait is bounded.
. "$(dirname "$0")/servers.sh" # SY W DATA EXR_EQUAL, pids killed on exit, fail, wait_until

# usage errors need no servers nor test data
"$SY" render demo -b whitted -w 16 -h 16 -o "$W/u.exr" --cluster tcp://127.0.0.1:1 --cluster-mode frames 2> "$W/u1.err"
[ $? -eq 2 ] && grep -qF -- "--cluster-mode frames renders sequences" "$W/u1.err" || fail "frames mode without --frames: $(cat "$W/u1.err")"
"$SY" render demo -b whitted -w 16 -h 16 -o "$W/u.mp4" --frames 0:1 --cluster tcp://127.0.0.1:1 --cluster-mode frames \
  2> "$W/u2.err"
[ $? -eq 2 ] && grep -qF "no video" "$W/u2.err" || fail "frames mode with a video: $(cat "$W/u2.err")"

BOXANIM="$DATA/gltf/BoxAnimated/glTF-Binary/BoxAnimated.glb"
if [ -z "$DATA" ] || [ ! -f "$BOXANIM" ]; then
  echo "skip: no test data at '$DATA' (BoxAnimated.glb)"
  exit 77
fi
printf 'frames-test-secret\n' > "$W/secret"; chmod 600 "$W/secret"
start() { # name
  "$SY" serve --listen tcp://127.0.0.1:0 --port-file "$W/$1.port" --secret-file "$W/secret" --max-lifetime 900 \
    2> "$W/$1.log" &
  pids+=($!)
  eval "pid_$1=$!"
  wait_until $! test -s "$W/$1.port" || fail "server $1 did not start"
}
start a
start b
URLS="tcp://127.0.0.1:$(cat "$W/a.port"),tcp://127.0.0.1:$(cat "$W/b.port")"
ARGS=(-b pathtracer --spp 4 -w 32 -h 24)
"$SY" render "$BOXANIM" "${ARGS[@]}" --frames 0:9 -o "$W/local_####.exr" > "$W/local.out" 2> "$W/local.err" ||
  fail "local sequence"
"$SY" render "$BOXANIM" "${ARGS[@]}" --frames 0:9 -o "$W/farm_####.exr" --cluster "$URLS" --secret-file "$W/secret" \
  --cluster-mode frames > "$W/farm.out" 2> "$W/farm.err" || fail "frames mode sequence"
grep -qF "frames 0..9 step 1 at 24 fps: 10 written, 0 skipped" "$W/farm.out" || fail "frames mode: $(cat "$W/farm.out")"
for k in 0 1 2 3 4 5 6 7 8 9; do
  "$EXR_EQUAL" "$W/local_000$k.exr" "$W/farm_000$k.exr" > /dev/null 2>&1 || fail "frame $k differs from the local sequence's"
done
"$EXR_EQUAL" "$W/farm_0000.exr" "$W/farm_0009.exr" > /dev/null 2>&1 && fail "frames 0 and 9 are the same image"
# the work queue gave both servers frames (each renders one at a time while 10 wait)
grep -qE "frames per server [1-9][0-9]* [1-9][0-9]*," "$W/farm.out" || fail "not both servers rendered: $(cat "$W/farm.out")"

# a sequence through the cluster mediator (sort-first) restarts the servers' accumulations per frame
# too (sy_context_restart travels as RENDER's RESTART): equal to the local frames, also where nothing
# moved (past the clip's end, 199 and 200: without the restart the servers would go on accumulating)
"$SY" render "$BOXANIM" "${ARGS[@]}" --frames 199:200 -o "$W/local_####.exr" > /dev/null 2>&1 || fail "local 199:200"
for fr in 0:2 199:200; do
  "$SY" render "$BOXANIM" "${ARGS[@]}" --frames "$fr" -o "$W/sf_####.exr" --cluster "$URLS" --secret-file "$W/secret" \
    --cluster-mode sort-first > "$W/sf.out" 2> "$W/sf.err" || fail "sort-first sequence $fr"
done
for k in 0000 0001 0002 0199 0200; do
  "$EXR_EQUAL" "$W/local_$k.exr" "$W/sf_$k.exr" > /dev/null 2>&1 || fail "sort-first sequence: frame $k differs"
done

# --resume: frames 3 and 7 missing, frame 5 a marker that must stay
rm "$W/farm_0003.exr" "$W/farm_0007.exr"
echo keep > "$W/farm_0005.exr"
"$SY" render "$BOXANIM" "${ARGS[@]}" --frames 0:9 -o "$W/farm_####.exr" --cluster "$URLS" --secret-file "$W/secret" \
  --cluster-mode frames --resume > "$W/resume.out" 2> "$W/resume.err" || fail "frames mode --resume"
grep -qF "2 written, 8 skipped" "$W/resume.out" || fail "--resume: $(cat "$W/resume.out")"
[ "$(cat "$W/farm_0005.exr")" = keep ] || fail "--resume rewrote an existing frame"
for k in 3 7; do
  "$EXR_EQUAL" "$W/local_000$k.exr" "$W/farm_000$k.exr" > /dev/null 2>&1 || fail "--resume: frame $k differs"
done

# a server killed mid-sequence: its frame in flight goes back to the queue, every frame is written
# (frames that cost more, so that many are left when the first one is written and b is killed)
KARGS=(-b pathtracer --spp 16 -w 48 -h 36)
"$SY" render "$BOXANIM" "${KARGS[@]}" --frames 0:11 -o "$W/klocal_####.exr" > "$W/klocal.out" 2> "$W/klocal.err" ||
  fail "local sequence (kill part)"
"$SY" render "$BOXANIM" "${KARGS[@]}" --frames 0:11 -o "$W/kill_####.exr" --cluster "$URLS" --secret-file "$W/secret" \
  --cluster-mode frames --timeout-ms 60000 > "$W/kill.out" 2> "$W/kill.err" &
client=$!
wait_until $client sh -c "ls '$W' | grep -q '^kill_.*\.exr$'" || fail "no frame written before the kill"
kill -9 "$pid_b"
wait "$pid_b" 2> /dev/null
wait "$client" || fail "frames mode with a killed server: status $?"
grep -qF "12 written, 0 skipped" "$W/kill.out" || fail "killed server: $(cat "$W/kill.out")"
grep -qE "[1-9][0-9]* re-queued, [1-9][0-9]* server failures" "$W/kill.out" || fail "killed server: no frame re-queued: $(cat "$W/kill.out")"
for k in 00 01 02 03 04 05 06 07 08 09 10 11; do
  "$EXR_EQUAL" "$W/klocal_00$k.exr" "$W/kill_00$k.exr" > /dev/null 2>&1 || fail "killed server: frame $k differs"
done
ls -a "$W" | grep -q '\.tmp-' && fail "temporary files left: $(ls -a "$W" | grep tmp)"
echo "cluster_frames_test: all checks passed"
