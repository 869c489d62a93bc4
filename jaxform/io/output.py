"""Output directories: never overwrite what a user gave us.

``prepare_output_dir`` creates a directory for results, refuses a non-empty directory unless the
caller says ``force`` (or the directory carries the marker of an earlier run of the same command,
which the command owns and may replace), and leaves a marker so a re-run can recognise it.
"""
from __future__ import annotations

import pathlib

MARKER = ".jaxform-output"


def prepare_output_dir(path, *, force: bool = False, owner: str = "jaxform", replaces=()) -> pathlib.Path:
    """Create or reuse an output directory.

    Args:
        path: directory to write into.
        force: allow writing into a non-empty directory that this command did not create.
        owner: name of the command writing there (recorded in the marker file).
        replaces: glob patterns of the files a run of ``owner`` writes (``"frames_*.vtu"``...): those
            left by an earlier run are removed first, so that two runs' outputs never mix (a rerun
            with fewer frames would otherwise leave stale frames beside the new ``.pvd``).

    Returns:
        The directory as a ``pathlib.Path``.

    Raises:
        FileExistsError: when ``path`` is a file, or a non-empty directory not created by
            ``owner`` and ``force`` is not set.
    """
    out = pathlib.Path(path)
    if out.exists() and not out.is_dir():
        raise FileExistsError(f"output path {out} exists and is a file; choose a directory")
    marker = out / MARKER
    if out.exists() and any(out.iterdir()) and not force:
        if not written_by(out, owner):
            raise FileExistsError(
                f"output directory {out} is not empty and was not written by 'jaxform {owner}'; "
                "choose another directory or pass --force to write into it"
            )
    out.mkdir(parents=True, exist_ok=True)
    remove_outputs(out, replaces)
    marker.write_text(owner + "\n")
    return out


def written_by(path, owner: str) -> bool:
    """Whether directory ``path`` carries the marker of a run of ``jaxform owner``."""
    marker = pathlib.Path(path) / MARKER
    return marker.is_file() and marker.read_text().strip() == owner


def remove_outputs(path, patterns) -> None:
    """Remove the files in ``path`` matching the glob ``patterns`` (a command's own outputs)."""
    for pattern in patterns:
        for old in pathlib.Path(path).glob(pattern):
            if old.is_file():
                old.unlink()
