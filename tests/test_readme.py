"""The Python examples of the runtime sampler, in the README and in docs/runtime.md, run as written and give
physical rebounds."""

import re
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text()
RUNTIME_DOC = (ROOT / "docs" / "runtime.md").read_text()


def _python_blocks(text: str, section: str) -> list:
    """The ```python blocks of the section of ``text`` titled ``section`` (up to the next level-2 title)."""
    start = text.index(f"\n## {section}\n")
    end = text.find("\n## ", start + 1)
    return re.findall(r"```python\n(.*?)```", text[start:end], flags=re.S)


def _run(code: str, namespace: dict, table_path) -> dict:
    """The draws of an example: its record ``hits`` (surrogate.Rebounds) if it makes one, else its arrays."""
    exec(compile(code.replace('"table.h5"', repr(str(table_path))), "README.md", "exec"), namespace)
    if re.search(r"^hits = ", code, flags=re.M):
        return {"V_out": np.array(namespace["hits"].V), "status": np.array(namespace["hits"].status)}
    return {k: np.array(namespace[k]) for k in ("V_out", "status")}


def _check_rebounds(result, V, n):
    """Every draw rebounded or trapped; every rebound leaves the wall without gaining speed."""
    status, V_out = result["status"], result["V_out"]
    assert set(np.unique(status)) <= {0, 1} and np.mean(status == 0) > 0.9
    ok = status == 0
    assert np.all(V_out[ok] @ n > 0.0)
    assert np.all(np.linalg.norm(V_out[ok], axis=1) <= np.linalg.norm(V[ok], axis=1))
    return V_out[ok]


def test_runtime_sampler_examples_run_and_draw_one_law(small_table_path):
    numpy_api, = _python_blocks(README, "Runtime sampler")
    numba_api, = _python_blocks(RUNTIME_DOC, "From numba code")
    spin_api, direct_api = _python_blocks(RUNTIME_DOC, "Spinning particles and states beyond the table")
    namespace = {}
    drawn = {"sample_global": _run(numpy_api, namespace, small_table_path)}
    # the direct model with spin (alone, and for the spinning half under "auto"): a law of its own (and spin can
    # feed |V⁺|), so only that rebounds leave the wall; "auto" answers the others from the table
    for code in (direct_api, spin_api):
        direct = _run(code, namespace, small_table_path)
        ok = direct["status"] == 0
        assert ok.mean() > 0.9 and np.all(direct["V_out"][ok] @ namespace["normals"] > 0.0)
    np.testing.assert_array_equal(namespace["hits"].path, np.resize([1, 0], 1000))
    drawn["table_rebound_many_rng"] = _run(numba_api, namespace, small_table_path)
    V, n = namespace["V"], namespace["normals"]
    per_particle = {k: np.empty_like(namespace[k]) for k in ("V_out", "Omega_out", "status")}
    namespace["bounce_hits"](namespace["data"], namespace["cdf"], V, namespace["n"], namespace["a"],
                             namespace["surrogate"].seed_state(2), *per_particle.values())
    drawn["table_rebound loop"] = per_particle
    rebounds = {name: _check_rebounds(result, V, n) for name, result in drawn.items()}
    # The three are independent samples of one law at one incident state: the difference of two
    # sample means has SE sqrt(s1²/n1 + s2²/n2); 5 SE over 3 components and 2 pairs leaves a false
    # alarm rate below 1e-5, while a wrong frame or sign moves a mean by tens of SE (n ≈ 1000).
    reference = rebounds["sample_global"]
    for name in ("table_rebound_many_rng", "table_rebound loop"):
        other = rebounds[name]
        se = np.sqrt(reference.var(axis=0) / len(reference) + other.var(axis=0) / len(other))
        assert np.all(np.abs(reference.mean(axis=0) - other.mean(axis=0)) < 5 * se), name


def test_the_tables_config_of_user_grains_builds_its_shapes(tmp_path):
    """The README's ```toml block (section "Tables") parses, its mesh path read beside the configuration, into
    the prism and the two grains it names."""
    import trimesh
    from tablegen.tabulation.config import load_config

    start = README.index("\n## Tables\n")
    block, = re.findall(r"```toml\n(.*?)```", README[start:README.find("\n## ", start + 1)], flags=re.S)
    (tmp_path / "grains").mkdir()
    trimesh.load(ROOT / "examples" / "grains" / "grain_1.obj", process=False).export(tmp_path / "grains" / "sand_a.stl")
    (tmp_path / "grains.toml").write_text(block)
    config = load_config(tmp_path / "grains.toml")
    assert config.shapes == ("prism", "sand_a", "sand_b")
    assert [g.name for g in config.grains] == ["sand_a", "sand_b"] and len(config.grain("sand_b").vertices) == 5
