#!/usr/bin/env bash
# Window mode under Xvfb: `tactus run haptics-wall --view window` opens a GLFW
# window on a virtual display, runs, and leaves a screenshot of its last frame
# in which the red tool shows. Also with --device mouse and a stereo mode.
# Exit 77 (skipped) only when xvfb-run is not installed.
#
#   test_window_screenshot.sh TACTUS PNG_PROBE
set -u
TACTUS=$(realpath "$1")
PROBE=$(realpath "$2")
command -v xvfb-run >/dev/null || { echo "xvfb-run is not installed: skipped"; exit 77; }
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
  timeout -k 5 90 xvfb-run -a -s "-screen 0 1280x1024x24" "$TACTUS" run haptics-wall --view window --quiet \
    --out "$out" "$@" >"$out.log" 2>&1
}

if ! window_run "$WORK/mono" --duration 1.5; then
  fail "window run failed: $(tail -n 3 "$WORK/mono.log")"
else
  read -r w h red < <("$PROBE" "$WORK/mono/frames/window.png") || fail "no screenshot"
  [ "${w:-0}" -eq 640 ] && [ "${h:-0}" -eq 480 ] || fail "screenshot is ${w:-?}x${h:-?}, expected 640x480"
  [ "${red:-0}" -gt 30 ] || fail "the red tool is not in the screenshot (${red:-0} red pixels)"
  grep -q '"view.frames"' "$WORK/mono/report.json" || fail "the report has no view.frames"
fi

# side by side in the window, the mouse as the device: the tool waits where the mouse device starts
if ! window_run "$WORK/mouse" --duration 1 --device mouse --stereo sbs; then
  fail "window run with --device mouse failed: $(tail -n 3 "$WORK/mouse.log")"
else
  read -r w h red < <("$PROBE" "$WORK/mouse/frames/window.png") || fail "no screenshot (mouse)"
  [ "${w:-0}" -eq 1280 ] || fail "sbs screenshot is ${w:-?} wide, expected 1280"
  [ "${red:-0}" -gt 60 ] || fail "the tool is not in both eyes (${red:-0} red pixels)"
  # the mouse device holds the tool 2 cm above the origin until the window moves it
  awk -F, 'NR > 1 && ($3 < 0.0199 || $3 > 0.0201) { bad = 1 } END { exit bad }' "$WORK/mouse/device0.csv" ||
    fail "the mouse device's y is not 0.02 m throughout"
fi

[ "$failures" -eq 0 ] && echo "window mode: all cases passed"
[ "$failures" -eq 0 ]
