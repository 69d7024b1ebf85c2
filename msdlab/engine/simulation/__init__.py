"""The simulation: steps a body in time (`simulation.Simulation`), books the energy each
mechanism takes out (`energy.EnergyLedger`), and says why a run blew up (`stability`)."""
