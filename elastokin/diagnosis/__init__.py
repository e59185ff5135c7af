"""What the model misses in measured data: the catalogue of causes, the virtual bench and K&C rig, the diagnoses."""
