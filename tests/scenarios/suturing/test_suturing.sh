#!/usr/bin/env bash
# The suturing scenario headless, in lockstep for its 17 s: the skin has a 3
# cm wound cut along z at x = 0 (38 links, none counted as torn); the needle
# goes in on one wound edge and out on the other, so A is done with one bite
# on each side of the wound (5 to 20 mm each, the 40 mm needle's), B (the
# thread pulled through) and G (the scissors' cut) are done, C to F are
# skipped (not scripted yet); the scorecard's JSON has the shape other tools
# read: eight steps A to H in order, "wound_gap_m" with "before" and "after"
# (a spacing, 2.5 mm, before: the skin is not pre-tensioned), each other
# measure with its value, unit and rule. The run's recordings of both hands
# (device0.bin, device1.bin) replayed in lockstep give the same scorecard,
# byte for byte, and hand 1 replayed from hand 0's recording scores
# otherwise. With OSMesa the run also writes its stereo frames (side by side)
# and a contact sheet. Release only (about 30 s).
#
#   test_suturing.sh TACTUS
set -eu
TACTUS=$1
command -v python3 >/dev/null || { echo "no python3: skipped"; exit 77; }
d=$(mktemp -d)
trap 'rm -rf "$d"' EXIT
view=()
[ "${TX_OSMESA:-1}" = 1 ] && view=(--view png --stereo sbs)
"$TACTUS" run suturing --lockstep --quiet --out "$d/o" "${view[@]}"
python3 - "$d/o" <<'PY'
import json, math, sys
out = sys.argv[1]
r = json.load(open(out + "/report.json"))["results"]
s = json.load(open(out + "/scorecard.json"))
def check(ok, what):
    if not ok:
        sys.exit("suturing: " + what)
check(r["skin.wound_links_cut"] == 38, "the wound cut %s links, not 38" % r["skin.wound_links_cut"])
check(r["skin.faults"] == 0 and r["thread.faults"] == 0, "a fault")
# the thread meets the instruments' jaws (instrumentN.capsules): the holder's, with the swage between them
check(r["thread.capsule_contact_steps"] > 0, "the thread never met a jaw: %r" % r["thread.capsule_contact_steps"])
check(s["scenario"] == "suturing", "scorecard scenario %r" % s["scenario"])
ids = [e["id"] for e in s["steps"]]
check(ids == list("ABCDEFGH"), "steps %r" % ids)
status = {e["id"]: e["status"] for e in s["steps"]}
print("steps:", status)
for k in "ABG":
    check(status[k] == "done" and next(e for e in s["steps"] if e["id"] == k)["done"] is True, "%s not done" % k)
for k in "CDEF":
    check(status[k] == "skipped", "%s is %s, not skipped" % (k, status[k]))
for e in s["steps"]:
    check(set(e) >= {"id", "name", "done", "t_start_s", "t_end_s"}, "step %s lacks a key" % e["id"])
b0, b1 = s["bite_entry_m"]["value"], s["bite_exit_m"]["value"]
print("bites %.2f and %.2f mm, wound gap %.3f -> %.3f mm, tissue force %.3f N, tears %d" % (
    1e3 * b0, 1e3 * b1, 1e3 * s["wound_gap_m"]["before"], 1e3 * s["wound_gap_m"]["after"],
    s["tissue_force_max_n"]["value"], s["tears"]["value"]))
check(0.005 < b0 < 0.02 and 0.005 < b1 < 0.02, "bites %g, %g m" % (b0, b1))
g = s["wound_gap_m"]
check(abs(g["before"] - 0.0025) < 1e-4 and math.isfinite(g["after"]) and g["unit"] == "m" and g["rule"], "wound gap %r" % g)
for k in ("bite_entry_m", "punctures", "peak_tension_n", "path_hand0_m", "tissue_force_max_n", "tears", "tears_pulled"):
    check(set(s[k]) == {"value", "unit", "rule"} and s[k]["rule"], "measure %s: %r" % (k, s[k]))
check(s["punctures"]["value"] == 2, "punctures %r" % s["punctures"])
# the needle's tip tore the punctures; nothing pulled hard enough to tear the skin elsewhere
check(s["tears"]["value"] > 0 and s["tears_pulled"]["value"] == 0, "tears %r, pulled %r" % (s["tears"], s["tears_pulled"]))
check(0 < s["tissue_force_max_n"]["value"] <= 3.3, "tissue force %r" % s["tissue_force_max_n"])
PY
test -s "$d/o/scorecard.png"
# the procedure's stereo frames (side by side: twice the width) and its contact sheet
if [ ${#view[@]} -gt 0 ]; then
  frames=("$d"/o/frames/frame_*.png)
  size=$(python3 -c 'import struct, sys; print("%d x %d" % struct.unpack(">II", open(sys.argv[1], "rb").read()[16:24]))' "${frames[-1]}")
  echo "frames: ${#frames[@]}, $size"
  [ "${#frames[@]}" -ge 30 ] && [ "$size" = "1280 x 480" ] && test -s "$d/o/frames/contact_sheet.png"
fi
# the session replayed from its recordings scores the same
"$TACTUS" run suturing --lockstep --no-record --quiet --device "replay:$d/o/device0.bin" --device "replay:$d/o/device1.bin" \
  --out "$d/r"
cmp "$d/o/scorecard.json" "$d/r/scorecard.json"
# and the replay is what drives the hands: hand 1 given hand 0's recording scores otherwise
"$TACTUS" run suturing --lockstep --no-record --quiet --device "replay:$d/o/device0.bin" --device "replay:$d/o/device0.bin" \
  --out "$d/x"
! cmp -s "$d/o/scorecard.json" "$d/x/scorecard.json"
echo "suturing: ok (the replay's scorecard is the same, byte for byte)"
