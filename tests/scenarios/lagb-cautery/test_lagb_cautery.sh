#!/usr/bin/env bash
# The lagb-cautery scenario headless, in lockstep for its 4.5 s on the
# committed assets: the report has every documented key and no warning but
# the device's own force limits; the hook's pedal was down 2.5 s on the liver
# (30 W: 75 J, all deposited), the liver's drawn surface reached boiling
# (100 C) where the hook held still, some tissue boiled and more than that
# has Omega > 1, and the stomach stayed at 37 C; the burn removed tissue:
# physics.organs removed the tetrahedra physics.cautery sent, none refused
# (the scenario's remove_fraction 0.02 removes the 3 the burn reached). With
# OSMesa (PNG=1) the run draws its frames, the organs coloured by
# temperature: each a PNG (test_renderer checks the colouring itself). A
# bad parameter is refused with status 2 and one line naming it.
#
#   test_lagb_cautery.sh TACTUS REPORT_CHECK [PNG]
set -eu
TACTUS=$1
CHECK=$2
PNG=${3:-0}
d=$(mktemp -d)
trap 'rm -rf "$d"' EXIT
value() { awk -v k="\"$2\":" '$1 == k { gsub(",", "", $2); print $2 }' "$1"; }
view=""
if [ "$PNG" = 1 ]; then view="--view png"; fi
# shellcheck disable=SC2086
"$TACTUS" run lagb-cautery --lockstep --quiet $view --out "$d/o"
if [ "$PNG" = 1 ]; then
  n=0
  for f in "$d"/o/frames/*.png; do
    head -c 8 "$f" | od -An -tx1 | tr -d ' \n' | grep -qx 89504e470d0a1a0a
    n=$((n + 1))
  done
  echo "$n frames"
  test "$n" -ge 5
fi
r=$d/o/report.json
"$CHECK" "$r" keys
# view.rows_not_drawn: a frame drawn just after a removal, before physics.cautery
# (another rate) has published the temperature on the new surface's rows, is
# drawn in the plain colour and counted; checked against the removals below
awk '/"warnings": \{/ { w = 1; next } w && /\}/ { w = 0 } w && $1 !~ /haptics.force_(clamped|rate_limited)|view.rows_not_drawn/ { v = $2; gsub(",", "", v); if (v + 0 != 0) { print "warning: " $0; bad = 1 } }
     END { exit bad }' "$r"
active=$(value "$r" cautery.active_s)
energy=$(value "$r" cautery.energy_j)
peak=$(value "$r" cautery.liver_peak_k)
damaged=$(value "$r" cautery.liver_damaged_m3)
boiled=$(value "$r" cautery.liver_boiled_m3)
speak=$(value "$r" cautery.stomach_peak_k)
sdamaged=$(value "$r" cautery.stomach_damaged_m3)
p99=$(value "$r" cautery.step_p99_ms)
echo "active $active s, $energy J; liver peak $peak K, $damaged m^3 with Omega > 1, $boiled m^3 boiled; stomach peak $speak K; step p99 $p99 ms"
awk -v a="$active" -v e="$energy" 'BEGIN { exit !(a > 2.4 && a < 2.6 && e > 29.99 * a && e < 30.01 * a) }'
awk -v p="$peak" -v dm="$damaged" -v b="$boiled" 'BEGIN { exit !(p > 373.14 && p < 373.16 && b > 0 && dm > b && dm < 2e-6) }'
awk -v p="$speak" -v dm="$sdamaged" 'BEGIN { exit !(p < 310.151 && dm == 0) }'
removed=$(value "$r" cautery.removed_tets)
oremoved=$(value "$r" organs.removed_tets)
echo "removed $removed tetrahedra ($oremoved by physics.organs), $(value "$r" cautery.removed_m3) m^3"
skipped=$(awk '$1 == "\"view.rows_not_drawn\":" { gsub(",", "", $2); print $2 }' "$r")
echo "frames drawn plain while the temperature caught up with a cut surface: ${skipped:-0}"
awk -v c="$removed" -v o="$oremoved" -v k="${skipped:-0}" 'BEGIN { exit !(c >= 1 && c == o && k <= 3 * c) }'
# a bad parameter: status 2, one line naming the key, nothing kept
rc=0
"$TACTUS" run lagb-cautery --lockstep --quiet --set cautery.power_w=-1 --out "$d/bad" >"$d/err" 2>&1 || rc=$?
cat "$d/err"
test "$rc" -eq 2 && test "$(grep -c '' "$d/err")" -eq 1 && grep -q 'power_w' "$d/err" && test ! -e "$d/bad/report.json"
