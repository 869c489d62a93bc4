"""Reading and writing forming case files (TOML). Host side: the only file access for cases."""
from __future__ import annotations

from pathlib import Path


def read_case(path):
    """Read and validate a case TOML file (see :mod:`jaxform.cases` for the keys)."""
    from jaxform.cases import loads

    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"case file {str(path)!r}: no such file")
    try:
        return loads(path.read_text(encoding="utf-8"))
    except ValueError as err:
        raise ValueError(f"{path}: {err}") from None


def write_case(case, path, *, overwrite: bool = False) -> Path:
    """Write a case as TOML (``jaxform.cases.to_toml``); refuses to overwrite unless asked."""
    from jaxform.cases import to_toml

    path = Path(path)
    if path.exists() and not overwrite:
        raise FileExistsError(f"case file {str(path)!r} exists (pass overwrite=True)")
    path.write_text(to_toml(case), encoding="utf-8")
    return path


__all__ = ["read_case", "write_case"]
