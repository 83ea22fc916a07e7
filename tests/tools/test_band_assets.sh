#!/usr/bin/env bash
# tactus-band-assets: regenerates the committed assets/lagb/band_* byte for
# byte; other dimensions give other meshes of the counts they ask for, with
# every tetrahedron of positive volume; bad input is refused with status 2,
# one line naming the key, and nothing written.
#
#   test_band_assets.sh GENERATOR ASSETS_DIR
set -eu
GEN=$1
ASSETS=$2
d=$(mktemp -d)
trap 'rm -rf "$d"' EXIT
mkdir "$d/a" "$d/b" "$d/bad"
"$GEN" "$d/a"
for f in band_ring.node band_ring.ele band_tube.node band_tube.ele; do cmp "$d/a/$f" "$ASSETS/$f"; done
"$GEN" "$d/b" ring_segments=10 ring_across=1 tube_segments=5 ring_arc_deg=300 > "$d/b/out"
test "$(head -1 "$d/b/band_ring.ele" | awk '{ print $1 }')" -eq 60
test "$(head -1 "$d/b/band_tube.ele" | awk '{ print $1 }')" -eq 30
test "$(head -1 "$d/b/band_ring.node" | awk '{ print $1 }')" -eq 44
# the ends' markers: one cross-section each
test "$(awk 'NR > 1 && NF == 5 && $5 == 1' "$d/b/band_tube.node" | wc -l)" -eq 4
test "$(awk 'NR > 1 && NF == 5 && $5 == 2' "$d/b/band_tube.node" | wc -l)" -eq 4
for bad in ring_segments=1 ring_segments=2.5 tube_length=x gap=0 nokey=1 ring_arc_deg=360; do
  rc=0
  "$GEN" "$d/bad" "$bad" > "$d/err" 2>&1 || rc=$?
  key=${bad%%=*}
  test $rc -eq 2 && test "$(grep -c '' "$d/err")" -eq 1 && grep -q "$key" "$d/err" || { echo "$bad:"; cat "$d/err"; exit 1; }
  test -z "$(ls "$d/bad")"
done
rc=0
"$GEN" "$d/missing" > "$d/err" 2>&1 || rc=$?
test $rc -eq 2 && grep -q missing "$d/err"
