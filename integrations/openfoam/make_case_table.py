"""Build the rebound table of the OpenFOAM case hopperRebound.

    python make_case_table.py OUT.h5 [--overwrite]

Prisms only (the case's `shape prism`), α1 from 1° to 90°, |V⁻| from 50 to
200 m/s (the case injects at 150 m/s; slower rebounds use the law at the
50 m/s edge, and the adapter counts them), 20 000 particles per cell: 40
cells, about 35 s on 2 cores.

Copyright (C) 2026 the rebound-scatter authors. License: GPL-3.0-or-later
(see LICENSE in this folder).
"""

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from rbs_api import build_table_from_text  # noqa: E402

CASE_TABLE_CONFIG = """\
[grid]
alpha1_deg = [1.0, 3.0, 7.5, 15.0, 30.0, 45.0, 60.0, 75.0, 85.0, 90.0]
speed_m_s = [50.0, 100.0, 150.0, 200.0]
shapes = ["prism"]
[simulation]
particles_per_cell = 20000
seed = 20261123
"""


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", type=Path)
    parser.add_argument("--overwrite", action="store_true")
    args = parser.parse_args(argv)
    build_table_from_text(CASE_TABLE_CONFIG, args.out, overwrite=args.overwrite)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
