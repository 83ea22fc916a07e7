#!/usr/bin/env bash
# on_xvfb.sh CMD ARGS...: CMD on a virtual screen (1280 x 1024 x 24) of its
# own; exits with CMD's status (1 if the screen would not start).
# Xvfb picks a free display number itself and writes it once it accepts
# connections (-displayfd), and the server is waited for on the way out.
# -noreset: by default the server resets whenever its last client leaves,
# and a client connecting meanwhile cannot open the display. The window
# tests poll with xdotool beside tactus's own connection: under load about
# 1 connection in 100 failed so (3 CI runs lost trainer_window to it), none
# in 1000 with -noreset.
set -u
dir=$(mktemp -d) || exit 1
xpid=""
stop() {
  if [ -n "$xpid" ]; then kill "$xpid" 2>/dev/null; wait "$xpid" 2>/dev/null; fi
  rm -rf "$dir"
}
trap stop EXIT
trap 'exit 143' TERM INT # timeout(1) stops this script: the server goes with it
Xvfb -displayfd 3 -nolisten tcp -noreset -screen 0 1280x1024x24 3>"$dir/display" 2>"$dir/log" &
xpid=$!
for _ in $(seq 600); do # up to a minute on a loaded machine
  grep -q . "$dir/display" 2>/dev/null && break
  kill -0 "$xpid" 2>/dev/null || break
  sleep 0.1
done
n=$(head -n 1 "$dir/display" 2>/dev/null)
if [ -z "$n" ]; then
  echo "on_xvfb: Xvfb did not start: $(tail -n 2 "$dir/log" | tr '\n' ' ')" >&2
  exit 1
fi
DISPLAY=":$n" "$@"
