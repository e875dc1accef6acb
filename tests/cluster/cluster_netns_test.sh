#!/usr/bin/env bash
# cluster_netns_test.sh SY WORKDIR EXR_EQUAL — a render server in its own network namespace (a separate
# host as far as TCP is concerned, joined by a veth pair), rendered from the root namespace with a
# shared secret; the image must equal a local render. Skipped (77, with the reason) unless running
# as root with `ip netns` working.
set -u
SY=$1; W=$2; EXR_EQUAL=${3:?exr_equal}
[ "$(id -u)" = 0 ] || { echo "SKIP: needs root for ip netns"; exit 77; }
command -v ip > /dev/null || { echo "SKIP: the ip tool (iproute2) is not installed"; exit 77; }
NS=sytest$$
ip netns add "$NS" 2> "$W.err" || { echo "SKIP: ip netns add failed: $(cat "$W.err")"; exit 77; }
cleanup() { [ -n "${SPID:-}" ] && kill "$SPID" 2>/dev/null; ip link del "v$NS" 2>/dev/null; ip netns del "$NS" 2>/dev/null; }
trap cleanup EXIT
rm -rf "$W"; mkdir -p "$W"
if ! ip link add "v$NS" type veth peer name "p$NS" 2> "$W/err" || ! ip link set "p$NS" netns "$NS" 2>> "$W/err"; then
  echo "SKIP: cannot create a veth pair here: $(cat "$W/err")"; exit 77
fi
ip addr add 10.213.0.1/24 dev "v$NS" && ip link set "v$NS" up &&
  ip netns exec "$NS" ip addr add 10.213.0.2/24 dev "p$NS" && ip netns exec "$NS" ip link set "p$NS" up &&
  ip netns exec "$NS" ip link set lo up || { echo "SKIP: cannot configure the veth pair"; exit 77; }
printf 'netns-secret' > "$W/secret"; chmod 600 "$W/secret"
ip netns exec "$NS" "$SY" serve --listen tcp://10.213.0.2:5791 --port-file "$W/port" --secret-file "$W/secret" \
  --max-lifetime 900 2> "$W/server.log" &
SPID=$!
. "$(dirname "$0")/../support/wait.sh" # the server listens once it has written its port (no sleep)
wait_until $SPID test -s "$W/port" || { echo "FAIL: the server in the namespace did not start"; cat "$W/server.log"; exit 1; }
"$SY" render demo -b whitted -w 64 -h 48 -o "$W/local.exr" > /dev/null || { echo "FAIL: local render"; exit 1; }
"$SY" render demo -b whitted -w 64 -h 48 -o "$W/remote.exr" --cluster tcp://10.213.0.2:5791 --secret-file "$W/secret" \
  --timeout-ms 20000 > /dev/null 2> "$W/client.log" || { echo "FAIL: remote render"; cat "$W"/*.log; exit 1; }
"$EXR_EQUAL" "$W/local.exr" "$W/remote.exr" || { echo "FAIL: image across namespaces differs"; exit 1; }
echo "cluster_netns: ok"
