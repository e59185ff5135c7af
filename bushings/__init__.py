"""Bushing force laws (STS, RT, STVS and relatives), their implicit integration, frequency characterisation.

A :class:`BushingBank` steps many 1-D channels at once with an implicit, unconditionally stable
scheme and returns each channel's force and tangent stiffness. All quantities are SI; parameter
sets are written in the thesis's units (N, mm, s) and converted once, when loaded.
"""

from elastokin.bushings.bank import BushingBank
from elastokin.bushings.parameter_sets import ParameterSet, available_parameter_sets, load_parameter_set
from elastokin.bushings.parameters import ChannelParams, to_si

__all__ = ["BushingBank", "ChannelParams", "ParameterSet", "available_parameter_sets", "load_parameter_set", "to_si"]
