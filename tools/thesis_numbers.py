"""The numbers the thesis gives (Bourgeteau 2009, chapters 3 to 6) beside this project's, for the
opening table of ``tools/thesis/report.md`` (issue 52): a row per number, "thesis | where | ours |
verdict | held by", each row's "ours" measured here and asserted by the test it names. The
vehicle-level rows take their numbers from the report's own runs (:func:`car_rows`), the bench
rows and the run time are measured here (:func:`bench_rows`, a few seconds)."""

from __future__ import annotations

import math
import sys
from pathlib import Path

from elastokin.bushings.bench import measured_figures, thesis_identification
from elastokin.bushings.parameter_sets import load_parameter_set
from elastokin.vehicle.model.elements import BuildOptions
from elastokin.vehicle.model.vehicle_file import load_vehicle
from elastokin.vehicle.simulation.rig import KCRig

sys.path.insert(0, str(Path(__file__).resolve().parent / "benchmarks"))
import vehicle_speed  # noqa: E402  (tools/benchmarks: the run-time figures, timed side by side)

HEADER = ["| thesis | where | ours | verdict | held by |", "|---|---|---|---|---|"]
#: The slow loops' speed of §5.2.5 [mm/s] and fig. 5.6's STS threshold there [N] (eq. 3.16's Fs).
V0_MM_S, FIG5_8_FS_N = 0.3, 40.6
#: §4.2.2's wheel unbalance: K0 = 493 daN/mm [N/m], m_ns [kg], m [kg], R [m], tan δ.
UNBALANCE = (493e4, 45.0, 0.010, 0.200, 0.15)
#: The shipped sets whose bench figures stand beside the thesis's measured part.
SETS = ("fig5_6", "fig5_9_caption", "fig5_9", "measured_figures_stvs")


def _row(thesis: str, where: str, ours: str, verdict: str, held_by: str) -> str:
    return f"| {thesis} | {where} | {ours} | {verdict} | {held_by} |"


def bench_rows() -> list[str]:
    """The rows of the bushing's measured figures, the parameter readings, the identification,
    the wheel-unbalance example and the run time."""
    m = {name: measured_figures.measures(load_parameter_set(name).channel()) for name in SETS}
    held = "`tests/test_measured_figures.py`"

    def figure(key: str, digits: str) -> str:
        return ", ".join(f"{name} {round(m[name].figures[key], 3) + 0.0:{digits}}" for name in SETS)

    caption, equations = (load_parameter_set(name).values for name in ("fig5_9_caption", "fig5_9"))
    viscous = {name: v["Co"] * V0_MM_S ** v["pw"] for name, v in (("caption", caption), ("equations", equations))}
    co_fig5_8 = FIG5_8_FS_N / V0_MM_S ** 0.1   # eq. 3.16 with the caption's pw
    pw_of_41 = math.log(FIG5_8_FS_N / 41.1) / math.log(V0_MM_S)
    k, m_ns, mass, radius, tan_delta = UNBALANCE
    f_n = math.sqrt(k / m_ns) / (2 * math.pi)
    peak_mm = 1e3 * radius * mass / (m_ns * tan_delta)
    rt = thesis_identification.identify("swept sine + step")
    k1, k2, a, b = rt.ours
    v = load_vehicle()
    steps = vehicle_speed.step_times({name: KCRig(v, BuildOptions(bushing_model=model, bushing_model_directions=d))
                                      for name, (model, d) in vehicle_speed.CARS.items()}, repeats=5)
    per_minute = {name: 60.0 * s / BuildOptions.timestep for name, s in steps.items()}
    thesis = vehicle_speed.THESIS_S_PER_MINUTE
    return [
        _row("920 N/mm at 1 Hz, 1 mm", "figs. 5.18–5.19 captions", figure("k_dyn_1hz_1mm_n_per_mm", ".0f"),
             "the figures' sets 2–3 % soft; the identified set meets it", held),
        _row("tan δ = 0.12 at 1 Hz, 1 mm", "figs. 5.18–5.19 captions", figure("tan_delta_1hz_1mm", ".3f"),
             "the figures' sets lossier (0.13–0.17); the identified set meets it", held),
        _row("≈ 50 % of the stiffness lost from 0.1 to 2 mm at 10 Hz", "§3.3.1", figure("payne_loss_10hz", ".2f"),
             "the figures' sets lose less (0.39–0.43); the identified set meets it", held),
        _row("≈ 20 % from 100 to 1 Hz at 0.5 mm", "§3.3.1", figure("frequency_loss_0p5mm", ".2f"),
             "the figures' sets lose little (0–0.11); the identified set meets it", held),
        _row("the STS threshold shared 80 / 20, slider / viscous, at 0.3 mm/s", "§5.2.5, eq. 5.10",
             f"fig5_9_caption: slider {caption['Ff']:g} N, viscous {viscous['caption']:.1f} N; fig5_9: "
             f"{equations['Ff']:g} N, {viscous['equations']:.2f} N",
             "the caption's numbers read 25 / 75; the named set fig5_9 holds the equations' 80 / 20, "
             "fig5_9_caption the caption's",
             "`tests/test_measured_figures.py::test_the_equations_reading_of_figs_5_8_and_5_9`"),
        _row("fig. 5.8: Co = 41.1 with pw = 0.1", "fig. 5.8 caption, eq. 3.16",
             f"Co = {FIG5_8_FS_N:g} / 0.3^0.1 = {co_fig5_8:.2f} (41.1 is pw = {pw_of_41:.2f})",
             "the caption's pw or Co misprinted",
             "`tests/test_measured_figures.py::test_the_equations_reading_of_figs_5_8_and_5_9`"),
        _row("2-cell RT identified to a = 0.567–0.586, b = 63–66.6 (truth 0.5, 50)", "§5.4.2",
             f"a = {a:.3f}, b = {b:.1f} (k1 {k1:.0f}, k2 {k2:.0f} N/mm; truth 1200, 800)",
             "ours finds the truth; the thesis's fits stopped short", "`tests/test_identification.py`"),
        _row("wheel unbalance: 0.3 mm peak near 20 Hz (45 kg, 493 daN/mm, tan δ 0.15)", "§4.2.2, fig. 4.14",
             f"{peak_mm:.3f} mm = R·m/(m_ns·tan δ) at {f_n:.1f} Hz = √(K/m_ns)/2π",
             "the peak agrees; 20 Hz is not the linear K0's frequency "
             "(the thesis ties it to its nonlinear stiffness)", "`tests/test_vehicle_coupling.py`"),
        _row("one simulated minute: 2 h in ADAMS with 18 STVS, 15 min without", "§6.3",
             f"{per_minute['stvs_18']:.1f} s and {per_minute['linear']:.1f} s of stepping (pumping on the rig), "
             f"ratio {per_minute['stvs_18'] / per_minute['linear']:.2f} against the thesis's 8",
             f"{thesis['stvs_18'] / per_minute['stvs_18']:.0f} and {thesis['linear'] / per_minute['linear']:.0f} "
             f"times faster; the 18 STVS cost {100 * (per_minute['stvs_18'] / per_minute['linear'] - 1):+.0f} %, "
             "not 8 ×",
             "`tools/benchmarks/vehicle_speed.py` (timed, not tested)"),
    ]


def span(low: float, high: float) -> str:
    """``low``–``high`` to three decimals, or one number when they print alike."""
    a, b = f"{low:.3f}", f"{high:.3f}"
    return a if a == b else f"{a}–{b}"


def car_rows(deflection_ratios: tuple[float, float], rt_thicker_pct: tuple[float, float], thinning_pct: float,
             loss_range: tuple[float, float], thesis_car_loss: tuple[float, float]) -> list[str]:
    """The vehicle-level rows, from the report's runs: the E1 rear deflection's 30 mm / 10 mm and
    30 mm / 20 mm ratios in pumping (fig. 4.28's caption says 10 and 30 mm, its plot 20 and 30),
    RT's camber loop against STVS's at 1.5 mm/s [%] (figs. 5.8-5.9 as the captions and as the
    equations read them), the STVS loop's change from 1.5 to 15 mm/s
    [%], the default car's front ladder laws' tan δ range (at 0.2 mm, 0.1 Hz), the thesis car's
    STVS laws' (at 15 Hz, 1 mm)."""
    held = "tests/test_thesis_phenomena.py"
    return [
        _row("the bushing deflection follows the pumping amplitude (caption: 10 and 30 mm; "
             "the plot's title: 20 and 30 mm)", "§4.4.1, fig. 4.28",
             f"30 mm / 10 mm: {deflection_ratios[0]:.2f}; 30 mm / 20 mm: {deflection_ratios[1]:.2f}",
             "agrees with both readings", f"`{held}::test_the_rear_pivot_bushing_follows_the_pumping_amplitude`"),
        _row("RT's camber loop clearly thicker than STVS's", "§4.4.1, fig. 4.29",
             f"captions' sets +{rt_thicker_pct[0]:.1f} %; equations' sets +{rt_thicker_pct[1]:.0f} %",
             "agrees with the equations' reading; with the captions', in direction only",
             f"`{held}::test_the_rt_camber_loop_is_thicker_than_the_stvs_one_at_low_speed`, "
             f"`{held}::test_with_the_equations_reading_the_rt_camber_loop_is_clearly_thicker`"),
        _row("the camber loop's thickness changes with the pumping speed", "§4.4.1, fig. 4.30",
             f"{thinning_pct:+.0f} % from 1.5 to 15 mm/s", "agrees; the dampers thin it",
             f"`{held}::test_the_camber_loop_thins_with_the_pumping_speed_through_the_dampers`"),
        _row("the car's bushings: a high loss angle, tan δ ≈ 0.3", "§4.4, §4.4.1",
             f"the thesis car's 18 STVS laws: {span(*thesis_car_loss)} (15 Hz, 1 mm); "
             f"the default car's front ladder laws: {loss_range[0]:.3f}–{loss_range[1]:.3f} (0.2 mm, 0.1 Hz)",
             "the thesis car meets it; the default car is not the thesis's",
             "`tests/test_thesis_car.py`, `tests/test_measured_figures.py::test_the_default_cars_ladder_laws_are_less_lossy_than_the_thesis_car`"),
    ]
