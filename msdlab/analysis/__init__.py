"""Analyses that run many simulations: parameter sweeps and where they run."""
