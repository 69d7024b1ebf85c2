"""The engine, in layers, lowest first; each imports only from the layers below it:

1. `equations`: each formula of the physics, once, on numbers or whole arrays;
2. `model`: particles, springs, bodies, units, errors, and the forces and constraints
   acting on a body;
3. `backends`: the contract a step needs, the choice of backend, and the backends
   (numpy, the readable reference; numba, compiled loops);
4. `dynamics`: a = F/m of a body, through the chosen backend;
5. `integrators`: the time steppers, each an update function of (x, v, a, dt);
6. `simulation`: the stepping loop, its energy ledger and its diagnosis of blow-ups.

``import msdlab as msd`` re-exports the public names (``msd.Body``, ``msd.Simulation``).
"""
