#!/usr/bin/env bash
# tactus-device serving over DDS (--dds) to `tactus run --device dds:...` on
# loopback: the run renders from the served device, the server applies its
# forces, and when the run ends (a lost simulation) the server's force is
# zero within 10 ms of the last one (with real-time priority; bounded without).
# Bad --dds input: exit 2 and one line. Usage: test_device_dds.sh TACTUS_DEVICE TACTUS
set -euo pipefail
dev=$1 tactus=$2
d=$(mktemp -d)
trap 'kill $(jobs -p) 2>/dev/null || true; rm -rf "$d"' EXIT
domain=$((150 + $$ % 80))

rc=0; "$dev" sim --dds 999 > "$d/bad" 2>&1 || rc=$?
[ $rc -eq 2 ] && [ "$(grep -c '' "$d/bad")" -eq 1 ] && grep -q -- '--dds 999' "$d/bad" || { echo "bad --dds:"; cat "$d/bad"; exit 1; }
rc=0; "$dev" sim --dds 5:arm,peer=10.0.0.300 > "$d/bad" 2>&1 || rc=$?
[ $rc -eq 2 ] && [ "$(grep -c '' "$d/bad")" -eq 1 ] && grep -q peer "$d/bad" || { echo "bad --dds peer:"; cat "$d/bad"; exit 1; }
rc=0; "$dev" sim --dds 5:Bad-name > "$d/bad" 2>&1 || rc=$?
[ $rc -eq 2 ] && [ "$(grep -c '' "$d/bad")" -eq 1 ] || { echo "bad --dds name:"; cat "$d/bad"; exit 1; }

"$dev" sim --dds "$domain:e2e" --duration 4 > "$d/server" 2>&1 &
server=$!
sleep 0.5
"$tactus" run haptics-wall --device "dds:$domain:e2e" --duration 1.5 --out "$d/run" > "$d/run.log" 2>&1 || { cat "$d/run.log"; exit 1; }
wait $server
cat "$d/server"
# the run rendered from the device it was served: states came in
grep -q '"haptics.steps"\|haptics' "$d/run.log"
applied=$(sed -n 's/.* \([0-9]*\) forces applied.*/\1/p' "$d/server")
[ "${applied:-0}" -gt 1000 ] || { echo "forces applied: ${applied:-none}"; exit 1; }
zero=$(sed -n 's/.*force zero \([0-9.]*\) ms after.*/\1/p' "$d/server")
if grep -q 'SCHED_FIFO$' "$d/server"; then limit=10.05; else limit=50; fi
awk -v z="$zero" -v l="$limit" 'BEGIN { exit !(z > 0 && z <= l) }' || { echo "force zero after $zero ms, limit $limit"; exit 1; }
echo "ok: $applied forces applied; force zero $zero ms after the last"
