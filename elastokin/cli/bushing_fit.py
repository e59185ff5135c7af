"""`vsim bushing fit RECORD.csv… --bushing-model stvs [-o SET.yaml]`: identify a bushing from bench records."""

from __future__ import annotations

import argparse
from pathlib import Path

from elastokin.bushings.parameters import DEFAULT_CELLS, FITTED_MODELS
from elastokin.cli.arguments import output_file


def _fit(args: argparse.Namespace) -> int:
    from elastokin.bushings.adams_bus import read_bus
    from elastokin.bushings.bench.identification import fit, initial_guesses, starting_set, with_elastic_curve
    from elastokin.bushings.bench.records import read_bench_csv
    from elastokin.bushings.parameter_sets import load_parameter_set, save_parameter_set
    from elastokin.presentation.fit_report import format_result

    records = [read_bench_csv(path) for path in args.records]
    initial = [starting_set(load_parameter_set(args.init), args.bushing_model)] if args.init else None
    if args.elastic is not None:
        curve = read_bus(args.elastic).parameter_set(args.direction).values["curve"]
        starts = initial or initial_guesses(records, args.bushing_model, args.n_cells or DEFAULT_CELLS)
        initial = [with_elastic_curve(s, curve, f"{args.elastic} ({args.direction})") for s in starts]
    result = fit(records, args.bushing_model, initial, n_cells=args.n_cells, max_samples=args.max_samples)
    print(format_result(result))
    if args.output:
        save_parameter_set(result.parameter_set(args.output.stem, [str(p) for p in args.records]), args.output)
        print(f"wrote {args.output}")
    return 0


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``fit`` (of the ``bushing`` group)."""
    p = subparsers.add_parser(
        "fit", help="fit STVS, RT or STS parameters to bench records",
        description="Least-squares fit of a ladder bushing model to several bench records at once "
                    "(t_s,e_mm,F_N CSV files, e.g. slow triangle + sine + relaxation + bi-sine). The "
                    "start is the direct STS identification of the slowest triangular record "
                    "(thesis eqs 5.5-5.8, then 5.10 for the STVS) unless --init is given.")
    p.add_argument("records", nargs="+", type=Path, metavar="RECORD.csv", help="bench records (t_s,e_mm,F_N)")
    p.add_argument("--bushing-model", choices=FITTED_MODELS, default="stvs", help="the bushing model to fit (default stvs)")
    p.add_argument("-o", "--output", type=output_file, metavar="SET.yaml", help="write the fitted parameter set here")
    p.add_argument("--n-cells", type=int, default=None, metavar="N",
                   help=f"ladder cells (default: the --init set's, else {DEFAULT_CELLS})")
    p.add_argument("--init", metavar="SET", help="starting parameter set (name in models/bushings/ or YAML "
                                                 "path); an STS set is converted by eq. 5.10 for STVS/RT")
    p.add_argument("--elastic", type=Path, metavar="F.bus",
                   help="take the elastic law from an Adams bushing property file's curve (held; the ladder is "
                        "fitted beside it, in parallel). The curve must be the parallel elastic part alone: a "
                        "curve of the whole bushing (as vsim bushing export writes, the centre line of its slow "
                        "loop) already holds the ladder's stiffness (thesis eq. 5.9), and the fit then finds "
                        "little ladder left")
    p.add_argument("--direction", choices=("x", "y", "z"), default="x", help="the --elastic file's direction (default x)")
    p.add_argument("--max-samples", type=int, default=3000,
                   help="subsample longer records to about this many samples (default 3000)")
    p.set_defaults(func=_fit)
