#!/usr/bin/env bash
# A full disk stops the run at once with the reason, not after its duration:
# the recording fills a 64 KiB tmpfs within a fraction of a second of a 5 s run.
# Usage: test_recording_disk_full.sh TACTUS
set -u
tactus=$1
work=$(mktemp -d)
cleanup() { umount "$work/tiny" 2>/dev/null; rm -rf "$work"; }
trap cleanup EXIT
mkdir "$work/tiny"
if ! mount -t tmpfs -o size=64k tmpfs "$work/tiny" 2>/dev/null; then
  echo "cannot mount a tmpfs here (not root, or no CAP_SYS_ADMIN): skipped"
  exit 77
fi
start=$(date +%s%N)
"$tactus" run haptics-wall --device sim --out "$work/tiny/r" >"$work/out" 2>"$work/err"
rc=$?
ms=$((($(date +%s%N) - start) / 1000000))
echo "the run ended after $ms ms with exit $rc:"
cat "$work/err"
fail=0
[ $rc -ne 0 ] || { echo "FAIL: exit 0 on a full disk"; fail=1; }
[ $ms -lt 3000 ] || { echo "FAIL: the run went on for $ms ms of its 5 s"; fail=1; }
grep -q "No space left on device" "$work/err" || { echo "FAIL: the reason is not on stderr"; fail=1; }
exit $fail
