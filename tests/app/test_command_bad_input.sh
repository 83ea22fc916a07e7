#!/usr/bin/env bash
# Bad input to the tactus command: for each case, exit status 2 and one line on
# stderr naming the file or the option, within 20 s, no crash. Then good input,
# which must write a whole report.
#
#   test_command_bad_input.sh TACTUS [REPORT_CHECK]
#
# REPORT_CHECK (tests/scenarios/report_check.c) checks the report's keys and
# types; without it a grep for each documented key stands in.
set -u
HERE=$(dirname "$(realpath "$0")")
TACTUS=$(realpath "$1")
CHECK=${2:-}
[ -n "$CHECK" ] && CHECK=$(realpath "$CHECK")
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
# no core files from a crash end up beside the sources
cd "$WORK" || exit 1
# scenarios are looked up in the source tree only, whatever the caller's environment says
unset TACTUS_SCENARIO_PATH
. "$HERE/../bad_input_lib.sh" || exit 1

S=$WORK/scenarios
mkdir -p "$S"
worker() { # NAME RATE [PARAMS]
  printf '{"name": "%s", "type": "rates.worker", "rate_hz": %s, "params": {%s}}' "$1" "$2" "${3:-}"
}
scenario() { # FILE CONTROLLER... : a scenario named t
  local file=$1
  shift
  local list
  list=$(IFS=,; echo "$*")
  printf '{\n  "name": "t",\n  "controllers": [%s]\n}\n' "$list" >"$S/$file"
}

# --- files: syntax -----------------------------------------------------------
printf '{\n  "name": "t",\n  "controllers": [\n}\n' >"$S/malformed.json"
expect_bad_re "malformed JSON" "^tactus: $S/malformed.json:4:[0-9]+: " "$S/malformed.json:4:" -- run "$S/malformed.json"
expect_bad_re "malformed JSON, describe" "malformed.json:4:[0-9]+: " "$S/malformed.json:4:" -- describe "$S/malformed.json"
printf '{"name": "t",\n "name": "u", "controllers": []}\n' >"$S/duplicate.json"
expect_bad_re "duplicate key" "duplicate.json:2:[0-9]+: " "$S/duplicate.json:2:" "duplicate" -- run "$S/duplicate.json"
printf '' >"$S/empty.json"
expect_bad "empty file" "$S/empty.json:" -- run "$S/empty.json"
printf '[1, 2]' >"$S/array.json"
expect_bad "top level not an object" "$S/array.json" "object" -- run "$S/array.json"
printf '{"name": "t", "controllers": [], "x": "\xff\xfe"}' >"$S/binary.json"
expect_bad "invalid UTF-8" "$S/binary.json:1:" -- run "$S/binary.json"

printf '{"name": "t", "bo\\ngus": 1, "controllers": []}' >"$S/newline_key.json"
expect_bad "a key with a newline in it" "$S/newline_key.json" "bo?gus" -- run "$S/newline_key.json"

# --- files: unknown names ----------------------------------------------------
expect_bad "unknown scenario name" "no_such_scenario" "unknown scenario" -- run no_such_scenario
expect_bad "unknown scenario name, describe" "no_such_scenario" -- describe no_such_scenario
expect_bad "missing file" "$S/missing.json" "No such file" -- run "$S/missing.json"
expect_bad "missing file in a missing folder" "/nonexistent/dir/x.json" -- run /nonexistent/dir/x.json
expect_bad "a folder, not a file" "$S" "not a regular file" -- run "$S/"
scenario unknown_type.json '{"name": "a", "type": "no.such", "rate_hz": 10}'
expect_bad "unknown controller type" "$S/unknown_type.json" "controllers[0].type" "no.such" -- run "$S/unknown_type.json"
printf '{"name": "t", "bogus": 1, "controllers": [%s]}' "$(worker a 10)" >"$S/unknown_key.json"
expect_bad "unknown top-level key" "$S/unknown_key.json" "bogus" -- run "$S/unknown_key.json"
scenario unknown_ckey.json '{"name": "a", "type": "rates.worker", "rate": 10}'
expect_bad "unknown controller key" "$S/unknown_ckey.json" "controllers[0].rate:" -- run "$S/unknown_ckey.json"
scenario unknown_param.json "$(worker a 10 '"bogus": 1')"
expect_bad "unknown parameter" "$S/unknown_param.json" "controllers[0].params.bogus" -- run "$S/unknown_param.json"
scenario unknown_read.json "$(worker a 10 '"reads": ["t.nope"]')"
expect_bad "read of an unknown component" "$S/unknown_read.json" "controllers[0]" "t.nope" -- run "$S/unknown_read.json"
scenario two_writers.json "$(worker a 10 '"write": "t.x"')" "$(worker b 20 '"write": "t.x"')"
expect_bad "two writers" "$S/two_writers.json" "controllers[1]" "two writers" -- run "$S/two_writers.json"
scenario thread_number.json '{"name": "a", "type": "rates.worker", "rate_hz": 10, "thread": 3}'
expect_bad "thread a number" "$S/thread_number.json" "controllers[0].thread" "a thread name" -- run "$S/thread_number.json"
scenario thread_bad.json '{"name": "a", "type": "rates.worker", "rate_hz": 10, "thread": "Tissue Thread"}'
expect_bad "thread of bad characters" "$S/thread_bad.json" "controllers[0].thread" "a-z 0-9 _ -" -- describe "$S/thread_bad.json"
scenario thread_rates.json '{"name": "a", "type": "rates.worker", "rate_hz": 10, "thread": "x"}' '{"name": "b", "type": "rates.worker", "rate_hz": 20, "thread": "x"}'
expect_bad "one thread, two rates" "$S/thread_rates.json" "controllers[1].thread" "cannot share it" -- run "$S/thread_rates.json"

# --- files: wrong types -------------------------------------------------------
scenario rate_string.json "$(worker a '"fast"')"
expect_bad "rate_hz a string" "$S/rate_string.json" "controllers[0].rate_hz" -- run "$S/rate_string.json"
scenario param_string.json "$(worker a 10 '"work_us": "lots"')"
expect_bad "work_us a string" "$S/param_string.json" "controllers[0].params.work_us" -- run "$S/param_string.json"
scenario reads_string.json "$(worker a 10 '"reads": "t.x"')"
expect_bad "reads not an array" "$S/reads_string.json" "controllers[0].params.reads" -- run "$S/reads_string.json"
printf '{"name": 5, "controllers": [%s]}' "$(worker a 10)" >"$S/name_number.json"
expect_bad "name a number" "$S/name_number.json" "name" -- run "$S/name_number.json"
printf '{"name": "t", "controllers": {}}' >"$S/controllers_object.json"
expect_bad "controllers an object" "$S/controllers_object.json" "controllers" -- run "$S/controllers_object.json"
printf '{"name": "t", "duration_s": "long", "controllers": [%s]}' "$(worker a 10)" >"$S/duration_string.json"
expect_bad "duration_s a string" "$S/duration_string.json" "duration_s" -- run "$S/duration_string.json"

# --- files: out of range ------------------------------------------------------
for rate in 0 -1 100001 1e300; do
  scenario "rate_$rate.json" "$(worker a "$rate")"
  expect_bad "rate_hz $rate" "$S/rate_$rate.json" "controllers[0].rate_hz" "out of range" -- run "$S/rate_$rate.json"
done
scenario work_big.json "$(worker a 10 '"work_us": 2e6')"
expect_bad "work_us too big" "$S/work_big.json" "controllers[0].params.work_us" "out of range" -- run "$S/work_big.json"
scenario rows_zero.json "$(worker a 10 '"write": "t.x", "rows": 0')"
expect_bad "rows 0" "$S/rows_zero.json" "controllers[0].params.rows" -- run "$S/rows_zero.json"
printf '{"name": "t", "duration_s": 0, "controllers": [%s]}' "$(worker a 10)" >"$S/duration_zero.json"
expect_bad "duration_s 0" "$S/duration_zero.json" "duration_s" -- run "$S/duration_zero.json"

# --- --out ----------------------------------------------------------------------
GOOD=(rates --lockstep --duration 0.05 --set physics.work_us=0 --set graphics.work_us=0)
expect_bad "--out under /dev/null" "--out /dev/null/x" -- run "${GOOD[@]}" --out /dev/null/x
printf 'a regular file\n' >"$WORK/regular"
expect_bad "--out under a regular file" "--out $WORK/regular/x" -- run "${GOOD[@]}" --out "$WORK/regular/x"
expect_bad "--out a regular file" "--out $WORK/regular" -- run "${GOOD[@]}" --out "$WORK/regular"
expect_bad "--out empty" "--out" -- run "${GOOD[@]}" --out ""
# a failed run leaves nothing behind: no report anywhere it could have gone
if [ -n "$(find "$WORK" -name report.json -o -name 'report.json.tmp' -o -name trace.csv)" ]; then
  fail "a run with a bad --out left files: $(find "$WORK" -name 'report.json*' -o -name trace.csv)"
fi
[ -f "$WORK/regular" ] || fail "--out under a regular file replaced the file"
[ -e "$WORK/out" ] && fail "a run with a bad --out made $WORK/out"

# --- --set ----------------------------------------------------------------------
expect_bad "--set of an unknown controller" "--set nobody.work_us=1" "nobody" -- run "${GOOD[@]}" --set nobody.work_us=1
expect_bad "--set of an unknown parameter" "--set physics.bogus=1" "unknown parameter" -- run "${GOOD[@]}" --set physics.bogus=1
expect_bad "--set of an unknown key" "--set bogus=1" -- run "${GOOD[@]}" --set bogus=1
expect_bad "--set without '='" "--set physics" "KEY=VALUE" -- run "${GOOD[@]}" --set physics
expect_bad "--set with an empty key" "--set =5" -- run "${GOOD[@]}" --set =5
expect_bad "--set rate_hz out of range" "--set physics.rate_hz=0" "out of range" -- run "${GOOD[@]}" --set physics.rate_hz=0
expect_bad "--set rate_hz too high" "--set haptics.rate_hz=100001" -- run "${GOOD[@]}" --set haptics.rate_hz=100001
expect_bad "--set param out of range" "--set physics.work_us=-1" -- run "${GOOD[@]}" --set physics.work_us=-1
expect_bad "--set param of the wrong type" "--set physics.rows=many" -- run "${GOOD[@]}" --set physics.rows=many
expect_bad "--set duration_s bad" "--set duration_s=abc" -- run "${GOOD[@]}" --set duration_s=abc
expect_bad "--set without a value" "--set" -- run rates --set

# --- other options ----------------------------------------------------------------
for d in 0 -1 abc nan inf 1e9 ""; do
  expect_bad "--duration '$d'" "--duration $d" -- run rates --lockstep --duration "$d"
done
expect_bad "--duration without a value" "--duration" -- run rates --duration
expect_bad "unknown subcommand" "bogus" -- bogus
expect_bad "no command at all" "expected a command" --
expect_bad "a newline in an argument" "no?such" -- run "$(printf 'no\nsuch')"
expect_bad "a newline in a --set" "--set a?b=1" -- run rates --set "$(printf 'a\nb=1')"
expect_bad "unknown option" "--bogus" -- run rates --bogus
expect_bad "unknown short option" "'-x'" -- run -x rates
expect_bad "unknown short options in a group" "'-x'" -- run -xy rates
expect_bad "bench unknown short option" "'-x'" -- bench -xy rates
expect_bad "unexpected argument" "extra" -- run rates extra
expect_bad "run without a scenario" "SCENARIO" -- run --lockstep
expect_bad "--view bogus" "--view bogus" -- run rates --view bogus
expect_bad "--stereo bogus" "--stereo bogus" -- run rates --stereo bogus
expect_bad "--device bogus" "--device bogus" -- run rates --device bogus
# devices go to the scenario's haptics controllers; each bad spec names the --device
expect_bad "--device unknown motion" "--device scripted:wiggle" "pierce-down" -- run haptics-wall --lockstep --device scripted:wiggle
expect_bad "--device unknown kind" "--device phantom:1" "unknown kind" -- run haptics-wall --lockstep --device phantom:1
expect_bad "--device missing file" "--device scripted:$WORK/none.csv" "No such file" -- run haptics-wall --lockstep --device "scripted:$WORK/none.csv"
printf 't,x,y,z\n0,0,0,0\n0.5,0,zero,0\n' > "$WORK/bad_row.csv"
expect_bad "--device bad waypoint row" "bad_row.csv:3:" "finite number" -- run haptics-wall --lockstep --device "scripted:$WORK/bad_row.csv"
expect_bad "--device replay of a text file" "--device replay:$WORK/regular" "not a tactus recording" -- run haptics-wall --lockstep --device "replay:$WORK/regular"
expect_bad "--device replay of a missing file" "none.bin" "No such file" -- run haptics-wall --lockstep --device "replay:$WORK/none.bin"
expect_bad "--device sim with a bad value" "--device sim:damping=-1" "damping" -- run haptics-wall --lockstep --device sim:damping=-1
expect_bad "--device sim with an unknown key" "--device sim:bogus=1" "unknown key" -- run haptics-wall --lockstep --device sim:bogus=1
expect_bad "--device sim with a bad hand" "scripted:nope" -- run haptics-wall --lockstep --device sim:hand=nope
expect_bad "--device without a haptics controller" "--device scripted:pierce-up" "0 haptics controllers" -- run rates --device scripted:pierce-up
expect_bad "--device more than the scenario has" "at most 1 --device" -- run haptics-wall --device scripted:pierce-up --device scripted:pierce-down
expect_bad "--device three times" "at most two" -- run haptics-wall --device scripted:pierce-up --device scripted:pierce-up --device scripted:pierce-up
expect_bad "haptics limit above the device's" "--set haptics.max_force=10" "above the device's 3.3" -- run haptics-wall --lockstep --set haptics.max_force=10
expect_bad "haptics mode unknown" "--set haptics.mode=fast" "sample_hold" -- run haptics-wall --lockstep --set haptics.mode=fast
# --- views: --view, --stereo and a scenario's "view" (docs/views.md) ---------------
expect_bad "--stereo without a view" "--stereo sbs" "--view png" -- run haptics-wall --lockstep --stereo sbs
expect_bad "--device mouse without a window" "--device mouse" "--view window" -- run haptics-wall --lockstep --device mouse
expect_bad "--device mouse with options" "--device mouse:fast" -- run haptics-wall --lockstep --device mouse:fast
DISPLAY= expect_bad "--view window without a display (or GLFW)" "--view window" -- run haptics-wall --view window
# --probe (view.probe): components nobody writes, a bad interval, nothing named
expect_bad "--probe of a component nobody writes" "--probe device0.pose,nobody.x" "nobody.x" -- run haptics-wall --lockstep --probe device0.pose,nobody.x
expect_bad "--probe with a bad interval" "--probe device0.pose@soon" "seconds" -- run haptics-wall --lockstep --probe device0.pose@soon
expect_bad "--probe of nothing" "--probe @0.1" "at least one component" -- run haptics-wall --lockstep --probe @0.1
view_scenario() { # FILE VIEW_JSON: the wall scenario with this "view"
  printf '{"name": "t", "controllers": [{"name": "wall", "type": "collision.wall", "rate_hz": 60},
  {"name": "haptics", "type": "haptics", "rate_hz": 1000, "params": {"force_model": "tool0.force_model"}}],
  "view": %s}\n' "$2" >"$S/$1"
}
view_scenario view_key.json '{"draw": [{"tool": "device0", "colur": [1, 0, 0]}]}'
expect_bad "view: unknown draw key, even without --view" "$S/view_key.json: view.draw[0].colur: unknown key" -- run "$S/view_key.json" --lockstep
# a build without OSMesa refuses --view png at once, in one line
if "$TACTUS" run rates --lockstep --view png --duration 0.01 --out "$WORK/probe" 2>&1 | grep -q "no OSMesa"; then
  expect_bad "--view png without OSMesa" "--view png" "no OSMesa" -- run haptics-wall --lockstep --view png
else
view_scenario view_colour.json '{"draw": [{"tool": "device0", "colour": [1, 0, 2]}]}'
expect_bad "view: colour out of range" "view.draw[0].colour" "[0, 1]" -- run "$S/view_colour.json" --lockstep --view png
view_scenario view_camera.json '{"camera": {"eye": [0, 0, 0], "target": [0, 0, 0]}}'
expect_bad "view: eye on the target" "view.camera" "differ" -- run "$S/view_camera.json" --lockstep --view png
view_scenario view_size.json '{"width": 100000}'
expect_bad "view: too wide" "view.width" -- run "$S/view_size.json" --lockstep --view png
view_scenario view_rate.json '{"rate_hz": "fast"}'
view_scenario view_cut.json '{"draw": [{"tool": "device0", "cut": {"normal": [0, 0, 1]}}]}'
expect_bad "view: a cut on a tool" "view.draw[0].cut" "only spheres" -- run "$S/view_cut.json" --lockstep
expect_bad "view: rate not a number" "view.rate_hz" -- run "$S/view_rate.json" --lockstep --view png
view_scenario view_missing.json '{"draw": [{"mesh": "skin"}]}'
expect_bad "view: draws what nobody writes" "$S/view_missing.json: view.draw" "skin.x" -- run "$S/view_missing.json" --lockstep --view png
view_scenario view_shape.json '{"draw": [{"tool": "tool0.force_model"}]}'
expect_bad "view: a tool that is no pose" "view.draw" -- run "$S/view_shape.json" --lockstep --view png
expect_bad "view: nothing drawable" "view" "nothing to draw" -- run rates --lockstep --view png
fi
expect_bad "bench render with a bad duration" "--duration 0" -- bench render --duration 0
expect_bad "bench unknown name" "bogus" -- bench bogus
expect_bad "bench unknown option" "--bogus" -- bench rates --bogus
expect_bad "bench --duration bad" "--duration" -- bench rates --duration abc
expect_bad "study unknown name" "bogus" -- study bogus
expect_bad "bench without a name" "bench" "NAME" -- bench
expect_bad "study --set unknown key" "--set device.bogus=1" "unknown key" -- study haptic-stability --set device.bogus=1 --out "$WORK/st"
expect_bad "study --set out of range" "damping" -- study haptic-stability --set device.damping=-5 --out "$WORK/st"
expect_bad "study --set not a number" "--set device.period=abc" -- study haptic-stability --set device.period=abc --out "$WORK/st"
expect_bad "study unwritable --out" "--out /dev/null/x" -- study haptic-stability --out /dev/null/x
expect_bad "study without a name" "study" "NAME" -- study

# --- the voxel needle: scenario keys, recordings, studies, bench ---------------------
expect_bad "needle tip unknown" "needle.tip" "sharp" -- run needle-voxel --lockstep --set needle.tip=sharp
expect_bad "needle gauge out of range" "needle.gauge" -- run needle-voxel --lockstep --set needle.gauge=40
expect_bad "needle radius negative" "needle.radius_m" -- run needle-voxel --lockstep --set needle.radius_m=-1
expect_bad "needle friction not a number" "needle.friction" -- run needle-voxel --lockstep --set needle.friction=lots
expect_bad "needle unknown key" "needle.bogus" -- run needle-voxel --lockstep --set needle.bogus=1
expect_bad "needle voxels packed too tight" "needle-voxel.json" "lattice spacing" -- run needle-voxel --lockstep --set needle.count_x=100
expect_bad "needle-fit without a file" "needle-fit" "FILE" -- study needle-fit --out "$WORK/nf"
expect_bad "needle-fit missing file" "$WORK/none.csv" "No such file" -- study needle-fit "$WORK/none.csv" --out "$WORK/nf"
printf 't_s,depth_m,fx_n,fy_n,fz_n,event\n0,0,0,0.1,0,\n0.001,0,0,x,0,\n' >"$WORK/bad_value.csv"
expect_bad "needle-fit bad value" "$WORK/bad_value.csv:3:" "finite" -- study needle-fit "$WORK/bad_value.csv" --out "$WORK/nf"
printf 't,depth,fx,fy,fz\n0,0,0,0.1,0,\n' >"$WORK/bad_header.csv"
expect_bad "needle-fit bad header" "$WORK/bad_header.csv:1:" "header" -- study needle-fit "$WORK/bad_header.csv" --out "$WORK/nf"
printf 't_s,depth_m,fx_n,fy_n,fz_n,event\n0,0,0,0.1,0,\n0.005,0,0,0.1,0,\n' >"$WORK/slow.csv"
expect_bad "needle-fit below 1 kHz" "$WORK/slow.csv:3:" "1 ms" -- study needle-fit "$WORK/slow.csv" --out "$WORK/nf"
printf 't_s,depth_m,fx_n,fy_n,fz_n,event\n0,0,0,0.1,0,\n0.001,0,0,0.1,0,jab\n' >"$WORK/bad_event.csv"
expect_bad "needle-fit unknown event" "$WORK/bad_event.csv:3:" "event" -- study needle-fit "$WORK/bad_event.csv" --out "$WORK/nf"
printf 't_s,depth_m,fx_n,fy_n,fz_n,event\n0,0,0,0,0,\n0.001,0,0,0,0,\n' >"$WORK/flat.csv"
expect_bad "needle-fit nothing to fit" "$WORK/flat.csv" "zero" -- study needle-fit "$WORK/flat.csv" --out "$WORK/nf"
printf 't_s,depth_m,fx_n,fy_n,fz_n,event\n0,0,0,0.1,0,\n0.001,0,0,0.1,0,\n' >"$WORK/ok.csv"
expect_bad "needle-fit --set unknown key" "--set bogus=1" "unknown key" -- study needle-fit "$WORK/ok.csv" --set bogus=1 --out "$WORK/nf"
expect_bad "needle-fit --set evals too few" "--set evals=3" -- study needle-fit "$WORK/ok.csv" --set evals=3 --out "$WORK/nf"
expect_bad "needle-fit --set evals fraction" "--set evals=20.5" -- study needle-fit "$WORK/ok.csv" --set evals=20.5 --out "$WORK/nf"
expect_bad "needle-stability with a file" "needle-stability" "unexpected argument" -- study needle-stability extra --out "$WORK/ns"
expect_bad "needle-stability --set unknown" "--set k=1" "unknown key" -- study needle-stability --set k=1 --out "$WORK/ns"
expect_bad "needle-stability --set bad duration" "--set duration_s=-1" -- study needle-stability --set duration_s=-1 --out "$WORK/ns"
expect_bad "haptic-stability with a file" "haptic-stability" "unexpected argument" -- study haptic-stability extra --out "$WORK/st"
expect_bad "bench voxels --duration bad" "--duration" -- bench voxels --duration 0
# collision.hip and view.force_curve parameters (the HIP needs no skin writer to be refused)
printf '{"name": "t", "controllers": [{"name": "hip", "type": "collision.hip", "rate_hz": 4000},
  {"name": "curve", "type": "view.force_curve", "rate_hz": 1000, "params": {"force": "tool0.force_model"}}]}\n' >"$S/hip.json"
expect_bad "hip rays not 26 or 98" "--set hip.rays=27" "26 or 98" -- run "$S/hip.json" --set hip.rays=27
expect_bad "hip radius out of range" "--set hip.radius_m=1" "out of range" -- run "$S/hip.json" --set hip.radius_m=1
expect_bad "hip k of 1" "--set hip.k=1" "out of range" -- run "$S/hip.json" --set hip.k=1
expect_bad "hip alpha not a number" "--set hip.alpha=soft" -- run "$S/hip.json" --set hip.alpha=soft
expect_bad "force curve bad axis" "--set curve.axis=w" "x, y or z" -- run "$S/hip.json" --set curve.axis=w
expect_bad "force curve file with a path" "--set curve.file=../x" "base name" -- run "$S/hip.json" --set curve.file=../x
# built without Bullet, suturing-skin itself is refused: its physics.skin is unknown
if "$TACTUS" describe suturing-skin >/dev/null 2>&1; then
  expect_bad "skin-paper --set bad HIP rays" "hip.rays" -- study skin-paper --set hip.rays=7 --out "$WORK/sp"
  # physics.skin parameters
  expect_bad "skin spacing not dividing the patch" "--set skin.spacing_m=0.003" "whole cells" -- run suturing-skin --set skin.spacing_m=0.003
  expect_bad "skin thickness out of range" "--set skin.thickness_m=0.5" "out of range" -- run suturing-skin --set skin.thickness_m=0.5
  expect_bad "skin iterations not a number" "--set skin.iterations=many" -- run suturing-skin --set skin.iterations=many
  expect_bad "skin rate out of range" "suturing-skin.json" "controllers[0]" "20 to 120 Hz" -- run suturing-skin --set skin.rate_hz=500
  expect_bad "skin gravity not a boolean" "--set skin.gravity=9.81" -- run suturing-skin --set skin.gravity=9.81
  expect_bad "skin unknown parameter" "--set skin.stiffnes=1" "unknown parameter" -- run suturing-skin --set skin.stiffnes=1
  expect_bad "skin pretension negative" "--set skin.pretension_n_per_m=-1" "out of range" -- run suturing-skin --set skin.pretension_n_per_m=-1
  expect_bad "skin pretension past half the modulus" "suturing-skin.json" "controllers[0]" "pretension" -- run suturing-skin --set skin.pretension_n_per_m=1e9
  expect_bad "skin rupture tension negative" "--set skin.rupture_tension_n_per_m=-1" "out of range" -- run suturing-skin --set skin.rupture_tension_n_per_m=-1
  expect_bad "skin rupture length zero" "--set skin.rupture_length_m=0" "out of range" -- run suturing-skin --set skin.rupture_length_m=0
  expect_bad "hip force mode unknown" "--set hip.force_mode=sideways" "mechanics" -- run suturing-skin --set hip.force_mode=sideways
  expect_bad "skin-stability takes no --set" "--set skin.iterations=3" -- study skin-stability --set skin.iterations=3 --out "$WORK/ss"
  expect_bad "skin-accuracy refuses a skin key" "--set skin.iterations=3" -- study skin-accuracy --set skin.iterations=3 --out "$WORK/sa"
  expect_bad "skin-stability unwritable --out" "--out /dev/null/x" -- study skin-stability --out /dev/null/x
else
  expect_bad "skin-paper without Bullet" "physics.skin" -- study skin-paper --out "$WORK/sp"
  expect_bad "skin-stability without Bullet" "Bullet" -- study skin-stability --out "$WORK/ss"
  expect_bad "bench cloth without Bullet" "Bullet" -- bench cloth
  expect_bad "skin-accuracy without Bullet" "Bullet" -- study skin-accuracy --out "$WORK/sa"
fi
expect_bad "describe with two names" "describe" -- describe rates rates
expect_bad "list with an argument" "list" -- list extra

# --- good input -------------------------------------------------------------------
OUT=$WORK/good/run
rc=0
timeout 20 "$TACTUS" run rates --lockstep --duration 0.2 --set physics.work_us=0 --set graphics.work_us=0 --out "$OUT" \
  >"$WORK/stdout" 2>"$WORK/stderr" || rc=$?
cases=$((cases + 1))
if [ "$rc" -ne 0 ]; then
  fail "good run: exit status $rc: $(head -n 1 "$WORK/stderr")"
elif [ ! -s "$OUT/report.json" ]; then
  fail "good run: no $OUT/report.json"
else
  [ -s "$WORK/stderr" ] && fail "good run: wrote to stderr: $(head -n 1 "$WORK/stderr")"
  [ -s "$OUT/trace.csv" ] || fail "good run: --lockstep wrote no trace.csv"
  [ -e "$OUT/report.json.tmp" ] && fail "good run: left report.json.tmp"
  if [ -n "$CHECK" ]; then
    "$CHECK" "$OUT/report.json" steps physics 4 collision 800 haptics 200 graphics 6 || fail "good run: report_check failed"
  else
    for key in scenario mode duration_s controllers name thread target_hz achieved_hz steps missed jitter_us step_us \
      p50 p99 max warnings; do
      grep -q "\"$key\":" "$OUT/report.json" || fail "good run: report.json has no \"$key\""
    done
  fi
  grep -q '"mode": "lockstep"' "$OUT/report.json" || fail "good run: report.json is not a lockstep report"
fi

finish
