"""Notebook 03 (hemisphere forming, Case A) runs top to bottom (tiny mesh and stroke)."""
from notebook_runner import run_notebook


def test_notebook_03_runs(tmp_path, monkeypatch):
    monkeypatch.setenv("JAXFORM_NOTEBOOK_QUICK", "1")
    nb = run_notebook("03_hemisphere_forming.ipynb", tmp_path, timeout=600)
    text = "".join(o.get("text", "") for c in nb.cells if c.cell_type == "code" for o in c.get("outputs", []))
    assert "complete: True" in text
    images = [o for c in nb.cells if c.cell_type == "code" for o in c.get("outputs", [])
              if "image/png" in o.get("data", {})]
    assert len(images) >= 3
