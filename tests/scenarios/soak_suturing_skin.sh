#!/usr/bin/env bash
# Soak: suturing-skin in real time with the sim device for SECONDS (CI: 540).
# Samples the process's resident memory every second into OUT/rss.csv and
# fails when it grows by more than SLACK_KB between WARMUP seconds in and the
# end: every buffer of a run is allocated and touched before its first tick,
# so a flat line is the expected shape. Prints memory at the start and the end,
# and the run's summary (missed deadlines per controller, warnings).
#
# usage: soak_suturing_skin.sh TACTUS OUT SECONDS [WARMUP] [SLACK_KB]
set -uo pipefail
tactus=$1 out=$2 seconds=$3 warmup=${4:-10} slack_kb=${5:-1024}

rm -rf "$out"
mkdir -p "$out"
"$tactus" run suturing-skin --device sim --duration "$seconds" --out "$out/run" >"$out/summary.txt" 2>&1 &
pid=$!
echo "t_s,rss_kb" >"$out/rss.csv"
start=$(date +%s)
while kill -0 "$pid" 2>/dev/null; do
  rss=$(awk '/^VmRSS:/ {print $2}' "/proc/$pid/status" 2>/dev/null)
  [ -n "$rss" ] && echo "$(( $(date +%s) - start )),$rss" >>"$out/rss.csv"
  sleep 1
done
wait "$pid"
rc=$?
cat "$out/summary.txt"

# the last sample is taken while the run's threads still step; the run's
# finish (CSV export, plots) comes after and is not part of the steady state
first=$(awk -F, -v w="$warmup" 'NR > 1 && $1 >= w {print $2; exit}' "$out/rss.csv")
last=$(awk -F, -v end="$seconds" 'NR > 1 && $1 <= end - 2 {v = $2} END {print v}' "$out/rss.csv")
samples=$(($(wc -l <"$out/rss.csv") - 1))
echo "soak: ${seconds} s, ${samples} memory samples in $out/rss.csv"
echo "soak: resident memory ${first:-?} kB at ${warmup} s, ${last:-?} kB at the end"
if [ "$rc" -ne 0 ]; then
  echo "soak: FAIL: the run exited with status $rc" >&2
  exit 1
fi
if [ -z "$first" ] || [ -z "$last" ]; then
  echo "soak: FAIL: too few memory samples (is the run shorter than $((warmup + 2)) s?)" >&2
  exit 1
fi
growth=$((last - first))
echo "soak: growth ${growth} kB (allowed ${slack_kb} kB)"
if [ "$growth" -gt "$slack_kb" ]; then
  echo "soak: FAIL: resident memory grew by ${growth} kB" >&2
  exit 1
fi
echo "soak: passed"
