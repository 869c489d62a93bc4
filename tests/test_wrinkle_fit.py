"""Wrinkle sections and the fit of the bending law from them (issue 16): the data's edge checks,
the position-tolerant residual, the pieces of the fit, and the script's refusals. The fit itself
runs end to end in notebook 07's test and in ``benchmarks/bench_wrinkle_fit.py``."""
import dataclasses
import math
import re
import threading

import jax.numpy as jnp
import numpy as np
import pytest

from jaxform import cases, forming
from jaxform.calibrate import sections as S
from jaxform.calibrate.sections import Section
from jaxform.contact import ToolLoad
from jaxform.calibrate import section_runs
from jaxform.calibrate import wrinkle_fit as wf
from jaxform.calibrate.transforms import law_from_q
from jaxform.calibrate.uncertainty import MISFIT_P
from jaxform.io import calibration_files as cf
from jaxform.materials import LinearBending, PolynomialShear, VoceBending, preset
from helpers import run_calibration_script

CASE = cases.resolve("case-a-woven-nlbm", element_size=25e-3)


def _section(s_mm=None, a_mm=None, line_mm=(60.0, 60.0, 120.0, 120.0), name="A"):
    s_mm = np.linspace(0.0, 80.0, 41) if s_mm is None else np.asarray(s_mm, float)
    a_mm = np.zeros_like(s_mm) if a_mm is None else np.asarray(a_mm, float)
    line = np.asarray(line_mm, float) * 1e-3
    return S.Section(s_mm * 1e-3, a_mm * 1e-3, line[:2], line[2:], name)


@pytest.mark.parametrize("kwargs,match", [
    (dict(line_mm=(0.06, 0.06, 0.12, 0.12), s_mm=np.linspace(0, 0.08, 9)), r"line is 0.0849 mm long .* in metres"),
    (dict(line_mm=(60.0, 60.0, 160.0, 160.0), s_mm=np.linspace(0.0, 140.0, 29)), r"outside the 250 mm square blank"),
    (dict(s_mm=np.linspace(0.0, 150.0, 20)), r"positions run from 0 to 150 mm, off the 84.85 mm line"),
    (dict(s_mm=[0.0, 1.0, 2.0]), r"need at least 5"),
    (dict(a_mm=np.full(41, 1e4)), r"amplitudes up to 1e\+04 mm, more than the 250 mm blank"),
])
def test_check_section_refuses(kwargs, match):
    with pytest.raises(ValueError, match=match):
        S.check_section(_section(**kwargs), CASE)


def test_check_section_accepts_a_line_to_the_blank_edge_and_refuses_one_a_millimetre_past_it():
    """The edge of the 250 mm blank is the limit: a section ending on it passes, 1 mm further does not."""
    edge = _section(s_mm=np.linspace(0.0, 65.0, 14), line_mm=(60.0, 0.0, 125.0, 0.0))
    assert np.isclose(np.max(np.abs(edge.points())), 0.125)
    S.check_section(edge, CASE)  # raises if refused
    past = _section(s_mm=np.linspace(0.0, 66.0, 14), line_mm=(60.0, 0.0, 126.0, 0.0))
    with pytest.raises(ValueError, match=r"1 of 14 measured points lie outside"):
        S.check_section(past, CASE)


def test_smoothing_tolerates_a_shifted_wrinkle():
    """A 3 mm crest moved by 2 mm: after smoothing over 8 mm its residual is a third of the raw one or
    less, and the smoothed crest still stands out against no wrinkle at all (the signal is kept)."""
    s = np.linspace(0.0, 0.1, 201)
    crest = lambda c: 3e-3 * np.exp(-0.5 * ((s - c) / 3e-3) ** 2)  # noqa: E731
    W = S.smoothing_matrix(s, 8e-3)
    assert np.allclose(W.sum(axis=1), 1.0)
    raw = np.sqrt(np.mean((crest(0.052) - crest(0.05)) ** 2))
    smooth = np.sqrt(np.mean((W @ (crest(0.052) - crest(0.05))) ** 2))
    signal = np.sqrt(np.mean((W @ crest(0.05)) ** 2))
    assert smooth < raw / 3.0
    assert signal > 5.0 * smooth
    assert np.allclose(S.smoothing_matrix(s, 0.0), np.eye(s.size))
    # a row's noise after smoothing: sigma * sqrt(sum W^2), below sigma
    rs = S.row_scale(W, 5e-5)
    assert np.all(rs < 5e-5) and np.all(rs > 5e-5 / np.sqrt(s.size))


def test_read_section_csv(tmp_path):
    p = tmp_path / "a.csv"
    p.write_text("s_mm,amplitude_mm\n2,0.5\n0,0.1\n1,0.3\n1,0.5\n3,0.2\n4,0.1\n5,0\n")
    sec = cf.read_section_csv(p, np.zeros(2), np.array([0.05, 0.0]))
    assert np.allclose(sec.s, np.arange(6) * 1e-3) and math.isclose(sec.amplitude[1], 0.4e-3)
    p.write_text("s,amp\n1,2\n")
    with pytest.raises(ValueError, match="must have columns s_mm,amplitude_mm"):
        cf.read_section_csv(p, np.zeros(2), np.ones(2))
    p.write_text("s_mm,amplitude_mm\n0,1\n1,\n2,1\n3,1\n4,1\n5,x\n")
    with pytest.raises(ValueError, match="not a number"):
        cf.read_section_csv(p, np.zeros(2), np.ones(2))
    out = cf.write_section_csv(tmp_path / "b.csv", sec.s, sec.amplitude)
    back = cf.read_section_csv(out, sec.start, sec.end)
    assert np.allclose(back.amplitude, sec.amplitude)
    with pytest.raises(FileExistsError):
        cf.write_section_csv(out, sec.s, sec.amplitude)


@pytest.mark.parametrize("text", ["1,2,3", "a,b,c,d", "1,2,3,nan"])
def test_parse_line_refuses(text):
    with pytest.raises(ValueError, match="four numbers X0,Y0,X1,Y1 in mm"):
        cf.parse_line_mm(text)


def test_scaled_shear_scales_the_force_of_both_fabrics():
    g = np.linspace(-0.8, 0.8, 17)
    for shear in (PolynomialShear([1.0, 2.0, 3.0]), preset("ncf-fcim359").shear):
        assert np.allclose(np.asarray(wf.scaled_shear(shear, 2.5).force(g)), 2.5 * np.asarray(shear.force(g)))


def test_voce_start_and_imperfections():
    lin = wf.voce_start(LinearBending(4e-4))
    assert isinstance(lin, VoceBending) and math.isclose(float(lin.b_init), 4e-4)
    x0 = np.stack(np.meshgrid(np.linspace(-0.1, 0.1, 11), np.linspace(-0.1, 0.1, 11)), -1).reshape(-1, 2)
    x0 = np.concatenate([x0, np.zeros((len(x0), 1))], 1)
    dz = wf.imperfections(x0, 3, 2e-5, 0.2)
    assert np.all(dz[0] == 0) and np.all(dz[:, :, :2] == 0)
    assert np.allclose(np.abs(dz[1:, :, 2]).max(axis=1), 2e-5)
    assert not np.allclose(dz[1], dz[2])
    # near the tools the field tapers to 0: none where the clearance is under the amplitude, all of it
    # beyond twice the amplitude, and never more than the clearance less the amplitude between
    clear = np.linspace(0.0, 6e-5, len(x0))
    dt = wf.imperfections(x0, 3, 2e-5, 0.2, clearance=clear)
    assert np.all(dt[:, clear <= 2e-5, 2] == 0)
    far = clear >= 4e-5
    np.testing.assert_array_equal(dt[:, far], dz[:, far])
    assert np.all(np.abs(dt[1:, :, 2]) <= np.maximum(clear - 2e-5, 0.0) + 1e-18)


def test_the_fit_s_imperfect_blanks_start_clear_of_the_tools():
    """An imperfect blank of the fit's rig starts outside holder, die and punch (8 mm woven Case A
    started 0.1 h deep in holder and die untapered, and blew up)."""
    case = cases.resolve("case-a-woven-nlbm", element_size=25e-3)
    sec = Section(s=np.linspace(0.0, 0.03, 31), amplitude=np.zeros(31), start=np.array([0.06, 0.0]),
                  end=np.array([0.09, 0.0]))
    runs = section_runs.SectionRuns(case, [sec], "voce", 3, 0.1 * case.ply_thickness, 1, 1)
    model, state = runs.rig[0], runs.rig[1]
    assert float(jnp.abs(runs.dz[1:]).max()) > 0
    for k in (1, 2):
        x = state.x + runs.dz[k]
        for ld, ls in zip(model.loads, state.loads):
            if isinstance(ld, ToolLoad):
                gap0, gap = np.asarray(ld.gap(state.x, state.t, ls)), np.asarray(ld.gap(x, state.t, ls))
                assert np.all(gap >= np.minimum(gap0, 0.0) - 1e-12)  # nobody pushed into a tool


def test_the_fit_s_step_is_built_for_the_stiffest_law_it_will_run():
    """A trial law stiffer than the start raises the shell's bending frequency; on the start's step it
    could outrun the explicit limit. ``step_b_init`` (the fit passes its box's largest B_init) builds the
    rig's step for that law, as ``forming.build`` gives it, and keeps the start law as ``law0``; a
    value below the start's changes nothing."""
    case = cases.resolve("case-a-woven-nlbm", element_size=25e-3)
    sec = Section(s=np.linspace(0.0, 0.03, 31), amplitude=np.zeros(31), start=np.array([0.06, 0.0]),
                  end=np.array([0.09, 0.0]))
    own = section_runs.SectionRuns(case, [sec], "voce", 1, 0.0, 1, 1)
    b0 = float(np.exp(wf.q_from_law(own.law0, "voce")[0]))
    softer = section_runs.SectionRuns(case, [sec], "voce", 1, 0.0, 1, 1, step_b_init=0.5 * b0)
    stiff = section_runs.SectionRuns(case, [sec], "voce", 1, 0.0, 1, 1, step_b_init=1000.0 * b0)
    assert float(softer.rig[0].dt) == float(own.rig[0].dt)
    law = law_from_q(wf.q_from_law(own.law0, "voce") + [np.log(1000.0), 0.0, 0.0], "voce")
    frames = dataclasses.replace(case, process=dataclasses.replace(case.process, frames=section_runs.GRAD_FRAMES))
    want = forming.build(frames, fabric=forming.build_fabric(case).replace(bending=(law, law))).info.dt
    assert float(stiff.rig[0].dt) == float(np.asarray(want, stiff.rig[0].dt.dtype))  # the rig holds it in its dtype
    assert float(stiff.rig[0].dt) < 0.95 * float(own.rig[0].dt)  # bending sets this law's step at 25 mm
    assert wf.q_from_law(stiff.law0, "voce") == pytest.approx(wf.q_from_law(own.law0, "voce"))


@pytest.mark.parametrize("width,workers", [(2, 1), (1, 2)])
def test_a_fit_run_that_fails_without_the_momentum_term_is_run_again_with_it(monkeypatch, width, workers):
    """As ``forming.run`` switches the fibre mass's momentum term on where a chunk fails without it
    (tested in test_fibre_mass), the fit runs a law again with the term where its run failed, and
    keeps the first result of the laws that did not fail; the same when the batches run in two
    threads at once (a CPU's cores: both must be inside the program together). Wiring only: the
    program is stubbed, the flag of the fibre mass tells which rig it got."""
    case = cases.resolve("case-a-woven-nlbm", element_size=25e-3, overrides=["numerics.fibre_mass_scaling=12"])
    sec = Section(s=np.linspace(0.0, 0.03, 31), amplitude=np.zeros(31), start=np.array([0.06, 0.0]),
                  end=np.array([0.09, 0.0]))
    runs = section_runs.SectionRuns(case, [sec], "voce", 1, 0.0, width, 1, workers)
    assert not runs.rig[0].fibre_mass.geometric and runs.rigs[1][0].fibre_mass.geometric
    m = len(sec.s)
    together = threading.Barrier(workers, timeout=30)

    def stub(Q, Z, rig, lines, static):  # law 0 fails without the term; the exact rig's results are 2 and 3
        exact = rig[0].fibre_mass.geometric
        if not exact:
            together.wait()
        y = np.full((len(Q), m), 2.0 if exact else 1.0)
        ok = np.ones(len(Q), bool) if exact else np.asarray(Q)[:, 0] > -5.0
        return y, np.ones((len(Q), m), bool), ok, np.full(len(Q), 3.0 if exact else 1.0)

    monkeypatch.setattr(section_runs, "_batch", stub)
    (y0, _, ok0, r0), (y1, _, ok1, r1) = runs.evaluate([np.array([-6.0, -1.0, 3.0]), np.array([-4.0, -1.0, 3.0])])
    assert ok0 and ok1 and np.all(y0 == 2.0) and r0 == 3.0 and np.all(y1 == 1.0) and r1 == 1.0
    assert runs.exact == {section_runs._key(np.array([-6.0, -1.0, 3.0]))}
    assert runs.runs == 2 + width  # both laws, and the failed one's batch again with the term


def _stub_case():
    """A coarse woven Case A and one radial section on it, for fits whose forming program is stubbed."""
    case = cases.resolve("case-a-woven-nlbm", element_size=25e-3, overrides=["numerics.fibre_mass_scaling=12"])
    sec = Section(s=np.linspace(0.0, 0.03, 31), amplitude=np.zeros(31), start=np.array([0.06, 0.0]),
                  end=np.array([0.09, 0.0]))
    return case, sec


def _linear_stub(monkeypatch):
    """:func:`_stub_case` with the forming program stubbed by amplitudes linear in the law (the truth
    0.3 up in log B_init and log kappa0 from the preset's): no forming run."""
    case, sec = _stub_case()
    q_true = wf.q_from_law(section_runs.SectionRuns(case, [sec], "voce", 1, 0.0, 1, 1).law0, "voce") + [0.3, 0.0, 0.3]
    shape = np.stack([np.ones(31), np.linspace(-1.0, 1.0, 31), np.zeros(31)], 1)

    def stub(Q, Z, rig, lines, static):
        y = 1e-3 * (np.asarray(Q, float) - q_true) @ shape.T
        return y, np.ones_like(y, bool), np.ones(len(Q), bool), np.full(len(Q), 10.0)

    monkeypatch.setattr(section_runs, "_batch", stub)
    return case, sec


def test_the_fit_moves_to_a_better_probe_of_its_final_jacobian(monkeypatch):
    """Where the optimiser stops (here: out of evaluations) and a probe of the final Jacobian fits
    better, the fit moves there and probes again, and reports the best law it saw. The forming
    program is stubbed by amplitudes linear in the law (the truth 0.3 up in log B_init and log
    kappa0), so this runs no forming run."""
    case, sec = _linear_stub(monkeypatch)
    fit = wf.fit_wrinkles(case, [sec], n_starts=1, max_iter=1, gradient_check=False)  # no optimiser step
    assert fit.moves == 1  # one 0.05 log step downhill, the most max_iter allows
    seen = wf.section_loss(case, [sec], [fit.q])[0][0]
    assert fit.loss_final == pytest.approx(seen) and fit.loss_final < 0.8 * fit.loss_initial
    assert not fit.converged and "Gauss-Newton" in fit.reason  # still about 0.25 from the truth


def test_the_fit_moves_to_a_probe_of_its_sigma_check_that_fits_better(monkeypatch):
    """Where the sigma check has run a law that fits better than the fit (by more than MOVE_RTOL),
    the fit moves there: it reports that law, with its own Jacobian and a check there, and says
    where it came from. The check is the real one, with a better law put among its probes on its
    first call (here the truth, as the round trip at 8 mm met one at chi-square 118 beside 310);
    the forming program is the linear stub (no forming run)."""
    case, sec = _linear_stub(monkeypatch)
    q_true = wf.q_from_law(section_runs.SectionRuns(case, [sec], "voce", 1, 0.0, 1, 1).law0, "voce") + [0.3, 0.0, 0.3]
    real, calls, probe = wf.checked_covariance, [], {}

    def check(rows, q, r, J, cov, lo, hi, **kw):
        out = real(rows, q, r, J, cov, lo, hi, **kw)
        calls.append(np.array(q, float))
        if len(calls) == 1:  # a better law among the probes
            chi = float(np.sum(rows(probe["q"]) ** 2))
            out[1]["lower"] = {"q": probe["q"].tolist(), "chi_square": chi, "fit_chi_square": float(r @ r),
                               "significant": False}
        return out

    monkeypatch.setattr(wf, "checked_covariance", check)
    kw = dict(n_starts=1, max_iter=1, gradient_check=False)  # the optimiser stops early
    probe["q"] = q_true
    fit = wf.fit_wrinkles(case, [sec], **kw)
    moved = fit.sigma_check["moved_from"]
    assert len(calls) == 2 and len(moved) == 1 and np.allclose(calls[1], q_true)  # checked again where it moved
    assert np.allclose(moved[0]["q"], calls[0]) and moved[0]["chi_square"] > 1e3
    assert np.allclose(fit.q, q_true) and fit.loss_final == pytest.approx(0.0, abs=1e-9)
    assert fit.converged, fit.reason  # the optimiser ran out, but at the law moved to no Gauss-Newton step is left
    calls.clear()  # a better law that is not a minimum: moved to, and said so
    probe["q"] = 0.5 * (q_true + moved[0]["q"])
    fit = wf.fit_wrinkles(case, [sec], **kw)
    assert np.allclose(fit.q, probe["q"]) and len(fit.sigma_check["moved_from"]) == 1 and not fit.converged
    assert fit.reason.startswith("the fit moved to a better law its sigma check had run"), fit.reason
    # a law whose remaining Gauss-Newton gain is over 1 in raw chi-square but under one of the noise's
    # degrees of freedom (the smoothed rows' misfit scale): converged, as the round trip's moved fit
    R = S.weights([sec], wf.NOISE, float(case.element_size))
    mean, var = S.chi_square_moments(R, wf.NOISE)
    scale, unit = var / (2.0 * mean), float(np.sum((R @ np.full(31, 1e-3)) ** 2))  # chi-square of a 1-log-unit offset
    assert scale > 4.0
    calls.clear()
    probe["q"] = q_true + np.array([math.sqrt(math.sqrt(scale) / unit), 0.0, 0.0])  # raw chi-square sqrt(scale)
    fit = wf.fit_wrinkles(case, [sec], **kw)
    d = fit.as_dict()
    assert np.allclose(fit.q, probe["q"]) and fit.misfit["scale"] == pytest.approx(scale)
    assert d["gn_decrease_chi2"] == pytest.approx(math.sqrt(scale), rel=1e-3) and d["gn_decrease_dof"] < 1.0
    assert fit.converged, fit.reason


def test_a_fit_in_a_local_minimum_runs_again_from_the_next_best_starts(monkeypatch):
    """Where the local fit from the best start ends in a local minimum (its chi-square beyond what
    the noise leaves at the true law), the fit runs the local phase again from the next-best starts
    and keeps the best (step 6). The forming program is stubbed: the amplitude is a cubic in log
    B_init, h(u) = u^3 - 3u + 2.5 with u = u* + 4 (q0 - q0_true) (u* its real root), whose square
    has a local minimum at u = 1 (h = 0.5, ten noise sds a row) and the zero at the truth, plus
    terms linear in the other two parameters; the starting law sits at u = 0, downhill of the trap."""
    case, sec = _stub_case()
    u_root = float(np.real(np.roots([1.0, 0.0, -3.0, 2.5])[np.isreal(np.roots([1.0, 0.0, -3.0, 2.5]))][0]))
    q_start = wf.q_from_law(section_runs.SectionRuns(case, [sec], "voce", 1, 0.0, 1, 1).law0, "voce")
    q_true = q_start + [u_root / 4.0, -0.2, 0.2]
    t = np.linspace(-1.0, 1.0, 31)
    shape = np.stack([np.ones(31), t, t**2], 1)

    def stub(Q, Z, rig, lines, static):
        d = np.asarray(Q, float) - q_true
        u = u_root + 4.0 * d[:, 0]
        y = 1e-3 * np.stack([u**3 - 3.0 * u + 2.5, d[:, 1], d[:, 2]], 1) @ shape.T
        return y, np.ones_like(y, bool), np.ones(len(Q), bool), np.full(len(Q), 10.0)

    monkeypatch.setattr(section_runs, "_batch", stub)
    kw = dict(n_starts=6, max_iter=20, gradient_check=False, smoothing=2e-3)  # rows ~unsmoothed: all three shapes tell
    trapped = wf.fit_wrinkles(case, [sec], restarts=0, **kw)
    assert len(trapped.local_fits) == 1 and not trapped.misfit["consistent"] and not trapped.converged
    assert abs(4.0 * (trapped.q[0] - q_true[0]) + u_root - 1.0) < 0.1  # in the trap, u = 1
    assert "local minimum" in trapped.reason and "after 1 local fit" in trapped.reason
    fit = wf.fit_wrinkles(case, [sec], **kw)  # restarts=2: the third start leaves the trap
    assert len(fit.local_fits) == 3 and all(f["misfit_p"] < MISFIT_P for f in fit.local_fits[:2])
    assert fit.converged and fit.misfit["consistent"], fit.reason
    assert np.max(np.abs(fit.q - q_true)) < 0.01 and fit.loss_final < 1e-3 * trapped.loss_final
    assert fit.as_dict()["local_fits"][-1]["loss_final"] == pytest.approx(fit.loss_final)


def test_the_optimiser_s_trial_runs_beside_its_difference_laws_in_idle_slots(monkeypatch):
    """With two workers (a CPU's two cores) the optimiser's trial law runs beside one of its
    forward-difference laws: an accepted trial's Jacobian then needs one round of runs, not two.
    The same fit, the same laws; fewer rounds (the stub of the moves test: linear, no forming run)."""
    case, sec = _linear_stub(monkeypatch)
    evaluate, rounds = section_runs.SectionRuns.evaluate, []

    def counted(self, qs):
        todo = len({section_runs._key(q) for q in qs if not self.cached(q)})
        rounds.append(-(-todo // 2))  # two workers
        return evaluate(self, qs)

    monkeypatch.setattr(section_runs.SectionRuns, "evaluate", counted)
    kw = dict(n_starts=1, max_iter=4, gradient_check=False, workers=2)
    fit = wf.fit_wrinkles(case, [sec], **kw)
    with_spare = sum(rounds)
    rounds.clear()
    monkeypatch.setattr(section_runs.SectionRuns, "round_laws", property(lambda self: 1))  # no spare slot used
    plain = wf.fit_wrinkles(case, [sec], **kw)
    assert np.allclose(fit.q, plain.q) and fit.loss_final == pytest.approx(plain.loss_final)
    assert with_spare < sum(rounds), (with_spare, sum(rounds))


def test_block_misfit_flags_a_block_that_the_whole_test_hides():
    """jaxform.calibrate.uncertainty.block_misfit on the joint fit's figures at a 0.0125 log step
    (record 20261204T-qs-joint-step.json): chi-square 401 against 205 +- 75 passes as a whole
    (p = 0.014), while its profile (0.0805 mm RMS on 60 rows, 0.05 mm noise: 156) fails on its own;
    rows drawn from the noise pass; one block is the plain misfit test."""
    from jaxform.calibrate.uncertainty import block_misfit, misfit

    sec_var = 74.67194314409132**2 - 120.0
    r = np.concatenate([np.full(145, math.sqrt((401.47 - 155.5) / 145)), np.full(60, 0.0805 / 0.05)])
    blocks = [("sections", slice(0, 145), 145.0, sec_var), ("profiles", slice(145, None), 60.0, 120.0)]
    out = block_misfit(r, blocks)
    assert out["p_value"] == pytest.approx(0.014, abs=0.002) and out["p_value"] > MISFIT_P
    assert out["failed"] == ["profiles"] and not out["consistent"]
    assert out["blocks"]["profiles"]["p_value"] < 1e-8 and out["blocks"]["sections"]["consistent"]
    assert out["blocks"]["profiles"]["limit"] == pytest.approx(MISFIT_P / 2)
    noise = np.random.default_rng(1).standard_normal(205)
    assert block_misfit(noise, [("a", slice(0, 145), 145.0, 290.0), ("b", slice(145, None), 60.0, 120.0)])["consistent"]
    one = block_misfit(r, [("all", slice(None), 205.0, 74.67194314409132**2)])
    assert one["consistent"] == misfit(float(r @ r), 205.0, 74.67194314409132**2)["consistent"] and one["failed"] == []
    assert block_misfit(3.0 * r, [("all", slice(None), 205.0, 74.67194314409132**2)])["failed"] == ["all"]


def _cli(argv, capsys):
    return run_calibration_script("fit_wrinkles", argv, capsys)


def _csv(path, s_mm, a_mm):
    path.write_text("s_mm,amplitude_mm\n" + "\n".join(f"{u},{v}" for u, v in zip(s_mm, a_mm)) + "\n")
    return path


@pytest.mark.parametrize("extra,match", [
    (["--line", "0.06,0.06,0.12,0.12"], r"line is .* mm long .* in metres"),
    (["--line", "100,100,200,200"], r"outside the 250 mm square blank"),
    (["--line", "60,60"], r"four numbers X0,Y0,X1,Y1"),
    (["--line", "60,60,120,120", "--set", "fabric.nope=1"], r"fabric.nope"),
    (["--line", "60,60,120,120", "--scatter-seeds", "-1"], r"--scatter-seeds"),
])
def test_fit_wrinkles_script_refuses_input(tmp_path, capsys, extra, match):
    sec = _csv(tmp_path / "a.csv", np.linspace(0, 80, 21), np.zeros(21))
    out = tmp_path / "params.json"
    rc, _, err = _cli(["--case", "case-a-woven-nlbm", "--section", sec, *extra, "--out", out], capsys)
    assert rc == 2, err
    assert re.search(match, err), err
    assert not out.exists()


def test_fit_wrinkles_script_refuses_before_running(tmp_path, capsys):
    sec = _csv(tmp_path / "a.csv", np.linspace(0, 80, 21), np.zeros(21))
    out = tmp_path / "params.json"
    out.write_text("{}")
    rc, _, err = _cli(["--case", "case-a-woven-nlbm", "--section", sec, "--line", "60,60,120,120", "--out", out], capsys)
    assert rc == 2 and "exists; refusing to overwrite" in err and out.read_text() == "{}"
    rc, _, err = _cli(["--case", "case-a-woven-nlbm", "--section", sec, "--out", tmp_path / "p.json"], capsys)
    assert rc == 2 and "give one line" in err
    rc, _, err = _cli(["--case", "case-a-woven-nlbm", "--section", sec, "--line", "60,60,120,120", "--profile", sec,
                       "--overhang-mm", "90", "--out", tmp_path / "p.json"], capsys)
    assert rc == 2 and "--areal-mass-gsm" in err


def test_misfit_is_the_noise_s_own_chi_square_at_the_true_law():
    """What the fit calls a misfit beyond the noise (jaxform.calibrate.uncertainty.misfit): the
    smoothed section rows' chi-square under the measurement noise alone (correlated rows) has the
    mean and variance ``chi_square_moments`` says (against 40,000 draws of the noise: 2 % and 6 %),
    its p-values are calibrated (1 % of those draws below p = 0.01, within 0.5-2 %), for
    independent rows they are the chi-square distribution's own, and a chi-square 12 sds out (the
    joint fit's local minimum at 62.5 mm/s) is inconsistent."""
    from scipy.stats import chi2

    from jaxform.calibrate.uncertainty import MISFIT_P, misfit

    secs = [Section(s=np.linspace(0.0, L, n), amplitude=np.zeros(n), start=np.array([0.06, 0.0]),
                    end=np.array([0.06 + L, 0.0])) for L, n in ((0.1, 101), (0.06, 41))]
    R = S.weights(secs, 5e-5, 8e-3)
    mean, var = S.chi_square_moments(R, 5e-5)
    draws = np.sum((R @ (5e-5 * np.random.default_rng(3).standard_normal((R.shape[1], 40_000)))) ** 2, axis=0)
    assert mean == pytest.approx(R.shape[0]) and np.mean(draws) == pytest.approx(mean, rel=0.02)
    assert np.var(draws) == pytest.approx(var, rel=0.06) and var > 4.0 * 2 * R.shape[0]  # far from independent
    p = np.array([misfit(c, mean, var)["p_value"] for c in draws[:4000]])
    assert 0.005 <= np.mean(p < 0.01) <= 0.02
    assert misfit(130.0, 100.0, 200.0)["p_value"] == pytest.approx(chi2.sf(130.0, 100), rel=1e-9)
    assert misfit(130.0, 100.0, 200.0)["scale"] == 1.0 and misfit(mean, mean, var)["scale"] > 4.0
    assert misfit(mean, mean, var)["consistent"]
    out = misfit(mean + 12.0 * math.sqrt(var), mean, var)
    assert not out["consistent"] and out["p_value"] < MISFIT_P


def test_checked_covariance_keeps_a_quadratic_loss_and_widens_a_jacobian_steeper_than_the_loss():
    """jaxform.calibrate.uncertainty: on a linear least-squares problem the probes along the
    covariance's principal axes measure exactly the quadratic model's rise (nothing widened; each
    axis probed once further out, 4 p runs); a Jacobian 10x steeper than the loss (what
    a rough finite difference gives) had sds 10x too small: the check widens them back to the loss's
    own Laplace figure; a probe beyond a bound moves back along its axis; a failed run is a steep
    loss; a law below the fit is reported."""
    from jaxform.calibrate.uncertainty import checked_covariance

    rng = np.random.default_rng(0)
    A = rng.normal(size=(40, 3)) * np.array([1.0, 5.0, 0.2])
    b = rng.normal(size=40)
    q = np.linalg.lstsq(A, b, rcond=None)[0]
    calls = []

    def rows(x):
        calls.append(x)
        return A @ x - b

    r, lo, hi = rows(q), np.full(3, -50.0), np.full(3, 50.0)
    cov = np.linalg.inv(A.T @ A)
    calls.clear()
    out, rep = checked_covariance(rows, q, r, A, cov, lo, hi, names=("a", "b", "c"))
    np.testing.assert_allclose([a["widened_by"] for a in rep["axes"]], 1.0, rtol=1e-9)
    np.testing.assert_allclose(out, cov, rtol=1e-9, atol=1e-15)
    assert rep["lower"] is None and len(calls) == 4 * 3 and not any(a["open"] for a in rep["axes"])
    for a in rep["axes"]:
        for pr in a["probes"]:
            assert pr["measured_rise"] == pytest.approx(pr["predicted_rise"], rel=1e-9)
    steep = 10.0 * A
    out, rep = checked_covariance(rows, q, r, steep, np.linalg.inv(steep.T @ steep), lo, hi, names=("a", "b", "c"))
    np.testing.assert_allclose([a["widened_by"] for a in rep["axes"]], 10.0, rtol=1e-9)
    np.testing.assert_allclose(out, cov, rtol=1e-9, atol=1e-15)
    # a probe beyond a bound moves back along its axis onto it; a failed model run counts as a steep loss
    lam, V = np.linalg.eigh(cov)
    hi2 = q + 1e-3 * np.abs(V[:, 0]).max()
    seen = []
    out, rep = checked_covariance(lambda x: np.full(40, np.nan) if np.any(x > hi2 - 1e-12) else rows(x), q, r, A, cov,
                                  lo, hi2, names=("a", "b", "c"), prefetch=seen.extend)
    steps = [pr["step"] for a in rep["axes"] for pr in a["probes"]]
    assert len(seen) == len(steps) and all(np.all(x <= hi2 + 1e-12) for x in seen)
    assert any(pr["measured_rise"] is None for a in rep["axes"] for pr in a["probes"])  # the failed ones
    np.testing.assert_allclose([a["widened_by"] for a in rep["axes"]], 1.0, rtol=1e-9)
    # a lower loss at the probes: the fit is not at a minimum
    out, rep = checked_covariance(lambda x: np.array([x[0] ** 2 - 1.0]), np.zeros(1), np.array([-1.0]),
                                  np.ones((1, 1)), np.array([[0.25]]), [-5.0], [5.0], names=("a",))
    assert rep["lower"]["chi_square"] == pytest.approx(0.0) and rep["lower"]["significant"]


@pytest.mark.parametrize("offset, is_open", [(0.25, False), (4.0, True)])
def test_checked_covariance_finds_the_flat_valley_under_a_rough_loss(offset, is_open):
    """jaxform.calibrate.uncertainty: a loss with a flat valley (sd 10 along it) that a rough
    Jacobian made look steep (Laplace sd 0.1 there), and a roughness that lifts the chi-square by
    ``offset`` at any law but the fit's (the fit sits in a dip of the rough loss, as an optimum of
    one does). The first probes see the offset, not the valley, and the valley is not the flattest
    axis of the Laplace covariance (sd 1 along another); each axis is probed 4x further out while its
    secant sd keeps growing: with a small offset it ends within 10 % of the valley's sd,
    with a large one the probes run out and the axis is reported open (its sd a lower bound) and the
    parameters it dominates with it. The steep axes keep their sds."""
    from jaxform.calibrate.uncertainty import checked_covariance, open_share

    V = np.linalg.qr(np.random.default_rng(1).normal(size=(3, 3)))[0]
    u = V[:, 2]
    # the loss's own curvature V diag(4, 1, 0.01) V^T: sds 0.5, 1, 10
    q = np.array([0.3, -0.2, 0.1])

    L = np.diag([2.0, 1.0, 0.1]) @ V.T  # L^T L = H

    def rows(x):
        return np.append(L @ (x - q), math.sqrt(offset) * float(np.any(x != q)))

    J = np.vstack([np.diag([2.0, 1.0, 10.0]) @ V.T, np.zeros(3)])  # steep (g = 100) along the valley
    cov = np.linalg.inv(J.T @ J)
    out, rep = checked_covariance(rows, q, np.zeros(4), J, cov, np.full(3, -1e3), np.full(3, 1e3), names="abc")
    along = math.sqrt(u @ out @ u)
    ax = max(rep["axes"], key=lambda a: abs(np.dot(a["direction"], u)))
    assert ax["laplace_sd"] == pytest.approx(0.1) and ax["open"] == is_open
    if is_open:
        assert 1.0 < along < 10.0 and max(open_share(rep)) > 0.5
    else:
        assert along == pytest.approx(10.0, rel=0.1) and max(open_share(rep)) == 0.0
    steep = [a for a in rep["axes"] if a is not ax]
    assert all(not a["open"] and a["widened_by"] == pytest.approx(1.0) for a in steep) and rep["lower"] is None

def test_checked_covariance_profiles_its_probes_to_follow_a_valley_the_jacobian_misses():
    """jaxform.calibrate.uncertainty: a linear loss with a valley of sd 10, and a Jacobian whose axes
    are turned 10 degrees from the loss's (Laplace sd 1 along its flattest axis). A probe along
    that axis climbs the valley's wall (0.87 of the valley's rise per unit step comes from the wall:
    the axis alone widens it to about 1.1); each probe re-fits the other axes by one Gauss-Newton
    step of the model before its rise is read (the profile), and the check finds the valley's sd
    within 10 % along it."""
    from jaxform.calibrate.uncertainty import checked_covariance

    U = np.linalg.qr(np.random.default_rng(2).normal(size=(3, 3)))[0]
    L = np.diag([20.0, 5.0, 0.1]) @ U.T  # the loss's sds 0.05, 0.2 and 10 (the valley U[:, 2])
    c, s = math.cos(math.radians(10.0)), math.sin(math.radians(10.0))
    J = np.diag([20.0, 5.0, 1.0]) @ (U @ np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])).T
    q = np.array([0.1, 0.2, -0.3])
    cov = np.linalg.inv(J.T @ J)
    u = U[:, 2]
    out, rep = checked_covariance(lambda x: L @ (x - q), q, np.zeros(3), J, cov, np.full(3, -1e3), np.full(3, 1e3),
                                  names="abc")
    assert math.sqrt(u @ cov @ u) < 1.0 and math.sqrt(u @ out @ u) == pytest.approx(10.0, rel=0.1)
    flat = max(rep["axes"], key=lambda a: a["laplace_sd"])
    assert any("profiled_rise" in pr and pr["profiled_rise"] < 0.1 * pr["on_axis_rise"] for pr in flat["probes"])
    assert not any(a["open"] for a in rep["axes"]) and rep["lower"] is None


def test_scatter_covariance_is_the_spread_of_the_fits_that_the_scatter_alone_moves():
    """jaxform.calibrate.uncertainty.scatter_covariance against an independent reference: the same
    linear least-squares problem re-fitted (numpy lstsq) to each sample of a correlated scatter (a
    shifting wrinkle: a few smooth shapes with random weights, 400 rows). The second moment of those
    fits' shifts is what it must give; the scatter's part along the Jacobian's columns maps one to
    one (a deviation J d moves the fit by -d), the part orthogonal to them not at all."""
    from jaxform.calibrate.uncertainty import scatter_covariance

    rng = np.random.default_rng(5)
    t = np.linspace(0.0, 1.0, 400)
    J = np.stack([np.ones_like(t), t, np.sin(3.0 * t)], 1) * 30.0
    shapes = np.stack([np.exp(-((t - c) / 0.05) ** 2) for c in (0.3, 0.5, 0.7)], 1)
    d = rng.normal(size=(200, 3)) @ shapes.T  # (samples, rows)
    cov0 = np.diag([1e-4, 2e-4, 3e-4])
    total, rep = scatter_covariance(J, d, cov0)
    shifts = np.array([np.linalg.lstsq(J, -x, rcond=None)[0] for x in d])
    assert np.allclose(total - cov0, shifts.T @ shifts / len(d), rtol=1e-8, atol=1e-14)
    assert rep["samples"] == 200 and 0.0 < min(rep["share"]) and max(rep["share"]) < 1.0
    step = np.array([0.01, -0.02, 0.005])
    one = scatter_covariance(J, [J @ step], np.zeros((3, 3)))[0]
    assert np.allclose(one, np.outer(step, step), atol=1e-12)
    ortho = np.linalg.svd(J, full_matrices=True)[0][:, 3]  # orthogonal to every column of J
    assert np.allclose(scatter_covariance(J, [ortho], cov0)[0], cov0, atol=1e-15)
    none, rep0 = scatter_covariance(J, [], cov0)
    assert np.array_equal(none, cov0) and rep0["samples"] == 0
    r = rng.normal(size=400)
    chis = scatter_covariance(J, d[:2], cov0, r)[1]["chi_squares"]
    assert np.allclose(chis, [np.sum((r + x) ** 2) for x in d[:2]])


def test_the_fit_adds_the_scatter_of_its_law_from_imperfect_blanks(monkeypatch):
    """fit_wrinkles runs the fitted law from ``scatter_seeds`` imperfect blanks and adds the scatter
    they show to its covariance. The forming program is stubbed: amplitudes linear in the law (the
    moves test's), plus a shift a_k along the B_init shape of ten times the blank's mean imperfection
    over its amplitude (0 for the fit's perfect blank): each imperfect blank k then moves the fit's
    log B_init by -a_k, and only that. No forming run."""
    case, sec = _stub_case()
    q_true = wf.q_from_law(section_runs.SectionRuns(case, [sec], "voce", 1, 0.0, 1, 1).law0, "voce") + [0.3, 0.0, 0.3]
    shape = np.stack([np.ones(31), np.linspace(-1.0, 1.0, 31), np.zeros(31)], 1)
    amp = 0.1 * float(case.ply_thickness)
    a, fail = {}, [False]

    def stub(Q, Z, rig, lines, static):
        z = np.asarray(Z, float)[:, :, 2]
        shift = (10.0 * z.mean(1) / amp)[:, None]  # 0 for the perfect blank
        for s in np.ravel(shift):
            a[round(float(s), 12)] = float(s)
        y = 1e-3 * ((np.asarray(Q, float) - q_true) @ shape.T + shift * shape[:, 0])
        ok = ~(fail[0] & (np.ravel(shift) != 0.0))  # fail[0]: every imperfect blank's run fails
        return y, np.ones_like(y, bool), ok, np.full(len(Q), 10.0)

    monkeypatch.setattr(section_runs, "_batch", stub)
    kw = dict(n_starts=1, max_iter=4, gradient_check=False, check_rounds=0)
    plain = wf.fit_wrinkles(case, [sec], scatter_seeds=0, **kw)
    fit = wf.fit_wrinkles(case, [sec], scatter_seeds=3, **kw)
    shifts = sorted(v for v in a.values() if v != 0.0)
    assert len(shifts) == 3 and fit.scatter["samples"] == 3 and plain.scatter["samples"] == 0
    assert fit.scatter["failed"] == 0 and plain.scatter["failed"] == 0
    extra = np.asarray(fit.covariance) - np.asarray(plain.covariance)
    assert extra[0, 0] == pytest.approx(np.mean(np.square(shifts)), rel=1e-3)
    assert np.allclose(np.delete(np.delete(extra, 0, 0), 0, 1), 0.0, atol=1e-9 * extra[0, 0])
    assert fit.forming_runs == plain.forming_runs + 3 and fit.as_dict()["scatter"]["share"][0] > 0.5
    assert len(fit.scatter["chi_squares"]) == 3 and min(fit.scatter["chi_squares"]) > 2.0 * fit.loss_final
    fail[0] = True  # failed blanks are left out and counted, not read as no scatter silently
    failed = wf.fit_wrinkles(case, [sec], scatter_seeds=2, **kw)
    assert failed.scatter["samples"] == 0 and failed.scatter["failed"] == 2
    assert np.allclose(failed.covariance, plain.covariance)
    with pytest.raises(ValueError, match="scatter_seeds"):
        wf.fit_wrinkles(case, [sec], scatter_seeds=-1, **kw)
