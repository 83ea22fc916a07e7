#!/usr/bin/env bash
# The lagb-organs scenario headless, in lockstep for its 6.5 s, on the coarse
# copy of the assets (tests/controllers/organs/coarse) to stay cheap, in both
# modes: the report has every documented key, no warning counted but the
# device's own force and force-rate limits (a desktop device's 3.3 N), no
# fault; the probe deformed the organs (a node moved more than 5 mm from
# rest) and met a reaction above 0.5 N; collision.organ, at 4 kHz, began a
# contact on each organ and carried a force of the physics' order to the
# tool; the haptics controller sent the hand (the scripted device's
# recording) a force of that order, up (+y, against the push) and within
# the device's 3.3 N.
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
  "$TACTUS" run lagb-organs --lockstep --quiet --out "$d/$mode" \
    --set organs.assets="$COARSE" --set organs.mode=$mode
  r=$d/$mode/report.json
  "$CHECK" "$r" keys
  awk '/"warnings": \{/ { w = 1; next } w && /\}/ { w = 0 } w && $1 !~ /haptics.force_(clamped|rate_limited)/ { v = $2; gsub(",", "", v); if (v + 0 != 0) { print "warning: " $0; bad = 1 } }
       END { exit bad }' "$r"
  moved=$(value "$r" organs.max_displacement_m)
  force=$(value "$r" organs.max_force_n)
  faults=$(value "$r" organs.faults)
  felt=$(value "$r" col.peak_force_N)
  onsets=$(value "$r" col.contacts)
  echo "$mode: largest displacement $moved m, largest force $force N, faults $faults; felt $felt N, $onsets contacts"
  awk -v m="$moved" -v f="$force" -v n="$faults" 'BEGIN { exit !(m > 0.005 && m < 0.1 && f > 0.5 && f < 50 && n == 0) }'
  awk -v f="$force" -v c="$felt" -v o="$onsets" 'BEGIN { exit !(o >= 2 && c > 0.5 * f && c < 2 * f) }'
  # the force the hand got: the recording's largest, and its direction
  sent=$(awk -F, 'NR > 1 && $1 + 0 == $1 { f = sqrt($5 * $5 + $6 * $6 + $7 * $7); if (f > m) { m = f; y = $6 } }
                  END { print m, y }' "$d/$mode/device0.csv")
  echo "$mode: the hand got up to $sent (N, |f| and f_y)"
  awk -v s="$sent" -v f="$force" 'BEGIN { split(s, a, " "); exit !(a[1] > 0.5 * f && a[1] <= 3.3 + 1e-9 && a[2] > 0.5 * a[1]) }'
done
