"""Command line of the runtime side: ``surrogate sample`` and ``surrogate info``.

Reads files through :mod:`data_schema` only (the runtime never imports tablegen).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import h5py
import numpy as np

from data_schema.common import DataFormatError
from data_schema.samples import (
    SAMPLES_FILE_TYPE, SHAPE_NAMES, STATUS_NAMES, SampleSet, read_samples, write_samples,
)
from data_schema.table import TABLE_FILE_TYPE



def _mix(args, parser):
    if args.mix is None:
        return args.shape or "ellipsoid", args.shape or "ellipsoid"
    try:
        weights = [float(w) for w in args.mix.split(",")]
    except ValueError:
        parser.error(f"--mix must be {len(SHAPE_NAMES)} comma-separated numbers; got {args.mix!r}")
    if len(weights) != len(SHAPE_NAMES):
        parser.error(f"--mix must have {len(SHAPE_NAMES)} weights ({','.join(SHAPE_NAMES)}); got {args.mix!r}")
    return weights, "mix:" + ",".join(f"{w:g}" for w in weights)


def _sample(args, parser) -> int:
    import surrogate

    if args.out and not args.overwrite and Path(args.out).exists():
        parser.error(f"--out {args.out} exists; pass --overwrite to replace it")
    if args.n < 1:
        parser.error(f"-n must be >= 1; got {args.n}")
    shape, label = _mix(args, parser)
    try:
        table = surrogate.load(args.table)
        draws = surrogate.sample_local(table, np.full(args.n, args.alpha1), args.speed, shape,
                                       random_state=args.seed, clamp=args.clamp)
    except (FileNotFoundError, DataFormatError, ValueError) as exc:
        parser.error(str(exc))
    speed = args.speed
    cb = np.cos(draws.beta2)
    velocity = speed * draws.speed_ratio[:, None] * np.column_stack(
        [cb * np.cos(draws.alpha2), cb * np.sin(draws.alpha2), np.sin(draws.beta2)])
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
    if args.out:
        print(f"samples written to {write_samples(args.out, samples, overwrite=args.overwrite)}")
    return 0


def _info(args, parser) -> int:
    path = Path(args.file)
    try:
        with h5py.File(path, "r") as f:
            file_type = f.attrs.get("file_type")
    except (OSError, FileNotFoundError) as exc:
        parser.error(f"{path}: not a readable HDF5 file: {exc}")
    if isinstance(file_type, bytes):
        file_type = file_type.decode()
    try:
        if file_type == TABLE_FILE_TYPE:
            import surrogate
            table = surrogate.load(path)
            print(f"{path}: rebound table, {path.stat().st_size / 1e6:.1f} MB, shapes {', '.join(table.shapes)}")
            print(f"  alpha1 {table.alpha1_range[0]:g}..{table.alpha1_range[1]:g} deg "
                  f"({len(table.alpha1_deg)} values), speed {table.speed_range[0]:g}..{table.speed_range[1]:g} m/s "
                  f"({len(table.speed_m_s)} values), {table.particles_per_cell} particles per cell, "
                  f"n_max {table.n_max}, config sha256 {table.config_sha256[:16]}")
            return 0
        if file_type == SAMPLES_FILE_TYPE:
            samples = read_samples(path)
        else:
            raise DataFormatError(f"{path}: file_type {file_type!r} is neither {TABLE_FILE_TYPE!r} nor "
                                  f"{SAMPLES_FILE_TYPE!r}")
    except (FileNotFoundError, DataFormatError) as exc:
        parser.error(str(exc))
    counts = ", ".join(f"{name} {int(np.sum(samples.status == code))}" for code, name in STATUS_NAMES.items())
    print(f"{path}: rebound samples by {samples.producer}")
    print(f"  shape {samples.shape}, alpha1 = {samples.alpha1:g} deg, |V-| = {samples.speed:g} m/s, "
          f"seed = {samples.seed}")
    print(f"  n = {len(samples)} ({counts})")
    if samples.extra:
        print(f"  optional datasets: {', '.join(sorted(samples.extra))}")
    return 0


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="surrogate", description="Runtime rebound sampler.")
    sub = parser.add_subparsers(dest="command", required=True)
    sample = sub.add_parser("sample", help="draw reflected states from a table at one incident state",
                            description="Draw n reflected states at one incident state and write them in "
                                        "the raw-samples layout of 'tablegen simulate --out' "
                                        "(n_collisions = -1: tables do not carry it per draw).")
    sample.add_argument("--table", required=True, metavar="TABLE.h5")
    sample.add_argument("--alpha1", type=float, required=True, metavar="DEG")
    sample.add_argument("--speed", type=float, required=True, metavar="M_PER_S")
    group = sample.add_mutually_exclusive_group()
    group.add_argument("--shape", choices=SHAPE_NAMES)
    group.add_argument("--mix", metavar="W1,W2,W3,W4", help="weights of ellipsoid, prism, cut_prism, tetrahedron")
    sample.add_argument("-n", type=int, required=True, metavar="N")
    sample.add_argument("--seed", type=int, default=None)
    sample.add_argument("--clamp", action="store_true", help="outside the table, use the nearest grid edge")
    sample.add_argument("--out", metavar="FILE.h5")
    sample.add_argument("--overwrite", action="store_true")
    info = sub.add_parser("info", help="describe a table or a rebound-samples file")
    info.add_argument("file")
    args = parser.parse_args(argv)
    commands = {"sample": _sample, "info": _info}
    return commands[args.command](args, parser)


if __name__ == "__main__":
    sys.exit(main())
