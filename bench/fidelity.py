#!/usr/bin/python3
"""Wall time of quiver-bake's fidelity stage (the reduced model against full-space StVK on four
static loads, serial, on rank 0) and of the whole default bake, on the 12.8k-tet bridge and
polyfem's 33k-tet cubes (k = 20, r = 30, one rank). Prints a markdown table (the one in
bench/README.md) and the CPU it ran on.

    /usr/bin/python3 bench/fidelity.py --build build/release [--meshes ../shared/meshes] [--repeat 2]

Each mesh is baked --repeat times and the fastest run is kept."""
import argparse
import os
import re
import subprocess
import sys
import tempfile
import time

from machine import machine_line

LINE = re.compile(r"^quiver-bake: fidelity: .*\[([0-9.e+-]+) s\]$")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default="build/release")
    ap.add_argument("--meshes", default=os.path.join(os.path.dirname(__file__), "..", "..", "shared", "meshes"))
    ap.add_argument("--repeat", type=int, default=2)
    args = ap.parse_args()
    bake = os.path.join(args.build, "apps", "quiver-bake")
    cases = [("vega_simpleBridge_tet.veg", 12827, ["--bou", os.path.join(args.meshes, "vega_simpleBridge_tet.bou")]),
             ("polyfem_cubes_v41.msh", 32981, ["--fix", "z<min+0.01", "--fidelity-max-tets", "40000"])]
    print(f"{machine_line()}\n")
    print("| mesh | tets | fidelity stage (s) | whole bake, wall (s) |")
    print("|---|---:|---:|---:|")
    with tempfile.TemporaryDirectory() as tmp:
        for name, tets, extra in cases:
            mesh = os.path.join(args.meshes, name)
            if not os.path.exists(mesh):
                sys.exit(f"{mesh} is missing (../shared/meshes)")
            best = None
            for _ in range(args.repeat):
                cmd = [bake, mesh, *extra, "--modes", "20", "--rank", "30", "-o", os.path.join(tmp, "out")]
                start = time.perf_counter()
                p = subprocess.run(cmd, capture_output=True, text=True, stdin=subprocess.DEVNULL)
                wall = time.perf_counter() - start
                if p.returncode != 0:
                    sys.exit(f"failed: {' '.join(cmd)}\n{p.stderr}")
                stage = next(float(m.group(1)) for m in map(LINE.match, p.stdout.splitlines()) if m)
                if best is None or stage < best[0]:
                    best = (stage, wall)
            print(f"| {name} | {tets} | {best[0]:.2f} | {best[1]:.2f} |", flush=True)


if __name__ == "__main__":
    main()
