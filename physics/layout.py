"""Named slots of packed arrays: each effect declares the entries it needs by name and gets ints.

The kernels index flat float64 / int64 arrays (parameters, flags and state indices, controls,
diagnostics). Their slots are declared here one after the other, never numbered by hand: a
:class:`Slots` table hands out the next free index for each name (``width`` entries for a
block), and the module-level constants the kernels read (``P_M = params["rotor.mass"]``) are
assigned from it at import time. numba treats module-level ints as compile-time constants, so a
name costs nothing at run time. Because ``@njit`` kernels compile these ints in, this file counts
as kernel source for the on-disk cache (:mod:`physics._jit` hashes every file that mentions
njit): a change to how slots are laid out recompiles the kernels.

A :class:`Layout` holds the tables of the drop model (:mod:`physics.model` builds it by asking
each registered effect to :func:`declare` its slots); the environments' kernels use a
:class:`Slots` table of their own for their configuration, monitor and output arrays.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Iterable, Iterator


class Slots:
    """The slots of one packed array: name -> first index, in declaration order, no gaps.

    ``what`` names the array in error messages (``"parameter"``, ``"control"`` ...)."""

    def __init__(self, what: str):
        self.what = what
        self._start: dict[str, int] = {}
        self._width: dict[str, int] = {}
        self._const: dict[str, str] = {}
        self.size = 0
        self._frozen = False

    def add(self, name: str, width: int = 1, const: str | None = None) -> int:
        """Declare ``name`` as the next ``width`` entries; returns its first index. ``const``:
        the kernels' constant for its first index (``"P_M"``), see :meth:`Layout.constants`."""
        if self._frozen:
            raise RuntimeError(f"the {self.what} slots are complete; {name!r} comes too late")
        if name in self._start:
            raise ValueError(f"{self.what} {name!r} is declared twice")
        if not (isinstance(width, int) and width >= 1):
            raise ValueError(f"{self.what} {name!r}: width must be a positive int, not {width!r}")
        if const is not None:
            if const in self._const.values():
                raise ValueError(f"{self.what} constant {const!r} is declared twice")
            self._const[name] = const
        self._start[name] = self.size
        self._width[name] = width
        self.size += width
        return self._start[name]

    def block(self, *names: str, consts: tuple[str, ...] = ()) -> int:
        """Declare ``names`` as consecutive single entries (with the constants ``consts``, one
        per name, when given); returns the first one's index (the kernels address the others as
        first + k)."""
        first = self.size
        for name, const in zip(names, consts or (None,) * len(names)):
            self.add(name, const=const)
        return first

    def add_each(self, *names: str, consts: tuple[str, ...] = ()) -> tuple[int, ...]:
        """Declare ``names`` as consecutive single entries; returns each one's index."""
        return tuple(self.add(name, const=const)
                     for name, const in zip(names, consts or (None,) * len(names)))

    def constants(self) -> dict[str, int]:
        """The declared constants: constant name -> first index of its slot."""
        return {c: self._start[n] for n, c in self._const.items()}

    def freeze(self) -> "Slots":
        """No more declarations (the size is final)."""
        self._frozen = True
        return self

    def __getitem__(self, name: str) -> int:
        try:
            return self._start[name]
        except KeyError:
            raise KeyError(f"unknown {self.what} {name!r}; the {self.what}s are: "
                           + ", ".join(self._start)) from None

    def indices(self, *names: str) -> tuple[int, ...]:
        """The first index of each of ``names``."""
        return tuple(self[n] for n in names)

    def width(self, name: str) -> int:
        self[name]                                          # a clear error for an unknown name
        return self._width[name]

    def __contains__(self, name: str) -> bool:
        return name in self._start

    def __iter__(self) -> Iterator[str]:
        return iter(self._start)

    def __len__(self) -> int:
        return self.size

    def spans(self) -> list[tuple[str, int, int]]:
        """(name, first, width) of every slot in index order."""
        return sorted(((n, s, self._width[n]) for n, s in self._start.items()),
                      key=lambda t: t[1])

    def check(self) -> None:
        """Every index 0 ... size - 1 belongs to exactly one slot (no overlap, no gap)."""
        at = 0
        for name, first, width in self.spans():
            if first != at:
                raise AssertionError(f"{self.what} {name!r} starts at {first}, expected {at}")
            at += width
        if at != self.size:
            raise AssertionError(f"the {self.what} slots cover {at} entries, not {self.size}")


class Layout:
    """The packed arrays of the drop model, each a :class:`Slots` table:

    * ``params``: float64 ``P`` (parameters),
    * ``index``: int64 ``I`` (runtime flags ``F_*`` and first state indices, -1 when absent),
    * ``plane``: the per-retainer-plane block of ``I`` (state indices ``J_*``),
    * ``controls``: float64 ``U`` (inputs that may change between integration segments),
    * ``aux``: float64 diagnostics, and ``plane_aux`` the per-retainer-plane block of it.

    State vectors are laid out per scene (an effect that is off adds no state): see
    :func:`physics.model.build_model`."""

    def __init__(self):
        self.params = Slots("parameter")
        self.index = Slots("index")
        self.plane = Slots("plane index")
        self.controls = Slots("control")
        self.aux = Slots("diagnostic")
        self.plane_aux = Slots("plane diagnostic")

    def tables(self) -> tuple[Slots, ...]:
        return self.params, self.index, self.plane, self.controls, self.aux, self.plane_aux

    def constants(self) -> dict[str, int]:
        """Every constant the kernels index with, generated from the declarations: each slot
        declared with ``const=`` (``P_M``: the first index of ``rotor.mass`` in ``P``) and the
        arrays' sizes (``N_P``, ``N_I``, ``N_U``, ``N_AUX``; ``N_PLANE_IDX`` and ``N_AUX_PLANE``
        of the per-plane blocks; ``I_PLANES``, the first plane's block in ``I``). A name
        declared twice is an error naming it."""
        out: dict[str, int] = {}
        for table in self.tables():
            for name, value in table.constants().items():
                if name in out:
                    raise ValueError(f"constant {name!r} is declared twice")
                out[name] = value
        out.update(N_P=self.params.size, N_I=self.index.size, N_U=self.controls.size,
                   N_AUX=self.aux.size, N_PLANE_IDX=self.plane.size,
                   N_AUX_PLANE=self.plane_aux.size, I_PLANES=self.index["planes"])
        return out

    def bind(self, module) -> None:
        """Make :meth:`constants` module-level names of ``module`` (an effect module whose
        kernels index the packed arrays, or its ``globals()``). numba reads a kernel's globals
        when it first compiles it and compiles module-level ints in as constants, so a bound name
        costs nothing at run time; :mod:`physics.model` binds every registered effect when it
        builds the layout, before any kernel compiles."""
        names = module if isinstance(module, dict) else vars(module)
        names.update(self.constants())

    @classmethod
    def build(cls, effects: Iterable, planes: int = 2) -> "Layout":
        """Ask each effect (a module or object with ``declare(layout)``) for its slots, in order,
        then place the per-plane blocks (one per retainer plane): ``index["planes"]`` after the
        declared index slots, ``aux["planes"]`` before the declared diagnostics (the diagnostics
        array starts with the planes' columns)."""
        layout = cls()
        for effect in effects:
            effect.declare(layout)
        layout.plane.freeze()
        layout.plane_aux.freeze()
        layout.index.add("planes", planes * layout.plane.size)
        declared, layout.aux = layout.aux, Slots("diagnostic")
        layout.aux.add("planes", planes * layout.plane_aux.size)
        for name, _, width in declared.spans():
            layout.aux.add(name, width, declared._const.get(name))
        for table in layout.tables():
            table.freeze().check()
        return layout


@dataclass(frozen=True)
class StateSizes:
    """Sizes an effect scales its states by (tolerance size: atol = rtol x size; observation
    size: the state's physical size for observations): the clearance, a tilt (clearance over the
    lever arm to the farther retainer plane), a spin speed, a translational velocity, the lever
    arm, and two energies (the rotor's kinetic energy at ``velocity`` and its spin energy)."""
    clearance: float
    tilt: float
    spin: float
    velocity: float
    lever: float
    energy: float
    spin_energy: float
