"""Command line of the runtime side: ``surrogate sample``, ``surrogate info`` and ``surrogate compile``.

Reads files through :mod:`data_schema` only (the runtime never imports tablegen).
A user error ends the command with one line on stderr and exit status 2
(:mod:`data_schema.command_line`); ``--overwrite`` replaces only a samples file
and never the table being read (:mod:`data_schema.output`).
"""

from __future__ import annotations

import math
import sys
import warnings
from pathlib import Path

import numpy as np

from data_schema.command_line import CommandParser, count_argument, run, seed_argument
from data_schema.common import DataFormatError
from data_schema.output import check_memory, check_output, kind_of
from data_schema.samples import (
    ALPHA1_RANGE_TEXT, SAMPLES_FILE_TYPE, SHAPE_NAMES, STATUS_FAILED, STATUS_NAMES, SampleSet,
    read_samples, rebound_angles, write_samples,
)
from data_schema.table import TABLE_FILE_TYPE

# memory per draw: the local draws, the lab-frame vectors and the file made in memory
BYTES_PER_DRAW = 300
COMPILE_DESCRIPTION = ("Call every kernel of the runtime once on a few particles of TABLE, so that numba compiles "
                       "them into its cache for this CPU (about 3 minutes on a fresh install) and no later draw "
                       "waits for it. Any table will do: the compiled code depends on the argument types only.")


def _mix(args):
    """(the ``shape`` argument of the NumPy API, the label of the samples) from --shape or --mix; the values are
    checked by :func:`surrogate.validation.check_shape`, as the API checks them. --mix is four weights (ellipsoid,
    prism, cut_prism, tetrahedron) or name=weight pairs (any shape of the table, user grains included)."""
    if args.mix is None:
        return args.shape or "ellipsoid", args.shape or "ellipsoid"
    items = [item.strip() for item in args.mix.split(",")]
    if all("=" in item for item in items):
        weights = {}
        for item in items:
            name, _, text = item.partition("=")
            try:
                weights[name.strip()] = float(text)
            except ValueError:
                raise ValueError(f"--mix weight of {name.strip()!r} must be a number; got {text!r}") from None
        if len(weights) < len(items):
            raise ValueError(f"--mix names each shape at most once; got {args.mix!r}")
        return weights, "mix:" + ",".join(f"{name}={w:g}" for name, w in weights.items())
    try:
        weights = [float(w) for w in items]
    except ValueError:
        raise ValueError(f"--mix must be {len(SHAPE_NAMES)} comma-separated numbers (ellipsoid, prism, cut_prism, "
                         f"tetrahedron) or name=weight pairs (prism=0.5,tetrahedron=0.5); got {args.mix!r}") from None
    return weights, "mix:" + ",".join(f"{w:g}" for w in weights)


def _grain_keys(path: str, n: int) -> np.ndarray:
    """(n,) int64 grain keys from the text file ``path`` (--grain-keys): whole numbers in [0, 2**63) separated by
    white space, one per draw; an unreadable file, another count or a bad entry is a ValueError naming it."""
    try:
        tokens = Path(path).read_text().split()
    except (OSError, UnicodeDecodeError) as exc:
        raise ValueError(f"--grain-keys {path}: cannot read it ({getattr(exc, 'strerror', None) or exc}).") from None
    keys = np.empty(len(tokens), dtype=np.int64)
    for i, token in enumerate(tokens):
        try:
            key = int(token)
        except ValueError:
            key = -1
        if not 0 <= key < 2 ** 63:
            raise ValueError(f"--grain-keys {path}: entry {i + 1} is {token!r}, not a whole number in [0, 2**63).")
        keys[i] = key
    if len(keys) != n:
        raise ValueError(f"--grain-keys {path}: {len(keys)} keys, but -n asks for {n} draws (one key each).")
    return keys


def _draw(table, args, shape, omega, keys=None, roughness=0.0):
    """The hits (:class:`surrogate.Rebounds`) of ``sample_global`` at the incident state of ``args``, in the lab frame
    (wall y = 0, normal +Y, V⁻ in the XY plane), which is their impact frame.

    On a smooth wall the path is that of :func:`surrogate.kernels.rebound_path`, the same for every draw of one
    incident state. With --grain-key every draw is the grain of that key (one grain over random orientations): on
    the table path its shape (the table holds that shape's law over its random proportions), on the direct path
    its shape, proportions and hand. With ``keys`` ((n,) int64, --grain-keys: one grain per draw), those keys. On a
    rough wall (``roughness`` > 0, degrees) each facet hit takes its own path."""
    from surrogate.kernels import PATH_DIRECT, rebound_path
    from surrogate.validation import check_local_states, check_method

    check_local_states(table, args.alpha1, args.speed, clamp=True)      # the physical range, named as α1 and |V⁻|
    a1, speed = math.radians(args.alpha1), args.speed
    V = (speed * math.cos(a1), -speed * math.sin(a1), 0.0)
    spin = tuple(float(w) * speed / HALF_SIZE for w in omega)
    path = rebound_path(table.kernel_data, V, spin, (0.0, 1.0, 0.0), HALF_SIZE, check_method(args.method))
    if roughness == 0.0 and path != PATH_DIRECT:        # the table's range, unless --clamp
        check_local_states(table, args.alpha1, args.speed, args.clamp)
    if keys is None and args.grain_key is not None:
        keys = np.full(args.n, args.grain_key)
    method = args.method if roughness > 0.0 else "direct" if path == PATH_DIRECT else "table"
    return _global(table, args, V, shape, spin, keys, roughness_deg=roughness, method=method)


HALF_SIZE = 1.0        # m, of the drawn particles: any value (the draws and Omega- are in units of |V-|, |V-|/a)


def _global(table, args, V, shape, spin, keys, **kwargs):
    """``sample_global`` of -n copies of the lab-frame hit V (m/s), its law-range warning left to the summary."""
    import surrogate
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", surrogate.WallLawRangeWarning)      # the summary says it (_sample)
        return surrogate.sample_global(table, np.tile(V, (args.n, 1)), (0.0, 1.0, 0.0), HALF_SIZE, shape,
                                       random_state=args.seed, omega=spin, clamp=args.clamp, grain_key=keys, **kwargs)


def _lab_draws(hits, speed):
    """The lab-frame rebounds of ``hits`` as local draws (the lab frame is the impact frame)."""
    import surrogate
    alpha2, beta2, v = rebound_angles(hits.V)
    return surrogate.LocalDraws(alpha2=alpha2, beta2=beta2, speed_ratio=v / speed,
                                omega=hits.Omega * (HALF_SIZE / speed), status=hits.status)


def _print_work(hits, speed) -> None:
    """The summary's lines of the work on the wall: the means of W_n and W_t over the hits that have one (every
    answered hit but those of a table of format 4.0), in J/kg and in units of ½|V-|²."""
    known = np.isfinite(hits.wall_work_normal) & np.isfinite(hits.wall_work_tangential)
    if not known.any():
        print("  work on the wall: not in this table (format 4.0; rebuild it for W_n, W_t)")
        return
    energy = 0.5 * speed * speed
    normal, tangential = hits.wall_work_normal[known].mean(), hits.wall_work_tangential[known].mean()
    print(f"  work on the wall per unit mass, mean over {int(known.sum())} hits: normal W_n {normal:.6g} J/kg "
          f"({normal / energy:.4f} of 1/2|V-|^2), tangential W_t {tangential:.6g} J/kg ({tangential / energy:.4f})")


def _sample(args) -> int:
    import surrogate
    from surrogate.kernels import PATH_DIRECT, PATH_TABLE
    from direct_model.wall import MAX_ROUGHNESS_DEG
    from surrogate.validation import check_omega, check_roughness, check_shape

    if args.out is not None:
        check_output(args.out, SAMPLES_FILE_TYPE, args.overwrite, inputs=(args.table,))
    check_memory(args.n, BYTES_PER_DRAW, "-n")
    shape, label = _mix(args)
    omega = check_omega(args.omega, 1)[0]         # Ω⁻ a/|V⁻|, lab frame
    keys = None if args.grain_keys is None else _grain_keys(args.grain_keys, args.n)
    table = surrogate.load(args.table)
    check_shape(table, shape)
    if args.roughness_deg is not None and not 0.0 <= args.roughness_deg <= MAX_ROUGHNESS_DEG:
        raise ValueError(f"--roughness-deg must be in [0, {MAX_ROUGHNESS_DEG:g}] degrees; got {args.roughness_deg:g}")
    roughness = check_roughness(table, args.roughness_deg)
    hits = _draw(table, args, shape, omega, keys, roughness)
    draws, paths, wall_hits = _lab_draws(hits, args.speed), hits.path, hits.wall_hits
    n_direct = int(np.count_nonzero(paths == PATH_DIRECT))
    n_table = int(np.count_nonzero(paths == PATH_TABLE))
    direct = n_direct == args.n
    speed = args.speed
    grain, fixed = {}, {}
    if args.grain_key is not None:
        kept = surrogate.grain_of(table, [args.grain_key], shape)
        if direct:        # what the direct path fixes (NaN: fixed proportions, one hand)
            fixed = {k: float(v[0]) for k, v in zip(("ratio_ba", "ratio_cb", "hand"), kept[1:]) if not np.isnan(v[0])}
        grain = {"grain_key": args.grain_key, "grain_shape": kept.shape[0],
                 **{f"grain_{k}": v for k, v in fixed.items()}}
    if keys is not None:
        names, counts = np.unique(surrogate.grain_of(table, keys, shape).shape, return_counts=True)
        grain = {"grain_keys": str(args.grain_keys),
                 "grain_shapes": ", ".join(f"{name} {count}" for name, count in zip(names, counts))}
    samples = SampleSet(velocity=hits.V, omega=draws.omega, n_collisions=np.full(args.n, -1, dtype=np.int32),
                        status=draws.status, alpha1=args.alpha1, speed=speed, shape=label, seed=args.seed,
                        producer="surrogate sample",
                        extra={name: getattr(hits, name) for name in ("wall_work_normal", "wall_work_tangential")},
                        provenance={"table": str(args.table), "table_config_sha256": table.config_sha256,
                                    "clamp": bool(args.clamp), "method": args.method, "omega_in": omega,
                                    "path": "direct model" if direct else "table" if n_table == args.n else
                                    f"table {n_table}, direct model {n_direct}", "roughness_deg": roughness,
                                    **grain})
    counts = ", ".join(f"{name} {int(np.sum(draws.status == code))}" for code, name in STATUS_NAMES.items())
    spin = "" if not np.any(omega) else f", Omega- a/|V-| = ({', '.join(f'{w:g}' for w in omega)})"
    print(f"{args.n} reflected states at alpha1 = {args.alpha1:g} deg, |V-| = {speed:g} m/s{spin}, {label}: {counts}")
    print(f"  answered by the table {n_table}, by the direct model {n_direct} "
          f"(method {args.method}{'; the last facet hit of each' if roughness > 0.0 else ''}); failed "
          f"{int(np.sum(draws.status == STATUS_FAILED))}")
    if roughness > 0.0:
        again = int(np.count_nonzero(wall_hits > 1))
        capped = int(np.count_nonzero(wall_hits == surrogate.MAX_WALL_HITS))
        print(f"  rough wall, roughness {roughness:g} deg: {again} hit the wall again (mean facet hits "
              f"{wall_hits[wall_hits > 0].mean():.3f}), {capped} reached the cap of {surrogate.MAX_WALL_HITS}")
    if table.wall.outside_speed_range(speed):
        print(f"  outside the speeds the wall law {table.wall.name!r} holds over ({table.wall.speed_range_text()}): "
              f"all {args.n}; the law is applied all the same")
    if keys is not None:
        print(f"  {args.n} grains, one per draw, from {args.grain_keys}: {grain['grain_shapes']}")
    elif grain:
        labels = {"ratio_ba": "b/a", "ratio_cb": "c/b", "hand": "hand"}
        kept = (", ".join(f"{labels[k]} {v:.4g}" for k, v in fixed.items()) + ", kept on every hit") if fixed else \
            "fixed proportions" if direct else "proportions from the shape's law (table path)"
        print(f"  one grain, key {args.grain_key}: {grain['grain_shape']}, {kept}")
    ok = samples.rebounded
    for name, values in (("alpha2 (deg)", np.degrees(draws.alpha2[ok])), ("beta2 (deg)", np.degrees(draws.beta2[ok])),
                         ("|V+|/|V-|", draws.speed_ratio[ok]), ("Omega_z a/|V-|", draws.omega[ok, 2])):
        if values.size:
            q05, q50, q95 = np.percentile(values, [5, 50, 95])
            print(f"  {name:<15} mean {values.mean():8.3f}   5% {q05:8.3f}   median {q50:8.3f}   95% {q95:8.3f}")
    _print_work(hits, speed)
    if args.out is not None:
        written = write_samples(args.out, samples, overwrite=args.overwrite, inputs=(args.table,))
        print(f"samples written to {written}")
    return 0


def _info(args) -> int:
    path = Path(args.file)
    if path.is_dir():
        raise DataFormatError(f"{path}: is a folder; give a table or a samples file")
    if not path.exists():
        raise FileNotFoundError(f"{path}: no such file")
    if not path.is_file():      # a FIFO or a device would block or never end
        raise DataFormatError(f"{path}: is not a regular file (a FIFO, a device or a socket); give a table or a "
                              f"samples file")
    file_type = kind_of(path)
    if file_type == TABLE_FILE_TYPE:
        import surrogate
        table = surrogate.load(path)
        print(f"{path}: rebound table, {path.stat().st_size / 1e6:.1f} MB, shapes {', '.join(table.shapes)}")
        print(f"  alpha1 {table.alpha1_range[0]:g}..{table.alpha1_range[1]:g} deg "
              f"({len(table.alpha1_deg)} values), speed {table.speed_range[0]:g}..{table.speed_range[1]:g} m/s "
              f"({len(table.speed_m_s)} values), {table.particles_per_cell} particles per cell, "
              f"n_max {table.n_max}, config sha256 {table.config_sha256[:16]}")
        return 0
    if file_type != SAMPLES_FILE_TYPE:
        raise DataFormatError(f"{path}: is neither a {TABLE_FILE_TYPE} nor a {SAMPLES_FILE_TYPE} file "
                              f"(found: {file_type or 'not a file of rebound-scatter'})")
    samples = read_samples(path)
    counts = ", ".join(f"{name} {int(np.sum(samples.status == code))}" for code, name in STATUS_NAMES.items())
    print(f"{path}: rebound samples by {samples.producer}")
    print(f"  shape {samples.shape}, alpha1 = {samples.alpha1:g} deg, |V-| = {samples.speed:g} m/s, "
          f"seed = {samples.seed}")
    print(f"  n = {len(samples)} ({counts})")
    if samples.extra:
        print(f"  optional datasets: {', '.join(sorted(samples.extra))}")
    return 0


def _compile(args) -> int:
    import surrogate
    from surrogate.compilation import compile_kernels
    table = surrogate.load(args.table)
    print(f"compiling the runtime's kernels into numba's cache for this CPU (with {table.path}'s types)", flush=True)
    def report(name, seconds, compiled):
        print(f"  {name}: {seconds:.1f} s, " + (f"{compiled} functions compiled" if compiled else "from the cache"),
              flush=True)

    done = compile_kernels(table, report)
    print(f"done: {len(done)} kernels in {sum(d[1] for d in done):.1f} s, {sum(d[2] for d in done)} functions "
          f"compiled; later processes load them from the cache")
    return 0


def main(argv=None) -> int:
    parser = CommandParser(prog="surrogate", description="Runtime rebound sampler.")
    sub = parser.add_subparsers(dest="command", required=True)
    sample = sub.add_parser("sample", help="draw reflected states from a table at one incident state",
                            description="Draw n reflected states at one incident state and write them in "
                                        "the raw-samples layout of 'tablegen simulate --out' "
                                        "(n_collisions = -1: neither the tables nor the run-time direct model "
                                        "carry it per draw).")
    sample.add_argument("--table", required=True, metavar="TABLE.h5")
    sample.add_argument("--alpha1", type=float, required=True, metavar="DEG",
                        help=f"incidence angle from the wall, {ALPHA1_RANGE_TEXT} (with --method table: in the "
                             f"table's range, unless --clamp)")
    sample.add_argument("--speed", type=float, required=True, metavar="M_PER_S",
                        help="incident speed |V-| in m/s, > 0 (with --method table: in the table's range, unless "
                             "--clamp)")
    group = sample.add_mutually_exclusive_group()
    group.add_argument("--shape", metavar="NAME", help="a shape the table holds: a built-in family or a user grain "
                                                       "(tablegen info lists them; default ellipsoid)")
    group.add_argument("--mix", metavar="W1,W2,W3,W4|NAME=W,...",
                       help="weights of ellipsoid, prism, cut_prism, tetrahedron, or name=weight pairs of any of "
                            "the table's shapes (user grains included), e.g. prism=0.5,tetrahedron=0.5; weights "
                            ">= 0 summing to 1")
    sample.add_argument("-n", type=count_argument, required=True, metavar="N", help="number of draws, >= 1")
    sample.add_argument("--seed", type=seed_argument, default=None, help="random seed in [0, 2**63)")
    sample.add_argument("--omega", type=float, nargs=3, default=(0.0, 0.0, 0.0), metavar=("WX", "WY", "WZ"),
                        help="incident angular velocity Omega- a/|V-|, lab frame (default 0 0 0), as tablegen "
                             "simulate's")
    sample.add_argument("--method", choices=("auto", "table", "direct"), default="auto",
                        help="auto (default): the table where it is valid (|Omega-|a/|V-| <= the spin tolerance, "
                             "inside the grid), the direct model elsewhere; table: always the table (Omega- "
                             "ignored); direct: always the direct model")
    keyed = sample.add_mutually_exclusive_group()
    keyed.add_argument("--grain-key", type=seed_argument, default=None, metavar="K",
                       help="a grain key in [0, 2**63): every draw is that one grain over random orientations "
                            "(its shape from the mix by the key; on the direct path its proportions and hand "
                            "too), as a particle of that key hits every time")
    keyed.add_argument("--grain-keys", default=None, metavar="FILE",
                       help="a text file of N grain keys in [0, 2**63), one per draw (white space between): draw "
                            "i is the grain of key i (sample_global's grain_key)")
    sample.add_argument("--roughness-deg", type=float, default=None, metavar="DEG",
                        help="the wall's roughness in degrees, in [0, 45] (default: the table's wall's; 0 a smooth "
                             "wall): each draw lands on a facet tilted at random and may hit again (docs/model.md "
                             "§12)")
    sample.add_argument("--clamp", action="store_true",
                        help="with --method table: outside the table's range (but physical), use the law at the "
                             "nearest grid edge")
    sample.add_argument("--out", metavar="FILE.h5", help="write the draws (HDF5 samples layout, docs/format.md)")
    sample.add_argument("--overwrite", action="store_true",
                        help="replace an existing --out file if it is a samples file (never the table)")
    info = sub.add_parser("info", help="describe a table or a rebound-samples file")
    info.add_argument("file")
    compile_ = sub.add_parser("compile", help="compile every kernel of the runtime into numba's cache",
                              description=COMPILE_DESCRIPTION)
    compile_.add_argument("--table", required=True, metavar="TABLE.h5")
    args = parser.parse_args(argv)
    commands = {"sample": _sample, "info": _info, "compile": _compile}
    return run(f"surrogate {args.command}", commands[args.command], args)


if __name__ == "__main__":
    sys.exit(main())
