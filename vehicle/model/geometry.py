"""Geometry of the car's parts: left/right mirror images of points, bushing frames and laws, wheel
axes, and frames built from two directions."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from elastokin.bushings.effects import Effects
from elastokin.bushings.parameters import ChannelParams


def mirror(p, sign: float) -> np.ndarray:
    """A left-side point or vector on the side ``sign`` (+1 left, −1 right)."""
    return np.array([p[0], sign * p[1], p[2]], dtype=float)


def _reversed_axis(axes) -> int:
    """Index of the bushing axis closest to the lateral direction (reversed on the right side)."""
    return int(np.argmax(np.abs(np.asarray(axes, float)[:, 1])))


def mirror_axes(axes, sign: float) -> np.ndarray:
    """Bushing axes (rows x, y, z) on side ``sign``, kept right-handed.

    A reflection makes the frame left-handed; the axis closest to the lateral direction is then
    reversed, so the longitudinal and vertical axes keep their world sense on both sides.
    """
    rows = np.array([mirror(a, sign) for a in axes])
    if sign < 0:
        rows[_reversed_axis(axes)] *= -1.0
    return rows


def mirror_signs(axes, sign: float) -> np.ndarray:
    """Per direction (x, y, z, rx, ry, rz), +1 or −1: in the mirror image of a left-side motion, a
    direction's deflection on side ``sign`` is this sign times the left one's.

    On the right the reversed axis (:func:`mirror_axes`) flips its translation, and a reflection
    flips every rotation (a pseudovector) except the one about the reversed axis.
    """
    signs = np.ones(6)
    if sign < 0:
        k = _reversed_axis(axes)
        signs[k] = -1.0
        signs[3:] = -1.0
        signs[3 + k] = 1.0
    return signs


def mirrored_law(params: ChannelParams, effects: Effects, sign: float) -> tuple[ChannelParams, Effects]:
    """(law, effects) of a direction whose deflection is the left one's times ``sign`` (see
    :func:`mirror_signs`): F(e) becomes −F(−e), so the elastic law's sides, the preload and the
    asymmetry (both its parts) swap; the rest of a law is odd already."""
    if sign > 0:
        return params, effects
    p = params.replace(N_sup=-params.N_inf, N_inf=-params.N_sup, S_sup=-params.S_inf, S_inf=-params.S_sup,
                       P_sup=params.P_inf, P_inf=params.P_sup)
    return p, dataclasses.replace(effects, preload=-effects.preload, asymmetry=-effects.asymmetry,
                                  asymmetry_step=-effects.asymmetry_step)


def wheel_axis(toe: float, camber: float, sign: float) -> np.ndarray:
    """Outward unit spin axis of a wheel with toe-in ``toe`` and camber ``camber`` [rad]."""
    return np.array([math.cos(camber) * math.sin(toe), sign * math.cos(camber) * math.cos(toe),
                     -math.sin(camber)])


def contact_point(centre, toe: float, camber: float, sign: float, radius: float) -> np.ndarray:
    """Where a wheel of ``radius`` [m] at ``centre`` [m] with toe-in ``toe`` and camber ``camber``
    [rad] (side ``sign``: +1 left) touches the ground: the centre less the radius along the wheel
    plane's up direction [m]."""
    spin_left = sign * wheel_axis(toe, camber, sign)
    up = np.array([0, 0, 1.0]) - spin_left * spin_left[2]
    return np.asarray(centre, float) - radius * up / np.linalg.norm(up)


def frame_from(primary: np.ndarray, secondary: np.ndarray, order: str = "zx") -> np.ndarray:
    """Rotation matrix (columns = local axes in world) with ``order[0]`` along ``primary``."""
    a = primary / np.linalg.norm(primary)
    b = secondary - a * (a @ secondary)
    b /= np.linalg.norm(b)
    cols = {order[0]: a, order[1]: b}
    if order == "zx":
        cols["y"] = np.cross(a, b)
    elif order == "yx":
        cols["z"] = np.cross(b, a)
    elif order == "xy":
        cols["z"] = np.cross(a, b)
    return np.column_stack([cols["x"], cols["y"], cols["z"]])
