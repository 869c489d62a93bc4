"""Execute notebooks/05_calibration.ipynb: cantilever round trip from the reference elastica and a
picture-frame fit checked on the shell (STYLE habit 9)."""
import re

import pytest

from notebook_runner import run_notebook

pytestmark = pytest.mark.slow


def test_notebook_05_runs(tmp_path):
    nb = run_notebook("05_calibration.ipynb", tmp_path, timeout=300)
    text = "".join(o.get("text", "") for c in nb.cells if c.cell_type == "code" for o in c.get("outputs", []))
    assert "B_init within 3 %: True" in text
    assert "solver converged: True" in text
    m = re.search(r"largest difference from the law ([0-9.]+) %", text)
    assert m is not None
    assert float(m.group(1)) < 5.0
