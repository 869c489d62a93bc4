"""Acceptance round trips of the cantilever calibration through jaxform.cantilever (slow).

Issue 6, done-when 1-3: profiles from jaxform.cantilever (known Voce laws unlike the presets, tip
angles 20°-75°, 0.05 mm noise on z) and from the independent reference elastica are fitted back;
the simulated standard test of the paper's NLBM laws is compared with Table 1 (reported, not
tuned). Run with ``pytest -m slow tests/test_calibration_cantilever.py``.
"""
import math

import numpy as np
import pytest

from jaxform import calibrate as C
from jaxform import cantilever
from jaxform.materials import NCF_FCIM359, TABLE1_LBM, WOVEN_38616, VoceBending
from reference import elastica as E

pytestmark = pytest.mark.slow
NOISE = 5e-5  # m


def _sample(x, z, L, rng, n=60):
    xq = np.linspace(0.02 * x[-1], 0.995 * x[-1], n)
    return C.Profile(xq, np.interp(xq, x, z) + rng.normal(0, NOISE, n), L)


# (law, areal mass, overhangs): one reaching >= 5 kappa0, one not
CASES = {
    "determined": (dict(b_inf=2.0e-5, m0=1.5e-3, kappa0=6.0), 0.30, (0.05, 0.075)),  # 38°, 73°; 14-23 kappa0
    "undetermined": (dict(b_inf=3.0e-5, m0=5.0e-3, kappa0=25.0), 0.21, (0.07, 0.095)),
}


@pytest.mark.parametrize("source", ["cantilever", "reference"])
@pytest.mark.parametrize("case", sorted(CASES))
def test_round_trip(case, source):
    params, mass, overhangs = CASES[case]
    rng = np.random.default_rng(0)
    profiles = []
    for L in overhangs:
        if source == "cantilever":
            o = cantilever.simulate(VoceBending(**params), overhang=L, areal_mass=mass)
            x, z, tip = np.asarray(o.x), np.asarray(o.z), float(o.tip_angle)
        else:
            r = E.solve_cantilever(E.voce_moment(**params), L, mass, n=2001)
            x, z, tip = r["x"], r["z"], r["tip_angle"]
        assert 20 <= math.degrees(tip) <= 75
        profiles.append(_sample(x, z, L, rng))
    fit = C.fit_cantilever(profiles, areal_mass=mass, compute_b41_5=False)
    b_init = params["b_inf"] + params["m0"] / params["kappa0"]
    print(f"\n{case}/{source}: B_init {100 * (fit.b_init / b_init - 1):+.2f} %, B_inf "
          f"{100 * (fit.b_inf / params['b_inf'] - 1):+.2f} %, kappa_max/kappa0 {fit.kappa_max_over_kappa0:.1f}, "
          f"determined {fit.b_inf_determined}, rmse {1e3 * fit.rmse:.4f} mm, {fit.iterations} iterations, "
          f"{fit.n_simulations} simulations, {fit.wall_time:.0f} s")
    assert fit.b_init == pytest.approx(b_init, rel=0.03)
    assert fit.b_init == pytest.approx(fit.b_inf + fit.m0 / fit.kappa0, rel=1e-12)
    assert np.all(np.isfinite([fit.b_inf, fit.m0, fit.kappa0]))
    if fit.kappa_max_over_kappa0 >= 5:
        assert fit.b_inf == pytest.approx(params["b_inf"], rel=0.10)
    else:
        assert not fit.b_inf_determined


def test_standard_test_with_paper_laws_report():
    """B_41.5 simulated with the paper's NLBM laws vs the elastica and Table 1 (all rows printed,
    then asserted: the shell within 3 % of the independent elastica, every solve converged; Table 1
    is reported, not asserted)."""
    rows = []
    for name, law, mass, table in (
        ("woven", WOVEN_38616.bending[0], 0.21, TABLE1_LBM["woven-38616"]["41.5"][0]),
        ("ncf pos", NCF_FCIM359.bending[0].pos, 0.44, TABLE1_LBM["ncf-fcim359"]["41.5"][0]),
        ("ncf neg", NCF_FCIM359.bending[0].neg, 0.44, TABLE1_LBM["ncf-fcim359"]["41.5"][1]),
    ):
        try:
            st = cantilever.standard_test(law, areal_mass=mass)
            shell, res = float(st.b_41_5), float(st.max_residual)
        except cantilever.CantileverNotConverged as err:  # reported with the other rows, then failed
            shell, res = float("nan"), float("inf")
            print(f"\n{name}: {err}")
        ref = E.standard_test_b(E.peirce_overhang(E.voce_moment(float(law.b_inf), float(law.m0), float(law.kappa0)), mass), mass)
        rows.append((name, shell, ref, 100 * (shell / ref - 1), table, res))
    print("\nB_41.5 (N·m): name, shell, reference elastica, shell vs elastica, Table 1, solver residual")
    for r in rows:
        print("  %-8s %.4e %.4e %+.2f %% %.1e %.1e" % r)
    for name, shell, ref, _, _, res in rows:
        assert res <= 1e-5, name
        assert shell == pytest.approx(ref, rel=0.03), name  # our shell against the independent elastica
