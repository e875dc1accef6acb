#!/usr/bin/env bash
# farm_bench.sh — the render farm's throughput (issue 35, "Farm throughput"): a sequence of an
# animated scene with the path tracer at fixed spp, rendered locally and with `--cluster-mode frames`
# on 1, 2 and 3 loopback `sy serve` processes; prints frames per minute (all, per server), the CPU
# seconds per frame (client + servers, from /proc), the frames each server took, and checks that
# every frame equals the local sequence's (exr_equal: pixel for pixel). Then one run on 2 servers
# with one of them killed (SIGKILL) once the first frame is written: every frame still written and
# equal, and what the kill cost (frames re-queued, the run's time against the 2-server run).
#
#   tests/anim/farm_bench.sh SY EXR_EQUAL [SCENE] [WORKDIR]
#       env: FRAMES (48), SPP (16), W_PX (160), H_PX (120), SERVERS ("1 2 3"), KILL (1: the kill run),
#            MPI (1: the same sequences through `mpirun -np N+1 ... --cluster mpi`, rank 0 the client,
#            when mpirun is there and sy was built with MPI; CPU time: mpirun's and its ranks'),
#            TCP (1: the loopback `sy serve` runs; 0: MPI and the local sequence only)
#
# A measurement, not a test of the suite (its numbers depend on the machine and its load: no timed
# tests). SCENE defaults to ../shared/testdata/gltf/BoxAnimated/glTF-Binary/BoxAnimated.glb next to
# the repository; exit 77 when it is absent, 1 when a frame differs or a run fails, 0 otherwise.
# Every server and the client render on one thread (threads=1) so that N servers are N busy
# processes; on a machine with fewer cores than servers they share them ("oversubscribed
# honestly": the CPU seconds per frame show the work did not grow, the frames per minute show
# the cores did not either).
set -u
SY=${1:?usage: farm_bench.sh SY EXR_EQUAL [SCENE] [WORKDIR]}
EXR_EQUAL=${2:?exr_equal}
HERE=$(cd "$(dirname "$0")" && pwd)
SCENE=${3:-$HERE/../../../shared/testdata/gltf/BoxAnimated/glTF-Binary/BoxAnimated.glb}
W=${4:-$(mktemp -d /tmp/sy_farm.XXXXXX)}
FRAMES=${FRAMES:-48} SPP=${SPP:-16} W_PX=${W_PX:-160} H_PX=${H_PX:-120} SERVERS=${SERVERS:-"1 2 3"} KILL=${KILL:-1}
[ -f "$SCENE" ] || { echo "skip: no scene at $SCENE"; exit 77; }
mkdir -p "$W"
. "$HERE/../support/wait.sh"
pids=()
cleanup() { for p in "${pids[@]}"; do kill "$p" 2>/dev/null; done; wait 2>/dev/null; }
trap cleanup EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
LAST=$((FRAMES - 1))
ARGS=(-b pathtracer --spp "$SPP" -w "$W_PX" -h "$H_PX" --params threads=1 --frames "0:$LAST")
TCK=$(getconf CLK_TCK)
# cpu PID: the process's user + system CPU seconds so far (children included once they were waited)
cpu() { awk -v t="$TCK" '{ printf "%.2f", ($14 + $15 + $16 + $17) / t }' "/proc/$1/stat" 2>/dev/null || echo 0; }
now() { date +%s.%N; }

start_server() { # NAME: a loopback server, its pid in srv_NAME
  rm -f "$W/$1.port"
  "$SY" serve --listen tcp://127.0.0.1:0 --port-file "$W/$1.port" --max-lifetime 3600 2> "$W/$1.log" &
  pids+=($!)
  eval "srv_$1=$!"
  wait_until $! test -s "$W/$1.port" || fail "server $1 did not start"
}

compare() { # PREFIX: every frame equal to the local one
  local k f
  for ((k = 0; k <= LAST; ++k)); do
    f=$(printf '%04d' "$k")
    "$EXR_EQUAL" "$W/local_$f.exr" "$W/$1_$f.exr" > /dev/null 2>&1 || fail "$1: frame $k differs from the local sequence's"
  done
}

echo "farm_bench: $FRAMES frames of $(basename "$SCENE"), ${W_PX}x${H_PX}, path tracer $SPP spp, one thread per" \
  "process; $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg)"
t0=$(now)
/usr/bin/env time -f '%U %S' -o "$W/local.time" "$SY" render "$SCENE" "${ARGS[@]}" -o "$W/local_####.exr" \
  > "$W/local.out" 2> "$W/local.err" || fail "local sequence: $(cat "$W/local.err")"
t1=$(now)
read -r lu ls < "$W/local.time"
awk -v f="$FRAMES" -v a="$t0" -v b="$t1" -v u="$lu" -v s="$ls" 'BEGIN {
  printf "| local (1 process) | %.1f | %.1f | %.2f | %d |\n", 60 * f / (b - a), 60 * f / (b - a), (u + s) / f, f }' \
  > "$W/table"

TCP=${TCP:-1}
for n in $SERVERS; do
  [ "$TCP" = 1 ] || break
  urls="" names=()
  for ((i = 0; i < n; ++i)); do
    start_server "s$n$i"
    names+=("s$n$i")
    urls="$urls${urls:+,}tcp://127.0.0.1:$(cat "$W/s$n$i.port")"
  done
  c0=0
  for s in "${names[@]}"; do c0=$(awk -v a="$c0" -v b="$(cpu "$(eval echo "\$srv_$s")")" 'BEGIN { print a + b }'); done
  t0=$(now)
  /usr/bin/env time -f '%U %S' -o "$W/farm$n.time" "$SY" render "$SCENE" "${ARGS[@]}" -o "$W/farm${n}_####.exr" \
    --cluster "$urls" --cluster-mode frames > "$W/farm$n.out" 2> "$W/farm$n.err" || fail "$n servers: $(cat "$W/farm$n.err")"
  t1=$(now)
  c1=0
  for s in "${names[@]}"; do c1=$(awk -v a="$c1" -v b="$(cpu "$(eval echo "\$srv_$s")")" 'BEGIN { print a + b }'); done
  read -r cu cs < "$W/farm$n.time"
  per=$(grep -o 'frames per server [0-9 ]*' "$W/farm$n.out" | sed 's/frames per server //; s/ *$//; s/ /+/g')
  awk -v f="$FRAMES" -v n="$n" -v a="$t0" -v b="$t1" -v u="$cu" -v s="$cs" -v c0="$c0" -v c1="$c1" -v p="$per" 'BEGIN {
    printf "| %d server%s | %.1f | %.1f | %.2f (servers %.2f) | %s |\n", n, (n > 1 ? "s" : ""), 60 * f / (b - a),
      60 * f / (b - a) / n, (c1 - c0 + u + s) / f, (c1 - c0) / f, p }' >> "$W/table"
  compare "farm$n"
  for s in "${names[@]}"; do kill "$(eval echo "\$srv_$s")" 2>/dev/null; done
done

MPI=${MPI:-1}
if [ "$MPI" = 1 ] && command -v mpirun > /dev/null; then
  # root in a container: Open MPI refuses root unless told; oversubscribed: more ranks than cores
  export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
  for n in $SERVERS; do
    t0=$(now)
    if ! /usr/bin/env time -f '%U %S' -o "$W/mpi$n.time" timeout 900 mpirun --oversubscribe -np $((n + 1)) "$SY" render \
      "$SCENE" "${ARGS[@]}" -o "$W/mpi${n}_####.exr" --cluster mpi --cluster-mode frames > "$W/mpi$n.out" 2> "$W/mpi$n.err"; then
      grep -q "built without MPI" "$W/mpi$n.err" && { echo "(MPI: sy was built without MPI; skipped)"; break; }
      fail "MPI, $n servers: $(tail -3 "$W/mpi$n.err")"
    fi
    t1=$(now)
    read -r cu cs < "$W/mpi$n.time"
    per=$(grep -o 'frames per server [0-9 ]*' "$W/mpi$n.out" | sed 's/frames per server //; s/ *$//; s/ /+/g')
    awk -v f="$FRAMES" -v n="$n" -v a="$t0" -v b="$t1" -v u="$cu" -v s="$cs" -v p="$per" 'BEGIN {
      printf "| MPI, %d server rank%s | %.1f | %.1f | %.2f (all ranks) | %s |\n", n, (n > 1 ? "s" : ""), 60 * f / (b - a),
        60 * f / (b - a) / n, (u + s) / f, p }' >> "$W/table"
    compare "mpi$n"
  done
fi

echo
echo "| | frames / min | per server | CPU s / frame | frames per server |"
echo "|---|---|---|---|---|"
cat "$W/table"

if [ "$KILL" = 1 ] && [ "$TCP" = 1 ]; then
  start_server ka
  start_server kb
  urls="tcp://127.0.0.1:$(cat "$W/ka.port"),tcp://127.0.0.1:$(cat "$W/kb.port")"
  t0=$(now)
  "$SY" render "$SCENE" "${ARGS[@]}" -o "$W/kill_####.exr" --cluster "$urls" --cluster-mode frames --timeout-ms 600000 \
    > "$W/kill.out" 2> "$W/kill.err" &
  client=$!
  pids+=($client)
  # kill kb once the client has written a third of the frames: it has a frame in flight then
  wait_until $client sh -c "[ \$(ls '$W' | grep -c '^kill_.*\.exr$') -ge $((FRAMES / 3)) ]" ||
    fail "kill run: frames not written"
  tk=$(now)
  kill -9 "$srv_kb"
  wait "$srv_kb" 2>/dev/null
  wait "$client" || fail "kill run: status $?: $(cat "$W/kill.err")"
  t1=$(now)
  compare kill
  echo
  echo "kill -9 of one of 2 servers after $((FRAMES / 3)) frames ($(awk -v a="$t0" -v b="$tk" 'BEGIN { printf "%.1f", b - a }') s):" \
    "run $(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.1f", b - a }') s; $(grep -o 'frames per server.*' "$W/kill.out")"
fi
echo "farm_bench: every frame of every run equal to the local sequence's (exr_equal); outputs in $W"
