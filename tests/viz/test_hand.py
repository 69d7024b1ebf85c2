"""The hand's path played back to the engine: at the hand's pace, late moves caught up
smoothly."""

import numpy as np
import pytest

from msdlab.viz.hand import CATCH_UP, HandPath

FRAME = 1000 / 60  # ms


def test_moves_that_arrive_together_are_played_back_a_frame_a_step():
    path = HandPath(0.0, [0.0, 0.0])
    for k in (1, 2, 3):  # a px a frame, three frames' moves at once
        path.add(k * FRAME, [float(k), 0.0])
    played = [path.advance(FRAME)[0] for _ in range(4)]
    assert played == [1.0, 2.0, 3.0, 3.0] and path.caught_up


def test_a_hand_half_a_second_ahead_is_caught_up_without_a_jump():
    path = HandPath(0.0, [0.0, 0.0])
    for k in range(1, 31):  # the moves of half a second arrive at once
        path.add(k * FRAME, [float(k), 0.0])
    played = [path.advance(FRAME)[0] for _ in range(30)]
    moves = np.diff([0.0, *played])
    assert moves.max() <= CATCH_UP + 1e-9  # before: one step jumped 24 px
    assert played[-1] == 30.0


def test_a_hand_that_stood_still_moves_at_once_when_it_moves_again():
    """The keyboard's move: the hand where it stood at the key's time, then the move
    100 ms later. Played back from the key's time, not from the grab two seconds before
    (before: the playback jumped to a second before the move, then caught up for 375 ms)."""
    path = HandPath(0.0, [0.0, 0.0])
    path.advance(FRAME)
    path.add(2000.0, [0.0, 0.0])
    path.add(2100.0, [6.0, 0.0])
    played = [path.advance(FRAME)[0] for _ in range(7)]
    assert played == pytest.approx([1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 6.0])
