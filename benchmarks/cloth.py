"""How fast does msdlab step a cloth built from an edge list, next to NVIDIA Warp's CPU kernels?

The cloth is the layout of Warp's mass-spring cloth benchmark: an n×n sheet of
particles 1 cm apart, stretch springs to the 4 neighbours, shear springs along
both diagonals of every cell and bend springs to the particles two apart, each
with a dashpot; two corners pinned, gravity, 16 substeps a frame of 1/60 s.
msdlab builds it with `Body.from_arrays` and runs it as a user does: `Simulation`
with `SymplecticEuler` and `Gravity`, the energy ledger on, float64, one
`Simulation.step` per substep. Warp runs the same cloth with two kernels written
here in the style of its examples (a spring pass adding each spring's force to
both ends with atomic adds, then the symplectic Euler update), on its CPU device,
in float32 (its benchmark's precision) and in float64.

Before timing, both run the cloth for a few frames and their positions are
compared: float64 Warp must agree with msdlab to rounding, float32 Warp to
float32's precision. Then the runs are interleaved in one process (a frame of
each, repeated) and the table shows the median time per frame and msdlab's
median ratio to Warp's float32 frame next to it.

    python benchmarks/cloth.py                    # n = 32, 64, 128
    python benchmarks/cloth.py --n 32 --repeats 31
    python benchmarks/cloth.py --scenes           # also the trampoline and gallery meshes

Warp is an optional dependency (``pip install -e ".[bench]"``); without it the
benchmark says so and times msdlab alone.
"""

import argparse
import logging
import os
import statistics
import time
from functools import partial

import numpy as np

import msdlab as msd
from msdlab.engine.backends.process import configure_process

configure_process()  # the process settings of the command line

SPACING = 0.01  # m between neighbours
MASS = 1e-3  # kg per particle
STIFFNESS = {"stretch": 100.0, "shear": 50.0, "bend": 20.0}  # N/m
DAMPING = 0.01  # N·s/m, every spring's dashpot
GRAVITY = (0.0, -9.81, 0.0)  # m/s², the sheet lies in the x-z plane
FRAME_DT = 1.0 / 60.0  # s
SUBSTEPS = 16
CHECK_FRAMES = 20
COLUMNS = ("msdlab", "Warp float32", "Warp float64")


def cloth_springs(n: int) -> tuple[np.ndarray, np.ndarray]:
    """The (E, 2) particle pairs of an n×n cloth (particle i·n + j) and their stiffness (N/m)."""
    index = np.arange(n * n).reshape(n, n)
    kinds = {
        "stretch": ((0, 1), (1, 0)),
        "shear": ((1, 1), (1, -1)),
        "bend": ((0, 2), (2, 0)),
    }
    pairs, stiffness = [], []
    for kind, offsets in kinds.items():
        for di, dj in offsets:
            rows = slice(0, n - di)
            a = index[rows, max(0, -dj) : n - max(0, dj)]
            b = index[di:, max(0, dj) : n - max(0, -dj)]
            pairs.append(np.column_stack([a.ravel(), b.ravel()]))
            stiffness.append(np.full(a.size, STIFFNESS[kind]))
    return np.concatenate(pairs), np.concatenate(stiffness)


def cloth_positions(n: int) -> np.ndarray:
    """(n², 3) positions (m): the sheet flat in the x-z plane at y = 0."""
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    return np.column_stack([i.ravel(), np.zeros(n * n), j.ravel()]) * SPACING


def pinned(n: int) -> np.ndarray:
    """(n²,) bool: the two corners of the first row."""
    fixed = np.zeros(n * n, dtype=bool)
    fixed[[0, n - 1]] = True
    return fixed


def msdlab_cloth(n: int, kernel: str | None = None) -> msd.Simulation:
    """The cloth as a user builds it: `Body.from_arrays`, `SymplecticEuler`, `Gravity`, ledger."""
    pairs, stiffness = cloth_springs(n)
    body = msd.Body.from_arrays(
        cloth_positions(n),
        pairs,
        masses=MASS,
        fixed=pinned(n),
        stiffness=stiffness,
        damping=DAMPING,
    )
    dt = FRAME_DT / SUBSTEPS
    return msd.Simulation(body, msd.SymplecticEuler(), dt, [msd.Gravity(GRAVITY)], kernel=kernel)


def msdlab_frame(sim: msd.Simulation) -> None:
    """One frame: `SUBSTEPS` steps."""
    for _ in range(SUBSTEPS):
        sim.step()


class WarpCloth:
    """The cloth on Warp's CPU device in ``precision`` ("float32" or "float64")."""

    def __init__(self, n: int, precision: str) -> None:
        import warp as wp

        self.wp = wp
        vector = wp.vec3 if precision == "float32" else wp.vec3d
        kernels = warp_kernels(vector)
        self.spring_pass, self.update = kernels
        dtype = np.float32 if precision == "float32" else np.float64
        pairs, stiffness = cloth_springs(n)
        x = cloth_positions(n)
        rest = np.linalg.norm(x[pairs[:, 0]] - x[pairs[:, 1]], axis=1)
        inverse_mass = np.where(pinned(n), 0.0, 1.0 / MASS)

        def array(values: np.ndarray, kind: object) -> object:
            return wp.array(values.astype(dtype), dtype=kind, device="cpu")

        scalar = vector._wp_scalar_type_
        self.x = array(x, vector)
        self.v = array(np.zeros_like(x), vector)
        self.f = array(np.zeros_like(x), vector)
        self.pairs = wp.array(pairs.ravel().astype(np.int32), dtype=wp.int32, device="cpu")
        self.rest = array(rest, scalar)
        self.stiffness = array(stiffness, scalar)
        self.damping = array(np.full(len(pairs), DAMPING), scalar)
        self.inverse_mass = array(inverse_mass, scalar)
        self.gravity = vector(*GRAVITY)
        self.dt = scalar(FRAME_DT / SUBSTEPS)
        self.n_springs, self.n_particles = len(pairs), n * n

    def frame(self) -> None:
        """One frame: `SUBSTEPS` times clear the forces, the spring pass, the update."""
        wp = self.wp
        for _ in range(SUBSTEPS):
            self.f.zero_()
            wp.launch(
                self.spring_pass,
                dim=self.n_springs,
                inputs=[self.x, self.v, self.pairs, self.rest, self.stiffness, self.damping],
                outputs=[self.f],
                device="cpu",
            )
            wp.launch(
                self.update,
                dim=self.n_particles,
                inputs=[self.f, self.inverse_mass, self.gravity, self.dt],
                outputs=[self.x, self.v],
                device="cpu",
            )

    def positions(self) -> np.ndarray:
        """(N, 3) float64 positions (m)."""
        return self.x.numpy().astype(float)


_WARP_KERNELS: dict = {}


def warp_kernels(vector: type) -> tuple:
    """The spring pass and the symplectic Euler update for ``vector`` (wp.vec3 or wp.vec3d)."""
    if vector in _WARP_KERNELS:
        return _WARP_KERNELS[vector]
    import warp as wp

    scalar = vector._wp_scalar_type_

    @wp.kernel(module="unique")
    def spring_pass(
        x: wp.array(dtype=vector),
        v: wp.array(dtype=vector),
        pairs: wp.array(dtype=wp.int32),
        rest: wp.array(dtype=scalar),
        stiffness: wp.array(dtype=scalar),
        damping: wp.array(dtype=scalar),
        f: wp.array(dtype=vector),
    ):
        s = wp.tid()
        a = pairs[2 * s]
        b = pairs[2 * s + 1]
        d = x[a] - x[b]
        length = wp.length(d)
        if length == scalar(0.0):
            return
        n = d / length
        rate = wp.dot(v[a] - v[b], n)  # how fast the spring lengthens
        force = n * (stiffness[s] * (rest[s] - length) - damping[s] * rate)
        wp.atomic_add(f, a, force)
        wp.atomic_sub(f, b, force)

    @wp.kernel(module="unique")
    def update(
        f: wp.array(dtype=vector),
        inverse_mass: wp.array(dtype=scalar),
        gravity: vector,
        dt: scalar,
        x: wp.array(dtype=vector),
        v: wp.array(dtype=vector),
    ):
        i = wp.tid()
        w = inverse_mass[i]
        if w == scalar(0.0):  # pinned
            return
        v_new = v[i] + (f[i] * w + gravity) * dt
        v[i] = v_new
        x[i] = x[i] + v_new * dt

    _WARP_KERNELS[vector] = spring_pass, update
    return spring_pass, update


def check_agreement(n: int, warps: dict) -> list[str]:
    """Run msdlab and each Warp cloth `CHECK_FRAMES` frames from rest; the largest position
    difference (m) of each, checked against its precision's bound."""
    sim = msdlab_cloth(n)
    for _ in range(CHECK_FRAMES):
        msdlab_frame(sim)
    reference = sim.body.positions
    lines = []
    for precision, make in warps.items():
        cloth = make()
        for _ in range(CHECK_FRAMES):
            cloth.frame()
        gap = float(np.abs(cloth.positions() - reference).max())
        bound = 1e-9 if precision == "float64" else 1e-4
        if not gap <= bound:
            raise SystemExit(
                f"{n}×{n}: Warp {precision} is {gap:.2e} m from msdlab after "
                f"{CHECK_FRAMES} frames (allowed {bound:g} m): not the same cloth"
            )
        lines.append(f"Warp {precision} {gap:.1e} m")
    return lines


def interleaved(runs: dict, repeats: int) -> dict[str, list[float]]:
    """Seconds per frame of each run in ``runs`` (name: frame function), a frame of each in
    turn, ``repeats`` times, after one warm-up frame each."""
    for frame in runs.values():
        frame()
    times: dict[str, list[float]] = {name: [] for name in runs}
    for _ in range(repeats):
        for name, frame in runs.items():
            start = time.perf_counter()
            frame()
            times[name].append(time.perf_counter() - start)
    return times


def warp_available() -> bool:
    """Whether Warp is installed (then initialised, quietly)."""
    try:
        import warp as wp
    except ImportError:
        return False
    wp.config.log_level = logging.ERROR  # no banner, no line per compiled module
    wp.init()
    return True


def cloth_table(sizes: list[int], repeats: int) -> None:
    """Print the agreement and the ms per frame of each cloth size in ``sizes``."""
    has_warp = warp_available()
    if not has_warp:
        print('Warp is not installed (pip install -e ".[bench]"): timing msdlab alone.')
    print(f"ms per frame ({SUBSTEPS} substeps), median of {repeats}; ratio: msdlab / Warp float32")
    print("| n | particles | springs | msdlab | Warp float32 | Warp float64 | ratio | agreement |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- |")
    for n in sizes:
        warps = {}
        if has_warp:
            warps = {p: partial(WarpCloth, n, p) for p in ("float32", "float64")}
        agreement = check_agreement(n, warps)
        sim = msdlab_cloth(n)
        runs = {"msdlab": partial(msdlab_frame, sim)}
        runs.update({f"Warp {p}": make().frame for p, make in warps.items()})
        times = interleaved(runs, repeats)
        ms = {name: statistics.median(t) * 1e3 for name, t in times.items()}
        ratio = "-"
        if has_warp:
            ratios = [m / w for m, w in zip(times["msdlab"], times["Warp float32"], strict=True)]
            ratio = f"{statistics.median(ratios):.2f}"
        cells = [f"{ms[name]:.2f}" if name in ms else "-" for name in COLUMNS]
        print(
            f"| {n} | {n * n} | {sim.body.n_springs} | {' | '.join(cells)} | {ratio} "
            f"| {', '.join(agreement) or '-'} |"
        )


def scene_table(repeats: int) -> None:
    """µs per `Simulation.step` of the trampoline and the gallery's meshes, median of batches."""
    from msdlab.scenes import gallery, trampoline

    scenes = {
        "trampoline": trampoline.trampoline,
        "gallery mesh": gallery.mesh,
        "gallery driven mesh": gallery.driven_mesh,
    }
    print("\nµs per step of the scenes (numba kernel), median of batches of 200 steps")
    print("| scene | particles | springs | µs per step |")
    print("| --- | --- | --- | --- |")
    for name, make in scenes.items():
        sim = make()
        sim.run(steps=50)  # compiled
        per_batch = 200
        times = []
        for _ in range(repeats):
            start = time.perf_counter()
            for _ in range(per_batch):
                sim.step()
            times.append((time.perf_counter() - start) / per_batch * 1e6)
        size = f"{len(sim.body)} | {sim.body.n_springs}"
        print(f"| {name} | {size} | {statistics.median(times):.1f} |")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, nargs="+", default=[32, 64, 128])
    parser.add_argument("--repeats", type=int, default=21)
    parser.add_argument("--scenes", action="store_true", help="also time the scenes' steps")
    args = parser.parse_args()
    print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    cloth_table(args.n, args.repeats)
    if args.scenes:
        scene_table(args.repeats)


if __name__ == "__main__":
    main()
