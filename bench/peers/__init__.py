"""Peer implementations of the Lyapunov-spectrum task, one module per tool.

Each module has ``make(model, accuracy=None, **params) -> Tool`` (see
``common.Tool``): ``c_yardstick`` (the hand-written C programs), ``numba_rk4``,
``jitcode_lyap``, ``scipy_ivp``, and gearsym itself (``gearsym_tool``, which also takes the ``scheme``: the
paper's ``Integration.paper()`` or the crossings located). ``python -m bench.peers.check`` checks that they agree.
"""
import importlib
from types import ModuleType

PEERS = ("c_yardstick", "numba_rk4", "jitcode_lyap", "scipy_ivp", "gearsym_tool")


def load(name: str) -> ModuleType:
    """The peer module ``name`` (imported on demand: numba and jitcode are slow to import)."""
    if name not in PEERS:
        raise ValueError(f"unknown peer {name!r}; known: {PEERS}")
    return importlib.import_module(f"bench.peers.{name}")
