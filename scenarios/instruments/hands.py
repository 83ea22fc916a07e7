#!/usr/bin/env python3
"""Writes hand0.csv and hand1.csv, the scripted hands of scenario instruments.

python3 scenarios/instruments/hands.py scenarios/instruments

The needle (instruments.json: needle_circle 0.5, needle_length_m 0.04,
needle_grasp_rad 0.1) stands in foam with its centre at FOAM, its arc in the
world's x-y plane, its point GRASP_RAD from the swage one radius along +x.
Drive, then regrasp: the holder takes it from outside the arc (its shaft
radial, pointing away from the centre, the wire across its jaws), turns it
about its centre CENTRE_Y above the skin until the shaft is level on the
other side (HOLDER_END_DEG), so its jaws never go under the skin, and the tip
is out of the exit; the forceps, lying along -z (beside the needle's plane,
level), take the wire GRASP_TIP_RAD behind the tip, the holder lets go and
rises, and the forceps turn the needle on until the swage is out.
Poses are each instrument's root (x to the tip, jaws opening along z).

Calibrating: the forceps come to where the holder's drive leaves the needle
(HANDOVER_CENTRE, HANDOVER_DEG), which the run decides (the skin's drag
against the holder's virtual coupling). After changing the drive, write the
CSVs, run the scenario, read the needle's centre and angle at 10 s (its
`needle.pose`), and set them; the environment variables CY, HC ("x,y,z"),
HD, GT and PD override CENTRE_Y, HANDOVER_CENTRE, HANDOVER_DEG,
GRASP_TIP_RAD and PULL_DEG for such trials, SX sets SHIFT_X (the
handover centre moves with it), PH sets PULL_HARD_M and TIE=1 writes the
instrument tie (the scenario takes the CSVs with --device scripted:FILE).
"""
import math
import os
import sys

R = 0.04 / math.pi          # the 1/2-circle needle, 40 mm along its arc
GRASP_RAD = 0.1             # the holder's grasp, from the swage
FOAM = (0.08, 0.02, 0.0)    # the needle's centre in foam
CENTRE_Y = 0.0085           # the centre above the skin while it turns
HOLDER_GRASP_M = 0.030      # the wire ahead of the holder's pivot
FORCEPS_GRASP_M = 0.125     # the wire ahead of the forceps' root
HOLDER_END_DEG = 178.0      # the holder's grasp point's angle about the centre at the end of its drive
GRASP_TIP_RAD = 0.08        # the forceps' grasp, behind the tip
PULL_DEG = 160.0            # the forceps' turn: the swage through both punctures and out
# Where the holder's drive leaves the needle, as the run has it at 10 s (the
# skin's drag holds the needle back on the holder's virtual coupling: its
# centre 5 mm lower than the hand's path puts it): its centre and the angle of
# its swage about the centre. The forceps come to it there and turn it on
# about that centre, the circle through both punctures.
HANDOVER_CENTRE = (-0.0014, 0.0035, -0.0017)
HANDOVER_DEG = 172.3
# The drive's centre across the wound (x): 0 puts it over the wound line, so
# the two bites match; a shift makes one bite shallow and the other deep (the
# go-wrong script of assets/procedures/simple-interrupted-suture/shallow-bite)
SHIFT_X = 0.0
# Pulling too hard (assets/procedures/simple-interrupted-suture/pull-too-hard):
# instead of taking the scissors the holder takes the thread's tail by its
# node two links beyond the entry, where the run has it once the forceps have
# pulled the needle through (measured with `tactus run suturing --lockstep
# --probe thread.nodes@0.5`: node 24 at 15.5 s), coming in low from -x under
# the needle's arc, and the forceps pull the needle on PULL_HARD_M further
# than the thread reaches. 0: the scissors cut, as scripted by default.
PULL_HARD_M = 0.0
# The instrument tie, so far its wrap (C) (assets/procedures/simple-interrupted-
# suture/instrument-tie, with a 12 cm thread that is a rod from 17.6 s): the
# forceps pull the needle TIE_UP further up, so that 3 cm of tail is left; the
# holder, closed, lies with its jaws along the needle's chord (TIE_CHORD, the
# swage to the tip at 15.5 s), TIE_R from the swage along +z; the forceps carry
# the needle TIE_TURNS times round the jaws' line, TIE_R out, in the plane
# across it (so the 25 mm needle keeps clear of the jaws), TIE_TURN_S a turn.
TIE = False
TIE_SWAGE = (0.0081, 0.0152, -0.0003)  # the swage at 15.5 s (--probe needle.swage)
TIE_CHORD = (-0.883, 0.469, 0.0)
TIE_UP = 0.055
TIE_R = 0.02
TIE_TURNS = 1.5
TIE_TURN_S = 5.0
TIE_WRAP_T = 18.5  # s, the wrap starts
TAIL_HOLD = (-0.0110, 0.0043, -0.0001)
TAIL_JAW_M = 0.028  # the hold, ahead of the holder's pivot (its jaws: 4 to 35 mm)


def qmul(a, b):
    return (a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
            a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
            a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
            a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0])


def rz(deg):
    h = math.radians(deg) / 2
    return (math.cos(h), 0.0, 0.0, math.sin(h))


def rot_z(deg, v):
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    return (c * v[0] - s * v[1], s * v[0] + c * v[1], v[2])


def quat_of(x, y, z):
    """The quaternion of the rotation whose columns are the axes x, y, z."""
    m = ((x[0], y[0], z[0]), (x[1], y[1], z[1]), (x[2], y[2], z[2]))
    t = m[0][0] + m[1][1] + m[2][2]
    if t > 0:
        s = 2 * math.sqrt(1 + t)
        return (s / 4, (m[2][1] - m[1][2]) / s, (m[0][2] - m[2][0]) / s, (m[1][0] - m[0][1]) / s)
    i = max(range(3), key=lambda k: m[k][k])
    j, k = (i + 1) % 3, (i + 2) % 3
    s = 2 * math.sqrt(1 + m[i][i] - m[j][j] - m[k][k])
    q = [0.0] * 4
    q[0] = (m[k][j] - m[j][k]) / s
    q[1 + i] = s / 4
    q[1 + j] = (m[j][i] + m[i][j]) / s
    q[1 + k] = (m[k][i] + m[i][k]) / s
    return tuple(q)


def about(centre, deg, p, q):
    """The pose (p, q) turned by deg about the world z axis through centre."""
    d = rot_z(deg, tuple(p[i] - centre[i] for i in range(3)))
    return tuple(centre[i] + d[i] for i in range(3)), qmul(rz(deg), q)


def row(t, p, q, grip, button=None):
    if q[0] < 0:
        q = tuple(-v for v in q)
    s = "%.3f,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.3f" % ((t,) + tuple(p) + tuple(q) + (grip,))
    return s if button is None else s + ",%d" % button


def hand0():
    rows = []
    # outside the arc, shaft along +x, tips along -x: turned half a turn about y
    q0 = (0.0, 0.0, 1.0, 0.0)
    at = lambda c, back: (c[0] + R + HOLDER_GRASP_M + back, c[1], c[2])
    rows.append(row(0.0, at(FOAM, 0.03), q0, 0))
    rows.append(row(0.3, at(FOAM, 0.03), q0, 0.4))
    rows.append(row(0.8, at(FOAM, 0), q0, 0.4))
    rows.append(row(1.2, at(FOAM, 0), q0, 0))
    rows.append(row(1.4, at(FOAM, 0), q0, 0))
    lifted = (FOAM[0], 0.07, FOAM[2])
    rows.append(row(1.9, at(lifted, 0), q0, 0))
    over = (SHIFT_X, 0.07, 0.0)
    rows.append(row(2.9, at(over, 0), q0, 0))
    centre = (SHIFT_X, CENTRE_Y, 0.0)
    rows.append(row(3.9, at(centre, 0), q0, 0))
    # the drive: 6 s about the centre, the grasp point from 0 to HOLDER_END_DEG
    n = 120
    for k in range(1, n + 1):
        p, q = about(centre, HOLDER_END_DEG * k / n, at(centre, 0), q0)
        rows.append(row(3.9 + 6.0 * k / n, p, q, 0))
    end = about(centre, HOLDER_END_DEG, at(centre, 0), q0)
    rows.append(row(12.0, end[0], end[1], 0))
    rows.append(row(12.3, end[0], end[1], 0.4))
    up = (end[0][0], end[0][1] + 0.03, end[0][2])
    rows.append(row(12.6, up, end[1], 0.4))
    if TIE:
        return hand0_tie(rows)
    if PULL_HARD_M:
        return hand0_tail(rows, up, end[1])
    rows.append(("# then it puts the holder down for the Metzenbaum scissors (button 0, the 10th column) and waits "
                 "beside the\n# patch (z = 7 cm) while the forceps pull the needle through; then, blades along -z, "
                 "it opens them across the\n# thread between the exit and the lifted needle, 12 mm above the skin, "
                 "and closes"))
    rows.append(row(12.7, up, end[1], 0.4, 1))
    rows.append(row(12.8, up, end[1], 0, 0))
    qs = (math.sqrt(0.5), 0.0, math.sqrt(0.5), 0.0)
    aside = (0.04, 0.03, 0.07)
    rows.append(row(13.2, aside, qs, 0, 0))
    rows.append(row(15.5, aside, qs, 0, 0))
    # the thread from the exit to the swage lifted 2 cm: cross it 12 mm up
    c = HANDOVER_CENTRE
    exit_deg = 360 - math.degrees(math.asin(c[1] / R))
    exit_x = c[0] + R * math.cos(math.radians(exit_deg))
    swage_deg = HANDOVER_DEG + PULL_DEG
    sw = (c[0] + R * math.cos(math.radians(swage_deg)), c[1] + R * math.sin(math.radians(swage_deg)) + 0.02)
    cut_x = exit_x + (sw[0] - exit_x) * 0.012 / sw[1]
    rows.append(row(15.8, (cut_x, 0.012, c[2] + 0.07), qs, 0, 0))
    rows.append(row(16.0, (cut_x, 0.012, c[2] + 0.07), qs, 0.6, 0))
    rows.append(row(16.3, (cut_x, 0.012, c[2] + 0.022), qs, 0.6, 0))
    rows.append(row(16.6, (cut_x, 0.012, c[2] + 0.022), qs, 0, 0))
    return ("t_s,x_m,y_m,z_m,qw,qx,qy,qz,grip_rad\n"
            "# device0, the needle holder (written by hands.py): takes the needle from the foam at (8, 2, 0) cm "
            "from outside its\n# arc, turns it about its centre %.1f mm above the skin by %.0f degrees (in, and the "
            "tip out of the exit) with\n# its shaft never below level, then opens and rises once the forceps "
            "hold it\n" % (CENTRE_Y * 1e3, HOLDER_END_DEG)
            + ("# (the centre %.1f mm off the wound line along x: one bite shallow, the other deep)\n" % (SHIFT_X * 1e3)
               if SHIFT_X else "") + "\n".join(rows) + "\n")


def hand0_tail(rows, up, q):
    """The holder, open and risen from the needle at 12.6 s, takes the tail near the entry."""
    # level, jaws along +x (opening along z, across the thread), low under the needle's arc
    qj = (1.0, 0.0, 0.0, 0.0)
    h = TAIL_HOLD
    at = lambda back: (h[0] - TAIL_JAW_M - back, h[1], h[2])
    rows.append(row(13.2, (at(0.04)[0], 0.03, h[2]), qj, 0.4))
    rows.append(row(15.6, at(0.04), qj, 0.4))
    rows.append(row(16.0, at(0), qj, 0.4))
    rows.append(row(16.3, at(0), qj, 0))
    rows.append(row(20.0, at(0), qj, 0))
    return ("t_s,x_m,y_m,z_m,qw,qx,qy,qz,grip_rad\n"
            "# device0, the needle holder (written by hands.py with PULL_HARD_M): takes the needle from the foam and "
            "drives it\n# as the default script does; then, open and risen, comes in level from -x and takes the "
            "thread's tail at (%.1f, %.1f, %.1f) mm, and holds it\n" % tuple(v * 1e3 for v in h) + "\n".join(rows) + "\n")


def tie_frame():
    """The wrap's geometry: the swage lifted, the jaws' line through P along
    the chord, the direction across it in the x-y plane, the holder's pivot."""
    d, z = TIE_CHORD, (0.0, 0.0, 1.0)
    n = (d[1] * z[2] - d[2] * z[1], d[2] * z[0] - d[0] * z[2], d[0] * z[1] - d[1] * z[0])
    lifted = (TIE_SWAGE[0], TIE_SWAGE[1] + TIE_UP, TIE_SWAGE[2])
    p = tuple(lifted[i] + TIE_R * z[i] for i in range(3))
    pivot = tuple(p[i] - 0.017 * d[i] for i in range(3))  # the swage's plane 17 mm along the jaws (4-35 mm)
    return d, z, n, lifted, p, pivot


def hand0_tie(rows):
    """The holder, open and risen from the needle at 12.6 s, goes over and lies closed along the needle's chord."""
    d, z, n, lifted, p, pivot = tie_frame()
    q = rz(math.degrees(math.atan2(d[1], d[0])))
    rows.append(row(13.2, (-0.0427, 0.09, 0.0), q, 0.4))
    rows.append(row(14.5, (pivot[0] + 0.03, 0.09, pivot[2] + 0.03), q, 0.4))
    rows.append(row(16.0, (pivot[0] + 0.03, pivot[1], pivot[2] + 0.03), q, 0))
    rows.append(row(TIE_WRAP_T - 0.3, pivot, q, 0))
    rows.append(row(TIE_WRAP_T + TIE_TURNS * TIE_TURN_S + 6, pivot, q, 0))
    return ("t_s,x_m,y_m,z_m,qw,qx,qy,qz,grip_rad\n"
            "# device0, the needle holder (written by hands.py with TIE): takes the needle from the foam and drives it "
            "as the\n# default script does; then, open and risen, comes over and lies closed with its jaws along the "
            "needle's chord,\n# %.0f mm above the lifted swage, for the thread to be wrapped round them\n" % (TIE_R * 1e3)
            + "\n".join(rows) + "\n")


def hand1(pinch):
    centre = HANDOVER_CENTRE
    psi = math.radians(HANDOVER_DEG + 180.0) - GRASP_TIP_RAD
    r = (math.cos(psi), math.sin(psi), 0.0)
    t = (-math.sin(psi), math.cos(psi), 0.0)
    g = (centre[0] + R * r[0], centre[1] + R * r[1], centre[2])
    # lying along -z beside the needle's plane, the wire along its y, closing along the radius
    q = quat_of((0.0, 0.0, -1.0), t, r)
    at = lambda back, up=0.0: (g[0], g[1] + up, g[2] + FORCEPS_GRASP_M + back)
    rows = list(pinch)
    rows.append(row(10.6, at(0.03, 0.03), q, 0))
    rows.append(row(10.9, at(0.03), q, 0))
    rows.append(row(11.1, at(0.03), q, 0.06))
    rows.append(row(11.5, at(0), q, 0.06))
    rows.append(row(11.8, at(0), q, 0))
    rows.append(row(13.0, at(0), q, 0))
    n = 40
    for k in range(1, n + 1):
        p, qq = about(centre, PULL_DEG * k / n, at(0), q)
        rows.append(row(13.0 + 2.0 * k / n, p, qq, 0))
    p, qq = about(centre, PULL_DEG, at(0), q)
    rows.append(row(15.5, (p[0], p[1] + 0.02, p[2]), qq, 0))
    pulled = ""
    if TIE:  # on up until 3 cm of tail is left, then round the holder's jaws
        d, z, n, lifted, centre, pivot = tie_frame()
        q0 = qq
        p1 = (p[0], p[1] + 0.02 + TIE_UP, p[2])
        rows.append(row(17.5, p1, q0, 0))
        rows.append(row(TIE_WRAP_T, p1, q0, 0))
        k = int(round(48 * TIE_TURNS))
        for j in range(1, k + 1):
            th = 2 * math.pi * TIE_TURNS * j / k
            sw = tuple(centre[i] - TIE_R * (math.cos(th) * z[i] + math.sin(th) * n[i]) for i in range(3))
            rows.append(row(TIE_WRAP_T + TIE_TURN_S * TIE_TURNS * j / k, tuple(p1[i] + sw[i] - lifted[i] for i in range(3)), q0, 0))
        last = rows[-1].split(",")
        rows.append(row(TIE_WRAP_T + TIE_TURNS * TIE_TURN_S + 6, tuple(float(v) for v in last[1:4]), q0, 0))
        pulled = ("# then on up %.0f mm, and %.1f times round the holder's jaws, %.0f mm out (the wrap)\n"
                  % (TIE_UP * 1e3, TIE_TURNS, TIE_R * 1e3))
    if PULL_HARD_M:  # once the holder holds the tail: on, up and out along the stitch's line, too far
        rows.append(row(16.5, (p[0], p[1] + 0.02, p[2]), qq, 0))
        far = (p[0] + PULL_HARD_M * 0.6, p[1] + 0.02 + PULL_HARD_M * 0.8, p[2])
        rows.append(row(18.5, far, qq, 0))
        rows.append(row(20.0, far, qq, 0))
        pulled = ("# from 16.5 s, the tail held in the holder, pull the needle on %.0f mm up and out: too hard\n"
                  % (PULL_HARD_M * 1e3))
    return ("t_s,x_m,y_m,z_m,qw,qx,qy,qz,grip_rad\n"
            "# device1, the thumb forceps (written by hands.py): from 3 s take a pinch of skin 2 cm beside the "
            "needle's plane\n# (the tips, 20 degrees down, 1 mm into it), lift it 8 mm and let go while the holder "
            "drives the needle; then,\n# lying along -z beside the needle's plane, close on its wire %.2f rad "
            "behind the tip (out of the exit);\n# from 13 s turn it on about its centre (%g, %.1f, 0) mm by %.0f "
            "degrees until the swage has left the skin, and lift it 2 cm\n"
            % (GRASP_TIP_RAD, SHIFT_X * 1e3, CENTRE_Y * 1e3, PULL_DEG) + pulled + "\n".join(rows) + "\n")


# the forceps' pinch of the skin beside the needle's plane and their way back
PINCH = [
    (0.0, (-0.172525, 0.013972, 0.0), (0.999699, 0, 0, -0.024530), 0),
    (3.0, (-0.172525, 0.013972, 0.0), (0.999699, 0, 0, -0.024530), 0),
    (3.8, (-0.119462, 0.061753, 0.02), (0.984808, 0, 0, -0.173648), 0),
    (4.1, (-0.119462, 0.061753, 0.02), (0.984808, 0, 0, -0.173648), 0.14),
    (4.6, (-0.119462, 0.041753, 0.02), (0.984808, 0, 0, -0.173648), 0.14),
    (4.9, (-0.119462, 0.041753, 0.02), (0.984808, 0, 0, -0.173648), 0),
    (5.6, (-0.119462, 0.049753, 0.02), (0.984808, 0, 0, -0.173648), 0),
    (6.2, (-0.119462, 0.041753, 0.02), (0.984808, 0, 0, -0.173648), 0),
    (6.5, (-0.119462, 0.041753, 0.02), (0.984808, 0, 0, -0.173648), 0.14),
    (7.0, (-0.119462, 0.061753, 0.02), (0.984808, 0, 0, -0.173648), 0.14),
    (7.5, (-0.119462, 0.061753, 0.02), (0.984808, 0, 0, -0.173648), 0),
    (9.0, (-0.119462, 0.061753, 0.02), (0.984808, 0, 0, -0.173648), 0),
    (10.0, (-0.172525, 0.043972, 0.0), (0.999699, 0, 0, -0.024530), 0),
]


def main():
    global CENTRE_Y, HANDOVER_CENTRE, HANDOVER_DEG, GRASP_TIP_RAD, PULL_DEG, SHIFT_X, PULL_HARD_M, TIE
    e = os.environ
    CENTRE_Y = float(e.get("CY", CENTRE_Y))
    SHIFT_X = float(e.get("SX", SHIFT_X))
    HANDOVER_CENTRE = (HANDOVER_CENTRE[0] + SHIFT_X,) + HANDOVER_CENTRE[1:]
    if "HC" in e:
        HANDOVER_CENTRE = tuple(float(v) for v in e["HC"].split(","))
    HANDOVER_DEG = float(e.get("HD", HANDOVER_DEG))
    GRASP_TIP_RAD = float(e.get("GT", GRASP_TIP_RAD))
    PULL_DEG = float(e.get("PD", PULL_DEG))
    PULL_HARD_M = float(e.get("PH", PULL_HARD_M))
    TIE = e.get("TIE", "") == "1"
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.abspath(__file__))
    pinch = [row(t, p, q, g) for t, p, q, g in PINCH]
    for name, text in (("hand0.csv", hand0()), ("hand1.csv", hand1(pinch))):
        with open(os.path.join(out, name + ".tmp"), "w") as f:
            f.write(text)
        os.replace(os.path.join(out, name + ".tmp"), os.path.join(out, name))


if __name__ == "__main__":
    main()
