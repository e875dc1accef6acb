#!/usr/bin/env bash
# view_cluster_test.sh SY PNG_COMPARE TMPDIR — `sy view --cluster` in a real window under Xvfb
# against two authenticated `sy serve` processes on free loopback ports:
#   1. sort-first: the window's screenshot equals the local viewer's screenshot byte for byte (the
#      cluster image is bit-identical to a local render) and sy render's PNG within 2 of 255;
#   2. cooperative path tracing: one server is killed (SIGKILL) while the viewer refines; the
#      viewer goes on with the other, reports it in the title and exits normally;
#   3. multi-display from a configuration file: the servers write their wall tiles at the swap
#      barrier, the window shows the configured viewer tile.
# Skipped (77) when xvfb-run is missing or sy was built without GLFW. Every wait is bounded; the
# servers stop by themselves (--max-lifetime) and are killed on exit.
set -u
. "$(dirname "$0")/view_setup.sh"
pids=()
cleanup() { for p in "${pids[@]}"; do kill "$p" 2>/dev/null; done; wait 2>/dev/null; }
trap cleanup EXIT
fail() { echo "FAIL: $*"; for f in "$W"/*.log "$W"/*.err "$W"/*.out; do [ -e "$f" ] && { echo "--- $f"; cat "$f"; }; done; exit 1; }
XVFB=(timeout 500 xvfb-run -a -s "-screen 0 1024x768x24")
# view NAME ARGS...: sy view under Xvfb, stdout/stderr to $W/NAME.out/.err; the title line checks
# that follow every call catch a viewer that failed for a real reason
view() {
    local name=$1
    shift
    "${XVFB[@]}" "$SY" view "$@" >"$W/$name.out" 2>"$W/$name.err"
    local rc=$?
    [ $rc -eq 0 ] || fail "sy view $* exited with status $rc"
}

. "$(dirname "$0")/../support/wait.sh" # wait_until: states, never sleeps (hang guard only)
printf 'view-cluster-secret\n' >"$W/secret"
chmod 600 "$W/secret"
start() { # name [extra args]: a server on a free port; its pid goes to $W/NAME.pid
    local n=$1
    shift
    "$SY" serve --listen tcp://127.0.0.1:0 --port-file "$W/$n.port" --secret-file "$W/secret" --max-lifetime 900 "$@" \
        2>"$W/$n.log" &
    local p=$!
    pids+=("$p")
    echo "$p" >"$W/$n.pid"
    wait_until "$p" test -s "$W/$n.port" || fail "server $n did not start"
}
start a
start b
URLS="tcp://127.0.0.1:$(cat "$W/a.port"),tcp://127.0.0.1:$(cat "$W/b.port")"

# 1. sort-first: bit-identical to the local viewer
view cluster demo -b whitted -w 320 -h 180 --frames 5 --cluster "$URLS" --cluster-mode sort-first --secret-file "$W/secret" \
    --screenshot "$W/cluster.png"
grep -q "cluster sort-first: whitted | 2/2 servers alive" "$W/cluster.out" || fail "the title does not show the mode and servers"
view local demo -b whitted -w 320 -h 180 --frames 5 --screenshot "$W/local.png"
grep -q "sy view | whitted" "$W/local.out" || fail "the local viewer did not finish"
"$CMP" "$W/cluster.png" "$W/local.png" 0 50 || fail "the sort-first cluster window differs from the local viewer"
"$SY" render demo -b whitted -w 320 -h 180 --tonemap aces -o "$W/render.png" >/dev/null || fail "sy render"
"$CMP" "$W/cluster.png" "$W/render.png" 2 50 || fail "the cluster window does not show the rendered image"

# 2. cooperative path tracing; server b is killed once the viewer has rendered with both
rm -f "$W/coop.fifo"
mkfifo "$W/coop.fifo" && exec 3<>"$W/coop.fifo" # the viewer's announced phases (apps/sy/sy_testpoint.h)
SY_TEST_PHASES="$W/coop.fifo" "${XVFB[@]}" "$SY" view demo -b pathtracer -w 64 -h 48 --frames 120 --cluster "$URLS" --cluster-mode cooperative \
    --secret-file "$W/secret" --screenshot "$W/coop.png" >"$W/coop.out" 2>"$W/coop.err" &
viewer=$!
pids+=("$viewer")
# once the viewer, connected to both servers, has shown a frame, b dies (the event, no sleep; the
# 300 s bound of read is a hang guard)
wait_until "$viewer" eval '[ "$(grep -c authenticated "$W/b.log")" -ge 2 ]' ||
    fail "the cooperative viewer did not connect to server b"
shown=
while read -r -t 300 -u 3 line; do [ "$line" = frame ] && { shown=1; break; }; done
[ -n "$shown" ] || fail "the cooperative viewer showed no frame"
{ kill -9 "$(cat "$W/b.pid")"; wait "$(cat "$W/b.pid")"; } 2>/dev/null
wait "$viewer"
rc=$?
if [ $rc -ne 0 ]; then
    fail "sy view --cluster cooperative exited with status $rc after a server died"
fi
grep -q "cluster cooperative: pathtracer | 1/2 servers alive" "$W/coop.out" ||
    fail "the title does not report the lost server"
# the loss is logged as a frame that dropped the server or, when it died between two frames, as
# the failed reconnection at the next one (which of the two depends on timing under load)
grep -Eq "dropped for this frame|cannot connect" "$W/coop.err" || fail "the viewer did not log the lost server"
spp=$(grep -o '[0-9][0-9]* spp' "$W/coop.out" | tail -n 1 | cut -d' ' -f1)
[ -n "$spp" ] && [ "$spp" -ge 2 ] || fail "cooperative refinement did not go on after the loss (spp '$spp')"
"$CMP" "$W/coop.png" "$W/coop.png" 0 20 || fail "the cooperative window is empty"

# 3. multi-display wall from a configuration file; the window shows the right tile
start c --output "$W/wall_c.png"
start d --output "$W/wall_d.png"
cat >"$W/wall.conf" <<CONF
mode multi-display
server tcp://127.0.0.1:$(cat "$W/c.port") tile 0 0 160 180
server tcp://127.0.0.1:$(cat "$W/d.port") tile 160 0 160 180
viewer tile 160 0 160 180
CONF
view wall demo -b whitted -w 320 -h 180 --frames 3 --cluster "$W/wall.conf" --secret-file "$W/secret" \
    --screenshot "$W/wall_view.png"
[ -s "$W/wall_c.png" ] && [ -s "$W/wall_d.png" ] || fail "the servers did not present their wall tiles"
grep -q "cluster multi-display: whitted | 2/2 servers alive" "$W/wall.out" || fail "no multi-display title"
"$CMP" "$W/wall_view.png" "$W/wall_view.png" 0 20 || fail "the viewer tile is empty"
echo "integration_view_cluster: ok"
