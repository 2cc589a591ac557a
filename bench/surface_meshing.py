#!/usr/bin/python3
"""Tetrahedralizing an artist-sized surface: a torus of about 50 000 triangles, written as an OBJ, into
about 20 000 tets by quiver-bake (gmsh, one thread), as the bake reports it, best of three runs.
    /usr/bin/python3 bench/surface_meshing.py --build build/release
Issue 14 asks for <= 10 s."""
import argparse
import math
import os
import re
import subprocess
import tempfile

from machine import cpu_model


def torus(path, major=1.0, minor=0.35, around=250, tube=100):
    """(around x tube x 2) = 50 000 outward triangles."""
    with open(path, "w") as f:
        for i in range(around):
            u = 2 * math.pi * i / around
            for j in range(tube):
                v = 2 * math.pi * j / tube
                r = major + minor * math.cos(v)
                f.write(f"v {r * math.cos(u):.7f} {r * math.sin(u):.7f} {minor * math.sin(v):.7f}\n")
        for i in range(around):
            for j in range(tube):
                a, b = i * tube + j, ((i + 1) % around) * tube + j
                c, d = i * tube + (j + 1) % tube, ((i + 1) % around) * tube + (j + 1) % tube
                f.write(f"f {a + 1} {b + 1} {d + 1}\nf {a + 1} {d + 1} {c + 1}\n")
    return around * tube * 2


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--build", default="build/release")
    parser.add_argument("--tets", type=int, default=20000)
    args = parser.parse_args()
    gmsh = subprocess.run(["gmsh", "--version"], capture_output=True, text=True)
    print(f"CPU: {cpu_model()}; gmsh {(gmsh.stdout + gmsh.stderr).strip()}, one thread")
    with tempfile.TemporaryDirectory() as tmp:
        obj = os.path.join(tmp, "torus.obj")
        triangles = torus(obj)
        best = None
        for _ in range(3):
            p = subprocess.run([os.path.join(args.build, "apps", "quiver-bake"), obj, "--tets", str(args.tets), "--modes", "2",
                                "--rank", "2", "--no-fidelity", "-o", os.path.join(tmp, "torus")],
                               capture_output=True, text=True, check=True)
            line = next(l for l in p.stdout.splitlines() if "by gmsh in" in l)
            seconds = float(re.search(r"by gmsh in ([0-9.]+) s", line).group(1))
            best = seconds if best is None else min(best, seconds)
        print(line.split(": ", 1)[1])
        print(f"{triangles} triangles -> tets: best of 3 {best:.1f} s (issue 14: <= 10 s)")


if __name__ == "__main__":
    main()
