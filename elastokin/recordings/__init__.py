"""Recorded runs: the MCAP run format, recording a scenario, rig recordings, CSV import, measured datasets."""
