#!/usr/bin/env bash
# tactus-hemisphere-assets: regenerates the committed assets/hemisphere/graded-*
# byte for byte (tetgen is deterministic), each level's tetrahedra about six
# times the last's; bad input is refused with status 2, one line, and nothing
# written.
#
#   test_hemisphere_assets.sh GENERATOR ASSETS_DIR
set -eu
GEN=$1
ASSETS=$2
d=$(mktemp -d)
trap 'rm -rf "$d"' EXIT
mkdir "$d/a" "$d/bad"
"$GEN" "$d/a" > "$d/out"
prev=0
for l in 0 1 2 3; do
  for ext in node ele; do cmp "$d/a/graded-$l.$ext" "$ASSETS/graded-$l.$ext"; done
  n=$(head -1 "$d/a/graded-$l.ele" | awk '{ print $1 }')
  test "$n" -gt $((4 * prev)) && test "$n" -lt $((9 * prev + 1000))
  prev=$n
done
test "$(grep -c tetrahedra "$d/out")" -eq 4
for bad in 4 -1 x 1.5; do
  rc=0
  "$GEN" "$d/bad" "$bad" > "$d/err" 2>&1 || rc=$?
  test $rc -eq 2 && test "$(grep -c '' "$d/err")" -eq 1 && grep -q -- "$bad" "$d/err" || { echo "$bad:"; cat "$d/err"; exit 1; }
  test -z "$(ls "$d/bad")"
done
rc=0
"$GEN" "$d/missing" > "$d/err" 2>&1 || rc=$?
test $rc -eq 2 && grep -q missing "$d/err"
