"""Flying instances of the free beam: free fall, landing on each kind of collider, a world of two,
and the colliders' own checks."""
import numpy as np
import pytest

import quiver

G = quiver.STANDARD_GRAVITY


def flyer(free_model, height):
    """A free beam at rest with its centre of mass `height` above the ground, under gravity."""
    s = quiver.Instance(free_model, free_flight=True)
    state = s.rigid_state
    state.position = [0.3, 0.05, height]
    s.rigid_state = state
    s.set_gravity((0, 0, -G))
    return s


def box_mesh(center, half):
    """A closed box as a triangle mesh, counter-clockwise seen from outside."""
    corners = np.array([(x, y, z) for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float) * half + center
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    return corners, [t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))]


def test_free_fall_is_a_parabola_and_keeps_the_shape(free_model):
    s = flyer(free_model, 0.3)
    assert s.flying and s.rigid_state.orientation.tolist() == [1, 0, 0, 0]
    steps = 120
    s.step(steps)
    t = steps * s.time_step
    state = s.rigid_state
    # A uniform field moves the frame only: v = -g t exactly, the drop within one step's g h t of
    # the parabola, no spin, no deformation.
    np.testing.assert_allclose(state.linear_velocity, [0, 0, -G * t], rtol=1e-12, atol=1e-12)
    assert abs(state.position[2] - (0.3 - G * t * t / 2)) <= G * s.time_step * t
    np.testing.assert_allclose(state.position[:2], [0.3, 0.05], atol=1e-12)
    np.testing.assert_allclose(state.angular_velocity, 0, atol=1e-12)
    assert np.abs(s.q).max() < 1e-12


def test_rigid_state_round_trips_and_is_checked(free_model):
    s = quiver.Instance(free_model, free_flight=True)
    turn = quiver.RigidState(position=(1, 2, 3), orientation=(2, 0, 0, 0), linear_velocity=(0, 1, 0),
                             angular_velocity=(0, 0, 0.5))
    s.rigid_state = turn
    back = s.rigid_state
    np.testing.assert_allclose(back.position, [1, 2, 3])
    np.testing.assert_allclose(back.orientation, [1, 0, 0, 0])  # normalised
    np.testing.assert_allclose(back.angular_velocity, [0, 0, 0.5], atol=1e-12)
    with pytest.raises(ValueError, match="non-zero quaternion"):
        quiver.RigidState(orientation=(0, 0, 0, 0))
    with pytest.raises(ValueError, match="NaN"):
        turn.position = (0, np.nan, 0)


@pytest.mark.parametrize("ground", [
    quiver.Plane((0, 0, 1), 0.0),
    quiver.Plane((0, 0, 2), 0.0, friction=0.8),  # any length of normal
    quiver.Box((0.3, 0.05, -0.5), (1, 1, 0.5)),
    quiver.Sphere((0.3, 0.05, -100), 100),
    quiver.Capsule((-1, 0.05, -0.5), (2, 0.05, -0.5), 0.5),
    quiver.MeshCollider(quiver.TriangleMesh(*box_mesh((0, 0, 0), (0.7, 1, 0.5))), (0.3, 0.05, -0.5)),
], ids=["plane", "plane-long-normal", "box", "sphere", "capsule", "mesh"])
def test_a_dropped_beam_comes_to_rest_on_the_ground(free_model, ground):
    s = flyer(free_model, 0.3)  # its underside 0.25 above the ground's top at z = 0
    s.set_colliders([ground])
    steps = 120
    for _ in range(steps):
        assert s.step() != quiver.StepStatus.RESET
    low = s.positions()[:, 2].min()
    # On it, not through it: the documented rest sinks 1.5 mm on this bar at 1/60 s.
    assert -0.01 < low < 0.005, low
    assert np.abs(s.rigid_state.linear_velocity).max() < 1e-3
    contacts = s.contacts()
    assert contacts.dtype == quiver.CONTACT_DTYPE and len(contacts) > 0
    assert np.all(contacts["collider"] == 0) and np.all(contacts["other"] == -1)
    assert np.all(contacts["normal"][:, 2] > 0.99)
    # At rest the ground carries the weight: the step's impulses add up to m g h.
    np.testing.assert_allclose(contacts["impulse"].sum(axis=0) / s.time_step, [0, 0, free_model.info.total_mass * G],
                               rtol=0, atol=0.02 * free_model.info.total_mass * G)


def test_with_soft_contacts_a_beam_rests_flat_on_the_ground(free_model):
    # The beam laid flat: its underside rests level (the ground holds all of it), sunk about a slop
    # (1e-3 of its 0.62 m diagonal), and still.
    s = quiver.Instance(free_model, free_flight=True, soft_contacts=True)
    assert s.config["soft_contacts"] is True
    state = s.rigid_state
    state.position = [0.3, 0.05, 0.06]
    s.rigid_state = state
    s.set_gravity((0, 0, -G))
    s.set_colliders([quiver.Plane((0, 0, 1), 0.0)])
    s.step(180)
    underside = s.positions()[free_model.rest_positions[:, 2] < 1e-9, 2]
    assert -2 * 0.62e-3 < underside.min() and underside.max() - underside.min() < 2e-4, underside
    assert np.abs(s.rigid_state.linear_velocity).max() < 1e-6
    with pytest.raises(ValueError, match="soft_contacts needs free_flight"):
        quiver.Instance(free_model, soft_contacts=True)
    for bad in ({"integrator": "central"}, {"elasticity": "warping"}):
        with pytest.raises(ValueError, match="an implicit integrator .* and no modal warping"):
            quiver.Instance(free_model, free_flight=True, soft_contacts=True, **bad)


def test_a_fast_spin_is_stepped_in_substeps(free_model):
    # At most 0.75 rad of turn a substep: 100 rad/s at the model's step asks ceil(100 h / 0.75) of
    # them, max_substeps caps it, and 1 keeps the step whole.
    def spun(**config):
        s = quiver.Instance(free_model, free_flight=True, **config)
        state = s.rigid_state
        state.angular_velocity = [0, 0, 100]
        s.rigid_state = state
        s.step()
        return s
    s = spun()
    assert s.config["max_substeps"] == 16
    assert s.last_step["substeps"] == int(np.ceil(100 * s.time_step / 0.75)) > 1
    assert spun(max_substeps=2).last_step["substeps"] == 2
    assert spun(max_substeps=1).last_step["substeps"] == 1
    for bad in (0, 65):
        with pytest.raises(ValueError, match="max_substeps must be between 1 and 64"):
            quiver.Instance(free_model, free_flight=True, max_substeps=bad)


def test_without_the_ground_it_falls_through(free_model):
    s = flyer(free_model, 0.3)
    s.set_colliders([quiver.Plane((0, 0, 1), 0.0)])
    s.set_colliders([])
    s.step(60)
    assert s.positions()[:, 2].max() < -1 and len(s.contacts()) == 0


def test_a_world_stacks_one_beam_on_another(free_model):
    world = quiver.World()
    low, high = flyer(free_model, 0.06), flyer(free_model, 0.25)
    assert (world.add(low), world.add(high)) == (0, 1) and len(world) == 2
    world.set_colliders([quiver.Plane((0, 0, 1), 0.0)])
    for _ in range(600):
        assert world.step() == 0
        if low.asleep and high.asleep:
            break
    # The lower rests on the ground, the upper on the lower (0.1 m thick), neither through; at rest
    # they sleep, without contacts from the next step on, until one is woken, which wakes the other
    # it rests on.
    assert low.asleep and high.asleep and world.step() == 0 and len(world.contacts()) == 0
    assert -0.01 < low.positions()[:, 2].min() < 0.005
    assert high.rigid_state.position[2] == pytest.approx(0.15, abs=0.02)
    high.wake()
    assert world.step() == 0 and not low.asleep and not high.asleep
    contacts = world.contacts()
    between = contacts[contacts["other"] >= 0]
    assert len(between) > 0 and set(between["instance"]) <= {0, 1}
    assert world.instances == [low, high]
    with pytest.raises(ValueError, match="already in a World"):
        world.add(low)
    # Despawning the lower: the upper, asleep on it, wakes and falls to the ground, named 0 now.
    for _ in range(600):
        world.step()
        if low.asleep and high.asleep:
            break
    assert low.asleep and high.asleep
    world.remove(low)
    assert world.instances == [high] and not low.asleep and not high.asleep
    for _ in range(60):
        assert world.step() == 0
    assert high.rigid_state.position[2] == pytest.approx(0.05, abs=0.01)
    assert set(world.contacts()["instance"]) == {0}
    low.step()  # alone now
    with pytest.raises(ValueError, match="not in this World"):
        world.remove(low)
    with pytest.raises(TypeError, match="takes a quiver.Instance"):
        world.remove("low")
    with pytest.raises(ValueError, match="threads must be at least 1"):
        world.step(threads=0)
    assert world.add(low) == 1
    with pytest.raises(ValueError, match="is in a World"):
        quiver.step_many([low])
    with pytest.raises(ValueError, match="is in a World"):
        low.step()
    with pytest.raises(ValueError, match="only flying instances"):
        world.add(quiver.Instance(free_model))
    with pytest.raises(ValueError, match="same time step"):
        world.add(quiver.Instance(free_model, free_flight=True, time_step=0.01))
    with pytest.raises(ValueError, match="restitution"):
        quiver.World(restitution=2)
    with pytest.raises(ValueError, match="sleep_speed"):
        quiver.World(sleep_speed=-1)


def test_a_world_snapshot_rewinds_a_stack_landing_bit_for_bit(free_model):
    world = quiver.World()
    low, high = flyer(free_model, 0.06), flyer(free_model, 0.25)
    world.add(low), world.add(high)
    world.set_colliders([quiver.Plane((0, 0, 1), 0.0)])

    def run(steps, threads=1):
        for _ in range(steps):
            assert world.step(threads=threads) == 0
        return [s.positions() for s in world.instances], world.contacts(), [s.asleep for s in world.instances]

    run(20)  # the upper is landing on the lower
    assert (world.contacts()["other"] >= 0).any()
    snapshot = world.save_snapshot()
    assert isinstance(snapshot, bytes)
    first = run(60)
    world.restore_snapshot(snapshot)
    again = run(60, threads=2)  # the same bits on two threads too
    for a, b in zip(first[0], again[0]):
        np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(first[1], again[1])
    assert first[2] == again[2]
    with pytest.raises(ValueError, match=r"snapshot of 3 bytes refused: not one this world's could have saved"):
        world.restore_snapshot(b"abc")
    with pytest.raises(ValueError, match="take at most"):
        world.restore_snapshot(snapshot + bytes(10 ** 6))
    with pytest.raises(ValueError, match="refused"):  # an instance's snapshot is not a world's
        world.restore_snapshot(low.save_snapshot())


def test_colliders_check_their_shape(free_model):
    with pytest.raises(ValueError, match="normal must not be zero"):
        quiver.Plane((0, 0, 0))
    with pytest.raises(ValueError, match="radius must be positive"):
        quiver.Sphere((0, 0, 0), -1)
    with pytest.raises(ValueError, match="half extent"):
        quiver.Box((0, 0, 0), (1, 0, 1))
    with pytest.raises(ValueError, match="restitution must be between 0 and 1"):
        quiver.Plane((0, 0, 1), restitution=1.5)
    with pytest.raises(ValueError, match="center contains NaN"):
        quiver.Sphere((0, np.nan, 0), 1)
    corners, triangles = box_mesh((0, 0, 0), (1, 1, 1))
    mesh = quiver.TriangleMesh(corners, triangles)
    assert (mesh.vertex_count, mesh.triangle_count) == (8, 12)
    with pytest.raises(quiver.FormatError) as open_mesh:  # one triangle missing: not closed
        quiver.TriangleMesh(corners, triangles[:-1])
    assert "edge" in str(open_mesh.value)
    with pytest.raises(IndexError, match="names vertex 8"):
        quiver.TriangleMesh(corners, [(0, 1, 8)])
    s = quiver.Instance(free_model, free_flight=True)
    with pytest.raises(TypeError, match=r"colliders\[1\] must be a quiver collider"):
        s.set_colliders([quiver.Plane((0, 0, 1)), "floor"])
    plane = quiver.Plane((0, 0, 1), 2.0, velocity=(0, 0, 1))
    assert plane.type == "plane" and plane.offset == 2.0 and plane.velocity.tolist() == [0, 0, 1]
