"""The registry of constraint terms: each term's numeric rows, symbolic form and independent check.

A *term* is a class of one of two families, each with a registering base class:

* a constraint block (:class:`~flipkit.transcription.constraints.base.Block`), registered in
  :data:`BLOCK_TERMS`: its numeric rows and Jacobian (``evaluate``), its CasADi form
  (``symbolic``) and its :class:`Check`;
* a spatula quantity (:class:`~flipkit.transcription.constraints.quantities.Quantity`) that a
  :class:`~flipkit.transcription.constraints.kinematic.KinematicBlock` applies at its nodes,
  registered in :data:`QUANTITY_TERMS`: its value and Jacobians (``__call__``) and its CasADi
  form (``symbolic``). Its independent check is its block's: the verify groups a kinematic
  block names are those of the spec's hooks that state it.

Defining the class in its module registers it (the base class's ``__init_subclass__``), so a
term's three parts live in one module. A term without a symbolic form says why in
``no_symbolic_form``; a block without an independent check says why in its
:class:`Check`'s ``none``. :meth:`Registry.problems` lists what a term lacks; the symbolic
builder (:mod:`flipkit.transcription.symbolic_blocks`) calls ``symbolic`` on the block, and
``verify`` (:mod:`flipkit.planning.plans.verify_checks`) holds one independent check per
group the terms name.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Check:
    """Where ``verify`` checks a block independently of its rows.

    Attributes:
        groups: Groups of verify's report (:data:`flipkit.planning.plans.verify_report.GROUPS`)
            whose checks recompute what the block requires from the plan's arrays.
        none: Why the block has no independent check of its own (empty when ``groups``
            names them).
    """

    groups: tuple[str, ...] = ()
    none: str = ""

    @property
    def stated(self) -> bool:
        """Whether the check names its groups or says why there are none (not both)."""
        return bool(self.groups) != bool(self.none.strip())


class Registry:
    """The terms of one family, keyed by class, in the order their modules define them.

    Args:
        family: What a term is, for messages ("constraint block").
        numeric: The method that computes a term's numeric rows.
        checked: Whether a term names its own :class:`Check` (blocks) or is checked through
            the block that applies it (quantities).
    """

    def __init__(self, family: str, numeric: str, checked: bool):
        self.family, self.numeric, self.checked = family, numeric, checked
        self.terms: dict[type, None] = {}

    def register(self, cls: type) -> None:
        """Add ``cls`` (called by the family's base class when a term class is defined)."""
        self.terms[cls] = None

    def __iter__(self):
        return iter(self.terms)

    def missing(self, cls: type) -> list[str]:
        """The parts term ``cls`` lacks: ``numeric`` (its rows), ``symbolic`` (a form or a
        stated reason for none), ``check`` (a stated :class:`Check`). A part is there when
        the term's class defines it below the family's base class (the last class of its MRO
        before ``object``)."""
        base = cls.__mro__[-2]
        out = []
        if getattr(cls, self.numeric) is getattr(base, self.numeric):
            out.append("numeric")
        if cls.symbolic is base.symbolic and not str(cls.no_symbolic_form).strip():
            out.append("symbolic")
        check = getattr(cls, "check", None)
        if self.checked and not (isinstance(check, Check) and check.stated):
            out.append("check")
        return out

    def problems(self, terms=None) -> list[str]:
        """One line per term (all, or those of ``terms``) that lacks a part."""
        return [f"{self.family} {cls.__module__}.{cls.__qualname__} lacks "
                f"{', '.join(parts)}"
                for cls in (self.terms if terms is None else terms)
                if (parts := self.missing(cls))]


BLOCK_TERMS = Registry("constraint block", "evaluate", checked=True)
QUANTITY_TERMS = Registry("spatula quantity", "__call__", checked=False)


def checked_groups() -> dict[str, list[type]]:
    """The verify groups the registered blocks name, each with the blocks that name it."""
    out: dict[str, list[type]] = {}
    for cls in BLOCK_TERMS:
        for group in getattr(cls, "check", Check()).groups:
            out.setdefault(group, []).append(cls)
    return out


__all__ = ["BLOCK_TERMS", "QUANTITY_TERMS", "Check", "Registry", "checked_groups"]
