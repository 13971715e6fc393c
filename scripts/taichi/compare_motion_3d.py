#!/usr/bin/env python3
"""Compare the final particle positions of a 3D mpm run (particles_final.csv) with a
Taichi run (positions .npy from mls_mpm_bench_3d.py --dump) on the same lattice.

The 3D version of ../shared/peers/taichi/compare_motion.py.  It first checks the
lattice: every mpm reference position (X0, Y0, Z0) must be a point of the Taichi
lattice (n/4 + 1/4 + i/2) dx, y_f + (1/4 + j/2) dx, (n/4 + 1/4 + k/2) dx, each point
exactly once, n^3 in all.  Then it prints the centre-of-mass displacement of both,
their relative difference, and the RMS distance between corresponding particles
relative to the RMS displacement.

usage: compare_motion_3d.py particles_final.csv taichi.npy N [taichi_initial.npy]
(the optional fourth argument, a dump of mls_mpm_bench_3d.py --steps 0, is compared
position by position with mpm's reference positions)."""
import sys

import numpy as np

csv, npy, n = sys.argv[1], sys.argv[2], int(sys.argv[3])
dx = 1.0 / n
yf = 2.5 * dx
d = np.genfromtxt(csv, delimiter=",", names=True)
X0 = np.c_[d["X0"], d["Y0"], d["Z0"]]
xr = np.c_[d["x"], d["y"], d["z"]]
# lattice indices of the mpm particles -> Taichi index p = (k * n + j) * n + i
fi = (X0[:, 0] / dx - n / 4 - 0.25) / 0.5
fj = ((X0[:, 1] - yf) / dx - 0.25) / 0.5
fk = (X0[:, 2] / dx - n / 4 - 0.25) / 0.5
i, j, k = (np.rint(f).astype(int) for f in (fi, fj, fk))
off = max(np.abs(fi - i).max(), np.abs(fj - j).max(), np.abs(fk - k).max())
p = (k * n + j) * n + i
ok = (len(X0) == n ** 3 and off < 1e-6 and i.min() >= 0 and j.min() >= 0 and k.min() >= 0
      and max(i.max(), j.max(), k.max()) < n and len(np.unique(p)) == n ** 3)
print(f"lattice: mpm {len(X0)} particles, Taichi {n ** 3}; largest offset from the Taichi lattice "
      f"{off:.1e} half-cells; each lattice point once: {'yes' if ok else 'NO'}")
assert ok, "the mpm particles are not the Taichi lattice"
if len(sys.argv) > 4:
    x0t = np.load(sys.argv[4])[p]
    print(f"initial positions: largest |X0 (mpm) - x0 (Taichi)| = {np.abs(x0t - X0).max():.1e}; "
          f"e.g. particle 0 mpm {X0[0].tolist()} Taichi {x0t[0].tolist()}, last mpm {X0[-1].tolist()} Taichi {x0t[-1].tolist()}")
xt_all = np.load(npy)
assert len(xt_all) == len(xr) == n ** 3
xt = xt_all[p]
ut, ur = xt - X0, xr - X0
ct, cr = ut.mean(0), ur.mean(0)
rms_u = np.sqrt((ut ** 2).sum(1).mean())
rms_d = np.sqrt(((xt - xr) ** 2).sum(1).mean())
print(f"COM displacement  taichi ({ct[0]:+.6f}, {ct[1]:+.6f}, {ct[2]:+.6f})  mpm ({cr[0]:+.6f}, {cr[1]:+.6f}, {cr[2]:+.6f})")
print(f"relative difference of the COM drop {abs(cr[1] / ct[1] - 1) * 100:.2f} %, "
      f"of the COM x shift {abs(cr[0] / ct[0] - 1) * 100:.2f} %")
print(f"RMS particle distance / RMS displacement {rms_d / rms_u * 100:.2f} %  "
      f"(RMS displacement {rms_u:.5f}, in cells {rms_u / dx:.2f})")
