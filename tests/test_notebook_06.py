"""Notebook 06 (the paper study) runs top to bottom: in the suite, one run of the study (woven
Case A NLBM, 25 mm elements, 3 mm of stroke) through the command, the report, claims and figures."""
from notebook_runner import run_notebook


def test_notebook_06_runs(tmp_path, monkeypatch):
    monkeypatch.setenv("JAXFORM_NOTEBOOK_QUICK", "1")
    nb = run_notebook("06_paper_study.ipynb", tmp_path, timeout=600)
    text = "".join(o.get("text", "") for c in nb.cells if c.cell_type == "code" for o in c.get("outputs", []))
    assert "exit status 0" in text
    assert "claim 9:" in text and "claim 1:" in text
    images = [o for c in nb.cells if c.cell_type == "code" for o in c.get("outputs", [])
              if "image/png" in o.get("data", {})]
    assert len(images) >= 3  # deviation maps, sections, the section from its CSV
    assert (tmp_path / "study-quick" / "report.md").is_file()
