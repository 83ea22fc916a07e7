#!/usr/bin/env bash
# Sutures that go wrong, each with the scorecard's verdict (docs/suturing.md,
# "Sutures that go wrong"), headless in lockstep:
# - the shallow bite (assets/procedures/simple-interrupted-suture/shallow-bite):
#   the needle turned about a centre 5 mm off the wound line enters near one
#   edge and comes out far from the other; the needle still passes (A done)
#   and the scorecard reports the bites asymmetric;
# - the held tail: the thread's tail pinned on the skin 2 cm from the wound
#   (thread.pin_tail) while the forceps pull the needle through as usual: the
#   thread cannot be drawn through, so B is never done; the thread bunches
#   where it is held, which the papers' knot rule takes for a knot, and the
#   classifier does not confirm it (thread.knots_unconfirmed), so no throw is
#   scored (D and E not reached) and no knot is fixed on the skin.
# - pulling too hard (assets/procedures/simple-interrupted-suture/pull-too-hard):
#   the holder takes the thread's tail once it is pulled through and the
#   forceps pull the needle on 5 cm further than the thread reaches: the
#   stitch tears out of the skin, and the scorecard counts the tears a pull
#   made (tears_pulled), apart from the needle tip's.
# Release only (two 17 s runs and one of 20 s, about 20 s).
#
#   go_wrong.sh TACTUS
set -eu
TACTUS=$1
command -v python3 >/dev/null || { echo "no python3: skipped"; exit 77; }
d=$(mktemp -d)
trap 'rm -rf "$d"' EXIT
p=procedures/simple-interrupted-suture
"$TACTUS" run suturing --lockstep --quiet --no-record --out "$d/shallow" \
  --device "scripted:$p/shallow-bite/hand0.csv" --device "scripted:$p/shallow-bite/hand1.csv"
"$TACTUS" run suturing --lockstep --quiet --no-record --out "$d/held" --set thread.pin_tail=true \
  --set 'thread.tail_m=[0.02,0,0]'
"$TACTUS" run suturing --lockstep --quiet --no-record --out "$d/hard" --duration 20 \
  --device "scripted:$p/pull-too-hard/hand0.csv" --device "scripted:$p/pull-too-hard/hand1.csv"
python3 - "$d" <<'PY'
import json, sys
d = sys.argv[1]
def card(name):
    s = json.load(open("%s/%s/scorecard.json" % (d, name)))
    return s, {e["id"]: e["status"] for e in s["steps"]}
def check(ok, what):
    if not ok:
        sys.exit("go_wrong: " + what)

s, status = card("shallow")
b0, b1, asym = s["bite_entry_m"]["value"], s["bite_exit_m"]["value"], s["bite_asymmetry_m"]["value"]
print("shallow bite: bites %.2f and %.2f mm, asymmetry %.2f mm, symmetric %s, steps %s" % (
    1e3 * b0, 1e3 * b1, 1e3 * asym, s["bite_symmetric"], status))
check(status["A"] == "done", "the shallow bite's needle did not pass: A %s" % status["A"])
check(s["bite_symmetric"] is False and asym > 0.001, "the shallow bite is not reported: %r" % s["bite_symmetric"])
check(b0 < 0.01 < b1 and abs(abs(b1 - b0) - asym) < 1e-9, "bites %g and %g m, asymmetry %g m" % (b0, b1, asym))
check(s["tears_pulled"]["value"] == 0, "the shallow bite tore by a pull: %r" % s["tears_pulled"])

s, status = card("held")
r = json.load(open(d + "/held/report.json"))["results"]
print("held tail: steps %s, knots %d, unconfirmed %d, peak tension %.2f N, tears by a pull %d" % (
    status, s["knots"]["value"], r["thread.knots_unconfirmed"], s["peak_tension_n"]["value"], s["tears_pulled"]["value"]))
check(status["A"] == "done" and status["B"] == "under way", "A %s, B %s" % (status["A"], status["B"]))
check(status["D"] == "not reached" and status["E"] == "not reached", "a throw scored: D %s, E %s" % (status["D"], status["E"]))
check(s["knots"]["value"] == 0 and s["knots_fixed"]["value"] == 0 and r["thread.knots_unconfirmed"] >= 1,
      "knots %r, unconfirmed %r" % (s["knots"], r["thread.knots_unconfirmed"]))

s, status = card("hard")
r = json.load(open(d + "/hard/report.json"))["results"]
print("pulled too hard: steps %s, tears %d, by a pull %d, peak tension %.2f N, wound gap %.2f -> %.2f mm" % (
    status, s["tears"]["value"], s["tears_pulled"]["value"], s["peak_tension_n"]["value"],
    1e3 * s["wound_gap_m"]["before"], 1e3 * s["wound_gap_m"]["after"]))
check(status["A"] == "done" and status["B"] == "done", "A %s, B %s" % (status["A"], status["B"]))
check(r["thread.grasps"] == 1, "the holder did not take the tail: thread.grasps %r" % r["thread.grasps"])
check(s["tears_pulled"]["value"] >= 1, "no tear by a pull counted: %r" % s["tears_pulled"])
check(s["wound_gap_m"]["after"] > s["wound_gap_m"]["before"] + 0.001, "the stitch did not tear out: %r" % s["wound_gap_m"])
PY
