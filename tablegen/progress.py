"""The progress bar of tablegen's long jobs (simulations, table builds, the study), on standard error, and
:func:`simulate` with it (the direct model itself, :mod:`direct_model`, takes a callback and no bar)."""


def progress_bar(enabled: bool, total: int, unit: str, desc: str, initial: int = 0):
    """A tqdm bar counting ``total`` items of ``unit`` (``initial`` already done), or None if not ``enabled``."""
    if not enabled:
        return None
    from tqdm.auto import tqdm
    return tqdm(total=total, initial=initial, unit=unit, unit_scale=unit == "particle", desc=desc)


def simulate(shape, alpha1, speed, n, seed=None, omega_in=(0.0, 0.0, 0.0), *, progress: bool = False, **options):
    """:func:`direct_model.simulate.simulate` (same arguments, units and frames), with a progress bar counting
    the particles on standard error when ``progress`` is true."""
    from direct_model.simulate import simulate as _simulate     # here: the bar alone loads no numba kernel

    bar = progress_bar(progress, n, "particle", "rebounds")
    try:
        return _simulate(shape, alpha1, speed, n, seed, omega_in, progress=None if bar is None else bar.update,
                         **options)
    finally:
        if bar is not None:
            bar.close()
