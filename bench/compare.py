#!/usr/bin/python3
"""What reduction buys and what it costs: one drag-and-twist scenario on a cantilever bar, run by
the full-space StVK reference (four sparse solvers) and by the runtime (reduced StVK, and linear
modal dynamics in a modal subspace), compared on wall time per simulated second, displacement
error against full StVK over time, and volume change at the largest twist.

    /usr/bin/python3 bench/compare.py --build build/release [--out bench/compare]

Writes OUT/table.md, OUT/error.png and OUT/volume.png, and prints the table.
Not yet included (see the issue tracker): full-space linear + warping."""
import argparse
import json
import os
import subprocess
import tempfile

import numpy as np

try:
    import meshio
except ImportError:
    raise SystemExit("bench/compare.py needs python3-meshio (scripts/quiver installs it)")

# 1 m x 10 cm x 10 cm bar, E = 1 MPa: the free end is twisted by 45 degrees and lifted by 10 cm over
# one second, then released for two. At 120 Hz: the full-space Newton does not converge after the
# release at 60 Hz with this much twist (StVK under large rotation and compression).
DT, HOLD, STEPS, EVERY = 1 / 120, 120, 360, 10
SCENARIO = ["--group", "x>max-1e-6", "--twist", "45", "--drag", "0,0,0.1", "--hold", HOLD, "--steps", STEPS,
            "--dt", DT, "--beta", "0.002", "--every", EVERY]
MPI_ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1", OMPI_MCA_pml="ob1")


def run(*cmd):
    return subprocess.run(list(map(str, cmd)), check=True, capture_output=True, text=True, env=MPI_ENV,
                          stdin=subprocess.DEVNULL).stdout


def frames(stem):
    """Displacements per saved frame, in step order."""
    names = sorted(f for f in os.listdir(os.path.dirname(stem)) if f.startswith(os.path.basename(stem) + "_"))
    out = [meshio.read(os.path.join(os.path.dirname(stem), n)) for n in names]
    return out[0].points, out[0].cells_dict["tetra"], [m.point_data["displacement"] for m in out]


def volume(points, tets):
    x = points[tets]
    return np.abs(np.linalg.det(np.stack([x[:, 1] - x[:, 0], x[:, 2] - x[:, 0], x[:, 3] - x[:, 0]], axis=1))).sum() / 6


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default="build/release")
    ap.add_argument("--out", default="bench/compare")
    args = ap.parse_args()
    apps = os.path.join(args.build, "apps")
    os.makedirs(args.out, exist_ok=True)
    rows, series = [], {}
    with tempfile.TemporaryDirectory() as tmp:
        mesh = os.path.join(tmp, "bar.vtu")
        run(os.path.join(apps, "quiver-mesh"), "beam", "--size", "1,0.1,0.1", "--cells", "30,3,3", "-o", mesh)
        material = ["--E", "1e6", "--nu", "0.4", "--density", "1000"]
        fix = ["--fix", "x<min+1e-9"]
        failures = {}
        for solver in ("ldlt", "llt", "cg", "lu"):
            out = os.path.join(tmp, "full_" + solver)
            try:
                j = json.loads(run(os.path.join(apps, "quiver"), "full", mesh, *fix, *material, "--solver", solver,
                                   *SCENARIO, "-o", out, "--json"))
                series[f"full StVK ({solver})"] = (out, j["seconds_per_simulated_second"])
            except subprocess.CalledProcessError as e:  # e.g. SimplicialLLT on an indefinite tangent
                failures[f"full StVK ({solver})"] = e.stderr.strip().replace("quiver: error: ", "")
        bake = os.path.join(apps, "quiver-bake")
        model = os.path.join(tmp, "stvk")
        run("mpirun", "-n", "2", bake, mesh, *fix, *material, "--modes", "20", "--rank", "30", "--export-npy",
            "--quiet", "-o", model)
        modal = os.path.join(tmp, "modal")
        run("mpirun", "-n", "2", bake, mesh, *fix, *material, "--modes", "30", "--export-npy", "--quiet", "-o",
            modal + "_modes")
        run("mpirun", "-n", "2", bake, mesh, *fix, *material, "--modes", "30", "--basis-from",
            modal + "_modes.modes.npy", "--quiet", "-o", modal)
        for name, qvr, extra in (("reduced StVK (r = 30, modes + derivatives)", model, []),
                                 ("linear modal (r = 30 modes)", modal, ["--elasticity", "linear"]),
                                 ("modal warping (r = 30 modes)", modal, ["--elasticity", "warping"])):
            out = os.path.join(tmp, os.path.basename(qvr) + (extra[1] if extra else ""))
            j = json.loads(run(os.path.join(apps, "quiver"), "sim", qvr + ".qvr", *SCENARIO, *extra, "--newton", "2",
                               "-o", out, "--json"))
            series[name] = (out, 1.0 / (j["steps_per_second"] * j["time_step_s"]))

        points, tets, reference = frames(series["full StVK (ldlt)"][0])
        rest_volume = volume(points, tets)
        hold_frame = HOLD // EVERY - 1  # the frame at the end of the hold: largest twist
        curves = {}
        for name, (stem, cost) in series.items():
            _, _, us = frames(stem)
            error = [np.linalg.norm(u - r) / max(np.linalg.norm(r), 1e-30) for u, r in zip(us, reference)]
            vols = [volume(points + u, tets) / rest_volume - 1 for u in us]
            curves[name] = (error, vols)
            rows.append((name, cost, max(error), vols[hold_frame]))
    dt = EVERY * DT
    table = ["| method | wall s per simulated s | speed-up vs full StVK (ldlt) | max displacement error vs full StVK | "
             "volume change at the largest twist |", "|---|---:|---:|---:|---:|"]
    base = rows[0][1]
    for name, cost, err, dv in rows:
        table.append(f"| {name} | {cost:.4g} | {base / cost:.0f}x | {err:.2%} | {dv:+.2%} |")
    for name, why in failures.items():
        table.append(f"| {name} | failed: {why} | | | |")
    text = "\n".join(table)
    with open(os.path.join(args.out, "table.md"), "w") as f:
        f.write(text + "\n")
    print(text)
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("(python3-matplotlib not installed: no plots)")
        return
    for index, (label, filename) in enumerate((("displacement error vs full StVK (ldlt)", "error.png"),
                                               ("volume change", "volume.png"))):
        plt.figure(figsize=(7, 4))
        for name, curve in curves.items():
            t = np.arange(1, len(curve[index]) + 1) * dt
            plt.plot(t, curve[index], label=name)
        plt.axvline(HOLD * DT, color="grey", linestyle=":", label="release")
        plt.xlabel("time (s)")
        plt.ylabel(label)
        plt.legend(fontsize=7)
        plt.tight_layout()
        plt.savefig(os.path.join(args.out, filename), dpi=110)
        plt.close()
    print(f"plots: {args.out}/error.png, {args.out}/volume.png")


if __name__ == "__main__":
    main()
