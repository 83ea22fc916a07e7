#!/usr/bin/env bash
# Three processes over loopback: suturing-skin's device, its simulation, and a
# view (the force curve) on a host of its own. The view process has neither
# the hand nor the skin: what it plots came over DDS from both others, and
# its peak force must be the one the device process rendered.
set -euo pipefail
tactus=$1
source "$(dirname "$0")/session.sh"
scenario=$(realpath "$(dirname "$0")/suturing-skin-three.json")
work=$(mktemp -d)
sim=; view=
trap 'kill $sim $view 2>/dev/null || true; rm -rf "$work"' EXIT
domain=$(( 1 + 5 * ($$ % 40) + 2 )) # a residue of its own (2 of 5): no two of these tests share a domain, whatever their PIDs
run() { exec "$tactus" run "$scenario" --role "$1" --duration "$2" --set net.domain=$domain --out "$1" --quiet >"$1.log" 2>&1; }
cd "$work"
# the sim and the view run until the device is done (session.sh)
run sim 60 & sim=$!
run view 60 & view=$!
started sim && started view
(run device 3) || { cat device.log; exit 1; }
stop $sim sim.log
stop $view view.log

python3 - <<'PY'
import csv, json
rep = {r: json.load(open(f"{r}/report.json")) for r in ("device", "sim", "view")}
for r, names in (("device", ["haptics", "net"]), ("sim", ["hip", "net", "skin"]), ("view", ["curve", "net"])):
    got = sorted(c["name"] for c in rep[r]["controllers"])
    assert got == names, (r, got)
    for k in ("net.foreign_samples", "net.malformed_samples"):
        assert rep[r]["warnings"][k] == 0, (r, k)
assert rep["view"]["results"]["curve.samples"] > 1000, rep["view"]["results"]
assert rep["view"]["results"]["net.samples_received"] > 1000
curve = list(csv.DictReader(open("view/force_displacement.csv")))
cols = list(curve[0].keys())
fcol = "fy_n"
view_peak = max(abs(float(r[fcol])) for r in curve)
dev_peak = max(abs(float(r["fy_n"])) for r in csv.DictReader(open("device/device0.csv")))
print(f"peak force: rendered by the device {dev_peak:.4f} N, plotted by the view {view_peak:.4f} N ({fcol})")
assert dev_peak > 0.1
assert abs(view_peak - dev_peak) <= 0.1 * dev_peak, (view_peak, dev_peak)
PY
