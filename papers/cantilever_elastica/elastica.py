#!/usr/bin/env python3
"""Large-deflection cantilever: elastica reference and mpm runs.

Standard library only. Usage:

    python3 elastica.py table              # elastica v/L, u/L along the load path
    python3 elastica.py check              # against Mattiasson (1981), k = 1, 2, 5, 10
    python3 elastica.py runs [SHAPE ...]   # mpm along the load path (4 cells/depth, 3 ppc)
    python3 elastica.py refine [SHAPE ...] # mpm at full load, several resolutions
    python3 elastica.py small [SHAPE ...]  # mpm at P = 100 N against the linear beam
    python3 elastica.py slender [SHAPE ...] # L/d = 20 (d = 0.5 m) at the same k = 9.6
    python3 elastica.py support [SHAPE ...] # full load against solver.min_node_support
    python3 elastica.py fe                 # finite-element reference: mesh convergence
    python3 elastica.py fe-mpm [SHAPE ...] # mpm against the finite-element reference

The mpm binary is taken from $MPM, else ../../target/release/mpm relative to
this folder, else $CARGO_TARGET_DIR/release/mpm. Runs go to $OUT (default a
temporary directory). The finite-element reference (examples/cantilever_fe,
`cargo build --release --example cantilever_fe`) is taken from $FE, else
target/release/examples/cantilever_fe under $CARGO_TARGET_DIR or ../../target.

Reference: a vertical dead load P at the tip of a cantilever of length L,
    EI theta''(s) = -P cos(theta),  theta(0) = 0,  theta'(L) = 0,
    v = int_0^L sin(theta) ds,  u = L - int_0^L cos(theta) ds.
In s/L the equation is theta'' = -k cos(theta) with k = P L^2 / EI. We shoot on
theta'(0) with classical RK4 and bisect: theta'(1) is negative for theta'(0) = 0
and positive for theta'(0) = k, so [0, k] brackets the root.

With extension and shear (Reissner's beam; used only to size those effects)
the section force (0, -P) gives N = P sin(theta), Q = P cos(theta), strains
eps = N/EA and gamma = Q/(kappa G A), so with a_e = P/EA and a_s = P/(kappa G A):
    x' = cos + (a_e - a_s) sin cos,  v' = sin + a_e sin^2 + a_s cos^2,
    EI theta'' = -P x'.
"""
import json
import math
import os
import subprocess
import sys
import tempfile
import time

# Published elastica values (Mattiasson 1981), k: (v/L, u/L).
MATTIASSON = {1: (0.30172, 0.05643), 2: (0.49346, 0.16064),
              5: (0.71379, 0.38763), 10: (0.81061, 0.55500)}

# The problem (reference README item 3), SI units, unit thickness.
L, DEPTH, E, NU, P_END = 10.0, 1.0, 12.0e6, 0.2, 100.0e3
I = DEPTH ** 3 / 12.0
EI_PLANE_STRAIN = E / (1.0 - NU * NU) * I   # the choice used for comparisons
EI_PLANE_STRESS = E * I
G = E / (2.0 * (1.0 + NU))
KAPPA = 5.0 / 6.0


def shoot(k, kappa0, a_e=0.0, a_s=0.0, n=2000):
    """Integrate from s = 0 to 1; returns (theta(1), theta'(1), v/L, x/L)."""
    h = 1.0 / n
    c = a_e - a_s

    def f(y):
        t, w = y[0], y[1]
        ct, st = math.cos(t), math.sin(t)
        xp = ct + c * st * ct
        return (w, -k * xp, st + a_e * st * st + a_s * ct * ct, xp)

    y = (0.0, kappa0, 0.0, 0.0)
    for _ in range(n):
        k1 = f(y)
        k2 = f(tuple(a + 0.5 * h * b for a, b in zip(y, k1)))
        k3 = f(tuple(a + 0.5 * h * b for a, b in zip(y, k2)))
        k4 = f(tuple(a + h * b for a, b in zip(y, k3)))
        y = tuple(a + h / 6.0 * (b1 + 2 * b2 + 2 * b3 + b4)
                  for a, b1, b2, b3, b4 in zip(y, k1, k2, k3, k4))
    return y


def elastica(k, a_e=0.0, a_s=0.0, n=2000):
    """(v/L, u/L, tip rotation) for load parameter k = P L^2 / EI."""
    if k == 0.0:
        return 0.0, 0.0, 0.0
    lo, hi = 0.0, k * (1.0 + abs(a_e - a_s))
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if shoot(k, mid, a_e, a_s, n)[1] > 0.0:
            hi = mid
        else:
            lo = mid
    t, _, v, x = shoot(k, 0.5 * (lo + hi), a_e, a_s, n)
    return v, 1.0 - x, t


def tip_reference(p, h, ppc, ei=EI_PLANE_STRAIN):
    """Elastica displacement (v, u) in metres of the loaded particle column.

    The load is carried by the last column of particles, centred at
    a = L - h / (2 ppc); the beam beyond it is unloaded, so the loaded point
    moves as the tip of a cantilever of length a."""
    a = L - 0.5 * h / ppc
    v, u, _ = elastica(p * a * a / ei)
    return v * a, u * a


def find_mpm():
    here = os.path.dirname(os.path.abspath(__file__))
    candidates = [os.environ.get("MPM", "")]
    if os.environ.get("CARGO_TARGET_DIR"):
        candidates.append(os.path.join(os.environ["CARGO_TARGET_DIR"], "release", "mpm"))
    candidates.append(os.path.join(here, "..", "..", "target", "release", "mpm"))
    for c in candidates:
        if c and os.path.exists(c):
            return c
    sys.exit("mpm binary not found: set MPM or CARGO_TARGET_DIR (cargo build --release)")


def read_csv(path):
    with open(path) as f:
        header = f.readline().strip().split(",")
        rows = [dict(zip(header, map(float, line.split(",")))) for line in f if line.strip()]
    return rows


def run_mpm(shape, cells_per_depth, ppc, p, steps, out, depth=DEPTH, extra=()):
    """Run problems/cantilever.toml; returns (status, wall seconds, v, u, message)."""
    h = depth / cells_per_depth
    nx, ny = round(11.0 / h), round(12.0 / h)
    here = os.path.dirname(os.path.abspath(__file__))
    scene = os.path.join(here, "..", "..", "problems", "cantilever.toml")
    x_min = L - h / ppc
    args = [find_mpm(), "run", scene, "--out", out,
            "--set", f"grid.shape_function={shape}",
            "--set", f"grid.cells=[{nx},{ny}]",
            "--set", f"body.0.particles_per_cell={ppc}",
            "--set", f"load.0.region_min=[{x_min!r},0.0]",
            "--set", f"load.0.force=[0.0,{-p!r}]",
            "--set", f"body.0.max=[{L!r},{depth!r}]",
            "--set", f"load.0.region_max=[{L!r},{depth!r}]",
            "--set", f"solver.load_steps={steps}"] + [x for kv in extra for x in ("--set", kv)]
    proc = subprocess.run(args, capture_output=True, text=True)
    with open(os.path.join(out, "summary.json")) as f:
        summary = json.load(f)
    if summary["status"] != "completed":
        return summary["status"], summary["wall_seconds"], None, None, summary.get("message", "")
    rows = read_csv(os.path.join(out, "particles_final.csv"))
    tip = [r for r in rows if r["X0"] >= x_min]
    v = -sum(r["y"] - r["Y0"] for r in tip) / len(tip)
    u = -sum(r["x"] - r["X0"] for r in tip) / len(tip)
    return "completed", summary["wall_seconds"], v, u, proc.stderr.strip()


def cmd_table():
    print("| P (kN) | k = PL²/EI, E/(1-ν²) | v/L | u/L | tip angle (rad) | "
          "k with E | v/L with E | u/L with E | v/L, u/L with extension and shear |")
    print("|---|---|---|---|---|---|---|---|---|")
    for i in range(1, 11):
        p = P_END * i / 10
        k = p * L * L / EI_PLANE_STRAIN
        k_e = p * L * L / EI_PLANE_STRESS
        v, u, t = elastica(k)
        ve, ue, _ = elastica(k_e)
        vr, ur, _ = elastica(k, p / (E / (1 - NU * NU) * DEPTH), p / (KAPPA * G * DEPTH))
        print(f"| {p / 1e3:.0f} | {k:.2f} | {v:.5f} | {u:.5f} | {t:.4f} | {k_e:.1f} | "
              f"{ve:.5f} | {ue:.5f} | {vr:.5f}, {ur:.5f} |")
    k = P_END * L * L / EI_PLANE_STRAIN
    a_e = P_END / (E / (1 - NU * NU) * DEPTH)
    a_s = P_END / (KAPPA * G * DEPTH)
    v0, u0, _ = elastica(k)
    v1, u1, _ = elastica(k, a_e, 0.0)
    v2, u2, _ = elastica(k, 0.0, a_s)
    v3, u3, _ = elastica(k, a_e, a_s)
    v10, u10, _ = elastica(P_END * L * L / EI_PLANE_STRESS)
    print()
    print(f"final load: k = 10 (E) v/L = {v10:.5f}, u/L = {u10:.5f}; "
          f"k = 9.6 (E/(1-nu^2)) v/L = {v0:.5f}, u/L = {u0:.5f}")
    print(f"  stiffness choice changes v by {100 * (v10 / v0 - 1):+.2f} %, u by {100 * (u10 / u0 - 1):+.2f} %")
    print(f"  extension (P/EA = {a_e:.4f}): v {100 * (v1 / v0 - 1):+.2f} %, u {100 * (u1 / u0 - 1):+.2f} %")
    print(f"  shear (P/(kappa G A) = {a_s:.4f}): v {100 * (v2 / v0 - 1):+.2f} %, u {100 * (u2 / u0 - 1):+.2f} %")
    print(f"  both: v/L = {v3:.5f} ({100 * (v3 / v0 - 1):+.2f} %), u/L = {u3:.5f} ({100 * (u3 / u0 - 1):+.2f} %)")
    lin = 3.0 * EI_PLANE_STRAIN / (KAPPA * G * DEPTH * L * L)
    print(f"  small-deflection Timoshenko estimate: shear/bending deflection = {100 * lin:.2f} %")


def cmd_check():
    worst = 0.0
    for k, (v_pub, u_pub) in MATTIASSON.items():
        v, u, t = elastica(float(k))
        worst = max(worst, abs(v - v_pub), abs(u - u_pub))
        print(f"k = {k:>2}: v/L {v:.5f} (Mattiasson {v_pub:.5f}), u/L {u:.5f} (Mattiasson {u_pub:.5f})")
    print(f"largest difference {worst:.1e}")


def reissner_reference(p, h, ppc, ei=EI_PLANE_STRAIN, depth=DEPTH):
    """As tip_reference, with extension and shear (plane-strain EA, kappa G A)."""
    a = L - 0.5 * h / ppc
    a_e = p / (E / (1.0 - NU * NU) * depth)
    a_s = p / (KAPPA * G * depth)
    v, u, _ = elastica(p * a * a / ei, a_e, a_s)
    return v * a, u * a


HEADER = ("| shape | cells/depth | ppc | P (kN) | k = PL²/EI | elastica v/a | ours v/a | error v | "
          "elastica u/a | ours u/a | error u | error v, u vs Reissner | wall (s) |\n"
          "|---|---|---|---|---|---|---|---|---|---|---|---|---|")


def row(shape, cells, ppc, p, out_root, depth=DEPTH, extra=(), label=None):
    steps = max(1, round(50 * p / (P_END * (depth / DEPTH) ** 3)))
    tag = "_".join(e.replace("=", "") for e in extra)
    out = os.path.join(out_root, f"{shape}_{cells}_{ppc}_{p / 1e3:.1f}_{depth}_{tag}")
    os.makedirs(out, exist_ok=True)
    status, wall, v, u, msg = run_mpm(shape, cells, ppc, p, steps, out, depth, extra)
    h = depth / cells
    a = L - 0.5 * h / ppc
    ei = EI_PLANE_STRAIN * (depth / DEPTH) ** 3
    k = p * L * L / ei
    v_ref, u_ref = tip_reference(p, h, ppc, ei)
    v_r, u_r = reissner_reference(p, h, ppc, ei, depth)
    first = label if label is not None else f"{p / 1e3:.1f}"
    head = f"| {shape} | {cells} | {ppc} | {first} | {k:.2f} | {v_ref / a:.5f} |"
    if status != "completed":
        line = msg.splitlines()[-1] if msg else ""
        print(f"{head} {status} | | {u_ref / a:.5f} | | | | {wall:.2f} |")
        print(f"<!-- {line} -->")
    else:
        print(f"{head} {v / a:.5f} | {100 * (v / v_ref - 1):+.2f} % | "
              f"{u_ref / a:.5f} | {u / a:.5f} | {100 * (u / u_ref - 1):+.2f} % | "
              f"{100 * (v / v_r - 1):+.2f} %, {100 * (u / u_r - 1):+.2f} % | {wall:.2f} |")
    sys.stdout.flush()


def cmd_runs(shapes):
    """Load path at 4 cells through the depth, 3x3 particles per cell."""
    shapes = shapes or ["bspline2", "ugimp", "cpdi"]
    out_root = os.environ.get("OUT") or tempfile.mkdtemp(prefix="cantilever_")
    print(HEADER)
    for shape in shapes:
        for p in [10e3, 20e3, 40e3, 60e3, 80e3, 100e3]:
            row(shape, 4, 3, p, out_root)


def cmd_refine(shapes):
    """Full load at several resolutions."""
    shapes = shapes or ["bspline2", "ugimp", "cpdi"]
    out_root = os.environ.get("OUT") or tempfile.mkdtemp(prefix="cantilever_")
    print(HEADER)
    for shape in shapes:
        for cells, ppc in [(4, 2), (4, 3), (4, 4), (8, 2), (8, 3)]:
            row(shape, cells, ppc, P_END, out_root)


def cmd_slender(shapes):
    """L/d = 20: d = 0.5 m, P = 12.5 kN (the same k = 9.6), 4 cells through the depth."""
    shapes = shapes or ["bspline2", "ugimp", "cpdi"]
    out_root = os.environ.get("OUT") or tempfile.mkdtemp(prefix="cantilever_")
    print(HEADER)
    for shape in shapes:
        for ppc in [2, 3]:
            row(shape, 4, ppc, P_END / 8.0, out_root, depth=0.5)


def cmd_support(shapes):
    """Full load, 4 cells/depth, 3 ppc, against solver.min_node_support (column P)."""
    shapes = shapes or ["bspline2", "ugimp", "cpdi"]
    out_root = os.environ.get("OUT") or tempfile.mkdtemp(prefix="cantilever_")
    print(HEADER.replace("| P (kN) |", "| min_node_support |"))
    for shape in shapes:
        for tol in ["1e-3", "3e-3", "1e-2", "3e-2", "1e-1"]:
            row(shape, 4, 3, P_END, out_root, extra=(f"solver.min_node_support={tol}",),
                label=tol)


def cmd_small(shapes):
    """P = 100 N in one step: linear Timoshenko beam (plane strain) and EB with E."""
    shapes = shapes or ["bspline2", "ugimp", "cpdi"]
    out_root = os.environ.get("OUT") or tempfile.mkdtemp(prefix="cantilever_")
    p = 100.0
    print("| shape | cells/depth | ppc | ours v (mm) | Timoshenko, E/(1-nu^2) | error | "
          "Euler-Bernoulli, E | error | wall (s) |")
    print("|---|---|---|---|---|---|---|---|---|")
    for shape in shapes:
        for cells, ppc in [(4, 2), (4, 3), (4, 4), (8, 2), (8, 3)]:
            out = os.path.join(out_root, f"small_{shape}_{cells}_{ppc}")
            os.makedirs(out, exist_ok=True)
            status, wall, v, _, msg = run_mpm(shape, cells, ppc, p, 1, out)
            a = L - 0.5 * DEPTH / cells / ppc
            timo = p * a ** 3 / (3 * EI_PLANE_STRAIN) + p * a / (KAPPA * G * DEPTH)
            eb_e = p * a ** 3 / (3 * EI_PLANE_STRESS)
            if v is None:
                print(f"| {shape} | {cells} | {ppc} | {status} | {1e3 * timo:.4f} | | "
                      f"{1e3 * eb_e:.4f} | | {wall:.2f} |")
                print(f"<!-- {msg.splitlines()[-1] if msg else ''} -->")
                continue
            print(f"| {shape} | {cells} | {ppc} | {1e3 * v:.4f} | {1e3 * timo:.4f} | "
                  f"{100 * (v / timo - 1):+.2f} % | {1e3 * eb_e:.4f} | {100 * (v / eb_e - 1):+.2f} % | "
                  f"{wall:.2f} |")
            sys.stdout.flush()


def find_fe():
    here = os.path.dirname(os.path.abspath(__file__))
    candidates = [os.environ.get("FE", "")]
    if os.environ.get("CARGO_TARGET_DIR"):
        candidates.append(os.path.join(os.environ["CARGO_TARGET_DIR"], "release", "examples",
                                       "cantilever_fe"))
    candidates.append(os.path.join(here, "..", "..", "target", "release", "examples",
                                   "cantilever_fe"))
    for c in candidates:
        if c and os.path.exists(c):
            return c
    sys.exit("cantilever_fe not found: set FE or CARGO_TARGET_DIR "
             "(cargo build --release --example cantilever_fe)")


def run_fe(nx, ny, strip=None, depth=DEPTH, force=P_END, steps=50):
    """The FE reference on nx x ny Q9 elements; returns ({P: (v, u)}, wall seconds).
    strip=None: traction on the end section, else a body force on X >= L - strip."""
    args = [find_fe(), str(nx), str(ny), "--csv", "--depth", repr(depth),
            "--force", repr(force), "--steps", str(steps)]
    if strip is not None:
        args += ["--strip", repr(strip)]
    start = time.time()
    proc = subprocess.run(args, capture_output=True, text=True)
    if proc.returncode != 0:
        sys.exit(f"cantilever_fe {' '.join(args[1:])}: {proc.stderr.strip()}")
    lines = proc.stdout.split()
    header = lines[0].split(",")
    levels = {}
    for line in lines[1:]:
        r = dict(zip(header, map(float, line.split(","))))
        levels[round(r["force"], 6)] = (r["v"], r["u"])
    return levels, time.time() - start


def fe_errors(v, u, a, p, depth=DEPTH):
    """(v, u) against the classical elastica with E/(1-nu^2), with E (Mattiasson's
    k = PL^2/EI at E I), and Reissner's beam, all for the arm a: percentages."""
    ei = EI_PLANE_STRAIN * (depth / DEPTH) ** 3
    out = []
    for k, a_e, a_s in [(p * a * a / ei, 0.0, 0.0),
                        (p * a * a / (EI_PLANE_STRESS * (depth / DEPTH) ** 3), 0.0, 0.0),
                        (p * a * a / ei, p / (E / (1.0 - NU * NU) * depth), p / (KAPPA * G * depth))]:
        vr, ur, _ = elastica(k, a_e, a_s)
        out += [100 * (v / (vr * a) - 1), 100 * (u / (ur * a) - 1)]
    return out


def cmd_fe():
    """FE mesh convergence at full load: traction on the end section, and the body
    force on the strip of the MPM's loaded particle column (4 cells/depth, 3 ppc)."""
    meshes = [(10, 1), (20, 2), (40, 4), (80, 8), (160, 16)]
    print("| load | elements | v (m) | u (m) | v/a | u/a | v, u vs finest | "
          "vs elastica E/(1-ν²) (v, u) | vs elastica E (v, u) | vs Reissner (v, u) | wall (s) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for label, strip in [("end section", None), ("strip h/3, h = d/4", DEPTH / 12.0)]:
        a = L if strip is None else L - 0.5 * strip
        rows = []
        for nx, ny in meshes:
            levels, wall = run_fe(nx, ny, strip)
            rows.append((nx, ny, *levels[round(P_END, 6)], wall))
        v_f, u_f = rows[-1][2], rows[-1][3]
        for nx, ny, v, u, wall in rows:
            e = fe_errors(v, u, a, P_END)
            print(f"| {label} | {nx} x {ny} | {v:.6f} | {u:.6f} | {v / a:.6f} | {u / a:.6f} | "
                  f"{100 * (v / v_f - 1):+.4f} %, {100 * (u / u_f - 1):+.4f} % | "
                  f"{e[0]:+.3f} %, {e[1]:+.3f} % | {e[2]:+.3f} %, {e[3]:+.3f} % | "
                  f"{e[4]:+.3f} %, {e[5]:+.3f} % | {wall:.2f} |")
            sys.stdout.flush()


FE_MESH = (80, 8)   # 0.01 % from 160 x 16 (python3 elastica.py fe)


def cmd_fe_mpm(shapes):
    """mpm against the FE reference of the same continuum and load (the strip of
    the loaded particle column, width h/ppc): load path at 4 x 3, full load at
    several resolutions, and the slender beam."""
    shapes = shapes or ["bspline2", "ugimp", "cpdi"]
    out_root = os.environ.get("OUT") or tempfile.mkdtemp(prefix="cantilever_fe_")
    print("| shape | L/d | cells/depth | ppc | P (kN) | FE v/a | mpm v/a | mpm vs FE, v | "
          "FE u/a | mpm u/a | mpm vs FE, u | FE vs elastica (v, u) | mpm wall (s) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    cases = [(4, 3, p, DEPTH) for p in [10e3, 20e3, 40e3, 60e3, 80e3]]
    cases += [(c, ppc, P_END, DEPTH) for c, ppc in [(4, 2), (4, 3), (4, 4), (8, 2), (8, 3)]]
    cases += [(4, ppc, P_END / 8.0, 0.5) for ppc in [2, 3]]
    fe_cache = {}
    for shape in shapes:
        for cells, ppc, p, depth in cases:
            h = depth / cells
            strip = h / ppc
            a = L - 0.5 * strip
            force = P_END * (depth / DEPTH) ** 3
            nx, ny = FE_MESH if depth == DEPTH else (2 * FE_MESH[0], FE_MESH[1])
            key = (strip, depth)
            if key not in fe_cache:
                fe_cache[key] = run_fe(nx, ny, strip, depth, force)[0]
            v_fe, u_fe = fe_cache[key][round(p, 6)]
            steps = max(1, round(50 * p / force))
            out = os.path.join(out_root, f"{shape}_{cells}_{ppc}_{p / 1e3:.1f}_{depth}")
            os.makedirs(out, exist_ok=True)
            status, wall, v, u, msg = run_mpm(shape, cells, ppc, p, steps, out, depth)
            e = fe_errors(v_fe, u_fe, a, p, depth)
            head = (f"| {shape} | {L / depth:.0f} | {cells} | {ppc} | {p / 1e3:.1f} | "
                    f"{v_fe / a:.5f} |")
            tail = f"{e[0]:+.2f} %, {e[1]:+.2f} % | {wall:.2f} |"
            if status != "completed":
                print(f"{head} {status} | | {u_fe / a:.5f} | | | {tail}")
                print(f"<!-- {msg.splitlines()[-1] if msg else ''} -->")
            else:
                print(f"{head} {v / a:.5f} | {100 * (v / v_fe - 1):+.2f} % | {u_fe / a:.5f} | "
                      f"{u / a:.5f} | {100 * (u / u_fe - 1):+.2f} % | {tail}")
            sys.stdout.flush()


if __name__ == "__main__":
    cmd = sys.argv[1] if len(sys.argv) > 1 else "table"
    if cmd == "table":
        cmd_table()
    elif cmd == "check":
        cmd_check()
    elif cmd == "runs":
        cmd_runs(sys.argv[2:])
    elif cmd == "small":
        cmd_small(sys.argv[2:])
    elif cmd == "refine":
        cmd_refine(sys.argv[2:])
    elif cmd == "slender":
        cmd_slender(sys.argv[2:])
    elif cmd == "support":
        cmd_support(sys.argv[2:])
    elif cmd == "fe":
        cmd_fe()
    elif cmd == "fe-mpm":
        cmd_fe_mpm(sys.argv[2:])
    else:
        sys.exit(__doc__)
