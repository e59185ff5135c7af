"""Metrics of runs and rig samples (K&C gradients, loops, relaxation, dynamic stiffness), comparison, `vsim kc`."""
