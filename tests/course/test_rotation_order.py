"""Every rotation of the course takes (angle_degrees, axis), as msd.rotation_matrix does: a
student who gives the axis first, in the template or in their answer, is told the order."""

from __future__ import annotations

import importlib.util
import re

import pytest

from msdlab.course import PROJECT_ROOT


def task_module(folder: str, name: str):
    spec = importlib.util.spec_from_file_location(
        f"{folder}_{name}", PROJECT_ROOT / folder / f"{name}.py"
    )
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.mark.parametrize("folder", ["assignments", "solutions"])
def test_axis_first_is_told_the_order(folder):
    task3, task4 = task_module(folder, "task3"), task_module(folder, "task4")
    grid = task4.grid_positions((2, 2, 2), 0.5)
    calls = {
        "rotation_matrix takes (angle_degrees, axis)": lambda: task3.rotation_matrix((0, 0, 1), 30),
        "rotate_layout takes (positions, angle_degrees, axis)": lambda: task3.rotate_layout(
            grid, (0, 0, 1), 30
        ),
        "drop_rotated_cube takes (angle_degrees, axis, neighbours, steps)": lambda: (
            task3.drop_rotated_cube((0, 0, 1), 30)
        ),
        "drop_rotated_cube takes (angle_degrees, axis, squared_distances, steps)": lambda: (
            task4.drop_rotated_cube((0, 0, 1), 30)
        ),
    }
    for order, call in calls.items():
        with pytest.raises(ValueError, match=re.escape(f"got 30.0: the angle? {order}")):
            call()
