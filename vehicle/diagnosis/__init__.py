"""Measured data against simulation: the virtual rig, the catalogue of causes and the diagnosis."""
