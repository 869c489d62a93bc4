"""The ``jaxform cases`` sub-command."""
from jaxform import cases
from jaxform.cli import main


def test_cases_lists_every_preset_one_line_each(capsys):
    assert main(["cases"]) == 0
    out = capsys.readouterr().out.strip().splitlines()
    assert len(out) == len(cases.PRESETS)
    for line, name in zip(out, cases.PRESETS):
        assert line.startswith(name + " ")
        assert "Case A" in line or "Case B" in line


def test_cases_name_prints_loadable_toml(capsys):
    assert main(["cases", "case-b-woven-nlbm"]) == 0
    text = capsys.readouterr().out
    assert cases.loads(text) == cases.load("case-b-woven-nlbm")


def test_unknown_case_is_an_error(capsys):
    assert main(["cases", "case-z"]) == 2
    assert "unknown case" in capsys.readouterr().err
