"""The hit records both solver adapters write (tablegen.study.hit_records): header, columns, counts."""

import numpy as np
import pytest

from tablegen.study.hit_records import (GRAIN_COLUMNS, HIT_COLUMNS, PATCH_COLUMNS, grain_mismatches, parse_header, rank_files,
                                        read_hit_files, solver_hits, summary_counts)

OPENFOAM = ("# stochasticRebound hits: seed 7, stream 1, table /t/a.h5, mix weights (prism 0.25, tetrahedron 0.75), "
            "halfSizeFactor 0.5, interpolation nearest, method auto, spin tolerance 0.001")
SATURNE = ("# code_saturne rebound-scatter hits: seed 7, stream 0, table /t/a.h5, mix weights (prism:0.25, "
           "tetrahedron:0.75), halfSizeFactor 0.5, interpolation nearest, method auto, spin tolerance 0.001")


def _write(path, header, rows, columns=HIT_COLUMNS):
    lines = [header, "# free text", ",".join(columns)]
    for k in range(rows):
        values = dict.fromkeys(HIT_COLUMNS, "0.5")
        values.update(rank="1", patch=f"wall{k}", origProc="-1", origId=str(k), status="0", path=str(k % 2),
                      Vx=str(k), Vy="-3", Vz="0.25", key=str(1000 + k), shape="prism" if k % 2 else "tetrahedron",
                      hand="-1" if k % 2 else "nan", interaction="rebound" if k == 1 else "stochasticRebound",
                      wall="corundum_on_St3" if k != 1 else "")
        lines.append(",".join(values[c] for c in columns))
    path.write_text("\n".join(lines) + "\n")


@pytest.mark.parametrize("title, header", [("stochasticRebound", OPENFOAM),
                                           ("code_saturne rebound-scatter", SATURNE)])
def test_both_headers_give_the_same_settings(title, header):
    settings = parse_header(header, title)
    assert settings["shape"] == {"prism": 0.25, "tetrahedron": 0.75}
    assert (settings["seed"], settings["table"], settings["method"], settings["spin_tolerance"]) == (
        7, "/t/a.h5", "auto", 0.001)
    # written before grain keys: a new grain per hit
    assert (settings["grain"], settings["grain_seed"]) == ("perHit", None)
    with pytest.raises(ValueError, match="not a other hits header"):
        parse_header(header, "other")


@pytest.mark.parametrize("grain, seed", [("kept (key seed 42)", 42), ("perHit", None)])
def test_the_header_names_the_grain_mode_and_the_keys_seed(grain, seed):
    settings = parse_header(OPENFOAM + f", grain {grain}", "stochasticRebound")
    assert (settings["grain"], settings["grain_seed"]) == (grain.split()[0], seed)
    for bad in (", grain sometimes", ", grain kept", ", grain perHit (key seed 42)"):
        with pytest.raises(ValueError, match="not a stochasticRebound hits header"):
            parse_header(OPENFOAM + bad, "stochasticRebound")


def test_the_grain_columns_and_a_file_written_before_them(tmp_path):
    _write(tmp_path / "hits_0.csv", OPENFOAM + ", grain kept (key seed 7)", 2)
    _write(tmp_path / "hits_1.csv", OPENFOAM, 2, columns=HIT_COLUMNS[:-len(GRAIN_COLUMNS) - len(PATCH_COLUMNS)])
    cols, headers = read_hit_files(rank_files(tmp_path), "stochasticRebound")
    assert [h["grain"] for h in headers] == ["kept", "perHit"]
    assert cols["key"].dtype == np.int64 and cols["key"].tolist() == [1000, 1001, -1, -1]
    assert cols["shape"].tolist() == ["tetrahedron", "prism", "", ""]
    assert cols["ratio_ba"][:2].tolist() == [0.5, 0.5] and np.isnan(cols["ratio_ba"][2:]).all()
    assert np.isnan(cols["hand"][[0, 2, 3]]).all() and cols["hand"][1] == -1
    assert cols["V"][:, 0].tolist() == [0, 1, 0, 1]
    # what the patch did, and a file without those columns: the title's model, no wall
    assert cols["interaction"].tolist() == ["stochasticRebound", "rebound", "stochasticRebound", "stochasticRebound"]
    assert cols["wall"].tolist() == ["corundum_on_St3", "", "", ""]
    # the comparison draws a kept grain's hits as its grain, and every hit afresh otherwise
    kept, kept_headers = read_hit_files(rank_files(tmp_path)[:1], "stochasticRebound")
    assert solver_hits(kept, kept_headers[0]).grain_key.tolist() == [1000, 1001]
    assert solver_hits(cols, headers[1]).grain_key is None


def test_files_read_in_rank_order_with_vectors_and_types(tmp_path):
    _write(tmp_path / "hits_10.csv", OPENFOAM, 2)
    _write(tmp_path / "hits_2.csv", OPENFOAM.replace("stream 1", "stream 2"), 3)
    files = rank_files(tmp_path)
    assert [f.name for f in files] == ["hits_2.csv", "hits_10.csv"]
    cols, headers = read_hit_files(files, "stochasticRebound")
    assert [h["stream"] for h in headers] == [2, 1]
    assert cols["V"].shape == (5, 3) and cols["V"][:, 0].tolist() == [0, 1, 2, 0, 1]
    assert cols["path"].dtype == np.int64 and cols["patch"].tolist()[:2] == ["wall0", "wall1"]
    record = solver_hits(cols, headers[0])
    assert record.shape == {"prism": 0.25, "tetrahedron": 0.75} and np.array_equal(record.V, cols["V"])


def test_a_file_of_another_layout_is_named(tmp_path):
    _write(tmp_path / "hits_0.csv", OPENFOAM, 1)
    text = (tmp_path / "hits_0.csv").read_text()
    (tmp_path / "hits_0.csv").write_text(text + "1,2,3\n")
    with pytest.raises(ValueError, match=rf"hits_0.csv, line 5: 3 fields, not {len(HIT_COLUMNS)}"):
        read_hit_files(rank_files(tmp_path), "stochasticRebound")
    for column, value, kind in (("Vx", "abc", "a number"), ("origId", "1.5", "an integer")):
        row = text.splitlines()[3].split(",")
        row[HIT_COLUMNS.index(column)] = value
        (tmp_path / "hits_0.csv").write_text("\n".join(text.splitlines()[:3] + [",".join(row)]) + "\n")
        with pytest.raises(ValueError, match=rf"hits_0.csv, line 4: column {column} is not {kind}: '{value}'"):
            read_hit_files(rank_files(tmp_path), "stochasticRebound")
    (tmp_path / "hits_0.csv").write_text(text.replace("Winx", "Wx0"))
    with pytest.raises(ValueError, match="line 3 is not the hits columns"):
        read_hit_files(rank_files(tmp_path), "stochasticRebound")
    with pytest.raises(FileNotFoundError, match="no hits_<rank>.csv"):
        rank_files(tmp_path / "empty")


def test_summary_counts():
    block = """rebound-scatter (2 ranks):
      - wall hits                   = 12057
      - answered by the table       = 6305
      - answered by the direct model = 5752 (mean cost 4.5 us per hit)
      - rebounded                   = 12000
      - trapped                     = 50
      - failed (direct model)       = 7
      - invalid                     = 0
      - outside the table's grid    = 12
    """
    counts = summary_counts(block)
    assert counts == {"hits": 12057, "table": 6305, "direct": 5752, "rebounded": 12000, "trapped": 50,
                      "failed": 7, "invalid": 0, "outside": 12, "direct_us": 4.5}
    with pytest.raises(ValueError, match="no count '- trapped'"):
        summary_counts(block.replace("- trapped", "- kept"))


def test_grain_mismatches_finds_each_kind_of_wrong_grain(small_table):
    """The columns a grain-kept run writes (its key's shape, and b/a, c/b, hand on the direct path only) give
    no mismatch; one wrong entry of each kind is counted once."""
    import surrogate
    from surrogate.kernels import PATH_DIRECT, PATH_TABLE

    keys = surrogate.grain_key(3, 0, np.arange(40))
    grains = surrogate.grain_of(small_table, keys, "mix")
    path = np.where(np.arange(40) % 2, PATH_DIRECT, PATH_TABLE)
    direct = path == PATH_DIRECT
    hits = {"key": keys.copy(), "shape": grains.shape.copy(), "path": path}
    for name in ("ratio_ba", "ratio_cb", "hand"):
        hits[name] = np.where(direct, getattr(grains, name), np.nan)
    assert np.isfinite(hits["ratio_ba"][direct]).any(), "the mix has a shape of random proportions"
    settings = {"shape": "mix"}
    assert grain_mismatches(hits, settings, small_table) == {"key": 0, "shape": 0, "direct": 0, "table": 0}
    other = {"prism": "tetrahedron"}.get(hits["shape"][0], "prism")
    finite = np.flatnonzero(direct & np.isfinite(hits["ratio_ba"]))[0]
    hits["shape"][0] = other
    hits["ratio_ba"][finite] = np.nextafter(hits["ratio_ba"][finite], 2)      # one ulp off
    hits["hand"][2] = 1.0                                                      # a table-path hit
    hits["key"][4] = -1
    assert grain_mismatches(hits, settings, small_table) == {"key": 1, "shape": 1, "direct": 1, "table": 1}
