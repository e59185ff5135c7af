"""Metrics of runs and rig samples (K&C gradients, loops, relaxation, dynamic stiffness; ISO 7401 / 4138 road metrics), comparison, `vsim kc`."""
