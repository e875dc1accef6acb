#!/usr/bin/env bash
# cluster_cli_test.sh SY WORKDIR [TESTDATA] EXR_EQUAL — `sy serve` and `sy render --cluster` through the command line:
# two authenticated servers on free loopback ports, sort-first output equal to a local render
# (EXR bytes), a wrong secret refused with a logged reason, a non-loopback listen refused without
# a secret, multi-display tiles written by the servers at the swap barrier. Servers stop by
# themselves (--max-lifetime) and are killed on exit; every wait is bounded. With TESTDATA (the
# shared test data): side-by-side stereo with a raster overlay on the cluster equals the local
# composite (one render path: nothing the local window does is dropped); BoxAnimated at --at 2 on the
# cluster equals the local render at that time (the moved nodes reach the replicas as changes).
. "$(dirname "$0")/servers.sh" # SY W DATA EXR_EQUAL, pids killed on exit, fail, wait_until
printf 'cli-test-secret\n' > "$W/secret"; chmod 600 "$W/secret"
start() { # name [extra args]
  local n=$1; shift
  "$SY" serve --listen tcp://127.0.0.1:0 --port-file "$W/$n.port" --secret-file "$W/secret" --max-lifetime 900 "$@" \
    2> "$W/$n.log" &
  pids+=($!)
  wait_until $! test -s "$W/$n.port" || fail "server $n did not start"
}
start a --output "$W/wall_a.exr"
start b --output "$W/wall_b.exr"
URLS="tcp://127.0.0.1:$(cat "$W/a.port"),tcp://127.0.0.1:$(cat "$W/b.port")"

"$SY" render demo -b whitted -w 120 -h 80 -o "$W/local.exr" > /dev/null || fail "local render"
"$SY" render demo -b whitted -w 120 -h 80 -o "$W/cluster.exr" --cluster "$URLS" --secret-file "$W/secret" \
  --cluster-mode sort-first 2> "$W/client.log" > /dev/null || fail "cluster render"
"$EXR_EQUAL" "$W/local.exr" "$W/cluster.exr" || fail "sort-first EXR differs from the local render"
SY_CLUSTER_SECRET=cli-test-secret "$SY" render demo -b whitted -w 120 -h 80 -o "$W/balanced.exr" --cluster "$URLS" \
  --cluster-mode balanced --repeat 3 2> "$W/client2.log" > /dev/null || fail "balanced render (secret from env)"
"$EXR_EQUAL" "$W/local.exr" "$W/balanced.exr" || fail "balanced EXR differs from the local render"

# stereo + a raster overlay: the same window as locally, the main viewport on the cluster
DUCK="$DATA/gltf/Duck/glTF-Binary/Duck.glb"
if [ -n "$DATA" ] && [ -f "$DUCK" ]; then
  "$SY" render demo -b whitted -w 320 -h 240 --stereo sbs --overlay "$DUCK:raster" -o "$W/sbs_local.exr" > /dev/null ||
    fail "local stereo render with overlay"
  "$SY" render demo -b whitted -w 320 -h 240 --stereo sbs --overlay "$DUCK:raster" -o "$W/sbs_cluster.exr" \
    --cluster "$URLS" --secret-file "$W/secret" > "$W/sbs.out" 2> "$W/sbs.err" || fail "cluster stereo render with overlay"
  grep -q "640x240, whitted on 2 servers (sort-first)" "$W/sbs.out" || fail "the cluster stereo image is not 640x240"
  "$EXR_EQUAL" "$W/sbs_local.exr" "$W/sbs_cluster.exr" || fail "cluster stereo + overlay differs from the local composite"
  # a request the cluster cannot serve is refused at set-up, naming the node and the reason
  if "$SY" render demo -b whitted -w 32 -h 24 -o "$W/coopw.exr" --cluster "$URLS" --secret-file "$W/secret" \
    --cluster-mode cooperative 2> "$W/coopw.err"; then fail "cooperative whitted was accepted"; fi
  grep -q "server 1 (tcp://127.0.0.1:[0-9]*) renders with whitted" "$W/coopw.err" || fail "the refusal does not name the node"
else
  echo "note: stereo + overlay part skipped: no test data at '$DATA' (Duck.glb)"
fi

# the scene clock: the client sets the time, the servers' replicas follow through the change list
BOXANIM="$DATA/gltf/BoxAnimated/glTF-Binary/BoxAnimated.glb"
if [ -n "$DATA" ] && [ -f "$BOXANIM" ]; then
  "$SY" render "$BOXANIM" -b whitted -w 96 -h 72 --at 2 -o "$W/anim_local.exr" > /dev/null || fail "local render --at 2"
  "$SY" render "$BOXANIM" -b whitted -w 96 -h 72 --at 0 -o "$W/anim_local0.exr" > /dev/null || fail "local render --at 0"
  "$SY" render "$BOXANIM" -b whitted -w 96 -h 72 --at 2 -o "$W/anim_cluster.exr" --cluster "$URLS" \
    --secret-file "$W/secret" --cluster-mode sort-first 2> "$W/anim.err" > /dev/null || fail "cluster render --at 2"
  "$EXR_EQUAL" "$W/anim_local.exr" "$W/anim_cluster.exr" || fail "cluster render --at 2 differs from the local one"
  if "$EXR_EQUAL" "$W/anim_local0.exr" "$W/anim_cluster.exr" 2> /dev/null; then
    fail "cluster render --at 2 equals the render at 0 (the time did not travel)"
  fi
else
  echo "note: animation part skipped: no test data at '$DATA' (BoxAnimated.glb)"
fi

# wrong secret: refused, reason logged on the server, exit code 2
if SY_CLUSTER_SECRET=nope "$SY" render demo -b whitted -w 16 -h 16 -o "$W/x.exr" --cluster "$URLS" 2> "$W/bad.err"; then
  fail "a wrong secret was accepted"
fi
grep -q "wrong secret" "$W/bad.err" || fail "client error does not name the reason"
wait_until "${pids[0]}" grep -q "authentication failed: wrong secret" "$W/a.log" || fail "server did not log the rejection"
[ ! -e "$W/x.exr" ] || fail "an output file was written after a refused connection"
sleep 0.3 # the servers refuse this address for 250 ms after a failed authentication (--auth-backoff-ms)

# half-float tiles: accepted by the option parser and the servers; a bad value is a usage error
"$SY" render demo -b whitted -w 120 -h 80 -o "$W/half.exr" --cluster "$URLS" --secret-file "$W/secret" \
  --cluster-pixels half 2> "$W/client3.log" > /dev/null || fail "cluster render with --cluster-pixels half"
[ -s "$W/half.exr" ] || fail "no image from the half-float cluster render"
if "$SY" render demo -b whitted -o "$W/y.exr" --cluster "$URLS" --cluster-pixels double 2> /dev/null; then
  fail "--cluster-pixels double was accepted"
fi

# multi-display: each server writes its column at the swap barrier
"$SY" render demo -b whitted -w 120 -h 80 -o "$W/unused.exr" --cluster "$URLS" --secret-file "$W/secret" \
  --cluster-mode multi-display > "$W/md.out" 2> "$W/md.err" || fail "multi-display render"
[ -s "$W/wall_a.exr" ] && [ -s "$W/wall_b.exr" ] || fail "multi-display tiles were not written"

# a wall layout from a configuration file, with a different back-end per server
rm -f "$W/wall_a.exr" "$W/wall_b.exr"
cat > "$W/wall.conf" <<CONF
# two displays side by side; the right one is a raster preview node
mode multi-display
server tcp://127.0.0.1:$(cat "$W/a.port") backend whitted tile 0 0 60 80
server tcp://127.0.0.1:$(cat "$W/b.port") backend raster  tile 60 0 60 80
CONF
"$SY" render demo -b whitted -w 120 -h 80 -o "$W/unused.exr" --cluster "$W/wall.conf" --secret-file "$W/secret" \
  > "$W/conf.out" 2> "$W/conf.err" || fail "multi-display from a configuration file"
[ -s "$W/wall_a.exr" ] && [ -s "$W/wall_b.exr" ] || fail "configured wall tiles were not written"
grep -q "wall presented" "$W/conf.out" || fail "no multi-display summary"
printf 'server tcp://127.0.0.1:1 tile 0 0 0 5\n' > "$W/bad.conf"
if "$SY" render demo -b whitted -w 16 -h 16 -o "$W/x.exr" --cluster "$W/bad.conf" 2> "$W/badconf.err"; then
  fail "an empty wall tile was accepted"
fi
grep -q "bad.conf:1: empty tile" "$W/badconf.err" || fail "configuration error does not name file:line"

# TLS (nng's mbedTLS transport): a self-signed certificate for "localhost" (mbedTLS 2.28 matches
# DNS names, not IP addresses); the right CA renders the same image, a wrong CA is refused
if command -v openssl > /dev/null; then
  for n in srv other; do
    openssl req -x509 -newkey rsa:2048 -nodes -keyout "$W/$n.key" -out "$W/$n.crt" -days 2 -subj "/CN=$n" \
      -addext "subjectAltName=DNS:localhost" 2> /dev/null || fail "openssl could not make a certificate"
  done
  "$SY" serve --listen tls+tcp://127.0.0.1:0 --port-file "$W/tls.port" --tls-cert "$W/srv.crt" --tls-key "$W/srv.key" \
    --secret-file "$W/secret" --max-lifetime 900 2> "$W/tls.log" &
  pids+=($!)
  wait_until $! test -s "$W/tls.port" || fail "TLS server did not start"
  TLS="tls+tcp://localhost:$(cat "$W/tls.port")"
  "$SY" render demo -b whitted -w 120 -h 80 -o "$W/tls.exr" --cluster "$TLS" --tls-ca "$W/srv.crt" \
    --secret-file "$W/secret" > /dev/null 2> "$W/tlsclient.log" || fail "TLS render"
  "$EXR_EQUAL" "$W/local.exr" "$W/tls.exr" || fail "TLS image differs from the local render"
  if "$SY" render demo -b whitted -w 16 -h 16 -o "$W/tlsbad.exr" --cluster "$TLS" --tls-ca "$W/other.crt" \
    --secret-file "$W/secret" --timeout-ms 3000 > /dev/null 2> "$W/tlsbad.err"; then
    fail "a server certificate from an unknown CA was accepted"
  fi
else
  echo "note: TLS part skipped: openssl is not installed"
fi

# no secret + non-loopback address: refused before listening
if env -u SY_CLUSTER_SECRET "$SY" serve --listen tcp://0.0.0.0:0 --max-lifetime 2 2> "$W/open.err"; then
  fail "listening on 0.0.0.0 without a secret was allowed"
fi
grep -q "not a loopback address" "$W/open.err" || fail "no reason for refusing 0.0.0.0"
echo "cluster_cli: ok"
