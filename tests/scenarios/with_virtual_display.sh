#!/usr/bin/env bash
# Runs a command on a private virtual X server (Xvfb), for ParaView's renderer on a machine
# without a display. Xvfb picks a free display itself and writes its number to a pipe only once
# it accepts connections (-displayfd), so the command never starts before the server is ready and
# two runs never race for the same display. A server that fails to start is retried, and its own
# message is printed if it never does. A command killed by a signal (the renderer aborts when it
# loses its display) is run once more on a new server, after saying so; any other failure is its
# own.
set -u
if [ $# -lt 1 ]; then
  echo "usage: $0 COMMAND [ARG...]" >&2
  exit 2
fi

work=$(mktemp -d)
server=""
stop_server() {
  if [ -n "$server" ]; then
    kill "$server" 2>/dev/null
    wait "$server" 2>/dev/null
  fi
  server=""
}
trap 'stop_server; rm -rf "$work"' EXIT

# Starts a server; sets `display`, empty if none started in three attempts.
start_server() {
  display=""
  for attempt in 1 2 3; do
    mkfifo "$work/ready"
    Xvfb -displayfd 3 -nolisten tcp -screen 0 1280x1024x24 3>"$work/ready" 2>"$work/xvfb.log" &
    server=$!
    # The read ends when Xvfb writes its display number, or with nothing when it exits first.
    read -r -t 30 display <"$work/ready" || display=""
    rm -f "$work/ready"
    if [ -n "$display" ] && kill -0 "$server" 2>/dev/null; then
      return
    fi
    stop_server
    display=""
  done
}

status=1
for run in 1 2; do
  start_server
  if [ -z "$display" ]; then
    echo "$0: Xvfb did not start in 3 attempts; its last message:" >&2
    cat "$work/xvfb.log" >&2
    exit 1
  fi
  DISPLAY=":$display" "$@"
  status=$?
  stop_server
  [ "$status" -le 128 ] && break
  echo "$0: the command ended by signal $((status - 128)) on display :$display (server log below)" >&2
  cat "$work/xvfb.log" >&2
  [ "$run" = 1 ] && echo "$0: running it again on a new server" >&2
done
exit "$status"
