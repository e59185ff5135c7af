"""The virtual K&C rig's measurement chain (issue 53 item 1): what a rig's transducers and
acquisition do to a signal besides the white noise, zero error and resolution of
:data:`elastokin.diagnosis.virtual_kc_rig.MEASUREMENT_DEFAULTS`. Written for the truth side only,
apart from any model the diagnosis makes of it.

A truth's ``chain`` key (K&C level), by channel (``toe_fl``) or by a channel's name without its
wheel (``toe``: every wheel; a channel's own elements go over its stem's)::

    chain:
      toe:    {delay_ms: 15, low_pass_hz: 9, gain: 0.01, crosstalk: {camber: 0.01}, ar1_sigma: 0.002,
               ar1_time_constant_s: 2, pink_sigma: 0.002, drift_per_min: 0.004}
      pad_fz: {gain: -0.015, crosstalk: {pad_fy: 0.01}}
      pad_fy: {gain: 0.015}                # a servoed input: the car gets the command / 1.015

Per channel, in this order (a transducer, then its amplifier and acquisition):

- ``gain``: the reading's fractional calibration error, reading = (1 + gain) × value;
- ``crosstalk``: other quantities of the same wheel the transducer sees, quantity -> coefficient
  [this channel's unit per that quantity's unit], added to the reading (a toe head seeing camber,
  a pad's Fz cell seeing Fy);
- ``low_pass_hz``: a 2nd-order Butterworth anti-alias filter of this cut-off f_c [Hz], an analogue
  filter before the sampling, whatever the recording's rate (:func:`analogue_low_pass`), started at
  rest on the first sample; its own lag at low frequency, sqrt(2) / (2π f_c), comes on top of
  ``delay_ms``;
- ``delay_ms``: a pure lag of the channel behind the time base [ms] (acquisition buffering,
  sensor-head processing), the first sample held before the record starts;
- ``drift_per_min``: a zero that drifts linearly through each recording, its rate drawn per
  recording in ± this [channel unit / min];
- ``ar1_sigma``, ``ar1_time_constant_s``: coloured noise, a stationary first-order autoregressive
  process of this standard deviation [channel unit] and correlation time [s];
- ``pink_sigma``: 1/f noise (amplifier flicker, the rig's temperature) of this expected standard
  deviation [channel unit], its power spectrum proportional to 1/f from 1/(the recording's length)
  to the Nyquist frequency.

The rig inputs (pad travel and forces, rack) are servoed: the rig's controller makes the reading of
the input's own transducer follow the command, so the recording holds the command and the car
gets the command / (1 + ``gain``). That gain is the only element an input takes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import Any, Mapping

import numpy as np
from scipy import signal as sps

from elastokin.vehicle.scenarios.channels import CORNER_TAGS, INPUT_CHANNELS, channel_quantity, channel_wheel
from elastokin.vehicle.scenarios.scenario import Scenario
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
#: the noise's correlation time [s], |cross-talk| coefficients of :data:`CROSSTALK` (sign drawn).
#: Where they come from: issue 53's figures for a typical rig (calibration ±0.5–2 %, angle channels
#: 12–15 ms late behind an 8–10 Hz anti-alias filter) and for a good one (3 ms, a 20 Hz filter, 0.5 %
#: gains, mild noise); the cross-talk's are assumed of the gains' order, and the 1/f noise's of the
#: AR(1)'s. No vendor datasheet was at hand to check them against (this machine has no internet
#: beyond the package registries).
#: ``rig``: the rig's own mechanics (:mod:`elastokin.vehicle.scenarios.rig_file`'s keys), drawn
#: uniformly in these: the floating pads' residual friction and their compliance in x and y, the body
#: clamp's compliance left after the rig's correction of the body's motion. No published figure was
#: at hand for any of them (Morse Measurements, "What exactly is K&C testing?", 2020, says only that
#: a rig without floating pads, whose tyres scrub, is easily 10 % off in ride rate): they are set so
#: that each shows in the default car's campaign at about the noise (20 N of pad friction and
#: 0.02 mm/kN of lateral clamp compliance give 1.8 and 2.3 × the noise in the lateral-force test),
#: a good rig's friction and clamp at a fifth of a typical one's, its pads' compliance at half.
GRADES = {
    "typical": {"delay_ms": {"wheel_sensors": (12.0, 15.0), "pad_sensors": (0.0, 5.0)},
                "low_pass_hz": {"wheel_sensors": (8.0, 10.0), "pad_sensors": (15.0, 25.0)},
                "gain": (0.005, 0.02), "crosstalk": (0.005, 0.02), "ar1": (1.0, 2.0),
                "ar1_time_constant_s": (0.5, 5.0), "pink": (1.0, 2.0), "drift": (1.0, 2.0),
                "rig": {"pad_friction_n": (5.0, 20.0), "pad_compliance_mm_per_kn": (2.0, 5.0),
                        "clamp_lateral_mm_per_kn": (0.005, 0.02), "clamp_vertical_mm_per_kn": (0.005, 0.02),
                        "clamp_roll_deg_per_knm": (0.001, 0.005), "clamp_pitch_deg_per_knm": (0.001, 0.005)}},
    "good": {"delay_ms": {"wheel_sensors": (2.0, 4.0), "pad_sensors": (0.0, 2.0)},
             "low_pass_hz": {"wheel_sensors": (18.0, 25.0), "pad_sensors": (25.0, 40.0)},
             "gain": (0.002, 0.005), "crosstalk": (0.001, 0.005), "ar1": (0.3, 0.7),
             "ar1_time_constant_s": (0.5, 5.0), "pink": (0.3, 0.7), "drift": (0.3, 0.7),
             "rig": {"pad_friction_n": (1.0, 4.0), "pad_compliance_mm_per_kn": (1.0, 2.0),
                     "clamp_lateral_mm_per_kn": (0.001, 0.004), "clamp_vertical_mm_per_kn": (0.001, 0.004),
                     "clamp_roll_deg_per_knm": (0.0002, 0.001), "clamp_pitch_deg_per_knm": (0.0002, 0.001)}},
}
#: Which quantity's transducer sees which other of the same wheel when a chain is drawn.
CROSSTALK = {"toe": "camber", "pad_fz": "pad_fy"}
#: What :func:`draw_rig` draws of a rig's mechanics: the pads' friction (with their compliance), the
#: body clamp's compliance (its four directions).
RIG_DRAWN = {"pad_friction": ("pad_friction_n", "pad_compliance_mm_per_kn"),
             "clamp": ("clamp_lateral_mm_per_kn", "clamp_vertical_mm_per_kn", "clamp_roll_deg_per_knm",
                       "clamp_pitch_deg_per_knm")}
#: What :func:`draw_chain` and :func:`draw_rig` can draw, alone or together (``input_gain``: the
#: servoed inputs' transducers).
DRAWN = ("delay", "low_pass", "gain", "crosstalk", "ar1", "pink", "drift", "input_gain", *RIG_DRAWN)
_SIGNED = ("gain",)
_FILTER_ORDER = 2
#: The rate, in multiples of the recording's, at which the analogue filter is computed.
_OVERSAMPLE = 8


@dataclass(frozen=True)
class ChannelChain:
    """What the rig's chain does to one channel (a truth's chain elements, each 0 when absent)."""

    gain: float = 0.0
    crosstalk: tuple[tuple[str, float], ...] = ()   #: (quantity of the same wheel, coefficient)
    low_pass_hz: float = 0.0
    delay_ms: float = 0.0
    drift_per_min: float = 0.0
    ar1_sigma: float = 0.0
    ar1_time_constant_s: float = 0.0
    pink_sigma: float = 0.0

    def apply(self, t_s: np.ndarray, x: np.ndarray, rng: np.random.Generator,
              seen: Mapping[str, np.ndarray] | None = None) -> np.ndarray:
        """The channel ``x`` (sampled at the uniform times ``t_s`` [s]) as this chain delivers it;
        ``seen``: the true signals of the cross-talk's quantities (same wheel, same samples). Draws
        the drift's rate and the coloured noises from ``rng``, always in the same number."""
        dt = float(t_s[1] - t_s[0])
        y = (1.0 + self.gain) * x + sum(c * (seen or {})[q] for q, c in self.crosstalk)
        if self.low_pass_hz > 0.0:
            y = analogue_low_pass(y, dt, self.low_pass_hz)
        if self.delay_ms > 0.0:
            y = np.interp(t_s - 1e-3 * self.delay_ms, t_s, y)
        rate = rng.uniform(-1.0, 1.0) * self.drift_per_min / 60.0
        y = y + rate * (t_s - t_s[0])
        white = rng.standard_normal((2, x.size))
        if self.ar1_sigma > 0.0:
            y = y + ar1(white[0], self.ar1_sigma, math.exp(-dt / self.ar1_time_constant_s))
        if self.pink_sigma > 0.0:
            y = y + pink(white[1], self.pink_sigma)
        return y


#: A channel's chain elements, the keys of a truth's chain entry.
ELEMENTS = tuple(f.name for f in fields(ChannelChain))


def analogue_low_pass(x: np.ndarray, dt: float, cutoff_hz: float) -> np.ndarray:
    """``x`` (samples ``dt`` [s] apart) through an analogue 2nd-order Butterworth low-pass of
    ``cutoff_hz``, started at rest on the first sample: the signal taken linear between samples at
    :data:`_OVERSAMPLE` × the rate, there the filter's bilinear transform pre-warped to the analogue
    cut-off, read back at the samples."""
    fine = dt / _OVERSAMPLE
    k = np.arange((len(x) - 1) * _OVERSAMPLE + 1)
    between = np.interp(k / _OVERSAMPLE, np.arange(len(x)), x)
    digital = math.atan(math.pi * cutoff_hz * fine) / (math.pi * fine)   # its pre-warped analogue one: cutoff_hz
    sos = sps.butter(_FILTER_ORDER, digital, fs=1.0 / fine, output="sos")
    y, _ = sps.sosfilt(sos, between, zi=sps.sosfilt_zi(sos) * x[0])
    return y[::_OVERSAMPLE]


def ar1(white: np.ndarray, sigma: float, phi: float) -> np.ndarray:
    """A stationary AR(1) process e[k] = φ e[k−1] + σ √(1 − φ²) w[k] of standard deviation ``sigma``
    from the standard normal draws ``white`` (e[0] = σ w[0])."""
    b = [sigma * math.sqrt(1.0 - phi * phi)]
    e, _ = sps.lfilter(b, [1.0, -phi], white[1:], zi=[phi * sigma * white[0]])
    return np.concatenate([[sigma * white[0]], e])


def pink(white: np.ndarray, sigma: float) -> np.ndarray:
    """1/f noise of expected standard deviation ``sigma`` from the standard normal draws ``white``:
    their discrete Fourier coefficients k = 1 .. n/2 divided by √k (the mean taken out), so that
    the power at frequency k/(n Δt) is ∝ 1/k; scaled by the expected mean square Σ m_k / k / n
    (m_k = 2, once at the Nyquist frequency of an even n), the variance of the process over the
    record (a single record's scatters: 1/f noise is dominated by its lowest frequencies)."""
    n = white.size
    k = np.arange(1, n // 2 + 1)
    spectrum = np.fft.rfft(white)
    spectrum[0] = 0.0
    spectrum[1:] /= np.sqrt(k)
    twice = np.where(2 * k == n, 1.0, 2.0)
    return sigma * np.fft.irfft(spectrum, n) / math.sqrt(float(np.sum(twice / k)) / n)


def _crosstalk(raw: Any, quantities: set[str], own: set[str], source: str, key: str
               ) -> tuple[tuple[str, float], ...]:
    if not isinstance(raw, Mapping) or not raw:
        raise InputError(f"expected a mapping of quantity of the same wheel -> coefficient (this channel's unit "
                         f"per that quantity's), got {raw!r}", source=source, key=key)
    out = []
    for q, value in raw.items():
        if q not in quantities or q in own:
            raise InputError(f"no other quantity {q!r} of the same wheel; expected one of "
                             f"{', '.join(sorted(quantities - own))}", source=source, key=f"{key}.{q}")
        out.append((str(q), truth_number(value, source, f"{key}.{q}")))
    return tuple(out)


def _entry(raw: Any, quantities: set[str], own: set[str], source: str, key: str) -> dict[str, Any]:
    if not isinstance(raw, Mapping):
        raise InputError(f"expected a mapping of {', '.join(ELEMENTS)}, got {raw!r}", source=source, key=key)
    values: dict[str, Any] = {}
    for name, value in raw.items():
        if name not in ELEMENTS:
            raise InputError(f"unknown chain element {name!r}; expected {', '.join(ELEMENTS)}", source=source,
                             key=f"{key}.{name}")
        values[name] = (_crosstalk(value, quantities, own, source, f"{key}.{name}") if name == "crosstalk" else
                        truth_number(value, source, f"{key}.{name}", **({} if name in _SIGNED else {"lower": 0.0})))
    if values.get("gain", 0.0) <= -1.0:
        raise InputError(f"expected a gain error > -1 (a reading of (1 + gain) × value), got {values['gain']!r}",
                         source=source, key=f"{key}.gain")
    return values


def parse_chain(raw: Any, channels: Mapping[str, str], inputs: tuple[str, ...], source: str
                ) -> dict[str, ChannelChain]:
    """A truth's ``chain`` mapping as channel -> :class:`ChannelChain` over the measured ``channels``
    (name -> unit; ``inputs`` among them are servoed and take a ``gain`` alone). A channel's
    elements are its quantity's (its name without the wheel) with its own entry's over them."""
    if raw is None:
        return {}
    if not isinstance(raw, Mapping):
        raise InputError(f"expected a mapping of channel (or channel without its wheel) -> chain elements, got "
                         f"{raw!r}", source=source, key="chain")
    stems = {name: channel_quantity(name) for name in channels}
    wheeled = {stems[n] for n in channels if channel_wheel(n)}
    merged: dict[str, dict[str, Any]] = {}
    for where in sorted(raw, key=lambda w: w in channels):   # stems first: a channel's own entry goes over
        key = f"chain.{where}"
        matched = [n for n in channels if n == where or stems[n] == where]
        if not matched:
            known = ", ".join(dict.fromkeys(stems[n] for n in channels))
            raise InputError(f"no measured channel {where!r}; expected a channel or one of {known}", source=source,
                             key=key)
        values = _entry(raw[where], wheeled, {stems[n] for n in matched}, source, key)
        servoed = [e for e in values if e != "gain"] if any(n in inputs for n in matched) else []
        if servoed:
            raise InputError(f"{where} is a servoed rig input, the command its transducer's reading follows: it "
                             f"takes a gain alone (the car gets the command / (1 + gain)), not {servoed[0]}",
                             source=source, key=f"{key}.{servoed[0]}")
        for n in matched:
            merged.setdefault(n, {}).update(values)
    for n, values in merged.items():
        if (values.get("ar1_sigma", 0.0) > 0.0) != (values.get("ar1_time_constant_s", 0.0) > 0.0):
            raise InputError(f"{n}: ar1_sigma and ar1_time_constant_s go together: give both > 0 or neither",
                             source=source, key="chain")
    return {n: ChannelChain(**values) for n, values in merged.items()}


def seen(chain: ChannelChain, channel: str, signals: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
    """The true signals ``chain``'s cross-talk on ``channel`` sees: its quantities at the same wheel."""
    return {q: signals[f"{q}_{channel_wheel(channel)}"] for q, _ in chain.crosstalk}


def servoed(scenario: Scenario, chains: Mapping[str, ChannelChain]) -> Scenario:
    """``scenario`` as the car plays it when its inputs' transducers read ``chains``' gains: each
    input channel's command divided by (1 + gain) (the servo makes the reading follow the command)."""
    return scenario.with_inputs_scaled(
        np.array([1.0 / (1.0 + chains[ch].gain) if ch in chains else 1.0 for ch in INPUT_CHANNELS]))


def _check_drawn(elements: tuple[str, ...]) -> None:
    """ValueError for an element :func:`draw_chain` and :func:`draw_rig` cannot draw."""
    unknown = [e for e in elements if e not in DRAWN]
    if unknown:
        raise ValueError(f"unknown chain element {unknown[0]!r}; expected one of {', '.join(DRAWN)}")


def draw_chain(rng: np.random.Generator, grade: str, white_noise: Mapping[str, float],
               elements: tuple[str, ...] = DRAWN) -> dict[str, dict[str, Any]]:
    """A measurement chain drawn in ``grade``'s ranges (:data:`GRADES`), as a truth's ``chain``
    mapping (channel or channel without its wheel -> elements); ``white_noise``: the white noise of
    each measured channel without its wheel [its unit], the scale of the drift and coloured noise;
    ``elements``: the ones of :data:`DRAWN` to draw (each alone, for the slow suite's kinds)."""
    ranges = GRADES[grade]
    _check_drawn(elements)
    signed = lambda bounds: float(rng.choice((-1.0, 1.0)) * rng.uniform(*bounds))
    out: dict[str, dict[str, Any]] = {}
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
            if "pink" in elements:
                entry["pink_sigma"] = float(rng.uniform(*ranges["pink"]) * white_noise[stem])
            if "drift" in elements:
                entry["drift_per_min"] = float(rng.uniform(*ranges["drift"]) * white_noise[stem])
    wheels = CORNER_TAGS.values()
    if "gain" in elements:
        for stem in (s for stems in GROUPS.values() for s in stems):
            for wheel in wheels:
                out[f"{stem}_{wheel}"] = {"gain": round(signed(ranges["gain"]), 5)}
    if "crosstalk" in elements:
        for stem, source in CROSSTALK.items():
            for wheel in wheels:
                out.setdefault(f"{stem}_{wheel}", {})["crosstalk"] = {source: round(signed(ranges["crosstalk"]), 5)}
    if "input_gain" in elements:
        for channel in INPUT_CHANNELS:
            out[channel] = {"gain": round(signed(ranges["gain"]), 5)}
    return {k: v for k, v in out.items() if v}


def draw_rig(rng: np.random.Generator, grade: str, elements: tuple[str, ...] = DRAWN) -> dict[str, float]:
    """A rig's mechanics drawn in ``grade``'s ranges (:data:`GRADES`), as a truth's ``rig`` mapping
    (file units); ``elements``: those of :data:`RIG_DRAWN` among them are drawn, the rest ideal
    (ValueError for one not in :data:`DRAWN`)."""
    ranges = GRADES[grade]["rig"]
    _check_drawn(elements)
    return {key: round(float(rng.uniform(*ranges[key])), 6) for element, keys in RIG_DRAWN.items()
            if element in elements for key in keys}
