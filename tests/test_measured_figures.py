"""The thesis's measured figures of its bushing (issue 52, item 2): 920 N/mm and tan δ 0.12 at 1 Hz,
1 mm (Bourgeteau 2009, figs. 5.18–5.19 captions), about 50 % lost from 0.1 to 2 mm at 10 Hz and 20 %
between 100 and 1 Hz at 0.5 mm (§3.3.1), held by the set identified to them with fig. 5.6's slow
loops; the figures' own sets miss them, by the margins the report gives."""

from __future__ import annotations

import pytest

from elastokin.bushings.bench.measured_figures import FIGURES, LOOP_TOLERANCE, identify, measures
from elastokin.bushings.parameter_sets import load_parameter_set
from elastokin.core.errors import InputError


def test_the_identified_set_meets_the_thesis_figures_and_fig_5_6s_slow_loop() -> None:
    m = measures(load_parameter_set("measured_figures_stvs").channel())
    for key, (target, tolerance) in FIGURES.items():
        assert abs(m.figures[key] - target) <= tolerance, (key, m.figures[key])
    assert m.loop_departure <= LOOP_TOLERANCE


@pytest.mark.parametrize("name", ["fig5_9_caption", "fig5_8_caption", "fig5_6", "fig5_9", "fig5_8"])
def test_the_figures_own_sets_miss_the_measured_figures(name: str) -> None:
    """As initialised from the slow loop (§5.2), in either reading of figs. 5.8-5.9's captions, the
    sets of figs. 5.6, 5.8 and 5.9 keep the part's stiffness within 3 % but are lossier at 1 Hz,
    1 mm than the part measured (tan δ 0.13-0.17 against 0.12) and lose less stiffness with
    amplitude (0.38-0.44 against 0.50) and with frequency (at most 0.12 against 0.20), each beyond
    the figure's tolerance, as the report's table says; their slow loops stay fig. 5.6's."""
    m = measures(load_parameter_set(name).channel())
    (k, _), (tan_delta, tan_tol), (payne, payne_tol), (frequency, frequency_tol) = FIGURES.values()
    assert abs(m.figures["k_dyn_1hz_1mm_n_per_mm"] / k - 1.0) < 0.03
    assert tan_delta + tan_tol < m.figures["tan_delta_1hz_1mm"] < 0.175
    assert 0.38 < m.figures["payne_loss_10hz"] < payne - payne_tol
    assert -0.01 < m.figures["frequency_loss_0p5mm"] < min(0.12, frequency - frequency_tol)
    assert m.loop_departure <= LOOP_TOLERANCE


def test_the_equations_reading_of_figs_5_8_and_5_9() -> None:
    """§5.2.5 from fig. 5.6's STS (Ff = 40.6 N at V0 = 0.3 mm/s): eq. 3.16's Co = Fs/V0^pw for the
    RT with pw = 0.1; eq. 5.10's 80/20 share for the STVS (slider 32.48 N, viscous 8.12 N at V0);
    fig. 5.6's Kpa and Kr; and the caption's Co = 41.1 is what pw = 0.01 would give."""
    fig5_6 = load_parameter_set("fig5_6").values
    rt, stvs = load_parameter_set("fig5_8").values, load_parameter_set("fig5_9").values
    v0 = 0.3
    assert rt["Co"] == pytest.approx(fig5_6["Ff"] / v0 ** rt["pw"], rel=1e-4)
    assert 41.1 == pytest.approx(fig5_6["Ff"] / v0 ** 0.01, abs=0.01)
    assert stvs["Ff"] == pytest.approx(0.8 * fig5_6["Ff"], rel=1e-4)
    assert stvs["Co"] * v0 ** stvs["pw"] == pytest.approx(0.2 * fig5_6["Ff"], rel=1e-3)
    assert stvs["Ff"] + stvs["Co"] * v0 ** stvs["pw"] == pytest.approx(fig5_6["Ff"], rel=1e-3)   # the STS threshold
    for law in (rt, stvs):
        assert (law["Kpa"], law["Kr"], law["K0"]) == (fig5_6["Kpa"], fig5_6["Kr"], fig5_6["K0"])


@pytest.mark.slow   # 40 s on a core: 200 evaluations of the figures and the slow loop
def test_the_identification_meets_the_figures_from_another_start() -> None:
    """`identify` from fig5_9 (tan δ 0.144, Payne 0.41, frequency 0.04: all three missed)
    finds a law that meets every figure within its tolerance and fig. 5.6's slow loop with it."""
    start = load_parameter_set("fig5_9")
    assert any(abs(measures(start.channel()).figures[k] - target) > tol for k, (target, tol) in FIGURES.items())
    found, m = identify(start, max_evaluations=200)
    for key, (target, tolerance) in FIGURES.items():
        assert abs(m.figures[key] - target) <= tolerance, (key, m.figures[key])
    assert m.loop_departure <= LOOP_TOLERANCE and found.model == "stvs"


def test_the_identification_refuses_a_start_it_cannot_fit() -> None:
    with pytest.raises(InputError, match=r"fig5_8.*expected an STVS set .* got a 'rt' set"):
        identify(load_parameter_set("fig5_8"))


def test_the_default_cars_ladder_laws_are_less_lossy_than_the_thesis_car() -> None:
    """The thesis's car ran lossy bushings ("angle de perte élevé", tan δ ≈ 0.3, §4.4.1); the default
    car's front ladder laws lose two thirds of that or less (0.06–0.17), at the lateral test's 0.2 mm,
    0.1 Hz and at 1 Hz, 1 mm."""
    import numpy as np

    from elastokin.bushings.frequency import first_harmonic
    from elastokin.vehicle.model.vehicle_file import load_vehicle

    bushings = {b.name: b for b in load_vehicle().bushings}
    for place in ("e1_front.y", "e1_front.z", "e2_front.x", "e2_front.y", "e2_front.z"):
        name, direction = place.split(".")
        law = bushings[name].directions[direction].channel()
        for amplitude_m, frequency_hz in ((0.2e-3, 0.1), (1e-3, 1.0)):
            k = first_harmonic(law, np.array([amplitude_m]), np.array([frequency_hz])).k_complex_n_per_m[0]
            assert 0.03 < k.imag / k.real < 0.2, (place, amplitude_m, frequency_hz, k.imag / k.real)
