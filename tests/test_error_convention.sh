#!/usr/bin/env bash
# One way to report errors (docs/architecture.md, "Errors"): library code
# returns -1/NULL/false and leaves one line in tx_error(); controllers and
# views use tx_setup_fail, tx_warn and tx_stop_run and never print. This
# fails on any return of the old conventions in the sources:
#   err-buffer   a "char* err, size_t n" parameter (controllers scenarios model studies views app include)
#   tx_fault     the old configuration fault struct
#   message-check  a tx_*_check returning "const char*" (a message) in a header
#   print        fprintf/fputs/perror/write to stderr in controllers/ or views/ (but the
#                network device's live lost/back line)
# Usage: test_error_convention.sh SOURCE_DIR        check the tree
#        test_error_convention.sh --self-test DIR   DIR holds one of each: all four must be found
set -uo pipefail
self_test=0
[ "${1:-}" = --self-test ] && { self_test=1; shift; }
src=$1
cd "$src" || exit 2

pending=() # files exempt while they are rewritten: none now

dirs=()
for d in controllers scenarios model studies views app include; do [ -d "$d" ] && dirs+=("$d"); done
files() { # sources under the given folders, less the pending ones
  find "$@" -type f \( -name '*.c' -o -name '*.h' -o -name '*.cpp' \) 2>/dev/null | sort | while read -r f; do
    skip=0
    for p in "${pending[@]}"; do case "$f" in "$p" | "$p"/*) skip=1 ;; esac; done
    [ $skip = 0 ] && echo "$f"
  done
}
report=""
hits() { # RULE PATTERN FILES...: every line that matches, comments left out
  local rule=$1 pattern=$2
  shift 2
  [ $# -eq 0 ] && return
  local out
  out=$(grep -HnE "$pattern" "$@" 2>/dev/null | grep -vE '^[^:]+:[0-9]+:\s*//')
  [ -n "$out" ] && while IFS= read -r line; do report+="test_error_convention: $rule: $line"$'\n'; done <<<"$out"
}
mapfile -t all < <(files "${dirs[@]}")
mapfile -t mvc < <(files $( [ -d controllers ] && echo controllers) $( [ -d views ] && echo views))
mapfile -t headers < <(printf '%s\n' "${all[@]}" | grep -E '\.h$')
hits err-buffer 'char\s*\*\s*(err|msg)\w*,\s*size_t' "${all[@]}"
hits tx_fault '\btx_fault\b' "${all[@]}"
hits message-check 'const char\s*\*\s*tx_\w*_check\w*\(' "${headers[@]}"
# the one exception: the network devices' live lost/back line (docs/architecture.md, "Errors")
mapfile -t mvc_print < <(printf '%s\n' "${mvc[@]}" | grep -vxE 'controllers/haptics/device_udp.c|controllers/net/device_dds.c')
hits print '(fprintf|fputs|vfprintf)\s*\(.*\bstderr\b|\bperror\s*\(|\bwrite\s*\(\s*(STDERR_FILENO|2)\s*,' "${mvc_print[@]}"
if [ $self_test = 1 ]; then # every rule must fire on the fixture
  for rule in err-buffer tx_fault message-check print; do
    grep -q "^test_error_convention: $rule: " <<<"$report" || { echo "self-test: rule $rule found nothing" >&2; exit 1; }
  done
  echo "test_error_convention: the fixture trips every rule"
  exit 0
fi
[ -n "$report" ] && { printf '%s' "$report" >&2; exit 1; }
echo "test_error_convention: ${#all[@]} sources follow the one error convention"
