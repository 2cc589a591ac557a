#!/usr/bin/python3
"""Wall time of each quiver-bake stage on the shared meshes, for k = 10 and 20 modes on 1 and 2
MPI ranks (r = 30). Prints a markdown table (the one in bench/README.md).

    /usr/bin/python3 bench/bake_stages.py --build build/release [--meshes ../shared/meshes] [--repeat 3]

Each configuration runs --repeat times and the fastest run is kept (least disturbed by the
machine). Stage times are those quiver-bake prints ("[0.15 s]"), measured between barriers."""
import argparse
import os
import re
import subprocess
import sys
import tempfile

STAGES = ["mesh", "partition", "assemble", "modes", "derivatives", "basis"]
LINE = re.compile(r"^quiver-bake: (\w+): .*\[([0-9.e+-]+) s\]$")


def run(bake, mesh, extra, ranks, k, out):
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1", OMPI_MCA_pml="ob1")
    cmd = ["mpirun", "-n", str(ranks), bake, mesh, *extra, "--modes", str(k), "--rank", "30", "--no-fidelity", "-o", out]
    p = subprocess.run(cmd, capture_output=True, text=True, env=env, stdin=subprocess.DEVNULL)
    if p.returncode != 0:
        sys.exit(f"failed: {' '.join(cmd)}\n{p.stderr}")
    times = {m.group(1): float(m.group(2)) for m in map(LINE.match, p.stdout.splitlines()) if m}
    return times


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default="build/release")
    ap.add_argument("--meshes", default=os.path.join(os.path.dirname(__file__), "..", "..", "shared", "meshes"))
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    bake = os.path.join(args.build, "apps", "quiver-bake")
    cases = [(f"polyfem_bar-{n}.msh", ["--fix", "x<min+1e-6"]) for n in (186, 651, 2523, 14114)]
    cases.append(("vega_simpleBridge_tet.veg", ["--bou", os.path.join(args.meshes, "vega_simpleBridge_tet.bou")]))
    print("| mesh | tets | k | ranks | " + " | ".join(STAGES) + " | total (s) |")
    print("|---|---:|---:|---:|" + "---:|" * (len(STAGES) + 1))
    with tempfile.TemporaryDirectory() as tmp:
        for name, extra in cases:
            mesh = os.path.join(args.meshes, name)
            if not os.path.exists(mesh):
                sys.exit(f"{mesh} not found: pass --meshes")
            tets = subprocess.run([os.path.join(args.build, "apps", "quiver-mesh"), "info", mesh], capture_output=True,
                                  text=True).stdout
            tets = re.search(r'"tets": (\d+)', tets).group(1)
            for k in (10, 20):
                for ranks in (1, 2):
                    # The stages up to the basis; bench/polynomials.py times the polynomials.
                    best = min((run(bake, mesh, extra, ranks, k, os.path.join(tmp, "b")) for _ in range(args.repeat)),
                               key=lambda t: sum(t.get(s, 0) for s in STAGES))
                    cells = [f"{best.get(s, 0):.3f}" for s in STAGES]
                    total = sum(best.get(s, 0) for s in STAGES)
                    print(f"| {name} | {tets} | {k} | {ranks} | " + " | ".join(cells) + f" | {total:.3f} |", flush=True)


if __name__ == "__main__":
    main()
