#!/usr/bin/env bash
# suturing-skin's sim and device roles on two "hosts": network namespaces that
# this test creates, joined by a veth pair, each process naming the other as
# its only peer. Where tc netem is available, the same session also runs with
# 1, 5 and 20 ms of delay and 1-10% loss on the link. The test touches no
# namespace it did not make, and skips (status 77) with the reason where
# namespaces cannot be made (no root, no CAP_NET_ADMIN, no iproute2).
set -uo pipefail
tactus=$1
source "$(dirname "$0")/session.sh"
command -v ip >/dev/null || { echo "SKIP: no ip command (iproute2)"; exit 77; }
[ "$(id -u)" -eq 0 ] || { echo "SKIP: network namespaces need root (CAP_NET_ADMIN)"; exit 77; }
id=$(( $$ % 250 + 1 ))
a=txnet${id}a; b=txnet${id}b
work=$(mktemp -d)
sim=
cleanup() {
  set +e # every step runs, whatever failed before
  [ -n "$sim" ] && kill $sim 2>/dev/null
  ip netns del $a 2>/dev/null; ip netns del $b 2>/dev/null; rm -rf "$work"
}
trap cleanup EXIT
trap "exit 1" INT TERM # a ctest timeout still removes the namespaces
if ! err=$(ip netns add $a 2>&1 && ip netns add $b 2>&1); then
  echo "SKIP: cannot create network namespaces here: $err"; exit 77
fi
set -e
ip link add txv${id}a type veth peer name txv${id}b
ip link set txv${id}a netns $a
ip link set txv${id}b netns $b
ip -n $a addr add 10.218.$id.1/24 dev txv${id}a
ip -n $b addr add 10.218.$id.2/24 dev txv${id}b
for n in $a $b; do ip -n $n link set lo up; done
ip -n $a link set txv${id}a up
ip -n $b link set txv${id}b up
cd "$work"

# one session over the link; its check in Python below
session() {
  local tag=$1
  # the sim runs until the device is done (session.sh)
  ip netns exec $a "$tactus" run suturing-skin --role sim --duration 60 --set "net.peers=[\"10.218.$id.2\"]" \
    --out sim-$tag --quiet >sim-$tag.log 2>&1 & sim=$!
  started sim-$tag || return 1
  ip netns exec $b "$tactus" run suturing-skin --role device --duration 3 --set "net.peers=[\"10.218.$id.1\"]" \
    --out device-$tag --quiet >device-$tag.log 2>&1 || { cat device-$tag.log; return 1; }
  stop $sim sim-$tag.log || return 1
  sim=
  python3 - "$tag" "$2" <<'PY'
import csv, json, sys
tag, tolerance = sys.argv[1], float(sys.argv[2])
dev, sim = (json.load(open(f"{r}-{tag}/report.json")) for r in ("device", "sim"))
assert dev["results"]["net.samples_received"] > 500, dev["results"]
assert sim["results"]["net.samples_received"] > 500, sim["results"]
rows = list(csv.DictReader(open(f"device-{tag}/device0.csv")))
received = max(abs(float(r["f0y_n"])) for r in rows)  # the force models that came over the link
hip = sim["results"]["hip.peak_force_N"]
print(f"{tag}: the sim's HIP peaked at {hip:.4f} N, the device received {received:.4f} N; "
      f"tool0.force_model one way p99 {dev['results']['net.tool0.force_model.latency_p99_us']:.0f} us")
assert hip > 0.1 and (1 - tolerance) * hip <= received <= hip * 1.0001, (received, hip)
PY
}

session veth 0.2
if ! err=$(tc -n $a qdisc add dev txv${id}a root netem delay 1ms loss 1% 2>&1); then
  echo "SKIP the delayed runs: tc netem is not available here ($err)"
  exit 0
fi
for setting in "1ms 1%" "5ms 5%" "20ms 10%"; do
  set -- $setting
  for n in a b; do
    dev=txv${id}$n; ns=txnet${id}$n
    tc -n $ns qdisc replace dev $dev root netem delay $1 loss $2
  done
  # the force arrives late and some of it not at all: what arrives is still the sim's, within 40%
  session "netem-$1-$2" 0.4
done
