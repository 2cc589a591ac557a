#!/usr/bin/python3
"""Two versions of the runtime alternated on this CPU, for changes smaller than a shared machine's
noise (on this project's VMs the same crowd read 16 to 23 ms within minutes while the FMA peak held:
neighbours fill the shared caches). Builds bench_runtime at --base (a commit, in a temporary
worktree: the runtime and the bench alone, about 15 s) unless --base names a bench_runtime binary,
bakes the cantilever at r as bench/runtime.py does, and runs the two binaries in turn, --runs times
each, every run with this core's FMA peak measured in it. Prints the CPU and BLAS core, then each
benchmark's median and fastest run for both and the median's ratio.

    /usr/bin/python3 bench/ab.py --base 811b657 [--build build/release] [--r 30] [--runs 8] [--seconds 1]
        [--filter 'ManyObjects/.*/together|EvaluateGroup/r'] [--flying (and the Flying/ benchmarks)]
"""
import argparse
import json
import os
import statistics
import subprocess
import tempfile

from machine import machine_line
from runtime import bake_beams

REPOSITORY = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def quietly(command):
    """Runs `command`; on failure, stops with its output."""
    p = subprocess.run(command, capture_output=True, text=True)
    if p.returncode != 0:
        raise SystemExit(f"{' '.join(command)} failed:\n{p.stdout}{p.stderr}")


def build_base(commit, tmp):
    """bench_runtime built at `commit` in a worktree under tmp, the worktree removed again."""
    source = os.path.join(tmp, "base")
    quietly(["git", "-C", REPOSITORY, "worktree", "add", "--detach", "-q", source, commit])
    try:
        quietly(["cmake", "-S", source, "-B", os.path.join(source, "build"), "-G", "Ninja", "-DCMAKE_BUILD_TYPE=Release",
                 *[f"-DQUIVER_BUILD_{part}=OFF" for part in ("BAKE", "TESTS", "PYTHON", "VIEWER", "EXAMPLES", "TOOLS")],
                 "-DQUIVER_BUILD_BENCH=ON"])
        quietly(["ninja", "-C", os.path.join(source, "build"), "bench_runtime"])
        binary = os.path.join(tmp, "bench_runtime_base")
        os.replace(os.path.join(source, "build", "bench", "bench_runtime"), binary)
        return binary
    finally:
        subprocess.run(["git", "-C", REPOSITORY, "worktree", "remove", "--force", source])


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--base", required=True, help="a commit, or a bench_runtime binary")
    ap.add_argument("--build", default="build/release", help="the build of the new version (its bench_runtime, its bake)")
    ap.add_argument("--r", type=int, default=30)
    ap.add_argument("--runs", type=int, default=8)
    ap.add_argument("--seconds", type=float, default=1.0, help="each benchmark's time in each run")
    ap.add_argument("--filter", default="ManyObjects/.*/together|EvaluateGroup/r")
    ap.add_argument("--flying", action="store_true",
                    help="also bake the beam free and time the Flying/ benchmarks (the base must have them: since 54c748e)")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        base = args.base if os.path.isfile(args.base) else build_base(args.base, tmp)
        binaries = {"base": base, "new": os.path.join(args.build, "bench", "bench_runtime")}
        models = bake_beams(os.path.join(args.build, "apps"), tmp, [args.r])
        if args.flying:
            args.filter += "|Flying/"
            models += [f"--flying={m}" for m in bake_beams(os.path.join(args.build, "apps"), tmp, [args.r], free=True)]
        times, peaks = {}, {"base": [], "new": []}
        for run in range(args.runs):
            for side in ("base", "new") if run % 2 == 0 else ("new", "base"):
                binary = binaries[side]
                out = subprocess.run([binary, *models, f"--benchmark_filter=PeakFma|{args.filter}", "--benchmark_format=json",
                                      f"--benchmark_min_time={args.seconds}"], check=True, capture_output=True, text=True).stdout
                for b in json.loads(out)["benchmarks"]:
                    if b["name"] == "PeakFma":
                        peaks[side].append(b["GFLOPS"] / 1e9)
                    else:
                        times.setdefault(f"{b['name']} ({b['time_unit']})", {"base": [], "new": []})[side].append(b["real_time"])
    print(machine_line())
    if peaks["base"] and peaks["new"]:
        print(f"FMA peak in the runs: base {min(peaks['base']):.1f}-{max(peaks['base']):.1f}, "
              f"new {min(peaks['new']):.1f}-{max(peaks['new']):.1f} GFLOP/s; {args.runs} runs each, alternated\n")
    else:
        print(f"(no FMA peak: this CPU has neither AVX2 nor AVX-512); {args.runs} runs each, alternated\n")
    print("| benchmark | base median | base fastest | new median | new fastest | new / base (medians) |")
    print("|---|---:|---:|---:|---:|---:|")
    for name, sides in times.items():
        b, n = sides["base"], sides["new"]
        print(f"| {name} | {statistics.median(b):.4g} | {min(b):.4g} | {statistics.median(n):.4g} | {min(n):.4g} | "
              f"{statistics.median(n) / statistics.median(b):.3f} |")


if __name__ == "__main__":
    main()
