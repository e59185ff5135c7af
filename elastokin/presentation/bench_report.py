"""What a bench diagnosis tells an engineer: the JSON verdict, the extended parameter set, and a
one-page markdown report with loop overlays before/after, residuals against speed, amplitude and
static load, the ranking with its evidence and the error per held-out test."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.figure import Figure

from elastokin.bushings.parameter_sets import save_parameter_set
from elastokin.diagnosis.bench_diagnosis import BenchDiagnosis, Candidate, aggregate
from elastokin.diagnosis.catalogue import PAIR_SEPARATOR, Cause, parts
from elastokin.diagnosis.verdict import MIN_GAIN
from elastokin.core.units import MM_PER_M
from elastokin.presentation.diagnosis_report import (Report, finite, partly_explained, ranking_chart,
                                                     separation_clause)
from elastokin.presentation.figures import save_figure

#: Held-out records overlaid in the report (the largest baseline errors first).
OVERLAYS = 4


def record_features(d: BenchDiagnosis) -> list[dict[str, float]]:
    """Per record, from the measured deflection: amplitude [mm], static level [mm], and median
    speed while moving [mm/s]."""
    out = []
    for k in range(len(d.replay.names)):
        on = d.replay.record == k
        e = d.replay.e[on] * MM_PER_M
        v = np.abs(np.diff(e) / d.replay.dts[on][1:])
        moving = v > 0.05 * v.max() if v.size else v.astype(bool)
        out.append({"amplitude_mm": float(np.ptp(e) / 2.0), "static_mm": float(np.median(e)),
                    "speed_mm_s": float(np.median(v[moving])) if moving.any() else 0.0})
    return out


def _parameters(d: BenchDiagnosis, cause: Cause | None = None) -> dict[str, Any]:
    """The named causes' fitted values (of ``cause`` only, one of them, if given)."""
    if not d.named:
        return {}
    # an uncertainty the tests cannot bound (a parameter they do not see) is null
    return {p.name: {"value": d.best.final[p.name], "std": finite(d.best.std.get(p.name, math.nan)), "unit": p.unit}
            for p in (cause or d.best.cause).parameters}


def _candidates(candidates: list[Candidate]) -> list[dict[str, Any]]:
    return [{"cause": c.cause.id, "heldout_error": c.heldout_error, "score": c.score,
             "n_parameters": len(c.cause.parameters), "parameters": c.values,
             "two_fold_error": finite(c.two_fold_error)} for c in candidates]


def summary(d: BenchDiagnosis) -> dict[str, Any]:
    """The machine-readable verdict (``vsim diagnose --json``)."""
    return {
        "cause": d.verdict,
        "location": {"level": "bench", "part": d.part} if d.named else None,
        "parameters": _parameters(d, parts(d.verdict)[0]) if d.named else {},
        "heldout_error_before": d.heldout_error_before,
        "heldout_error_after": d.heldout_error_after,
        "noise_floor": aggregate(d.noise, d.heldout),
        "ranking": _candidates(d.ranking),
        "pairs": _candidates(d.pairs),
        "explained": d.explained[0],
        "share_explained": d.explained[1],
        "causes": [{"cause": c.id, "location": {"level": "bench", "part": d.part}, "parameters": _parameters(d, c),
                    "share_explained": share} for c, share in zip(parts(d.verdict), d.shares)] if d.named else [],
        "tests": [{"name": n, "heldout": bool(h), "error_before": float(b),
                   "error_after": float(d.best.record_errors[k]) if d.named else float(b)}
                  for k, (n, h, b) in enumerate(zip(d.replay.names, d.heldout, d.baseline_errors))],
        "alike": [{"cause": c.cause.id, "parameters": c.values, "heldout_error": c.heldout_error,
                   "separated_by": None if sep is None else {"programme": sep.test, "file": str(sep.path),
                                                             "difference": sep.difference, "separates": sep.separates}}
                  for c, sep in zip(d.alike, d.separations)],
        "baseline": {"name": d.baseline.name, "model": d.baseline.model},
        "wall_s": d.wall_s,
    }


def verdict_sentence(d: BenchDiagnosis) -> str:
    """One sentence for people."""
    before, after = d.heldout_error_before, d.heldout_error_after
    if d.verdict == "none":
        return (f"Nothing significant is missing: the baseline's held-out error ({before:.2%} of the force range) "
                f"is at the noise floor or no cause reduces it by {MIN_GAIN:.0%}.")
    if d.verdict == "unexplained":
        best = d.ranking[0] if d.ranking else None
        partial = f"; the best catalogue cause, {best.cause.id}, only brings it to {best.heldout_error:.2%}" if best else ""
        return f"The mismatch is real ({before:.2%} held-out error) but no catalogue cause explains it{partial}."
    pm = lambda v: f"± {v['std']:.2g} {v['unit']}" if v["std"] is not None else f"{v['unit']}, not seen by the tests"
    named = " and ".join(f"**{c.id}** (" + ", ".join(f"{k} = {v['value']:.4g} {pm(v)}"
                                                     for k, v in _parameters(d, c).items()) + ")"
                         for c in parts(d.verdict))
    sentence = (f"Cause{'s' if PAIR_SEPARATOR in d.verdict else ''}: {named}; held-out error {before:.2%} → "
                f"{after:.2%} of the force range.")
    how, share = d.explained
    if how == "partial":
        sentence += partly_explained(share)
    first = d.ranking[0]
    if d.best is not first and PAIR_SEPARATOR not in d.verdict:
        sentence += (f" The held-out tests alone could not tell it from **{first.cause.id}**; each fitted on one half "
                     f"and scored on the other, it is the better ({d.best.two_fold_error:.2%} against "
                     f"{first.two_fold_error:.2%}).")
    for c, sep in zip(d.alike, d.separations):
        values = ", ".join(f"{p.name} = {c.values[p.name]:.4g} {p.unit}" for p in c.cause.parameters)
        sentence += (f" These tests cannot tell it from **{c.cause.id}** ({values}; held-out error "
                     f"{c.heldout_error:.2%}): " + ("no shipped bench programme can follow them." if sep is None else
                                                   separation_clause(sep, "bench programme")))
    return sentence


def write_extended_model(d: BenchDiagnosis, path: Path) -> Path | None:
    """The baseline parameter set extended by the named cause, as a parameter-set YAML file."""
    return save_parameter_set(d.best.model, path) if d.named else None


def _overlays(d: BenchDiagnosis, after: np.ndarray | None, out: Path) -> Path:
    held = [k for k in np.argsort(-d.baseline_errors) if d.heldout[k]][:OVERLAYS]
    fig = Figure(figsize=(4.2 * len(held), 3.8))
    base = d.replay.simulate([d.baseline])[0]
    for i, k in enumerate(held):
        ax = fig.add_subplot(1, len(held), i + 1)
        on = d.replay.record == k
        e = d.replay.e[on] * MM_PER_M
        step = "step" in d.replay.names[k]
        t = np.cumsum(d.replay.dts[on])
        x = t if step else e
        ax.plot(x, d.replay.measured[on], "k.", ms=1.5, label="measured")
        offset = np.median(d.replay.measured[on] - base[on])
        ax.plot(x, base[on] + offset, "C3-", lw=0.8, label="baseline")
        if after is not None:
            offset = np.median(d.replay.measured[on] - after[on])
            ax.plot(x, after[on] + offset, "C0-", lw=0.8, label=f"+ {d.verdict}")
        if step:
            ax.set_xscale("log")
        ax.set_xlabel("time [s]" if step else "deflection [mm]")
        ax.set_ylabel("force [N]")
        ax.set_title(f"{d.replay.names[k]} (held out)", fontsize=8)
        ax.legend(fontsize=7)
    return save_figure(fig, out)


def _residuals(d: BenchDiagnosis, features: list[dict[str, float]], out: Path) -> Path:
    fig = Figure(figsize=(12, 3.6))
    for i, (key, label) in enumerate((("speed_mm_s", "median speed [mm/s]"), ("amplitude_mm", "amplitude [mm]"),
                                      ("static_mm", "static level [mm]"))):
        ax = fig.add_subplot(1, 3, i + 1)
        x = np.array([f[key] for f in features])
        ax.scatter(x, 100 * d.baseline_errors, c="C3", label="baseline", s=14)
        if d.named:
            ax.scatter(x, 100 * d.best.record_errors, c="C0", marker="s", label=f"+ {d.verdict}", s=14)
        if key == "speed_mm_s" and (x > 0).all():
            ax.set_xscale("log")
        ax.set_xlabel(label)
        ax.set_ylabel("RMS error [% of force range]")
        ax.set_yscale("log")
        ax.legend(fontsize=7)
    return save_figure(fig, out)


def _ranking(d: BenchDiagnosis, out: Path) -> Path:
    return ranking_chart(100 * d.heldout_error_before, [(c.cause.id, 100 * c.heldout_error) for c in d.ranking],
                         (100 * aggregate(d.noise, d.heldout), "noise floor"), "held-out RMS error [% of force range]",
                         out, log=True)


def write_report(d: BenchDiagnosis, out_dir: Path) -> list[Path]:
    """Write report.md, its PNGs, diagnosis.json and (for a named cause) extended_model.yaml."""
    out_dir.mkdir(parents=True, exist_ok=True)
    after = d.replay.simulate([d.best.model])[0] if d.named else None
    features = record_features(d)
    written = [_overlays(d, after, out_dir / "overlays.png"), _residuals(d, features, out_dir / "residuals.png"),
               _ranking(d, out_dir / "ranking.png")]
    model_path = write_extended_model(d, out_dir / "extended_model.yaml")
    result = summary(d)
    report = Report(f"Diagnosis: {d.part}", verdict_sentence(d),
                    f"Baseline: `{d.baseline.name}` ({d.baseline.model}); {len(d.replay.names)} tests, "
                    f"{int(d.heldout.sum())} held out from every fit (every other test). Errors are RMS of measured − "
                    f"simulated force relative to half the test's peak-to-peak force; noise floor "
                    f"{result['noise_floor']:.2%}.")
    if model_path is not None:
        report.paragraph(f"Extended model: [`{model_path.name}`]({model_path.name}) (a parameter set: "
                         f"`vsim bushing run` benches and vehicles can use it).")
    report.section("Ranking (fitted on the training tests, scored on the held-out ones)")
    report.table(("cause", "parameters", "held-out error", "score (with parameter penalty)", "fitted values"),
                 [("baseline", "0", f"{d.heldout_error_before:.3%}", "", "")]
                 + [(c.cause.id, str(len(c.cause.parameters)), f"{c.heldout_error:.3%}", f"{c.score:.3%}",
                     ", ".join(f"{p.name} = {c.values[p.name]:.4g} {p.unit}" for p in c.cause.parameters))
                    for c in d.ranking])
    if d.pairs:
        report.paragraph(f"Second stage: {d.ranking[0].cause.id} left a mismatch beyond the noise; every pair of "
                         f"causes fitted (two are named when the pair removes most of what the best one left):")
        report.table(("causes", "parameters", "held-out error", "fitted values"),
                     [(c.cause.id, str(len(c.cause.parameters)), f"{c.heldout_error:.3%}",
                       ", ".join(f"{p.name} = {c.values[p.name]:.4g} {p.unit}" for p in c.cause.parameters))
                      for c in d.pairs])
    report.picture("ranking.png")
    report.section("Tests")
    report.table(("test", "held out", "amplitude [mm]", "static [mm]", "speed [mm/s]", "error before", "error after"),
                 [(t["name"], "yes" if t["heldout"] else "", f"{f['amplitude_mm']:.3g}", f"{f['static_mm']:.3g}",
                   f"{f['speed_mm_s']:.3g}", f"{t['error_before']:.3%}", f"{t['error_after']:.3%}")
                  for t, f in zip(result["tests"], features)])
    report.section("Loops and relaxations (held-out tests with the largest baseline error)")
    report.picture("overlays.png")
    report.section("Residual against speed, amplitude and static load")
    report.picture("residuals.png")
    return written + report.write(out_dir, result) + ([model_path] if model_path else [])
