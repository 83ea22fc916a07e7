#!/usr/bin/env bash
# An instructor's host: the suture's procedure runs in a sim process (a
# scripted stand-in for the instruments and the thread, suture_feed_plugin,
# and procedure.suture), its scorecard in an instructor process that has
# only the bridge and view.scorecard. The instructor's scorecard.json, made
# from the mirrored steps and measures, shows every step done at the times
# the sim's script set (time_scale 0.4: 0.4 s per script second).
set -euo pipefail
tactus=$1
scenario=$2
source "$(dirname "$0")/session.sh"
work=$(mktemp -d)
instructor=
trap 'kill $instructor 2>/dev/null || true; rm -rf "$work"' EXIT
domain=$(( 1 + 5 * ($$ % 40) + 4 )) # a residue of its own (4 of 5): no two of these tests share a domain, whatever their PIDs
run() { exec "$tactus" run "$scenario" --role "$1" --duration "$2" --set net.domain=$domain --out "$1" --quiet >"$1.log" 2>&1; }
cd "$work"
# the instructor runs until the sim is done (session.sh)
run instructor 60 & instructor=$!
started instructor
(run sim 4) || { cat sim.log; exit 1; }
stop $instructor instructor.log

python3 - <<'PY'
import json
rep = json.load(open("instructor/report.json"))
names = sorted(c["name"] for c in rep["controllers"])
assert names == ["net", "scorecard"], names
assert rep["results"]["scorecard.steps_done"] == 8, rep["results"]
card = json.load(open("instructor/scorecard.json"))
ends = [2.0, 3.0, 4.0, 5.0, 5.5, 6.5, 7.5, 8.5]
assert [s["id"] for s in card["steps"]] == list("ABCDEFGH"), card["steps"]
for s, end in zip(card["steps"], ends):
    assert s["done"], s
    assert abs(s["t_end_s"] - 0.4 * end) < 0.025, (s, 0.4 * end)
assert abs(card["bite_entry_m"]["value"] - 0.004) < 1e-9 and abs(card["bite_exit_m"]["value"] - 0.0025) < 1e-9
assert card["knots"]["value"] == 2 and card["knots_fixed"]["value"] == 1
print("instructor's scorecard: " + ", ".join(f'{s["id"]} {s["t_end_s"]:.2f} s' for s in card["steps"]))
PY
