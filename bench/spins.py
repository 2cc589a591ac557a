#!/usr/bin/python3
"""Fast spins and the energy: free objects baked as an artist would (the bake's defaults), spun
about their largest axis or tumbling, undamped, in the model's 1/60 s steps for 20 s, in substeps
(the default) and whole (--max-substeps 1). The start is the rigid spin's energy, w . I w / 2 with
the box's inertia by hand; the table gives the most the body's energy (kinetic and elastic, from
`quiver sim`'s CSV) reached over 20 s as a multiple of it, the last, and the step's median time.
Prints a markdown table (the figures docs/architecture.md's Free flight quotes) and the CPU.

    /usr/bin/python3 bench/spins.py --build build/release [--spins 50,100,140,200,300,500,1000]

About a minute and a half on one core."""
import argparse
import json
import os
import subprocess
import sys
import tempfile

import numpy as np

from machine import machine_line

# (name, size in m, cells, Young's modulus in Pa): a 0.6 m bar of 1 MPa (the runtime tests' bar,
# on the bake's basis) and a 0.3 m block of 10 kPa (the apps tests' soft block).
OBJECTS = (("0.6 m bar, 1 MPa", (0.6, 0.1, 0.1), (12, 2, 2), 1e6), ("0.3 m block, 10 kPa", (0.3, 0.1, 0.1), (12, 4, 4), 1e4))
DENSITY = 1000


def run(cmd):
    p = subprocess.run([str(c) for c in cmd], capture_output=True, text=True, stdin=subprocess.DEVNULL)
    if p.returncode != 0:
        sys.exit(f"failed: {' '.join(map(str, cmd))}\n{p.stderr}")
    return p.stdout


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default="build/release")
    ap.add_argument("--spins", default="50,100,140,200,300,500,1000")
    args = ap.parse_args()
    apps = os.path.join(args.build, "apps")
    spins = [[0, 0, float(w)] for w in args.spins.split(",")] + [[-120, 90, 150]]
    print(f"{machine_line()}\n")
    print("| object | spin (rad/s) | substeps: most | after 20 s | step (us) | whole steps: most | after 20 s | step (us) |")
    print("|---|---|---:|---:|---:|---:|---:|---:|")
    with tempfile.TemporaryDirectory() as tmp:
        for name, size, cells, modulus in OBJECTS:
            mesh, model = os.path.join(tmp, "object.vtu"), os.path.join(tmp, "object")
            run([os.path.join(apps, "quiver-mesh"), "beam", "--size", ",".join(map(str, size)), "--cells",
                 ",".join(map(str, cells)), "-o", mesh])
            run([os.path.join(apps, "quiver-bake"), mesh, "--E", modulus, "--nu", "0.45", "--density", DENSITY, "--quiet",
                 "-o", model])
            a, b, c = size
            mass = a * b * c * DENSITY
            inertia = np.diag([b * b + c * c, a * a + c * c, a * a + b * b]) * mass / 12
            for spin in spins:
                start = 0.5 * np.dot(spin, inertia @ spin)
                cells_out = []
                for extra in ([], ["--max-substeps", 1]):
                    out = os.path.join(tmp, "spun")
                    j = json.loads(run([os.path.join(apps, "quiver"), "sim", model + ".qvr", "--free", "--angular-velocity",
                                        ",".join(map(str, spin)), "--alpha", 0, "--beta", 0, *extra, "--steps", 1200,
                                        "--hold", 0, "-o", out, "--every", 100000, "--json"]))
                    energy = np.loadtxt(out + ".csv", delimiter=",", skiprows=1, usecols=(2, 3)).sum(axis=1)
                    resets = f" ({j['resets']} resets)" if j["resets"] else ""
                    cells_out += [f"{energy.max() / start:.4g}{resets}", f"{energy[-1] / start:.3g}", f"{j['step_us_median']:.0f}"]
                print(f"| {name} | {','.join(f'{w:g}' for w in spin)} | " + " | ".join(cells_out) + " |", flush=True)


if __name__ == "__main__":
    main()
