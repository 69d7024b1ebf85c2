"""The planted-bug set: single-bug variants and correct alternatives of the solutions.

Each variant is the solution file ``solutions/taskN.py`` with small text patches (old ->
new, each old found exactly once). A bug must lose points in its own task: ``check`` fails
with a message containing ``words`` (its cause). An alternative is correct code written
differently: it must lose no point. These come on top of the typical mistakes and the
alternatives of ``test_checks_judge_fairly.py``.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Variant:
    """A changed solution: its name, task, patches and (bugs) what must catch it."""

    name: str
    task: int
    patches: tuple[tuple[str, str], ...]
    check: str = ""
    words: str = ""

    def apply(self, source: str) -> str:
        for old, new in self.patches:
            if source.count(old) != 1:
                raise ValueError(f"{self.name}: {old!r} is not in the solution exactly once")
            source = source.replace(old, new)
        return source


def bug(name: str, task: int, old: str, new: str, check: str, words: str) -> Variant:
    return Variant(name, task, ((old, new),), check, words)


def alternative(name: str, task: int, *patches: tuple[str, str]) -> Variant:
    return Variant(name, task, tuple(patches))


# ------------------------------------------------------------------------------- task 1
T1_VERLET = "return 2.0 * current - old + np.asarray(acceleration, dtype=float) * dt**2"
T1_HEIGHT = "return y0 + g * dt**2 * steps * (steps + 1) / 2"
T1_CHECK = """    if not (y0 > 0 and g < 0 and dt > 0):
        raise ValueError(f"need y0 > 0, g < 0 and dt > 0; got y0={y0}, g={g}, dt={dt}")
"""
T1_SEARCH = """    n = max(math.floor((math.sqrt(1.0 - 8.0 * y0 / (g * dt**2)) - 1.0) / 2.0) - 1, 0)
    while height_after(n, y0, dt, g) > 0:
        n += 1
    return n
"""

BUGS = [
    bug("count: n squared", 1, "return n**3", "return n * n", "particle_count", "one layer (n²)"),
    bug(
        "count: default N",
        1,
        "return n**3",
        "return N**3",
        "particle_count_for_any_size",
        "default N only",
    ),
    bug(
        "scheme: explicit euler",
        1,
        '"position verlet"\n',
        '"explicit euler"\n',
        "kernel_is_position_verlet",
        "explicit Euler moves with the velocity",
    ),
    bug(
        "scheme: runge-kutta",
        1,
        '"position verlet"\n',
        '"runge-kutta 4"\n',
        "kernel_is_position_verlet",
        "four times per step",
    ),
    bug(
        "verlet_step ignores dt",
        1,
        T1_VERLET,
        T1_VERLET.replace("dt**2", "DT**2"),
        "verlet_step_is_the_kernel",
        "instead of the dt argument",
    ),
    Variant(  # an adapted course: the template's dt changed
        "verlet_step ignores dt, the template's dt changed",
        1,
        (
            ("DT = 0.1  # time step", "DT = 0.05  # time step"),
            (T1_VERLET, T1_VERLET.replace("dt**2", "DT**2")),
        ),
        "verlet_step_is_the_kernel",
        "your DT = 0.05 instead of the dt argument",
    ),
    bug(
        "verlet_step a dt",
        1,
        T1_VERLET,
        T1_VERLET.replace("dt**2", "dt"),
        "verlet_step_is_the_kernel",
        "a·dt instead of a·dt²",
    ),
    bug(
        "verlet_step half a dt2",
        1,
        T1_VERLET,
        T1_VERLET.replace("+ np.", "+ 0.5 * np."),
        "verlet_step_is_the_kernel",
        "½·a·dt²",
    ),
    bug(
        "verlet_step clamps at the floor",
        1,
        T1_VERLET,
        "new = 2.0 * current - old + np.asarray(acceleration, dtype=float) * dt**2\n"
        "    new[..., 1] = np.maximum(new[..., 1], 0.0)\n    return new",
        "verlet_step_is_the_kernel",
        "floor clamp",
    ),
    bug(
        "verlet_step in place",
        1,
        T1_VERLET,
        "current *= 2.0\n    current -= old\n"
        "    current += np.asarray(acceleration, dtype=float) * dt**2\n    return current",
        "verlet_step_leaves_its_inputs_alone",
        "in-place updates",
    ),
    bug(
        "height off by one",
        1,
        T1_HEIGHT,
        T1_HEIGHT.replace("(steps + 1)", "(steps - 1)"),
        "height_after_as_template",
        "(1 + 2 + ... + n)",
    ),
    bug(
        "height ignores y0",
        1,
        T1_HEIGHT,
        T1_HEIGHT.replace("y0 +", "ORIGIN[1] +"),
        "height_after_for_any_start",
        "ORIGIN[1] = 1.5 used instead of the argument y0",
    ),
    bug(
        "height ignores g",
        1,
        T1_HEIGHT,
        T1_HEIGHT.replace("g *", "GRAVITY[1] *"),
        "height_after_for_any_start",
        "GRAVITY[1] = -0.001 used instead of the argument g",
    ),
    Variant(  # a friend's copy of the template: another student's own numbers
        "constants copied from another student",
        1,
        (
            ("ORIGIN = (-1.0, 1.5, -1.0)", "ORIGIN = (-1.0, 1.3, -1.0)"),
            ("GRAVITY = (0.0, -0.001, 0.0)", "GRAVITY = (0.0, -0.0008, 0.0)"),
        ),
        "steps_to_floor_as_template",
        "not the ones given to you",
    ),
    bug(
        "floor: no input check",
        1,
        T1_CHECK,
        "",
        "steps_to_floor_refuses_a_start_on_or_below_the_floor",
        "no check of the inputs",
    ),
    bug(
        "floor: one step late",
        1,
        T1_SEARCH,
        T1_SEARCH.replace("return n", "return n + 1"),
        "steps_to_floor_for_any_start",
        "one step late",
    ),
    bug(
        "floor: default arguments in the search",
        1,
        T1_SEARCH,
        T1_SEARCH.replace("height_after(n, y0, dt, g)", "height_after(n)"),
        "steps_to_floor_for_any_start",
        "only works for the default numbers",
    ),
    bug(
        "verlet_step delegated to msd.Verlet",
        1,
        T1_VERLET,
        "import msdlab as msd\n\n"
        "    flat = current.reshape(-1, 3)\n"
        "    dynamics = msd.Dynamics(msd.Body.from_arrays(flat), [msd.Gravity(acceleration)])\n"
        "    velocity = (flat - old.reshape(-1, 3)) / dt\n"
        "    return msd.Verlet().step(flat, velocity, dt, dynamics)[0].reshape(current.shape)",
        "verlet_step_is_the_kernel",
        "asks for your own implementation",
    ),
    bug(
        "count: n + 1 per edge",
        1,
        "return n**3",
        "return (n + 1) ** 3",
        "particle_count",
        "n + 1 particles per edge",
    ),
    bug(
        "height: no return",
        1,
        T1_HEIGHT,
        T1_HEIGHT.replace("return ", "height = "),
        "height_after_as_template",
        "height_after must end with return",
    ),
]

ALTERNATIVES = [
    alternative("count by multiplication", 1, ("return n**3", "return n * n * n")),
    alternative(
        "count from the grid", 1, ("return n**3", "return len(initial_grid(n).reshape(-1, 3))")
    ),
    alternative(
        "scheme named symplectic Euler (the same update)",
        1,
        ('return "position verlet"', 'return "symplectic euler"'),
    ),
    alternative("scheme from the list", 1, ('return "position verlet"', "return SCHEMES[2]")),
    alternative(
        "verlet_step as x + (x - x_old) + a dt dt",
        1,
        (T1_VERLET, "return current + (current - old) + np.asarray(acceleration) * dt * dt"),
    ),
    alternative(
        "verlet_step as the kernel's lines",
        1,
        (
            T1_VERLET,
            "velocity = (current - old) / dt + dt * np.asarray(acceleration, dtype=float)\n"
            "    return current + dt * velocity",
        ),
    ),
    alternative(
        "height by a loop",
        1,
        (
            T1_HEIGHT,
            "y_old = y = y0\n    for _ in range(steps):\n"
            "        y_old, y = y, 2 * y - y_old + g * dt**2\n    return y",
        ),
    ),
    alternative(
        "height with a half", 1, (T1_HEIGHT, "return y0 + 0.5 * g * dt**2 * (steps**2 + steps)")
    ),
    alternative(
        "floor by counting from zero",
        1,
        (
            T1_SEARCH,
            "    n = 0\n    while height_after(n, y0, dt, g) > 0:\n        n += 1\n    return n\n",
        ),
    ),
    alternative(
        "floor by the quadratic's root, rounded up",
        1,
        (
            T1_SEARCH,
            "    root = (math.sqrt(1.0 - 8.0 * y0 / (g * dt**2)) - 1.0) / 2.0\n"
            "    n = math.ceil(root)\n"
            "    while n > 0 and height_after(n - 1, y0, dt, g) <= 0:\n        n -= 1\n"
            "    while height_after(n, y0, dt, g) > 0:\n        n += 1\n    return n\n",
        ),
    ),
    alternative(
        "input check written as a list of conditions",
        1,
        (
            T1_CHECK,
            "    if y0 <= 0 or g >= 0 or dt <= 0:\n"
            '        raise ValueError(f"y0 > 0, g < 0 and dt > 0 are needed, got "'
            '"{y0}, {g}, {dt}")\n',
        ),
    ),
]

# ------------------------------------------------------------------------------- task 2
T2_FORCE = "        f = stiffness * (spacing - length) * direction  # eq. (1.2), the force on i\n"
T2_DIRECTION = "direction = np.divide(d, length, out=np.zeros_like(d), where=length > 0)"
T2_LENGTH = "length = np.linalg.norm(d, axis=-1, keepdims=True)"
T2_DIFF = "d = x[first] - x[second]  # x_i - x_j for the spring from i to its +axis neighbour j"
T2_REACTION = "        a[second] -= f  # the equal and opposite force on j\n"

BUGS += [
    bug(
        "stiffness ignored",
        2,
        T2_FORCE,
        T2_FORCE.replace("f = stiffness", "f = STIFFNESS"),
        "any_grid_size_spacing_and_stiffness",
        "stiffness argument is ignored",
    ),
    bug(
        "spacing ignored",
        2,
        T2_FORCE,
        T2_FORCE.replace("(spacing", "(SPACING"),
        "any_grid_size_spacing_and_stiffness",
        "spacing argument is ignored",
    ),
    Variant(  # an adapted course: the template's k changed, the checks' diagnosis follows it
        "stiffness ignored, the template's k changed",
        2,
        (
            ("STIFFNESS = 0.5  # k of every spring", "STIFFNESS = 0.8  # k of every spring"),
            (T2_FORCE, T2_FORCE.replace("f = stiffness", "f = STIFFNESS")),
        ),
        "any_grid_size_spacing_and_stiffness",
        "your STIFFNESS = 0.8 used instead",
    ),
    bug(
        "two axes only",
        2,
        "    for axis in range(3):\n",
        "    for axis in range(2):\n",
        "one_displaced_corner",
        "only two of the three axes",
    ),
    bug(
        "sign of the spring force reversed",
        2,
        T2_FORCE,
        T2_FORCE.replace("(spacing - length)", "(length - spacing)"),
        "stretched_pulls_compressed_pushes",
        "a stretched spring pushes its ends apart",
    ),
    bug(
        "no reaction on j",
        2,
        T2_REACTION,
        "",
        "forces_are_equal_and_opposite",
        "only one end of each spring gets its force",
    ),
    bug(
        "rest length 1 instead of one spacing",
        2,
        T2_FORCE,
        T2_FORCE.replace("(spacing - length)", "(1.0 - length)"),
        "grid_at_rest_feels_no_force",
        "'rest length 1' means one grid spacing",
    ),
    bug(
        "reaction with the same sign",
        2,
        T2_REACTION,
        T2_REACTION.replace("-=", "+="),
        "forces_are_equal_and_opposite",
        "the reaction on j has the same sign as the force on i",
    ),
    bug(
        "not divided by the length",
        2,
        T2_DIRECTION,
        "direction = d",
        "any_grid_size_spacing_and_stiffness",
        "not divided by the spring length",
    ),
    bug(
        "zero length divides by zero",
        2,
        T2_DIRECTION,
        "direction = d / length",
        "coincident_neighbours_give_no_nan",
        "without a guard for zero length",
    ),
    bug(
        "squared length",
        2,
        T2_LENGTH,
        "length = np.sum(d * d, axis=-1, keepdims=True)",
        "grid_at_rest_feels_no_force",
        "pre-stressed",
    ),
    bug(
        "force split between the ends",
        2,
        T2_FORCE,
        T2_FORCE.replace("direction  #", "direction / 2  #"),
        "one_displaced_corner",
        "half of each spring force",
    ),
    bug(
        "positions centred in place",
        2,
        "    a = np.zeros_like(x)\n",
        "    x -= x.reshape(-1, 3).mean(axis=0)  # centred for precision\n"
        "    a = np.zeros_like(x)\n",
        "positions_are_not_modified",
        "in-place operations on x",
    ),
    bug(
        "average instead of sum",
        2,
        "    return a\n    ### END SOLUTION",
        "    count = np.zeros(x.shape[:3])\n"
        "    for axis in range(3):\n"
        "        count += (np.arange(x.shape[axis]) > 0).reshape("
        "[-1 if i == axis else 1 for i in range(3)])\n"
        "        count += (np.arange(x.shape[axis]) < x.shape[axis] - 1).reshape("
        "[-1 if i == axis else 1 for i in range(3)])\n"
        "    return a / np.maximum(count, 1)[..., None]\n    ### END SOLUTION",
        "matches_equations_on_a_deformed_grid",
        "not their average",
    ),
    bug(
        "delegated to Body.grid and Dynamics",
        2,
        "    a = np.zeros_like(x)\n",
        "    import msdlab as msd\n\n"
        "    body = msd.Body.grid(x.shape[:3], spacing, stiffness)\n"
        "    flat = x.reshape(-1, 3)\n"
        "    return msd.Dynamics(body).acceleration(flat, 0 * flat).reshape(x.shape)\n"
        "    a = np.zeros_like(x)\n",
        "matches_equations_on_a_deformed_grid",
        "asks for your own implementation",
    ),
    bug(
        "delegated to the spring kernel",
        2,
        "    a = np.zeros_like(x)\n",
        "    import msdlab as msd\n    from msdlab.engine.backends.numpy import spring_forces\n\n"
        "    body = msd.Body.from_arrays(x.reshape(-1, 3))\n"
        "    for axis in range(3):\n"
        "        index = np.arange(x[..., 0].size).reshape(x.shape[:3])\n"
        "        pairs = np.stack([np.delete(index, -1, axis).ravel(),"
        " np.delete(index, 0, axis).ravel()], axis=1)\n"
        "        body.add_springs(pairs, stiffness, spacing)\n"
        "    flat = x.reshape(-1, 3)\n"
        "    return spring_forces(body, flat, 0 * flat)[0].reshape(x.shape)\n"
        "    a = np.zeros_like(x)\n",
        "matches_equations_on_a_deformed_grid",
        "asks for your own implementation",
    ),
    bug(
        "no return",
        2,
        "    return a\n",
        "",
        "grid_at_rest_feels_no_force",
        "spring_acceleration must end with return",
    ),
]

ALTERNATIVES += [
    alternative("difference the other way round", 2, (T2_DIFF, "d = -(x[second] - x[first])")),
    alternative(
        "length by einsum",
        2,
        (T2_LENGTH, "length = np.sqrt(np.einsum('...i,...i->...', d, d))[..., None]"),
    ),
    alternative(
        "direction by where", 2, (T2_DIRECTION, "direction = d / np.where(length > 0, length, 1.0)")
    ),
    alternative(
        "direction by an infinite length",
        2,
        (T2_DIRECTION, "direction = d / np.where(length > 0, length, np.inf)"),
    ),
    alternative(
        "force written as -k(|d| - l)",
        2,
        (
            T2_FORCE,
            T2_FORCE.replace("stiffness * (spacing - length)", "-stiffness * (length - spacing)"),
        ),
    ),
    alternative(
        "springs seen from the other end",
        2,
        (T2_DIFF, "d = x[second] - x[first]"),
        ("        a[first] += f\n", "        a[second] += f\n"),
        (T2_REACTION, "        a[first] -= f\n"),
    ),
    alternative(
        "stiffness applied at the end",
        2,
        (T2_FORCE, T2_FORCE.replace("stiffness * ", "")),
        ("    return a\n    ### END SOLUTION", "    return stiffness * a\n    ### END SOLUTION"),
    ),
    alternative(
        "axes in reverse order", 2, ("    for axis in range(3):\n", "    for axis in (2, 1, 0):\n")
    ),
    alternative(
        "zeros of the shape", 2, ("    a = np.zeros_like(x)\n", "    a = np.zeros(x.shape)\n")
    ),
]

# ------------------------------------------------------------------------------- task 3
T3_RODRIGUES = (
    "return np.cos(theta) * np.eye(3) + np.sin(theta) * cross + (1 - np.cos(theta)) * "
    "np.outer(n, n)"
)
T3_ROTATE = "return ((points - centroid) @ rotation.T + centroid).reshape(positions.shape)"
T3_FORCE = "f = stiffness * (rest_lengths[:, None] - length) * direction"
T3_DIRECTION = "direction = np.divide(d, length, out=np.zeros_like(d), where=length > 0)"
T3_SUM = """    for axis in range(3):
        a[:, axis] = np.bincount(i, f[:, axis], len(positions)) - np.bincount(
            j, f[:, axis], len(positions)
        )
"""
T3_GRID = "neighbours=neighbours)"
T3_RUN = "simulation.run(steps=steps, record_every=steps)"

BUGS += [
    bug(
        "degrees used as radians",
        3,
        "theta = np.radians(angle_degrees)",
        "theta = angle_degrees",
        "rotation_matrix_right_handed",
        "radians where degrees are given",
    ),
    bug(
        "axis not normalised",
        3,
        "n = axis / np.linalg.norm(axis)",
        "n = axis",
        "rotation_matrix_right_handed",
        "the axis is not normalised",
    ),
    bug(
        "Rodrigues without the n n^T term",
        3,
        T3_RODRIGUES,
        T3_RODRIGUES.replace(" + (1 - np.cos(theta)) * np.outer(n, n)", ""),
        "rotation_matrix_right_handed",
        "Rodrigues' formula with the unit axis",
    ),
    bug(
        "centroid of all coordinates",
        3,
        "centroid = points.mean(axis=0)",
        "centroid = points.mean()",
        "rotate_layout_turns_about_centroid",
        "c the centroid",
    ),
    bug(
        "layout rotated about the origin",
        3,
        "centroid = points.mean(axis=0)",
        "centroid = np.zeros(3)",
        "rotate_layout_turns_about_centroid",
        "rotating about the origin instead of the centroid",
    ),
    bug(
        "layout turned the other way",
        3,
        T3_ROTATE,
        T3_ROTATE.replace("rotation.T", "rotation"),
        "rotate_layout_turns_about_centroid",
        "row vectors need x @ R.T",
    ),
    bug(
        "layout angle fixed",
        3,
        "rotation = rotation_matrix(angle_degrees, axis)",
        "rotation = rotation_matrix(45.0, axis)",
        "rotate_layout_turns_about_centroid",
        "the angle argument is ignored",
    ),
    bug(
        "rest lengths averaged",
        3,
        T3_FORCE,
        T3_FORCE.replace("rest_lengths[:, None]", "rest_lengths.mean()"),
        "spring_acceleration_matches_equations",
        "one rest length for every spring",
    ),
    bug(
        "stiffness ignored",
        3,
        T3_FORCE,
        T3_FORCE.replace("f = stiffness", "f = STIFFNESS"),
        "any_spring_list",
        "stiffness argument is ignored",
    ),
    bug(
        "no reaction on j",
        3,
        T3_SUM,
        "    for axis in range(3):\n"
        "        a[:, axis] = np.bincount(i, f[:, axis], len(positions))\n",
        "spring_acceleration_matches_equations",
        "-f_ij is never added to particle j",
    ),
    bug(
        "zero length divides by zero",
        3,
        T3_DIRECTION,
        "direction = d / length",
        "zero_length_spring_gives_no_nan",
        "without a guard for zero length",
    ),
    bug(
        "cube neighbours ignored",
        3,
        T3_GRID,
        "neighbours=(1,))",
        "drop_rotated_cube_uses_steps_and_neighbours",
        "the neighbours argument is ignored",
    ),
    bug(
        "cube dropped with damped Verlet",
        3,
        "msd.Verlet(), DT",
        "msd.Verlet(0.05), DT",
        "tilted_cube_collapses_upright_one_stands",
        "undamped scheme",
    ),
    bug(
        "cube steps ignored",
        3,
        T3_RUN,
        "simulation.run(steps=1500, record_every=1500)",
        "drop_rotated_cube_uses_steps_and_neighbours",
        "the number of steps is ignored",
    ),
    bug(
        "rotation delegated to msd.rotation_matrix",
        3,
        T3_RODRIGUES,
        "return msd.rotation_matrix(angle_degrees, axis)",
        "rotation_matrix_right_handed",
        "asks for your own implementation",
    ),
    bug(
        "springs delegated to Dynamics",
        3,
        "    i, j = springs[:, 0], springs[:, 1]\n",
        "    body = msd.Body.from_arrays(positions, springs, stiffness=stiffness,"
        " rest_lengths=rest_lengths)\n"
        "    return msd.Dynamics(body).acceleration(positions, 0 * positions)\n"
        "    i, j = springs[:, 0], springs[:, 1]\n",
        "spring_acceleration_matches_equations",
        "asks for your own implementation",
    ),
    bug(
        "rotation_matrix called axis first",
        3,
        "rotation = rotation_matrix(angle_degrees, axis)",
        "rotation = rotation_matrix(axis, angle_degrees)",
        "rotate_layout_turns_about_centroid",
        "rotation_matrix takes (angle_degrees, axis)",
    ),
]

ALTERNATIVES += [
    alternative(
        "Rodrigues with K squared",
        3,
        (
            T3_RODRIGUES,
            "return np.eye(3) + np.sin(theta) * cross + (1 - np.cos(theta)) * cross @ cross",
        ),
    ),
    alternative(
        "axis normalised by hand",
        3,
        ("n = axis / np.linalg.norm(axis)", "n = axis / np.sqrt(axis @ axis)"),
    ),
    alternative(
        "matrix applied from the left",
        3,
        (
            T3_ROTATE,
            "return ((rotation @ (points - centroid).T).T + centroid).reshape(positions.shape)",
        ),
    ),
    alternative(
        "matrix applied by einsum",
        3,
        (
            T3_ROTATE,
            "turned = np.einsum('ij,nj->ni', rotation, points - centroid)\n"
            "    return (turned + centroid).reshape(positions.shape)",
        ),
    ),
    alternative(
        "accumulated with np.add.at",
        3,
        (T3_SUM, "    np.add.at(a, i, f)\n    np.subtract.at(a, j, f)\n"),
    ),
    alternative(
        "springs seen from the other end",
        3,
        ("i, j = springs[:, 0], springs[:, 1]", "i, j = springs[:, 1], springs[:, 0]"),
    ),
    alternative(
        "direction by where", 3, (T3_DIRECTION, "direction = d / np.where(length > 0, length, 1.0)")
    ),
    alternative(
        "force as -k(|d| - l)",
        3,
        (T3_FORCE, "f = -stiffness * (length - rest_lengths[:, None]) * direction"),
    ),
    alternative(
        "lift as a vector",
        3,
        (
            "body.positions[:, 1] += LIFT - body.positions[:, 1].min()",
            "body.positions = body.positions + np.array([0.0, LIFT - body.positions[:, 1].min(), "
            "0.0])",
        ),
    ),
]

# ------------------------------------------------------------------------------- task 4
T4_TEST = "if di * di + dj * dj + dk * dk in wanted"
T4_REST = "rest.append(np.full(len(found), spacing * np.sqrt(np.sum(offset**2))))"
T4_SLICES = "second = tuple(slice(max(0, o), n - max(0, -o)) for o, n in zip(offset, shape))"
T4_DROP_SPRINGS = "springs, rest = grid_springs((N, N, N), 2.0 / N, squared_distances)"
T4_DROP_RUN = "    simulation.run(steps=steps, record_every=steps)\n    return flatness"
T4_COST = "return len(springs), (time.perf_counter() - start) / steps"
T4_COST_BUILD = """    springs, rest = grid_springs((n, n, n), 2.0 / n, squared_distances)
    positions = grid_positions((n, n, n), 2.0 / n)
"""
T4_OFFSETS = "    return np.array(offsets, dtype=int)\n"

BUGS += [
    bug(
        "no body diagonals",
        4,
        T4_TEST,
        T4_TEST + " and abs(di) + abs(dj) + abs(dk) < 3",
        "neighbour_offsets_26",
        "none of squared length 3 was kept",
    ),
    bug(
        "offsets ignore the choice",
        4,
        T4_TEST,
        T4_TEST.replace("wanted", "(1, 2, 3)"),
        "neighbour_offsets_26",
        "not only those that were asked for",
    ),
    bug(
        "offsets include the particle itself",
        4,
        T4_TEST,
        T4_TEST + " or (di, dj, dk) == (0, 0, 0)",
        "neighbour_offsets_26",
        "the zero offset",
    ),
    bug(
        "springs one short at the far border",
        4,
        T4_SLICES,
        "second = tuple(slice(max(0, o), n - max(0, -o)) for o, n in zip(offset, shape))\n"
        "        first = tuple(slice(s.start, s.stop - (o > 0)) for s, o in zip(first, offset))\n"
        "        second = tuple(slice(s.start, s.stop - (o > 0)) for s, o in zip(second, offset))",
        "grid_springs_each_pair_once",
        "springs missing at the border",
    ),
    bug(
        "rest lengths without the root",
        4,
        T4_REST,
        T4_REST.replace("np.sqrt(np.sum(offset**2))", "np.sum(offset**2)"),
        "rest_lengths_unstressed",
        "without the root",
    ),
    bug(
        "diagonal rest lengths one spacing",
        4,
        T4_REST,
        T4_REST.replace("spacing * np.sqrt(np.sum(offset**2))", "spacing"),
        "rest_lengths_unstressed",
        "one rest length, the spacing, for every spring",
    ),
    bug(
        "no face diagonals",
        4,
        T4_TEST,
        T4_TEST + " and di * di + dj * dj + dk * dk != 2",
        "neighbour_offsets_26",
        "none of squared length 2 was kept",
    ),
    bug(
        "springs listed from both ends",
        4,
        "        if tuple(offset) <= (0, 0, 0):  # keep one of o and -o: each spring once\n"
        "            continue\n",
        "",
        "grid_springs_each_pair_once",
        "both i→j and j→i listed",
    ),
    bug(
        "rest lengths for the template's spacing",
        4,
        T4_REST,
        T4_REST.replace("spacing * ", "2.0 / N * "),
        "any_grid_shape_and_neighbours",
        "not spacing·√(squared length)",
    ),
    bug(
        "springs ignore the choice",
        4,
        "neighbour_offsets(squared_distances):",
        "neighbour_offsets():",
        "any_grid_shape_and_neighbours",
        "were asked for",
    ),
    bug(
        "Fortran order",
        4,
        "index = np.arange(np.prod(shape)).reshape(shape)",
        "index = np.arange(np.prod(shape)).reshape(shape, order='F')",
        "grid_springs_each_pair_once",
        "C order mixed up",
    ),
    bug(
        "cube ignores the neighbours",
        4,
        T4_DROP_SPRINGS,
        "springs, rest = grid_springs((N, N, N), 2.0 / N)",
        "rotated_cube_holds_its_shape",
        "ignores squared_distances",
    ),
    bug(
        "cube ignores the steps",
        4,
        T4_DROP_RUN,
        "    simulation.run(steps=1500, record_every=1500)\n    return flatness",
        "drop_rotated_cube_runs_the_steps_asked_for",
        "the number of steps is ignored",
    ),
    bug(
        "cost: the total time",
        4,
        T4_COST,
        "return len(springs), time.perf_counter() - start",
        "step_cost_reports_springs_and_time",
        "the total time of all steps",
    ),
    bug(
        "cost: n ignored",
        4,
        T4_COST_BUILD,
        T4_COST_BUILD.replace("(n, n, n), 2.0 / n", "(10, 10, 10), 0.2"),
        "step_cost_reports_springs_and_time",
        "is n ignored",
    ),
    bug(
        "cost: springs counted twice",
        4,
        T4_COST,
        T4_COST.replace("len(springs)", "2 * len(springs)"),
        "step_cost_reports_springs_and_time",
        "springs counted twice",
    ),
    bug(
        "offsets delegated to the engine's lattice",
        4,
        "    steps = (-1, 0, 1)\n",
        "    from msdlab.engine.model.lattice import neighbour_offsets as engine_offsets\n\n"
        "    return engine_offsets(3, wanted)\n    steps = (-1, 0, 1)\n",
        "neighbour_offsets_26",
        "asks for your own implementation",
    ),
    bug(
        "springs delegated to Body.grid",
        4,
        "    index = np.arange(np.prod(shape)).reshape(shape)\n",
        "    body = msd.Body.grid(shape, spacing, neighbours=squared_distances)\n"
        "    edges = body.edges()\n"
        "    return np.stack([edges.a, edges.b], axis=1), edges.rest_lengths.copy()\n"
        "    index = np.arange(np.prod(shape)).reshape(shape)\n",
        "grid_springs_each_pair_once",
        "asks for your own implementation",
    ),
    bug(
        "offsets by length, not squared length",
        4,
        T4_TEST,
        "if np.sqrt(di * di + dj * dj + dk * dk) in wanted",
        "neighbour_offsets_26",
        "neighbour_offsets keeps an offset by its length",
    ),
    bug(
        "springs: no return",
        4,
        "return np.concatenate(pairs).astype(int), np.concatenate(rest)",
        "springs = np.concatenate(pairs).astype(int), np.concatenate(rest)",
        "grid_springs_each_pair_once",
        "grid_springs must end with return",
    ),
]

ALTERNATIVES += [
    alternative(
        "offsets by itertools",
        4,
        (
            "    steps = (-1, 0, 1)\n",
            "    import itertools\n\n"
            "    found = [o for o in itertools.product((-1, 0, 1), repeat=3)"
            " if sum(c * c for c in o) in wanted]\n"
            "    return np.array(found, dtype=int)\n    steps = (-1, 0, 1)\n",
        ),
    ),
    alternative(
        "offsets by np.indices",
        4,
        (
            "    steps = (-1, 0, 1)\n",
            "    cube = np.indices((3, 3, 3)).reshape(3, -1).T - 1\n"
            "    return cube[np.isin((cube**2).sum(axis=1), wanted)]\n    steps = (-1, 0, 1)\n",
        ),
    ),
    alternative(
        "the other half of the offsets",
        4,
        ("if tuple(offset) <= (0, 0, 0):", "if tuple(offset) >= (0, 0, 0):"),
    ),
    alternative(
        "rest length by norm",
        4,
        (T4_REST, "rest.append(np.full(len(found), spacing * np.linalg.norm(offset)))"),
    ),
    alternative(
        "offsets as float array", 4, (T4_OFFSETS, "    return np.array(offsets).reshape(-1, 3)\n")
    ),
    alternative(
        "springs by a loop over particles",
        4,
        (
            "    index = np.arange(np.prod(shape)).reshape(shape)\n",
            "    pairs_found, rests = [], []\n"
            "    for offset in neighbour_offsets(squared_distances):\n"
            "        if tuple(offset) <= (0, 0, 0):\n            continue\n"
            "        for cell in np.ndindex(*shape):\n"
            "            other = tuple(int(c + o) for c, o in zip(cell, offset))\n"
            "            if all(0 <= c < n for c, n in zip(other, shape)):\n"
            "                pairs_found.append((np.ravel_multi_index(cell, shape),"
            " np.ravel_multi_index(other, shape)))\n"
            "                rests.append(spacing * float(np.sqrt(offset @ offset)))\n"
            "    return np.array(pairs_found, dtype=int).reshape(-1, 2), np.array(rests)\n"
            "    index = np.arange(np.prod(shape)).reshape(shape)\n",
        ),
    ),
    alternative(
        "centroid rotation written out",
        4,
        (
            "positions = (positions - centroid) @ msd.rotation_matrix(angle_degrees, axis).T"
            " + centroid",
            "rotation = msd.rotation_matrix(angle_degrees, axis)\n"
            "    positions = centroid + np.einsum('ij,nj->ni', rotation, positions - centroid)",
        ),
    ),
    alternative(
        "time in nanoseconds",
        4,
        ("    start = time.perf_counter()\n", "    start = time.perf_counter_ns()\n"),
        (T4_COST, "return len(springs), (time.perf_counter_ns() - start) / 1e9 / steps"),
    ),
    alternative(
        "springs counted from the body",
        4,
        (T4_COST, "return body.n_springs, (time.perf_counter() - start) / steps"),
    ),
]

# ------------------------------------------------------------------------------- task 5
T5_NEW = "new = (2.0 - lam) * current - (1.0 - lam) * old + acceleration * dt**2"
T5_OLD = "old, current = x - v * dt, x"
T5_ACC = "acceleration = dynamics.acceleration(current, v)"
T5_RANGE = "if not 0.0 <= lam < 1.0:"
T5_RETURN = "return new, (new - current) / dt"
T5_MEASURE = "return msd.measure_blowup_dt(jelly(n), DampedVerlet(damping), steps=steps, rtol=rtol)"

BUGS += [
    bug(
        "damping ignored",
        5,
        "        lam = self.damping\n",
        "        lam = 0.0\n",
        "one_step_is_equation_1_4",
        "λ is ignored",
    ),
    bug(
        "acceleration at zero velocity",
        5,
        T5_ACC,
        "acceleration = dynamics.acceleration(current, np.zeros_like(v))",
        "velocity_dependent_forces_see_the_velocity",
        "zero velocity",
    ),
    bug(
        "x(t - dt) as x + v dt",
        5,
        T5_OLD,
        "old, current = x + v * dt, x",
        "one_step_is_equation_1_4",
        "x + v·dt",
    ),
    bug(
        "signs of damping reversed",
        5,
        T5_NEW,
        "new = (2.0 + lam) * current - (1.0 + lam) * old + acceleration * dt**2",
        "one_step_is_equation_1_4",
        "signs of λ reversed",
    ),
    bug(
        "damping applied to the whole update",
        5,
        T5_NEW,
        "new = (1.0 - lam) * (2.0 * current - old + acceleration * dt**2) + lam * current",
        "damping_acts_on_velocity_only",
        "damping applied to the whole update",
    ),
    bug(
        "damping applied to the positions",
        5,
        T5_NEW,
        "new = (1.0 - lam) * (2.0 * current - old) + acceleration * dt**2",
        "damping_acts_on_velocity_only",
        "pulls particles towards the origin",
    ),
    bug(
        "no damping refused",
        5,
        T5_RANGE,
        "if not 0.0 < lam < 1.0:",
        "damping_outside_0_to_1_is_refused",
        "excludes valid values",
    ),
    bug(
        "damping 1 accepted",
        5,
        T5_RANGE,
        "if not 0.0 <= lam <= 1.0:",
        "damping_outside_0_to_1_is_refused",
        "was accepted",
    ),
    bug(
        "NaN damping accepted",
        5,
        T5_RANGE,
        "if lam < 0.0 or lam >= 1.0:",
        "damping_outside_0_to_1_is_refused",
        "NaN",
    ),
    bug(
        "velocity damped in place",
        5,
        T5_NEW,
        "v *= 1.0 - lam\n        new = current + v * dt + acceleration * dt**2",
        "one_step_in_2d_and_3d",
        "in-place",
    ),
    bug(
        "central difference velocity",
        5,
        T5_RETURN,
        "return new, (new - old) / (2 * dt)",
        "one_step_is_equation_1_4",
        "central difference",
    ),
    bug(
        "jelly size ignored",
        5,
        T5_MEASURE,
        T5_MEASURE.replace("jelly(n)", "jelly()"),
        "measured_stable_dt_of_another_jelly",
        "n is ignored",
    ),
    bug(
        "measured without damping",
        5,
        T5_MEASURE,
        T5_MEASURE.replace("DampedVerlet(damping)", "DampedVerlet(0.0)"),
        "measured_stable_dt_as_predicted",
        "the damping λ is not passed on",
    ),
    bug(
        "measured with the engine's Verlet",
        5,
        T5_MEASURE,
        T5_MEASURE.replace("DampedVerlet(damping)", "msd.Verlet(damping)"),
        "measured_stable_dt_as_predicted",
        "asks for your own implementation",
    ),
    bug(
        "step delegated to msd.Verlet",
        5,
        "        lam = self.damping\n",
        "        return msd.Verlet(self.damping).step(x, v, dt, dynamics)\n"
        "        lam = self.damping\n",
        "one_step_is_equation_1_4",
        "asks for your own implementation",
    ),
    Variant(
        "a subclass of msd.Verlet",
        5,
        (
            ("class DampedVerlet(msd.Integrator):", "class DampedVerlet(msd.Verlet):"),
            (
                "        ### BEGIN SOLUTION\n        # TODO: check that 0 <= damping",
                "        super().__init__(damping)\n        ### BEGIN SOLUTION\n"
                "        # TODO: check that 0 <= damping",
            ),
            (
                "        lam = self.damping\n",
                "        return super().step(x, v, dt, dynamics)\n        lam = self.damping\n",
            ),
        ),
        "one_step_is_equation_1_4",
        "asks for your own implementation",
    ),
]

ALTERNATIVES += [
    alternative(
        "x + (1 - λ)(x - x_old) + a dt²",
        5,
        (T5_NEW, "new = current + (1.0 - lam) * (current - old) + acceleration * dt**2"),
    ),
    alternative(
        "velocity form",
        5,
        (
            T5_NEW,
            "velocity = (1.0 - lam) * v + acceleration * dt\n        new = current + velocity * dt",
        ),
        (T5_RETURN, "return new, velocity"),
    ),
    alternative(
        "range check with isnan", 5, (T5_RANGE, "if np.isnan(lam) or lam < 0.0 or lam >= 1.0:")
    ),
    alternative(
        "copies of x and v",
        5,
        (T5_OLD, "old = np.array(x) - np.array(v) * dt\n        current = np.array(x)"),
    ),
    alternative(
        "body named first",
        5,
        (
            T5_MEASURE,
            "body = jelly(n)\n    integrator = DampedVerlet(damping)\n"
            "    return msd.measure_blowup_dt(body, integrator, "
            "steps=steps, rtol=rtol)",
        ),
    ),
    alternative(
        "damping as a difference",
        5,
        (T5_NEW, "new = 2.0 * current - old - lam * (current - old) + acceleration * dt**2"),
    ),
    alternative(
        "acceleration of the arguments", 5, (T5_ACC, "acceleration = dynamics.acceleration(x, v)")
    ),
    alternative(
        "velocity by division first", 5, (T5_RETURN, "return new, new / dt - current / dt")
    ),
]
