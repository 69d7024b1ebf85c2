"""Checks of task 4: face- and body-diagonal springs, a rotated cube that holds, cost per step."""

from __future__ import annotations

import functools
import math

import numpy as np
import pytest

from msdlab.course import oracles
from msdlab.course.experiments import cube_ratio
from msdlab.course.feedback import (
    CheckFailed,
    Recognised,
    as_array,
    expect,
    matching_variant,
    num,
    percent,
    returned,
)

pytestmark = pytest.mark.task4

SHAPE = (3, 4, 5)
KINDS = {1: "axis", 2: "face-diagonal", 3: "body-diagonal"}


def engine_pairs(shape, neighbours):
    body = oracles.grid_body(shape, 1.0, 1.0, neighbours)
    return {frozenset(p) for p in zip(body.edges().a.tolist(), body.edges().b.tolist())}, body


def student_offsets(task4, wanted):
    """The student's neighbour_offsets(wanted) as an array (a check fails if it returns None)."""
    return np.asarray(returned(task4.neighbour_offsets(wanted), f"neighbour_offsets({wanted})"))


def engine_offsets(wanted):
    """The offsets (M, 3) in {-1, 0, 1}³ whose squared length is in ``wanted``, sorted."""
    cube = np.stack(np.meshgrid(*3 * [(-1, 0, 1)], indexing="ij"), axis=-1).reshape(-1, 3)
    return cube[np.isin(np.sum(cube**2, axis=1), wanted)]


OFFSET_WANTS = ((1,), (2,), (3,), (1, 2, 3))
BY_LENGTH = (
    "neighbour_offsets keeps an offset by its length √(di² + dj² + dk²), not by its squared "
    "length di² + dj² + dk²: squared_distances lists squared lengths (2 and 3 keep nothing)"
)


@functools.lru_cache(maxsize=16)  # per task module: the checks of one submission ask often
def offsets_of(task4):
    """The student's neighbour_offsets for each of `OFFSET_WANTS`, sorted (raises where the
    function does)."""
    return [sorted(map(tuple, student_offsets(task4, w).tolist())) for w in OFFSET_WANTS]


def offsets_mistake(task4):
    """The mistake recognised in the student's neighbour_offsets, run on its own, or None: its
    offsets for (1,), (2,), (3,) and (1, 2, 3) are those of an offset's length compared with
    the squared lengths asked for."""
    try:
        got = offsets_of(task4)
    except Exception:  # the checks say what is wrong
        return None
    by_length = [
        sorted(map(tuple, engine_offsets([s for s in w if math.isqrt(s) ** 2 == s]).tolist()))
        for w in OFFSET_WANTS
    ]
    return Recognised(BY_LENGTH) if got == by_length else None


def offsets_wrong(task4):
    """Why neighbour_offsets is wrong (its recognised mistake, that it fails, or that its
    offsets differ from those asked for), or None where it is right."""
    try:
        got = offsets_of(task4)
    except Exception as error:
        return f"your neighbour_offsets fails ({type(error).__name__}), and grid_springs uses it"
    if got != [sorted(map(tuple, engine_offsets(w).tolist())) for w in OFFSET_WANTS]:
        return offsets_mistake(task4) or (
            "your neighbour_offsets is wrong (see its check), and grid_springs uses it"
        )
    return None


def called_grid_springs(task4, shape, spacing, neighbours):
    """The student's grid_springs(shape, spacing, neighbours); where it fails and their
    neighbour_offsets, which it uses, has a recognised mistake, a failure naming that one."""
    call = f"grid_springs({shape}, {spacing}, {tuple(neighbours)})"
    try:
        return returned(task4.grid_springs(shape, spacing, neighbours), call)
    except CheckFailed:
        raise
    except Exception as error:
        upstream = offsets_mistake(task4)
        if not upstream:
            raise
        expect(False, saw=f"{call} fails ({type(error).__name__}: {error})", cause=upstream)


def student_springs(task4, shape, spacing, neighbours):
    springs, rest = called_grid_springs(task4, shape, spacing, neighbours)
    springs = np.asarray(springs)
    rest = as_array(rest, "grid_springs (rest lengths)")
    expect(
        springs.ndim == 2 and springs.shape[1:] == (2,) and len(springs) == len(rest),
        saw=f"grid_springs returned springs of shape {springs.shape} and {len(rest)} rest "
        "lengths; expected (E, 2) and (E,)",
    )
    expect(
        np.issubdtype(springs.dtype, np.integer),
        saw=f"grid_springs returned spring ends of type {springs.dtype}, not integers",
        cause="building the index pairs with floats (np.array of a float grid)",
    )
    return springs.astype(np.int64), rest


TWICE = "both i→j and j→i listed (a spring counted twice doubles its force)"
EVERY_KIND = (
    "neighbours of every kind (axis, face- and body-diagonal), not only those that were "
    "asked for with squared_distances"
)
AT_THE_BORDER = (
    "springs missing at the border: each offset joins every particle whose neighbour "
    "(i, j, k) + offset is inside the grid, up to the last one"
)
LENGTHS = {1: "axis (spacing)", 2: "face-diagonal (spacing·√2)", 3: "body-diagonal (spacing·√3)"}


@functools.lru_cache(maxsize=16)  # per task module: the checks of one submission ask often
def springs_mistake(task4):
    """The typical mistake the student's grid_springs (and the neighbour_offsets it uses) is
    recognised as, or None: the springs of a 3 × 4 × 5 grid (with interior particles) of
    spacing 0.3 (no template's number) with all neighbours and with axis neighbours only
    are exactly what the mistake gives.

    Every check of the springs and of what is built from them (the cube, the cost) names it
    as its cause, so the report names the one mistake once.
    """
    shape, spacing = (3, 4, 5), 0.3
    try:
        every = student_springs(task4, shape, spacing, (1, 2, 3))
        axis = student_springs(task4, shape, spacing, (1,))
    except Exception:  # the checks say what is wrong; a mistake upstream is the cause
        return offsets_mistake(task4)
    found = sorted(tuple(sorted(p)) for p in every[0].tolist())
    own = pairs_mistake(found, shape, axis[0]) or rest_mistake(every, shape, spacing)
    if own or grid_springs_wrong(task4):  # the neighbour_offsets it uses is named first
        return offsets_mistake(task4) or own
    return None


def pairs_mistake(found, shape, axis_springs):
    """The mistake whose springs are ``found`` (sorted pairs, all neighbours asked for) and
    ``axis_springs`` (axis neighbours asked for) of a ``shape`` grid, or None."""
    expected, _ = engine_pairs(shape, (1, 2, 3))
    twice = sorted(2 * [tuple(sorted(p)) for p in expected])
    if found == twice:
        return Recognised(TWICE)
    for kept in ((1,), (2,), (3,), (1, 2), (1, 3), (2, 3)):
        pairs, _ = engine_pairs(shape, kept)
        if found == sorted(tuple(sorted(p)) for p in pairs):
            missing = [n for n in (1, 2, 3) if n not in kept]
            names = " and ".join(LENGTHS[n] for n in missing)
            return Recognised(
                f"none of squared length {' or '.join(map(str, missing))} was kept: the "
                f"{names} neighbours are missing"
            )
    c_to_f = np.ravel_multi_index(np.unravel_index(np.arange(np.prod(shape)), shape), shape,
                                  order="F")  # fmt: skip
    if found == sorted(tuple(sorted(c_to_f[list(p)].tolist())) for p in expected):
        return Recognised("C order mixed up: particle (i, j, k) is row (i·ny + j)·nz + k")
    axis = {frozenset(p) for p in axis_springs.tolist()}
    if axis == set(expected) and len(axis_springs) == len(expected):
        return Recognised(EVERY_KIND)
    wanted = {tuple(sorted(p)) for p in expected}
    missing = wanted - set(found)
    if missing and set(found) < wanted and len(set(found)) == len(found):
        border = np.array([(0, n - 1) for n in shape])
        where = np.stack(np.unravel_index(np.array(sorted(missing)), shape), axis=-1)  # (M, 2, 3)
        if np.all(np.any((where == border[:, 0]) | (where == border[:, 1]), axis=(1, 2))):
            return Recognised(AT_THE_BORDER)
    return None


def rest_mistake(springs_and_rest, shape, spacing):
    """The mistake whose rest lengths are these, for the right springs of a ``shape`` grid of
    ``spacing``, or None."""
    springs, rest = springs_and_rest
    positions = oracles.template_positions(shape, spacing, (0.0, 0.0, 0.0)).reshape(-1, 3)
    distance = np.linalg.norm(positions[springs[:, 0]] - positions[springs[:, 1]], axis=1)
    if distance.shape != rest.shape or np.allclose(rest, distance, rtol=1e-12):
        return None
    squared = np.round((distance / spacing) ** 2)
    mistakes = {
        "rest lengths spacing·(squared length), without the root: a face-diagonal spring is "
        "spacing·√2 long at rest, a body-diagonal one spacing·√3": spacing * squared,
        "one rest length, the spacing, for every spring: a face-diagonal spring is "
        "spacing·√2 long at rest, a body-diagonal one spacing·√3": np.full_like(rest, spacing),
        "rest lengths in grid units (1, √2, √3), not times the spacing": np.sqrt(squared),
    }
    found = matching_variant(rest, mistakes, rtol=1e-9)
    scale = rest / distance
    if found is None and np.allclose(scale, scale[0], rtol=1e-9):
        return Recognised(
            "rest lengths for another spacing (a constant such as 2/N), not spacing·√(squared "
            "length) with the spacing given"
        )
    return found


@functools.lru_cache(maxsize=16)
def cube_mistake(task4):
    """The mistake recognised in drop_rotated_cube, or None: the same ratio whatever
    squared_distances (the springs of every kind, or axis springs only, are built), where the
    student's neighbour_offsets and grid_springs, run on their own, are right."""
    if springs_mistake(task4) or springs_wrong(task4):
        return None
    try:
        axis_only = cube_ratio(task4, 45.0, (0.0, 0.0, 1.0), (1,))
        every = cube_ratio(task4, 45.0, (0.0, 0.0, 1.0), (1, 2, 3))
    except Exception:  # the checks say what is wrong
        return None
    if axis_only != every:
        return None
    return Recognised(
        "drop_rotated_cube ignores squared_distances: build the cube with "
        "grid_springs(..., squared_distances), the springs asked for"
    )


def springs_at_fault(task4):
    """Why drop_rotated_cube may be wrong because of grid_springs, or of the springs it
    builds (the mistake recognised there, where there is one), or None."""
    return springs_mistake(task4) or springs_wrong(task4) or cube_mistake(task4)


def springs_wrong(task4):
    """Why the springs the cube is built from are wrong, or None where grid_springs, run on
    its own, is right: where it is wrong, the neighbour_offsets it uses, where that is
    wrong too."""
    wrong = grid_springs_wrong(task4)
    return wrong and (offsets_wrong(task4) or wrong)


@functools.lru_cache(maxsize=16)
def grid_springs_wrong(task4):
    """Why the student's grid_springs of a 2 × 2 × 3 grid with all neighbours is wrong, or
    None where its springs and rest lengths are the engine's."""
    expected, body = engine_pairs((2, 2, 3), (1, 2, 3))
    try:
        springs, rest = student_springs(task4, (2, 2, 3), 1.0, (1, 2, 3))
    except Exception as error:
        return f"your grid_springs fails ({type(error).__name__}), and the cube is built with it"
    lengths = {frozenset(p): r for p, r in zip(springs.tolist(), rest.tolist())}
    wrong_rest = any(
        not np.isclose(lengths.get(frozenset(p), -1.0), r)
        for p, r in zip(
            zip(body.edges().a.tolist(), body.edges().b.tolist()), body.edges().rest_lengths
        )
    )
    if len(springs) != len(expected) or set(lengths) != expected or wrong_rest:
        return "your grid_springs is wrong (see its checks), and the cube is built with it"
    return None


def missing_and_extra(springs, expected):
    found = [frozenset(p) for p in springs.tolist()]
    return expected - set(found), set(found) - expected, len(found) - len(set(found))


@pytest.mark.points(2)
def test_neighbour_offsets_26(task4):
    """6 axis, 12 face-diagonal and 8 body-diagonal neighbours, each offset once, both signs."""
    for wanted, count in (((1,), 6), ((2,), 12), ((3,), 8), ((1, 2, 3), 26)):
        offsets = student_offsets(task4, wanted)
        expect(
            offsets.ndim == 2 and offsets.shape[1:] == (3,),
            saw=f"neighbour_offsets({wanted}) has shape {offsets.shape}, expected (M, 3)",
            cause=springs_mistake(task4)
            or "no offsets at all: none of squared length "
            f"{' or '.join(map(str, wanted))} was kept (e.g. a test that leaves out the body "
            "diagonals)"
            if offsets.size == 0
            else "",
        )
        unique = {tuple(o) for o in offsets.astype(int).tolist()}
        lengths = sorted({int(np.sum(np.square(o))) for o in unique})
        if 0 in lengths:
            cause = "the zero offset (the particle itself) is included"
        elif lengths != sorted(wanted):
            cause = f"offsets of squared lengths {lengths}, not the {sorted(wanted)} asked for"
        elif len(unique) * 2 == count:
            cause = "only one of o and -o (both directions are neighbours)"
        else:
            cause = "offsets listed twice, or some of them missing"
        cause = springs_mistake(task4) or cause
        expect(
            len(offsets) == len(unique) == count and lengths == sorted(wanted),
            saw=f"neighbour_offsets({wanted}) gives {len(offsets)} offsets ({len(unique)} "
            f"different) of squared lengths {lengths}; an interior particle has {count} such "
            "neighbours",
            cause=cause,
        )
        expect(
            all(tuple(-np.array(o)) in unique for o in unique),
            saw=f"neighbour_offsets({wanted}) has an offset without its opposite",
            cause="a neighbour in one direction is a neighbour in the other too",
        )


@pytest.mark.points(3)
def test_grid_springs_each_pair_once(task4):
    """On a 3 × 4 × 5 grid the springs are exactly the engine's: none missing, none twice."""
    for neighbours in ((1,), (2,), (3,), (1, 2, 3)):
        springs, _ = student_springs(task4, SHAPE, 0.1, neighbours)
        expected, _ = engine_pairs(SHAPE, neighbours)
        missing, extra, repeated = missing_and_extra(springs, expected)
        kinds = "+".join(KINDS[n] for n in neighbours)
        example = example_pair(springs, missing, extra)
        expect(
            not missing and not extra and repeated == 0,
            saw=f"for {kinds} springs of a {SHAPE} grid you give {len(springs)} springs, "
            f"{len(expected)} expected: {len(missing)} missing, {len(extra)} that are not "
            f"neighbour pairs, {repeated} listed twice (e.g. particles {example})",
            cause=springs_mistake(task4)
            or every_kind_cause(springs, neighbours)
            or pairs_cause(missing, extra, repeated, len(springs), len(expected)),
        )


def example_pair(springs, missing, extra):
    """One pair of particles that is wrong: missing, else not neighbours, else listed twice."""
    wrong = missing or extra
    if not wrong:
        seen, wrong = set(), set()
        for pair in map(frozenset, springs.tolist()):
            (wrong if pair in seen else seen).add(pair)
    return sorted(tuple(sorted(p)) for p in wrong)[0] if wrong else None


def every_kind_cause(springs, neighbours):
    """The cause if ``springs`` are those of all kinds, whatever ``neighbours`` asked for."""
    every, _ = engine_pairs(SHAPE, (1, 2, 3))
    given = {frozenset(p) for p in springs.tolist()}
    if tuple(neighbours) != (1, 2, 3) and given == every:
        return EVERY_KIND
    return None


def pairs_cause(missing, extra, repeated, given, expected):
    """The usual cause of a wrong list of grid springs."""
    if repeated or (given == 2 * expected and not missing):
        return TWICE
    if missing and not extra:
        return AT_THE_BORDER
    if missing and extra and given == expected:
        return "C order mixed up: particle (i, j, k) is row (i·ny + j)·nz + k"
    return "neighbours across the border wrapped around, or offsets of the wrong kind"


@pytest.mark.points(2)
def test_rest_lengths_unstressed(task4):
    """Rest lengths are the distances at rest (h, h√2, h√3): the grid at rest feels no force."""
    spacing = 0.1
    springs, rest = student_springs(task4, SHAPE, spacing, (1, 2, 3))
    positions = oracles.template_positions(SHAPE, spacing, (0.0, 0.0, 0.0)).reshape(-1, 3)
    expected, _ = engine_pairs(SHAPE, (1, 2, 3))
    to_itself = int(np.sum(springs[:, 0] == springs[:, 1]))
    expect(
        len(springs) == len(expected) and to_itself == 0,
        saw=f"grid_springs gives {len(springs)} springs where the {SHAPE} grid has "
        f"{len(expected)}"
        + (
            f", {to_itself} of them joining a particle to itself (a spring without length is "
            "unstressed trivially)"
            if to_itself
            else ""
        )
        + ": the rest lengths are judged on the grid's springs, so this earns no point",
        cause=springs_mistake(task4)
        or "springs missing, listed twice, or spring ends left at zero",
    )
    expect(
        np.all((springs >= 0) & (springs < len(positions))),
        saw=f"spring ends outside 0 .. {len(positions) - 1}",
        cause="indices computed for another grid shape",
    )
    distance = np.linalg.norm(positions[springs[:, 0]] - positions[springs[:, 1]], axis=1)
    worst = int(np.argmax(np.abs(rest - distance)))
    stiffness = 0.5
    expect(
        np.allclose(rest, distance, rtol=1e-12),
        saw=f"spring {worst} joins particles {springs[worst].tolist()} at distance "
        f"{num(distance[worst])} but has rest length {num(rest[worst])}: the body at rest is "
        f"pre-stressed (with k = {stiffness} that spring pulls or pushes with "
        f"{num(stiffness * abs(rest[worst] - distance[worst]))})",
        cause=springs_mistake(task4) or rest_length_cause(rest, distance, spacing),
    )


def rest_length_cause(rest, distance, spacing):
    """The usual cause of rest lengths that differ from the distances at rest."""
    scale = rest / distance
    if np.allclose(scale, scale[0]) and not np.isclose(scale[0], 1.0 / spacing):
        return (
            f"rest lengths {num(scale[0])}× the distances, for another spacing: not "
            f"spacing·√(squared length) with the given spacing {spacing}"
        )
    return (
        "rest lengths in grid units (1, √2, √3) instead of times the spacing, or the same "
        "rest length for every kind of spring"
    )


@pytest.mark.points(3)
def test_rotated_cube_holds_its_shape(task4):
    """Tilted 45° about z, a cube with 1, √2, √3 springs stands; with axis springs only it folds."""
    axis, angle = (0.0, 0.0, 1.0), 45.0
    held = cube_ratio(task4, angle, axis, (1, 2, 3))
    expect(
        held > 0.9,
        saw=f"with 26 neighbours, tilted {angle}° about z, the cube kept {percent(held)} of its "
        "thickness; the diagonal springs give it the shear stiffness to stand",
        cause=lambda: (
            springs_at_fault(task4)
            or "missing diagonal springs or wrong rest lengths, or a different experiment"
        ),
    )
    folded = cube_ratio(task4, angle, axis, (1,))
    expect(
        folded < 0.3,
        saw=f"with axis springs only the tilted cube kept {percent(folded)} of its thickness; "
        "it has no shear stiffness and should fold flat",
        cause=lambda: springs_at_fault(task4) or "drop_rotated_cube ignores squared_distances",
    )


@pytest.mark.points(1)
def test_step_cost_reports_springs_and_time(task4, own_numbers):
    """step_cost gives the number of springs of the n³ grid and a plausible time per step."""
    n = own_numbers.cost_size
    for neighbours in ((1,), (1, 2, 3)):
        springs, seconds = returned(task4.step_cost(n, neighbours, 5), "step_cost")
        expected = oracles.grid_body((n, n, n), 1.0, 1.0, neighbours).n_springs
        expect(
            springs == expected,
            saw=f"step_cost({n}, {neighbours}) counts {springs} springs, a {n}³ grid has "
            f"{expected}",
            cause=springs_mistake(task4)
            or (
                "springs counted twice"
                if springs == 2 * expected
                else "the wrong neighbours, or a grid other than n³ (is n ignored?)"
            ),
        )
        expect(
            math.isfinite(seconds) and 0 < seconds < 1.0,
            saw=f"step_cost({n}, {neighbours}) reports {num(seconds)} s per step",
            cause="the total time not divided by the number of steps, or a wrong clock",
        )
    springs, _ = task4.step_cost(3, (1,), 1)
    expect(
        springs == 54,
        saw=f"step_cost(3, (1,)) counts {springs} springs, a 3³ grid has 54 axis springs",
        cause="the size n is ignored: build the n³ grid",
    )
    # A run's set-up (its first and last frames) costs several compiled steps of this grid,
    # so only many steps make a total time stand out: with 60, a total was 6.1 times the
    # total of 3 steps, at the threshold; with 200 it is 20-30 times, a time per step < 1.
    few = float(task4.step_cost(10, (1, 2, 3), 3)[1])
    many = float(task4.step_cost(10, (1, 2, 3), 200)[1])
    expect(
        many < 6 * few,
        saw=f"step_cost reports {num(few)} s per step for 3 steps but {num(many)} s per step "
        "for 200 steps of the same grid: the time grows with the number of steps",
        cause="the total time of all steps reported instead of the time per step (divide by steps)",
    )
