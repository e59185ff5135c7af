"""The result of a bushing fit (`vsim bushing fit`) as a text table: the fitted parameters with their
standard errors, and the fit error per record."""

from __future__ import annotations

from elastokin.bushings.bench.identification import FIT_PARAMETERS, LOG_SPAN, FitResult
from elastokin.bushings.parameters import parameter_unit


def format_result(result: FitResult) -> str:
    """Human-readable table of the fitted parameters (± one standard error) and fit errors."""
    lines = [f"{result.model.upper()} fit, N = {result.values['N']} cells, {result.seconds:.1f} s "
             f"({result.evaluations} record simulations): {result.message}"]
    for name in FIT_PARAMETERS[result.model]:
        unit = parameter_unit(name, "translation")
        if name in result.std_errors:
            lines.append(f"  {name:4s} = {result.values[name]:10.4g} ± {result.std_errors[name]:.2g} {unit}")
        elif name in result.values:
            lines.append(f"  {name:4s} = {result.values[name]:10.4g} {unit} (held)")
    if "curve" in result.values:
        points = result.values["curve"]
        lines.append(f"  elastic law: the curve of {len(points)} points from {points[0][0]:g} to {points[-1][0]:g} mm "
                     f"(held)")
    lost = [n for n in result.std_errors if n != "pw" and result.values[n] <= result.initial[n] * 10 ** (1 - LOG_SPAN)]
    if lost:
        why = (" the held curve likely holds the ladder's stiffness already (a whole bushing's centre line, "
               "thesis eq. 5.9): give the parallel elastic part" if "curve" in result.values else "")
        lines.append(f"WARNING: {', '.join(lost)} fell over {LOG_SPAN - 1:g} decades below the start (the fit stops at "
                     f"{LOG_SPAN:g}): the records do not need {'them' if len(lost) > 1 else 'it'};"
                     f"{why or ' a simpler model may do'}")
    lines.append("fit error (RMS of simulated − measured force):")
    for e in result.errors:
        lines.append(f"  {e.source}: {e.rms_N:.3g} N ({e.percent:.2f} % of the {e.range_N:.4g} N range)")
    return "\n".join(lines)
