#!/usr/bin/python3
"""Writes the fuzzers' seed corpus (tests/fuzz/seeds/<format>/) from one tiny box mesh, in every
encoding meshio can produce, plus hand-written Vega, MFEM and .bou files, numpy's .npy files and
.qvr models written from formats/model/QVR.md independently of the C++ writer.
Re-run after changing it: /usr/bin/python3 tests/fuzz/make_seeds.py"""
import itertools
import math
import os
import shutil
import struct
import tempfile

import meshio
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
SEEDS = os.path.join(HERE, "seeds")
# The seed folders this script writes; the others (drag_script, scenario) are written by hand.
GENERATED = ("gmsh", "vtk", "vtu", "medit", "tetgen", "vega", "mfem", "bou", "npy", "qvr", "surface")

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
    assert fmt in GENERATED, fmt
    folder = os.path.join(SEEDS, fmt)
    os.makedirs(folder, exist_ok=True)
    return os.path.join(folder, name)


def fnv1a64(data, state=0xCBF29CE484222325):
    for byte in data:
        state = ((state ^ byte) * 0x100000001B3) & 0xFFFFFFFFFFFFFFFF
    return state


def qvr_file(sections, minor=0, header_extra=b""):
    """A .qvr file (QVR.md): the header, the section table right after it, then each section
    (type, flags, bytes) at the next multiple of 64 bytes, with zero padding."""
    header_size = 64 + len(header_extra)
    offsets, end = [], header_size + 32 * len(sections)
    for _, _, data in sections:
        offsets.append(-(-end // 64) * 64)
        end = offsets[-1] + len(data)
    table = b"".join(struct.pack("<IIQQQ", t, f, o, len(d), fnv1a64(d)) for (t, f, d), o in zip(sections, offsets))
    header = b"\x89QVR\r\n\x1a\n" + struct.pack("<HHIIIQQQ8x", 1, minor, 0x01020304, header_size, len(sections),
                                                 header_size, end, fnv1a64(table))
    header += struct.pack("<Q", fnv1a64(header + header_extra))
    out = bytearray(end)
    out[:header_size + len(table)] = header + header_extra + table
    for (_, _, data), offset in zip(sections, offsets):
        out[offset:offset + len(data)] = data
    return bytes(out)


def qvr_sections(precision, with_tets):
    """One tet of side 0.1 with r = 2: the sections of types 1-8 (and 9), as (type, flags, bytes)."""
    rest = [(0.5, 0.0, -0.25), (0.6, 0.0, -0.25), (0.5, 0.1, -0.25), (0.5, 0.0, -0.15)]
    triangles = [0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3]  # outward, counter-clockwise
    r, n, file_n = 2, len(rest), 5
    eigenvalues = [400.0, 900.0]
    # Energy monomials: (0,0) (0,1) (1,1); (0,0,0) (0,0,1) (0,1,1) (1,1,1); (0,0,0,0) ... (1,1,1,1).
    energy = [200.0, 0.0, 450.0, 1.5, -2.0, 0.25, 3.0, 0.125, 0.5, -0.75, 1.0, 2.0]
    basis = [0.5 * math.sin(row + 2 * j) for row in range(3 * n) for j in range(r)]
    gravity = [0.1, -0.2, 0.0, 0.3, -0.4, 0.05]
    density = 1000.0
    lo = [min(p[a] for p in rest) for a in range(3)]
    hi = [max(p[a] for p in rest) for a in range(3)]
    info = struct.pack("<8I3d2I3d3d3dd", r, n, 1, len(triangles) // 3, file_n, len(eigenvalues), precision, 1,
                       1e5, 0.3, density, 1, 0, density * 0.1 ** 3 / 6, 0.5, 0.01, *lo, *hi, 1 / 60)
    info += bytes(192 - len(info))
    f64 = lambda values: struct.pack(f"<{len(values)}d", *values)
    u32 = lambda values: struct.pack(f"<{len(values)}I", *values)
    sections = [(1, 0, info), (2, 0, f64(energy)),
                (3, 0, f64(basis) if precision == 64 else struct.pack(f"<{len(basis)}f", *basis)),
                (4, 0, f64([x for p in rest for x in p])), (5, 0, u32(triangles)), (6, 0, u32([3, 0, 1, 2])),
                (7, 0, f64(gravity)), (8, 0, f64(eigenvalues))]
    return sections + [(9, 0, u32([0, 1, 2, 3]))] if with_tets else sections


def write_qvr_seeds():
    open(write("qvr", "float32_tets.qvr"), "wb").write(qvr_file(qvr_sections(32, True)))
    open(write("qvr", "float64.qvr"), "wb").write(qvr_file(qvr_sections(64, False)))
    # The float32 model as a later minor version writes it might: a longer header, a longer
    # MODEL_INFO, an unknown optional section, the sections in reverse order.
    sections = qvr_sections(32, True)
    sections[0] = (1, 0, sections[0][2] + struct.pack("<2d", 1.5, -2.5))
    sections.insert(4, (200, 1, b"data of a later version"))
    open(write("qvr", "newer_minor.qvr"), "wb").write(qvr_file(sections[::-1], 1, bytes(range(64))))
    # A free model: RIGID_BODY (type 12, optional) with centre c, second moments S0, B (9 x r), A (9 x r x r).
    r = 2
    rigid = [0.525, 0.025, -0.225] + [2e-4, 1e-5, 0, 1e-5, 3e-4, 0, 0, 0, 4e-4]
    rigid += [0.01 * math.cos(i) for i in range(9 * r)] + [0.05 * math.sin(i) for i in range(9 * r * r)]
    free = qvr_sections(64, True) + [(12, 1, struct.pack(f"<{len(rigid)}d", *rigid))]
    open(write("qvr", "free_rigid_body.qvr"), "wb").write(qvr_file(free))
    # A render mesh (RENDER_MESH, type 13, optional): 3 vertices in tet 0 (one outside it), one
    # triangle, normals and UVs, the render basis (3V x r).
    weights = [0.25, 0.25, 0.25, 0.25, 1, 0, 0, 0, -0.5, 0.5, 0.5, 0.5]
    header = struct.pack("<4I", 3, 1, 3, 0)
    f32 = lambda values: struct.pack(f"<{len(values)}f", *values)
    render = header + f32([0.5, 0.0, -0.25, 0.6, 0.0, -0.25, 0.55, 0.1, -0.2]) + struct.pack("<3I", 0, 1, 2)
    render += struct.pack("<3I", 0, 0, 0) + f32(weights) + f32([0, 0, 1] * 3) + f32([0, 0, 1, 0, 0, 1])
    render += f32([0.01 * i for i in range(9 * r)])
    open(write("qvr", "render_mesh.qvr"), "wb").write(qvr_file(qvr_sections(32, True) + [(13, 1, render)]))


def write_surface_seeds():
    """Small closed surfaces for fuzz_surface: the first byte picks the format (0 obj, 1 stl, 2 ply,
    3 off, 4 gltf, 5 glb), the rest is the file."""
    corners = [(x, y, z) for z in (0, 1) for y in (0, 1) for x in (0, 1)]
    quads = [(0, 4, 6, 2), (1, 3, 7, 5), (0, 1, 5, 4), (2, 6, 7, 3), (0, 2, 3, 1), (4, 5, 7, 6)]
    tris = [t for q in quads for t in ((q[0], q[1], q[2]), (q[0], q[2], q[3]))]
    obj = "".join(f"v {x} {y} {z}\n" for x, y, z in corners) + "vt 0 0\nvn 0 0 1\n"
    obj += "".join("f " + " ".join(f"{i + 1}/1/1" for i in q) + "\n" for q in quads)
    stl = "solid cube\n" + "".join("facet normal 0 0 0\nouter loop\n" + "".join(
        "vertex {} {} {}\n".format(*corners[i]) for i in t) + "endloop\nendfacet\n" for t in tris) + "endsolid cube\n"
    binary = bytes(80) + struct.pack("<I", len(tris)) + b"".join(
        struct.pack("<12fH", 0, 0, 0, *[c for i in t for c in corners[i]], 0) for t in tris)
    ply = ("ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\nproperty float z\n"
           "element face 6\nproperty list uchar int vertex_indices\nend_header\n")
    ply += "".join(f"{x} {y} {z}\n" for x, y, z in corners) + "".join("4 " + " ".join(map(str, q)) + "\n" for q in quads)
    ply_binary = ("ply\nformat binary_big_endian 1.0\nelement vertex 8\nproperty double x\nproperty double y\n"
                  "property double z\nproperty float nx\nproperty float ny\nproperty float nz\nproperty float s\n"
                  "property float t\nelement face 6\nproperty list uchar uint vertex_indices\nend_header\n").encode()
    ply_binary += b"".join(struct.pack(">3d5f", x, y, z, 0, 0, 1, x, y) for x, y, z in corners)
    ply_binary += b"".join(struct.pack(">B4I", 4, *q) for q in quads)
    off_prefixed = "STCNOFF\n8 6 0\n" + "".join(f"{x} {y} {z} 0 0 1 0.5 0.5 0.5 {x} {y}\n" for x, y, z in corners)
    off_prefixed += "".join("4 " + " ".join(map(str, q)) + " 255 0 0\n" for q in quads)
    off = "OFF\n8 6 0\n" + "".join(f"{x} {y} {z}\n" for x, y, z in corners) + "".join("4 " + " ".join(map(str, q)) + "\n" for q in quads)
    for name, kind, data in (("cube.obj", 0, obj.encode()), ("cube_ascii.stl", 1, stl.encode()), ("cube_binary.stl", 1, binary),
                             ("cube.ply", 2, ply.encode()), ("cube_binary.ply", 2, ply_binary),
                             ("cube.off", 3, off.encode()), ("cube_prefixed.off", 3, off_prefixed.encode())):
        open(write("surface", name), "wb").write(bytes([kind]) + data)


def main():
    for fmt in GENERATED:
        shutil.rmtree(os.path.join(SEEDS, fmt), ignore_errors=True)
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

    write_qvr_seeds()
    write_surface_seeds()


if __name__ == "__main__":
    main()
