"""The Warp backend's kernels: `msdlab.equations` as Warp functions, and the passes that
apply them, for one precision.

Warp compiles its own subset of Python, statically typed, in which a bare ``2.0`` is a
float32: each equation is written here once more as a ``wp.func`` of the precision's
scalar (``wp.float64`` by default), with the same operations in the same order as
`msdlab.equations`, so that on Warp's CPU device they give the numpy kernel's bits. The
functions and kernels are made per precision by `Kernels` (closures over the scalar
type), in a Warp module of their own per precision; Warp compiles that module on its first
launch and keeps it in its kernel cache (``wp.config.kernel_cache_dir``).

The passes, one thread per particle unless said otherwise:

- `gather_lattice`, `gather_edges`: each particle sums the forces of its springs (eq. 1.1
  with eq. 1.2 and the dashpot) into its own row (``add``: added to what it holds), no
  atomics, in a fixed order: a lattice
  (the springs of `Body.grid`) by neighbour offset, an edge list by the springs of each
  particle in the body's order (`Incidence`). A spring's force is computed at both ends
  (f_b = -f_a exactly). The end a of each spring adds its stretch |d|/l to the step's
  largest and its dashpot's power c ṡ² to the step's sum.
- `energy_lattice`, `energy_edges`: Σ ½ k (|d| - l)², each spring once.
- `finite_rows`, `damping_rows`, `clamp_rows`: the host contract's checks and sums over
  given states.
- the particle pass of an integrator's update (`backends.warp.update`) calls
  `particle_step`: a = (F + m·g)/m, 0 for fixed particles, the update, pinning, the
  ground, and the step's sums.

The step's sums (`SUMS`) are added with atomics into bins, particle i into bin i mod B
(one bin on the CPU device; on a GPU, enough that threads seldom wait on the same
address), and `reduce_sums` adds the bins up in order into one small array, clearing
them: on the CPU device in the particles' order, on a GPU in no fixed order within a bin
(the sums then agree to rounding).
"""

from dataclasses import dataclass
from typing import Any

import warp as wp

# The step's scalars, in one array read back once a step: the largest stretch |d|/l, the
# dashpots' power (W) at the start, the integrator's damping work (J), the energy the
# ground removed (J), and the number of coordinates that are not finite numbers.
SUMS = ("stretch", "power", "damping", "ground", "not_finite")
STRETCH, POWER, DAMPING, GROUND, NOT_FINITE = range(len(SUMS))

# Options of the kernels' Warp modules: no autodiff (half the code to compile), and no
# fused multiply-adds, which round once where numpy rounds twice.
MODULE_OPTIONS = {"enable_backward": False, "fuse_fp": False}


def module_name(scalar: type) -> str:
    """The Warp module of the kernels of precision ``scalar``."""
    return f"msdlab_{scalar.__name__}"


def equations(scalar: type, module: str) -> dict[str, Any]:
    """`msdlab.equations`' spring terms, a particle's acceleration and the work of the
    damping's kick, as Warp functions of ``scalar``."""

    @wp.func(module=module)
    def spring_state(k: scalar, rest: scalar, c: scalar, d: Any, w: Any):
        """`equations.spring_state`: |d|, the divisor, ṡ = w·n and |f_a|/|d|."""
        length = wp.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
        safe = length
        if length == scalar(0.0):
            safe = scalar(1.0)
        rate = (w[0] * d[0] + w[1] * d[1] + w[2] * d[2]) / safe
        tension = k * (rest - length) - c * rate
        return length, safe, rate, tension / safe

    @wp.func(module=module)
    def acceleration(force: scalar, mass: scalar, free: scalar) -> scalar:
        """`equations.acceleration`: F/m for a free particle, 0 for a fixed one."""
        return force * (free / mass)

    @wp.func(module=module)
    def damping_kick_work(mass: scalar, factor: scalar, before: scalar, after: scalar) -> scalar:
        """`equations.damping_kick_work`: the work of the kick (factor - 1)·v_before."""
        return scalar(0.5) * mass * ((factor - scalar(1.0)) * before) * (before + after)

    return {
        "spring_state": spring_state,
        "acceleration": acceleration,
        "damping_kick_work": damping_kick_work,
    }


def ground_function(scalar: type, module: str) -> Any:
    """`equations.ground_contact` as a Warp function of ``scalar``."""
    vector = wp.types.vector(3, scalar)

    @wp.func(module=module)
    def ground_contact(
        mass: scalar,
        position: vector,
        above: scalar,
        velocity: vector,
        start: vector,
        start_velocity: vector,
        n: vector,
        height: scalar,
        dt: scalar,
        keep: scalar,
    ):
        """`equations.ground_contact`: the particle on the plane, its velocity, the energy."""
        depth = height - above
        put = vector(
            position[0] + depth * n[0], position[1] + depth * n[1], position[2] + depth * n[2]
        )
        landing = velocity[0] * n[0] + velocity[1] * n[1] + velocity[2] * n[2]
        moved = (put[0] - start[0]) * n[0] + (put[1] - start[1]) * n[1] + (put[2] - start[2]) * n[2]
        before = start_velocity[0] * n[0] + start_velocity[1] * n[1] + start_velocity[2] * n[2]
        t = vector(
            velocity[0] - landing * n[0], velocity[1] - landing * n[1], velocity[2] - landing * n[2]
        )
        normal_speed = moved / dt
        work = scalar(0.5) * mass * (normal_speed - landing) * (before + normal_speed)
        tangential = t[0] * t[0] + t[1] * t[1] + t[2] * t[2]
        removed = scalar(0.5) * (scalar(1.0) - keep * keep) * mass * tangential - work
        speed = vector(
            keep * t[0] + normal_speed * n[0],
            keep * t[1] + normal_speed * n[1],
            keep * t[2] + normal_speed * n[2],
        )
        return put, speed, removed

    return ground_contact


def spring_terms(scalar: type, module: str, spring_state: Any) -> Any:
    """The Warp function that reads one spring i-j from the state: its terms
    (`equations.spring_state`) and its vector d = x_i - x_j."""
    vector = wp.types.vector(3, scalar)

    @wp.func(module=module)
    def terms(
        x: wp.array2d(dtype=scalar),
        v: wp.array2d(dtype=scalar),
        i: int,
        j: int,
        k: scalar,
        rest: scalar,
        c: scalar,
    ):
        """|d|, ṡ and |f|/|d| of the spring from particle j to particle i, and d."""
        d2 = scalar(0.0)  # the third coordinate, 0 in 2-D
        w0 = scalar(0.0)
        w1 = scalar(0.0)
        w2 = scalar(0.0)
        if x.shape[1] == 3:
            d2 = x[i, 2] - x[j, 2]
        if c != scalar(0.0):  # the velocities are read only for a dashpot
            w0 = v[i, 0] - v[j, 0]
            w1 = v[i, 1] - v[j, 1]
            if x.shape[1] == 3:
                w2 = v[i, 2] - v[j, 2]
        d = vector(x[i, 0] - x[j, 0], x[i, 1] - x[j, 1], d2)
        length, _safe, rate, scale = spring_state(k, rest, c, d, vector(w0, w1, w2))
        return length, rate, scale, d

    return terms


def lattice_neighbour(module: str) -> Any:
    """The Warp function giving the neighbour of particle i along ± an offset of a grid."""

    @wp.func(module=module)
    def neighbour(i: int, shape: wp.vec3i, offsets: wp.array2d(dtype=wp.int32), m: int, sign: int):
        """The index of the particle at i's grid coordinates + sign·offsets[m], -1 if none."""
        c0 = i // (shape[1] * shape[2]) + sign * offsets[m, 0]
        c1 = (i // shape[2]) % shape[1] + sign * offsets[m, 1]
        c2 = i % shape[2] + sign * offsets[m, 2]
        inside = c0 >= 0 and c0 < shape[0] and c1 >= 0 and c1 < shape[1]
        if inside and c2 >= 0 and c2 < shape[2]:
            return (c0 * shape[1] + c1) * shape[2] + c2
        return -1

    return neighbour


@dataclass(frozen=True)
class Kernels:
    """The Warp kernels of one precision ``scalar`` (``wp.float64`` or ``wp.float32``), and
    the Warp functions an update's particle pass calls (``functions``)."""

    scalar: type
    functions: dict[str, Any]
    gather_lattice: Any
    gather_edges: Any
    energy_lattice: Any
    energy_edges: Any
    finite_rows: Any
    damping_rows: Any
    clamp_rows: Any
    reduce_sums: Any

    @classmethod
    def of(cls, scalar: type) -> "Kernels":
        """The kernels of ``scalar``, made once per process (`_KERNELS`)."""
        if scalar not in _KERNELS:
            module = module_name(scalar)
            wp.set_module_options(MODULE_OPTIONS, wp.get_module(module))
            functions = equations(scalar, module)
            terms = spring_terms(scalar, module, functions["spring_state"])
            neighbour = lattice_neighbour(module)
            ground = ground_function(scalar, module)
            functions["clamp"] = clamp_particle(scalar, module, ground)
            functions["particle_acceleration"] = particle_acceleration(scalar, module, functions)
            _KERNELS[scalar] = cls(
                scalar,
                functions,
                gather_lattice_kernel(scalar, module, terms, neighbour),
                gather_edges_kernel(scalar, module, terms),
                energy_lattice_kernel(scalar, module, terms, neighbour),
                energy_edges_kernel(scalar, module, terms),
                finite_kernel(scalar, module),
                damping_kernel(scalar, module, functions["damping_kick_work"]),
                clamp_kernel(scalar, module, functions["clamp"]),
                reduce_kernel(scalar, module),
            )
        return _KERNELS[scalar]


_KERNELS: dict[type, Kernels] = {}


def gather_lattice_kernel(scalar: type, module: str, terms: Any, neighbour: Any) -> Any:
    """The lattice's forces by offset: each particle gathers its springs (`gather_lattice`)."""
    vector = wp.types.vector(3, scalar)

    @wp.kernel(module=module)
    def gather_lattice(
        x: wp.array2d(dtype=scalar),
        v: wp.array2d(dtype=scalar),
        shape: wp.vec3i,
        offsets: wp.array2d(dtype=wp.int32),
        stiffness: wp.array(dtype=scalar),
        rest: wp.array(dtype=scalar),
        damping: wp.array(dtype=scalar),
        add: int,
        forces: wp.array2d(dtype=scalar),
        bins: wp.array2d(dtype=scalar),
    ):
        i = wp.tid()
        f = vector()
        peak = scalar(0.0)
        power = scalar(0.0)
        for m in range(offsets.shape[0]):
            for side in range(2):
                sign = 1 - 2 * side  # +offset: i is the spring's end a
                j = neighbour(i, shape, offsets, m, sign)
                if j >= 0:
                    length, rate, scale, d = terms(x, v, i, j, stiffness[m], rest[m], damping[m])
                    f = f + scale * d
                    if sign == 1:
                        peak = wp.max(peak, length / rest[m])
                        power += damping[m] * (rate * rate)
        for q in range(x.shape[1]):  # added to what ``forces`` holds, or in its place
            forces[i, q] = f[q] + (forces[i, q] if add != 0 else scalar(0.0))
        wp.atomic_max(bins, i % bins.shape[0], STRETCH, peak)
        if power != scalar(0.0):
            wp.atomic_add(bins, i % bins.shape[0], POWER, power)

    return gather_lattice


def gather_edges_kernel(scalar: type, module: str, terms: Any) -> Any:
    """An edge list's forces: each particle gathers its springs, listed by `Incidence`."""
    vector = wp.types.vector(3, scalar)

    @wp.kernel(module=module)
    def gather_edges(
        x: wp.array2d(dtype=scalar),
        v: wp.array2d(dtype=scalar),
        start: wp.array(dtype=wp.int32),
        other: wp.array(dtype=wp.int32),
        spring: wp.array(dtype=wp.int32),
        first: wp.array(dtype=wp.int32),
        stiffness: wp.array(dtype=scalar),
        rest: wp.array(dtype=scalar),
        damping: wp.array(dtype=scalar),
        add: int,
        forces: wp.array2d(dtype=scalar),
        bins: wp.array2d(dtype=scalar),
    ):
        i = wp.tid()
        f = vector()
        peak = scalar(0.0)
        power = scalar(0.0)
        for e in range(start[i], start[i + 1]):
            s = spring[e]
            length, rate, scale, d = terms(x, v, i, other[e], stiffness[s], rest[s], damping[s])
            f = f + scale * d
            if first[s] == i:
                peak = wp.max(peak, length / rest[s])
                power += damping[s] * (rate * rate)
        for q in range(x.shape[1]):  # added to what ``forces`` holds, or in its place
            forces[i, q] = f[q] + (forces[i, q] if add != 0 else scalar(0.0))
        wp.atomic_max(bins, i % bins.shape[0], STRETCH, peak)
        if power != scalar(0.0):
            wp.atomic_add(bins, i % bins.shape[0], POWER, power)

    return gather_edges


def energy_lattice_kernel(scalar: type, module: str, terms: Any, neighbour: Any) -> Any:
    """Σ ½ k (|d| - l)² of a lattice, each spring at its end a."""

    @wp.kernel(module=module)
    def energy_lattice(
        x: wp.array2d(dtype=scalar),
        shape: wp.vec3i,
        offsets: wp.array2d(dtype=wp.int32),
        stiffness: wp.array(dtype=scalar),
        rest: wp.array(dtype=scalar),
        total: wp.array(dtype=scalar),
    ):
        i = wp.tid()
        energy = scalar(0.0)
        for m in range(offsets.shape[0]):
            j = neighbour(i, shape, offsets, m, 1)
            if j >= 0:
                length, _rate, _scale, _d = terms(x, x, i, j, stiffness[m], rest[m], scalar(0.0))
                stretch = length - rest[m]
                energy += scalar(0.5) * stiffness[m] * (stretch * stretch)
        wp.atomic_add(total, 0, energy)

    return energy_lattice


def energy_edges_kernel(scalar: type, module: str, terms: Any) -> Any:
    """Σ ½ k (|d| - l)² of an edge list, one thread per spring."""

    @wp.kernel(module=module)
    def energy_edges(
        x: wp.array2d(dtype=scalar),
        a: wp.array(dtype=wp.int32),
        b: wp.array(dtype=wp.int32),
        stiffness: wp.array(dtype=scalar),
        rest: wp.array(dtype=scalar),
        total: wp.array(dtype=scalar),
    ):
        s = wp.tid()
        length, _rate, _scale, _d = terms(x, x, a[s], b[s], stiffness[s], rest[s], scalar(0.0))
        stretch = length - rest[s]
        wp.atomic_add(total, 0, scalar(0.5) * stiffness[s] * (stretch * stretch))

    return energy_edges


def finite_kernel(scalar: type, module: str) -> Any:
    """Counts the coordinates of (x, v) that are not finite numbers."""

    @wp.kernel(module=module)
    def finite_rows(
        x: wp.array2d(dtype=scalar), v: wp.array2d(dtype=scalar), bins: wp.array2d(dtype=scalar)
    ):
        i = wp.tid()
        for q in range(x.shape[1]):
            if not (wp.isfinite(x[i, q]) and wp.isfinite(v[i, q])):
                wp.atomic_add(bins, i % bins.shape[0], NOT_FINITE, scalar(1.0))

    return finite_rows


def damping_kernel(scalar: type, module: str, damping_kick_work: Any) -> Any:
    """`equations.damping_work` over the particles."""

    @wp.kernel(module=module)
    def damping_rows(
        masses: wp.array(dtype=scalar),
        before: wp.array2d(dtype=scalar),
        after: wp.array2d(dtype=scalar),
        factor: scalar,
        bins: wp.array2d(dtype=scalar),
    ):
        i = wp.tid()
        work = scalar(0.0)
        for q in range(before.shape[1]):
            work += damping_kick_work(masses[i], factor, before[i, q], after[i, q])
        wp.atomic_add(bins, i % bins.shape[0], DAMPING, -work)

    return damping_rows


def clamp_particle(scalar: type, module: str, ground_contact: Any) -> Any:
    """The Warp function putting particle i back on the ground plane (`kernels.ground_clamp`)."""
    vector = wp.types.vector(3, scalar)

    @wp.func(module=module)
    def row(x: wp.array2d(dtype=scalar), i: int):
        """Row i of ``x`` as three coordinates, the third 0 in 2-D."""
        third = scalar(0.0)
        if x.shape[1] == 3:
            third = x[i, 2]
        return vector(x[i, 0], x[i, 1], third)

    @wp.func(module=module)
    def clamp(
        i: int,
        x: wp.array2d(dtype=scalar),
        v: wp.array2d(dtype=scalar),
        x_old: wp.array2d(dtype=scalar),
        v_old: wp.array2d(dtype=scalar),
        mass: scalar,
        plane: wp.types.vector(4, scalar),
        dt: scalar,
        keep: scalar,
    ) -> scalar:
        """Clamp particle i (free, below the plane n·x = h, ``plane`` = (n, h)) in place;
        the energy (J) the ground removed."""
        dim = x.shape[1]
        above = scalar(0.0)
        for q in range(dim):
            above += x[i, q] * plane[q]
        if not (above < plane[3]):
            return scalar(0.0)
        n = vector(plane[0], plane[1], plane[2])
        put, speed, lost = ground_contact(
            mass, row(x, i), above, row(v, i), row(x_old, i), row(v_old, i), n, plane[3], dt, keep
        )
        for q in range(dim):
            x[i, q] = put[q]
            v[i, q] = speed[q]
        return lost

    return clamp


def clamp_kernel(scalar: type, module: str, clamp: Any) -> Any:
    """The ground's clamp of the host contract (`SpringKernel.ground_clamp`)."""

    @wp.kernel(module=module)
    def clamp_rows(
        x: wp.array2d(dtype=scalar),
        v: wp.array2d(dtype=scalar),
        x_old: wp.array2d(dtype=scalar),
        v_old: wp.array2d(dtype=scalar),
        masses: wp.array(dtype=scalar),
        free: wp.array(dtype=scalar),
        plane: wp.types.vector(4, scalar),
        dt: scalar,
        keep: scalar,
        bins: wp.array2d(dtype=scalar),
    ):
        i = wp.tid()
        if free[i] != scalar(0.0):
            wp.atomic_add(
                bins,
                i % bins.shape[0],
                GROUND,
                clamp(i, x, v, x_old, v_old, masses[i], plane, dt, keep),
            )

    return clamp_rows


def particle_acceleration(scalar: type, module: str, functions: dict[str, Any]) -> Any:
    """The Warp function of a step's particle pass around an integrator's update: the
    acceleration of coordinate q of particle i, a = (F + m·g)/m, 0 if fixed, F the springs'
    forces plus the other forces (``others``, an empty array if none)."""
    acceleration = functions["acceleration"]

    @wp.func(module=module)
    def acceleration_of(
        i: int,
        q: int,
        forces: wp.array2d(dtype=scalar),
        others: wp.array2d(dtype=scalar),
        masses: wp.array(dtype=scalar),
        free: wp.array(dtype=scalar),
        field: wp.types.vector(3, scalar),
    ) -> scalar:
        """a_q of particle i (m/s²)."""
        total = forces[i, q]
        if others.shape[0] > 0:
            total = total + others[i, q]
        return acceleration(total + masses[i] * field[q], masses[i], free[i])

    return acceleration_of


def reduce_kernel(scalar: type, module: str) -> Any:
    """The step's sums from their bins (B, `SUMS`), one thread per sum: the bins added (the
    largest stretch: their largest) in order into ``sums``, and cleared for the next step."""

    @wp.kernel(module=module)
    def reduce_sums(bins: wp.array2d(dtype=scalar), sums: wp.array(dtype=scalar)):
        q = wp.tid()
        total = bins[0, q]
        bins[0, q] = scalar(0.0)
        for b in range(1, bins.shape[0]):
            total = wp.max(total, bins[b, q]) if q == STRETCH else total + bins[b, q]
            bins[b, q] = scalar(0.0)
        sums[q] = total

    return reduce_sums
