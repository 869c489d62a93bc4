"""Test configuration: verification tests run in float64 (STYLE habit 8).

x64 is switched on here, for the test session only; the library itself never changes global JAX
configuration. Tests that check float32 behaviour cast their inputs explicitly.
"""
import os

os.environ.setdefault("MPLBACKEND", "Agg")

# One compilation cache for the whole run, shared by the two xdist workers and the notebook kernels
# and command-line subprocesses they start: a program compiled once (the forming step of the small
# test cases, the cantilever solver) is read back instead of compiled again. A fresh directory per
# run, made by the process that starts the workers (they inherit its environment) and removed by it
# at the end, so every run starts cold, like a fresh clone.
if "JAX_COMPILATION_CACHE_DIR" not in os.environ:
    import tempfile

    os.environ["JAX_COMPILATION_CACHE_DIR"] = tempfile.mkdtemp(prefix="jaxform-test-xla-")
    os.environ["JAX_PERSISTENT_CACHE_MIN_COMPILE_TIME_SECS"] = "0.3"

# Most of the suite's time is XLA compiling (60 % of the test time measured in one run, more in
# the notebooks), few tests run long. XLA's older CPU loop emitters compile the forming step in
# about half the time of the default fusion emitters, for ~12 % slower steps: the trade a test run
# wants, not a forming run (the library leaves XLA's defaults alone). Set for the workers and the
# subprocesses they start; a user's own XLA_FLAGS setting of it wins.
if "xla_cpu_use_fusion_emitters" not in os.environ.get("XLA_FLAGS", ""):
    os.environ["XLA_FLAGS"] = (os.environ.get("XLA_FLAGS", "") + " --xla_cpu_use_fusion_emitters=false").strip()

import jax  # noqa: E402
import pytest  # noqa: E402

jax.config.update("jax_enable_x64", True)
# two CPU devices, so that batched runs are sharded over devices in the tests as on a real machine
# (jaxform.forming.batch); everything else runs on the first, as it would without this
jax.config.update("jax_num_cpu_devices", 2)


def rtol_for(dtype) -> float:
    """A relative tolerance suited to the floating dtype of a computation."""
    import numpy as np

    return 1e-10 if np.dtype(dtype) == np.float64 else 1e-4


@pytest.fixture
def tmp_out(tmp_path):
    """An empty output directory for command-line and file-writing tests."""
    out = tmp_path / "out"
    return out


# The longest files first (longest-processing-time order: the two workers take files in collection
# order as they come free, ``--dist loadfile --no-loadscope-reorder``; xdist's default order, most
# tests first, put the one-test notebook and README files last, and the README block ran alone for
# 40 s after the other worker had finished). The order is each file's measured time (``--durations``,
# 2026-12-05, both workers, a fresh cache), longest first; the short files fill the tail.
LONG_FIRST = ("test_forming.py", "test_fibre_mass.py", "test_integrate.py", "test_self_contact.py",
              "test_metrics_distance.py", "test_cantilever.py", "test_sweep.py", "test_notebook_06",
              "test_forming_patch.py", "test_readme.py", "test_energy_balance.py", "test_cli_wrinkles.py",
              "test_shell_element.py", "test_frame_tests.py", "test_cli_demo.py", "test_metrics_wrinkles.py",
              "test_contact.py", "test_notebook_")


def pytest_collection_modifyitems(items):
    def rank(item):
        name = item.path.name
        return next((i for i, p in enumerate(LONG_FIRST) if name.startswith(p)), len(LONG_FIRST))

    items.sort(key=rank)  # stable: each file keeps its own order


def pytest_sessionfinish(session):
    """The controller removes the run's compilation cache (workers leave it to the controller)."""
    if hasattr(session.config, "workerinput"):
        return
    import shutil

    path = os.environ.get("JAX_COMPILATION_CACHE_DIR", "")
    if os.path.basename(path).startswith("jaxform-test-xla-"):
        shutil.rmtree(path, ignore_errors=True)
