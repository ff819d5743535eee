"""What a sweep spares at each point: tables of time kept while they stay the same, files written once."""
from __future__ import annotations

import numpy as np
import pytest

import conftest
from gearsym import Integration, run_sweep
from gearsym.sweep.store import SweepStore

RUN = Integration(periods=30, discard=10)


@pytest.fixture(scope="module")
def one_stage():
    return conftest.compiled("one_stage")


def test_a_next_point_keeps_the_tables_only_while_no_timed_parameter_changes(one_stage):
    names = list(one_stage.parameter_names)
    assert "omega" not in one_stage.timed_parameters and "B1" in one_stage.timed_parameters
    p = one_stage.parameter_vector()
    first = one_stage.prepare(p)
    p[names.index("omega")] = 1.1  # in place, as a caller may
    second = one_stage.prepare(p)
    assert second.table is first.table
    fresh = one_stage.clone()._tables(p, 0.0)  # (a clone remembers no earlier inputs)
    assert np.array_equal(second.constants, fresh.constants) and second.period == fresh.period
    p[names.index("B1")] = 2.5  # a parameter in the tables, changed in place too
    third = one_stage.prepare(p)
    assert third.table is not first.table
    assert np.array_equal(third.table, one_stage.clone()._tables(p, 0.0).table)
    assert not np.array_equal(third.table, first.table)


def test_a_fresh_sweep_whose_points_finish_in_order_writes_its_tables_once(tmp_path, one_stage, monkeypatch):
    written = []
    original = SweepStore._write_table

    def counting(path, columns, rows):
        written.append(path.name)
        return original(path, columns, rows)

    monkeypatch.setattr(SweepStore, "_write_table", staticmethod(counting))
    run_sweep(one_stage, {"omega": [1.0, 1.2, 1.4]}, options=RUN, progress=False, out=tmp_path / "s.csv")
    assert sorted(written) == ["s.csv", "s.poincare.csv"]  # started, then appended to; not rewritten at the end
    rows = (tmp_path / "s.csv").read_text().splitlines()
    assert len(rows) == 4 and rows[0].startswith("omega,direction")
