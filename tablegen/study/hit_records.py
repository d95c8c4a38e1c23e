"""The wall-hit records a solver adapter writes, read into arrays: the layout both adapters share.

The OpenFOAM adapter (integrations/openfoam) and the code_saturne user sources (integrations/code_saturne)
write one CSV file per rank, ``hits_<rank>.csv``:

* line 1, the run's settings: ``# <title> hits: seed S, stream K, table PATH, mix MIX, halfSizeFactor F,
  interpolation I, method M, spin tolerance T, grain G (key seed K)``, MIX a shape name, ``mix`` or
  ``weights (name w, ...)``
  (OpenFOAM writes ``name w``, code_saturne ``name:w``), G ``kept`` (a particle hits as one grain, its key
  fixed for life from the seed K and its ids, docs/model.md §11) or ``perHit`` (a new grain from the mix at
  every hit, without ``(key seed K)``; files written before grain keys have no ``, grain G`` and drew per hit);
* line 2, free text; line 3, the column names :data:`HIT_COLUMNS`;
* a row per hit: time (s), rank, the boundary (``patch``), origProc/origId (−1 where the solver has no
  persistent particle id), d (m), a (m), V⁻ relative to the wall (m/s), Ω⁻ (rad/s), n into the gas, U_w (m/s),
  status (``surrogate.STATUS_*``), path (0 table, 1 direct model, −1 invalid), V⁺, Ω⁺, |Ω⁻|a/|V⁻|, the
  draw's first uniform, and the grain (:data:`GRAIN_COLUMNS`): the particle's grain key (−1: a new grain per
  hit), its shape's name (empty: drawn per hit), and b/a, c/b and the hand (±1) where the direct path fixed
  them (NaN on the table path, which draws them from the shape's law, and for a shape without them); all in
  the solver's frame; then what the patch does (:data:`PATCH_COLUMNS`): ``interaction`` (the title's model,
  or a stock one such as ``rebound``) and ``wall``, the name of its table's wall (empty for a stock one).
  Files written before grain keys lack the grain columns: they read with key −1, shape empty and NaN; files
  without the patch columns (code_saturne's) read as the title's model with the wall empty.

The solver's log ends with a summary of counts (``- wall hits = N`` and so on, :func:`summary_counts`).
What is a solver's own (where the files are, its other records) stays in its integration; the comparison's
statistics are :mod:`tablegen.study.solver_comparison`'s.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

import surrogate
from surrogate.kernels import PATH_DIRECT
from tablegen.study.solver_comparison import SolverHits

__all__ = ["GRAIN_COLUMNS", "HIT_COLUMNS", "PATCH_COLUMNS", "grain_mismatches", "parse_header", "rank_files", "read_hit_files",
           "solver_hits", "summary_counts"]

_HIT_COLUMNS_BEFORE_GRAINS = ("time,rank,patch,origProc,origId,d,a,Vx,Vy,Vz,Winx,Winy,Winz,nx,ny,nz,Uwx,Uwy,Uwz,"
                              "status,path,Voutx,Vouty,Voutz,Wx,Wy,Wz,spin_ratio,u0").split(",")
GRAIN_COLUMNS = ["key", "shape", "ratio_ba", "ratio_cb", "hand"]
_HIT_COLUMNS_BEFORE_PATCHES = _HIT_COLUMNS_BEFORE_GRAINS + GRAIN_COLUMNS
PATCH_COLUMNS = ["interaction", "wall"]
HIT_COLUMNS = _HIT_COLUMNS_BEFORE_PATCHES + PATCH_COLUMNS
_INTEGER_COLUMNS = ("rank", "origProc", "origId", "status", "path", "key")
_TEXT_COLUMNS = ("patch", "shape", "interaction", "wall")
_GRAIN_DEFAULTS = {"key": "-1", "shape": "", "ratio_ba": "nan", "ratio_cb": "nan", "hand": "nan"}
_VECTORS = {"V": "Vx Vy Vz", "Win": "Winx Winy Winz", "n": "nx ny nz", "Uw": "Uwx Uwy Uwz",
            "Vout": "Voutx Vouty Voutz", "Wout": "Wx Wy Wz"}
_COUNTS = {"hits": "- wall hits", "table": "- answered by the table", "direct": "- answered by the direct model",
           "rebounded": "- rebounded", "trapped": "- trapped", "failed": "- failed (direct model)",
           "invalid": "- invalid", "outside": "- outside the table's grid"}


def parse_header(line: str, title: str) -> dict:
    """The run's settings from the first line of a hits file whose header starts ``# <title> hits:``.

    Returns seed, stream, table, shape (a name or a dict of weights), half_size_factor, interpolation, method,
    spin_tolerance, grain (``kept`` or ``perHit``; ``perHit`` for a header written before grain keys) and
    grain_seed (the keys' seed under ``kept``, else None).
    ValueError if the line is not such a header.
    """
    m = re.match(rf"# {re.escape(title)} hits: seed (\d+), stream (\d+), table (.*), mix (.*), "
                 r"halfSizeFactor (\S+), interpolation (\w+), method (\w+), spin tolerance ([^,\s]+)"
                 r"(?:, grain (kept \(key seed (\d+)\)|perHit))?$", line.strip())
    if not m:
        raise ValueError(f"not a {title} hits header: {line!r}")
    mix = m.group(4)
    if mix.startswith("weights ("):
        items = (re.split(r"[:\s]+", item.strip()) for item in mix[len("weights ("):-1].split(","))
        shape = {name: float(weight) for name, weight in items}
    else:
        shape = mix
    return {"seed": int(m.group(1)), "stream": int(m.group(2)), "table": m.group(3), "shape": shape,
            "half_size_factor": float(m.group(5)), "interpolation": m.group(6), "method": m.group(7),
            "spin_tolerance": float(m.group(8)), "grain": (m.group(9) or "perHit").split()[0],
            "grain_seed": int(m.group(10)) if m.group(10) else None}


def _is_number(text: str, integer: bool) -> bool:
    """Whether ``text`` reads as an int (``integer``) or a float."""
    try:
        int(text) if integer else float(text)
    except ValueError:
        return False
    return True


def read_hit_files(files, title: str) -> tuple[dict, list]:
    """The hit records of ``files`` (in the order given) as columns, and each file's settings.

    Columns by :data:`HIT_COLUMNS` name (``patch``, ``shape``, ``interaction`` and ``wall`` strings, the integer
    columns int64, the rest float64), plus the (N, 3) arrays V, Win, n, Uw, Vout and Wout. A file written before
    grain keys (no :data:`GRAIN_COLUMNS`) reads with key −1, shape ``""`` and NaN proportions and hand; one
    without :data:`PATCH_COLUMNS`, with interaction ``title`` and wall ``""``. ValueError naming the
    file and line for a file of another layout.
    """
    headers, rows = [], []
    for f in files:
        with open(f) as fh:
            headers.append(parse_header(fh.readline(), title))
            fh.readline()
            columns = fh.readline().strip().split(",")
            if columns not in (HIT_COLUMNS, _HIT_COLUMNS_BEFORE_PATCHES, _HIT_COLUMNS_BEFORE_GRAINS):
                raise ValueError(f"{f}: line 3 is not the hits columns {','.join(HIT_COLUMNS)}")
            defaults = {**_GRAIN_DEFAULTS, "interaction": title, "wall": ""}
            missing = [defaults[c] for c in HIT_COLUMNS[len(columns):]]
            for line_no, line in enumerate(fh, start=4):
                if not line.strip():
                    continue
                row = line.rstrip("\n").split(",")
                if len(row) != len(columns):
                    raise ValueError(f"{f}, line {line_no}: {len(row)} fields, not {len(columns)}")
                for name, value in zip(columns, row):
                    if name not in _TEXT_COLUMNS and not _is_number(value, name in _INTEGER_COLUMNS):
                        raise ValueError(f"{f}, line {line_no}: column {name} is not "
                                         f"{'an integer' if name in _INTEGER_COLUMNS else 'a number'}: {value!r}")
                rows.append(row + missing)
    cols = {}
    for j, name in enumerate(HIT_COLUMNS):
        values = [r[j] for r in rows]
        dtype = object if name in _TEXT_COLUMNS else np.int64 if name in _INTEGER_COLUMNS else float
        cols[name] = np.array(values, dtype=dtype)
    for vector, names in _VECTORS.items():
        cols[vector] = np.column_stack([cols[c] for c in names.split()]).reshape(-1, 3)
    return cols, headers


def rank_files(folder: Path) -> list:
    """The ``hits_<rank>.csv`` files of a folder in rank order (FileNotFoundError if there are none)."""
    files = sorted(Path(folder).glob("hits_*.csv"), key=lambda p: int(p.stem.split("_")[1]))
    if not files:
        raise FileNotFoundError(f"{folder}: no hits_<rank>.csv")
    return files


def solver_hits(hits: dict, settings: dict) -> SolverHits:
    """The columns of :func:`read_hit_files` as a :class:`SolverHits` (``settings``: a file's header), with the
    particles' grain keys under ``grain kept``."""
    return SolverHits(V=hits["V"], Omega=hits["Win"], n=hits["n"], a=hits["a"], shape=settings["shape"],
                      V_out=hits["Vout"], Omega_out=hits["Wout"], status=hits["status"], path=hits["path"],
                      grain_key=hits["key"] if settings["grain"] == "kept" else None)


def grain_mismatches(hits: dict, settings: dict, table) -> dict:
    """How many hits of a grain-kept run do not carry their key's grain: the grain :func:`surrogate.grain_of`
    gives the recorded key in the run's mix (``settings["shape"]``) of ``table`` (the loaded table the run drew
    from). Counts: ``key`` (a key < 0), and of the others ``shape`` (another shape name), ``direct`` (on the
    direct path, a b/a, c/b or hand other than the key's, to the bit, NaN equal to NaN); ``table`` (off the
    direct path, a proportion or hand recorded: the table path draws them from the shape's law). All zero:
    every hit carried its particle's grain."""
    keys = hits["key"]
    valid = keys >= 0
    grains = surrogate.grain_of(table, np.where(valid, keys, 0), settings["shape"])
    direct = hits["path"] == PATH_DIRECT
    recorded = np.column_stack([hits["ratio_ba"], hits["ratio_cb"], hits["hand"]])
    expected = np.column_stack([grains.ratio_ba, grains.ratio_cb, grains.hand])
    same = (recorded == expected) | (np.isnan(recorded) & np.isnan(expected))
    return {"key": int(np.sum(~valid)), "shape": int(np.sum(valid & (hits["shape"] != grains.shape))),
            "direct": int(np.sum(valid & direct & ~same.all(axis=1))),
            "table": int(np.sum(~direct & ~np.isnan(recorded).all(axis=1)))}


def summary_counts(block: str) -> dict:
    """The counts of an adapter's summary (``- wall hits = N`` ...) in a block of a solver's log.

    Keys: hits, table, direct, rebounded, trapped, failed, invalid, outside, and direct_us, the direct model's
    mean cost per hit (µs). ValueError naming the first count missing from the block.
    """
    out = {}
    for key, label in _COUNTS.items():
        m = re.search(re.escape(label) + r"[^=]*=\s*([-0-9.eE+]+)", block)
        if m is None:
            raise ValueError(f"the summary has no count {label!r}")
        out[key] = int(float(m.group(1)))
    cost = re.search(r"answered by the direct model\s*=\s*\d+ \(mean cost\s*([-0-9.eE+]+) us per hit\)", block)
    if cost is None:
        raise ValueError("the summary has no mean cost of the direct model")
    out["direct_us"] = float(cost.group(1))
    return out
