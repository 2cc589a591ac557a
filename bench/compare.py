#!/usr/bin/python3
"""What reduction buys and what it costs: one drag-and-twist scenario on a cantilever bar, run by
the full-space StVK reference (four sparse solvers) and by the runtime (reduced StVK, and linear
modal dynamics in a modal subspace), compared on wall time per simulated second, displacement
error against full StVK over time, and volume change at the largest twist.

    /usr/bin/python3 bench/compare.py --build build/release [--out bench/compare]

Three cases: a generated bar twisted, and Vega's beam3 pulled and twisted (../shared/meshes,
skipped when absent). Writes
OUT/CASE.md, OUT/CASE_error.png and OUT/CASE_volume.png for each, and prints the tables.
"""
import argparse
import json
import os
import subprocess
import tempfile

import numpy as np

from machine import machine_line

try:
    import meshio
except ImportError:
    raise SystemExit("bench/compare.py needs python3-meshio (scripts/quiver installs it)")

# 1 m x 10 cm x 10 cm bar, E = 1 MPa: the free end is twisted by 45 degrees and lifted by 10 cm over
# one second, then released for two; 120 Hz.
DT, HOLD, STEPS, EVERY = 1 / 120, 120, 360, 10
TIMING = ["--hold", HOLD, "--steps", STEPS, "--dt", DT, "--beta", "0.002", "--every", EVERY]
BAR = ["--group", "x>max-1e-6", "--twist", "45", "--drag", "0,0,0.1", *TIMING]
# Vega's beam3 (0.12 x 1.0 x 0.04 m, long along y, E = 10 MPa, fixed at y = 1 by its .bou), its free
# end (y = 0) either pulled down by 4 N (about a fifth of the length), or twisted by 45 degrees about
# y and pushed down by 10 cm; then released.
BEAM3_PULL = ["--group", "y<min+1e-6", "--force", "0,0,-4", *TIMING]
BEAM3_TWIST = ["--group", "y<min+1e-6", "--twist", "45", "--axis", "y", "--drag", "0,0,-0.1", *TIMING]
MPI_ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1", OMPI_MCA_pml="ob1")


def run(*cmd, ok=(0,)):
    p = subprocess.run(list(map(str, cmd)), capture_output=True, text=True, env=MPI_ENV, stdin=subprocess.DEVNULL)
    if p.returncode not in ok:
        raise subprocess.CalledProcessError(p.returncode, cmd, p.stdout, p.stderr)
    return p.stdout


def frames(stem):
    """Displacements per saved frame, in step order."""
    names = sorted(f for f in os.listdir(os.path.dirname(stem)) if f.startswith(os.path.basename(stem) + "_"))
    out = [meshio.read(os.path.join(os.path.dirname(stem), n)) for n in names]
    return out[0].points, out[0].cells_dict["tetra"], [m.point_data["displacement"] for m in out]


def volume(points, tets):
    x = points[tets]
    return np.abs(np.linalg.det(np.stack([x[:, 1] - x[:, 0], x[:, 2] - x[:, 0], x[:, 3] - x[:, 0]], axis=1))).sum() / 6


def compare(apps, tmp, mesh, constraints, material, scenario):
    """Every method on one case: table rows, curves over time, and the methods that failed."""
    series, failures = {}, {}
    quiver = os.path.join(apps, "quiver")
    for solver in ("ldlt", "llt", "cg", "lu"):
        out = os.path.join(tmp, "full_" + solver)
        try:
            j = json.loads(run(quiver, "full", mesh, *constraints, *material, "--solver", solver, *scenario, "-o", out,
                               "--json"))
            series[f"full StVK ({solver})"] = (out, j["seconds_per_simulated_second"])
        except subprocess.CalledProcessError as e:  # e.g. SimplicialLLT on an indefinite tangent
            failures[f"full StVK ({solver})"] = e.stderr.strip().replace("quiver: error: ", "")
    for elasticity, name in (("linear", "full linear (ldlt)"), ("warping", "full linear + warping (ldlt)")):
        out = os.path.join(tmp, "full_" + elasticity)
        j = json.loads(run(quiver, "full", mesh, *constraints, *material, "--elasticity", elasticity, *scenario, "-o",
                           out, "--json"))
        series[name] = (out, j["seconds_per_simulated_second"])
    bake = os.path.join(apps, "quiver-bake")
    model, modal = os.path.join(tmp, "stvk"), os.path.join(tmp, "modal")
    run("mpirun", "-n", "2", bake, mesh, *constraints, *material, "--modes", "20", "--rank", "30", "--quiet", "-o", model)
    run("mpirun", "-n", "2", bake, mesh, *constraints, *material, "--modes", "30", "--export-npy", "--quiet", "-o",
        modal + "_modes")
    run("mpirun", "-n", "2", bake, mesh, *constraints, *material, "--modes", "30", "--basis-from",
        modal + "_modes.modes.npy", "--quiet", "-o", modal)
    # Reduced StVK with both solvers: Newton iterations damp with beta K(q), as the full-space reference
    # does, but two fixed ones can run away after a large twist's release; the default, minimising
    # solver cannot, and damps with K at each step's start (one step behind).
    fixed = ["--solver", "newton", "--newton", "2"]
    for name, qvr, elasticity, solver in (("reduced StVK (r = 30, modes + derivatives), default solver", model, "stvk", []),
                                          ("reduced StVK (r = 30, modes + derivatives), 2 fixed Newton iterations", model,
                                           "stvk", fixed),
                                          ("linear modal (r = 30 modes)", modal, "linear", []),
                                          ("modal warping (r = 30 modes)", modal, "warping", [])):
        out = os.path.join(tmp, os.path.basename(qvr) + "_" + elasticity + ("_newton" if solver else "_default"))
        j = json.loads(run(quiver, "sim", qvr + ".qvr", *scenario, "--elasticity", elasticity, *solver, "-o", out,
                           "--json", ok=(0, 2)))  # 2: finished, some steps reset
        label = name + (f" ({j['resets']} steps reset)" if j["resets"] else "") + (
            f" ({j['minimized_steps']} steps the minimiser took)" if j.get("minimized_steps") else "")
        series[label] = (out, 1.0 / (j["steps_per_second"] * j["time_step_s"]))
    points, tets, reference = frames(series["full StVK (ldlt)"][0])
    rest_volume = volume(points, tets)
    hold_frame = HOLD // EVERY - 1  # the frame at the end of the hold: largest twist
    rows, curves = [], {}
    for name, (stem, cost) in series.items():
        _, _, us = frames(stem)
        error = [np.linalg.norm(u - r) / max(np.linalg.norm(r), 1e-30) for u, r in zip(us, reference)]
        vols = [volume(points + u, tets) / rest_volume - 1 for u in us]
        curves[name] = (error, vols)
        rows.append((name, cost, max(error), vols[hold_frame]))
    return rows, curves, failures


def report(out, case, rows, curves, failures):
    table = [f"**{case}**", "", "| method | wall s per simulated s | speed-up vs full StVK (ldlt) | "
             "max displacement error vs full StVK | volume change at the end of the load |", "|---|---:|---:|---:|---:|"]
    base = rows[0][1]
    for name, cost, err, dv in rows:
        table.append(f"| {name} | {cost:.4g} | {base / cost:.0f}x | {err:.2%} | {dv:+.2%} |")
    for name, why in failures.items():
        table.append(f"| {name} | failed: {why} | | | |")
    text = "\n".join(table)
    with open(os.path.join(out, case + ".md"), "w") as f:
        f.write(text + "\n")
    print(text + "\n")
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("(python3-matplotlib not installed: no plots)")
        return
    for index, (label, suffix) in enumerate((("displacement error vs full StVK (ldlt)", "error"),
                                             ("volume change", "volume"))):
        plt.figure(figsize=(7, 4))
        for name, curve in curves.items():
            plt.plot(np.arange(1, len(curve[index]) + 1) * EVERY * DT, curve[index], label=name)
        plt.axvline(HOLD * DT, color="grey", linestyle=":", label="release")
        plt.title(case)
        plt.xlabel("time (s)")
        plt.ylabel(label)
        plt.legend(fontsize=7)
        plt.tight_layout()
        plt.savefig(os.path.join(out, f"{case}_{suffix}.png"), dpi=110)
        plt.close()


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default="build/release")
    ap.add_argument("--out", default="bench/compare")
    ap.add_argument("--meshes", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "shared",
                                                     "meshes"))
    args = ap.parse_args()
    print(machine_line() + "; one thread per simulation\n")
    apps = os.path.join(args.build, "apps")
    os.makedirs(args.out, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        bar = os.path.join(tmp, "bar.vtu")
        run(os.path.join(apps, "quiver-mesh"), "beam", "--size", "1,0.1,0.1", "--cells", "30,3,3", "-o", bar)
        report(args.out, "bar", *compare(apps, tmp, bar, ["--fix", "x<min+1e-9"],
                                         ["--E", "1e6", "--nu", "0.4", "--density", "1000"], BAR))
    beam3 = os.path.join(args.meshes, "vega_beam3_tet.veg")
    if not os.path.exists(beam3):
        print(f"{beam3} not found: the beam3 case is skipped")
        return
    for case, scenario in (("vega_beam3_tet_pull", BEAM3_PULL), ("vega_beam3_tet_twist", BEAM3_TWIST)):
        with tempfile.TemporaryDirectory() as tmp:
            report(args.out, case, *compare(apps, tmp, beam3, ["--bou", beam3[:-4] + ".bou"], [], scenario))


if __name__ == "__main__":
    main()
