"""`WarpKernel`: the backend contract (`backends.contract.SpringKernel`) on NVIDIA Warp.

Beyond the contract, a device's own state: two buffers of positions and velocities, the
step's start (``state_0``) and its end (``state_1``), swapped after each step as Warp's
examples do. `load` copies the host's arrays there, unless they are those `state` copied
from there last, unedited; a whole step of an update integrator (`step`, or a frame of
them, `frame`) runs there: the springs' gather, then one particle pass doing a, the
update, the pinned particles, the ground and the ledger's sums, which come back in one copy
of five numbers (`kernels.SUMS`); `state` copies x and v to the host once per state asked
for (a recorded frame, the end of a call). A public step thus copies x and v once, to the
host, and a recorded frame too: the ledger's energies read the device's state.

The contract's methods take host arrays, as the numpy and numba backends do: they run
the same Warp kernels on the arrays copied to the device (or on the device's state, where
the arrays are that state's host copy) and copy the result back. A few springs
(``springs=``, a constraint's energy) and the Jacobians (implicit Euler's sparse solve runs
on the host) are the numpy kernel's, on the host.
"""

from __future__ import annotations

import types
import warnings
from collections.abc import Callable
from typing import NamedTuple

import numpy as np
import warp as wp

from ... import equations
from ...model.lattice import LatticeSprings
from ...model.springs import incidence
from ..contract import Advanced, Jacobians, SpringSums, Update
from ..layout import Layout
from ..numpy import NumpyKernel
from .kernels import DAMPING, GROUND, NOT_FINITE, POWER, STRETCH, SUMS, Kernels
from .update import MOST_COEFFICIENTS, NotCompiled, particle_pass

# Warp's banner and its lines about compiling modules are not a student's business: below
# warnings, Warp says nothing unless its settings were changed.
if wp.config.log_level == wp.LOG_INFO:
    wp.config.log_level = wp.LOG_WARNING

PRECISIONS = {"float64": wp.float64, "float32": wp.float32}
KEPT_LAUNCHES = 64  # recorded launches kept for replay (`WarpKernel._launch`)
NO_LAUNCH = types.SimpleNamespace(launch=lambda: None)  # a launch on no threads
# Bins of the step's sums on a GPU (`kernels.reduce_kernel`): particle i adds to bin i mod
# this, so few threads wait on one address, and one thread per sum adds them up (not tuned
# on a GPU yet).
GPU_BINS = 256


class StepSums(NamedTuple):
    """What a device step sends back (`kernels.SUMS`), one copy of five numbers."""

    stretch: float  # the largest |x_a - x_b| / l at the step's start
    power: float  # the dashpots' power (W) at the step's start
    damping: float  # the integrator's damping work (J) over the step
    ground: float  # the energy (J) the ground removed in the step
    finite: bool  # whether the new state is all finite numbers


class Ground(NamedTuple):
    """A ground plane for a device step: unit ``normal`` (d,), ``height`` (m), ``friction``."""

    normal: np.ndarray
    height: float
    friction: float


def default_device() -> str:
    """Warp's CUDA device where there is one, else its CPU device."""
    return "cuda" if wp.get_cuda_device_count() > 0 else "cpu"


class WarpKernel:
    """The Warp backend: the state on ``device`` ("cuda", "cpu"; default `default_device`) in
    ``precision`` ("float64", the default, or "float32"), the step's sums added in ``bins``
    (default: 1 on the CPU device, `GPU_BINS` on a GPU)."""

    name = "warp"

    def __init__(
        self, device: str | None = None, precision: str = "float64", bins: int | None = None
    ) -> None:
        if precision not in PRECISIONS:
            raise ValueError(f"precision must be float64 or float32, got {precision!r}")
        self.device = wp.get_device(default_device() if device is None else device)
        self.kernels = Kernels.of(PRECISIONS[precision])
        self.dtype = np.float64 if precision == "float64" else np.float32
        self._state: list[wp.array] = []  # x and v of state_0, then of state_1
        self._host: tuple[np.ndarray, np.ndarray] | None = None  # what `state` handed out
        self._seen: list[np.ndarray] = []  # the state `state` copied them from (`_holds`)
        self._sums = wp.zeros(len(SUMS), dtype=self.kernels.scalar, device=self.device)
        bins = bins or (1 if self.device.is_cpu else GPU_BINS)
        self._bins = wp.zeros((bins, len(SUMS)), dtype=self.kernels.scalar, device=self.device)
        self._scratch: dict[str, wp.array] = {}
        self._topology: tuple[object, tuple] = (None, ())
        self._kept_particles: tuple[np.ndarray, ...] = ()  # `_particle_arrays`
        self._step_plans: dict[tuple, tuple[list, list]] = {}  # `_step_commands`
        self._frames: dict[tuple, tuple[object, wp.array]] = {}  # `frame`: graph, sums rows
        self._passes: dict[Callable, object] = {}  # the particle pass of each update
        self._coefficients = np.zeros(MOST_COEFFICIENTS)
        self._commands: dict[tuple, tuple[list, object]] = {}  # recorded launches (`_launch`)

    # ------------------------------------------------------------------ the state
    def load(self, x: np.ndarray, v: np.ndarray) -> None:
        """Step from ``x`` (m) and ``v`` (m/s), (N, d), copied to the device unless it holds
        them already (`_holds`: the arrays `state` handed out, which the body adopts, as they
        were; an edit in place between two steps is seen and copied)."""
        if self._holds(0, x) and self._holds(1, v):
            return
        if not self._state or self._state[0].shape != x.shape:
            self._state = [self._empty(x.shape) for _ in range(4)]
        self._state[0].assign(x.astype(self.dtype, copy=False))
        self._state[1].assign(v.astype(self.dtype, copy=False))
        self._host = None

    def state(self) -> tuple[np.ndarray, np.ndarray]:
        """The positions (m) and velocities (m/s) on the device, copied to the host once per
        state (float64 arrays no one else holds)."""
        if self._host is None:
            # on a GPU a copy, on Warp's CPU device the state's own memory
            self._seen = [array.numpy() for array in self._state[:2]]
            self._host = tuple(np.array(seen, dtype=np.float64) for seen in self._seen)
        return self._host

    def _holds(self, index: int, array: np.ndarray) -> bool:
        """Whether the device's state holds ``array`` as its positions (``index`` 0) or
        velocities (1): the state `state` copied to the host last is still the device's,
        and ``array`` equals it (compared on the host, nothing copied)."""
        return self._host is not None and np.array_equal(array, self._seen[index])

    def step(
        self,
        update: Update,
        layout: Layout,
        field: np.ndarray,
        dt: float,
        coefficients: tuple[float, ...],
        factor: float = 1.0,
        ground: tuple[np.ndarray, float, float] | None = None,
    ) -> StepSums | None:
        """One step of ``update`` on the device from the state there: the springs' pass, then
        a = (F + m·g)/m (g = ``field``, m/s²), the update, the fixed particles kept in place at
        rest, the clamp to the ``ground`` plane (normal, height, friction) and the work of the
        integrator's velocity ``factor`` (`equations.damping_work`); the two states swapped.
        None, with nothing stepped, for an update Warp cannot compile."""
        commands = self._step_commands(update, layout, field, dt, coefficients, factor, ground)
        if commands is None:
            return None
        for command in commands[0]:
            command.launch()
        self._state = [*self._state[2:], *self._state[:2]]
        self._host = None
        sums = self._sums.numpy()
        return StepSums(
            float(sums[STRETCH]), float(sums[POWER]), float(sums[DAMPING]),
            float(sums[GROUND]), not sums[NOT_FINITE],
        )  # fmt: skip

    def _step_commands(
        self,
        update: Update,
        layout: Layout,
        field: np.ndarray,
        dt: float,
        coefficients: tuple[float, ...],
        factor: float,
        ground: tuple[np.ndarray, float, float] | None,
    ) -> tuple[list, list] | None:
        """The launches of a step from the state there now (the springs' gather, the update's
        particle pass) and the arrays they use, recorded once for each state buffer and
        each plan (the body's springs, the step's numbers); None for an update Warp cannot
        compile. The masses and pins are copied again after a `load`, in place."""
        plane = None if ground is None else (*ground[0], *ground[1:])
        x, v, x_new, v_new = self._state
        plan = (update, layout, id(x), dt, factor, plane)
        plan += (tuple(field), tuple(coefficients))
        masses, free = self._particle_arrays(layout)
        kept = self._step_plans.get(plan)
        if kept is None:
            try:
                particle_step = self._particle_pass(update)
            except NotCompiled:
                return None
            state = (x, v, self._scratch_array("forces", x.shape), None, x_new, v_new)
            gather = self._gather(layout, x, v, run=False)[1]
            numbers = (field, dt, coefficients, factor, None if ground is None else Ground(*ground))
            particles = self._particles(particle_step, layout, state, *numbers, run=False)
            if len(self._step_plans) >= KEPT_LAUNCHES:
                self._step_plans.clear()
            sums = [self._bins, self._sums]
            reduce = self._launch(self.kernels.reduce_sums, len(SUMS), sums, run=False)
            kept = self._step_plans[plan] = ([gather, particles, reduce], [*state, masses, free])
        return kept

    def frame(
        self,
        steps: int,
        update: Update,
        layout: Layout,
        field: np.ndarray,
        dt: float,
        coefficients: tuple[float, ...],
        factor: float = 1.0,
        ground: tuple[np.ndarray, float, float] | None = None,
    ) -> np.ndarray | None:
        """``steps`` whole steps (`step`) replayed as one captured sequence of launches (a CUDA
        graph on a GPU, Warp's recorded launches on its CPU device), each step's sums in a row
        of their own, read back once: an array (steps, 5) of `kernels.SUMS`. Captured once per
        plan and starting state buffer; None, with nothing stepped, if the update cannot
        compile. A frame checks nothing between its steps: the caller reads the rows."""
        plan = (steps, update, layout, id(self._state[0]), dt, factor, repr(ground))
        plan += (tuple(field), tuple(coefficients))
        if plan not in self._frames:
            arguments = (update, layout, field, dt, coefficients, factor, ground)
            for _ in range(2):  # both states' launches recorded (and compiled) before capture
                if self._step_commands(*arguments) is None:
                    return None
                self._state = [*self._state[2:], *self._state[:2]]
            self._frames.clear()  # one frame plan kept: a graph holds device memory
            self._frames[plan] = self._capture(steps, arguments)
        graph, rows = self._frames[plan]
        for name, array in zip(("x_start", "v_start"), self._state[:2]):
            wp.copy(self._scratch_array(name, array.shape), array)  # for `undo_frame`
        wp.capture_launch(graph)
        if steps % 2:
            self._state = [*self._state[2:], *self._state[:2]]
        self._host = None
        return rows.numpy().astype(np.float64)

    def undo_frame(self) -> None:
        """Back to the state the last `frame` started from (one of its steps blew up)."""
        self._state[0].assign(self._scratch["x_start"])
        self._state[1].assign(self._scratch["v_start"])
        self._host = None

    def _capture(self, steps: int, arguments: tuple) -> tuple[object, wp.array]:
        """The launches of ``steps`` steps captured as one graph, step s adding its sums to row
        s of the rows returned (`kernels.reduce_kernel` writes it); the state buffers as they
        were before."""
        rows = wp.zeros((steps, len(SUMS)), dtype=self.kernels.scalar, device=self.device)
        start = self._state
        with wp.ScopedCapture(device=self.device) as capture:
            for row in range(steps):
                *passes, reduce = self._step_commands(*arguments)[0]
                for command in passes:
                    command.launch()
                reduce.set_param_by_name("sums", rows[row])
                reduce.launch()
                reduce.set_param_by_name("sums", self._sums)
                self._state = [*self._state[2:], *self._state[:2]]
        self._state = start
        return capture.graph, rows

    def undo_step(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Back to the state the last `step` started from (it diverged); the positions there
        and the new positions and velocities it reached, on the host, for the diagnosis."""
        reached = [self._read(array) for array in self._state[:2]]
        self._state = [*self._state[2:], *self._state[:2]]
        self._host = None
        return self._read(self._state[0]), *reached

    # ------------------------------------------------------------------ the host contract
    def spring_forces(
        self,
        layout: Layout,
        x: np.ndarray,
        v: np.ndarray,
        out: np.ndarray,
        springs: np.ndarray | None = None,
    ) -> SpringSums:
        """Add the spring and dashpot forces (N) to ``out`` (N, d): the device's gather, with the
        largest stretch and the dashpots' power (W); some ``springs`` on the host (numpy)."""
        if springs is not None:
            return self._reference.spring_forces(layout, x, v, out, springs)
        forces = self._gather(layout, *self._on_device(x, v), start=out)[0]
        out[...] = self._read(forces)
        sums = self._read_sums()
        return SpringSums(float(sums[STRETCH]), float(sums[POWER]))

    def elastic_energy(
        self, layout: Layout, x: np.ndarray, springs: np.ndarray | None = None
    ) -> float:
        """Energy (J) stored in the springs, on the device; some ``springs`` on the host."""
        if springs is not None:
            return self._reference.elastic_energy(layout, x, springs)
        total = self._scratch_array("energy", (1,))
        total.zero_()
        positions = self._device_array(0, "x", x)
        kernel, dim, arguments = self._springs(layout)[1]
        self._launch(kernel, dim, [positions, *arguments, total])
        return float(total.numpy()[0])

    def jacobians(self, layout: Layout, x: np.ndarray) -> Jacobians:
        """∂F/∂x and ∂F/∂v of the springs on ``layout.pattern``: the numpy kernel's, on the
        host, where the sparse solve of implicit Euler runs."""
        return self._reference.jacobians(layout, x)

    def finite(self, x: np.ndarray, v: np.ndarray) -> bool:
        """Whether every position and velocity (N, d) is a finite number (on the device)."""
        wp.launch(
            self.kernels.finite_rows, len(x), [*self._on_device(x, v), self._bins],
            device=self.device,
        )  # fmt: skip
        return not self._read_sums()[NOT_FINITE]

    def advance(
        self,
        update: Update,
        layout: Layout,
        x: np.ndarray,
        v: np.ndarray,
        field: np.ndarray,
        dt: float,
        coefficients: tuple[float, ...],
        forces: np.ndarray | None = None,
    ) -> Advanced:
        """``update(x, v, a, dt, *coefficients)`` with a = (F + m·g)/m (0 if fixed), F the
        spring forces plus ``forces`` (N, d) if given, g = ``field`` (d,) in m/s²: the gather
        and the update's particle pass on the device, the new state copied to the host. An
        update Warp cannot compile runs on the host, on whole arrays (it says so once)."""
        device_x, device_v = self._on_device(x, v)
        total = self._gather(layout, device_x, device_v)[0]
        try:
            particle_step = self._particle_pass(update)
        except NotCompiled:
            new = on_host(update, layout, self._read(total), forces, field, x, v, dt, coefficients)
            return Advanced(*new, *self._spring_sums())
        others = None if forces is None else self._upload("others", forces)
        x_new, v_new = self._scratch_array("x_new", x.shape), self._scratch_array("v_new", x.shape)
        state = (device_x, device_v, total, others, x_new, v_new)
        self._particles(particle_step, layout, state, field, dt, coefficients, 1.0, None, pin=False)
        return Advanced(self._read(x_new), self._read(v_new), *self._spring_sums())

    def damping_work(
        self, masses: np.ndarray, v_before: np.ndarray, v_after: np.ndarray, factor: float
    ) -> float:
        """`equations.damping_work` (J), summed on the device."""
        arrays = (self._upload("masses", masses), self._upload("v_before", v_before))
        arrays += (self._upload("v_after", v_after), self._scalar(factor), self._bins)
        self._launch(self.kernels.damping_rows, len(masses), list(arrays))
        return float(self._read_sums()[DAMPING])

    def ground_clamp(
        self,
        x: np.ndarray,
        v: np.ndarray,
        x_old: np.ndarray,
        v_old: np.ndarray,
        masses: np.ndarray,
        fixed: np.ndarray,
        normal: np.ndarray,
        height: float,
        dt: float,
        friction: float,
    ) -> float:
        """`interaction.Ground`'s clamp of ``x`` and ``v`` in place, on the device (the clamp
        of a device step, `kernels.clamp_particle`); the energy (J) the ground removed."""
        plane, keep = self._plane(Ground(normal, height, friction))
        device = [self._upload(name, array) for name, array in (("x_new", x), ("v_new", v))]
        arrays = [*device, self._upload("x", x_old), self._upload("v", v_old)]
        arrays += [self._upload("masses", masses), self._upload("free", (~fixed).astype(float))]
        arrays += [plane, self._scalar(dt), keep, self._bins]
        self._launch(self.kernels.clamp_rows, len(x), arrays)
        x[...], v[...] = (self._read(array) for array in device)
        return float(self._read_sums()[GROUND])

    # ------------------------------------------------------------------ the passes
    @property
    def _reference(self) -> NumpyKernel:
        """The numpy kernel, for what runs on the host (a few springs, the Jacobians)."""
        if "_numpy" not in vars(self):
            self._numpy = NumpyKernel()
        return self._numpy

    def _particle_pass(self, update: Update) -> object:
        """The compiled particle pass of ``update`` (`update.particle_pass`), made once; raises
        `NotCompiled` (and warns once) for an update Warp cannot compile."""
        if update not in self._passes:
            try:
                if not isinstance(update, types.FunctionType):
                    raise NotCompiled(method_reason(update))
                self._passes[update] = particle_pass(update, self.kernels, self.device)
            except NotCompiled as reason:
                self._passes[update] = reason
                warnings.warn(falls_back(update, reason), RuntimeWarning, stacklevel=4)
        kept = self._passes[update]
        if isinstance(kept, NotCompiled):
            raise kept
        return kept

    def _gather(
        self,
        layout: Layout,
        x: wp.array,
        v: wp.array,
        start: np.ndarray | None = None,
        run: bool = True,
    ) -> tuple[wp.array, object]:
        """The springs' forces (N) at (x, v) on the device, added to ``start`` (N, d) if given,
        with their largest stretch and power added to the sums; and the launch (not ``run``:
        only recorded, `_launch`)."""
        forces = self._scratch_array("forces", x.shape)
        if start is not None:
            forces.assign(start.astype(self.dtype, copy=False))
        kernel, arguments = self._springs(layout)[0]
        arguments = [x, v, *arguments, int(start is not None), forces, self._bins]
        return forces, self._launch(kernel, x.shape[0], arguments, run)

    def _particles(
        self,
        particle_step: object,
        layout: Layout,
        state: tuple,
        field: np.ndarray,
        dt: float,
        coefficients: tuple[float, ...],
        factor: float,
        ground: Ground | None,
        pin: bool = True,
        run: bool = True,
    ) -> object:
        """Launch ``particle_step`` on ``state`` (x, v, forces, others or None, x_new, v_new);
        the launch (not ``run``: only recorded, with coefficients of its own, `_launch`)."""
        x, v, forces, others, x_new, v_new = state
        masses, free = self._particle_arrays(layout)
        self._coefficients[: len(coefficients)] = coefficients
        padded = self._upload("c", self._coefficients) if run else self._table(self._coefficients)
        plane, keep = self._plane(ground, layout.dim)
        others = self._scratch_array("none", (0, 0)) if others is None else others
        arrays = [x, v, forces, others, masses, free, self._vector(field), self._scalar(dt)]
        arrays += [padded, int(pin), plane, keep, int(ground is not None), self._scalar(factor)]
        return self._launch(particle_step, len(x_new), [*arrays, x_new, v_new, self._bins], run)

    def _launch(self, kernel: object, threads: int, arguments: list, run: bool = True) -> object:
        """Launch ``kernel`` on ``threads`` threads: the first time with these arguments (the
        same arrays, equal values) through ``wp.launch``, after that by replaying the launch
        it recorded. Warp packs a launch's arguments in Python, tens of µs a launch; a step
        alternates between the same two states, so its launches repeat. Not ``run``: recorded
        only, and returned for the caller to launch."""
        if threads == 0:  # Warp records nothing for no threads
            return NO_LAUNCH
        if not run:  # recorded for the caller to replay
            return wp.launch(kernel, threads, arguments, device=self.device, record_cmd=True)
        key = (kernel, threads, *map(identity, arguments))
        kept = self._commands.get(key)
        if kept is None:
            if len(self._commands) >= KEPT_LAUNCHES:
                self._commands.clear()
            command = wp.launch(kernel, threads, arguments, device=self.device, record_cmd=True)
            kept = self._commands[key] = (arguments, command)  # its arrays kept: ids stay theirs
        kept[1].launch()
        return kept[1]

    def _read_sums(self) -> np.ndarray:
        """The sums (`kernels.SUMS`) of the passes since the last read, added up from their
        bins on the device (`kernels.reduce_kernel`) and copied to the host."""
        self._launch(self.kernels.reduce_sums, len(SUMS), [self._bins, self._sums])
        return self._sums.numpy()

    def _spring_sums(self) -> tuple[float, float]:
        """The largest stretch and the dashpots' power (W) of the last gather."""
        sums = self._read_sums()
        return float(sums[STRETCH]), float(sums[POWER])

    # ------------------------------------------------------------------ what is kept
    def _springs(self, layout: Layout) -> tuple[tuple, tuple]:
        """The springs of ``layout`` on the device, made for each new layout (each edit of
        the body): (gather kernel, its arguments), (energy kernel, its threads, arguments)."""
        if self._topology[0] is not layout:
            n = layout.n_particles
            if layout.lattice is not None:
                arrays = self._lattice_arrays(layout.lattice)
                energy = (self.kernels.energy_lattice, n, arrays[:4])
                passes = ((self.kernels.gather_lattice, arrays), energy)
            else:
                edges = layout.edges
                start, springs, partners = incidence(edges, n)
                ends = [self._indices(index) for index in (start, partners, springs, edges.a)]
                values = [self._table(value) for value in edges.values()]
                pair = [ends[3], self._indices(edges.b), *values[:2]]
                energy = (self.kernels.energy_edges, edges.count, pair)
                passes = ((self.kernels.gather_edges, [*ends, *values]), energy)
            self._topology = (layout, passes)
        return self._topology[1]

    def _lattice_arrays(self, lattice: LatticeSprings) -> list:
        """A lattice's grid shape, offsets (M, 3) and values per offset, on the device."""
        shape = (*lattice.shape, 1)[:3]
        offsets = np.zeros((len(lattice.offsets), 3), dtype=np.int32)
        offsets[:, : len(lattice.shape)] = lattice.offsets
        offsets = wp.array(offsets, dtype=wp.int32, device=self.device)
        return [wp.vec3i(*shape), offsets, *(self._table(value) for value in lattice.values())]

    def _particle_arrays(self, layout: Layout) -> tuple[wp.array, wp.array]:
        """The masses (kg) and 1 for free, 0 for fixed particles, on the device: copied again
        (in place) when the layout's differ from those copied last, as the body's arrays may
        be edited between steps (compared on the host with the copies kept)."""
        n = layout.n_particles
        if not self._kept_particles or len(self._kept_particles[0]) != n:
            unequal = (np.full(n, np.nan), np.zeros(n, dtype=bool))  # NaN: equal to no mass
            self._kept_particles = (*unequal, self._empty((n,)), self._empty((n,)))
        masses, fixed, device_masses, free = self._kept_particles
        if not (np.array_equal(layout.masses, masses) and np.array_equal(layout.fixed, fixed)):
            masses[:], fixed[:] = layout.masses, layout.fixed
            device_masses.assign(masses.astype(self.dtype))
            free.assign((~fixed).astype(self.dtype))
        return device_masses, free

    def _on_device(self, x: np.ndarray, v: np.ndarray) -> tuple[wp.array, wp.array]:
        """``x`` and ``v`` on the device: its state where it holds them (`_holds`), else
        copied to its scratch arrays."""
        return self._device_array(0, "x", x), self._device_array(1, "v", v)

    def _device_array(self, index: int, name: str, array: np.ndarray) -> wp.array:
        """``array`` on the device: the state's positions (``index`` 0) or velocities (1) where
        they are ``array`` (`_holds`), else ``array`` copied to the scratch array ``name``."""
        return self._state[index] if self._holds(index, array) else self._upload(name, array)

    def _upload(self, name: str, array: np.ndarray) -> wp.array:
        """``array`` copied into the device's scratch array ``name``."""
        scratch = self._scratch_array(name, array.shape)
        scratch.assign(np.ascontiguousarray(array, dtype=self.dtype))
        return scratch

    def _scratch_array(self, name: str, shape: tuple[int, ...]) -> wp.array:
        """The device's scratch array ``name`` of ``shape``, made again when it changes."""
        if name not in self._scratch or self._scratch[name].shape != tuple(shape):
            self._scratch[name] = self._empty(shape)
        return self._scratch[name]

    def _empty(self, shape: tuple[int, ...]) -> wp.array:
        return wp.zeros(shape, dtype=self.kernels.scalar, device=self.device)

    def _table(self, values: np.ndarray) -> wp.array:
        """Values (n,) on the device, in the backend's precision."""
        return wp.array(np.ascontiguousarray(values, dtype=self.dtype), device=self.device)

    def _indices(self, values: np.ndarray) -> wp.array:
        return wp.array(values.astype(np.int32), dtype=wp.int32, device=self.device)

    def _read(self, array: wp.array) -> np.ndarray:
        """A device array copied to a new float64 host array."""
        return np.array(array.numpy(), dtype=np.float64)

    def _scalar(self, value: float) -> object:
        return self.kernels.scalar(value)

    def _vector(self, values: np.ndarray) -> object:
        """A (d,) vector as Warp's 3-vector of the precision, the third 0 in 2-D."""
        return wp.types.vector(3, self.kernels.scalar)(*(*map(float, values), 0.0, 0.0)[:3])

    def _plane(self, ground: Ground | None, dim: int = 3) -> tuple[object, object]:
        """The plane (n, h) as Warp's 4-vector and the tangential factor 1 - friction."""
        plane = np.zeros(4)
        if ground is not None:
            plane[: len(ground.normal)] = ground.normal
            plane[3] = ground.height
        keep = 1.0 - (0.0 if ground is None else ground.friction)
        return wp.types.vector(4, self.kernels.scalar)(*plane), self._scalar(keep)


def identity(argument: object) -> object:
    """What tells a launch's ``argument`` from another: an array's identity, a value's text
    (exact for Warp's scalars and vectors)."""
    if isinstance(argument, wp.array):
        return id(argument)
    if isinstance(argument, (int, float)):
        return repr(argument)
    return tuple(map(repr, argument)) if hasattr(argument, "__len__") else repr(argument)


def on_host(
    update: Update,
    layout: Layout,
    springs: np.ndarray,
    forces: np.ndarray | None,
    field: np.ndarray,
    x: np.ndarray,
    v: np.ndarray,
    dt: float,
    coefficients: tuple[float, ...],
) -> tuple[np.ndarray, np.ndarray]:
    """``update`` on whole host arrays with a = (F + m·g)/m, F the ``springs``' forces plus
    the other ``forces``: for an update Warp cannot compile."""
    total = springs if forces is None else springs + forces
    masses, free = layout.masses[:, None], ~layout.fixed[:, None]
    return update(
        x, v, equations.acceleration(total + masses * field, masses, free), dt, *coefficients
    )


def method_reason(update: object) -> str:
    """Why an update that is not a plain function cannot compile, and the fix."""
    name = getattr(update, "__qualname__", type(update).__name__)
    return (
        f"{name} is a {type(update).__name__}, not a plain function; make it a @staticmethod "
        "(an update takes x, v, a, dt and coefficients, not self)"
    )


def falls_back(update: object, reason: NotCompiled) -> str:
    """The warning for an update that runs on the host: whose, why, and what it costs."""
    name = getattr(update, "__qualname__", type(update).__name__)
    code = getattr(update, "__code__", None)
    where = f" ({code.co_filename}, line {code.co_firstlineno})" if code is not None else ""
    return (
        f"Warp cannot compile the update {name}{where}: {reason}. It runs on the host instead, "
        "on whole numpy arrays, with the same result; the state crosses to the host and back "
        "every step"
    )
