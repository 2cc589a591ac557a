#!/usr/bin/python3
"""The runtime's speed for r = 10, 20, 30, 40, 60 on one core, against the core's FMA peak, against
a plain read of the bytes one evaluation streams, and against Vega FEM's way of stepping
(../shared/tools/vega_like_step.cpp, compiled here at bench time with -O3 -march=native, never copied
into the project), all measured in the same run on the same CPU. Bakes a 1 x 0.1 x 0.1 cantilever
(40 x 4 x 4 cells) at each r, runs bench_runtime on the models (and on the beam baked free at
r = 20 and 30: the step in flight), prints the CPU, the BLAS core the bake's OpenBLAS picks, and
markdown tables (the ones in bench/README.md).

    /usr/bin/python3 bench/runtime.py --build build/release [--shared ../shared]
"""
import argparse
import json
import os
import re
import statistics
import subprocess
import tempfile

from machine import machine_line

RANKS = (10, 20, 30, 40, 60)
FLYING = (20, 30)  # the free beam's r for the flying step


def vega_steps(shared, tmp, repetitions):
    """Median step time (us) of vega_like_step at each r, or {} when ../shared/tools is absent."""
    source = os.path.join(shared, "tools", "vega_like_step.cpp")
    if not os.path.exists(source):
        print(f"(no {source}: the same-run Vega baseline is skipped)")
        return {}
    exe = os.path.join(tmp, "vega_like_step")
    subprocess.run(["g++", "-O3", "-march=native", "-std=c++17", source, "-o", exe], check=True)
    steps = {}
    for r in RANKS:
        times = []
        for _ in range(repetitions):
            out = subprocess.run([exe, "--random", str(r), "--vega-like"], check=True, capture_output=True, text=True).stdout
            times.append(float(re.search(r"step_us=([0-9.eE+-]+)", out).group(1)))
        steps[r] = statistics.median(times)
    return steps


def bake_beams(apps, tmp, basis_sizes, free=False):
    """The 1 x 0.1 x 0.1 cantilever (40 x 4 x 4 cells) baked at each r of basis_sizes on 2 ranks: the .qvr paths.
    free: the same beam with no fixed vertex (a model that can fly)."""
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1", OMPI_MCA_pml="ob1")
    mesh = os.path.join(tmp, "beam.vtu")
    if not os.path.exists(mesh):
        subprocess.run([os.path.join(apps, "quiver-mesh"), "beam", "--size", "1,0.1,0.1", "--cells", "40,4,4", "-o", mesh],
                       check=True)
    models = []
    for r in basis_sizes:
        name = os.path.join(tmp, f"{'free' if free else 'r'}{r}")
        subprocess.run(["mpirun", "-n", "2", os.path.join(apps, "quiver-bake"), mesh,
                        *([] if free else ["--fix", "x<min+1e-9"]), "--modes", "12", "--rank", str(r), "--quiet",
                        "-o", name], check=True, env=env, stdin=subprocess.DEVNULL)
        models.append(name + ".qvr")
    return models


def heading(*columns, text=("solver",)):
    """A markdown table's header row and its alignment row (numbers right, `text` columns left)."""
    print("| " + " | ".join(columns) + " |")
    print("|" + "|".join("---" if c in text else "---:" for c in columns) + "|")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default="build/release")
    ap.add_argument("--repetitions", type=int, default=3)
    ap.add_argument("--shared", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "shared"))
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        models = bake_beams(os.path.join(args.build, "apps"), tmp, RANKS)
        flying = [f"--flying={m}" for m in bake_beams(os.path.join(args.build, "apps"), tmp, FLYING, free=True)]
        out = subprocess.run([os.path.join(args.build, "bench", "bench_runtime"), *models, *flying, "--benchmark_format=json",
                              f"--benchmark_repetitions={args.repetitions}", "--benchmark_report_aggregates_only=true"],
                             check=True, capture_output=True, text=True).stdout
        vega = vega_steps(args.shared, tmp, args.repetitions)
    # The median of the repetitions: robust to the odd disturbed run on a shared machine.
    rows = {b["run_name"]: b for b in json.loads(out)["benchmarks"] if b.get("aggregate_name") == "median"}

    def get(name):
        return rows.get(name)
    peak = get("PeakFma")
    peak_gflops = peak["GFLOPS"] / 1e9 if peak else float("nan")
    print(machine_line())
    print(f"Peak FMA throughput of this core, measured in the same run: {peak_gflops:.1f} GFLOP/s (double, its widest vectors)\n")
    heading("r", "force (us)", "force + stiffness (us)", "energy alone (us)", "Newmark step, fixed Newton (us)",
            "its steps the minimiser took", "Vega-like step, same run (us)", "x Vega", "Newmark step, minimise (us)",
            "its Newton iterations", "evaluation GFLOP/s", "fraction of peak")
    for r in RANKS:
        f, fk, energy = get(f"Evaluate/force/r{r}"), get(f"Evaluate/force+stiffness/r{r}"), get(f"Evaluate/energy/r{r}")
        newton, minimize = get(f"Step/newton/r{r}"), get(f"Step/minimize/r{r}")
        gflops = fk["GFLOPS"] / 1e9
        reference = vega.get(r, float("nan"))
        print(f"| {r} | {f['real_time']:.2f} | {fk['real_time']:.2f} | {energy['real_time']:.2f} | {newton['real_time']:.2f} | "
              f"{newton['minimized']:.2%} | {reference:.1f} | "
              f"{reference / newton['real_time']:.1f} | {minimize['real_time']:.2f} | {minimize['newton_per_step']:.2f} | {gflops:.1f} | {gflops / peak_gflops:.0%} |")
    print("\nCoefficient precision and the memory floor (force + stiffness; *stream* reads the same bytes as "
          "doubles, same run):\n")
    heading("r", "one state reads, f64 (MB)", "evaluation f64 (us)", "stream f64 (us)", "f64 / stream",
            "evaluation f32 (us)", "stream f32 (us)", "f32 / stream", "f32 speed-up", "Newmark step f64 (us)",
            "Newmark step f32 (us)")
    for r in RANKS:
        e64, e32 = get(f"Evaluate/force+stiffness/r{r}"), get(f"Evaluate/force+stiffness/f32/r{r}")
        s64, s32 = get(f"Stream/f64/r{r}"), get(f"Stream/f32/r{r}")
        n64, n32 = get(f"Step/newton/r{r}"), get(f"Step/newton/f32/r{r}")
        print(f"| {r} | {s64['bytes'] / 1e6:.2f} | {e64['real_time']:.2f} | {s64['real_time']:.2f} | "
              f"{e64['real_time'] / s64['real_time']:.1f} | {e32['real_time']:.2f} | {s32['real_time']:.2f} | "
              f"{e32['real_time'] / s32['real_time']:.1f} | {e64['real_time'] / e32['real_time']:.2f} | "
              f"{n64['real_time']:.2f} | {n32['real_time']:.2f} |")
    print("\nGroups of states evaluated at once (force, stiffness and energy, as qv_instances_step "
          "evaluates them): the crowd's arithmetic, against the same run's peak:\n")
    heading("r", "states", "group f64 (us)", "GFLOP/s", "fraction of peak", "group f32 (us)", "1000 states f64 (ms)",
            "1000 states at the peak (ms)")
    for r in RANKS:
        g64, g32 = get(f"EvaluateGroup/r{r}"), get(f"EvaluateGroup/f32/r{r}")
        gflops, groups = g64["GFLOPS"] / 1e9, 1000 / g64["states"]
        print(f"| {r} | {int(g64['states'])} | {g64['real_time']:.1f} | {gflops:.1f} | {gflops / peak_gflops:.0%} | "
              f"{g32['real_time']:.1f} | {g64['real_time'] * groups / 1e3:.2f} | "
              f"{g64['real_time'] * groups / 1e3 * gflops / peak_gflops:.2f} |")
    print("\nMany objects: 1000 instances per frame on one core, each under its own push (bench/runtime.cpp):\n")
    heading("r", "solver", "one by one (ms per frame)", "qv_instances_step (ms per frame)", "speed-up", "resets",
            "fixed Newton steps the minimiser took")
    for r in (20, 30):
        for solver in ("newton", "minimize"):
            alone, together = get(f"ManyObjects/{solver}/one-by-one/r{r}/1000"), get(f"ManyObjects/{solver}/together/r{r}/1000")
            if alone and together:
                print(f"| {r} | {solver} | {alone['real_time']:.2f} | {together['real_time']:.2f} | "
                      f"{alone['real_time'] / together['real_time']:.2f} | {int(alone['resets'] + together['resets'])} | "
                      f"{int(alone['minimized'] + together['minimized'])} |")

    print("\nFree flight: the same beam baked free, one instance in flight (spun at (0, 3, 10) rad/s, pushed on a "
          "corner), against the same push on the model without flight (bench/runtime.cpp, FlyingStep):\n")
    heading("r", "flying step (us)", "its Newton iterations", "unmoved step (us)", "its Newton iterations", "ratio",
            "resets")
    for r in FLYING:
        fly, still = get(f"Flying/step/r{r}"), get(f"Flying/unmoved/r{r}")
        if not (fly and still):
            print(f"| {r} | (not measured) |")
            continue
        print(f"| {r} | {fly['real_time']:.2f} | {fly['newton_per_step']:.2f} | {still['real_time']:.2f} | "
              f"{still['newton_per_step']:.2f} | {fly['real_time'] / still['real_time']:.2f} | "
              f"{int(fly['resets'] + still['resets'])} |")


if __name__ == "__main__":
    main()
