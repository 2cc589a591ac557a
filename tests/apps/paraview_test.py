#!/usr/bin/python3
"""ParaView (Debian's pvpython) opens what the bake and the simulator write, and sees in them what
h5py and meshio read from the same files: the bake's XDMF index over its HDF5 archive (modes,
derivatives and basis as time series of vector fields on the tets) and a simulation's .pvd series."""
import json
import os
import subprocess
import tempfile
import unittest

import meshio
import numpy as np

BAKE = os.environ["QUIVER_BAKE"]
MESH = os.environ["QUIVER_MESH"]
QUIVER = os.environ["QUIVER"]
PVPYTHON = os.environ["PVPYTHON"]

# Runs inside pvpython: what ParaView's readers make of a file, at a few times, as JSON.
SEE = r'''
import json, sys
from paraview import servermanager
from paraview.simple import OpenDataFile
from vtkmodules.numpy_interface import dataset_adapter as dsa
reader = OpenDataFile(sys.argv[1])
times = list(reader.TimestepValues) if hasattr(reader, "TimestepValues") else []
seen = {"reader": reader.GetXMLName(), "times": times, "at": {}}
for t in map(float, sys.argv[2:]):
    reader.UpdatePipeline(t)
    data = dsa.WrapDataObject(servermanager.Fetch(reader))
    blocks = {}
    for name in data.PointData.keys():
        arrays = data.PointData[name]
        arrays = arrays.Arrays if hasattr(arrays, "Arrays") else [arrays]
        blocks[name] = [a.tolist() for a in arrays if a is not None and hasattr(a, "tolist")]
    seen["at"][str(t)] = {"points": data.GetNumberOfPoints(), "cells": data.GetNumberOfCells(), "arrays": blocks}
print("SEEN" + json.dumps(seen))
'''


def paraview_sees(path, *times):
    with tempfile.NamedTemporaryFile("w", suffix=".py", delete=False) as script:
        script.write(SEE)
    try:
        # An absolute path: given "NAME.xmf" alone, ParaView 5.11's XDMF 3 reader looks for the
        # archive at "NAME.xmfNAME.h5" (its own path joining; the GUI always passes absolute paths).
        p = subprocess.run([PVPYTHON, "--force-offscreen-rendering", script.name, os.path.abspath(path), *map(str, times)],
                           capture_output=True, text=True, timeout=300, stdin=subprocess.DEVNULL)
    finally:
        os.unlink(script.name)
    line = next((l for l in p.stdout.splitlines() if l.startswith("SEEN")), None)
    if line is None:
        raise AssertionError(f"pvpython failed on {path}:\n{p.stdout[-2000:]}\n{p.stderr[-2000:]}")
    return json.loads(line[4:])


class ParaView(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        d = cls.tmp.name
        subprocess.run([MESH, "beam", "--size", "1,0.1,0.15", "--cells", "8,2,3", "-o", os.path.join(d, "beam.vtu")],
                       check=True, capture_output=True)
        cls.name = os.path.join(d, "beam")
        subprocess.run([BAKE, os.path.join(d, "beam.vtu"), "--fix", "x<min+1e-9", "--modes", "4", "--rank", "6",
                        "--no-fidelity", "--quiet", "-o", cls.name], check=True, capture_output=True)
        cls.vertices, cls.tets = 9 * 3 * 4, 8 * 2 * 3 * 6
        cls.frames = 8
        subprocess.run([QUIVER, "sim", cls.name + ".qvr", "--group", "x>max-1e-6", "--force", "0,0,-2", "--hold", "12",
                        "--steps", str(3 * cls.frames), "--every", "3", "-o", os.path.join(d, "sim", "beam")],
                       check=True, capture_output=True)

    def test_the_bake_archive_through_its_xdmf_index(self):
        import h5py
        with h5py.File(self.name + ".h5", "r") as f:
            stored = {key: f[f"/{key}/vectors"][()] for key in ("modes", "derivatives", "basis")}
        seen = paraview_sees(self.name + ".xmf", 0, 3)
        self.assertEqual(seen["reader"], "Xdmf3ReaderS")
        # Each series is one time step per vector; ParaView shows the longest: the 10 derivatives.
        self.assertEqual(seen["times"], [float(t) for t in range(len(stored["derivatives"]))])
        for t in (0, 3):
            at = seen["at"][str(float(t))]
            self.assertEqual(set(at["arrays"]), {"modes", "derivatives", "basis"})
            for key, vectors in stored.items():
                with self.subTest(t=t, field=key):
                    (array,) = at["arrays"][key]
                    np.testing.assert_array_equal(np.array(array), vectors[t])
            self.assertEqual(at["points"], 3 * self.vertices)  # one copy of the mesh per series
            self.assertEqual(at["cells"], 3 * self.tets)

    def test_a_simulation_series(self):
        pvd = os.path.join(self.tmp.name, "sim", "beam.pvd")
        seen = paraview_sees(pvd, 0.05, 0.4)
        self.assertEqual(seen["reader"], "PVDReader")
        np.testing.assert_allclose(seen["times"], 0.05 * np.arange(1, self.frames + 1))
        for t, frame in ((0.05, 3), (0.4, 24)):
            at = seen["at"][str(t)]
            self.assertEqual((at["points"], at["cells"]), (self.vertices, self.tets))
            written = meshio.read(os.path.join(self.tmp.name, "sim", f"beam_{frame:05d}.vtu"))
            (array,) = at["arrays"]["displacement"]
            np.testing.assert_array_equal(np.array(array), written.point_data["displacement"])
            self.assertGreater(np.abs(written.point_data["displacement"]).max(), 0)


if __name__ == "__main__":
    unittest.main(verbosity=2)
