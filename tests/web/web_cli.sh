#!/bin/bash
# web_cli: `sy web` as a user starts it: the URL it prints (loopback: no token), the page and a
# still through curl, a clean exit on the first SIGTERM; bad options are refused with the reason;
# --clip: a usage error on a scene without it, and (with the test data) the Fox's timeline plays
# Survey, its first clip, as sy render --at does.
# Usage: web_cli.sh SY [TESTDATA]
set -u
SY=$1
DATA=${2:-}
fail=0
bad() { echo "FAIL: $*"; fail=1; }
command -v curl >/dev/null || { echo "skip: curl is not installed"; exit 77; }
. "$(dirname "$0")/../support/wait.sh" # wait_until: states, never sleeps (hang guard only)
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

"$SY" web demo --listen 127.0.0.1:99999 >/dev/null 2>"$out/err"; rc=$?
[ $rc = 1 ] && grep -q "port must be 0..65535" "$out/err" || bad "a bad port: exit $rc, $(cat "$out/err")"
"$SY" web demo -b no_such_backend --listen 127.0.0.1:0 >/dev/null 2>"$out/err"; rc=$?
[ $rc = 1 ] && grep -q "no_such_backend" "$out/err" || bad "an unknown back-end: exit $rc, $(cat "$out/err")"
"$SY" web demo --quality 0 >/dev/null 2>&1; [ $? = 2 ] || bad "--quality 0 is not a usage error"
"$SY" web demo --clip 1 >/dev/null 2>"$out/err"; rc=$?
[ $rc = 2 ] && grep -q "clip 1: the scene has no animations" "$out/err" || bad "--clip on the demo: exit $rc, $(cat "$out/err")"
fox=$DATA/gltf/Fox/glTF/Fox.gltf
if [ -n "$DATA" ] && [ -f "$fox" ]; then
    "$SY" web "$fox" --clip Nope >/dev/null 2>"$out/err"; rc=$?
    [ $rc = 2 ] && grep -q "available: 0:Survey, 1:Walk, 2:Run" "$out/err" || bad "--clip Nope on the Fox: exit $rc, $(cat "$out/err")"
    # (files of its own: a background job's redirections happen after the fork, so the server below
    # must not find this one's URL in a log it has not truncated yet)
    "$SY" web "$fox" --listen 127.0.0.1:0 -b whitted >"$out/fox.log" 2>"$out/fox.err" &
    pid=$!
    wait_until $pid grep -q 'http://' "$out/fox.log"
    grep -q "the timeline plays clip 0 (Survey) of 3" "$out/fox.err" || bad "the Fox's timeline: $(cat "$out/fox.err")"
    kill -TERM $pid
    wait_gone $pid || kill -9 $pid
    wait $pid
else
    echo "note: the Fox's clip not checked ($fox absent)"
fi

"$SY" web demo --listen 127.0.0.1:0 -b whitted >"$out/log" 2>"$out/err" &
pid=$!
wait_until $pid grep -q 'http://' "$out/log"
url=$(grep -o 'http://[^ ]*' "$out/log" 2>/dev/null | head -1)
if [ -z "$url" ]; then
    bad "no URL printed: $(cat "$out/log" "$out/err")"
else
    case $url in *token=*) bad "a loopback server asks for a token: $url" ;; esac
    origin=${url%/}  # stills and POSTs need the page's own Origin (docs/WEB.md, Security)
    code=$(curl -s -o "$out/page.html" -w '%{http_code}' "$url")
    [ "$code" = 200 ] && grep -q 'id="sy-canvas"' "$out/page.html" || bad "the page: HTTP $code"
    code=$(curl -s -o "$out/still.jpg" -w '%{http_code} %{content_type}' -H "Origin: $origin" "${url}api/frame.jpg?w=64&h=48")
    [ "$code" = "200 image/jpeg" ] || bad "the still: $code"
    head -c 2 "$out/still.jpg" | od -An -tx1 | grep -q "ff d8" || bad "the still is no JPEG"
    code=$(curl -s -o "$out/e" -w '%{http_code}' -H "Origin: $origin" "${url}api/frame.jpg?w=64")
    [ "$code" = 400 ] && grep -q "missing h=" "$out/e" || bad "a still without h: $code $(cat "$out/e")"
    # remote culling (where sy has the culling service): the view, a query, an object, bad input
    code=$(curl -s -o "$out/view.json" -w '%{http_code}' "${url}api/view")
    if [ "$code" = 200 ]; then
        view=$(sed 's/,"target".*/}/' "$out/view.json")
        q=${view%\}},\"width\":64,\"height\":48,\"budget\":100000000\}
        code=$(curl -s -o "$out/cull.json" -w '%{http_code}' -H 'Content-Type: application/json' -H "Origin: $origin" --data "$q" "${url}api/cull")
        id=$(grep -o '"objects":\[{"id":[0-9]*' "$out/cull.json" | grep -o '[0-9]*$')
        [ "$code" = 200 ] && [ -n "$id" ] || bad "POST /api/cull of the server's view: $code $(head -c 300 "$out/cull.json")"
        code=$(curl -s -o "$out/obj.glb" -w '%{http_code} %{content_type}' "${url}api/object/$id")
        [ "$code" = "200 model/gltf-binary" ] && head -c 4 "$out/obj.glb" | grep -q glTF || bad "GET /api/object/$id: $code"
        code=$(curl -s -o "$out/e" -w '%{http_code}' "${url}api/object/4000000000")
        [ "$code" = 404 ] || bad "an unknown object: $code $(cat "$out/e")"
        code=$(curl -s -o "$out/e" -w '%{http_code}' -H 'Content-Type: application/json' -H "Origin: $origin" --data '{"position":[0,0,' "${url}api/cull")
        [ "$code" = 400 ] || bad "malformed JSON: $code $(cat "$out/e")"
        code=$(curl -s -o "$out/e" -w '%{http_code}' -H 'Content-Type: application/json' -H "Origin: $origin" --data "${q/\"fov\":/\"fov\":-}" "${url}api/cull")
        [ "$code" = 400 ] && grep -q fov "$out/e" || bad "a negative fov: $code $(cat "$out/e")"
        # issue 32: a position past SY_COORD_MAX aborted the process in Embree (ray.valid())
        code=$(curl -s -o "$out/e" -w '%{http_code}' -H 'Content-Type: application/json' -H "Origin: $origin" \
            --data "$(echo "$q" | sed 's/"position":\[[^]]*\]/"position":[1e19,0,0]/')" "${url}api/cull")
        [ "$code" = 400 ] && grep -q "position.x" "$out/e" || bad "a position of 1e19: $code $(cat "$out/e")"
        kill -0 $pid 2>/dev/null || bad "sy web died on a position of 1e19"
        # a cross-site "simple" POST (text/plain, another Origin, or none) is refused
        code=$(curl -s -o "$out/e" -w '%{http_code}' -H 'Content-Type: text/plain' -H "Origin: $origin" --data "$q" "${url}api/cull")
        [ "$code" = 415 ] || bad "a text/plain POST: $code $(cat "$out/e")"
        code=$(curl -s -o "$out/e" -w '%{http_code}' -H 'Content-Type: application/json' -H "Origin: http://evil.example" --data "$q" "${url}api/cull")
        [ "$code" = 403 ] || bad "a POST from another origin: $code $(cat "$out/e")"
        code=$(curl -s -o "$out/e" -w '%{http_code}' -H 'Content-Type: application/json' --data "$q" "${url}api/cull")
        [ "$code" = 403 ] || bad "a POST without Origin: $code $(cat "$out/e")"
        code=$(curl -s -o "$out/e" -w '%{http_code}' "${url}client/client.html")
        [ "$code" = 404 ] || bad "the client page without --client-render: $code"
    elif [ "$code" != 404 ]; then
        bad "GET /api/view: $code"
    fi
fi
kill -TERM $pid # (a background job ignores SIGINT)
if ! wait_gone $pid; then bad "sy web did not stop on SIGTERM"; kill -9 $pid; fi
wait $pid; rc=$?
[ $rc = 0 ] || bad "sy web exited $rc after SIGTERM: $(cat "$out/err")"
[ $fail = 0 ] && echo "ok: sy web serves the page and stills, stops on SIGTERM, refuses bad options"
exit $fail
