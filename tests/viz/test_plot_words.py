"""The notebooks' pictures in words: the numbers said are those the picture draws."""

import matplotlib.pyplot as plt
import numpy as np

import msdlab as msd
from msdlab.viz.plot_words import body_in_words, number, plot_in_words, run_in_words


def test_numbers_keep_three_figures_and_no_exponent_in_the_usual_range():
    values = (1200.0, 1.5, 0.04912, -0.0, 2.5e-5, np.nan, 1.0, 0.99996, 12345.0)
    assert [number(v) for v in values] == [
        "1200",
        "1.50",
        "0.0491",
        "0",
        "2.50e-05",
        "not a number",
        "1",
        "1",
        "12345",
    ]


def test_a_plot_says_each_line_from_its_own_data():
    fig, ax = plt.subplots()
    t = np.linspace(0.0, 2.0, 21)
    ax.plot(t, 1.5 - t**2, label="lowest particle")
    ax.axhline(0.0)
    ax.plot(t, 1.0 - 1e-5 * t, label="resting")  # level to three figures
    ax.set(xlabel="time (s)", ylabel="height (m)", title="A fall")
    words = plot_in_words(ax)
    plt.close(fig)
    assert words.splitlines() == [
        "A fall: height (m) against time (s), 3 line(s).",
        "- lowest particle: from 1.50 m at time = 0 s to -2.50 m at time = 2 s; lowest "
        "-2.50 m at time = 2 s, highest 1.50 m at time = 0 s",
        "- a line: level at 0 m",
        "- resting: level at 1 m",
    ]


def test_a_run_says_how_its_lowest_particle_and_its_height_change():
    body = msd.Body.grid((2, 2, 2), spacing=0.5, neighbours=(1,))
    body.positions[:, 1] += 1.0
    forces = [msd.Gravity((0.0, -9.81, 0.0)), msd.Ground(0.0)]
    run = msd.Simulation(body, msd.Verlet(), 0.01, forces).run(steps=100, record_every=10)
    lowest = run.positions[..., 1].min(axis=1)
    words = run_in_words(run, time_unit="s")
    assert words.startswith(f"Animation of {len(run.times)} frames, t = 0 to 1 s:")
    assert f"lowest particle's height: from {number(lowest[0])} at t = 0" in words
    assert f"lowest {number(lowest.min())}" in words


def test_a_figure_says_each_of_its_plots():
    fig, (left, right) = plt.subplots(1, 2)
    left.plot([0, 1], [2, 3], label="rising")
    right.plot([0, 1], [3, 2], label="falling")
    words = plot_in_words(fig)
    plt.close(fig)
    assert words == "\n".join([plot_in_words(left), plot_in_words(right)])
    assert "- rising: from 2 at x = 0 to 3 at x = 1" in words and "- falling: from 3" in words


def test_a_body_says_its_size_lowest_point_and_strains():
    body = msd.Body.grid((2, 3), spacing=0.5, neighbours=(1,))
    stretched = body.positions * (1.1, 1.0)  # the springs along x 10 % longer
    words = body_in_words(body, stretched, up=1, title="A sheet")
    assert words == (
        "A sheet: a body of 6 particles and 7 springs, 0.550 along x by 1 along y; its "
        f"lowest point at y = {number(stretched[:, 1].min())}; its springs' strain from "
        "+0.00% to +10.00%"
    )
