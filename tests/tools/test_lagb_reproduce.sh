#!/usr/bin/env bash
# The committed LAGB assets are exactly what the generator writes: the whole
# pipeline at 1.4 mm (about 7 s of CPU) and the phantom's NIfTI, compared byte
# for byte with assets/lagb/.
#
#   test_lagb_reproduce.sh GENERATOR ASSETS_DIR
set -u
GEN=$1
ASSETS=$2
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
fail=0
"$GEN" all "$WORK" >"$WORK.out" 2>&1 || { cat "$WORK.out"; echo "FAIL: the pipeline failed"; exit 1; }
grep "volume to tetrahedra" "$WORK.out"
rm -f "$WORK.out"
"$GEN" phantom "$WORK/phantom.nii.gz" >/dev/null 2>&1 || echo "this build writes no NIfTI: phantom.nii.gz not compared"
for f in "$ASSETS"/*; do
  name=$(basename "$f")
  [ "$name" = README.md ] && continue
  [ "${name#band_}" != "$name" ] && continue # the band's meshes: tactus-band-assets, band_assets_reproduce
  [ -e "$WORK/$name" ] || { [ "$name" = phantom.nii.gz ] && continue; echo "FAIL: the generator wrote no $name"; fail=1; continue; }
  cmp -s "$f" "$WORK/$name" || { echo "FAIL: $f differs from the generator's output"; fail=1; }
done
for f in "$WORK"/*; do
  [ -e "$ASSETS/$(basename "$f")" ] || { echo "FAIL: the generator wrote $(basename "$f"), not committed"; fail=1; }
done
[ $fail = 0 ] && echo "assets/lagb is what tactus-lagb-assets writes"
exit $fail
