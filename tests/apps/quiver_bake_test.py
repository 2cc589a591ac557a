#!/usr/bin/python3
"""quiver-bake from the outside, on 1 and 2 MPI ranks: it runs, agrees across rank counts, and
refuses bad input with one clear message on every rank count, never a hang."""
import os
import subprocess
import tempfile
import unittest

BAKE = os.environ["QUIVER_BAKE"]
MESH = os.environ["QUIVER_MESH"]
MPIEXEC = os.environ.get("MPIEXEC") or "mpirun"


def bake(ranks, *args):
    cmd = [MPIEXEC, "-n", str(ranks), BAKE, *map(str, args)]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=120, stdin=subprocess.DEVNULL)


class QuiverBake(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.beam = os.path.join(cls.tmp.name, "beam.vtu")
        subprocess.run([MESH, "beam", "--size", "1,0.1,0.1", "--cells", "20,2,2", "-o", cls.beam], check=True)

    def test_runs_on_one_and_two_ranks(self):
        for ranks in (1, 2):
            with self.subTest(ranks=ranks):
                p = bake(ranks, self.beam, "--fix", "x<min+1e-9", "--E", "1e6", "-o", os.path.join(self.tmp.name, "b"))
                self.assertEqual(p.returncode, 0, p.stderr)
                self.assertIn("189 vertices, 480 tets, 9 fixed vertices", p.stdout)
                self.assertIn(f"partition: {ranks} part(s)", p.stdout)
                self.assertEqual(p.stdout.count("189 vertices"), 1, "only rank 0 reports")

    def test_petsc_options_pass_through(self):
        p = bake(1, self.beam, "-o", os.path.join(self.tmp.name, "b"), "-log_view", ":/dev/null")
        self.assertEqual(p.returncode, 0, p.stderr)

    def test_bad_input_fails_on_every_rank_with_one_message(self):
        cases = [
            (["--nu", "0.7"], "Poisson ratio nu = 0.7 must lie in (-1, 0.5)"),
            (["--E", "-1"], "Young's modulus"),
            (["--fix", "x<-5"], "selects no vertex"),
            (["--fix", "q<1"], "expected x, y or z"),
        ]
        for ranks in (1, 2):
            for extra, message in cases:
                with self.subTest(ranks=ranks, extra=extra):
                    p = bake(ranks, self.beam, *extra, "-o", os.path.join(self.tmp.name, "b"))
                    self.assertNotEqual(p.returncode, 0)
                    self.assertIn(message, p.stderr)
                    self.assertEqual(p.stderr.count("quiver-bake: error:"), 1, p.stderr)

    def test_missing_mesh_is_named(self):
        p = bake(2, os.path.join(self.tmp.name, "none.msh"), "-o", os.path.join(self.tmp.name, "b"))
        self.assertNotEqual(p.returncode, 0)
        self.assertIn("none.msh: cannot open", p.stderr)


if __name__ == "__main__":
    unittest.main(verbosity=2)
