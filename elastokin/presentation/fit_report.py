"""The result of a bushing fit (`vsim bushing fit`) as a text table: the fitted parameters with their
standard errors, and the fit error per record."""

from __future__ import annotations

from elastokin.bushings.bench.identification import FIT_PARAMETERS, FitResult
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
    lines.append("fit error (RMS of simulated − measured force):")
    for e in result.errors:
        lines.append(f"  {e.source}: {e.rms_N:.3g} N ({e.percent:.2f} % of the {e.range_N:.4g} N range)")
    return "\n".join(lines)
