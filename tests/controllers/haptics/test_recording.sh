#!/usr/bin/env bash
# Device recordings through the command: a run killed with SIGKILL leaves its
# records on disk, and they replay; a file cut short replays with one warning
# and exports its CSV; a replay ends with its recording; a corrupt recording
# is refused in one line; a CSV that cannot be written at the end stops the run.
# Usage: test_recording.sh TACTUS
set -u
tactus=$1
# stderr lines are counted: under LeakSanitizer, no report of the suppressions used
export LSAN_OPTIONS="${LSAN_OPTIONS:+$LSAN_OPTIONS:}print_suppressions=0"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
failures=0
fail() { echo "FAIL: $*" >&2; failures=$((failures + 1)); }
records() { "$tactus" export "$1" --out "$work/count.csv" >/dev/null 2>&1 && echo $(($(grep -c '' "$work/count.csv") - 1)) || echo 0; }

# 1. kill -9 two seconds into a real-time run: about 2000 whole records, which replay
"$tactus" run haptics-wall --device sim --duration 30 --out "$work/killed" --quiet >/dev/null 2>&1 &
pid=$!
sleep 2
kill -9 $pid
wait $pid 2>/dev/null
n=$(records "$work/killed/device0.bin")
echo "killed after 2 s: $n records on disk"
[ "$n" -ge 1000 ] || fail "killed run: $n records on disk, expected about 2000"
"$tactus" run haptics-wall --lockstep --device replay:"$work/killed/device0.bin" --out "$work/killed-play" --quiet \
  >/dev/null 2>"$work/err" || fail "killed run's recording does not replay: $(head -n 1 "$work/err")"
[ -s "$work/err" ] && fail "killed run's recording, replayed: unexpected stderr: $(head -n 1 "$work/err")"
[ "$(grep -c '' "$work/killed-play/device0.csv" 2>/dev/null)" = $((n + 1)) ] || fail "the replay did not play all $n records"

# 2. cut in the middle of a block (a kill during a write): whole blocks, one warning line, exit 0
"$tactus" run haptics-wall --lockstep --duration 2.9 --out "$work/rec" --quiet || fail "recording run failed"
cp "$work/rec/device0.bin" "$work/cut.bin"
truncate -s -100 "$work/cut.bin"
"$tactus" run haptics-wall --lockstep --device replay:"$work/cut.bin" --out "$work/cut-play" --quiet >/dev/null 2>"$work/err"
rc=$?
[ $rc -eq 0 ] || fail "a recording cut short: exit $rc, expected 0: $(head -n 1 "$work/err")"
[ "$(grep -c '' "$work/err")" -eq 1 ] && grep -q "warning: .*cut.bin: cut short in block" "$work/err" ||
  fail "a recording cut short: expected one warning line, got: $(cat "$work/err")"
"$tactus" export "$work/cut.bin" >/dev/null 2>"$work/err" || fail "export of a recording cut short failed: $(cat "$work/err")"
[ "$(grep -c '' "$work/err")" -eq 1 ] || fail "export of a recording cut short: expected one warning line"
m=$(($(grep -c '' "$work/cut.csv") - 1))
[ "$m" -gt 2600 ] && [ "$m" -lt 2900 ] || fail "export of a recording cut short: $m records, expected its whole blocks"

# 3. a 2.9 s recording in the 5 s scenario: the run ends with the recording, unless --duration says otherwise
rep="$work/rec/device0.bin"
"$tactus" run haptics-wall --lockstep --device replay:"$rep" --out "$work/play" --quiet || fail "replay failed"
[ "$(grep -c '' "$work/play/device0.csv")" -eq 2901 ] || fail "the replay did not end with the recording"
for w in device_silent watchdog; do
  grep -q "\"haptics.$w\": 0" "$work/play/report.json" || fail "replay: $(grep "haptics.$w" "$work/play/report.json")"
done
"$tactus" run haptics-wall --lockstep --device replay:"$rep" --duration 5 --out "$work/long" --quiet || fail "replay --duration 5 failed"
grep -q '"haptics.device_silent": 2100' "$work/long/report.json" ||
  fail "replay --duration 5: $(grep haptics.device_silent "$work/long/report.json"), expected 2100 silent ticks"

# 4. 2000 random bytes over the records: refused in one line naming the file and the block
cp "$rep" "$work/bad.bin"
dd if=/dev/urandom of="$work/bad.bin" bs=1 seek=104 count=2000 conv=notrunc status=none
for cmd in "run haptics-wall --lockstep --device replay:$work/bad.bin --out $work/bad-play" "export $work/bad.bin"; do
  # shellcheck disable=SC2086
  "$tactus" $cmd >/dev/null 2>"$work/err"
  rc=$?
  [ $rc -eq 2 ] || fail "corrupt recording, tactus $cmd: exit $rc, expected 2"
  [ "$(grep -c '' "$work/err")" -eq 1 ] && grep -q "bad.bin: block 0" "$work/err" ||
    fail "corrupt recording, tactus $cmd: $(cat "$work/err")"
done
[ -e "$work/bad.csv" ] && fail "export of a corrupt recording left bad.csv"

# 5. bad input to export: one line, exit 2, nothing written
for args in "" "$work/none.bin" "$work/rec/device0.bin --out" "$work/rec/device0.bin --bogus" "$work/rec/device0.csv"; do
  # shellcheck disable=SC2086
  "$tactus" export $args >/dev/null 2>"$work/err"
  rc=$?
  [ $rc -eq 2 ] && [ "$(grep -c '' "$work/err")" -eq 1 ] || fail "tactus export $args: exit $rc, $(grep -c '' "$work/err") lines"
done
[ -e "$work/none.csv" ] && fail "export of a missing recording left none.csv"

# 6. a CSV that cannot be written when the run ends (its temporary file is
# taken by a folder): the run stops there, writes its report, says why in one
# line naming the file, and exits 1
mkdir -p "$work/fin/device0.csv.tmp"
"$tactus" run haptics-wall --lockstep --duration 0.2 --out "$work/fin" --force --quiet >/dev/null 2>"$work/err"
rc=$?
[ $rc -eq 1 ] && [ "$(grep -c '' "$work/err")" -eq 1 ] &&
  grep -q "stopped at t = 0.199 s: haptics: recording: $work/fin/device0.csv.tmp: Is a directory" "$work/err" ||
  fail "a recording that cannot be finished: exit $rc, $(cat "$work/err")"
[ -s "$work/fin/report.json" ] || fail "a recording that cannot be finished: no report"

[ $failures -eq 0 ] || exit 1
echo "recordings: killed, cut short, replayed to their end, corrupt, unfinishable: all as expected"
