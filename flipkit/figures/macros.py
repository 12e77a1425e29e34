"""LaTeX number macros from the figure manifest: the report quotes generated numbers only."""

from __future__ import annotations

import json
import math
from pathlib import Path


MACRO_HEADER = r"""% Made by flipkit.figures.write_macros from figures/manifest.json; do not edit.
% \fknum{<figure id>}{<number key>} prints a number of the manifest (nested keys joined by
% ".", list items numbered from 1); \fkmm and \fkpct print metre values in mm and ratios
% in %; \fkmeta{<key>} prints run metadata and the package's configuration (config.*);
% \fkcaption{<figure id>} the figure's caption. An unknown key prints a bold "??" and
% logs "flipkit: undefined number macro <name>".
\providecommand{\fkdef}[3]{\expandafter\def\csname fk@#1@#2\endcsname{#3}}
\providecommand{\fkdefmm}[3]{\expandafter\def\csname fkmm@#1@#2\endcsname{#3}}
\providecommand{\fkdefpct}[3]{\expandafter\def\csname fkpct@#1@#2\endcsname{#3}}
\providecommand{\fkdefmeta}[2]{\expandafter\def\csname fkmeta@#1\endcsname{#2}}
\providecommand{\fkdefcaption}[2]{\expandafter\def\csname fkcaption@#1\endcsname{#2}}
\providecommand{\fklookup}[1]{\ifcsname #1\endcsname\csname #1\endcsname\else
  \textbf{??}\typeout{flipkit: undefined number macro #1}\fi}
\providecommand{\fknum}[2]{\fklookup{fk@#1@#2}}
\providecommand{\fkmm}[2]{\fklookup{fkmm@#1@#2}}
\providecommand{\fkpct}[2]{\fklookup{fkpct@#1@#2}}
\providecommand{\fkmeta}[1]{\fklookup{fkmeta@#1}}
\providecommand{\fkcaption}[1]{\fklookup{fkcaption@#1}}
"""
_TEX_SPECIAL = {"\\": r"\textbackslash{}", "&": r"\&", "%": r"\%", "$": r"\$", "#": r"\#",
                "_": r"\_", "{": r"\{", "}": r"\}", "~": r"\textasciitilde{}",
                "^": r"\textasciicircum{}", "<": r"\textless{}", ">": r"\textgreater{}",
                "|": r"\textbar{}", "μ": r"$\mu$", "δ": r"$\delta$", "ξ": r"$\xi$",
                "→": r"$\rightarrow$", "≤": r"$\le$", "≥": r"$\ge$", "°": r"$^\circ$",
                "±": r"$\pm$", "×": r"$\times$", "−": "-", "–": "--", "—": "---", "²": r"$^2$",
                "·": r"$\cdot$", "’": "'", "‘": "`", "ᵀ": r"$^\top$", "√": r"$\surd$"}


def flatten_numbers(numbers, prefix: str = "") -> list[tuple[str, object]]:
    """The scalar leaves of a figure's ``numbers``: (key, value), nested dict keys joined by
    ``.`` and list items numbered from 1 (``segment_max_error_m.3``), in the stored order.
    One leaf is one LaTeX macro of :func:`write_macros`."""
    if isinstance(numbers, dict):
        items = list(numbers.items())
    elif isinstance(numbers, (list, tuple)):
        items = [(str(k), v) for k, v in enumerate(numbers, 1)]
    else:
        return [(prefix, numbers)]
    out = []
    for key, value in items:
        out += flatten_numbers(value, f"{prefix}.{key}" if prefix else str(key))
    return out


def tex_escape(text: str) -> str:
    """``text`` with LaTeX's special characters escaped (for plain-text macro bodies)."""
    return "".join(_TEX_SPECIAL.get(c, c) for c in str(text))


def format_number(value, digits: int = 3) -> str:
    """A manifest value as LaTeX text: floats rounded to ``digits`` significant digits,
    trailing zeros dropped (scientific, ``\\ensuremath{1.2\\times10^{-5}}``, below 1e-3 or
    from 1e5; negative numbers in ``\\ensuremath`` too, so they work in text and in math),
    integers as they are, booleans as yes/no, None as an en dash, strings escaped."""
    if value is None:
        return "--"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if not math.isfinite(value):
            return "--"
        if value == 0:
            return "0"
        if abs(value) < 1e-3 or abs(value) >= 1e5:
            mant, exp = f"{value:.{digits - 1}e}".split("e")
            return f"\\ensuremath{{{mant}\\times10^{{{int(exp)}}}}}"
        decimals = max(digits - 1 - int(math.floor(math.log10(abs(value)))), 0)
        text = f"{value:.{decimals}f}"
        if "." in text:  # 2.00 -> 2, 0.500 -> 0.5
            text = text.rstrip("0").rstrip(".")
        return f"\\ensuremath{{{text}}}" if text.startswith("-") else text
    return tex_escape(value)


def config_constants() -> dict:
    """The configuration values the report quotes, read from the package (not typed by
    hand): friction coefficients (burger-blade ``mu``, burger-grill ``grill_mu`` of the
    simulated cell), the scoop's commanded press into the grill and its band (mm), the
    flip's landing radius (mm), release fraction and node and minimum landing tilt (deg), acceleration limit, burger and spatula
    sizes, grill height, nodes per segment, and the duration bounds (s) of every
    segment with their sum over pickup-and-flip."""
    # Not at the top: `flipkit --help` imports this module (flipkit.figures), and these load
    # the cell's configuration, pinocchio and CasADi.
    from flipkit.behaviors import library, options
    from flipkit.config import CellConfig, task
    from flipkit.model.flight import TILT_MIN_DEG

    cell = CellConfig()
    out = {"mu": cell.burger.mu, "grill_mu": cell.physics.mu_grill,
           "scoop_press_mm": 1e3 * task.SCOOP_PRESS, "scoop_tip_band_mm": 1e3 * task.SCOOP_TIP_BAND,
           "r_land_mm": 1e3 * task.R_LAND, "release_fraction": task.RELEASE_FRACTION,
           "landing_tilt_min_deg": TILT_MIN_DEG, "mu_safety": task.MU_SAFETY, "mu_plan": task.MU_PLAN,
           "release_press_m_s2": task.RELEASE_PRESS,
           "scoop_start_margin_mm": 1e3 * task.SCOOP_START_MARGIN,
           "flight_margin_mm": 1e3 * task.FLIGHT_MARGIN,
           "release_node": options.SegmentOptions().release_node(),
           "accel_limit_rad_s2": cell.robot.accel_limit, "burger_diameter_m":
               cell.burger.diameter, "burger_thickness_m": cell.burger.thickness,
           "burger_mass_kg": cell.burger.mass,
           "spatula_length_m": cell.spatula.length, "spatula_width_m": cell.spatula.width,
           "grill_height_m": cell.grill.height, "nodes": options.SegmentOptions().N + 1,
           "segment_intervals": options.SegmentOptions().N}
    for name, spec in library.SUBBEHAVIORS.items():
        lo, hi = spec.duration
        out[f"T_{name}_min_s"], out[f"T_{name}_max_s"] = lo, hi
    out["T_pickup_and_flip_max_s"] = round(
        sum(library.SUBBEHAVIORS[n].duration[1] for n in library.FLIP_NAMES), 9)
    return out


def write_macros(manifest, path) -> Path:
    """Write the LaTeX macro file of a figure manifest (``paper/numbers.tex``).

    One ``\\fkdef{<figure>}{<key>}{<value>}`` per scalar leaf of every figure's ``numbers``
    (:func:`flatten_numbers`), read in the report as ``\\fknum{<figure>}{<key>}``; besides,
    keys ending in ``_m`` get a millimetre version (``\\fkmm``) and ratios and fractions
    (keys ending in ``_ratio`` or containing ``fraction``) a percentage (``\\fkpct``), and
    the run metadata (flipkit version, git commit, per-figure quick flag) and
    :func:`config_constants` (``config.<key>``) ``\\fkmeta``, and every caption
    ``\\fkcaption{<figure>}``.

    Args:
        manifest: The manifest as a dict, or the path of ``manifest.json``.
        path: The ``.tex`` file to write (its directory must exist).

    Returns:
        The path written.
    """
    if not isinstance(manifest, dict):
        manifest = json.loads(Path(manifest).read_text())
    lines = [MACRO_HEADER.rstrip("\n"), ""]
    meta = {"flipkit": manifest.get("flipkit"), "git": (manifest.get("git") or "")[:12] or None}
    for fig_id, entry in sorted(manifest.get("figures", {}).items()):
        params = entry.get("parameters") or {}
        meta[f"{fig_id}.quick"] = params.get("quick")
    meta.update({f"config.{k}": v for k, v in config_constants().items()})
    lines += [f"\\fkdefmeta{{{k}}}{{{format_number(v)}}}" for k, v in meta.items()]
    for fig_id, entry in sorted(manifest.get("figures", {}).items()):
        lines.append(f"% {fig_id} ({entry.get('notebook', '')})")
        lines.append(f"\\fkdefcaption{{{fig_id}}}{{{tex_escape(entry.get('caption', ''))}}}")
        for key, value in flatten_numbers(entry.get("numbers", {})):
            lines.append(f"\\fkdef{{{fig_id}}}{{{key}}}{{{format_number(value)}}}")
            numeric = isinstance(value, (int, float)) and not isinstance(value, bool)
            last = key.rsplit(".", 1)[0] if key.rsplit(".", 1)[-1].isdigit() else key
            if numeric and last.endswith("_m"):
                lines.append(f"\\fkdefmm{{{fig_id}}}{{{key}}}{{{format_number(1e3 * value)}}}")
            if numeric and (last.endswith("_ratio") or "fraction" in last):
                lines.append(f"\\fkdefpct{{{fig_id}}}{{{key}}}"
                             f"{{{format_number(100.0 * value, 3)}\\,\\%}}")
    out = Path(path)
    out.write_text("\n".join(lines) + "\n")
    return out
