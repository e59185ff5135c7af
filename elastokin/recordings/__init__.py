"""Recorded runs: the MCAP run format, recording a scenario, rig and road-test recordings, CSV import, measured datasets."""
