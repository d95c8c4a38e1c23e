"""Command line of the runtime side: ``surrogate info FILE``.

Reads files through :mod:`data_schema` only (the runtime never imports tablegen).
"""

from __future__ import annotations

import argparse
import sys

import numpy as np

from data_schema.common import DataFormatError
from data_schema.samples import STATUS_NAMES, read_samples


def _info(args, parser) -> int:
    try:
        samples = read_samples(args.file)
    except (FileNotFoundError, DataFormatError) as exc:
        parser.error(str(exc))
    counts = ", ".join(f"{name} {int(np.sum(samples.status == code))}" for code, name in STATUS_NAMES.items())
    print(f"{args.file}: rebound samples by {samples.producer}")
    print(f"  shape {samples.shape}, alpha1 = {samples.alpha1:g} deg, |V-| = {samples.speed:g} m/s, "
          f"seed = {samples.seed}")
    print(f"  n = {len(samples)} ({counts})")
    if samples.extra:
        print(f"  optional datasets: {', '.join(sorted(samples.extra))}")
    return 0


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="surrogate", description="Runtime rebound sampler.")
    sub = parser.add_subparsers(dest="command", required=True)
    info = sub.add_parser("info", help="describe a rebound-samples file")
    info.add_argument("file", help="HDF5 file written by 'tablegen simulate --out'")
    args = parser.parse_args(argv)
    commands = {"info": _info}
    return commands[args.command](args, parser)


if __name__ == "__main__":
    sys.exit(main())
