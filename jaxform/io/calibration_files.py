"""Host-side files of the calibration: profile CSVs, picture-frame CSVs, params JSON, shear TOML.

Units are converted here, once: the files are in the lab's units (mm, degrees, N), everything
returned is SI (m, rad, N/m). Every reader validates what it reads and raises ``ValueError`` naming
the file, what is wrong and how to fix it.
"""
from __future__ import annotations

import csv
import json
import math
import os
import pathlib
import tomllib

import numpy as np

MIN_POINTS = 5
MIN_GAMMA_DEG = 1.2  # a gamma_deg column that never reaches this is in radians
MAX_GAMMA_RAD = 1.5  # a gamma_rad column beyond this (86°) is in degrees
MIN_PROFILE_FRACTION = 0.01  # a profile spanning less of its overhang is in the wrong unit


def _read_columns(path, owner: str) -> dict[str, np.ndarray]:
    """Columns of a CSV (lower-case header names → float arrays, missing values as NaN).

    The key ``"#line"`` holds each data row's line number in the file (comments and blank lines
    counted), for messages that name rows.
    """
    path = pathlib.Path(path)
    if not path.is_file():
        raise ValueError(f"{owner}: {path}: no such file")
    with path.open(newline="") as fh:
        reader = csv.reader(fh)
        rows = [(reader.line_num, r) for r in reader if r and not r[0].lstrip().startswith("#")]
    if not rows:
        raise ValueError(f"{owner}: {path} is empty")
    header = [h.strip().lower() for h in rows[0][1]]
    cols: dict[str, list] = {h: [] for h in header}
    lines = []
    for lineno, row in rows[1:]:
        if len(row) != len(header):
            raise ValueError(f"{owner}: {path} line {lineno}: {len(row)} fields, header has {len(header)}")
        for h, v in zip(header, row):
            v = v.strip()
            try:
                cols[h].append(float(v) if v not in ("", "nan", "NaN") else math.nan)
            except ValueError:
                raise ValueError(f"{owner}: {path} line {lineno}: {h} = {v!r} is not a number") from None
        lines.append(lineno)
    out = {h: np.asarray(v, float) for h, v in cols.items()}
    out["#line"] = np.asarray(lines, int)
    return out


def _header(cols) -> str:
    return ",".join(h for h in cols if h != "#line")


def _lines_text(lines) -> str:
    lines = [int(v) for v in lines]
    shown = ", ".join(str(v) for v in lines[:10])
    return f"line{'s' if len(lines) > 1 else ''} {shown}" + (f" (and {len(lines) - 10} more)" if len(lines) > 10 else "")


def _refuse_missing(owner, path, cols, names, show=None) -> None:
    """Refuse rows with a missing or non-finite value in any of ``names``, naming their lines."""
    bad = np.zeros(cols["#line"].shape, bool)
    for n in names:
        bad |= ~np.isfinite(cols[n])
    names = [(show or {}).get(n, n) for n in names]
    if np.any(bad):
        raise ValueError(
            f"{owner}: {path}: {int(bad.sum())} row{'s' if bad.sum() > 1 else ''} with a missing or non-numeric "
            f"value in {','.join(names)} ({_lines_text(cols['#line'][bad])}); every row needs all of "
            f"{','.join(names)} — delete those rows or fill them in"
        )


def _sorted_averaged(x, y):
    """``(x, y)`` sorted by ``x``, the ``y`` of repeated ``x`` averaged."""
    order = np.argsort(x, kind="stable")
    ux, inv = np.unique(x[order], return_inverse=True)
    return ux, np.bincount(inv, weights=y[order]) / np.bincount(inv)


def read_profile_csv(path, overhang: float | None = None):
    """Read a cantilever side profile (header ``x_mm,z_mm``) and return ``(x, z)`` in m.

    Points may come in any order and with noise: points are sorted by x, repeated x are averaged.
    Every row must have both values (rows with a missing value are refused, by line number, not
    dropped: a gap usually means a broken export). The file must describe a strip clamped
    horizontally at the origin and hanging down: x from near the clamp (>= -1 mm), z mostly
    negative, at least 5 points, and (given ``overhang``, m) the horizontal extent and the drop no
    longer than the strip, and a profile spanning at least 1 % of it (a profile in metres in this
    millimetre file spans 0.1 %).

    Raises:
        ValueError: with what is wrong (missing columns or values, too few points, upward z, first
            point far from the clamp, x or z beyond the overhang, a profile in metres).
    """
    owner = "read_profile_csv"
    cols = _read_columns(path, owner)
    if "x_mm" not in cols or "z_mm" not in cols:
        raise ValueError(
            f"{owner}: {path}: header is {_header(cols)}; it must have columns x_mm,z_mm "
            "(mm from the clamp edge, z negative downwards)"
        )
    _refuse_missing(owner, path, cols, ("x_mm", "z_mm"))
    x, z = cols["x_mm"], cols["z_mm"]
    if x.size < MIN_POINTS:
        raise ValueError(f"{owner}: {path}: {x.size} points; need at least {MIN_POINTS} along the strip")
    x, z = _sorted_averaged(x, z)
    if x.size < MIN_POINTS:
        raise ValueError(f"{owner}: {path}: {x.size} distinct x values; need at least {MIN_POINTS}")
    if overhang is not None and not (np.isfinite(overhang) and overhang > 0):
        raise ValueError(f"{owner}: overhang = {overhang!r} m: must be > 0")
    if overhang is not None:
        L_mm = overhang * 1e3
        extent = max(float(x[-1] - min(x[0], 0.0)), float(np.max(np.abs(z))))
        if extent < MIN_PROFILE_FRACTION * L_mm:
            raise ValueError(
                f"{owner}: {path}: the profile spans only {extent:.3g} mm (x up to {x[-1]:.3g} mm, |z| up to "
                f"{np.max(np.abs(z)):.3g} mm), under {100 * MIN_PROFILE_FRACTION:g} % of the {L_mm:.4g} mm overhang; "
                "x_mm,z_mm are millimetres — this looks like a profile in metres (multiply by 1000)"
            )
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
        if xm[-1] > overhang * 1.02:
            raise ValueError(
                f"{owner}: {path}: x reaches {x[-1]:.4g} mm, beyond the overhang {overhang * 1e3:.4g} mm; "
                "the horizontal extent of a hanging strip cannot exceed its length (check --overhang-mm)"
            )
        if np.max(-z) > overhang * 1e3 * 1.02:
            raise ValueError(
                f"{owner}: {path}: z reaches {np.min(z):.4g} mm, a drop beyond the overhang {overhang * 1e3:.4g} mm; "
                "a strip cannot hang lower than its length (check --overhang-mm and the units of z_mm)"
            )
    return xm, zm


def write_profile_csv(path, x, z, *, force: bool = False) -> pathlib.Path:
    """Write a profile (x, z in m) as ``x_mm,z_mm``; refuses to overwrite unless ``force``."""
    return _write_mm_columns(path, ("x_mm", "z_mm"), x, z, force)


def _write_mm_columns(path, header, a, b, force: bool) -> pathlib.Path:
    """Two columns given in m written in mm under ``header``; refuses to overwrite unless ``force``."""
    path = _check_new(path, force)
    with path.open("w", newline="") as fh:
        wr = csv.writer(fh)
        wr.writerow(list(header))
        for u, v in zip(np.asarray(a) * 1e3, np.asarray(b) * 1e3):
            wr.writerow([f"{u:.6f}", f"{v:.6f}"])
    return path


def read_shear_csv(path, frame_side: float | None = None):
    """Picture-frame data → ``(gamma, f_norm)`` in rad and N/m.

    Accepted headers: ``gamma_rad`` or ``gamma_deg`` with ``f_norm_N_per_m``; or raw frame data
    ``gamma_deg``/``gamma_rad`` (or ``displacement_mm``) with ``force_N``, which needs
    ``frame_side`` (m, pin to pin) and is normalised ``F / (2 L cos(pi/4 - gamma/2))``.

    Refused (``ValueError`` naming the file, the column or the rows): missing values (every row
    needs both columns), a ``gamma_deg`` column that never reaches 1.2° (radians under a degree
    header), a ``gamma_rad`` column beyond 1.5 rad (degrees), a displacement the frame cannot
    travel, forces of the opposite sign to the shear angle (beyond 5 % of the peak: noise near
    zero is fine) or all zero, a frame side that is not > 0.
    """
    owner = "read_shear_csv"
    cols = _read_columns(path, owner)
    if frame_side is not None and not (np.isfinite(frame_side) and frame_side > 0):
        raise ValueError(f"{owner}: frame side = {frame_side!r} m: must be > 0 (pin to pin)")
    if "gamma_rad" in cols:
        gname = "gamma_rad"
    elif "gamma_deg" in cols:
        gname = "gamma_deg"
    elif "displacement_mm" in cols:
        gname = "displacement_mm"
    else:
        raise ValueError(
            f"{owner}: {path}: header {_header(cols)}: need gamma_rad or gamma_deg (or displacement_mm) "
            "and f_norm_N_per_m (or force_N with the frame side)"
        )
    if "f_norm_n_per_m" in cols:
        fname = "f_norm_n_per_m"
    elif "force_n" in cols:
        fname = "force_n"
    else:
        raise ValueError(f"{owner}: {path}: header {_header(cols)}: no f_norm_N_per_m or force_N column")
    if (gname == "displacement_mm" or fname == "force_n") and frame_side is None:
        raise ValueError(f"{owner}: {path}: {'displacement_mm' if gname == 'displacement_mm' else 'raw force_N'} "
                         "needs the frame side length (--frame-side-mm)")
    _refuse_missing(owner, path, cols, (gname, fname), show={"f_norm_n_per_m": "f_norm_N_per_m", "force_n": "force_N"})
    fshow = {"f_norm_n_per_m": "f_norm_N_per_m", "force_n": "force_N"}[fname]
    lines, raw_g, raw_f = cols["#line"], cols[gname], cols[fname]
    if raw_g.size < 3:
        raise ValueError(f"{owner}: {path}: {raw_g.size} rows; need at least 3")
    gpeak = float(np.max(np.abs(raw_g)))
    if gname == "gamma_deg" and gpeak < MIN_GAMMA_DEG:
        raise ValueError(
            f"{owner}: {path}: gamma_deg reaches only {gpeak:.3g}° while {fshow} reaches "
            f"{np.max(np.abs(raw_f)):.4g}; a picture-frame test shears to tens of degrees — these look like "
            "radians: name the column gamma_rad (or convert it to degrees)"
        )
    if gname == "gamma_rad" and gpeak > MAX_GAMMA_RAD:
        raise ValueError(
            f"{owner}: {path}: gamma_rad reaches {gpeak:.4g} rad (> {MAX_GAMMA_RAD} rad = 86°); these look like "
            "degrees: name the column gamma_deg (or convert it to radians)"
        )
    if gname == "gamma_rad":
        gamma = raw_g
    elif gname == "gamma_deg":
        gamma = np.radians(raw_g)
    else:
        d = raw_g * 1e-3
        reach = (2.0 - math.sqrt(2.0)) * frame_side
        bad = (d > reach) | (d < -math.sqrt(2.0) * frame_side)
        if np.any(bad):
            raise ValueError(
                f"{owner}: {path}: displacement_mm reaches {raw_g[bad][0]:.4g} mm ({_lines_text(lines[bad])}); a frame "
                f"of side {frame_side * 1e3:.4g} mm travels at most {reach * 1e3:.4g} mm (90° shear) — check the "
                "units of displacement_mm (mm) and --frame-side-mm (pin to pin)"
            )
        gamma = 0.5 * np.pi - 2.0 * np.arccos(np.sqrt(0.5) + d / (2.0 * frame_side))
    if fname == "f_norm_n_per_m":
        f = raw_f
    else:
        f = raw_f / (2.0 * frame_side * np.cos(0.25 * np.pi - 0.5 * gamma))
    peak = float(np.max(np.abs(f)))
    if peak == 0.0:
        raise ValueError(f"{owner}: {path}: {fshow} is zero on every row; there is no force to fit")
    wrong = np.sign(gamma) * f < -0.05 * peak
    if np.any(wrong):
        raise ValueError(
            f"{owner}: {path}: {int(wrong.sum())} of {f.size} rows have a force of the opposite sign to the shear "
            f"angle ({_lines_text(lines[wrong])}, e.g. {gname} = {raw_g[wrong][0]:.4g}, {fshow} = "
            f"{raw_f[wrong][0]:.4g}); the shear force has the sign of the shear angle — if the load cell reads "
            f"tension as negative, flip the sign of {fshow}"
        )
    return gamma, f


def _check_new(path, force: bool) -> pathlib.Path:
    path = pathlib.Path(path)
    if path.exists() and not force:
        raise FileExistsError(f"{path} exists; refusing to overwrite it (pass --force / force=True)")
    path.parent.mkdir(parents=True, exist_ok=True)
    return path


def _write_whole(path: pathlib.Path, text: str) -> None:
    """Write ``text`` to a temporary file beside ``path`` and rename it: an interrupted write
    (Ctrl-C, a full disk) leaves no partial file."""
    tmp = path.with_name(f".{path.name}.tmp")
    try:
        tmp.write_text(text)
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)


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
    _write_whole(path, json.dumps(_json_safe(data), indent=2) + "\n")
    return path


def shear_toml(fit_dict: dict) -> str:
    """TOML text of a fitted shear law (N/m, rad).

    ``[fabric] shear_poly_N_per_m = [...]`` is the key a forming case (:mod:`jaxform.cases`) reads
    for a custom odd polynomial, with ``shear_reading = "conjugate"``: the fitted ``F_norm`` is the
    frame force the test measured, so the formed fabric takes it as its shear resultant and a
    simulated frame gives the measured force back (under the default reading, eq. A.14's tangent
    modulus, the resultant would be its integral: 2.6-3.6x softer over 30-55 deg for the woven law;
    README, "Modelling choices"). Merge those lines into a case file. ``[shear_fit]`` records the fit
    (kind, range, rmse and, for the NCF form, the stitch knots, which forming cases cannot take
    yet); :func:`read_shear_toml` loads the full law back from it.
    """
    def arr(v):
        return "[" + ", ".join(repr(float(x)) for x in v) + "]"

    ok = fit_dict.get("converged", True)
    lines = ["# Shear law fitted by calibration/fit_shear.py (normalised force N/m, shear angle rad)"]
    if not ok:
        lines += ["# NOT A VALID FIT, do not use it in a forming case: " + str(fit_dict.get("reason", ""))]
    lines += ["[fabric]", f"shear_poly_N_per_m = {arr(fit_dict['coeffs_N_per_m'])}",
              "# the measured frame force is the shear resultant (\"a14\", the default, would make it its integral)",
              'shear_reading = "conjugate"', "", "[shear_fit]",
             f'kind = "{fit_dict["kind"]}"']
    if fit_dict["kind"] == "ncf":
        lines += [f"stitch_gamma_knots_rad = {arr(fit_dict['stitch_gamma_knots_rad'])}",
                  f"stitch_force_knots_N_per_m = {arr(fit_dict['stitch_force_knots_N_per_m'])}"]
    lines += [f"gamma_range_rad = {arr(fit_dict['gamma_range_rad'])}",
              f"rmse_N_per_m = {float(fit_dict['rmse_N_per_m'])!r}",
              f"monotone = {'true' if fit_dict.get('monotone', True) else 'false'}",
              f"converged = {'true' if ok else 'false'}"]
    if fit_dict.get("reason"):
        lines.append(f"reason = {json.dumps(str(fit_dict['reason']), ensure_ascii=False)}")
    return "\n".join(lines) + "\n"


def write_shear_toml(path, fit_dict: dict, *, force: bool = False) -> pathlib.Path:
    """Write :func:`shear_toml`; refuses to overwrite unless ``force``."""
    path = _check_new(path, force)
    _write_whole(path, shear_toml(fit_dict))
    return path


def read_shear_toml(path_or_text):
    """Load a shear law from a ``[shear]`` TOML table (file path or text)."""
    from jaxform.materials import PolynomialShear, ncf_shear

    p = pathlib.Path(path_or_text) if not str(path_or_text).lstrip().startswith(("#", "[")) else None
    data = tomllib.loads(p.read_text() if p is not None else str(path_or_text))
    fab, fit = data.get("fabric", {}), data.get("shear_fit", {})
    if "shear_poly_N_per_m" not in fab:
        raise ValueError("read_shear_toml: no [fabric] shear_poly_N_per_m = [...] in the file")
    if fit.get("converged", True) is False:
        raise ValueError(f"read_shear_toml: the file records a fit that did not converge ({fit.get('reason', 'no reason')}); "
                         "refit the data (calibration/fit_shear.py) instead of using it")
    coeffs = fab["shear_poly_N_per_m"]
    if fit.get("kind", "polynomial") == "ncf":
        return ncf_shear(coeffs, fit["stitch_gamma_knots_rad"], fit["stitch_force_knots_N_per_m"])
    return PolynomialShear(coeffs)


def parse_line_mm(text: str, owner: str = "--line"):
    """``"X0,Y0,X1,Y1"`` (mm, top view, punch axis at the origin) → ``(start (2,), end (2,))`` in m."""
    try:
        v = [float(t) for t in str(text).split(",")]
    except ValueError:
        v = []
    if len(v) != 4 or not all(math.isfinite(t) for t in v):
        raise ValueError(f"{owner} {text!r}: give four numbers X0,Y0,X1,Y1 in mm (the section line's end points "
                         "in the top view, punch axis at the origin)")
    a, b = np.array(v[:2]) * 1e-3, np.array(v[2:]) * 1e-3
    return a, b


def read_section_csv(path, start, end):
    """Read a wrinkle section (header ``s_mm,amplitude_mm``) measured along the line from ``start``
    to ``end`` (m) and return a :class:`jaxform.calibrate.sections.Section` in m.

    Rows are sorted by ``s``; repeated positions are averaged; rows with a missing value are
    refused by line number. Whether the line fits a case is checked by
    :func:`jaxform.calibrate.sections.check_section`.
    """
    from jaxform.calibrate.sections import MIN_POINTS, Section

    owner = "read_section_csv"
    cols = _read_columns(path, owner)
    if "s_mm" not in cols or "amplitude_mm" not in cols:
        raise ValueError(f"{owner}: {path}: header is {_header(cols)}; it must have columns s_mm,amplitude_mm "
                         "(position along the line from its start, mm; wrinkle amplitude d_P, mm)")
    _refuse_missing(owner, path, cols, ("s_mm", "amplitude_mm"))
    s, a = cols["s_mm"], cols["amplitude_mm"]
    s, a = _sorted_averaged(s, a)
    if s.size < MIN_POINTS:
        raise ValueError(f"{owner}: {path}: {s.size} distinct positions; need at least {MIN_POINTS} along the section")
    return Section(s * 1e-3, a * 1e-3, np.asarray(start, float), np.asarray(end, float), pathlib.Path(path).name)


def write_section_csv(path, s, amplitude, *, force: bool = False) -> pathlib.Path:
    """Write a section (s, amplitude in m) as ``s_mm,amplitude_mm``; refuses to overwrite unless ``force``."""
    return _write_mm_columns(path, ("s_mm", "amplitude_mm"), s, amplitude, force)


__all__ = ["read_profile_csv", "read_section_csv", "write_section_csv", "parse_line_mm", "write_profile_csv", "read_shear_csv", "write_json", "shear_toml",
           "write_shear_toml", "read_shear_toml"]
