"""Sweeps: sweep files, designs (grid, Latin hypercube, Sobol'), one run as a pure function, the table, Sobol' indices."""
