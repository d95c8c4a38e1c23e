"""Offline table build: the direct model over the (shape, α1, |V⁻|) grid into one HDF5 table.

Each cell is an independent task whose seed derives from (master seed, shape,
α1 index, speed index) (:func:`tablegen.config.cell_seed`), so the table is
bit-identical whatever the number of workers, the scheduler or the order in
which cells finish.

Checkpoints: next to the output ``table.h5`` the build keeps a folder
``table.h5.partial/`` holding the resolved configuration (headed by the table
format version) and one ``.npz`` file per finished cell (each written to a
temporary name and renamed, so a killed build leaves only whole files).
Rerunning the same command computes only the missing cells; a checkpoint made
with another configuration or for another table format is refused. The
table is assembled into a temporary file and renamed onto the output path, so
that path never holds a half-written table; the checkpoint is then removed.
"""

from __future__ import annotations

import datetime
import multiprocessing
import os
import shutil
import tempfile
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path

import numpy as np

from data_schema.table import CELL_DATASETS, TABLE_VERSION, CellTable, ReboundTable, write_table
from data_schema.common import package_version
from tablegen.config import BuildConfig, cell_seed, derive_seed
from tablegen.wall import CORUNDUM_ON_STEEL
from tablegen.simulate import simulate
from tablegen.tabulate import CellAccumulator

CHUNK_PARTICLES = 1_000_000      # particles simulated at a time within one cell


class BuildError(RuntimeError):
    """A cell failed or the checkpoint does not match; the message says which."""


REPRESENTATION_KEY = 2 ** 31    # spawn key of the k-means seed (chunks use keys 0, 1, ...)


def cell_label(config: BuildConfig, shape: str, i_alpha: int, i_speed: int) -> str:
    return (f"cell (shape={shape}, alpha1={config.alpha1_deg[i_alpha]:g} deg, "
            f"speed={config.speed_m_s[i_speed]:g} m/s)")


def compute_cell(config: BuildConfig, shape: str, i_alpha: int, i_speed: int) -> CellTable:
    """Simulate one cell and build its stored representation (runs in a worker)."""
    seed = cell_seed(config.seed, shape, i_alpha, i_speed)
    acc = CellAccumulator()
    for chunk, start in enumerate(range(0, config.particles_per_cell, CHUNK_PARTICLES)):
        n = min(CHUNK_PARTICLES, config.particles_per_cell - start)
        acc.add(simulate(shape, config.alpha1_deg[i_alpha], config.speed_m_s[i_speed], n,
                         seed=derive_seed(seed, chunk), kappa=config.kappa,
                         aspect=config.aspect, n_max=config.n_max))
    return acc.finish(config.resolution, derive_seed(seed, REPRESENTATION_KEY),
                      cell_label(config, shape, i_alpha, i_speed))


def _worker_init(threads: int) -> None:
    import numba
    numba.set_num_threads(threads)


class Checkpoint:
    """The folder of finished cells of one build (see module doc)."""

    def __init__(self, out: Path, config: BuildConfig):
        self.path = out.with_name(out.name + ".partial")
        self.config = config
        marker = self.path / "config.toml"
        expected = f"# table format {TABLE_VERSION[0]}.{TABLE_VERSION[1]}\n" + config.to_toml()
        if marker.exists():
            if marker.read_text() != expected:
                raise BuildError(
                    f"{self.path} holds a checkpoint of a build with another configuration or table format; "
                    f"rerun with the configuration and package version it was made with, or delete "
                    f"{self.path} to start over")
        else:
            self.path.mkdir(exist_ok=True)
            _write_atomically(marker, expected.encode())
        for stale in self.path.glob(".*.tmp"):      # left by a build killed mid-write
            stale.unlink()

    def cell_path(self, shape: str, i_alpha: int, i_speed: int) -> Path:
        return self.path / f"{shape}_{i_alpha:03d}_{i_speed:03d}.npz"

    def done(self, shape: str, i_alpha: int, i_speed: int) -> bool:
        return self.cell_path(shape, i_alpha, i_speed).exists()

    def save(self, shape: str, i_alpha: int, i_speed: int, cell: CellTable) -> None:
        fd, tmp = tempfile.mkstemp(prefix=".cell.", suffix=".tmp", dir=self.path)
        with os.fdopen(fd, "wb") as f:
            np.savez(f, **cell.arrays())
        os.replace(tmp, self.cell_path(shape, i_alpha, i_speed))

    def load(self, shape: str, i_alpha: int, i_speed: int) -> CellTable:
        with np.load(self.cell_path(shape, i_alpha, i_speed)) as data:
            return CellTable(**{name: data[name] for name in CELL_DATASETS})

    def remove(self) -> None:
        shutil.rmtree(self.path)


def _write_atomically(path: Path, data: bytes) -> None:
    fd, tmp = tempfile.mkstemp(prefix=".config.", suffix=".tmp", dir=path.parent)
    with os.fdopen(fd, "wb") as f:
        f.write(data)
    os.replace(tmp, path)


def build_table(config: BuildConfig, out, workers: int | None = None, scheduler: str | None = None,
                overwrite: bool = False, progress: bool = False) -> Path:
    """Build the table of ``config`` into ``out`` (HDF5); return its path.

    Parameters
    ----------
    config : the resolved build configuration.
    out : output path; an existing file is replaced only with ``overwrite``.
    workers : local worker processes (default: the CPU count); ignored with ``scheduler``.
    scheduler : address of a running Dask distributed scheduler to send the cells to.
    overwrite : replace an existing output file.
    progress : show a progress bar with cells done/total and ETA.
    """
    out = Path(out)
    if out.exists() and not overwrite:
        raise FileExistsError(f"{out} exists; pass overwrite=True (CLI: --overwrite) to replace it")
    if not out.parent.is_dir():
        raise FileNotFoundError(f"{out.parent}: output directory does not exist")
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1):
        raise ValueError(f"The 'workers' parameter must be an integer >= 1; got {workers!r}.")
    checkpoint = Checkpoint(out, config)
    tasks = [(shape, ia, iv) for shape in config.shapes for ia in range(len(config.alpha1_deg))
             for iv in range(len(config.speed_m_s)) if not checkpoint.done(shape, ia, iv)]
    bar = _progress_bar(config.n_cells, config.n_cells - len(tasks), progress)
    try:
        if scheduler is not None:
            _run_dask(config, tasks, checkpoint, scheduler, bar)
        else:
            _run_local(config, tasks, checkpoint, workers or os.cpu_count() or 1, bar)
    finally:
        if bar is not None:
            bar.close()
    table = _assemble(config, checkpoint)
    write_table(out, table, overwrite=overwrite)
    checkpoint.remove()
    return out


def _run_local(config, tasks, checkpoint, workers, bar) -> None:
    if not tasks:
        return
    threads = max(1, (os.cpu_count() or 1) // workers)
    # spawn, not fork: forking a process whose numba kernels already ran on OpenMP threads is unsafe
    context = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(max_workers=workers, mp_context=context, initializer=_worker_init,
                             initargs=(threads,)) as pool:
        futures = {pool.submit(compute_cell, config, *task): task for task in tasks}
        try:
            for future in as_completed(futures):
                _store(config, checkpoint, futures[future], future, bar)
        except BaseException:
            for future in futures:
                future.cancel()
            raise


def _run_dask(config, tasks, checkpoint, scheduler, bar) -> None:
    try:
        from dask.distributed import Client, as_completed
    except ImportError:
        raise BuildError("--scheduler needs dask.distributed: pip install 'rebound-scatter[dask]'") from None
    if not tasks:
        return
    with Client(scheduler) as client:
        futures = {client.submit(compute_cell, config, *task, pure=False): task for task in tasks}
        for future in as_completed(futures):
            _store(config, checkpoint, futures[future], future, bar)


def _store(config, checkpoint, task, future, bar) -> None:
    try:
        cell = future.result()
    except Exception as exc:
        raise BuildError(f"{cell_label(config, *task)} failed: {type(exc).__name__}: {exc}") from exc
    checkpoint.save(*task, cell)
    if bar is not None:
        bar.update(1)


def _assemble(config: BuildConfig, checkpoint: Checkpoint) -> ReboundTable:
    shapes = config.resolution.cell_shapes()
    lead = (len(config.shapes), len(config.alpha1_deg), len(config.speed_m_s))
    cells = {name: np.empty(lead + shapes[name], dtype=CELL_DATASETS[name][0]) for name in CELL_DATASETS}
    for s, shape in enumerate(config.shapes):
        for ia in range(lead[1]):
            for iv in range(lead[2]):
                for name, arr in checkpoint.load(shape, ia, iv).arrays().items():
                    cells[name][s, ia, iv] = arr
    return ReboundTable(
        alpha1_deg=np.array(config.alpha1_deg), speed_m_s=np.array(config.speed_m_s), shapes=config.shapes,
        resolution=config.resolution, cells=cells, kappa=config.kappa, n_max=config.n_max,
        restitution_k=CORUNDUM_ON_STEEL.k, restitution_p=CORUNDUM_ON_STEEL.p,
        particles_per_cell=config.particles_per_cell, config_text=config.to_toml(),
        config_sha256=config.sha256(), master_seed=config.seed,
        created=datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        package_version=package_version())


def _progress_bar(total: int, done: int, enabled: bool):
    if not enabled:
        return None
    from tqdm.auto import tqdm
    return tqdm(total=total, initial=done, unit="cell", desc="table cells")
