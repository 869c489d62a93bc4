"""Host-side files of the calibration: profile CSVs, picture-frame CSVs, params JSON, shear TOML.

Units are converted here, once: the files are in the lab's units (mm, degrees, N), everything
returned is SI (m, rad, N/m). Every reader validates what it reads and raises ``ValueError`` naming
the file, what is wrong and how to fix it.
"""
from __future__ import annotations

import csv
import json
import math
import pathlib
import tomllib

import numpy as np

MIN_POINTS = 5


def _read_columns(path, owner: str) -> dict[str, np.ndarray]:
    path = pathlib.Path(path)
    if not path.is_file():
        raise ValueError(f"{owner}: {path}: no such file")
    with path.open(newline="") as fh:
        rows = [r for r in csv.reader(fh) if r and not r[0].lstrip().startswith("#")]
    if not rows:
        raise ValueError(f"{owner}: {path} is empty")
    header = [h.strip().lower() for h in rows[0]]
    cols: dict[str, list] = {h: [] for h in header}
    for lineno, row in enumerate(rows[1:], start=2):
        if len(row) != len(header):
            raise ValueError(f"{owner}: {path} line {lineno}: {len(row)} fields, header has {len(header)}")
        for h, v in zip(header, row):
            v = v.strip()
            try:
                cols[h].append(float(v) if v not in ("", "nan", "NaN") else math.nan)
            except ValueError:
                raise ValueError(f"{owner}: {path} line {lineno}: {h} = {v!r} is not a number") from None
    return {h: np.asarray(v, float) for h, v in cols.items()}


def read_profile_csv(path, overhang: float | None = None):
    """Read a cantilever side profile (header ``x_mm,z_mm``) and return ``(x, z)`` in m.

    Points may come in any order, with gaps and noise: rows with a missing value are dropped,
    points are sorted by x, repeated x are averaged. The file must describe a strip clamped
    horizontally at the origin and hanging down: x from near the clamp (>= -1 mm), z mostly
    negative, at least 5 points, and (given ``overhang``, m) the horizontal extent no longer than
    the strip.

    Raises:
        ValueError: with what is wrong (missing columns, too few points, upward z, first point far
            from the clamp, x beyond the overhang).
    """
    owner = "read_profile_csv"
    cols = _read_columns(path, owner)
    if "x_mm" not in cols or "z_mm" not in cols:
        raise ValueError(
            f"{owner}: {path}: header is {', '.join(cols)}; it must have columns x_mm,z_mm "
            "(mm from the clamp edge, z negative downwards)"
        )
    x, z = cols["x_mm"], cols["z_mm"]
    ok = np.isfinite(x) & np.isfinite(z)
    x, z = x[ok], z[ok]
    if x.size < MIN_POINTS:
        raise ValueError(f"{owner}: {path}: {x.size} valid points; need at least {MIN_POINTS} along the strip")
    order = np.argsort(x, kind="stable")
    x, z = x[order], z[order]
    ux, inv = np.unique(x, return_inverse=True)
    if ux.size < x.size:
        z = np.bincount(inv, weights=z) / np.bincount(inv)
        x = ux
    if x.size < MIN_POINTS:
        raise ValueError(f"{owner}: {path}: {x.size} distinct x values; need at least {MIN_POINTS}")
    if x[0] < -1.0:
        raise ValueError(
            f"{owner}: {path}: x starts at {x[0]:.3g} mm; x is measured from the clamp edge (>= 0) "
            "along the overhang — shift the profile so the clamp is at x = 0"
        )
    span = x[-1] - min(x[0], 0.0)
    if x[0] > 0.25 * span:
        raise ValueError(
            f"{owner}: {path}: the first point is at x = {x[0]:.3g} mm, far from the clamp (x = 0) for a "
            f"profile reaching {x[-1]:.3g} mm; the profile must start near the clamp edge"
        )
    drop = np.median(z[x > 0.5 * x[-1]]) if np.any(x > 0.5 * x[-1]) else z[-1]
    if drop >= 0 or np.mean(z < 0.5) < 0.8:
        raise ValueError(
            f"{owner}: {path}: z is not negative along the strip (median of the outer half {drop:.3g} mm); "
            "z must be negative downwards for a hanging strip — if the profile is upside down, flip "
            "the sign of z_mm"
        )
    if np.max(np.abs(z[x < 0.05 * x[-1]]), initial=0.0) > 0.2 * abs(z[-1]) + 1.0:
        raise ValueError(
            f"{owner}: {path}: z near the clamp is far from 0; the strip must be clamped at the origin"
        )
    xm, zm = x * 1e-3, z * 1e-3
    if overhang is not None:
        if not (np.isfinite(overhang) and overhang > 0):
            raise ValueError(f"{owner}: overhang = {overhang!r} m: must be > 0")
        if xm[-1] > overhang * 1.02:
            raise ValueError(
                f"{owner}: {path}: x reaches {x[-1]:.4g} mm, beyond the overhang {overhang * 1e3:.4g} mm; "
                "the horizontal extent of a hanging strip cannot exceed its length (check --overhang-mm)"
            )
    return xm, zm


def write_profile_csv(path, x, z, *, force: bool = False) -> pathlib.Path:
    """Write a profile (x, z in m) as ``x_mm,z_mm``; refuses to overwrite unless ``force``."""
    path = _check_new(path, force)
    with path.open("w", newline="") as fh:
        wr = csv.writer(fh)
        wr.writerow(["x_mm", "z_mm"])
        for a, b in zip(np.asarray(x) * 1e3, np.asarray(z) * 1e3):
            wr.writerow([f"{a:.6f}", f"{b:.6f}"])
    return path


def read_shear_csv(path, frame_side: float | None = None):
    """Picture-frame data → ``(gamma, f_norm)`` in rad and N/m.

    Accepted headers: ``gamma_rad`` or ``gamma_deg`` with ``f_norm_N_per_m``; or raw frame data
    ``gamma_deg``/``gamma_rad`` (or ``displacement_mm``) with ``force_N``, which needs
    ``frame_side`` (m, pin to pin) and is normalised ``F / (2 L cos(pi/4 - gamma/2))``.
    """
    owner = "read_shear_csv"
    cols = _read_columns(path, owner)
    if "gamma_rad" in cols:
        gamma = cols["gamma_rad"]
    elif "gamma_deg" in cols:
        gamma = np.radians(cols["gamma_deg"])
    elif "displacement_mm" in cols:
        if frame_side is None:
            raise ValueError(f"{owner}: {path}: displacement_mm needs the frame side length (--frame-side-mm)")
        d = cols["displacement_mm"] * 1e-3
        gamma = 0.5 * np.pi - 2.0 * np.arccos(np.sqrt(0.5) + d / (2.0 * frame_side))
    else:
        raise ValueError(
            f"{owner}: {path}: header {', '.join(cols)}: need gamma_rad or gamma_deg (or displacement_mm) "
            "and f_norm_N_per_m (or force_N with the frame side)"
        )
    if "f_norm_n_per_m" in cols:
        f = cols["f_norm_n_per_m"]
    elif "force_n" in cols:
        if frame_side is None:
            raise ValueError(f"{owner}: {path}: raw force_N needs the frame side length (--frame-side-mm)")
        f = cols["force_n"] / (2.0 * frame_side * np.cos(0.25 * np.pi - 0.5 * gamma))
    else:
        raise ValueError(f"{owner}: {path}: no f_norm_N_per_m or force_N column")
    ok = np.isfinite(gamma) & np.isfinite(f)
    if ok.sum() < 3:
        raise ValueError(f"{owner}: {path}: {ok.sum()} valid rows; need at least 3")
    return gamma[ok], f[ok]


def _check_new(path, force: bool) -> pathlib.Path:
    path = pathlib.Path(path)
    if path.exists() and not force:
        raise FileExistsError(f"{path} exists; refusing to overwrite it (pass --force / force=True)")
    path.parent.mkdir(parents=True, exist_ok=True)
    return path


def _json_safe(v):
    if isinstance(v, dict):
        return {k: _json_safe(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [_json_safe(x) for x in v]
    if isinstance(v, (np.floating, float)):
        v = float(v)
        return v if math.isfinite(v) else None
    if isinstance(v, np.integer):
        return int(v)
    if isinstance(v, np.bool_):
        return bool(v)
    return v


def write_json(path, data: dict, *, force: bool = False) -> pathlib.Path:
    """Write ``data`` as JSON (non-finite numbers as null); refuses to overwrite unless ``force``."""
    path = _check_new(path, force)
    path.write_text(json.dumps(_json_safe(data), indent=2) + "\n")
    return path


def shear_toml(fit_dict: dict) -> str:
    """TOML text of a fitted shear law (N/m, rad).

    ``[fabric] shear_poly_N_per_m = [...]`` is the key a forming case (:mod:`jaxform.cases`) reads
    for a custom odd polynomial: merge that line into a case file. ``[shear_fit]`` records the fit
    (kind, range, rmse and, for the NCF form, the stitch knots, which forming cases cannot take
    yet); :func:`read_shear_toml` loads the full law back from it.
    """
    def arr(v):
        return "[" + ", ".join(repr(float(x)) for x in v) + "]"

    lines = ["# Shear law fitted by calibration/fit_shear.py (normalised force N/m, shear angle rad)",
             "[fabric]", f"shear_poly_N_per_m = {arr(fit_dict['coeffs_N_per_m'])}", "", "[shear_fit]",
             f'kind = "{fit_dict["kind"]}"']
    if fit_dict["kind"] == "ncf":
        lines += [f"stitch_gamma_knots_rad = {arr(fit_dict['stitch_gamma_knots_rad'])}",
                  f"stitch_force_knots_N_per_m = {arr(fit_dict['stitch_force_knots_N_per_m'])}"]
    lines += [f"gamma_range_rad = {arr(fit_dict['gamma_range_rad'])}",
              f"rmse_N_per_m = {float(fit_dict['rmse_N_per_m'])!r}",
              f"monotone = {'true' if fit_dict.get('monotone', True) else 'false'}"]
    return "\n".join(lines) + "\n"


def write_shear_toml(path, fit_dict: dict, *, force: bool = False) -> pathlib.Path:
    """Write :func:`shear_toml`; refuses to overwrite unless ``force``."""
    path = _check_new(path, force)
    path.write_text(shear_toml(fit_dict))
    return path


def read_shear_toml(path_or_text):
    """Load a shear law from a ``[shear]`` TOML table (file path or text)."""
    from jaxform.materials import PolynomialShear, ncf_shear

    p = pathlib.Path(path_or_text) if not str(path_or_text).lstrip().startswith(("#", "[")) else None
    data = tomllib.loads(p.read_text() if p is not None else str(path_or_text))
    fab, fit = data.get("fabric", {}), data.get("shear_fit", {})
    if "shear_poly_N_per_m" not in fab:
        raise ValueError("read_shear_toml: no [fabric] shear_poly_N_per_m = [...] in the file")
    coeffs = fab["shear_poly_N_per_m"]
    if fit.get("kind", "polynomial") == "ncf":
        return ncf_shear(coeffs, fit["stitch_gamma_knots_rad"], fit["stitch_force_knots_N_per_m"])
    return PolynomialShear(coeffs)


__all__ = ["read_profile_csv", "write_profile_csv", "read_shear_csv", "write_json", "shear_toml",
           "write_shear_toml", "read_shear_toml"]
