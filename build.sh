#!/usr/bin/env bash
# The two ways in, as the README gives them:
#   ./build.sh run    install what is missing, build, run the default scenario headless
#   ./build.sh test   install what is missing, build every variant CI checks, run every test
# Other targets: build (Release only), quick (Release build + its tests).
set -euo pipefail
cd "$(dirname "$0")"

jobs=$(nproc 2>/dev/null || echo 2)
default_scenario=suturing-skin
fuzz_seconds=${TX_FUZZ_SECONDS:-15}
soak_seconds=${TX_SOAK_SECONDS:-540}

say() { printf '\n== %s\n' "$*" >&2; }

# configure and build one variant: build_variant DIR [cmake args...]; with
# targets set, only those (and what they need)
build_variant() {
  local dir=$1; shift
  cmake -S . -B "$dir" -DTX_WERROR=ON "$@" >/dev/null
  cmake --build "$dir" -j"$jobs" ${targets:+--target $targets} >/dev/null
}

# run a variant's tests: test_variant DIR [ctest args...]
test_variant() {
  local dir=$1; shift
  ctest --test-dir "$dir" --output-on-failure -j"$jobs" "$@"
}

tsan() {
  # ThreadSanitizer needs a fixed address layout on kernels with many ASLR bits
  if setarch "$(uname -m)" -R true 2>/dev/null; then setarch "$(uname -m)" -R "$@"; else "$@"; fi
}

target=${1:-}
case "$target" in
  run)
    tools/install-deps.sh
    say "build (Release)"
    build_variant build -DCMAKE_BUILD_TYPE=Release
    say "run $default_scenario (headless)"
    ./build/tactus run "$default_scenario" "${@:2}"
    ;;
  build)
    tools/install-deps.sh
    build_variant build -DCMAKE_BUILD_TYPE=Release
    ;;
  quick)
    tools/install-deps.sh
    build_variant build -DCMAKE_BUILD_TYPE=Release
    test_variant build -LE soak
    ;;
  test)
    tools/install-deps.sh
    start=$(date +%s)
    say "Release: build and test"
    build_variant build -DCMAKE_BUILD_TYPE=Release -DTX_SOAK_SECONDS="$soak_seconds"
    test_variant build -LE soak

    # the soak takes 9 minutes of wall clock but little CPU (its loops sleep to
    # absolute deadlines; its spinners are SCHED_IDLE and yield), so it runs in
    # the background while the other variants build and test, the ASan tests
    # with their real-time cases last; it passes on memory and exit status
    say "soak: suturing-skin in real time for ${soak_seconds} s, in the background; memory must stay flat"
    soak_log=build/soak.log
    setsid ctest --test-dir build --output-on-failure -L soak >"$soak_log" 2>&1 &
    soak_pid=$!
    trap 'kill -- -"$soak_pid" 2>/dev/null || true' EXIT

    say "ThreadSanitizer: the model and scheduler tests"
    targets=tsan_checks build_variant build-tsan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DTX_SANITIZE=thread
    TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1 suppressions=$PWD/tests/tsan.supp" tsan ctest --test-dir build-tsan --output-on-failure -L tsan

    say "core only: every optional part off"
    build_variant build-core -DCMAKE_BUILD_TYPE=Release -DTX_WITH_BULLET=OFF -DTX_WITH_ODE=OFF -DTX_WITH_ASSIMP=OFF -DTX_WITH_URDFDOM=OFF \
      -DTX_WITH_OSMESA=OFF -DTX_WITH_GLFW=OFF -DTX_WITH_DDS=OFF -DTX_WITH_PLPLOT=OFF \
      -DTX_WITH_GTS=OFF -DTX_WITH_NIFTI=OFF
    test_variant build-core

    say "libFuzzer: the scenario loader, the device packet decoder, the recording and waypoint readers and the sim spec, ${fuzz_seconds} s each"
    CC=clang targets=fuzzers build_variant build-fuzz -DCMAKE_BUILD_TYPE=Debug -DTX_FUZZ=ON -DTX_SANITIZE=address,undefined \
      -DTX_FUZZ_SECONDS="$fuzz_seconds"
    test_variant build-fuzz -R fuzz

    say "Debug + AddressSanitizer + UndefinedBehaviorSanitizer: build and test"
    build_variant build-asan -DCMAKE_BUILD_TYPE=Debug -DTX_SANITIZE=address,undefined
    ASAN_OPTIONS=detect_leaks=1 LSAN_OPTIONS=suppressions=$PWD/tests/lsan.supp UBSAN_OPTIONS=print_stacktrace=1 \
      test_variant build-asan

    say "soak: its result"
    soak_rc=0
    wait "$soak_pid" || soak_rc=$?
    trap - EXIT
    cat "$soak_log"
    [ "$soak_rc" -eq 0 ] || exit "$soak_rc"

    say "all variants passed in $(( $(date +%s) - start )) s"
    ;;
  *)
    sed -n '2,6p' "$0" | sed 's/^# \{0,1\}//'
    [ "$target" = "-h" ] || [ "$target" = "--help" ] && exit 0
    exit 2
    ;;
esac
