"""The progress bar of tablegen's long jobs (simulations, table builds, the study), on standard error."""


def progress_bar(enabled: bool, total: int, unit: str, desc: str, initial: int = 0):
    """A tqdm bar counting ``total`` items of ``unit`` (``initial`` already done), or None if not ``enabled``."""
    if not enabled:
        return None
    from tqdm.auto import tqdm
    return tqdm(total=total, initial=initial, unit=unit, unit_scale=unit == "particle", desc=desc)
