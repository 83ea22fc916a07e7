#!/usr/bin/env bash
# The trainer's target: with the panels shown, haptics-wall and suturing-skin
# in a window keep every haptics-rate controller (1 kHz and faster: the device
# loop, the HIP, the force curve) within 1 % of its rate. Each runs 2 s in a
# 640 x 480 window under Xvfb; report.json's achieved_hz and missed are read.
# Release only (the sanitizers slow the loop by design). Exit 77 (skipped)
# only when xvfb-run is not installed.
#
#   test_trainer_rates.sh TACTUS
set -u
TACTUS=$(realpath "$1")
command -v xvfb-run >/dev/null || { echo "xvfb-run is not installed: skipped"; exit 77; }
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
unset TACTUS_SCENARIO_PATH
failures=0
for sc in haptics-wall suturing-skin; do
  if ! timeout -k 5 60 xvfb-run -a "$TACTUS" run "$sc" --view window --quiet --out "$WORK/$sc" --duration 2 \
      >"$WORK/$sc.log" 2>&1; then
    echo "FAIL: $sc in a window: $(tail -n 3 "$WORK/$sc.log")" >&2
    failures=$((failures + 1))
    continue
  fi
  python3 - "$sc" "$WORK/$sc/report.json" <<'PY' || failures=$((failures + 1))
import json, sys
sc, path = sys.argv[1], sys.argv[2]
bad, fast = [], 0
for c in json.load(open(path))["controllers"]:
    if c["target_hz"] < 1000:
        continue
    fast += 1
    hz, miss = c["achieved_hz"], c["missed"] / max(1, c["steps"] + c["missed"])
    print(f"{sc}: {c['name']} {hz:.1f} of {c['target_hz']:g} Hz, {100 * miss:.2f} % missed")
    if hz < 0.99 * c["target_hz"] or miss > 0.01:
        bad.append(c["name"])
if not fast or bad:
    print(f"FAIL: {sc}: {'no haptics-rate controller' if not fast else ', '.join(bad) + ' below 99 % of its rate'}", file=sys.stderr)
    sys.exit(1)
PY
done
[ "$failures" -eq 0 ] && echo "trainer rates: ok"
exit $((failures > 0))
