"""`vsim bushing run BENCH.yaml -o OUT.csv [--plot DIR]`: a programme on one bushing law, on the virtual bench."""

from __future__ import annotations

import argparse
from pathlib import Path

from elastokin.cli.arguments import output_file, output_folder


def _run(args: argparse.Namespace) -> int:
    from elastokin.bushings.bench.bench_file import load_bench, run_bench
    from elastokin.core.tables import write_csv_columns
    from elastokin.presentation.bench_plots import plot_bench

    bench = load_bench(args.bench)
    columns = run_bench(bench)
    write_csv_columns(args.output, columns)
    print(f"wrote {args.output}")
    if args.plot is not None:
        for path in plot_bench(bench, columns, args.plot, Path(args.bench).stem):
            print(f"wrote {path}")
    return 0


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``run`` (of the ``bushing`` group)."""
    run = subparsers.add_parser(
        "run", help="run a bench file (programme on one bushing) and write a CSV",
        description="Impose a bench programme (triangle, sine, bisine, step, firtree, csv, sweep) on one "
        "bushing model; a sine with static_mm is played about that static offset. Time series write t_s,e_mm,F_N; a sweep writes amplitude_mm,frequency_hz,"
        "k_dyn_n_per_mm,tan_delta (first harmonic of the last, stabilised cycle). --plot draws the "
        "force-deflection loop and the time histories (log time for a step), or for a sweep |K*| and "
        "tan delta against amplitude and frequency, with the equivalent-damping approximation (Bourgeteau "
        "2009, §5.3.1, eqs. 5.16-5.17) dashed over the time-domain result.")
    run.add_argument("bench", metavar="BENCH", help="bench file, or the name of a built-in one (bisine, sweep, ...)")
    run.add_argument("-o", "--output", type=output_file, required=True, metavar="OUT.csv")
    run.add_argument("--plot", type=output_folder, metavar="DIR", help="also write PNG plots into this directory")
    run.set_defaults(func=_run, compiles=True)
