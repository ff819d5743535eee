"""The suite's own parallel run (the README's pytest -n auto --dist loadgroup) keeps each group on one worker."""
from __future__ import annotations

import os

import pytest


def test_a_parallel_run_sends_each_test_to_its_files_group(request):
    """Under pytest-xdist with --dist loadgroup a test's node id ends with its group (its file, or its page of the
    docs: tests/conftest.py): a pytest whose node ids xdist cannot suffix groups nothing, so each worker would run
    every page of the docs and make every module fixture again."""
    if not os.environ.get("PYTEST_XDIST_WORKER") or request.config.getoption("dist", "no") != "no" \
            or not request.config.getvalue("loadgroup"):
        pytest.skip("not a worker of a parallel run with --dist loadgroup")
    assert request.node.nodeid.endswith("@tests/test_parallel_groups.py"), request.node.nodeid
