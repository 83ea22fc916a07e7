#!/usr/bin/env bash
# Parameter tables on the command line: `tactus describe` lists every
# parameter with its value, units, range and meaning; an unknown key in a file
# or a --set names the valid keys; bad tables and bad requests exit 2 with one
# line naming the file or flag and the key.
#
#   test_param_tables.sh TACTUS BAD_TABLE_PLUGIN NO_TABLE_PLUGIN
set -u
HERE=$(dirname "$(realpath "$0")")
TACTUS=$(realpath "$1")
BAD_TABLE=$(realpath "$2")
NO_TABLE=$(realpath "$3")
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
cd "$WORK" || exit 1
unset TACTUS_SCENARIO_PATH
. "$HERE/../bad_input_lib.sh" || exit 1

# expect_out "what" ARGS... -- FRAGMENT...: exit 0 and every fragment in stdout
expect_out() {
  local what=$1
  shift
  local args=()
  while [ $# -gt 0 ] && [ "$1" != "--" ]; do
    args+=("$1")
    shift
  done
  shift
  cases=$((cases + 1))
  local rc=0
  timeout -k 5 20 "$TACTUS" "${args[@]}" >"$WORK/stdout" 2>"$WORK/stderr" </dev/null || rc=$?
  [ "$rc" -eq 0 ] || { fail "$what: exit status $rc: $(head -n 1 "$WORK/stderr")"; return; }
  local f
  for f in "$@"; do
    grep -qF -- "$f" "$WORK/stdout" || fail "$what: stdout lacks '$f'"
  done
}

VALID="(valid: work_us, reads, write, rows, cols, units)"

# --- good: describe lists every parameter ------------------------------------
expect_out "describe lists the parameters" describe rates -- \
  "parameters (the value in this scenario, or the default):" "physics (rates.worker):" \
  "work_us" "us" "[0, 1e6]" "busy computation per step" "\"1\" (default)"
# every key of every table appears under each instance of its class
for key in work_us reads write rows cols units; do
  n=$(grep -c "^  $key " "$WORK/stdout")
  [ "$n" -eq "$(grep -c '(rates.worker):' "$WORK/stdout")" ] || fail "describe rates: $key listed $n times"
done
expect_out "describe shows the value of the scenario" describe haptics-wall -- \
  "wall (collision.wall):" "stiffness" "N/m" "max_force" "the device's (default)"
# numbers as the file writes them, not 17 digits
expect_out "describe shows numbers as written" describe needle-voxel -- \
  "  damage_shrink        0.5238394913 " "  skin_m               0.0002 "
expect_out "describe --class prints the Markdown table" describe --class collision.wall -- \
  "| key | kind | default | units | range | meaning |" "| \`stiffness\` | number | 300 | N/m | [0, 1e6] |"
expect_out "describe --classes lists the built-in types" describe --classes -- rates.worker collision.wall haptics

# a plugin class without a table: described, and said to have none
printf '{"name": "t", "plugins": ["%s"], "controllers": [{"name": "old", "type": "test.fails_init", "rate_hz": 10}]}' \
  "$NO_TABLE" >"$WORK/no_table.json"
expect_out "a class without a table" describe "$WORK/no_table.json" -- "old (test.fails_init): no parameter table"
expect_out "describe --class of a class without a table" describe --class rates.worker -- "| \`work_us\` |"

# --- bad: unknown keys name the valid ones ------------------------------------
printf '{"name": "t", "controllers": [{"name": "a", "type": "rates.worker", "rate_hz": 10, "params": {"wrk_us": 5}}]}' \
  >"$WORK/typo.json"
expect_bad "unknown key in a file" "$WORK/typo.json: controllers[0].params.wrk_us: unknown parameter for rates.worker $VALID" \
  -- run "$WORK/typo.json"
expect_bad "unknown key in a file, describe" "$WORK/typo.json" "params.wrk_us" "$VALID" -- describe "$WORK/typo.json"
expect_bad "--set of an unknown key" "--set physics.wrk_us=1: unknown parameter for rates.worker $VALID" \
  -- run rates --lockstep --duration 0.05 --set physics.wrk_us=1
expect_bad "--set of an unknown haptics key" "--set haptics.maxforce=1" "valid: device, hand," "ramp_s)" \
  -- run haptics-wall --lockstep --set haptics.maxforce=1

# --- bad: values against the table's range and kind ---------------------------
expect_bad "--set out of the table's range" "--set wall.stiffness=-1" "out of range [0, 1e+06]" \
  -- run haptics-wall --lockstep --set wall.stiffness=-1
expect_bad "--set of the wrong kind" "--set wall.stiffness=stiff" "expected a number" \
  -- run haptics-wall --lockstep --set wall.stiffness=stiff
expect_bad "a limit above the device's" "--set haptics.max_force=10" "above the device's 3.3" \
  -- run haptics-wall --lockstep --set haptics.max_force=10

# --- bad: a plugin whose table cannot be trusted ------------------------------
printf '{"name": "t", "plugins": ["%s"], "controllers": []}' "$BAD_TABLE" >"$WORK/bad_table.json"
expect_bad "a plugin table with a key twice" "$WORK/bad_table.json: plugins[0]" \
  "test.bad_table: parameter table: params[1]: key 'gain' appears twice" -- describe "$WORK/bad_table.json"

# --- bad: describe's own arguments --------------------------------------------
expect_bad "describe --class of an unknown type" "describe --class no.such" "unknown controller type" \
  -- describe --class no.such
expect_bad "describe --class without a type" "describe --class" -- describe --class
expect_bad "describe --class with two types" "describe --class" -- describe --class rates.worker haptics

echo "$cases cases, $failures failed"
[ "$failures" -eq 0 ]
