#!/usr/bin/env bash
# tactus study suturing-accuracy, quick (the 5 mm skin with 16 thread nodes
# against the scenario's 2.5 mm and 31): two rows, each run's scripted
# suture still completes A, the scenario's also B (B asks that the thread
# runs through the stitch: the coarse thread, 4 mm links, passes the entry
# but not the exit, thread.punctures_passed 1), every value finite, the
# reference row's
# own errors 0 and the other's finite; JSON, CSV (and the PNG with PLplot);
# a bad --set is refused with 2 and one line. About 8 s.
#
#   suturing_accuracy.sh TACTUS PLPLOT(0|1)
set -eu
TACTUS=$1 PLPLOT=$2
command -v python3 >/dev/null || { echo "no python3: skipped"; exit 77; }
d=$(mktemp -d)
trap 'rm -rf "$d"' EXIT
"$TACTUS" study suturing-accuracy --out "$d/o" --set quick=1
python3 - "$d/o/suturing-accuracy.json" <<'PY'
import json, math, sys
doc = json.load(open(sys.argv[1]))
rows = doc["rows"]
def check(ok, what):
    if not ok:
        sys.exit("suturing-accuracy: " + what)
check(doc["study"] == "suturing-accuracy" and doc["path"] == "quick" and len(rows) == 2, "shape %r" % doc)
keys = ("wound_gap_after_m", "peak_tension_n", "tissue_force_max_n", "bite_entry_m", "bite_exit_m")
for r in rows:
    check("A" in r["steps"], "steps %s at %g m" % (r["steps"], r["spacing_m"]))
    check(r["cpu_s"] > 0 and all(math.isfinite(r[k]) for k in keys), "row %r" % r)
check("B" in rows[1]["steps"], "steps %s at the scenario's spacing" % rows[1]["steps"])
check(all(rows[1][k + "_rel_error"] == 0 for k in keys), "the reference's own errors %r" % rows[1])
check(all(math.isfinite(rows[0][k + "_rel_error"]) for k in keys), "errors %r" % rows[0])
check(rows[0]["spacing_m"] == 0.005 and rows[1]["spacing_m"] == 0.0025, "spacings")
PY
test -s "$d/o/suturing-accuracy.csv"
if [ "$PLPLOT" = 1 ]; then test -s "$d/o/suturing-accuracy.png"; else test ! -e "$d/o/suturing-accuracy.png"; fi
rc=0
"$TACTUS" study suturing-accuracy --out "$d/bad" --set quick=2 2>"$d/err" || rc=$?
cat "$d/err"
test $rc = 2 && grep -q 'quick=2' "$d/err" && test "$(wc -l < "$d/err")" = 1
