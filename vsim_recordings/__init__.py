"""Recorded runs: the MCAP run format, its writer and reader, rig recordings, CSV import, measured datasets."""
