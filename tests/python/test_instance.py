"""quiver.Instance on the fixed beam: its defaults, statics against an independent Newton solve,
positions against the basis, constraints, state and snapshots, and refused arguments."""
import numpy as np
import pytest

import quiver


def settle(instance, steps, load=None):
    for _ in range(steps):
        if load:
            load(instance)
        assert instance.step() != quiver.StepStatus.RESET


def static_equilibrium(model, reduced_force):
    """R(q) = f by Newton on Model.evaluate, independently of any integrator."""
    q = np.zeros(model.info.r)
    for _ in range(50):
        _, R, K = model.evaluate(q)
        q -= np.linalg.solve(K, R - reduced_force)
    assert np.linalg.norm(model.evaluate(q)[1] - reduced_force) < 1e-12 * np.linalg.norm(reduced_force)
    return q


def test_defaults_are_the_documented_ones(model):
    s = quiver.Instance(model)
    c = s.config
    assert (c["integrator"], c["solver"], c["elasticity"]) == ("newmark", "minimize", "stvk")
    assert (c["newton_iterations"], c["newton_tolerance"], c["max_constraints"], c["max_contacts"]) == (8, 1e-6, 4, 64)
    assert c["time_step"] == model.info.time_step and c["rayleigh_beta"] == model.info.rayleigh_beta
    assert c["max_displacement"] == pytest.approx(100 * np.linalg.norm([0.6, 0.1, 0.1]))
    assert not s.flying and s.model is model
    assert set(quiver.INTEGRATORS) == {"newmark", "euler", "central"} and set(quiver.SOLVERS) == {"minimize", "newton"}
    e = quiver.Instance(model, integrator="euler", solver="newton", newton_iterations=1, rayleigh_alpha=2.0)
    assert (e.config["integrator"], e.config["solver"], e.config["newton_iterations"], e.config["rayleigh_alpha"]) == (
        "euler", "newton", 1, 2.0)
    assert np.all(s.q == 0) and np.all(s.velocity == 0) and s.energies() == (0, 0)


def test_a_fixed_newton_step_that_would_blow_up_is_the_minimisers_and_says_so(model, tip):
    s = quiver.Instance(model, solver="newton", newton_iterations=1, max_displacement=0.01)
    s.add_vertex_force(tip, (0, 0, -1e9))
    assert s.step() != quiver.StepStatus.RESET
    assert s.last_step["minimized"] and np.all(np.isfinite(s.q)) and np.abs(s.q).max() > 0
    s.step()
    assert np.all(np.isfinite(s.q))


def test_an_instance_keeps_its_model_alive(model_path):
    s = quiver.Instance(quiver.Model(model_path))
    s.set_gravity((0, 0, -quiver.STANDARD_GRAVITY))
    s.step(10)
    assert s.model.rest_positions.shape == (117, 3) and s.positions()[:, 2].min() < 0


def test_a_constant_tip_force_settles_where_the_elastic_force_balances_it(model, tip, basis):
    f = np.array([0.0, 0.5, -2.0])
    reduced = basis[3 * tip:3 * tip + 3].T @ f  # U^T f
    expected = static_equilibrium(model, reduced)
    s = quiver.Instance(model, rayleigh_alpha=20.0)
    settle(s, 300, lambda s: s.add_vertex_force(tip, f))
    np.testing.assert_allclose(s.q, expected, rtol=0, atol=1e-5 * np.abs(expected).max())
    assert np.abs(s.velocity).max() < 1e-6 * np.abs(expected).max() / s.time_step
    # positions() is X + U q for the instance's own q.
    x = s.positions()
    assert x.dtype == np.float32 and x.shape == (117, 3)
    np.testing.assert_allclose(x, model.rest_positions + model.displacements(s.q), rtol=0, atol=2e-7)
    out = np.empty((117, 3), np.float32)
    assert s.positions(out=out) is out and np.array_equal(out, x)
    np.testing.assert_array_equal(s.positions_of([tip, 0]), x[[tip, 0]])
    assert s.positions_of([]).shape == (0, 3)
    kinetic, elastic = s.energies()
    assert elastic == pytest.approx(model.evaluate(s.q)[0], rel=1e-12) and kinetic < 1e-12
    # The same load through add_reduced_force settles at the same place.
    r = quiver.Instance(model, rayleigh_alpha=20.0)
    settle(r, 300, lambda r: r.add_reduced_force(reduced))
    np.testing.assert_allclose(r.q, expected, rtol=0, atol=1e-5 * np.abs(expected).max())


def test_gravity_settles_at_the_static_sag(model):
    g = np.array([0, 0, -quiver.STANDARD_GRAVITY])
    expected = static_equilibrium(model, model.gravity.T @ g)
    s = quiver.Instance(model, rayleigh_alpha=20.0)
    s.set_gravity(g)
    settle(s, 300)
    np.testing.assert_allclose(s.q, expected, rtol=0, atol=1e-5 * np.abs(expected).max())


def test_constraints_hold_their_vertices_at_the_targets(model, tip, basis):
    X = model.rest_positions
    lift = np.array([0.0, 0.0, 0.05])
    k = 1e4
    s = quiver.Instance(model, rayleigh_alpha=20.0)
    s.set_constraint(0, [tip], [X[tip] + lift], k)
    settle(s, 240)
    # At rest the spring's pull k (target - x) on the vertex is what the elastic force balances.
    U_tip = basis[3 * tip:3 * tip + 3]
    x = X[tip] + U_tip @ s.q
    R = model.evaluate(s.q)[1]
    np.testing.assert_allclose(R, U_tip.T @ (k * (X[tip] + lift - x)), rtol=0, atol=1e-5 * np.abs(R).max())
    # Against the beam's ~300 N/m at the tip the vertex comes within a few percent of the 5 cm.
    assert np.abs(s.positions()[tip] - (X[tip] + lift)).max() < 3e-3
    # A group (the whole end face) held at a lifted copy of itself: its centre follows.
    end = np.flatnonzero(np.abs(X[:, 0] - 0.6) < 1e-9)
    assert len(end) == 9
    s.set_constraint(0, end, X[end] + lift, k)
    settle(s, 240)
    np.testing.assert_allclose(s.positions()[end].mean(axis=0), X[end].mean(axis=0) + lift, rtol=0, atol=1e-3)
    s.clear_constraint(0)
    settle(s, 240)
    assert np.abs(s.positions() - X).max() < 1e-4


def test_state_can_be_set_and_a_snapshot_repeats_the_same_bits(model, tip):
    s = quiver.Instance(model)
    s.set_gravity((0, 0, -9.81))

    def run(steps, start):
        states = []
        for k in range(start, start + steps):
            s.add_vertex_force(tip, (0, np.sin(0.3 * k), 1.0))
            s.step()
            states.append(np.concatenate([s.q, s.velocity, s.acceleration]))
        return np.array(states)

    run(20, 0)
    snapshot = s.save_snapshot()
    assert isinstance(snapshot, bytes)
    first = run(30, 20)
    s.restore_snapshot(snapshot)
    np.testing.assert_array_equal(run(30, 20), first)
    s.reset()
    assert np.all(s.q == 0) and s.energies() == (0, 0)
    q = np.linspace(-0.01, 0.01, 10)
    s.q = q
    np.testing.assert_array_equal(s.q, q)
    assert s.energies()[1] == pytest.approx(model.evaluate(q)[0], rel=1e-12)
    s.set_state(velocity=np.ones(10), acceleration=np.zeros(10))
    np.testing.assert_array_equal(s.velocity, np.ones(10))
    np.testing.assert_array_equal(s.acceleration, np.zeros(10))
    with pytest.raises(ValueError, match="snapshot of 3 bytes"):
        s.restore_snapshot(b"abc")


def test_bad_arguments_raise_with_a_clear_message(model, free_model, tip):
    s = quiver.Instance(model)
    with pytest.raises(IndexError, match="vertex 117 out of range: the model has 117 vertices"):
        s.add_vertex_force(117, (0, 0, 1))
    with pytest.raises(IndexError, match="vertex -1"):
        s.add_vertex_force(-1, (0, 0, 1))
    with pytest.raises(ValueError, match="force contains NaN"):
        s.add_vertex_force(tip, (0, np.nan, 1))
    with pytest.raises(ValueError, match=r"force must have shape \(3,\), got \(2,\)"):
        s.add_vertex_force(tip, (0, 1))
    with pytest.raises(ValueError, match=r"force must have shape \(10,\)"):
        s.add_reduced_force(np.zeros((10, 1)))
    with pytest.raises(ValueError, match="NaN or infinity"):
        s.set_gravity((0, 0, np.inf))
    with pytest.raises(ValueError, match=r"q must have shape \(10,\)"):
        s.q = np.zeros(11)
    with pytest.raises(IndexError, match="constraint slot 4 out of range"):
        s.set_constraint(4, [tip], [[0, 0, 0]], 1e3)
    with pytest.raises(TypeError, match="vertices must be integers"):
        s.set_constraint(0, [1.5], [[0, 0, 0]], 1e3)
    with pytest.raises(IndexError, match="vertex 500"):
        s.set_constraint(0, [500], [[0, 0, 0]], 1e3)
    with pytest.raises(ValueError, match=r"targets must have shape \(2, 3\)"):
        s.set_constraint(0, [1, 2], [[0, 0, 0]], 1e3)
    with pytest.raises(ValueError, match="stiffness must be positive"):
        s.set_constraint(0, [tip], [[0, 0, 0]], 0)
    with pytest.raises(ValueError, match="only a flying instance"):
        s.rigid_state
    with pytest.raises(ValueError, match="colliders are for flying instances"):
        s.set_colliders([quiver.Plane((0, 0, 1))])
    with pytest.raises(ValueError, match="no render mesh"):
        s.render()
    with pytest.raises(TypeError, match="dtype float32"):
        s.positions(out=np.zeros((117, 3)))
    with pytest.raises(ValueError, match=r"shape \(117, 3\)"):
        s.positions(out=np.zeros((116, 3), np.float32))
    frozen = np.zeros((117, 3), np.float32)
    frozen.flags.writeable = False
    with pytest.raises(ValueError, match="read-only"):
        s.positions(out=frozen)
    with pytest.raises(ValueError, match="count must be >= 0"):
        s.step(-1)
    with pytest.raises(ValueError, match="unknown integrator 'rk4': one of 'newmark', 'euler', 'central'"):
        quiver.Instance(model, integrator="rk4")
    for h in (-0.01, 1e-300):  # 1e-300: 1 / h^2 overflows
        with pytest.raises(ValueError, match="time_step must be finite and at least 1e-12 s"):
            quiver.Instance(model, time_step=h)
    with pytest.raises(ValueError, match="free_flight needs a model baked free"):
        quiver.Instance(model, free_flight=True)
    with pytest.raises(ValueError, match="penalty constraints are for pinned models"):
        quiver.Instance(free_model, free_flight=True).set_constraint(0, [0], [[0, 0, 0]], 1.0)
    with pytest.raises(TypeError):
        quiver.Instance(None)
    # Nothing above changed the instance: it still steps from rest.
    assert s.step() == quiver.StepStatus.OK and np.all(s.q == 0)
