#!/usr/bin/env bash
# Where SCHED_FIFO is refused the real-time executor runs without it and says
# so: in the scheduler line and as a warning of report.json.
# Usage: test_realtime_fallback.sh TACTUS
set -u
tactus=$1
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

# drop the capability that lets root ask for real-time priority, and the rlimit
if ! setpriv --inh-caps=-sys_nice --bounding-set=-sys_nice true 2>/dev/null; then
  echo "setpriv cannot drop CAP_SYS_NICE here: skipped"
  exit 77
fi
( ulimit -r 0 && setpriv --inh-caps=-sys_nice --bounding-set=-sys_nice \
    "$tactus" run rates --duration 0.3 --set physics.work_us=0 --set graphics.work_us=0 --out "$out" --quiet ) || {
  echo "FAIL: the run did not complete without SCHED_FIFO"; exit 1; }

grep -q '"scheduler": "[^"]*SCHED_FIFO refused' "$out/report.json" || {
  echo "FAIL: report.json does not say SCHED_FIFO was refused"; grep scheduler "$out/report.json"; exit 1; }
grep -q '"scheduler.no_sched_fifo": 1' "$out/report.json" || {
  echo "FAIL: no scheduler.no_sched_fifo warning in report.json"; exit 1; }
grep -q '"steps": [1-9]' "$out/report.json" || { echo "FAIL: no controller stepped"; exit 1; }
echo "ran without SCHED_FIFO and reported it"
