"""quiver.bake on a small beam (2 MPI ranks where mpiexec exists), its archive read with h5py
against the model it wrote, a render mesh through Instance.render, and a failing bake."""
import os
import shutil
import subprocess

import numpy as np
import pytest

import quiver

BAKE = os.environ.get("QUIVER_BAKE")
MESH = os.environ.get("QUIVER_MESH") or shutil.which("quiver-mesh")
MPIEXEC = os.environ.get("MPIEXEC") or shutil.which("mpiexec")

pytestmark = [
    pytest.mark.skipif(not BAKE, reason="quiver-bake not built (QUIVER_BAKE unset): configure with QUIVER_BUILD_BAKE=ON"),
    pytest.mark.skipif(not MESH, reason="quiver-mesh not found (QUIVER_MESH unset and not on the PATH)"),
]


def write_box_obj(path, low, high):
    """A closed box surface inside the beam, for a render mesh."""
    corners = [(x, y, z) for x in (low[0], high[0]) for y in (low[1], high[1]) for z in (low[2], high[2])]
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    with open(path, "w") as f:
        f.writelines(f"v {x} {y} {z}\n" for x, y, z in corners)
        f.writelines(f"f {a + 1} {b + 1} {c + 1}\nf {a + 1} {c + 1} {d + 1}\n" for a, b, c, d in quads)


@pytest.fixture(scope="module")
def baked(tmp_path_factory):
    folder = tmp_path_factory.mktemp("bake")
    mesh = folder / "beam.vtu"
    subprocess.run([MESH, "beam", "--size", "1,0.1,0.1", "--cells", "8,2,2", "-o", str(mesh)], check=True,
                   capture_output=True)
    write_box_obj(folder / "box.obj", (0.02, 0.02, 0.02), (0.98, 0.08, 0.08))
    ranks = 2 if MPIEXEC else 1
    path = quiver.bake(mesh, folder / "beam.qvr", ranks=ranks, mpiexec=MPIEXEC, fix="x<min+1e-9", modes=6, rank=10,
                       E=1e6, nu=0.4, density=1000, no_fidelity=True, render_mesh=folder / "box.obj")
    return path, ranks


def test_the_archive_holds_the_basis_the_model_uses(baked):
    path, ranks = baked
    assert path.suffix == ".qvr" and path.exists() and path.with_suffix(".h5").exists()
    model = quiver.Model(path)
    archive = quiver.read_archive(path.with_suffix(".h5"))
    n, r = 9 * 3 * 3, 10
    assert (model.info.vertex_count, model.info.r) == (n, r)
    assert (model.info.youngs_modulus, model.info.poisson_ratio, model.info.density) == (1e6, 0.4, 1000)
    U = archive["/basis/vectors"]
    assert U.shape == (r, n, 3) and archive["/mesh/vertices"].shape == (n, 3)
    # Match the model's vertices to the archive's rows through the mesh file's numbering.
    row = {file: v for v, file in enumerate(archive["/mesh/file_vertex"])}
    rows = np.array([row[file] for file in model.vertex_map])
    np.testing.assert_array_equal(model.rest_positions, archive["/mesh/vertices"][rows])
    # Unit q gives each basis vector, to the .qvr's float32 basis.
    assert model.info.basis_precision == 32
    for j in range(r):
        u = model.displacements(np.eye(r)[j])
        np.testing.assert_allclose(u, U[j][rows], rtol=0, atol=1e-6 * np.abs(U[j]).max())
    np.testing.assert_allclose(model.eigenvalues, archive["/modes/eigenvalues"], rtol=1e-12)
    assert "/fidelity/displacement_error" not in archive  # no_fidelity=True reached the bake
    import h5py
    with h5py.File(path.with_suffix(".h5"), "r") as f:
        assert f["/provenance"].attrs["ranks"] == ranks
        assert "--no-fidelity" in f["/provenance"].attrs["command_line"]


def test_the_render_mesh_follows_the_tets(baked):
    path, _ = baked
    model = quiver.Model(path)
    assert model.info.render_vertex_count > 0
    rest, normals = model.render_rest_positions, model.render_normals
    assert rest.shape == (model.info.render_vertex_count, 3) and not rest.flags.writeable
    assert model.render_triangles.shape == (model.info.render_triangle_count, 3)
    assert rest[:, 0].min() == pytest.approx(0.02) and rest[:, 0].max() == pytest.approx(0.98)
    s = quiver.Instance(model)
    positions, turned = s.render()
    np.testing.assert_allclose(positions, rest, atol=1e-6)
    np.testing.assert_allclose(turned, normals, atol=1e-6)
    s.set_gravity((0, 0, -quiver.STANDARD_GRAVITY))
    s.step(30)
    out = (np.empty_like(positions), np.empty_like(turned))
    got = s.render(out=out)
    assert got[0] is out[0] and got[1] is out[1]
    # The far end sags; the normals stay unit length.
    far = rest[:, 0] > 0.9
    assert (out[0][far, 2] - rest[far, 2]).max() < -1e-3
    np.testing.assert_allclose(np.linalg.norm(out[1], axis=1), 1, atol=1e-3)


def test_a_failing_bake_raises_with_its_message(tmp_path):
    with pytest.raises(quiver.BakeError) as failed:
        quiver.bake(tmp_path / "missing.vtu", tmp_path / "out", modes=6)
    assert failed.value.returncode != 0 and "missing.vtu" in str(failed.value)
    assert not (tmp_path / "out.qvr").exists()
