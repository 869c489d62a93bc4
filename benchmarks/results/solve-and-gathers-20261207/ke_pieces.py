"""Which float32 piece of the step makes float32's extra kinetic energy (issue 13)? Woven Case A NLBM as shipped
at SIZE mm in float64, with one piece of the step computed in float32 (its inputs and parameters rounded to
float32, its outputs cast back): ``shell`` (the shell's forces and energies; ``shell_input``: the shell in
float64 on displacements rounded to float32; ``membrane``, ``bending``: one element gradient of its kernel;
``stretch``: the fibre stretch alone rounded to float32),
``loads`` (the tools' and the
self-contact's forces and their backward friction), ``mass`` (the fibre mass's inverse), or ``none``. A
monkeypatch for this experiment, not library code. Prints one JSON line (ke_seed.measure).
Run: .venv/bin/python ke_pieces.py SIZE PIECE   (both cores)"""
import json
import sys

import jax

jax.config.update("jax_enable_x64", True)
import jax.numpy as jnp  # noqa: E402

from jaxform import cases, contact, forming, integrate, self_contact  # noqa: E402
from ke_seed import measure  # noqa: E402  (this folder's)

size, piece = float(sys.argv[1]), sys.argv[2]


def cast(tree, dtype):
    src = jnp.float64 if dtype == jnp.float32 else jnp.float32
    return jax.tree.map(lambda a: a.astype(dtype) if hasattr(a, "dtype") and a.dtype == src else a, tree)


def in32(fn):
    def wrapped(*args):
        return cast(fn(*cast(args, jnp.float32)), jnp.float64)
    return wrapped


if piece == "shell":
    integrate.forces_and_energy_sym = in32(integrate.forces_and_energy_sym)
elif piece == "shell_input":  # the shell in float64 on displacements rounded to float32
    _sh = integrate.forces_and_energy_sym
    integrate.forces_and_energy_sym = lambda us, shell: _sh(us.astype(jnp.float32).astype(us.dtype), shell)
elif piece in ("membrane", "bending"):  # one element gradient of the shell's kernel in float32 (kinematics and
    # assembly in float64)
    from jaxform import shell as _shell
    name = "_membrane_gradient" if piece == "membrane" else "_bending_gradient"
    setattr(_shell, name, in32(getattr(_shell, name)))
elif piece == "stretch":  # the fibre stretch lambda = |g| alone rounded to float32 (g and the rest in float64)
    from jaxform import shell as _shell
    _st = _shell._stretch
    _shell._stretch = lambda g: _st(g.astype(jnp.float32)).astype(g.dtype)
elif piece == "mass":
    integrate._fm.inverse_mass_times = in32(integrate._fm.inverse_mass_times)
elif piece == "loads":
    for cls in (contact.ToolLoad, self_contact.SelfContactLoad):
        cls.force = in32(cls.force)
        cls.backward = in32(cls.backward)
elif piece != "none":
    sys.exit(f"ke_pieces.py: PIECE = {piece!r}: shell, shell_input, membrane, bending, stretch, loads, mass or none")

case = cases.resolve("case-a-woven-nlbm", element_size=size * 1e-3, overrides=["numerics.dtype=float64"])
res = forming.run(forming.build(case))
print(json.dumps({"size_mm": size, "piece_in_float32": piece, **measure(res)}))
