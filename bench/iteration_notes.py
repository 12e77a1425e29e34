"""The notes the translate bench prints under its table: why a peer needs more iterations
than exact-Hessian IPOPT. A peer set up as its authors advise should stay within 1.5 × of
exact IPOPT's iterations on the same NLP; where one does not, the bench says why."""

from __future__ import annotations

ITERATION_RATIO = 1.5  # a peer's median iterations within this × exact IPOPT's


def iteration_notes(rows, names, med, labels) -> list[str]:
    """One line per peer whose median iterations exceed :data:`ITERATION_RATIO` × exact
    IPOPT's, with why where its solves were profiled: over all segments, how many of its
    iterations regularised the Hessian and how many cut the primal step below half, beside
    exact IPOPT's (:mod:`flipkit.solvers.step_profile`).

    Args:
        rows: The bench's rows: per segment, ``{solver: {"iterations", "profile"}}`` (a
            profile as a dict of :class:`~flipkit.solvers.step_profile.StepProfile`, or
            ``None``). names: The solvers, in the table's order. med: ``{solver:
            {"iterations": median}}``. labels: ``{solver: name printed}``.
    """
    ref = "ipopt_exact"
    if ref not in names or not med[ref]["iterations"]:
        return []

    def total(name):
        profiles = [r[name]["profile"] for r in rows if r[name].get("profile")]
        return None if not profiles else {k: sum(p[k] for p in profiles) for k in profiles[0]}

    lines, base = [], total(ref)
    for name in names:
        ratio = med[name]["iterations"] / med[ref]["iterations"]
        if name in ("sqp", ref) or ratio <= ITERATION_RATIO:
            continue
        p = total(name)
        why = ("not profiled" if p is None or base is None else
               f"it regularised its Hessian on {p['regularised']} of its {p['iterations']} "
               f"iterations over the segments (exact IPOPT: {base['regularised']} of "
               f"{base['iterations']}) and cut its primal step below half on "
               f"{p['short_steps']} ({base['short_steps']})")
        lines.append(f"{labels[name]}: median {med[name]['iterations']:.0f} "
                     f"iterations, {ratio:.1f} × exact IPOPT's {med[ref]['iterations']:.0f} "
                     f"(over {ITERATION_RATIO:g} ×): {why}")
    return lines


__all__ = ["ITERATION_RATIO", "iteration_notes"]
