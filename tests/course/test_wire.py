"""The grader's pipe protocol: a buffered reader returns each framed message whole."""

from __future__ import annotations

import os
import threading

import numpy as np
import pytest

from msdlab.instructor.judging import wire


def test_a_reader_returns_each_message_whole_however_its_bytes_arrive():
    read_fd, write_fd = os.pipe()
    first, second = {"x": np.arange(6.0).reshape(2, 3), "n": 3}, (np.array(2.5), "b", None)
    data = wire.encode(first) + wire.encode(second)

    def trickle() -> None:  # a few bytes at a time: messages split and run together
        for start in range(0, len(data), 7):
            os.write(write_fd, data[start : start + 7])
        os.close(write_fd)

    writer = threading.Thread(target=trickle)
    writer.start()
    read = wire.Reader(read_fd)
    got_first, got_second = wire.decode(read), wire.decode(read)
    with pytest.raises(EOFError):
        wire.decode(read)
    writer.join()
    os.close(read_fd)
    assert np.array_equal(got_first["x"], first["x"]) and got_first["n"] == 3
    assert got_second[0].shape == (1,) and got_second[0][0] == 2.5  # a 0-d array goes as (1,)
    assert got_second[1:] == ("b", None)
