"""One numba object for everything a kernel reads and writes: the structref pattern of the network's
:func:`~cerebx.snn.kernels.run_step`, written once.

A kernel that takes its arrays one by one, or as named tuples, pays on every call for numba checking each of
them (a few hundred nanoseconds an array); a structref is passed as one pointer whatever it holds. Subclass
:class:`KernelStruct` with the named tuple that lists the fields (arrays, scalars, named tuples of either)::

    class Cord(NamedTuple):
        fifo: np.ndarray
        delay: int

    class CordState(KernelStruct, fields=Cord):
        \"\"\"The spinal cord's arrays as one numba object.\"\"\"

    state = CordState.of(Cord(fifo, 3))   # the same arrays: writes either way are seen both ways

A jitted kernel reads ``state.fifo``, ``state.delay`` as attributes. Define the subclass at module level (its
compiled code and its pickles name it by module and name). Pass the handle as an argument of its own, not inside
a tuple: numba's dispatcher types a tuple holding one through Python at every call (~100 us, against ~1 us).
The handle pickles as the named tuple it was made of, so an object that keeps one checkpoints like its arrays.
"""

from __future__ import annotations

from typing import Any

from numba import njit, types
from numba.experimental import structref


def _packer(cls: type) -> Any:
    """The compiled constructor of ``cls`` from its named tuple, cached on disk (a fresh process loads it) in a
    file of its own: numba names a cache by the function's qualified name, and a file shared by every subclass
    would import each subclass's module (a plugin's too) to read the index."""

    def pack(fields):  # pragma: no cover - numba
        return cls(*fields)

    pack.__qualname__ = f"{cls.__module__}.{cls.__qualname__}.pack"
    return njit(cache=True)(pack)


class KernelStruct(structref.StructRefProxy):
    """Base of a kernel's handle on a named tuple (the class keyword ``fields``): one numba object whose
    attributes are the tuple's fields. Make one with :meth:`of`; ``source`` is the tuple it was made of.

    Parameters
    ----------
    fields : type
        A ``typing.NamedTuple`` class (class keyword): the names and order of the struct's members.
    """

    def __init_subclass__(cls, *, fields: type, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        taken = set(fields._fields) & {"of", "source", "fields", "numba_type"}
        if taken:
            raise TypeError(f"{cls.__name__}: field names {sorted(taken)} are KernelStruct's own")
        numba_type = type(f"{cls.__name__}Type", (types.StructRef,), {
            "__module__": cls.__module__, "__qualname__": f"{cls.__qualname__}.numba_type",
            "__doc__": f"numba type of :class:`{cls.__name__}`."})
        cls.numba_type = structref.register(numba_type)
        cls.fields = fields
        structref.define_proxy(cls, numba_type, fields._fields)
        cls._pack = _packer(cls)

    @classmethod
    def of(cls, source: tuple) -> Any:
        """The kernels' handle on ``source`` (an instance of the class's ``fields``; the same objects, not
        copies).

        Parameters
        ----------
        source : tuple
            The named tuple of arrays and values.

        Returns
        -------
        KernelStruct
            An instance of ``cls`` that a jitted function takes as one argument.
        """
        state = cls._pack(source)
        state.source = source
        return state

    def __reduce__(self) -> tuple:
        return type(self).of, (self.source,)
