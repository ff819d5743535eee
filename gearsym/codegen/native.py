"""Calling a generated library's functions directly, into caller-owned NumPy buffers.

``casadi.external`` loads the same functions with CasADi's argument handling:
about 15 us per call plus a copy per output. A sweep makes hundreds of
thousands of chunk calls, so the compiled backend calls the C entry points
through ctypes instead: pointers to preallocated arrays in, results written in
place (a run's outputs land directly in its result arrays; the next chunk
reads its start state where the previous one wrote it). The generated
functions keep no state (``checkout`` returns 0), so each ``NativeFunction``
owns its work arrays and distinct objects may run in different threads.
"""
from __future__ import annotations

import ctypes
from collections.abc import Sequence

import casadi as ca
import numpy as np

from ..errors import GearsymError

_ptr = ctypes.c_void_p


class NativeFunction:
    """One exported function of a generated library, called with raw pointers."""

    def __init__(self, library: ctypes.CDLL, name: str, reference: ca.Function):
        self.name = name
        self._call = getattr(library, name)
        self._call.restype = ctypes.c_int
        self._call.argtypes = [_ptr, _ptr, _ptr, _ptr, ctypes.c_int]
        self.n_in, self.n_out = reference.n_in(), reference.n_out()
        for i in range(self.n_in):
            if not reference.sparsity_in(i).is_dense():
                raise GearsymError(f"{name}: input {i} is sparse; the native call needs dense arrays")
        self.shapes_out = [reference.size_out(i) for i in range(self.n_out)]
        self._arg = (_ptr * max(reference.sz_arg(), 1))()
        self._res = (_ptr * max(reference.sz_res(), 1))()
        self._iw = np.zeros(max(reference.sz_iw(), 1), dtype=np.int64)
        self._w = np.zeros(max(reference.sz_w(), 1), dtype=np.float64)
        self._iw_ptr, self._w_ptr = self._iw.ctypes.data, self._w.ctypes.data
        self._arg_ptr, self._res_ptr = ctypes.addressof(self._arg), ctypes.addressof(self._res)

    def call(self, args: Sequence[int], results: Sequence[int]) -> None:
        """Evaluate with input and output *addresses* (e.g. ``array.ctypes.data + offset``)."""
        self._arg[:len(args)] = args
        self._res[:len(results)] = results
        if self._call(self._arg_ptr, self._res_ptr, self._iw_ptr, self._w_ptr, 0):
            raise GearsymError(f"the generated function {self.name} reported an error")

    def __call__(self, *args: np.ndarray) -> list[np.ndarray]:
        """Convenience form: arrays in, new arrays out (column-major, as CasADi stores them)."""
        keep = [np.asfortranarray(a, dtype=np.float64) for a in args]
        out = [np.zeros(shape, dtype=np.float64, order="F") for shape in self.shapes_out]
        self.call([a.ctypes.data for a in keep], [o.ctypes.data for o in out])
        return out


def load_native(path, functions: dict[str, ca.Function]) -> dict[str, NativeFunction]:
    library = ctypes.CDLL(str(path))
    return {name: NativeFunction(library, name, f) for name, f in functions.items()}
