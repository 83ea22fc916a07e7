#!/usr/bin/env bash
# tactus-needle-reference: regenerates the shipped asset byte for byte, and
# refuses bad input with one line and exit status 2.
#
#   test_needle_reference.sh GENERATOR ASSET
set -u
GEN=$1
ASSET=$2
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
fail=0
"$GEN" "$WORK/ref.csv" >/dev/null || { echo "FAIL: the generator failed"; exit 1; }
cmp -s "$WORK/ref.csv" "$ASSET" || { echo "FAIL: $ASSET differs from the generator's output"; fail=1; }
bad() { # WHAT FRAGMENT ARGS...
  local what=$1 frag=$2
  shift 2
  local rc=0
  "$GEN" "$@" >"$WORK/out" 2>"$WORK/err" || rc=$?
  local lines
  lines=$(grep -c '' "$WORK/err")
  if [ "$rc" -ne 2 ] || [ "$lines" -ne 1 ] || ! grep -qF -- "$frag" "$WORK/err"; then
    echo "FAIL: $what: status $rc, $lines lines: $(head -c 300 "$WORK/err")"
    fail=1
  fi
}
bad "no arguments" "expected OUT.csv"
bad "an option first" "expected OUT.csv" --bogus
bad "unknown key" "bogus=1: unknown key" "$WORK/x.csv" bogus=1
bad "not a number" "a1=x" "$WORK/x.csv" a1=x
bad "no equals sign" "a1: expected KEY=VALUE" "$WORK/x.csv" a1
bad "out of range" "rate" "$WORK/x.csv" rate=10
bad "negative cutting" "cutting" "$WORK/x.csv" cutting=-1
bad "unwritable" "/nonexistent/dir/x.csv" /nonexistent/dir/x.csv
[ -e "$WORK/x.csv" ] && { echo "FAIL: a refused run left $WORK/x.csv"; fail=1; }
exit $fail
