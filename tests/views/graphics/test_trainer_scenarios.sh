#!/usr/bin/env bash
# haptics-wall and suturing-skin run 2 s in a 640 x 480 window under Xvfb with
# the trainer's panels shown: each exits 0, its report.json has every
# controller stepping (the haptics loop, the HIP and the force curve among
# them, at more than half their rates) and the view drew frames. The rates
# are printed; the target on them (haptics within 1 % with the panels shown)
# is measured by `tactus bench render-gui`, not here: a timing on a shared
# machine is a bench's. Exit 77 (skipped) only when Xvfb is not installed.
#
#   test_trainer_scenarios.sh TACTUS
set -u
TACTUS=$(realpath "$1")
command -v Xvfb >/dev/null || { echo "Xvfb is not installed: skipped"; exit 77; }
ON_XVFB="$(dirname "$(realpath "$0")")/on_xvfb.sh"
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
unset TACTUS_SCENARIO_PATH
failures=0
for sc in haptics-wall suturing-skin; do
  if ! timeout -k 5 60 bash "$ON_XVFB" "$TACTUS" run "$sc" --view window --quiet --out "$WORK/$sc" --duration 2 \
      >"$WORK/$sc.log" 2>&1; then
    echo "FAIL: $sc in a window: $(tail -n 3 "$WORK/$sc.log")" >&2
    failures=$((failures + 1))
    continue
  fi
  python3 - "$sc" "$WORK/$sc/report.json" <<'PY' || failures=$((failures + 1))
import json, sys
sc, path = sys.argv[1], sys.argv[2]
r = json.load(open(path))
bad, haptics = [], 0
for c in r["controllers"]:
    print(f"{sc}: {c['name']} {c['achieved_hz']:.1f} of {c['target_hz']:g} Hz, {c['missed']} missed")
    haptics += c["type"] == "haptics"
    if not (c["steps"] > 0 and c["achieved_hz"] > 0.5 * c["target_hz"]):
        bad.append(c["name"])
if not haptics or bad or not r["results"].get("view.frames", 0) > 0:
    print(f"FAIL: {sc}: no haptics controller, no frame, or not stepping: {bad}", file=sys.stderr)
    sys.exit(1)
PY
done
[ "$failures" -eq 0 ] && echo "trainer scenarios: ok"
exit $((failures > 0))
