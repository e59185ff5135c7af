"""Rubber-bushing force laws (linear, nonlinear elastic, STS, continuous STS, STSn+, RT, STVS, TVS).

A :class:`BushingBank` steps many 1-D channels at once with an implicit, unconditionally stable
scheme and returns each channel's force and tangent stiffness. All quantities are SI.
"""

from vsim_core.errors import InputError
from bushings.parameters import (ChannelParams, ParameterSet, available_parameter_sets,
                                 load_parameter_set, to_si)
from bushings.bank import BushingBank

__all__ = ["BushingBank", "ChannelParams", "InputError", "ParameterSet", "available_parameter_sets",
           "load_parameter_set", "to_si"]
