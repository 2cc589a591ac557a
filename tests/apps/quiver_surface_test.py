#!/usr/bin/python3
"""quiver-bake on an artist's triangle surface, as a technical artist meets it: a UV sphere written as
an OBJ (split at its seams, with normals and UVs) baked on 2 ranks becomes tets (NAME.tets.vtu) whose
volume and quality are measured here, not taken from the bake's print; the render mesh at rest is the
input's vertices; pulled, each render vertex is where the barycentric interpolation of its deformed
tet puts it (found here from the .vtu files alone); every kind of bad surface gets a clear error; a
public artist's mesh from Debian's assimp-testmodels bakes."""
import glob
import json
import math
import os
import shutil
import signal
import subprocess
import tempfile
import time
import unittest

import numpy as np

BAKE = os.environ["QUIVER_BAKE"]
QUIVER = os.environ["QUIVER"]
VIEW = os.environ.get("QUIVER_VIEW", "")
XVFB_RUN = shutil.which("xvfb-run")
MPIEXEC = os.environ.get("MPIEXEC") or "mpirun"
HUMAN = "/usr/share/assimp/models/BLEND/HUMAN.blend"


def run(*args, ok=True):
    p = subprocess.run([*map(str, args)], capture_output=True, text=True, stdin=subprocess.DEVNULL, timeout=600)
    if ok:
        assert p.returncode == 0, p.stderr
    return p


def uv_sphere(radius=0.5, segments=24, rings=12):
    """Positions, UVs and outward triangles of a UV sphere, its seam column repeated (as artists' files are)."""
    v, uv = [], []
    for j in range(rings + 1):
        theta = math.pi * j / rings
        for i in range(segments + 1):
            phi = 2 * math.pi * i / segments
            v.append((radius * math.sin(theta) * math.cos(phi), radius * math.sin(theta) * math.sin(phi), radius * math.cos(theta)))
            uv.append((i / segments, 1 - j / rings))
    tris = []
    for j in range(rings):
        for i in range(segments):
            a, b = j * (segments + 1) + i, j * (segments + 1) + i + 1
            c, d = a + segments + 1, b + segments + 1
            if j > 0:
                tris.append((a, c, b))
            if j < rings - 1:
                tris.append((b, c, d))
    return np.array(v), np.array(uv), tris


def write_obj(path, v, uv, tris):
    with open(path, "w") as f:
        f.write("".join(f"v {x:.9f} {y:.9f} {z:.9f}\n" for x, y, z in v))
        f.write("".join(f"vt {a:.6f} {b:.6f}\n" for a, b in uv))
        f.write("".join("vn {:.6f} {:.6f} {:.6f}\n".format(*(p / np.linalg.norm(p))) for p in v))
        f.write("".join("f " + " ".join(f"{k + 1}/{k + 1}/{k + 1}" for k in t) + "\n" for t in tris))


class Vtu:
    """A .vtu with appended raw data (what the tools write), read here from VTK's XML format alone
    (meshio 1.11 mixes up arrays whose rewritten offsets collide)."""

    def __init__(self, path):
        import struct
        import xml.etree.ElementTree as ET
        with open(path, "rb") as f:
            raw = f.read()
        start = raw.index(b"<AppendedData")
        data = raw[raw.index(b"_", start) + 1:]
        root = ET.fromstring(raw[:start] + b"</VTKFile>")
        types = {"Float32": "<f4", "Float64": "<f8", "Int64": "<i8", "Int32": "<i4", "UInt8": "u1"}
        self.arrays = {}
        for a in root.iter("DataArray"):
            offset = int(a.get("offset"))
            size = struct.unpack("<Q", data[offset:offset + 8])[0]
            values = np.frombuffer(data[offset + 8:offset + 8 + size], types[a.get("type")])
            self.arrays[a.get("Name")] = values.reshape(-1, int(a.get("NumberOfComponents", 1))).squeeze()
        self.points = self.arrays["Points"].astype(float)


def tets_of(vtu):
    return vtu.arrays["connectivity"].reshape(-1, 4)


def read_vtu(path):
    return Vtu(path)


def polyhedral_volume(v, tris):
    return sum(np.dot(v[a], np.cross(v[b], v[c])) for a, b, c in tris) / 6


def dihedral_min(x, tets):
    """Smallest dihedral angle (degrees) over all tets, from the face normals."""
    worst = 180.0
    faces = [(1, 2, 3), (0, 3, 2), (0, 1, 3), (0, 2, 1)]
    for t in tets:
        p = x[t]
        normals = []
        for f in faces:
            n = np.cross(p[f[1]] - p[f[0]], p[f[2]] - p[f[0]])
            normals.append(n / np.linalg.norm(n))
        for i in range(4):
            for j in range(i + 1, 4):
                worst = min(worst, 180 - math.degrees(math.acos(max(-1, min(1, np.dot(normals[i], normals[j]))))))
    return worst


class Surface(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.v, cls.uv, cls.tris = uv_sphere()
        cls.obj = os.path.join(cls.tmp.name, "ball.obj")
        write_obj(cls.obj, cls.v, cls.uv, cls.tris)
        cls.name = os.path.join(cls.tmp.name, "ball")
        p = run(MPIEXEC, "-n", 2, "--oversubscribe", BAKE, cls.obj, "--tets", 2000, "--E", "1e5", "--nu", "0.4",
                "--density", "1000", "--fix", "z<min+0.06", "--modes", 8, "--rank", 16, "--no-fidelity", "-o", cls.name)
        cls.bake_output = p.stdout
        # The same tets with a finer sphere inside as the render mesh (--render-mesh), and with none.
        cls.inner_v, cls.inner_uv, cls.inner_tris = uv_sphere(radius=0.35, segments=40, rings=20)
        inner = os.path.join(cls.tmp.name, "inner.obj")
        write_obj(inner, cls.inner_v, cls.inner_uv, cls.inner_tris)
        common = ["--E", "1e5", "--nu", "0.4", "--density", "1000", "--fix", "z<min+0.06", "--modes", 8, "--rank", 16, "--no-fidelity"]
        cls.inner = os.path.join(cls.tmp.name, "ball_inner")
        run(BAKE, cls.name + ".tets.vtu", "--render-mesh", inner, *common, "-o", cls.inner)
        cls.plain = os.path.join(cls.tmp.name, "ball_plain")
        run(BAKE, cls.name + ".tets.vtu", *common, "-o", cls.plain)
        cls.free = os.path.join(cls.tmp.name, "ball_free")  # no fixed vertex: it flies
        run(BAKE, cls.name + ".tets.vtu", "--render-mesh", inner, *[a for a in common if a not in ("--fix", "z<min+0.06")],
            "-o", cls.free)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_tets_fill_the_surface_with_quality(self):
        m = read_vtu(self.name + ".tets.vtu")
        tets = tets_of(m)
        x = m.points
        volume = sum(abs(np.linalg.det(np.array([x[t[1]] - x[t[0]], x[t[2]] - x[t[0]], x[t[3]] - x[t[0]]]))) / 6 for t in tets)
        surface = polyhedral_volume(self.v, self.tris)
        worst = dihedral_min(x, tets)
        print(f"{len(tets)} tets for a target of 2000; volume {volume:.5f} m^3 of the surface's {surface:.5f} "
              f"({volume / surface - 1:+.2%}); smallest dihedral {worst:.1f} degrees")
        self.assertGreater(len(tets), 0.8 * 2000)
        self.assertLess(len(tets), 1.25 * 2000)
        self.assertLess(abs(volume / surface - 1), 0.03)  # Gmsh's surface at the tets' edge cuts chords of the input
        self.assertGreaterEqual(worst, 5.0)  # the floor the bake promises (--min-dihedral)

    def test_the_render_mesh_at_rest_is_the_input(self):
        info = json.loads(run(QUIVER, "info", self.name + ".qvr").stdout)
        self.assertEqual(info["render_triangles"], len(self.tris))
        self.assertEqual(info["render_vertices"], 3 * len(self.tris))  # Assimp gives each OBJ corner its own vertex
        # At rest (frame 0 is not written: the rest render mesh is the .vtu of a 0 N pull) it is the input.
        rest_out = os.path.join(self.tmp.name, "rest", "ball")
        run(QUIVER, "sim", self.name + ".qvr", "--force", "0,0,0", "--steps", 1, "--hold", 1, "-o", rest_out)
        rest = read_vtu(rest_out + "_render_00001.vtu").points
        size = np.ptp(self.v, axis=0).max()
        corners = self.v[np.array(self.tris).ravel()]
        self.assertEqual(rest.shape, corners.shape)
        gap = np.abs(np.sort(rest, axis=0) - np.sort(corners, axis=0)).max() / size
        print(f"rest render mesh: its vertices are the input's within {gap:.2g} of its size")
        self.assertLess(gap, 1e-6)

    def test_a_render_mesh_inside_moves_as_its_tets(self):
        # --render-mesh: a finer sphere inside the ball, every vertex in some tet. Pulled, each is where
        # the barycentric interpolation of its tet, deformed, puts it (tets found here from the .vtu).
        v, tris, name = self.inner_v, self.inner_tris, self.inner
        out = os.path.join(self.tmp.name, "pull_inner", "ball")
        run(QUIVER, "sim", name + ".qvr", "--group", "z>max-0.06", "--force", "0,40,0", "--steps", 20, "--hold", 20,
            "-o", out, "--every", 20)
        tets_mesh = read_vtu(self.name + ".tets.vtu")
        X, tets = tets_mesh.points, tets_of(tets_mesh)
        frame = read_vtu(out + "_00020.vtu")
        self.assertLess(np.abs(frame.points - X).max(), 1e-9)  # the frames are over the same tets, same order
        deformed = frame.points + frame.arrays["displacement"]
        rest = v[np.array(tris).ravel()]  # Assimp's order: each OBJ corner in turn
        render = read_vtu(out + "_render_00020.vtu").points
        D = np.stack([X[tets[:, k]] - X[tets[:, 0]] for k in (1, 2, 3)], axis=2)
        inverse = np.linalg.inv(D)
        worst, moved = 0.0, 0.0
        for i, p in enumerate(rest):
            b = np.einsum("tij,tj->ti", inverse, p - X[tets[:, 0]])
            w = np.column_stack([1 - b.sum(axis=1), b])
            t = int(np.argmax(w.min(axis=1)))
            self.assertGreater(w[t].min(), -1e-9)
            worst = max(worst, np.abs(w[t] @ deformed[tets[t]] - render[i]).max())
            moved = max(moved, np.abs(render[i] - p).max())
        print(f"pulled: {len(rest)} render vertices within {worst:.2g} m of their tets' interpolation; moved up to {moved:.3g} m")
        self.assertGreater(moved, 5e-3)
        self.assertLess(worst, 1e-6 + 1e-5 * moved)  # float32 outputs

    @unittest.skipUnless(XVFB_RUN and VIEW, "SKIPPED: xvfb-run (Debian package xvfb) or quiver-view not found")
    def test_the_viewer_draws_the_render_mesh(self):
        # The same tets drawn with the finer sphere inside as render mesh cover about (0.35/0.5)^2 of
        # the pixels they cover without one.
        import matplotlib.image

        def covered(model, name, *extra):
            path = os.path.join(self.tmp.name, name)
            p = subprocess.run([XVFB_RUN, "-a", "-s", "-screen 0 1280x1024x24", VIEW, model + ".qvr", "--size", "640,480",
                                "--no-panel", "--screenshot", path, *map(str, extra)], capture_output=True, text=True, timeout=120,
                               stdin=subprocess.DEVNULL)
            self.assertEqual(p.returncode, 0, p.stderr)
            image = matplotlib.image.imread(path)[:, :, :3]
            return np.abs(image - image[0, 0]).sum(axis=2) > 0.1

        plain, inner = covered(self.plain, "plain.png", "--frames", 5), covered(self.inner, "inner.png", "--frames", 5)
        ratio = inner.sum() / plain.sum()
        print(f"viewer: {inner.sum()} pixels with the inner render mesh, {plain.sum()} without one ({ratio:.2f}; (0.35/0.5)^2 = 0.49)")
        self.assertGreater(ratio, 0.35)
        self.assertLess(ratio, 0.65)
        # --gpu-skinning (the render basis in the vertex shader) covers the pixels the CPU's output does:
        # sagging under gravity, and falling in flight onto the ground, turned.
        for model, args in ((self.inner, ["--frames", 40, "--gravity"]),
                            (self.free, ["--frames", 40, "--free", "--angular-velocity", "1,2,0"])):
            cpu = covered(model, "cpu.png", *args)
            gpu = covered(model, "gpu.png", *args, "--gpu-skinning")
            print(f"--gpu-skinning {' '.join(map(str, args))}: {np.count_nonzero(cpu != gpu)} of {cpu.sum()} pixels differ")
            self.assertLess(np.count_nonzero(cpu != gpu), 0.01 * inner.sum())  # 1% of the ball's own pixels

    def bad(self, name, text, *extra):
        path = os.path.join(self.tmp.name, name)
        with open(path, "w") as f:
            f.write(text)
        p = run(BAKE, path, *extra, "-o", os.path.join(self.tmp.name, "bad"), ok=False)
        self.assertEqual(p.returncode, 1, p.stderr)
        self.assertIn(path, p.stderr)
        self.assertNotIn("Traceback", p.stderr)
        return p.stderr

    def cube_obj(self, lo=0.0, size=1.0, offset=0):
        corners = [(lo + size * x, lo + size * y, lo + size * z) for z in (0, 1) for y in (0, 1) for x in (0, 1)]
        corners = [tuple(f"{c:g}" for c in corner) for corner in corners]
        quads = [(0, 4, 6, 2), (1, 3, 7, 5), (0, 1, 5, 4), (2, 6, 7, 3), (0, 2, 3, 1), (4, 5, 7, 6)]
        text = "".join("v {} {} {}\n".format(*c) for c in corners)
        return text, ["f " + " ".join(str(offset + k + 1) for k in q) for q in quads]

    def test_a_surface_without_material_is_named(self):
        # A surface carries no material: the warning names it, not the tets the bake meshed from it.
        p = run(BAKE, self.obj, "--tets", 500, "--fix", "z<min+0.06", "--modes", 2, "--rank", 2, "--no-fidelity", "--quiet",
                "-o", os.path.join(self.tmp.name, "unnamed_material"))
        self.assertIn(f"{self.obj} defines no material; using E = ", p.stderr)
        self.assertNotIn(".tets.vtu defines no material", p.stderr)

    def test_bad_surfaces_are_named(self):
        verts, faces = self.cube_obj()
        self.assertIn("open edges (holes)", self.bad("open.obj", verts + "\n".join(faces[:5]) + "\n", "--no-fill-holes"))
        verts2, faces2 = self.cube_obj(3.0, 1.0, 8)
        self.assertIn("separate pieces", self.bad("two.obj", verts + verts2 + "\n".join(faces + faces2) + "\n"))
        # Two cubes sharing an edge: four triangles on it.
        shared, _ = self.cube_obj(1.0, 1.0)
        fin = verts + shared + "\n".join(faces) + "\n" + "\n".join(
            "f " + " ".join(str({0: 4, 4: 8}.get(k, 9 + k)) for k in q) for q in [(0, 4, 6, 2), (1, 3, 7, 5), (0, 1, 5, 4), (2, 6, 7, 3), (0, 2, 3, 1), (4, 5, 7, 6)]) + "\n"
        self.assertIn("non-manifold", self.bad("fin.obj", fin))
        folded = verts.replace("1 1 1\n", "0.6 0.3 -0.5\n")
        self.assertIn("cross each other", self.bad("folded.obj", folded + "\n".join(faces) + "\n"))
        self.assertIn("beyond 1e9", self.bad("huge.obj", verts.replace("1 1 1\n", "1e12 1 1\n") + "\n".join(faces) + "\n"))
        message = self.bad("points.obj", verts)
        self.assertTrue("holds no triangle" in message or "contains no faces" in message, message)
        message = self.bad("empty.obj", "")
        self.assertTrue("cannot read" in message or "no triangle" in message, message)
        # Named at its line and v record, not at Assimp's number for a face's corner.
        message = self.bad("nan.obj", verts.replace("1 1 1\n", "nan 1 1\n") + "\n".join(faces) + "\n")
        self.assertRegex(message, r"nan\.obj:\d+: vertex \d+: coordinate 'nan' is not finite")

    def test_a_bake_stopped_while_gmsh_meshes_leaves_nothing_behind(self):
        # SIGTERM, or Ctrl-C's SIGINT, while gmsh meshes: gmsh is stopped, the bake's temporary folder
        # removed and the bake ends as signalled (std::system() left gmsh running and the folder).
        def gmsh_children(pid):  # not Open MPI's own helpers
            found = []
            for stat in glob.glob("/proc/[0-9]*/stat"):
                try:
                    with open(stat) as f:
                        name, fields = f.read().split(" (", 1)[1].rsplit(")", 1)
                except OSError:
                    continue
                if int(fields.split()[1]) == pid and name == "gmsh":
                    found.append(int(stat.split("/")[2]))
            return found

        # SIGTERM as kill or a job scheduler sends it: to the bake alone. SIGINT as a terminal's Ctrl-C
        # sends it: to the bake's whole process group, gmsh included, which may end of it first.
        for sig, whole_group in ((signal.SIGTERM, False), (signal.SIGINT, True)):
            with tempfile.TemporaryDirectory() as tmp:
                p = subprocess.Popen([BAKE, self.obj, "--tets", "400000", "--modes", "8", "--rank", "16", "--no-fidelity",
                                      "-o", os.path.join(tmp, "stopped")], env=dict(os.environ, TMPDIR=tmp),
                                     stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                                     start_new_session=True,  # a group of its own, as a terminal's job
                                     preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))  # whatever we ignore
                try:
                    deadline, started = time.monotonic() + 120, []
                    while not started and p.poll() is None and time.monotonic() < deadline:
                        time.sleep(0.05)
                        started = glob.glob(os.path.join(tmp, "quiver-mesher-*", "surface.geo"))
                    self.assertTrue(started, "gmsh never started")
                    time.sleep(0.5)
                    gmsh = gmsh_children(p.pid)
                    self.assertTrue(gmsh, "gmsh is not the bake's child")
                    if whole_group:
                        os.killpg(p.pid, sig)
                    else:
                        p.send_signal(sig)
                    _, err = p.communicate(timeout=60)
                finally:
                    if p.poll() is None:
                        os.killpg(p.pid, signal.SIGKILL)
                        p.wait()
                self.assertEqual(p.returncode, -sig, err)
                self.assertIn("quiver-bake: interrupted by", err)
                self.assertEqual(glob.glob(os.path.join(tmp, "quiver-mesher-*")), [])
                for pid in gmsh:
                    self.assertFalse(os.path.exists(f"/proc/{pid}"), f"gmsh ({pid}) still runs after {sig.name}")

    def test_a_gmsh_run_past_the_time_limit_stops_the_bake(self):
        # A hung gmsh held the bake forever. Here a run that would take far longer than its limit:
        # it is stopped, its folder removed, and the bake fails saying so, before any output.
        with tempfile.TemporaryDirectory() as tmp:
            name = os.path.join(tmp, "out_of_time")
            start = time.monotonic()
            p = subprocess.run([BAKE, self.obj, "--tets", "400000", "--mesher-time-limit", "1", "--modes", "2", "--rank", "2",
                                "--no-fidelity", "--quiet", "-o", name], env=dict(os.environ, TMPDIR=tmp),
                               capture_output=True, text=True, timeout=120, stdin=subprocess.DEVNULL)
            elapsed = time.monotonic() - start
            self.assertNotEqual(p.returncode, 0)
            self.assertIn(f"{self.obj}: gmsh ran past the time limit of 1 s (--mesher-time-limit)", p.stderr)
            self.assertLess(elapsed, 30)  # the limit, gmsh's two seconds to stop, and the bake's start
            self.assertEqual(glob.glob(os.path.join(tmp, "quiver-mesher-*")), [])
            self.assertEqual(sorted(os.listdir(tmp)), [])
            for cwd in glob.glob("/proc/[0-9]*/cwd"):
                try:
                    self.assertFalse(os.readlink(cwd).startswith(tmp), f"{cwd} still runs in the bake's folder")
                except OSError:
                    continue

    def test_a_public_artist_mesh_bakes(self):
        if not os.path.exists(HUMAN):
            self.skipTest(f"Debian's assimp-testmodels is not installed ({HUMAN})")
        name = os.path.join(self.tmp.name, "human")
        p = run(BAKE, HUMAN, "--tets", 3000, "--modes", 6, "--rank", 12, "--no-fidelity", "-o", name)
        print(next(line for line in p.stdout.splitlines() if "tets (edge" in line))
        info = json.loads(run(QUIVER, "info", name + ".qvr").stdout)
        self.assertEqual(info["render_vertices"], 17120)
        self.assertEqual(info["render_triangles"], 8560)
        self.assertGreaterEqual(dihedral_min(read_vtu(name + ".tets.vtu").points, tets_of(read_vtu(name + ".tets.vtu"))), 5.0)


if __name__ == "__main__":
    unittest.main(verbosity=2)
