#!/usr/bin/env python3
"""MLS-MPM / APIC 3D elastic block on Taichi's CPU backend, timed for a throughput
comparison with the Rust `mpm` program (issue 13; docs/performance_explicit.md, "3D").

The 3D version of ../shared/peers/taichi/mls_mpm_bench.py, with the same design:
domain [0,1]^3, n^3 cells (nodes at i*dx, i = 0..n), quadratic B-spline weights,
neo-Hookean solid (tau = mu (F F^T - I) + lambda ln J I, full 3D), gravity -9.81
along y, fixed dt = 1/(64 n).  Block [0.25,0.75] x [y_f, y_f+0.5] x [0.25,0.75],
y_f = 2.5 dx, with 2 x 2 x 2 particles per cell on the same lattice as the mpm scene
of gen_scenes_3d.py (n^3 particles), initial velocity (0.5, -1, 0).  Floor (sticky):
nodes j <= 3 held at zero velocity (--floor-rows 3 holds j <= 2 only; the mpm clamped
spline lies between the two); the other walls (never reached) are slip.

Timing: one warm-up step compiles every kernel; the state is then reset and S
steps are timed, with ti.sync() before the clock stops.  Same flags and JSON fields
as the 2D script.
"""
import argparse
import json
import time

import numpy as np
import taichi as ti

ap = argparse.ArgumentParser()
ap.add_argument("--n", type=int, default=32, help="cells per direction")
ap.add_argument("--steps", type=int, default=100)
ap.add_argument("--fp", choices=["f64", "f32"], default="f64")
ap.add_argument("--threads", type=int, default=2)
ap.add_argument("--json", help="write the result here as JSON")
ap.add_argument("--dump", help="write final particle positions (x, y, z) here (.npy)")
ap.add_argument("--floor-rows", type=int, default=4,
                help="node rows j < this held at zero velocity (4: j <= 3, closest to the mpm clamped spline; 3 brackets it from the other side)")
args = ap.parse_args()

ti.init(arch=ti.cpu, cpu_max_num_threads=args.threads,
        default_fp=ti.f64 if args.fp == "f64" else ti.f32, log_level=ti.WARN)

n = args.n
dx, inv_dx = 1.0 / n, float(n)
dt = 1.0 / (64 * n)
n_side = n                      # n particles across the block: 2 per cell over n/2 cells
N = n_side ** 3
y_floor = 2.5 * dx
p_vol = (0.5 * dx) ** 3
rho = 1000.0
p_mass = rho * p_vol
E, nu = 1.0e5, 0.3
mu = E / (2 * (1 + nu))
lam = E * nu / ((1 + nu) * (1 - 2 * nu))
gravity = -9.81
v0 = (0.5, -1.0, 0.0)
floor_rows = args.floor_rows

x = ti.Vector.field(3, dtype=float, shape=N)
v = ti.Vector.field(3, dtype=float, shape=N)
C = ti.Matrix.field(3, 3, dtype=float, shape=N)
F = ti.Matrix.field(3, 3, dtype=float, shape=N)
grid_v = ti.Vector.field(3, dtype=float, shape=(n + 1, n + 1, n + 1))
grid_m = ti.field(dtype=float, shape=(n + 1, n + 1, n + 1))


@ti.kernel
def init():
    for p in range(N):
        # p = (k * n + j) * n + i: x fastest, then y, then z (mpm's particle order)
        i, j, k = p % n_side, (p // n_side) % n_side, p // (n_side * n_side)
        # the mpm lattice: (n/4 + 1/4 + i/2) dx, y_f + (1/4 + j/2) dx, (n/4 + 1/4 + k/2) dx
        x[p] = ti.Vector([(n / 4 + 0.25 + 0.5 * i) * dx,
                          y_floor + (0.25 + 0.5 * j) * dx,
                          (n / 4 + 0.25 + 0.5 * k) * dx])
        v[p] = ti.Vector([v0[0], v0[1], v0[2]])
        C[p] = ti.Matrix.zero(float, 3, 3)
        F[p] = ti.Matrix.identity(float, 3)


@ti.kernel
def substep():
    for I in ti.grouped(grid_m):
        grid_v[I] = ti.Vector.zero(float, 3)
        grid_m[I] = 0.0
    # P2G: mass, APIC momentum and the MLS stress term in one scatter
    for p in x:
        Xp = x[p] * inv_dx
        base = int(Xp - 0.5)
        fx = Xp - base
        w = [0.5 * (1.5 - fx) ** 2, 0.75 - (fx - 1.0) ** 2, 0.5 * (fx - 0.5) ** 2]
        J = F[p].determinant()
        Id = ti.Matrix.identity(float, 3)
        tau = mu * (F[p] @ F[p].transpose() - Id) + lam * ti.log(J) * Id  # Kirchhoff
        stress = (-dt * p_vol * 4.0 * inv_dx * inv_dx) * tau
        affine = stress + p_mass * C[p]
        for i, j, k in ti.static(ti.ndrange(3, 3, 3)):
            offset = ti.Vector([i, j, k])
            dpos = (offset - fx) * dx
            weight = w[i][0] * w[j][1] * w[k][2]
            grid_v[base + offset] += weight * (p_mass * v[p] + affine @ dpos)
            grid_m[base + offset] += weight * p_mass
    # grid update: velocity, gravity, walls
    for i, j, k in grid_m:
        if grid_m[i, j, k] > 0:
            vg = grid_v[i, j, k] / grid_m[i, j, k]
            vg[1] += dt * gravity
            if j < floor_rows:
                vg = ti.Vector.zero(float, 3)       # fixed floor
            if i < 3 and vg[0] < 0:
                vg[0] = 0.0
            if i > n - 3 and vg[0] > 0:
                vg[0] = 0.0
            if j > n - 3 and vg[1] > 0:
                vg[1] = 0.0
            if k < 3 and vg[2] < 0:
                vg[2] = 0.0
            if k > n - 3 and vg[2] > 0:
                vg[2] = 0.0
            grid_v[i, j, k] = vg
    # G2P: APIC velocity and affine matrix, F update, advection
    for p in x:
        Xp = x[p] * inv_dx
        base = int(Xp - 0.5)
        fx = Xp - base
        w = [0.5 * (1.5 - fx) ** 2, 0.75 - (fx - 1.0) ** 2, 0.5 * (fx - 0.5) ** 2]
        new_v = ti.Vector.zero(float, 3)
        new_C = ti.Matrix.zero(float, 3, 3)
        for i, j, k in ti.static(ti.ndrange(3, 3, 3)):
            offset = ti.Vector([i, j, k])
            dpos = offset - fx
            g_v = grid_v[base + offset]
            weight = w[i][0] * w[j][1] * w[k][2]
            new_v += weight * g_v
            new_C += 4.0 * inv_dx * weight * g_v.outer_product(dpos)
        v[p] = new_v
        C[p] = new_C
        x[p] += dt * new_v
        F[p] = (ti.Matrix.identity(float, 3) + dt * new_C) @ F[p]


def com():
    xs = x.to_numpy()
    return xs.mean(axis=0).tolist(), xs


init()
substep()            # warm-up: JIT-compiles init and substep
ti.sync()
init()               # reset: the timed run starts from the initial state
ti.sync()
com0, _ = com()
t0, c0 = time.perf_counter(), time.process_time()
for _ in range(args.steps):
    substep()
ti.sync()
seconds = time.perf_counter() - t0
cpu_seconds = time.process_time() - c0   # CPU time of all threads of the process
com1, xs = com()
Fs = F.to_numpy()
J = np.linalg.det(Fs)
result = {
    "program": "taichi",
    "taichi": ti.__version__ if isinstance(ti.__version__, str) else ".".join(map(str, ti.__version__)),
    "fp": args.fp,
    "threads": args.threads,
    "floor_rows": floor_rows,
    "n": n,
    "particles": N,
    "steps": args.steps,
    "dt": dt,
    "seconds": seconds,
    "particle_steps_per_second": N * args.steps / seconds,
    "cpu_seconds": cpu_seconds,
    "com0": com0,
    "com1": com1,
    "finite": bool(np.isfinite(xs).all()),
    "J_min": float(J.min()),
    "J_max": float(J.max()),
}
print(json.dumps(result))
if args.json:
    with open(args.json, "w") as fh:
        json.dump(result, fh, indent=1)
if args.dump:
    np.save(args.dump, xs)
