"""Forming case files: TOML text read with ``tomllib`` and written with ``tomli-w``.

The host edge for cases: the only place where a case meets text or a file. Keys and units are
those of :mod:`jaxform.forming.case` (lengths in mm, key names say the unit).
"""
from __future__ import annotations

import tomllib
from pathlib import Path

import tomli_w

from jaxform.forming.case import Case, from_dict, to_dict

_HEADER = "# jaxform forming case (lengths in mm; see jaxform.forming.case for the keys)\n"


def loads(text: str) -> Case:
    """Parse and validate the TOML text of a case."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise ValueError(f"case file is not valid TOML: {err}") from None
    return from_dict(data)


def dumps(case: Case) -> str:
    """TOML text of a case (readable by :func:`loads`): dump a preset, edit it, run it."""
    return _HEADER + tomli_w.dumps(to_dict(case))


def read_case(path) -> Case:
    """Read and validate a case TOML file."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"case file {str(path)!r}: no such file")
    try:
        return loads(path.read_text(encoding="utf-8"))
    except ValueError as err:
        raise ValueError(f"{path}: {err}") from None


def write_case(case: Case, path, *, overwrite: bool = False) -> Path:
    """Write a case as TOML; refuses to overwrite an existing file unless asked."""
    path = Path(path)
    if path.exists() and not overwrite:
        raise FileExistsError(f"case file {str(path)!r} exists (pass overwrite=True)")
    path.write_text(dumps(case), encoding="utf-8")
    return path


__all__ = ["loads", "dumps", "read_case", "write_case"]
