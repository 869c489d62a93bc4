"""notebooks/01_material_laws.ipynb runs top to bottom (issue 2)."""
from notebook_runner import run_notebook


def test_material_laws_notebook_runs(tmp_path):
    nb = run_notebook("01_material_laws.ipynb", tmp_path, timeout=300)
    text = "".join(
        out.get("text", "") for cell in nb.cells if cell.cell_type == "code" for out in cell.get("outputs", [])
    )
    assert "stiffness == grad(moment): True" in text
    assert "moment == grad(energy):   True" in text
    images = sum(
        1
        for cell in nb.cells
        if cell.cell_type == "code"
        for out in cell.get("outputs", [])
        if "image/png" in out.get("data", {})
    )
    assert images >= 4, "Figures 1, 2, the shear laws and the Voce family must be drawn"
