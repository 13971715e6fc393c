#!/usr/bin/env python3
"""Alternating 3D throughput runs: mpm (usl, usf, musl) and Taichi (f64, f32) at each
size, R rounds, every run under /usr/bin/time -v.  One JSON line per run.

The 3D variant of ../shared/peers/taichi/bench.py (same records, same alternation),
running gen_scenes_3d.py and mls_mpm_bench_3d.py of this folder.

usage: bench_3d.py MPM_BINARY OUT_DIR ROUNDS [n:steps ...]   (default 32:100 64:40 100:10)
environment: THREADS (default 2) for both programs; JOBS (default
"mpm:usl,taichi:f64,mpm:usf,taichi:f32,mpm:musl"), run in this order in even
rounds and in reverse order in odd rounds.
"""
import json
import os
import re
import subprocess
import sys
import time

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, here)
from gen_scenes_3d import scene  # noqa: E402

DEFAULT_SIZES = [(32, 100), (64, 40), (100, 10)]

mpm, out, rounds = sys.argv[1], sys.argv[2], int(sys.argv[3])
sizes = [tuple(map(int, a.split(":"))) for a in sys.argv[4:]] or DEFAULT_SIZES
threads = os.environ.get("THREADS", "2")
os.makedirs(out, exist_ok=True)
log = open(os.path.join(out, "results.jsonl"), "a")


def timed(cmd):
    r = subprocess.run(["/usr/bin/time", "-v"] + cmd, capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(f"{cmd}: {r.stderr[-2000:]}")
    t = {}
    for key, pat in [("max_rss_kb", r"Maximum resident set size \(kbytes\): (\d+)"),
                     ("user_s", r"User time \(seconds\): ([\d.]+)"),
                     ("sys_s", r"System time \(seconds\): ([\d.]+)"),
                     ("elapsed", r"Elapsed \(wall clock\) time \(h:mm:ss or m:ss\): ([\d:.]+)")]:
        m = re.search(pat, r.stderr)
        t[key] = m.group(1)
    parts = [float(p) for p in t["elapsed"].split(":")]
    t["process_wall_s"] = sum(p * 60 ** k for k, p in enumerate(reversed(parts)))
    del t["elapsed"]
    t["max_rss_kb"] = int(t["max_rss_kb"])
    for k in ("user_s", "sys_s"):
        t[k] = float(t[k])
    return r.stdout, t


def run_mpm(n, steps, scheme, rnd):
    path = os.path.join(out, f"scene3d_n{n}_{scheme}.toml")
    with open(path, "w") as fh:
        fh.write(scene(n, steps, scheme))
    d = os.path.join(out, f"mpm_n{n}_{scheme}")
    _, t = timed([mpm, "run", path, "--out", d, "--threads", threads])
    s = json.load(open(os.path.join(d, "summary.json")))
    st = s["stages"][0]
    return dict(program="mpm", variant=scheme, dim=3, n=n, particles=s["particles"], steps=s["steps"],
                loop_s=st["wall_seconds"], wall_s=s["wall_seconds"],
                pss=s["particles"] * st["steps"] / st["wall_seconds"], round=rnd, **t)


def run_taichi(n, steps, fp, rnd):
    js = os.path.join(out, f"taichi_n{n}_{fp}.json")
    cmd = [sys.executable, os.path.join(here, "mls_mpm_bench_3d.py"), "--n", str(n), "--steps", str(steps),
           "--fp", fp, "--threads", threads, "--json", js]
    if rnd == 0:
        cmd += ["--dump", os.path.join(out, f"taichi_n{n}_{fp}.npy")]
    _, t = timed(cmd)
    r = json.load(open(js))
    return dict(program="taichi", variant=fp, dim=3, n=n, particles=r["particles"], steps=r["steps"],
                loop_s=r["seconds"], pss=r["particle_steps_per_second"], round=rnd,
                loop_cpu_s=r.get("cpu_seconds"), com1=r["com1"], **t)


jobs = os.environ.get("JOBS", "mpm:usl,taichi:f64,mpm:usf,taichi:f32,mpm:musl").split(",")
for rnd in range(rounds):
    for n, steps in sizes:
        order = jobs if rnd % 2 == 0 else jobs[::-1]
        for job in order:
            prog, var = job.split(":")
            rec = (run_mpm if prog == "mpm" else run_taichi)(n, steps, var, rnd)
            rec["load1"] = os.getloadavg()[0]
            rec["threads"] = int(threads)
            rec["time"] = time.strftime("%H:%M:%S")
            log.write(json.dumps(rec) + "\n")
            log.flush()
            print(f"round {rnd} n={n} (3D) {job}: {rec['pss'] / 1e6:.3f} M particle-steps/s "
                  f"(loop {rec['loop_s']:.2f} s, process {rec['process_wall_s']:.2f} s, "
                  f"rss {rec['max_rss_kb'] / 1024:.0f} MiB, load {rec['load1']:.1f})", flush=True)
