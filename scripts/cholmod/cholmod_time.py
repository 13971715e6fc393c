"""CHOLMOD's analyze + factorize + solve on each exported tangent (median of 7 after a
warm-up), one JSON line per matrix, with nnz(L) and the relative residual."""
import glob, json, os, sys, time

import numpy as np
import scipy.io
import scipy.sparse as sp
from sksparse.cholmod import analyze

REPEATS = 7

for path in sorted(glob.glob(os.path.join(sys.argv[1], "*.mtx"))):
    name = os.path.basename(path)[:-4]
    a = sp.csc_matrix(scipy.io.mmread(path))  # the symmetric file gives both triangles
    b = np.asarray(scipy.io.mmread(path[:-4] + "_rhs.mtx")).ravel()
    times = []
    for rep in range(REPEATS + 1):
        start = time.perf_counter()
        factor = analyze(a, mode="supernodal")
        factor.cholesky_inplace(a)
        x = factor(b)
        elapsed = time.perf_counter() - start
        if rep > 0:
            times.append(elapsed)
    residual = np.linalg.norm(a @ x - b) / np.linalg.norm(b)
    print(json.dumps({"name": name, "seconds": float(np.median(times)),
                      "nnz_l": int(factor.L().nnz), "residual": float(residual)}))
