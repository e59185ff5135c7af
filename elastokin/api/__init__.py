"""The Python API: vehicles, scenarios, simulations and their runs, diagnoses, sweeps and the built-ins.

Everything here is re-exported at the package's top (``elastokin.Simulation``); the command line is a
thin layer over it.
"""
