#!/usr/bin/env bash
# Do two builds of `mpm` give the same results on every shipped scene?
#
#   scripts/same_results.sh run MPM DIR      run every scene of problems/ with MPM into DIR
#   scripts/same_results.sh diff DIR_A DIR_B compare two such directories
#   scripts/same_results.sh REV              build REV (a git revision) in a worktree, run
#                                            both it and this tree's release build, compare
#
# Add --full before the command to run the long scenes at their shipped settings
# (about 3 minutes on 2 cores) instead of the quick settings below (about 1 minute).
# Add --tolerance REL (before the command) for a change that is meant to alter the
# last bits only (a new summation order or fill-reducing ordering): every number of
# the particle files, history.csv, the tables and summary.json is then compared
# within REL times the largest magnitude of its kind (the columns whose names start
# with the same letter: all stress components sxx, sxy, … share one scale, so a
# shear stress that is round-off noise is measured against the stresses; a JSON
# number against itself), the frames are skipped, and the worst relative
# difference of each file is printed.
#
# Compared byte for byte: particles_final.csv (every one, strength-reduction trials
# included), history.csv and the ParaView frames. Compared after dropping the
# wall-clock fields: summary.json (wall_seconds, particle_steps_per_second, and the
# solver timings of limit analysis; the output directory in messages), and, value by
# value (numbers as numbers, so only the text format of a number may differ),
# footing.csv, newton.csv, strength_reduction.csv and refinement.csv without their
# wall_seconds and solver-time columns. Exit status 0 when
# everything agrees, 1 otherwise, with one line per difference.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
full=0
tolerance=""
while true; do
  case "${1:-}" in
    --full) full=1; shift ;;
    --tolerance) tolerance="$2"; shift 2 ;;
    *) break ;;
  esac
done

# Shorter runs of the long scenes (their behaviour is exercised all the same).
quick_overrides() {
  case "$1" in
    collapse) echo "--set solver.end_time=0.25" ;;
    limit_slope) echo "--set mesh.refinements=[0]" ;;
    limit_footing_mc) echo "--set mesh.refinements=[0]" ;;
    footing_3d) echo "--set grid.cells=[8,8,6] --set solver.load_steps=2 --set solver.end_time=0.25" ;;
    collapse_3d) echo "--set grid.cells=[32,32,20] --set solver.end_time=0.02 --set output.frames=2" ;;
    *) echo "" ;;
  esac
}

run_all() {
  local mpm="$1" out="$2"
  mkdir -p "$out"
  for scene in "$root"/problems/*.toml; do
    local name cmd extra
    name="$(basename "$scene" .toml)"
    case "$name" in limit_*) cmd=limit ;; *) cmd=run ;; esac
    extra=""
    [ "$full" = 1 ] || extra="$(quick_overrides "$name")"
    # The million-particle collapse takes hours to its end: a few steps even in full.
    if [ "$full" = 1 ] && [ "$name" = collapse_3d ]; then
      extra="--set solver.end_time=0.002 --set output.frames=1"
    fi
    rm -rf "${out:?}/$name"
    # shellcheck disable=SC2086
    if "$mpm" "$cmd" "$scene" --out "$out/$name" $extra >"$out/$name.log" 2>&1; then
      echo "ran $name"
    else
      echo "ran $name (exit $?)"
    fi
  done
}

diff_all() {
  python3 - "$1" "$2" "$tolerance" <<'EOF'
import csv, io, json, os, sys
a_root, b_root = sys.argv[1], sys.argv[2]
tol = float(sys.argv[3]) if sys.argv[3] else None
# Wall-clock fields (and every field or column whose name ends in _seconds).
TIMING = {"seconds", "particle_steps_per_second"}
BYTES = ("particles_final.csv", "history.csv")
TABLES = ("footing.csv", "newton.csv", "strength_reduction.csv", "refinement.csv")

def strip(v, root):
    """Without wall-clock fields, and with the output directory in messages as OUT."""
    if isinstance(v, dict):
        return {k: strip(x, root) for k, x in v.items() if k not in TIMING and not k.endswith("_seconds")}
    if isinstance(v, list):
        return [strip(x, root) for x in v]
    if isinstance(v, str):
        return v.replace(root, "OUT")
    return v

def value(field):
    """A number as its float (so 7.65e-1 and 0.765 agree; NaN equals NaN), else the text."""
    try:
        x = float(field)
    except ValueError:
        return field
    return "NaN" if x != x else x

def table(path):
    rows = list(csv.reader(open(path, newline="")))
    if not rows:
        return rows
    keep = [i for i, h in enumerate(rows[0]) if h not in TIMING and not h.endswith("_seconds")]
    return [rows[0]] + [[value(r[i]) for i in keep if i < len(r)] for r in rows[1:]]

def files(root):
    out = set()
    for d, _, names in os.walk(root):
        for n in names:
            out.add(os.path.relpath(os.path.join(d, n), root))
    return out

def numbers(rows):
    """Columns of a table (header dropped) as lists of values."""
    return [list(col) for col in zip(*rows[1:])] if len(rows) > 1 else []

def worst_table(ra, rb):
    """Largest |a − b| / (largest |value| of the column), or None if the shapes or texts differ."""
    if len(ra) != len(rb) or (ra and ra[0] != rb[0]):
        return None
    worst = 0.0
    header = ra[0] if ra else []
    magnitude = {}
    for name, ca, cb in zip(header, numbers(ra), numbers(rb)):
        nums = [abs(x) for x in ca + cb if isinstance(x, float) and x == x and abs(x) != float("inf")]
        kind = name[:1]
        magnitude[kind] = max(magnitude.get(kind, 0.0), max(nums, default=0.0))
    for name, ca, cb in zip(header, numbers(ra), numbers(rb)):
        if len(ca) != len(cb):
            return None
        scale = magnitude[name[:1]]
        for x, y in zip(ca, cb):
            if isinstance(x, float) and isinstance(y, float):
                if x != y:
                    worst = max(worst, abs(x - y) / scale if scale > 0 else float("inf"))
            elif x != y:
                return None
    return worst

def worst_json(a, b):
    """The same for two JSON values, each number against its own magnitude."""
    if isinstance(a, dict) and isinstance(b, dict):
        if a.keys() != b.keys():
            return None
        ws = [worst_json(a[k], b[k]) for k in a]
    elif isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            return None
        ws = [worst_json(x, y) for x, y in zip(a, b)]
    elif isinstance(a, (int, float)) and isinstance(b, (int, float)) and not isinstance(a, bool):
        scale = max(abs(a), abs(b))
        return 0.0 if a == b or (a != a and b != b) else abs(a - b) / scale
    else:
        return 0.0 if a == b else None
    return None if None in ws else max(ws, default=0.0)

bad = 0
a_files, b_files = files(a_root), files(b_root)
for rel in sorted(a_files ^ b_files):
    if rel.endswith(".log"):
        continue
    print(f"only in {'A' if rel in a_files else 'B'}: {rel}")
    bad += 1
checked = 0
for rel in sorted(a_files & b_files):
    name = os.path.basename(rel)
    pa, pb = os.path.join(a_root, rel), os.path.join(b_root, rel)
    if tol is not None:
        if name in BYTES or name in TABLES:
            w = worst_table(table(pa), table(pb))
        elif name == "summary.json":
            w = worst_json(strip(json.load(open(pa)), a_root), strip(json.load(open(pb)), b_root))
        else:
            continue
        checked += 1
        if w is None or w > tol:
            print(f"differs: {rel} ({'shape or text' if w is None else f'{w:.2e}'})")
            bad += 1
        elif w > 0:
            print(f"within {tol:g}: {rel} ({w:.2e})")
        continue
    if name in BYTES or name.endswith(".vtu") or name.endswith(".pvd"):
        same = open(pa, "rb").read() == open(pb, "rb").read()
    elif name == "summary.json":
        same = strip(json.load(open(pa)), a_root) == strip(json.load(open(pb)), b_root)
    elif name in TABLES:
        same = table(pa) == table(pb)
    else:
        continue
    checked += 1
    if not same:
        print(f"differs: {rel}")
        bad += 1
print(f"{checked} files compared, {bad} differences")
sys.exit(1 if bad else 0)
EOF
}

case "${1:-}" in
  run) run_all "$2" "$3" ;;
  diff) diff_all "$2" "$3" ;;
  "" | -h | --help) sed -n '2,17p' "$0" ;;
  *)
    rev="$1"
    work="$(mktemp -d)"
    trap 'git -C "$root" worktree remove --force "$work/src" >/dev/null 2>&1 || true; rm -rf "$work"' EXIT
    git -C "$root" worktree add --detach "$work/src" "$rev" >/dev/null
    echo "building $rev"
    # Its own target directory under this tree's, kept between calls.
    CARGO_TARGET_DIR="$root/target/same_results" cargo build --release --quiet \
      --manifest-path "$work/src/Cargo.toml" --bin mpm
    cp "$root/target/same_results/release/mpm" "$work/mpm_base"
    echo "building this tree"
    cargo build --release --quiet --manifest-path "$root/Cargo.toml" --bin mpm
    # The scenes of this tree for both (scene files do not change).
    run_all "$work/mpm_base" "$work/a" >/dev/null
    run_all "$root/target/release/mpm" "$work/b" >/dev/null
    diff_all "$work/a" "$work/b"
    ;;
esac
