#!/usr/bin/env bash
# A scenario whose plugin is not there: exit status 2 and one line that names
# the scenario file and plugins[0], for absolute and relative plugin paths,
# and for a file that is there but is no shared library.
#
#   test_plugin_missing.sh TACTUS
set -u
HERE=$(dirname "$(realpath "$0")")
TACTUS=$(realpath "$1")
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
cd "$WORK" || exit 1
. "$HERE/../bad_input_lib.sh" || exit 1

controllers='"controllers": [{"name": "a", "type": "rates.worker", "rate_hz": 10}]'
printf '{"name": "t", "plugins": ["/nonexistent/libnope.so"], %s}\n' "$controllers" >"$WORK/absolute.json"
expect_bad "absolute plugin path" "$WORK/absolute.json" "plugins[0]" "/nonexistent/libnope.so" -- \
  run "$WORK/absolute.json" --lockstep --duration 0.1 --out "$WORK/out"
printf '{"name": "t", "plugins": ["libnope.so"], %s}\n' "$controllers" >"$WORK/relative.json"
expect_bad "relative plugin path, resolved beside the file" "$WORK/relative.json" "plugins[0]" "$WORK/libnope.so" -- \
  run "$WORK/relative.json" --lockstep --duration 0.1 --out "$WORK/out"
expect_bad "describe names it too" "$WORK/relative.json" "plugins[0]" -- describe "$WORK/relative.json"
printf 'not a shared library\n' >"$WORK/libfake.so"
printf '{"name": "t", "plugins": ["libfake.so"], %s}\n' "$controllers" >"$WORK/fake.json"
expect_bad "a file that is no library" "$WORK/fake.json" "plugins[0]" "libfake.so" -- \
  run "$WORK/fake.json" --lockstep --duration 0.1 --out "$WORK/out"
printf '{"name": "t", "plugins": [42], %s}\n' "$controllers" >"$WORK/number.json"
expect_bad "a plugin that is no path" "$WORK/number.json" "plugins[0]" -- run "$WORK/number.json"
[ -e "$WORK/out/report.json" ] && fail "a scenario with a missing plugin wrote a report"

finish
