#!/usr/bin/python3
"""`quiver full` from the outside: the four sparse solvers end on one displacement, the files it
promises exist and read back, and bad input is refused clearly."""
import json
import os
import subprocess
import tempfile
import unittest

import numpy as np

QUIVER = os.environ["QUIVER"]
MESH = os.environ["QUIVER_MESH"]


def full(*args, ok=True):
    p = subprocess.run([QUIVER, "full", *map(str, args)], capture_output=True, text=True, timeout=300)
    if ok:
        assert p.returncode == 0, p.stderr
    return p


class QuiverFull(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.mesh = os.path.join(cls.tmp.name, "bar.vtu")
        subprocess.run([MESH, "beam", "--size", "0.6,0.1,0.1", "--cells", "12,2,2", "-o", cls.mesh], check=True)
        cls.common = [cls.mesh, "--fix", "x<min+1e-9", "--E", "1e6", "--nu", "0.4", "--force", "0,0,-2", "--hold", 20,
                      "--steps", 40, "--beta", "0.002"]

    def test_four_solvers_one_trajectory(self):
        finals = {}
        for solver in ("ldlt", "llt", "cg", "lu"):
            path = os.path.join(self.tmp.name, f"{solver}.npy")
            j = json.loads(full(*self.common, "--solver", solver, "--json", "--final-npy", path).stdout)
            self.assertEqual(j["dofs"], 3 * 13 * 3 * 3)
            self.assertGreaterEqual(j["newton_iterations_mean"], 1)
            finals[solver] = np.load(path)
        reference = finals["ldlt"]
        self.assertGreater(np.abs(reference).max(), 1e-3)
        for solver, u in finals.items():
            np.testing.assert_allclose(u, reference, atol=1e-8 * np.abs(reference).max(), err_msg=solver)

    def test_writes_series(self):
        out = os.path.join(self.tmp.name, "series", "bar")
        full(*self.common, "-o", out, "--every", 10)
        with open(out + ".pvd") as f:
            self.assertEqual(f.read().count("<DataSet"), 4)
        with open(out + ".csv") as f:
            self.assertEqual(len(f.read().strip().split("\n")), 41)

    def test_bad_input(self):
        p = full(*self.common, "--solver", "qr", ok=False)
        self.assertNotEqual(p.returncode, 0)
        self.assertIn("qr", p.stderr)
        p = full(os.path.join(self.tmp.name, "none.vtu"), ok=False)
        self.assertIn("none.vtu: cannot open", p.stderr)
        p = full(self.mesh, "--fix", "x<min+1e-9", "--nu", "0.6", ok=False)
        self.assertIn("Poisson", p.stderr)


if __name__ == "__main__":
    unittest.main(verbosity=2)
