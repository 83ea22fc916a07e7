#!/usr/bin/env bash
# tactus-instrument-assets: regenerates assets/instruments byte for byte, and
# refuses bad input with one line and exit status 2.
#
#   test_instrument_assets.sh GENERATOR ASSETDIR
set -u
GEN=$1
ASSETS=$2
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
fail=0
mkdir "$WORK/out"
"$GEN" "$WORK/out" >/dev/null || { echo "FAIL: the generator failed"; exit 1; }
for f in "$ASSETS"/*.urdf "$ASSETS"/meshes/*; do
  rel=${f#"$ASSETS"/}
  cmp -s "$f" "$WORK/out/$rel" || { echo "FAIL: $rel differs from the generator's output"; fail=1; }
done
for f in "$WORK"/out/*.urdf "$WORK"/out/meshes/*; do
  rel=${f#"$WORK"/out/}
  [ -e "$ASSETS/$rel" ] || { echo "FAIL: the generator writes $rel, which is not committed"; fail=1; }
done
[ "$(ls "$WORK"/out/*.urdf | wc -l)" -eq 6 ] || { echo "FAIL: expected six instruments"; fail=1; }
bad() { # WHAT FRAGMENT ARGS...
  local what=$1 frag=$2
  shift 2
  local rc=0
  "$GEN" "$@" >"$WORK/stdout" 2>"$WORK/err" || rc=$?
  local lines
  lines=$(grep -c '' "$WORK/err")
  if [ "$rc" -ne 2 ] || [ "$lines" -ne 1 ] || ! grep -qF -- "$frag" "$WORK/err"; then
    echo "FAIL: $what: status $rc, $lines lines: $(head -c 300 "$WORK/err")"
    fail=1
  fi
}
bad "no arguments" "expected one argument"
bad "an option" "expected one argument" --bogus
bad "two folders" "expected one argument" "$WORK/a" "$WORK/b"
bad "no such folder" "$WORK/none: not a folder" "$WORK/none"
touch "$WORK/file"
bad "a file, not a folder" "$WORK/file: not a folder" "$WORK/file"
mkdir "$WORK/ro"
chmod a-w "$WORK/ro"
if [ ! -w "$WORK/ro" ]; then # root writes anywhere
  bad "unwritable folder" "$WORK/ro/meshes" "$WORK/ro"
  [ -n "$(ls -A "$WORK/ro")" ] && { echo "FAIL: a refused run left files in $WORK/ro"; fail=1; }
fi
chmod u+w "$WORK/ro"
exit $fail
