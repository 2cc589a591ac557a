#!/usr/bin/python3
"""What `--pca-amplitude` trades: the bake's fidelity report (the reduced model against full-space
StVK on static loads, and the reduced frequencies against the baked ones) at several amplitudes, on
the demo's beam and human and on Vega's bridge and beam3. Prints a markdown table (the figures
README.md's basis stage quotes) and the CPU it ran on.

    /usr/bin/python3 bench/pca_amplitude.py --build build/release [--meshes ../shared/meshes]
        [--amplitudes 0.03,0.3,1,3]

One rank (two give the same basis). A model whose input is missing is skipped, saying so."""
import argparse
import os
import re
import subprocess
import sys
import tempfile

from machine import machine_line

# quiver-bake: fidelity: own weight 0.681% off (at 41.7% of the size), pull 4.2% off (...), twist 30
# 18.5% off (...), twist 60 20.1% off (...), 15 of the 20 baked frequencies within 1% (worst 87.3% off) [0.12 s]
LINE = re.compile(r"^quiver-bake: fidelity: (.*) \[[0-9.e+-]+ s\]$")
LOAD = re.compile(r"(own weight|pull|twist 30|twist 60) ([0-9.e+-]+)% off")
FREQUENCIES = re.compile(r"(\d+) of the (\d+) baked frequencies within 1%")
LOADS = ("own weight", "pull", "twist 30", "twist 60")


def fidelity(bake, mesh, options, amplitude, folder):
    cmd = [bake, mesh, *options, "--pca-amplitude", str(amplitude), "-o", os.path.join(folder, "out")]
    p = subprocess.run(cmd, capture_output=True, text=True, stdin=subprocess.DEVNULL)
    if p.returncode != 0:
        sys.exit(f"failed: {' '.join(cmd)}\n{p.stderr}")
    text = next((m.group(1) for m in map(LINE.match, p.stdout.splitlines()) if m), None)
    if text is None:
        sys.exit(f"no fidelity line from: {' '.join(cmd)}\n{p.stdout}")
    loads = dict((name, float(value)) for name, value in LOAD.findall(text))
    held = FREQUENCIES.search(text)
    return loads, f"{held.group(1)} / {held.group(2)}" if held else "-"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default="build/release")
    ap.add_argument("--meshes", default=os.path.join(os.path.dirname(__file__), "..", "..", "shared", "meshes"))
    ap.add_argument("--amplitudes", default="0.03,0.3,1,3")
    args = ap.parse_args()
    apps = os.path.join(args.build, "apps")
    bake = os.path.join(apps, "quiver-bake")
    amplitudes = [float(a) for a in args.amplitudes.split(",")]
    print(f"{machine_line()}\n")
    print("| model | amplitude | frequencies within 1% | " + " | ".join(f"{name} off (%)" for name in LOADS) + " |")
    print("|---|---:|---:|" + "---:|" * len(LOADS))
    with tempfile.TemporaryDirectory() as tmp:
        # The demo's models, as scripts/quiver demo bakes them.
        beam = os.path.join(tmp, "beam.vtu")
        subprocess.run([os.path.join(apps, "quiver-mesh"), "beam", "--size", "1,0.1,0.1", "--cells", "20,2,2", "-o", beam],
                       check=True, capture_output=True)
        cases = [("demo beam", beam, ["--fix", "x<min+1e-9", "--E", "1e6", "--nu", "0.45", "--density", "1000",
                                      "--modes", "20", "--rank", "30"])]
        human = "/usr/share/assimp/models/BLEND/HUMAN.blend"
        human_options = ["--fix", "z<min+0.4", "--E", "1e5", "--nu", "0.4", "--density", "100", "--modes", "12",
                         "--rank", "24"]
        if os.path.exists(human):
            # Tetrahedralised once; every amplitude bakes the same tets.
            first = os.path.join(tmp, "human")
            subprocess.run([bake, human, "--tets", "3000", *human_options, "--no-fidelity", "--quiet", "-o", first],
                           check=True, capture_output=True, stdin=subprocess.DEVNULL)
            cases.append(("demo human", first + ".tets.vtu", human_options))
        else:
            print(f"{human} not found (Debian's assimp-testmodels): the human is skipped", file=sys.stderr)
        for label, name in (("Vega bridge", "vega_simpleBridge_tet"), ("Vega beam3", "vega_beam3_tet")):
            mesh = os.path.join(args.meshes, name + ".veg")
            if os.path.exists(mesh):
                cases.append((label, mesh, ["--bou", mesh[:-4] + ".bou", "--modes", "20", "--rank", "30"]))
            else:
                print(f"{mesh} not found (../shared/meshes): {label} is skipped", file=sys.stderr)
        for label, mesh, options in cases:
            for amplitude in amplitudes:
                loads, held = fidelity(bake, mesh, options, amplitude, tmp)
                cells = " | ".join(f"{loads[name]:.3g}" if name in loads else "-" for name in LOADS)
                print(f"| {label} | {amplitude:g} | {held} | {cells} |", flush=True)


if __name__ == "__main__":
    main()
