"""What a K&C diagnosis tells an engineer: the JSON verdict, the extended vehicle file, and a
one-page markdown report with overlays before/after, the error per test against its amplitude and
static load, and the ranking with its evidence."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.figure import Figure

from elastokin.vehicle.model.definition import VehicleDefinition
from elastokin.core.files import atomic_output
from elastokin.diagnosis.catalogue import PAIR_SEPARATOR
from elastokin.diagnosis.kc_catalogue import Hypothesis, extended_vehicle_yaml, parameters
from elastokin.diagnosis.kc_diagnosis import KCDiagnosis
from elastokin.diagnosis.kc_hidden_cause import HIDDEN_ALPHA, HiddenCause
from elastokin.diagnosis.kc_misfits import Misfit
from elastokin.diagnosis.kc_fits import Candidate
from elastokin.diagnosis.kc_noise import coloured_noise
from elastokin.diagnosis.kc_rig_mechanics import BY_KEY, RIG
from elastokin.diagnosis.kc_transducers import INPUT_GAIN
from elastokin.diagnosis.verdict import MISFIT_CHANCE, NOISE_FACTOR, Separation
from elastokin.presentation.diagnosis_report import (Report, finite, partly_explained, ranking_chart,
                                                     separation_clause)
from elastokin.presentation.figures import save_figure
from elastokin.vehicle.scenarios.channels import channel_quantity

#: Channels overlaid in the report (the largest baseline mismatch on held-out tests first).
OVERLAYS = 4


def _parameters(d: KCDiagnosis, c: Candidate | None = None) -> dict[str, Any]:
    """A named cause's parameters (the first's, or ``c``'s), each with its uncertainty if it was
    fitted: the screening fits only the first, with a second held at mid-range (``"fitted": false``,
    no uncertainty); the refit fits both."""
    if not d.named:
        return {}
    c = c or d.best
    return {p.name: {"value": c.hypothesis.values[p.name], "std": c.std.get(p.name), "unit": p.unit,
                     "fitted": p.name in c.std} for p in parameters(c.hypothesis.cause)}


def _candidate(c: Candidate) -> dict[str, Any]:
    return {"cause": c.hypothesis.cause, "location": c.hypothesis.location_json(),
            "heldout_error": c.heldout_error if c.verified else None, "training_error": _training_error(c),
            "score": c.score, "n_parameters": len(parameters(c.hypothesis.cause)),
            "parameters": dict(c.hypothesis.values)}


def _training_error(c: Candidate) -> float | None:
    """The linearised fit's RMS on the training tests; None for a candidate no such fit gave (a pair
    refit's halved step, :func:`elastokin.diagnosis.kc_fits.halfway`), which only its runs scored."""
    return finite(c.screened_error)


def _run_with(d: KCDiagnosis, c: Candidate) -> list[Hypothesis]:
    """The hypotheses a second-stage candidate was run with: the first cause (refitted with it, if it
    was) and its own."""
    return [(c.beside or d.best).hypothesis, c.hypothesis]


def _pair(d: KCDiagnosis, c: Candidate) -> dict[str, Any]:
    """A second-stage candidate: the pair run, both causes with the values it was run with."""
    both = _run_with(d, c)
    return {"cause": PAIR_SEPARATOR.join(h.cause for h in both), "heldout_error": c.heldout_error,
            "training_error": _training_error(c), "score": c.score,
            "causes": [{"cause": h.cause, "location": h.location_json(), "parameters": dict(h.values)} for h in both]}


def summary(d: KCDiagnosis) -> dict[str, Any]:
    """The machine-readable verdict (``vsim diagnose --json``)."""
    after = d.final.test_errors if d.named else d.baseline_errors
    return {
        "cause": d.verdict,
        "location": d.causes[0].hypothesis.location_json() if d.named else None,
        "parameters": _parameters(d, d.causes[0]) if d.named else {},
        "heldout_error_before": d.heldout_error_before,
        "heldout_error_after": d.heldout_error_after,
        "noise_floor": 1.0,
        "ranking": [_candidate(c) for c in d.ranking],
        "pairs": [_pair(d, c) for c in d.pairs],
        "tests": [{"name": n, "heldout": bool(h), "error_before": float(b), "error_after": float(a),
                   "excess_before": excess(float(b))}
                  for n, h, b, a in zip(d.test_names, d.heldout, d.baseline_errors, after)],
        "explained": d.explained[0],
        "share_explained": d.explained[1],
        "causes": [{"cause": c.hypothesis.cause, "location": c.hypothesis.location_json(),
                    "parameters": _parameters(d, c), "share_explained": share} for c, share in zip(d.causes, d.shares)],
        "alike": [_alike(c, sep) for c, sep in zip(d.alike, d.separations)],
        "misfits": [_misfit(m) for m in d.misfits],
        "misfits_after": [_misfit(m) for m in d.misfits_after],
        "noise": {c: float(s) for c, s in zip(d.layout.channels, d.noise)},
        "noise_model": _noise_model(d),
        "acquisition": [{"path": r.path, "channels": list(r.channels), "lag_ms": 1e3 * r.lag_s,
                         "cutoff_hz": r.cutoff_hz or None, "delay_ms": 1e3 * r.delay_s, "delay_std_ms": 1e3 * r.std_s}
                        for r in d.responses],
        "transducers": [{"kind": g.kind, "channel": g.channel, "source": g.source, "value": g.value,
                         "std": finite(g.std), "unit": g.unit or "1", "at_bound": g.at_bound, "shown": g.said}
                        for g in d.rig_errors if g.kind != RIG],
        "rig": [{"element": g.channel, "value": g.value, "std": finite(g.std), "unit": BY_KEY[g.channel].unit,
                 "at_bound": g.at_bound, "shown": g.said} for g in d.rig_errors if g.kind == RIG],
        "rig_or_car": [{"group": c.group, "readings": [f"{g.label} {g.text}" for g in c.readings],
                        "rivals": [{"cause": h.cause, "location": h.location_json(), "parameters": dict(h.values)}
                                   for h in c.rivals],
                        "remedy": c.remedy, "training_error_held": c.error_held,
                        "training_error_rivals": list(c.error_rivals), "training_error": c.error}
                       for c in d.rig_or_car],
        "hidden_cause": _hidden(d.hidden),
        "damage": list(d.layout.damage),
        "wall_s": d.wall_s,
    }


def _hidden(h: HiddenCause | None) -> dict[str, Any] | None:
    """The car cause the data prefer beside the rig's errors and the shown rig errors it moves."""
    if h is None:
        return None
    return {"cause": h.hypothesis.cause, "location": h.hypothesis.location_json(),
            "parameters": dict(h.hypothesis.values), "z": h.z, "threshold": h.threshold,
            "training_error": h.error, "training_error_without": h.error_without,
            "readings": [{"kind": g.kind, "channel": g.channel, "source": g.source, "value": g.value,
                          "std": finite(g.std), "value_with": w.value, "std_with": finite(w.std)} for g, w in h.moved]}


def _noise_model(d: KCDiagnosis) -> dict[str, dict[str, float]]:
    """Per quantity (its channels share them): the white and coloured noise [its unit], the coloured
    noise's correlation time [s] (:mod:`elastokin.diagnosis.kc_noise`)."""
    m, out = d.noise_model, {}
    for i, c in enumerate(d.layout.channels if m is not None else ()):
        out.setdefault(channel_quantity(c), {"white": float(m.white[i]), "coloured": float(m.coloured[i]),
                                             "correlation_time_s": float(m.correlation_time_s[i])})
    return out


def _alike(c: Candidate, sep: Separation | None) -> dict[str, Any]:
    """A rival the campaign cannot tell from the named cause, and the shipped test that separates them."""
    return {"cause": c.hypothesis.cause, "location": c.hypothesis.location_json(),
            "parameters": dict(c.hypothesis.values), "heldout_error": c.heldout_error,
            "separated_by": None if sep is None else {"scenario": sep.test, "file": str(sep.path),
                                                      "difference": sep.difference, "separates": sep.separates}}


def _alike_sentence(d: KCDiagnosis) -> str:
    """What the campaign cannot tell apart, and the test that would."""
    out = ""
    for c, sep in zip(d.alike, d.separations):
        out += (f" These tests cannot tell it from **{c.hypothesis.cause}** at {_where(c.hypothesis)} "
                f"({_values(c.hypothesis)}; held-out error "
                f"{c.heldout_error:.2f}): ")
        if sep is None:
            out += ("the dataset holds every shipped rig test." if not d.extra_tests else
                    f"none of the {d.extra_tests} shipped rig tests the dataset lacks ran on both (the car left "
                    f"its valid range).")
        else:
            out += separation_clause(sep, "rig test")
    return out


def _values(h: Hypothesis) -> str:
    """A hypothesis's parameters with their units."""
    return ", ".join(f"{k} = {v:.4g} {p.unit}" for (k, v), p in zip(h.values.items(), parameters(h.cause)))


def _misfit(m: Misfit) -> dict[str, Any]:
    return {"test": m.test, "heldout": m.heldout, "error": m.error, "excess": excess(m.error),
            "noise_chance": m.chance, "start_s": m.start_s, "end_s": m.end_s, "channel": m.channel}


def excess(error: float) -> float:
    """The model error in excess of the noise, from an error in units of the noise (1: perfect)."""
    return math.sqrt(max(error ** 2 - 1.0, 0.0))


def _where(h: Hypothesis) -> str:
    loc = h.location_json() or {}
    return ", ".join(f"{k} {'/'.join(v) if isinstance(v, list) else v}" for k, v in loc.items())


#: A path's lag is said in the verdict beyond this many standard uncertainties and this [s] (a
#: rig's own lag well under a sample is not worth a word).
LAG_SAID, LAG_SAID_S = 3.0, 1e-3


def _acquisition_sentence(d: KCDiagnosis) -> str:
    """What the diagnosis took out of the data as the rig's acquisition (each path's lag), if anything."""
    said = [r for r in d.responses if abs(r.lag_s) > max(LAG_SAID * r.std_s, LAG_SAID_S)]
    return "".join(f" The {r.path}' channels lag the rig inputs by {1e3 * r.lag_s:.1f} ms ("
                   + (f"a {r.cutoff_hz:.3g} Hz low-pass filter, then " if r.cutoff_hz else "")
                   + f"{1e3 * r.delay_s:.1f} ± {1e3 * r.std_s:.2g} ms): the rig's acquisition, estimated and taken "
                     f"out." for r in said)


def _transducers_sentence(d: KCDiagnosis) -> str:
    """Which transducers the data show misreading, and what of the rig's own mechanics they show, if any
    (over the scenarios' own ``rig``, when they state one: the columns move it from there)."""
    said = [g for g in d.rig_errors if g.said and g.kind != RIG]
    mechanics = [g for g in d.rig_errors if g.said and g.kind == RIG]
    out = "" if not said else (
        " The rig's transducers misread: " + ", ".join(f"{g.label} {g.text}" for g in said)
        + " (fitted with every hypothesis and taken out; a cause acting on the campaign as such an error does "
          "is not told from it: a static calibration of the transducer separates them).")
    beyond = " beyond the mechanics its scenarios state" if any(not t.job.scenario.rig.ideal
                                                                for t in d.layout.tests) else ""
    return out + ("" if not mechanics else (
        f" The rig itself shows{beyond}: " + ", ".join(f"{g.label} {g.text}" for g in mechanics)
        + " (fitted with every hypothesis and taken out: the rig's, not the car's)."))


def _rig_or_car_sentence(d: KCDiagnosis) -> str:
    """The rig errors taken out that a car cause would explain as well, and the check that tells them apart."""
    return "".join(
        f" What the data show of {c.group} ({', '.join(f'{g.label} {g.text}' for g in c.readings[:3])}"
        f"{', …' if len(c.readings) > 3 else ''}) "
        + " or ".join(f"**{h.cause}** at {_where(h)} ({_values(h)})" for h in c.rivals)
        + f" would explain as well: this campaign cannot tell them apart; {c.remedy}." for c in d.rig_or_car)


def _hidden_sentence(d: KCDiagnosis) -> str:
    """The car cause the rig's errors may hide, and what the rig errors shown would read with it."""
    h = d.hidden
    if h is None:
        return ""
    moved = ", ".join(f"{g.label} {w.text} (not {g.text})" for g, w in h.moved)
    return (f" Beside the rig's errors the data prefer **{h.hypothesis.cause}** at {_where(h.hypothesis)} "
            f"({_values(h.hypothesis)}; {h.z:.1f} standard uncertainties off none, where chance passes "
            f"{h.threshold:.1f} in {HIDDEN_ALPHA:.0%} of campaigns; it lowers the training error from "
            f"{h.error_without:.3f} to {h.error:.3f}, not named): if the car has it, the rig's errors read {moved}; "
            f"this campaign cannot tell which.")


def _noise_sentence(d: KCDiagnosis) -> str:
    """Which channels' noise is coloured, if any: the noise the verdict was judged against."""
    said = coloured_noise(d.layout.channels, d.noise_model) if d.noise_model is not None else {}
    if not said:
        return ""
    return " The measurement noise is coloured (counted in the noise the verdict is judged against): " + "; ".join(
        f"{q} {coloured / white:.2g} × its white noise, correlated over {tau:.2g} s"
        for q, (white, coloured, tau) in said.items()) + "."


def verdict_sentence(d: KCDiagnosis) -> str:
    """One sentence for people: the cause, what was taken out as the rig's acquisition and its
    transducers' errors, and the noise's colour."""
    return (_cause_sentence(d) + _acquisition_sentence(d) + _transducers_sentence(d) + _rig_or_car_sentence(d)
            + _hidden_sentence(d) + _noise_sentence(d))


def _cause_sentence(d: KCDiagnosis) -> str:
    before, after = d.heldout_error_before, d.heldout_error_after
    if d.verdict == "none":
        return (f"Nothing significant is missing: the baseline's held-out error ({before:.2f} × the measurement "
                f"noise) is at the noise or no cause of the catalogue reduces it.")
    best = d.ranking[0]
    if d.verdict == "unexplained" and before <= NOISE_FACTOR and d.misfits:
        worst = min(d.misfits, key=lambda m: (m.chance, -m.error))
        tests = f"{len(d.misfits)} tests on their own" if len(d.misfits) > 1 else "one test on its own"
        return (f"A local misfit: the baseline fits the held-out tests taken together ({before:.2f} × the noise) "
                f"but not {tests}, most of all {worst.test} ({worst.error:.2f} × the noise, most between "
                f"{worst.start_s:.2f} and {worst.end_s:.2f} s of its input, in {worst.channel}); no catalogue cause "
                f"can be judged on it.")
    if d.verdict == "unexplained":
        return (f"The mismatch is real ({before:.2f} × the noise on held-out tests) but no catalogue cause explains "
                f"it; the best, {best.hypothesis.label}, only brings it to {best.heldout_error:.2f}.")
    named = " and ".join(
        f"**{c.hypothesis.cause}** at {_where(c.hypothesis)} (" + ", ".join(
            f"{k} = {v['value']:.4g} ± {v['std']:.2g} {v['unit']}" if v["fitted"] else
            f"{k} = {v['value']:.4g} {v['unit']} (held at mid-range)" for k, v in _parameters(d, c).items()) + ")"
        for c in d.causes)
    sentence = (f"Cause{'s' if len(d.causes) > 1 else ''}: {named}; held-out error {before:.2f} → {after:.2f} "
                f"× the measurement noise.")
    how, share = d.explained
    if how == "partial":
        sentence += partly_explained(share, ", ".join(m.test for m in d.misfits_after))
    return sentence + _alike_sentence(d)


def _test_features(d: KCDiagnosis, measured: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per test: peak-to-peak wheel travel [mm] (largest wheel) and mean static pad load [N]."""
    cols = d.layout.channels
    travel = [i for i, c in enumerate(cols) if c.startswith("wheel_travel_")]
    load = [i for i, c in enumerate(cols) if c.startswith("pad_fz_")]
    amp = np.array([np.ptp(measured[t.rows][:, travel], axis=0).max() for t in d.layout.tests])
    static = np.array([measured[t.rows][:, load].mean() for t in d.layout.tests])
    return amp, static


def _overlays(d: KCDiagnosis, out: Path) -> Path:
    held = d.heldout[d.layout.test]
    mismatch = np.std((d.layout.measured - d.baseline)[held], axis=0) / d.noise   # a zero error does not count
    worst = [int(i) for i in np.argsort(-mismatch)[:OVERLAYS]]
    k = max((i for i in range(len(d.layout.tests)) if d.heldout[i]), key=lambda i: d.baseline_errors[i])
    rows = d.layout.tests[k].rows
    fig = Figure(figsize=(4.2 * len(worst), 3.6))
    for j, c in enumerate(worst):
        ax = fig.add_subplot(1, len(worst), j + 1)
        m = d.layout.measured[rows, c]
        x = np.arange(len(rows))
        ax.plot(x, m, "k.", ms=1.5, label="measured")
        for sim, style, label in ((d.baseline, "C3-", "baseline"),
                                  (d.final.simulated if d.named else None, "C0-", f"+ {d.verdict}")):
            if sim is not None:
                ax.plot(x, sim[rows, c] + np.median(m - sim[rows, c]), style, lw=0.8, label=label)
        ax.set_xlabel("sample of the input phase")
        ax.set_ylabel(d.layout.channels[c])
        ax.set_title(f"{d.layout.tests[k].name} (held out)", fontsize=8)
        ax.legend(fontsize=7)
    return save_figure(fig, out)


def _residuals(d: KCDiagnosis, out: Path) -> Path:
    amp, static = _test_features(d, d.layout.measured)
    fig = Figure(figsize=(8.5, 3.6))
    for i, (x, label) in enumerate(((amp, "peak-to-peak wheel travel [mm]"), (static, "mean pad load [N]"))):
        ax = fig.add_subplot(1, 2, i + 1)
        ax.scatter(x, d.baseline_errors, c="C3", s=14, label="baseline")
        if d.named:
            ax.scatter(x, d.final.test_errors, c="C0", marker="s", s=14, label=f"+ {d.verdict}")
        ax.axhline(1.0, color="k", ls="--", lw=0.8, label="noise")
        ax.set_xlabel(label)
        ax.set_ylabel("RMS error [× noise]")
        ax.legend(fontsize=7)
    return save_figure(fig, out)


def _ranking(d: KCDiagnosis, out: Path) -> Path:
    return ranking_chart(d.heldout_error_before, [(c.hypothesis.label, c.heldout_error) for c in d.ranking if c.verified],
                         (1.0, "noise"), "held-out RMS error [× noise]", out)


def write_report(d: KCDiagnosis, baseline: VehicleDefinition, out_dir: Path, dataset: str) -> list[Path]:
    """Write report.md, its PNGs, diagnosis.json and (for a named cause) extended_vehicle.yaml."""
    out_dir.mkdir(parents=True, exist_ok=True)
    written = [_overlays(d, out_dir / "overlays.png"), _residuals(d, out_dir / "residuals.png"),
               _ranking(d, out_dir / "ranking.png")]
    result = summary(d)
    report = Report(f"K&C diagnosis of {dataset}", verdict_sentence(d),
                    f"Baseline: `{baseline.path}`; {len(d.test_names)} tests (recorded cases), {int(d.heldout.sum())} "
                    f"held out from every fit (every other one). Errors are RMS of measured − simulated over every "
                    f"measured channel but the rig inputs, each in units of its own measurement noise (estimated from "
                    f"the data, white and coloured), each channel's zero in each recording removed and each acquisition path's filter and "
                    f"delay behind the rig inputs taken out: 1 is a perfect model.")
    if d.layout.damage:
        report.paragraph("**Diagnosed on a damaged dataset** (`--use-damaged`), with the samples its recordings hold: "
                         + "; ".join(d.layout.damage) + ".")
    if d.named:
        model = out_dir / "extended_vehicle.yaml"
        hypotheses = [c.hypothesis for c in d.causes]
        note = (f"{baseline.path} extended by " + " and ".join(f"{h.label} {dict(h.values)}" for h in hypotheses)
                + f", fitted by vsim diagnose on {dataset}.")
        with atomic_output(model) as tmp:
            tmp.write_text(extended_vehicle_yaml(baseline, hypotheses, note))
        written.append(model)
        report.paragraph(f"Extended model: [`{model.name}`]({model.name}) (a vehicle file: `vsim run` uses it "
                         f"through a scenario's `vehicle:` key).")
    report.section("The rig's acquisition, taken out")
    report.paragraph("Each acquisition path (channels sharing a filter and a delay behind the rig inputs, which the "
                     "simulation is driven by) as fitted on the data beside the final model "
                     "(`elastokin/diagnosis/kc_lags.py`; the cut-off's own uncertainty is not estimated):")
    report.table(("path", "channels", "lag at low frequency [ms]", "low-pass [Hz]", "delay [ms]"),
                 [(r.path, f"{len(r.channels)}", f"{1e3 * r.lag_s:.2f}", f"{r.cutoff_hz:.3g}" if r.cutoff_hz else "none",
                   f"{1e3 * r.delay_s:.2f} ± {1e3 * r.std_s:.2g}") for r in d.responses])
    shown = [g for g in d.rig_errors if g.kind == INPUT_GAIN or (g.said and g.kind != RIG)]
    if shown:
        report.paragraph("The transducers' errors fitted with every hypothesis (`elastokin/diagnosis/kc_transducers.py`): "
                         "each moved rig input's gain g (it reads (1 + g) × the truth; the car got the command / (1 + g)), "
                         "and each measured channel's gain, cross-talk or zero drifting through a recording of repeated "
                         "tests the data show:")
        report.table(("transducer", "value"), [(g.label, g.text) for g in shown])
    mechanics = [g for g in d.rig_errors if g.kind == RIG]
    if mechanics:
        report.paragraph("The rig's own mechanics fitted with every hypothesis (`elastokin/diagnosis/kc_rig_mechanics.py`): "
                         "its floating pads' friction and its body clamp's compliance, each from none to a rig's most:")
        report.table(("element", "value"), [(g.label, g.text) for g in mechanics])
    report.paragraph("The measurement noise per quantity, from the residual's differences between successive "
                     "samples (white) and, in the tests whose input repeats, between the samples a period apart "
                     "(coloured: what each recording's zero leaves of it; `elastokin/diagnosis/kc_noise.py`):")
    report.table(("quantity", "white noise", "coloured noise", "correlation time [s]"),
                 [(q, f"{v['white']:.3g}", f"{v['coloured']:.3g}", f"{v['correlation_time_s']:.2g}" if v["coloured"]
                   else "") for q, v in result["noise_model"].items()])
    report.section("Ranking")
    report.paragraph("Every cause at every place it can sit was run once on the training tests and its magnitude "
                     "fitted; the best were run on every test and scored on the held-out ones.")
    report.table(("hypothesis", "parameters", "held-out error", "training error", "fitted values"),
                 [("baseline", "0", f"{d.heldout_error_before:.3f}", "", "")]
                 + [(c.hypothesis.label, str(len(parameters(c.hypothesis.cause))),
                     f"{c.heldout_error:.3f}" if c.verified else "(not run)", f"{c.screened_error:.3f}",
                     ", ".join(f"{k} = {v:.4g}" for k, v in c.hypothesis.values.items())) for c in d.ranking[:12]])
    if d.pairs:
        report.paragraph(f"Second stage: {d.best.hypothesis.label} left a mismatch beyond the noise or a test it "
                         f"does not fit; every other hypothesis was fitted beside it, the best run with it on every "
                         f"test, both magnitudes (and the second's shape) refitted together, a refit that did worse "
                         f"than where it started once more at half its step (two causes are named "
                         f"when the pair removes most of what the first left and the second's magnitude stands over "
                         f"two of its fit's standard uncertainties off no effect):")
        report.table(("pair", "held-out error", "fitted values"),
                     [(" + ".join(h.label for h in both), f"{c.heldout_error:.3f}",
                       "; ".join(", ".join(f"{k} = {v:.4g}" for k, v in h.values.items()) for h in both))
                      for c, both in ((c, _run_with(d, c)) for c in d.pairs)])
    report.picture("ranking.png")
    report.section("Tests")
    report.paragraph("Every test is checked, training ones included (the baseline fitted nothing): a test is "
                     f"misfit when the baseline's error on it exceeds {NOISE_FACTOR:g} × the noise, or when one "
                     f"channel over a stretch of it departs more than the noise would with a chance of "
                     f"{MISFIT_CHANCE:g} anywhere in the test.")
    report.table(("test", "held out", "error before", "excess over noise", "error after"),
                 [(t["name"], "yes" if t["heldout"] else "", f"{t['error_before']:.3f}", f"{t['excess_before']:.3f}",
                   f"{t['error_after']:.3f}") for t in result["tests"]])
    for title, misfits in ((f"Tests the baseline with {d.verdict} does not fit", d.misfits_after),
                           ("Tests the baseline does not fit", d.misfits)):
        if misfits:
            report.section(title)
            report.table(("test", "held out", "error", "chance from noise", "where (s of its input)", "worst channel"),
                         [(m.test, "yes" if m.heldout else "", f"{m.error:.3f}", f"{m.chance:.1e}",
                           f"{m.start_s:.2f} – {m.end_s:.2f}", m.channel) for m in misfits])
    report.section("Channels with the largest mismatch (held-out test with the largest baseline error)")
    report.picture("overlays.png")
    report.section("Error against amplitude and static load")
    report.picture("residuals.png")
    return written + report.write(out_dir, result)
