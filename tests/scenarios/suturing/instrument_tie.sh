#!/usr/bin/env bash
# The instrument tie's wrap (C) as scripted so far
# (assets/procedures/simple-interrupted-suture/instrument-tie, written by
# scenarios/instruments/hands.py with TIE=1), a wrap drawn taut: with a 12
# cm thread that is a rod from 17.6 s, the forceps pull the needle up until
# 3 cm of tail is left (B), then carry it 1.5 times round the closed needle
# holder's jaws 20 mm out. The loop lacks the thread the wrap takes up: the
# stitch holds the thread only until it is pulled (thread.md, "Passing
# through punctures"), so the wrap draws the tail back through the stitch
# to its end at the entry (out of it, or its last node there: the run is
# chaotic) and the thread never winds round the jaws: C is not scored.
# (Before, the stitch held the thread whatever pulled it, and a link
# through it stretched to 5.4 times its length: C was scored on that; then
# the skin's contact, solved after the stretch cap, held the bite's strand
# under the skin and stretched it by 0.54.)
# Checked: A and B done, C not, the rod within a strain of 0.12 (0.09: the
# cap is 0.05, and the skin's and the jaws' contacts have the last turn),
# no fault.
# Release only (26.5 s simulated, about 14 s).
#
#   instrument_tie.sh TACTUS
set -eu
TACTUS=$1
command -v python3 >/dev/null || { echo "no python3: skipped"; exit 77; }
d=$(mktemp -d)
trap 'rm -rf "$d"' EXIT
p=procedures/simple-interrupted-suture/instrument-tie
"$TACTUS" run suturing --lockstep --quiet --no-record --out "$d/o" --duration 26.5 \
  --set thread.length_m=0.12 --set thread.nodes=61 --set thread.rod_after_s=17.6 --set thread.puncture_friction_n=0.3 \
  --device "scripted:$p/hand0.csv" --device "scripted:$p/hand1.csv"
python3 - "$d/o" <<'PY'
import json, sys
out = sys.argv[1]
s = json.load(open(out + "/scorecard.json"))
r = json.load(open(out + "/report.json"))["results"]
status = {e["id"]: e["status"] for e in s["steps"]}
t = {e["id"]: e["t_end_s"] for e in s["steps"]}
print("instrument tie (a wrap drawn taut): steps %s, C at %s s; thread on the holder's capsules %d steps, max strain %.2f, faults %d" % (
    status, t["C"], r["thread.capsule_contact_steps"], r["thread.max_strain"], r["thread.faults"]))
def check(ok, what):
    if not ok:
        sys.exit("instrument_tie: " + what)
check(all(status[k] == "done" for k in "AB"), "A, B: %s" % status)
check(status["C"] == "under way", "C %s: a wrap that pulls the tail out is scored" % status["C"])
check(r["thread.max_strain"] <= 0.12, "max strain %.2f" % r["thread.max_strain"])
check(r["thread.faults"] == 0 and r["skin.faults"] == 0, "a fault")
check(r["thread.capsule_contact_steps"] > 0 and r["instruments.thread_grasps"] == 0, "the thread is not on the holder: %r" % r)
PY
