"""The physical bounds of a forming run (:mod:`jaxform.forming.health`): which crossings stop a run
as a failed forming (nothing to change) and which as a failed simulation (the driver tries remedies)."""
import numpy as np

from jaxform import cases
from jaxform.forming import build_mesh
from jaxform.forming.driver import Standing
from jaxform.forming.health import (DRAWN_IN, drawn_in, failure_reason, health_bounds, out_of_bounds_message,
                                    physical_causes)
from jaxform.forming.rig import _blank_edges

CALM = {"max_fibre_strain": 0.0, "max_node_speed": 0.0, "max_penetration": 0.0}


def _case_mesh_bounds():
    case = cases.resolve("case-b-woven-nlbm", element_size=25e-3)  # two plies
    mesh = build_mesh(case)
    return case, mesh, health_bounds(case, _blank_edges(mesh))


def test_the_blank_edges_are_every_plys_outer_ring():
    case, mesh, b = _case_mesh_bounds()
    x = np.asarray(mesh.nodes)
    half = 0.5 * case.blank_size
    on_edge = np.max(np.abs(x[:, :2]), axis=1) > half - 1e-9
    assert sorted(b.edge) == np.flatnonzero(on_edge).tolist()
    assert len(b.edge) == case.n_plies * 4 * (mesh.shape[0] - 1)
    assert b.die_opening == case.tools.die_opening_radius


def test_an_edge_node_inside_the_die_opening_is_a_failed_forming_and_nothing_is_retried():
    case, mesh, b = _case_mesh_bounds()
    x = np.array(mesh.nodes)
    assert physical_causes(x, CALM, b) == []
    i = b.edge[-1]  # ply 2's: every ply counts
    x[i, :2] = 0.999 * case.tools.die_opening_radius * np.array([np.cos(0.3), np.sin(0.3)])
    causes = physical_causes(x, CALM, b)
    assert len(causes) == 1 and drawn_in(causes[0]) and f"{1e3 * case.tools.die_opening_radius:.3g} mm opening" in causes[0]
    x[i, :2] = 1.001 * case.tools.die_opening_radius * np.array([1.0, 0.0])  # on the fillet: still a flange
    assert physical_causes(x, CALM, b) == []

    msg = out_of_bounds_message(120, 0.5, 0.03, causes)
    assert msg.startswith("the forming failed near step 120") and "30.00 mm" in msg and "Likely cause" not in msg
    assert failure_reason(msg) == msg
    # beside a numerical cause (an edge node flung into the die) the numerics come first: remedies are tried
    both = causes + ["a node moves at 20 m/s"]
    assert not drawn_in("; ".join(both))
    plain = out_of_bounds_message(120, 0.5, 0.03, both)
    assert "left its physical bounds" in plain and failure_reason(plain) == f"simulation failed: {plain}"
    x[i] = np.nan  # a non-finite edge node is not a drawn-in blank
    assert not any(drawn_in(c) for c in physical_causes(x, CALM, b))

    at = Standing(model=None, state=None, may_cut=True, may_stiffen=True)  # no remedy is tried: nothing is touched
    assert at.recover(None, "; ".join(causes)) is False and at.cuts == [] and at.switched is None
    assert DRAWN_IN in causes[0]
