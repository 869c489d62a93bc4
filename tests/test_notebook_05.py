"""Execute notebooks/05_calibration.ipynb: cantilever round trip (two overhangs, one fit) from the
reference elastica and a picture-frame fit checked on the shell (STYLE habit 9).

Part of the default suite: about 31 s alone on a quiet 2-core machine (one compile of the 20-element
cantilever, which dominates; the picture frame about 10 s).
"""
import re

from notebook_runner import run_notebook


def test_notebook_05_runs(tmp_path, monkeypatch):
    monkeypatch.setenv("JAXFORM_NOTEBOOK_QUICK", "1")  # one profile instead of two
    nb = run_notebook("05_calibration.ipynb", tmp_path, timeout=300)
    text = "".join(o.get("text", "") for c in nb.cells if c.cell_type == "code" for o in c.get("outputs", []))
    assert "B_init within 3 %: True" in text
    m = re.search(r"b_init +true \S+ +fitted \S+ ± \S+ +error ([-+0-9.]+) %", text)
    assert m is not None
    assert abs(float(m.group(1))) < 3.0
    assert "solver converged: True" in text
    m = re.search(r"largest difference from the law ([0-9.]+) %", text)
    assert m is not None
    assert float(m.group(1)) < 5.0
