"""The live view in words: the line a screen reader hears and the whole state on request,
from a body's summary (no browser), and from a running view."""

import dataclasses

import pytest

from msdlab.scenes import SCENES
from msdlab.viz import words
from msdlab.viz.widget import LiveView

ENERGY = {
    "time": 1.5,
    "kinetic": 6.0,
    "elastic": 2.9,
    "gravitational": 1.1,
    "other": 0.0,
    "zero": 0.0,
    "dissipated": {"drag": 0.0, "hand": 0.0},
}
RESTING = words.BodySummary(
    particles=25,
    springs=72,
    pinned=0,
    size=(1.2, 0.8),
    lowest=0.0,
    has_floor=True,
    up=1,
    rise=0.0,
    fastest=0.0,
    still=0.01,
    held=None,
    held_at=None,
    energy=ENERGY,
    length_unit="m",
    energy_unit="J",
    time_unit="s",
)


def summary(**changes) -> words.BodySummary:
    return dataclasses.replace(RESTING, **changes)


@pytest.mark.parametrize(
    "changes, said",
    [
        ({}, "resting on the floor"),
        ({"lowest": 0.5}, "at rest"),
        ({"fastest": 1.0, "rise": -1.0, "lowest": 0.5}, "falling"),
        ({"fastest": 1.0, "rise": 1.0, "lowest": 0.5}, "rising"),
        ({"fastest": 1.0, "rise": -1.0}, "bouncing on the floor"),
        ({"fastest": 1.0, "lowest": 0.5, "pinned": 1}, "swinging"),
        ({"fastest": 1.0, "lowest": 0.5, "has_floor": False}, "moving"),
        ({"stopped": "diverged at step 9"}, "stopped: the simulation blew up"),
    ],
)
def test_what_the_body_does_in_words(changes, said):
    assert words.motion(summary(**changes)) == said


def test_the_line_says_the_motion_the_particle_in_hand_and_the_energys_shares():
    held = summary(fastest=1.0, rise=-1.0, lowest=0.5, held=3, held_at=(0.1234, -0.40312))
    assert words.brief(held) == (
        "The body is swinging. Particle 3 in hand at x 0.12, y -0.40 m. "
        "Energy 60 % kinetic, 30 % spring, 10 % gravity."
    )


def test_the_shares_are_coarse_and_sum_to_a_hundred():
    thirds = {**ENERGY, "kinetic": 1.0, "elastic": 1.0, "gravitational": 1.0}
    assert sum(words.shares(thirds).values()) == 100
    nudged = {**ENERGY, "kinetic": 6.01}  # a small change: the same line, nothing new to say
    assert words.brief(summary(energy=nudged)) == words.brief(RESTING)
    lost = {**ENERGY, "dissipated": {"drag": 10.0, "hand": -5.0}}  # the hand's is put in
    assert words.shares(lost)["lost"] == 50


def test_the_whole_state_has_the_body_its_size_its_lowest_point_and_the_energy_table():
    energy = {**ENERGY, "dissipated": {"drag": 0.5, "hand": -2.0, "walls": -4.4e-16}}
    text = words.full(summary(lowest=0.25, pinned=2, energy=energy))
    assert text.startswith("A 2-D body of 25 particles and 72 springs, 2 of them pinned.")
    assert "Its size: 1.20 m along x, 0.80 m along y." in text
    assert "Its lowest point is 0.25 m above the floor." in text
    assert (
        "Energy in J: kinetic 6; spring 2.9; gravity 1.1; taken out by drag 0.5; "
        "your hand put in 2; total 8.5." in text  # 6 + 2.9 + 1.1 + 0.5 - 2; walls: crumbs
    )
    assert text.endswith("Simulated time t = 1.5 s.")


def test_a_running_view_sends_the_line_and_the_whole_state_when_asked():
    view = LiveView(SCENES["jelly-cube"].build(size=3), steps_per_second=60)
    sent: list[dict] = []
    view.send = lambda content, buffers: sent.append(content)
    view.advance(0.3, budget=60)
    view.publish()
    assert sent[-1]["words"].startswith("The body is falling.")
    assert "full" not in sent[-1]
    view._on_message(view, {"type": "describe"}, [])
    view.publish(energy=False)
    assert sent[-1]["full"].startswith("A 3-D body of 27 particles")
    assert "above the floor" in sent[-1]["full"]
