#!/usr/bin/env python3
"""Write problems/slope_terrain.asc: the ground surface of problems/slope_terrain.toml.

A 2:1 slope 10 m high (crest z = 12 m for x <= 10 m, toe z = 2 m for x >= 30 m)
across y in [0, 20] m, with a gully down its face: a Gaussian trough of depth
1.5 m and half-width 4 m about y = 10 m, fading out on the level ground above
and below the face. An ESRI ASCII grid of 81 x 41 points, 0.5 m apart, from
(0, 0); the northern row (largest y) first.
"""
import math
import pathlib

def elevation(x, y):
    face = min(max((30.0 - x) / 20.0, 0.0), 1.0)  # 1 on the crest, 0 at the toe
    plane = 2.0 + 10.0 * face
    on_face = math.sin(math.pi * face)  # 0 on the level ground, 1 mid-face
    gully = 1.5 * on_face * math.exp(-(((y - 10.0) / 4.0) ** 2))
    return plane - gully

def main():
    ncols, nrows, size = 81, 41, 0.5
    lines = [f"ncols {ncols}", f"nrows {nrows}", "xllcenter 0", "yllcenter 0",
             f"cellsize {size}", "NODATA_value -9999"]
    for i in reversed(range(nrows)):
        y = i * size
        lines.append(" ".join(f"{elevation(j * size, y):.4f}" for j in range(ncols)))
    out = pathlib.Path(__file__).with_suffix(".asc")
    out.write_text("\n".join(lines) + "\n")

if __name__ == "__main__":
    main()
