"""Command line of the runtime side: ``surrogate sample`` and ``surrogate info``.

Reads files through :mod:`data_schema` only (the runtime never imports tablegen).
A user error ends the command with one line on stderr and exit status 2
(:mod:`data_schema.command_line`); ``--overwrite`` replaces only a samples file
and never the table being read (:mod:`data_schema.output`).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from data_schema.command_line import CommandParser, count_argument, run, seed_argument
from data_schema.common import DataFormatError
from data_schema.output import check_memory, check_output, kind_of
from data_schema.samples import (
    ALPHA1_RANGE_TEXT, SAMPLES_FILE_TYPE, SHAPE_NAMES, STATUS_NAMES, SampleSet, angles_to_velocity, read_samples,
    write_samples,
)
from data_schema.table import TABLE_FILE_TYPE

# memory per draw: the local draws, the lab-frame vectors and the file made in memory
BYTES_PER_DRAW = 300


def _mix(args):
    if args.mix is None:
        return args.shape or "ellipsoid", args.shape or "ellipsoid"
    try:
        weights = [float(w) for w in args.mix.split(",")]
    except ValueError:
        raise ValueError(f"--mix must be {len(SHAPE_NAMES)} comma-separated numbers; got {args.mix!r}") from None
    if len(weights) != len(SHAPE_NAMES):
        raise ValueError(f"--mix must have {len(SHAPE_NAMES)} weights ({','.join(SHAPE_NAMES)}); got {args.mix!r}")
    return weights, "mix:" + ",".join(f"{w:g}" for w in weights)


def _sample(args) -> int:
    import surrogate

    if args.out is not None:
        check_output(args.out, SAMPLES_FILE_TYPE, args.overwrite, inputs=(args.table,))
    check_memory(args.n, BYTES_PER_DRAW, "-n")
    shape, label = _mix(args)
    table = surrogate.load(args.table)
    draws = surrogate.sample_local(table, np.full(args.n, args.alpha1), args.speed, shape,
                                   random_state=args.seed, clamp=args.clamp)
    speed = args.speed
    velocity = angles_to_velocity(draws.alpha2, draws.beta2, speed * draws.speed_ratio)
    samples = SampleSet(velocity=velocity, omega=draws.omega, n_collisions=np.full(args.n, -1, dtype=np.int32),
                        status=draws.status, alpha1=args.alpha1, speed=speed, shape=label, seed=args.seed,
                        producer="surrogate sample",
                        provenance={"table": str(args.table), "table_config_sha256": table.config_sha256,
                                    "clamp": bool(args.clamp)})
    counts = ", ".join(f"{name} {int(np.sum(draws.status == code))}" for code, name in STATUS_NAMES.items())
    print(f"{args.n} reflected states at alpha1 = {args.alpha1:g} deg, |V-| = {speed:g} m/s, {label}: {counts}")
    ok = samples.rebounded
    for name, values in (("alpha2 (deg)", np.degrees(draws.alpha2[ok])), ("beta2 (deg)", np.degrees(draws.beta2[ok])),
                         ("|V+|/|V-|", draws.speed_ratio[ok]), ("Omega_z a/|V-|", draws.omega[ok, 2])):
        if values.size:
            q05, q50, q95 = np.percentile(values, [5, 50, 95])
            print(f"  {name:<15} mean {values.mean():8.3f}   5% {q05:8.3f}   median {q50:8.3f}   95% {q95:8.3f}")
    if args.out is not None:
        path = write_samples(args.out, samples, overwrite=args.overwrite, inputs=(args.table,))
        print(f"samples written to {path}")
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


def main(argv=None) -> int:
    parser = CommandParser(prog="surrogate", description="Runtime rebound sampler.")
    sub = parser.add_subparsers(dest="command", required=True)
    sample = sub.add_parser("sample", help="draw reflected states from a table at one incident state",
                            description="Draw n reflected states at one incident state and write them in "
                                        "the raw-samples layout of 'tablegen simulate --out' "
                                        "(n_collisions = -1: tables do not carry it per draw).")
    sample.add_argument("--table", required=True, metavar="TABLE.h5")
    sample.add_argument("--alpha1", type=float, required=True, metavar="DEG",
                        help=f"incidence angle from the wall, in the table's range (with --clamp: {ALPHA1_RANGE_TEXT})")
    sample.add_argument("--speed", type=float, required=True, metavar="M_PER_S",
                        help="incident speed |V-| in m/s, in the table's range (with --clamp: > 0)")
    group = sample.add_mutually_exclusive_group()
    group.add_argument("--shape", choices=SHAPE_NAMES)
    group.add_argument("--mix", metavar="W1,W2,W3,W4", help="weights of ellipsoid, prism, cut_prism, tetrahedron")
    sample.add_argument("-n", type=count_argument, required=True, metavar="N", help="number of draws, >= 1")
    sample.add_argument("--seed", type=seed_argument, default=None, help="random seed in [0, 2**63)")
    sample.add_argument("--clamp", action="store_true",
                        help="outside the table's range (but physical), use the law at the nearest grid edge")
    sample.add_argument("--out", metavar="FILE.h5", help="write the draws (HDF5 samples layout, docs/format.md)")
    sample.add_argument("--overwrite", action="store_true",
                        help="replace an existing --out file if it is a samples file (never the table)")
    info = sub.add_parser("info", help="describe a table or a rebound-samples file")
    info.add_argument("file")
    args = parser.parse_args(argv)
    commands = {"sample": _sample, "info": _info}
    return run(f"surrogate {args.command}", commands[args.command], args)


if __name__ == "__main__":
    sys.exit(main())
