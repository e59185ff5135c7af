"""Metrics of recorded runs (K&C gradients, loops, relaxation, dynamic stiffness) and their comparison."""
