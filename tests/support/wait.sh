# tests/support/wait.sh — sourced by the shell tests: wait for a state, never for a time (issue 32).
#
# wait_until PID CMD...: runs CMD until it succeeds (true), polling about 20 times a second; false
# as soon as process PID has ended with CMD still false ("" or 0: no process to watch), or after the
# hang guard SY_WAIT_GUARD seconds (default 300, generous for the ASan build on two loaded cores;
# it says so on stderr). Nothing here depends on how fast the machine is: the poll interval only
# bounds the waste.
wait_until() {
    local pid=$1 start=$SECONDS
    shift
    while ! "$@"; do
        if [ -n "$pid" ] && [ "$pid" != 0 ] && ! kill -0 "$pid" 2>/dev/null; then
            "$@" # the state may have come just before the process ended
            return
        fi
        if [ $((SECONDS - start)) -ge "${SY_WAIT_GUARD:-300}" ]; then
            echo "wait_until: hang guard: '$*' still false after ${SY_WAIT_GUARD:-300} s" >&2
            return 1
        fi
        sleep 0.05
    done
}
# wait_gone PID: until process PID has ended (hang guard as above); false if it is still there
wait_gone() {
    local start=$SECONDS
    while kill -0 "$1" 2>/dev/null; do
        if [ $((SECONDS - start)) -ge "${SY_WAIT_GUARD:-300}" ]; then
            echo "wait_gone: hang guard: process $1 still running after ${SY_WAIT_GUARD:-300} s" >&2
            return 1
        fi
        sleep 0.05
    done
}
