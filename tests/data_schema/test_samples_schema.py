"""The raw-samples HDF5 layout (data_schema.samples) and its checks."""

import h5py
import numpy as np
import pytest

from data_schema.output import OutputError

from data_schema import DataFormatError, SampleSet, read_samples, write_samples
from data_schema.samples import REQUIRED_DATASETS, SAMPLES_FILE_TYPE
from surrogate.cli import main as surrogate_main


def _sample_set(n=50):
    rng = np.random.default_rng(0)
    return SampleSet(velocity=rng.normal(size=(n, 3)), omega=rng.normal(size=(n, 3)),
                     n_collisions=rng.integers(1, 5, n).astype(np.int32),
                     status=rng.integers(0, 3, n).astype(np.int8), alpha1=45.0, speed=200.0,
                     shape="mix", seed=7, producer="test", extra={"b_over_a": rng.uniform(0.5, 1, n)},
                     provenance={"n_max": 1000})


def test_round_trip(tmp_path):
    s = _sample_set()
    path = write_samples(tmp_path / "a.h5", s)
    back = read_samples(path)
    for name in ("velocity", "omega", "n_collisions", "status"):
        assert np.array_equal(getattr(back, name), getattr(s, name))
    assert back.extra["b_over_a"].tobytes() == s.extra["b_over_a"].tobytes()
    assert (back.alpha1, back.speed, back.shape, back.seed, back.producer) == (45.0, 200.0, "mix", 7, "test")
    assert back.provenance["n_max"] == 1000
    with h5py.File(path) as f:
        assert set(REQUIRED_DATASETS) <= set(f["samples"])
        assert f["samples/u"].attrs["units"] == "m/s"


def test_refuses_to_overwrite_and_leaves_no_temporary(tmp_path):
    path = write_samples(tmp_path / "a.h5", _sample_set())
    before = path.read_bytes()
    with pytest.raises(OutputError, match="overwrite"):
        write_samples(path, _sample_set(10))
    assert path.read_bytes() == before
    write_samples(path, _sample_set(10), overwrite=True)
    assert len(read_samples(path)) == 10
    assert [p.name for p in tmp_path.iterdir()] == ["a.h5"]


def test_rejects_other_major_version(tmp_path):
    path = write_samples(tmp_path / "a.h5", _sample_set())
    with h5py.File(path, "a") as f:
        f.attrs["format_version"] = np.array([2, 0])
    with pytest.raises(DataFormatError, match=r"a\.h5.*version 2\.0"):
        read_samples(path)


def test_rejects_missing_dataset_and_wrong_type(tmp_path):
    path = write_samples(tmp_path / "a.h5", _sample_set())
    with h5py.File(path, "a") as f:
        del f["samples/omega_y"]
    with pytest.raises(DataFormatError, match="omega_y"):
        read_samples(path)
    other = tmp_path / "b.h5"
    with h5py.File(other, "w") as f:
        f.attrs["file_type"] = "something_else"
    with pytest.raises(DataFormatError, match=f"expected '{SAMPLES_FILE_TYPE}'"):
        read_samples(other)


def test_rejects_truncated_file(tmp_path):
    path = write_samples(tmp_path / "a.h5", _sample_set(5000))
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 2])
    with pytest.raises(DataFormatError, match="a.h5"):
        read_samples(path)


def test_surrogate_info(tmp_path, capsys):
    path = write_samples(tmp_path / "a.h5", _sample_set())
    assert surrogate_main(["info", str(path)]) == 0
    out = capsys.readouterr().out
    assert "n = 50" in out and "alpha1 = 45" in out
    assert surrogate_main(["info", str(tmp_path / "missing.h5")]) == 2
    assert capsys.readouterr().err == f"surrogate info: error: {tmp_path / 'missing.h5'}: no such file\n"
