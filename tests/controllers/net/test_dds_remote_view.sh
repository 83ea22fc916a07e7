#!/usr/bin/env bash
# A display host: suturing-skin's sim and device processes, and a third that
# runs only the view role (no controller of its own) with --view png in
# side-by-side stereo. It draws the skin and the tool from what came over DDS
# (skin.x and skin.tri reliable, the device's pose and force best effort):
# its last frame shows the skin, and the last of its frames that shows the
# tool's red tip shows it in each eye beside the skin.
set -euo pipefail
tactus=$1
source "$(dirname "$0")/session.sh"
work=$(mktemp -d)
sim=; view=
trap 'kill $sim $view 2>/dev/null || true; rm -rf "$work"' EXIT
domain=$(( 1 + 5 * ($$ % 40) + 3 )) # a residue of its own (3 of 5): no two of these tests share a domain, whatever their PIDs
run() { local r=$1 d=$2; shift 2; exec "$tactus" run suturing-skin --role "$r" --duration "$d" --set net.domain=$domain --out "$r" --quiet "$@" >"$r.log" 2>&1; }
cd "$work"
# the sim and the view run until the device is done (session.sh)
run sim 60 & sim=$!
run view 60 --view png --stereo sbs & view=$!
started sim && started view
(run device 3) || { cat device.log; exit 1; }
stop $sim sim.log
stop $view view.log

# a display role with nothing to display is refused, with one line
if "$tactus" run suturing-skin --role view --out none --quiet >none.log 2>&1; then echo "a view role without --view ran"; exit 1; fi
grep -q "^tactus: --role view: this role of .*suturing-skin.json runs no controller: give it a view (--view png or --view window)$" none.log \
  || { cat none.log; exit 1; }

python3 - <<'PY'
import glob, json, struct, zlib
rep = json.load(open("view/report.json"))
names = sorted(c["name"] for c in rep["controllers"])
assert names == ["net", "view"], names
res = rep["results"]
assert res["net.samples_received"] > 100, res
assert res["view.frames_written"] >= 2, res
for k in ("net.foreign_samples", "net.malformed_samples"):
    assert rep["warnings"][k] == 0, k

def read_png(path):  # 8-bit RGB or RGBA, non-interlaced: what the frame writer makes
    data = open(path, "rb").read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    pos, idat, w = 8, b"", 0
    while pos < len(data):
        n, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + n]
        if kind == b"IHDR":
            w, h, depth, colour = struct.unpack(">IIBB", body[:10])
            assert depth == 8 and colour in (2, 6), (depth, colour)
            bpp = 3 if colour == 2 else 4
        elif kind == b"IDAT":
            idat += body
        pos += 12 + n
    raw, stride, rows, prev = zlib.decompress(idat), w * bpp, [], bytearray(w * bpp)
    for y in range(h):
        f, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b, c = prev[i], prev[i - bpp] if i >= bpp else 0
            if f == 1: line[i] = (line[i] + a) & 255
            elif f == 2: line[i] = (line[i] + b) & 255
            elif f == 3: line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(line)
        prev = line
    return w, h, bpp, rows

def counts(path):  # per eye: skin-coloured and red pixels, every 2nd pixel
    w, h, bpp, rows = read_png(path)
    assert w == 2 * h * 4 // 3, (w, h)  # side by side: two 4:3 eyes
    out = []
    for eye in (0, 1):
        skin = red = 0
        for y in range(0, h, 2):
            for x in range(eye * w // 2, (eye + 1) * w // 2, 2):
                r, g, b = rows[y][bpp * x:bpp * x + 3]
                if r > 150 and 90 < g < 190 and 60 < b < 170 and r > g > b: skin += 1
                if r > 150 and g < 90 and b < 90: red += 1
        out.append((skin, red, 0.1 * (w // 4) * (h // 2)))
    return out

# the last frame that shows the tool: the view runs on after the device has
# gone, and a sim slowed by load may have let the skin slip over the tip by then
frames = sorted(glob.glob("view/frames/frame_*.png"))
assert all(skin > least for skin, _, least in counts(frames[-1])), "the last frame lacks the skin"
for path in reversed(frames[-12:]):
    c = counts(path)
    if all(skin > least and red > 0 for skin, red, least in c):
        for eye, (skin, red, _) in enumerate(c):
            print(f"{path}: eye {eye}: skin {skin} px, red tip {red} px (every 2nd pixel)")
        break
else:
    raise AssertionError(f"none of the last 12 frames shows the skin and the tool's tip in both eyes: {c}")
PY
