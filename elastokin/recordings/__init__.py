"""Recorded runs: the MCAP run format, recording a scenario, rig and road-test recordings, a rig's CSV exports in and out, measured datasets."""
