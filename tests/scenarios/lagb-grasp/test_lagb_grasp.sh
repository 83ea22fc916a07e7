#!/usr/bin/env bash
# The lagb-grasp scenario headless, in lockstep for its 5 s on the committed
# assets: the report has every documented key and no warning but the
# device's own force limits; the lap grasper closed on the liver once and
# let go once (organs.grasps 1, organs.grasp_releases 1), held some of its
# nodes, carried them about the script's retraction (15 mm up and 10 mm
# cranially: 18 mm) and felt the liver pull back; no numerical fault. A
# bad parameter is refused with status 2 and one line naming it.
#
#   test_lagb_grasp.sh TACTUS REPORT_CHECK
set -eu
TACTUS=$1
CHECK=$2
d=$(mktemp -d)
trap 'rm -rf "$d"' EXIT
value() { awk -v k="\"$2\":" '$1 == k { gsub(",", "", $2); print $2 }' "$1"; }
"$TACTUS" run lagb-grasp --lockstep --quiet --out "$d/o"
r=$d/o/report.json
"$CHECK" "$r" keys
awk '/"warnings": \{/ { w = 1; next } w && /\}/ { w = 0 } w && $1 !~ /haptics.force_(clamped|rate_limited)/ { v = $2; gsub(",", "", v); if (v + 0 != 0) { print "warning: " $0; bad = 1 } }
     END { exit bad }' "$r"
grasps=$(value "$r" organs.grasps)
releases=$(value "$r" organs.grasp_releases)
nodes=$(value "$r" organs.grasp_nodes_max)
carried=$(value "$r" organs.grasp_carried_max_m)
force=$(value "$r" organs.grasp_force_max_n)
moved=$(value "$r" organs.max_displacement_m)
faults=$(value "$r" organs.faults)
echo "grasps $grasps, releases $releases; $nodes nodes held, carried $carried m, pull up to $force N; liver moved $moved m; faults $faults"
awk -v g="$grasps" -v r="$releases" -v n="$nodes" -v f="$faults" 'BEGIN { exit !(g == 1 && r == 1 && n >= 3 && f == 0) }'
awk -v c="$carried" -v m="$moved" -v f="$force" 'BEGIN { exit !(c > 0.016 && c < 0.021 && m >= c - 0.001 && f > 0.1 && f < 20) }'
# a bad parameter: status 2, one line naming the key, nothing kept
rc=0
"$TACTUS" run lagb-grasp --lockstep --quiet --set organs.grasp_open_rad=0.05 --out "$d/bad" >"$d/err" 2>&1 || rc=$?
cat "$d/err"
test "$rc" -eq 2 && test "$(grep -c '' "$d/err")" -eq 1 && grep -q 'grasp_open_rad' "$d/err" && test ! -e "$d/bad/report.json"
