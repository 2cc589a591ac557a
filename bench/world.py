#!/usr/bin/python3
"""Worlds of free bodies in contact: N soft bars dropped in layers of four onto the ground and onto
each other (`quiver sim --free --gravity --pile N`), one world step each frame on one thread, the
median and 99th percentile of its wall time over 10 simulated seconds at 60 Hz, with sleeping off
(`--sleep-speed 0`: every body stepped and its contacts solved to the end) and on (the default: the
groups that have come to rest sleep). Bakes the bar (0.6 x 0.1 x 0.1 m, E = 1 MPa, no fixed vertex,
10 modes and their derivatives, r = 16) on 2 ranks. Then N bars apart on the ground (`--spread`:
each touches the ground only, as objects scattered over a level), where the cost once they rest is
what sleeping leaves: finding which bodies could touch. Each world with the contacts on the bars'
rigid shapes (the default) and with soft contacts (`--soft-contacts`: on their deformed surfaces,
which give way where they push).

    /usr/bin/python3 bench/world.py --build build/release [--piles 20,80,320] [--spread 1024] [--contacts rigid,soft]

With --against QUIVER (another build's `quiver`, e.g. one built at an earlier commit), compares the
two instead, kept awake (`--sleep-speed 0`), with each of --contacts: each pile, the spread and one
bar resting alone (no world), --runs alternated runs of --steps steps each, their medians and ratio.

    /usr/bin/python3 bench/world.py --build build/release --against /tmp/quiver_before [--runs 3] [--steps 600]

With --threads T, compares the build's world steps on one thread and on T (`quiver sim --threads`,
qv_world_set_jobs) the same way, the piles and the spread only.

    /usr/bin/python3 bench/world.py --build build/release --threads 2 [--runs 3] [--steps 600]
"""
import statistics
import argparse
import json
import os
import subprocess
import tempfile

from machine import machine_line

ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1", OMPI_MCA_pml="ob1")
STEPS = 600


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default="build/release")
    ap.add_argument("--piles", default="20,80,320")
    ap.add_argument("--spread", type=int, default=1024)
    ap.add_argument("--contacts", default="rigid,soft", help="comma-separated: rigid (the default contacts), soft")
    ap.add_argument("--against", help="another build's quiver binary: compare the two (see above)")
    ap.add_argument("--threads", type=int, help="compare one thread against this many (see above)")
    ap.add_argument("--runs", type=int, default=3, help="with --against or --threads: alternated runs of each")
    ap.add_argument("--steps", type=int, default=STEPS, help="steps of 1/60 s a run")
    args = ap.parse_args()
    if args.against and args.threads:
        ap.error("--against and --threads: one comparison at a time")
    if not set(args.contacts.split(",")) <= {"rigid", "soft"}:
        ap.error(f"--contacts: expected rigid, soft or rigid,soft, not '{args.contacts}'")
    apps = os.path.join(args.build, "apps")
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        mesh, bar = os.path.join(tmp, "bar.vtu"), os.path.join(tmp, "bar")
        subprocess.run([os.path.join(apps, "quiver-mesh"), "beam", "--size", "0.6,0.1,0.1", "--cells", "12,2,2",
                        "-o", mesh], check=True, capture_output=True)
        subprocess.run(["mpirun", "-n", "2", os.path.join(apps, "quiver-bake"), mesh, "--modes", "10", "--rank", "16",
                        "--quiet", "-o", bar], check=True, env=ENV, stdin=subprocess.DEVNULL, capture_output=True)
        worlds = [(int(x), []) for x in args.piles.split(",")] + [(args.spread, ["--spread"])]
        quiver = os.path.join(apps, "quiver")
        if args.against:
            return compare(args, bar + ".qvr", worlds + [("one bar alone", None)],
                           [(args.against, args.against, []), (quiver, quiver, [])])
        if args.threads:
            return compare(args, bar + ".qvr", worlds,
                           [("1 thread", quiver, []), (f"{args.threads} threads", quiver, ["--threads", str(args.threads)])])
        for n, layout in worlds:
            for contacts in args.contacts.split(","):
                for sleep in ("0", "0.02"):
                    soft = ["--soft-contacts"] if contacts == "soft" else []
                    j = simulate(quiver, bar + ".qvr", ["--pile", str(n), *layout, *soft, "--sleep-speed", sleep], args.steps,
                                 f"quiver sim --pile {n}")
                    rows.append((f"{n} apart" if layout else str(n), contacts, "off" if sleep == "0" else f"{sleep} m/s", j))
    print(machine_line() + f"; one thread, {args.steps} steps of 1/60 s\n")
    print("| bodies | contacts | sleeping | world step, median (ms) | 99th percentile (ms) | median per body (us) "
          "| asleep at the end | fastest body at the end (m/s) | deepest deformed-vertex penetration (mm) | resets |")
    print("|---:|---|---|---:|---:|---:|---:|---:|---:|---:|")
    for n, contacts, sleep, j in rows:
        bodies = j["bodies"]
        print(f"| {n} | {contacts} | {sleep} | {j['step_us_median'] / 1e3:.2f} | {j['step_us_p99'] / 1e3:.1f} | {j['step_us_median'] / bodies:.1f} "
              f"| {j['asleep_at_end']} | {j['max_final_speed_mps']:.1g} "
              f"| {j['max_penetration_m'] * 1e3:.0f} | {j['resets']} |")


def simulate(quiver, model, options, steps, what):
    """`quiver sim` of the bar dropped onto the ground with `options`, its JSON; exit code 2 (some
    step reset) is a result, which the tables count."""
    sim = subprocess.run([quiver, "sim", model, "--free", "--gravity", *options, "--position", "0,0,0.2",
                          "--collider", "plane:0,0,1,0", "--steps", str(steps), "--json"],
                         capture_output=True, text=True, stdin=subprocess.DEVNULL)
    if sim.returncode not in (0, 2):
        raise SystemExit(f"{what} failed ({sim.returncode}): {sim.stderr.strip()}")
    return json.loads(sim.stdout)


def compare(args, model, worlds, sides):
    """--against or --threads: each world (kept awake; ("one bar alone", None): one bar resting, no
    world) with each kind of contacts, the two sides alternated. sides: (label, quiver, options) twice."""
    cases = []
    for contacts in args.contacts.split(","):
        soft = ["--soft-contacts"] if contacts == "soft" else []
        for n, layout in worlds:
            if layout is None:
                name, options = n, []
            else:
                name, options = f"{n} apart" if layout else f"pile of {n}", ["--pile", str(n), *layout, "--sleep-speed", "0"]
            cases.append((f"{name}, {contacts} contacts", options + soft))
    print(machine_line() + f"; {args.steps} steps of 1/60 s, {args.runs} alternated runs each, medians\n")
    print(f"| world | {sides[0][0]} (ms) | {sides[1][0]} (ms) | ratio |")
    print("|---|---:|---:|---:|")
    for name, options in cases:
        times = [[], []]
        for _ in range(args.runs):
            for k, (label, binary, extra) in enumerate(sides):
                times[k].append(simulate(binary, model, options + extra, args.steps, f"{label} sim ({name})")["step_us_median"] / 1e3)
        before, after = statistics.median(times[0]), statistics.median(times[1])
        print(f"| {name} | {before:.3f} | {after:.3f} | {after / before:.2f} |")


if __name__ == "__main__":
    main()
