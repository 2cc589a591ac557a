#!/usr/bin/python3
"""The default solver (QV_SOLVER_MINIMIZE) as a user meets it, on meshes it was not built around: the
public polyfem bar-2523 (slivers: smallest normalised volume 0.02, dihedral angles down to 1.3
degrees) and a beam whose vertices the test jitters into slivers. Each is baked as a user would (fixed
over 8% of its length, E = 1 MPa, nu = 0.4, 20 modes, r = 30), then dragged sideways by half and by the
whole length, twisted by 60 and 180 degrees with stiff springs (1e5 N/m per vertex) at 120 Hz, pulled
under gravity at 1/30 s steps, and let go at once. No step may reset, with either solver (the fixed
Newton step hands the steps it cannot take to the minimiser), and after the release, with no
damping, kinetic + elastic energy may never exceed what it was at the release.

And the bake on a spectrum spread over decades (slender beams whose 20 modes span 250x in frequency,
6e4 in eigenvalue): every basis recipe bakes, more vectors than the recipe yields give a warning
and the largest r (or, with --exact-rank, a clear error), keep-modes reproduces every baked
frequency exactly, and the result steps through a hard drag without a reset."""
import csv
import json
import os
import subprocess
import tempfile
import unittest

import numpy as np

BAKE = os.environ["QUIVER_BAKE"]
MESH = os.environ["QUIVER_MESH"]
QUIVER = os.environ["QUIVER"]
MPIEXEC = os.environ.get("MPIEXEC") or "mpirun"
SHARED = os.environ.get("QUIVER_SHARED_MESHES", "")


def run(*args, codes=(0,)):
    p = subprocess.run([*map(str, args)], capture_output=True, text=True, stdin=subprocess.DEVNULL, timeout=600)
    assert p.returncode in codes, p.stderr
    return p


def jittered_beam(folder):
    """A 1 x 0.2 x 0.2 beam of 20 x 4 x 4 cells whose interior vertices move by up to 45% of a cell,
    as far as every tet stays positive: a mesh full of slivers."""
    import meshio
    path = os.path.join(folder, "grid.vtu")
    run(MESH, "beam", "--size", "1,0.2,0.2", "--cells", "20,4,4", "-o", path)
    m = meshio.read(path)
    points, tets = m.points.copy(), m.cells_dict["tetra"]
    h = np.array([0.05, 0.05, 0.05])
    lo, hi = points.min(axis=0), points.max(axis=0)
    inside = np.all((points > lo + 1e-9) & (points < hi - 1e-9), axis=1)
    rng = np.random.default_rng(7)

    def volumes(p):
        a, b, c, d = (p[tets[:, i]] for i in range(4))
        return np.einsum("ij,ij->i", np.cross(b - a, c - a), d - a)

    for v in np.nonzero(inside)[0]:
        step = rng.uniform(-0.45, 0.45, 3) * h
        for _ in range(6):  # halve the move until no tet turns over
            trial = points.copy()
            trial[v] += step
            if volumes(trial).min() > 0:
                points = trial
                break
            step /= 2
    out = os.path.join(folder, "jittered.vtu")
    meshio.write(out, meshio.Mesh(points, [("tetra", tets)]))
    return out


class RobustStep(unittest.TestCase):
    models = {}

    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        d = cls.tmp.name
        meshes = {}
        try:
            meshes["jittered beam"] = (jittered_beam(d), 1.0)
        except ImportError:
            print("python3-meshio not installed: skipping the jittered beam")
        bar = os.path.join(SHARED, "polyfem_bar-2523.msh")
        if os.path.exists(bar):
            meshes["polyfem bar-2523"] = (bar, 10.0)
        else:
            print(f"shared mesh folder absent ({SHARED}): skipping polyfem bar-2523")
        for name, (path, length) in meshes.items():
            info = json.loads(run(MESH, "info", path).stdout)
            out = os.path.join(d, name.replace(" ", "_"))
            run(MPIEXEC, "-n", "2", "--oversubscribe", BAKE, path, "--fix", f"x<min+{0.08 * length}", "--E", "1e6",
                "--nu", "0.4", "--density", "1000", "--modes", "20", "--rank", "30", "--quiet", "-o", out)
            cls.models[name] = (out + ".qvr", length, info["quality"]["normalised_volume"]["min"])

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def sim(self, model, length, *args, codes=(0,)):
        out = os.path.join(self.tmp.name, "run")
        p = run(QUIVER, "sim", model, "--group", f"x>max-{0.08 * length}", "--json", "-o", out, "--every", 1000,
                *args, codes=codes)
        with open(out + ".csv") as f:
            rows = list(csv.DictReader(f))
        return json.loads(p.stdout), rows

    def test_meshes_have_slivers(self):
        if not self.models:
            self.skipTest("no mesh to test")
        for name, (_, _, smallest) in self.models.items():
            self.assertLess(smallest, 0.05, name)

    def test_hard_interactions_never_reset(self):
        if not self.models:
            self.skipTest("no mesh to test")
        for name, (model, L, _) in self.models.items():
            held = ["--hold", 120, "--steps", 240, "--dt", 1 / 120, "--stiffness", 1e5]
            for label, args in (("drag by half the length", [*held, "--drag", f"0,{L / 2},0"]),
                                ("drag by the whole length", [*held, "--drag", f"0,{L},0"]),
                                ("twist 60 degrees", [*held, "--twist", 60]),
                                ("twist 180 degrees", [*held, "--twist", 180]),
                                ("pull under gravity at 1/30 s", ["--hold", 30, "--steps", 60, "--dt", 1 / 30,
                                                                   "--gravity", "--force", "0,0,-200"]),
                                ("drag by the whole length at 1/30 s", ["--hold", 30, "--steps", 60, "--dt", 1 / 30,
                                                                        "--stiffness", 1e5, "--drag", f"0,{L},0"])):
                with self.subTest(mesh=name, scenario=label):
                    j, rows = self.sim(model, L, *args)
                    newton, _ = self.sim(model, L, *args, "--solver", "newton", "--newton", 1)
                    print(f"{name}, {label}: {j['resets']} resets (fixed Newton: {newton['resets']}, "
                          f"{newton['minimized_steps']} of its steps taken by the minimiser), "
                          f"{j['newton_iterations_mean']:.2f} Newton iterations a step, {j['held_back_steps']} held back, "
                          f"{j['energy_removed_J']:.3g} J taken out, {j['step_us_median']:.0f} us a step")
                    self.assertEqual(j["resets"], 0)
                    self.assertEqual(newton["resets"], 0)
                    self.assertTrue(all(np.isfinite(float(r["elastic_J"])) for r in rows))

    def twist_and_release(self, model, length, integrator, *args):
        """Twisted 180 degrees by stiff springs for 1 s at 120 Hz, then let go for 4 s, undamped: the
        run's JSON, the kinetic + elastic energy the springs let go of, and that of each step after."""
        j, rows = self.sim(model, length, "--hold", 120, "--steps", 600, "--dt", 1 / 120, "--stiffness", 1e5,
                           "--twist", 180, "--alpha", 0, "--beta", 0, "--integrator", integrator, *args)
        energy = np.array([float(r["kinetic_J"]) + float(r["elastic_J"]) for r in rows])
        return j, energy[119], energy[120:]

    def test_energy_never_grows_after_release_without_damping(self):
        if not self.models:
            self.skipTest("no mesh to test")
        for name, (model, L, _) in self.models.items():
            for integrator in ("newmark", "euler"):
                with self.subTest(mesh=name, integrator=integrator):
                    _, released, after = self.twist_and_release(model, L, integrator)
                    print(f"{name}, {integrator}: energy at release {released:.4g} J, then {after.min():.4g} .. "
                          f"{after.max():.4g} J, drift over {len(after)} steps {(after[-1] - released) / released:+.2%}")
                    self.assertGreater(released, 0)
                    self.assertLessEqual(after.max(), released * (1 + 1e-5))  # the CSV prints 6 digits
                    # No lower bound here: after a 180-degree twist of a sliver mesh the energy the trapezoidal
                    # rule trades with the budget swings widely and the phase at any one step differs between bakes.
                    # That the budget keeps energy (wipes no velocity) is the lower bound of
                    # Step.UndampedNewmarkEnergyDipsAtSecondOrderAndNeverGrows, on a model of its own.

    def test_fixed_newton_energy_stays_within_the_release_but_for_single_steps(self):
        """The fixed Newton step (one iteration) holds the same budget one step late: a step may end
        above it until the next starts, and after a step's end is drawn back the next 60 are held at
        once (runtime/src/integrators/fixed_newton.h). Measured: 6-7 of 480 step ends above the release's
        energy on the jittered beam, never two in a row, none on bar-2523; runtime 0.11 ended 84% and
        99% of them above, with a median of 33 and 9e6 times the release energy. Which steps end above
        depends on the last bits (the beam's last step did in one build, 2.0 times the release), and an
        excess the velocity takes out arms no end checks, so two in a row may happen: three may not."""
        if not self.models:
            self.skipTest("no mesh to test")
        for name, (model, L, _) in self.models.items():
            for integrator in ("newmark", "euler"):
                with self.subTest(mesh=name, integrator=integrator):
                    j, released, after = self.twist_and_release(model, L, integrator, "--solver", "newton", "--newton", 1)
                    high = after > released * 1.01
                    in_a_row = int(np.sum(high[1:] & high[:-1]))  # pairs of consecutive step ends above
                    three = int(np.sum(high[2:] & high[1:-1] & high[:-2]))
                    print(f"{name}, {integrator}, fixed Newton: energy at release {released:.4g} J, {np.mean(high):.1%} "
                          f"of the steps after it end above ({in_a_row} right after another), median "
                          f"{np.median(after) / released:.3g} of it, over the last second "
                          f"{np.median(after[-120:]) / released:.3g}; {j['held_back_steps']} drawn back")
                    self.assertEqual(j["resets"], 0)
                    self.assertLess(np.mean(high), 0.03)
                    self.assertEqual(three, 0)
                    self.assertLess(np.median(after), released)
                    self.assertLess(np.median(after[-120:]), released)


class SpreadSpectrum(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.beams = {}
        for length in (20, 30):
            path = os.path.join(cls.tmp.name, f"slender{length}.vtu")
            run(MESH, "beam", "--size", f"{length},0.1,0.1", "--cells", f"{10 * length},1,1", "-o", path)
            cls.beams[length] = path

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def bake(self, length, *args, codes=(0,)):
        out = os.path.join(self.tmp.name, f"b{length}")
        p = run(MPIEXEC, "-n", "2", "--oversubscribe", BAKE, self.beams[length], "--fix", f"x<min+{0.08 * length}",
                "--E", "1e6", "--nu", "0.4", "--density", "1000", "--modes", "20", "--quiet", "-o", out, *args,
                codes=codes)
        return out, p

    def test_every_recipe_bakes_and_says_when_r_is_smaller(self):
        for length in (20, 30):
            for kind, rank, expect in (("pca", 30, 30), ("keep-modes", 60, 60), ("modes", 30, 20)):
                with self.subTest(length=length, basis=kind, rank=rank):
                    out, p = self.bake(length, "--basis", kind, "--rank", rank)
                    info = json.loads(run(QUIVER, "info", out + ".qvr").stdout)
                    hz = np.array(info["frequencies_hz"])
                    self.assertGreater(hz[-1] / hz[0], 200, "the spectrum must be spread")
                    self.assertEqual(info["r"], expect)
                    self.assertEqual("warning" in p.stderr, expect < rank, p.stderr)
            # More than the mass-PCA can resolve (57-60 of the 230 vectors): a warning and the largest r,
            # or with --exact-rank an error.
            out, p = self.bake(length, "--basis", "pca", "--rank", 100)
            info = json.loads(run(QUIVER, "info", out + ".qvr").stdout)
            self.assertLess(info["r"], 100)
            self.assertIn(f"r = {info['r']} instead of 100", p.stderr)
            _, p = self.bake(length, "--basis", "pca", "--rank", 100, "--exact-rank", codes=(1,))
            self.assertIn("--exact-rank", p.stderr)
            self.assertEqual(p.stderr.count("error"), 1, p.stderr)  # one message, not one per rank

    def test_keep_modes_reproduces_every_baked_frequency(self):
        out, _ = self.bake(30, "--basis", "keep-modes", "--rank", 40)
        info = json.loads(run(QUIVER, "info", out + ".qvr").stdout)
        baked, reduced = np.array(info["frequencies_hz"]), np.sort(info["reduced_frequencies_hz"])[:20]
        np.testing.assert_allclose(reduced, baked, rtol=1e-6)
        # The bake's fidelity report says the same through quiver info, and what it could not measure.
        report = info["fidelity"]
        self.assertEqual(list(report["cases"]), ["own weight", "pull", "twist 30", "twist 60"])
        self.assertLess(np.max(np.abs(report["frequency_errors"])), 1e-6)
        self.assertEqual(len(report["frequency_errors"]), 20)
        weight = report["cases"]["own weight"]["displacement_error"]  # a 30 m beam may fold: null, not measured
        self.assertTrue(weight is None or np.isfinite(weight))
        self.assertTrue(np.isfinite(report["cases"]["pull"]["displacement_error"]))
        none, _ = self.bake(30, "--basis", "modes", "--rank", 10, "--no-fidelity")
        self.assertIsNone(json.loads(run(QUIVER, "info", none + ".qvr").stdout)["fidelity"])
        pca, _ = self.bake(30, "--basis", "pca", "--rank", 30)
        info = json.loads(run(QUIVER, "info", pca + ".qvr").stdout)
        worst = np.max(np.abs(np.sort(info["reduced_frequencies_hz"])[:20] / baked - 1))
        print(f"slender beam, 20 modes spanning {baked[-1] / baked[0]:.0f}x: keep-modes holds them to 1e-6, "
              f"pca (r = 30) to {worst:.1%}")

    def test_the_spread_model_steps_through_a_hard_drag(self):
        out, _ = self.bake(30, "--basis", "keep-modes", "--rank", 40)
        p = run(QUIVER, "sim", out + ".qvr", "--group", "x>max-2.4", "--drag", "0,15,0", "--stiffness", 1e4,
                "--hold", 120, "--steps", 240, "--dt", 1 / 60, "--json")
        self.assertEqual(json.loads(p.stdout)["resets"], 0)


class FidelityAgainstFullSpace(unittest.TestCase):
    """The bake's fidelity report against runs it has no part in: the full-space reference (quiver full) and
    the runtime (quiver sim) each let a beam settle under its own weight, heavily damped, and the relative
    difference of their rest shapes is the report's "own weight" error; the report's frequency errors are
    the runtime's reduced frequencies against the baked ones."""

    def test_own_weight_and_frequencies(self):
        try:
            import meshio
        except ImportError:
            self.skipTest("python3-meshio not installed")
        with tempfile.TemporaryDirectory() as d:
            mesh, out = os.path.join(d, "beam.vtu"), os.path.join(d, "beam")
            material = ["--E", "1e8", "--nu", "0.4", "--density", "1000"]
            run(MESH, "beam", "--size", "1,0.1,0.1", "--cells", "10,2,2", "-o", mesh)
            run(BAKE, mesh, "--fix", "x<min+1e-9", *material, "--modes", 10, "--rank", 20, "--quiet", "-o", out)
            info = json.loads(run(QUIVER, "info", out + ".qvr").stdout)
            report = info["fidelity"]
            # alpha = 64/s damps the first bending mode (32 rad/s) critically: 2 s leave e^-64 of the motion.
            settle = ["--gravity", "--hold", 400, "--steps", 400, "--dt", 0.005, "--alpha", 64, "--beta", 0]
            full = os.path.join(d, "full.npy")
            run(QUIVER, "full", mesh, "--fix", "x<min+1e-9", *material, *settle, "--final-npy", full)
            run(QUIVER, "sim", out + ".qvr", *settle, "-o", os.path.join(d, "sim"), "--every", 400)
            u_full = np.load(full).reshape(-1, 3)
            u_reduced = meshio.read(os.path.join(d, "sim_00400.vtu")).point_data["displacement"]
            error = np.linalg.norm(u_reduced - u_full) / np.linalg.norm(u_full)
            weight = report["cases"]["own weight"]
            print(f"own weight: report {weight['displacement_error']:.4%}, quiver full vs quiver sim {error:.4%}")
            self.assertGreater(error, 1e-5)  # a real difference to compare, not round-off
            self.assertAlmostEqual(weight["displacement_error"] / error, 1, delta=0.05)
            box = np.array(info["bbox"]["max"]) - np.array(info["bbox"]["min"])
            largest = np.linalg.norm(u_full, axis=1).max() / np.linalg.norm(box)
            self.assertAlmostEqual(weight["largest_displacement"] / largest, 1, delta=1e-3)
            baked, reduced = np.array(info["frequencies_hz"]), np.sort(info["reduced_frequencies_hz"])
            np.testing.assert_allclose(report["frequency_errors"], reduced[:len(baked)] / baked - 1, atol=1e-7)


if __name__ == "__main__":
    unittest.main(verbosity=2)
