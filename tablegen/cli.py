"""Command line of tablegen: ``tablegen simulate|build|info|report|calibrate|grid ...``.

A user error ends the command with one line on stderr naming the value and
its allowed range, and exit status 2; SIGINT and SIGTERM with one line and
128 + the signal number (:mod:`data_schema.command_line`). Outputs are checked
before any work and never replace what is not ours (:mod:`data_schema.output`).
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

from data_schema.command_line import CommandParser, count_argument, run, seed_argument
from data_schema.output import check_memory, check_output
from data_schema.samples import ALPHA1_RANGE_TEXT, SAMPLES_FILE_TYPE, write_samples
from tablegen.tabulation.calibration import DEFAULT_PARTICLES, DEFAULT_SEED
from tablegen.tabulation.config import PRESETS
from direct_model.registry import FAMILIES
from direct_model.shapes import DEFAULT_KAPPA, MIX, SHAPES, AspectRatioLaw
from direct_model.simulate import DEFAULT_N_MAX
from direct_model.wall import CORUNDUM_ON_STEEL, EXPONENTIAL, WALL_FAMILIES, Wall, wall_record
from tablegen.study.report import DEFAULT_N as REPORT_DEFAULT_N

# memory per simulated particle: its arrays, their merge and the file made in memory
BYTES_PER_PARTICLE = 400
CUSTOM_WALL = "custom"      # the name of a wall law given by --wall-k/-p/-q other than the default


def _build_parser() -> argparse.ArgumentParser:
    parser = CommandParser(prog="tablegen", description=(
        "Direct rebound model of non-spherical particles and offline table build."))
    sub = parser.add_subparsers(dest="command", required=True)
    sim = sub.add_parser("simulate", help="simulate n rebounds at one incident state and print a summary",
                         description="Simulate n rebounds at one incident state (lab frame: wall y = 0, "
                                     "V- = |V-|(cos a1, -sin a1, 0)) and print a summary.")
    sim.add_argument("--shape", required=True, metavar="NAME",
                     help=f"particle shape: {', '.join(FAMILIES)}, {MIX} (the paper's four families' equal-weight "
                          f"mix), or a user grain of --config")
    sim.add_argument("--config", metavar="FILE",
                     help="TOML build configuration: its [shapes.NAME] sections define the grains --shape may name, "
                          "and its model (kappa, the b/a and c/b law, n_max, the wall law) replaces the defaults "
                          "below, so that the particles are a table cell's; a flag given still wins")
    sim.add_argument("--alpha1", type=float, required=True, metavar="DEG", help=f"incidence angle from the wall, {ALPHA1_RANGE_TEXT}")
    sim.add_argument("--speed", type=float, required=True, metavar="M_PER_S", help="incident speed |V-| in m/s, > 0")
    sim.add_argument("-n", type=count_argument, required=True, metavar="N", help="number of particles, >= 1")
    sim.add_argument("--seed", type=seed_argument, default=None,
                     help="random seed in [0, 2**63) (default: fresh, printed)")
    sim.add_argument("--omega", type=float, nargs=3, default=(0.0, 0.0, 0.0), metavar=("WX", "WY", "WZ"),
                     help="incident angular velocity Omega- a/|V-|, lab frame (default 0 0 0)")
    sim.add_argument("--kappa", type=float, metavar="KAPPA",
                     help=f"cut_prism corner truncation, [0, 1) (default {DEFAULT_KAPPA}, or --config's)")
    sim.add_argument("--n-max", type=int, metavar="N_MAX",
                     help=f"collisions before a particle is trapped (default {DEFAULT_N_MAX}, or --config's)")
    law = CORUNDUM_ON_STEEL
    sim.add_argument("--wall-k", type=float, metavar="K",
                     help=f"wall law: restitution rate constant k, (m/s)^-p, > 0 (default {law.k}, or --config's)")
    sim.add_argument("--wall-p", type=float, metavar="P",
                     help=f"wall law: restitution speed exponent p, > 0 (default {law.p}, or --config's)")
    sim.add_argument("--wall-q", type=float, metavar="Q",
                     help=f"wall law: friction factor exp(q cos gamma), finite (default {law.q}, or --config's; "
                          f"the three defaults are the law {law.name}; a law changed by a flag is recorded as "
                          f"'{CUSTOM_WALL}')")
    sim.add_argument("--out", metavar="FILE.h5", help="write the per-particle samples (HDF5, docs/format.md)")
    sim.add_argument("--overwrite", action="store_true",
                     help="replace an existing --out file if it is a samples file (nothing else is replaced)")
    sim.add_argument("--no-progress", action="store_true", help="do not show a progress bar")

    build = sub.add_parser("build", help="build a rebound table over a grid of incident states",
                           description="Run the direct model over the (shape, alpha1, speed) grid of a "
                                       "configuration and write the table (HDF5, docs/format.md). "
                                       "Resumable: rerun the same command after an interruption.")
    source = build.add_mutually_exclusive_group()
    source.add_argument("--config", metavar="FILE", help="TOML build configuration (docs/format.md)")
    source.add_argument("--preset", default="default", choices=PRESETS,
                        help="embedded configuration (default: %(default)s)")
    build.add_argument("-o", "--out", metavar="TABLE.h5", help="output table file (required unless --print-config)")
    build.add_argument("--workers", type=int, default=None,
                       help="local worker processes, >= 1 (default and cap: the CPU count and the cells left)")
    build.add_argument("--scheduler", metavar="ADDRESS", help="Dask distributed scheduler to run the cells on")
    build.add_argument("--overwrite", action="store_true",
                       help="replace an existing output file if it is a table (nothing else is replaced)")
    build.add_argument("--no-progress", action="store_true", help="do not show a progress bar")
    build.add_argument("--print-config", action="store_true",
                       help="print the resolved configuration and exit without building")

    info = sub.add_parser("info", help="describe a rebound table",
                          description="Describe a rebound table; with --config, print the build configuration it "
                                      "stores (any table of format 3 or 4), from which tablegen build --config "
                                      "rebuilds it.")
    info.add_argument("--config", action="store_true",
                      help="print the stored build configuration (TOML) and nothing else: rebuild a table with "
                           "tablegen info --config TABLE.h5 > TABLE.toml && tablegen build --config TABLE.toml "
                           "-o NEW.h5")
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
    report.add_argument("--config", metavar="FILE",
                        help="with --direct: a TOML build configuration whose grid shapes (its user grains too) and "
                             "model (kappa, the b/a and c/b law, n_max, the wall law) are run, as its table's cells "
                             "would be")
    report.add_argument("--shapes", nargs="+", metavar="NAME",
                        help=f"shapes to report, and 'mix' for the equal-weight mix (default: all): with --direct "
                             f"among {', '.join((*FAMILIES, MIX))} or --config's grid shapes; with --table the table's "
                             f"(its user grains too)")
    report.add_argument("-n", type=count_argument, default=REPORT_DEFAULT_N, metavar="N",
                        help="particles (--direct) or draws (--table) per shape and alpha1, >= 1 "
                             "(default %(default)s)")
    report.add_argument("--seed", type=seed_argument, default=None,
                        help="random seed in [0, 2**63) (default: fresh, recorded)")
    report.add_argument("--alpha1", type=_alpha1_list, metavar="LIST",
                        help=f"comma-separated incidence angles in {ALPHA1_RANGE_TEXT} deg (default: 5,10,...,90 with "
                             "--direct; the table's grid with --table, of which LIST must be a subset)")
    report.add_argument("--roughness-deg", type=_roughness_list, metavar="LIST",
                        help="with --table: comma-separated wall roughness values in [0, 45] deg; the report adds the "
                             "law of the mix (or of the first shape) on those rough walls (docs/model.md §12)")
    report.add_argument("--overwrite", action="store_true",
                        help="replace an existing output folder if it is a report this command wrote")
    report.add_argument("--no-progress", action="store_true", help="do not show a progress bar")

    calibrate = sub.add_parser(
        "calibrate", help="fit the wall law's parameters to measured mean rebounds",
        description="Fit the parameters of a wall law (docs/model.md section 4.6) to measured mean rebounds by "
                    "weighted least squares against the direct model (Omega- = 0, the same particles at every "
                    "evaluation), print the fit and write it as the [wall] section that tablegen build --config "
                    "reads: paste it into a configuration, or build with the file itself.")
    calibrate.add_argument("--data", required=True, metavar="FILE.csv",
                           help="measurements, CSV with a header: alpha1_deg (in (0, 90]), speed_m_s (> 0), then the "
                                "means over the rebounded particles of e_n = -v+/v- and e_t = u+/u- (alpha1 < 90) or "
                                "of u_ratio = u+/|V-| and v_ratio = v+/|V-|; optional: their standard deviations over "
                                "the particles (e_n_sd, e_t_sd or u_ratio_sd, v_ratio_sd) and the particle count n. "
                                "Weights 1/(sd^2/n + the model's variance of its mean); a missing sd is taken as the "
                                "same in every row and estimated from the fit's residuals (standard errors then "
                                "scaled by chi2/dof); a missing n is 1. Other columns are ignored with a warning")
    calibrate.add_argument("-o", "--out", required=True, metavar="WALL.toml",
                           help="output: the fitted law as a [wall] section (TOML) with comments on the fit")
    grains = calibrate.add_mutually_exclusive_group()
    grains.add_argument("--shapes", type=_name_list, metavar="NAME,...",
                        help=f"the grains, in equal parts: among {', '.join(FAMILIES)} and --config's grid shapes "
                             f"(default: {', '.join(SHAPES)} in equal parts)")
    grains.add_argument("--mix", type=_weight_list, metavar="NAME=W,...",
                        help="the grains with weights (normalised), e.g. prism=0.7,tetrahedron=0.3")
    calibrate.add_argument("--config", metavar="FILE",
                           help="TOML build configuration: its grid's user grains may be named in --shapes/--mix, and "
                                "its kappa, b/a and c/b law and n_max are run (its [wall] is not: it is fitted)")
    calibrate.add_argument("--law", default=EXPONENTIAL, choices=tuple(WALL_FAMILIES),
                           help="the wall law family (default: %(default)s, parameters k, p, q; tabulated: a_nc at "
                                "normal contact at each speed of the data, a_nc_<speed>, and q)")
    calibrate.add_argument("--fix", type=_fixed_list, action="append", default=[], metavar="NAME=VALUE,...",
                           help="hold parameters at values instead of fitting them, e.g. --fix p=0.61 or --fix q=1 "
                                "(repeatable)")
    calibrate.add_argument("--particles", type=count_argument, default=DEFAULT_PARTICLES, metavar="N",
                           help="direct-model particles per data row, shared by the grains by weight, >= 1 (default "
                                "%(default)s: a mean's model standard error about 0.002)")
    calibrate.add_argument("--seed", type=seed_argument, default=DEFAULT_SEED,
                           help="seed of the model's particles, in [0, 2**63) (default %(default)s); the same "
                                "particles serve every evaluation of the fit")
    calibrate.add_argument("--figure", metavar="FILE.png",
                           help="also draw the data, the fit and the default law against alpha1 (PNG; matplotlib)")
    calibrate.add_argument("--overwrite", action="store_true",
                           help="replace an existing -o or --figure file if this command wrote it (nothing else)")
    calibrate.add_argument("--no-progress", action="store_true", help="do not show a progress bar")

    grid = sub.add_parser(
        "grid", help="propose a table grid that covers a run's wall hits",
        description="Read a run's wall hits, print the quantiles of their incidence alpha1 (deg from the wall) and "
                    "speed |V-| (m/s, relative to the wall), and propose the [grid] section (alpha1_deg, speed_m_s) "
                    "that tablegen build --config reads, whose ranges cover the share --cover of the hits: the "
                    "hits a table of that grid answers instead of the direct model (docs/tables.md).")
    grid.add_argument("--from-hits", required=True, nargs="+", metavar="HITS",
                      help="hits files or folders (a folder: every hits file under it): an adapter's hits_<rank>.csv "
                           "(OpenFOAM's stochasticRebound or code_saturne's), or OpenFOAM's patchPostProcessing "
                           "records postProcessing/lagrangian/<cloud>/<name>/<time>/<patch>.post, whose normals come "
                           "from the case's mesh (the walls taken at rest)")
    grid.add_argument("--cover", type=_share, default=0.99, metavar="SHARE",
                      help="the share of the hits the grid's ranges cover, in (0, 1] (default %(default)s): as many "
                           "hits trimmed from the low end of alpha1 as from each end of |V-|")
    grid.add_argument("--alpha1-points", type=int, metavar="N",
                      help="alpha1 grid points, linear up to 90 deg, an integer in [2, 1000] (default: the default "
                           "preset's density, about one per 2.4 deg)")
    grid.add_argument("--speed-points", type=int, metavar="M",
                      help="speed grid points, geometric when the range spans more than a factor 3, else linear, an "
                           "integer in [2, 1000], neighbours at most a factor 16 apart (default: the default "
                           "preset's density, about a factor 1.35 per point)")
    grid.add_argument("--normal", type=_normal, action="append", default=[], metavar="PATCH=NX,NY,NZ",
                      help="a flat patch's normal into the gas for its patchPostProcessing records, instead of the "
                           "mesh's (repeatable; normalised)")
    grid.add_argument("--patch", action="append", metavar="NAME",
                      help="only the hits on this patch (repeatable; default: every patch of the files)")
    grid.add_argument("--table", metavar="TABLE.h5", help="also print the share of the hits this table's grid covers")
    grid.add_argument("-o", "--out", metavar="GRID.toml",
                      help="write the [grid] section there (default: print it, after the report as TOML comments)")
    grid.add_argument("--overwrite", action="store_true",
                      help="replace an existing -o file if tablegen grid wrote it (nothing else)")
    return parser


def _share(text: str) -> float:
    """A share in (0, 1] (argparse type)."""
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not 0.0 < value <= 1.0:
        raise argparse.ArgumentTypeError(f"must be a share in (0, 1]; got {text!r}")
    return value


def _normal(text: str) -> tuple:
    """``PATCH=NX,NY,NZ`` as (patch, (nx, ny, nz)) (argparse type)."""
    name, equals, vector = (part.strip() for part in text.partition("="))
    try:
        values = tuple(float(v) for v in vector.split(","))
    except ValueError:
        values = ()
    if not (name and equals) or len(values) != 3:
        raise argparse.ArgumentTypeError(f"PATCH=NX,NY,NZ, the patch's normal into the gas; got {text!r}")
    return name, values


def _name_list(text: str) -> tuple:
    """Comma-separated names (argparse type)."""
    names = tuple(name.strip() for name in text.split(","))
    if not all(names):
        raise argparse.ArgumentTypeError(f"comma-separated grain names; got {text!r}")
    return names


def _pairs(text: str, what: str) -> dict:
    """``NAME=NUMBER,...`` as a dict; ArgumentTypeError saying ``what`` is expected."""
    pairs = {}
    for item in text.split(","):
        name, equals, value = (part.strip() for part in item.partition("="))
        try:
            number = float(value)
        except ValueError:
            number = None
        if not (name and equals) or number is None or name in pairs:
            raise argparse.ArgumentTypeError(f"comma-separated {what}; got {text!r}")
        pairs[name] = number
    return pairs


def _weight_list(text: str) -> dict:
    """``NAME=WEIGHT,...`` (argparse type)."""
    return _pairs(text, "NAME=WEIGHT pairs, each name once, e.g. prism=0.7,tetrahedron=0.3")


def _fixed_list(text: str) -> dict:
    """``NAME=VALUE,...`` (argparse type)."""
    return _pairs(text, "NAME=VALUE pairs, each name once, e.g. p=0.61")


def _alpha1_list(text: str) -> tuple:
    """Comma-separated angles in the physical range (ALPHA1_RANGE_TEXT) in degrees, as a tuple (argparse type)."""
    from direct_model.simulate import check_alpha1

    try:
        return tuple(check_alpha1(v) for v in text.split(","))
    except ValueError as exc:
        raise argparse.ArgumentTypeError(f"comma-separated angles in {ALPHA1_RANGE_TEXT} deg; {exc}") from None


def _roughness_list(text: str) -> tuple:
    """Comma-separated roughness values in [0, MAX_ROUGHNESS_DEG] degrees, as a tuple (argparse type)."""
    from direct_model.wall import MAX_ROUGHNESS_DEG, check_roughness

    try:
        return tuple(check_roughness(float(v)) for v in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"comma-separated roughness values in [0, {MAX_ROUGHNESS_DEG:g}] deg; got "
                                         f"{text!r}") from None


def _progress(args) -> bool:
    return not args.no_progress and sys.stderr.isatty()


def _simulate(args) -> int:
    from tablegen.progress import simulate
    from tablegen.study.statistics import format_summary, summarize

    if args.out is not None:
        check_output(args.out, SAMPLES_FILE_TYPE, args.overwrite)
    check_memory(args.n, BYTES_PER_PARTICLE, "-n")
    config, kappa, aspect, n_max, wall = _model(args)
    samples = simulate(_shape(args, config), args.alpha1, args.speed, args.n, seed=args.seed, omega_in=args.omega,
                       kappa=kappa, aspect=aspect, n_max=n_max, wall=wall, progress=_progress(args))
    print(format_summary(samples, summarize(samples)))
    if args.out is not None:
        print(f"samples written to {write_samples(args.out, samples, overwrite=args.overwrite)}")
    return 0


def _config(args):
    """The build configuration of --config, or None without it; its warnings on stderr."""
    if args.config is None:
        return None
    from tablegen.tabulation.config import load_config

    return load_config(args.config, log=lambda line: print(line, file=sys.stderr))


def _model(args):
    """(the --config configuration or None, kappa, the b/a and c/b law, n_max, the wall law) that simulate runs:
    --config's model, else the model's defaults; the --kappa, --n-max and --wall-* flags given replace them."""
    config = _config(args)
    model = (config.model() if config is not None else
             {"kappa": DEFAULT_KAPPA, "aspect": AspectRatioLaw(), "n_max": DEFAULT_N_MAX, "wall": CORUNDUM_ON_STEEL})
    return (config, model["kappa"] if args.kappa is None else args.kappa, model["aspect"],
            model["n_max"] if args.n_max is None else args.n_max, _wall(args, model["wall"]))


def _shape(args, config):
    """--shape: a family's name or the mix, or the record of a user grain of ``config`` (--config's, or None);
    ValueError naming it."""
    if args.shape in FAMILIES or args.shape == MIX:
        return args.shape
    if config is None:
        raise ValueError(f"--shape must be one of {', '.join((*FAMILIES, MIX))}, or a user grain with --config "
                         f"FILE defining its [shapes.NAME] section; got {args.shape!r}")
    record = config.grain(args.shape)
    if record is None:
        names = ", ".join(g.name for g in config.grains) or "none"
        raise ValueError(f"--shape {args.shape!r} is neither a built-in shape ({', '.join((*FAMILIES, MIX))}) nor a "
                         f"user grain of {args.config} (its grains: {names})")
    return record


def _wall(args, law: Wall) -> Wall:
    """The wall law: ``law`` (the default or --config's) with what --wall-k/-p/-q change, a custom law if they
    change it; ValueError naming the flag (--wall-k and --wall-p set the exponential family's k and p only)."""
    given = {key: value for key, value in {"k": args.wall_k, "p": args.wall_p, "q": args.wall_q}.items()
             if value is not None}
    own = law.parameters()
    foreign = [key for key in given if key not in own]
    if foreign:
        raise ValueError(f"--wall-{foreign[0]} sets the exponential law's {foreign[0]}; the wall law of "
                         f"{args.config} is {law.family} (its parameters: {', '.join(own)})")
    values = {**own, **given}
    if values == own:
        return law
    for key, value in values.items():
        positive = key != "q"
        if not (math.isfinite(value) and (value > 0 or not positive)):
            raise ValueError(f"--wall-{key} must be finite{' and > 0' if positive else ''}; got {value!r}")
    return wall_record(law.family, {**values, **law.arrays()}, CUSTOM_WALL)


def _build(args) -> int:
    from tablegen.tabulation.driver import BuildError, build_table
    from tablegen.tabulation.config import load_config

    config = load_config(args.config, args.preset, log=lambda line: print(line, file=sys.stderr))
    if args.print_config:
        print(config.to_toml(), end="")
        return 0
    if args.out is None:
        raise ValueError("-o/--out is required: the output table file (or pass --print-config)")
    if args.workers is not None and args.workers < 1:
        raise ValueError(f"--workers must be >= 1; got {args.workers}")
    try:
        path = build_table(config, args.out, workers=args.workers, scheduler=args.scheduler,
                           overwrite=args.overwrite, progress=_progress(args),
                           log=lambda line: print(line, file=sys.stderr))
    except BuildError as exc:
        print(f"tablegen build: error: {exc}", file=sys.stderr)
        return 1
    print(f"table written to {path}")
    return 0


def _build_interrupted(args) -> str | None:
    """The line printed when a build is interrupted: what is kept and how to resume."""
    if not args.out:
        return None
    partial = Path(args.out).with_name(Path(args.out).name + ".partial")
    cells = sum(1 for _ in partial.glob("*.npz")) if partial.is_dir() else 0
    return f"workers stopped; {cells} finished cells kept in {partial}; rerun the same command to resume"


def _info(args) -> int:
    from data_schema.table import read_table, stored_config
    from tablegen.tabulation.info import describe_table

    if args.config:
        text = stored_config(args.table)
        print(text, end="" if text.endswith("\n") else "\n")
        return 0
    print(describe_table(read_table(args.table), Path(args.table)))
    return 0


def _report(args) -> int:
    from direct_model.simulate import check_seed
    from tablegen.study.figures import require_matplotlib
    from tablegen.study.report import DEFAULT_ALPHA1, REPORT_KIND, direct_data, table_data, write_report

    seed = check_seed(args.seed)
    check_output(args.out, REPORT_KIND, args.overwrite, folder=True)
    require_matplotlib()
    if args.config is not None and not args.direct:
        raise ValueError(f"--config {args.config} goes with --direct: a table (--table) holds its own model")
    if args.roughness_deg is not None and args.direct:
        raise ValueError("--roughness-deg goes with --table: the rough wall's facet hits take the table's paths")
    if args.direct:
        config = _config(args)
        available = (tuple(FAMILIES) if config is None else config.shapes) + (MIX,)
        shapes = args.shapes or available
        unknown = [s for s in shapes if s not in available]
        if unknown:
            raise ValueError(f"--shapes with --direct must be among {', '.join(available)}; got {unknown[0]!r}"
                             + (" (a user grain: name it in the grid of a --config FILE)" if config is None else ""))
        data = direct_data(shapes, args.alpha1 or DEFAULT_ALPHA1, args.n, seed, progress=_progress(args),
                           config=config)
    else:
        data = table_data(args.table, args.shapes, args.alpha1, args.n, seed, args.roughness_deg or ())
    path = write_report(data, args.out, overwrite=args.overwrite)
    print(f"report written to {path / 'index.md'}")
    return 0


def _calibrate(args) -> int:
    from data_schema.output import replace_file
    from tablegen.progress import progress_bar
    from tablegen.tabulation import calibration

    if args.figure is not None and Path(args.figure).resolve() == Path(args.out).resolve():
        raise ValueError(f"--figure {args.figure} is the -o file; give two files")
    check_output(args.out, calibration.WALL_FILE_KIND, args.overwrite, inputs=(args.data,))
    if args.figure is not None:
        check_output(args.figure, calibration.FIGURE_KIND, args.overwrite, inputs=(args.data,))
        calibration.require_matplotlib()
    fixed = {}
    for pairs in args.fix:
        repeated = set(pairs) & set(fixed)
        if repeated:
            raise ValueError(f"--fix names '{sorted(repeated)[0]}' twice; give each parameter once")
        fixed.update(pairs)
    data = calibration.read_measurements(args.data)
    config = _config(args)
    bars = []

    def advance(count):
        if not bars:        # the bar starts with the work: a refusal before it stays one line
            bars.append(progress_bar(True, None, "evaluation", "calibrate"))
        bars[0].update(count)

    try:
        result = calibration.calibrate(data, args.law, fixed, args.mix or args.shapes, args.particles, args.seed,
                                       config, progress=advance if _progress(args) else None,
                                       log=lambda line: print(line, file=sys.stderr))
    finally:
        for bar in bars:
            bar.close()
    print(calibration.format_calibration(result))
    figure = calibration.figure_png(result) if args.figure is not None else None
    replace_file(args.out, calibration.wall_toml(result, f"calibrated_{Path(args.data).stem}").encode("utf-8"),
                 args.overwrite)
    print(f"\nwall law written to {args.out}")
    if figure is not None:
        replace_file(args.figure, figure, args.overwrite)
        print(f"figure written to {args.figure}")
    return 0


def _grid(args) -> int:
    from data_schema.output import replace_file
    from data_schema.table import read_table
    from tablegen.tabulation import grid_fit

    normals = {}
    for patch, vector in args.normal:
        if patch in normals:
            raise ValueError(f"--normal names patch {patch!r} twice; give each patch once")
        normals[patch] = vector
    grid_fit.check_options(args.cover, args.alpha1_points, args.speed_points)
    inputs = [*args.from_hits, *([args.table] if args.table else [])]
    if args.out is not None:
        check_output(args.out, grid_fit.GRID_FILE_KIND, args.overwrite, inputs)
    table = None
    if args.table is not None:
        stored = read_table(args.table)
        table = (args.table, stored.alpha1_deg, stored.speed_m_s)
    hits = grid_fit.read_hits(args.from_hits, normals, args.patch)
    proposal = grid_fit.propose_grid(hits.alpha1, hits.speed, args.cover, args.alpha1_points, args.speed_points)
    report = grid_fit.format_report(hits, proposal, table)
    section = grid_fit.grid_toml(proposal, hits, args.from_hits)
    if args.out is None:
        # the report after the section, as TOML comments: the output redirected to a file is a grid file
        print(section)
        print("\n".join(f"# {line}".rstrip() for line in report.splitlines()))
        return 0
    print(report)
    replace_file(args.out, section.encode("utf-8"), args.overwrite)
    print(f"\ngrid written to {args.out}")
    return 0


def main(argv=None) -> int:
    args = _build_parser().parse_args(argv)
    commands = {"simulate": _simulate, "build": _build, "info": _info, "report": _report, "calibrate": _calibrate,
                "grid": _grid}
    on_interrupt = _build_interrupted if args.command == "build" else None
    return run(f"tablegen {args.command}", commands[args.command], args,
               on_interrupt=lambda signal_number: on_interrupt(args) if on_interrupt else None)


if __name__ == "__main__":
    sys.exit(main())
