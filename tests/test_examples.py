"""Every script in examples/ runs and prints the numbers it promises (scikit-fem's test_examples
habit): the figures are checked against closed forms written here, not against jaxform."""
import math
import pathlib
import re
import runpy

import pytest

EXAMPLES = sorted((pathlib.Path(__file__).resolve().parent.parent / "examples").glob("*.py"))


def _voce(k, b_inf, m0, kappa0):
    return b_inf * k + m0 * (1.0 - math.exp(-k / kappa0))


def _check_material_laws(out: str):
    mine = (0.02e-3, 0.006, 25.0)  # the example's law, SI: b_inf N·m, m0 N, kappa0 1/m
    preset = (1.549e-5, 7.57e-3, 20.0)  # SPEC section 3, woven 38616
    rows = re.findall(r"^\s*([\d.]+)\s+([\d.eE+-]+)\s+([\d.eE+-]+)\s*$", out, re.M)
    assert [float(r[0]) for r in rows] == [1.0, 10.0, 50.0, 200.0]
    for k, m_preset, m_mine in rows:
        assert float(m_preset) == pytest.approx(_voce(float(k), *preset), rel=1e-3)
        assert float(m_mine) == pytest.approx(_voce(float(k), *mine), rel=1e-3)
    b = re.search(r"B_init: preset ([\d.e+-]+) N·m, mine ([\d.e+-]+) N·m", out)
    assert float(b.group(1)) == pytest.approx(preset[0] + preset[1] / preset[2], rel=1e-3)
    assert float(b.group(2)) == pytest.approx(mine[0] + mine[1] / mine[2], rel=1e-3)
    g = re.search(r"d b_inf = ([\d.e+-]+) 1/m, /d m0 = ([\d.e+-]+), /d kappa0 = ([\d.e+-]+) N·m", out)
    k, (_, m0, kappa0) = 50.0, mine
    assert float(g.group(1)) == pytest.approx(k, rel=1e-2)
    assert float(g.group(2)) == pytest.approx(1.0 - math.exp(-k / kappa0), rel=1e-2)
    assert float(g.group(3)) == pytest.approx(-m0 * k / kappa0**2 * math.exp(-k / kappa0), rel=1e-2)
    assert re.search(r"LBM with B_init: LinearBending\(b=0\.00026", out)


CHECKS = {"material_laws.py": _check_material_laws}


def test_every_example_has_its_numbers_checked():
    assert sorted(p.name for p in EXAMPLES) == sorted(CHECKS)


@pytest.mark.parametrize("path", EXAMPLES, ids=[p.name for p in EXAMPLES])
def test_example_prints_its_numbers(path, capsys, monkeypatch, tmp_path):
    monkeypatch.chdir(tmp_path)
    runpy.run_path(str(path), run_name="__main__")
    out = capsys.readouterr().out
    assert out.strip(), f"{path.name} printed nothing"
    CHECKS[path.name](out)
