#!/usr/bin/env bash
# The lagb-band scenario headless, in lockstep for its 3.5 s on the committed
# band: the scripted grasper threads the tube's tip through the held buckle
# and the band locks (band.locked 1, one latch event on band.events), the
# distance joint held its length within 1 % throughout, no warning and no
# fault. Then the same run with the grasper's path moved 2 cm along the
# band's width (z), past the buckle outside its opening: no lock. A bad
# parameter is refused with status 2 and one line naming it.
#
#   test_lagb_band.sh TACTUS
set -eu
TACTUS=$1
d=$(mktemp -d)
trap 'rm -rf "$d"' EXIT
value() { awk -v k="\"$2\":" '$1 == k { gsub(",", "", $2); print $2 }' "$1"; }
"$TACTUS" run lagb-band --lockstep --quiet --out "$d/o"
r=$d/o/report.json
locked=$(value "$r" band.locked)
err=$(value "$r" band.joint_error_max)
faults=$(value "$r" band.faults)
echo "locked $locked, joint error max $err, faults $faults"
awk -v l="$locked" -v e="$err" -v f="$faults" 'BEGIN { exit !(l == 1 && e < 0.01 && f == 0) }'
awk '/"warnings": \{/ { w = 1; next } w && /\}/ { w = 0 } w { v = $2; gsub(",", "", v); if (v + 0 != 0) { print "warning: " $0; bad = 1 } }
     END { exit bad }' "$r"
grep -A3 '"band.events"' "$r" | grep -q '"sent": 1'

# the same path 2 cm off along z: past the buckle, outside its opening
src=$("$TACTUS" list | awk '$1 == "lagb-band" { print $2 }')
dir=$(dirname "$src")
awk -F, 'NR == 1 || /^#/ { print; next } { printf "%s,%s,%s,0.02\n", $1, $2, $3 }' "$dir/pull.csv" > "$d/off.csv"
sed "s|scripted:lagb-band/pull.csv|scripted:$d/off.csv|" "$src" > "$d/off.json"
"$TACTUS" run "$d/off.json" --lockstep --quiet --out "$d/off"
off=$(value "$d/off/report.json" band.locked)
echo "2 cm off: locked $off"
awk -v l="$off" 'BEGIN { exit !(l == 0) }'

rc=0
"$TACTUS" run lagb-band --lockstep --quiet --set band.buckle_radius_m=-1 --out "$d/bad" > "$d/err" 2>&1 || rc=$?
cat "$d/err"
test $rc -eq 2 && test "$(grep -c '' "$d/err")" -eq 1 && grep -q buckle_radius_m "$d/err"
