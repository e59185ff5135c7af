"""Tyres: .tir property files read and checked, the Magic Formula 6.1 and 5.2 compiled, transient slip, tyres on a flat road."""
