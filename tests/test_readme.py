"""The README's Python block runs as written (issue 14 item 9) and gives what its comments say."""
import pathlib
import re

import numpy as np

README = pathlib.Path(__file__).resolve().parents[1] / "README.md"


def test_readme_python_block_runs_as_written():
    text = README.read_text()
    block = re.search(r"From Python.*?```python\n(.*?)```", text, re.S).group(1)
    env: dict = {}
    exec(compile(block, str(README), "exec"), env)  # noqa: S102 - the README's own example
    result, d, k1 = env["result"], env["d"], env["k1"]
    assert result.complete and len(repr(result)) < 200 and "complete" in repr(result)
    assert 0 < result.summary["max_shear_angle_deg"] < 90 and result.summary["draw_in"]["edge_mid_m"] > 0
    assert 0 < float(env["strip"].tip_angle) < np.pi / 2 and np.all(np.isfinite(k1))
    assert len(repr(env["strip"])) < 120 and "tip_angle" in repr(env["strip"])  # results have short reprs
    # the ply lies on the punch at the end of the stroke: its nodes there sit half a ply above it
    top = np.hypot(env["nodes"][:, 0], env["nodes"][:, 1]) < 0.02
    assert top.any()
    np.testing.assert_allclose(np.asarray(d)[top], 0.5 * env["case"].ply_thickness, atol=0.3e-3)

