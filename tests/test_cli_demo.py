"""``jaxform demo`` and the command's wiring (issue 2)."""
import subprocess
import sys

import pytest

from jaxform.cli import main


QUICK = ["--element-size-mm", "25", "--set", "process.stroke_mm=3", "--set", "process.frames=2", "--quiet"]


def test_demo_prints_table_and_writes_plots(tmp_out, capsys):
    assert main(["demo", "--out", str(tmp_out), *QUICK]) == 0
    text = capsys.readouterr().out
    assert "woven-38616" in text and "ncf-fcim359" in text
    assert "0.000394" in text and "0.00804" in text and "0.00567" in text  # B_init of the three laws
    for name in ("fig1_woven_bending.png", "fig2_ncf_bending.png", "shear_laws.png"):
        path = tmp_out / name
        assert path.stat().st_size > 10_000
        assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
        assert str(path) in text or name in text
    # the forming run (Case A, woven, NLBM; coarse here for speed) and how to open it
    assert "case-a-woven-nlbm" in text and "ParaView" in text
    forming = tmp_out / "forming"
    for name in ("frames.pvd", "summary.json", "shear_angle.png", "deviation.png", "punch_force.png"):
        assert (forming / name).exists(), name
        assert str(forming / name) in text
    # a second run may replace its own output
    assert main(["demo", "--out", str(tmp_out), "--no-forming"]) == 0


def test_demo_refuses_a_users_non_empty_directory(tmp_out, capsys):
    tmp_out.mkdir()
    keep = tmp_out / "my_results.csv"
    keep.write_text("precious\n")
    assert main(["demo", "--out", str(tmp_out), "--no-forming"]) == 2
    assert "not empty" in capsys.readouterr().err
    assert keep.read_text() == "precious\n"
    assert not (tmp_out / "fig1_woven_bending.png").exists()
    assert main(["demo", "--out", str(tmp_out), "--force", "--no-forming"]) == 0
    assert keep.read_text() == "precious\n"


def test_console_script_is_installed():
    out = subprocess.run([sys.executable, "-m", "jaxform.cli", "--help"], capture_output=True, text=True, check=True)
    assert "demo" in out.stdout


@pytest.mark.parametrize("argv", [[], ["--version"]])
def test_help_and_version(argv, capsys):
    if argv == ["--version"]:
        with pytest.raises(SystemExit) as exc:
            main(argv)
        assert exc.value.code == 0
        assert "jaxform 0.1.0" in capsys.readouterr().out
    else:
        assert main(argv) == 2
