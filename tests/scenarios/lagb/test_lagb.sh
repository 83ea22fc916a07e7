#!/usr/bin/env bash
# The lagb scenario headless, in lockstep, with its scripted hands
# (assets/procedures/lagb/hand0.csv, hand1.csv): every step of phases 2 and 3
# done, in order, the band locked round the stomach, nothing burnt outside
# the membranes, no fault and no warning. Then the two scripts that go
# wrong, each for hand 1 over the first seconds: a burn on the liver (the
# scorecard's burn_outside_target true; the band, untouched, not round the
# stomach) and the band's tip pushed beside the
# buckle (taken, never locked, 3c not done). Bad parameters of
# procedure.lagb and of the scorecard are refused with status 2 and one line.
#
#   test_lagb.sh TACTUS
set -eu
TACTUS=$1
d=$(mktemp -d)
trap 'rm -rf "$d"' EXIT
"$TACTUS" run lagb --lockstep --quiet --out "$d/o"
python3 - "$d/o" <<'PY'
import json, sys
o = sys.argv[1]
card = json.load(open(o + "/scorecard.json"))
steps = card["steps"]
ids = [s["id"] for s in steps]
assert ids == ["2a", "2b", "2c", "3a", "3b", "3c"], ids
for s in steps:
    assert s["done"] and s["status"] == "done", s
    assert s["t_start_s"] <= s["t_end_s"], s
    assert len(s["path_m"]) == 2, s
ends = {s["id"]: s["t_end_s"] for s in steps}
assert ends["2a"] <= min(ends["2b"], ends["2c"]) and max(ends["2b"], ends["2c"]) <= ends["3a"] <= ends["3b"] <= ends["3c"], ends
band = card["band"]
assert band["locked"] is True and band["encircles_stomach"] is True and abs(band["linking_number"]) == 1, band
assert abs(band["from_gej_m"]) < 0.06 and band["off_axis_m"] < 0.04, band
assert card["burn_outside_target"] is False and card["damage_outside_target_m3"]["value"] == 0, card
assert card["liver_force_max_n"]["value"] > 0.2, card["liver_force_max_n"]
assert card["path_hand1_m"]["value"] > 0.5, card["path_hand1_m"]
print("steps ends", ends, "band", {k: band[k] for k in ("locked", "encircles_stomach", "from_gej_m")},
      "liver pull", card["liver_force_max_n"]["value"])
PY
value() { awk -v k="\"$2\":" '$1 == k { gsub(",", "", $2); print $2 }' "$1"; }
r=$d/o/report.json
for k in procedure.steps_done scorecard.steps_done band.locked band.grasps organs.faults band.faults pars_flaccida.faults his.faults \
         pars_flaccida.passes his.passes; do
  echo "$k $(value "$r" "$k")"
done
awk -v a="$(value "$r" procedure.steps_done)" -v b="$(value "$r" band.locked)" -v f="$(value "$r" organs.faults)" \
  -v g="$(value "$r" band.faults)" -v p="$(value "$r" pars_flaccida.faults)" -v h="$(value "$r" his.faults)" \
  'BEGIN { exit !(a == 6 && b == 1 && f + g + p + h == 0) }'
awk '/"warnings": \{/ { w = 1; next } w && /\}/ { w = 0 } w { v = $2; gsub(",", "", v); if (v + 0 != 0) { print "warning: " $0; bad = 1 } }
     END { exit bad }' "$r"

# a burn on the wrong organ: the liver
"$TACTUS" run lagb --lockstep --quiet --duration 4.5 --device scenario --device scripted:procedures/lagb/wrong-organ-burn.csv --out "$d/w"
python3 - "$d/w/scorecard.json" <<'PY'
import json, sys
card = json.load(open(sys.argv[1]))
print("wrong organ: damage outside", card["damage_outside_target_m3"]["value"], "m^3")
assert card["burn_outside_target"] is True and card["damage_outside_target_m3"]["value"] > 1e-9, card
assert not any(s["done"] for s in card["steps"] if s["id"] in ("2b", "2c")), card["steps"]
# the tube's tip still where it was placed, 15 cm from the buckle: its loop is not closed, whatever the chord gives
assert card["band"]["encircles_stomach"] is False, card["band"]
PY

# the band not locked: its tip pushed past the buckle, 15 mm off its opening
"$TACTUS" run lagb --lockstep --quiet --duration 6 --device scenario --device scripted:procedures/lagb/band-not-locked.csv --out "$d/n"
echo "not locked: band.locked $(value "$d/n/report.json" band.locked), band.grasps $(value "$d/n/report.json" band.grasps)"
awk -v l="$(value "$d/n/report.json" band.locked)" -v g="$(value "$d/n/report.json" band.grasps)" 'BEGIN { exit !(l == 0 && g == 1) }'
python3 - "$d/n/scorecard.json" <<'PY'
import json, sys
card = json.load(open(sys.argv[1]))
assert card["band"]["locked"] is False, card["band"]
lock = [s for s in card["steps"] if s["id"] == "3c"][0]
assert not lock["done"], lock
PY

for bad in procedure.opening_m=-1 scorecard.measures=knots band.rotation_deg=[0,0] band.obstacles=[[0,0,0,0,0,0,-1]]; do
  rc=0
  "$TACTUS" run lagb --lockstep --quiet --duration 0.1 --set "$bad" --out "$d/bad" > "$d/err" 2>&1 || rc=$?
  cat "$d/err"
  key=${bad%%=*}; key=${key#*.}
  test $rc -eq 2 && test "$(grep -c '' "$d/err")" -eq 1 && grep -q "$key" "$d/err"
done
