#!/usr/bin/python3
"""A baked .qvr through `quiver info` / `quiver eval`, which run on the runtime library alone:
sizes against the documented formula, the modal model's stiffness against the bake's eigenvalues,
force and stiffness against finite differences of the energy, and damaged files refused."""
import json
import os
import subprocess
import tempfile
import unittest
import xml.etree.ElementTree

import numpy as np

BAKE = os.environ["QUIVER_BAKE"]
MESH = os.environ["QUIVER_MESH"]
QUIVER = os.environ["QUIVER"]
MPIEXEC = os.environ.get("MPIEXEC") or "mpirun"


def quiver(*args, ok=True):
    p = subprocess.run([QUIVER, *map(str, args)], capture_output=True, text=True, timeout=60)
    if ok:
        assert p.returncode == 0, p.stderr
        return json.loads(p.stdout)
    return p


def evaluate(model, q):
    j = quiver("eval", model, "--q", ",".join(repr(float(x)) for x in q))
    return j["energy"], np.array(j["force"]), np.array(j["stiffness"])


class QuiverModel(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        d = cls.tmp.name
        beam = os.path.join(d, "beam.vtu")
        subprocess.run([MESH, "beam", "--size", "1,0.1,0.15", "--cells", "10,2,3", "-o", beam], check=True)
        common = [beam, "--fix", "x<min+1e-9", "--E", "1e6", "--nu", "0.4", "--density", "1000", "--modes", "6"]
        cls.full = os.path.join(d, "full")
        cls.modal = os.path.join(d, "modal")
        for name, extra in ((cls.full, ["--rank", "12", "--export-npy"]),
                            (cls.modal, ["--basis-from", cls.full + ".modes.npy", "--basis-precision", "64"])):
            p = subprocess.run([MPIEXEC, "-n", "2", "--oversubscribe", BAKE, *common, *extra, "-o", name, "--quiet"],
                               capture_output=True, text=True, stdin=subprocess.DEVNULL, timeout=300)
            assert p.returncode == 0, p.stderr
        cls.eigenvalues = np.load(cls.full + ".eigenvalues.npy")

    def test_info_counts_and_documented_sizes(self):
        j = quiver("info", self.full + ".qvr")
        r = 12
        self.assertEqual((j["r"], j["vertices"], j["tets"]), (r, 11 * 3 * 4, 6 * 10 * 2 * 3))
        self.assertEqual(j["surface_triangles"], 4 * (10 * 2 + 10 * 3 + 2 * 3))  # 2 per boundary cell face
        c2, c3, c4 = r * (r + 1) // 2, r * (r + 1) * (r + 2) // 6, r * (r + 1) * (r + 2) * (r + 3) // 24
        self.assertEqual(j["sections"]["ENERGY_COEFFICIENTS"], 8 * (c2 + c3 + c4))
        vega = 8 * r * (r + r * (r + 1) // 2 + r * (r + 1) * (r + 2) // 6)  # Vega's .cub coefficient layout
        self.assertLess(j["sections"]["ENERGY_COEFFICIENTS"], vega)
        self.assertEqual(j["sections"]["BASIS"], 4 * 3 * j["vertices"] * r)  # float32 by default
        # Every section by its name in QVR.md (the reader's own table), none as a bare type number.
        self.assertEqual(j["sections"]["MODAL_ROTATIONS"], 8 * 3 * j["vertices"] * r)
        self.assertEqual([name for name in j["sections"] if "type" in name], [])
        np.testing.assert_allclose(j["frequencies_hz"], np.sqrt(self.eigenvalues) / (2 * np.pi), rtol=1e-12)
        # The modes as the reduced model has them (its own K~(0) in span U) are Rayleigh-Ritz approximations of
        # the ones SLEPc baked: never below them; the first, which the basis weighs most, close.
        reduced = np.array(j["reduced_frequencies_hz"])
        self.assertEqual(len(reduced), r)
        self.assertTrue(np.all(reduced[:6] >= np.array(j["frequencies_hz"]) * (1 - 1e-9)))
        self.assertLess(reduced[0] / j["frequencies_hz"][0] - 1, 1e-3)
        # A basis of exactly the modes holds them exactly.
        modal = quiver("info", self.modal + ".qvr")
        np.testing.assert_allclose(modal["reduced_frequencies_hz"], modal["frequencies_hz"], rtol=1e-9)
        self.assertAlmostEqual(j["total_mass"], 1000 * 1 * 0.1 * 0.15, places=9)
        self.assertEqual(j["material"]["poisson_ratio"], 0.4)

    def test_modal_model_stiffness_at_rest_is_the_eigenvalues(self):
        energy, force, K = evaluate(self.modal + ".qvr", np.zeros(6))
        self.assertEqual(energy, 0.0)
        self.assertEqual(np.abs(force).max(), 0.0)
        np.testing.assert_allclose(K, np.diag(self.eigenvalues), atol=1e-10 * self.eigenvalues.max())

    def test_force_and_stiffness_are_derivatives_of_the_energy(self):
        rng = np.random.default_rng(1)
        model = self.full + ".qvr"
        q = rng.normal(size=12) * 0.02  # displacements of a few cm on a 1 m beam: cubic and quartic terms matter
        _, force, K = evaluate(model, q)
        np.testing.assert_allclose(K, K.T, atol=1e-12 * np.abs(K).max())
        h = 1e-5
        for i in range(12):
            e = np.zeros(12)
            e[i] = h
            ep, fp, _ = evaluate(model, q + e)
            em, fm, _ = evaluate(model, q - e)
            self.assertLess(abs((ep - em) / (2 * h) - force[i]), 1e-6 * np.abs(force).max())
            self.assertLess(np.abs((fp - fm) / (2 * h) - K[:, i]).max(), 1e-6 * np.abs(K).max())

    def test_q_from_npy(self):
        path = os.path.join(self.tmp.name, "q.npy")
        q = np.linspace(-0.01, 0.01, 12)
        np.save(path, q)
        a = quiver("eval", self.full + ".qvr", "--q", path)
        b = evaluate(self.full + ".qvr", q)
        self.assertEqual(a["energy"], b[0])

    def test_bad_arguments_and_damaged_files_are_refused_clearly(self):
        model = self.full + ".qvr"
        # Non-finite or overflowing q once printed null energies and forces with exit code 0.
        for q, message in (("1,2", "the model has r = 12"), ("1,x," + "0," * 9 + "0", "'x' is not a number"),
                           ("0,nan," + "0," * 9 + "0", "--q: value 1 is not finite"),
                           ("1e200," + "0," * 10 + "0", "--q is too large: the energy, force or stiffness there overflows")):
            p = quiver("eval", model, "--q", q, ok=False)
            self.assertEqual(p.returncode, 1)
            self.assertIn(message, p.stderr)
        with open(model, "rb") as f:
            data = f.read()
        damaged = os.path.join(self.tmp.name, "damaged.qvr")
        for name, content, message in (("truncated", data[:len(data) // 2], "damaged.qvr"),
                                       ("flipped", data[:5000] + bytes([data[5000] ^ 0x10]) + data[5001:], "checksum"),
                                       ("empty", b"", "damaged.qvr")):
            with self.subTest(name=name):
                with open(damaged, "wb") as f:
                    f.write(content)
                p = quiver("info", damaged, ok=False)
                self.assertEqual(p.returncode, 1)
                self.assertIn(message, p.stderr)
                self.assertIn("damaged.qvr", p.stderr)
        p = quiver("info", os.path.join(self.tmp.name, "none.qvr"), ok=False)
        self.assertIn("none.qvr: cannot open", p.stderr)


class OnTheBakedModel(unittest.TestCase):
    """Shares QuiverModel's baked beam, so the bake runs once per file."""

    @classmethod
    def setUpClass(cls):
        if not hasattr(QuiverModel, "full"):
            QuiverModel.setUpClass()
        cls.model = QuiverModel.full + ".qvr"
        cls.tmp = QuiverModel.tmp


class QuiverSim(OnTheBakedModel):
    """`quiver sim` as a user runs it: the files it promises, readable by an independent reader."""

    def sim(self, *args, ok=True):
        p = subprocess.run([QUIVER, "sim", self.model, *map(str, args)], capture_output=True, text=True, timeout=120)
        if ok:
            self.assertEqual(p.returncode, 0, p.stderr)
        return p

    def test_json_summary(self):
        j = json.loads(self.sim("--steps", 50, "--hold", 20, "--force", "0,0,-2", "--json").stdout)
        self.assertEqual((j["r"], j["steps"], j["resets"]), (12, 50, 0))
        self.assertGreater(j["step_us_p99"], 0)
        self.assertLessEqual(j["step_us_median"], j["step_us_p99"])

    def test_series_csv_and_pvd(self):
        out = os.path.join(self.tmp.name, "run", "pull")
        self.sim("--steps", 40, "--hold", 20, "--force", "0,0,-2", "--gravity", "-o", out, "--every", 10)
        with open(out + ".csv") as f:
            rows = f.read().strip().split("\n")
        self.assertEqual(len(rows), 41)
        with open(out + ".pvd") as f:
            self.assertEqual(f.read().count("<DataSet"), 4)
        # "-o NAME.pvd" names the series as "-o NAME" does (it once wrote NAME.pvd.pvd).
        self.sim("--steps", 2, "-o", out + "2.pvd")
        self.assertTrue(os.path.exists(out + "2.pvd") and os.path.exists(out + "2.csv"))
        # A name with XML's own characters: the .pvd still parses and names the frames written.
        odd = os.path.join(self.tmp.name, "run", "a&b\"<c>'d")
        self.sim("--steps", 2, "-o", odd)
        files = [d.get("file") for d in xml.etree.ElementTree.parse(odd + ".pvd").getroot().iter("DataSet")]
        self.assertEqual(files, ["a&b\"<c>'d_00001.vtu", "a&b\"<c>'d_00002.vtu"])
        self.assertTrue(all(os.path.exists(os.path.join(self.tmp.name, "run", f)) for f in files))
        try:
            import meshio
        except ImportError:
            self.skipTest("python3-meshio not installed")
        frame = meshio.read(out + "_00020.vtu")
        u = frame.point_data["displacement"]
        self.assertLess(u[:, 2].min(), 0)  # pulled and pulled down
        fixed = frame.points[:, 0] < 1e-9
        self.assertLess(np.abs(u[fixed]).max(), 1e-6)  # the clamped end stays put (positions are float32)

    def test_drag_and_twist_keeps_running(self):
        j = json.loads(self.sim("--steps", 60, "--hold", 30, "--twist", 30, "--drag", "0,0.01,0", "--newton", 2,
                                "--json").stdout)
        self.assertEqual(j["resets"], 0)

    def test_instances_report_frame_times(self):
        for extra, threads, stepping in (([], 1, "together"), (["--threads", 2], 2, "together"),
                                         (["--one-by-one"], 1, "one by one")):
            j = json.loads(self.sim("--instances", 20, "--steps", 30, "--hold", 10, "--json", *extra).stdout)
            self.assertEqual((j["instances"], j["threads"], j["stepping"], j["steps"], j["resets"]),
                             (20, threads, stepping, 30, 0))
            self.assertGreater(j["frame_ms_median"], 0)
            self.assertLessEqual(j["frame_ms_median"], j["frame_ms_p99"])
            self.assertAlmostEqual(j["instance_step_us_median"], 1e3 * j["frame_ms_median"] / 20)
        for args, message in ((["--instances", 0], "--instances"), (["--instances", 3, "--twist", 10], "--drag or --twist"),
                              (["--instances", 3, "-o", os.path.join(self.tmp.name, "crowd")], "leave out -o"),
                              (["--instances", 3, "--threads", 0], "--threads"),
                              (["--instances", 3, "--pile", 4], "need --free")):  # --pile was ignored
            p = self.sim(*args, ok=False)
            self.assertNotEqual(p.returncode, 0)
            self.assertIn(message, p.stderr)

    def test_bad_options(self):
        for args, message in ((["--group", "x<-5"], "selects no vertex"), (["--group", "q<1"], "--group"),
                              (["--dt", "-1"], "--dt"), (["--newton", "0"], "--newton"), (["--solver", "gauss"], "gauss"),
                              # 1 / h^2 overflowed, and the state gone non-finite was blamed on the load.
                              (["--dt", "1e-300"], "--dt: expected a time step of at least 1e-12 s"),
                              # Once taken: a NaN load reset the model every step, a spring of no stiffness
                              # did nothing, and a negative damping meant the model's.
                              (["--force", "nan,0,0"], "--force: expected a finite number, not 'nan'"),
                              (["--twist", "inf"], "--twist: expected a finite number"),
                              (["--drag", "0,0,0.1", "--stiffness", "0"], "--stiffness: expected a positive number"),
                              (["--alpha", "-100"], "--alpha: expected a number >= 0"),
                              (["--beta", "nan"], "--beta: expected a number >= 0"),
                              (["--hold", "-5"], "--hold: expected a number >= 0"),
                              # Once ignored in silence: what nothing would write, friction with nothing to touch.
                              (["--every", "3"], "--every requires --output"),
                              (["--friction", "0.1"], "need --free"), (["--restitution", "0.9"], "need --free")):
            p = self.sim(*args, ok=False)
            self.assertNotEqual(p.returncode, 0)
            self.assertIn(message, p.stderr)

    def test_a_load_the_model_cannot_take_is_reported(self):
        # 1e300 N at the tip: its work overflows, every step goes non-finite, and the runtime resets the
        # bar to rest.
        p = self.sim("--force", "0,0,-1e300", "--steps", "5", ok=False)
        self.assertEqual(p.returncode, 2)
        self.assertIn("went non-finite 5 times and the runtime reset it to rest", p.stderr)
        # A crowd says so too (it exited 2 in silence).
        p = self.sim("--force", "0,0,-1e300", "--steps", "5", "--instances", "3", "--json", ok=False)
        self.assertEqual(p.returncode, 2)
        self.assertEqual(json.loads(p.stdout)["resets"], 15)
        self.assertIn("states went non-finite 15 times and the runtime reset them to rest", p.stderr)


class QuiverRender(OnTheBakedModel):
    """`quiver render` without a display: the pictures decode, show the model, and show it moving."""

    def render(self, name, *args, ok=True):
        path = os.path.join(self.tmp.name, name)
        p = subprocess.run([QUIVER, "render", self.model, "-o", path, *map(str, args)], capture_output=True, text=True,
                           timeout=120)
        if ok:
            self.assertEqual(p.returncode, 0, p.stderr)
        return path, p

    def picture(self, name, *args):
        try:
            import matplotlib.image
        except ImportError:
            self.skipTest("python3-matplotlib not installed: cannot decode the PNG")
        return matplotlib.image.imread(self.render(name, *args)[0])[:, :, :3]

    def frames(self, name, *args):
        try:
            from PIL import Image, ImageSequence
        except ImportError:
            self.skipTest("python3-pil not installed: cannot decode the GIF")
        with Image.open(self.render(name, *args)[0]) as gif:
            self.assertEqual(gif.info.get("loop"), 0)  # loops forever
            frames, durations = [], []
            for f in ImageSequence.Iterator(gif):
                frames.append(np.asarray(f.convert("RGB"), dtype=float) / 255)
                durations.append(f.info["duration"])
            return frames, {"durations": durations}

    def assertFramed(self, image):
        covered = (image < 0.99).any(axis=2).mean()
        self.assertGreater(covered, 0.02)  # not blank
        self.assertLess(covered, 0.9)  # and not all model: the camera frames it

    def assertMoved(self, a, b):
        self.assertGreater((np.abs(a - b).max(axis=2) > 0.05).mean(), 0.005)

    def test_rest_pulled_and_modes(self):
        rest = self.picture("rest.png", "--size", "320,200")
        self.assertEqual(rest.shape, (200, 320, 3))
        self.assertFramed(rest)
        self.assertGreater(len(np.unique(rest.reshape(-1, 3), axis=0)), 3)  # shaded faces, not one flat colour
        pulled = self.picture("pulled.png", "--size", "320,200", "--force", "0,0,-20", "--hold", "90", "--steps", "90")
        self.assertMoved(pulled, rest)
        twisted = self.picture("twisted.png", "--size", "320,200", "--twist", "40", "--hold", "60", "--steps", "60")
        self.assertMoved(twisted, rest)
        self.assertMoved(twisted, pulled)
        modes = self.picture("modes.png", "--size", "300,300", "--modes", "4")
        _, p = self.render("many.png", "--size", "64,64", "--modes", "1000")  # said nothing of drawing r = 12
        self.assertIn("--modes 1000: the model has r = 12, so 12 are drawn", p.stderr)
        self.assertFramed(modes)
        basis = self.picture("basis.png", "--size", "300,300", "--modes", "4", "--basis")
        self.assertFramed(basis)
        # The first linear mode is the first basis vector's largest part, not all of it: the tiles differ.
        self.assertMoved(modes, basis)

    def test_scenario_file(self):
        scenario = os.path.join(self.tmp.name, "twist.scenario")
        with open(scenario, "w") as f:
            f.write("# the free end twisted\ngroup = x>max-1e-6\ntwist = 40  # degrees\nhold = 60\nsteps = 60\n")
        a, _ = self.render("from_file.png", "--size", "160,100", "--scenario", scenario)
        b, _ = self.render("explicit.png", "--size", "160,100", "--twist", "40", "--hold", "60", "--steps", "60")
        with open(a, "rb") as fa, open(b, "rb") as fb:
            self.assertEqual(fa.read(), fb.read())  # the runtime is deterministic: the same picture
        # Options after the file override it.
        c, _ = self.render("override.png", "--size", "160,100", "--scenario", scenario, "--steps", "10")
        d, _ = self.render("override_explicit.png", "--size", "160,100", "--twist", "40", "--hold", "60", "--steps", "10")
        with open(c, "rb") as fc, open(d, "rb") as fd:
            self.assertEqual(fc.read(), fd.read())
        j = json.loads(subprocess.run([QUIVER, "sim", self.model, "--scenario", scenario, "--json"], capture_output=True,
                                      text=True, check=True).stdout)
        self.assertEqual(j["steps"], 60)
        for line, message in (("twirl = 3", "twist.scenario:6: 'twirl' is not a scenario option (steps, hold,"),
                              ("steps = many", "twist.scenario:6: --steps: expected a positive number, not 'many'"),
                              ("force = 0,-1", "twist.scenario:6: --force"),
                              ("scenario = twist.scenario", "'scenario' is not a scenario option")):
            with self.subTest(line=line):
                broken = os.path.join(self.tmp.name, "broken", "twist.scenario")
                os.makedirs(os.path.dirname(broken), exist_ok=True)
                with open(scenario) as f, open(broken, "w") as g:
                    g.write(f.read() + line + "\n")
                _, p = self.render("never.png", "--scenario", broken, ok=False)
                self.assertEqual(p.returncode, 1)
                self.assertIn(message, p.stderr)

    def test_animations(self):
        frames, info = self.frames("pull.gif", "--size", "160,100", "--force", "0,0,-20", "--hold", "20", "--steps",
                                   "40", "--every", "4")
        self.assertEqual(len(frames), 1 + 40 // 4)  # the rest pose, then every 4th step
        self.assertEqual(frames[0].shape, (100, 160, 3))
        self.assertFramed(frames[0])
        self.assertMoved(frames[5], frames[0])  # pulled at step 20
        # Played at simulation speed: 4 steps of 1/60 s a frame is 6.67 hundredths, so delays of 6 and 7 add up.
        self.assertEqual(sum(info["durations"]), 10 * round(100 * len(frames) * 4 / 60))
        modes, _ = self.frames("modes.gif", "--size", "200,200", "--modes", "4")
        self.assertEqual(len(modes), 30)  # one oscillation
        self.assertMoved(modes[7], modes[0])  # a quarter period: at full amplitude, from rest
        sequence = os.path.join(self.tmp.name, "seq")
        os.makedirs(sequence)
        self.render(os.path.join(sequence, "f_%03d.png"), "--size", "64,48", "--gravity", "--steps", "6", "--every", "3")
        self.assertEqual(sorted(os.listdir(sequence)), ["f_000.png", "f_001.png", "f_002.png"])

    def test_bad_options(self):
        for name, args, message in (("x.png", ["--size", "4,4"], "--size"),
                                    ("x.png", ["--force", "0,0,-1", "--group", "q<1"], "--group"),
                                    ("x.png", ["--force", "0,0,-1", "--group", "x<-5"], "selects no vertex"),
                                    ("x.png", ["--modes", "3", "--gravity"], "drop the scenario"),
                                    ("x.jpg", ["--modes", "3"], ".gif animation"),
                                    ("x_%d_%d.png", [], "one %d or %0Nd field"),
                                    ("x_%5d.png", [], "one %d or %0Nd field"),  # would pad with spaces
                                    ("x.png", ["--modes", "2", "--amplitude", "nan"], "--amplitude"),
                                    ("x.png", ["--modes", "-3"], "--modes"),
                                    ("x.png", ["--force", "1,2"], "--force"),
                                    ("x.gif", [], "nothing moves")):
            with self.subTest(args=args):
                _, p = self.render(name, *args, ok=False)
                self.assertNotEqual(p.returncode, 0)
                self.assertIn(message, p.stderr)
                self.assertEqual([f for f in os.listdir(self.tmp.name) if f.startswith("x")], [])
        # An absurd load: Barbic & James's fixed Newton steps would diverge (they used to reset to rest);
        # the minimiser takes those steps, so neither solver resets.
        for solver in ("newton", "minimize"):
            _, p = self.render(f"held_{solver}.png", "--force", "0,0,-1e9", "--hold", "3", "--steps", "3", "--solver", solver)
            self.assertNotIn("reset to rest", p.stderr)


if __name__ == "__main__":
    unittest.main(verbosity=2)
