"""Sweeps (issue 17): batched members equal their single runs, groups and parts, failed members,
the ``jaxform sweep`` command, and the same sweep over two processes (jax.distributed, CPU)."""
import csv
import json
import os
import pathlib
import socket
import subprocess
import sys

import meshio
import numpy as np
import pytest

from jaxform import cases, forming
from jaxform.cli import main
from jaxform.cli.sweep import member_names, parse_vary, split_values
from jaxform.forming import batch
from helpers import FAST, FAST_SET

# the 1e16 Pa/m members are meant to blow up (even with the step cut to 1/8: omega dt ~ 400): build warns
# about them, as it should
pytestmark = pytest.mark.filterwarnings("ignore:forming.build. the time step and contact stiffness:RuntimeWarning")

BASE = ["--element-size-mm", "25", "--set", "process.stroke_mm=4", "--set", "process.frames=3", *FAST_SET]
VARY = ["--vary", "fabric.friction_tool=0.2,0.3", "--vary", "contact.penalty_stiffness_Pa_per_m=auto,1e16,1e3"]


def _case(*overrides):
    return cases.resolve("case-a-woven-nlbm", element_size=25e-3,
                         overrides=[*FAST, "process.stroke_mm=4", "process.frames=3", *overrides])


def _rows(path):
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


@pytest.fixture(scope="module")
def swept(tmp_path_factory):
    """One sweep of 6 members (friction x contact stiffness; the 1e16 Pa/m members blow up, the
    1e3 Pa/m ones cannot be built), in this process, the 4 that run sharded over the two CPU
    devices of the test session."""
    out = tmp_path_factory.mktemp("sweep") / "out"
    code = main(["sweep", "case-a-woven-nlbm", *BASE, *VARY, "--out", str(out), "--quiet"])
    return code, out, _rows(out / "sweep.csv")


def test_vary_values_and_member_names():
    assert split_values("0.1, 0.2,[1, 2],'a,b'") == ["0.1", "0.2", "[1, 2]", "'a,b'"]
    vary = parse_vary(["fabric.friction_tool=0.2,0.3", "holder.gap_mm=0.4"])
    assert vary == [("fabric.friction_tool", ["0.2", "0.3"]), ("holder.gap_mm", ["0.4"])]
    assert member_names(vary, [("0.2", "0.4"), ("0.3", "0.4")]) == ["000-friction_tool=0.2-gap_mm=0.4",
                                                                     "001-friction_tool=0.3-gap_mm=0.4"]
    for bad, why in [("fabric.friction_tool", "expected KEY=V1,V2"), ("x=1,,2", "empty value"), ("=1", "KEY=")]:
        with pytest.raises(ValueError, match=why):
            parse_vary([bad])
    with pytest.raises(ValueError, match="given twice"):
        parse_vary(["a.b=1", "a.b=2"])


def test_members_share_a_step_count_and_split_into_groups_and_parts():
    fast, slow = _case(), _case("process.speed_mm_per_s=250")
    lbm = _case("fabric.bending=membrane")
    rigs, groups = batch.build_members([fast, slow, lbm])
    assert groups == [[0, 1], [2]]  # another bending law type: another program
    own = forming.build(fast)
    r_fast, r_slow = rigs[0], rigs[1]
    # the slower member's step count for both; the faster one's step shortened, its stiffness kept
    assert r_fast.info.every == r_slow.info.every > own.info.every
    assert r_fast.info.n_steps == r_slow.info.n_steps
    assert r_fast.info.dt == pytest.approx(r_fast.info.stroke_time / r_fast.info.n_steps)
    k = [float(r.model.loads[forming.rig.PUNCH].params.stiffness) for r in (r_fast, own)]
    assert k[0] == pytest.approx(k[1], rel=1e-6)
    assert "share" in r_fast.info.numerics.why
    # the step budget (omega dt / 2 of shell and contacts) of the shorter step: in proportion to it
    ratio = r_fast.info.dt / own.info.dt
    assert r_fast.info.numerics.budget == pytest.approx(own.info.numerics.budget * ratio, rel=1e-9) and ratio < 1
    assert r_fast.info.numerics.safety == pytest.approx(own.info.numerics.safety * ratio**2, rel=1e-9)
    with pytest.raises(ValueError, match="at least"):
        forming.build(fast, every=own.info.every - own.info.samples_per_frame)
    # memory: a group that would not fit is split, and says so
    per = batch.member_bytes(rigs[0])
    parts = batch.plan_parts(rigs, groups, available_bytes=1.5 * per / batch.MEMORY_FRACTION)
    assert [p.members for p in parts] == [(0,), (1,), (2,)]
    assert parts[0].parts == 2 and "split" in parts[0].why and "GB" in parts[0].why
    assert [p.members for p in batch.plan_parts(rigs, groups, available_bytes=1e15)] == [(0, 1), (2,)]
    with pytest.raises(TypeError, match="list of"):
        batch.member_cases(fast, ["contact.friction=0.2"])


def test_lbm_and_nlbm_members_share_a_program_and_the_lbm_one_equals_its_own_run():
    import jax.numpy as jnp

    from jaxform.materials import LinearBending, VoceBending

    lbm = _case('fabric.bending="lbm-41"')
    rigs, groups = batch.build_members([_case(), lbm, _case("fabric.bending=membrane")])
    assert groups == [[0, 1], [2]]  # the linear law joins the Voce member; membrane-only runs apart
    law, own = rigs[1].model.shell.fabrics[0].bending[0], forming.build(lbm).model.shell.fabrics[0].bending[0]
    b = own.b
    assert isinstance(own, LinearBending) and isinstance(law, VoceBending)
    assert float(law.m0) == 0.0 and float(law.b_inf) == pytest.approx(float(b))
    kappa = jnp.array([-300.0, -1.0, 0.0, 2.0, 250.0])
    for f in ("moment", "stiffness", "energy"):
        assert np.array_equal(getattr(law, f)(kappa), getattr(LinearBending(b), f)(kappa))
        assert np.array_equal(getattr(LinearBending(2.2e-4).as_voce(), f)(kappa), getattr(LinearBending(2.2e-4), f)(kappa))
    res = batch.simulate_batch(_case(), [[], ['fabric.bending="lbm-41"']])
    single = forming.simulate(lbm)
    assert res[1].summary["batch"]["members"] == 2 and res[1].complete and single.complete
    assert np.max(np.abs(np.asarray(res[1].x[-1]) - np.asarray(single.x[-1]))) < 1e-6  # m


def test_sweep_writes_each_member_like_a_run_and_a_table(swept):
    code, out, rows = swept
    assert code == 1  # members failed: the command says so
    assert [r["fabric.friction_tool"] for r in rows] == ["0.2"] * 3 + ["0.3"] * 3
    assert [r["complete"] for r in rows] == ["True", "False", "False"] * 2
    for r in rows[2::3]:  # no rig: reported, with no frames and nothing that looks like a result
        s = json.loads((out / r["dir"] / "summary.json").read_text())
        assert r["reason"].startswith("error before the run started: contact_params") and s["reason"] == r["reason"]
        assert not s["complete"] and s["max_shear_angle_deg"] is None and r["max_shear_angle_deg"] == ""
        assert not list((out / r["dir"]).glob("frames_*.vtu"))
    for r in rows[0::3] + rows[1::3]:
        d = out / r["dir"]
        s = json.loads((d / "summary.json").read_text())
        assert s["batch"]["members"] == 4 and s["batch"]["devices"] == 2
        assert (d / "frames.pvd").is_file() and (d / "shear_angle.png").is_file()
        if r["complete"] == "True":
            assert len(list(d.glob("frames_*.vtu"))) == 3 and float(r["max_shear_angle_deg"]) > 0
            # 500 mm/s over a 4 mm stroke: inertia dominates, and the table says so beside the numbers
            assert float(r["max_ke_ie"]) > 0.1 and r["warnings"].split(";")[0] == "kinetic_energy"
        else:  # a failed member keeps its frames so far and says why; the others went on
            assert "energy blow-up" in r["reason"] and r["reason"].count("simulation failed") == 1
            assert not s["complete"] and s["reason"] == r["reason"]
            assert 1 <= len(list(d.glob("frames_*.vtu"))) < 3
    assert (out / "sweep_fabric.friction_tool.png").is_file()
    assert (out / "sweep_contact.penalty_stiffness_Pa_per_m.png").is_file()


def test_a_member_equals_its_single_run(swept):
    _, out, rows = swept
    single = forming.simulate(_case("fabric.friction_tool=0.3"))
    row = rows[3]
    assert float(row["max_shear_angle_deg"]) == pytest.approx(single.summary["max_shear_angle_deg"], abs=0.01)
    assert float(row["draw_in_edge_mid_mm"]) == pytest.approx(1e3 * single.summary["draw_in"]["edge_mid_m"], rel=1e-3)
    last = sorted((out / row["dir"]).glob("frames_*.vtu"))[-1]
    assert np.max(np.abs(meshio.read(last).points - single.x[-1])) < 1e-6  # m


def _free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


# 51 s in the default run (two processes compiling the same program at once): run with -m slow
@pytest.mark.slow
def test_two_processes_share_a_sweep_and_process_0_gathers_the_table(swept, tmp_path):
    _, _, rows = swept
    out = tmp_path / "two"
    port = _free_port()
    env = dict(os.environ, PYTHONPATH=str(pathlib.Path(__file__).resolve().parents[1]))
    cmd = [sys.executable, "-m", "jaxform", "sweep", "case-a-woven-nlbm", *BASE, "--vary",
           "fabric.friction_tool=0.2,0.3", "--out", str(out), "--quiet", "--cpu-devices", "1",
           "--coordinator", f"127.0.0.1:{port}", "--num-processes", "2"]
    procs = [subprocess.Popen([*cmd, "--process-id", str(i)], env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                              text=True) for i in range(2)]
    logs = [p.communicate(timeout=300)[0] for p in procs]
    assert [p.returncode for p in procs] == [0, 0], logs
    two = _rows(out / "sweep.csv")
    assert [r["process"] for r in two] == ["0", "1"] and all(r["complete"] == "True" for r in two)
    for r2, r1 in zip(two, (rows[0], rows[3])):  # the same members as the in-process sweep's
        assert float(r2["max_shear_angle_deg"]) == pytest.approx(float(r1["max_shear_angle_deg"]), abs=0.01)
        assert float(r2["draw_in_edge_mid_mm"]) == pytest.approx(float(r1["draw_in_edge_mid_mm"]), rel=1e-3)
        assert (out / r2["dir"] / "frames.pvd").is_file()


def test_sweep_refuses_bad_input_before_it_writes_anything(tmp_path, capsys):
    out = tmp_path / "bad"
    for vary, why in [("fabric.nope=1,2", "fabric.nope"), ("fabric.friction_tool=0.2,-1", "friction"),
                      ("fabric.friction_tool", "KEY=V1,V2")]:
        assert main(["sweep", "case-a-woven-nlbm", "--vary", vary, "--out", str(out), "--quiet"]) == 2
        assert why in capsys.readouterr().err
    assert not out.exists()
    assert main(["sweep", "case-a-woven-nlbm", "--vary", "fabric.friction_tool=0.2", "--out", str(out),
                 "--coordinator", "127.0.0.1:1", "--quiet"]) == 2
    assert "--num-processes" in capsys.readouterr().err and not out.exists()


def test_a_batch_member_whose_blank_is_drawn_into_the_die_stops_as_a_failed_forming():
    """The 120 mm blank of ``test_a_blank_drawn_into_the_die_stops_the_run_as_a_failed_forming``
    (drawn in near 27 mm of travel) beside a member that stops at 20 mm: the first fails as a forming,
    with no remedy tried alone afterwards; the other completes."""
    from jaxform.forming.health import DRAWN_IN

    case = cases.resolve("case-a-woven-nlbm", element_size=12e-3,
                         overrides=[*FAST, "blank.size_mm=120", "process.frames=6"])
    drawn, short = batch.simulate_batch(case, [[], ["process.stroke_mm=20"]])
    assert drawn.summary["batch"]["members"] == 2
    assert not drawn.complete and drawn.reason.startswith("the forming failed near step ") and DRAWN_IN in drawn.reason
    assert "simulation failed" not in drawn.reason and not drawn.step_cuts and drawn.momentum_term_from is None
    assert short.complete and len(drawn.t) >= 2
