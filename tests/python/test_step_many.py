"""quiver.step_many against stepping one by one (the bound quiver.h and docs/architecture.md give),
its threads against one job, and what it refuses."""
import threading

import numpy as np
import pytest

import quiver


def crowd(model, count, **config):
    """`count` beams under gravity (as tests/runtime/step_many_test.cpp's Crowd)."""
    out = []
    for _ in range(count):
        s = quiver.Instance(model, **config)
        s.set_gravity((0, 0, -9.81))
        out.append(s)
    return out


def load(instances, step, tip):
    """A push on the tip that differs per instance and flips every 20 steps, and a reduced force."""
    sign = -1.0 if (step // 20) % 2 else 1.0
    for i, s in enumerate(instances):
        s.add_vertex_force(tip, (0, sign * (2.0 + 0.5 * i), 1.0 * (i % 3)))
        reduced = np.zeros(s.model.info.r)
        reduced[i % len(reduced)] = 0.2 * sign
        s.add_reduced_force(reduced)


def states(instances):
    return np.array([np.concatenate([s.q, s.velocity]) for s in instances])


@pytest.mark.parametrize("solver", ["newton", "minimize"])
def test_states_agree_with_stepping_one_by_one(model, tip, solver):
    config = dict(solver=solver, newton_iterations=1) if solver == "newton" else {}
    count = 21  # two full groups of 8 and one of 5
    batched, single = crowd(model, count, **config), crowd(model, count, **config)
    for step in range(120):
        load(batched, step, tip)
        load(single, step, tip)
        statuses = quiver.step_many(batched)
        assert statuses == [s.step() for s in single]
    a, b = states(batched)[:, :10], states(single)[:, :10]
    largest = np.abs(b).max()
    # To rounding (1e-9 of the largest coordinate after 2 s), not bit for bit: the groups sum in
    # another order (zero would mean no group was evaluated together).
    assert largest > 1e-3
    assert 0 < np.abs(a - b).max() < 1e-9 * largest


def test_a_model_without_the_group_layout_steps_its_instances_alone(model_path, tip):
    plain = quiver.Model(model_path, group_layout=0)
    batched, single = crowd(plain, 9), crowd(plain, 9)
    for step in range(30):
        load(batched, step, tip)
        load(single, step, tip)
        quiver.step_many(batched)
        for s in single:
            s.step()
    np.testing.assert_array_equal(states(batched), states(single))
    with pytest.raises(ValueError, match="group_layout must be -1, 0 or 1"):
        quiver.Model(model_path, group_layout=2)


def test_threads_give_the_same_bits_as_one_job(model, tip):
    count = 19  # groups of 8, 8, 3 whatever the threads
    one, two, three = crowd(model, count), crowd(model, count), crowd(model, count)
    for step in range(40):
        for c in (one, two, three):
            load(c, step, tip)
        quiver.step_many(one)
        quiver.step_many(two, threads=2)
        quiver.step_many(three, threads=8)  # more threads than groups
    np.testing.assert_array_equal(states(one), states(two))
    np.testing.assert_array_equal(states(one), states(three))


def test_other_integrators_and_flying_instances_step_as_alone(model, free_model):
    euler = crowd(model, 3, integrator="euler")
    alone = crowd(model, 3, integrator="euler")
    for _ in range(10):
        quiver.step_many(euler)
        for s in alone:
            s.step()
    np.testing.assert_array_equal(states(euler), states(alone))
    flying = [quiver.Instance(free_model, free_flight=True) for _ in range(3)]
    for s in flying:
        s.set_gravity((0, 0, -9.81))
    assert quiver.step_many(flying, threads=2) == [quiver.StepStatus.OK] * 3
    assert flying[0].rigid_state.linear_velocity[2] < 0


def test_bad_arguments_are_refused(model, model_path):
    a, b = quiver.Instance(model), quiver.Instance(model)
    other = quiver.Instance(quiver.Model(model_path))
    assert quiver.step_many([]) == []
    with pytest.raises(ValueError, match="same Model object"):
        quiver.step_many([a, other])
    with pytest.raises(ValueError, match="appears twice"):
        quiver.step_many([a, b, a])
    with pytest.raises(ValueError, match="threads must be at least 1"):
        quiver.step_many([a], threads=0)
    with pytest.raises(TypeError, match="item 1 is a str"):
        quiver.step_many([a, "b"])
    assert np.all(a.q == 0)


def test_python_threads_step_instances_in_parallel_and_a_busy_instance_refuses_calls(model, tip):
    # Instance.step releases the GIL: threads stepping their own instances get what one thread gets.
    together, apart = crowd(model, 4), crowd(model, 4)

    def run(s):
        for k in range(50):
            s.add_vertex_force(tip, (0, 1.0, np.cos(0.1 * k)))
            s.step()

    threads = [threading.Thread(target=run, args=(s,)) for s in together]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for s in apart:
        run(s)
    np.testing.assert_array_equal(states(together), states(apart))
    # While one thread steps an instance, another thread's call on it raises instead of racing it.
    busy = quiver.Instance(model)
    worker = threading.Thread(target=busy.step, args=(200000,))
    refused = None
    worker.start()
    while worker.is_alive() and refused is None:
        try:
            busy.q
        except RuntimeError as e:
            refused = e
    worker.join()
    assert refused is not None and "being stepped on another thread" in str(refused)
    assert busy.q.shape == (10,)  # usable again afterwards
