#!/usr/bin/python3
"""Bake a beam, pull its free end up for a second, let go, and plot how the tip swings.

    PYTHONPATH=build/release/python python3 examples/python/bake_and_plot.py -o tip.png

Needs quiver-mesh and quiver-bake ($QUIVER_MESH and $QUIVER_BAKE, or on the PATH), NumPy and
matplotlib. Bakes on 2 MPI ranks when mpiexec is found ($MPIEXEC or on the PATH), else on 1.
"""
import argparse
import os
import shutil
import subprocess
import sys
import tempfile

import numpy as np

import quiver


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("-o", "--output", required=True, help="the plot, a PNG file")
    parser.add_argument("--keep", metavar="DIR", help="bake into DIR and keep the files (default: a temporary folder)")
    args = parser.parse_args()

    mesh_tool = os.environ.get("QUIVER_MESH") or shutil.which("quiver-mesh")
    if not mesh_tool:
        sys.exit("bake_and_plot: quiver-mesh not found (set QUIVER_MESH or put it on the PATH)")
    mpiexec = os.environ.get("MPIEXEC") or shutil.which("mpiexec")
    with tempfile.TemporaryDirectory() as scratch:
        folder = args.keep or scratch
        os.makedirs(folder, exist_ok=True)
        # A 1 m x 10 cm x 10 cm beam of soft rubber, clamped at x = 0.
        mesh = os.path.join(folder, "beam.vtu")
        subprocess.run([mesh_tool, "beam", "--size", "1,0.1,0.1", "--cells", "10,2,2", "-o", mesh], check=True,
                       capture_output=True)
        path = quiver.bake(mesh, os.path.join(folder, "beam"), ranks=2 if mpiexec else 1, mpiexec=mpiexec,
                           fix="x<min+1e-9", E=1e6, nu=0.45, density=1000, modes=6, rank=10)
        model = quiver.Model(path)

    X = model.rest_positions
    tip = int(np.argmin(np.abs(X[:, 0] - X[:, 0].max()) + np.hypot(X[:, 1] - 0.05, X[:, 2] - 0.05)))
    beam = quiver.Instance(model)
    h = beam.time_step
    pull_steps, free_steps = round(1.0 / h), round(3.0 / h)

    # The first second: a drag spring (as a mouse would) whose target rises 10 cm; then let go.
    times, heights = [0.0], [0.0]
    for step in range(pull_steps + free_steps):
        if step < pull_steps:
            lift = 0.1 * (step + 1) / pull_steps
            beam.set_constraint(0, [tip], [X[tip] + (0, 0, lift)], stiffness=2000.0)
        elif step == pull_steps:
            beam.clear_constraint(0)
        if beam.step() == quiver.StepStatus.RESET:
            sys.exit(f"bake_and_plot: the beam reset at step {step}")
        times.append((step + 1) * h)
        heights.append(float(beam.positions_of([tip])[0, 2] - X[tip, 2]))
    times, heights = np.array(times), np.array(heights)

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figure, axes = plt.subplots(figsize=(8, 4))
    axes.plot(times, 100 * heights, color="tab:blue")
    axes.axvline(1.0, color="grey", linestyle="--", label="released")
    axes.axhline(0.0, color="grey", linewidth=0.5)
    axes.set_xlabel("time (s)")
    axes.set_ylabel("tip displacement, z (cm)")
    axes.set_title(f"quiver {quiver.__version__}: beam r = {model.info.r}, {model.info.vertex_count} vertices")
    axes.legend()
    figure.tight_layout()
    figure.savefig(args.output, dpi=100)
    if not os.path.isfile(args.output) or os.path.getsize(args.output) == 0:
        sys.exit(f"bake_and_plot: {args.output} was not written")
    after, last = times > 1.0, times > times[-1] - 1.0
    mode_hz = np.sqrt(model.eigenvalues[0]) / (2 * np.pi)
    print(f"tip lifted {100 * heights[pull_steps]:.1f} cm in 1 s, released: swung down to {100 * heights[after].min():.1f} cm, "
          f"within {100 * np.abs(heights[last]).max():.1f} cm in the last second (first mode {mode_hz:.2f} Hz); "
          f"plot {args.output}")


if __name__ == "__main__":
    main()
