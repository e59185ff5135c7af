"""The MuJoCo car, its K&C rig, scenarios, recordings, comparison with measured data and diagnosis."""
