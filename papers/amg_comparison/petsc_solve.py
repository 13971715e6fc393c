#!/usr/bin/env python3
"""Solve the linear systems that `mpm` exported (`[output] linear_systems`) with
PETSc's conjugate gradients preconditioned by GAMG (smoothed aggregation, with
the rigid-body modes as near-null space) and by hypre BoomerAMG, and print one
JSON line per system and preconditioner: unknowns, iterations, converged reason,
set-up and solve seconds.

    petsc_solve.py DIR [--rtol 1e-8]

DIR holds stepSSSSSS_cutC_iterII.mtx, …_rhs.mtx and stepSSSSSS_cutC_unknowns.csv
(docs/scene.md, "Outputs"). Needs petsc4py and scipy (papers/amg_comparison/run.sh
installs them from Debian).
"""
import argparse
import csv
import json
import sys
import time
from pathlib import Path

import numpy as np
import scipy.io
import scipy.sparse as sp
from petsc4py import PETSc


def rigid_body_modes(unknowns):
    """Translations and rotations of the unknowns' nodes: D + D(D-1)/2 vectors."""
    comp = np.array([int(r["component"]) for r in unknowns])
    dim = 3 if "z" in unknowns[0] else 2
    x = np.array([[float(r[a]) for a in "xyz"[:dim]] for r in unknowns])
    x -= x.mean(axis=0)
    modes = []
    for d in range(dim):
        modes.append((comp == d).astype(float))
    # Rotation in the plane (a, b): u_a = -x_b, u_b = x_a.
    for a, b in [(0, 1)] if dim == 2 else [(0, 1), (1, 2), (0, 2)]:
        m = np.zeros(len(comp))
        m[comp == a] = -x[comp == a, b]
        m[comp == b] = x[comp == b, a]
        modes.append(m)
    q, _ = np.linalg.qr(np.array(modes).T)  # PETSc wants orthonormal vectors
    return q.T


def petsc_matrix(a):
    a = sp.csr_matrix(a)
    m = PETSc.Mat().createAIJ(size=a.shape, csr=(a.indptr, a.indices, a.data))
    m.assemble()
    return m


def solve(a, b, modes, pc_type, rtol):
    opts = PETSc.Options()
    opts.clear()
    ksp = PETSc.KSP().create()
    ksp.setType("cg")
    ksp.setTolerances(rtol=rtol, atol=0.0, max_it=5000)
    ksp.setNormType(PETSc.KSP.NormType.UNPRECONDITIONED)
    pc = ksp.getPC()
    if pc_type == "gamg":
        pc.setType("gamg")
        vecs = []
        for v in modes:
            pv = a.createVecLeft()
            pv.setArray(v)
            vecs.append(pv)
        a.setNearNullSpace(PETSc.NullSpace().create(vectors=vecs))
    else:
        pc.setType("hypre")
        pc.setHYPREType("boomeramg")
    ksp.setOperators(a)
    ksp.setFromOptions()
    x, rhs = a.createVecRight(), a.createVecLeft()
    rhs.setArray(b)
    t0 = time.perf_counter()
    ksp.setUp()
    t1 = time.perf_counter()
    ksp.solve(rhs, x)
    t2 = time.perf_counter()
    return ksp.getIterationNumber(), int(ksp.getConvergedReason()), t1 - t0, t2 - t1


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("dir")
    ap.add_argument("--rtol", type=float, default=1e-8)
    args = ap.parse_args()
    d = Path(args.dir)
    for path in sorted(d.glob("step*_iter*.mtx")):
        if path.name.endswith("_rhs.mtx"):
            continue
        stem = path.name[: -len(".mtx")]
        attempt = stem[: stem.index("_iter")]
        a = scipy.io.mmread(path)  # a symmetric file gives both triangles
        b = np.asarray(scipy.io.mmread(d / f"{stem}_rhs.mtx")).ravel()
        with open(d / f"{attempt}_unknowns.csv") as f:
            unknowns = list(csv.DictReader(f))
        modes = rigid_body_modes(unknowns)
        m = petsc_matrix(a)
        for pc_type in ("gamg", "hypre"):
            try:
                its, reason, setup, seconds = solve(m, b, modes, pc_type, args.rtol)
            except PETSc.Error as e:  # hypre may be missing from a PETSc build
                print(f"{stem}: {pc_type}: {e}", file=sys.stderr)
                continue
            print(json.dumps({"system": stem, "unknowns": a.shape[0], "pc": pc_type,
                              "iterations": its, "reason": reason,
                              "setup_seconds": setup, "solve_seconds": seconds}))
            sys.stdout.flush()


if __name__ == "__main__":
    main()
