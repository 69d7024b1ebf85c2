"""2-D springs gallery: analytic checks (Hooke, oscillation period, hanging chains, catenary),
shapes, the driven mesh, and the page's per-frame model beside the physical one."""

import math

import numpy as np
import pytest
from scipy.optimize import brentq, curve_fit

import msdlab as msd
from msdlab.scenes import SCENES, gallery
from msdlab.scenes.frame_model import FrameEuler

MODELS = ["physical", "frame"]


def settle(sim, frames):
    sim.run(steps=frames, record_every=frames)
    return sim.body.positions.copy()


def test_spring_counts_are_the_pages():
    assert gallery.mesh().body.n_springs == 342
    blob = gallery.blob()
    assert (len(blob.body), blob.body.n_springs) == (60, 240)
    wheel = gallery.wheel(spokes=12)
    assert (len(wheel.body), wheel.body.n_springs) == (13, 24)


def test_two_particles_oscillate_with_the_analytic_period():
    """Undamped, the separation oscillates with ω² = K/μ, μ = m/2 for equal masses."""
    sim = gallery.two_particles(damping=1.0)
    sim.dt = 0.05
    trajectory = sim.run(duration=60.0, record_every=1)
    separation = trajectory.positions[:, 1, 0] - trajectory.positions[:, 0, 0] - 100.0
    crossings = np.flatnonzero(np.diff(np.sign(separation)) > 0)
    t = trajectory.times
    # linear interpolation of the upward zero crossings
    times = t[crossings] - separation[crossings] * (t[crossings + 1] - t[crossings]) / (
        separation[crossings + 1] - separation[crossings]
    )
    period = np.mean(np.diff(times))
    assert period == pytest.approx(2 * math.pi * math.sqrt(0.5 / 0.1), rel=1e-3)
    centre = trajectory.positions.mean(axis=1)
    np.testing.assert_allclose(centre - centre[0], 0.0, atol=1e-9)  # no external force: COM still


@pytest.mark.parametrize("model", MODELS)
def test_hanging_particle_stretches_by_mg_over_k(model):
    x = settle(gallery.hanging_particle(model=model), 2000)
    assert x[0, 1] - x[1, 1] == pytest.approx(100.0 + 0.5 / 0.1, abs=1e-6)


@pytest.mark.parametrize("model", MODELS)
def test_rope_hangs_straight_down_with_hookes_stretch(model):
    """Link i carries the particles below it: stretch_i = (N - 1 - i) m g / K."""
    x = settle(gallery.rope(model=model), 4000)
    lengths = np.linalg.norm(np.diff(x, axis=0), axis=1)
    carried = np.arange(17, 0, -1)
    np.testing.assert_allclose(lengths, 12.0 + carried * 0.1 / 0.1, atol=1e-3)
    np.testing.assert_allclose(x[:, 0], x[0, 0], atol=1e-3)
    assert x[-1, 1] == pytest.approx(380.0 - 17 * 12.0 - 153.0, abs=1e-3)  # as its docstring says


@pytest.mark.parametrize("name", [n for n, s in SCENES.items() if s.unit == "frames"])
def test_gallery_scenes_start_and_stay_inside_their_canvas(name):
    sim = SCENES[name].build()
    x = sim.run(steps=600, record_every=10).positions
    assert np.all((x[0] >= 0.0) & (x[0] <= (gallery.WIDTH, gallery.HEIGHT))), "starts outside"
    assert np.all((x >= -1.0) & (x <= (gallery.WIDTH + 1.0, gallery.HEIGHT + 1.0)))


def discrete_catenary(count, rest, stiffness, weight, left, right):
    """Equilibrium of an elastic chain of ``count`` particles fixed at both ends, from statics.

    The horizontal tension H is the same in every link (no horizontal load); the vertical
    force grows by one particle weight per link. With equal end heights the middle is the
    lowest point, so link j pulls with F_j = (H, V_0 + j w), V_0 = -(count - 2) w / 2, and
    is stretched to rest + |F_j| / k. H is the root of "the chain ends at ``right``".
    """
    links = count - 1
    forces = lambda h: np.column_stack(  # noqa: E731
        [np.full(links, h), (np.arange(links) - (count - 2) / 2) * weight]
    )

    def shape(h):
        f = forces(h)
        tension = np.linalg.norm(f, axis=1)
        steps = (rest + tension / stiffness)[:, None] * f / tension[:, None]
        return np.vstack([left, left + np.cumsum(steps, axis=0)])

    h = brentq(lambda h: shape(h)[-1, 0] - right[0], 1e-6, 1e3)
    return shape(h), h


@pytest.fixture(scope="module", params=MODELS)
def hanging_rope(request):
    return settle(gallery.hanging_rope(model=request.param), 5000)


def test_hanging_rope_is_the_discrete_catenary(hanging_rope):
    x = hanging_rope
    expected, _ = discrete_catenary(18, 40.0, 0.1, 0.1, x[0], x[-1])
    assert expected[-1, 1] == pytest.approx(x[-1, 1], abs=1e-9)  # both ends at one height
    np.testing.assert_allclose(x, expected, atol=1e-3)


def test_hanging_rope_is_close_to_the_continuous_catenary(hanging_rope):
    """y = y0 + a (cosh((x - x0)/a) - 1) fits the chain to within 1 % of its sag.

    For an inextensible rope a = H / (weight per length). This rope stretches more near
    its ends, where the tension is higher, so its weight per length falls from the
    bottom to the ends: the fitted a lies between H over the weight per length at the
    bottom and H over the mean weight per length."""
    x = hanging_rope
    _, h = discrete_catenary(18, 40.0, 0.1, 0.1, x[0], x[-1])

    def catenary(xs, a, x0, y0):
        return y0 + a * (np.cosh((xs - x0) / a) - 1.0)

    (a, x0, y0), _ = curve_fit(catenary, x[:, 0], x[:, 1], p0=(200.0, 300.0, x[:, 1].min()))
    sag = x[0, 1] - x[:, 1].min()
    assert np.max(np.abs(catenary(x[:, 0], a, x0, y0) - x[:, 1])) < 0.01 * sag
    assert x0 == pytest.approx(300.0, abs=0.5)  # symmetric about the middle of the span
    links = np.linalg.norm(np.diff(x, axis=0), axis=1)
    at_bottom = 0.1 / links[len(links) // 2]  # one particle's weight per link length
    mean = 16 * 0.1 / links.sum()  # 16 free particles of weight 0.1
    assert h / at_bottom < a < h / mean


@pytest.mark.parametrize("model", MODELS)
def test_mesh_keeps_its_shape_only_with_diagonals(model):
    braced = settle(gallery.mesh(model=model, tilt=15.0), 800)
    loose = settle(gallery.mesh(model=model, tilt=15.0, diagonals=False), 800)
    assert np.ptp(braced[:, 1]) > 0.8 * 270.0
    assert np.ptp(loose[:, 1]) < 0.3 * 270.0  # squares shear flat


@pytest.mark.parametrize("scene", ["triangle", "wheel", "blob", "truss"])
@pytest.mark.parametrize("model", MODELS)
def test_bodies_in_hard_walls_stay_inside_and_keep_their_springs(scene, model):
    sim = getattr(gallery, scene)(model=model)
    trajectory = sim.run(steps=600, record_every=20)
    x = trajectory.positions
    past = 0.0 if model == "physical" else 10.0  # the page's walls let a frame's move through
    assert np.all((x >= -past) & (x <= (600.0 + past, 400.0 + past)))
    assert x[-1, :, 1].min() < 2.0  # landed on the floor (the page's walls: within 2 px)
    d = x[-1, sim.body.edges().a] - x[-1, sim.body.edges().b]
    strain = np.linalg.norm(d, axis=1) / sim.body.edges().rest_lengths - 1.0
    assert np.max(np.abs(strain)) < 0.35


def test_driven_mesh_follows_its_seeded_driver():
    sim = gallery.driven_mesh(seed=3)
    driver = sim.constraints[-1]
    trajectory = sim.run(steps=300, record_every=300)
    (particle,) = driver.particles
    np.testing.assert_allclose(trajectory.positions[-1, particle], driver.path(300.0))
    assert trajectory.energies.dissipated["driven"][-1] < 0.0  # the driver put energy in
    again = gallery.driven_mesh(seed=3).run(steps=300, record_every=300)
    np.testing.assert_array_equal(again.positions[-1], trajectory.positions[-1])
    other = gallery.driven_mesh(seed=4).run(steps=300, record_every=300)
    assert np.max(np.abs(other.positions[-1] - trajectory.positions[-1])) > 1.0


def test_frame_model_is_the_pages_update():
    """As in the page's draw(), the springs act at the end of a frame: the first frame
    moves nothing and leaves the kick F/m in v; the second moves by damping·v."""
    sim = gallery.two_particles(model="frame", pull=10.0)
    sim.step()
    force = 0.1 * 10.0  # K · stretch, pulling the particles together
    np.testing.assert_allclose(sim.body.positions, [[250.0, 200.0], [360.0, 200.0]])
    np.testing.assert_allclose(sim.body.velocities, [[force, 0.0], [-force, 0.0]])
    sim.step()
    np.testing.assert_allclose(sim.body.positions, [[250.96, 200.0], [359.04, 200.0]])


def test_speed_cap_hides_the_instability_the_physical_model_reports():
    """K = 1.5 puts the rope's stiffest mode at ω dt = 2.4 > 2: unstable at dt = 1 frame.

    The physical model stops and says so; the page's update never blows up, because
    its speed cap holds every particle at 10 px/frame, but the rope is torn apart."""
    with pytest.raises(msd.SimulationDiverged, match="stable limit"):
        gallery.rope(stiffness=1.5, damping=1.0).run(steps=400)
    capped = gallery.rope(stiffness=1.5, damping=1.0, model="frame")
    trajectory = capped.run(steps=400, record_every=1)
    moves = np.linalg.norm(np.diff(trajectory.positions, axis=0), axis=2)
    assert moves.max() == pytest.approx(10.0)  # px per frame
    lengths = np.linalg.norm(np.diff(trajectory.positions[-100:], axis=1), axis=2)
    # At rest the top link carries 17 particles: 17 · 0.1 / 1.5 = 1.1 px, 9 % of 12 px.
    assert np.max(np.abs(lengths / 12.0 - 1.0)) > 0.2


def test_springs_shorter_than_one_pixel_do_not_push_in_the_frame_model():
    body = msd.Body.from_arrays([[0.0, 0.0], [0.5, 0.0]], [[0, 1]], rest_lengths=10.0)
    sim = msd.Simulation(body, FrameEuler(), 1.0)
    sim.step()
    np.testing.assert_array_equal(sim.body.velocities, 0.0)
    physical = msd.Simulation(body.copy(), msd.SymplecticEuler(), 1.0)
    physical.step()
    assert physical.body.velocities[1, 0] > 0.0


def test_bad_settings_name_the_choices():
    with pytest.raises(ValueError, match="physical, frame"):
        gallery.rope(model="p5")
    with pytest.raises(ValueError, match="none, hard, periodic"):
        gallery.blob(walls="soft")
    with pytest.raises(ValueError, match=r"\(0, 1\]"):
        gallery.blob(damping=1.2)
    with pytest.raises(ValueError, match=r"\(0, 1\]"):
        FrameEuler(damping=1.2)


def test_periodic_walls_wrap_a_loose_particle():
    body = msd.Body.from_arrays(
        [[595.0, 200.0]], np.zeros((0, 2), dtype=int), velocities=[[10.0, 0.0]]
    )
    sim = gallery.simulation(body, walls="periodic", damping=1.0)
    sim.step()
    assert sim.body.positions[0, 0] == pytest.approx(5.0)


def test_the_page_model_skips_the_ledger_bookkeeping_and_the_physical_model_keeps_it():
    frame, physical = gallery.mesh(model="frame"), gallery.mesh(model="physical")
    assert not frame.ledger and physical.ledger
    assert frame.run(steps=20).energies.dissipated == {}
    assert "drag" in physical.run(steps=20).energies.dissipated
