"""The model: particles, springs and bodies, their checks, units and errors.

What is simulated, as arrays a backend reads (`body.Body`: positions, velocities, masses,
fixed particles and one spring set, an edge list `springs.EdgeSprings` or a lattice
`lattice.LatticeSprings`), and what acts on it besides its springs: force fields
(`forces.Force`) and constraints applied after each step (`constraint.Constraint`).
"""
