"""Forming cases for users: presets by name, case files by path, overrides (one entry point).

A thin edge over :mod:`jaxform.forming.case` (the SI description and its checks),
:mod:`jaxform.forming.presets` (the paper's cases, ``--set`` overrides) and
:mod:`jaxform.io.case_file` (TOML in and out). The rig a case describes is built by
:func:`jaxform.forming.build`.
"""
from __future__ import annotations

from jaxform.forming.case import (BENDING_MODELS, Case, ContactSpec, FabricSpec, HolderSpec, ProcessSpec, ToolSpec,
                                  from_dict, ply_heights, to_dict)
from jaxform.forming.presets import PRESETS, apply_overrides, list_presets, preset, with_element_size
from jaxform.io.case_file import dumps as to_toml
from jaxform.io.case_file import loads, read_case


def load(name_or_path) -> Case:
    """A preset by name, or a case TOML file by path."""
    if isinstance(name_or_path, str) and name_or_path in PRESETS:
        return preset(name_or_path)
    if not str(name_or_path).endswith(".toml"):
        raise ValueError(f"unknown case {str(name_or_path)!r}: presets are {', '.join(PRESETS)} (or give a .toml file)")
    return read_case(name_or_path)


def resolve(case, *, element_size: float | None = None, overrides=()) -> Case:
    """The case a run uses, normalised once: a :class:`Case`, preset name or ``.toml`` path, with
    ``element_size`` (m) and ``["section.key=value", ...]`` overrides applied."""
    if not isinstance(case, Case):
        case = load(case)
    if element_size is not None:
        case = with_element_size(case, element_size)
    if overrides:
        case = apply_overrides(case, list(overrides))
    return case


def simulate(case, *, element_size: float | None = None, overrides=(), **kwargs):
    """Run a forming case given as a :class:`Case`, a preset name or a ``.toml`` path
    (:func:`resolve`, then :func:`jaxform.forming.simulate` with the other keyword arguments)."""
    from jaxform.forming.driver import simulate as _simulate

    return _simulate(resolve(case, element_size=element_size, overrides=overrides), **kwargs)


def simulate_batch(case, overrides_per_member, *, element_size: float | None = None, overrides=(), **kwargs):
    """Run a forming case (a :class:`Case`, a preset name or a ``.toml`` path, with ``overrides``
    for all) once per member, ``overrides_per_member`` a list of ``["section.key=value", ...]``:
    :func:`jaxform.forming.batch.simulate_batch` with the other keyword arguments (members that
    share a mesh run as one vmapped program over the devices). One result per member."""
    from jaxform.forming.batch import simulate_batch as _batch

    return _batch(resolve(case, element_size=element_size, overrides=overrides), overrides_per_member, **kwargs)


__all__ = ["Case", "FabricSpec", "ToolSpec", "HolderSpec", "ProcessSpec", "ContactSpec", "BENDING_MODELS", "PRESETS",
           "list_presets", "preset", "load", "loads", "resolve", "from_dict", "to_dict", "to_toml", "apply_overrides",
           "with_element_size", "ply_heights", "simulate", "simulate_batch"]
