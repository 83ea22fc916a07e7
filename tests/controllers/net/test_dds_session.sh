#!/usr/bin/env bash
# The session of docs/distributed.md on one host: suturing-skin split into its
# sim and device roles, two processes over loopback DDS. The device process
# has no skin and no HIP, so any force it renders came from the sim process;
# the scripted hand presses the skin there, and the force the device renders
# must be the sim's HIP force (its peak within 10%; ~0.2 N at 3 s).
set -euo pipefail
tactus=$1
work=$(mktemp -d)
trap 'kill $sim_pid 2>/dev/null || true; rm -rf "$work"' EXIT
domain=$(( 1 + $$ % 200 )) # apart from other sessions on this host
cd "$work"

"$tactus" run suturing-skin --role sim --duration 3.6 --set net.domain=$domain --out sim --quiet >sim.log 2>&1 &
sim_pid=$!
sleep 0.5
"$tactus" run suturing-skin --role device --duration 3 --set net.domain=$domain --out device --quiet >device.log 2>&1 ||
  { cat device.log; exit 1; }
wait $sim_pid || { cat sim.log; exit 1; }

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

def peak(path):
    return max(abs(float(row["fy_n"])) for row in csv.DictReader(open(path)))
split, hip = peak("device/device0.csv"), sim["results"]["hip.peak_force_N"]
print(f"peak force: rendered by the device process {split:.4f} N, the sim process's HIP {hip:.4f} N")
assert hip > 0.1, hip
assert abs(split - hip) <= 0.1 * hip, (split, hip)
PY
