# Sourced by the session tests. A run's clock starts once it has loaded, and
# on a loaded machine (ctest -j2, DDS discovery) a process can load seconds
# after it was started: a CI run saw the device's press reach a sim whose
# fixed duration had ended first (HIP peak 0.069 N of ~0.2 N). So a process
# that must outlive another is started first, waited for, and stopped by
# SIGTERM once the other is done; it still writes its report (status 143).

# started DIR: wait until the run writing to DIR has loaded (its folder exists)
started() {
  local i
  for i in $(seq 300); do [ -d "$1" ] && return 0; sleep 0.1; done
  echo "$1: the run had not loaded after 30 s"
  return 1
}

# stop PID LOG: end the run PID with SIGTERM and check that it ended as asked
stop() {
  local rc=0
  kill -TERM "$1"
  wait "$1" || rc=$?
  [ $rc -eq 143 ] || { echo "expected status 143 after SIGTERM, got $rc"; cat "$2"; return 1; }
}
