#!/usr/bin/env python3
"""Issue 17: candidate stall measures on the chapter-7 square and sine (section 7.1-7.2),
on the wang-hybrid preset as shipped and on the controls (the chapter-9 solenoid variant, which
has no charging interval; the preset with a tenth of the pilot spring, whose charging interval is
under 1 ms; a smooth constant-deceleration turn). Runs `hydrocyl simulate` (pass its
path) at 0.1 ms from 60 mm below mid-stroke and prints, per reversal direction, mean over the
reversals after the first period, in ms:

  |v|     time with |v| < 1 mm/s from the command's reversal to half the new speed (chapter7::stall)
  lp30/50 the same on the velocity low-passed (2nd-order Butterworth, forward-backward) at 30/50 Hz,
          below the shut column's natural frequency (~90 Hz at 20 kg, ~40 Hz with the K H added mass)
  ma10    the same on the mean velocity over 10 ms (about one ringing period), centred, from the
          position: (x(t + 5 ms) - x(t - 5 ms)) / 10 ms
  centred time the four-way valve is centred (pilot_spool = 0; solenoid |spool| < its 0.05 threshold)
  travel  the piston's position range in the centred samples [mm]
  band    time the position stays within 0.037 mm (one sensor count) of its turning point

Usage: python3 xtask/stall_measures.py target/release/hydrocyl [workdir]   (stdlib only)
"""
import csv, math, os, subprocess, sys

A1, A2, K, V, T, DT = 0.0008042, 0.00055, 1.07e-5, 0.05, 5.0, 1e-4
THR, COUNT = 1e-3, 0.037e-3


def commands(d):
    n = int(round(3 * T / DT))
    ue, ur = V * A1 / K, -V * A2 / K
    amp, bias = V * (A1 + A2) / (2 * K), V * (A1 - A2) / (2 * K)
    for name, f in (("square", lambda t: ue if (t / T) % 1.0 < 0.5 else ur),
                    ("sine", lambda t: bias + amp * math.sin(2 * math.pi * t / T))):
        with open(os.path.join(d, name + ".csv"), "w") as o:
            o.write("time,command\n")
            for k in range(n + 1):
                o.write(f"{k * DT:.4f},{f(k * DT)}\n")


def load(fn):
    with open(fn) as f:
        r = csv.reader(f)
        h = [c.split(" [")[0] for c in next(r)]
        cols = {k: [] for k in h}
        for row in r:
            for k, c in zip(h, row):
                cols[k].append(float(c))
    return cols


def inside(a, b):
    if a == b:
        return 1.0 if abs(a) < THR else 0.0
    s1, s2 = (-THR - a) / (b - a), (THR - a) / (b - a)
    return max(min(max(s1, s2), 1.0) - max(min(s1, s2), 0.0), 0.0)


def lowpass(x, fc):
    w = math.tan(math.pi * fc * DT)
    q = math.sqrt(2)
    d = 1 + q * w + w * w
    b0, a1, a2 = w * w / d, 2 * (w * w - 1) / d, (1 - q * w + w * w) / d

    def one(x):
        y, x1, x2, y1, y2 = [], x[0], x[0], x[0], x[0]
        for xi in x:
            yi = b0 * (xi + 2 * x1 + x2) - a1 * y1 - a2 * y2
            x2, x1, y2, y1 = x1, xi, y1, yi
            y.append(yi)
        return y
    return one(one(x)[::-1])[::-1]


def measures(c):
    t, v, x, u = c["time"], c["velocity"], c["position"], c["command"]
    n = len(t)
    spool, thr_sp = (c["pilot_spool"], 0.0) if "pilot_spool" in c else (c.get("spool"), 0.05)
    h = 50  # the mean velocity over 10 ms, centred: (x(t + 5 ms) - x(t - 5 ms)) / 10 ms
    ma10 = [(x[min(i + h, n - 1)] - x[max(i - h, 0)]) / ((min(i + h, n - 1) - max(i - h, 0)) * DT) for i in range(n)]
    sig = {"|v|": v, "lp30": lowpass(v, 30), "lp50": lowpass(v, 50), "ma10": ma10}
    out = {}
    for k in range(1, n):
        if t[k] <= T or (u[k - 1] > 0) == (u[k] > 0) or t[k] + 0.5 * T > t[-1] + 1e-9:
            continue
        d = 1.0 if u[k] > 0 else -1.0
        j = k
        while v[j] * d < 0.5 * V:
            j += 1
        m = {name: sum(inside(s[i], s[i + 1]) for i in range(k, j)) * DT for name, s in sig.items()}
        cen = [i for i in range(k, j) if spool is not None and abs(spool[i]) <= thr_sp]
        m["centred"] = len(cen) * DT
        m["travel"] = (max(x[i] for i in cen) - min(x[i] for i in cen)) if cen else 0.0
        ke = min(range(k, j), key=lambda i: d * x[i])
        a = b = ke
        while abs(x[a] - x[ke]) <= COUNT:
            a -= 1
        while abs(x[b] - x[ke]) <= COUNT:
            b += 1
        m["band"] = (b - a) * DT
        out.setdefault("->ext" if d > 0 else "->ret", []).append(m)
    return out


def show(label, out):
    for key in ("->ret", "->ext"):
        ms = out.get(key, [])
        if not ms:
            continue
        avg = {k: sum(m[k] for m in ms) / len(ms) for k in ms[0]}
        print(f"{label:28s} {key}  " + "  ".join(
            f"{k} {avg[k] * 1e3:6.3f}" if k == "travel" else f"{k} {avg[k] * 1e3:6.1f}" for k in avg))


def main():
    exe = sys.argv[1]
    d = sys.argv[2] if len(sys.argv) > 2 else "target/stall-measures"
    os.makedirs(d, exist_ok=True)
    commands(d)
    rigs = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "fixtures", "rigs")
    # the preset, the solenoid variant, and the preset with a tenth of the pilot spring (shift pressure
    # ~1 bar instead of 10.34: the same circuit with almost no charging interval)
    runs = (("wang-hybrid", []), ("wang-hybrid-solenoid", []),
            ("wang-hybrid", ["pilot_valve.spring_rate=1.379e8"]))
    for rig, sets in runs:
        for shape in ("square", "sine"):
            out = os.path.join(d, f"{rig}-{shape}.csv")
            args = [exe, "simulate", "--quiet", "--rig", os.path.join(rigs, rig + ".json"),
                    "--command", os.path.join(d, shape + ".csv"), "--out", out,
                    "--set", "cylinder.initial.position=-0.06"]
            for x in sets:
                args += ["--set", x]
            subprocess.run(args, check=True)
            show(f"{rig}{' ' + ' '.join(sets) if sets else ''} {shape}", measures(load(out)))
    # a smooth turn: constant deceleration a through v = 0 (no dwell, no ringing), 0.2 Hz square timing
    for a in (2.0, 4.0):
        t = [k * DT for k in range(int(3 * T / DT) + 1)]
        v, x, pos = [], [], 0.0
        for ti in t:
            s = 2.5 * math.floor(ti / 2.5)
            dr = 1.0 if (s / T) % 1.0 < 0.5 else -1.0  # the direction the command asks for since s
            vi = dr * V if s == 0.0 else max(-V, min(V, -dr * V + dr * a * (ti - s)))
            pos += vi * DT
            v.append(vi)
            x.append(pos)
        u = [(A1 if ((ti / T) % 1.0) < 0.5 else -A2) for ti in t]
        show(f"smooth turn {a:.0f} m/s^2", measures({"time": t, "velocity": v, "position": x, "command": u}))


if __name__ == "__main__":
    main()
