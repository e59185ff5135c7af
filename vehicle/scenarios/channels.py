"""The rig's input channels: pad heights, pad forces and aligning torques per corner, and the rack;
their order, their units in scenario files, and the corner tags (fl, fr, rl, rr)."""

from __future__ import annotations

from elastokin.vehicle.model.definition import CORNERS
from elastokin.core import units

#: Corner names of the rig (order of ``elastokin.vehicle.model.definition.CORNERS``) and their short tags (fl, fr, rl, rr).
CORNER_TAGS = {corner: "".join(word[0] for word in corner.split("_")) for corner in CORNERS}
AXLES = ("front", "rear")

#: Rig input channels, in the order of :meth:`Case.inputs` columns: pad vertical displacement
#: (bump positive) [m], longitudinal and lateral pad force [N], aligning torque [N·m] per corner,
#: then the rack displacement (+y, to the left) [m].
INPUT_QUANTITIES = ("pad_z", "pad_fx", "pad_fy", "pad_mz")
INPUT_CHANNELS = tuple(f"{q}_{tag}" for q in INPUT_QUANTITIES for tag in CORNER_TAGS.values()) + ("rack",)

#: Unit of each input quantity in scenario files (the suffix of their keys and CSV columns).
FILE_UNITS = {"pad_z": "mm", "pad_fx": "daN", "pad_fy": "daN", "pad_mz": "Nm", "rack": "mm"}


def channel_wheel(channel: str) -> str:
    """The wheel tag a channel's name ends with (``toe_fl`` → ``fl``), "" for a channel of no wheel
    (``rack``)."""
    head, _, tag = channel.rpartition("_")
    return tag if head and tag in CORNER_TAGS.values() else ""


def channel_quantity(channel: str) -> str:
    """A channel's name without its wheel: ``pad_z_fl`` → ``pad_z``; ``rack`` → ``rack``."""
    wheel = channel_wheel(channel)
    return channel[:-len(wheel) - 1] if wheel else channel


def csv_columns() -> tuple[str, ...]:
    """Input columns a scenario CSV may have besides ``t_s``: channel name and file unit."""
    return tuple(f"{ch}_{FILE_UNITS[channel_quantity(ch)]}" for ch in INPUT_CHANNELS)


def file_si(quantity: str) -> float:
    """SI per scenario-file unit of an input quantity (1e-3 for ``pad_z`` in mm, 10 for daN)."""
    return units.si(FILE_UNITS[quantity])
