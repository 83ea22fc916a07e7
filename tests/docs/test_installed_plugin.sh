#!/bin/bash
# docs/writing-a-controller.md, followed from outside the build: cmake --install
# into a temporary prefix, build the page's plugin with the page's cc line
# against the installed headers (pkg-config, tactus.pc), run the page's
# scenario with the installed tactus, and check what it did.
#   test_installed_plugin.sh CMAKE BUILD_DIR PLUGIN.c CC_LINE_FILE SCENARIO.json
set -euo pipefail
cmake=$1 build=$2 plugin_c=$3 cc_line=$(cat "$4") scenario=$5
d=$(mktemp -d)
trap 'rm -rf "$d"' EXIT
fail() { echo "docs_installed_plugin: $*" >&2; exit 1; }

"$cmake" --install "$build" --prefix "$d/prefix" >/dev/null
p=$d/prefix
for f in include/tactus/tactus.h include/tactus/controller.h include/tactus/model.h include/tactus/haptics.h \
         include/tactus/config.h lib/libtactus.so lib/pkgconfig/tactus.pc bin/tactus bin/tactus-device; do
  [ -e "$p/$f" ] || fail "cmake --install did not install $f"
done
grep -q 'include <tactus/haptics.h>' "$p/include/tactus/tactus.h" || fail "tactus.h does not include haptics.h"

# the plugin, in a folder of its own, with nothing of the source tree in reach
mkdir "$d/work"
cp "$plugin_c" "$d/work/demo_counter.c"
cp "$scenario" "$d/work/demo.json"
export PKG_CONFIG_PATH=$p/lib/pkgconfig
flags=$(pkg-config --cflags --libs tactus) || fail "pkg-config finds no tactus in $PKG_CONFIG_PATH"
case "$flags" in *"-I$p"*) ;; *) fail "pkg-config --cflags points outside the prefix: $flags" ;; esac
(cd "$d/work" && env -u CPATH -u C_INCLUDE_PATH bash -c "set -e; $cc_line -Werror") ||
  fail "the page's cc line failed: $cc_line"
[ -f "$d/work/libdemo_counter.so" ] || fail "the page's cc line made no libdemo_counter.so"

# the scenario names the plugin by a path relative to its own folder
"$p/bin/tactus" run "$d/work/demo.json" --lockstep --duration 1 --out "$d/out" --quiet ||
  fail "the installed tactus failed to run the page's scenario"
# one second at 100 Hz: 100 publishes of demo.count
n=$(grep -c ',counter,demo.count,' "$d/out/trace.csv") || true
[ "$n" = 100 ] || fail "$n publishes of demo.count in trace.csv, expected 100"
grep -q '"steps": 100' "$d/out/report.json" || fail "report.json does not list 100 steps for counter"
echo "docs_installed_plugin: installed, built with '$cc_line', 100 steps"
