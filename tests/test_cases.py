"""Forming case descriptions: presets, strict validation naming the key, overrides, TOML round trip."""
import copy
import math

import pytest

from jaxform import cases, forming, materials, tools

SPEC_NAMES = [f"case-a-{f}-{b}" for f in ("woven", "ncf") for b in ("nlbm", "lbm-init", "lbm-41", "lbm-inf", "membrane")]
SPEC_NAMES += ["case-b-woven-nlbm", "case-b-ncf-nlbm"]


def test_presets_are_the_spec_names_and_load():
    assert [n for n, _ in cases.list_presets()] == SPEC_NAMES
    for name in SPEC_NAMES:
        case = cases.load(name)
        assert case.name == name
        fab = forming.build_fabric(case)
        assert isinstance(fab, materials.Fabric)
        assert fab.membrane_only == name.endswith("membrane")
        assert cases.loads(cases.to_toml(case)) == case  # TOML round trip


def test_case_a_and_b_match_the_paper():
    a = cases.load("case-a-woven-nlbm")
    assert a.n_plies == 1 and a.holder.mode == "gap"
    assert a.holder.gap == pytest.approx(7e-3) and a.element_size == pytest.approx(2e-3)
    assert a.process.stroke == pytest.approx(0.05) and a.blank_size == pytest.approx(0.25)
    assert a.tools.punch_radius == pytest.approx(0.05) and a.tools.die_opening_radius == pytest.approx(0.053)
    assert a.tools.die_fillet == pytest.approx(0.006)
    b = cases.load("case-b-ncf-nlbm")
    assert b.n_plies == 2 and b.orientations == (0.0, 0.0)
    assert b.holder.mode == "force" and b.holder.force == 1000.0 and b.element_size == pytest.approx(1e-3)
    assert forming.build_fabric(cases.load("case-a-woven-lbm-41")).bending[0].b == pytest.approx(2.2e-4)
    assert forming.build_fabric(cases.load("case-a-ncf-lbm-inf")).name.endswith("lbm-inf")


def test_build_tools_places_the_rig():
    case = cases.load("case-b-woven-nlbm")
    rig = forming.build_tools(case)
    h = case.ply_thickness
    assert isinstance(rig.punch, tools.Punch)
    assert float(rig.punch.apex_z) == pytest.approx(2 * h)
    assert float(rig.holder.bottom_z) == pytest.approx(2 * h)
    assert cases.ply_heights(case) == pytest.approx([1.5 * h, 0.5 * h])
    assert float(rig.punch.motion.displacement(1e3)) == pytest.approx(-0.05)
    v = case.process.speed  # the automatic quasi-static speed; the ramp takes 10 % of the stroke at half speed
    assert forming.stroke_time(case) == pytest.approx(0.05 / v + 0.5 * 0.1 * 0.05 / v)
    a = forming.build_tools(cases.load("case-a-woven-nlbm"))
    assert float(a.holder.bottom_z) == pytest.approx(7e-3)


def _error_of(change) -> str:
    """The message of the ValueError that validating a changed preset raises."""
    d = copy.deepcopy(cases.PRESETS["case-a-woven-nlbm"])
    change(d)
    with pytest.raises(ValueError) as err:
        cases.from_dict(d)
    return str(err.value)


def test_each_validation_error_names_its_key():
    assert "'tools.punch_radus_mm'" in _error_of(lambda d: d["tools"].update(punch_radus_mm=50.0))
    assert "'colour'" in _error_of(lambda d: d.update(colour="red"))
    assert "'blank.size_mm'" in _error_of(lambda d: d["blank"].pop("size_mm"))
    assert "[process]" in _error_of(lambda d: d.pop("process"))
    assert "'holder.gap_mm'" in _error_of(lambda d: d["holder"].pop("gap_mm"))
    assert "'holder.force_N'" in _error_of(lambda d: d["holder"].update(mode="force"))
    assert "'blank.size_mm'" in _error_of(lambda d: d["blank"].update(size_mm=100.0))  # smaller than the opening
    assert "'holder.gap_mm'" in _error_of(lambda d: d["holder"].update(gap_mm=0.2))  # gap smaller than the stack
    assert "'blank.element_size_mm'" in _error_of(lambda d: d["blank"].update(element_size_mm=0.0))
    assert "'blank.element_size_mm'" in _error_of(lambda d: d["blank"].update(element_size_mm=-1.0))
    assert "'tools.punch_radius_mm'" in _error_of(lambda d: d["tools"].update(punch_radius_mm=-5.0))
    assert "'tools.punch_radius_mm'" in _error_of(lambda d: d["tools"].update(punch_radius_mm=53.0))  # does not fit
    assert "'tools.die_fillet_mm'" in _error_of(lambda d: d["tools"].update(die_fillet_mm=12.0))
    assert "'process.stroke_mm'" in _error_of(lambda d: d["process"].update(stroke_mm="50"))
    assert "'process.frames'" in _error_of(lambda d: d["process"].update(frames=1))
    assert "'process.speed_mm_per_s'" in _error_of(lambda d: d["process"].update(speed_mm_per_s=0.0))
    assert "'fabric.bending'" in _error_of(lambda d: d["fabric"].update(bending="cubic"))
    assert "'fabric.preset'" in _error_of(lambda d: d["fabric"].update(preset="silk"))
    assert "'fabric.voce.kappa0_per_m'" in _error_of(lambda d: d["fabric"].update(voce={"b_inf_Nm": 1e-5, "m0_N": 1e-3}))
    assert "'numerics.dtype'" in _error_of(lambda d: d["numerics"].update(dtype="float16"))
    assert "'contact.penalty_stiffness_Pa_per_m'" in _error_of(lambda d: d["contact"].update(penalty_stiffness_Pa_per_m=-1.0))
    assert "'plies.orientations_deg'" in _error_of(lambda d: d["plies"].update(orientations_deg=[]))
    for bad in (0.0, -1e4, float("inf"), float("nan")):
        assert "'contact.expected_pressure_Pa'" in _error_of(lambda d: d["contact"].update(expected_pressure_Pa=bad))
    # Eight plies of 0.3 mm do not fit a 2 mm gap.
    def thick(d):
        d["plies"]["orientations_deg"] = [0.0] * 8
        d["holder"]["gap_mm"] = 2.0
    assert "'holder.gap_mm'" in _error_of(thick)


def test_overrides():
    case = cases.load("case-a-woven-nlbm")
    c2 = cases.apply_overrides(case, ["holder.gap_mm=5", "plies.orientations_deg=[0, 45]", "fabric.bending=membrane",
                                      "numerics.dtype=float64", "fabric.voce.b_inf_Nm=2e-5",
                                      "fabric.voce.m0_N=7e-3", "fabric.voce.kappa0_per_m=20"])
    assert c2.holder.gap == pytest.approx(5e-3)
    assert c2.orientations == pytest.approx((0.0, math.pi / 4))
    assert c2.fabric.bending == "membrane" and c2.dtype == "float64"
    assert c2.fabric.voce == (2e-5, 7e-3, 20.0)
    assert cases.with_element_size(case, 4e-3).element_size == pytest.approx(4e-3)
    with pytest.raises(ValueError, match="'holder.gpa_mm'"):
        cases.apply_overrides(case, ["holder.gpa_mm=5"])
    with pytest.raises(ValueError, match="key=value"):
        cases.apply_overrides(case, ["holder.gap_mm"])
    with pytest.raises(ValueError, match="'holder.gap_mm'"):
        cases.apply_overrides(case, ["holder.gap_mm=0.1"])
    # Custom Voce law reaches the fabric.
    fab = forming.build_fabric(cases.apply_overrides(case, ["fabric.voce={b_inf_Nm = 2e-5, m0_N = 7e-3, kappa0_per_m = 20.0}"]))
    assert float(fab.bending[0].b_inf) == pytest.approx(2e-5)


def test_toml_file_roundtrip_and_unknown_names(tmp_path):
    from jaxform.io.case_file import read_case, write_case

    case = cases.apply_overrides(cases.load("case-b-ncf-nlbm"), ["process.frames=21", "fabric.thickness_mm=0.45",
                                                               "contact.expected_pressure_Pa=3e4"])
    path = write_case(case, tmp_path / "my.toml")
    assert cases.load(str(path)) == case and case.contact.expected_pressure == 3e4
    assert cases.load("case-b-ncf-nlbm").contact.expected_pressure is None  # 'auto'
    assert 'expected_pressure_Pa = "auto"' in cases.to_toml(cases.load("case-b-ncf-nlbm"))
    assert read_case(path).ply_thickness == pytest.approx(0.45e-3)
    with pytest.raises(FileExistsError):
        write_case(case, path)
    with pytest.raises(ValueError, match="unknown case"):
        cases.load("case-c-woven")
    with pytest.raises(FileNotFoundError):
        cases.load(str(tmp_path / "missing.toml"))
    bad = tmp_path / "bad.toml"
    bad.write_text(cases.to_toml(case).replace("[holder]", "[holder]\nclamp = true"))
    with pytest.raises(ValueError, match="'holder.clamp'"):
        cases.load(str(bad))
    (tmp_path / "broken.toml").write_text("name = ")
    with pytest.raises(ValueError, match="not valid TOML"):
        cases.load(str(tmp_path / "broken.toml"))


def test_the_shear_reading_is_a_case_key_that_reaches_the_shell(tmp_path):
    """``fabric.shear_reading``: eq. A.14's tangent modulus (the default, left out of the TOML) or
    ``"conjugate"`` (``F_norm`` itself the shear resultant); it round-trips through a file, an
    unknown reading is refused naming the allowed ones, and the rig's shell reads the law so: its
    resultant at 40 deg is the law's ``integral`` (a14) or its ``force`` (conjugate), 1.70 and 4.38 N/m."""
    from jaxform.io.case_file import write_case
    from jaxform.shell import shear_resultant

    case = cases.with_element_size(cases.load("case-a-woven-nlbm"), 25e-3)
    conj = cases.apply_overrides(case, ["fabric.shear_reading=conjugate"])
    assert case.fabric.shear_reading == "a14" and "shear_reading" not in cases.to_toml(case)
    assert 'shear_reading = "conjugate"' in cases.to_toml(conj)
    assert cases.load(str(write_case(conj, tmp_path / "c.toml"))) == conj
    with pytest.raises(ValueError, match=r"'fabric\.shear_reading' = 'tangent': must be one of a14, conjugate"):
        cases.apply_overrides(case, ["fabric.shear_reading=tangent"])
    g, law = math.radians(40.0), materials.WOVEN_38616.shear
    for c, want in ((case, law.integral(g)), (conj, law.force(g))):
        shell = forming.build(c).model.shell
        got = shear_resultant(law, g, shell.shear_reading)
        assert float(got) == pytest.approx(float(want), rel=1e-6)
    assert float(law.integral(g)) == pytest.approx(1.70, abs=0.01) and float(law.force(g)) == pytest.approx(4.38, abs=0.01)


def test_overrides_are_named_in_the_description():
    c = cases.with_element_size(cases.load("case-a-woven-nlbm"), 4e-3)
    assert "2 mm elements" in c.description and "blank.element_size_mm=4.0" in c.description
    assert cases.apply_overrides(c, ['description="my run"']).description == "my run"


@pytest.mark.parametrize("override, key, words", [
    ("tools.holder_opening_radius_mm=40", "tools.holder_opening_radius_mm", "holder opening"),
    ("fabric.shear_poly_N_per_m=[-37.35, 322.61]", "fabric.shear_poly_N_per_m", "initial shear stiffness"),
    ("fabric.shear_poly_N_per_m=[10.0, -100.0]", "fabric.shear_poly_N_per_m", "must be positive"),
    ("contact.damping_ratio=30", "contact.damping_ratio", "critical damping"),
])
def test_physically_impossible_setups_are_refused_with_the_allowed_range(override, key, words):
    with pytest.raises(ValueError, match=key.replace(".", r"\.")) as err:
        cases.apply_overrides(cases.load("case-a-woven-nlbm"), [override])
    assert words in str(err.value)


def test_contact_damping_bound_follows_the_explicit_stability_limit():
    case = cases.load("case-a-woven-nlbm")
    # omega dt = sqrt(safety): stable while zeta <= (4 - safety) / (4 sqrt(safety)), 0.782 at 0.95
    cases.apply_overrides(case, ["contact.safety=0.95", "contact.damping_ratio=0.78"])
    with pytest.raises(ValueError, match="stable only up to 0.782"):
        cases.apply_overrides(case, ["contact.safety=0.95", "contact.damping_ratio=0.79"])
    cases.apply_overrides(case, ["contact.safety=0.1", "contact.damping_ratio=1.0"])
    # 'auto' may choose a safety up to 0.81 (four contacts sharing the step's budget): zeta <= 0.886
    cases.apply_overrides(case, ["contact.damping_ratio=0.88"])
    with pytest.raises(ValueError, match="contact.safety = auto the explicit step is stable only up to 0.886"):
        cases.apply_overrides(case, ["contact.damping_ratio=1.0"])


def test_automatic_punch_speed_follows_the_fibre_layout_and_round_trips():
    """``process.speed_mm_per_s = "auto"`` (the presets): the quasi-static speed of the study for
    the plies' fibre layout, recorded as chosen; a given speed is kept and dumps as given."""
    from jaxform.forming.speed import QUASI_STATIC_SPEED

    woven, ncf = cases.load("case-a-woven-nlbm"), cases.load("case-a-ncf-nlbm")
    assert woven.process.speed == QUASI_STATIC_SPEED["along"] and "auto" in woven.process.speed_choice
    assert ncf.process.speed == QUASI_STATIC_SPEED["off_axis"]
    assert QUASI_STATIC_SPEED["off_axis"] < 0.5 and QUASI_STATIC_SPEED["along"] < 0.5  # slower than the former 500 mm/s
    turned = cases.apply_overrides(woven, ["plies.orientations_deg=[45.0]"])  # woven at 45 deg: fibres off the edges
    assert turned.process.speed == QUASI_STATIC_SPEED["off_axis"]
    assert cases.to_dict(woven)["process"]["speed_mm_per_s"] == "auto"
    given = cases.apply_overrides(woven, ["process.speed_mm_per_s=250"])
    assert given.process.speed == pytest.approx(0.25) and given.process.speed_choice is None
    assert cases.to_dict(given)["process"]["speed_mm_per_s"] == pytest.approx(250.0)
    with pytest.raises(ValueError, match="speed_mm_per_s"):
        cases.apply_overrides(woven, ["process.speed_mm_per_s=-1"])
    with pytest.raises(ValueError, match="speed_mm_per_s"):
        cases.apply_overrides(woven, ['process.speed_mm_per_s="fast"'])
