"""A bushing law of this library as an Adams bushing property file can carry it: an elastic curve
and a viscous damping coefficient per direction, with what that loses measured side by side.

The curve is the centre line of the law's slow loop: a triangle at the thesis's slow rate
(20 mm/min, fig. 5.6 of Bourgeteau 2009; 20 deg/min for a rotation) over ±``range``, its last cycle's
rising and falling branches averaged at each of ``points`` deflections. The damping is the
equivalent viscous coefficient at one frequency and amplitude: c = Im K* / ω of the law's first
harmonic there (:func:`elastokin.bushings.frequency.first_harmonic`), the dashpot that dissipates
the same energy per cycle. What a curve and a dashpot cannot carry — the hysteresis that stays at
vanishing rates, relaxation, the Payne effect's amplitude dependence, the frequency dependence away
from the chosen point, and any law extension (preload, asymmetry, Mullins, heating, backlash) — is
said in the file and measured by :func:`compare`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from elastokin.bushings.adams_bus import BusDirection
from elastokin.bushings.bank import BushingBank
from elastokin.bushings.bench.programmes import triangle
from elastokin.bushings.frequency import first_harmonic
from elastokin.bushings.parameters import ChannelParams, to_si
from elastokin.core.units import DEG, MM

#: The slow loop's rate [mm/s or deg/s]: the thesis's 20 mm/min triangle (fig. 5.6).
SLOW_RATE = 20.0 / 60.0
#: Where the comparison is made: frequencies [Hz] and amplitudes [mm or deg].
COMPARED_HZ, COMPARED_AMPLITUDES = (1.0, 10.0), (0.1, 1.0)
#: Samples per slow-loop cycle.
_LOOP_SAMPLES = 4000


@dataclass(frozen=True)
class Export:
    """A law's export: the direction as a ``.bus`` file holds it, and how it was made."""

    direction: BusDirection
    range: float            #: the curve's half range [mm or deg]
    damping_hz: float       #: where the damping was matched: frequency [Hz]...
    damping_amplitude: float   #: ... and amplitude [mm or deg]


def _unit(channel: ChannelParams) -> float:
    """SI per the parameter sets' length unit of ``channel`` (mm or deg)."""
    return MM if channel.quantity == "translation" else DEG


def slow_loop(channel: ChannelParams, range_: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The slow triangle's loop over ±``range_`` [mm or deg] once first loading is past: deflection
    [mm or deg] and the force [N or N·m] of its rising (from −A, through the end of the first cycle)
    and falling (of the second cycle) branches, on one grid of 201 deflections."""
    unit, n = _unit(channel), _LOOP_SAMPLES
    period = 4.0 * range_ / SLOW_RATE
    _, e = triangle(range_ * unit, SLOW_RATE * unit, 2, period / n)   # 0 → +A → −A → 0, twice: 2n + 1 samples
    force, _ = BushingBank([channel]).run(e, period / n)
    rise, fall = slice(3 * n // 4, n + n // 4 + 1), slice(n + n // 4, n + 3 * n // 4 + 1)
    grid = np.linspace(-range_, range_, 201) * unit
    rising = np.interp(grid, e[rise], force[rise])
    falling = np.interp(grid, e[fall][::-1], force[fall][::-1])
    return grid / unit, rising, falling


def export(channel: ChannelParams, direction: str, range_: float, damping_hz: float = 1.0,
           damping_amplitude: float = 1.0, points: int = 21) -> Export:
    """``channel`` (SI) as ``direction`` of a ``.bus`` file: its slow loop's centre line at
    ``points`` (odd: one at zero) deflections over ±``range_`` [mm or deg] and its equivalent
    viscous damping at ``damping_hz`` and ``damping_amplitude`` [mm or deg] (in N·s/mm or
    N·m·s/deg). ValueError for an even or too small ``points`` or a range that is not positive."""
    if points < 3 or points % 2 == 0 or not range_ > 0.0:
        raise ValueError(f"expected an odd number of points >= 3 and a positive range, got {points}, {range_}")
    x, rising, falling = slow_loop(channel, range_)
    grid = np.linspace(-range_, range_, points)
    centre = np.interp(grid, x, 0.5 * (rising + falling))
    centre[points // 2] = 0.0   # a symmetric law's centre line passes through zero (the loop's sampling aside)
    centre = np.maximum.accumulate(centre)   # the mean of two rising branches rises (round-off aside)
    unit = _unit(channel)
    k = first_harmonic(channel, np.array([damping_amplitude * unit]), np.array([damping_hz])).k_complex_n_per_m[0]
    c = float(k.imag) / (2.0 * math.pi * damping_hz) * unit
    curve = tuple((float(a), float(b)) for a, b in zip(grid, centre))
    return Export(BusDirection(direction, curve, max(c, 0.0)), range_, damping_hz, damping_amplitude)


def law_of(exported: BusDirection) -> ChannelParams:
    """The ``curve`` law an export reads back as (SI)."""
    values = {"curve": [list(p) for p in exported.curve], **({"C": exported.damping} if exported.damping else {})}
    return to_si("curve", values, exported.quantity, source=f"export of {exported.direction}")


@dataclass(frozen=True)
class Comparison:
    """A law beside its export: first-harmonic |K*| [N/mm or N·m/deg] and tan δ at every compared
    (frequency, amplitude), and the slow loop's width at zero deflection [N or N·m]."""

    frequencies_hz: tuple[float, ...]
    amplitudes: tuple[float, ...]        #: [mm or deg]
    k_dyn: dict[str, np.ndarray]         #: "law" / "export" → (frequencies, amplitudes)
    tan_delta: dict[str, np.ndarray]
    loop_width: dict[str, float]


def compare(channel: ChannelParams, exported: Export) -> Comparison:
    """The law and its export side by side on the bench (:data:`COMPARED_HZ` × :data:`COMPARED_AMPLITUDES`)."""
    unit = _unit(channel)
    f, a = np.meshgrid(COMPARED_HZ, COMPARED_AMPLITUDES, indexing="ij")
    k_dyn, tan_delta, width = {}, {}, {}
    for name, law in (("law", channel), ("export", law_of(exported.direction))):
        h = first_harmonic(law, a * unit, f)
        k_dyn[name], tan_delta[name] = h.k_dyn_n_per_m * unit, h.tan_delta
        x, rising, falling = slow_loop(law, exported.range)
        width[name] = float(np.interp(0.0, x, rising - falling))   # moving up, the loss adds to the force
    return Comparison(COMPARED_HZ, COMPARED_AMPLITUDES, k_dyn, tan_delta, width)


def comparison_lines(comparison: Comparison, quantity: str) -> list[str]:
    """The comparison as lines of text (for the file's comments and the command's output)."""
    length, force = ("mm", "N") if quantity == "translation" else ("deg", "N·m")
    lines = [f"{'':>18}" + "".join(f"{f'{f:g} Hz, {a:g} {length}':>22}" for f in comparison.frequencies_hz
                                    for a in comparison.amplitudes)]
    for name in ("law", "export"):
        k, t = comparison.k_dyn[name], comparison.tan_delta[name]
        lines.append(f"{f'{name} K_dyn [{force}/{length}]':>18}" + "".join(f"{v:22.4g}" for v in k.ravel()))
        lines.append(f"{f'{name} tan delta':>18}" + "".join(f"{v:22.4f}" for v in t.ravel()))
    lines.append(f"slow-loop width at 0 [{force}]: law {comparison.loop_width['law']:.4g}, export "
                 f"{comparison.loop_width['export']:.4g}")
    return lines
