#!/usr/bin/env bash
# tactus-lagb-assets: the whole pipeline at a coarse resolution (4 mm voxels,
# the paper's triangle counts) gives closed, manifold, outward surfaces and
# tetrahedra none of which is inverted, and reports the worst dihedral angles;
# a user's volume (raw + JSON, and NIfTI when built with it) goes through the
# same pipeline; bad input gets one line naming the file, exit status 2, and
# nothing written.
#
#   test_lagb_assets.sh GENERATOR
set -u
GEN=$1
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
fail=0
say_fail() { echo "FAIL: $*"; fail=1; }

# the pipeline, coarse
mkdir "$WORK/coarse"
"$GEN" all "$WORK/coarse" voxel=4 >"$WORK/all.out" 2>&1 || { cat "$WORK/all.out"; say_fail "the coarse pipeline failed"; }
cat "$WORK/all.out"
"$GEN" check "$WORK/coarse" >"$WORK/check.out" 2>&1 || say_fail "the coarse assets fail their check"
[ "$(ls -A "$WORK/coarse" | sort | tr '\n' ' ')" = "lagb.json liver.ele liver.face liver.node liver.obj peritoneum.obj spleen.obj stomach.ele stomach.face stomach.node stomach.obj " ] ||
  say_fail "the pipeline wrote other files: $(ls -A "$WORK/coarse")"
cat "$WORK/check.out"
for organ in liver stomach spleen peritoneum; do
  grep -q "^$organ *surface .*closed, manifold, oriented outward" "$WORK/check.out" || say_fail "$organ: no closed surface"
done
for organ in liver stomach; do
  grep -q "^$organ *tetrahedra .*none inverted.*dihedral angles" "$WORK/check.out" || say_fail "$organ: no tetrahedra"
done
# the paper's counts (the stomach's odd 1863 made even: a closed surface has 3F = 2E)
for pair in liver:2484 stomach:1862 spleen:1040 peritoneum:384; do
  grep -q "^${pair%%:*} *surface *${pair##*:} triangles" "$WORK/check.out" || say_fail "${pair%%:*}: not ${pair##*:} triangles"
done
# about 3000 tetrahedra each (within 10 %)
for organ in liver stomach; do
  n=$(sed -n "s/^$organ *tetrahedra *\([0-9]*\) .*/\1/p" "$WORK/check.out")
  [ -n "$n" ] && [ "$n" -ge 2700 ] && [ "$n" -le 3300 ] || say_fail "$organ: ${n:-no} tetrahedra, not about 3000"
done

# the check finds a defect: a surface with a hole
mkdir "$WORK/holed"
cp "$WORK/coarse"/* "$WORK/holed/"
sed -i '$d' "$WORK/holed/spleen.obj"
rc=0
"$GEN" check "$WORK/holed" >"$WORK/holed.out" 2>&1 || rc=$?
[ "$rc" -eq 1 ] && grep -q "^spleen .*DEFECT (boundary 3," "$WORK/holed.out" || say_fail "a hole went unseen (status $rc)"

small="faces.liver=600 faces.stomach=400 faces.spleen=200 tets.liver=600 tets.stomach=600"
# a user's volume: raw voxels and a JSON header
"$GEN" phantom "$WORK/user.json" voxel=8 >/dev/null || say_fail "phantom to raw + JSON failed"
mkdir "$WORK/user"
# shellcheck disable=SC2086
"$GEN" all "$WORK/user" volume="$WORK/user.json" $small >"$WORK/user.out" 2>&1 || { cat "$WORK/user.out"; say_fail "the pipeline on raw + JSON failed"; }
"$GEN" check "$WORK/user" >/dev/null 2>&1 || say_fail "the assets of raw + JSON fail their check"
# and NIfTI, when this build reads it
if "$GEN" --help | grep -q "NIfTI: yes"; then
  "$GEN" phantom "$WORK/user.nii.gz" voxel=8 >/dev/null || say_fail "phantom to NIfTI failed"
  mkdir "$WORK/nifti"
  # shellcheck disable=SC2086
  "$GEN" all "$WORK/nifti" volume="$WORK/user.nii.gz" $small >"$WORK/nifti.out" 2>&1 ||
    { cat "$WORK/nifti.out"; say_fail "the pipeline on NIfTI failed"; }
  "$GEN" check "$WORK/nifti" >/dev/null 2>&1 || say_fail "the assets of NIfTI fail their check"
  # the same volume either way: the same voxels
  cmp -s <(sed -n 's/^\(liver\|stomach\|spleen\) *\([0-9]*\) voxels.*/\1 \2/p' "$WORK/user.out") \
    <(sed -n 's/^\(liver\|stomach\|spleen\) *\([0-9]*\) voxels.*/\1 \2/p' "$WORK/nifti.out") ||
    say_fail "raw + JSON and NIfTI of one phantom differ"
else
  echo "this build reads no NIfTI: that part skipped"
fi

# bad input
mkdir "$WORK/out"
bad() { # WHAT FRAGMENT ARGS...
  local what=$1 frag=$2
  shift 2
  local rc=0
  timeout -k 5 60 "$@" >"$WORK/stdout" 2>"$WORK/err" || rc=$?
  local lines
  lines=$(grep -c '' "$WORK/err")
  if [ "$rc" -ne 2 ] || [ "$lines" -ne 1 ] || ! grep -qF -- "$frag" "$WORK/err"; then
    say_fail "$what: status $rc, $lines lines: $(head -c 300 "$WORK/err")"
  fi
  [ -z "$(ls -A "$WORK/out")" ] || { say_fail "$what: left $(ls -A "$WORK/out")"; rm -rf "${WORK:?}/out"/* "$WORK/out"/.[!.]*; }
}
printf '{"size": [4, 4], "spacing": [0.001, 0.001, 0.001], "type": "uint8", "data": "x.raw"}' >"$WORK/bad.json"
bad "a malformed header" "$WORK/bad.json: key \"size\"" "$GEN" all "$WORK/out" volume="$WORK/bad.json"
printf '{"size": [4, 4, 4], "spacing": [0.001, 0.001' >"$WORK/cut.json"
bad "a header cut short" "$WORK/cut.json:" "$GEN" all "$WORK/out" volume="$WORK/cut.json"
printf '{"size": [4, 4, 4], "spacing": [0.001, 0.001, 0.001], "type": "uint8", "data": "short.raw"}' >"$WORK/short.json"
head -c 63 /dev/zero >"$WORK/short.raw"
bad "a volume short of voxels" "$WORK/short.json: key \"data\"" "$GEN" all "$WORK/out" volume="$WORK/short.json"
head -c 1000 /dev/urandom >"$WORK/noise.nii"
bad "a malformed NIfTI file" "$WORK/noise.nii" "$GEN" all "$WORK/out" volume="$WORK/noise.nii"
bad "a label not present" "$WORK/user.json: spleen: label 9 is not present" \
  "$GEN" all "$WORK/out" volume="$WORK/user.json" label.spleen=9
bad "a volume of no known kind" "$WORK/user.raw: a volume is" "$GEN" all "$WORK/out" volume="$WORK/user.raw"
bad "a missing volume" "$WORK/none.json" "$GEN" all "$WORK/out" volume="$WORK/none.json"
bad "an unknown organ" "label.heart=5: unknown organ" "$GEN" all "$WORK/out" label.heart=5
bad "an odd triangle count" "faces.liver=2483" "$GEN" all "$WORK/out" faces.liver=2483
bad "a voxel size out of range" "voxel=0.01" "$GEN" all "$WORK/out" voxel=0.01
bad "no such folder" "$WORK/nowhere: not a folder" "$GEN" all "$WORK/nowhere"
bad "no command" "expected a command" "$GEN"
# a mesh with holes
head -n -1 "$WORK/coarse/spleen.obj" >"$WORK/holed.obj"
bad "a mesh with holes" "$WORK/holed.obj: not a closed" "$GEN" tets "$WORK/holed.obj" "$WORK/out/t"
# TetGen fails: two closed cubes through each other, then a tetgen that dies
cube() { # OFFSET: a closed cube of side 1 at (OFFSET, OFFSET, OFFSET), vertices 8 on
  local o=$1 b=$2
  for v in "0 0 0" "1 0 0" "1 1 0" "0 1 0" "0 0 1" "1 0 1" "1 1 1" "0 1 1"; do
    set -- $v
    awk -v x="$1" -v y="$2" -v z="$3" -v o="$o" 'BEGIN { print "v", x + o, y + o, z + o }'
  done
  for f in "1 3 2" "1 4 3" "5 6 7" "5 7 8" "1 2 6" "1 6 5" "2 3 7" "2 7 6" "3 4 8" "3 8 7" "4 1 5" "4 5 8"; do
    set -- $f
    echo "f $(($1 + b)) $(($2 + b)) $(($3 + b))"
  done
}
{ cube 0 0; cube 0.5 8; } >"$WORK/crossed.obj"
bad "a TetGen failure" "$WORK/crossed.obj: tetgen" "$GEN" tets "$WORK/crossed.obj" "$WORK/out/t" tets=100
cube 0 0 >"$WORK/cube.obj"
bad "a TetGen crash" "$WORK/cube.obj: tetgen" env TACTUS_TETGEN=/bin/false "$GEN" tets "$WORK/cube.obj" "$WORK/out/t" tets=100
bad "a TetGen failure in the pipeline" "user.json: liver: tetgen" \
  env TACTUS_TETGEN=/bin/false "$GEN" all "$WORK/out" volume="$WORK/user.json" $small
bad "a check of no assets" "$WORK/out/lagb.json" "$GEN" check "$WORK/out"
exit $fail
