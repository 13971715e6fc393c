#!/usr/bin/env python3
"""Write problems/slope_gmsh.msh: the Griffiths & Lane slope of
problems/slope_griffiths_lane.toml (the polygon (0, 0), (35, 0), (15, 10),
(0, 10)) as a Gmsh MSH 4.1 ASCII mesh, for problems/slope_gmsh.toml.

No Gmsh is needed: the slope is a trapezoid with horizontal top and bottom,
so it is meshed as the bilinear image of a structured NX x NY grid of the
unit square: row j at y = 10 j / NY, column i at x = (i / NX) (35 - 2 y)
(straight lines from the base to the crest). Each quadrilateral is cut into
two counter-clockwise triangles along its diagonal from lower left to upper
right (`--quads` keeps the quadrilaterals). The file holds, as Gmsh writes
it, point, curve and surface entities, the base as 2-node lines (physical
group 2 "base", which a 2D body passes over) and the triangles of surface 1
(physical group 1 "soil").

Usage: python3 problems/slope_gmsh.py [--nx 90] [--ny 30] [--quads] [OUT]
"""

import argparse


def nodes(nx, ny):
    """The (nx + 1) (ny + 1) nodes, row by row from the base; tag = 1 + index."""
    out = []
    for j in range(ny + 1):
        y = 10.0 * j / ny
        right = 35.0 - 2.0 * y
        for i in range(nx + 1):
            out.append((right * i / nx, y))
    return out


def cells(nx, ny, quads):
    """The elements as tuples of node tags, counter-clockwise."""
    tag = lambda i, j: 1 + j * (nx + 1) + i
    out = []
    for j in range(ny):
        for i in range(nx):
            a, b, c, d = tag(i, j), tag(i + 1, j), tag(i + 1, j + 1), tag(i, j + 1)
            out += [(a, b, c, d)] if quads else [(a, b, c), (a, c, d)]
    return out


def write(path, nx, ny, quads):
    xy = nodes(nx, ny)
    elements = cells(nx, ny, quads)
    base = [(1 + i, 2 + i) for i in range(nx)]
    kind = 3 if quads else 2  # Gmsh element types: 3 = 4-node quad, 2 = 3-node triangle
    lines = ["$MeshFormat", "4.1 0 8", "$EndMeshFormat"]
    lines += ["$PhysicalNames", "2", '1 2 "base"', '2 1 "soil"', "$EndPhysicalNames"]
    # Entities: points 1, 2 (the base's ends), curve 1 (the base), surface 1.
    lines += ["$Entities", "2 1 1 0"]
    lines += ["1 0 0 0 0", "2 35 0 0 0"]
    lines += ["1 0 0 0 35 0 0 1 2 2 1 -2"]
    lines += ["1 0 0 0 35 10 0 1 1 1 1"]
    lines += ["$EndEntities"]
    n = len(xy)
    lines += ["$Nodes", f"1 {n} 1 {n}", f"2 1 0 {n}"]
    lines += [str(t + 1) for t in range(n)]
    lines += [f"{x!r} {y!r} 0" for x, y in xy]
    lines += ["$EndNodes"]
    total = len(base) + len(elements)
    lines += ["$Elements", f"2 {total} 1 {total}", f"1 1 1 {len(base)}"]
    lines += [f"{k + 1} {a} {b}" for k, (a, b) in enumerate(base)]
    lines += [f"2 1 {kind} {len(elements)}"]
    first = len(base) + 1
    lines += [f"{first + k} " + " ".join(map(str, e)) for k, e in enumerate(elements)]
    lines += ["$EndElements"]
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--nx", type=int, default=90)
    p.add_argument("--ny", type=int, default=30)
    p.add_argument("--quads", action="store_true")
    p.add_argument("out", nargs="?", default="problems/slope_gmsh.msh")
    a = p.parse_args()
    write(a.out, a.nx, a.ny, a.quads)


if __name__ == "__main__":
    main()
