"""The virtual K&C rig's measurement chain (issue 53 item 1): what a rig's transducers and
acquisition do to a signal besides the white noise, zero error and resolution of
:data:`elastokin.diagnosis.virtual_kc_rig.MEASUREMENT_DEFAULTS`. Written for the truth side only,
apart from any model the diagnosis makes of it.

A truth's ``chain`` key (K&C level), by channel (``toe_fl``) or by a channel's name without its
wheel (``toe``: every wheel; a channel's own elements go over its stem's)::

    chain:
      toe:    {delay_ms: 15, low_pass_hz: 9, gain: 0.01, ar1_sigma: 0.002, ar1_time_constant_s: 2,
               drift_per_min: 0.004}
      pad_fz: {gain: -0.015}

Per channel, in this order (a transducer, then its amplifier and acquisition):

- ``gain``: the reading's fractional calibration error, reading = (1 + gain) × value;
- ``low_pass_hz``: a causal digital 2nd-order Butterworth anti-alias filter at this cut-off f_c [Hz]
  (bilinear, at the recording's rate f_s), started at rest on the first sample; its own lag at low
  frequency, sqrt(2) / (2π f_a) with f_a = (f_s/π) tan(π f_c/f_s), comes on top of ``delay_ms``;
- ``delay_ms``: a pure lag of the channel behind the time base [ms] (acquisition buffering,
  sensor-head processing), the first sample held before the record starts;
- ``drift_per_min``: a zero that drifts linearly through each recording, its rate drawn per
  recording in ± this [channel unit / min];
- ``ar1_sigma``, ``ar1_time_constant_s``: coloured noise, a stationary first-order autoregressive
  process of this standard deviation [channel unit] and correlation time [s].

The rig inputs (pad travel and forces, rack) are written as commanded, so no chain applies to them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import Any, Mapping

import numpy as np
from scipy import signal as sps

from elastokin.vehicle.scenarios.channels import CORNER_TAGS
from elastokin.core.errors import InputError
from elastokin.diagnosis.measurement import truth_number

#: Channels (without their wheel) that share an acquisition path, so a lag and a filter: the
#: wheel-position heads' (angles and wheel-centre positions) and the pads' (load cells, heights).
GROUPS = {"wheel_sensors": ("camber", "toe", "steer", "wheel_travel", "half_track", "wheel_centre_x",
                            "wheel_centre_y", "wheel_centre_z"),
          "pad_sensors": ("pad_fz", "pad_height")}
#: Elements a chain is drawn from, and their ranges by rig grade: lag [ms] and cut-off [Hz] per
#: group (each wheel alike), |gain| per channel (sign drawn), the coloured noise's standard deviation
#: and the drift's bound per minute as multiples of the channel's white noise (MEASUREMENT_DEFAULTS),
#: the noise's correlation time [s]. Where they come from: issue 53's figures for a typical rig
#: (calibration ±0.5–2 %, angle channels 12–15 ms late behind an 8–10 Hz anti-alias filter) and for a
#: good one (3 ms, a 20 Hz filter, 0.5 % gains, mild noise); no vendor datasheet was at hand to check
#: them against (this machine has no internet beyond the package registries).
GRADES = {
    "typical": {"delay_ms": {"wheel_sensors": (12.0, 15.0), "pad_sensors": (0.0, 5.0)},
                "low_pass_hz": {"wheel_sensors": (8.0, 10.0), "pad_sensors": (15.0, 25.0)},
                "gain": (0.005, 0.02), "ar1": (1.0, 2.0), "ar1_time_constant_s": (0.5, 5.0), "drift": (1.0, 2.0)},
    "good": {"delay_ms": {"wheel_sensors": (2.0, 4.0), "pad_sensors": (0.0, 2.0)},
             "low_pass_hz": {"wheel_sensors": (18.0, 25.0), "pad_sensors": (25.0, 40.0)},
             "gain": (0.002, 0.005), "ar1": (0.3, 0.7), "ar1_time_constant_s": (0.5, 5.0), "drift": (0.3, 0.7)},
}
#: What :func:`draw_chain` can draw, alone or together.
DRAWN = ("delay", "low_pass", "gain", "ar1", "drift")
_SIGNED = ("gain",)
_FILTER_ORDER = 2


@dataclass(frozen=True)
class ChannelChain:
    """What the rig's chain does to one channel (a truth's chain elements, each 0 when absent)."""

    gain: float = 0.0
    low_pass_hz: float = 0.0
    delay_ms: float = 0.0
    drift_per_min: float = 0.0
    ar1_sigma: float = 0.0
    ar1_time_constant_s: float = 0.0

    def apply(self, t_s: np.ndarray, x: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        """The channel ``x`` (sampled at the uniform times ``t_s`` [s]) as this chain delivers it;
        draws the drift's rate and the coloured noise from ``rng``, always in the same number."""
        dt = float(t_s[1] - t_s[0])
        y = (1.0 + self.gain) * x
        if self.low_pass_hz > 0.0:
            sos = sps.butter(_FILTER_ORDER, self.low_pass_hz, fs=1.0 / dt, output="sos")
            y, _ = sps.sosfilt(sos, y, zi=sps.sosfilt_zi(sos) * y[0])
        if self.delay_ms > 0.0:
            y = np.interp(t_s - 1e-3 * self.delay_ms, t_s, y)
        rate = rng.uniform(-1.0, 1.0) * self.drift_per_min / 60.0
        y = y + rate * (t_s - t_s[0])
        white = rng.standard_normal(x.shape)
        if self.ar1_sigma > 0.0:
            y = y + ar1(white, self.ar1_sigma, math.exp(-dt / self.ar1_time_constant_s))
        return y


#: A channel's chain elements, the keys of a truth's chain entry.
ELEMENTS = tuple(f.name for f in fields(ChannelChain))


def ar1(white: np.ndarray, sigma: float, phi: float) -> np.ndarray:
    """A stationary AR(1) process e[k] = φ e[k−1] + σ √(1 − φ²) w[k] of standard deviation ``sigma``
    from the standard normal draws ``white`` (e[0] = σ w[0])."""
    b = [sigma * math.sqrt(1.0 - phi * phi)]
    e, _ = sps.lfilter(b, [1.0, -phi], white[1:], zi=[phi * sigma * white[0]])
    return np.concatenate([[sigma * white[0]], e])


def _entry(raw: Any, source: str, key: str) -> dict[str, float]:
    if not isinstance(raw, Mapping):
        raise InputError(f"expected a mapping of {', '.join(ELEMENTS)}, got {raw!r}", source=source, key=key)
    values = {}
    for name, value in raw.items():
        if name not in ELEMENTS:
            raise InputError(f"unknown chain element {name!r}; expected {', '.join(ELEMENTS)}", source=source,
                             key=f"{key}.{name}")
        values[name] = truth_number(value, source, f"{key}.{name}", **({} if name in _SIGNED else {"lower": 0.0}))
    if values.get("gain", 0.0) <= -1.0:
        raise InputError(f"expected a gain error > -1 (a reading of (1 + gain) × value), got {values['gain']!r}",
                         source=source, key=f"{key}.gain")
    return values


def parse_chain(raw: Any, channels: Mapping[str, str], inputs: tuple[str, ...], source: str
                ) -> dict[str, ChannelChain]:
    """A truth's ``chain`` mapping as channel -> :class:`ChannelChain` over the measured ``channels``
    (name -> unit; ``inputs`` among them are written as commanded and take no chain). A channel's
    elements are its stem's (its name without the wheel) with its own entry's over them."""
    if raw is None:
        return {}
    if not isinstance(raw, Mapping):
        raise InputError(f"expected a mapping of channel (or channel without its wheel) -> chain elements, got "
                         f"{raw!r}", source=source, key="chain")
    stems = {name: name.rsplit("_", 1)[0] for name in channels}
    merged: dict[str, dict[str, float]] = {}
    for where in sorted(raw, key=lambda w: w in channels):   # stems first: a channel's own entry goes over
        key = f"chain.{where}"
        matched = [n for n in channels if n == where or stems[n] == where]
        if not matched:
            known = ", ".join(dict.fromkeys(stems[n] for n in channels if n not in inputs))
            raise InputError(f"no measured channel {where!r}; expected a channel or one of {known}", source=source,
                             key=key)
        if any(n in inputs for n in matched):
            raise InputError(f"{where} is a rig input, written as commanded: no measurement chain applies to it",
                             source=source, key=key)
        values = _entry(raw[where], source, key)
        for n in matched:
            merged.setdefault(n, {}).update(values)
    for n, values in merged.items():
        if (values.get("ar1_sigma", 0.0) > 0.0) != (values.get("ar1_time_constant_s", 0.0) > 0.0):
            raise InputError(f"{n}: ar1_sigma and ar1_time_constant_s go together: give both > 0 or neither",
                             source=source, key="chain")
    return {n: ChannelChain(**values) for n, values in merged.items()}


def draw_chain(rng: np.random.Generator, grade: str, white_noise: Mapping[str, float],
               elements: tuple[str, ...] = DRAWN) -> dict[str, dict[str, float]]:
    """A measurement chain drawn in ``grade``'s ranges (:data:`GRADES`), as a truth's ``chain``
    mapping (channel or channel without its wheel -> elements); ``white_noise``: the white noise of
    each measured channel without its wheel [its unit], the scale of the drift and coloured noise;
    ``elements``: the ones of :data:`DRAWN` to draw (each alone, for the slow suite's kinds)."""
    ranges = GRADES[grade]
    unknown = [e for e in elements if e not in DRAWN]
    if unknown:
        raise ValueError(f"unknown chain element {unknown[0]!r}; expected one of {', '.join(DRAWN)}")
    out: dict[str, dict[str, float]] = {}
    for group, stems in GROUPS.items():
        lag = float(rng.uniform(*ranges["delay_ms"][group]))
        cutoff = float(rng.uniform(*ranges["low_pass_hz"][group]))
        for stem in stems:
            entry = out.setdefault(stem, {})
            if "delay" in elements:
                entry["delay_ms"] = round(lag, 2)
            if "low_pass" in elements:
                entry["low_pass_hz"] = round(cutoff, 2)
            if "ar1" in elements:
                entry["ar1_sigma"] = float(rng.uniform(*ranges["ar1"]) * white_noise[stem])
                entry["ar1_time_constant_s"] = round(float(rng.uniform(*ranges["ar1_time_constant_s"])), 2)
            if "drift" in elements:
                entry["drift_per_min"] = float(rng.uniform(*ranges["drift"]) * white_noise[stem])
    if "gain" in elements:
        for stem in (s for stems in GROUPS.values() for s in stems):
            for wheel in CORNER_TAGS.values():
                out[f"{stem}_{wheel}"] = {"gain": round(float(rng.choice((-1.0, 1.0)) * rng.uniform(*ranges["gain"])), 5)}
    return {k: v for k, v in out.items() if v}
