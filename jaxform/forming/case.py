"""A forming case (SPEC section 4): the frozen SI description and its validation from TOML-shaped dicts.

A case is written by users in TOML with lengths in **mm** (key names say the unit) and is turned,
at this edge, into a :class:`Case` whose fields are SI. Every key is checked before anything is
compiled: unknown keys, missing values, wrong types and impossible setups (a blank smaller than
the openings, a gap smaller than the stack, non-positive sizes, a punch that does not fit the die)
raise ``ValueError`` naming the key (``section.key``).

TOML layout (every key of the presets; ``jaxform.cases.to_toml(jaxform.cases.load("case-a-woven-nlbm"))``)::

    name = "case-a-woven-nlbm"
    description = "..."
    [fabric]   preset = "woven-38616" | "ncf-fcim359"; bending = "nlbm" | "lbm-init" | "lbm-41" |
               "lbm-inf" | "membrane"; optional: thickness_mm, areal_mass_gsm, friction_tool,
               friction_fabric, voce = {b_inf_Nm, m0_N, kappa0_per_m} (custom NLBM law, both
               families), shear_poly_N_per_m = [c1, c2, ...] (custom odd polynomial), shear_reading =
               "a14" (default) | "conjugate" (how F_norm is read: jaxform.shell, README "Modelling choices")
    [plies]    orientations_deg = [0.0, ...]   (one angle per ply, ply 1 touches the punch)
    [blank]    size_mm, element_size_mm         (square blank centred on the punch axis)
    [tools]    punch_radius_mm, die_opening_radius_mm, die_fillet_mm, die_thickness_mm,
               holder_opening_radius_mm, holder_edge_radius_mm, holder_thickness_mm,
               optional punch_mesh = "file.stl", punch_mesh_units, punch_mesh_cell_mm
    [holder]   mode = "gap" | "force"; gap_mm (gap mode); force_N, mass_kg (force mode)
    [process]  stroke_mm, speed_mm_per_s (simulated punch speed, or "auto": the quasi-static speed of
               jaxform.forming.speed.quasi_static_speed), ramp_fraction, frames
    [contact]  penalty_stiffness_Pa_per_m ("auto" or a number), safety ("auto" or a number in
               (0, 1): (omega_c dt)^2 of one contact, see jaxform.forming.rig), slip_velocity_fraction,
               damping_ratio, optional self_contact (default true: folds lie on themselves),
               optional expected_pressure_Pa ("auto", the default, or > 0: the contact pressure
               the penalty keeps below 10% of the ply, jaxform.forming.numerics.expected_pressure),
               optional implicit_normal ("auto", the default, true or false: jaxform.forming.numerics.contact_numerics)
    [numerics] dtype = "float32" | "float64", mass_scaling, optional fibre_mass_scaling ("auto", the
               default: jaxform.forming.numerics.auto_fibre_mass; or a number >= 1, 1 = off:
               inertia added to fibre stretching only, the membrane limit of the step grows by
               that factor; see jaxform.fibre_mass), optional
               fibre_mass_momentum_term (default false: the exact term of a position-dependent mass)

No I/O and no physics here: TOML text is parsed and written by :mod:`jaxform.io.case_file`, the
presets live in :mod:`jaxform.forming.presets`, and the rig is built by :mod:`jaxform.forming.rig`.
"""
from __future__ import annotations

import dataclasses
import math
from typing import Any

from jaxform import units
from jaxform.penalty import stable_damping_ratio
from jaxform.shell import SHEAR_READINGS
from jaxform.forming.speed import quasi_static_speed

BENDING_MODELS = ("nlbm", "lbm-init", "lbm-41", "lbm-inf", "membrane")
LBM_VARIANTS = {"lbm-init": "init", "lbm-41": "41.5", "lbm-inf": "inf"}
"""Bending model -> the :func:`jaxform.materials.lbm_variant` constant it uses."""


# ---------------------------------------------------------------------------------------------
# The description (SI)
# ---------------------------------------------------------------------------------------------


@dataclasses.dataclass(frozen=True)
class FabricSpec:
    """Which fabric and bending model. Lengths m, areal mass kg/m², laws SI (N·m, N, 1/m, N/m)."""

    preset: str
    bending: str
    thickness: float | None = None
    areal_mass: float | None = None
    friction_tool: float | None = None
    friction_fabric: float | None = None
    voce: tuple | None = None  # (b_inf N·m, m0 N, kappa0 1/m)
    shear_poly: tuple | None = None  # coefficients of g, g^2, ... in N/m
    shear_reading: str = "a14"  # F_norm as eq. A.14's tangent modulus, or "conjugate": the resultant itself


@dataclasses.dataclass(frozen=True)
class ToolSpec:
    """Rig geometry, m (see :mod:`jaxform.tools` for the orientation)."""

    punch_radius: float
    die_opening_radius: float
    die_fillet: float
    die_thickness: float
    holder_opening_radius: float
    holder_edge_radius: float
    holder_thickness: float
    punch_mesh: str | None = None
    punch_mesh_units: str = "mm"
    punch_mesh_cell: float | None = None


@dataclasses.dataclass(frozen=True)
class HolderSpec:
    """Blank holder control: ``mode`` ``"gap"`` (fixed ``gap`` m above the die) or ``"force"``
    (clamping ``force`` N on a holder of ``mass`` kg free to move vertically)."""

    mode: str
    gap: float | None = None
    force: float | None = None
    mass: float | None = None


@dataclasses.dataclass(frozen=True)
class ProcessSpec:
    """Punch stroke m (from first contact), simulated speed m/s, speed ramp (fraction of the stroke time), frames."""

    stroke: float
    speed: float
    ramp_fraction: float
    frames: int
    speed_choice: str | None = None  # why, when the speed was chosen ("auto": jaxform.forming.speed.quasi_static_speed)


@dataclasses.dataclass(frozen=True)
class ContactSpec:
    """Penalty stiffness Pa/m (``None``: automatic, :func:`jaxform.penalty.contact_params`), its stability
    ``safety`` (``(omega_c dt)^2`` of one contact), friction regularisation speed as a fraction of the punch
    speed, normal damping ratio; ``self_contact``: every ply with itself and the plies not next to it
    (:mod:`jaxform.self_contact`, on by default); ``expected_pressure``: Pa; ``implicit_normal``: normal
    forces backward (:mod:`jaxform.backward_normal`). ``None``: automatic (``safety``, ``expected_pressure``
    and ``implicit_normal``: :mod:`jaxform.forming.numerics`)."""

    penalty_stiffness: float | None
    safety: float | None
    slip_velocity_fraction: float
    damping_ratio: float
    self_contact: bool = True
    expected_pressure: float | None = None
    implicit_normal: bool | None = None


@dataclasses.dataclass(frozen=True)
class Case:
    """A hemisphere forming run (SI units throughout)."""

    name: str
    description: str
    fabric: FabricSpec
    orientations: tuple  # rad, one per ply; ply 1 touches the punch
    blank_size: float
    element_size: float
    tools: ToolSpec
    holder: HolderSpec
    process: ProcessSpec
    contact: ContactSpec
    dtype: str
    mass_scaling: float
    fibre_mass_scaling: float | None = None  # None: automatic (jaxform.forming.numerics.auto_fibre_mass)
    fibre_mass_momentum_term: bool = False  # jaxform.fibre_mass.geometric_force

    @property
    def n_plies(self) -> int:
        return len(self.orientations)

    @property
    def ply_thickness(self) -> float:
        """Thickness of one ply, m (the preset's unless overridden)."""
        if self.fabric.thickness is not None:
            return self.fabric.thickness
        from jaxform.materials import preset

        return float(preset(self.fabric.preset).thickness)

    @property
    def stack_thickness(self) -> float:
        return self.n_plies * self.ply_thickness


# ---------------------------------------------------------------------------------------------
# Schema: TOML key -> (kind, required, SI factor); kinds: float, int, str, floats, table
# ---------------------------------------------------------------------------------------------

_MM = units.MM
SCHEMA: dict[str, dict[str, tuple]] = {
    "": {"name": ("str", True), "description": ("str", False)},
    "fabric": {
        "preset": ("str", True), "bending": ("str", True), "thickness_mm": ("float", False),
        "areal_mass_gsm": ("float", False), "friction_tool": ("float", False),
        "friction_fabric": ("float", False), "voce": ("table", False), "shear_poly_N_per_m": ("floats", False),
        "shear_reading": ("str", False),
    },
    "plies": {"orientations_deg": ("floats", True)},
    "blank": {"size_mm": ("float", True), "element_size_mm": ("float", True)},
    "tools": {
        "punch_radius_mm": ("float", True), "die_opening_radius_mm": ("float", True),
        "die_fillet_mm": ("float", True), "die_thickness_mm": ("float", True),
        "holder_opening_radius_mm": ("float", True), "holder_edge_radius_mm": ("float", True),
        "holder_thickness_mm": ("float", True), "punch_mesh": ("str", False),
        "punch_mesh_units": ("str", False), "punch_mesh_cell_mm": ("float", False),
    },
    "holder": {"mode": ("str", True), "gap_mm": ("float", False), "force_N": ("float", False),
               "mass_kg": ("float", False)},
    "process": {"stroke_mm": ("float", True), "speed_mm_per_s": ("auto", True),
                "ramp_fraction": ("float", True), "frames": ("int", True)},
    "contact": {"penalty_stiffness_Pa_per_m": ("auto", True), "safety": ("auto", True),
                "slip_velocity_fraction": ("float", True), "damping_ratio": ("float", True),
                "self_contact": ("bool", False), "expected_pressure_Pa": ("auto", False), "implicit_normal": ("bool_auto", False)},
    "numerics": {"dtype": ("str", True), "mass_scaling": ("float", True), "fibre_mass_scaling": ("auto", False),
                 "fibre_mass_momentum_term": ("bool", False)},
}
_VOCE_KEYS = ("b_inf_Nm", "m0_N", "kappa0_per_m")


def _err(key: str, value: Any, why: str) -> ValueError:
    return ValueError(f"case key '{key}' = {value!r}: {why}")


def _typed(key: str, kind: str, value: Any):
    if kind == "str":
        if not isinstance(value, str):
            raise _err(key, value, "must be a string")
        return value
    if kind in ("bool", "bool_auto"):
        if not isinstance(value, bool) and not (kind == "bool_auto" and value == "auto"):
            raise _err(key, value, "must be true or false" + (', or "auto"' if kind == "bool_auto" else ""))
        return value
    if kind == "int":
        if isinstance(value, bool) or not isinstance(value, int):
            raise _err(key, value, "must be an integer")
        return value
    if kind == "float":
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise _err(key, value, "must be a finite number")
        return float(value)
    if kind == "floats":
        if not isinstance(value, (list, tuple)) or not value:
            raise _err(key, value, "must be a non-empty list of numbers")
        return [_typed(key, "float", v) for v in value]
    if kind == "auto":
        if value == "auto":
            return value
        return _typed(key, "float", value)
    if kind == "table":
        if not isinstance(value, dict):
            raise _err(key, value, "must be a table")
        return value
    raise AssertionError(kind)


def _positive(d, key, section):
    v = d[section][key] if section else d[key]
    if not v > 0:
        raise _err(f"{section}.{key}" if section else key, v, "must be > 0")


def from_dict(data: dict) -> Case:
    """Validate a TOML-shaped dict (mm units) and build the SI :class:`Case`."""
    if not isinstance(data, dict):
        raise ValueError("a case must be a TOML table")
    d: dict[str, Any] = {}
    for key, value in data.items():
        if key in SCHEMA and key:
            if not isinstance(value, dict):
                raise _err(key, value, "must be a table ([section])")
            continue
        if key not in SCHEMA[""]:
            known = ", ".join(sorted(list(SCHEMA[""]) + [s for s in SCHEMA if s]))
            raise ValueError(f"unknown case key '{key}' (known top-level keys: {known})")
    for section, keys in SCHEMA.items():
        src = data if section == "" else data.get(section)
        if src is None:
            raise ValueError(f"missing case section '[{section}]'")
        out = {}
        for key, value in src.items():
            if section == "" and key in SCHEMA and key:
                continue
            full = f"{section}.{key}" if section else key
            if key not in keys:
                raise ValueError(f"unknown case key '{full}' (known keys in [{section or 'top level'}]: "
                                 f"{', '.join(sorted(keys))})")
            out[key] = _typed(full, keys[key][0], value)
        for key, spec in keys.items():
            if spec[1] and key not in out:
                raise ValueError(f"missing case key '{section + '.' if section else ''}{key}'")
        d[section] = out
    return _build(d)


def _build(d) -> Case:
    from jaxform.materials import PRESETS

    fab = d["fabric"]
    if fab["preset"] not in PRESETS:
        raise _err("fabric.preset", fab["preset"], f"must be one of {', '.join(sorted(PRESETS))}")
    if fab["bending"] not in BENDING_MODELS:
        raise _err("fabric.bending", fab["bending"], f"must be one of {', '.join(BENDING_MODELS)}")
    for key in ("thickness_mm", "areal_mass_gsm"):
        if key in fab:
            _positive(d, key, "fabric")
    for key in ("friction_tool", "friction_fabric"):
        if key in fab and fab[key] < 0:
            raise _err(f"fabric.{key}", fab[key], "must be >= 0")
    if fab.get("shear_reading", "a14") not in SHEAR_READINGS:
        raise _err("fabric.shear_reading", fab["shear_reading"], f"must be one of {', '.join(SHEAR_READINGS)} (how "
                   "Table 1's F_norm is read: eq. A.14's tangent modulus, or the shear resultant itself)")
    voce = None
    if "voce" in fab:
        for k in fab["voce"]:
            if k not in _VOCE_KEYS:
                raise ValueError(f"unknown case key 'fabric.voce.{k}' (known: {', '.join(_VOCE_KEYS)})")
        vals = []
        for k in _VOCE_KEYS:
            if k not in fab["voce"]:
                raise ValueError(f"missing case key 'fabric.voce.{k}'")
            v = _typed(f"fabric.voce.{k}", "float", fab["voce"][k])
            if not v > 0:
                raise _err(f"fabric.voce.{k}", v, "must be > 0")
            vals.append(v)
        voce = tuple(vals)
    fabric = FabricSpec(
        preset=fab["preset"], bending=fab["bending"],
        thickness=fab["thickness_mm"] * _MM if "thickness_mm" in fab else None,
        areal_mass=units.gsm_to_kg_per_m2(fab["areal_mass_gsm"]) if "areal_mass_gsm" in fab else None,
        friction_tool=fab.get("friction_tool"), friction_fabric=fab.get("friction_fabric"),
        voce=voce, shear_poly=tuple(fab["shear_poly_N_per_m"]) if "shear_poly_N_per_m" in fab else None,
        shear_reading=fab.get("shear_reading", "a14"),
    )
    if fabric.bending == "lbm-41" and PRESETS[fabric.preset].measured_b41_5 is None:
        raise _err("fabric.bending", "lbm-41", f"preset {fabric.preset!r} has no measured B_41.5")

    for key in ("size_mm", "element_size_mm"):
        _positive(d, key, "blank")
    t = d["tools"]
    for key in ("punch_radius_mm", "die_opening_radius_mm", "die_fillet_mm", "die_thickness_mm",
                "holder_opening_radius_mm", "holder_edge_radius_mm", "holder_thickness_mm"):
        _positive(d, key, "tools")
    if "punch_mesh_cell_mm" in t:
        _positive(d, "punch_mesh_cell_mm", "tools")
    if t.get("punch_mesh_units", "mm") not in ("m", "mm", "cm", "in"):
        raise _err("tools.punch_mesh_units", t["punch_mesh_units"], "must be one of m, mm, cm, in")
    if "punch_mesh" in t and "punch_mesh_cell_mm" not in t:
        raise ValueError("missing case key 'tools.punch_mesh_cell_mm' (required with tools.punch_mesh)")
    for fil, thick in (("die_fillet_mm", "die_thickness_mm"), ("holder_edge_radius_mm", "holder_thickness_mm")):
        if not t[fil] < 0.5 * t[thick]:
            raise _err(f"tools.{fil}", t[fil], f"must be < tools.{thick} / 2 = {0.5 * t[thick]:g} mm")
    tools_spec = ToolSpec(
        punch_radius=t["punch_radius_mm"] * _MM, die_opening_radius=t["die_opening_radius_mm"] * _MM,
        die_fillet=t["die_fillet_mm"] * _MM, die_thickness=t["die_thickness_mm"] * _MM,
        holder_opening_radius=t["holder_opening_radius_mm"] * _MM,
        holder_edge_radius=t["holder_edge_radius_mm"] * _MM, holder_thickness=t["holder_thickness_mm"] * _MM,
        punch_mesh=t.get("punch_mesh"), punch_mesh_units=t.get("punch_mesh_units", "mm"),
        punch_mesh_cell=t["punch_mesh_cell_mm"] * _MM if "punch_mesh_cell_mm" in t else None,
    )

    h = d["holder"]
    if h["mode"] not in ("gap", "force"):
        raise _err("holder.mode", h["mode"], "must be 'gap' or 'force'")
    needed = ("gap_mm",) if h["mode"] == "gap" else ("force_N", "mass_kg")
    for key in needed:
        if key not in h:
            raise ValueError(f"missing case key 'holder.{key}' (required when holder.mode = '{h['mode']}')")
        _positive(d, key, "holder")
    holder = HolderSpec(mode=h["mode"], gap=h["gap_mm"] * _MM if "gap_mm" in h else None,
                        force=h.get("force_N"), mass=h.get("mass_kg"))

    p = d["process"]
    for key in ("stroke_mm",) + (() if p["speed_mm_per_s"] == "auto" else ("speed_mm_per_s",)):
        _positive(d, key, "process")
    if not 0 <= p["ramp_fraction"] < 1:
        raise _err("process.ramp_fraction", p["ramp_fraction"], "must lie in [0, 1)")
    if p["frames"] < 2:
        raise _err("process.frames", p["frames"], "must be >= 2")
    speed, choice = (quasi_static_speed(fabric.preset, [math.radians(a) for a in d["plies"]["orientations_deg"]])
                     if p["speed_mm_per_s"] == "auto" else (p["speed_mm_per_s"] * _MM, None))
    process = ProcessSpec(stroke=p["stroke_mm"] * _MM, speed=speed, ramp_fraction=p["ramp_fraction"],
                          frames=p["frames"], speed_choice=choice)

    c = d["contact"]
    k = c["penalty_stiffness_Pa_per_m"]
    if k != "auto" and not k > 0:
        raise _err("contact.penalty_stiffness_Pa_per_m", k, "must be > 0 or 'auto'")
    safety = c["safety"]
    if safety != "auto" and not 0 < safety < 1:
        raise _err("contact.safety", safety, "must lie in (0, 1) or be 'auto'")
    _positive(d, "slip_velocity_fraction", "contact")
    if (pe := c.get("expected_pressure_Pa", "auto")) != "auto" and not (math.isfinite(pe) and pe > 0):
        raise _err("contact.expected_pressure_Pa", pe, "must be a finite number > 0 (Pa) or 'auto'")
    # 'auto' chooses at most AUTO_SAFETY_MAX (jaxform.forming.numerics.contact_numerics)
    zeta_stable = stable_damping_ratio(AUTO_SAFETY_MAX if safety == "auto" else safety) if k == "auto" else math.inf
    if not 0 <= c["damping_ratio"] <= min(1.0, zeta_stable):
        raise _err("contact.damping_ratio", c["damping_ratio"],
                   f"must lie in [0, {min(1.0, zeta_stable):.3g}]: 1 is critical damping (beyond it the contact "
                   "turns sticky)" + (f"; with contact.safety = {safety} the explicit step is stable only up "
                                      f"to {zeta_stable:.3g}" if zeta_stable < 1.0 else ""))
    contact_spec = ContactSpec(penalty_stiffness=None if k == "auto" else k, safety=None if safety == "auto" else safety,
                               slip_velocity_fraction=c["slip_velocity_fraction"], damping_ratio=c["damping_ratio"],
                               self_contact=c.get("self_contact", True), expected_pressure=None if pe == "auto" else pe,
                               implicit_normal=None if (im := c.get("implicit_normal", "auto")) == "auto" else im)

    n = d["numerics"]
    if n["dtype"] not in ("float32", "float64"):
        raise _err("numerics.dtype", n["dtype"], "must be 'float32' or 'float64'")
    _positive(d, "mass_scaling", "numerics")
    fms = n.get("fibre_mass_scaling", "auto")
    if fms != "auto" and not (math.isfinite(fms) and fms >= 1.0):
        raise _err("numerics.fibre_mass_scaling", fms, "must be a number >= 1 (1 = off) or 'auto'")

    orient = tuple(math.radians(a) for a in d["plies"]["orientations_deg"])
    case = Case(
        name=d[""]["name"], description=d[""].get("description", ""), fabric=fabric, orientations=orient,
        blank_size=d["blank"]["size_mm"] * _MM, element_size=d["blank"]["element_size_mm"] * _MM,
        tools=tools_spec, holder=holder, process=process, contact=contact_spec,
        dtype=n["dtype"], mass_scaling=n["mass_scaling"], fibre_mass_scaling=None if fms == "auto" else fms,
        fibre_mass_momentum_term=n.get("fibre_mass_momentum_term", False),
    )
    _check_setup(case)
    return case


AUTO_SAFETY_MAX = 0.81
"""The largest contact safety ``(omega_c dt)^2`` the automatic choice can make: the step budget
``(2 x 0.9)^2`` shared by :data:`jaxform.forming.numerics.STACKED_CONTACTS` = 4 contacts."""


def _check_shear_poly(coeffs) -> None:
    """A custom shear law must resist shear: positive initial stiffness and a positive force up to 60°."""
    key = "fabric.shear_poly_N_per_m"
    if not coeffs[0] > 0:
        raise _err(key, list(coeffs), "the first coefficient (the initial shear stiffness, N/m) must be > 0")
    for deg in range(1, 61):
        g = math.radians(deg)
        force = sum(c * g ** (i + 1) for i, c in enumerate(coeffs))
        if not force > 0:
            raise _err(key, list(coeffs), f"the shear force must be positive for shear angles up to 60 degrees "
                       f"(it is {force:.4g} N/m at {deg} degrees): a negative force would shear the fabric by itself")


def _check_setup(case: Case) -> None:
    """Impossible rigs, each refused with the key to change."""
    t, mm = case.tools, 1e3
    half = 0.5 * case.blank_size
    need = max(t.die_opening_radius + t.die_fillet, t.holder_opening_radius + t.holder_edge_radius)
    if not half > need:
        raise _err("blank.size_mm", case.blank_size * mm,
                   f"the blank must be larger than the openings: its half-size must exceed "
                   f"{need * mm:g} mm (opening radius + edge radius), i.e. size_mm > {2 * need * mm:g}")
    if not case.element_size <= case.blank_size / 10:
        raise _err("blank.element_size_mm", case.element_size * mm,
                   f"must be <= blank.size_mm / 10 = {case.blank_size * mm / 10:g} (at least 10 elements across)")
    stack = case.stack_thickness
    if t.punch_mesh is None and not t.punch_radius + stack < t.die_opening_radius:
        raise _err("tools.punch_radius_mm", t.punch_radius * mm,
                   f"the punch and the stack ({stack * mm:g} mm) must pass through the die opening "
                   f"(tools.die_opening_radius_mm = {t.die_opening_radius * mm:g})")
    if t.punch_mesh is None and not t.punch_radius + stack < t.holder_opening_radius:
        raise _err("tools.holder_opening_radius_mm", t.holder_opening_radius * mm,
                   f"the punch and the stack ({stack * mm:g} mm) must pass through the holder opening: it must "
                   f"exceed tools.punch_radius_mm + stack = {(t.punch_radius + stack) * mm:g} mm")
    if case.fabric.shear_poly is not None:
        _check_shear_poly(case.fabric.shear_poly)
    if case.holder.mode == "gap" and not case.holder.gap > stack:
        raise _err("holder.gap_mm", case.holder.gap * mm,
                   f"must exceed the stack thickness {stack * mm:g} mm ({case.n_plies} plies)")
    if case.process.stroke > t.die_thickness + t.punch_radius + 0.5 * case.blank_size:
        raise _err("process.stroke_mm", case.process.stroke * mm, "is longer than the rig allows")


# ---------------------------------------------------------------------------------------------
# Back to TOML
# ---------------------------------------------------------------------------------------------


def _mm(x):
    return float(f"{x / _MM:.12g}")


def to_dict(case: Case) -> dict:
    """The TOML-shaped dict (mm units) of a case; ``from_dict(to_dict(c)) == c``."""
    f = case.fabric
    optional = {"thickness_mm": None if f.thickness is None else _mm(f.thickness),
                "areal_mass_gsm": None if f.areal_mass is None else float(f"{units.kg_per_m2_to_gsm(f.areal_mass):.12g}"),
                "friction_tool": f.friction_tool, "friction_fabric": f.friction_fabric,
                "voce": None if f.voce is None else dict(zip(_VOCE_KEYS, f.voce)),
                "shear_poly_N_per_m": None if f.shear_poly is None else list(f.shear_poly),
                "shear_reading": None if f.shear_reading == "a14" else f.shear_reading}  # the default left out
    fab = {"preset": f.preset, "bending": f.bending, **{k: v for k, v in optional.items() if v is not None}}
    t = case.tools
    tools_d = {
        "punch_radius_mm": _mm(t.punch_radius), "die_opening_radius_mm": _mm(t.die_opening_radius),
        "die_fillet_mm": _mm(t.die_fillet), "die_thickness_mm": _mm(t.die_thickness),
        "holder_opening_radius_mm": _mm(t.holder_opening_radius),
        "holder_edge_radius_mm": _mm(t.holder_edge_radius), "holder_thickness_mm": _mm(t.holder_thickness),
    }
    if t.punch_mesh is not None:
        tools_d.update(punch_mesh=t.punch_mesh, punch_mesh_units=t.punch_mesh_units,
                       punch_mesh_cell_mm=_mm(t.punch_mesh_cell))
    h = case.holder
    holder = {"mode": h.mode, **{k: v for k, v in (("gap_mm", None if h.gap is None else _mm(h.gap)),
                                                   ("force_N", h.force), ("mass_kg", h.mass)) if v is not None}}
    p, c = case.process, case.contact
    numerics = {"dtype": case.dtype, "mass_scaling": case.mass_scaling,
                "fibre_mass_scaling": "auto" if case.fibre_mass_scaling is None else case.fibre_mass_scaling,
                "fibre_mass_momentum_term": case.fibre_mass_momentum_term}
    return {
        "name": case.name,
        "description": case.description,
        "fabric": fab,
        "plies": {"orientations_deg": [float(f"{math.degrees(a):.12g}") for a in case.orientations]},
        "blank": {"size_mm": _mm(case.blank_size), "element_size_mm": _mm(case.element_size)},
        "tools": tools_d,
        "holder": holder,
        "process": {"stroke_mm": _mm(p.stroke), "speed_mm_per_s": "auto" if p.speed_choice else _mm(p.speed),
                    "ramp_fraction": p.ramp_fraction,
                    "frames": p.frames},
        "contact": {"penalty_stiffness_Pa_per_m": "auto" if c.penalty_stiffness is None else c.penalty_stiffness,
                    "safety": "auto" if c.safety is None else c.safety, "slip_velocity_fraction": c.slip_velocity_fraction,
                    "damping_ratio": c.damping_ratio, "self_contact": c.self_contact,
                    "expected_pressure_Pa": "auto" if c.expected_pressure is None else c.expected_pressure,
                    "implicit_normal": "auto" if c.implicit_normal is None else c.implicit_normal},
        "numerics": numerics,
    }


def ply_heights(case: Case) -> list[float]:
    """Initial mid-surface height of each ply, m (ply 1 on top)."""
    h, n = case.ply_thickness, case.n_plies
    return [(n - i + 0.5) * h for i in range(1, n + 1)]


__all__ = ["Case", "FabricSpec", "ToolSpec", "HolderSpec", "ProcessSpec", "ContactSpec", "BENDING_MODELS",
           "LBM_VARIANTS", "SCHEMA", "from_dict", "to_dict", "ply_heights"]
