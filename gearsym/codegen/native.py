"""Calling a generated library's functions directly, into caller-owned NumPy buffers.

``casadi.external`` loads the same functions with CasADi's argument handling:
about 15 us per call plus a copy per output. A sweep makes hundreds of
thousands of chunk calls, so the compiled backend calls the C entry points
through ctypes instead: pointers to preallocated arrays in, results written in
place (a run's outputs land directly in its result arrays; the next chunk
reads its start state where the previous one wrote it). The generated
functions keep no state (``checkout`` returns 0), so each ``NativeFunction``
owns its work arrays and distinct objects may run in different threads.
What CasADi would tell of a function (its inputs and outputs, their sparsity, its work sizes) is read from the
entry points the generated C exports beside it (``<f>_n_in``, ``<f>_sparsity_in``, ``<f>_work`` ...): a run on a
cached model never imports CasADi (its import was about a tenth of that start-up).

Where those arrays and the stack sit decided the speed of a step while CasADi's
loops called each step through them: every step stored pointers into the argument
arrays, its state into the work vector and temporaries onto the stack, and loaded
them back at once; a load whose address matches an older store's in its low 12
bits but not in the page (4K aliasing) waits for that store. With the arrays
wherever the allocator put them and the stack wherever the process started, about
one load in a few dozen ran every step 1.2-2.4x slower for its whole life
(bench/speed/notes.md). The loops are now printed by gearsym (:mod:`.printed`:
the state in local arrays, no pointer arrays per step), which leaves the stack
and the per-call arrays; the same placement keeps every load of a library alike.
So the arrays live in one page-aligned block
(argument pointers, result pointers, integer and real work, each on its own cache
lines, never overlapping), and the library's ``gearsym_call`` (compiled into every
library, see :data:`.compiler.CALL_SOURCE`) moves the stack so that it starts at
the same place modulo 4 KiB as that block: every load of a library then places its
memory the same way, and measured at the fast speed.
"""
from __future__ import annotations

import ctypes
from collections.abc import Iterable, Sequence

import numpy as np

from ..errors import GearsymError
from .loaded import open_library

_ptr = ctypes.c_void_p
_int = ctypes.c_longlong  # (the generated C's casadi_int)
PAGE = 4096
LINE = 64


def work_layout(sizes: Sequence[int]) -> tuple[list[int], int]:
    """Offsets of consecutive arrays of ``sizes`` bytes, each starting on a cache line, and the total bytes."""
    offsets, at = [], 0
    for size in sizes:
        offsets.append(at)
        at += -(-max(size, 1) // LINE) * LINE
    return offsets, at


class NativeFunction:
    """One exported function of a generated library, called with raw pointers."""

    def __init__(self, library: ctypes.CDLL, name: str):
        self.name = name
        self._call = getattr(library, name)
        self._call.restype = ctypes.c_int
        self._call.argtypes = [_ptr, _ptr, _ptr, _ptr, ctypes.c_int]
        self.n_in, self.n_out = _count(library, f"{name}_n_in"), _count(library, f"{name}_n_out")
        sparsity_in = [_sparsity(library, f"{name}_sparsity_in", i) for i in range(self.n_in)]
        sparsity_out = [_sparsity(library, f"{name}_sparsity_out", i) for i in range(self.n_out)]
        for i, (_, _, dense) in enumerate(sparsity_in):
            if not dense:
                raise GearsymError(f"{name}: input {i} is sparse; the native call needs dense arrays")
        self.shapes_in = [(rows, cols) for rows, cols, _ in sparsity_in]
        self.shapes_out = [(rows, cols) for rows, cols, _ in sparsity_out]
        self.dense_out = [dense for _, _, dense in sparsity_out]
        work = getattr(library, f"{name}_work")
        work.restype, work.argtypes = ctypes.c_int, [ctypes.POINTER(_int)] * 4
        counts = [_int() for _ in range(4)]
        work(*(ctypes.byref(c) for c in counts))
        # (as casadi.external counts them, so that the arrays sit where they always did: a pointer per input and
        # output of its own, then the function's work)
        arg, res, iw, w = (self.n_in + counts[0].value, self.n_out + counts[1].value, counts[2].value,
                           counts[3].value)
        sizes = [8 * max(n, 1) for n in (arg, res, iw, w)]
        offsets, total = work_layout(sizes)
        self._block = np.zeros(total + PAGE, dtype=np.uint8)
        self.base = -(-self._block.ctypes.data // PAGE) * PAGE  # (page-aligned: the layout is the same in every load)
        at = [self.base + o for o in offsets]
        self._arg = (_ptr * (sizes[0] // 8)).from_address(at[0])
        self._res = (_ptr * (sizes[1] // 8)).from_address(at[1])
        views = [self._block[a - self._block.ctypes.data:][:size] for a, size in zip(at, sizes)]
        self._iw, self._w = views[2].view(np.int64), views[3].view(np.float64)
        self._arg_ptr, self._res_ptr, self._iw_ptr, self._w_ptr = at
        self._entry = ctypes.cast(self._call, _ptr).value
        self._aligned = _stack_aligned_call(library)

    def call(self, args: Sequence[int], results: Sequence[int]) -> None:
        """Evaluate with input and output *addresses* (e.g. ``array.ctypes.data + offset``)."""
        self._arg[:len(args)] = args
        self._res[:len(results)] = results
        if self._aligned is not None:
            failed = self._aligned(self._entry, self._arg_ptr, self._res_ptr, self._iw_ptr, self._w_ptr, self.base)
        else:
            failed = self._call(self._arg_ptr, self._res_ptr, self._iw_ptr, self._w_ptr, 0)
        if failed:
            raise GearsymError(f"the generated function {self.name} reported an error")

    def __call__(self, *args: np.ndarray) -> list[np.ndarray]:
        """Convenience form: arrays in, new arrays out (column-major, as CasADi stores them)."""
        keep = [np.asfortranarray(a, dtype=np.float64) for a in args]
        out = [np.zeros(shape, dtype=np.float64, order="F") for shape in self.shapes_out]
        self.call([a.ctypes.data for a in keep], [o.ctypes.data for o in out])
        return out


def _stack_aligned_call(library: ctypes.CDLL):
    """The library's ``gearsym_call`` (None in a library built without it)."""
    try:
        call = library.gearsym_call
    except AttributeError:
        return None
    call.restype = ctypes.c_int
    call.argtypes = [_ptr] * 6
    return call


def _count(library: ctypes.CDLL, entry: str) -> int:
    """What the generated entry point ``entry`` (``<f>_n_in``, ``<f>_n_out``) returns."""
    f = getattr(library, entry)
    f.restype, f.argtypes = _int, []
    return int(f())


def _sparsity(library: ctypes.CDLL, entry: str, i: int) -> tuple[int, int, bool]:
    """Rows, columns and whether it is dense, of the ``i``-th pattern ``entry`` (``<f>_sparsity_in``) gives, in
    CasADi's compressed form: rows, columns, then 1 for a dense pattern, else the column offsets (from 0) and the
    rows of the nonzeros."""
    f = getattr(library, entry)
    f.restype, f.argtypes = ctypes.POINTER(_int), [_int]
    pattern = f(i)
    rows, cols = int(pattern[0]), int(pattern[1])
    if pattern[2] == 1:  # (the compressed form of a dense pattern; a sparse one starts its offsets with 0)
        return rows, cols, True
    return rows, cols, int(pattern[2 + cols]) == rows * cols


def load_native(path, names: Iterable[str]) -> dict[str, NativeFunction]:
    """The functions ``names`` of the library at ``path``, each with its own work arrays."""
    library = open_library(path)
    return {name: NativeFunction(library, name) for name in names}
