#!/usr/bin/python3
"""Time of the bake's polynomial stage (computeEnergyPolynomial, exact reduced StVK energy) on the
shared meshes for r = 10, 20, 30, 40 on 1 and 2 MPI ranks of one thread, and on 1 rank of 2 threads
(as quiver-bake runs alone on a machine of 2 cores), with the achieved FLOP rate as a fraction of
this machine's single-thread DGEMM peak times the cores at work, measured in the same run. Prints
a markdown table (the one in bench/README.md).

    /usr/bin/python3 bench/polynomials.py --build build/release [--meshes ../shared/meshes] [--repeat 2] [--runs 2]

bench_polynomials times each r between MPI barriers, at least --repeat times and for at least
half a second, and keeps the fastest; each rank count runs --runs
times (1, 2, 1 x 2, 1, ... ranks x threads) and the fastest time per r is kept (least disturbed by
the machine); runs whose DGEMM rate fell under 95% of the best seen (another process shared a core)
are set aside, and a configuration with no clean run is measured again, up to --retries times. FLOPs
are the dsyrk's, K N (N + 1) with N = r + r(r+1)/2 and K = 6 tets (no Vega ratio: there is no
same-run baseline of Vega's precomputation, and figures from other machines are not compared);
"dsyrk share" is the time of the stage's dsyrk calls alone (same shapes, in the same run) over
the stage's time on one thread, the rest being the per-tet row building; "speed-up" is the time on
1 rank of 1 thread over the row's."""
import argparse
import csv
import os
import re
import subprocess
import sys

MESHES = [f"polyfem_bar-{n}.msh" for n in (186, 651, 2523, 14114)]
MESHES += ["vega_simpleBridge_tet.veg", "polyfem_cubes_v41.msh"]
RS = (10, 20, 30, 40)
BLAS_LINE = re.compile(r"^# r = (\d+): .*dsyrk alone ([0-9.e+-]+) s")


CONFIGURATIONS = ((1, 1), (2, 1), (1, 2))  # (ranks, threads per rank)


def run(program, mesh, ranks, threads, repeat):
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1", OMPI_MCA_pml="ob1")
    # mpirun binds each rank to one core: a rank of more threads must be let off it.
    binding = ["--bind-to", "none"] if threads > 1 else []
    cmd = ["mpirun", "-n", str(ranks), *binding, program, mesh, "--r", ",".join(map(str, RS)), "--repeat", str(repeat),
           "--threads", str(threads)]
    p = subprocess.run(cmd, capture_output=True, text=True, env=env, stdin=subprocess.DEVNULL)
    if p.returncode != 0:
        sys.exit(f"failed: {' '.join(cmd)}\n{p.stderr}")
    notes = [line[2:].split(";")[0] for line in p.stdout.splitlines() if line.startswith("# OpenBLAS")]
    rows = {int(row["r"]): row for row in csv.DictReader(l for l in p.stdout.splitlines() if not l.startswith("#"))}
    for m in filter(None, map(BLAS_LINE.match, p.stdout.splitlines())):
        rows[int(m.group(1))]["dsyrk_alone"] = m.group(2)
    return rows, notes


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default="build/release")
    ap.add_argument("--meshes", default=os.path.join(os.path.dirname(__file__), "..", "..", "shared", "meshes"))
    ap.add_argument("--repeat", type=int, default=2, help="timings per r inside one run (best kept)")
    ap.add_argument("--runs", type=int, default=2, help="separate runs per rank count, alternating (best kept)")
    ap.add_argument("--retries", type=int, default=4, help="new runs of a rank count whose DGEMM rate was disturbed")
    args = ap.parse_args()
    program = os.path.join(args.build, "bench", "bench_polynomials")
    if not os.path.exists(program):
        sys.exit(f"{program} not found: build target bench_polynomials (QUIVER_BUILD_BENCH and QUIVER_BUILD_BAKE on)")
    print("| mesh | tets | r | ranks | threads | seconds | us/tet | tets·r⁴/s | GFLOP/s | DGEMM peak/core | "
          "fraction of peak | dsyrk share | speed-up |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    notes = set()
    best_peak = 0.0  # the best per-rank DGEMM rate seen so far: the undisturbed machine
    retries = []
    for name in MESHES:
        mesh = os.path.join(args.meshes, name)
        if not os.path.exists(mesh):
            sys.exit(f"{mesh} not found: pass --meshes")
        runs = {c: [] for c in CONFIGURATIONS}  # per configuration: one {r: row} per run

        def measure(configuration):
            nonlocal best_peak
            rows, n = run(program, mesh, *configuration, args.repeat)
            notes.update(n)
            best_peak = max([best_peak] + [float(row["dgemm_peak_gflops_per_rank"]) for row in rows.values()])
            runs[configuration].append(rows)

        def clean(rows):
            return all(float(row["dgemm_peak_gflops_per_rank"]) >= 0.95 * best_peak for row in rows.values())

        for _ in range(args.runs):
            for configuration in CONFIGURATIONS:
                measure(configuration)
        # A rank that shared its core with another process shows it in its DGEMM rate: such runs
        # are set aside, and the configuration runs again if none was clean.
        results = {}
        for configuration in CONFIGURATIONS:
            for _ in range(args.retries):
                if any(map(clean, runs[configuration])):
                    break
                retries.append(f"{name} on {configuration[0]} rank(s) of {configuration[1]} thread(s)")
                measure(configuration)
            kept = [rows for rows in runs[configuration] if clean(rows)] or runs[configuration]
            results[configuration] = {r: min((rows[r] for rows in kept), key=lambda row: float(row["seconds"]))
                                      for r in RS}
        for r in RS:
            for ranks, threads in CONFIGURATIONS:
                row = results[ranks, threads][r]
                seconds, us = float(row["seconds"]), float(row["us_per_tet"])
                alone = (ranks, threads) == (1, 1)
                speedup = "" if alone else f"{float(results[1, 1][r]['seconds']) / seconds:.2f}"
                share = f"{float(row['dsyrk_alone']) / seconds:.2f}" if threads == 1 else ""
                print(f"| {name} | {row['tets']} | {r} | {ranks} | {threads} | {seconds:.4f} | {us:.1f} | "
                      f"{float(row['tets_r4_per_s']):.3g} | {float(row['gflops']):.1f} | "
                      f"{float(row['dgemm_peak_gflops_per_rank']):.1f} | {float(row['fraction_of_peak']):.2f} | "
                      f"{share} | {speedup} |",
                      flush=True)
    for note in sorted(notes):
        print(f"\n{note}")
    if retries:
        print(f"\nMeasured again (DGEMM rate under 95% of the best, {best_peak:.1f} GFLOP/s, in every run): " +
              "; ".join(retries))


if __name__ == "__main__":
    main()
