"""Regenerate the tables of papers/contact/README.md.

Runs `mpm` on the contact scenes of problems/ and of this folder, measures each
run against its closed form or published number, and prints the tables as
Markdown. Standard library only.

usage (from the repository root, after `cargo build --release`):
    python3 papers/contact/reproduce.py [OUT_DIR] [--quick] [--only NAME,...]
MPM=path/to/mpm picks the binary (default target/release/mpm, else `mpm`).
--quick leaves out the finest grids (R/20, R/16 and R/32 cylinders, the h = B/32
footings, the 1.25 ms implicit runs near the sticking limit); NAME is one of
cylinder, seed, seed3d, incline, limit, terrain, disks, plate, footing. The
whole run takes 35–50 minutes on 2 cores.
"""
import csv
import json
import math
import os
import pathlib
import shutil
import subprocess
import sys
import time
import tomllib

ROOT = pathlib.Path(__file__).resolve().parents[2]
HERE = pathlib.Path(__file__).resolve().parent


def mpm_binary():
    if "MPM" in os.environ:
        return os.environ["MPM"]
    local = ROOT / "target" / "release" / "mpm"
    return str(local) if local.exists() else shutil.which("mpm") or "mpm"


MPM = mpm_binary()


def run(scene, out, sets):
    """Run `mpm run scene` into out with --set overrides; the wall time in s."""
    cmd = [MPM, "run", str(scene), "--out", str(out)]
    for s in sets:
        cmd += ["--set", s]
    start = time.monotonic()
    done = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"failed: {' '.join(cmd)}\n{done.stderr}")
    return time.monotonic() - start


def rows(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def column(table, key):
    return [float(r[key]) for r in table]


def particles(out, body=None):
    """(body, x, y, vx, vy, mass, volume, syy) of particles_final.csv."""
    result = []
    for r in rows(out / "particles_final.csv"):
        b = int(float(r["body"]))
        if body is None or b == body:
            result.append((b, float(r["x"]), float(r["y"]), float(r["vx"]), float(r["vy"]),
                           float(r["mass"]), float(r["volume"]), float(r["syy"])))
    return result


def spin(ps):
    """Angular momentum about the centre of mass over the moment of inertia (x–y plane)."""
    m = sum(p[5] for p in ps)
    xc = sum(p[5] * p[1] for p in ps) / m
    yc = sum(p[5] * p[2] for p in ps) / m
    l = sum(p[5] * ((p[1] - xc) * p[4] - (p[2] - yc) * p[3]) for p in ps)
    i = sum(p[5] * ((p[1] - xc) ** 2 + (p[2] - yc) ** 2) for p in ps)
    return l / i


def moved(out, body="body1_x"):
    """(end time, displacement of a body's centre along x) from history.csv."""
    h = rows(out / "history.csv")
    return float(h[-1]["t"]), float(h[-1][body]) - float(h[0][body])


def pct(a, b):
    return f"{100.0 * (a / b - 1.0):+.2f} %"


def rolling_closed_form(g, theta, mu, radius, t, ramp):
    """Centre displacement and spin of a rigid solid cylinder at t, gravity
    raised linearly over `ramp` (the motion of a load applied at ramp/2, plus
    a small offset): slip when tan θ > 3μ, else rolling without slip."""
    te = t - 0.5 * ramp
    if math.tan(theta) > 3.0 * mu:
        a = g * (math.sin(theta) - mu * math.cos(theta))
        omega = -2.0 * mu * g * math.cos(theta) * te / radius
    else:
        a = 2.0 / 3.0 * g * math.sin(theta)
        omega = -a * te / radius
    return a * (0.5 * te * te + ramp * ramp / 24.0), omega + 0.0  # no −0 when μ = 0


def cylinder_setup(scene):
    """g, θ, the cylinder's radius and the gravity ramp of a rolling-cylinder
    scene (gravity tilted in x–y, the cylinder its second body)."""
    with open(scene, "rb") as f:
        config = tomllib.load(f)
    gx, gy = config["gravity"][:2]
    ramp = config["solver"].get("gravity_ramp_time", 0.0)
    return math.hypot(gx, gy), math.atan2(gx, -gy), config["body"][1]["radius"], ramp


def roll(out, scene, tag, label, mu, sets=(), ramp=None):
    """Run the cylinder of `scene` at friction μ with `sets` and print its row
    against the rigid cylinder's closed form (`ramp` if the sets change the
    scene's gravity ramp). `label` may hold {wall}, the run's wall time."""
    g, theta, radius, shipped_ramp = cylinder_setup(scene)
    d = out / tag
    wall = run(scene, d, [f"contact.0.friction_coefficient={mu}", *sets])
    t, x = moved(d)
    w = spin(particles(d, 1))
    x0, w0 = rolling_closed_form(g, theta, mu, radius, t, shipped_ramp if ramp is None else ramp)
    regime = "slip" if math.tan(theta) > 3.0 * mu else "rolling"
    spin_err = pct(w, w0) if w0 != 0.0 else f"ω = {w:+.3f} rad/s"
    print(f"| {label.format(wall=wall)} | {mu} ({regime}) | {x:.4f} | {x0:.4f} | {pct(x, x0)} "
          f"| {w:+.4f} | {w0:+.4f} | {spin_err} |")


CYL_HEADER = ("| case | μ | centre moved (m) | closed form (m) | error | spin (rad/s) | closed form | error |\n"
              "|---|---|---:|---:|---:|---:|---:|---:|")


def cylinder(out, quick):
    """problems/contact_cylinder.toml as shipped (polar fill, λ = 0.02, gravity
    over 0.1 s), both regimes at R/10 and R/20, and the lattice cylinder."""
    scene = ROOT / "problems" / "contact_cylinder.toml"
    print("\n### Rolling cylinder, `problems/contact_cylinder.toml` (θ = 45°, R = 0.5 m, E = 10 MPa)\n")
    print(CYL_HEADER)
    grids = [("[60,28]", "R/10")] + ([] if quick else [("[120,56]", "R/20")])
    for cells, h in grids:
        for mu in (0.0, 0.1, 0.5):
            roll(out, scene, f"cylinder_{h[2:]}_{mu}", f"shipped, h = {h}", mu, [f"grid.cells={cells}"])
    lattice = ['body.1.fill="lattice"', "contact.0.gap_factor=0.5", "solver.gravity_ramp_time=0"]
    for cells, h in grids:
        roll(out, scene, f"cylinder_lattice_{h[2:]}", f"lattice, λ = 0.5, no ramp, h = {h}", 0.5,
             [f"grid.cells={cells}"] + lattice, ramp=0.0)


def seed(out, quick):
    """The seed's cylinder (report 001 Part 2 §3.1) in plane strain, θ = 30°."""
    scene = HERE / "seed_cylinder.toml"
    print("\n### Rolling cylinder at the seed's scale, `seed_cylinder.toml` (θ = 30°, R = 3.2 m, E = 42 MPa on 420 MPa)\n")
    print(CYL_HEADER)
    grids = [("[50,23]", "0.4 m = R/8 (the seed's)")]
    if not quick:
        grids += [("[100,46]", "0.2 m = R/16"), ("[200,92]", "0.1 m = R/32")]
    for cells, h in grids:
        for mu in (0.0, 0.1, 0.3):
            tag = f"seed_{cells.strip('[]').replace(',', 'x')}_{mu}"
            roll(out, scene, tag, f"h = {h}", mu, [f"grid.cells={cells}"])
    if not quick:
        # Contact declared closer to touch: λ = 0.005 instead of the scene's 0.02.
        for mu in (0.0, 0.1, 0.3):
            roll(out, scene, f"seed_200x92_gap0.005_{mu}", "h = R/32, λ = 0.005", mu,
                 ["grid.cells=[200,92]", "contact.0.gap_factor=0.005"])


def seed3d(out, quick):
    """The seed's cylinder in 3D (4 m long, free ends), as the report ran it."""
    scene = HERE / "seed_cylinder_3d.toml"
    print("\n### The same in 3D, `seed_cylinder_3d.toml` (a cylinder 4 m long, h = 0.4 m)\n")
    print(CYL_HEADER)
    for mu in (0.0, 0.1, 0.3):
        roll(out, scene, f"seed3d_{mu}", "3D, {wall:.0f} s", mu)


def incline(out, quick):
    """problems/contact_incline.toml: a block on a deformable incline."""
    scene = ROOT / "problems" / "contact_incline.toml"
    th, g = math.radians(45.0), 9.81
    print("\n### Block on a deformable incline, `problems/contact_incline.toml` (θ = 45°, 2D)\n")
    print("| μ | moved (m) | ½ g t² (sin θ − μ cos θ) (m) | error |\n|---|---:|---:|---:|")
    for mu in (0.0, 0.3, 0.5):
        d = out / f"incline_{mu}"
        run(scene, d, [f"contact.0.friction_coefficient={mu}", "output.frames=0"])
        t, x = moved(d)
        x0 = 0.5 * g * t * t * (math.sin(th) - mu * math.cos(th))
        print(f"| {mu} | {x:.5f} | {x0:.5f} | {pct(x, x0)} |")
    for mu, damping in ((1.2, 0.1), (1.2, 0.0), (1.5, 0.0), (2.0, 0.0)):
        d = out / f"incline_stick_{mu}_{damping}"
        run(scene, d, [f"contact.0.friction_coefficient={mu}", f"solver.damping={damping}",
                       "output.frames=0", "solver.end_time=1.0"])
        t, x = moved(d)
        label = f"{100 * damping:.0f} % local damping" if damping else "undamped"
        print(f"| {mu} (tan θ ≤ μ: sticks), {label}, t = {t:.1f} s | {x:.2e} | 0 | — |")
    # θ = 30°: the weight meets the base within its middle third, so the whole
    # base stays in compression; gravity raised over 0.3 s, no damping.
    g30 = [f"gravity=[{g * 0.5},{-g * math.sqrt(3.0) / 2.0}]", "solver.gravity_ramp_time=0.3",
           "solver.end_time=1.0", "output.frames=0"]
    # The same block on a rigid base (the base a `model = "rigid"` body).
    text = scene.read_text().replace(
        '[[body]]\nname = "base"\nmaterial = "elastic"',
        '[[material]]\nname = "rigid"\nmodel = "rigid"\ndensity = 1000.0\n\n'
        '[[body]]\nname = "base"\nmaterial = "rigid"').replace(
        '[[boundary]]\nface = "ymin"\ncondition = "fixed"\n', "")
    rigid = out / "rigid_incline.toml"
    rigid.write_text(text)
    for mu, damping, end in ((0.3, 0.0, 0.5), (1.2, 0.1, 1.0), (1.2, 0.0, 1.0), (1.5, 0.0, 1.0),
                             (2.0, 0.0, 1.0)):
        d = out / f"rigid_incline_{mu}_{damping}"
        run(rigid, d, [f"contact.0.friction_coefficient={mu}", f"solver.damping={damping}",
                       "output.frames=0", f"solver.end_time={end}"])
        t, x = moved(d)
        x0 = 0.5 * g * t * t * max(math.sin(th) - mu * math.cos(th), 0.0)
        label = f"{100 * damping:.0f} % local damping" if damping else "undamped"
        err = pct(x, x0) if x0 > 0.0 else "—"
        print(f"| rigid base, {mu}, {label}, t = {t:.1f} s | {x:.4g} | {x0:.4g} | {err} |")
    for base, path in (("elastic", scene), ("rigid", rigid)):
        d = out / f"stick30_{base}"
        run(path, d, ["contact.0.friction_coefficient=0.7"] + g30)
        t, x = moved(d)
        print(f"| {base} base, θ = 30°, 0.7 (= 1.21 tan θ), undamped, gravity over 0.3 s, t = {t:.1f} s "
              f"| {x:.2e} | 0 | — |")


def limit(out, quick):
    """The block of problems/contact_incline.toml near the sticking limit,
    undamped, explicit (PIC, APIC, FLIP) beside the implicit solver
    (problems/contact_incline_implicit.toml) at several time steps."""
    explicit = ROOT / "problems" / "contact_incline.toml"
    implicit = ROOT / "problems" / "contact_incline_implicit.toml"
    th, g = math.radians(45.0), 9.81
    transfers = (("PIC", "solver.flip=0.0"), ("APIC", 'solver.velocity_transfer="apic"'),
                 ("FLIP", "solver.flip=1.0"))
    steps = (0.005, 0.0025) if quick else (0.005, 0.0025, 0.00125)

    def rigid_law(mu, t, ramp):
        a = g * max(math.sin(th) - mu * math.cos(th), 0.0)
        if ramp == 0.0:
            return 0.5 * a * t * t
        return a * (ramp * ramp / 6.0 + ramp * (t - ramp) / 2.0 + (t - ramp) ** 2 / 2.0)

    def measure(scene, tag, mu, sets, ramp):
        d = out / tag
        run(scene, d, [f"contact.0.friction_coefficient={mu}", "output.frames=0", *sets])
        t, x = moved(d)
        x0 = rigid_law(mu, t, ramp)
        return pct(x, x0) if x0 > 0.0 else f"{x:.3g} m"

    print("\n### Near the sticking limit: explicit beside implicit (θ = 45°, undamped)\n")
    print("| case | implicit, Δt = " + " / ".join(f"{1e3 * dt:g}" for dt in steps)
          + " ms | explicit " + " / ".join(n for n, _ in transfers) + " |\n|---|---|---|")
    cases = (("μ = 0.8, gravity at once, 0.5 s", 0.8, [], 0.0),
             ("μ = 0.9, gravity at once, 0.5 s", 0.9, [], 0.0),
             ("μ = 0.8, gravity over 0.3 s, 1 s", 0.8, ["solver.gravity_ramp_time=0.3", "solver.end_time=1.0"], 0.3),
             ("μ = 1.2, gravity over 0.3 s, 1 s: moved", 1.2,
              ["solver.gravity_ramp_time=0.3", "solver.end_time=1.0"], 0.3),
             ("block half as tall, μ = 1.2, over 0.3 s, 1 s: moved", 1.2,
              ["body.1.max=[1.0,0.5]", "solver.gravity_ramp_time=0.3", "solver.end_time=1.0"], 0.3))
    for k, (label, mu, sets, ramp) in enumerate(cases):
        imp = [measure(implicit, f"limit_{k}_implicit_{dt}", mu, [f"solver.dt={dt}", *sets], ramp)
               for dt in steps]
        exp = [measure(explicit, f"limit_{k}_{name}", mu, [key, *sets], ramp) for name, key in transfers]
        print(f"| {label} | {' / '.join(imp)} | {' / '.join(exp)} |")


def terrain(out, quick):
    """MPM-Geomechanics' terrain-contact block (3D, rigid terrain)."""
    scene = HERE / "terrain_block.toml"
    g = math.hypot(7.07, 7.07)
    th = math.radians(45.0)
    published = {0.0: "+0.009 %", 0.3: "+0.11 %", 0.5: "+0.68 %"}
    print("\n### Block on rigid terrain, `terrain_block.toml` (MPM-Geomechanics' terrain-contact set-up, 3D)\n")
    print("| μ | moved (m) | closed form (m) | error, ours | error, MPM-Geomechanics | wall (s) |\n"
          "|---|---:|---:|---:|---:|---:|")
    for mu in (0.0, 0.3, 0.5):
        d = out / f"terrain_{mu}"
        wall = run(scene, d, [f"contact.0.friction_coefficient={mu}"])
        t, x = moved(d)
        x0 = 0.5 * g * t * t * (math.sin(th) - mu * math.cos(th))
        print(f"| {mu} | {x:.4f} | {x0:.4f} | {pct(x, x0)} | {published[mu]} | {wall:.0f} |")
    # Sticking: at 45° a cube stands exactly at its tipping limit (its weight
    # passes through the lower edge), so the stick cases tilt gravity by 30°.
    print("\n| θ = 30°, tan θ = 0.577 | moved along the slope (m) | centre raised (m) | wall (s) |\n"
          "|---|---:|---:|---:|")
    for mu, damping in ((0.7, 0.0), (1.3, 0.0), (1.3, 0.1)):
        d = out / f"terrain_stick_{mu}_{damping}"
        wall = run(scene, d, [f"contact.0.friction_coefficient={mu}", f"solver.damping={damping}",
                              "gravity=[5.0,0.0,-8.660254037844386]"])
        _, x = moved(d)
        _, z = moved(d, "body1_z")
        label = f"{100 * damping:.0f} % local damping" if damping else "undamped"
        print(f"| μ = {mu}, {label} | {x:.4f} | {z:.4f} | {wall:.0f} |")


def disks(out, quick):
    """problems/contact_disks.toml: off-centre elastic disks with friction."""
    scene = ROOT / "problems" / "contact_disks.toml"
    print("\n### Off-centre elastic disks with friction, `problems/contact_disks.toml` (μ = 0.3)\n")
    d = out / "disks"
    run(scene, d, ["output.frames=0"])
    ps = particles(d)
    left = [p for p in ps if p[0] == 0]
    right = [p for p in ps if p[0] == 1]
    apart = min(math.hypot(a[1] - b[1], a[2] - b[2]) for a in left for b in right)
    px = sum(p[5] * p[3] for p in ps)
    py = sum(p[5] * p[4] for p in ps)
    scale = sum(p[5] * 0.2 for p in ps)
    h = rows(d / "history.csv")
    c = rows(d / "contact.csv")
    dissipated = {float(r["t"]): float(r["dissipation"]) for r in c}
    e0 = float(h[0]["kinetic"]) + float(h[0]["strain"])
    worst = max(abs((float(r["kinetic"]) + float(r["strain"]) + dissipated.get(float(r["t"]), 0.0)) / e0 - 1.0)
                for r in h)
    deep = out / "disks_deepest"
    run(scene, deep, ["output.frames=0", "solver.end_time=0.65"])
    ps = particles(deep)
    closest = min(math.hypot(a[1] - b[1], a[2] - b[2])
                  for a in ps if a[0] == 0 for b in ps if b[0] == 1)
    print("| quantity | value |\n|---|---:|")
    print(f"| closest particles of the two disks at the end (2 s) | {apart:.4f} m (they separated) |")
    print(f"| closest particles at the deepest compression (0.65 s), particle spacing 0.0125 m | {closest:.4f} m |")
    print(f"| total momentum at the end, over m v₀ | ({px / scale:.1e}, {py / scale:.1e}) |")
    print(f"| spin of the left disk at the end | {spin([p for p in particles(d) if p[0] == 0]):+.4f} rad/s |")
    print(f"| friction dissipated | {max(dissipated.values()):.4f} J of {e0:.4f} J |")
    print(f"| worst energy balance, kinetic + strain + dissipated against the initial energy | {100 * worst:.2f} % |")


def plate(out, quick):
    """problems/contact_plate_implicit.toml: AMPSSIE's tutorial 2 in 2D, implicit penalty."""
    scene = ROOT / "problems" / "contact_plate_implicit.toml"
    exact = 1.0e6 * math.log(0.75) / 0.75
    print("\n### Rigid plate on a Hencky block, `problems/contact_plate_implicit.toml` (AMPSSIE tutorial 2, 2D, quasi-static)\n")
    print(f"Cauchy σ_yy = E ln λ / λ = {exact / 1e3:.1f} kPa at λ = 0.75.\n")
    print("| penalty factor α | mean σ_yy (kPa) | error | deepest penetration (m) | Newton iterations |\n"
          "|---:|---:|---:|---:|---:|")
    for alpha in (10, 100, 1000):
        d = out / f"plate_{alpha}"
        run(scene, d, [f"contact.0.penalty_factor={alpha}", "output.frames=0"])
        body = particles(d, 0)
        mean = sum(p[7] * p[6] for p in body) / sum(p[6] for p in body)
        s = json.loads((d / "summary.json").read_text())
        pen = find_key(s, "contact_penetration")
        newton = find_key(s, "newton_iterations")
        print(f"| {alpha} | {mean / 1e3:.1f} | {pct(mean, exact)} | {pen:.2e} | {newton} |")


def find_key(tree, key):
    """The first value under `key` anywhere in a JSON tree."""
    if isinstance(tree, dict):
        if key in tree:
            return tree[key]
        children = tree.values()
    elif isinstance(tree, list):
        children = tree
    else:
        return None
    for child in children:
        found = find_key(child, key)
        if found is not None:
            return found
    return None


def footing(out, quick):
    """problems/contact_footing_implicit.toml: a rigid strip footing pushed into Tresca soil."""
    scene = ROOT / "problems" / "contact_footing_implicit.toml"
    prandtl = 2.0 + math.pi
    print("\n### Rigid strip footing on Tresca soil through contact, `problems/contact_footing_implicit.toml` (implicit)\n")
    print("| h | contact | q/c_u | against 2 + π | wall (s) |\n|---|---|---:|---:|---:|")
    grids = [("[20,14]", "B/8"), ("[40,28]", "B/16")] + ([] if quick else [("[80,56]", "B/32")])
    for cells, h in grids:
        for mu, label in (("0", "smooth"), ("10", "rough (μ = 10)")):
            d = out / f"footing_{h[2:]}_{mu}"
            wall = run(scene, d, [f"grid.cells={cells}", f"contact.0.friction_coefficient={mu}",
                                  "output.frames=0"])
            q = -float(rows(d / "contact.csv")[-1]["fy"]) / 1.0e4
            print(f"| {h} | {label} | {q:.3f} | {pct(q, prandtl)} | {wall:.0f} |")


CASES = {"cylinder": cylinder, "seed": seed, "seed3d": seed3d, "incline": incline, "limit": limit,
         "terrain": terrain, "disks": disks, "plate": plate, "footing": footing}


def main():
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    quick = "--quick" in sys.argv
    only = list(CASES)
    if "--only" in sys.argv:
        only = sys.argv[sys.argv.index("--only") + 1].split(",")
        args = [a for a in args if a != sys.argv[sys.argv.index("--only") + 1]]
    out = pathlib.Path(args[0] if args else ROOT / "out" / "contact").resolve()
    out.mkdir(parents=True, exist_ok=True)
    print(f"mpm: {MPM}; outputs in {out}")
    for name in only:
        CASES[name](out, quick)


if __name__ == "__main__":
    main()
