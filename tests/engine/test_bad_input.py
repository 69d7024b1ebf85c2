"""Bad input gets a clear error that says what was wrong and how to fix it."""

import numpy as np
import pytest

import msdlab as msd


def body_2d() -> msd.Body:
    return msd.Body.from_arrays([[0.0, 0.0], [1.0, 0.0]], [[0, 1]])


@pytest.mark.parametrize("mass", [0.0, -1.0, float("nan")])
def test_non_positive_mass(mass):
    with pytest.raises(ValueError, match=r"mass.*> 0.*fixed=True"):
        msd.Particle(position=(0, 0), mass=mass)
    with pytest.raises(ValueError, match="mass"):
        body_2d().masses = [1.0, mass]


@pytest.mark.parametrize("dt", [0.0, -1e-3, float("inf")])
def test_dt_must_be_positive(dt):
    with pytest.raises(ValueError, match=r"dt must be a positive.*seconds"):
        msd.Simulation(body_2d(), msd.Verlet(), dt=dt)


@pytest.mark.parametrize("damping", [-0.1, 1.0, 1.2])
def test_verlet_damping_outside_unit_interval(damping):
    with pytest.raises(ValueError, match=r"λ must be in \[0, 1\)"):
        msd.Verlet(damping=damping)


@pytest.mark.parametrize("bad", [float("nan"), float("inf")])
def test_non_finite_positions(bad):
    with pytest.raises(ValueError, match="finite"):
        msd.Particle(position=(0, bad, 0))
    body = body_2d()
    with pytest.raises(ValueError, match=r"positions must be finite.*row 1"):
        body.positions = [[0, 0], [bad, 0]]
    body.positions[1, 0] = bad  # written behind the body's back
    with pytest.raises(ValueError, match="positions must be finite"):
        msd.Simulation(body, msd.Verlet(), dt=0.1)


def test_spring_to_itself():
    with pytest.raises(ValueError, match="itself"):
        msd.Spring(1, 1)
    with pytest.raises(ValueError, match="itself"):
        body_2d().add_springs([[0, 0]])


def test_spring_to_missing_particle():
    with pytest.raises(ValueError, match=r"joins particles 0 and 5.*2 particles.*0 to 1"):
        body_2d().add_spring(msd.Spring(0, 5))


def test_spring_ends_must_be_integers():
    with pytest.raises(TypeError, match="particle indices"):
        msd.Spring(0.5, 1)


def test_zero_length_spring():
    body = msd.Body.from_arrays([[0.0, 0.0], [0.0, 0.0]])
    with pytest.raises(ValueError, match=r"zero-length spring.*rest_length"):
        body.add_spring(msd.Spring(0, 1))
    with pytest.raises(ValueError, match="rest_length"):
        msd.Spring(0, 1, rest_length=0.0)


def test_mixed_dimensions():
    body = msd.Body()
    body.add_particle(msd.Particle(position=(0, 0, 0)))
    with pytest.raises(ValueError, match=r"3-D.*2 coordinates.*do not mix"):
        body.add_particle(msd.Particle(position=(0, 0)))


def test_wrong_shape_assigned_to_positions():
    body = body_2d()
    with pytest.raises(ValueError, match=r"shape \(2, 2\), got shape \(3, 2\)"):
        body.positions = np.zeros((3, 2))
    with pytest.raises(ValueError, match="shape"):
        body.velocities = np.zeros((2, 3))


def test_negative_stiffness():
    with pytest.raises(ValueError, match=r"stiffness must be finite and >= 0"):
        msd.Spring(0, 1, stiffness=-1.0)
    with pytest.raises(ValueError, match="stiffness"):
        body_2d().add_springs([[0, 1]], stiffness=-5.0)


def test_integrator_class_instead_of_instance():
    with pytest.raises(TypeError, match=r"Verlet\(\)"):
        msd.Simulation(body_2d(), msd.Verlet, dt=0.1)


def test_force_of_wrong_dimension_and_unknown_force():
    with pytest.raises(ValueError, match=r"3 components.*2-D"):
        msd.Simulation(body_2d(), msd.Verlet(), 0.1, [msd.Gravity((0, -9.81, 0))])
    with pytest.raises(TypeError, match=r"neither a msdlab\.Force"):
        msd.Simulation(body_2d(), msd.Verlet(), 0.1, ["gravity"])


def test_run_needs_steps_or_duration():
    sim = msd.Simulation(body_2d(), msd.Verlet(), 0.1)
    with pytest.raises(ValueError, match="record_every"):
        sim.run(steps=3, record_every=0)


def test_integrator_returning_wrong_shape_is_named():
    class Broken(msd.Integrator):
        def step(self, x, v, dt, dynamics):
            return x[:1], v

    with pytest.raises(ValueError, match=r"returned x_new of shape \(1, 2\)"):
        msd.Simulation(body_2d(), Broken(), 0.1).step()


def test_bad_grid_arguments():
    with pytest.raises(ValueError, match="squared distances"):
        msd.Body.grid((3, 3), neighbours=(0,))
    with pytest.raises(ValueError, match="spacing"):
        msd.Body.grid((3, 3), spacing=-1)
    with pytest.raises(ValueError, match="origin must have 2"):
        msd.Body.grid((3, 3), origin=(0, 0, 0))


def test_whole_array_assignments_and_spring_values_are_checked():
    body = body_2d()
    body.set_springs(stiffness=5.0)
    assert body.edges().stiffness[0] == 5.0
    with pytest.raises(ValueError, match=r"stiffness must be finite and >= 0"):
        body.set_springs(stiffness=-1.0)
    with pytest.raises(ValueError, match=r"rest length must be finite and > 0"):
        body.set_springs(rest_lengths=[0.0])
    with pytest.raises(ValueError, match=r"damping needs one value or one per spring \(1\)"):
        body.add_springs([[0, 1]], damping=[0.1, 0.2])
    with pytest.raises(ValueError, match="read-only"):
        body.edges().a[0] = 1  # the spring set changes through the body's methods only
    with pytest.raises(AttributeError, match="cannot assign"):
        body.edges().a = [1]
    assert (
        body.edges().stiffness[0] == 5.0 and body.n_springs == 1
    )  # nothing changed by the failures


def test_a_single_force_needs_no_list_and_a_wrong_one_is_named():
    alone = msd.Simulation(body_2d(), msd.Verlet(), dt=0.1, forces=msd.Gravity((0, -9.81)))
    listed = msd.Simulation(body_2d(), msd.Verlet(), dt=0.1, forces=[msd.Gravity((0, -9.81))])
    alone.run(steps=3)
    listed.run(steps=3)
    assert np.array_equal(alone.body.positions, listed.body.positions)
    assert len(alone.forces) == 1
    with pytest.raises(TypeError, match=r"forces must be a list .* got a float"):
        msd.Simulation(body_2d(), msd.Verlet(), dt=0.1, forces=9.81)
    with pytest.raises(TypeError, match=r"forces holds a ndarray: neither a msdlab.Force"):
        msd.Simulation(body_2d(), msd.Verlet(), dt=0.1, forces=[np.array([0, -9.81])])


@pytest.mark.parametrize(
    ("make", "plain"),
    [
        (lambda: msd.Body.grid((2, 2), spacing=0.1, stiffness=np.float64(-5.0)), "got -5.0."),
        (lambda: msd.Body.grid((2, 2), spacing=0.1, stiffness=-5.0), "got -5.0."),
        (lambda: msd.Simulation(body_2d(), dt=np.float64(-0.1)), "got -0.1."),
        (lambda: msd.Gravity(np.array([0.0, np.nan])), "got [0.0, nan]"),
        (lambda: msd.Simulation(body_2d(), dt=0.1).run(steps=np.int64(-2)), "got -2"),
        (lambda: msd.Particle(position=np.array([1.0])), "got [1.0]"),
        (lambda: msd.Spring(np.float64(0.5), 1), "got 0.5 and 1"),
    ],
)
def test_numbers_in_messages_are_plain_not_numpy_reprs(make, plain):
    with pytest.raises((ValueError, TypeError)) as raised:
        make()
    message = str(raised.value)
    assert plain in message
    assert "np." not in message and "array(" not in message


def test_grid_stiffness_that_is_no_number_names_the_parameter_and_an_example():
    with pytest.raises(ValueError) as error:
        msd.Body.grid((3, 3, 3), stiffness="stiff")
    message = str(error.value)
    assert "stiffness must be a number, got 'stiff'" in message
    assert "Body.grid((4, 4, 4), spacing=0.1, stiffness=100.0)" in message
    msd.Body.grid((4, 4, 4), spacing=0.1, stiffness=100.0)  # the example works
    with pytest.raises(ValueError, match=r"damping must be a number, got 'lots'.*damping=0\.1"):
        msd.Body.grid((3, 3), damping="lots")


@pytest.mark.parametrize("shape", [3, "abc", (3.5, 3), None])
def test_grid_shape_that_is_not_sizes_says_one_size_per_axis(shape):
    with pytest.raises(TypeError) as error:
        msd.Body.grid(shape)
    message = str(error.value)
    assert f"grid shape must be 2 or 3 sizes, got {shape!r}" in message
    assert "one size per axis, e.g. Body.grid((4, 4, 4)" in message
    assert "not iterable" not in message


@pytest.mark.parametrize("shape", [(3,), (2, 2, 2, 2), (3, 0, 3)])
def test_grid_shape_of_wrong_length_or_empty_axis(shape):
    with pytest.raises(ValueError, match=r"grid shape must be 2 or 3 sizes >= 1.*per axis"):
        msd.Body.grid(shape)


@pytest.mark.parametrize(
    ("item", "example"),
    [
        (msd.Gravity, "Gravity is a class; create one: msd.Gravity((0, -9.81, 0))"),
        (msd.Ground, "Ground is a class; create one: msd.Ground()"),
        (msd.SphereContact, "SphereContact is a class; create one: msd.SphereContact(...)"),
    ],
)
def test_a_force_class_instead_of_a_force_says_how_to_create_one(item, example):
    with pytest.raises(TypeError) as error:
        msd.Simulation(body_2d(), msd.Verlet(), forces=[item])
    assert str(error.value) == example
    assert "ABCMeta" not in str(error.value)


def test_gravity_example_in_the_message_runs():
    body = msd.Body.from_arrays([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]], [[0, 1]])
    msd.Simulation(body, msd.Verlet(), forces=[msd.Gravity((0, -9.81, 0))]).step()


def test_run_without_steps_or_duration_says_how_long_to_run():
    sim = msd.Simulation(body_2d(), msd.Verlet(), dt=0.01)
    with pytest.raises(ValueError) as error:
        sim.run()
    message = str(error.value)
    assert "steps=..." in message and "duration=..." in message
    assert "sim.run(steps=1000)" in message and "not both" not in message
    with pytest.raises(ValueError, match="not both"):
        sim.run(steps=3, duration=1.0)
    assert sim.run(steps=3).positions.shape[0] == 4
