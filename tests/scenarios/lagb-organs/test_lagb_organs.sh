#!/usr/bin/env bash
# The lagb-organs scenario headless, in lockstep for its 6.5 s, on the coarse
# copy of the assets (tests/controllers/organs/coarse) to stay cheap, in both
# modes: the report has every documented key, no warning counted, no fault;
# the probe deformed the organs (a node moved more than 5 mm from rest) and
# met a reaction above 0.5 N; collision.organ, at 4 kHz, began a contact on
# each organ and carried a force of the physics' order to the tool.
#
#   test_lagb_organs.sh TACTUS REPORT_CHECK COARSE_DIR ["MODES"]   (default "fem links")
set -eu
TACTUS=$1
CHECK=$2
COARSE=$3
MODES=${4:-fem links}
d=$(mktemp -d)
trap 'rm -rf "$d"' EXIT
value() { awk -v k="\"$2\":" '$1 == k { gsub(",", "", $2); print $2 }' "$1"; }
for mode in $MODES; do
  "$TACTUS" run lagb-organs --lockstep --no-record --quiet --out "$d/$mode" \
    --set organs.assets="$COARSE" --set organs.mode=$mode
  r=$d/$mode/report.json
  "$CHECK" "$r" keys
  awk '/"warnings": \{/ { w = 1; next } w && /\}/ { w = 0 } w { v = $2; gsub(",", "", v); if (v + 0 != 0) { print "warning: " $0; bad = 1 } }
       END { exit bad }' "$r"
  moved=$(value "$r" organs.max_displacement_m)
  force=$(value "$r" organs.max_force_n)
  faults=$(value "$r" organs.faults)
  felt=$(value "$r" col.peak_force_N)
  onsets=$(value "$r" col.contacts)
  echo "$mode: largest displacement $moved m, largest force $force N, faults $faults; felt $felt N, $onsets contacts"
  awk -v m="$moved" -v f="$force" -v n="$faults" 'BEGIN { exit !(m > 0.005 && m < 0.1 && f > 0.5 && f < 50 && n == 0) }'
  awk -v f="$force" -v c="$felt" -v o="$onsets" 'BEGIN { exit !(o >= 2 && c > 0.5 * f && c < 2 * f) }'
done
