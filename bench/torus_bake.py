#!/usr/bin/python3
"""The whole bake of a torus of about 98 000 tets, as issue 15 asks of Vega's `torus-easy` model (which
the project does not have: a gmsh torus of the same size stands in), fixed at its lowest 2 cm, k = 20
modes, r = 30, on 1 and 2 ranks, with each eigensolver (the default block Krylov-Schur and SLEPc's),
without the fidelity stage (its serial full-space solves take many minutes at this size; best of
--repeat runs, wall time of mpirun and the stages the bake prints); and the bake's modes stage
against scipy's `eigsh` in shift-invert mode on the same K and M (dumped by SLEPc's
-eps_view_mat0/1 from the bake itself), in the same run on the same CPU.

    /usr/bin/python3 bench/torus_bake.py --build build/release
"""
import argparse
import os
import re
import subprocess
import sys
import tempfile
import time

import numpy as np
import scipy
import scipy.sparse
import scipy.sparse.linalg

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from machine import machine_line  # noqa: E402
from surface_meshing import torus  # noqa: E402

ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1", OMPI_MCA_pml="ob1")
STAGE = re.compile(r"^quiver-bake: (\w+): .*\[([0-9.e+-]+) s\]$")


def petsc_matrix(path):
    """A PETSc binary AIJ matrix (big-endian: class id, rows, columns, nonzeros, row lengths, columns, values)."""
    with open(path, "rb") as f:
        classid, rows, cols, nnz = np.fromfile(f, dtype=">i4", count=4)
        if classid != 1211216:
            sys.exit(f"{path}: not a PETSc matrix")
        lengths = np.fromfile(f, dtype=">i4", count=rows)
        columns = np.fromfile(f, dtype=">i4", count=nnz)
        values = np.fromfile(f, dtype=">f8", count=nnz)
    indptr = np.concatenate([[0], np.cumsum(lengths)])
    return scipy.sparse.csr_matrix((values.astype(np.float64), columns.astype(np.int64), indptr), shape=(rows, cols))


def bake(build, ranks, mesh, out, *extra):
    cmd = ["mpirun", "-n", str(ranks), os.path.join(build, "apps", "quiver-bake"), mesh, "--fix", "z<min+0.02",
           "--E", "1e6", "--nu", "0.45", "--density", "1000", "--modes", "20", "--rank", "30", "-o", out, *extra]
    start = time.perf_counter()
    p = subprocess.run(cmd, capture_output=True, text=True, env=ENV, stdin=subprocess.DEVNULL)
    wall = time.perf_counter() - start
    if p.returncode != 0:
        sys.exit(f"failed: {' '.join(cmd)}\n{p.stderr}")
    stages = {m.group(1): float(m.group(2)) for m in map(STAGE.match, p.stdout.splitlines()) if m}
    blas = next((l.split("BLAS: ", 1)[1] for l in p.stdout.splitlines() if "BLAS:" in l), "?")
    return wall, stages, blas


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default="build/release")
    ap.add_argument("--tets", type=int, default=98000)
    ap.add_argument("--repeat", type=int, default=2)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        obj = os.path.join(tmp, "torus.obj")
        torus(obj)
        subprocess.run([os.path.join(args.build, "apps", "quiver-bake"), obj, "--tets", str(args.tets), "--modes", "2",
                        "--rank", "2", "--no-fidelity", "--quiet", "-o", os.path.join(tmp, "mesh")], check=True)
        mesh = os.path.join(tmp, "mesh.tets.vtu")
        tets = next(int(m.group(1)) for m in [re.search(r'NumberOfCells="(\d+)"', open(mesh, errors="ignore").read(4096))])
        print(f"{machine_line()}; torus of {tets} tets (major radius 1 m, minor 0.35 m), fixed below its lowest 2 cm, "
              "k = 20, r = 30\n")
        stage_names = ("mesh", "partition", "assemble", "modes", "derivatives", "basis", "polynomials", "export")
        print("| ranks | eigensolver | whole bake, wall (s) | " + " | ".join(stage_names) + " | BLAS |")
        print("|---:|---|---:|" + "---:|" * len(stage_names) + "---|")
        best = {}
        for ranks in (1, 2):
            for solver in ("block", "krylov-schur"):
                runs = [bake(args.build, ranks, mesh, os.path.join(tmp, "t"), "--no-fidelity", "--eigensolver", solver)
                        for _ in range(args.repeat)]
                wall, stages, blas = min(runs, key=lambda run: run[0])
                best[ranks, solver] = stages
                cells = " | ".join(f"{stages.get(s, float('nan')):.2f}" for s in stage_names)
                print(f"| {ranks} | {solver} | {wall:.2f} | {cells} | {blas} |")
        # The same K and M as the bake's eigen-solve, dumped by SLEPc from a one-rank bake.
        name = os.path.join(tmp, "dump")
        bake(args.build, 1, mesh, name, "--no-fidelity", "--export-npy", "--eigensolver", "krylov-schur",
             "-eps_view_mat0", "binary:" + name + ".K", "-eps_view_mat1", "binary:" + name + ".M")
        K, M = petsc_matrix(name + ".K"), petsc_matrix(name + ".M")
        slepc = np.load(name + ".eigenvalues.npy")
        bake(args.build, 1, mesh, name + "_block", "--no-fidelity", "--export-npy")
        block = np.load(name + "_block.eigenvalues.npy")
        times = []
        for _ in range(args.repeat):
            start = time.perf_counter()
            values = scipy.sparse.linalg.eigsh(K.tocsc(), k=20, M=M.tocsc(), sigma=0, which="LM", return_eigenvectors=True)[0]
            times.append(time.perf_counter() - start)
        values = np.sort(values)
        agree = {solver: np.max(np.abs(values - ours) / ours) for solver, ours in (("block", block), ("krylov-schur", slepc))}
        ratios = "; ".join(f"{solver} {best[ranks, solver]['modes']:.2f} s on {ranks} rank(s) "
                           f"({min(times) / best[ranks, solver]['modes']:.1f}x)"
                           for solver in ("block", "krylov-schur") for ranks in (1, 2))
        print(f"\nModes, K phi = lambda M phi, {K.shape[0]} DOFs, 20 lowest: scipy {scipy.__version__} eigsh "
              f"(shift-invert at 0, SuperLU) {min(times):.2f} s; the bake's modes stage: {ratios}; "
              f"eigenvalues agree with scipy's to {agree['block']:.1e} (block) and {agree['krylov-schur']:.1e} (krylov-schur), relative.")


if __name__ == "__main__":
    main()
