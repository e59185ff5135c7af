"""Tyres: the industry's .tir property files (the Magic Formula's coefficients) read and checked."""
