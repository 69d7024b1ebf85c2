"""The notebooks' pictures in words: the numbers said are those the picture draws."""

import matplotlib.pyplot as plt
import numpy as np

import msdlab as msd
from msdlab.course.plot_words import number, plot_in_words, run_in_words


def test_numbers_keep_three_figures_and_no_exponent_in_the_usual_range():
    assert [number(v) for v in (1200.0, 1.5, 0.04912, -0.0, 2.5e-5, np.nan, 1.0)] == [
        "1200",
        "1.50",
        "0.0491",
        "0",
        "2.50e-05",
        "not a number",
        "1",
    ]


def test_a_plot_says_each_line_from_its_own_data():
    fig, ax = plt.subplots()
    t = np.linspace(0.0, 2.0, 21)
    ax.plot(t, 1.5 - t**2, label="lowest particle")
    ax.axhline(0.0)
    ax.set(xlabel="time", ylabel="height", title="A fall")
    words = plot_in_words(ax)
    plt.close(fig)
    assert words.splitlines() == [
        "A fall: height against time, 2 line(s).",
        "- lowest particle: from 1.50 at time = 0 to -2.50 at time = 2; lowest -2.50 at "
        "time = 2, highest 1.50 at time = 0",
        "- a line: level at 0",
    ]


def test_a_run_says_how_its_lowest_particle_and_its_height_change():
    body = msd.Body.grid((2, 2, 2), spacing=0.5, neighbours=(1,))
    body.positions[:, 1] += 1.0
    forces = [msd.Gravity((0.0, -9.81, 0.0)), msd.Ground(0.0)]
    run = msd.Simulation(body, msd.Verlet(), 0.01, forces).run(steps=100, record_every=10)
    lowest = run.positions[..., 1].min(axis=1)
    words = run_in_words(run, time_unit="s")
    assert words.startswith(f"Animation of {len(run.times)} frames, t = 0 to 1.00 s:")
    assert f"lowest particle's height: from {number(lowest[0])} at t = 0" in words
    assert f"lowest {number(lowest.min())}" in words
