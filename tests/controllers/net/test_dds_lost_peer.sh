#!/usr/bin/env bash
# A lost peer, and one that comes back (docs/distributed.md, "A lost peer"):
# suturing-skin's device process renders the sim process's force; the sim
# process is killed (SIGKILL, nothing said goodbye) while the hand presses the
# skin (a scripted press, short of a tear), and a new one starts 0.3 s
# later. With haptics.model_timeout_s = 5 ms
# the force must be zero within 10 ms of the last force model that arrived,
# stay zero while no sim runs, and the force models of the new sim process
# must be taken up again.
set -euo pipefail
tactus=$1
source "$(dirname "$0")/session.sh"
work=$(mktemp -d)
sim1=; sim2=
trap 'kill $sim1 $sim2 2>/dev/null || true; rm -rf "$work"' EXIT
domain=$(( 1 + 5 * ($$ % 40) + 1 )) # a residue of its own (1 of 5): no two of these tests share a domain, whatever their PIDs
cd "$work"
# the sim on the 2.5 mm skin: this test is about the link, and the shipped
# 1/600 m skin's start and steps, on a loaded machine, left the hand not yet
# pressing when the sim was killed
sim() { exec "$tactus" run suturing-skin --role sim --duration "$1" --set net.domain=$domain \
  --set skin.spacing_m=0.0025 --set skin.coarse_block=0 --out "$2" --quiet >"$2.log" 2>&1; }

# the hand comes down to 3 mm above the mid-plane, then presses on at 2 mm/s
# (0.15 to 0.2 N by the kill, short of a tear; moving, so each force model
# differs from the one before), slowly, so that a sim process that starts or
# steps late under load meets a gentle press, not a deep one that tears;
# from 4 s it slides 1 mm along x at that depth, still moving, so that the
# new sim process, however slow to load, has a second to be taken up in
printf 't_s,x_m,y_m,z_m\n0,0,0.006,0\n0.3,0,0.003,0\n4.0,0,-0.0044,0\n5.0,0.001,-0.0044,0\n' >press.csv
sim 60 sim1 & sim1=$!
started sim1
"$tactus" run suturing-skin --role device --duration 5 --set net.domain=$domain --set haptics.model_timeout_s=0.005 \
  --device scripted:$PWD/press.csv --out device --quiet >device.log 2>&1 & device=$!
started device
sleep 2.9 # the device's clock at about 3 s
kill -9 $sim1
sleep 0.3
sim 60 sim2 & sim2=$!
wait $device || { cat device.log; exit 1; }
stop $sim2 sim2.log

python3 - <<'PY'
import csv
rows = list(csv.DictReader(open("device/device0.csv")))
key = ("f0x_n", "f0y_n", "f0z_n", "x0x_m", "x0y_m", "x0z_m", "kyy")
model = [tuple(r[k] for k in key) for r in rows]
# ticks at which a new force model had arrived (the HIP's x0 follows the hand every tick)
new = [i for i in range(1, len(rows)) if model[i] != model[i - 1]]
gaps = [(a, b) for a, b in zip(new, new[1:]) if b - a > 100 and a > 1000]
assert len(gaps) == 1, f"expected one silence of the sim, got {gaps}"
last, back = gaps[0]
force = [abs(float(r["fy_n"])) for r in rows]
print(f"last model at tick {last} (|F| {force[last]:.3f} N), next at tick {back}")
assert force[last] > 0.05, "the hand was not pressing the skin when the sim was lost"
zero = next(i for i in range(last, back) if force[i] == 0)
print(f"force zero {zero - last} ms after the last model")
assert zero - last <= 10, zero - last
assert max(force[zero:back]) == 0, "the force came back without a sim"
taken = sum(1 for i in new if i > back)
print(f"{taken} new force models from the new sim process")
assert taken > 200, taken
PY
