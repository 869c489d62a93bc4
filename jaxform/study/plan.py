"""The runs of the paper study (``jaxform study paper``): which cases, with which settings, and
whether a run already in the study's folder can be reused.

The study runs, for both fabrics, Case A with NLBM, LBM (B_init, B_41.5, B_inf) and membrane only,
and Case B with NLBM: the twelve presets of :mod:`jaxform.forming.presets`, each in the folder
``DIR/runs/<preset>/``. Runs of one fabric's Case A are batched (they share the mesh;
:func:`jaxform.forming.batch.simulate_batch` groups them by program structure: the four bending laws as
one program, the linear ones written as Voce laws with ``m0 = 0``; membrane-only apart).
"""
from __future__ import annotations

import dataclasses
import json
import pathlib

from jaxform.forming.case import BENDING_MODELS

SETS = {"case-a-woven": ("woven", "a"), "case-a-ncf": ("ncf", "a"), "case-b": (None, "b")}
"""The study's parts (``--only``): name -> (fabric or None for both, paper case)."""
SETTINGS = ("numerics.fibre_mass_scaling=auto",)
"""Overrides every study run gets before the user's ``--set`` (the presets' automatic quasi-static
punch speed is kept, :mod:`jaxform.forming.speed`; the report's numerics section says what ran)."""
FABRIC_SETTINGS = {"ncf": ("numerics.fibre_mass_momentum_term=true",)}
"""Overrides by fabric, after :data:`SETTINGS`. The +-45 deg NCF's fibres run off the blank's
edges, where its corners are held in-plane by shear alone: with the fibre mass but without its
momentum term they whip (README, fibre mass), and on 4 mm elements ``case-a-ncf-nlbm`` blew up at
98.6 % of the stroke with the automatic factor 3. With the term the automatic factor is 12 and
the run completes (183 s at 4 mm, as with 3 where that completed)."""
RUNS_DIR = "runs"
"""Sub-folder of the study holding one ``jaxform run`` folder per run."""


@dataclasses.dataclass(frozen=True)
class StudyRun:
    """One run of the study.

    Attributes:
        name: the preset (and folder) name, e.g. ``case-a-ncf-lbm-41``; part: key of :data:`SETS`;
        fabric: ``woven``/``ncf``; bending: one of ``BENDING_MODELS``; paper_case: ``a``/``b``;
        base: the preset the run's batch starts from; overrides: ``--set`` items making the base
        this run (name, bending law, settings, element size).
    """

    name: str
    part: str
    fabric: str
    bending: str
    paper_case: str
    base: str
    overrides: tuple

    def case(self):
        """The :class:`~jaxform.forming.case.Case` this run uses."""
        from jaxform import cases

        return cases.apply_overrides(cases.load(self.base), list(self.overrides))


def plan(*, only=None, bending=None, element_size_mm: float | None = None, settings=()) -> list[StudyRun]:
    """The study's runs, in order (``only``: one key of :data:`SETS`, or None for all; ``bending``:
    the bending models to run, default all of ``BENDING_MODELS``; Case B runs NLBM only).

    Raises ``ValueError`` for an unknown part or bending model, or a setting that is not a valid
    case override.
    """
    from jaxform import cases

    if only is not None and only not in SETS:
        raise ValueError(f"--only {only!r}: the study's parts are {', '.join(SETS)}")
    bending = tuple(BENDING_MODELS if bending is None else bending)
    bad = [b for b in bending if b not in BENDING_MODELS]
    if bad or not bending:
        raise ValueError(f"--bending {','.join(bending)}: choose from {', '.join(BENDING_MODELS)}")
    common = [*SETTINGS, *settings]
    if element_size_mm is not None:
        if not element_size_mm > 0:
            raise ValueError(f"--element-size-mm {element_size_mm}: must be > 0")
        common.append(f"blank.element_size_mm={float(element_size_mm)!r}")
    runs = []
    for part, (fabric, paper_case) in SETS.items():
        if only is not None and part != only:
            continue
        if paper_case == "a":
            variants = [(fabric, b) for b in BENDING_MODELS if b in bending]
        else:
            variants = [("woven", "nlbm"), ("ncf", "nlbm")] if "nlbm" in bending else []
        for fab, bend in variants:
            name = f"case-{paper_case}-{fab}-{bend}"
            base = f"case-{paper_case}-{fab}-nlbm"
            own = [f"name={json.dumps(name)}"]
            if bend != "nlbm":
                own.append(f"fabric.bending={json.dumps(bend)}")
            runs.append(StudyRun(name, part, fab, bend, paper_case, base,
                                 tuple(own + common[:len(SETTINGS)] + list(FABRIC_SETTINGS.get(fab, ()))
                                       + common[len(SETTINGS):])))
    for r in runs:  # every input checked before anything runs
        cases.apply_overrides(cases.load(r.base), list(r.overrides))
    return runs


NOT_ENDED = ("running", "not run", "interrupted", "error before")
"""Beginnings of the reasons of runs that did not end by themselves (their outcome says nothing)."""


def failed_by_itself(m: dict) -> bool:
    """Whether a run ended incomplete for a reason of its own (blow-up, physical bounds), not
    because it never ran, is still running or was interrupted."""
    reason = m.get("reason") or ""
    return not m.get("complete") and not reason.startswith(NOT_ENDED) and "terminated" not in reason


def comparable(inputs: dict) -> dict:
    """A deep copy of a run's ``inputs`` without what does not change the run (its description)."""
    d = json.loads(json.dumps(inputs))
    d.pop("description", None)
    return d


def differences(have: dict, want: dict, prefix: str = "", label: str = "this study") -> list[str]:
    """``"key = have (label: want)"`` for each leaf where two nested input dicts differ."""
    out = []
    for k in sorted(set(have) | set(want)):
        h, w = have.get(k), want.get(k)
        if isinstance(h, dict) and isinstance(w, dict):
            out += differences(h, w, f"{prefix}{k}.", label)
        elif h != w:
            out.append(f"{prefix}{k} = {h!r} ({label}: {w!r})")
    return out


def run_state(run: StudyRun, folder) -> tuple[bool, str]:
    """``(reusable, why)`` for the run in ``folder``: reusable when its ``summary.json`` says it
    ended (complete, or failed for a reason of its own) with this run's inputs. A run that is
    missing, still 'running', was interrupted, or ran other inputs (another element size or
    setting) is not, and ``why`` says which."""
    from jaxform import cases

    try:
        s = json.loads((pathlib.Path(folder) / "summary.json").read_text())
    except (OSError, ValueError):
        return False, "not run"
    if not s.get("complete") and not failed_by_itself(s):
        return False, s.get("reason") or "not run"
    diff = differences(comparable(s.get("inputs") or {}), comparable(cases.to_dict(run.case())))
    if diff:
        return False, f"the run there has other inputs: {'; '.join(diff[:3])}"
    return True, "complete" if s.get("complete") else f"failed: {s.get('reason')}"


def finished(run: StudyRun, folder) -> str | None:
    """Why the run in ``folder`` can be reused, or None when it must run (:func:`run_state`)."""
    reusable, why = run_state(run, folder)
    return why if reusable else None


__all__ = ["SETS", "SETTINGS", "FABRIC_SETTINGS", "RUNS_DIR", "NOT_ENDED", "failed_by_itself", "StudyRun", "plan", "run_state", "finished",
           "comparable", "differences"]
