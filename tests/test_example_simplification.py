"""examples/grains/simplification.py: each simplified hull within its max_vertices, a row for every version and
state, and the 16-vertex grain at least as distinguishable from the full one as the full one from itself."""

import math
import re

import pytest

from tests.helpers.examples import EXAMPLES, example_module

N = 300


def test_the_simplification_example_compares_every_version_at_every_state(tmp_path, capsys):
    pytest.importorskip("fast_simplification")
    pytest.importorskip("matplotlib")
    module = example_module(EXAMPLES / "grains" / "simplification.py")
    figure = tmp_path / "simplification.png"
    assert module.main(["--n", str(N), "--figure", str(figure)]) == 0
    out = capsys.readouterr().out
    full = int(re.search(r"full hull: (\d+) vertices", out).group(1))
    assert full > max(module.MAX_VERTICES)                      # scanned-like: every version is a simplification
    simplified = [tuple(map(int, m)) for m in re.findall(r"max_vertices = (\d+): simplified from (\d+) to (\d+)", out)]
    assert [(n, before) for n, before, _ in simplified] == [(n, full) for n in module.MAX_VERTICES]
    assert all(after <= n for n, _, after in simplified)
    versions = (module.BASELINE, *map(str, module.MAX_VERTICES))
    rows = {(r[0], float(r[1])): r for r in (line.split() for line in out.splitlines()) if r and r[0] in versions}
    assert list(rows) == [(v, a) for a in module.ALPHA1_DEG for v in versions]
    for (version, _), r in rows.items():
        vertices, us, accuracy, ks = int(r[2]), float(r[3]), float(r[6]), float(r[7])
        assert vertices == full if version == module.BASELINE else vertices <= int(version)
        assert us > 0.0 and 0.0 <= accuracy <= 1.0 and 0.0 <= ks <= 1.0
    noise = 4.0 * math.sqrt(0.25 / N)                           # four standard errors of the held-out accuracy
    for alpha1 in module.ALPHA1_DEG:
        assert float(rows["16", alpha1][6]) >= float(rows[module.BASELINE, alpha1][6]) - noise
    assert figure.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
