"""`vsim bushing fit RECORD.csv… --model stvs [-o SET.yaml]`: identify a bushing from bench records."""

from __future__ import annotations

import argparse
import datetime as dt
from pathlib import Path
from typing import Sequence

from bushings.bench.identification import FIT_PARAMETERS, FitResult, fit, rt_initial, stvs_initial
from bushings.parameters import DEFAULT_CELLS, ParameterSet, load_parameter_set, save_parameter_set
from bushings.bench.records import read_bench_csv

_UNITS = {"K0": "N/mm", "Kpa": "N/mm", "Kr": "N/mm", "Ff": "N", "Co": "N/(mm/s)^pw", "pw": ""}


def add_fit_command(bushing_subparsers: argparse._SubParsersAction) -> None:
    """Add the ``fit`` sub-command to the ``vsim bushing`` sub-parsers."""
    p = bushing_subparsers.add_parser(
        "fit", help="fit STVS, RT or STS parameters to bench records",
        description="Least-squares fit of a ladder bushing model to several bench records at once "
                    "(t_s,e_mm,F_N CSV files, e.g. slow triangle + sine + relaxation + bi-sine). The "
                    "start is the direct STS identification of the slowest triangular record "
                    "(thesis eqs 5.5-5.8, then 5.10 for the STVS) unless --init is given.")
    p.add_argument("records", nargs="+", type=Path, metavar="RECORD.csv", help="bench records (t_s,e_mm,F_N)")
    p.add_argument("--model", choices=tuple(FIT_PARAMETERS), default="stvs", help="model to fit (default stvs)")
    p.add_argument("-o", "--output", type=Path, metavar="SET.yaml", help="write the fitted parameter set here")
    p.add_argument("--n-cells", type=int, default=None, metavar="N",
                   help=f"ladder cells (default: the --init set's, else {DEFAULT_CELLS})")
    p.add_argument("--init", metavar="SET", help="starting parameter set (name in models/bushings/ or YAML "
                                                 "path); an STS set is converted by eq. 5.10 for STVS/RT")
    p.add_argument("--max-samples", type=int, default=3000,
                   help="subsample longer records to about this many samples (default 3000)")
    p.set_defaults(func=run_fit)


def run_fit(args: argparse.Namespace) -> int:
    """Fit, print the parameters with their standard errors and the per-record error, write YAML."""
    records = [read_bench_csv(path) for path in args.records]
    initial = None
    if args.init:
        pset = load_parameter_set(args.init)
        if pset.model == "sts" and args.model == "stvs":
            pset = stvs_initial(pset)
        elif pset.model == "sts" and args.model == "rt":
            pset = rt_initial(pset)
        initial = [pset]
    result = fit(records, args.model, initial, n_cells=args.n_cells, max_samples=args.max_samples)
    print(format_result(result))
    if args.output:
        write_parameter_set(args.output, result, [str(p) for p in args.records])
        print(f"wrote {args.output}")
    return 0


def format_result(result: FitResult) -> str:
    """Human-readable table of the fitted parameters (± one standard error) and fit errors."""
    lines = [f"{result.model.upper()} fit, N = {result.values['N']} cells, {result.seconds:.1f} s "
             f"({result.evaluations} record simulations): {result.message}"]
    for name in FIT_PARAMETERS[result.model]:
        lines.append(f"  {name:4s} = {result.values[name]:10.4g} ± {result.std_errors[name]:.2g} {_UNITS[name]}")
    lines.append("fit error (RMS of simulated − measured force):")
    for e in result.errors:
        lines.append(f"  {e.source}: {e.rms_N:.3g} N ({e.percent:.2f} % of the {e.range_N:.4g} N range)")
    return "\n".join(lines)


def write_parameter_set(path: Path, result: FitResult, record_paths: Sequence[str]) -> None:
    """Write a parameter-set YAML (the format of models/bushings/*.yaml) with its provenance."""
    errors = ", ".join(f"{e.source} {e.rms_N:.3g} N ({e.percent:.2f} %)" for e in result.errors)
    source = (f"fitted by vsim bushing fit ({result.model}) on {dt.date.today().isoformat()} to "
              f"{', '.join(record_paths)}; RMS fit error {errors}")
    params = {k: (int(v) if k == "N" else float(f"{v:.5g}")) for k, v in result.values.items()}
    save_parameter_set(ParameterSet(Path(path).stem, result.model, "translation", params, source), path)
