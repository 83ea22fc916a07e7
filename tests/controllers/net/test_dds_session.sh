#!/usr/bin/env bash
# The session of docs/distributed.md on one host: suturing-skin split into its
# sim and device roles, two processes over loopback DDS. The device process
# has no skin and no HIP, so any force it renders came from the sim process;
# the scripted hand presses the skin there, and the force models the device
# receives are the sim's HIP's (their peak within 20% of the HIP's, never
# above it: ~0.2 N at 3 s), rendered rather than faded.
set -euo pipefail
tactus=$1
source "$(dirname "$0")/session.sh"
work=$(mktemp -d)
trap 'kill $sim_pid 2>/dev/null || true; rm -rf "$work"' EXIT
domain=$(( 1 + 5 * ($$ % 40) + 0 )) # a residue of its own (0 of 5): no two of these tests share a domain, whatever their PIDs
cd "$work"

# bad input: exit status 2 and one line, before anything runs
bad() {
  local want=$1; shift
  set +e; "$tactus" run suturing-skin "$@" --out bad --quiet >out.txt 2>err.txt; local rc=$?; set -e
  [ $rc -eq 2 ] || { echo "expected status 2 for $*, got $rc"; cat err.txt; exit 1; }
  [ "$(wc -l <err.txt)" -eq 1 ] && grep -qF -- "$want" err.txt || { echo "for $*: expected '$want', got:"; cat err.txt; exit 1; }
  [ ! -e bad ] || { echo "$* left bad/ behind"; exit 1; }
}
bad "--role nurse: unknown role" --role nurse
bad "net.domain: expected an integer in [0, 232]" --role sim --set net.domain=233
bad "net.peers[1]: expected an IPv4 address or a host name" --role sim --set 'net.peers=["10.0.0.2", "10.0.0.300"]'
bad "net.fast[3]: 'tool9.force_model' is not in the model" --role device --set 'net.fast=["device0.pose", "device0.force", "tool0.force_model", "tool9.force_model"]'
bad "--role sim: a session runs in real time" --role sim --lockstep

# the sim runs until the device is done (session.sh): the hand presses
# hardest at the device's 3 s, and after the device has gone the sim keeps
# its last pose
"$tactus" run suturing-skin --role sim --duration 60 --set net.domain=$domain --out sim --quiet >sim.log 2>&1 &
sim_pid=$!
started sim
"$tactus" run suturing-skin --role device --duration 3 --set net.domain=$domain --out device --quiet >device.log 2>&1 ||
  { cat device.log; exit 1; }
stop $sim_pid sim.log

python3 - <<'PY'
import csv, json, sys
dev = json.load(open("device/report.json"))
sim = json.load(open("sim/report.json"))
names = sorted(c["name"] for c in dev["controllers"])
assert names == ["haptics", "net"], f"the device role runs {names}"
assert sorted(c["name"] for c in sim["controllers"]) == ["curve", "hip", "net", "skin"]
r = dev["results"]
assert r["net.samples_received"] > 1000, r            # the force model, mirrored in
assert sim["results"]["net.samples_received"] > 1000  # the pose and force, mirrored out
for rep in (dev, sim):
    for k in ("net.foreign_samples", "net.malformed_samples", "net.send_failed"):
        assert rep["warnings"][k] == 0, (k, rep["warnings"][k])

rows = list(csv.DictReader(open("device/device0.csv")))
rendered = max(abs(float(r["fy_n"])) for r in rows)
received = max(abs(float(r["f0y_n"])) for r in rows)  # the force models that came over DDS
hip = sim["results"]["hip.peak_force_N"]
print(f"peak force: the sim's HIP {hip:.4f} N, received by the device {received:.4f} N, rendered {rendered:.4f} N")
assert hip > 0.1, hip
# every force model the device got is one the HIP made (keep last 1: not all of them)
assert 0.8 * hip <= received <= hip * 1.0001, (received, hip)
assert rendered > 0.5 * hip, (rendered, hip)  # rendered, not faded by the watchdog
PY
