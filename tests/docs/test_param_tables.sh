#!/usr/bin/env bash
# The parameter tables in docs/ are the ones the code declares: every block
#   <!-- params TYPE -->
#   ...
#   <!-- /params -->
# in docs/*.md must equal `tactus describe --class TYPE`, and every controller
# class built in must have such a block. With --update, the blocks are
# rewritten from the code instead (how the docs' tables are made).
#
#   test_param_tables.sh TACTUS DOCS_DIR [--update]
set -u
TACTUS=$(realpath "$1")
DOCS=$(realpath "$2")
UPDATE=${3:-}
failures=0
fail() {
  echo "FAIL: $*" >&2
  failures=$((failures + 1))
}
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT

"$TACTUS" describe --classes >"$WORK/classes" || { echo "FAIL: tactus describe --classes" >&2; exit 1; }
[ -s "$WORK/classes" ] || fail "tactus describe --classes listed nothing"
blocks=0
for doc in "$DOCS"/*.md; do
  # TYPE and line numbers of each block: "TYPE START END"
  awk '/^<!-- params [a-z0-9_.]+ -->$/ { type = $3; start = NR; next }
       /^<!-- \/params -->$/ { if (type != "") print type, start, NR; type = "" }' "$doc" >"$WORK/blocks"
  cp "$doc" "$WORK/doc"
  # bottom up, so that rewriting one block keeps the line numbers of those above
  while read -r type start end; do
    if ! grep -qxF "$type" "$WORK/classes"; then
      echo "skip: $(basename "$doc"):$start: $type is not built in this build" >&2
      continue
    fi
    "$TACTUS" describe --class "$type" >"$WORK/want" || { fail "tactus describe --class $type"; continue; }
    sed -n "$((start + 1)),$((end - 1))p" "$WORK/doc" >"$WORK/have"
    if [ "$UPDATE" = "--update" ]; then
      { head -n "$start" "$WORK/doc"; cat "$WORK/want"; tail -n "+$end" "$WORK/doc"; } >"$WORK/doc.new"
      mv "$WORK/doc.new" "$WORK/doc"
    elif ! diff -u "$WORK/have" "$WORK/want" >"$WORK/diff"; then
      fail "$(basename "$doc"):$start: the table of $type differs from the code (tests/docs/test_param_tables.sh TACTUS docs --update rewrites it):"
      sed 's/^/    /' "$WORK/diff" >&2
    fi
  done < <(sort -k2,2nr "$WORK/blocks")
  [ "$UPDATE" = "--update" ] && ! cmp -s "$WORK/doc" "$doc" && cp "$WORK/doc" "$doc" && echo "updated $(basename "$doc")"
  blocks=$((blocks + $(grep -c '' "$WORK/blocks")))
  cat "$WORK/blocks" >>"$WORK/all_blocks"
done
# every class built in, but the tests' own, has its table in the docs
touch "$WORK/all_blocks"
while read -r type; do
  case "$type" in test.*) continue ;; esac
  grep -q "^$type " "$WORK/all_blocks" || fail "$type: no <!-- params $type --> block in docs/"
done <"$WORK/classes"
[ "$blocks" -gt 0 ] || fail "no parameter blocks found in $DOCS"
echo "$blocks blocks checked"
[ "$failures" -eq 0 ]
