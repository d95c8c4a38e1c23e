"""Command line of tablegen: ``tablegen simulate|build|info|report ...``.

Bad arguments exit with status 2 and a message naming the argument and its
allowed range (argparse convention).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from data_schema.samples import write_samples
from tablegen.config import PRESETS
from tablegen.shapes import MIX, SHAPES


def _build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="tablegen", description=(
        "Direct rebound model of non-spherical particles and offline table build."))
    sub = parser.add_subparsers(dest="command", required=True)
    sim = sub.add_parser("simulate", help="simulate n rebounds at one incident state and print a summary",
                         description="Simulate n rebounds at one incident state (lab frame: wall y = 0, "
                                     "V- = |V-|(cos a1, -sin a1, 0)) and print a summary.")
    sim.add_argument("--shape", required=True, choices=SHAPES + (MIX,), help="particle shape or the equal-weight mix")
    sim.add_argument("--alpha1", type=float, required=True, metavar="DEG", help="incidence angle from the wall, (0, 90]")
    sim.add_argument("--speed", type=float, required=True, metavar="M_PER_S", help="incident speed |V-| in m/s, > 0")
    sim.add_argument("-n", type=int, required=True, metavar="N", help="number of particles, >= 1")
    sim.add_argument("--seed", type=int, default=None, help="random seed (default: fresh, printed)")
    sim.add_argument("--omega", type=float, nargs=3, default=(0.0, 0.0, 0.0), metavar=("WX", "WY", "WZ"),
                     help="incident angular velocity Omega- a/|V-|, lab frame (default 0 0 0)")
    sim.add_argument("--kappa", type=float, default=0.3, help="cut_prism corner truncation, [0, 1) (default 0.3)")
    sim.add_argument("--n-max", type=int, default=1000, help="collisions before a particle is trapped (default 1000)")
    sim.add_argument("--out", metavar="FILE.h5", help="write the per-particle samples (HDF5, docs/format.md)")
    sim.add_argument("--overwrite", action="store_true", help="replace an existing --out file")
    sim.add_argument("--no-progress", action="store_true", help="do not show a progress bar")

    build = sub.add_parser("build", help="build a rebound table over a grid of incident states",
                           description="Run the direct model over the (shape, alpha1, speed) grid of a "
                                       "configuration and write the table (HDF5, docs/format.md). "
                                       "Resumable: rerun the same command after an interruption.")
    source = build.add_mutually_exclusive_group()
    source.add_argument("--config", metavar="FILE", help="TOML build configuration (docs/format.md)")
    source.add_argument("--preset", default="default", choices=PRESETS,
                        help="embedded configuration (default: %(default)s)")
    build.add_argument("-o", "--out", required=True, metavar="TABLE.h5", help="output table file")
    build.add_argument("--workers", type=int, default=None, help="local worker processes (default: CPU count)")
    build.add_argument("--scheduler", metavar="ADDRESS", help="Dask distributed scheduler to run the cells on")
    build.add_argument("--overwrite", action="store_true", help="replace an existing output file")
    build.add_argument("--no-progress", action="store_true", help="do not show a progress bar")
    build.add_argument("--print-config", action="store_true",
                       help="print the resolved configuration and exit without building")

    info = sub.add_parser("info", help="describe a rebound table")
    info.add_argument("table", metavar="TABLE.h5")

    report = sub.add_parser("report", help="write the paper's study (figures and index.md) to a folder",
                            description="Write the study of Panfilov & Tsirkunov (2022) at |V-| = 200 m/s, "
                                        "Omega- = 0 to a new folder: PNG figures against alpha1, PDFs, "
                                        "indicatrices, collision counts and index.md (docs/report.md). "
                                        "Needs matplotlib: pip install \"rebound-scatter[plots]\".")
    source = report.add_mutually_exclusive_group(required=True)
    source.add_argument("--table", metavar="TABLE.h5",
                        help="draw from a table, at its grid alpha1 and its grid speed nearest 200 m/s")
    source.add_argument("--direct", action="store_true", help="run the direct model at 200 m/s")
    report.add_argument("-o", "--out", required=True, metavar="FOLDER", help="output folder (must not exist)")
    report.add_argument("--shapes", nargs="+", choices=SHAPES + (MIX,), default=list(SHAPES + (MIX,)),
                        help="shapes to report, and 'mix' for the equal-weight mix (default: all)")
    report.add_argument("-n", type=int, default=20_000, metavar="N",
                        help="particles (--direct) or draws (--table) per shape and alpha1, >= 1 "
                             "(default %(default)s)")
    report.add_argument("--seed", type=int, default=None, help="random seed (default: fresh, recorded)")
    report.add_argument("--alpha1", type=_alpha1_list, metavar="LIST",
                        help="comma-separated incidence angles in (0, 90] deg (default: 5,10,...,90 with "
                             "--direct; the table's grid with --table, of which LIST must be a subset)")
    report.add_argument("--overwrite", action="store_true", help="replace an existing output folder")
    report.add_argument("--no-progress", action="store_true", help="do not show a progress bar")
    return parser


def _alpha1_list(text: str) -> tuple:
    """Comma-separated angles in (0, 90] degrees, as a tuple (argparse type)."""
    from tablegen.simulate import check_alpha1

    try:
        return tuple(check_alpha1(v) for v in text.split(","))
    except ValueError as exc:
        raise argparse.ArgumentTypeError(f"comma-separated angles in (0, 90] deg; {exc}") from None


def _simulate(args, parser) -> int:
    from tablegen.simulate import simulate
    from tablegen.summary import format_summary, summarize

    if args.out and not args.overwrite and Path(args.out).exists():
        parser.error(f"--out {args.out} exists; pass --overwrite to replace it")
    try:
        samples = simulate(args.shape, args.alpha1, args.speed, args.n, seed=args.seed,
                           omega_in=args.omega, kappa=args.kappa, n_max=args.n_max,
                           progress=not args.no_progress and sys.stderr.isatty())
    except ValueError as exc:
        parser.error(str(exc))
    print(format_summary(samples, summarize(samples)))
    if args.out:
        try:
            path = write_samples(args.out, samples, overwrite=args.overwrite)
        except (FileExistsError, FileNotFoundError) as exc:
            parser.error(str(exc))
        print(f"samples written to {path}")
    return 0


def _build(args, parser) -> int:
    from tablegen.build import BuildError, build_table
    from tablegen.config import ConfigError, load_config

    try:
        config = load_config(args.config, args.preset)
    except ConfigError as exc:
        parser.error(str(exc))
    if args.print_config:
        print(config.to_toml(), end="")
        return 0
    if args.workers is not None and args.workers < 1:
        parser.error(f"--workers must be >= 1; got {args.workers}")
    if Path(args.out).exists() and not args.overwrite:
        parser.error(f"{args.out} exists; pass --overwrite to replace it")
    print(f"building {config.n_cells} cells x {config.particles_per_cell} particles into {args.out}",
          file=sys.stderr)
    try:
        path = build_table(config, args.out, workers=args.workers, scheduler=args.scheduler,
                           overwrite=args.overwrite, progress=not args.no_progress and sys.stderr.isatty())
    except (BuildError, FileNotFoundError) as exc:
        print(f"tablegen build: error: {exc}", file=sys.stderr)
        return 1
    print(f"table written to {path}")
    return 0


def _info(args, parser) -> int:
    from data_schema.common import DataFormatError
    from data_schema.table import read_table
    from tablegen.info import describe_table

    try:
        table = read_table(args.table)
    except (FileNotFoundError, DataFormatError) as exc:
        parser.error(str(exc))
    print(describe_table(table, Path(args.table)))
    return 0


def _report(args, parser) -> int:
    from data_schema.common import DataFormatError
    from tablegen.report import DEFAULT_ALPHA1, check_output_folder, direct_data, table_data, write_report
    from tablegen.report_plots import require_matplotlib
    from tablegen.simulate import check_seed

    if args.n < 1:
        parser.error(f"argument -n: must be >= 1; got {args.n}")
    try:
        seed = check_seed(args.seed)
        check_output_folder(args.out, args.overwrite)
    except (ValueError, FileExistsError, FileNotFoundError) as exc:
        parser.error(str(exc))
    try:
        require_matplotlib()
    except ImportError as exc:
        print(f"tablegen report: error: {exc}", file=sys.stderr)
        return 1
    try:
        if args.direct:
            data = direct_data(args.shapes, args.alpha1 or DEFAULT_ALPHA1, args.n, seed,
                               progress=not args.no_progress and sys.stderr.isatty())
        else:
            data = table_data(args.table, args.shapes, args.alpha1, args.n, seed)
    except (ValueError, FileNotFoundError, DataFormatError) as exc:
        parser.error(str(exc))
    path = write_report(data, args.out, overwrite=args.overwrite)
    print(f"report written to {path / 'index.md'}")
    return 0


def main(argv=None) -> int:
    parser = _build_parser()
    args = parser.parse_args(argv)
    commands = {"simulate": _simulate, "build": _build, "info": _info, "report": _report}
    return commands[args.command](args, parser)


if __name__ == "__main__":
    sys.exit(main())
