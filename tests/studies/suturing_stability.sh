#!/usr/bin/env bash
# tactus study suturing-stability, quick (the hands jittered 2 mm, the
# instruments and the thread at 500 Hz, the tissue x100 stiffer; each run
# through the needle's pass, 12.5 s): exit 0 only
# when every case passes (completed, no NaN or Inf to or from a hand, no force
# over the device's clamp); three cases in the JSON, each passing, with the
# largest force within the clamp read back; CSV (and the PNG with PLplot); a
# bad --set is refused with 2 and one line. About 15 s.
#
#   suturing_stability.sh TACTUS PLPLOT(0|1)
set -eu
TACTUS=$1 PLPLOT=$2
command -v python3 >/dev/null || { echo "no python3: skipped"; exit 77; }
d=$(mktemp -d)
trap 'rm -rf "$d"' EXIT
"$TACTUS" study suturing-stability --out "$d/o" --set quick=1
python3 - "$d/o/suturing-stability.json" <<'PY'
import json, sys
doc = json.load(open(sys.argv[1]))
cases = doc["cases"]
def check(ok, what):
    if not ok:
        sys.exit("suturing-stability: " + what)
check(doc["study"] == "suturing-stability" and doc["path"] == "quick" and len(cases) == 3, "shape %r" % doc)
for c in cases:
    check(c["pass"] and c["completed"] and c["non_finite"] == 0, "case %r" % c)
    check(0 < c["force_max_n"] <= c["clamp_n"] * (1 + 1e-9) and c["clamp_n"] > 0, "force %r" % c)
PY
test -s "$d/o/suturing-stability.csv"
if [ "$PLPLOT" = 1 ]; then test -s "$d/o/suturing-stability.png"; else test ! -e "$d/o/suturing-stability.png"; fi
rc=0
"$TACTUS" study suturing-stability --out "$d/bad" --set fast=1 2>"$d/err" || rc=$?
cat "$d/err"
test $rc = 2 && grep -q 'fast=1' "$d/err" && test "$(wc -l < "$d/err")" = 1
