# Shared by the command-line tests: run tactus on bad input and check the
# contract of docs and DESIGN: exit status 2, exactly one line on stderr that
# names the file or the option, no crash, no hang. Sourced, not run.
#
#   TACTUS=/path/to/tactus; WORK=$(mktemp -d); cd "$WORK"
#   expect_bad "what it is" FRAGMENT... -- ARGS...

failures=0
cases=0

fail() {
  echo "FAIL: $*" >&2
  failures=$((failures + 1))
}

# the stderr line must contain every FRAGMENT (fixed strings)
expect_bad() {
  local what=$1
  shift
  local fragments=()
  while [ $# -gt 0 ] && [ "$1" != "--" ]; do
    fragments+=("$1")
    shift
  done
  shift
  cases=$((cases + 1))
  local rc=0
  timeout -k 5 20 "$TACTUS" "$@" >"$WORK/stdout" 2>"$WORK/stderr" </dev/null || rc=$?
  local lines
  lines=$(grep -c '' "$WORK/stderr")
  local line
  line=$(head -n 1 "$WORK/stderr")
  if [ "$rc" -eq 124 ]; then
    fail "$what: hung (killed after 20 s): tactus $*"
    return
  fi
  if [ "$rc" -gt 128 ]; then
    fail "$what: died of signal $((rc - 128)): tactus $*"
    return
  fi
  if [ "$rc" -ne 2 ]; then
    fail "$what: exit status $rc, expected 2: tactus $* (stderr: $line)"
    return
  fi
  if [ "$lines" -ne 1 ]; then
    fail "$what: $lines lines on stderr, expected 1: tactus $*"
    sed 's/^/    /' "$WORK/stderr" >&2
    return
  fi
  local f
  for f in "${fragments[@]}"; do
    case "$line" in
    *"$f"*) ;;
    *) fail "$what: stderr does not name '$f': $line" ;;
    esac
  done
  if compgen -G "$WORK/core*" >/dev/null; then
    fail "$what: left a core file"
    rm -f "$WORK"/core*
  fi
}

# a case whose line must also match an extended regular expression
expect_bad_re() {
  local what=$1 re=$2
  shift 2
  local before=$failures
  expect_bad "$what" "$@"
  if [ "$failures" -eq "$before" ] && ! grep -Eq -- "$re" "$WORK/stderr"; then
    fail "$what: stderr does not match /$re/: $(head -n 1 "$WORK/stderr")"
  fi
}

finish() {
  if [ "$failures" -ne 0 ]; then
    echo "$failures of $cases checks failed" >&2
    exit 1
  fi
  echo "all $cases cases passed"
}
