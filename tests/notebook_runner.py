"""Execute a notebook from ``notebooks/`` with nbclient (scikit-fem's test_examples habit).

Notebooks are run top to bottom in a fresh kernel, in a temporary working directory so that
anything they write stays out of the tree; a failing cell fails the test with its traceback.
"""
from __future__ import annotations

import os
import pathlib

NOTEBOOKS = pathlib.Path(__file__).resolve().parent.parent / "notebooks"


def run_notebook(name: str, workdir: pathlib.Path, timeout: int = 600):
    """Run ``notebooks/<name>`` in ``workdir``; return the executed notebook node."""
    import nbformat
    from nbclient import NotebookClient

    nb = nbformat.read(NOTEBOOKS / name, as_version=4)
    env_backup = os.environ.get("MPLBACKEND")
    # Figures render inline (as PNG outputs) in the kernel, like a user's Jupyter session.
    os.environ["MPLBACKEND"] = "module://matplotlib_inline.backend_inline"
    try:
        client = NotebookClient(
            nb, timeout=timeout, kernel_name="python3", resources={"metadata": {"path": str(workdir)}}
        )
        client.execute()
    finally:
        if env_backup is None:
            os.environ.pop("MPLBACKEND", None)
        else:
            os.environ["MPLBACKEND"] = env_backup
    return nb
