"""Claim 1 under the other reading of Table 1's shear polynomial: the study of ``screen.py`` (woven
Case A NLBM, 8 mm) with every shell built with ``shear_reading="conjugate"`` (``F_norm`` itself the
shear resultant conjugate to gamma, instead of eq. A.14's tangent modulus, whose resultant is
``integral F_norm dgamma``; ``jaxform.shell``), which the case file cannot choose. A diagnostic of
the claim's cause, not a setting to ship: the summary's inputs do not record the reading.
Run: .venv/bin/python shear_reading.py OUT [SIZE_MM [BENDING]] (8 mm and nlbm by default)."""
import sys

from jaxform import cli
from jaxform.forming import rig
from jaxform.shell import Shell

_build = Shell.build


def conjugate(mesh, fabrics, *, shear_reading="a14"):
    return _build(mesh, fabrics, shear_reading="conjugate")


rig.Shell = type("ConjugateShell", (), {"build": staticmethod(conjugate)})
sys.exit(cli.main(["study", "paper", "--out", sys.argv[1], "--element-size-mm", sys.argv[2] if len(sys.argv) > 2 else "8", "--only", "case-a-woven",
                   "--bending", sys.argv[3] if len(sys.argv) > 3 else "nlbm", "--quiet"]))
