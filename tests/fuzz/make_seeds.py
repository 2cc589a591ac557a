#!/usr/bin/python3
"""Writes the fuzzers' seed corpus (tests/fuzz/seeds/<format>/) from one tiny box mesh, in every
encoding meshio can produce, plus hand-written Vega, MFEM and .bou files and numpy's .npy files.
Re-run after changing it: /usr/bin/python3 tests/fuzz/make_seeds.py"""
import itertools
import os
import shutil
import tempfile

import meshio
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
SEEDS = os.path.join(HERE, "seeds")

# One unit cube cut into six Kuhn tets (positively oriented), plus one boundary triangle and
# two regions, so that readers also meet skipped cells and region data.
points = np.array(list(itertools.product([0.0, 1.0], repeat=3)))[:, ::-1].copy()  # x fastest
index = {tuple(p): i for i, p in enumerate(points)}
tets = []
for order in itertools.permutations(range(3)):
    c = [0, 0, 0]
    t = [index[tuple(map(float, c))]]
    for axis in order:
        c[axis] += 1
        t.append(index[tuple(map(float, c))])
    x = points[t]
    if np.linalg.det((x[1:] - x[0]).T) < 0:
        t[1], t[2] = t[2], t[1]
    tets.append(t)
tets = np.array(tets)
triangles = np.array([[0, 1, 2]])
regions = [np.array([1]), np.array([1, 1, 1, 2, 2, 2])]


def mesh(with_triangles=True):
    cells = [("triangle", triangles), ("tetra", tets)] if with_triangles else [("tetra", tets)]
    data = regions if with_triangles else regions[1:]
    return meshio.Mesh(points, cells, cell_data={"gmsh:physical": data, "gmsh:geometrical": data})


def write(fmt, name, **kwargs):
    folder = os.path.join(SEEDS, fmt)
    os.makedirs(folder, exist_ok=True)
    return os.path.join(folder, name)


def main():
    shutil.rmtree(SEEDS, ignore_errors=True)
    m = mesh()
    meshio.gmsh.write(write("gmsh", "ascii22.msh"), m, fmt_version="2.2", binary=False)
    meshio.gmsh.write(write("gmsh", "binary22.msh"), m, fmt_version="2.2", binary=True)
    # meshio's 4.1 writer needs entity information for mixed cells: tets only there.
    meshio.gmsh.write(write("gmsh", "ascii41.msh"), mesh(False), fmt_version="4.1", binary=False)
    meshio.gmsh.write(write("gmsh", "binary41.msh"), mesh(False), fmt_version="4.1", binary=True)
    plain = meshio.Mesh(points, [("triangle", triangles), ("tetra", tets)])
    meshio.vtk.write(write("vtk", "ascii.vtk"), plain, binary=False)
    meshio.vtk.write(write("vtk", "binary.vtk"), plain, binary=True)
    meshio.vtu.write(write("vtu", "ascii.vtu"), plain, binary=False)
    meshio.vtu.write(write("vtu", "binary.vtu"), plain, binary=True, compression=None)
    meshio.vtu.write(write("vtu", "zlib.vtu"), plain, binary=True, compression="zlib")
    meshio.medit.write(write("medit", "cube.mesh"), meshio.Mesh(points, [("triangle", triangles), ("tetra", tets)]))
    with tempfile.TemporaryDirectory() as tmp:
        meshio.tetgen.write(os.path.join(tmp, "cube.node"), meshio.Mesh(points, [("tetra", tets)]))
        node = open(os.path.join(tmp, "cube.node"), "rb").read()
        ele = open(os.path.join(tmp, "cube.ele"), "rb").read()
    open(write("tetgen", "cube.node_ele"), "wb").write(node + b"\0" + ele)

    lines = ["*VERTICES", f"{len(points)} 3 0 0"]
    lines += [f"{i + 1} {p[0]} {p[1]} {p[2]}" for i, p in enumerate(points)]
    lines += ["", "*ELEMENTS", "TET", f"{len(tets)} 4 0"]
    lines += [f"{i + 1} " + " ".join(str(v + 1) for v in t) for i, t in enumerate(tets)]
    lines += ["", "*MATERIAL soft", "ENU, 1000, 1e6, 0.45", "*MATERIAL hard", "ENU, 1200, 1e8, 0.3",
              "", "*SET upper", "4, 5, 6,", "", "*REGION", "allElements, soft", "upper, hard", ""]
    open(write("vega", "cube.veg"), "w").write("\n".join(lines))

    lines = ["MFEM mesh v1.0", "", "dimension", "3", "", "elements", str(len(tets))]
    lines += [f"{r} 4 " + " ".join(map(str, t)) for r, t in zip(regions[1], tets)]
    lines += ["", "boundary", "1", "1 2 0 1 2", "", "vertices", str(len(points)), "3"]
    lines += [" ".join(map(str, p)) for p in points]
    open(write("mfem", "cube.mesh"), "w").write("\n".join(lines) + "\n")

    open(write("bou", "fixed.bou"), "w").write("1,2,3,\n4, 8 # comment\n")

    # .npy as numpy writes it: each case the reader handles, plus one dtype it refuses.
    np.save(write("npy", "vector.npy"), np.array([0.0, -0.0, 1.5, np.nan, np.inf]))
    np.save(write("npy", "fortran_f4.npy"), np.asfortranarray(np.arange(6, dtype="<f4").reshape(2, 3)))
    np.save(write("npy", "big_endian.npy"), np.array([[1.0, -2.5], [1e300, 5e-324]], dtype=">f8"))
    with open(write("npy", "version2.npy"), "wb") as f:
        np.lib.format.write_array(f, np.arange(3.0), version=(2, 0))
    np.save(write("npy", "empty.npy"), np.zeros((0, 3)))
    np.save(write("npy", "int32.npy"), np.arange(4, dtype="<i4"))


if __name__ == "__main__":
    main()
