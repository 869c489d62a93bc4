"""The paper's forming cases as presets (SPEC sections 4 and 6) and ``--set``-style overrides.

No I/O and no physics: presets are TOML-shaped dicts validated by :func:`jaxform.forming.case.from_dict`;
:func:`apply_overrides` edits a case the way ``jaxform run --set key=value`` does.
"""
from __future__ import annotations

import copy
import tomllib

from jaxform import units
from jaxform.forming.case import BENDING_MODELS, SCHEMA, Case, from_dict, to_dict

FABRIC_PRESETS = {"woven": "woven-38616", "ncf": "ncf-fcim359"}
_MM = units.MM

_BASE = {
    "tools": {"punch_radius_mm": 50.0, "die_opening_radius_mm": 53.0, "die_fillet_mm": 6.0,
              "die_thickness_mm": 20.0, "holder_opening_radius_mm": 53.0, "holder_edge_radius_mm": 1.0,
              "holder_thickness_mm": 20.0},
    "process": {"stroke_mm": 50.0, "speed_mm_per_s": "auto", "ramp_fraction": 0.1, "frames": 11},
    "contact": {"penalty_stiffness_Pa_per_m": "auto", "safety": "auto", "slip_velocity_fraction": 0.01,
                "damping_ratio": 0.1},
    "numerics": {"dtype": "float32", "mass_scaling": 1.0, "fibre_mass_scaling": "auto"},
}
_BENDING_TEXT = {
    "nlbm": "non-linear (Voce) bending", "lbm-init": "linear bending, B_init", "lbm-41": "linear bending, B_41.5",
    "lbm-inf": "linear bending, B_inf", "membrane": "membrane only (no bending)",
}
_FABRIC_TEXT = {"woven": "woven 38616 twill", "ncf": "NCF FCIM359"}


def _preset_dict(case: str, fabric: str, bending: str) -> dict:
    d = copy.deepcopy(_BASE)
    name = f"case-{case}-{fabric}-{bending}"
    if case == "a":
        desc = f"Case A: one ply of {_FABRIC_TEXT[fabric]}, {_BENDING_TEXT[bending]}, 7 mm holder gap, 2 mm elements"
        d.update(plies={"orientations_deg": [0.0]}, blank={"size_mm": 250.0, "element_size_mm": 2.0},
                 holder={"mode": "gap", "gap_mm": 7.0})
    else:
        desc = (f"Case B: two plies of {_FABRIC_TEXT[fabric]} (same orientation), {_BENDING_TEXT[bending]}, "
                "holder clamped with 1000 N, 1 mm elements")
        d.update(plies={"orientations_deg": [0.0, 0.0]}, blank={"size_mm": 250.0, "element_size_mm": 1.0},
                 holder={"mode": "force", "force_N": 1000.0, "mass_kg": 5.0})
    d.update(name=name, description=desc, fabric={"preset": FABRIC_PRESETS[fabric], "bending": bending})
    return d


PRESETS: dict[str, dict] = {}
for _fab in ("woven", "ncf"):
    for _b in BENDING_MODELS:
        PRESETS[f"case-a-{_fab}-{_b}"] = _preset_dict("a", _fab, _b)
for _fab in ("woven", "ncf"):
    PRESETS[f"case-b-{_fab}-nlbm"] = _preset_dict("b", _fab, "nlbm")


def list_presets() -> list[tuple[str, str]]:
    """``(name, one-line description)`` of every preset, in SPEC order."""
    return [(name, d["description"]) for name, d in PRESETS.items()]


def preset(name: str) -> Case:
    """The preset case called ``name``."""
    if name not in PRESETS:
        raise ValueError(f"unknown case {name!r}: presets are {', '.join(PRESETS)} (or give a .toml file)")
    return from_dict(copy.deepcopy(PRESETS[name]))



def _parse_value(text: str):
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        return text  # a bare word: a string


def apply_overrides(case: Case, assignments) -> Case:
    """Apply ``["section.key=value", ...]`` (TOML units and syntax; bare words are strings).

    ``--set holder.gap_mm=5 --set plies.orientations_deg=[0,45]``; each is validated like a file.
    """
    d = to_dict(case)
    assignments = list(assignments)
    for item in assignments:
        if "=" not in item:
            raise ValueError(f"override {item!r}: expected key=value (e.g. holder.gap_mm=5)")
        key, text = (s.strip() for s in item.split("=", 1))
        parts = key.split(".")
        value = _parse_value(text)
        if len(parts) == 1:
            if key not in SCHEMA[""]:
                raise ValueError(f"unknown case key '{key}' in override {item!r}")
            d[key] = value
            continue
        section, rest = parts[0], parts[1:]
        if section not in SCHEMA or not section:
            raise ValueError(f"unknown case key '{key}' in override {item!r}: no section [{section}]")
        target = d[section]
        for p in rest[:-1]:
            target = target.setdefault(p, {})
            if not isinstance(target, dict):
                raise ValueError(f"unknown case key '{key}' in override {item!r}")
        target[rest[-1]] = value
    if assignments and not any(a.split("=", 1)[0].strip() == "description" for a in assignments):
        # a preset's text names its own element size, holder mode...: say what was changed
        d["description"] = f"{d.get('description', '')} (overridden: {', '.join(a.strip() for a in assignments)})".strip()
    return from_dict(d)


def with_element_size(case: Case, size: float) -> Case:
    """The case with another element size, m (``--element-size-mm``)."""
    return apply_overrides(case, [f"blank.element_size_mm={size / _MM!r}"])


__all__ = ["PRESETS", "FABRIC_PRESETS", "list_presets", "preset", "apply_overrides", "with_element_size"]
