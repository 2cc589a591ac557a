"""quiver.Model: what it reports against what the suite's beam is known to be, its arrays as views
that keep it alive, the reduced elastic model against finite differences, and refused files."""
import gc
import weakref

import numpy as np
import pytest

import quiver


def test_info_is_the_known_beam(model, free_model):
    i = model.info
    assert (i.r, i.vertex_count, i.tet_count, i.file_vertex_count) == (10, 13 * 3 * 3, 12 * 2 * 2 * 6, 117)
    # Two triangles per face cell: 2 x (12x2) on each of the four long faces, 2 x (2x2) on each end.
    assert i.triangle_count == 4 * 2 * 12 * 2 + 2 * 2 * 2 * 2
    assert (i.eigenvalue_count, i.basis_precision) == (6, 64)
    assert (i.youngs_modulus, i.poisson_ratio, i.density) == (1e6, 0.4, 1000.0)
    assert i.total_mass == pytest.approx(0.6 * 0.1 * 0.1 * 1000, rel=1e-12)
    assert i.bbox_min == pytest.approx((0, 0, 0)) and i.bbox_max == pytest.approx((0.6, 0.1, 0.1))
    assert i.material_is_uniform and not i.has_rigid_body
    assert (i.render_vertex_count, i.render_triangle_count) == (0, 0)
    assert i.time_step == pytest.approx(1 / 60)
    assert set(i.as_dict()) >= {"r", "rayleigh_beta", "bbox_max", "has_modal_rotations"}
    assert i.as_dict()["tet_count"] == 288
    with pytest.raises(AttributeError):
        i.r = 3
    assert free_model.info.has_rigid_body and free_model.info.r == 16


def test_stored_arrays_describe_the_beam(model):
    X = model.rest_positions
    assert X.shape == (117, 3) and X.dtype == np.float64
    for axis, (length, cells) in enumerate([(0.6, 12), (0.1, 2), (0.1, 2)]):
        np.testing.assert_allclose(np.unique(X[:, axis].round(12)), np.linspace(0, length, cells + 1), atol=1e-12)
    assert sorted(model.vertex_map.tolist()) == list(range(117))
    T = model.triangles
    assert T.shape == (208, 3) and T.dtype == np.uint32
    corners = X[T]  # (t, 3, 3)
    normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    # Each surface triangle lies in a face of the box and faces out of it.
    on_face = [(np.ptp(corners[:, :, a], axis=1) < 1e-12) for a in range(3)]
    assert np.all(on_face[0] | on_face[1] | on_face[2])
    assert np.all(np.einsum("ij,ij->i", normals, corners.mean(axis=1) - [0.3, 0.05, 0.05]) > 0)
    assert model.gravity.shape == (3, 10)
    assert model.render_rest_positions is None and model.render_uvs is None


def test_eigenvalues_bound_the_reduced_ones_from_below(model):
    # Rayleigh-Ritz: the i-th eigenvalue of K(0) restricted to the M-orthonormal basis is at least
    # the i-th of the full model; the basis holds the lowest modes nearly, so the first is close.
    lam = model.eigenvalues
    assert np.all(np.diff(lam) > 0) and lam[0] > 0
    reduced = np.linalg.eigvalsh(model.evaluate(np.zeros(10))[2])
    assert np.all(reduced[:6] >= lam * (1 - 1e-9))
    assert reduced[0] == pytest.approx(lam[0], rel=0.01)


def test_a_free_basis_feels_no_gravity(free_model):
    # Row a of the gravity projection is U^T M e_a; a free model's elastic basis is M-orthogonal to
    # the rigid translations e_a, so a uniform field only moves its frame.
    assert np.abs(free_model.gravity).max() < 1e-10


def test_arrays_are_read_only_views_that_keep_the_model_alive(model_path):
    m = quiver.Model(model_path)
    for name in ["rest_positions", "triangles", "vertex_map", "eigenvalues", "gravity"]:
        a, b = getattr(m, name), getattr(m, name)
        assert np.shares_memory(a, b), name
        assert not a.flags.writeable, name
        with pytest.raises(ValueError):
            a[0] = 0
    del a, b  # the loop's last views
    rest = m.rest_positions
    copy = rest.copy()
    alive = weakref.ref(m)
    del m
    gc.collect()
    assert alive() is not None
    np.testing.assert_array_equal(rest, copy)
    del rest
    gc.collect()
    assert alive() is None


def test_evaluate_is_the_gradient_and_hessian_of_the_energy(model, model_path):
    r = model.info.r
    q = np.random.default_rng(1).normal(size=r)
    q *= 0.03 / np.abs(model.displacements(q)).max()  # 3 cm on a 60 cm beam: well into the nonlinear range
    energy, force, K = model.evaluate(q)
    assert energy > 0 and force.shape == (r,) and K.shape == (r, r)
    np.testing.assert_allclose(K, K.T, rtol=0, atol=1e-9 * np.abs(K).max())
    h = 1e-6 * np.abs(q).max()
    fd_force = np.empty(r)
    fd_K = np.empty((r, r))
    for j in range(r):
        e = np.zeros(r)
        e[j] = h
        plus, minus = model.evaluate(q + e), model.evaluate(q - e)
        fd_force[j] = (plus[0] - minus[0]) / (2 * h)
        fd_K[:, j] = (plus[1] - minus[1]) / (2 * h)
    np.testing.assert_allclose(force, fd_force, rtol=0, atol=1e-6 * np.abs(force).max())
    np.testing.assert_allclose(K, fd_K, rtol=0, atol=1e-6 * np.abs(K).max())
    # The half-precision coefficients give the same within the documented 1e-7.
    half = quiver.Model(model_path, coefficient_precision=32)
    np.testing.assert_allclose(half.evaluate(q)[1], force, rtol=0, atol=1e-6 * np.abs(force).max())


def test_displacements_are_linear_and_zero_where_clamped(model, basis):
    rng = np.random.default_rng(2)
    q1, q2 = rng.normal(size=10), rng.normal(size=10)
    u = model.displacements(2 * q1 - 3 * q2)
    assert u.shape == (117, 3) and u.dtype == np.float32
    expected = 2 * model.displacements(q1).astype(float) - 3 * model.displacements(q2).astype(float)
    np.testing.assert_allclose(u, expected, rtol=0, atol=1e-6 * np.abs(expected).max())
    np.testing.assert_allclose(u.reshape(-1), basis @ (2 * q1 - 3 * q2), rtol=0, atol=1e-6 * np.abs(expected).max())
    clamped = model.rest_positions[:, 0] < 1e-9
    assert clamped.sum() == 9 and np.all(u[clamped] == 0)


def test_bad_files_and_arguments_are_refused_with_their_reason(model, model_path, tmp_path):
    with pytest.raises(OSError, match="/nonexistent/beam.qvr: cannot open"):
        quiver.Model("/nonexistent/beam.qvr")
    data = open(model_path, "rb").read()
    with pytest.raises(quiver.FormatError) as refused:
        quiver.Model.from_bytes(data[: len(data) // 2])
    assert isinstance(refused.value, ValueError) and len(str(refused.value)) > 10
    broken = tmp_path / "broken.qvr"
    broken.write_bytes(data[:100])
    with pytest.raises(ValueError, match=str(broken)):
        quiver.Model(broken)
    with pytest.raises(ValueError, match="coefficient_precision must be 32 or 64"):
        quiver.Model(model_path, coefficient_precision=16)
    with pytest.raises(TypeError):
        quiver.Model.from_bytes(12)
    assert quiver.Model.from_bytes(bytearray(data)).info.r == 10
    with pytest.raises(ValueError, match=r"q must have shape \(10,\), got \(9,\)"):
        model.evaluate(np.zeros(9))
    with pytest.raises(ValueError, match="NaN or infinity"):
        model.displacements([0, 0, np.nan, 0, 0, 0, 0, 0, 0, 0])
    with pytest.raises(TypeError, match="array of numbers"):
        model.evaluate("ten numbers")
