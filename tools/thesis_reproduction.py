"""The thesis's vehicle-level phenomena (Bourgeteau 2009, chapter 4, §4.4.1, figs. 4.28–4.41)
reproduced on the default car and on the thesis's car (lossy STVS on its 18 principal directions),
with numbers, plots and a verdict each; every disagreement traced to its cause by experiments.

    python tools/thesis_reproduction.py [--out tools/thesis] [--scheduler ADDRESS]

Writes ``report.md`` and its PNGs into ``--out`` (default ``tools/thesis``, linked from the README).
About 6 min on 2 cores (the runs go to a local Dask cluster, or to ``--scheduler``).
"""

from __future__ import annotations

import argparse
import re
import sys
from dataclasses import replace
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from elastokin.bushings.bank import BushingBank  # noqa: E402
from elastokin.bushings.frequency import first_harmonic, lossier  # noqa: E402
from elastokin.bushings.parameter_sets import load_parameter_set  # noqa: E402
from elastokin.vehicle.model.file_overrides import lossier_places, vehicle_with  # noqa: E402
from elastokin.vehicle.model.definition import DirectionDef  # noqa: E402
from elastokin.vehicle.model.vehicle_file import load_vehicle  # noqa: E402
from elastokin.vehicle.scenarios.scenario_file import load_scenario, with_case_values  # noqa: E402
from elastokin.analysis.run_metrics import case_lag_s, case_loop, case_mask, case_relaxation, cases  # noqa: E402
from elastokin.cluster.executor import executor  # noqa: E402
from elastokin.core.shipped import DEFAULT_VEHICLE  # noqa: E402
from elastokin.recordings.recorder import simulate  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
import thesis_numbers  # noqa: E402  (tools/: the opening table's rows)

ROOT = Path(__file__).resolve().parents[1]
#: The thesis's car (Bourgeteau 2009, §4.4), written by tools/thesis_car.py.
THESIS_CAR = ROOT / "models" / "vehicles" / "c_segment_thesis.yaml"
#: The dampers reduced to 1 N at 1 m/s (they must still dissipate): the car without its dampers.
NO_DAMPERS = {f"{axle}.damper.curve.{i}.1": value for axle in ("front", "rear") for i, value in ((0, -1.0), (2, 1.0))}
#: The front bushings' directions with ladder laws in the vehicle file, made lossier one at a time
#: and all together in the fig. 4.31 experiment.
FRONT_LADDERS = ("e1_front.y", "e1_front.z", "e2_front.x", "e2_front.y", "e2_front.z")
#: The control of the fig. 4.31 experiment: E1 front's lateral law with its stiffnesses and slider
#: thresholds scaled by this (its force scaled at every deflection).
SOFTER = 0.9
#: Time after a rack step's ramp beyond which its transient has died out [s].
SETTLED_S = 0.5
#: The slower ramp of the rack-step experiment [s].
SLOW_RISE_S = 0.5
#: The rear beam's bending stiffness of the fig. 4.30 experiment [N·m/rad] (EI/L of a 1.2 m cross
#: member, EI ≈ 6e4 N·m²: an assumption).
BEAM_BENDING_NM_PER_RAD = 5e4
#: The shares of a rack step at which the toe's lag behind the rack is measured.
LAG_AT = (0.1, 0.5, 0.9)
#: Where a lossier law keeps its |K*| (elastokin.bushings.frequency.lossier): amplitude [m] and frequency [Hz]
#: (E2 front's lateral direction works about there in the lateral-force test; E1 front's, at 0.3–2 mm).
LOSS_AT = (0.2e-3, 0.1)


def _bench_relaxation(set_name: str, ringing_m: float = 0.0, deflection_m: float = 0.3e-3, rise_s: float = 0.05,
                      hold_s: float = 6.0) -> float:
    """Relative force change of a parameter set held at ``deflection_m`` after a ramp of ``rise_s``
    and a ringing of ``ringing_m`` (20 Hz, decaying in 0.1 s, as the car's corner rings), from
    :data:`SETTLED_S` after the ramp to ``hold_s`` (the bench: deflection imposed)."""
    dt = 1e-4
    t = np.arange(0.0, hold_s, dt)
    after = np.clip(t - rise_s, 0.0, None)
    e = np.clip(t / rise_s, 0.0, 1.0) * deflection_m + ringing_m * np.sin(40 * np.pi * after) * np.exp(-after / 0.1)
    force, _ = BushingBank([load_parameter_set(set_name).channel()]).run(e[:, None], dt)
    settled = int(round((rise_s + SETTLED_S) / dt))
    return float(force[-1, 0] / force[settled, 0] - 1.0)


def _direction(direction: str) -> DirectionDef:
    """``bushing.direction`` of the default car's vehicle file."""
    bushing, axis = direction.split(".")
    return next(b for b in load_vehicle(DEFAULT_VEHICLE).bushings if b.name == bushing).directions[axis]


def _loss(direction: str, lossier_law: bool) -> tuple[float, float]:
    """(tan δ, |K*| [N/mm]) at :data:`LOSS_AT` of ``direction``'s law in the vehicle file, or made lossier."""
    law = _direction(direction).channel()
    at = (np.array([LOSS_AT[0]]), np.array([LOSS_AT[1]]))
    k = first_harmonic(lossier(law, *LOSS_AT) if lossier_law else law, *at).k_complex_n_per_m[0]
    return float(k.imag / k.real), float(abs(k) / 1e3)


def _run(job: tuple[str, str, str | None, tuple]) -> tuple[str, dict]:
    """One experiment: (label, scenario, bushing model or None for the file's, vehicle values) →
    (label, the numbers and traces the report reads). A label ending in ``_slow`` ramps its rack
    step in :data:`SLOW_RISE_S`."""
    label, name, model, values = job
    scenario = load_scenario(name)
    if label.endswith("_slow"):
        scenario = with_case_values(scenario, {"rise_time_s": SLOW_RISE_S}, f"{name} ({label})")
    if label.startswith("toe_lag"):   # the toe's lag is a few milliseconds: sampled every one
        scenario = replace(scenario, output_rate_hz=1000.0)
    if model is not None:   # "file": the vehicle file's own laws, whatever the scenario says
        scenario = replace(scenario, bushing_model=None if model == "file" else model)
    # the default file leaves the beam's bending out (rigid): a bending run sets it
    bending = {"rear.beam_bending_stiffness": BEAM_BENDING_NM_PER_RAD} if "_bending" in label else {}
    path = THESIS_CAR if label.startswith("thesis_car") else DEFAULT_VEHICLE
    text = path.read_text()
    if label.startswith("equations_"):   # figs. 5.8-5.9 as the equations read them, for the file's captions'
        text = re.sub(r"\bfig5_([89])_caption\b", r"fig5_\1", text)
    vehicle = vehicle_with(text, path, {**dict(values), **bending}, label)
    if not bending and vehicle.rear.beam_bending_stiffness is not None:
        raise RuntimeError(f"{DEFAULT_VEHICLE}: the file bends its beam; the experiments without bending need it rigid")
    run = simulate(scenario, vehicle)
    steps = scenario.type in ("rack_step", "double_rack_step") and not label.startswith("toe_lag")
    # a step's own relaxation: the run's change over the hold less its control's, the same run
    # without the last step (the car settling under its bushings, the first of two steps relaxing)
    control = simulate(scenario.without_last_steps(), vehicle) if steps else None
    out: dict = {}
    for c in cases(run):
        k, on = c["case"], case_mask(run, c)
        r: dict = {"label": c["label"]}
        if scenario.type in ("pumping", "roll", "lateral_force"):
            driver = "pad_fy_fl" if scenario.type == "lateral_force" else "pad_height_fl"
            x = driver if scenario.type == "lateral_force" else "pad_height_fl"
            for y in ("camber_fl", "toe_fl", "camber_rr"):
                loop = case_loop(run, c, "pad_height_rr" if y.endswith("rr") else x, y,
                                 "pad_height_rr" if y.endswith("rr") else driver)
                r[f"{y}_loop_deg"] = None if loop is None else loop.width
            r["camber_rr_range_deg"] = float(np.ptp(run.signals["camber_rr"][on]))
            z = run.signals["e1_rear_right_z_deflection"][on]
            r["e1_rear_z_pp_mm"] = float(np.ptp(z))
            # how far the test works each front ladder direction: half its peak to peak [mm]
            r["amplitude_mm"] = {d: float(np.ptp(run.signals[d.replace(".", "_left_") + "_deflection"][on]) / 2)
                                 for d in FRONT_LADDERS}
            last = case_mask(run, c, last_cycle=True)
            r["trace"] = {s: run.signals[s][last][::5].tolist() for s in (x, "camber_fl", "toe_fl")}
        elif control is None:   # a toe-lag run: the toe behind the rack, from rest to the transient's end
            r["toe_lag_ms"] = [1e3 * case_lag_s(run, c, "toe_fl", "rack", share, SETTLED_S) for share in LAG_AT]
        else:
            t = run.t_s[on] - c["input_start_s"]
            hold = c["hold_from_s"] - c["input_start_s"]
            settled = np.searchsorted(t, hold + SETTLED_S)
            # the last sample at rest: the ramp's first sample already kicks the corner (+12 N)
            rest = int(np.searchsorted(run.t_s, c["input_start_s"]))
            for s in ("e2_front_left_y_force", "e2_front_left_y_deflection", "toe_fl"):
                y, y0 = run.signals[s][on], control.signals[s][on]
                r[f"{s}_relax"] = case_relaxation(run, c, s)                  # from the hold's start
                r[f"{s}_settled_relax"] = float(y[-1] - y[settled])           # after the transient
                r[f"{s}_settled_control"] = float(y0[-1] - y0[settled])
                r[f"{s}_settled_own"] = r[f"{s}_settled_relax"] - r[f"{s}_settled_control"]
                r[f"{s}_static"] = float(run.signals[s][rest])
                r[f"{s}_step"] = float(y[-1] - r[f"{s}_static"])
                r[f"{s}_own_step"] = float((y - y0)[settled])   # the last step's (0 before it)
                r[f"{s}_ringing"] = float(np.ptp(y[(t >= hold) & (t < hold + SETTLED_S)]))
            # figs. 4.33-4.34: what the rear pivot bushing sees of the step (its largest direction)
            for q in ("force", "deflection"):
                r[f"e1_rear_{q}_ptp"] = max(float(np.ptp(run.signals[f"e1_rear_left_{d}_{q}"][on])) for d in "xyz")
            keep = t >= -0.5
            r["trace"] = {"t": t[keep][::4].tolist(),
                          **{s: run.signals[s][on][keep][::4].tolist() for s in ("e2_front_left_y_force", "toe_fl")}}
        out[k] = r
    return label, out


def jobs() -> list[tuple[str, str, str | None, tuple]]:
    """The experiments: (label, scenario, bushing model or None for the file's, vehicle values)."""
    vehicle = load_vehicle(DEFAULT_VEHICLE)
    lossy = {d: lossier_places(vehicle, d, *LOSS_AT) for d in FRONT_LADDERS}
    every = {k: v for values in lossy.values() for k, v in values.items()}
    # the control: E1 front's lateral law (an STS) with its stiffnesses and thresholds scaled, so that
    # its force is SOFTER times its own at every deflection: the same loss factor, a softer part
    law = load_parameter_set(_direction("e1_front.y").set_name)
    softer = tuple((f"bushings.e1_front.y.{k}", SOFTER * law.values[k]) for k in ("K0", "Kpa", "Kr", "Ff"))
    return JOBS + [(f"lateral_lossier_{d}", "lateral_force", None, tuple(lossy[d].items())) for d in FRONT_LADDERS] \
        + [("lateral_lossier_front", "lateral_force", None, tuple(every.items())),
           ("lateral_softer_e1_front.y", "lateral_force", None, softer)]


JOBS = [
    ("pumping_stvs", "pumping", "stvs", ()),
    ("speeds_stvs", "pumping_speeds", "stvs", ()),
    ("speeds_rt", "pumping_speeds", "rt", ()),
    ("speeds_stvs_no_dampers", "pumping_speeds", "stvs", tuple(NO_DAMPERS.items())),
    ("speeds_stvs_bending", "pumping_speeds", "stvs", ()),
    ("speeds_stvs_bending_no_dampers", "pumping_speeds", "stvs", tuple(NO_DAMPERS.items())),
    ("speeds_sts", "pumping_speeds", "sts", ()),
    ("speeds_sts_no_dampers", "pumping_speeds", "sts", tuple(NO_DAMPERS.items())),
    ("speeds_linear", "pumping_speeds", "linear", ()),
    ("speeds_linear_no_dampers", "pumping_speeds", "linear", tuple(NO_DAMPERS.items())),
    ("roll_stvs", "roll", "stvs", ()),
    ("lateral_file", "lateral_force", None, ()),
    ("rack_stvs", "rack_step", "stvs", ()),
    ("rack_rt", "rack_step", "rt", ()),
    ("rack_stvs_slow", "rack_step", "stvs", ()),
    ("rack_file", "rack_step", "file", ()),
    ("rack_file_linear_dashpots", "rack_step", "file", tuple((f"bushings.e2_front.{d}.pw", 1.0) for d in "xyz")),
    ("double_same_stvs", "double_rack_step_same", "stvs", ()),
    ("double_opposite_stvs", "double_rack_step_opposite", "stvs", ()),
    ("rack_rt_slow", "rack_step", "rt", ()),
    ("lateral_stvs", "lateral_force", "stvs", ()),
    # fig. 4.31 with the thesis's own two parts: E1 front's radial law fig. 5.7's (the file's) or fig. 5.6's
    ("lateral_part_fig5_6", "lateral_force", None,
     tuple((f"bushings.e1_front.{d}.{k}", v) for d in "yz" for k, v in load_parameter_set("fig5_6").values.items())),
    # figs. 5.8 and 5.9 as the equations read them (fig5_8, fig5_9) in place of the captions' (the car file's)
    *[(f"equations_{label}", name, law, ()) for label, name, law in (
        ("speeds_stvs", "pumping_speeds", "stvs"), ("speeds_rt", "pumping_speeds", "rt"),
        ("rack_stvs_slow", "rack_step", "stvs"), ("rack_rt_slow", "rack_step", "rt"))],
    # the thesis's car (tools/thesis_car.py): its own laws, lossy STVS on the 18 principal directions
    *[(f"thesis_car_{label}", name, "file", ()) for label, name in (
        ("pumping", "pumping"), ("speeds", "pumping_speeds"), ("lateral", "lateral_force"), ("rack_slow", "rack_step"),
        ("double_same_slow", "double_rack_step_same"), ("double_opposite_slow", "double_rack_step_opposite"))],
    ("toe_lag_linear", "rack_step", "linear", ()),
    ("toe_lag_stvs", "rack_step", "stvs", ()),
    *[(f"double_{way}_{law}_slow", f"double_rack_step_{way}", law, ())
      for way in ("same", "opposite") for law in ("stvs", "rt")],
]


def _stiffness_change(direction: str, amplitudes_mm: list[float]) -> list[float]:
    """The change of |K*| at 0.1 Hz [%] of ``direction``'s law made lossier, at each amplitude [mm]."""
    law = _direction(direction).channel()
    a, f = np.array(amplitudes_mm) * 1e-3, np.full(len(amplitudes_mm), LOSS_AT[1])
    before, after = (first_harmonic(x, a, f).k_dyn_n_per_m for x in (law, lossier(law, *LOSS_AT)))
    return [float(100.0 * (y / x - 1.0)) for x, y in zip(before, after)]


def _relaxed(case: dict, signal: str = "e2_front_left_y_force") -> float:
    """How much a rack step's last step changes ``signal`` after its transient, its control's change
    taken away [% of that step's own change, > 0 towards its start]."""
    return -100.0 * case[f"{signal}_settled_own"] / case[f"{signal}_own_step"]


def _fmt(v: float | None, digits: int = 4) -> str:
    return "—" if v is None else f"{v:.{digits}f}"


def _speed_rows(r: dict, keys: list[str], quantity: str) -> list[str]:
    rows = []
    for key in keys:
        w = [r[key][c][quantity] for c in (1, 2, 3)]
        change = 100 * (w[2] / w[0] - 1) if w[0] else float("nan")
        shown = f"{change:+.0f} %" if w[0] >= 1e-3 else "—"   # no percentage of a loop that is not there
        rows.append(f"| {key.removeprefix('speeds_').replace('_', ' ')} | " + " | ".join(_fmt(x) for x in w)
                    + f" | {shown} |")
    return rows


def _plots(r: dict, out: Path) -> dict[str, str]:
    files = {}
    fig, ax = plt.subplots(figsize=(6, 4), constrained_layout=True)
    for c in (1, 2, 3):
        tr = r["speeds_stvs"][c]["trace"]
        x, y = np.array(tr["pad_height_fl"]), np.array(tr["camber_fl"])
        # the kinematic curve (a cubic through the cycle) taken away, so that the loop shows
        ax.plot(x, 1e3 * (y - np.polyval(np.polyfit(x, y, 3), x)), lw=0.8, label=r["speeds_stvs"][c]["label"])
    ax.set_xlabel("front left pad height [mm]")
    ax.set_ylabel("front left camber − its cubic fit [mdeg]")
    ax.set_title("Pumping 60 mm at three speeds, STVS everywhere (cf. fig. 4.30)")
    ax.legend()
    ax.grid(alpha=0.3)
    files["speeds"] = "pumping_speeds_camber.png"
    fig.savefig(out / files["speeds"], dpi=110)
    plt.close(fig)
    fig, axes = plt.subplots(2, 1, figsize=(6, 5.5), sharex=True, constrained_layout=True)
    for label in ("rack_stvs", "rack_rt", "double_same_stvs", "double_opposite_stvs"):
        tr = r[label][1]["trace"]
        axes[0].plot(tr["t"], tr["e2_front_left_y_force"], lw=0.8, label=label.replace("_", " "))
        axes[1].plot(tr["t"], tr["toe_fl"], lw=0.8)
    axes[0].set_ylabel("E2 front left, y force [N]")
    axes[1].set_ylabel("front left toe [deg]")
    axes[1].set_xlabel("time since the rack input [s]")
    axes[0].legend(fontsize=8)
    for ax in axes:
        ax.grid(alpha=0.3)
    fig.suptitle("Rack steps: a ringing transient, then almost nothing (cf. figs. 4.32–4.39)")
    files["rack"] = "rack_steps.png"
    fig.savefig(out / files["rack"], dpi=110)
    plt.close(fig)
    return files


def report(r: dict, files: dict[str, str]) -> str:
    """The Markdown report of the experiments' results ``r``."""
    p = r["pumping_stvs"]
    pp = [p[c]["e1_rear_z_pp_mm"] for c in sorted(p)]
    amps = [p[c]["label"] for c in sorted(p)]
    toe = {label: [r[label][c]["toe_fl_loop_deg"] for c in sorted(r[label])] for label in r if label.startswith("lateral_")}
    change = {label[len("lateral_lossier_"):]: [100.0 * (w / f - 1.0) for w, f in zip(widths, toe["lateral_file"])]
              for label, widths in toe.items() if label.startswith("lateral_lossier_")}
    carrier = max(FRONT_LADDERS, key=lambda d: min(change[d]))
    others = max(max(change[d]) for d in FRONT_LADDERS if d != carrier)
    loss = {d: (_loss(d, False), _loss(d, True)) for d in FRONT_LADDERS}
    worked = {d: [r["lateral_file"][c]["amplitude_mm"][d] for c in sorted(r["lateral_file"])] for d in FRONT_LADDERS}
    kept = {d: _stiffness_change(d, worked[d]) for d in FRONT_LADDERS}
    softer = [100.0 * (w / f - 1.0) for w, f in zip(toe["lateral_softer_e1_front.y"], toe["lateral_file"])]
    roll_rear = [r["roll_stvs"][c]["camber_rr_loop_deg"] for c in sorted(r["roll_stvs"])]
    speeds_rear = [r["speeds_stvs"][c]["camber_rr_loop_deg"] for c in (1, 2, 3)]
    bent_rear = [r["speeds_stvs_bending"][c]["camber_rr_loop_deg"] for c in (1, 2, 3)]
    bent_rear_free = [r["speeds_stvs_bending_no_dampers"][c]["camber_rr_loop_deg"] for c in (1, 2, 3)]
    rigid_range, bent_range = (r[label][1]["camber_rr_range_deg"] for label in ("speeds_stvs", "speeds_stvs_bending"))
    stvs_fl = [r["speeds_stvs"][c]["camber_fl_loop_deg"] for c in (1, 2, 3)]
    # RT's camber loop against STVS's at 1.5 mm/s [%], figs. 5.8-5.9 as the captions and as the equations read them
    rt_thicker = tuple(100 * (r[f"{reading}speeds_rt"][1]["camber_fl_loop_deg"]
                              / r[f"{reading}speeds_stvs"][1]["camber_fl_loop_deg"] - 1) for reading in ("", "equations_"))
    thesis_loss = thesis_car_loss()
    file_loss = [loss[d][0][0] for d in FRONT_LADDERS]
    lines = [
        "# The thesis's vehicle-level phenomena, reproduced",
        "",
        "Bourgeteau 2009, chapter 4, §4.4.1 (figures 4.28–4.41), against the default car "
        "(`models/vehicles/c_segment.yaml`) on the virtual K&C rig, and at the end against the thesis's car "
        "(`models/vehicles/c_segment_thesis.yaml`: lossy STVS on its 18 principal directions). Generated by "
        "`python tools/thesis_reproduction.py`; every number below comes from that run. The thesis's "
        "statements are paraphrased from the French; it gives shapes, not numbers, so the verdicts "
        "compare directions and orders of size.",
        "",
        "## The thesis's numbers",
        "",
        "The numbers the thesis does give (chapters 3 to 6), each beside this project's and held by the "
        "test named (`tools/thesis_numbers.py`; the bench rows in detail in `identification.md`):",
        "",
        *thesis_numbers.HEADER,
        *thesis_numbers.bench_rows(),
        *thesis_numbers.car_rows((pp[2] / pp[0], pp[2] / pp[1]), rt_thicker, 100 * (stvs_fl[2] / stvs_fl[0] - 1),
                                 (min(file_loss), max(file_loss)), thesis_loss),
        "",
        "## Fig. 4.28 — the E1 rear bushing follows the pumping triangle",
        "",
        "Thesis: in pumping, the rubber bushings see triangles of deflection whose amplitude follows the "
        "amplitude of the triangle at the wheel base (E1 rear, STVS). The caption says 10 and 30 mm; the "
        "plot's own title says « en pompage à 20 et 30 mm »: both pairs are read below.",
        "",
        "Scenario `pumping` (0.1 Hz triangles, 10 … 60 mm), STVS on every direction. Peak-to-peak radial "
        "(z) deflection of the right E1 rear bushing:",
        "",
        "| pumping | " + " | ".join(amps) + " |",
        "|---|" + "---|" * len(amps),
        "| E1 rear z deflection, peak to peak [mm] | " + " | ".join(_fmt(v, 3) for v in pp) + " |",
        "",
        f"**Agrees with both readings.** The deflection grows with the amplitude, nearly in proportion "
        f"(30 mm / 10 mm: {pp[2] / pp[0]:.2f}, 3 if proportional; 30 mm / 20 mm: {pp[2] / pp[1]:.2f}, 1.5 if "
        "proportional).",
        "",
        "## Fig. 4.29 — RT against STVS: the camber loop",
        "",
        "Thesis: the two laws identified on the same bushing keep the loop's general shape, but RT gives a "
        "clearly thicker camber loop (more dissipation).",
        "",
        "Scenario `pumping_speeds` (60 mm), every direction RT (family set fig5_8_caption) or STVS (fig5_9_caption), "
        "front left camber loop width at design height [deg]:",
        "",
        "| law | 1.5 mm/s | 3 mm/s | 15 mm/s | 1.5 → 15 mm/s |",
        "|---|---|---|---|---|",
        *_speed_rows(r, ["speeds_rt", "speeds_stvs"], "camber_fl_loop_deg"),
        "",
        f"**Agrees in direction, far smaller in size.** RT's loop is thicker by "
        f"{100 * (r['speeds_rt'][1]['camber_fl_loop_deg'] / r['speeds_stvs'][1]['camber_fl_loop_deg'] - 1):.1f} % "
        "at 1.5 mm/s. The two family sets share K0, Kpa and Kr (figs. 5.8 and 5.9 were identified on the "
        "same bench loops), so at quasi-static speeds they dissipate nearly the same energy per cycle; the "
        "thesis's RT was identified separately and gives no number to compare. With the sets as the equations "
        "read figs. 5.8–5.9 (below, \"Figs. 5.8–5.9 read two ways\"), RT's loop is "
        f"{rt_thicker[1]:.0f} % "
        "thicker: the thesis's clear difference.",
        "",
        "## Fig. 4.30 — the camber loop against the pumping speed",
        "",
        "Thesis: with 60 mm of pumping at 1.5, 3 and 15 mm/s, the thickness of the camber loop changes "
        "with the speed (it does not say in which direction), with numerical instabilities at the fastest.",
        "",
        f"![camber loops at three speeds]({files['speeds']})",
        "",
        "Front left camber loop width [deg], the same scenario with the experiments that find the cause:",
        "",
        "| car | 1.5 mm/s | 3 mm/s | 15 mm/s | 1.5 → 15 mm/s |",
        "|---|---|---|---|---|",
        *_speed_rows(r, ["speeds_stvs", "speeds_stvs_no_dampers", "speeds_sts", "speeds_sts_no_dampers",
                         "speeds_linear", "speeds_linear_no_dampers"], "camber_fl_loop_deg"),
        "",
        "**Agrees: the loop's thickness changes with the speed; here it thins as the speed rises**, and the "
        "experiments say why. With a rate-independent law (STS) and no dampers the loop does not depend on the "
        "speed: the rig and the car's inertia add nothing. The dampers make a loop of their own, which grows "
        "with the speed (the linear car's row) and runs the other way round from the bushings' sliders: the "
        "two widths subtract rather than add (STS at 15 mm/s: "
        f"{_fmt(r['speeds_sts_no_dampers'][3]['camber_fl_loop_deg'])} − "
        f"{_fmt(r['speeds_linear'][3]['camber_fl_loop_deg'])} against "
        f"{_fmt(r['speeds_sts'][3]['camber_fl_loop_deg'])} with both). STVS's own viscous branch thins the "
        "loop too (without dampers). The loops are smooth at every speed: the thesis observes numerical "
        "instabilities at the fastest (§4.4.1) without naming their cause; they likely came from its own "
        "integration of the laws, an explicit Euler without error corrector inside Adams's VARSUB routine "
        "(§3.4.3, §3.5.2); here they are stepped implicitly.",
        "",
        "The rear (twist-beam) camber loop [deg] is "
        + ", ".join(_fmt(v, 5) for v in speeds_rear)
        + " at the three speeds: **cannot be compared** on this car. In pumping both wheels move together: "
        "the moments of the two wheels' loads about the pivots are mirror images that the beam, rigid in "
        "bending here, carries between its arms, so the pivot bushings do not rotate and the wheels do not "
        "camber relative to the body beyond the kinematics. In roll, where the beam twists, the rear camber "
        "loop is " + ", ".join(_fmt(v, 5) for v in roll_rear) + " deg over the roll amplitudes: the rear "
        "bushings do make a loop once the beam lets the arms move apart. A rear camber loop in pumping needs "
        "a beam that bends, as a flexible twist beam in Adams would. The experiment: the same car with its "
        f"beam bending about x at {BEAM_BENDING_NM_PER_RAD / 1e3:.0f} kN·m/rad (`rear.beam_bending_stiffness`; "
        "EI/L of a 1.2 m cross member of EI ≈ 6·10⁴ N·m², an assumption: the thesis gives no figure) "
        "cambers the rear wheels by " + _fmt(bent_range, 3) + " deg over the pumping (against "
        + _fmt(rigid_range, 3) + " rigid), and its camber loop [deg] is "
        + ", ".join(_fmt(v, 5) for v in bent_rear) + " at the three speeds ("
        + ", ".join(_fmt(v, 5) for v in bent_rear_free) + " without dampers): "
        + ("**with a bending beam the rear loop changes with the speed, as in the thesis**"
           + (", thinning as the speed rises as the front loop does (the dampers' loop against the bushings')"
              if bent_rear[2] < bent_rear[0] < bent_rear_free[0] else "")
           + "; the default car keeps its beam rigid, having no measured bending stiffness to give it."
           if max(bent_rear) > 1.2 * min(bent_rear) and min(bent_rear) > 20 * max(speeds_rear) else
           "even with a bending beam the rear loop hardly changes with the speed."),
        "",
        "## Fig. 4.31 — toe against lateral force, two bushings of different loss",
        "",
        "Thesis: with STVS identified on two bushings of different loss tangent, the toe loop under lateral "
        "force (50 to 300 daN) changes a lot: the lossier bushing dissipates more.",
        "",
        "Scenario `lateral_force`, the vehicle file's laws, and the same with the law of one front "
        "bushing direction (or of all five front directions with ladder laws) made lossier: its ladder twice "
        "as stiff and its linear spring lowered to keep |K*| at 0.2 mm and 0.1 Hz (`elastokin.bushings.frequency.lossier`; "
        "tan δ there " + ", ".join(f"{d} {a[0]:.3f} → {b[0]:.3f}" for d, (a, b) in loss.items() if d.endswith(".y"))
        + "). Where the test works them the stiffness moves too: E1 front y, worked at "
        f"{min(worked['e1_front.y']):.2f}–{max(worked['e1_front.y']):.2f} mm, is "
        f"{-max(kept['e1_front.y']):.1f}–{-min(kept['e1_front.y']):.1f} % softer; E2 front's directions, "
        f"worked at {min(min(worked[d]) for d in FRONT_LADDERS if d.startswith('e2')):.3f}–"
        f"{max(max(worked[d]) for d in FRONT_LADDERS if d.startswith('e2')):.2f} mm, up to "
        f"{max(max(kept[d]) for d in FRONT_LADDERS if d.startswith('e2')):.0f} % stiffer. Front left toe loop "
        "width [deg], and its change with the lossier law:",
        "",
        "| lossier law in | " + " | ".join(r["lateral_file"][c]["label"] for c in sorted(r["lateral_file"])) + " |",
        "|---|" + "---|" * len(toe["lateral_file"]),
        "| — (the vehicle file's laws) | " + " | ".join(_fmt(v, 5) for v in toe["lateral_file"]) + " |",
        *[f"| {'every front ladder' if d == 'front' else d} | "
          + " | ".join(f"{_fmt(w, 5)} ({c:+.1f} %)" for w, c in zip(toe[f"lateral_lossier_{d}"], change[d])) + " |"
          for d in (*FRONT_LADDERS, "front")],
        "",
        (f"**Agrees, once the bushing that carries the loop is the lossier one.** The toe loop under lateral "
         f"force is carried by {carrier}: its law made lossier widens the loop by {min(change[carrier]):.0f} to "
         f"{max(change[carrier]):.0f} %; any other front direction alone by {others:.1f} % at most (E2 front's "
         f"lateral direction by {max(change['e2_front.y']):.1f} %). It is the loss, not the softening that "
         f"comes with it: the control, E1 front y's force {100 * (1 - SOFTER):.0f} % lower at every deflection (its "
         f"loss factor unchanged), widens the loop by {min(softer):.0f} to {max(softer):.0f} % only. Every front ladder "
         f"lossier, as the thesis swapped the identified laws of whole bushings: {min(change['front']):.0f} to "
         f"{max(change['front']):.0f} %, the large change the thesis shows (it gives no numbers)."
         if min(change["front"]) > 20.0 else
         f"**Disagrees in size**: every front ladder lossier widens the toe loop by {min(change['front']):.1f} "
         f"to {max(change['front']):.1f} % only."),
        "",
        *_steps_section(r, files),
        "",
        *_readings_section(r, rt_thicker),
        "",
        *_thesis_car_section(r, thesis_loss),
    ]
    return "\n".join(lines)


def thesis_car_loss() -> tuple[float, float]:
    """The range of tan δ at PSA's specification point (15 Hz, 1 mm) over the thesis car's STVS laws."""
    at = (np.array([1e-3]), np.array([15.0]))
    laws = [d.channel() for b in load_vehicle(THESIS_CAR).bushings for d in b.directions.values() if d.model == "stvs"]
    loss = [float(first_harmonic(law, *at).tan_delta[0]) for law in laws]
    return min(loss), max(loss)


def _readings_section(r: dict, thicker: tuple[float, float]) -> list[str]:
    """The report's section on figs. 5.8-5.9's two readings (captions, equations) at the car level;
    ``thicker``: RT's camber loop against STVS's at 1.5 mm/s [%], each reading."""
    at = (np.array([1e-3]), np.array([1.0]))
    bench = {name: first_harmonic(load_parameter_set(name).channel(), *at)
             for name in ("fig5_9_caption", "fig5_8_caption", "fig5_9", "fig5_8")}
    rows = []
    for reading, prefix, suffix in (("the captions' (fig5_9_caption, fig5_8_caption)", "", "_caption"),
                                    ("the equations' (fig5_9, fig5_8)", "equations_", "")):
        stvs, rt = (bench[f"fig5_{n}{suffix}"] for n in (9, 8))
        loop = {law: [r[f"{prefix}speeds_{law}"][c]["camber_fl_loop_deg"] for c in (1, 2, 3)] for law in ("stvs", "rt")}
        relax = {law: _relaxed(r[f"{prefix}rack_{law}_slow"][1]) for law in ("stvs", "rt")}
        rows.append(f"| {reading} | {stvs.k_dyn_n_per_m[0] / 1e3:.0f} / {stvs.tan_delta[0]:.3f} | "
                    f"{rt.k_dyn_n_per_m[0] / 1e3:.0f} / {rt.tan_delta[0]:.3f} | "
                    f"{_fmt(loop['stvs'][0])} / {_fmt(loop['rt'][0])} ({_change(loop['rt'][0], loop['stvs'][0])}) | "
                    f"{_change(loop['stvs'][2], loop['stvs'][0])} / {_change(loop['rt'][2], loop['rt'][0])} | "
                    f"{relax['stvs']:.2f} / {relax['rt']:.2f} % |")
    return [
        "## Figs. 5.8–5.9 read two ways: the car-level consequences",
        "",
        "The captions of figs. 5.8 and 5.9 and the equations of §5.2.5 (eqs. 3.16, 3.24, 5.10 and the sentence "
        "on pure hysteresis) give different parameter sets (the opening table; each set's `source` says why). "
        "Both readings on the default car, every direction read as the family's law: the bench figures at "
        f"1 Hz, 1 mm, fig. 4.29's RT against STVS camber loop at 1.5 mm/s, fig. 4.30's trend from 1.5 to 15 "
        f"mm/s, and the rack step's own relaxation (10 mm ramped in {SLOW_RISE_S:g} s, E2 front y force, "
        "after the transient):",
        "",
        "| reading | STVS K_dyn [N/mm] / tan δ | RT K_dyn [N/mm] / tan δ | camber loop STVS / RT [deg] | "
        "1.5 → 15 mm/s, STVS / RT | rack step relaxation, STVS / RT |",
        "|---|---|---|---|---|---|",
        *rows,
        "",
        "The equations' reading gives the STVS slider 80 % of the STS threshold (25 % in the captions') and "
        "RT the whole of it at V0: the STVS law is less viscous, RT nearly as before. "
        + (f"**With it, fig. 4.29 agrees in size too**: RT's camber loop is {thicker[1]:.0f} % thicker than "
           f"STVS's, against {thicker[0]:.0f} % with the captions' sets: the thesis's difference « bien nette »; and "
           "the STVS law hardly relaxes after a rack step, RT does." if thicker[1] > 3 * max(thicker[0], 1.0) else
           f"RT's camber loop is {thicker[1]:.0f} % thicker than STVS's with it, {thicker[0]:.0f} % with the captions'."),
        "",
        "The named sets `fig5_8` and `fig5_9` hold the equations' reading; `fig5_8_caption` and `fig5_9_caption` the "
        "captions'. The default car keeps the captions' as its family sets and on E2 front (so do the sections "
        f"above): the lossier reading (STVS tan δ {bench['fig5_9_caption'].tan_delta[0]:.2f} against "
        f"{bench['fig5_9'].tan_delta[0]:.2f}), nearer the lossy bushings the thesis ran (§4.4.1), and the baseline "
        "its shipped datasets, their truths and the diagnosis's observability floors were made with.",
    ]


def _change(new: float, old: float) -> str:
    return f"{100.0 * (new / old - 1.0):+.0f} %"


def _thesis_car_section(r: dict, loss: tuple[float, float]) -> list[str]:
    """The report's section on the thesis's car: chapter 4's experiments on it beside the default car
    (``loss``: :func:`thesis_car_loss`)."""
    at = (np.array([1e-3]), np.array([15.0]))
    family = float(first_harmonic(load_parameter_set("fig5_9_caption").channel(), *at).tan_delta[0])
    pp = {car: [r[label][c]["e1_rear_z_pp_mm"] for c in sorted(r[label])]
          for car, label in (("default", "pumping_stvs"), ("thesis", "thesis_car_pumping"))}
    cam = {car: [r[label][c]["camber_fl_loop_deg"] for c in (1, 2, 3)]
           for car, label in (("default", "speeds_stvs"), ("thesis", "thesis_car_speeds"))}
    toe = {label: [r[label][c]["toe_fl_loop_deg"] for c in sorted(r[label])]
           for label in ("lateral_stvs", "thesis_car_lateral", "lateral_file", "lateral_part_fig5_6")}
    f = "e2_front_left_y_force"
    rack = {car: r[label][1] for car, label in (("default", "rack_stvs_slow"), ("thesis", "thesis_car_rack_slow"))}
    double = {(car, way): r[f"{prefix}double_{way}{suffix}_slow"][1] for car, prefix, suffix in
              (("default", "", "_stvs"), ("thesis", "thesis_car_", "")) for way in ("same", "opposite")}
    part = [100.0 * (b / a - 1.0) for a, b in zip(toe["lateral_file"], toe["lateral_part_fig5_6"])]
    thicker = all(t > d for t, d in zip(cam["thesis"], cam["default"]))
    return [
        "## The thesis's car: lossy STVS on its 18 principal directions (§4.4)",
        "",
        "The thesis ran chapter 4 on a 307 \"comportant des articulations d'angle de perte élevé\" (§4.4), STVS on "
        "the three principal directions of E1 and E2 front and E1 rear (18 models), identified on a part of "
        "tan δ 0.3 (§4.4.1). `models/vehicles/c_segment_thesis.yaml` (written by `tools/thesis_car.py`) is the "
        "default car with each of those directions' laws read as STVS (fig. 5.9's shape at the direction's own "
        f"K0; tan δ {family:.3f} at 15 Hz, 1 mm) made lossier to tan δ {thesis_numbers.span(*loss)} there, PSA's "
        "specification point (§2.1.1), with |K*| there kept; the rotations keep the default car's linear laws. "
        "The same experiments on both, the default car with STVS everywhere (`--bushing-model stvs`), the "
        "thesis car with its own laws:",
        "",
        "| figure | quantity | default car, STVS | thesis car | verdict |",
        "|---|---|---|---|---|",
        f"| 4.28 | E1 rear z deflection, 30 mm / 10 mm; 30 / 20 mm | {pp['default'][2] / pp['default'][0]:.2f}; "
        f"{pp['default'][2] / pp['default'][1]:.2f} | {pp['thesis'][2] / pp['thesis'][0]:.2f}; "
        f"{pp['thesis'][2] / pp['thesis'][1]:.2f} | agrees on both: the deflection follows the amplitude |",
        f"| 4.30 | front left camber loop at 1.5 / 3 / 15 mm/s [deg] | {' / '.join(_fmt(v) for v in cam['default'])} "
        f"| {' / '.join(_fmt(v) for v in cam['thesis'])} | "
        + ("agrees: the lossier car's loop is thicker at every speed "
           f"({_change(cam['thesis'][0], cam['default'][0])} at 1.5 mm/s) and still changes with the speed "
           f"({_change(cam['thesis'][2], cam['thesis'][0])} from 1.5 to 15 mm/s)" if thicker else
           "the lossier car's loop is not thicker at every speed") + " |",
        f"| 4.31 | front left toe loop at the smallest / largest lateral force [deg] | {_fmt(toe['lateral_stvs'][0], 5)} / {_fmt(toe['lateral_stvs'][-1], 5)} | "
        f"{_fmt(toe['thesis_car_lateral'][0], 5)} / {_fmt(toe['thesis_car_lateral'][-1], 5)} | the lossier car's "
        f"loop {_change(toe['thesis_car_lateral'][0], toe['lateral_stvs'][0])} / "
        f"{_change(toe['thesis_car_lateral'][-1], toe['lateral_stvs'][-1])}: a large change, as the thesis shows |",
        "| 4.31, the thesis's two parts | the same toe loop on the default car with its file's laws, E1 front's "
        f"radial law fig. 5.7's (the file's) or fig. 5.6's | fig. 5.7: {_fmt(toe['lateral_file'][0], 5)} / "
        f"{_fmt(toe['lateral_file'][-1], 5)} | fig. 5.6: {_fmt(toe['lateral_part_fig5_6'][0], 5)} / "
        f"{_fmt(toe['lateral_part_fig5_6'][-1], 5)} | a large change, {min(part):+.0f} to {max(part):+.0f} %; the "
        "two parts differ in stiffness (K0 1363 against 508 N/mm) more than in loss, so it mixes both |",
        f"| 4.32 | E2 front y force, a 10 mm step ramped in {SLOW_RISE_S:g} s: its own relaxation after the transient "
        f"| {_relaxed(rack['default']):.2f} % | {_relaxed(rack['thesis']):.2f} % | "
        + ("agrees: the lossier bushings relax more" if _relaxed(rack["thesis"]) > _relaxed(rack["default"])
           else "disagrees: the lossier bushings relax less. Their loss was added by a stiffer ladder "
                "(`with_loss`), the viscous branch, which relaxes, kept; which form the thesis's part's loss "
                "took it does not say") + " |",
        f"| 4.35 | front left toe, the step's own change after the transient [deg] | "
        f"{rack['default']['toe_fl_settled_own']:+.1e} | {rack['thesis']['toe_fl_settled_own']:+.1e} | "
        "the wheel plane creeps with the bushing |",
        f"| 4.33, 4.34 | E1 rear, largest peak-to-peak force [N] / deflection [mm] over the rack step | "
        f"{rack['default']['e1_rear_force_ptp']:.3g} / {rack['default']['e1_rear_deflection_ptp']:.2g} | "
        f"{rack['thesis']['e1_rear_force_ptp']:.3g} / {rack['thesis']['e1_rear_deflection_ptp']:.2g} | "
        f"cannot be compared: on the clamped rig the rack hardly reaches the rear (E2 front's force step: "
        f"{rack['thesis'][f + '_step']:.0f} N); the thesis's E1 rear answered through a car free on its wheels |",
        "| 4.36–4.39 | second step's own relaxation, same way / back [% of its step] | "
        f"{_relaxed(double['default', 'same']):.1f} / {_relaxed(double['default', 'opposite']):.1f} | "
        f"{_relaxed(double['thesis', 'same']):.1f} / {_relaxed(double['thesis', 'opposite']):.1f} | "
        "fading memory on both: the second step relaxes after any history |",
        "| 4.41 | the rear axle's stiffness against the rig (too low in ADAMS) | — | — | cannot be compared: no "
        "measurement of the thesis's car is held; its suspected cause, the bushings' preload, is absent here "
        "too (every law starts from zero deflection at design) |",
    ]


def _lags(lags: list[float]) -> str:
    """Lags [ms] as the report writes them."""
    return ", ".join(f"{x:+.1f}" for x in lags)


def _span(double: dict, law: str) -> str:
    """The range of the second steps' own relaxation [% of the step] with ``law``, both ways."""
    shares = sorted(_relaxed(x) for (_, each), x in double.items() if each == law)
    return f"{shares[0]:.1f}–{shares[-1]:.1f} %"


def _steps_section(r: dict, files: dict[str, str]) -> list[str]:
    """The report's rack-step sections (figs. 4.32–4.39)."""
    rs, rr = r["rack_stvs"][1], r["rack_rt"][1]
    same, opp = r["double_same_stvs"][1], r["double_opposite_stvs"][1]
    slow, slow_rt = r["rack_stvs_slow"][1], r["rack_rt_slow"][1]
    bench = {name: _bench_relaxation(name) for name in ("fig5_9_caption", "fig5_8_caption")}
    ringing = {a: _bench_relaxation("fig5_9_caption", a * 1e-3) for a in (0.05, 0.15)}
    own, dashpots = r["rack_file"][1], r["rack_file_linear_dashpots"][1]
    f, d = "e2_front_left_y_force", "e2_front_left_y_deflection"
    rt_more = _relaxed(slow_rt) > _relaxed(slow)
    still = abs(rs[f + "_settled_relax"]) < 1e-3 * abs(rs[f + "_step"])   # the 50 ms step: nothing after
    lag = {law: r[f"toe_lag_{law}"][1]["toe_lag_ms"] for law in ("linear", "stvs")}
    added = [a - b for a, b in zip(lag["stvs"], lag["linear"])]
    rest_s = load_scenario("rack_step").settle.before_input_s
    double = {(way, law): r[f"double_{way}_{law}_slow"][1] for way in ("same", "opposite") for law in ("stvs", "rt")}
    follows = all(x[f"{f}_settled_own"] * x[f"{f}_own_step"] < 0.0 for x in double.values())
    return [
        "## Figs. 4.32, 4.35 — a rack step: the bushing relaxes, the toe lags",
        "",
        "Thesis: after a steering step the bushing force is a step followed by relaxation, more with RT than "
        "with STVS (4.32); the toe follows the step with a delay, which may slow the car's response (4.35).",
        "",
        f"![rack steps]({files['rack']})",
        "",
        f"Scenario `rack_step` (10 mm in 50 ms, held 5 s), and the same ramped in {SLOW_RISE_S} s. The "
        "step is taken from rest (the ramp's first sample already kicks the corner) to the hold's end "
        "(50 ms), or to the transient's end, the control's change taken away (smooth ramps); the "
        f"ringing is the peak-to-peak change in the {SETTLED_S} s after the ramp; the changes are taken "
        f"from then (the transient over) to the end of the hold: in the run, in its control (the same run "
        f"without the step: the car settling on bushing laws switched on {rest_s:g} s before the input), and the "
        "step's own (the run's less the control's), in % of the step given back (force) or crept on "
        "(deflection):",
        "",
        "| law, ramp | E2 front y force: step [N] | ringing [N] | after the transient [N] | control [N] | "
        "own [% of step] | E2 front y deflection: step [mm] | own creep [% of step] | toe: step [deg] | "
        "toe's own after the transient [deg] |",
        "|---|---|---|---|---|---|---|---|---|---|",
        *[f"| {name} | {x[f + '_own_step']:.1f} | {x[f + '_ringing']:.0f} | {x[f + '_settled_relax']:+.4f} | "
          f"{x[f + '_settled_control']:+.4f} | {_relaxed(x):+.2f} | {x[d + '_own_step']:.4f} | "
          f"{-_relaxed(x, d):+.1f} | {x['toe_fl_own_step']:.3f} | {x['toe_fl_settled_own']:+.1e} |"
          if smooth else
          f"| {name} | {x[f + '_step']:.1f} | {x[f + '_ringing']:.0f} | {x[f + '_settled_relax']:+.4f} | "
          f"{x[f + '_settled_control']:+.4f} | — | {x[d + '_step']:.4f} | — | {x['toe_fl_step']:.3f} | — |"
          for name, x, smooth in (("STVS, 50 ms", rs, False), ("RT, 50 ms", rr, False),
                                  (f"STVS, {SLOW_RISE_S} s", slow, True), (f"RT, {SLOW_RISE_S} s", slow_rt, True))],
        "",
        ("**Disagrees with the 50 ms ramp, " if still else "**Agrees with the 50 ms ramp, ")
        + ("agrees with a smooth one.** " if rt_more else "disagrees with a smooth one.** ")
        + "With the 50 ms ramp, what moves during the hold is the transient: the ramp rings a lightly damped "
        f"mode of the steered corner ({rs[f + '_ringing']:.0f} N peak to peak in the E2 front bushing), and "
        f"once it has died out, {SETTLED_S} s later, the force and the toe hardly move ({rs[f + '_settled_relax']:+.4f} N, "
        f"{rs['toe_fl_settled_relax']:+.1e} deg over 4.5 s), with either law, though without the step the "
        f"car itself still settles by {rs[f + '_settled_control']:+.3f} N over the same time: the ringing works "
        "off that creep too (so the control cannot be taken away from these runs: —). The law itself relaxes: on the bench, held at 0.3 mm after a 50 ms ramp, fig5_9_caption "
        f"loses {-100 * bench['fig5_9_caption']:.1f} % of its force and fig5_8_caption (RT) {-100 * bench['fig5_8_caption']:.1f} % "
        f"between {SETTLED_S} s and 6 s (RT more, as the thesis says). **The cause is the ringing**, found "
        "by three experiments. On the bench, the same step followed by a 20 Hz ringing that decays in 0.1 s, "
        f"as the corner's does, leaves {-100 * ringing[0.05]:.1f} % of relaxation after it with ±0.05 mm of "
        f"ringing and {abs(100 * ringing[0.15]):.1f} % with ±0.15 mm (the car's: "
        f"±{rs[d + '_ringing'] / 2:.2f} mm in E2 front's lateral direction): the oscillation works the "
        "ladder's viscous elements to their relaxed state within the transient. The viscous law's exponent "
        f"is not the cause: with the vehicle file's own laws, E2 front's force changes by "
        f"{own[f + '_settled_relax']:+.3f} N after the transient, and with linear dashpots (pw = 1) in E2 "
        f"front by {dashpots[f + '_settled_relax']:+.3f} N. Ramped in {SLOW_RISE_S} s, the step rings "
        f"{slow[f + '_ringing']:.0f} N peak to peak and relaxes after its transient, "
        f"**{'RT more than STVS' if rt_more else 'STVS more than RT'}**: its force gives back "
        f"{_relaxed(slow_rt):.2f} % of its step against {_relaxed(slow):.2f} %; its deflection creeps on by "
        f"{abs(slow_rt[d + '_settled_own']) * 1e3:.2f} µm against {abs(slow[d + '_settled_own']) * 1e3:.2f} µm "
        f"(of steps of {abs(slow_rt[d + '_own_step']) * 1e3:.1f} and {abs(slow[d + '_own_step']) * 1e3:.1f} µm). The "
        "control is what showed it: the run's own change mixes in the car settling under its static load "
        f"(E2 front y carries {abs(slow[f + '_static']):.0f} N), by {slow[f + '_settled_control']:+.3f} N "
        f"with STVS and {slow_rt[f + '_settled_control']:+.3f} N with RT over the same time, so that the run "
        f"alone had RT give back {-100 * slow_rt[f + '_settled_relax'] / slow_rt[f + '_step']:.1f} % of its step "
        f"against STVS's {-100 * slow[f + '_settled_relax'] / slow[f + '_step']:.1f} %. That the deflection creeps "
        f"{abs(_relaxed(slow, d) / _relaxed(slow)):.0f} times more than the force relaxes (in shares of the step) "
        "says how the bushing is loaded: through the corner, its force set by the rack and the wheel's "
        "contact, not held at a deflection as on the bench. Left to find: whether the 50 ms ramp's ringing is right, its damping "
        "against a measured rig (the thesis's response was smoothed, 'filtered by the suspension's structure "
        "and by Adams', and its 4.32 shows the relaxation that a smooth step leaves).",
        "",
        f"The toe lags the rack (4.35): sampled at 1 kHz, after the 50 ms ramp it reaches {LAG_AT[0]:.0%}, "
        f"{LAG_AT[1]:.0%} and {LAG_AT[2]:.0%} of its step {_lags(lag['stvs'])} ms after the rack with STVS "
        f"against {_lags(lag['linear'])} ms with linear bushings (the corner's inertia and its compliant "
        f"joints): " + ("**agrees in kind, small in size** — " if added[1] > 0.0 else "**disagrees** — ")
        + f"the laws change the lag by {_lags(added)} ms"
        + (" (a delay at half the step, none at its ends)" if added[1] > 0.0 and min(added) <= 0.0 else "")
        + f", and the toe's own change after the smooth step's transient is "
        f"{slow['toe_fl_settled_own']:+.1e} deg ({100 * abs(slow['toe_fl_settled_own'] / slow['toe_fl_own_step']):.0e} % "
        "of its step): the rack sets the toe through the tie rod, and E2 front's creep of "
        f"{abs(slow[d + '_settled_own']) * 1e3:.1f} µm barely turns the wheel. The thesis's delay, from a figure "
        "without numbers, cannot be compared in size.",
        "",
        "## Figs. 4.36–4.39 — two steps: fading memory",
        "",
        "Thesis: a first rack step, a rest, then a smaller second step in the same or the opposite "
        "direction: the response to the second step depends on the history, as fading memory has it.",
        "",
        "Scenarios `double_rack_step_same` (10 mm, then +5 mm) and `double_rack_step_opposite` (10 mm, then "
        f"−5 mm), STVS; after the second step: the change over the hold from {SETTLED_S} s on, and the force "
        "where each ends against the single 10 mm step's:",
        "",
        "| second step | E2 front y force after the transient [N] | toe after the transient [deg] | "
        "final force − single step's [N] |",
        "|---|---|---|---|",
        f"| same direction | {same[f + '_settled_relax']:+.4f} | {same['toe_fl_settled_relax']:+.1e} | "
        f"{same[f + '_step'] - rs[f + '_step']:+.2f} |",
        f"| opposite | {opp[f + '_settled_relax']:+.4f} | {opp['toe_fl_settled_relax']:+.1e} | "
        f"{opp[f + '_step'] - rs[f + '_step']:+.2f} |",
        "",
        "**Disagrees with the 50 ms ramps.** The two histories end at different forces (the sliders' "
        "hysteresis: memory, but a permanent one), and nothing fades afterwards: as after the single step, "
        "nothing creeps once the second step's transient is over. Fading memory needs that creep; the ringing "
        f"of each step works it off, as above. With every step ramped in {SLOW_RISE_S} s, the force does "
        "creep after the second step; its control here is the first step alone (the same run without the "
        "second), in which the first step's relaxation and the car's settling go on through the second hold:",
        "",
        "| law, second step | second step [N] | after the transient [N] | control: the first step alone [N] | "
        "the second step's own [N] | own [% of its step] |",
        "|---|---|---|---|---|---|",
        *[f"| {law.upper()}, {'the same way' if way == 'same' else 'back'} | {x[f + '_own_step']:+.2f} | "
          f"{x[f + '_settled_relax']:+.3f} | {x[f + '_settled_control']:+.3f} | {x[f + '_settled_own']:+.3f} | "
          f"{_relaxed(x):+.1f} |" for (way, law), x in double.items()],
        "",
        ("**With smooth steps it agrees in kind**: taken apart from what goes on from before it, the second "
         "step relaxes towards where it started, either way and with either law (RT, the law the thesis ran "
         f"these steps with, by {_span(double, 'rt')} of its step, STVS by {_span(double, 'stvs')}): what the "
         "force does after the second step is that relaxation added to what goes on from before it, the "
         "history the response depends on." if follows else
         "With smooth steps the second step's own creep does not always run back towards where it started."),
        "",
    ]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=ROOT / "tools" / "thesis", help="report folder")
    parser.add_argument("--scheduler", help="a Dask scheduler's address (default: a local cluster)")
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    todo = jobs()
    with executor(args.scheduler) as ex:
        print(f"{len(todo)} experiments on {ex.description}", file=sys.stderr)
        results = dict(ex.map(_run, todo))
    files = _plots(results, args.out)
    (args.out / "report.md").write_text(report(results, files), encoding="utf-8")
    print(f"wrote {args.out / 'report.md'} and {len(files)} PNGs")
    return 0


if __name__ == "__main__":
    sys.exit(main())
