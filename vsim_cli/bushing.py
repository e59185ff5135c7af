"""`vsim bushing`: the virtual bushing bench (`run`) and, when installed, identification (`fit`)."""

from __future__ import annotations

import argparse
import importlib
from pathlib import Path

# The bench and matplotlib are imported when the command runs, not when `vsim` builds its parser.


def _run(args: argparse.Namespace) -> int:
    from bushings.bench.bench_file import load_bench, run_bench, write_table

    bench = load_bench(args.bench)
    columns = run_bench(bench)
    write_table(args.output, columns)
    print(f"wrote {args.output}")
    if args.plot is not None:
        from vsim_presentation.bench_plots import plot_sweep, plot_time_series

        stem = args.bench.stem
        if bench.programme.kind == "sweep":
            paths = plot_sweep(columns, bench.channel, args.plot, stem)
        else:
            paths = plot_time_series(columns, bench.programme.kind, args.plot, stem)
        for path in paths:
            print(f"wrote {path}")
    return 0


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``bushing`` with its ``run`` sub-command, and ``fit`` if vsim_cli.bushing_fit exists."""
    bushing = subparsers.add_parser("bushing", help="virtual bushing bench and identification",
                                    description="Rubber-bushing models (STS, RT, STVS, ...) on a virtual bench.")
    commands = bushing.add_subparsers(dest="bushing_command", required=True)
    run = commands.add_parser(
        "run", help="run a bench file (programme on one bushing) and write a CSV",
        description="Impose a bench programme (triangle, sine, bisine, step, firtree, csv, sweep) on one "
        "bushing model. Time series write t_s,e_mm,F_N; a sweep writes amplitude_mm,frequency_hz,"
        "k_dyn_n_per_mm,tan_delta (first harmonic of the last, stabilised cycle). --plot draws the "
        "force-deflection loop and the time histories (log time for a step), or for a sweep |K*| and "
        "tan delta against amplitude and frequency, with the equivalent-damping approximation (spec "
        "5.16/5.17) dashed over the time-domain result.")
    run.add_argument("bench", type=Path, metavar="BENCH.yaml")
    run.add_argument("-o", "--output", type=Path, required=True, metavar="OUT.csv")
    run.add_argument("--plot", type=Path, metavar="DIR", help="also write PNG plots into this directory")
    run.set_defaults(func=_run)
    try:
        identification_cli = importlib.import_module("vsim_cli.bushing_fit")
    except ModuleNotFoundError as exc:
        if exc.name != "vsim_cli.bushing_fit":
            raise
    else:
        identification_cli.add_fit_command(commands)
