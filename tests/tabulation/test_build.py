"""Table build: determinism across workers and schedulers, resume after SIGKILL, atomicity."""

import os
import signal
import subprocess
import sys
import time

import h5py
import numpy as np
import pytest

from data_schema.common import DataFormatError
from data_schema.table import CELL_DATASETS, TABLE_VERSION, read_table, table_fingerprint
from data_schema.output import OutputError
from tablegen.tabulation.driver import BuildError, Checkpoint, CheckpointError, build_table
from tablegen.tabulation.config import parse_config
from direct_model.wall import CORUNDUM_ON_STEEL

TINY = """
[grid]
alpha1_deg = [30.0, 80.0]
speed_m_s = [100.0, 250.0]
shapes = ["prism", "tetrahedron"]
[simulation]
particles_per_cell = 3000
seed = 7
"""


@pytest.fixture(scope="module")
def tiny_table(tmp_path_factory):
    path = tmp_path_factory.mktemp("tiny") / "table.h5"
    build_table(parse_config(TINY), path, workers=1)
    return path


def _cell_bytes(path):
    with h5py.File(path, "r") as f:
        return {name: f["cells"][name][()].tobytes() for name in CELL_DATASETS}


def test_table_contents_are_consistent(tiny_table):
    table = read_table(tiny_table)
    assert table.shapes == ("prism", "tetrahedron")
    counts = table.cells["status_counts"]
    assert np.all(counts.sum(axis=-1) == 3000)
    assert np.all(table.cells["collision_counts"].sum(axis=-1) == counts[..., 0])
    # mixture weights are cluster counts over the rebounds; unused components (weight 0) come last
    w = table.cells["cluster_weight"]
    np.testing.assert_allclose(w.sum(axis=-1), 1.0, rtol=1e-12)
    counts_in_clusters = w * counts[..., :1]
    np.testing.assert_allclose(counts_in_clusters, np.round(counts_in_clusters), atol=1e-9)
    assert np.all(np.diff((w > 0).astype(int), axis=-1) <= 0)
    assert set(np.unique(table.cells["cluster_regime"])) <= {0, 1}
    # about 25 rebounds per cluster (k-means may leave a few centres empty)
    used = (w > 0).sum(axis=-1)
    assert np.all(used <= counts[..., 0] // 25) and np.all(used >= 0.8 * (counts[..., 0] // 25))
    # the dictionary holds standardised quantile functions: finite, non-decreasing, mean 0, sd 1
    dic = table.cells["shape_dictionary"].astype(np.float64)
    assert np.all(np.isfinite(dic)) and np.all(np.diff(dic, axis=-1) >= 0)
    np.testing.assert_allclose(dic.mean(axis=-1), 0.0, atol=1e-5)
    np.testing.assert_allclose(dic.std(axis=-1), 1.0, rtol=1e-5)
    assert table.cells["cluster_shape"].max() < table.resolution.dictionary_size
    for name in ("cluster_loc", "cluster_scale", "cluster_slope"):
        assert np.all(np.isfinite(table.cells[name])), name
    assert table.cells["cluster_scale"].min() >= 0
    # indicatrices are densities: ∫ I dα2 = 1 and ∫∫ I dα2 dβ2 = 1
    d = np.pi / 72
    np.testing.assert_allclose(table.cells["indicatrix_2d"].sum(axis=-1) * d, 1.0, rtol=1e-5)
    np.testing.assert_allclose(table.cells["indicatrix_3d"].sum(axis=(-1, -2)) * d * d, 1.0, rtol=1e-5)


def test_bit_identical_for_one_or_two_workers(tiny_table, tmp_path):
    two = build_table(parse_config(TINY), tmp_path / "two.h5", workers=2)
    assert _cell_bytes(two) == _cell_bytes(tiny_table)
    assert table_fingerprint(two) == table_fingerprint(tiny_table)


def test_bit_identical_on_a_dask_cluster(tiny_table, tmp_path):
    distributed = pytest.importorskip("dask.distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:
        path = build_table(parse_config(TINY), tmp_path / "dask.h5", scheduler=cluster.scheduler_address)
    assert _cell_bytes(path) == _cell_bytes(tiny_table)
    assert table_fingerprint(path) == table_fingerprint(tiny_table)


def test_resume_after_sigkill_gives_the_same_table(tmp_path):
    config_text = TINY.replace("particles_per_cell = 3000", "particles_per_cell = 30000")
    cfg = tmp_path / "c.toml"
    cfg.write_text(config_text)
    out = tmp_path / "killed.h5"
    command = [sys.executable, "-m", "tablegen.cli", "build", "--config", str(cfg), "-o", str(out),
               "--workers", "1", "--no-progress"]
    proc = subprocess.Popen(command, start_new_session=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    partial = tmp_path / "killed.h5.partial"
    deadline = time.time() + 120
    while time.time() < deadline and len(list(partial.glob("*.npz"))) < 2:
        time.sleep(0.01)
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait()
    done = len(list(partial.glob("*.npz")))
    assert 2 <= done < 8, f"kill landed outside the build ({done} cells done)"
    assert not out.exists()
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL)
    assert not partial.exists()
    reference = build_table(parse_config(config_text), tmp_path / "whole.h5", workers=1)
    assert _cell_bytes(out) == _cell_bytes(reference)


def test_checkpoint_of_another_config_is_refused(tmp_path):
    out = tmp_path / "t.h5"
    partial = tmp_path / "t.h5.partial"
    partial.mkdir()
    (partial / "config.toml").write_text("something else\n")
    with pytest.raises(CheckpointError, match="another table format, package version, model source hash, "
                                              "configuration"):
        build_table(parse_config(TINY), out, workers=1)
    assert not out.exists()


def test_checkpoint_of_another_wall_law_is_refused(tmp_path):
    """Cells of one wall law are not mixed into a table of another: the law is in the checkpoint's configuration."""
    out = tmp_path / "t.h5"
    with Checkpoint(out, parse_config(TINY)):
        pass
    with pytest.raises(CheckpointError, match="another configuration"):
        build_table(parse_config(TINY + "[wall]\nk = 0.2\n"), out, workers=1)
    assert not out.exists()


def test_table_records_the_wall_law(tiny_table):
    """The wall is the group /wall: its family and name as attributes, its parameters as one row read by name."""
    table = read_table(tiny_table)
    law = CORUNDUM_ON_STEEL
    assert table.wall == law and table.wall.family == "exponential"
    assert parse_config(table.config_text).wall == law
    with h5py.File(tiny_table, "r") as f:
        assert dict(f["wall"].attrs) == {"family": "exponential", "name": law.name}
        row = f["wall/parameters"]
        assert row.shape == (1,) and row.chunks == (1,) and row.fletcher32
        assert {name: float(row[0][name]) for name in law.parameters()} == law.parameters()
        assert tuple(row[0]["speed_range_m_s"]) == law.speed_range_m_s == (50.0, 300.0)
        assert f["model/parameters"].fletcher32 and f["model/parameters"][0]["kappa"] == table.kappa
        assert not {"restitution_k", "kappa", "wall_law"} & set(f["grid"].attrs) and "law" not in f["grid"]


def test_checkpoint_of_another_table_format_is_refused(tmp_path):
    """Cells checkpointed by a package writing another table format are not mixed into this one."""
    out = tmp_path / "t.h5"
    with Checkpoint(out, parse_config(TINY)) as checkpoint:
        marker = checkpoint.path / "config.toml"
    marker.write_text(marker.read_text().replace(f"# table format {TABLE_VERSION[0]}.{TABLE_VERSION[1]}",
                                                 "# table format 2.1"))
    with pytest.raises(CheckpointError, match="another table format "):
        build_table(parse_config(TINY), out, workers=1)
    assert not out.exists()


def test_existing_output_needs_overwrite(tiny_table, tmp_path):
    out = tmp_path / "t.h5"
    out.write_bytes(b"keep")
    with pytest.raises(OutputError, match="overwrite"):
        build_table(parse_config(TINY), out, workers=1)
    assert out.read_bytes() == b"keep"


def test_worker_failure_names_the_cell(tmp_path):
    """A cell with too few rebounds to represent fails the build loudly, naming the cell.

    With n_max = 1 every tetrahedron needing a second collision at normal
    impact is trapped: about 5 % of 256 particles rebound, below the 25 a cell needs.
    """
    config = parse_config("[grid]\nalpha1_deg = [90.0]\nspeed_m_s = [200.0]\nshapes = [\"tetrahedron\"]\n"
                          "[simulation]\nparticles_per_cell = 256\nn_max = 1\nseed = 3\n")
    with pytest.raises(BuildError, match=r"cell \(shape=tetrahedron, alpha1=90 deg, speed=200 m/s\).*rebounds"):
        build_table(config, tmp_path / "t.h5", workers=1)
    assert not (tmp_path / "t.h5").exists()


def test_info_describes_the_table(tiny_table, capsys):
    from tablegen.cli import main
    assert main(["info", str(tiny_table)]) == 0
    out = capsys.readouterr().out
    for text in (f"format version {TABLE_VERSION[0]}.{TABLE_VERSION[1]}",
                 f"fingerprint sha256 {table_fingerprint(tiny_table)}", "alpha1 (deg): 2 values", "prism",
                 "tetrahedron", "config sha256", "3000 particles", "the work on the wall: W_n, W_t drawn with each rebound"):
        assert text in out


def test_reader_rejects_version_missing_dataset_and_truncation(tiny_table, tmp_path):
    import shutil
    bad = tmp_path / "v.h5"
    shutil.copy(tiny_table, bad)
    with h5py.File(bad, "a") as f:
        f.attrs["format_version"] = np.array([2, 1])          # a table of an old format
    with pytest.raises(DataFormatError, match=r"v\.h5.*version 2\.1 .*reads major version 4; make the file again"):
        read_table(bad)
    shutil.copy(tiny_table, bad)
    with h5py.File(bad, "a") as f:
        del f["cells/cluster_slope"]
    with pytest.raises(DataFormatError, match="cells/cluster_slope"):
        read_table(bad)
    data = tiny_table.read_bytes()
    bad.write_bytes(data[: len(data) // 3])
    with pytest.raises(DataFormatError, match="v.h5"):
        read_table(bad)


def test_every_model_source_is_hashed():
    """A pattern of MODEL_SOURCES that matches no file (a folder renamed, say) would leave that source out of
    model_sha256 unnoticed."""
    from tablegen.tabulation.driver import MODEL_SOURCES, SOURCE_ROOT, model_files

    hashed = set(model_files())
    for pattern in MODEL_SOURCES:
        matched = set(SOURCE_ROOT.glob(pattern))
        assert matched and matched <= hashed, pattern
    assert {"cells.py", "resolution.py", "tabulate.py", "body_rebound.py"} <= {path.name for path in hashed}
