"""The table build driver: every cell of a configuration, on local workers or a Dask cluster, into one HDF5 table.

Cells are computed by :func:`tablegen.tabulation.cells.compute_cell` (seeded per
cell, so the table does not depend on the workers or the order in which cells
finish). Checkpoints: next to the output ``table.h5`` the build keeps a folder
``table.h5.partial/`` holding what produced it (table format version, package
version, :func:`model_sha256` and the resolved configuration, wall law
included) and one ``.npz`` file per finished cell, each written to a temporary
name and renamed (by the local worker that computed it, or by the driver for
a Dask worker's cell). Rerunning the same command computes only the missing cells;
a checkpoint made by another model, package version, table format or
configuration is refused, so a table never mixes cells of two laws. While a
build runs it holds a lock on that folder. The table is assembled in memory,
written to a temporary file and renamed onto the output path; the checkpoint
is then removed.
"""

from __future__ import annotations

import datetime
import fcntl
import hashlib
import io
import multiprocessing
import os
import shutil
import signal
import sys
from concurrent.futures import ProcessPoolExecutor, as_completed
from concurrent.futures.process import BrokenProcessPool
from pathlib import Path

import numpy as np

from data_schema.common import package_version
from data_schema.output import check_free_space, check_memory, check_output, remove_stale_temporaries, replace_file
from data_schema.table import TABLE_CELL_DATASETS, TABLE_FILE_TYPE, TABLE_VERSION, CellTable, ReboundTable, write_table
from direct_model.shapes import second_moment_factors
from direct_model.simulate import DEFAULT_CONTACT_TOL, DEFAULT_MAX_STEPS, DEFAULT_SET_TOL     # cells.py's simulate uses these
from tablegen.tabulation.cells import cell_label, compile_cell_kernels, compute_cell
from tablegen.tabulation.config import BuildConfig
from tablegen.progress import progress_bar


class BuildError(RuntimeError):
    """A cell failed to compute; the message names it."""


class CheckpointError(ValueError):
    """The checkpoint folder belongs to another build or is in use; the message says what differs."""


SCHEDULER_TIMEOUT_S = 10       # how long to try to reach a Dask scheduler before giving up
SOURCE_ROOT = Path(__file__).resolve().parents[2]       # the folder holding tablegen/ and data_schema/
# the source that decides a cell's content (not this driver): hashed into checkpoints and tables
MODEL_SOURCES = ("direct_model/*.py", "tablegen/tabulation/resolution.py", "tablegen/tabulation/tabulate.py",
                 "tablegen/tabulation/cells.py", "data_schema/samples.py")


def model_files() -> list:
    """The files of :data:`MODEL_SOURCES`, sorted by their path under :data:`SOURCE_ROOT`."""
    return sorted({path for pattern in MODEL_SOURCES for path in SOURCE_ROOT.glob(pattern)},
                  key=lambda path: path.relative_to(SOURCE_ROOT).as_posix())


def model_sha256() -> str:
    """SHA-256 of the source of :data:`MODEL_SOURCES`: identifies the model that computed a cell."""
    digest = hashlib.sha256()
    for path in model_files():
        digest.update(path.relative_to(SOURCE_ROOT).as_posix().encode() + b"\0")
        digest.update(path.read_bytes())
    return digest.hexdigest()


_WORKER_CONFIG = None       # a local worker's build configuration, sent once (_worker_init)


def _worker_init(threads: int, config) -> None:
    """Worker set-up: numba threads and the build's configuration (once, not once per cell: a population's hulls
    make it megabytes); Ctrl-C is the main process's to handle; die with the main process."""
    global _WORKER_CONFIG
    import numba
    numba.set_num_threads(threads)
    _WORKER_CONFIG = config
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if sys.platform == "linux":
        import ctypes
        PR_SET_PDEATHSIG = 1
        ctypes.CDLL(None, use_errno=True).prctl(PR_SET_PDEATHSIG, signal.SIGTERM)


class Checkpoint:
    """The folder of finished cells of one build, locked while the build runs (see module doc).

    Use as a context manager: entering takes the lock (CheckpointError if another build holds it) and
    checks the provenance; leaving releases the lock.
    """

    def __init__(self, out: Path, config: BuildConfig):
        self.out = out
        self.path = out.with_name(out.name + ".partial")
        self.config = config
        self.provenance = (f"# table format {TABLE_VERSION[0]}.{TABLE_VERSION[1]}\n"
                           f"# package {package_version()}\n# model sha256 {model_sha256()}\n")
        self._lock = None

    def __enter__(self) -> "Checkpoint":
        self.path.mkdir(exist_ok=True)
        self._lock = os.open(self.path, os.O_RDONLY)
        try:
            fcntl.flock(self._lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            os.close(self._lock)
            self._lock = None
            raise CheckpointError(f"{self.path}: another build of this table is running (it holds the lock on "
                                  f"this folder); wait for it to finish or stop it") from None
        marker = self.path / "config.toml"
        expected = self.provenance + self.config.to_toml()
        if marker.exists():
            self._check(marker.read_text())
        else:
            replace_file(marker, expected.encode())
        remove_stale_temporaries(self.path)
        remove_stale_temporaries(self.out.parent, self.out.name)      # a final write killed mid-way
        return self

    def __exit__(self, exc_type, *exc) -> None:
        if exc_type is not None and self.path.is_dir() and self.count() == 0:
            shutil.rmtree(self.path)        # a build that stopped before its first cell leaves nothing
        if self._lock is not None:
            os.close(self._lock)
            self._lock = None

    def _check(self, found: str) -> None:
        labels = ("table format", "package version", "model source hash")
        head = found.splitlines(keepends=True)[:len(labels)]
        differ = [label for label, mine, theirs in zip(labels, self.provenance.splitlines(keepends=True),
                                                       head + [""] * len(labels)) if mine != theirs]
        if found[len("".join(head)):] != self.config.to_toml():
            differ.append("configuration")
        if differ:
            raise CheckpointError(
                f"{self.path}: its cells were made with another {', '.join(differ)} (checked: table format, "
                f"package version, model source hash, configuration); they cannot go into this table; rerun "
                f"with the code and configuration that made them, or delete {self.path} to start over")

    def cell_path(self, shape: str, i_alpha: int, i_speed: int) -> Path:
        return self.path / f"{shape}_{i_alpha:03d}_{i_speed:03d}.npz"

    def done(self, shape: str, i_alpha: int, i_speed: int) -> bool:
        return self.cell_path(shape, i_alpha, i_speed).exists()

    def save(self, shape: str, i_alpha: int, i_speed: int, cell: CellTable) -> None:
        save_cell(self.cell_path(shape, i_alpha, i_speed), cell)

    def load(self, shape: str, i_alpha: int, i_speed: int) -> CellTable:
        with np.load(self.cell_path(shape, i_alpha, i_speed)) as data:
            return CellTable(**{name: data[name] for name in TABLE_CELL_DATASETS})

    def count(self) -> int:
        """Cells finished so far."""
        return sum(1 for _ in self.path.glob("*.npz"))

    def remove(self) -> None:
        shutil.rmtree(self.path)


def save_cell(path: Path, cell: CellTable) -> None:
    """Write ``cell`` to ``path`` (.npz), under a temporary name first and then renamed onto it."""
    buffer = io.BytesIO()
    np.savez(buffer, **cell.arrays())
    replace_file(path, buffer.getvalue())


def build_table(config: BuildConfig, out, workers: int | None = None, scheduler: str | None = None,
                overwrite: bool = False, progress: bool = False, log=None) -> Path:
    """Build the table of ``config`` into ``out`` (HDF5); return its path.

    Parameters
    ----------
    config : the resolved build configuration.
    out : output path; an existing file is replaced only with ``overwrite``, and only if it is a table
        (:func:`data_schema.output.check_output`). Checked before any cell is computed.
    workers : local worker processes (default: the CPU count), capped at the CPU count and the number
        of cells left to compute; ignored with ``scheduler``.
    scheduler : address of a running Dask distributed scheduler to send the cells to (reached within
        SCHEDULER_TIMEOUT_S s, or ValueError).
    overwrite : replace an existing table file.
    progress : show a progress bar with cells done/total and ETA.
    log : called with one line saying what is about to be computed, once every check has passed.

    Raises OutputError (output path), CheckpointError (checkpoint of another build, or in use),
    ValueError (arguments, disk space, memory, scheduler) before computing; BuildError if a cell fails.
    Interrupted (KeyboardInterrupt) stops the workers; finished cells stay checkpointed.
    """
    out = check_output(out, TABLE_FILE_TYPE, overwrite)
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1):
        raise ValueError(f"The 'workers' parameter must be an integer >= 1; got {workers!r}.")
    client = _connect(scheduler) if scheduler is not None else None
    try:
        with Checkpoint(out, config) as checkpoint:
            tasks = [(shape, ia, iv) for shape in config.shapes for ia in range(len(config.alpha1_deg))
                     for iv in range(len(config.speed_m_s)) if not checkpoint.done(shape, ia, iv)]
            cell_bytes = config.resolution.cell_nbytes()
            check_free_space(out, (len(tasks) + config.n_cells) * cell_bytes, "the build (checkpoints and table)")
            check_memory(2 * config.n_cells, cell_bytes, "the table's cells (in memory twice while it is written)")
            if log is not None:
                log(f"building {len(tasks)} of {config.n_cells} cells x {config.particles_per_cell} particles "
                    f"into {out}" + (f" ({config.n_cells - len(tasks)} from {checkpoint.path})"
                                     if len(tasks) < config.n_cells else ""))
            bar = progress_bar(progress, config.n_cells, "cell", "table cells", initial=config.n_cells - len(tasks))
            try:
                if client is not None:
                    _run_dask(config, tasks, checkpoint, client, bar)
                else:
                    _run_local(config, tasks, checkpoint, workers, bar)
            finally:
                if bar is not None:
                    bar.close()
            write_table(out, _assemble(config, checkpoint), overwrite=overwrite)
            checkpoint.remove()
    finally:
        if client is not None:
            client.close()
    return out


def worker_count(requested: int | None, pending: int) -> int:
    """Local worker processes for ``pending`` cells: ``requested`` (default: the CPU count), at most the
    CPU count and the number of cells."""
    cpus = os.cpu_count() or 1
    return max(1, min(requested or cpus, cpus, pending))


def _run_local(config, tasks, checkpoint, workers, bar) -> None:
    if not tasks:
        return
    workers = worker_count(workers, len(tasks))
    if workers > 1:
        compile_cell_kernels(config)
    threads = max(1, (os.cpu_count() or 1) // workers)
    # spawn, not fork: forking a process whose numba kernels already ran on OpenMP threads is unsafe
    pool = ProcessPoolExecutor(max_workers=workers, mp_context=multiprocessing.get_context("spawn"),
                               initializer=_worker_init, initargs=(threads, config))
    try:
        futures = {pool.submit(_compute_and_save, checkpoint.cell_path(*task), *task): task for task in tasks}
        for future in as_completed(futures):
            task = futures[future]
            try:
                future.result()
            except BrokenProcessPool as exc:
                raise BuildError(f"a worker process died before computing {cell_label(config, *task)} ({exc}); "
                                 f"a script calling build_table with workers must guard its main code with "
                                 f"`if __name__ == \"__main__\":`") from None
            except Exception as exc:
                raise BuildError(f"{cell_label(config, *task)} failed: {type(exc).__name__}: {exc}") from exc
            if bar is not None:
                bar.update(1)
    finally:
        _stop(pool)


def _compute_and_save(path: Path, shape: str, i_alpha: int, i_speed: int) -> None:
    """A local worker's task: compute a cell of its configuration and checkpoint it to ``path`` itself.

    Its reply through the pool's pipe is then a few bytes, which a pipe writes whole or not at all
    (PIPE_BUF). A 100 kB cell sent back instead could be cut off by :func:`_stop` terminating its worker,
    and the pool's reader thread would wait forever for the rest (the main process holds the pipe's other
    end), hanging the interpreter's exit.
    """
    save_cell(path, compute_cell(_WORKER_CONFIG, shape, i_alpha, i_speed))


def _stop(pool: ProcessPoolExecutor) -> None:
    """Stop ``pool`` now: pending cells cancelled, running workers terminated (after a signal or a failed
    cell nothing of theirs is wanted; their finished cells are already checkpointed)."""
    processes = list((pool._processes or {}).values())     # the executor has no public way to terminate them
    pool.shutdown(wait=False, cancel_futures=True)
    for process in processes:
        process.terminate()
    for process in processes:
        process.join()


def _connect(scheduler: str):
    """A Dask client of ``scheduler``; ValueError naming it if it cannot be reached."""
    try:
        from dask.distributed import Client
    except ImportError:
        raise ValueError("--scheduler needs dask.distributed: pip install 'rebound-scatter[dask]'") from None
    try:
        return Client(scheduler, timeout=f"{SCHEDULER_TIMEOUT_S}s")
    except (OSError, TimeoutError, ValueError) as exc:
        raise ValueError(f"--scheduler {scheduler}: cannot reach a Dask scheduler there within "
                         f"{SCHEDULER_TIMEOUT_S} s ({type(exc).__name__}: {' '.join(str(exc).split())})") from None


def _run_dask(config, tasks, checkpoint, client, bar) -> None:
    from dask.distributed import as_completed

    # the configuration once to every worker, not once per cell (a population's hulls make it megabytes)
    shared = client.scatter(config, broadcast=True)
    futures = {client.submit(compute_cell, shared, *task, pure=False): task for task in tasks}
    try:
        for future in as_completed(futures):
            task = futures[future]
            try:
                cell = future.result()
            except Exception as exc:
                raise BuildError(f"{cell_label(config, *task)} failed: {type(exc).__name__}: {exc}") from exc
            _store(checkpoint, task, cell, bar)
    finally:
        client.cancel(list(futures))


def _store(checkpoint, task, cell, bar) -> None:
    checkpoint.save(*task, cell)
    if bar is not None:
        bar.update(1)


def _assemble(config: BuildConfig, checkpoint: Checkpoint) -> ReboundTable:
    shapes = config.resolution.cell_shapes()
    lead = (len(config.shapes), len(config.alpha1_deg), len(config.speed_m_s))
    cells = {name: np.empty(lead + shapes[name], dtype=dtype) for name, (dtype, _, _) in TABLE_CELL_DATASETS.items()}
    for s, shape in enumerate(config.shapes):
        for ia in range(lead[1]):
            for iv in range(lead[2]):
                for name, arr in checkpoint.load(shape, ia, iv).arrays().items():
                    cells[name][s, ia, iv] = arr
    return ReboundTable(
        alpha1_deg=np.array(config.alpha1_deg), speed_m_s=np.array(config.speed_m_s), shapes=config.shapes,
        resolution=config.resolution, cells=cells, kappa=config.kappa, n_max=config.n_max,
        wall=config.wall, aspect_ratio=(config.aspect.mean, config.aspect.sd, config.aspect.low, config.aspect.high),
        contact_tol=DEFAULT_CONTACT_TOL, set_tol=DEFAULT_SET_TOL, max_steps=DEFAULT_MAX_STEPS,
        second_moment_factors=tuple(second_moment_factors(config.kappa)),
        particles_per_cell=config.particles_per_cell, config_text=config.to_toml(),
        config_sha256=config.sha256(), master_seed=config.seed,
        created=datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        package_version=package_version(), model_sha256=model_sha256(), records=config.shape_records())
