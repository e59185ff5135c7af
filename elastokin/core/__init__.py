"""Foundation of every package: input errors, the YAML reader, units, atomic files, CSV tables, provenance, numba's cache."""
