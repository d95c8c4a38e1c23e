"""The small table an example builds for itself when it is given none (examples/rough_wall.py, wall_work.py,
examples/grain_key_paths.py)."""

from pathlib import Path

import surrogate


def load_or_build(path, out: Path, name: str, config_text: str):
    """Load the table ``path``; for None, the table ``out/name`` built (once) from the TOML ``config_text``."""
    if path is None:
        path = out / name
        if not path.exists():
            from tablegen import build_table, parse_config
            out.mkdir(parents=True, exist_ok=True)
            print(f"building a small table into {path} ...", flush=True)
            build_table(parse_config(config_text), path)
    return surrogate.load(path)
