#!/usr/bin/env bash
# A run's life on the command line (issue 11): it is refused at load when the
# clocks cannot hold it, stops on SIGINT/SIGTERM with 130/143, stops at once on
# a full disk with the reason and still leaves report.json and the summary,
# never overwrites a used --out without --force, keeps nothing when it fails
# before its first step, and names the real fault of a bad --set. Also the
# haptic stall warning's path through the command, `tactus list` with a
# shadowed name, and study assets found from any folder.
#
#   test_command_lifecycle.sh TACTUS REPORT_CHECK FAILING_INIT_PLUGIN
set -u
HERE=$(dirname "$(realpath "$0")")
TACTUS=$(realpath "$1")
CHECK=$(realpath "$2")
PLUGIN=$(realpath "$3")
WORK=$(mktemp -d)
MOUNTED=
cleanup() {
  [ -n "$MOUNTED" ] && umount "$MOUNTED" 2>/dev/null
  rm -rf "$WORK"
}
trap cleanup EXIT
cd "$WORK" || exit 1
unset TACTUS_SCENARIO_PATH
. "$HERE/../bad_input_lib.sh" || exit 1

FAST=(--set physics.work_us=0 --set graphics.work_us=0)

# --- row 1: rates and durations the clocks cannot hold are refused at load -------------
expect_bad "rate 1e-10 by --set, lockstep" "--set physics.rate_hz=1e-10" "out of range [0.001" -- \
  run rates --set physics.rate_hz=1e-10 --lockstep --duration 0.05
expect_bad "rate 1e-10 by --set, real time" "--set physics.rate_hz=1e-10" "out of range" -- \
  run rates --set physics.rate_hz=1e-10 --duration 0.05
sed 's/"rate_hz": 20,/"rate_hz": 1e-10,/' "$(dirname "$HERE")/../scenarios/rates/rates.json" >"$WORK/slow.json"
grep -q '1e-10' "$WORK/slow.json" || fail "could not write the slow scenario"
expect_bad "rate 1e-10 in a file" "$WORK/slow.json" "controllers[0].rate_hz" "out of range" -- run "$WORK/slow.json" --lockstep
printf '{"name": "t", "controllers": [{"name": "w", "type": "rates.worker", "rate_hz": 10}], "view": {"rate_hz": 1e-10}}\n' \
  >"$WORK/slow_view.json"
expect_bad "view rate 1e-10" "$WORK/slow_view.json" "view.rate_hz" -- run "$WORK/slow_view.json" --lockstep
expect_bad "duration 1e-300 in a --set" "--set duration_s=1e-300" -- run rates --set duration_s=1e-300 --lockstep
# output is bounded: a lockstep trace that could pass 1 GiB is refused before anything is written
expect_bad "a trace over the cap" "run rates --lockstep" "1 GB cap" -- run rates --lockstep --duration 86400 "${FAST[@]}" --out "$WORK/huge"
[ -e "$WORK/huge" ] && fail "a refused run made its --out"

# a signal always stops a run; the exit status says which, the report is whole
signal_case() { # SIGNAL STATUS ARGS...
  local sig=$1 want=$2
  shift 2
  cases=$((cases + 1))
  local out=$WORK/sig-$sig-$cases
  last_sig_out=$out
  timeout -k 5 60 "$TACTUS" run rates "$@" --out "$out" --quiet >"$WORK/sig.stdout" 2>"$WORK/sig.stderr" &
  local pid=$!
  sleep 1.5
  local start
  start=$(date +%s%N)
  kill "-$sig" "$pid"
  wait "$pid"
  local rc=$? ms=$((($(date +%s%N) - start) / 1000000))
  [ "$rc" -eq "$want" ] || fail "SIG$sig: exit status $rc, expected $want: $(head -n 1 "$WORK/sig.stderr")"
  # the runs last 30 s and 3000 s: 10 s leaves room for a sanitizer build on a loaded machine
  [ "$ms" -lt 10000 ] || fail "SIG$sig: took $ms ms to stop"
  grep -Eq "^tactus: run rates stopped early at t = [0-9.]+ s by SIG$sig" "$WORK/sig.stderr" ||
    fail "SIG$sig: no 'stopped early at t = ...' line: $(head -n 1 "$WORK/sig.stderr")"
  [ "$(grep -c '' "$WORK/sig.stderr")" -eq 1 ] || fail "SIG$sig: more than one line on stderr"
  "$CHECK" "$out/report.json" keys >/dev/null || fail "SIG$sig: report.json is not whole"
  grep -q '"stopped_early": true' "$out/report.json" || fail "SIG$sig: report.json does not say stopped_early"
}
signal_case INT 130 --duration 30                    # row 10, real time
signal_case TERM 143 --duration 30
signal_case INT 130 --lockstep --duration 3000 "${FAST[@]}" # lockstep, a long virtual run
grep -q '"mode": "lockstep"' "$last_sig_out/report.json" || fail "lockstep SIGINT: not a lockstep report"
[ -s "$last_sig_out/trace.csv" ] || fail "lockstep SIGINT: the trace up to the stop was not kept"

# --- row 6: a used --out is refused unless --force ------------------------------------
cases=$((cases + 1))
if "$TACTUS" run haptics-wall --lockstep --duration 0.2 --out "$WORK/used" --quiet 2>"$WORK/stderr"; then
  cp "$WORK/used/device0.bin" "$WORK/first.bin"
  expect_bad "run into a used --out" "--out $WORK/used" "not empty" "--force" -- \
    run haptics-wall --lockstep --duration 0.3 --out "$WORK/used"
  cmp -s "$WORK/used/device0.bin" "$WORK/first.bin" || fail "a refused run changed the earlier device0.bin"
  "$TACTUS" run haptics-wall --lockstep --duration 0.3 --out "$WORK/used" --force --quiet 2>"$WORK/stderr" ||
    fail "--force: exit status $?: $(head -n 1 "$WORK/stderr")"
  cmp -s "$WORK/used/device0.bin" "$WORK/first.bin" && fail "--force did not write the new run"
else
  fail "first run into --out: $(head -n 1 "$WORK/stderr")"
fi
expect_bad "study into a used --out" "--out $WORK/used" "not empty" -- study haptic-stability --out "$WORK/used"
expect_bad "bench into a used --out" "--out $WORK/used" "not empty" -- bench rates --out "$WORK/used"
"$TACTUS" run --help | grep -q -- '--force' || fail "run --help does not mention --force"

# --- row 15: the real fault is named -----------------------------------------------
expect_bad "a bad component name" "--set physics.write=Bad Name!" "bad component name 'Bad Name!'" -- \
  run rates --lockstep --duration 0.05 --set 'physics.write=Bad Name!'
expect_bad "a number past a double" "--set physics.work_us=1e999" "out of range" -- \
  run rates --lockstep --duration 0.05 --set physics.work_us=1e999
grep -q "a string" "$WORK/stderr" && fail "1e999 is still called a string"

# --- row 16: a run that fails before its first step keeps nothing --------------------
printf '{"name": "t", "plugins": ["%s"], "controllers": [
  {"name": "wall", "type": "collision.wall", "rate_hz": 60},
  {"name": "haptics", "type": "haptics", "rate_hz": 1000, "params": {"force_model": "tool0.force_model"}},
  {"name": "late", "type": "test.fails_init", "rate_hz": 10}]}\n' "$PLUGIN" >"$WORK/fails.json"
# the haptics controller has opened OUT/device0.bin by then. Its recorder may add a
# line of its own about the empty recording (controllers/haptics); the run's line
# is checked to be the only other one
init_fails() { # WHAT ARGS...
  local what=$1
  shift
  cases=$((cases + 1))
  local rc=0
  timeout -k 5 20 "$TACTUS" run "$WORK/fails.json" "$@" >"$WORK/stdout" 2>"$WORK/stderr" </dev/null || rc=$?
  [ "$rc" -eq 2 ] || fail "$what: exit status $rc, expected 2: $(head -n 1 "$WORK/stderr")"
  local lines
  lines=$(grep -v '^tactus: recording: ' "$WORK/stderr")
  [ "$lines" = "tactus: run t: late: no device here (a test)" ] || fail "$what: stderr is not the one reason: $lines"
}
for mode in --lockstep --duration=1; do
  init_fails "init failure ($mode), a new --out" $mode --out "$WORK/new/deep"
  [ -e "$WORK/new" ] && fail "init failure ($mode): left $(find "$WORK/new" | head -n 3 | tr '\n' ' ')"
  mkdir -p "$WORK/empty"
  init_fails "init failure ($mode), an empty --out" $mode --out "$WORK/empty"
  [ -d "$WORK/empty" ] || fail "init failure ($mode): removed a folder it did not make"
  [ -z "$(ls -A "$WORK/empty")" ] || fail "init failure ($mode): left $(ls -A "$WORK/empty" | tr '\n' ' ')"
  mkdir -p "$WORK/kept" && echo keep >"$WORK/kept/notes.txt"
  init_fails "init failure ($mode), --force" $mode --out "$WORK/kept" --force
  [ "$(ls -A "$WORK/kept")" = notes.txt ] || fail "init failure ($mode), --force: left $(ls -A "$WORK/kept" | tr '\n' ' ')"
  mkdir -p "$WORK/cwd" && cd "$WORK/cwd" && init_fails "init failure ($mode), default --out" $mode
  cd "$WORK" || exit 1
  [ -e "$WORK/cwd/out" ] && fail "init failure ($mode): left $WORK/cwd/out"
done
# a window on a display that is not there: exit 2 and nothing half-written
if [ -z "$(DISPLAY= "$TACTUS" run haptics-wall --view window --duration 0.1 2>&1 | grep 'no GLFW')" ]; then
  cases=$((cases + 1))
  rc=0
  (cd "$WORK/cwd" && DISPLAY=:77 timeout -k 5 20 "$TACTUS" run haptics-wall --view window --duration 1 >/dev/null 2>"$WORK/stderr") || rc=$?
  [ "$rc" -eq 2 ] || fail "DISPLAY=:77: exit status $rc, expected 2: $(head -n 1 "$WORK/stderr")"
  [ -e "$WORK/cwd/out" ] && fail "DISPLAY=:77: left $(find "$WORK/cwd/out" | tr '\n' ' ')"
fi
# scenario assets are found from any folder; a failed study leaves no folder
cases=$((cases + 1))
if (cd "$WORK/cwd" && "$TACTUS" study needle-fit assets/needle/reference-insertion.csv --set evals=20 --out fit >/dev/null 2>"$WORK/stderr"); then
  [ -s "$WORK/cwd/fit/needle-fit.json" ] || fail "needle-fit from another folder wrote no needle-fit.json"
else
  fail "needle-fit from another folder: $(head -n 1 "$WORK/stderr")"
fi
cd "$WORK/cwd" || exit 1
expect_bad "needle-fit of a missing file" "none.csv" "No such file" -- study needle-fit none.csv
[ -e "$WORK/cwd/out" ] && fail "a failed study left $(find "$WORK/cwd/out" | tr '\n' ' ')"
expect_bad "needle-fit of a missing file, --out" "none.csv" -- study needle-fit none.csv --out nf
[ -e "$WORK/cwd/nf" ] && fail "a failed study left its --out"
cd "$WORK" || exit 1

# --- row 18: tactus list shows paths, and which of two same names wins ---------------
cases=$((cases + 1))
mkdir -p "$WORK/path/rates"
cp "$(dirname "$HERE")/../scenarios/rates/rates.json" "$WORK/path/rates/"
TACTUS_SCENARIO_PATH=$WORK/path "$TACTUS" list >"$WORK/list" 2>&1 || fail "list: exit status $?"
first=$(grep -n "^rates " "$WORK/list" | head -n 1)
second=$(grep -n "^rates (shadowed) " "$WORK/list" | head -n 1)
case "$first" in *"$WORK/path/rates/rates.json"*) ;; *) fail "list: the first rates is not the copy on the path: $first" ;; esac
case "$second" in *"/scenarios/rates/rates.json"*) ;; *) fail "list: the built-in rates is not marked (shadowed): $second" ;; esac
[ "$(grep -c "^rates" "$WORK/list")" -eq 2 ] || fail "list: expected two rates rows"
TACTUS_SCENARIO_PATH=$WORK/path "$TACTUS" describe rates | grep -q "^file: $WORK/path/rates/rates.json" ||
  fail "describe does not run the one list says wins"

# --- row 5: a full disk stops the run at once, with the reason; report and summary stay ---
tiny=$WORK/tiny
mkdir -p "$tiny"
if ! mount -t tmpfs -o size=64k tmpfs "$tiny" 2>/dev/null; then
  [ "$failures" -ne 0 ] && finish
  echo "mount -t tmpfs is not permitted here: the full-disk cases are skipped"
  exit 77
fi
MOUNTED=$tiny
cases=$((cases + 1))
start=$(date +%s%N)
rc=0
timeout -k 5 60 "$TACTUS" run haptics-wall --device sim --no-record --lockstep --duration 60 --out "$tiny/r" \
  >"$WORK/full.stdout" 2>"$WORK/full.stderr" || rc=$?
ms=$((($(date +%s%N) - start) / 1000000))
[ "$rc" -eq 1 ] || fail "full disk, lockstep: exit status $rc, expected 1"
grep -q "trace.csv: No space left on device" "$WORK/full.stderr" ||
  fail "full disk, lockstep: the trace error gives no reason: $(head -n 1 "$WORK/full.stderr")"
grep -Eq "^tactus: run haptics-wall stopped at t = [0-9.]+ s: " "$WORK/full.stderr" || fail "full disk: no 'stopped at' line"
[ "$(grep -c '' "$WORK/full.stderr")" -eq 1 ] || fail "full disk, lockstep: $(grep -c '' "$WORK/full.stderr") lines on stderr"
"$CHECK" "$tiny/r/report.json" keys >/dev/null || fail "full disk, lockstep: no whole report.json"
grep -q "^warnings:" "$WORK/full.stdout" || fail "full disk, lockstep: no summary"
[ "$ms" -lt 10000 ] || fail "full disk, lockstep: took $ms ms"
rm -rf "${tiny:?}"/*
# in real time, the recording fills the disk: the report is still written
cases=$((cases + 1))
rc=0
timeout -k 5 60 "$TACTUS" run haptics-wall --device sim --duration 5 --out "$tiny/r" >"$WORK/full.stdout" 2>"$WORK/full.stderr" || rc=$?
grep -q "No space left on device" "$WORK/full.stderr" || fail "full disk, real time: no reason given"
"$CHECK" "$tiny/r/report.json" keys >/dev/null || fail "full disk, real time: no whole report.json"
grep -q "^warnings:" "$WORK/full.stdout" || fail "full disk, real time: no summary"

finish
