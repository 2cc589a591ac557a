#!/usr/bin/python3
"""quiver-mesh from the outside: JSON facts checked against analytic values, every reader checked
against meshio (an independent implementation) on files meshio writes, and bad input."""
import itertools
import json
import os
import subprocess
import sys
import tempfile
import unittest

import numpy as np

TOOL = os.environ["QUIVER_MESH"]
SHARED = os.environ.get("QUIVER_SHARED_MESHES", "")

try:
    import meshio
except ImportError:  # the suite installs python3-meshio; without it only the cross-checks skip
    meshio = None


def run(*args, ok=True):
    p = subprocess.run([TOOL, *map(str, args)], capture_output=True, text=True, timeout=120)
    if ok and p.returncode != 0:
        raise AssertionError(f"quiver-mesh {' '.join(map(str, args))} failed:\n{p.stderr}")
    return p


def info(path, *extra):
    return json.loads(run("info", path, *extra).stdout)


class Beam(unittest.TestCase):
    def test_counts_volume_and_bbox_are_analytic(self):
        with tempfile.TemporaryDirectory() as tmp:
            out = os.path.join(tmp, "beam.vtu")
            run("beam", "--size", "2,0.3,0.5", "--cells", "8,3,2", "-o", out)
            j = info(out, "--fix", "x<min+1e-9")
            self.assertEqual(j["vertices"], 9 * 4 * 3)
            self.assertEqual(j["tets"], 6 * 8 * 3 * 2)
            self.assertAlmostEqual(j["volume"], 2 * 0.3 * 0.5, places=12)
            self.assertEqual(j["bbox"]["min"], [0, 0, 0])
            np.testing.assert_allclose(j["bbox"]["max"], [2, 0.3, 0.5], rtol=1e-15)
            self.assertEqual(j["fixed_vertices"], 4 * 3)
            self.assertGreater(j["quality"]["normalised_volume"]["min"], 0)

    def test_bad_options_fail_cleanly(self):
        for args in (["--cells", "0,1,1"], ["--size", "1,-1,1"], ["--size", "1,1"]):
            p = run("beam", *args, "-o", "x.vtu", ok=False)
            self.assertNotEqual(p.returncode, 0, args)
            self.assertTrue(p.stderr.strip(), args)
        # Once accepted: a mesh of 6e9 tets (6 GB in 16 s before it was stopped), coordinates that
        # overflowed, and tets the bake refuses as degenerate.
        for args, message in ((["--cells", "1000,1000,1000"], "6000000000 tets; at most 50000000"),
                              (["--size", "1,1e308,1"], "--size: an edge beyond 1e9"),
                              (["--size", "1e-10,1,1"], "their tets are degenerate")):
            p = run("beam", *args, "-o", "x.vtu", ok=False)
            self.assertEqual(p.returncode, 1, args)
            self.assertIn(message, p.stderr)
            self.assertFalse(os.path.exists("x.vtu"))


@unittest.skipIf(meshio is None, "python3-meshio not installed")
class AgainstMeshio(unittest.TestCase):
    """meshio writes a jittered, two-region mesh in each encoding; quiver-mesh converts it to
    legacy VTK; meshio reads that back. Coordinates must survive bit for bit."""

    @classmethod
    def setUpClass(cls):
        rng = np.random.default_rng(7)
        n = 4
        grid = np.array(list(itertools.product(range(n + 1), repeat=3)), dtype=float)[:, ::-1]
        index = {tuple(p.astype(int)): i for i, p in enumerate(grid)}
        tets = []
        for cell in itertools.product(range(n), repeat=3):
            for order in itertools.permutations(range(3)):
                c = list(cell)
                t = [index[tuple(c)]]
                for axis in order:
                    c[axis] += 1
                    t.append(index[tuple(c)])
                tets.append(t)
        cls.points = grid + rng.uniform(-0.2, 0.2, grid.shape)  # jitter keeps every tet positive
        tets = np.array(tets)
        x = cls.points[tets]
        neg = np.linalg.det(np.stack([x[:, 1] - x[:, 0], x[:, 2] - x[:, 0], x[:, 3] - x[:, 0]], axis=1)) < 0
        tets[neg, 1], tets[neg, 2] = tets[neg, 2], tets[neg, 1].copy()
        cls.tets = tets
        cls.region = np.where(cls.points[tets].mean(axis=1)[:, 0] < n / 2, 1, 2)

    def roundtrip(self, writer, name, has_region, exact=True):
        with tempfile.TemporaryDirectory() as tmp:
            src = os.path.join(tmp, name)
            writer(src)
            out = os.path.join(tmp, "out.vtk")
            run("convert", src, out)
            back = meshio.read(out)
            if exact:
                np.testing.assert_array_equal(back.points, self.points)
            else:  # meshio's ASCII VTU writer prints 12 significant digits
                np.testing.assert_allclose(back.points, self.points, rtol=1e-11)
            np.testing.assert_array_equal(back.cells_dict["tetra"], self.tets)
            if has_region:
                np.testing.assert_array_equal(back.cell_data["region"][0].ravel(), self.region)

    def mesh(self, with_triangle):
        cells = [("tetra", self.tets)]
        data = {"gmsh:physical": [self.region], "gmsh:geometrical": [self.region]}
        if with_triangle:  # a boundary triangle the readers must skip
            cells.insert(0, ("triangle", self.tets[:1, :3]))
            data = {k: [np.array([9]), self.region] for k in data}
        return meshio.Mesh(self.points, cells, cell_data=data)

    def test_gmsh(self):
        for version, binary in itertools.product(["2.2", "4.1"], [False, True]):
            with self.subTest(version=version, binary=binary):
                m = self.mesh(with_triangle=version == "2.2")
                # meshio's 4.1 writer drops physical groups (no $Entities): regions only from 2.2.
                self.roundtrip(lambda p: meshio.gmsh.write(p, m, fmt_version=version, binary=binary), "m.msh",
                               has_region=version == "2.2")

    def test_vtk_legacy(self):
        for binary in (False, True):
            with self.subTest(binary=binary):
                m = meshio.Mesh(self.points, [("triangle", self.tets[:1, :3]), ("tetra", self.tets)])
                self.roundtrip(lambda p: meshio.vtk.write(p, m, binary=binary), "m.vtk", has_region=False)

    def test_vtu(self):
        for binary, compression in ((False, None), (True, None), (True, "zlib")):
            with self.subTest(binary=binary, compression=compression):
                m = meshio.Mesh(self.points, [("triangle", self.tets[:1, :3]), ("tetra", self.tets)])
                self.roundtrip(lambda p: meshio.vtu.write(p, m, binary=binary, compression=compression), "m.vtu",
                               has_region=False, exact=binary)

    def test_medit_and_tetgen(self):
        m = meshio.Mesh(self.points, [("tetra", self.tets)], cell_data={"medit:ref": [self.region]})
        self.roundtrip(lambda p: meshio.medit.write(p, m), "m.mesh", has_region=True)
        t = meshio.Mesh(self.points, [("tetra", self.tets)])
        self.roundtrip(lambda p: meshio.tetgen.write(p, t), "m.node", has_region=False)

    def test_our_writers_read_back_in_meshio(self):
        with tempfile.TemporaryDirectory() as tmp:
            src = os.path.join(tmp, "m.msh")
            meshio.gmsh.write(src, self.mesh(False), fmt_version="4.1", binary=False)
            for ext in ("vtu", "vtk", "msh", "mesh"):
                out = os.path.join(tmp, "out." + ext)
                run("convert", src, out)
                back = meshio.read(out)
                np.testing.assert_array_equal(back.points, self.points, err_msg=ext)
                np.testing.assert_array_equal(back.cells_dict["tetra"], self.tets, err_msg=ext)
            # .veg holds regions only as materials: converting there says the two regions merge (from
            # 2.2: meshio's 4.1 writer drops the regions).
            src = os.path.join(tmp, "m22.msh")
            meshio.gmsh.write(src, self.mesh(False), fmt_version="2.2", binary=False)
            p = run("convert", src, os.path.join(tmp, "out.veg"))
            self.assertIn("quiver-mesh: warning: " + os.path.join(tmp, "out.veg") + " holds regions only as materials",
                          p.stderr)


class BadInput(unittest.TestCase):
    def test_missing_file_is_named(self):
        p = run("info", "/nonexistent/m.msh", ok=False)
        self.assertEqual(p.returncode, 1)
        self.assertIn("/nonexistent/m.msh: cannot open", p.stderr)
        self.assertEqual(p.stdout, "")

    def test_inverted_mesh_names_element_and_leaves_output_untouched(self):
        bad = os.path.join(SHARED, "sofa_6_tetra_bad.msh")
        if not os.path.exists(bad):
            self.skipTest(f"shared mesh folder absent ({SHARED}): skipping sofa_6_tetra_bad.msh")
        with tempfile.TemporaryDirectory() as tmp:
            out = os.path.join(tmp, "out.vtu")
            open(out, "w").write("keep me")
            p = run("convert", bad, out, ok=False)
            self.assertEqual(p.returncode, 1)
            self.assertIn(f"{bad}:31: element 44 is inverted", p.stderr)
            self.assertEqual(open(out).read(), "keep me")
            self.assertEqual(os.listdir(tmp), ["out.vtu"])  # no temporary left behind
            run("convert", bad, out, "--fix-orientation")
            self.assertEqual(info(out)["tets"], 6)

    def test_garbage_is_refused(self):
        with tempfile.TemporaryDirectory() as tmp:
            for name, text in (("g.msh", "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n3\n1 0 0\n"),
                               ("g.vtk", "not a vtk file"), ("g.veg", "*VERTICES\nmany\n"), ("g.xyz", "1 2 3")):
                path = os.path.join(tmp, name)
                open(path, "w").write(text)
                p = run("info", path, ok=False)
                self.assertEqual(p.returncode, 1, name)
                self.assertIn(path, p.stderr, name)


if __name__ == "__main__":
    unittest.main(verbosity=2)
