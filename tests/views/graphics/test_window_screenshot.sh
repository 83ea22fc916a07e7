#!/usr/bin/env bash
# Window mode under Xvfb: `tactus run haptics-wall --view window` opens a GLFW
# window on a virtual display, runs, and leaves a screenshot of its last frame
# in which the red tool and the overlay show. Also with --device mouse and the
# sbs and tb stereo modes (the overlay in both eyes), `--stereo lr` on a
# display without quad buffers and a display that cannot be opened (exit 2 at
# load, one line, nothing written). Exit 77 (skipped) only when Xvfb is
# not installed.
#
#   test_window_screenshot.sh TACTUS PNG_PROBE
set -u
TACTUS=$(realpath "$1")
PROBE=$(realpath "$2")
command -v Xvfb >/dev/null || { echo "Xvfb is not installed: skipped"; exit 77; }
ON_XVFB="$(dirname "$(realpath "$0")")/on_xvfb.sh"
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
cd "$WORK" || exit 1
unset TACTUS_SCENARIO_PATH
failures=0
fail() { echo "FAIL: $*" >&2; failures=$((failures + 1)); }

# one run on a fresh virtual screen; ARGS after the output folder
window_run() { # OUT ARGS...
  local out=$1
  shift
  timeout -k 5 90 bash "$ON_XVFB" "$TACTUS" run haptics-wall --view window --quiet \
    --out "$out" "$@" >"$out.log" 2>&1
}

# the overlay's backing rectangle is 330 px wide from (4, 4) of each eye: most
# of a 330 x 36 px region there is its colour, and none of it without an overlay
OVERLAY_MIN=6000
overlay_in() { # PNG X Y WHAT
  local shade
  read -r _ _ _ shade < <("$PROBE" "$1" "$2" "$3" 330 36)
  [ "${shade:-0}" -gt "$OVERLAY_MIN" ] || fail "no overlay in $4 (${shade:-0} px of its colour at $2,$3)"
}

if ! window_run "$WORK/mono" --duration 1.5; then
  fail "window run failed: $(tail -n 3 "$WORK/mono.log")"
else
  read -r w h red < <("$PROBE" "$WORK/mono/frames/window.png") || fail "no screenshot"
  [ "${w:-0}" -eq 640 ] && [ "${h:-0}" -eq 480 ] || fail "screenshot is ${w:-?}x${h:-?}, expected 640x480"
  [ "${red:-0}" -gt 30 ] || fail "the red tool is not in the screenshot (${red:-0} red pixels)"
  grep -q '"view.frames"' "$WORK/mono/report.json" || fail "the report has no view.frames"
  overlay_in "$WORK/mono/frames/window.png" 4 4 "the mono window"
  # the check can fail: the rest of the frame holds none of the overlay's colour
  read -r _ _ _ shade < <("$PROBE" "$WORK/mono/frames/window.png" 340 4 290 36)
  [ "${shade:-1}" -eq 0 ] || fail "the overlay's colour outside the overlay (${shade} px): the probe cannot tell"
fi

# top-bottom: the left eye above, each eye with its own overlay
if ! window_run "$WORK/tb" --duration 1 --stereo tb; then
  fail "window run with --stereo tb failed: $(tail -n 3 "$WORK/tb.log")"
else
  read -r w h red < <("$PROBE" "$WORK/tb/frames/window.png") || fail "no screenshot (tb)"
  [ "${w:-0}" -eq 640 ] && [ "${h:-0}" -eq 960 ] || fail "tb screenshot is ${w:-?}x${h:-?}, expected 640x960"
  overlay_in "$WORK/tb/frames/window.png" 4 4 "the tb left eye (top)"
  overlay_in "$WORK/tb/frames/window.png" 4 484 "the tb right eye (bottom)"
fi

# lr needs quad buffers in a window, which Xvfb's GL has not: refused at load
# (status 2, one line naming --stereo lr, no output folder); where a display
# has them, the run works and leaves its screenshot
window_run "$WORK/lr" --duration 2 --stereo lr
rc=$?
if [ "$rc" -eq 2 ]; then
  [ "$(wc -l <"$WORK/lr.log")" -eq 1 ] || fail "lr: expected one line, got: $(cat "$WORK/lr.log")"
  grep -q -- "--stereo lr" "$WORK/lr.log" || fail "lr: the line does not name --stereo lr: $(cat "$WORK/lr.log")"
  [ ! -e "$WORK/lr" ] || fail "lr: refused, yet $WORK/lr was made: $(ls -R "$WORK/lr")"
elif [ "$rc" -ne 0 ] || [ ! -s "$WORK/lr/frames/window.png" ]; then
  fail "lr in a window: status $rc (expected 2 without quad buffers, 0 with): $(tail -n 3 "$WORK/lr.log")"
fi

# a display that cannot be opened: found at load, before anything is written
if [ ! -e /tmp/.X11-unix/X77 ]; then
  DISPLAY=:77 timeout -k 5 30 "$TACTUS" run haptics-wall --view window --quiet --out "$WORK/nodisplay" \
    >"$WORK/nodisplay.log" 2>&1
  rc=$?
  [ "$rc" -eq 2 ] || fail "DISPLAY=:77: status $rc, expected 2: $(cat "$WORK/nodisplay.log")"
  [ "$(wc -l <"$WORK/nodisplay.log")" -eq 1 ] || fail "DISPLAY=:77: expected one line, got: $(cat "$WORK/nodisplay.log")"
  grep -q -- "--view window" "$WORK/nodisplay.log" || fail "DISPLAY=:77: the line does not name --view window"
  [ ! -e "$WORK/nodisplay" ] || fail "DISPLAY=:77: $WORK/nodisplay was made: $(ls -R "$WORK/nodisplay")"
fi

# side by side in the window, the mouse as the device: the tool waits where the mouse device starts
if ! window_run "$WORK/mouse" --duration 1 --device mouse --stereo sbs; then
  fail "window run with --device mouse failed: $(tail -n 3 "$WORK/mouse.log")"
else
  read -r w h red < <("$PROBE" "$WORK/mouse/frames/window.png") || fail "no screenshot (mouse)"
  [ "${w:-0}" -eq 1280 ] || fail "sbs screenshot is ${w:-?} wide, expected 1280"
  [ "${red:-0}" -gt 60 ] || fail "the tool is not in both eyes (${red:-0} red pixels)"
  overlay_in "$WORK/mouse/frames/window.png" 4 4 "the sbs left eye"
  overlay_in "$WORK/mouse/frames/window.png" 644 4 "the sbs right eye"
  # the mouse device holds the tool 2 cm above the origin until the window moves it
  awk -F, 'NR > 1 && ($3 < 0.0199 || $3 > 0.0201) { bad = 1 } END { exit bad }' "$WORK/mouse/device0.csv" ||
    fail "the mouse device's y is not 0.02 m throughout"
fi

[ "$failures" -eq 0 ] && echo "window mode: all cases passed"
[ "$failures" -eq 0 ]
