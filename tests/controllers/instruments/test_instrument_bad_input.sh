#!/usr/bin/env bash
# tactus describe --instrument: each shipped description is read whole; each
# kind of bad description (malformed, missing mesh, joint with no limits, zero
# or negative inertia, mesh with no faces) gives status 2 and one line naming
# the file and the element or line.
#
#   test_instrument_bad_input.sh TACTUS ASSETDIR
set -u
HERE=$(dirname "$(realpath "$0")")
TACTUS=$(realpath "$1")
ASSETS=$(realpath "$2")
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
cd "$WORK" || exit 1
. "$HERE/../../bad_input_lib.sh" || exit 1

for f in "$ASSETS"/*.urdf; do
  cases=$((cases + 1))
  if ! "$TACTUS" describe --instrument "$f" >"$WORK/out" 2>"$WORK/err"; then
    fail "$f: $(head -n 1 "$WORK/err")"
  elif ! grep -q "links" "$WORK/out" || [ -s "$WORK/err" ]; then
    fail "$f: no description, or something on stderr"
  fi
done
grep -q "jaw_upper_joint  revolute  root -> jaw_upper  axis (0, -1, 0)  0 to 0.26 rad" <("$TACTUS" describe --instrument "$ASSETS/needle_holder.urdf") ||
  fail "the needle holder's upper jaw is not described as its URDF gives it"

D=$WORK/d
mkdir "$D"
ln -s "$ASSETS/meshes" "$D/meshes"
NH=$ASSETS/needle_holder.urdf
sed 's#</link>#</lnk>#' "$NH" >"$D/malformed.urdf"
expect_bad "malformed URDF" "$D/malformed.urdf: line 22:" -- describe --instrument "$D/malformed.urdf"
sed 's#<limit lower="0" upper="0.26" effort="0.5" velocity="4"/>##' "$NH" >"$D/nolimit.urdf"
expect_bad "joint with no limits" "$D/nolimit.urdf" "jaw_upper_joint" "limits" -- describe --instrument "$D/nolimit.urdf"
sed '0,/ixx="/s//ixx="0" was="/' "$NH" >"$D/zero.urdf"
expect_bad "zero inertia" "$D/zero.urdf: link 'root' <inertia> ixx: must be positive, is 0" -- describe --instrument "$D/zero.urdf"
sed '0,/izz="/s//izz="-/' "$NH" >"$D/negative.urdf"
expect_bad "negative inertia" "$D/negative.urdf: link 'root' <inertia> izz: must be positive" -- describe --instrument "$D/negative.urdf"
sed '0,/<mass value="/s//<mass value="-/' "$NH" >"$D/mass.urdf"
expect_bad "negative mass" "$D/mass.urdf: link 'root' <mass>: must be positive" -- describe --instrument "$D/mass.urdf"
sed 's#meshes/needle_holder_jaw_upper.obj#meshes/gone.obj#' "$NH" >"$D/nomesh.urdf"
expect_bad "missing mesh" "$D/nomesh.urdf: link 'jaw_upper' <visual> <mesh>: $D/meshes/gone.obj: No such file" -- \
  describe --instrument "$D/nomesh.urdf"
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\n' >"$D/points.obj"
sed 's#meshes/needle_holder_root.obj#points.obj#' "$NH" >"$D/noface.urdf"
expect_bad "mesh with no faces" "$D/noface.urdf: link 'root' <visual> <mesh>: $D/points.obj: no faces" -- \
  describe --instrument "$D/noface.urdf"
expect_bad "no such file" "$D/none.urdf" -- describe --instrument "$D/none.urdf"
expect_bad "no file given" "describe --instrument: expected one FILE" -- describe --instrument
finish
